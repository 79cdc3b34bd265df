"""Which input files belong to one sample.

A lab measures one sample on several instruments: a height map on a profiler, reflectance
on a spectrophotometer, psi/Delta on an ellipsometer, a BRDF on a scatterometer. Comparing
one file's prediction with another file's measurement is only meaningful when both are of
the same sample, so the files are grouped first, by exactly two kinds of evidence:

1. the sample name *stated in the files* (the ``sample`` column of a
   :class:`~labbrdf.dataset.Measurement`, which readers take from the file's header);
2. a mapping the user gives (``labbrdf report --same-sample a.dat,b.di``; in Python a list
   of lists of paths).

Nothing else pairs files: not a wavelength range that happens to overlap, and not a file
name. Readers fall back to the file stem when a file states no sample name, and a stem is
not evidence (two folders both hold a ``data.dat``); a name equal to the file's own stem
(or stem plus the ``#k`` / ``block k`` suffix readers add for multi-spectrum files) is
therefore treated as *not stated*. Height maps (``.di``, ``.opdx``, MetroPro ``.dat``)
and Zemax ``.bsdf`` files carry no sample name in their formats, so they are paired only
by a mapping.

Every group says why its files belong together (:attr:`SampleGroup.reason`). A mapping that
contradicts itself or the files is an error naming the files (:class:`PairingError`):
a file listed in two groups, a file listed twice, a group of one file, a path that is not
among the inputs, and two given groups that the files' own sample names join.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeAlias

__all__ = [
    "PairingError",
    "SampleFile",
    "SampleGroup",
    "group_of",
    "pair_samples",
    "sample_file",
    "split_same_sample",
    "stated_names",
]


class PairingError(ValueError):
    """A sample mapping that cannot hold (message names the files)."""


@dataclass(frozen=True)
class SampleFile:
    """One input file and the sample name(s) its reader found in it.

    Attributes
    ----------
    path : Path
        The file as given.
    names : tuple of str
        Every distinct value of its ``sample`` column (several for a multi-sample file),
        empty for a file without one (a height map, a file that could not be read).
    """

    path: Path
    names: tuple[str, ...] = ()


@dataclass(frozen=True)
class SampleGroup:
    """Files of one sample, and why they are one.

    Attributes
    ----------
    name : str
        The sample's name: the sample name(s) the files share, else the names they state,
        else the names their readers gave (file stems), else the file names.
    paths : tuple of Path
        The files, in input order.
    reason : str
        Why these files are one sample (``"sample name 'Ta2O5-1' in a.dat and b.dat"``,
        ``"given with --same-sample (a.dat and b.di)"``), or, for a file on its own, why it was
        not paired with any other.
    """

    name: str
    paths: tuple[Path, ...]
    reason: str

    @property
    def paired(self) -> bool:
        """True when the group holds more than one file."""
        return len(self.paths) > 1


#: what :func:`pair_samples` accepts for one file
FileLike: TypeAlias = (
    SampleFile | tuple[str | os.PathLike[str], str | Iterable[str]] | str | os.PathLike[str]
)


def _key(p: str | os.PathLike[str]) -> str:
    """One identity per file whatever the spelling (relative, ``..``, symlink, case)."""
    return os.path.normcase(os.path.realpath(os.fspath(p)))


def _from_file_name(name: str, path: Path) -> bool:
    """True when ``name`` is what readers derive from the file name, not a stated name."""
    stems = {path.stem, path.name.split(".")[0], path.name}
    pattern = "|".join(re.escape(s) for s in stems if s)
    return bool(pattern) and re.fullmatch(rf"(?:{pattern})(?: #\d+| block \d+)?", name) is not None


def stated_names(f: SampleFile) -> tuple[str, ...]:
    """The sample names ``f`` states itself: blank names and file-name fallbacks dropped."""
    return tuple(n for n in f.names if n.strip() and not _from_file_name(n, f.path))


def sample_file(path: str | os.PathLike[str], source: Any = None) -> SampleFile:
    """A :class:`SampleFile` from a file and what its reader returned.

    Parameters
    ----------
    path : path-like
        The file.
    source : Measurement or HeightMap or DataFrame or None
        A :class:`~labbrdf.dataset.Measurement` or a dataset frame (its ``sample``
        column); a :class:`~labbrdf.adapters.topography.HeightMap` (its ``meta["sample"]``
        where a reader reports one); None for a file that could not be read.
    """
    data = getattr(source, "data", source)
    names: list[str] = []
    if data is not None and hasattr(data, "columns") and "sample" in data.columns:
        names = [str(s) for s in dict.fromkeys(data["sample"].astype(str))]
    elif isinstance(getattr(source, "meta", None), dict):
        v = source.meta.get("sample")
        if isinstance(v, str) and v.strip():
            names = [v.strip()]
    return SampleFile(Path(path), tuple(names))


def _as_file(item: Any) -> SampleFile:
    if isinstance(item, SampleFile):
        return item
    if isinstance(item, (str, os.PathLike)):
        return SampleFile(Path(item))
    if isinstance(item, tuple) and len(item) == 2:
        path, names = item
        names = (names,) if isinstance(names, str) else tuple(str(n) for n in names)
        return SampleFile(Path(path), names)
    raise TypeError(f"files: expected SampleFile, a path or (path, sample names), got {item!r}")


def _names(paths: Iterable[Path]) -> str:
    shown = [p.name for p in paths]
    if len(shown) <= 2:
        return " and ".join(shown)
    return ", ".join(shown[:-1]) + " and " + shown[-1]


class _Union:
    def __init__(self, n: int) -> None:
        self.parent = list(range(n))

    def find(self, i: int) -> int:
        while self.parent[i] != i:
            self.parent[i] = self.parent[self.parent[i]]
            i = self.parent[i]
        return i

    def join(self, i: int, j: int) -> None:
        a, b = self.find(i), self.find(j)
        if a != b:
            self.parent[max(a, b)] = min(a, b)


def _check_mapping(
    files: Sequence[SampleFile], keys: dict[str, int], same_sample: Sequence[Sequence[Any]]
) -> list[list[int]]:
    """The given groups as file indices; every way a mapping can be wrong raises."""
    given: list[list[int]] = []
    where: dict[int, int] = {}
    inputs = ", ".join(str(f.path) for f in files)
    for g, group in enumerate(same_sample, start=1):
        if isinstance(group, (str, os.PathLike)):
            raise PairingError(
                f"same-sample group {g} ({os.fspath(group)}): expected a list of two or more "
                "files, got one path"
            )
        paths = [Path(p) for p in group]
        if len(paths) < 2:
            raise PairingError(
                f"same-sample group {g} ({', '.join(map(str, paths)) or 'empty'}): expected "
                "two or more files"
            )
        idx: list[int] = []
        for p in paths:
            i = keys.get(_key(p))
            if i is None:
                raise PairingError(
                    f"same-sample group {g}: {p} is not among the input files ({inputs})"
                )
            if i in idx:
                raise PairingError(f"same-sample group {g}: {p} is listed twice")
            if i in where:
                raise PairingError(
                    f"{p} is in same-sample groups {where[i]} and {g}: a file belongs to one "
                    "sample; merge the groups or drop it from one"
                )
            where[i] = g
            idx.append(i)
        given.append(idx)
    return given


def pair_samples(
    files: Sequence[FileLike],
    same_sample: Sequence[Sequence[str | os.PathLike[str]]] = (),
    *,
    given_as: str = "given as one sample",
) -> list[SampleGroup]:
    """Group files by sample: by the sample names they state, and by a given mapping.

    Parameters
    ----------
    files : sequence
        Every input file: :class:`SampleFile` (see :func:`sample_file`), a
        ``(path, sample names)`` pair, or a bare path (a file without a sample name).
        A file given twice counts once.
    same_sample : sequence of sequences of path-like
        Files the user says are one sample, one sequence per sample (two or more files
        each, every one among ``files``; spelt any way that resolves to the same file).
    given_as : str
        How a given group is described in its reason, e.g. ``"given with --same-sample"``;
        the group's files follow it.

    Returns
    -------
    list of SampleGroup
        Every file in exactly one group, groups in the order of their first file. Files
        sharing a stated sample name are one group ("sample name 'X' in a.dat and b.dat");
        a given group joins its files whatever their names say, and files sharing a stated
        name with one of its files join it too. A file paired with no other is a group of
        one whose reason says why.

    Raises
    ------
    PairingError
        A given group with fewer than two files, a path that is not among ``files``, a
        file listed twice in one group or in two groups, or two given groups that the
        files' stated sample names join into one (naming the files and the name).
    TypeError
        An item of ``files`` of another kind.

    Notes
    -----
    Files are never paired by overlapping wavelengths or by their file names; see the
    module docstring for what counts as a stated name.
    """
    uniq: list[SampleFile] = []
    keys: dict[str, int] = {}
    for item in files:
        f = _as_file(item)
        k = _key(f.path)
        if k in keys:
            i = keys[k]
            merged = tuple(dict.fromkeys(uniq[i].names + f.names))
            uniq[i] = SampleFile(uniq[i].path, merged)
            continue
        keys[k] = len(uniq)
        uniq.append(f)
    given = _check_mapping(uniq, keys, same_sample)

    u = _Union(len(uniq))
    for idx in given:
        for i in idx[1:]:
            u.join(idx[0], i)
    stated = [stated_names(f) for f in uniq]
    holders: dict[str, list[int]] = {}
    for i, names in enumerate(stated):
        for n in names:
            holders.setdefault(n, []).append(i)
    for idx in holders.values():
        for i in idx[1:]:
            u.join(idx[0], i)

    group_of_file = {i: g for g, idx in enumerate(given) for i in idx}
    comps: dict[int, list[int]] = {}
    for i in range(len(uniq)):
        comps.setdefault(u.find(i), []).append(i)

    out: list[SampleGroup] = []
    for members in comps.values():
        gs = sorted({group_of_file[i] for i in members if i in group_of_file})
        shared = [n for n, idx in holders.items() if len(idx) > 1 and idx[0] in members]
        if len(gs) > 1:
            a, b = (given[g] for g in gs[:2])
            evidence = "; ".join(
                f"{n!r} in {_names(uniq[i].path for i in holders[n])}" for n in shared
            )
            raise PairingError(
                f"same-sample groups {gs[0] + 1} ({_names(uniq[i].path for i in a)}) and "
                f"{gs[1] + 1} ({_names(uniq[i].path for i in b)}) are one sample by the "
                f"sample names the files state ({evidence}): give them as one group"
            )
        reasons = [f"{given_as} ({_names(uniq[i].path for i in given[g])})" for g in gs]
        reasons += [
            f"sample name {n!r} in {_names(uniq[i].path for i in holders[n])}" for n in shared
        ]
        paths = tuple(uniq[i].path for i in members)
        if shared:
            name = " / ".join(shared)
        else:  # the names the files state, else those their readers gave, else file names
            said = list(dict.fromkeys(n for i in members for n in stated[i]))
            carried = list(dict.fromkeys(n for i in members for n in uniq[i].names if n.strip()))
            name = " / ".join(said or carried) or " + ".join(p.name for p in paths)
        if len(members) == 1:
            f = uniq[members[0]]
            if stated[members[0]]:
                listed = ", ".join(repr(n) for n in stated[members[0]])
                why = f"no other file states the sample name {listed}"
            elif f.names:
                listed = ", ".join(repr(n) for n in f.names)
                why = (
                    f"the file states no sample name (its reader's {listed} is its file name, "
                    "which pairs nothing); give a mapping to pair it"
                )
            else:
                why = "the file carries no sample name; give a mapping to pair it"
            reasons = [why]
        out.append(SampleGroup(name, paths, "; ".join(reasons)))
    return out


def group_of(groups: Sequence[SampleGroup], path: str | os.PathLike[str]) -> SampleGroup:
    """The group holding ``path`` (any spelling of the same file).

    Raises
    ------
    KeyError
        ``path`` is in none of ``groups``.
    """
    k = _key(path)
    for g in groups:
        if any(_key(p) == k for p in g.paths):
            return g
    raise KeyError(f"{os.fspath(path)} is in no sample group")


def split_same_sample(
    text: str, inputs: Sequence[str | os.PathLike[str]]
) -> list[str | os.PathLike[str]]:
    """The files of one ``--same-sample`` value: comma-separated, commas in names allowed.

    File names may hold commas (``F4-P3HT 1-10 0,5 mgml.Probe.Raw.asc``), so the value
    is split at the commas that make every piece one of ``inputs``; when no split does,
    at every comma (and :func:`pair_samples` then names the piece that is no input).

    Parameters
    ----------
    text : str
        The option's value, e.g. ``"a.dat,b.di"``.
    inputs : sequence of path-like
        The command's input files.

    Returns
    -------
    list
        The paths, as the inputs spell them where they match one.

    Notes
    -----
    A piece can only be an input if it holds as many commas as some spelling of one (as
    given, absolute, resolved), so at each comma only those few piece lengths are tried:
    the work grows linearly with the number of commas (times the number of distinct comma
    counts among the inputs), whatever the value holds. Where several splits work, each
    piece is the shortest that leaves a splittable rest before it.
    """
    known = {_key(p): p for p in inputs}
    commas = sorted(
        {
            os.fspath(s).count(",")
            for p in inputs
            for s in (p, os.path.abspath(os.fspath(p)), _key(p))
        }
    )
    parts = text.split(",")
    n = len(parts)
    # offset[i]: where parts[i] starts in text, so a piece is one slice, not a join
    offset = [0] * (n + 1)
    for i, part in enumerate(parts):
        offset[i + 1] = offset[i] + len(part) + 1
    # start[end]: where the last piece of a split of parts[:end] starts (-1: no split)
    start = [0] + [-1] * n
    match: dict[str, str | os.PathLike[str] | None] = {}
    for end in range(1, n + 1):
        for s in (end - 1 - c for c in commas):
            if s < 0 or start[s] < 0:
                continue
            piece = text[offset[s] : offset[end] - 1]
            if piece not in match:
                match[piece] = known.get(_key(piece)) if piece and "\0" not in piece else None
            if match[piece] is not None:
                start[end] = s
                break
    if start[n] < 0:
        return [p for p in parts if p]
    found: list[str | os.PathLike[str]] = []
    end = n
    while end > 0:
        s = start[end]
        hit = match[text[offset[s] : offset[end] - 1]]
        assert hit is not None
        found.append(hit)
        end = s
    return found[::-1]
