"""``labbrdf ingest``: read instrument exports into one dataset, a table per file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ._options import UsageError, _add_selection, _emit_json, _selected
from ._paths import InputPath, OutputPath, _add_overwrite


def cmd_ingest(args: argparse.Namespace) -> int:
    """Read the files, print one row per file, write the dataset with ``-o``."""
    from .. import adapters
    from ..dataset import concat, write
    from ..outputs import check_file_output

    out = None
    if args.output:  # checked with the inputs by _checked_outputs
        out = Path(args.output)
        if out.suffix.lower() == ".csv":  # its metadata goes to a sidecar beside it
            from ..dataset import sidecar_path

            check_file_output(
                sidecar_path(out), suffixes=(".json",), option=f"-o {out}: its metadata file"
            )
    from ..selection import SelectionError

    rows: list[dict[str, Any]] = []
    measurements = []
    failures: list[dict[str, str]] = []
    unselected: list[str] = []
    try:
        inputs = adapters.read_inputs(
            args.files,
            args.format,
            columns=_columns_spec(args),
            on_error="collect" if args.keep_going else "raise",
        )
    except (ValueError, NotImplementedError, OSError, ImportError) as exc:
        print(f"labbrdf ingest: {exc}", file=sys.stderr)
        return 2
    maps = [(i.path, i.height_map) for i in inputs.files if i.height_map is not None]
    for i in inputs.files:
        path, m = i.path, i.measurement
        if i.error:
            failures.append({"file": path, "error": i.error})
            continue
        if m is None:  # a height map: reported below, not part of the dataset
            continue
        try:
            m = _selected(args, m)
        except SelectionError as exc:
            unselected.append(f"{path}: {exc}")
            continue
        s = m.summary()
        _print_notes("ingest", path, i.measurement.meta if i.measurement is not None else m.meta)
        measurements.append(m)
        rows.append(
            {
                "file": path,
                "format": m.meta.get("format", args.format),
                "sample": s["sample"][0] if len(s["sample"]) == 1 else s["sample"],
                "rows": s["rows"],
                "quantities": s["quantities"],
                "channels": _channels(m.data),
                "wavelength_nm": s["wavelength_nm"],
                # False: the file states none and wavelength_nm is a label (.bsdf)
                "wavelength_stated": m.meta.get("wavelength_stated") is not False,
                "theta_i_deg": s["theta_i_deg"],
            }
        )
    if unselected and not measurements and not failures:
        raise UsageError("; ".join(unselected))
    if out is not None and measurements:
        write(concat(measurements), out)
    if args.json:
        payload: Any = rows + [{"file": p, "height_map": hm.summary()} for p, hm in maps]
        if failures:
            payload = payload + [{"file": f["file"], "error": f["error"]} for f in failures]
        _emit_json(payload)
    else:
        if rows or not maps:
            _print_ingest_table(rows)
        for p, hm in maps:
            print(f"{p}: height map, not optical data: {hm.summary_line()}")
        if out is not None and measurements:
            print(f"wrote {out} ({sum(r['rows'] for r in rows)} rows)")
    if out is not None and maps and not measurements:
        print(f"labbrdf ingest: no optical data, {out} not written", file=sys.stderr)
    for f in failures:
        print(f"labbrdf ingest: FAILED {f['error']}", file=sys.stderr)
    for u in unselected:
        print(f"labbrdf ingest: nothing selected in {u}", file=sys.stderr)
    return 2 if failures else 0


def _print_notes(command: str, path: str, meta: dict[str, Any]) -> None:
    """Print what a reader noted in ``meta["notes"]`` (rows dropped, lines skipped...).

    One line per note on stderr, prefixed with the file.
    """
    notes = list(meta.get("notes") or ())
    for part in meta.get("parts") or ():
        notes += (part.get("meta") or {}).get("notes") or ()
    for note in notes:
        print(f"labbrdf {command}: note: {path}: {note}", file=sys.stderr)


def _columns_spec(args: argparse.Namespace) -> str | None:
    """``--columns`` with ``--skip-lines`` joined as its ``skip_lines=`` setting."""
    if args.skip_lines is None:
        return args.columns
    if args.columns is None:
        raise UsageError("--skip-lines skips the leading lines of a file read with --columns")
    return f"{args.columns},skip_lines={args.skip_lines}"


def _channels(d: Any) -> dict[str, list[str]]:
    """The channels of each quantity that has any, in file order.

    ``p``/``s`` reflectance, generalised ellipsometry ``pp``/``ps``/``sp``, tristimulus
    ``X``/``Y``/``Z``; quantities without a channel are left out.
    """
    if "channel" not in d.columns:
        return {}
    out: dict[str, list[str]] = {}
    for q, c in d[["quantity", "channel"]].drop_duplicates().itertuples(index=False):
        if c:
            out.setdefault(str(q), []).append(str(c))
    return out


def _channels_cell(channels: dict[str, list[str]]) -> str:
    """``"p"``; ``"pp,ps,sp"`` when every quantity has the same; else per quantity."""
    if not channels:
        return "-"
    lists = {tuple(v) for v in channels.values()}
    if len(lists) == 1:
        return ",".join(next(iter(lists)))
    return " ".join(f"{q}:{','.join(v)}" for q, v in channels.items())


def _short(text: str, width: int = 36) -> str:
    return text if len(text) <= width else text[: width - 3] + "..."


def _quantities_cell(qs: list[str]) -> str:
    mm = [q for q in qs if q.startswith("mueller_")]
    rest = [q for q in qs if not q.startswith("mueller_")]
    if len(mm) > 2:
        rest.append(f"mueller({len(mm)})")
    else:
        rest.extend(mm)
    return ",".join(rest)


def _print_ingest_table(rows: list[dict[str, Any]]) -> None:
    head = [
        "file",
        "format",
        "sample",
        "quantities",
        "channel",
        "wavelength_nm",
        "theta_i_deg",
        "rows",
    ]
    table = []
    for r in rows:
        wl = r["wavelength_nm"]
        th = r["theta_i_deg"]
        table.append(
            [
                Path(r["file"]).name,
                str(r["format"]),
                _short(
                    str(r["sample"])
                    if isinstance(r["sample"], str)
                    else f"{len(r['sample'])} samples: {r['sample'][0]}, ..."
                ),
                _quantities_cell(r["quantities"]),
                _channels_cell(r["channels"]),
                f"{wl[0]:.6g}-{wl[1]:.6g}" if r["wavelength_stated"] else "not stated",
                ",".join(f"{t:g}" for t in th[:8]) + (",..." if len(th) > 8 else "") or "-",
                str(r["rows"]),
            ]
        )
    widths = [
        max(len(h), *(len(t[i]) for t in table)) if table else len(h) for i, h in enumerate(head)
    ]
    print("  ".join(h.ljust(w) for h, w in zip(head, widths, strict=True)))
    for t in table:
        print("  ".join(c.ljust(w) for c, w in zip(t, widths, strict=True)))


def add_parser(sub: Any) -> None:
    """The ``ingest`` subcommand's options."""
    s = sub.add_parser("ingest", help="read instrument exports into one dataset")
    s.add_argument("files", nargs="+", action=InputPath, metavar="FILE")
    s.add_argument("--format", default=None, help="force an adapter (see `labbrdf formats`)")
    s.add_argument(
        "--columns",
        default=None,
        metavar="NAMES",
        help="declare the columns of a headerless numeric file (implies --format columns), "
        "e.g. wavelength_nm,absorbance; see docs/formats.md",
    )
    s.add_argument(
        "--skip-lines",
        default=None,
        metavar="N|auto",
        help="with --columns: skip the first N lines (a title or header), or with 'auto' "
        "every line before the first row of numbers; the skipped lines go in the metadata",
    )
    s.add_argument(
        "-o",
        "--output",
        action=OutputPath,
        suffixes=(".parquet", ".csv"),
        default=None,
        help="write OUT.parquet, or OUT.csv and its metadata OUT.meta.json",
    )
    _add_overwrite(s)
    s.add_argument("--json", action="store_true", help="print a JSON list, one object per file")
    s.add_argument("--keep-going", action="store_true", help="read the rest after a failure")
    _add_selection(s)
    s.set_defaults(func=cmd_ingest)
