"""The files a command reads and writes: declared on the parser, checked before it runs."""

from __future__ import annotations

import argparse
import contextlib
import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, Literal

from ._options import UsageError


class InputPath(argparse.Action):
    """An option or positional argument that names files the command reads.

    Every output of the command refuses all of them (see :func:`_checked_outputs`), so
    an option declared with ``action=InputPath`` cannot be forgotten by a writer. A file
    that names other files (``inside="model"``: a film model file, ``inside="fit"``: a film
    fit JSON, ``inside="map"``: a wafer map's listing) brings those in as inputs too
    (:func:`labbrdf.films.named_inputs`, :func:`labbrdf.fitting.film_map.read_map_listing`).
    """

    def __init__(
        self,
        option_strings: Sequence[str],
        dest: str,
        *,
        inside: Literal["model", "fit", "map"] | None = None,
        **kw: Any,
    ) -> None:
        super().__init__(option_strings, dest, **kw)
        self.inside = inside

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        setattr(namespace, self.dest, values)


class OutputPath(argparse.Action):
    """An option that names an output the command writes; checked before it runs.

    ``kind`` is ``"file"`` (with the accepted ``suffixes``) or ``"dir"`` (a report folder).
    """

    def __init__(
        self,
        option_strings: Sequence[str],
        dest: str,
        *,
        suffixes: Sequence[str] = (),
        kind: Literal["file", "dir"] = "file",
        **kw: Any,
    ) -> None:
        super().__init__(option_strings, dest, **kw)
        self.suffixes = tuple(suffixes)
        self.kind = kind

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        setattr(namespace, self.dest, values)


def path_actions(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """The :class:`InputPath` and :class:`OutputPath` arguments of a (sub)parser."""
    return [a for a in parser._actions if isinstance(a, InputPath | OutputPath)]


def _option_name(a: argparse.Action) -> str:
    return a.option_strings[0] if a.option_strings else str(a.metavar or a.dest)


def _named_paths(args: argparse.Namespace, kind: type) -> list[tuple[argparse.Action, str]]:
    out: list[tuple[argparse.Action, str]] = []
    actions: Sequence[argparse.Action] = getattr(args, "path_actions", ())
    for a in actions:
        v = getattr(args, a.dest, None)
        if isinstance(a, kind) and v is not None:
            out.extend((a, str(p)) for p in (v if isinstance(v, list) else [v]))
    return out


def _inputs(args: argparse.Namespace) -> list[str]:
    """Every file the command's options name as an input."""
    return [p for _, p in _named_paths(args, InputPath)]


def _layer_files(spec: str) -> list[str]:
    """The file a ``--layer NAME:MATERIAL:...`` names as its material, if any."""
    fields = spec.split(":")
    return [fields[1]] if len(fields) >= 2 and os.path.exists(fields[1]) else []


def _named_inside(args: argparse.Namespace) -> list[str]:
    """The files named inside the inputs: a model's or a fit's tables, ``--layer`` files."""
    inner = [f for spec in getattr(args, "layer", None) or () for f in _layer_files(spec)]
    for a, p in _named_paths(args, InputPath):
        kind = getattr(a, "inside", None)
        if kind is not None:
            try:
                inner += _files_named_by(p, kind)
            except ValueError as exc:  # the loader's message, naming the file
                raise UsageError(f"{_option_name(a)} {exc}") from None
    return inner


def _files_named_by(path: str, kind: str) -> list[str]:
    """The files an input names: a film model's or fit's tables, a map listing's points."""
    if kind == "map":
        from ..fitting.film_map import read_map_listing

        return [pt.file for pt in read_map_listing(path)]
    from ..films import named_inputs

    return [str(f) for f in named_inputs(path, kind)]


def _check_outputs(args: argparse.Namespace) -> None:
    """Check every output option against the :func:`labbrdf.outputs.write_policy` in force."""
    from ..outputs import check_file_output, check_report_dir

    seen: dict[Path, str] = {}
    for a, path in _named_paths(args, OutputPath):
        if not isinstance(a, OutputPath):  # pragma: no cover - _named_paths filtered
            continue
        name = _option_name(a)
        if a.kind == "dir":
            out = check_report_dir(path, option=name)
        else:
            out = check_file_output(path, suffixes=a.suffixes, option=name)
        key = Path(os.path.abspath(out))
        if key in seen:
            raise UsageError(f"{name} {path}: also given to {seen[key]}; expected two names")
        seen[key] = name


@contextlib.contextmanager
def _checked_outputs(args: argparse.Namespace) -> Iterator[None]:
    """Check every input and output of the command, then run it under the output rule.

    The rule (:func:`labbrdf.outputs.write_policy`): an existing output is replaced only
    with ``--overwrite``, an input never; every file written inside, sidecars included,
    follows it. The files named inside the inputs (:func:`_named_inside`) are inputs too,
    checked against every output before the command runs; their readers check that they
    are regular files, naming the file that names them.
    """
    from ..outputs import check_input_files, refuse_input_as_output, write_policy

    inputs = _inputs(args)
    check_input_files(inputs)
    for a, path in _named_paths(args, OutputPath):  # an input given as an output: said first
        kind = a.kind if isinstance(a, OutputPath) else "file"
        refuse_input_as_output(path, inputs=inputs, kind=kind, option=_option_name(a))
    inputs += _named_inside(args)
    with write_policy(overwrite=bool(getattr(args, "overwrite", False)), inputs=inputs):
        _check_outputs(args)
        yield


def _add_overwrite(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="replace existing outputs (never an input); without it an existing file is "
        "refused before any work",
    )
