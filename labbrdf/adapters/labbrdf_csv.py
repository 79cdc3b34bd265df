"""labbrdf's own documented CSV layouts: specular scans and hemispherical-reflectance spectra.

No public real file of a goniometric specular scan was found (docs/formats.md, "Formats we
looked for"), so labbrdf defines two small CSV layouts that any lab script or spreadsheet
can write. Both are UTF-8 text (a UTF-8 BOM is allowed), any line ending, ``.`` as the
decimal separator, ``,`` as the cell separator.

Common rules
------------
1. Line 1 is the magic line, exactly ``# labbrdf specular-scan v1`` or
   ``# labbrdf hemispherical-reflectance v1`` (trailing blanks or commas, as spreadsheets
   write them, are ignored). Another version number is refused.
2. Then optional header lines ``# key: value``. Keys are case-insensitive; ``sample``,
   ``instrument``, ``quantity``, ``unit`` and ``theta_i_deg`` have a meaning (below), any
   other key (``operator``, ``date``, ``notes`` ...) is kept in ``meta["header"]``. A ``#``
   line without a colon is a free comment, kept in ``meta["comments"]``. Blank lines are
   ignored everywhere.
3. The first other line is the column header; column names are case-insensitive, in any
   order, each at most once; unknown names are an error.
4. Every data row has one cell per column (one extra empty trailing cell is tolerated).
   An empty ``value`` cell, or ``nan``, is a missing point: dropped and counted in
   ``meta["dropped_points"]``. An empty ``sigma`` means "no uncertainty" (NaN). Every other
   cell must be a finite decimal number. ``#`` lines between data rows are comments.
5. ``sample`` defaults to the file stem, ``instrument`` to ``labbrdf-csv``.
6. A bad row raises :class:`~labbrdf.AdapterError` with its line number: wrong
   cell count, a non-number, wavelength <= 0, an angle outside its range, sigma < 0.
7. A last data row without line end whose last number is written shorter than its column
   (a file cut mid-number: ``0.0`` where the column is written ``0.01``) is refused, or
   warned about where the column's writing varies
   (``check_last_field``; the warning is kept in
   ``meta["warnings"]``).

(a) Specular scan: ``# labbrdf specular-scan v1``
-------------------------------------------------
Header keys: ``quantity`` (required): ``brdf`` or ``specular_intensity``; ``unit``:
``sr-1`` for ``brdf`` (the default and only choice), ``1`` (default), ``sr-1`` or ``%``
(converted to ``1``) for ``specular_intensity``. ``detector_half_angle_deg`` and
``beam_half_angle_deg`` (optional, each in [0, 20]): the instrument's aperture, the
half-angles of the detector's cone and of the beam's divergence [deg], kept in
``meta["aperture"]`` (a fit uses it: ``labbrdf fit --aperture``; a key left out is 0).

Columns: ``wavelength_nm``, ``theta_i_deg``, ``theta_r_deg``, ``value`` (required);
``sigma`` (1-sigma uncertainty, same unit as value), ``phi_r_deg`` (optional).
Angles in degrees. theta_i in [0, 90]; theta_r in [0, 90] is the polar angle of the
detector and phi_r in [0, 360) its azimuth, with the source at phi_i = 0; without a
``phi_r_deg`` column every row is in the specular half-plane, phi_r = 180 (theta_r >= 0 on
the specular side, the specular direction is theta_r = theta_i).

A *signed in-plane scan* (detector angle negative on the source side of the normal, as
many goniometers report it) may be written as is, without a ``phi_r_deg`` column: a row
with theta_r < 0 is converted to theta_r = |theta_r|, phi_r = 0 (the source's half-plane),
and the number of such rows is given in ``meta["signed_theta_r_converted"]``. With a
``phi_r_deg`` column, theta_r must be >= 0.

Example::

    # labbrdf specular-scan v1
    # sample: Al mirror M3
    # instrument: goniometer-A
    # quantity: brdf
    # unit: sr-1
    # notes: s-polarised source, 2 deg detector aperture
    wavelength_nm,theta_i_deg,theta_r_deg,value,sigma
    632.8,45,43,12.5,0.4
    632.8,45,45,180.2,3.1

(b) Hemispherical reflectance: ``# labbrdf hemispherical-reflectance v1``
-------------------------------------------------------------------------
Header keys: ``unit`` (required): ``1`` (fraction) or ``%`` (converted to a fraction);
``theta_i_deg``: the incidence angle of the sphere's sample port, e.g. ``8`` (default:
NaN, i.e. not stated). Columns: ``wavelength_nm``, ``value`` (required), ``sigma``.
The quantity is ``hemispherical_reflectance``.

Example::

    # labbrdf hemispherical-reflectance v1
    # sample: OSR tile 7
    # instrument: Lambda 1050 + 150 mm sphere
    # unit: %
    # theta_i_deg: 8
    wavelength_nm,value,sigma
    250,8.12,0.05
    255,8.30,0.05
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Any

from ..dataset import Measurement, make_frame
from ._base import AdapterError, Format, decode, read_bytes, split_lines
from ._spectro import finish, number
from ._truncation import check_last_row

__all__ = ["FORMATS", "read_hemispherical", "read_specular_scan"]

DEFAULT_INSTRUMENT = "labbrdf-csv"
_MAGIC = re.compile(r"#\s*labbrdf\s+(specular-scan|hemispherical-reflectance)\s+v(\d+)[\s,]*")
_SPECULAR = "specular-scan"
_HEMI = "hemispherical-reflectance"

_COLUMNS = {
    _SPECULAR: (
        ("wavelength_nm", "theta_i_deg", "theta_r_deg", "value"),
        ("sigma", "phi_r_deg"),
    ),
    _HEMI: (("wavelength_nm", "value"), ("sigma",)),
}

#: quantity -> {unit in the file: (canonical unit, factor)}
_UNITS: dict[str, dict[str, tuple[str, float]]] = {
    "brdf": {"sr-1": ("sr-1", 1.0)},
    "specular_intensity": {"1": ("1", 1.0), "sr-1": ("sr-1", 1.0), "%": ("1", 0.01)},
    "hemispherical_reflectance": {"1": ("1", 1.0), "%": ("1", 0.01)},
}
_DEFAULT_UNIT = {"brdf": "sr-1", "specular_intensity": "1"}


def _sniff_layout(head: bytes, layout: str) -> bool:
    head = head.removeprefix(b"\xef\xbb\xbf")
    first = head.split(b"\n", 1)[0].rstrip(b"\r")
    m = _MAGIC.fullmatch(first.decode("ascii", "replace"))
    return m is not None and m.group(1) == layout


def _sniff_specular(head: bytes) -> bool:
    return _sniff_layout(head, _SPECULAR)


def _sniff_hemi(head: bytes) -> bool:
    return _sniff_layout(head, _HEMI)


def _parse(
    path: str | os.PathLike[str], layout: str
) -> tuple[dict[str, str], list[str], dict[str, int], list[tuple[int, list[str]]]]:
    """Magic, ``# key: value`` header, column header and raw data rows (line, cells)."""
    raw = read_bytes(path)
    text, _ = decode(raw, path, ("utf-8",))
    lines = split_lines(text)
    m = _MAGIC.fullmatch(lines[0].strip()) if lines else None
    if m is None or m.group(1) != layout:
        raise AdapterError(path, f"expected the first line '# labbrdf {layout} v1'", 1)
    if m.group(2) != "1":
        raise AdapterError(
            path, f"version v{m.group(2)} of the {layout} layout is not supported (only v1)", 1
        )
    keys: dict[str, str] = {}
    comments: list[str] = []
    columns: dict[str, int] | None = None
    rows: list[tuple[int, list[str]]] = []
    for n, line in enumerate(lines[1:], start=2):
        s = line.strip()
        if not s or s.strip(",") == "":
            continue
        if s.startswith("#"):
            body = s[1:].strip().rstrip(",").strip()
            if columns is None and ":" in body:
                key, _, value = body.partition(":")
                key = key.strip().lower()
                if key in keys:
                    raise AdapterError(path, f"header key {key!r} given twice", n)
                keys[key] = value.strip()
            elif body:
                comments.append(body)
            continue
        cells = [c.strip() for c in line.split(",")]
        if columns is None:
            columns = _columns(path, layout, cells, n)
            continue
        if len(cells) == len(columns) + 1 and cells[-1] == "":
            cells = cells[:-1]
        if len(cells) != len(columns):
            raise AdapterError(
                path,
                f"expected {len(columns)} cells ({', '.join(columns)}), found {len(cells)}",
                n,
            )
        rows.append((n, cells))
    if columns is None:
        raise AdapterError(path, "no column header line after the '# key: value' lines")
    if not rows:
        raise AdapterError(path, "no data rows after the column header")
    keys["__comments__"] = "\n".join(comments)
    keys["__warnings__"] = _check_cut(path, text, lines, rows)
    return keys, lines, columns, rows


def _check_cut(
    path: str | os.PathLike[str], text: str, lines: list[str], rows: list[tuple[int, list[str]]]
) -> str:
    """Refuse (or warn about, returned) a last data row without line end that looks cut."""
    return check_last_row(path, text, lines, [n for n, _ in rows], ",") or ""


def _columns(
    path: str | os.PathLike[str], layout: str, cells: list[str], n: int
) -> dict[str, int]:
    required, optional = _COLUMNS[layout]
    names = [c.lower() for c in cells]
    if names and names[-1] == "":
        names = names[:-1]
    unknown = [c for c in names if c not in required + optional]
    if unknown:
        raise AdapterError(
            path,
            f"unknown column(s) {unknown}; required {list(required)}, optional {list(optional)}",
            n,
        )
    dup = sorted({c for c in names if names.count(c) > 1})
    if dup:
        raise AdapterError(path, f"column(s) {dup} given twice", n)
    missing = [c for c in required if c not in names]
    if missing:
        raise AdapterError(
            path, f"missing column(s) {missing}; the header must name {list(required)}", n
        )
    return {c: i for i, c in enumerate(names)}


def _cell(
    path: str | os.PathLike[str], n: int, cells: list[str], columns: dict[str, int], name: str
) -> float:
    """A required number, or NaN for an empty/``nan`` value or sigma."""
    text = cells[columns[name]]
    if name in ("value", "sigma") and text.lower() in ("", "nan"):
        return math.nan
    return number(text, path, n, name)


def _meta(keys: dict[str, str], layout: str, used: tuple[str, ...]) -> dict[str, Any]:
    comments = keys.pop("__comments__")
    doubt = keys.pop("__warnings__")
    meta: dict[str, Any] = {
        "format": f"labbrdf-{layout}",
        "version": 1,
        "header": {k: v for k, v in keys.items() if k not in used},
        "comments": comments.split("\n") if comments else [],
    }
    if doubt:
        meta["warnings"] = [doubt]
    return meta


def _range(
    path: str | os.PathLike[str], n: int, name: str, v: float, lo: float, hi: float, hi_open: bool
) -> None:
    if not (lo <= v < hi if hi_open else lo <= v <= hi):
        bracket = ")" if hi_open else "]"
        raise AdapterError(path, f"{name} {v:g} is outside [{lo:g}, {hi:g}{bracket}", n)


#: header key -> the aperture's half-angle it states [deg]
_APERTURE = {"detector_half_angle_deg": "detector_deg", "beam_half_angle_deg": "beam_deg"}
#: largest half-angle a header may state [deg] (as ``models.aperture.MAX_APERTURE_DEG``)
_MAX_HALF_ANGLE_DEG = 20.0


def _aperture(path: str | os.PathLike[str], keys: dict[str, str]) -> dict[str, float]:
    """``{"detector_deg", "beam_deg"}`` from the header's half-angle keys; {} if none."""
    if not any(k in keys for k in _APERTURE):
        return {}
    out = {}
    for key, name in _APERTURE.items():
        text = keys.get(key, "0")
        try:
            v = float(text)
        except ValueError:
            v = math.nan
        if not 0.0 <= v <= _MAX_HALF_ANGLE_DEG:
            raise AdapterError(
                path,
                f"'# {key}: {text}': expected a half-angle in [0, {_MAX_HALF_ANGLE_DEG:g}] deg",
            )
        out[name] = v
    return out


def read_specular_scan(path: str | os.PathLike[str]) -> Measurement:
    """Read a ``# labbrdf specular-scan v1`` CSV (layout (a) of this module's docstring).

    Parameters
    ----------
    path : str or path-like
        The CSV file.

    Returns
    -------
    Measurement
        One row per measured direction: quantity ``brdf`` [sr-1] or ``specular_intensity``,
        with wavelength [nm], theta_i, theta_r and phi_r [deg].

    Raises
    ------
    AdapterError
        A wrong magic line, a missing or unknown header key value or column, or a bad row
        (with its line number).
    """
    keys, _, columns, rows = _parse(path, _SPECULAR)
    quantity = keys.get("quantity", "")
    if quantity not in ("brdf", "specular_intensity"):
        raise AdapterError(
            path, f"'# quantity:' must be 'brdf' or 'specular_intensity', found {quantity!r}"
        )
    unit_in = keys.get("unit", _DEFAULT_UNIT[quantity])
    if unit_in not in _UNITS[quantity]:
        raise AdapterError(
            path, f"'# unit: {unit_in}' does not fit {quantity}; use {sorted(_UNITS[quantity])}"
        )
    unit, factor = _UNITS[quantity][unit_in]
    has_phi = "phi_r_deg" in columns
    has_sigma = "sigma" in columns
    out: dict[str, list[float]] = {k: [] for k in ("wl", "ti", "tr", "pr", "v", "s")}
    dropped = converted = 0
    for n, cells in rows:
        wl = _cell(path, n, cells, columns, "wavelength_nm")
        ti = _cell(path, n, cells, columns, "theta_i_deg")
        tr = _cell(path, n, cells, columns, "theta_r_deg")
        v = _cell(path, n, cells, columns, "value")
        s = _cell(path, n, cells, columns, "sigma") if has_sigma else math.nan
        if wl <= 0:
            raise AdapterError(path, f"wavelength_nm {wl:g}: expected > 0", n)
        _range(path, n, "theta_i_deg", ti, 0, 90, False)
        if has_phi:
            pr = _cell(path, n, cells, columns, "phi_r_deg")
            _range(path, n, "phi_r_deg", pr, 0, 360, True)
            _range(path, n, "theta_r_deg", tr, 0, 90, False)
        else:
            _range(path, n, "theta_r_deg", tr, -90, 90, False)
            pr = 180.0
            if tr < 0:
                tr, pr = -tr, 0.0
                converted += 1
        if s < 0:
            raise AdapterError(path, f"sigma {s:g}: expected >= 0", n)
        if math.isnan(v):
            dropped += 1
            continue
        for key, val in zip(out, (wl, ti, tr, pr, v * factor, s * factor), strict=True):
            out[key].append(val)
    frame = make_frame(
        sample=keys.get("sample") or Path(path).stem,
        instrument=keys.get("instrument") or DEFAULT_INSTRUMENT,
        source=os.path.basename(os.fspath(path)),
        quantity=quantity,
        value=out["v"],
        sigma=out["s"],
        unit=unit,
        wavelength_nm=out["wl"],
        theta_i_deg=out["ti"],
        theta_r_deg=out["tr"],
        phi_r_deg=out["pr"],
    )
    aperture = _aperture(path, keys)
    meta = _meta(keys, _SPECULAR, ("sample", "instrument", "quantity", "unit", *_APERTURE))
    if aperture:
        meta["aperture"] = aperture
    meta.update(
        quantity=quantity,
        unit_in_file=unit_in,
        dropped_points=dropped,
        signed_theta_r_converted=converted,
    )
    return finish(path, [frame], meta)


def read_hemispherical(path: str | os.PathLike[str]) -> Measurement:
    """Read a ``# labbrdf hemispherical-reflectance v1`` CSV (layout (b) of the docstring).

    Parameters
    ----------
    path : str or path-like
        The CSV file.

    Returns
    -------
    Measurement
        Quantity ``hemispherical_reflectance`` [1] against wavelength [nm], theta_i from the
        ``theta_i_deg`` header key (NaN when absent).

    Raises
    ------
    AdapterError
        A wrong magic line, a missing ``unit`` key, a bad ``theta_i_deg``, a missing or
        unknown column, or a bad row (with its line number).
    """
    keys, _, columns, rows = _parse(path, _HEMI)
    if "unit" not in keys:
        raise AdapterError(path, "missing '# unit:' header line ('1' for fractions or '%')")
    units = _UNITS["hemispherical_reflectance"]
    if keys["unit"] not in units:
        raise AdapterError(path, f"'# unit: {keys['unit']}': expected one of {sorted(units)}")
    _, factor = units[keys["unit"]]
    theta_i = math.nan
    if keys.get("theta_i_deg"):
        theta_i = number(keys["theta_i_deg"], path, None, "'# theta_i_deg:'")
        if not 0 <= theta_i <= 90:
            raise AdapterError(path, f"'# theta_i_deg: {theta_i:g}' is outside [0, 90]")
    has_sigma = "sigma" in columns
    wls: list[float] = []
    vals: list[float] = []
    sigs: list[float] = []
    dropped = 0
    for n, cells in rows:
        wl = _cell(path, n, cells, columns, "wavelength_nm")
        v = _cell(path, n, cells, columns, "value")
        s = _cell(path, n, cells, columns, "sigma") if has_sigma else math.nan
        if wl <= 0:
            raise AdapterError(path, f"wavelength_nm {wl:g}: expected > 0", n)
        if s < 0:
            raise AdapterError(path, f"sigma {s:g}: expected >= 0", n)
        if math.isnan(v):
            dropped += 1
            continue
        wls.append(wl)
        vals.append(v * factor)
        sigs.append(s * factor)
    frame = make_frame(
        sample=keys.get("sample") or Path(path).stem,
        instrument=keys.get("instrument") or DEFAULT_INSTRUMENT,
        source=os.path.basename(os.fspath(path)),
        quantity="hemispherical_reflectance",
        value=vals,
        sigma=sigs,
        unit="1",
        wavelength_nm=wls,
        theta_i_deg=theta_i,
    )
    meta = _meta(keys, _HEMI, ("sample", "instrument", "unit", "theta_i_deg"))
    meta.update(
        unit_in_file=keys["unit"],
        theta_i_deg=None if math.isnan(theta_i) else theta_i,
        dropped_points=dropped,
    )
    return finish(path, [frame], meta)


FORMATS = (
    Format(
        "labbrdf-specular-scan",
        "labbrdf specular-scan CSV v1 (BRDF or specular intensity vs angles)",
        (".csv",),
        _sniff_specular,
        read_specular_scan,
        ("brdf", "specular_intensity"),
        keywords=(b"# labbrdf ",),
    ),
    Format(
        "labbrdf-hemispherical-reflectance",
        "labbrdf hemispherical-reflectance CSV v1 (spectrum from a sphere)",
        (".csv",),
        _sniff_hemi,
        read_hemispherical,
        ("hemispherical_reflectance",),
        keywords=(b"# labbrdf ",),
    ),
)
