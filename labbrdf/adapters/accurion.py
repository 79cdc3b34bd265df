"""Accurion nanofilm EP3/EP4 imaging-ellipsometer exports (``.dat``, ``.ds.dat``).

Layout (docs/formats.md section 3, checked on every real EP3/EP4 export the test suite
reads): TAB separated, a ``#``-line of column names, a
``#``-line of units (Latin-1: ``µm`` is byte 0xB5), then one row per measurement. Two column
layouts are in use, so columns are matched by NAME (:data:`COLUMN_MAP`), never by position:

* EP4 software: ``#Lambda Bandwidth AOI Delta Psi Zone Amin Pmin Afix Pfix ROIidx [Time]
  X_pos Y_pos`` (Delta before Psi);
* DataStudio 2024: ``#ROIidx AOI Lambda Bandwidth ExposureTime ROI_x ROI_y Delta Psi``.

The EP4 software's "WVASE format" export is read too: a title line, then
``nm<TAB><TAB>Psi<TAB>Delta`` (the empty name is the AOI), then ``lambda AOI Psi Delta`` rows.

Zones (nulling ellipsometry measures each point in up to four polariser/compensator zones):
a ``Zone`` column numbers the rows 1-4 (one nulling measurement each), 0 (the zone average,
nulling angles NaN) and 5. **Zone 5 is the peak-to-peak spread (max - min) of the valid
zones, not a standard deviation**: in ``15-1-1.dat`` at AOI 50 deg, Psi of zones 1-4 is
31.277, 31.291, 31.520, 31.474 and zone 5 says 0.243 = 31.520 - 31.277 (Delta: 0.220 =
169.785 - 169.565); at 66 deg, where zone 4 failed, it is the spread of zones 1-3.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import Measurement, wrap_delta
from ._base import AdapterError, Example, Format, decode, read_bytes, split_lines
from ._frame import build_frame, check_rows, delta_range, group_angles, measurement
from ._numblock import Block, parse_block, split_head

__all__ = ["COLUMN_MAP", "FORMATS", "read_accurion", "sniff_accurion"]

#: Accurion column name -> labbrdf meaning (column names are matched case-sensitively).
COLUMN_MAP: dict[str, str] = {
    "Lambda": "wavelength_nm",
    "AOI": "theta_i_deg",
    "Psi": "psi",
    "Delta": "delta",
    "Zone": "zone",
    "Time": "time_s",
    "X_pos": "x_mm",
    "Y_pos": "y_mm",
}

#: the unit each mapped column must carry when the file has a unit row
_UNITS = {
    "Lambda": "nm",
    "AOI": "deg",
    "Psi": "deg",
    "Delta": "deg",
    "Zone": "-",
    "Time": "s",
    "X_pos": "mm",
    "Y_pos": "mm",
}
_REQUIRED = ("Lambda", "AOI", "Psi", "Delta")
_DATA_ZONES = (1, 2, 3, 4)
_WVASE_LINE2 = re.compile(r"^nm\t\t(Psi\tDelta|Delta\tPsi)\s*$")


def sniff_accurion(head: bytes) -> bool:
    """True for an EP3/EP4 table (``#`` name row with AOI, Psi, Delta) or its WVASE export."""
    try:
        lines = head.removeprefix(b"\xef\xbb\xbf").decode("latin-1").splitlines()
        if not lines:
            return False
        if lines[0].startswith("#"):
            names = {s.strip() for s in lines[0][1:].split("\t")}
            return {"AOI", "Psi", "Delta"} <= names and ("Lambda" in names)
        return len(lines) > 1 and bool(_WVASE_LINE2.match(lines[1]))
    except Exception:  # a sniffer never raises
        return False


def _layout(
    path: str | os.PathLike[str], text: str
) -> tuple[list[str], list[str] | None, str, int, dict[str, Any]]:
    """Column names, units (or None), body text and its first line number, and meta."""
    head, _ = split_head(text, 2)
    meta: dict[str, Any] = {}
    if not head:
        raise AdapterError(path, "the file is empty")
    if head[0].startswith("#"):
        names = [s.strip() for s in head[0][1:].split("\t")]
        units: list[str] | None = None
        nhead = 1
        if len(head) > 1 and head[1].startswith("#"):
            units = [s.strip() for s in head[1][1:].split("\t")]
            nhead = 2
            if len(units) != len(names):
                raise AdapterError(
                    path,
                    f"the unit row has {len(units)} entries for {len(names)} column names",
                    2,
                )
        meta["variant"] = "ep4-table"
    elif len(head) > 1 and _WVASE_LINE2.match(head[1]):
        meta["variant"] = "ep4-wvase-format"
        meta["title"] = head[0].strip()
        fields = [s.strip() for s in head[1].split("\t")]
        names = ["Lambda", "AOI", fields[2], fields[3]]
        units = ["nm", "deg", "deg", "deg"]
        nhead = 2
    else:
        raise AdapterError(
            path,
            "expected a '#' column-name row (Accurion EP3/EP4 table) or the EP4 WVASE-format "
            "header 'nm<TAB><TAB>Psi<TAB>Delta' on line 2",
            1,
        )
    dup = sorted({n for n in names if names.count(n) > 1 and n})
    if dup:
        raise AdapterError(path, f"duplicate column name(s) {dup}", 1)
    missing = [c for c in _REQUIRED if c not in names]
    if missing:
        raise AdapterError(path, f"missing column(s) {missing}; the header names {names}", 1)
    if units is not None:
        for c, u in zip(names, units, strict=True):
            if c in _UNITS and u != _UNITS[c]:
                raise AdapterError(path, f"column {c!r} has unit {u!r}, expected {_UNITS[c]!r}", 2)
    _, body = split_head(text, nhead)
    return names, units, body, nhead + 1, meta


def _check_empty_fields(
    path: str | os.PathLike[str],
    body: str,
    first: int,
    lines: np.ndarray,
    values: np.ndarray,
    names: list[str],
) -> None:
    """Refuse an empty field among the columns: only a written ``NaN`` is a missing value.

    The block parser gives NaN for both, so the (few) rows with a NaN are looked at again
    in the text: a row cut after a TAB must not be read with its last columns NaN.
    """
    rows = np.flatnonzero(np.isnan(values[:, : len(names)]).any(axis=1))
    if rows.size == 0:
        return
    text_lines = split_lines(body)
    for i in rows:
        lineno = int(lines[i])
        fields = text_lines[lineno - first].split("\t")
        for k, name in enumerate(names):
            if k >= len(fields) or not fields[k].strip():
                raise AdapterError(
                    path,
                    f"field {k + 1} ({name or 'unnamed'}) is empty: expected a number "
                    f"(or NaN) in each of the {len(names)} columns (row cut short?)",
                    lineno,
                )


def read_accurion(path: str | os.PathLike[str]) -> Measurement:
    """Read an Accurion nanofilm EP3/EP4 export.

    Parameters
    ----------
    path : str or path-like
        The ``.dat`` / ``.ds.dat`` table or the EP4 "WVASE format" export.

    Returns
    -------
    Measurement
        ``psi`` and ``delta`` [deg] (Delta wrapped into [0, 360)), wavelength from
        ``Lambda`` [nm], theta_i from ``AOI`` (theta_r = theta_i, phi_r = 180 deg), sigma NaN
        (the file has none), and ``time_s``, ``x_mm``, ``y_mm`` from ``Time``, ``X_pos``,
        ``Y_pos`` when present.

    Raises
    ------
    AdapterError
        Missing or duplicate columns, a unit other than expected, a row with the wrong
        number of fields or a non-number (with its line), psi or AOI out of range, no data.

    Notes
    -----
    Zones: the rows of zones 1-4 are the data (each a complete nulling measurement) and
    keep their number in the ``zone`` column, so the four rows of one spot and angle stay
    distinguishable. The
    zone-0 rows (average of the zones) are dropped as redundant and the zone-5 rows (the
    max - min spread of the zones, see the module docstring) are not measurements either;
    both are counted in ``meta["dropped_rows"]`` and the spreads are kept in
    ``meta["zone_spread"]``. A file with zone-0 rows but no zone 1-4 rows keeps its zone-0
    rows (``meta["data_zones"]`` says which). Rows whose Psi or Delta is ``NaN`` (a zone
    that did not null) are dropped and counted. Zone rows carry no sigma: the spread of four
    zones is not a per-zone 1-sigma, and the zones differ systematically (that is why
    nulling ellipsometers average them), so sigma stays NaN.

    Delta is taken as written (0..360, the Nebraska convention: a thin film on Si gives
    0 < Delta < 180 deg in ``15-1-1.dat`` and ``corefine_PNIPAM_ellipsometry.dat``) and only
    wrapped. Columns without a place in the schema (Bandwidth, nulling angles, exposure,
    ROI position on the camera) are summarised in meta.
    """
    raw = read_bytes(path)
    text, encoding = decode(raw, path, ("utf-8", "latin-1"))
    meta, names, block, col = _read_table(path, text, encoding)
    wl, aoi, psi, delta = col["Lambda"], col["AOI"], col["Psi"], col["Delta"]
    n = len(wl)
    data, dropped = _data_zones(path, block, col, meta)
    failed = data & ~(np.isfinite(psi) & np.isfinite(delta))
    if failed.any():
        dropped.append(
            {"count": int(failed.sum()), "reason": "Psi/Delta NaN (the zone did not null)"}
        )
    keep = data & ~failed
    if not keep.any():
        raise AdapterError(path, f"no valid Psi/Delta rows (dropped: {dropped})")
    frame = _frame(path, meta, col, keep)
    for c, key in (("Bandwidth", "bandwidth_nm_range"), ("ExposureTime", "exposure_range")):
        if c in col and np.isfinite(col[c][keep]).any():
            meta[key] = [float(np.nanmin(col[c][keep])), float(np.nanmax(col[c][keep]))]
    if "ROIidx" in col:
        meta["roi_indices"] = sorted({int(x) for x in col["ROIidx"][keep] if np.isfinite(x)})
    ignored = [c for c in names if c and c not in COLUMN_MAP and c not in ("ROIidx",)]
    meta["columns_not_in_schema"] = ignored
    meta["data_lines"] = int(n)
    meta["blank_lines_skipped"] = block.blank_lines
    meta["dropped_rows"] = dropped
    meta["delta_convention"] = "Nebraska, as written by the EP4 software (0..360 deg)"
    meta["delta_range_in_file"] = delta_range(delta[keep])
    meta["delta_range"] = "[0, 360)"
    meta["angles_deg"] = group_angles(aoi[keep])
    meta["wavelength_nm"] = [float(wl[keep].min()), float(wl[keep].max())]
    meta["sigma"] = "none in the file (NaN)"
    return measurement(path, frame, meta)


def _read_table(
    path: str | os.PathLike[str], text: str, encoding: str
) -> tuple[dict[str, Any], list[str], Block, dict[str, np.ndarray]]:
    """The header's meta, the column names, the checked block and its columns by name."""
    names, units, body, first, meta = _layout(path, text)
    p = Path(path)
    meta = {"source_file": p.name, "encoding": encoding, **meta}
    meta["columns"] = names
    if units is not None:
        meta["units"] = units
    ncol = len(names)
    block = parse_block(path, body, first, ncol, sep="\t", count_fields=True)
    if len(block.lines) == 0:
        raise AdapterError(path, "no data rows after the header")
    assert block.nfields is not None
    check_rows(
        path,
        block,
        block.nfields < ncol,
        f"expected {ncol} TAB-separated fields ({', '.join(n or '?' for n in names)})",
    )
    v = block.values
    _check_empty_fields(path, body, first, block.lines, v, names)
    col = {n: v[:, k] for k, n in enumerate(names) if n}
    wl, aoi, psi, delta = col["Lambda"], col["AOI"], col["Psi"], col["Delta"]
    check_rows(path, block, ~(np.isfinite(wl) & (wl > 0)), "Lambda must be a number > 0 [nm]")
    check_rows(
        path,
        block,
        ~(np.isfinite(aoi) & (aoi >= 0) & (aoi <= 90)),
        "AOI must be within [0, 90] deg",
    )
    check_rows(
        path, block, np.isfinite(psi) & ((psi < 0) | (psi > 90)), "Psi must be within [0, 90] deg"
    )
    check_rows(path, block, np.isinf(psi) | np.isinf(delta), "Psi/Delta must be finite or NaN")
    return meta, names, block, col


def _data_zones(
    path: str | os.PathLike[str],
    block: Block,
    col: dict[str, np.ndarray],
    meta: dict[str, Any],
) -> tuple[np.ndarray, list[dict[str, Any]]]:
    """The rows of the data zones, and the zone rows dropped (see :func:`read_accurion`)."""
    wl, aoi, psi, delta = col["Lambda"], col["AOI"], col["Psi"], col["Delta"]
    data = np.ones(len(wl), dtype=bool)
    dropped: list[dict[str, Any]] = []
    if "Zone" in col:
        zone = col["Zone"]
        ok = np.isfinite(zone) & (zone == np.round(zone)) & (zone >= 0) & (zone <= 5)
        check_rows(path, block, ~ok, "Zone must be an integer 0-5")
        zone = zone.astype(np.int64)
        has_zones = np.isin(zone, _DATA_ZONES)
        data_zones = list(_DATA_ZONES) if has_zones.any() else [0]
        data = np.isin(zone, data_zones)
        meta["data_zones"] = data_zones
        n0 = int(((zone == 0) & ~data).sum())
        if n0:
            dropped.append(
                {
                    "zone": 0,
                    "count": n0,
                    "reason": "zone average (redundant with the zone 1-4 rows kept)",
                }
            )
        z5 = zone == 5
        if z5.any():
            dropped.append(
                {
                    "zone": 5,
                    "count": int(z5.sum()),
                    "reason": "peak-to-peak spread of the zones, not a measurement",
                }
            )
            meta["zone_spread"] = [
                {
                    "wavelength_nm": float(wl[i]),
                    "aoi_deg": float(aoi[i]),
                    "psi_pp_deg": float(psi[i]) if np.isfinite(psi[i]) else None,
                    "delta_pp_deg": float(delta[i]) if np.isfinite(delta[i]) else None,
                }
                for i in np.flatnonzero(z5)
            ]
    return data, dropped


def _frame(
    path: str | os.PathLike[str],
    meta: dict[str, Any],
    col: dict[str, np.ndarray],
    keep: np.ndarray,
) -> pd.DataFrame:
    """The tidy frame of the rows ``keep``: a psi row then a delta row for each."""
    p = Path(path)
    wl, aoi, psi, delta = col["Lambda"], col["AOI"], col["Psi"], col["Delta"]
    r = np.flatnonzero(keep)
    m = r.size

    def two(a: np.ndarray) -> np.ndarray:  # psi row then delta row for each data row
        return np.repeat(a[r], 2)

    optional: dict[str, Any] = {}
    for c in ("Time", "X_pos", "Y_pos", "Zone"):
        if c in col:
            optional[COLUMN_MAP[c]] = two(col[c])
    values = np.empty(2 * m)
    values[0::2] = psi[r]
    values[1::2] = wrap_delta(delta[r])
    sample = p.name
    for suffix in (".dat", ".ds"):
        sample = sample.removesuffix(suffix)
    if meta.get("title"):
        sample = re.split(r"[\\/]", meta["title"])[-1] or sample
    return build_frame(
        sample=sample,
        instrument="accurion-ep4",
        source=p.name,
        quantity=np.tile(np.array(["psi", "delta"], dtype=object), m),
        value=values,
        unit="deg",
        wavelength_nm=two(wl),
        theta_i_deg=two(aoi),
        theta_r_deg=two(aoi),
        phi_r_deg=180.0,
        **optional,
    )


FORMATS: tuple[Format, ...] = (
    Format(
        name="accurion-ep4",
        description="Accurion nanofilm EP3/EP4 imaging ellipsometer export (both column "
        "layouts, zone rows, WVASE-format export)",
        extensions=(".dat",),
        sniff=sniff_accurion,
        read=read_accurion,
        quantities=("psi", "delta"),
        keywords=(b"#Lambda\t", b"#ROIidx\t", b"\tAOI\t", b"WVASEformat"),
        examples=(
            Example("accurion-ep4-dat/15-1-1.dat", rows_per_line=2),
            Example("accurion-ep4-dat/corefine_PNIPAM_ellipsometry.dat", rows_per_line=2),
            Example(
                "accurion-ep4-dat/Si3N4_on_4inBF33_W02_20240903-150451.ds.dat", rows_per_line=2
            ),
            Example("accurion-ep4-dat/testData1_11nm_PNIPAM_on_Si_EP4.dat", rows_per_line=2),
            Example("accurion-ep4-dat/post synthesis.dat", number=("143.615", 3)),
        ),
    ),
)
