"""SENTECH SpectraRay ASCII exports (``.txt``): Psi/Delta at several angles, or a Mueller matrix.

Layout (docs/formats.md section 5, checked on ``Si_SiO2_theta_50_60_70.txt`` and
``Wafer_MM_70.txt``): one header line ``; WAVELENGTH a1 a2 ...`` giving the angle of
incidence of every data column, then rows ``wavelength[nm] v1 v2 ...`` separated by spaces,
each with a trailing space. The header does not say what the columns hold:

* Psi/Delta: 2 * nAOI columns, Psi then Delta for each AOI, so the angles come in equal
  pairs (``50.2 50.2 60.2 60.2 70.2 70.2``);
* Mueller matrix: 16 columns, all at one AOI, row-major M11..M44 normalised by M11 (the
  M11 column is 1).

16 columns at one angle fit both readings (eight Psi/Delta pairs at the same angle would be
a strange but legal export), so they are read as a Mueller matrix only when the first column
is 1 in every row; otherwise the reader refuses to guess and asks for ``kind=``.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement, wrap_delta
from ._base import AdapterError, Example, Format, decode, read_bytes
from ._frame import (
    MUELLER_S1_FLIP,
    build_frame,
    check_rows,
    delta_range,
    group_angles,
    measurement,
    mueller_convention,
)
from ._numblock import NUMBER, Block, parse_block, split_head

__all__ = ["FORMATS", "read_sentech", "sniff_sentech"]

_HEADER = re.compile(r"^\s*;\s*WAVELENGTH\b(.*)$", re.IGNORECASE)
_KINDS = ("psi_delta", "mueller")
_MM = np.array([f"mueller_{i}{j}" for i in range(1, 5) for j in range(1, 5)], dtype=object)


def sniff_sentech(head: bytes) -> bool:
    """True when the first line is ``; WAVELENGTH <angles>``."""
    try:
        lines = head.removeprefix(b"\xef\xbb\xbf").splitlines()
        first = lines[0].decode("latin-1") if lines else ""
        return bool(_HEADER.match(first))
    except Exception:  # a sniffer never raises
        return False


def _kind(path: str | os.PathLike[str], angles: np.ndarray, first_col: np.ndarray) -> str:
    n = angles.size
    same = bool(np.all(angles == angles[0]))
    pairs = n % 2 == 0 and bool(np.all(angles[0::2] == angles[1::2]))
    if n == 16 and same:
        if np.all(first_col == 1.0):
            return "mueller"
        raise AdapterError(
            path,
            "ambiguous: 16 columns at one angle but the first column is not M11 = 1 in every "
            "row; pass kind='psi_delta' or kind='mueller'",
            1,
        )
    if pairs:
        return "psi_delta"
    raise AdapterError(
        path,
        f"cannot tell what the {n} columns hold: expected Psi/Delta pairs (2 x nAOI columns "
        "with equal angles in pairs) or a 16-column Mueller matrix at one angle; the header "
        f"angles are {angles.tolist()}",
        1,
    )


def read_sentech(path: str | os.PathLike[str], kind: str | None = None) -> Measurement:
    """Read a SpectraRay ASCII export.

    Parameters
    ----------
    path : str or path-like
        The ``.txt`` export.
    kind : {None, "psi_delta", "mueller"}
        What the columns hold; by default decided from the header angles (see the module
        docstring) and refused when ambiguous.

    Returns
    -------
    Measurement
        ``psi`` and ``delta`` [deg] per AOI (Delta wrapped into [0, 360)), or the 16
        ``mueller_ij`` [1] (as written, normalised, M11 included); sigma NaN (none in the
        file); theta_i from the header (theta_r = theta_i, phi_r = 180 deg).

    Raises
    ------
    AdapterError
        No ``; WAVELENGTH`` header, header angles that are not numbers or not in [0, 90],
        a column count that fits neither kind or both, a row whose field count differs from
        the header, a non-number (comma decimals included) with its line, psi out of range.

    Notes
    -----
    Delta is taken as SpectraRay writes it (0..360) and only wrapped. The Nebraska reading
    is consistent with the data: at 3484 nm, where Si is transparent, the thin-oxide-on-Si
    file has Delta = 170.6, 160.1 and 125.0 deg at 50.2, 60.2 and 70.2 deg (all below the
    Brewster angle of Si, 73.7 deg), i.e. a thin film lowers Delta from 180 deg, as in the
    Film Sense check; and the Mueller file at 3484 nm has M12 = -cos 2psi = -0.938, M33 =
    sin 2psi cos Delta = -0.201 and M34 = +sin 2psi sin Delta = +0.282 with psi near 10.1
    and Delta near 125 deg, the values of the Psi/Delta file at 70.2 deg. That sign pattern
    (M12 = -cos 2psi, M34 = +sin 2psi sin Delta) is the vendor's; the values are converted
    to :mod:`labbrdf.optics` (M12 = +cos 2psi) and ``meta["mueller_convention"]`` says so.
    """
    if kind is not None and kind not in _KINDS:
        raise AdapterError(path, f"kind must be one of {_KINDS} or None, got {kind!r}")
    raw = read_bytes(path)
    text, encoding = decode(raw, path)
    head, body = split_head(text, 1)
    angles = _header_angles(path, head)
    n = angles.size
    block = parse_block(path, body, 2, n + 1, sep=None)
    if len(block.lines) == 0:
        raise AdapterError(path, "no data rows after the header")
    v = block.values
    check_rows(
        path,
        block,
        np.isnan(v).any(axis=1),
        f"expected {n + 1} numbers (wavelength and one value per header angle)",
    )
    wl = v[:, 0]
    check_rows(path, block, ~(np.isfinite(wl) & (wl > 0)), "wavelength must be > 0 [nm]")
    check_rows(path, block, ~np.isfinite(v[:, 1:]).all(axis=1), "values must be finite")
    if kind is None:
        kind = _kind(path, angles, v[:, 1])
    elif kind == "mueller" and n != 16:
        raise AdapterError(path, f"kind='mueller' needs 16 columns, the header has {n}", 1)
    elif kind == "psi_delta" and (n % 2 or not np.all(angles[0::2] == angles[1::2])):
        raise AdapterError(path, "kind='psi_delta' needs the header angles in equal pairs", 1)
    p = Path(path)
    meta: dict[str, Any] = {
        "source_file": p.name,
        "encoding": encoding,
        "header_angles_deg": angles.tolist(),
        "kind": kind,
        "data_lines": len(wl),
        "blank_lines_skipped": block.blank_lines,
        "wavelength_nm": [float(wl.min()), float(wl.max())],
        "sigma": "none in the file (NaN)",
    }
    if kind == "psi_delta":
        values, quantity, theta, wl_rows = _psi_delta_rows(path, block, angles, meta)
    else:
        values, quantity, theta, wl_rows = _mueller_rows(v, angles, meta)
    frame = build_frame(
        sample=p.stem,
        instrument="sentech-spectraray",
        source=p.name,
        quantity=quantity,
        value=values,
        unit="deg" if kind == "psi_delta" else "1",
        wavelength_nm=wl_rows,
        theta_i_deg=theta,
        theta_r_deg=theta,
        phi_r_deg=180.0,
    )
    return measurement(path, frame, meta)


def _header_angles(path: str | os.PathLike[str], head: list[str]) -> np.ndarray:
    """The angles [deg] of the header line ``; WAVELENGTH <angle> <angle> ...``."""
    m = _HEADER.match(head[0]) if head else None
    if m is None:
        raise AdapterError(
            path,
            "expected the header '; WAVELENGTH <angle> <angle> ...' on "
            "line 1 (SENTECH SpectraRay ASCII export)",
            1,
        )
    tokens = m.group(1).split()
    bad = [t for t in tokens if not NUMBER.fullmatch(t)]
    if bad or not tokens:
        raise AdapterError(path, f"header angles must be numbers, found {bad[:3] or 'none'}", 1)
    angles = np.array([float(t) for t in tokens])
    if not np.all(np.isfinite(angles) & (angles >= 0) & (angles <= 90)):
        raise AdapterError(path, "header angles must be within [0, 90] deg", 1)
    return angles


def _psi_delta_rows(
    path: str | os.PathLike[str], block: Block, angles: np.ndarray, meta: dict[str, Any]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Psi/Delta columns in pairs, one pair per AOI: values, quantities, theta_i, wavelengths."""
    v = block.values
    wl = v[:, 0]
    rows = len(wl)
    nao = angles.size // 2
    psi = v[:, 1::2]
    delta = v[:, 2::2]
    badpsi = np.asarray(((psi < 0) | (psi > 90)).any(axis=1))
    check_rows(path, block, badpsi, "psi must be within [0, 90] deg")
    aoi = angles[0::2]
    # row-major: for each line, for each AOI: psi, delta
    values = np.stack([psi, wrap_delta(delta)], axis=2).ravel()
    quantity = np.tile(np.array(["psi", "delta"], dtype=object), rows * nao)
    theta = np.tile(np.repeat(aoi, 2), rows)
    wl_rows = np.repeat(wl, 2 * nao)
    meta["delta_convention"] = "Nebraska, as written by SpectraRay (0..360 deg)"
    meta["delta_range_in_file"] = delta_range(delta)
    meta["delta_range"] = "[0, 360)"
    meta["angles_deg"] = group_angles(aoi)
    return values, quantity, theta, wl_rows


def _mueller_rows(
    v: np.ndarray, angles: np.ndarray, meta: dict[str, Any]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The 16 Mueller columns at one AOI: values, quantities, theta_i, wavelengths."""
    wl = v[:, 0]
    # to the labbrdf.optics convention: SpectraRay writes M12 = -cos 2psi
    flip = np.array([-1.0 if q in MUELLER_S1_FLIP else 1.0 for q in _MM])
    values = (v[:, 1:] * flip).ravel()
    quantity = np.tile(_MM, len(wl))
    theta = np.full(values.size, angles[0])
    wl_rows = np.repeat(wl, 16)
    meta["mueller"] = "row-major M11..M44, normalised by M11"
    meta["mueller_convention"] = mueller_convention("SENTECH SpectraRay")
    meta["angles_deg"] = group_angles(angles[:1])
    return values, quantity, theta, wl_rows


FORMATS: tuple[Format, ...] = (
    Format(
        name="sentech-spectraray",
        description="SENTECH SpectraRay ASCII export: psi/Delta at several angles or a "
        "normalised Mueller matrix",
        extensions=(".txt",),
        sniff=sniff_sentech,
        read=read_sentech,
        quantities=("psi", "delta", *(str(q) for q in _MM)),
        keywords=(b"; WAVELENGTH", b"SpectraRay"),
        examples=(
            Example(
                "sentech-spectraray-ascii/Si_SiO2_theta_50_60_70.txt",
                number=("47.53618", 3),
                rows_per_line=6,
            ),
            Example("sentech-spectraray-ascii/Wafer_MM_70.txt", rows_per_line=16),
        ),
    ),
)
