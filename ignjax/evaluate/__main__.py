"""``python -m ignjax.evaluate``."""

from ignjax.scenes.viz import headless_gl

headless_gl()  # before anything imports mujoco: headless EGL where it is installed and MUJOCO_GL is unset

from ignjax.devices import configure_cpu_devices  # noqa: E402

configure_cpu_devices()  # before JAX starts: one CPU device per core (IGNJAX_CPU_DEVICES overrides)

from ignjax.evaluate.cli import main  # noqa: E402
from ignjax.devices.quickexit import exit_now  # noqa: E402

exit_now(main())  # without Python's teardown (ignjax.devices.quickexit)
