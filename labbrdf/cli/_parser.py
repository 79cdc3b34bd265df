"""The ``labbrdf`` argument parser: one subparser per command, from the command's module."""

from __future__ import annotations

import argparse
from typing import Any

from . import (
    cache,
    export,
    film,
    film_map,
    fit,
    formats,
    hemispherical,
    ingest,
    nk,
    report,
    surface,
    trace,
    validate,
)
from ._paths import path_actions

#: the commands in the order ``labbrdf --help`` lists them
COMMANDS = (ingest, formats, fit, nk, film, film_map, surface, export, hemispherical, trace,
            validate, report, cache)  # fmt: skip


class _Parser(argparse.ArgumentParser):
    """A parser that takes options by their full names only.

    No abbreviations (``allow_abbrev=False``): ``--wavelength`` must never be taken for
    ``--wavelength-range``, nor a later option's prefix for an earlier one.
    """

    def __init__(self, *args: Any, **kw: Any) -> None:
        kw.setdefault("allow_abbrev", False)
        super().__init__(*args, **kw)


def build_parser() -> argparse.ArgumentParser:
    """The parser of the ``labbrdf`` command, every subcommand with its options."""
    from .. import __version__

    p = _Parser(
        prog="labbrdf",
        description="Optical-metrology toolkit: read instrument exports, fit BRDF models, "
        "check physics, trace polarized rays, write validation reports.",
    )
    p.add_argument("--version", action="version", version=f"labbrdf {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for command in COMMANDS:
        command.add_parser(sub)
    for sp in sub.choices.values():  # what _checked_outputs checks, per command
        sp.set_defaults(path_actions=tuple(path_actions(sp)))
    return p
