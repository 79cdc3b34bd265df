"""``labbrdf formats``: the export formats the readers know."""

from __future__ import annotations

import argparse
from typing import Any

from ._options import _emit_json


def cmd_formats(args: argparse.Namespace) -> int:
    """Print the formats the readers know (``--json``: as a list)."""
    from ..adapters import formats

    fmts = formats()
    if args.json:
        _emit_json(fmts)
    else:
        for f in fmts:
            print(f)
    return 0


def add_parser(sub: Any) -> None:
    """The ``formats`` subcommand's options."""
    s = sub.add_parser("formats", help="list the supported export formats")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_formats)
