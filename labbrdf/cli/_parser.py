"""The ``labbrdf`` argument parser: one subparser per command, from the command's module.

Start-up is kept short: :data:`COMMANDS` names each command's module and its one-line help
without importing it, so that ``labbrdf --help`` and ``labbrdf --version`` import no
command (nor numpy), and ``labbrdf CMD ...`` imports the module of ``CMD`` only
(:func:`build_parser` with ``commands``); the other commands are then stubs that carry
their help line.
"""

from __future__ import annotations

import argparse
import importlib
from collections.abc import Collection, Sequence
from types import ModuleType
from typing import Any

from ._paths import path_actions

#: command -> its one-line help, in the order ``labbrdf --help`` lists them; the command
#: is the module ``labbrdf.cli.<name>`` (``add_parser`` and ``cmd_<name>``), imported only
#: when the command is chosen (tests check that each line is the module's own)
COMMANDS: dict[str, str] = {
    "ingest": "read instrument exports into one dataset",
    "formats": "list the supported export formats",
    "fit": "fit a model per group (sample, wavelength)",
    "nk": "optical constants n, k from ellipsometer psi/Delta",
    "film": "fit a thin-film stack (thicknesses, n, k) to psi/Delta, R and T of one sample",
    "film-map": "fit a film model to every point of a wafer map (thickness, index maps)",
    "surface": "roughness statistics of a height map or profile",
    "psd": "power spectral density of height maps (composite over maps, model fit)",
    "export": "write a model BRDF in an exchange format",
    "hemispherical": "directional-hemispherical reflectance of a model",
    "trace": "Monte Carlo polarization ray tracing (pBRDF)",
    "validate": "run the whole validation and write the HTML report",
    "report": "HTML report for your own files",
    "cache": "show or clear the tracer's operator cache",
}


#: every command's ``--quiet`` (a command may define its own, saying more)
QUIET_HELP = "no progress line (there is none when stderr is not a terminal)"


class _Parser(argparse.ArgumentParser):
    """A parser that takes options by their full names only.

    No abbreviations (``allow_abbrev=False``): ``--wavelength`` must never be taken for
    ``--wavelength-range``, nor a later option's prefix for an earlier one.
    """

    def __init__(self, *args: Any, **kw: Any) -> None:
        kw.setdefault("allow_abbrev", False)
        super().__init__(*args, **kw)


def command_module(name: str) -> ModuleType:
    """The module of the command ``name`` (imported on this call, not before).

    A hyphen in a command's name is an underscore in its module's (``film-map``).
    """
    return importlib.import_module(f"{__package__}.{name.replace('-', '_')}")


def chosen_command(argv: Sequence[str]) -> str | None:
    """The command named on a command line, or None (none, or not a command).

    The top-level parser has no option that takes a value, so the command is the first
    word that is not an option.
    """
    for word in argv:
        if word == "--":
            return None
        if not word.startswith("-"):
            return word if word in COMMANDS else None
    return None


def build_parser(commands: Collection[str] | None = None) -> argparse.ArgumentParser:
    """The parser of the ``labbrdf`` command.

    Parameters
    ----------
    commands : collection of str, optional
        Build these commands' options only (their modules are the only ones imported);
        the other commands are listed with their help line. Default: every command in
        full (what the documentation shows).
    """
    from .. import __version__

    p = _Parser(
        prog="labbrdf",
        description="Optical-metrology toolkit: read instrument exports, fit BRDF models, "
        "check physics, trace polarized rays, write validation reports.",
    )
    p.add_argument("--version", action="version", version=f"labbrdf {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for name, help_line in COMMANDS.items():
        if commands is None or name in commands:
            command_module(name).add_parser(sub)
        else:
            sub.add_parser(name, help=help_line)
    for sp in sub.choices.values():
        if not any(a.dest == "quiet" for a in sp._actions):
            sp.add_argument("--quiet", action="store_true", help=QUIET_HELP)
        sp.set_defaults(path_actions=tuple(path_actions(sp)))  # what _checked_outputs checks
    return p
