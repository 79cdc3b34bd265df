"""``python -m labbrdf.cli``: the ``labbrdf`` command."""

import sys

from ._run import main

if __name__ == "__main__":
    sys.exit(main())
