"""The header of a J.A. Woollam ASCII export: which software wrote it, how, in which unit.

The layout is described in :mod:`labbrdf.adapters.woollam`. Here: the sniffers that tell a
WVASE32 export from a CompleteEASE one by the method line, the method line's items
(:func:`parse_method`), the header lines found by content (:func:`read_header`) and the
spectral axis converted to nm (:func:`to_nm`, with WVASE's own 1240 eV nm).
"""

from __future__ import annotations

import os
import re
from datetime import datetime
from typing import Any

import numpy as np

from ._base import DECIMAL, AdapterError
from ._frame import check_rows, within
from ._numblock import Block, head_lines

__all__ = [
    "WVASE_HC_EV_NM",
    "ascii_head",
    "parse_method",
    "read_header",
    "sniff_completeease",
    "sniff_wvase",
    "to_nm",
]

_METHOD = re.compile(r"^\s*(VASE|RT)method\[(.*)\]\s*$")
_ORIGINAL = re.compile(r"^\s*Original\[(.*)\]\s*$")

#: spectral unit line -> (canonical name, conversion to nm)
_UNITS: dict[str, str] = {
    "nm": "nm",
    "ev": "eV",
    "angstroms": "Angstrom",
    "angstrom": "Angstrom",
    "a": "Angstrom",
    "um": "um",
    "microns": "um",
    "micrometers": "um",
    "cm-1": "cm-1",
    "1/cm": "cm-1",
}

#: The h*c [eV nm] WVASE32 uses to write an eV axis: lambda[nm] = 1240 / E[eV]. Inverting
#: the software's own conversion gives back the monochromator's wavelengths: the eV grid of
#: ``wafer_2_01242007.dat`` times 1240 reproduces the nm grid of ``w2_10102006.dat`` (same
#: instrument and spectral grid) to 6e-7 relative, the 7 digits printed; CODATA
#: hc = 1239.84198 eV nm would be 1.3e-4 (0.2 nm at 1698 nm) off.
WVASE_HC_EV_NM = 1240.0

_DATE_FORMATS = ("%a %b %d %H:%M:%S %Y",)


# ----------------------------------------------------------------------------- sniffing


def _method_line(head: bytes) -> str | None:
    try:
        text = head.decode("latin-1")
        for line in text.splitlines()[:4]:
            if _METHOD.match(line) or line.lstrip().startswith(("VASEmethod[", "RTmethod[")):
                return line
    except Exception:  # a sniffer never raises
        return None
    return None


def sniff_wvase(head: bytes) -> bool:
    """True for a WVASE32 export: a ``VASEmethod[``/``RTmethod[`` line without CompleteEASE."""
    line = _method_line(head)
    return line is not None and "CompleteEASE" not in line


def sniff_completeease(head: bytes) -> bool:
    """True for a CompleteEASE export: the method line names ``CompleteEASE=``."""
    line = _method_line(head)
    return line is not None and "CompleteEASE" in line


# ----------------------------------------------------------------------------- header


def _number_or_text(v: str) -> float | int | str:
    if DECIMAL.fullmatch(v) is None:
        return v
    try:
        f = float(v)
    except ValueError:
        return v
    if not np.isfinite(f):
        return v
    return int(f) if re.fullmatch(r"[+-]?[0-9]+", v) else f


def parse_method(line: str) -> dict[str, Any]:
    """Parse a ``VASEmethod[...]`` / ``RTmethod[...]`` line.

    Parameters
    ----------
    line : str
        The method line.

    Returns
    -------
    dict
        ``method`` (``"VASEmethod"`` or ``"RTmethod"``), ``settings`` (``key=value`` items,
        numbers as numbers; keys kept verbatim, e.g. ``"Acq. Parameters"``), ``flags`` (bare
        items such as ``Isotropic``), ``date`` (the date item as written) and ``datetime``
        (ISO 8601, when the date parses), ``simulated`` (True for WVASE's model-generated
        ``Simulation for ...`` / ``Normal Fit Generation`` data) and ``software``.

    Raises
    ------
    ValueError
        The line is not a method line.
    """
    m = _METHOD.match(line)
    if m is None:
        raise ValueError(f"not a VASEmethod[...] / RTmethod[...] line: {line!r}")
    out: dict[str, Any] = {"method": f"{m.group(1)}method", "settings": {}, "flags": []}
    simulated = False
    for item in (s.strip() for s in m.group(2).split(",")):
        if not item:
            continue
        if "=" in item:
            k, v = (s.strip() for s in item.split("=", 1))
            out["settings"][k] = _number_or_text(v)
            continue
        for fmt in _DATE_FORMATS:
            try:
                out["datetime"] = datetime.strptime(item, fmt).isoformat()
                out["date"] = item
                break
            except ValueError:
                continue
        else:
            if item.startswith(("Simulation for", "Normal Fit Generation")):
                simulated = True
            out["flags"].append(item)
    out["simulated"] = simulated
    st = out["settings"]
    if "CompleteEASE" in st:
        out["software"] = f"CompleteEASE {st['CompleteEASE']}"
    elif "WVASE" in st:
        out["software"] = f"WVASE32 {st['WVASE']}"
    return out


def read_header(path: str | os.PathLike[str], text: str) -> tuple[dict[str, Any], int, int]:
    """Find the header lines by content; return meta, the body's offset and first line."""
    lines, _ = head_lines(text, 7)
    meta: dict[str, Any] = {}
    i = 0
    # title: every line before the method line (normally one, may be empty)
    mi = next((k for k, s in enumerate(lines[:3]) if _METHOD.match(s)), None)
    if mi is None:
        raise AdapterError(
            path,
            "no VASEmethod[...] or RTmethod[...] line in the first 3 lines: not a Woollam "
            "WVASE32/CompleteEASE ASCII export",
            min(len(lines), 2) or 1,
        )
    if mi > 2 or (mi == 2 and lines[0].strip()):
        raise AdapterError(path, "expected at most one title line before the method line", mi)
    meta["title"] = lines[mi - 1].strip() if mi >= 1 else ""
    meta.update(parse_method(lines[mi]))
    i = mi + 1
    if i < len(lines) and _ORIGINAL.match(lines[i]):
        meta["original_file"] = _ORIGINAL.match(lines[i]).group(1)  # type: ignore[union-attr]
        i += 1
    meta["dynamic"] = False
    if i < len(lines) and lines[i].strip().lower() == "dynamic":
        meta["dynamic"] = True
        i += 1
    if i >= len(lines):
        raise AdapterError(path, "file ends before the spectral unit line (nm, eV, Angstroms)")
    unit = lines[i].strip()
    if unit.lower() not in _UNITS:
        raise AdapterError(
            path,
            f"expected the spectral unit line (nm, eV or Angstroms), found {unit[:40]!r}",
            i + 1,
        )
    meta["spectral_unit"] = _UNITS[unit.lower()]
    meta["spectral_unit_as_written"] = unit
    if meta["spectral_unit"] == "eV":
        meta["ev_to_nm"] = "lambda[nm] = 1240 / E[eV] (the constant WVASE writes eV with)"
    _, offset = head_lines(text, i + 1)
    return meta, offset, i + 2


def to_nm(
    path: str | os.PathLike[str], x: np.ndarray, unit: str, block: Block, rows: np.ndarray
) -> np.ndarray:
    """The spectral values ``x`` in ``unit`` converted to wavelengths [nm].

    A value that is not a finite number > 0 on a row of ``rows`` is refused with its line.
    """
    if not (within(x, 0.0, np.inf) and x.min() > 0):
        check_rows(
            path,
            block,
            rows & ~(np.isfinite(x) & (x > 0)),
            f"spectral value must be a finite number > 0 [{unit}]",
        )
    with np.errstate(divide="ignore", invalid="ignore"):
        if unit == "nm":
            return x
        if unit == "eV":
            return WVASE_HC_EV_NM / x
        if unit == "Angstrom":
            return x / 10.0
        if unit == "um":
            return x * 1000.0
        if unit == "cm-1":
            return 1e7 / x
    raise AssertionError(unit)  # pragma: no cover


def ascii_head(raw: bytes, nlines: int) -> str:
    """The first ``nlines`` LF-ended lines of an ASCII file, decoded (all of it if shorter).

    Ends right after an LF, so a CRLF is never split; lone-CR files give at least as many
    lines. Enough for :func:`read_header`, which looks at the first 7 lines.
    """
    pos = -1
    for _ in range(nlines):
        pos = raw.find(b"\n", pos + 1)
        if pos < 0:
            return raw.decode("ascii")
    return raw[: pos + 1].decode("ascii")
