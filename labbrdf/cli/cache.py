"""``labbrdf cache``: show or empty the tracer's operator cache."""

from __future__ import annotations

import argparse
from typing import Any

from ._options import _emit_json


def cmd_cache(args: argparse.Namespace) -> int:
    """Show (``info``) or empty (``clear``) the tracer's operator cache."""
    from ..tracer import cache

    if args.action == "clear":
        n, size = cache.clear()
        print(f"removed {n} file(s), {size / 1e6:.1f} MB, from {cache.cache_dir()}")
        return 0
    info = cache.info()
    if args.json:
        _emit_json(
            {
                "folder": str(info.folder),
                "entries": [vars(e) for e in info.entries],
                "total_bytes": info.total_bytes,
                "max_bytes": info.max_bytes,
                "problem": info.problem,
            }
        )
        return 0
    print(f"folder   {info.folder}" + (f" (not used: {info.problem})" if info.problem else ""))
    print(f"entries  {len(info.entries)}")
    print(f"total    {info.total_bytes / 1e6:.1f} MB")
    print(f"cap      {info.max_bytes / 1e6:.1f} MB (set with {cache.ENV_MAX_BYTES})")
    return 0


def add_parser(sub: Any) -> None:
    """The ``cache`` subcommand's options."""
    s = sub.add_parser("cache", help="show or clear the tracer's operator cache")
    s.add_argument(
        "action",
        nargs="?",
        choices=("info", "clear"),
        default="info",
        help="info: where the cache is, its entries, their total size and the cap (default); "
        "clear: remove labbrdf's entries",
    )
    s.add_argument("--json", action="store_true", help="info as JSON")
    s.set_defaults(func=cmd_cache)
