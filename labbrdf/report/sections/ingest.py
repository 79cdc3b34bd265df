"""Section ``ingest``: every input file read into the common dataset, with what it holds."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ... import adapters
from ...adapters.inputs import InputFile
from ..builder import Unavailable
from ..context import Context
from ..published import read_published

__all__ = [
    "fixture_files",
    "fixtures_section",
    "ingest_files",
    "ingest_inputs",
    "ingest_read",
    "list_unreadable",
    "sample_groups",
]


def fixture_files(folder: Path) -> list[Path]:
    """Every data file under ``folder`` except ``published/``, docs and the generator.

    ``predict_measure/`` is left out too: that set is one sample for the section
    ``model_measurement``, which reads it itself (its .bsdf is not a specular scan to fit).
    """
    skip_dirs = {"published", "predict_measure", "__pycache__"}
    out = []
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder)
        if not p.is_file() or any(part in skip_dirs or part.startswith(".") for part in rel.parts):
            continue
        if p.suffix.lower() in (".md", ".py", ".txt", ".pyc") or p.name.startswith("."):
            continue
        out.append(p)
    return out


def fixtures_section(ctx: Context) -> None:
    """The validation report's ingest: the published tables, then every fixture file."""
    fx = ctx.fixtures
    if fx is None:
        raise Unavailable("no fixture folder given")
    b = ctx.b
    b.text(
        f"Fixture folder: {fx}. Every file below was read with labbrdf.read (format "
        "from the extension and the header) into the common dataset. The fixtures are "
        "SYNTHETIC files in real export formats, see fixtures/README.md."
    )
    tables, pub = read_published(fx / "published")
    ctx.published.update(tables)
    b.text("Published tables read: " + (", ".join(pub) if pub else "none found") + ".")
    if not fx.is_dir():
        raise Unavailable(f"fixture folder {fx} not found")
    ingest_files(ctx, fixture_files(fx), root=fx)


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
    (:func:`~labbrdf.report.sections.surface.ingest_height_maps`), optical exports to
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
    from .surface import ingest_height_maps  # the section that shows the height maps

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
    from ...samples import PairingError, pair_samples, sample_file

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


# --------------------------------------------------------------------------- fits
