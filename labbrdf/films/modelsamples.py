"""The ``[samples]`` table of a film model file: several samples fitted in one model.

::

    [samples]
    per_sample = ["film.thickness_nm"]     # each sample has its own; the rest are shared

    [samples.files]                        # sample name -> its file(s), relative to the model
    wafer1 = "w1.dat"
    wafer2 = ["w2.dat", "w2_p-pol_refl.dat"]

:func:`parse_samples` checks the parsed table (names, files, parameters) and
:func:`sample_files` lists the files it names (inputs of whoever reads the model); the
model file's reader (:mod:`~labbrdf.films.modelfile`) calls both.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .limits import FilmError

__all__ = ["ModelSamples", "parse_samples", "sample_files"]

#: the keys of a ``[samples]`` table
_KEYS = ("per_sample", "files")


@dataclass(frozen=True)
class ModelSamples:
    """Which files are which sample, and which parameters each sample has of its own.

    Parameters
    ----------
    files : dict
        Sample name -> its files (as the reader opens them: relative to the model's folder).
    per_sample : tuple of str
        ``"<layer>.<parameter>"`` names fitted per sample; every other free parameter is
        shared by all samples.
    """

    files: dict[str, tuple[Path, ...]]
    per_sample: tuple[str, ...]


def _paths(value: Any, base: Path) -> tuple[Path, ...] | None:
    """The files of one sample (a string or a non-empty list of strings), or None if not."""
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, list) or not items or not all(isinstance(v, str) for v in items):
        return None
    return tuple(p if (p := Path(v)).is_absolute() else base / p for v in items)


def parse_samples(
    doc: Mapping[str, Any], where: str, line: Callable[..., int], base: Path
) -> ModelSamples | None:
    """The ``[samples]`` table of a parsed model file, or None if it has none.

    Parameters
    ----------
    doc : mapping
        The parsed TOML document.
    where : str
        The model file, for messages.
    line : callable
        ``line(table, index, key)``: the 1-based line of a key (the model reader's scan).
    base : Path
        The model file's folder (relative file names are relative to it).

    Raises
    ------
    FilmError
        Naming the file and the line: an unknown key, no files, a sample without files, a
        per-sample name that is not a string.
    """
    tbl = doc.get("samples")
    if tbl is None:
        return None
    if not isinstance(tbl, dict):
        raise FilmError(f"{where}, line {line('', 0, 'samples')}: 'samples' must be a table")
    bad = sorted(set(tbl) - set(_KEYS))
    if bad:
        raise FilmError(
            f"{where}, line {line('samples', 0, bad[0])}: unknown key {bad[0]!r} in [samples]; "
            "expected per_sample = [...] and a [samples.files] table"
        )
    per = tbl.get("per_sample", [])
    if not isinstance(per, list) or not all(isinstance(x, str) for x in per):
        raise FilmError(
            f"{where}, line {line('samples', 0, 'per_sample')}: per_sample must be a list of "
            'parameter names, e.g. ["film.thickness_nm"]'
        )
    files = tbl.get("files")
    if not isinstance(files, dict) or len(files) < 1:
        raise FilmError(
            f"{where}, line {line('samples')}: [samples] needs a [samples.files] table "
            'naming each sample\'s file(s), e.g. wafer1 = "w1.dat"'
        )
    out: dict[str, tuple[Path, ...]] = {}
    for name, value in files.items():
        paths = _paths(value, base)
        if paths is None:
            raise FilmError(
                f"{where}, line {line('samples.files', 0, name)}: sample {name!r}: expected a "
                f"file name or a list of file names, got {value!r}"
            )
        out[str(name)] = paths
    return ModelSamples(out, tuple(dict.fromkeys(per)))


def sample_files(doc: Mapping[str, Any], base: Path) -> list[Path]:
    """The files a parsed model's ``[samples]`` table names (none if it has no valid one)."""
    tbl = doc.get("samples")
    files = tbl.get("files") if isinstance(tbl, dict) else None
    if not isinstance(files, dict):
        return []
    return [p for v in files.values() for p in (_paths(v, base) or ())]
