"""One pairing of files to samples for every section of a report.

Sections name a file by its rows' ``source`` (the file name); the report's sample groups
(:attr:`~labbrdf.report.context.Context.samples`, from :func:`labbrdf.samples.pair_samples`:
the sample names the files state, or the user's mapping) hold paths. :func:`same_sample`
asks the groups whether two files are one sample, so every section pairs by the same rule.
Where a report was built without groups (a section run on its own), the groups are those
of the sample names the rows state, by the same function.

Two inputs of one file name in different folders cannot be told apart by their rows'
``source``; such a name pairs with nothing rather than with the wrong sample.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from ..samples import PairingError, SampleGroup, pair_samples, sample_file
from .context import Context

__all__ = ["how_to_pair", "same_sample", "sample_groups", "sample_groups_of"]


def sample_groups_of(ctx: Context) -> list[SampleGroup]:
    """The report's sample groups; without any, those of the names the rows state."""
    if ctx.samples:
        return ctx.samples
    names: dict[str, list[str]] = {}
    for f in ctx.frames:
        if not len(f) or "sample" not in f.columns:
            continue
        for src, g in f.groupby(f["source"].astype(str), sort=False):
            names.setdefault(str(src), []).extend(str(s) for s in g["sample"].unique())
    return pair_samples([(Path(src), tuple(dict.fromkeys(v))) for src, v in names.items()])


def _group_names(groups: list[SampleGroup], source: str) -> set[str] | None:
    """File names of the one group holding the file named ``source`` (None: none or two)."""
    holding = [g for g in groups if any(Path(p).name == source for p in g.paths)]
    if len(holding) != 1 or sum(Path(p).name == source for p in holding[0].paths) != 1:
        return None
    return {Path(p).name for p in holding[0].paths}


def same_sample(ctx: Context, a: str, b: str) -> bool:
    """True when the files named ``a`` and ``b`` are one sample (the same file included).

    Parameters
    ----------
    ctx : Context
        The report (its :attr:`~labbrdf.report.context.Context.samples`).
    a, b : str
        File names, as the rows' ``source`` gives them.
    """
    if a == b:
        return True
    names = _group_names(sample_groups_of(ctx), a)
    return names is not None and b in names


def how_to_pair(ctx: Context, files: list[str]) -> str:
    """How a user says that ``files`` (file names) are one sample, in both interfaces.

    One group holding every file of the groups the files are in now (a file may be in one
    ``--same-sample`` group only, so groups are merged, not added), spelt as the inputs
    were given where the report's groups know them.
    """
    spelt: list[str] = []
    for f in files:
        holding = [g for g in ctx.samples if any(Path(p).name == f for p in g.paths)]
        members = [str(p) for p in holding[0].paths] if len(holding) == 1 else [f]
        spelt += [m for m in members if m not in spelt]
    return (
        f"if they are one sample, give the mapping: labbrdf report --same-sample "
        f"{','.join(spelt)} (Python: same_sample=[{spelt!r}])"
    )


def sample_groups(
    ctx: Context,
    paths: Sequence[str | os.PathLike[str]],
    same_sample: Sequence[Sequence[str | os.PathLike[str]]] = (),
    given_as: str = "given with --same-sample",
) -> None:
    """Group the input files by sample (``ctx.samples``) and show the groups with reasons.

    The names are those the readers found (``ctx.files``; height maps carry none), the
    mapping is the user's (:func:`labbrdf.samples.pair_samples`). A mapping that the files'
    own sample names contradict fails the check ``ingest.samples`` and pairs nothing.
    """
    names = {str(f["path"]): tuple(f.get("samples", ())) for f in ctx.files}
    maps = {str(hm.path): sample_file(hm.path, hm).names for hm in ctx.height_maps}
    files = [(p, names.get(str(p), maps.get(str(p), ()))) for p in paths]
    try:
        groups = pair_samples(files, same_sample, given_as=given_as)
    except PairingError as exc:
        ctx.b.check(
            "ingest.samples",
            "the files' sample names agree with the given sample mapping",
            False,
            against="the sample names stated in the files",
            reason=str(exc),
            substantive=False,
        )
        return
    ctx.samples[:] = groups
    rows = [
        {
            "sample": g.name,
            "files": ", ".join(Path(p).name for p in g.paths),
            "n": len(g.paths),
            "reason": g.reason,
        }
        for g in groups
    ]
    ctx.b.table(
        "sample_groups",
        "Files grouped by sample",
        [
            ("sample", "sample", ""),
            ("files", "files", ""),
            ("n", "files [n]", "d"),
            ("reason", "why these files are one sample", ""),
        ],
        rows,
        caption="Files are one sample when they state the same sample name (a name that is "
        "only the file's own name does not count) or when the user says so (--same-sample); "
        "never because their wavelengths overlap. Predictions made from one file (e.g. a "
        "height map's roughness) are set against measurements of the same sample only.",
    )
