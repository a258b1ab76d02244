"""``python -m ignjax.sweep``."""

import sys

from ignjax.sweep.cli import main

sys.exit(main())
