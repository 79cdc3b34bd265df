"""PerkinElmer UV WinLab ASCII export (``.asc``, "PE UV ... PEDS 4.00", e.g. ``*.Probe.Raw.asc``).

Layout (docs/formats.md section 8, seen in three Lambda 1050 files of UV WinLab 6.3.2):
line 1 is the magic ``PE UV SUBTECH SPECTRUM ASCII PEDS <version>`` (blank-padded), then one
value per line without labels: original file name (3; it is the sample name, used without
its ``.Probe.Raw.asc`` endings, else the file stem), creation date ``yy/mm/dd`` and time
(4-5), operator (8), comment (9), instrument (12), serial (13), software (14), the accessory
and detector description (25). The spectrum follows three markers found by search, not by
line number: ``#HDR``; ``#GR`` followed by x unit (``nm``), y unit (``%T``, ``%R``, ``A``),
y scale, y offset, FIRSTX, DELTAX, NPOINTS, a precision code, max Y, min Y; and ``#DATA``
followed by ``x<TAB>y`` rows. The number of rows must equal NPOINTS, and the X values must
lie on FIRSTX + i * DELTAX. Ordinates are ``y * scale + offset`` as the #GR block says.

Quantities: ``%T`` -> ``transmittance``; ``%R`` -> ``reflectance``, or
``hemispherical_reflectance`` when the accessory line (line 25) names a sphere
("150mm sphere / downward view"); ``A`` -> ``absorbance``. Percent becomes a fraction.
theta_i is NaN (normal incidence or 8-degree sphere port, which the file does not state).

Notes
-----
A transmittance measured with the sphere stays ``transmittance`` (total transmittance has no
separate quantity); ``meta["sphere"]`` records the accessory either way. The file's values
are kept as written: ``sphere_test01`` (a bad-setup test scan) holds -450 to +690 %T, which
is physically impossible but is what the instrument wrote.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import AdapterError, Example, Format, check_count, decode, read_bytes, split_lines
from ._spectro import PERCENT, finish, number, spectrum_frame
from ._truncation import check_joined, check_last_row

__all__ = ["FORMATS", "read_perkinelmer_asc"]

INSTRUMENT = "perkinelmer-uvwinlab"

_MAGIC = re.compile(r"PE UV\s+SUBTECH\s+SPECTRUM\s+ASCII\s+PEDS\s+(\S+)\s*")
_SPHERE = re.compile(r"sphere", re.IGNORECASE)

#: y unit of the #GR block -> (quantity, scale)
_YUNITS: dict[str, tuple[str, float]] = {
    "%T": ("transmittance", PERCENT),
    "%R": ("reflectance", PERCENT),
    "A": ("absorbance", 1.0),
    "ABS": ("absorbance", 1.0),
}

#: header line (1-based) -> meta key
_HEADER_LINES = {
    3: "original_file",
    4: "date",
    5: "time",
    6: "modified_date",
    7: "modified_time",
    8: "operator",
    9: "comment",
    12: "instrument_model",
    13: "serial",
    14: "software",
    21: "mode",
    25: "accessory",
    42: "detector_change_nm",
    43: "lamp_change_nm",
}


def _sniff(head: bytes) -> bool:
    return re.match(rb"PE UV\s+SUBTECH\s+SPECTRUM\s+ASCII\s+PEDS", head) is not None


def _sample_name(original: str, path: str | os.PathLike[str]) -> str:
    """Line 3 (the name the sample was saved under) without its extensions, else the stem."""
    name = re.sub(r"(\.Probe|\.Raw|\.Sample|\.asc|\.sp)+$", "", original, flags=re.IGNORECASE)
    return name.strip() or Path(path).name.split(".")[0] or Path(path).stem


def _find(path: str | os.PathLike[str], lines: list[str], marker: str, start: int) -> int:
    for i in range(start, len(lines)):
        if lines[i].strip() == marker:
            return i
    raise AdapterError(path, f"no {marker!r} line found (truncated or not a UV WinLab file)")


def read_perkinelmer_asc(path: str | os.PathLike[str]) -> Measurement:
    """Read a PerkinElmer UV WinLab ASCII spectrum (``.asc``).

    Parameters
    ----------
    path : str or path-like
        The export file.

    Returns
    -------
    Measurement
        One spectrum: transmittance, (hemispherical) reflectance or absorbance [1] against
        wavelength [nm]; ``meta`` has the positional header fields and the #GR block.

    Raises
    ------
    AdapterError
        Wrong magic line, a missing #HDR/#GR/#DATA marker, an unknown unit, a bad data row,
        a row count that disagrees with NPOINTS, or an X off the FIRSTX/DELTAX grid.
    """
    raw = read_bytes(path)
    text, encoding = decode(raw, path)
    lines = split_lines(text)
    check_joined(path, lines)
    m = _MAGIC.fullmatch(lines[0]) if lines else None
    if m is None:
        raise AdapterError(
            path, "expected the magic 'PE UV SUBTECH SPECTRUM ASCII PEDS <version>'", 1
        )
    hdr = _find(path, lines, "#HDR", 1)
    gr = _find(path, lines, "#GR", hdr + 1)
    data = _find(path, lines, "#DATA", gr + 1)
    grm = _gr_block(path, lines, gr, data, len(raw))
    xs, ys, at = _data_rows(path, lines, data, grm)
    doubt = check_last_row(path, text, lines, at, "\t" if "\t" in lines[-1] else None)
    header = {key: lines[n - 1].strip() for n, key in _HEADER_LINES.items() if n <= hdr}
    accessory = header.get("accessory", "")
    sphere = bool(_SPHERE.search(accessory))
    quantity, scale = _YUNITS[grm["y_unit"].upper()]
    if quantity == "reflectance" and sphere:
        quantity = "hemispherical_reflectance"
    y = np.asarray(ys) * grm["y_scale"] + grm["y_offset"]
    frame, dropped = spectrum_frame(
        path=path,
        sample=_sample_name(header.get("original_file", ""), path),
        instrument=INSTRUMENT,
        quantity=quantity,
        scale=scale,
        x_nm=xs,
        y=y,
    )
    meta: dict[str, Any] = {
        "format": "perkinelmer-uvwinlab-asc",
        "peds_version": m.group(1),
        "encoding": encoding,
        **header,
        "sphere": sphere,
        "gr": grm,
        "dropped_points": dropped,
    }
    if doubt:
        meta["warnings"] = [doubt]
    return finish(path, [frame], meta)


def _gr_block(
    path: str | os.PathLike[str], lines: list[str], gr: int, data: int, file_size: int
) -> dict[str, Any]:
    """The #GR block (lines ``gr + 1`` up to #DATA): units, Y scale and offset, X grid."""
    block = [s.strip() for s in lines[gr + 1 : data]]
    if len(block) < 7:
        raise AdapterError(
            path,
            f"the #GR block has {len(block)} lines, expected x unit, y unit, y scale, "
            "y offset, FIRSTX, DELTAX, NPOINTS",
            gr + 1,
        )
    xunit, yunit = block[0], block[1]
    if xunit.lower() != "nm":
        raise AdapterError(path, f"x unit {xunit!r}: only 'nm' is supported", gr + 2)
    if yunit.upper() not in _YUNITS:
        raise AdapterError(path, f"y unit {yunit!r} is not one of {sorted(_YUNITS)}", gr + 3)
    yscale = number(block[2], path, gr + 4, "y scale")
    yoffset = number(block[3], path, gr + 5, "y offset")
    firstx = number(block[4], path, gr + 6, "FIRSTX")
    deltax = number(block[5], path, gr + 7, "DELTAX")
    npoints = number(block[6], path, gr + 8, "NPOINTS")
    if npoints != int(npoints) or npoints < 1:
        raise AdapterError(path, f"NPOINTS {block[6]!r}: expected a positive integer", gr + 8)
    # a data row "x<TAB>y<LF>" takes at least 4 bytes
    check_count(path, "NPOINTS", int(npoints), line=gr + 8, file_size=file_size, bytes_per_point=4)
    return {
        "x_unit": xunit,
        "y_unit": yunit,
        "y_scale": yscale,
        "y_offset": yoffset,
        "firstx_nm": firstx,
        "deltax_nm": deltax,
        "npoints": int(npoints),
        "extra": block[7:],
    }


def _data_rows(
    path: str | os.PathLike[str], lines: list[str], data: int, grm: dict[str, Any]
) -> tuple[list[float], list[float], list[int]]:
    """The ``x<TAB>y`` rows after #DATA and their 1-based lines.

    Checked against NPOINTS and the FIRSTX/DELTAX grid.
    """
    firstx, deltax, npoints = grm["firstx_nm"], grm["deltax_nm"], grm["npoints"]
    xs: list[float] = []
    ys: list[float] = []
    at: list[int] = []
    last = data
    for i in range(data + 1, len(lines)):
        line = lines[i]
        if not line.strip():
            continue
        cells = line.split("\t") if "\t" in line else line.split()
        if len(cells) != 2:
            raise AdapterError(
                path, f"expected 'x<TAB>y' in the data, found {len(cells)} cells", i + 1
            )
        xs.append(number(cells[0], path, i + 1, "X"))
        ys.append(number(cells[1], path, i + 1, "Y"))
        last = i + 1
        at.append(last)
    if len(xs) != npoints:
        raise AdapterError(
            path,
            f"NPOINTS is {int(npoints)} but #DATA has {len(xs)} rows (truncated or edited?)",
            last,
        )
    with np.errstate(over="ignore", invalid="ignore"):
        grid = firstx + deltax * np.arange(len(xs))
        off = ~(np.abs(np.asarray(xs) - grid) <= 0.01 * abs(deltax) + 1e-9)
    if off.any():
        k = int(np.flatnonzero(off)[0])
        raise AdapterError(
            path,
            f"X {xs[k]} is not on the FIRSTX + i*DELTAX grid (expected {grid[k]:.6g})",
            data + 2 + k,
        )
    return xs, ys, at


FORMATS = (
    Format(
        "perkinelmer-uvwinlab-asc",
        "PerkinElmer UV WinLab ASCII spectrum (PEDS 4.00 .asc)",
        (".asc",),
        _sniff,
        read_perkinelmer_asc,
        ("transmittance", "reflectance", "hemispherical_reflectance", "absorbance"),
        keywords=(b"PE UV", b"PEDS"),
        examples=(
            Example("perkinelmer-uvwinlab-asc/KTF-D.Probe.Raw.asc", number=("89.940565", 91)),
        ),
        states_count=True,
    ),
)
