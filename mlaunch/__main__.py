"""``python -m mlaunch``: the same as the ``mlaunch`` command."""

import sys

from mlaunch.cli import main

sys.exit(main())
