"""``python -m ignjax.build``."""

from ignjax.scenes.viz import headless_gl

headless_gl()  # before anything imports mujoco

from ignjax.build.cli import main  # noqa: E402
from ignjax.devices.quickexit import exit_now  # noqa: E402

exit_now(main())  # without Python's teardown (ignjax.devices.quickexit)
