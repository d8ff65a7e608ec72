"""``python -m pin_susp.cli``: the ``pin-susp`` command."""

import sys

from . import main

sys.exit(main())
