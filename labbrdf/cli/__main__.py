"""``python -m labbrdf.cli``: the ``labbrdf`` command."""

import sys

from ._run import main

sys.exit(main())
