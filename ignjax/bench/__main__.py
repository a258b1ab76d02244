"""``python -m ignjax.bench``."""

import sys

from ignjax.bench.runner import main

sys.exit(main())
