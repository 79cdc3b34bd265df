"""The report's input files read into its Context: optical exports and height maps.

Every section reads its data from the :class:`~labbrdf.report.context.Context` these fill
(``ctx.frames``, ``ctx.files``, ``ctx.height_maps``), each with the table of what was read
and the check that everything was; the sections themselves do not import each other.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from .. import adapters
from ..adapters.inputs import InputFile
from .builder import Unavailable
from .context import Context

__all__ = [
    "file_frames",
    "ingest_files",
    "ingest_height_maps",
    "ingest_inputs",
    "ingest_read",
    "list_unreadable",
    "psi_delta_of_group",
]


def _meta_header(meta: Mapping[str, Any], limit: int = 3) -> str:
    for key in ("header_lines", "header", "comments", "comment", "notes"):
        v = meta.get(key)
        if isinstance(v, str) and v.strip():
            return v.strip()[:300]
        if isinstance(v, list) and v:
            return " | ".join(str(x) for x in v[:limit])[:300]
        if isinstance(v, Mapping) and v:
            return " | ".join(f"{k}: {x}" for k, x in list(v.items())[:limit])[:300]
    return ""


def _quantities(names: Sequence[str]) -> str:
    """The quantities of a file, Mueller elements folded to one entry."""
    mm = [q for q in names if q.startswith("mueller_")]
    rest = [q for q in names if not q.startswith("mueller_")]
    if len(mm) > 2:
        rest.append(f"Mueller matrix ({len(mm)} elements)")
    else:
        rest.extend(mm)
    return ", ".join(rest)


def ingest_files(
    ctx: Context,
    paths: Sequence[str | os.PathLike[str]],
    root: Path | None = None,
    *,
    check_id: str = "ingest.read",
    table_id: str = "ingested_files",
) -> None:
    """Read every file as an optical export (``read_inputs``) and :func:`ingest_read` them."""
    if not paths:
        raise Unavailable("no input files")
    files = adapters.read_inputs(paths, kind="optical").files
    ingest_read(ctx, files, root, check_id=check_id, table_id=table_id)


def ingest_inputs(ctx: Context, paths: Sequence[str | os.PathLike[str]]) -> list[str]:
    """Read a user's files once (:func:`labbrdf.adapters.read_inputs`) and list them.

    Height maps go to ``ctx.height_maps`` with their table and check
    (:func:`ingest_height_maps`), optical exports to
    ``ctx.frames`` with theirs (:func:`ingest_read`). A file that cannot be read is left out
    of both, as if it had not been given, and listed with its reason
    (:func:`list_unreadable`).

    Returns
    -------
    list of str
        The paths that were read, in the given order.

    Raises
    ------
    Unavailable
        No file could be read.
    """
    inputs = adapters.read_inputs(paths)
    list_unreadable(ctx, inputs.failures)
    read = [f for f in inputs.files if f.ok]
    ingest_height_maps(ctx, read)
    optical = [f for f in read if f.kind == "optical"]
    if optical:
        ingest_read(ctx, optical)
    elif not ctx.height_maps:
        raise Unavailable("no file could be read")
    return [f.path for f in read]


def list_unreadable(ctx: Context, failures: Sequence[InputFile]) -> None:
    """A note naming every file that cannot be read and why, and a failed check.

    The report's tables are those of the other files alone: an unreadable file is named
    here and nowhere else.
    """
    if not failures:
        return
    lines = [f.error if f.error.startswith(f.path) else f"{f.path}: {f.error}" for f in failures]
    ctx.b.note(
        "not read",
        f"{len(failures)} file(s) could not be read and are left out; everything else is "
        "reported as if they had not been given: " + "; ".join(lines),
    )
    ctx.b.check(
        "ingest.unreadable",
        "every input file can be read",
        False,
        against="the readers of labbrdf.read_inputs (optical exports and height maps)",
        value=len(failures),
        tolerance=0,
        justification="value = files that could not be read; none may be",
        reason="; ".join(lines)[:2000],
        substantive=False,
    )


def ingest_read(
    ctx: Context,
    files: Sequence[InputFile],
    root: Path | None = None,
    *,
    check_id: str = "ingest.read",
    table_id: str = "ingested_files",
) -> None:
    """Files already read: a table of what each holds; a check that all were read.

    Parameters
    ----------
    ctx : Context
    files : sequence of InputFile
        Optical inputs as :func:`labbrdf.adapters.read_inputs` read them (read or failed).
    root : Path, optional
        Files under it are named relative to it.
    check_id, table_id : str
        Ids of the check that every file was read and of the table (a second ingest on one
        page, e.g. the validation report's model-against-measurement set, needs its own).
    """
    b = ctx.b
    if not files:
        raise Unavailable("no input files")
    rows, failures = [], []
    for f in files:
        p = Path(f.path)
        name = str(p.relative_to(root)) if root is not None and p.is_relative_to(root) else p.name
        m = f.measurement
        if m is None:
            failures.append(f"{name}: {f.error}")
            rows.append({"file": name, "status": "error", "error": f.error})
            continue
        fmt_name = m.meta.get("format") or m.meta.get("adapter") or ""
        if not fmt_name:
            try:
                cands = adapters.sniff(p)
                fmt_name = cands[0] if len(cands) == 1 else ""
            except Exception:  # noqa: BLE001 - format name is informative only
                fmt_name = ""
        s = m.summary()
        d = m.data
        ctx.frames.append(d)
        rec = {
            "file": name,
            "status": "read",
            "format": fmt_name,
            "sample": ", ".join(s["sample"]),
            "instrument": ", ".join(sorted(set(d["instrument"]))),
            "quantities": _quantities(s["quantities"]),
            "rows": s["rows"],
            "wl_min": s["wavelength_nm"][0],
            "wl_max": s["wavelength_nm"][1],
            "theta_i": ", ".join(f"{t:g}" for t in s["theta_i_deg"]),
            "sigma": "yes" if d["sigma"].notna().any() else "no",
            "header": _meta_header(m.meta),
            "error": "",
        }
        ctx.files.append({**rec, "path": str(p), "meta": m.meta, "samples": s["sample"]})
        rows.append(rec)
    b.table(
        table_id,
        "Ingested files",
        [
            ("file", "file", ""),
            ("status", "status", ""),
            ("format", "format", ""),
            ("sample", "sample(s)", ""),
            ("instrument", "instrument", ""),
            ("quantities", "quantities", ""),
            ("rows", "rows", "d"),
            ("wl_min", "\u03bb min [nm]", ".6g"),
            ("wl_max", "\u03bb max [nm]", ".6g"),
            ("theta_i", "\u03b8i [deg]", ""),
            ("sigma", "\u03c3 given", ""),
            ("header", "header / comments (from the file)", ""),
            ("error", "error", ""),
        ],
        rows,
        caption="One row per input file: what the reader found in it. Text in the last "
        "columns is copied from the file and shown verbatim.",
    )
    b.check(
        check_id,
        "every input file reads into the common dataset",
        not failures,
        against="labbrdf.read (adapters) and the dataset schema",
        value=len(files) - len(failures),
        tolerance=len(files),
        justification="value = files read, tolerance = files given; all must read",
        reason="; ".join(failures)[:2000],
        substantive=False,
    )
    if not ctx.frames:
        raise Unavailable("no file could be read")


def _height_map_row(f: InputFile) -> dict[str, Any]:
    """The table row of one height-map file: what it holds, or why it was not read."""
    name = Path(f.path).name
    if f.height_map is None:
        return {"file": name, "status": "error", "error": f.error}
    hm = f.height_map
    s = hm.summary()
    return {
        "file": name,
        "status": "read",
        "kind": s["kind"],
        "reader": s["reader"],
        "channel": s["channel"],
        "points": " x ".join(str(n) for n in s["points"]),
        "size_um": " x ".join(f"{v:.4g}" for v in s["size_um"]),
        "pixel_nm": " x ".join(f"{v:.4g}" for v in s["pixel_nm"]),
        "missing": s["missing"],
        "error": "",
    }


def ingest_height_maps(ctx: Context, files: Sequence[InputFile]) -> None:
    """The height maps among the read input files: to ``ctx.height_maps``, a table, a check.

    Parameters
    ----------
    ctx : Context
    files : sequence of InputFile
        The report's inputs as :func:`labbrdf.adapters.read_inputs` read them; those of kind
        ``"height_map"`` (read or not) are listed, and a check fails for every one that
        could not be read, with the reason.
    """
    maps = [f for f in files if f.kind == "height_map"]
    if not maps:
        return
    ctx.height_maps.extend(f.height_map for f in maps if f.height_map is not None)
    rows = [_height_map_row(f) for f in maps]
    failures = [f"{Path(f.path).name}: {f.error}" for f in maps if f.error]
    ctx.b.table(
        "ingested_height_maps",
        "Ingested height maps and profiles (topography files)",
        [
            ("file", "file", ""),
            ("status", "status", ""),
            ("kind", "kind", ""),
            ("reader", "reader (SurfaceTopography)", ""),
            ("channel", "channel", ""),
            ("points", "points", ""),
            ("size_um", "size [\u00b5m]", ""),
            ("pixel_nm", "pixel [nm]", ""),
            ("missing", "missing points", "d"),
            ("error", "error", ""),
        ],
        rows,
        caption="Topography files (profilometer, AFM, interferometer), read with "
        "SurfaceTopography and converted to metres; they appear in the section "
        "'Measured surface topography', not in the fits.",
    )
    ctx.b.check(
        "ingest.topography",
        "every topography file reads as a height map",
        not failures,
        against="labbrdf.adapters.topography.read_height_map (SurfaceTopography)",
        value=len(rows) - len(failures),
        tolerance=len(rows),
        justification="value = height maps read, tolerance = topography files given",
        reason="; ".join(failures)[:2000],
    )


def file_frames(ctx: Context) -> list[tuple[str, pd.DataFrame, Mapping[str, Any]]]:
    """``(source, rows, reader meta)`` per ingested file, in the order read."""
    metas: dict[str, Mapping[str, Any]] = {}
    for rec in ctx.files:
        metas.setdefault(Path(str(rec.get("path", ""))).name, rec.get("meta") or {})
    out = []
    for f in ctx.frames:
        for src, g in f.groupby("source", sort=False, observed=True):
            g = g.assign(quantity=g["quantity"].astype(str)).reset_index(drop=True)
            out.append((str(src), g, metas.get(str(src), {})))
    return out


def psi_delta_of_group(
    ctx: Context, path: str | os.PathLike[str]
) -> list[tuple[Path, pd.DataFrame]]:
    """The psi/Delta files of the sample group holding ``path``, with their ingested rows.

    In the order the group lists them; ``path`` itself is left out. A file whose name two
    inputs share is left out too (its rows' ``source`` cannot tell them apart).
    """
    key = str(Path(path))
    holding = [g for g in ctx.samples if any(str(Path(p)) == key for p in g.paths)]
    out = []
    for p in (Path(q) for q in (holding[0].paths if len(holding) == 1 else ())):
        if str(p) == key:
            continue
        found = [f for f in ctx.frames if len(f) and set(f["source"].astype(str)) == {p.name}]
        if len(found) == 1 and (found[0]["quantity"].astype(str) == "psi").any():
            out.append((p, found[0]))
    return out
