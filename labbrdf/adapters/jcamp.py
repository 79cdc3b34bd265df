"""JCAMP-DX 4.24/5 UV-Vis-NIR spectra (``.jdx``, ``.dx``), including LINK files and compression.

Reference: R.S. McDonald, P.A. Wilks, "JCAMP-DX: a standard form for exchange of infrared
spectra in computer readable form", Appl. Spectrosc. 42 (1988) 151,
doi:10.1366/0003702884428734 (ASDF compression, section "XYDATA"); the UV-Vis use of the
same records is as in the two real files of docs/formats.md section 10.

What is read
    Labelled data records ``##LABEL= value``; labels are normalised (upper case, blanks,
    ``-``, ``_`` and ``/`` removed, so ``##BLOCK_ID``, ``##BLOCK-ID =`` and ``##DATA TYPE``
    match), ``$$`` comments are stripped. A block runs from ``##TITLE=`` to ``##END=``;
    a ``##DATA TYPE= LINK`` block holds child blocks (``##BLOCKS=`` must equal their number).
    Every spectrum block needs ``##XYDATA= (X++(Y..Y))`` with ``FIRSTX``, ``LASTX``,
    ``NPOINTS``, or ``##XYPOINTS= (XY..XY)`` with ``NPOINTS``; ``XFACTOR``/``YFACTOR``
    default to 1. XYDATA ordinates may be AFFN, PAC (sign-separated), SQZ, DIF and DUP forms
    and ``?`` (missing, dropped and counted); X = FIRSTX + i * (LASTX - FIRSTX) /
    (NPOINTS - 1). XYPOINTS holds AFFN X, Y pairs (comma, semicolon or blank separated,
    several per line, ``?`` for a missing Y); X = the written X times XFACTOR.

Checks (each raises AdapterError with the line)
    * the X at the start of every data line (times XFACTOR) must be within half a step of
      the abscissa of the line's first ordinate: a lost or duplicated line is caught;
    * when a line ends in DIF form, the next line starts with a Y check value that must
      equal the last ordinate (and is not a new point);
    * the number of ordinates must equal NPOINTS; ``DELTAX`` must agree with
      (LASTX - FIRSTX) / (NPOINTS - 1) to 1 %;
    * XYPOINTS: NPOINTS is checked against the point cap before reading, a line whose pairs
      go past NPOINTS is refused, the number of pairs must equal NPOINTS, every line holds
      whole pairs, X is strictly monotonic, and FIRSTX/LASTX (when given) match the
      first/last X;
    * a table of another kind (``PEAK TABLE``, ``NTUPLES``) is refused at its line;
    * unclosed blocks, a ``##TITLE`` inside a spectrum block, a repeated label in one block,
      text after the last ``##END=``.

Quantities: YUNITS ``ABSORBANCE``/``A`` -> ``absorbance``; ``TRANSMITTANCE`` (a fraction in
JCAMP-DX) or ``%T``/``PERCENT TRANSMITTANCE`` (percent) -> ``transmittance``;
``REFLECTANCE``/``%R`` likewise -> ``reflectance``, or ``hemispherical_reflectance`` when a
record of the block mentions an integrating sphere. XUNITS must be NANOMETERS/NM, MICROMETERS
(converted) or 1/CM (wavenumbers, lambda [nm] = 1e7 / nu), also spelled out (``Wavelength
(nm)``, ``Wavenumber (cm-1)``); YUNITS may be spelled out too (``Transmittance (%)``). A DOS
end-of-file byte (0x1A) after the last ``##END=`` is ignored. The sample of each block is its
``TITLE``.

Notes
-----
Own decoder rather than the PyPI ``jcamp`` package: ``jcamp`` reads both real files
correctly (we use it as an optional cross-check in the tests) but returns an empty dict
for non-JCAMP text, reports no line numbers, does not check the X checkpoints or Y
checks, and we would have to wrap its exceptions anyway. The decoder here is under 200 lines.
``MAXY``/``MINY``/``FIRSTY`` are kept in meta but not checked: in ``blckpac1.jdx`` they are
swapped and FIRSTY disagrees with the data.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import Measurement
from ._base import (
    MAX_POINTS,
    AdapterError,
    Example,
    Format,
    check_count,
    decode,
    read_bytes,
    split_lines,
)
from ._spectro import PERCENT, finish, number, spectrum_frame

__all__ = ["FORMATS", "read_jcamp"]

INSTRUMENT = "jcamp-dx"

_YUNITS: dict[str, tuple[str, float]] = {
    "ABSORBANCE": ("absorbance", 1.0),
    "A": ("absorbance", 1.0),
    "ABS": ("absorbance", 1.0),
    "TRANSMITTANCE": ("transmittance", 1.0),
    "%T": ("transmittance", PERCENT),
    "PERCENTTRANSMITTANCE": ("transmittance", PERCENT),
    "REFLECTANCE": ("reflectance", 1.0),
    "%R": ("reflectance", PERCENT),
    "PERCENTREFLECTANCE": ("reflectance", PERCENT),
}
_XUNITS = {"NANOMETERS": 1.0, "NM": 1.0, "MICROMETERS": 1000.0, "UM": 1000.0}
#: spelled-out X units (lower case, after removing the axis name, brackets and blanks)
_X_SPELLED: dict[str, str] = {
    **dict.fromkeys(("nm", "nanometers", "nanometer", "nanometres", "nanometre"), "nm"),
    **dict.fromkeys(
        (
            "um",
            "µm",
            "μm",
            "micrometers",
            "micrometer",
            "micrometres",
            "micrometre",
            "microns",
            "micron",
        ),
        "um",
    ),
    **dict.fromkeys(("1/cm", "cm-1", "cm^-1", "cm⁻¹", "/cm", "wavenumbers", "wavenumber"), "1/cm"),
}
#: file X unit -> (name in meta, function to wavelength [nm])
_X_TO_NM: dict[str, Any] = {
    "nm": lambda v: v,
    "um": lambda v: v * 1000.0,
    "1/cm": lambda v: 1.0e7 / v,  # lambda [nm] = 1e7 / wavenumber [1/cm]
}


def _xunit(text: str) -> str | None:
    """``nm``, ``um`` or ``1/cm`` for an XUNITS value, spelled out or not, else None.

    ``NANOMETERS`` (the standard's spelling), ``nm``, ``Wavelength (nm)``,
    ``wavelength [nm]``, ``MICROMETERS``, ``1/CM`` (the IR spelling), ``Wavenumber (cm-1)``.
    """
    t = text.strip().lower()
    if t.upper() in _XUNITS:
        return "nm" if _XUNITS[t.upper()] == 1.0 else "um"
    t = re.sub(r"^(wavelengths?|wavenumbers?|lambda)\b", "", t)
    t = re.sub(r"[\s()\[\]]", "", t)
    if not t and re.match(r"\s*wavenumbers?\s*$", text, re.IGNORECASE):
        return "1/cm"
    return _X_SPELLED.get(t)


def _yunit(text: str) -> tuple[str, float] | None:
    """Quantity and scale for a YUNITS value, spelled out or not, else None.

    Beyond the standard's names: ``Transmittance (%)``, ``% Reflectance``,
    ``Absorbance (A)``, ``Abs.``; ``%`` or ``percent`` means percent.
    """
    key = _norm(text)
    if key in _YUNITS:
        return _YUNITS[key]
    t = text.strip().lower()
    percent = "%" in t or "percent" in t
    for word, quantity in (
        ("absorbance", "absorbance"),
        ("abs", "absorbance"),
        ("transmittance", "transmittance"),
        ("transmission", "transmittance"),
        ("reflectance", "reflectance"),
        ("reflection", "reflectance"),
    ):
        if re.search(rf"\b{word}\b", t):
            if quantity == "absorbance":
                return None if percent else (quantity, 1.0)
            return quantity, PERCENT if percent else 1.0
    return None


_SQZ = {c: i for i, c in enumerate("@ABCDEFGHI")} | {c: -i for i, c in enumerate("@abcdefghi")}
_DIF = {c: i for i, c in enumerate("%JKLMNOPQR")} | {c: -i for i, c in enumerate("%jklmnopqr")}
_DUP = {c: i for i, c in enumerate("STUVWXYZs", start=1)}
_TOKEN = re.compile(
    r"(?P<affn>[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-][0-9]+)?)"
    r"|(?P<sqz>[@A-Ia-i][0-9]*\.?[0-9]*)"
    r"|(?P<dif>[%J-Rj-r][0-9]*\.?[0-9]*)"
    r"|(?P<dup>[S-Zs][0-9]*)"
    r"|(?P<missing>\?)"
    r"|(?P<sep>[\s,;]+)"
)


#: The data tables read: equidistant ``(X++(Y..Y))`` and explicit ``(XY..XY)`` pairs.
_TABLES = ("XYDATA", "XYPOINTS")
#: Tables that exist in JCAMP-DX but are not spectra this reader takes.
_OTHER_TABLES = ("PEAKTABLE", "NTUPLES", "PEAKASSIGNMENTS", "XYPOINTS")
_PAIR_TOKEN = re.compile(r"[^\s,;]+")


def _norm(label: str) -> str:
    return re.sub(r"[\s\-_/]", "", label).upper()


@dataclass
class _Block:
    line: int
    records: dict[str, str] = field(default_factory=dict)
    labels: dict[str, str] = field(default_factory=dict)
    data: list[tuple[int, str]] = field(default_factory=list)
    data_line: int = 0
    lines: dict[str, int] = field(default_factory=dict)
    children: list[_Block] = field(default_factory=list)


def _sniff(head: bytes) -> bool:
    return re.match(rb"\s*##TITLE\s*=", head) is not None and b"##JCAMP" in head.upper()


def _parse_blocks(path: str | os.PathLike[str], lines: list[str]) -> _Block:
    stack: list[_Block] = []
    root: _Block | None = None
    current: str | None = None
    for n, line in enumerate(lines, start=1):
        s = line.split("$$", 1)[0].strip()
        if not s.startswith("##"):
            if not s:
                continue
            if root is not None and not stack:
                raise AdapterError(path, f"text after the last ##END=: {s[:30]!r}", n)
            if current in _TABLES and stack:
                stack[-1].data.append((n, s))
            elif current and current != "END" and stack:
                stack[-1].records[current] += "\n" + s  # continuation of a value
            else:
                raise AdapterError(path, f"expected a '##LABEL=' record, found {s[:30]!r}", n)
            continue
        label, eq, value = s[2:].partition("=")
        if not eq:
            raise AdapterError(path, f"expected '##LABEL= value', found {s[:30]!r}", n)
        key, value = _norm(label), value.strip()
        current = key
        if key == "TITLE":
            if stack and stack[-1].records.get("DATATYPE", "").upper() != "LINK":
                raise AdapterError(
                    path,
                    f"##TITLE= inside the block opened at line {stack[-1].line}, which has no "
                    "##END= and is not a LINK block",
                    n,
                )
            if root is not None and not stack:
                raise AdapterError(path, "a second top-level block after ##END=", n)
            block = _Block(line=n)
            if stack:
                stack[-1].children.append(block)
            else:
                root = block
            stack.append(block)
        elif not stack:
            what = "after the last ##END=" if root is not None else "before ##TITLE="
            raise AdapterError(path, f"record ##{label.strip()}= {what}", n)
        if key == "END":
            stack.pop()
            continue
        if not key:  # "##=" comment record
            continue
        block = stack[-1]
        if key in block.records and not key.startswith("$"):
            raise AdapterError(path, f"label ##{label.strip()}= repeated in one block", n)
        if key in _TABLES and block.data_line:
            raise AdapterError(
                path,
                f"a second data table (##{label.strip()}=) in the block opened at line "
                f"{block.line}",
                n,
            )
        block.records[key] = value
        block.labels[key] = label.strip()
        block.lines[key] = n
        if key in _TABLES:
            block.data_line = n
    if root is None:
        raise AdapterError(path, "no ##TITLE= record: not a JCAMP-DX file")
    if stack:
        raise AdapterError(
            path, f"the block opened at line {stack[-1].line} has no ##END= (truncated?)"
        )
    return root


def _decode_line(
    path: str | os.PathLike[str], n: int, text: str, room: int = MAX_POINTS
) -> tuple[float, list[float], bool]:
    """One ``(X++(Y..Y))`` line: X, the ordinates, whether the line ends in DIF form.

    ``room`` is the most ordinates the line may hold (what NPOINTS leaves, plus a Y check
    value): a DUP count that would go past it is refused before it is expanded.
    """
    pos = 0
    toks: list[tuple[str, str]] = []
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            raise AdapterError(
                path, f"character {text[pos]!r} at column {pos + 1} is not JCAMP-DX data", n
            )
        if m.lastgroup != "sep":
            toks.append((m.lastgroup or "", m.group()))
        pos = m.end()
    if not toks or toks[0][0] not in ("affn", "sqz"):
        raise AdapterError(path, "a data line must start with its X value", n)

    def absval(kind: str, tok: str) -> float:
        if kind == "affn":
            v = float(tok)
        else:
            lead = (_SQZ if kind == "sqz" else _DIF)[tok[0]]
            v = float(f"{abs(lead)}{tok[1:]}") * (-1 if tok[0].islower() else 1)
        if not np.isfinite(v):
            raise AdapterError(path, f"value {tok[:20]!r} overflows a float", n)
        return v

    x = absval(*toks[0])
    ys: list[float] = []
    prev: tuple[str, float] | None = None
    ends_dif = False
    for kind, tok in toks[1:]:
        if kind in ("affn", "sqz"):
            v = absval(kind, tok)
            ys.append(v)
            prev, ends_dif = ("abs", v), False
        elif kind == "dif":
            if not ys or np.isnan(ys[-1]):
                raise AdapterError(path, f"DIF value {tok!r} without a preceding ordinate", n)
            d = absval(kind, tok)
            ys.append(ys[-1] + d)
            prev, ends_dif = ("dif", d), True
        elif kind == "dup":
            if prev is None:
                raise AdapterError(path, f"DUP count {tok!r} without a value to repeat", n)
            count = _DUP[tok[0]] if len(tok) == 1 else int(f"{_DUP[tok[0]]}{tok[1:]}")
            if len(ys) + count - 1 > room:
                raise AdapterError(
                    path,
                    f"DUP count {tok!r} repeats a value {count} times, past the "
                    f"{room} ordinates that NPOINTS leaves for this line",
                    n,
                )
            for _ in range(count - 1):
                ys.append(ys[-1] + prev[1] if prev[0] == "dif" else prev[1])
        else:  # missing
            ys.append(float("nan"))
            prev, ends_dif = None, False
    return x, ys, ends_dif


def _decode_table(
    path: str | os.PathLike[str],
    block: _Block,
    first: float,
    step: float,
    xfactor: float,
    npoints: int,
) -> list[float]:
    ys: list[float] = []
    pending_check = False
    for n, text in block.data:
        room = max(npoints - len(ys), 0) + int(pending_check)
        x, vals, ends_dif = _decode_line(path, n, text, room)
        index = len(ys)
        if pending_check:
            if not vals:
                raise AdapterError(path, "expected the Y check value of the DIF line before", n)
            check, vals = vals[0], vals[1:]
            last = ys[-1]
            if not np.isclose(check, last, rtol=1e-9, atol=1e-9):
                raise AdapterError(
                    path,
                    f"Y check value {check:g} differs from the last ordinate {last:g} of the "
                    "line before (corrupt DIF data)",
                    n,
                )
            index -= 1
        expected = first + index * step
        if abs(x * xfactor - expected) > 0.5 * abs(step):
            raise AdapterError(
                path,
                f"X checkpoint {x * xfactor:.6g} does not match the abscissa {expected:.6g} of "
                f"point {index} (a data line lost, duplicated or corrupt)",
                n,
            )
        ys.extend(vals)
        pending_check = ends_dif
    return ys


def _decode_points(
    path: str | os.PathLike[str], block: _Block, npoints: int
) -> tuple[list[float], list[float]]:
    """An ``(XY..XY)`` table: AFFN X, Y pairs separated by commas, semicolons or blanks.

    Pairs may run over several per line but never across lines; ``?`` is a missing Y.
    More pairs than NPOINTS are refused at the line where they begin, before they are kept.
    """
    xs: list[float] = []
    ys: list[float] = []
    for n, text in block.data:
        fields = _PAIR_TOKEN.findall(text)
        if len(fields) % 2:
            raise AdapterError(
                path, f"an odd number of values ({len(fields)}): expected X, Y pairs", n
            )
        if len(xs) + len(fields) // 2 > npoints:
            raise AdapterError(
                path, f"the table runs past its {npoints} points: more than NPOINTS = {npoints}", n
            )
        for k in range(0, len(fields), 2):
            x = number(fields[k], path, n, "X")
            y = float("nan") if fields[k + 1] == "?" else number(fields[k + 1], path, n, "Y")
            if len(xs) >= 2 and (x - xs[-1]) * (xs[1] - xs[0]) <= 0 or (xs and x == xs[-1]):
                raise AdapterError(
                    path, f"X {x:g} after {xs[-1]:g}: the abscissae are not strictly monotonic", n
                )
            xs.append(x)
            ys.append(y)
    return xs, ys


def _spectrum(
    path: str | os.PathLike[str], block: _Block, index: int
) -> tuple[pd.DataFrame, int, dict[str, Any]]:
    rec = block.records
    where = block.line
    if "XYDATA" in rec:
        table = "XYDATA"
        if re.sub(r"\s", "", rec["XYDATA"]).upper() != "(X++(Y..Y))":
            raise AdapterError(
                path,
                f"##XYDATA= {rec['XYDATA']!r}: only (X++(Y..Y)) is supported",
                block.data_line,
            )
    elif "XYPOINTS" in rec:
        table = "XYPOINTS"
        if re.sub(r"\s", "", rec["XYPOINTS"]).upper() != "(XY..XY)":
            raise AdapterError(
                path,
                f"##XYPOINTS= {rec['XYPOINTS']!r}: only (XY..XY) is supported",
                block.data_line,
            )
    else:
        other = next((k for k in _OTHER_TABLES if k in rec), None)
        raise AdapterError(
            path,
            "block has no ##XYDATA= table (nor ##XYPOINTS=)"
            + (f"; ##{block.labels[other]}= is not supported" if other else ""),
            block.lines[other] if other else where,
        )
    needed = ("FIRSTX", "LASTX", "NPOINTS") if table == "XYDATA" else ("NPOINTS",)
    for key in needed:
        if key not in rec:
            raise AdapterError(path, f"block has no ##{key}= record", where)
    xunit = _xunit(rec.get("XUNITS", ""))
    if xunit is None:
        raise AdapterError(
            path,
            f"XUNITS {rec.get('XUNITS', '')[:40]!r}: expected a wavelength in NANOMETERS or "
            "MICROMETERS, or a wavenumber in 1/CM (spelled out as 'Wavelength (nm)' too)",
            block.lines.get("XUNITS", where),
        )
    yunit = _yunit(rec.get("YUNITS", ""))
    if yunit is None:
        raise AdapterError(
            path,
            f"YUNITS {rec.get('YUNITS', '')[:40]!r}: expected one of {sorted(_YUNITS)} "
            "(or spelled out, e.g. 'Transmittance (%)')",
            block.lines.get("YUNITS", where),
        )
    xfactor = number(rec.get("XFACTOR", "1"), path, where, "XFACTOR")
    yfactor = number(rec.get("YFACTOR", "1"), path, where, "YFACTOR")
    if table == "XYDATA":
        x, ys = _xydata(path, block, xfactor)
    else:
        x, ys = _xypoints(path, block, xfactor)
    quantity, scale = yunit
    if quantity == "reflectance" and any(
        re.search(r"sphere", v, re.IGNORECASE) for v in rec.values()
    ):
        quantity = "hemispherical_reflectance"
    if xunit == "1/cm" and not np.all(x > 0):
        raise AdapterError(
            path, "a wavenumber [1/cm] <= 0 cannot be converted to a wavelength", block.data_line
        )
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        x_nm = _X_TO_NM[xunit](x)
    title = rec.get("TITLE", "").strip() or f"{Path(path).stem} block {index + 1}"
    frame, dropped = spectrum_frame(
        path=path,
        sample=title,
        instrument=INSTRUMENT,
        quantity=quantity,
        scale=scale * yfactor,
        x_nm=x_nm,
        y=np.asarray(ys, dtype=float),
    )
    header = {block.labels[k]: v for k, v in rec.items() if k not in _TABLES}
    info = {"title": title, "line": block.line, "table": table, "header": header}
    return frame, dropped, info


def _xydata(
    path: str | os.PathLike[str], block: _Block, xfactor: float
) -> tuple[np.ndarray, list[float]]:
    """Abscissae and ordinates of an ``(X++(Y..Y))`` table, with its checks.

    Abscissae are actual values (FIRSTX and LASTX are not scaled by XFACTOR); ordinates are
    not yet multiplied by YFACTOR.
    """
    rec, where = block.records, block.line
    first = number(rec["FIRSTX"], path, where, "FIRSTX")
    last = number(rec["LASTX"], path, where, "LASTX")
    npoints = number(rec["NPOINTS"], path, where, "NPOINTS")
    if npoints < 2 or npoints != int(npoints):
        raise AdapterError(path, f"NPOINTS {rec['NPOINTS']!r}: expected an integer >= 2", where)
    npoints = check_count(path, "NPOINTS", int(npoints), line=where)
    step = (last - first) / (npoints - 1)
    if step == 0 or xfactor == 0:
        raise AdapterError(path, "FIRSTX equals LASTX or XFACTOR is 0", where)
    if "DELTAX" in rec:
        delta = number(rec["DELTAX"], path, where, "DELTAX")
        if abs(delta - step) > 0.01 * abs(step):
            raise AdapterError(
                path,
                f"DELTAX {delta:g} disagrees with (LASTX - FIRSTX)/(NPOINTS - 1) = {step:g}",
                where,
            )
    ys = _decode_table(path, block, first, step, xfactor, npoints)
    if np.isinf(ys).any():
        raise AdapterError(path, "DIF accumulation overflows a float", block.data_line)
    if len(ys) != npoints:
        raise AdapterError(
            path,
            f"NPOINTS is {npoints} but the table decodes to {len(ys)} ordinates",
            block.data[-1][0] if block.data else block.data_line,
        )
    with np.errstate(over="ignore", invalid="ignore"):
        x = first + step * np.arange(npoints)
    return x, ys


def _xypoints(
    path: str | os.PathLike[str], block: _Block, xfactor: float
) -> tuple[np.ndarray, list[float]]:
    """Abscissae (actual values: X times XFACTOR) and ordinates of an ``(XY..XY)`` table.

    NPOINTS is checked against the cap before any pair is kept and must equal the number
    of pairs; FIRSTX and LASTX, when given, must match the first and last X (to 1e-6 of
    the X range, relative).
    """
    rec = block.records
    nline = block.lines["NPOINTS"]
    declared = number(rec["NPOINTS"], path, nline, "NPOINTS")
    if declared < 1 or declared != int(declared):
        raise AdapterError(path, f"NPOINTS {rec['NPOINTS']!r}: expected an integer >= 1", nline)
    npoints = check_count(path, "NPOINTS", int(declared), line=nline)
    if xfactor == 0:
        raise AdapterError(path, "XFACTOR is 0", block.lines["XFACTOR"])
    xs, ys = _decode_points(path, block, npoints)
    last_line = block.data[-1][0] if block.data else block.data_line
    if len(xs) != npoints:
        raise AdapterError(
            path, f"NPOINTS is {npoints} but the table has {len(xs)} points", last_line
        )
    x = np.asarray(xs, dtype=float) * xfactor
    span = abs(float(x[-1] - x[0])) or abs(float(x[0])) or 1.0
    for key, k, line in (
        ("FIRSTX", 0, block.data[0][0] if block.data else block.data_line),
        ("LASTX", -1, last_line),
    ):
        if key in rec:
            want = number(rec[key], path, block.lines[key], key)
            if abs(want - x[k]) > 1e-6 * span:
                what = "first" if k == 0 else "last"
                raise AdapterError(
                    path,
                    f"{key} {want:g} disagrees with the {what} X {x[k]:g} of the table",
                    line,
                )
    return x, ys


def read_jcamp(path: str | os.PathLike[str]) -> Measurement:
    """Read a JCAMP-DX UV-Vis-NIR spectrum file, single block or LINK compound.

    Parameters
    ----------
    path : str or path-like
        The ``.jdx``/``.dx`` file.

    Returns
    -------
    Measurement
        One spectrum per block (``sample`` = block title) against wavelength [nm];
        ``meta["blocks"]`` has each block's records.

    Raises
    ------
    AdapterError
        Structure, label, unit, count, X-checkpoint or Y-check errors, with the line.
    """
    raw = read_bytes(path)
    text, encoding = decode(raw, path, ("utf-8", "cp1252"))
    # a DOS end-of-file byte (Ctrl-Z) after the last ##END= is no text after it
    body = text.rstrip()
    if body.endswith("\x1a"):
        text = body[:-1]
    root = _parse_blocks(path, split_lines(text))
    if root.records.get("DATATYPE", "").strip().upper() == "LINK":
        spectra = root.children
        if "BLOCKS" in root.records:
            declared = number(root.records["BLOCKS"], path, root.line, "BLOCKS")
            if declared != len(spectra):
                raise AdapterError(
                    path,
                    f"##BLOCKS= {root.records['BLOCKS']} but the LINK block holds "
                    f"{len(spectra)} blocks",
                    root.line,
                )
        if not spectra:
            raise AdapterError(path, "LINK block without child blocks", root.line)
    else:
        spectra = [root]
    frames, blocks, dropped = [], [], 0
    for k, block in enumerate(spectra):
        if block.children:
            raise AdapterError(path, "nested LINK blocks are not supported", block.line)
        frame, d, info = _spectrum(path, block, k)
        frames.append(frame)
        blocks.append(info)
        dropped += d
    meta: dict[str, Any] = {
        "format": "jcamp-dx",
        "encoding": encoding,
        "link": {root.labels[k]: v for k, v in root.records.items()} if root.children else None,
        "blocks": blocks,
        "dropped_points": dropped,
    }
    return finish(path, frames, meta)


FORMATS = (
    Format(
        "jcamp-dx",
        "JCAMP-DX UV-Vis-NIR spectra (LINK blocks; XYDATA AFFN, PAC, SQZ, DIF, DUP; XYPOINTS)",
        (".jdx", ".dx", ".jcamp"),
        _sniff,
        read_jcamp,
        ("absorbance", "transmittance", "reflectance", "hemispherical_reflectance"),
        keywords=(b"##TITLE", b"##JCAMP", b"##XYDATA", b"##XYPOINTS"),
        examples=(Example("jcamp-dx/dupinc1.jdx", number=("2860", 22)),),
        states_count=True,
    ),
)
