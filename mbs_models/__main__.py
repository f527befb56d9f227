"""``python -m mbs_models`` is the ``recoil`` command."""

import sys

from .cli import main

sys.exit(main())
