"""``python -m ignjax.view``: see :mod:`ignjax.view.cli`."""

from ignjax.scenes.viz import headless_gl

headless_gl()  # before anything imports mujoco: headless EGL where it is installed and MUJOCO_GL is unset

from ignjax.view.cli import main  # noqa: E402
from ignjax.devices.quickexit import exit_now  # noqa: E402

exit_now(main())  # without Python's teardown (ignjax.devices.quickexit)
