"""Agilent/Varian Cary WinUV "Scan" CSV export (``.csv``), one or many samples side by side.

Layout (docs/formats.md section 9; ``CuPCtS_H2O_vis.csv`` with one sample and
``filters.csv`` with eleven, Cary 50, Scan 3.00):

* row 1: the sample names, each followed by an empty cell (``600LP,,600LP1,,...``);
* row 2: per sample ``Wavelength (nm),<Y mode>`` with Y mode ``Abs``, ``%T`` or ``%R``;
  modes may differ between samples;
* data rows: ``x,y`` pairs of all samples side by side, with a trailing comma. Samples with
  shorter scans leave both cells empty (ragged columns); these padding cells are skipped
  and counted per sample in ``meta["samples"][k]["padding_rows"]``; a pair with only one of
  x or y empty is a missing point, dropped and counted in ``meta["dropped_points"]``;
* a blank line ends the data (a file without it is truncated and refused);
* one metadata block per sample: name, ``Collection Time: 5/10/2018 5:14:12 PM`` (US
  format, stored as ISO 8601 in ``collection_time``), ``Scan Software Version``, the
  ``Parameter List`` of fixed-width ``key   value`` lines (Instrument, Start/Stop (nm),
  X Mode, Y Mode, data interval, beam mode, baseline ...), the ``Method Log`` with its
  ``... Changed:`` lines, and ``<Current Wavelength> , 701.0``.

Blocks are paired with samples in order and must carry the same names. When a sample's
block gives ``UV-Vis Data Interval (nm)``, consecutive wavelengths of that sample must
differ by 0.5 to 1.5 intervals (the instrument's actual steps scatter by a few percent), so
that a lost or duplicated data row is an error, not a silently shorter spectrum.

Quantities: ``Abs`` -> ``absorbance``; ``%T`` -> ``transmittance``; ``%R`` ->
``reflectance``, or ``hemispherical_reflectance`` when the sample's parameter list names
an integrating sphere or a DRA (diffuse reflectance accessory). theta_i is NaN.
"""

from __future__ import annotations

import datetime as _dt
import os
import re
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import Measurement
from ._base import DECIMAL, AdapterError, Example, Format, decode, read_bytes, split_lines
from ._spectro import PERCENT, finish, number, spectrum_frame
from ._truncation import check_joined, warn

__all__ = ["FORMATS", "read_cary_csv"]

INSTRUMENT = "agilent-cary-winuv"

_YMODES: dict[str, tuple[str, float]] = {
    "Abs": ("absorbance", 1.0),
    "%T": ("transmittance", PERCENT),
    "%R": ("reflectance", PERCENT),
}
_XHEADER = "Wavelength (nm)"
_SPHERE = re.compile(r"sphere|\bDRA\b", re.IGNORECASE)
#: the line that ends every metadata block
_END_OF_BLOCK = "<Current Wavelength>"


def _sniff(head: bytes) -> bool:
    lines = head.splitlines()
    return (
        len(lines) >= 2
        and lines[1].startswith(b"Wavelength (nm),")
        and (b"Abs" in lines[1] or b"%T" in lines[1] or b"%R" in lines[1])
    )


def _cells(line: str, width: int) -> list[str] | None:
    cells = line.split(",")
    if len(cells) == width + 1 and cells[-1].strip() == "":
        cells = cells[:-1]
    return cells if len(cells) == width else None


def read_cary_csv(path: str | os.PathLike[str]) -> Measurement:
    """Read a Cary WinUV scan CSV with one or several samples.

    Parameters
    ----------
    path : str or path-like
        The export file.

    Returns
    -------
    Measurement
        All samples' spectra (``sample`` column from row 1) against wavelength [nm];
        ``meta["samples"]`` has each sample's Y mode, point count and metadata block.

    Raises
    ------
    AdapterError
        Wrong header rows, an unknown Y mode, a row with the wrong number of cells, a
        non-numeric cell, data not ended by a blank line, metadata blocks that do not match
        the samples, or a wavelength step inconsistent with the sample's data interval.
    """
    raw = read_bytes(path)
    text, encoding = decode(raw, path)
    lines = split_lines(text)
    check_joined(path, lines)
    if len(lines) < 3:
        raise AdapterError(path, "expected sample names, column titles and data rows")
    modes = _y_modes(path, lines[1])
    nsample = len(modes)
    names = _sample_names(path, lines[0], nsample)
    cols = _columns(path, lines, names, modes)
    end = cols.end
    blocks = _footer_blocks(lines, end)
    _check_footer_complete(path, text, lines, blocks)
    paired = len(blocks) == nsample and all(
        b["name"] == n for b, n in zip(blocks, names, strict=True)
    )
    if blocks and not paired:
        raise AdapterError(
            path,
            f"the {len(blocks)} metadata blocks after the data ({[b['name'] for b in blocks]}) "
            f"do not match the {nsample} samples {names}",
            end + 1,
        )
    frames, samples_meta, dropped_total = _samples(path, names, modes, cols, blocks, paired)
    meta: dict[str, Any] = {
        "format": "agilent-cary-winuv-csv",
        "encoding": encoding,
        "samples": samples_meta,
        "dropped_points": dropped_total,
    }
    if not blocks and "%R" in modes:
        meta["warnings"] = [_warn_no_footer(path, end, names, modes)]
    return finish(path, frames, meta)


def _samples(
    path: str | os.PathLike[str],
    names: list[str],
    modes: list[str],
    cols: _Columns,
    blocks: list[dict[str, Any]],
    paired: bool,
) -> tuple[list[pd.DataFrame], list[dict[str, Any]], int]:
    """Each sample's frame and meta (with its metadata block), and the points dropped."""
    nsample, end = len(names), cols.end
    x, y, present, half = cols.x, cols.y, cols.present, cols.half
    frames: list[pd.DataFrame] = []
    samples_meta: list[dict[str, Any]] = []
    dropped_total = 0
    for k in range(nsample):
        rows = np.flatnonzero(present[:, k])
        block = blocks[k] if paired else {}
        params = block.get("parameters", {})
        with_x = np.flatnonzero(np.isfinite(x[:, k]))  # incl. points whose y is missing
        _check_steps(path, names[k], x[with_x, k], with_x, params)
        quantity, scale = _YMODES[modes[k]]
        if quantity == "reflectance" and any(
            _SPHERE.search(f"{key} {val}") for key, val in params.items()
        ):
            quantity = "hemispherical_reflectance"
        frame, _ = spectrum_frame(
            path=path,
            sample=names[k],
            instrument=INSTRUMENT,
            quantity=quantity,
            scale=scale,
            x_nm=x[rows, k],
            y=y[rows, k],
        )
        frames.append(frame)
        missing = int(np.count_nonzero(half[:, k]))
        dropped_total += missing
        last = int(rows[-1]) if rows.size else 1
        padding = int(np.count_nonzero(~present[2:end, k] & ~half[2:end, k]))
        samples_meta.append(
            {
                "name": names[k],
                "y_mode": modes[k],
                "quantity": quantity,
                "points": int(rows.size),
                "missing_points": missing,
                "padding_rows": padding,
                "last_data_line": last + 1,
                **{key: val for key, val in block.items() if key != "name"},
            }
        )
    return frames, samples_meta, dropped_total


def _y_modes(path: str | os.PathLike[str], line: str) -> list[str]:
    """Row 2, the column titles: the Y mode of every sample."""
    titles = line.split(",")
    if titles and titles[-1].strip() == "":
        titles = titles[:-1]
    if len(titles) < 2 or len(titles) % 2:
        raise AdapterError(
            path, "row 2: expected 'Wavelength (nm),<Y mode>' pairs, one per sample", 2
        )
    nsample = len(titles) // 2
    modes = []
    for k in range(nsample):
        if titles[2 * k].strip() != _XHEADER:
            raise AdapterError(
                path,
                f"row 2, column {2 * k + 1}: expected {_XHEADER!r}, found "
                f"{titles[2 * k].strip()[:30]!r} (only nm scans are supported)",
                2,
            )
        mode = titles[2 * k + 1].strip()
        if mode not in _YMODES:
            raise AdapterError(
                path,
                f"row 2, column {2 * k + 2}: Y mode {mode!r} is not one of {sorted(_YMODES)}",
                2,
            )
        modes.append(mode)
    return modes


def _sample_names(path: str | os.PathLike[str], line: str, nsample: int) -> list[str]:
    """Row 1: a sample name then an empty cell for every sample."""
    names_row = _cells(line, 2 * nsample)
    if names_row is None:
        raise AdapterError(
            path, f"row 1: expected {nsample} sample names each followed by an empty cell", 1
        )
    names = [names_row[2 * k].strip() for k in range(nsample)]
    if any(not n for n in names) or any(names_row[2 * k + 1].strip() for k in range(nsample)):
        raise AdapterError(
            path, "row 1: expected a sample name then an empty cell for every sample", 1
        )
    return names


@dataclass
class _Columns:
    """The x, y pairs of every sample by line (NaN where a sample has no point)."""

    x: np.ndarray
    y: np.ndarray
    #: both x and y written
    present: np.ndarray
    #: only one of x and y written (a point the instrument did not record)
    half: np.ndarray
    #: the blank line that ends the data
    end: int


def _columns(
    path: str | os.PathLike[str], lines: list[str], names: list[str], modes: list[str]
) -> _Columns:
    """The data rows from row 3 up to the blank line before the metadata blocks."""
    nsample = len(names)
    width = 2 * nsample
    x = np.full((len(lines), nsample), np.nan)
    y = np.full((len(lines), nsample), np.nan)
    present = np.zeros((len(lines), nsample), dtype=bool)
    half = np.zeros((len(lines), nsample), dtype=bool)
    i = 2
    while i < len(lines) and lines[i].strip():
        cells = _cells(lines[i], width)
        if cells is None:
            raise AdapterError(
                path,
                f"expected {width} cells ({nsample} x,y pairs) and a trailing comma, found "
                f"{len(lines[i].split(','))}",
                i + 1,
            )
        for k in range(nsample):
            cx, cy = cells[2 * k].strip(), cells[2 * k + 1].strip()
            if cx and cy:
                x[i, k] = number(cx, path, i + 1, f"{names[k]} wavelength")
                y[i, k] = number(cy, path, i + 1, f"{names[k]} {modes[k]}")
                present[i, k] = True
            elif cx or cy:
                half[i, k] = True
                if cx:
                    x[i, k] = number(cx, path, i + 1, f"{names[k]} wavelength")
                else:
                    number(cy, path, i + 1, f"{names[k]} {modes[k]}")
        i += 1
    end = i
    if end == 2:
        raise AdapterError(path, "no data rows after the column titles", 3)
    if end == len(lines):
        raise AdapterError(
            path,
            "the data are not followed by a blank line and the metadata blocks (file truncated?)",
            end,
        )
    return _Columns(x, y, present, half, end)


def _check_steps(
    path: str | os.PathLike[str],
    name: str,
    xs: np.ndarray,
    rows: np.ndarray,
    params: dict[str, str],
) -> None:
    interval = next((v for k, v in params.items() if "Data Interval" in k), None)
    if interval is None or xs.size < 2:
        return
    if DECIMAL.fullmatch(interval.strip()) is None:
        return
    step = float(interval)
    if not (np.isfinite(step) and step > 0):
        return
    with np.errstate(over="ignore", invalid="ignore"):
        dx = np.abs(np.diff(xs))
        bad = ~((dx >= 0.5 * step) & (dx <= 1.5 * step))
        sign = np.sign(np.diff(xs))
    bad |= sign != sign[0]
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise AdapterError(
            path,
            f"sample {name!r}: wavelength step {xs[j + 1] - xs[j]:.4g} nm between "
            f"{xs[j]:.6g} and {xs[j + 1]:.6g} does not match its data interval {step:g} nm "
            "(a data row lost or duplicated?)",
            int(rows[j + 1]) + 1,
        )


def _check_footer_complete(
    path: str | os.PathLike[str], text: str, lines: list[str], blocks: list[dict[str, Any]]
) -> None:
    """Refuse a file cut inside its last metadata block.

    Cary ends every block with its ``<Current Wavelength>`` line. A last block without it,
    or a file whose last line has no line end, was cut short: what is missing may be the
    parameter that names the sphere, and with it the quantity of a %R sample.
    """
    if not blocks:
        return
    last = max(i for i, ln in enumerate(lines) if ln.strip())
    if not lines[last].strip().startswith(_END_OF_BLOCK):
        raise AdapterError(
            path,
            f"the metadata block of sample {blocks[-1]['name']!r} ends without its "
            f"{_END_OF_BLOCK!r} line: the file looks truncated (its accessory, and so the "
            "quantity of a %R sample, may be in the part that is missing)",
            last + 1,
        )
    if not text.endswith(("\n", "\r")):
        raise AdapterError(
            path,
            f"the last line ({lines[last].strip()[:40]!r}) has no line end: the file looks "
            "truncated",
            last + 1,
        )


def _warn_no_footer(
    path: str | os.PathLike[str], end: int, names: list[str], modes: list[str]
) -> str:
    """The doubt about a %R sample of a file that ends after its data (no metadata blocks)."""
    r = [n for n, m in zip(names, modes, strict=True) if m == "%R"]
    return warn(
        path,
        f"the data end without the metadata blocks Cary writes after them (file truncated?): "
        f"the accessory is unknown, so the %R sample(s) {r} are read as specular "
        "'reflectance', not 'hemispherical_reflectance', and no wavelength step is checked",
        end + 1,
    )


def _footer_blocks(lines: list[str], start: int) -> list[dict[str, Any]]:
    """Split the metadata after the data into one dict per sample block."""
    blocks: list[dict[str, Any]] = []
    current: list[str] = []
    for line in [*lines[start:], ""]:
        if line.strip():
            current.append(line)
        elif current:
            blocks.append(_parse_block(current))
            current = []
    return blocks


def _parse_block(block: list[str]) -> dict[str, Any]:
    name = block[0].split(",")[0].strip()
    out: dict[str, Any] = {"name": name}
    params: dict[str, str] = {}
    changes: list[str] = []
    in_params = False
    for line in block[1:]:
        s = line.strip()
        if s.startswith("Parameter List"):
            in_params = True
            continue
        if s.startswith("Method Log"):
            in_params = False
        if in_params:
            parts = re.split(r"\s{2,}", s, maxsplit=1)
            params[parts[0]] = parts[1].strip() if len(parts) > 1 else ""
            continue
        if " Changed: " in s:
            changes.append(s)
        elif s.startswith("<Current Wavelength>"):
            out["current_wavelength"] = s.split(",", 1)[-1].strip()
        elif ":" in s:
            key, _, value = s.partition(":")
            key, value = key.strip(), value.strip()
            if key == "Collection Time":
                out["collection_time_raw"] = value
                out["collection_time"] = _us_time(value)
            elif key:
                out[key] = value
    out["parameters"] = params
    out["method_changes"] = changes
    return out


def _us_time(value: str) -> str | None:
    try:
        return _dt.datetime.strptime(value, "%m/%d/%Y %I:%M:%S %p").isoformat()
    except ValueError:
        return None


FORMATS = (
    Format(
        "agilent-cary-winuv-csv",
        "Agilent/Varian Cary WinUV scan CSV (one or many samples side by side)",
        (".csv",),
        _sniff,
        read_cary_csv,
        ("absorbance", "transmittance", "reflectance", "hemispherical_reflectance"),
        keywords=(b"Wavelength (nm),",),
        examples=(
            Example("agilent-cary-winuv-csv/CuPCtS_H2O_vis.csv", number=("0.0340631865", 5)),
        ),
        states_count=True,
    ),
)
