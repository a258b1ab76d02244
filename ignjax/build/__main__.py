"""``python -m ignjax.build``."""

import sys

from ignjax.scenes.viz import headless_gl

headless_gl()  # before anything imports mujoco

from ignjax.build.cli import main  # noqa: E402

sys.exit(main())
