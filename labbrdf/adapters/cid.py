"""CID Bio-Science SpectraVue (CI-710s leaf spectrometer) ``Measurements.csv`` exports.

Layout (row-oriented: one measurement per line)
    line 1: ``Date,Mode,IntegrationTime(ms),Smoothing,ScansToAverage,Tag,Version,
    CalibrationID,Coordinates,Wavelengths(nm),`` then the detector's wavelengths [nm]
    (2048 of them), and a trailing comma; every further line: the nine metadata fields, an
    empty field under ``Wavelengths(nm)``, one value per wavelength and a trailing comma.
    Dates are US month/day (``3/8/2022 3:02:47 PM``).

Quantity (by ``Mode``)
    ``Reflectance`` and ``Abs Reflectance``: reflectance; ``Transmittance`` and
    ``Abs Transmittance``: transmittance. ``Absorbance`` rows are refused: the file does
    not say whether they are decadic absorbance or absorptance (1 - R - T), and either
    reading could be wrong.

Unit
    The file states no unit. The values are percent when the median over the
    instrument's usable range, 380-1000 nm, exceeds 1 (more than half of a reflectance or
    transmittance spectrum above 1 cannot be a fraction); otherwise percent and fraction
    cannot be told apart, and the file is refused unless the unit is declared by forcing
    ``cid-spectravue-percent`` or ``cid-spectravue-fraction`` (``--format`` on the command
    line, ``format=`` in Python). ``meta["unit_from"]`` says how the unit was decided.
    Every point is kept, including those outside the usable range (noisy, often 0 or far
    above 100 %).

The sample of a row is its ``Tag``, else the file name and the row's date.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import AdapterError, Example, Format, check_count, decode, read_bytes, split_lines
from ._spectro import PERCENT, finish, number, spectrum_frame

__all__ = ["FORMATS", "read_spectravue"]

INSTRUMENT = "cid-spectravue"

_FIELDS = (
    "Date",
    "Mode",
    "IntegrationTime(ms)",
    "Smoothing",
    "ScansToAverage",
    "Tag",
    "Version",
    "CalibrationID",
    "Coordinates",
    "Wavelengths(nm)",
)
_MAGIC = ",".join(_FIELDS[:3]).encode()
_MODES = {
    "reflectance": "reflectance",
    "abs reflectance": "reflectance",
    "transmittance": "transmittance",
    "abs transmittance": "transmittance",
}
#: the CI-710s usable range [nm] (outside it the values are noise)
USABLE_NM = (380.0, 1000.0)


def _sniff(head: bytes) -> bool:
    h = head[3:] if head.startswith(b"\xef\xbb\xbf") else head
    return h.startswith(_MAGIC) and b"Wavelengths(nm)" in h


def read_spectravue(path: str | os.PathLike[str], unit: str | None = None) -> Measurement:
    """Read a SpectraVue ``Measurements.csv`` export.

    Parameters
    ----------
    path : str or path-like
        The export.
    unit : {None, "percent", "fraction"}
        The unit of the values; None decides from the values (see the module notes) and
        refuses the file where they do not tell.

    Returns
    -------
    Measurement
        One reflectance or transmittance spectrum per line against wavelength [nm]
        (theta_i NaN); ``meta["rows"]`` holds each line's metadata.

    Raises
    ------
    AdapterError
        A wrong header, an Absorbance or unknown mode, a line whose field count differs
        from the header's, a value that is not a number, or a unit that cannot be told;
        with the line.
    """
    raw = read_bytes(path)
    text, encoding = decode(raw, path, ("utf-8", "cp1252"))
    lines = split_lines(text)
    wl = _wavelengths(path, lines[0])
    rows = []
    seen: dict[str, int] = {}
    for n in range(1, len(lines)):
        if not lines[n].strip():
            continue
        if lines[n] in seen:
            raise AdapterError(
                path, f"the same measurement as line {seen[lines[n]]} (a duplicated line)", n + 1
            )
        seen[lines[n]] = n + 1
        rows.append(_row(path, lines[n], n + 1, wl.size))
    if not rows:
        raise AdapterError(path, "no measurement lines after the header", 1)
    scale, unit_from = _unit(path, wl, rows, unit)
    frames = []
    for r in rows:
        frame, _ = spectrum_frame(
            path=path,
            sample=r["Tag"] or f"{Path(path).stem} {r['Date']}",
            instrument=INSTRUMENT,
            quantity=r["quantity"],
            scale=scale,
            x_nm=wl,
            y=r["values"],
        )
        frames.append(frame)
    meta: dict[str, Any] = {
        "format": INSTRUMENT,
        "encoding": encoding,
        "rows": [{k: v for k, v in r.items() if k != "values"} for r in rows],
        "percent": scale == PERCENT,
        "unit_from": unit_from,
        "usable_range_nm": list(USABLE_NM),
        "dropped_points": 0,
    }
    return finish(path, frames, meta)


def _wavelengths(path: str | os.PathLike[str], line: str) -> np.ndarray:
    fields = line.split(",")
    if tuple(f.strip() for f in fields[: len(_FIELDS)]) != _FIELDS:
        raise AdapterError(path, f"expected the header {','.join(_FIELDS)},<wavelengths>", 1)
    values = fields[len(_FIELDS) :]
    if values and not values[-1].strip():
        values = values[:-1]  # the trailing comma
    check_count(path, "wavelengths", len(values), line=1)
    wl = np.array([number(v, path, 1, "wavelength") for v in values])
    if wl.size < 2 or not (np.diff(wl) > 0).all() or wl[0] <= 0:
        raise AdapterError(path, "the wavelengths must be > 0 and strictly increasing", 1)
    return wl


def _row(path: str | os.PathLike[str], line: str, n: int, count: int) -> dict[str, Any]:
    fields = next(csv.reader([line]))
    meta = fields[: len(_FIELDS)]
    values = fields[len(_FIELDS) :]
    if values and not values[-1].strip():
        values = values[:-1]
    if len(meta) != len(_FIELDS) or len(values) != count:
        raise AdapterError(
            path,
            f"expected {len(_FIELDS)} metadata fields and {count} values (as the header), "
            f"found {len(fields)} fields",
            n,
        )
    mode = meta[1].strip()
    quantity = _MODES.get(mode.lower())
    if quantity is None:
        why = (
            "the file does not say whether it is decadic absorbance or absorptance (1 - R - T)"
            if mode.lower() == "absorbance"
            else "not a SpectraVue mode labbrdf knows"
        )
        raise AdapterError(
            path,
            f"Mode {mode!r}: {why}; labbrdf reads the Reflectance and Transmittance modes",
            n,
        )
    row: dict[str, Any] = {
        k: v.strip()[:200] for k, v in zip(_FIELDS[:-1], meta[:-1], strict=True)
    }
    row["quantity"] = quantity
    row["values"] = np.array([number(v, path, n, "value") for v in values])
    return row


def _unit(
    path: str | os.PathLike[str], wl: np.ndarray, rows: list[dict[str, Any]], unit: str | None
) -> tuple[float, str]:
    if unit is not None:
        return (PERCENT if unit == "percent" else 1.0), f"declared ({unit})"
    usable = (wl >= USABLE_NM[0]) & (wl <= USABLE_NM[1])
    values = np.concatenate([r["values"][usable] for r in rows])
    median = float(np.median(values)) if values.size else float("nan")
    if median > 1.0:
        return PERCENT, f"values (median {median:.3g} over {USABLE_NM[0]:g}-{USABLE_NM[1]:g} nm)"
    raise AdapterError(
        path,
        f"the file states no unit and its values (median {median:.3g} over "
        f"{USABLE_NM[0]:g}-{USABLE_NM[1]:g} nm) could be percent or fractions: declare the "
        "unit by forcing format 'cid-spectravue-percent' or 'cid-spectravue-fraction'",
    )


def _declared(unit: str) -> Any:
    def read(path: str | os.PathLike[str]) -> Measurement:
        return read_spectravue(path, unit)

    read.__doc__ = f"Read a SpectraVue export whose values are declared {unit}."
    return read


def _never(head: bytes) -> bool:
    """A declared unit is chosen by the user, never by content."""
    return False


FORMATS = (
    Format(
        INSTRUMENT,
        "CID Bio-Science SpectraVue Measurements.csv (reflectance, transmittance; unit from "
        "the values)",
        (".csv",),
        _sniff,
        read_spectravue,
        ("reflectance", "transmittance"),
        keywords=(b"Wavelengths(nm)", b"IntegrationTime(ms)"),
        examples=(Example("cid-spectravue/cid-spectravue-Rpc-Measurements.csv"),),
    ),
    Format(
        "cid-spectravue-percent",
        "CID SpectraVue Measurements.csv whose values are declared percent (forced only)",
        (),
        _never,
        _declared("percent"),
        ("reflectance", "transmittance"),
    ),
    Format(
        "cid-spectravue-fraction",
        "CID SpectraVue Measurements.csv whose values are declared fractions (forced only)",
        (),
        _never,
        _declared("fraction"),
        ("reflectance", "transmittance"),
    ),
)
