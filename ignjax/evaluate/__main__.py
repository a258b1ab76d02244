"""``python -m ignjax.evaluate``."""

import sys

from ignjax.evaluate.cli import main

sys.exit(main())
