"""``python -m ignjax.view``: see :mod:`ignjax.view.cli`."""

import sys

from ignjax.view.cli import main

sys.exit(main())
