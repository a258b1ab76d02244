"""``python -m ignjax.view``: see :mod:`ignjax.view.cli`."""

import sys

from ignjax.scenes.viz import headless_gl

headless_gl()  # before anything imports mujoco: headless EGL where it is installed and MUJOCO_GL is unset

from ignjax.view.cli import main  # noqa: E402

sys.exit(main())
