"""``python -m ignjax.build``."""

import sys

from ignjax.build.cli import main

sys.exit(main())
