"""``python -m labbrdf``: the ``labbrdf`` command."""

import sys

from .cli._run import main

if __name__ == "__main__":
    sys.exit(main())
