"""``python -m mosys.cli``: the ``mosys`` command."""

import sys

from mosys.cli import main

sys.exit(main())
