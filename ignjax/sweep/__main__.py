"""``python -m ignjax.sweep``."""

import sys

from ignjax.sweep.runner import main

sys.exit(main())
