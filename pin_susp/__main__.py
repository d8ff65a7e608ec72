"""``python -m pin_susp``: the ``pin-susp`` command."""

import sys

from .cli import main

sys.exit(main())
