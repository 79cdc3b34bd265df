"""ASTM E1392-style BRDF tables (``.astm``; format ``astm-brdf``): one point per row.

Layout (as the ``.astm`` files of measured BRDFs are read by libbsdf's ASTM reader): header
lines ``KEYWORD value`` (``NAME``, ``NUM_POINTS n``, ...) ending with the ``VARS`` line, the
comma-separated column names; then one comma-separated row per point::

    NAME "white paint"
    NUM_POINTS 3
    VARS theta_i,phi_i,theta_s,phi_s,450nm,550nm,650nm
    0.5236,0,0.5236,3.1416,0.30,0.31,0.33
    ...

The first four columns are the incident and scattered directions in radians (theta from the
normal, phi in one frame for both); the others are BRDF [sr-1] per channel: a wavelength
(``550nm``: a spectral, e.g. in-plane spectral, table), ``X``/``Y``/``Z``, or one unnamed
value (photometric: 555 nm written as a label, ``meta["wavelength_stated"]`` False).
``R``/``G``/``B`` columns (a renderer's colours, no wavelength) are refused by name.

The dataset's ``phi_r_deg`` is ``phi_s - phi_i`` (source at 0, specular at 180). Angles
above 2 pi (a table written in degrees) are refused rather than read as radians.
``NUM_POINTS``, when given, must equal the number of rows.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import Measurement
from ._base import AdapterError, Format, decode, read_bytes, split_lines
from ._frame import build_frame
from ._truncation import check_last_row

__all__ = ["FORMATS", "read_astm_brdf"]

INSTRUMENT = "astm-brdf"
DEFAULT_WAVELENGTH_NM = 555.0
ANGLES = ("theta_i", "phi_i", "theta_s", "phi_s")
_WAVELENGTH = re.compile(r"([0-9]+(?:\.[0-9]*)?)\s*nm", re.IGNORECASE)
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_SNIFF = re.compile(rb"^VARS\s+theta_i\s*,\s*phi_i\s*,\s*theta_s\s*,\s*phi_s\s*,", re.M)
_TWO_PI = 2.0 * np.pi + 1e-6


def _header(path: str | os.PathLike[str], lines: list[str]) -> tuple[dict[str, Any], int]:
    """The header keywords (name -> (value, line)) up to ``VARS``; the next line's index."""
    head: dict[str, Any] = {}
    for i, raw in enumerate(lines):
        s = raw.strip()
        if not s:
            continue
        key, _, value = s.partition(" ")
        head.setdefault(key.upper(), (value.strip(), i + 1))
        if key.upper() == "VARS":
            return head, i + 1
    raise AdapterError(path, "missing the 'VARS theta_i,phi_i,theta_s,phi_s,...' line")


def _channels(path: str | os.PathLike[str], text: str, ln: int) -> tuple[list[str], list[float]]:
    """Channel labels and wavelengths [nm] (NaN: none stated) of the value columns."""
    names = [n.strip() for n in text.split(",")]
    if [n.lower() for n in names[:4]] != list(ANGLES) or len(names) < 5:
        raise AdapterError(
            path, f"VARS: expected {','.join(ANGLES)} and at least one value column", ln
        )
    vals = names[4:]
    if [v.upper() for v in vals] == ["R", "G", "B"]:
        raise AdapterError(
            path,
            "VARS: R,G,B columns are a renderer's colours, with no wavelength: not read",
            ln,
        )
    if [v.upper() for v in vals] == ["X", "Y", "Z"]:
        return ["X", "Y", "Z"], [np.nan] * 3
    if len(vals) == 1 and not _WAVELENGTH.fullmatch(vals[0]):
        return [""], [np.nan]
    wls = []
    for v in vals:
        m = _WAVELENGTH.fullmatch(v)
        if m is None or float(m.group(1)) <= 0:
            raise AdapterError(
                path, f"VARS: value column {v!r}: expected a wavelength such as '550nm'", ln
            )
        wls.append(float(m.group(1)))
    return [""] * len(wls), wls


def _rows(
    path: str | os.PathLike[str], lines: list[str], first: int, ncol: int
) -> tuple[np.ndarray, list[int]]:
    rows = [(i + 1, s.strip()) for i, s in enumerate(lines[first:], first) if s.strip()]
    if not rows:
        raise AdapterError(path, "no data rows after VARS")
    nums = [n for n, _ in rows]
    out = np.empty((len(rows), ncol))
    for k, (n, s) in enumerate(rows):
        cells = s.split(",")
        if len(cells) != ncol:
            raise AdapterError(
                path, f"expected {ncol} comma-separated values, found {len(cells)}", n
            )
        for j, c in enumerate(cells):
            if not _NUMBER.fullmatch(c.strip()):
                raise AdapterError(path, f"column {j + 1}: expected a number, found {c!r}", n)
        out[k] = [float(c) for c in cells]
    if not np.isfinite(out).all():
        k = int(np.flatnonzero(~np.isfinite(out).all(axis=1))[0])
        raise AdapterError(path, "a value overflows a float", nums[k])
    return out, nums


def read_astm_brdf(path: str | os.PathLike[str]) -> Measurement:
    """Read an ASTM E1392-style BRDF table (``VARS theta_i,phi_i,theta_s,phi_s,...``).

    Returns
    -------
    Measurement
        Quantity ``brdf`` [sr-1], one row per point and value column: ``wavelength_nm``
        from the column name (``550nm``), else 555 nm as a label; ``channel`` X/Y/Z for
        tristimulus columns; angles in degrees, ``phi_r_deg`` = phi_s - phi_i.

    Raises
    ------
    AdapterError
        No ``VARS`` line or the wrong first columns, R/G/B columns, a row with the wrong
        number of values or a non-number (its line named), an angle out of range (above
        2 pi: degrees where radians are expected), a scattered direction below the
        horizon, or ``NUM_POINTS`` different from the rows found.
    """
    raw = read_bytes(path)
    text, _ = decode(raw, path)
    lines = split_lines(text)
    head, first = _header(path, lines)
    vars_text, vln = head["VARS"]
    labels, wls = _channels(path, vars_text, vln)
    data, nums = _rows(path, lines, first, 4 + len(labels))
    check_last_row(path, text, lines, nums, ",")
    _check_count(path, head, len(nums))
    ang = data[:, :4]
    bad = np.flatnonzero((np.abs(ang) > _TWO_PI).any(axis=1))
    if bad.size:
        raise AdapterError(
            path,
            "an angle above 2 pi: expected radians (is the table in degrees?)",
            nums[int(bad[0])],
        )
    ti, pi_, ts, ps = np.degrees(ang).T
    wrong = np.flatnonzero((ti < 0) | (ti >= 90) | (ts < 0) | (ts > 90))
    if wrong.size:
        raise AdapterError(
            path,
            "expected theta_i in [0, 90) and theta_s in [0, 90] deg (reflection)",
            nums[int(wrong[0])],
        )
    frame = _frame(path, data[:, 4:], labels, wls, ti, ts, np.mod(ps - pi_, 360.0))
    meta = {
        "format": INSTRUMENT,
        "header": {k: v for k, (v, _) in head.items()},
        "wavelength_stated": bool(np.isfinite(wls).all()),
    }
    try:
        return Measurement(frame, meta)
    except ValueError as exc:
        raise AdapterError(path, f"invalid data: {exc}") from None


def _check_count(path: str | os.PathLike[str], head: dict[str, Any], n: int) -> None:
    if "NUM_POINTS" not in head:
        return
    text, ln = head["NUM_POINTS"]
    if not text.isdigit() or int(text) != n:
        raise AdapterError(path, f"NUM_POINTS {text!r}: the file has {n} data rows", ln)


def _frame(
    path: str | os.PathLike[str],
    values: np.ndarray,
    labels: list[str],
    wls: list[float],
    ti: np.ndarray,
    ts: np.ndarray,
    phi_r: np.ndarray,
) -> pd.DataFrame:
    n, nch = values.shape
    wl = np.where(np.isfinite(wls), wls, DEFAULT_WAVELENGTH_NM)
    optional: dict[str, Any] = {}
    if labels == ["X", "Y", "Z"]:
        codes = np.tile(np.arange(3, dtype=np.int8), n)
        optional["channel"] = pd.Categorical.from_codes(codes, categories=["X", "Y", "Z"])
    return build_frame(
        sample=Path(path).stem,
        instrument=INSTRUMENT,
        source=os.path.basename(os.fspath(path)),
        quantity="brdf",
        value=values.reshape(-1),
        unit="sr-1",
        wavelength_nm=np.tile(wl, n),
        theta_i_deg=np.repeat(ti, nch),
        theta_r_deg=np.repeat(ts, nch),
        phi_r_deg=np.repeat(phi_r, nch),
        **optional,
    )


def _sniff(head: bytes) -> bool:
    try:
        return _SNIFF.search(head) is not None
    except Exception:  # pragma: no cover - a sniffer never raises
        return False


FORMATS = (
    Format(
        "astm-brdf",
        "ASTM E1392-style BRDF table (VARS theta_i,phi_i,theta_s,phi_s,...; radians, "
        "spectral or XYZ columns)",
        (".astm",),
        _sniff,
        read_astm_brdf,
        ("brdf",),
        keywords=(b"VARS",),
        states_count=False,
    ),
)
