"""Film Sense FS-series multi-wavelength ellipsometer text exports (``.txt``).

Layout (docs/formats.md section 4, checked on ``Filmsense_staticTest.txt`` and
``Filmsense_kineticTest.txt``), TAB separated:

1. ``Film_Sense_Data`` (one measurement) or ``Film_Sense_Dyn_Data`` (a time series);
2. ``n_wavelengths n_datasets AOI ...``: 6 fields (static) or 4 (dynamic), enforced so that a
   lost field cannot shift the AOI; the AOI is written negative (``-70.012``); a static
   file adds align X, align Y and the average intensity, a dynamic one one more number;
3. ``n_wavelengths`` LED lines ``wavelength[nm] brightness ...`` (7 numbers);
4. static: ``n_wavelengths`` lines ``N C S P I``; dynamic: a name row ``Time UV_N UV_C UV_S
   UV_P UV_I Blue_N ... AlignX AlignY AveInt Temp TempSrc Fit_Diff Thick(nm).2`` and one row
   per time point;
5. static: a footer with the software's fit (``3``, then ``Fit_Diff 0.0046``,
   ``Thick(nm).1 1.5973``, ``Amb_n(633nm) 0.99793``) and ``Model: ..., Date: ..., Ver: ...``.

N, C, S are the normalised Stokes-like ellipsometric quantities (N^2 + C^2 + S^2 = 1 to the
5 digits printed), P the degree of polarisation, I the intensity.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from ..dataset import Measurement, wrap_delta
from ._base import AdapterError, Example, Format, decode, read_bytes, split_lines
from ._frame import build_frame, group_angles, measurement
from ._numblock import NUMBER
from ._truncation import check_joined, check_last_row

__all__ = ["FORMATS", "filmsense_psi_delta", "read_filmsense", "sniff_filmsense"]

_MAGIC = {"Film_Sense_Data": False, "Film_Sense_Dyn_Data": True}
_LED_COLUMNS = ["wavelength_nm", "brightness", "exp_l", "exp_r", "col5", "col6", "col7"]
#: fields of line 2, static and dynamic files (both real files; other counts are refused)
_COUNT_FIELDS = {False: 6, True: 4}


def sniff_filmsense(head: bytes) -> bool:
    """True when the file starts with ``Film_Sense_Data`` or ``Film_Sense_Dyn_Data``."""
    try:
        lines = head.removeprefix(b"\xef\xbb\xbf").splitlines()
        first = lines[0].strip() if lines else b""
        return first in (b"Film_Sense_Data", b"Film_Sense_Dyn_Data")
    except Exception:  # a sniffer never raises
        return False


def filmsense_psi_delta(
    n: ArrayLike, c: ArrayLike, s: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Psi and Delta from the normalised ellipsometric quantities N, C, S.

    Parameters
    ----------
    n, c, s : array_like
        N = cos 2psi, C = sin 2psi cos Delta, S = sin 2psi sin Delta [1].

    Returns
    -------
    psi : numpy.ndarray
        psi = arccos(N) / 2 [deg], in [0, 90].
    delta : numpy.ndarray
        Delta = arg((C + iS) / (1 + N)) = atan2(S, C) [deg] (1 + N > 0 is real), wrapped
        into [0, 360): the Nebraska convention (``docs/conventions.md``), see Notes.

    Notes
    -----
    The formula is the one docs/formats.md section 4 gives (refellips' reading of Film
    Sense files). Its sign was checked against physics on ``Filmsense_staticTest.txt`` (a Si
    wafer, the software's own fit is a 1.60 nm film): at 946.73 nm, where crystalline Si is
    nearly transparent (n = 3.58), N, C, S give psi = 8.35 deg and Delta = 176.36 deg, and a
    Fresnel calculation for 1.6 nm of SiO2 on Si at 70.012 deg gives Delta = 176.3 deg in
    the Nebraska convention (a thin transparent film below the Brewster angle lowers Delta
    from 180 deg), whereas the opposite sign would give 183.6 deg. All eight wavelengths
    give 0 < Delta < 180 deg, as a (nearly) bare absorbing substrate must. So no sign flip.
    """
    n_ = np.asarray(n, dtype=float)
    psi = np.degrees(0.5 * np.arccos(np.clip(n_, -1.0, 1.0)))
    delta = wrap_delta(
        np.degrees(np.arctan2(np.asarray(s, dtype=float), np.asarray(c, dtype=float)))
    )
    return psi, delta


def _numbers(
    path: str | os.PathLike[str],
    line: str,
    lineno: int,
    what: str,
    count: int | None = None,
    at_least: int | None = None,
) -> list[float]:
    fields = line.rstrip(" \t").split("\t")
    if count is not None and len(fields) != count:
        raise AdapterError(
            path,
            f"{what}: expected {count} TAB-separated numbers, found {len(fields)} field(s)",
            lineno,
        )
    if at_least is not None and len(fields) < at_least:
        raise AdapterError(
            path,
            f"{what}: expected at least {at_least} numbers, found {len(fields)} field(s)",
            lineno,
        )
    out = []
    for k, f in enumerate(fields):
        f = f.strip()
        if not NUMBER.fullmatch(f):
            raise AdapterError(path, f"{what}: field {k + 1} {f[:30]!r} is not a number", lineno)
        v = float(f)
        if not np.isfinite(v):
            raise AdapterError(
                path, f"{what}: field {k + 1} is {f!r}, expected a finite number", lineno
            )
        out.append(v)
    return out


def _is_numeric_row(line: str) -> bool:
    fields = [f.strip() for f in line.split("\t") if f.strip()]
    return len(fields) >= 2 and all(NUMBER.fullmatch(f) for f in fields)


def read_filmsense(path: str | os.PathLike[str]) -> Measurement:
    """Read a Film Sense static or dynamic export.

    Parameters
    ----------
    path : str or path-like
        The ``.txt`` export.

    Returns
    -------
    Measurement
        Per wavelength (and time point) ``psi`` and ``delta`` [deg] from N, C, S by
        :func:`filmsense_psi_delta`, and ``depolarization`` = 1 - P [fraction]; sigma NaN
        (the file has none); theta_i = |AOI| (theta_r = theta_i, phi_r = 180 deg); dynamic
        files add ``time_s``. The intensity I is not a schema quantity and is left out.

    Raises
    ------
    AdapterError
        Wrong magic line, a count in line 2 that the file does not match, a row with the
        wrong number of fields or a non-number (with its line), N outside [-1, 1].

    Notes
    -----
    The AOI is written negative by the instrument (``-70.012``); it is stored as its
    absolute value, and ``meta["aoi_in_file"]`` keeps the number as written. The row counts
    announced in line 2 are enforced, so a missing or extra line is an error, never a
    shifted table.
    """
    raw = read_bytes(path)
    text, encoding = decode(raw, path)
    lines = split_lines(text)
    check_joined(path, lines)
    p = Path(path)
    f, head, aoi_file = _count_line(path, lines)
    aoi = abs(aoi_file)
    meta: dict[str, Any] = {
        "source_file": p.name,
        "encoding": encoding,
        "variant": "dynamic" if f.dynamic else "static",
        "count_line": head,
        "aoi_in_file": aoi_file,
        "aoi_sign": "written negative by the instrument; stored as |AOI|"
        if aoi_file < 0
        else "as written",
    }
    if not f.dynamic and len(head) >= 6:
        meta["align_x"], meta["align_y"], meta["average_intensity"] = head[3:6]
    wl = _led_table(f, meta)
    k0 = 2 + f.nwl
    if not f.dynamic:
        rows = _static_rows(f, k0, wl)
    else:
        rows = _dynamic_rows(f, k0, wl, meta)
    doubt = check_last_row(path, text, lines, sorted(set(rows.lineno.tolist())), "\t")
    if doubt:
        meta["warnings"] = [doubt]
    bad = ~((rows.nn >= -1) & (rows.nn <= 1))
    if bad.any():
        raise AdapterError(
            path,
            "N must be within [-1, 1] (N = cos 2 psi)",
            int(rows.lineno[np.flatnonzero(bad)[0]]),
        )
    _footer(f, rows.footer_start, meta)
    frame = _frame(path, rows, aoi)
    meta["delta_convention"] = (
        "Nebraska: Delta = atan2(S, C), sign checked against a Fresnel "
        "calculation (see filmsense_psi_delta)"
    )
    meta["delta_range"] = "[0, 360)"
    meta["depolarization"] = "1 - P (P: degree of polarisation as written)"
    meta["angles_deg"] = group_angles([aoi])
    meta["wavelength_nm"] = [float(wl.min()), float(wl.max())]
    meta["sigma"] = "none in the file (NaN)"
    return measurement(path, frame, meta)


def _frame(path: str | os.PathLike[str], rows: _Rows, aoi: float) -> pd.DataFrame:
    """The tidy frame: psi and delta from N, C, S and depolarization 1 - P for each row."""
    psi, delta = filmsense_psi_delta(rows.nn, rows.cc, rows.ss)
    m = psi.size
    quantity = np.tile(np.array(["psi", "delta", "depolarization"], dtype=object), m)
    values = np.column_stack([psi, delta, 1.0 - rows.pp]).ravel()
    units = np.tile(np.array(["deg", "deg", "1"], dtype=object), m)
    optional: dict[str, Any] = {}
    if rows.times is not None:
        optional["time_s"] = np.repeat(rows.times, 3)
    return build_frame(
        sample=Path(path).stem,
        instrument="filmsense",
        source=Path(path).name,
        quantity=quantity,
        value=values,
        unit=units,
        wavelength_nm=np.repeat(rows.wl_rows, 3),
        theta_i_deg=aoi,
        theta_r_deg=aoi,
        phi_r_deg=180.0,
        **optional,
    )


@dataclass
class _Lines:
    """The lines of an export with the counts its line 2 announces."""

    path: str | os.PathLike[str]
    lines: list[str]
    dynamic: bool
    nwl: int
    nsets: int

    def need(self, k: int, what: str) -> str:
        """Line ``k`` (0-based), or an error saying the file ends early."""
        if k >= len(self.lines):
            raise AdapterError(
                self.path,
                f"file ends early: expected {what} on line {k + 1} "
                f"(line 2 announces {self.nwl} wavelengths"
                + (f" and {self.nsets} time points)" if self.dynamic else ")"),
                k + 1,
            )
        return self.lines[k]


@dataclass
class _Rows:
    """The N, C, S, P values of every (time point and) wavelength, with their lines."""

    nn: np.ndarray
    cc: np.ndarray
    ss: np.ndarray
    pp: np.ndarray
    lineno: np.ndarray
    times: np.ndarray | None
    wl_rows: np.ndarray
    footer_start: int


def _count_line(
    path: str | os.PathLike[str], lines: list[str]
) -> tuple[_Lines, list[float], float]:
    """Check the magic line 1 and read the count line 2: the lines, line 2 and the AOI."""
    magic = lines[0].strip() if lines else ""
    if magic not in _MAGIC:
        raise AdapterError(
            path,
            f"expected 'Film_Sense_Data' or 'Film_Sense_Dyn_Data' on line 1, found {magic[:40]!r}",
            1,
        )
    dynamic = _MAGIC[magic]
    if len(lines) < 2:
        raise AdapterError(path, "file ends after line 1; expected the count line", 2)
    # line 2 has a fixed number of fields (static: n_wl n_sets AOI align_x align_y
    # intensity; dynamic: n_wl n_sets AOI and one more): a lost field would shift the AOI
    head = _numbers(
        path,
        lines[1],
        2,
        "count line (n_wavelengths n_datasets AOI "
        + ("x)" if dynamic else "align_x align_y intensity)"),
        count=_COUNT_FIELDS[dynamic],
    )
    nwl, nsets, aoi_file = head[0], head[1], head[2]
    if nwl != int(nwl) or nwl < 1 or nsets != int(nsets) or nsets < 1:
        raise AdapterError(
            path, f"line 2: expected positive integer counts, found {nwl:g} and {nsets:g}", 2
        )
    if abs(aoi_file) > 90:
        raise AdapterError(path, f"line 2: AOI {aoi_file:g} deg is outside [-90, 90]", 2)
    return _Lines(path, lines, dynamic, int(nwl), int(nsets)), head, aoi_file


def _led_table(f: _Lines, meta: dict[str, Any]) -> np.ndarray:
    """Read the LED lines into ``meta["led_table"]``; return the wavelengths [nm]."""
    path = f.path
    led = []
    width = None
    for k in range(2, 2 + f.nwl):
        row = _numbers(path, f.need(k, "an LED line"), k + 1, "LED line", at_least=2)
        if width is None:
            width = len(row)
            if width != len(_LED_COLUMNS):
                raise AdapterError(
                    path,
                    f"LED line: expected {len(_LED_COLUMNS)} numbers (wavelength, brightness, "
                    f"...), found {width}",
                    k + 1,
                )
        elif len(row) != width:
            raise AdapterError(
                path,
                f"LED line: expected {width} numbers like the first LED line, found {len(row)}",
                k + 1,
            )
        led.append(row)
    wl = np.array([r[0] for r in led])
    if not (wl > 0).all():
        k = int(np.flatnonzero(~(wl > 0))[0])
        raise AdapterError(path, "LED wavelength must be > 0 [nm]", k + 3)
    meta["led_table"] = {
        "columns": _LED_COLUMNS[: width or 0]
        + [f"col{j + 1}" for j in range(len(_LED_COLUMNS), width or 0)],
        "rows": led,
    }
    return wl


def _static_rows(f: _Lines, k0: int, wl: np.ndarray) -> _Rows:
    """The static variant: one ``N C S P I`` line per wavelength from line ``k0``."""
    nwl = f.nwl
    rows = [
        _numbers(f.path, f.need(k, "an N C S P I line"), k + 1, "N C S P I line", count=5)
        for k in range(k0, k0 + nwl)
    ]
    a = np.array(rows)
    lineno = np.arange(k0, k0 + nwl) + 1
    return _Rows(a[:, 0], a[:, 1], a[:, 2], a[:, 3], lineno, None, wl, k0 + nwl)


def _dynamic_rows(f: _Lines, k0: int, wl: np.ndarray, meta: dict[str, Any]) -> _Rows:
    """The dynamic variant: a column-name row, then one row per time point."""
    path, nwl, nsets = f.path, f.nwl, f.nsets
    names = [s.strip() for s in f.need(k0, "the column-name row").rstrip(" \t").split("\t")]
    if names[0] != "Time":
        raise AdapterError(
            path,
            f"expected the column-name row starting with 'Time', found {names[0][:30]!r}",
            k0 + 1,
        )
    leds = [nm[:-2] for nm in names if nm.endswith("_N")]
    if len(leds) != nwl:
        raise AdapterError(
            path,
            f"the name row has {len(leds)} LED groups (*_N), line 2 announces {nwl} wavelengths",
            k0 + 1,
        )
    idx = {}
    for q in ("N", "C", "S", "P"):
        for led_name in leds:
            key = f"{led_name}_{q}"
            if key not in names:
                raise AdapterError(path, f"column {key!r} missing from the name row", k0 + 1)
            idx[key] = names.index(key)
    rows = [
        _numbers(path, f.need(k, "a time-point row"), k + 1, "time-point row", count=len(names))
        for k in range(k0 + 1, k0 + 1 + nsets)
    ]
    a = np.array(rows)
    t = a[:, 0]

    def grid(q: str) -> np.ndarray:  # (time, led) -> flat, time-major
        return np.column_stack([a[:, idx[f"{ln}_{q}"]] for ln in leds]).ravel()

    meta["led_names"] = leds
    extra = [c for c in names if c != "Time" and not re.fullmatch(r".+_[NCSPI]", c)]
    meta["per_time_point"] = {c: a[:, names.index(c)].tolist() for c in extra}
    return _Rows(
        grid("N"),
        grid("C"),
        grid("S"),
        grid("P"),
        np.repeat(np.arange(k0 + 1, k0 + 1 + nsets) + 1, nwl),
        np.repeat(t, nwl),
        np.tile(wl, nsets),
        k0 + 1 + nsets,
    )


def _footer(f: _Lines, footer_start: int, meta: dict[str, Any]) -> None:
    """Refuse a data row after the announced ones; keep the footer and its fit results."""
    lines = f.lines
    footer = [ln for ln in lines[footer_start:] if ln.strip()]
    for j, ln in enumerate(lines[footer_start:]):
        if _is_numeric_row(ln):
            raise AdapterError(
                f.path,
                "unexpected data row after the rows line 2 announces "
                f"({f.nwl} wavelengths" + (f", {f.nsets} time points)" if f.dynamic else ")"),
                footer_start + j + 1,
            )
    if footer:
        meta["footer"] = footer
        fit = {}
        for ln in footer:
            parts = ln.split("\t")
            if len(parts) == 2 and NUMBER.fullmatch(parts[1].strip()):
                fit[parts[0].strip()] = float(parts[1])
            for mt in re.finditer(r"(Model|Date|Ver|Temp):\s*([^,]*)", ln):
                meta[mt.group(1).lower()] = mt.group(2).strip()
        if fit:
            meta["software_fit"] = fit


FORMATS: tuple[Format, ...] = (
    Format(
        name="filmsense",
        description="Film Sense FS-series ellipsometer text export (static and dynamic)",
        extensions=(".txt",),
        sniff=sniff_filmsense,
        read=read_filmsense,
        quantities=("psi", "delta", "depolarization"),
        keywords=(b"Film_Sense",),
        examples=(
            Example(
                "filmsense-txt/Filmsense_staticTest.txt", number=("14.32", 3), rows_per_line=3
            ),
            Example("filmsense-txt/Filmsense_kineticTest.txt", rows_per_line=24),
        ),
    ),
)
