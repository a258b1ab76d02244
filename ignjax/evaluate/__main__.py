"""``python -m ignjax.evaluate``."""

import sys

from ignjax.devices import configure_cpu_devices

configure_cpu_devices()  # before JAX starts: one CPU device per core (IGNJAX_CPU_DEVICES overrides)

from ignjax.evaluate.cli import main  # noqa: E402

sys.exit(main())
