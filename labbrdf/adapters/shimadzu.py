"""Shimadzu UVProbe exports: the ASCII text export (``.txt``) and the binary ``.spc``.

Text export (``shimadzu-uvprobe-text``)
    One block per data set: a quoted title line (``"sa281-02-280K - RawData"``: file and data
    set name), a quoted column header ``"Wavelength nm."`` then the ordinate label, then one
    ``wavelength<TAB>value`` row per point. UVProbe writes numbers in the Windows locale, so
    a German installation writes decimal commas (``300,00<TAB>0,322``); with TAB separators
    both decimal marks are read. A comma-separated export must use decimal points (a comma
    cannot be both). Ordinate labels: ``"Abs."`` -> ``absorbance``; ``"%T"`` ->
    ``transmittance`` and ``"%R"`` -> ``reflectance`` (percent, divided by 100). Other labels
    (``"Energy"``, single-beam intensity) have no dataset quantity and are refused by name.

Binary ``.spc`` (``shimadzu-uvprobe-spc``)
    Not a Galactic SPC, although it has the same extension: an OLE2 compound document (see
    ``labbrdf.adapters._ole2``). Layout, established on the shared sample and its text
    export (values agree to the 3 decimals of the text):

    * ``DataStorage1/DataSetGroup/DataSet<k>/`` holds data set ``k`` (1, 2, ...);
    * ``.../DataSpectrumStorage/Data/X Data.1`` and ``Y Data.1``: the abscissa [nm] and the
      ordinate as little-endian float64 arrays of equal length (UVProbe stores the scan in
      acquisition order, e.g. 900 down to 300 nm);
    * ``.../DataSpectrumStorage/Data/Data Header.1``: int32 point count, int32 (2);
    * ``.../DataSpectrumStorage/DataHeader/Header Info``: float64 start and end wavelength
      [nm] and the sampling interval;
    * ``.../MethodStorage/PageTexts<i>``: the method's property pages as length-prefixed
      (one byte) strings, label then value; ``Measuring Mode:`` is ``Absorbance``,
      ``Transmittance`` or ``Reflectance`` (the latter two in percent, as UVProbe shows and
      exports them).

    The point count must agree between the header and both arrays, the X axis must be
    strictly monotonic and inside 1 nm to 1 mm, and the header's start and end must be the
    first and last X; otherwise AdapterError names the stream.

Notes
-----
The ``.spc`` layout is not published by Shimadzu; it is decoded here from the stream names
and checked against the text export of the same measurement. A file without the streams
above is refused with "export it as text from UVProbe".
"""

from __future__ import annotations

import os
import re
import struct
from pathlib import Path
from typing import Any

import numpy as np

from ..dataset import Measurement
from ._base import AdapterError, Format, check_count, decode, read_bytes, split_lines
from ._ole2 import ole_names, open_ole2, read_stream
from ._spectro import PERCENT, finish, number, spectrum_frame
from ._truncation import check_last_field, unterminated

__all__ = ["FORMATS", "read_uvprobe_spc", "read_uvprobe_text"]

INSTRUMENT = "shimadzu-uvprobe"

#: ordinate label of the text export -> (quantity, scale)
_TEXT_LABELS: dict[str, tuple[str, float]] = {
    "ABS.": ("absorbance", 1.0),
    "ABS": ("absorbance", 1.0),
    "%T": ("transmittance", PERCENT),
    "%R": ("reflectance", PERCENT),
}
#: ``Measuring Mode:`` of the binary method -> (quantity, scale)
_MODES: dict[str, tuple[str, float]] = {
    "ABSORBANCE": ("absorbance", 1.0),
    "TRANSMITTANCE": ("transmittance", PERCENT),
    "REFLECTANCE": ("reflectance", PERCENT),
}
_X_LABEL = "WAVELENGTH NM."
_HEADER = re.compile(rb'\A(?:\xef\xbb\xbf)?"[^"\r\n]*"\r?\n"Wavelength nm\."[\t,]"')
_HINT = "export it as text from UVProbe (File > Save As, Data Print table as .txt)"
_WAVELENGTH_RANGE_NM = (1.0, 1.0e6)


def _sniff_text(head: bytes) -> bool:
    return _HEADER.match(head) is not None


def _unquote(field: str) -> str:
    s = field.strip()
    return s[1:-1].strip() if len(s) >= 2 and s[0] == s[-1] == '"' else s


def read_uvprobe_text(path: str | os.PathLike[str]) -> Measurement:
    """Read a Shimadzu UVProbe ASCII export (one or several data sets).

    Parameters
    ----------
    path : str or path-like
        The ``.txt`` export.

    Returns
    -------
    Measurement
        One spectrum per data set (``sample`` = its title line) against wavelength [nm].

    Raises
    ------
    AdapterError
        A block without the quoted title and ``"Wavelength nm."`` header, an unknown
        ordinate label, a row that is not two numbers, or repeated wavelengths; the message
        gives the line.
    """
    raw = read_bytes(path)
    text, encoding = decode(raw, path, ("utf-8", "cp1252"))
    lines = split_lines(text)
    cut_at_end = unterminated(text)
    frames, dropped = [], 0
    blocks: list[dict[str, Any]] = []
    notes: list[str] = []
    n = 0
    while n < len(lines):
        if not lines[n].strip():
            n += 1
            continue
        title_line = n + 1
        title = lines[n].strip()
        if not (len(title) >= 2 and title[0] == title[-1] == '"'):
            raise AdapterError(
                path,
                f'expected a quoted data set title ("name - RawData"), found {title[:40]!r}',
                title_line,
            )
        title = _unquote(title)
        if n + 1 >= len(lines):
            raise AdapterError(
                path, 'the file ends after the title: expected the "Wavelength nm." header', n + 1
            )
        header = lines[n + 1]
        sep = "\t" if "\t" in header else ","
        cols = [_unquote(c) for c in header.split(sep)]
        if len(cols) != 2 or cols[0].upper() != _X_LABEL:
            raise AdapterError(
                path,
                f'expected the header "Wavelength nm." and one ordinate label, found '
                f"{header[:60]!r}",
                n + 2,
            )
        label = cols[1]
        if label.upper() not in _TEXT_LABELS:
            raise AdapterError(
                path,
                f"ordinate {label!r} has no labbrdf quantity; expected one of "
                '"Abs.", "%T", "%R" (export the spectrum in one of these modes)',
                n + 2,
            )
        quantity, scale = _TEXT_LABELS[label.upper()]
        n += 2
        xs: list[float] = []
        ys: list[float] = []
        first_row = n + 1
        while n < len(lines) and lines[n].strip() and not lines[n].lstrip().startswith('"'):
            if n == len(lines) - 1 and cut_at_end:
                note = check_last_field(path, lines[n], lines[first_row - 1 : n], n + 1, sep)
                notes.extend([note] if note else [])
            fields = lines[n].strip().split(sep)
            if len(fields) != 2:
                raise AdapterError(
                    path,
                    f"expected 2 fields (wavelength, {label}) separated by "
                    f"{'TAB' if sep == chr(9) else 'comma'}, found {len(fields)}",
                    n + 1,
                )
            if sep == "\t":
                fields = [f.replace(",", ".", 1) if "." not in f else f for f in fields]
            xs.append(number(fields[0], path, n + 1, "wavelength"))
            ys.append(number(fields[1], path, n + 1, label))
            check_count(path, "rows", len(xs), line=n + 1)
            n += 1
        if not xs:
            raise AdapterError(path, f"data set {title!r} has no data rows", first_row)
        x = np.asarray(xs)
        _check_axis(path, x, first_row)
        _check_repeat(path, blocks, title, label, x, title_line)
        frame, d = spectrum_frame(
            path=path,
            sample=title or Path(path).stem,
            instrument=INSTRUMENT,
            quantity=quantity,
            scale=scale,
            x_nm=x,
            y=ys,
        )
        frames.append(frame)
        dropped += d
        blocks.append(
            {"title": title, "line": title_line, "ordinate": label, "points": len(xs), "x": x}
        )
    if not frames:
        raise AdapterError(path, "no data set in the file")
    meta: dict[str, Any] = {
        "format": "shimadzu-uvprobe-text",
        "encoding": encoding,
        "blocks": [{k: v for k, v in b.items() if k != "x"} for b in blocks],
        "dropped_points": dropped,
    }
    if notes:
        meta["warnings"] = notes
    return finish(path, frames, meta)


def _check_repeat(
    path: str | os.PathLike[str],
    blocks: list[dict[str, Any]],
    title: str,
    label: str,
    x: np.ndarray,
    line: int,
) -> None:
    """Refuse a data set that repeats an earlier one's title, ordinate and wavelengths.

    Two such blocks would merge into one spectrum with every wavelength twice: the file is
    two exports of the same data set joined (``cat a.txt a.txt``), not two data sets.
    """
    for b in blocks:
        if b["title"] == title and b["ordinate"].upper() == label.upper():
            if np.intersect1d(b["x"], x).size:
                raise AdapterError(
                    path,
                    f"data set {title!r} ({label}) starting here repeats the data set of line "
                    f"{b['line']} (same title, ordinate and wavelengths): two exports joined "
                    "into one file? Keep one copy, or give each data set its own title",
                    line,
                )


def _check_axis(path: str | os.PathLike[str], x: np.ndarray, line: int) -> None:
    """Wavelengths strictly monotonic and within the optical range, or AdapterError."""
    lo, hi = _WAVELENGTH_RANGE_NM
    bad = np.flatnonzero(~((x >= lo) & (x <= hi)))
    if bad.size:
        raise AdapterError(
            path,
            f"wavelength {x[bad[0]]:g} nm is outside {lo:g} to {hi:g} nm",
            line + int(bad[0]),
        )
    if x.size > 1:
        step = np.diff(x)
        sign = 1.0 if step[0] > 0 else -1.0
        k = np.flatnonzero(step * sign <= 0)
        if k.size:
            raise AdapterError(
                path,
                f"wavelength {x[k[0] + 1]:g} nm repeats or breaks the scan order: wavelengths "
                "must be strictly increasing or decreasing",
                line + int(k[0]) + 1,
            )


# ----------------------------------------------------------------------------- binary

_SET = "DataStorage1/DataSetGroup/DataSet{k}"
_WHAT = "Shimadzu UVProbe .spc"


def _sniff_spc(head: bytes) -> bool:
    return ole_names(head, "DataSpectrumStorage")


def _pascal_strings(data: bytes) -> list[str]:
    """Length-prefixed (one byte) strings of a PageTexts stream, after its 8-byte prefix."""
    out: list[str] = []
    i = 8
    while i < len(data):
        n = data[i]
        chunk = data[i + 1 : i + 1 + n]
        if len(chunk) < n:
            break
        out.append(chunk.decode("cp1252", errors="replace"))
        i += 1 + n
        if len(out) == 1 and i + 4 <= len(data):  # the page title is followed by an int32
            i += 4
    return out


def _method(ole: Any, path: str | os.PathLike[str], base: str) -> dict[str, str]:
    """The ``label: value`` pairs of the method's property pages."""
    props: dict[str, str] = {}
    for name in sorted(ole.listdir(streams=True, storages=False)):
        if name[:-1] != [*base.split("/"), "MethodStorage"]:
            continue
        if not name[-1].startswith("PageTexts"):
            continue
        strings = _pascal_strings(read_stream(ole, path, "/".join(name), _WHAT))
        for label, value in zip(strings[1::2], strings[2::2], strict=False):
            props[label.rstrip(":").strip()] = value.strip()
    return props


def _f8(data: bytes, path: str | os.PathLike[str], stream: str) -> np.ndarray:
    if len(data) % 8:
        raise AdapterError(
            path, f"{_WHAT}: stream {stream!r} is {len(data)} bytes, not a float64 array"
        )
    with np.errstate(invalid="ignore"):
        return np.frombuffer(data, "<f8").astype(float)


def read_uvprobe_spc(path: str | os.PathLike[str]) -> Measurement:
    """Read a Shimadzu UVProbe binary ``.spc`` (OLE2 compound document).

    Parameters
    ----------
    path : str or path-like
        The ``.spc`` file.

    Returns
    -------
    Measurement
        One spectrum per data set (``sample`` = file stem, ``#k`` appended when there are
        several) against wavelength [nm].

    Raises
    ------
    AdapterError
        Not an OLE2 file, missing streams, inconsistent point counts, an unknown measuring
        mode or a broken X axis; the message names the stream.
    """
    read_bytes(path)  # regular, non-empty file
    with open_ole2(path, _WHAT) as ole:
        sets = sorted(
            {
                int(m.group(1))
                for e in ole.listdir(streams=True, storages=True)
                if len(e) >= 3
                and e[:2] == ["DataStorage1", "DataSetGroup"]
                and (m := re.fullmatch(r"DataSet(\d+)", e[2]))
            }
        )
        if not sets:
            raise AdapterError(
                path,
                f"{_WHAT}: an OLE2 compound document without the UVProbe data storage "
                f"(DataStorage1/DataSetGroup/DataSet1); {_HINT}",
            )
        frames, infos, dropped = [], [], 0
        for k in sets:
            base = _SET.format(k=k)
            frame, d, info = _data_set(
                ole, path, base, f"{Path(path).stem}" + (f" #{k}" if len(sets) > 1 else "")
            )
            frames.append(frame)
            infos.append(info)
            dropped += d
        meta: dict[str, Any] = {
            "format": "shimadzu-uvprobe-spc",
            "data_sets": infos,
            "dropped_points": dropped,
        }
    return finish(path, frames, meta)


def _data_set(
    ole: Any, path: str | os.PathLike[str], base: str, sample: str
) -> tuple[Any, int, dict[str, Any]]:
    data = f"{base}/DataSpectrumStorage/Data"
    names = {
        "header": f"{data}/Data Header.1",
        "x": f"{data}/X Data.1",
        "y": f"{data}/Y Data.1",
        "info": f"{base}/DataSpectrumStorage/DataHeader/Header Info",
    }
    for name in names.values():
        if not ole.exists(name):
            raise AdapterError(path, f"{_WHAT}: no stream {name!r}; {_HINT}")
    head = read_stream(ole, path, names["header"], _WHAT)
    if len(head) < 4:
        raise AdapterError(path, f"{_WHAT}: stream {names['header']!r} is shorter than 4 bytes")
    (npoints,) = struct.unpack_from("<i", head, 0)
    if npoints <= 0:
        raise AdapterError(
            path, f"{_WHAT}: point count {npoints} in {names['header']!r}: expected > 0"
        )
    check_count(path, f"point count of {names['header']!r}", npoints)
    x = _f8(read_stream(ole, path, names["x"], _WHAT), path, names["x"])
    y = _f8(read_stream(ole, path, names["y"], _WHAT), path, names["y"])
    for key, arr in (("x", x), ("y", y)):
        if arr.size != npoints:
            raise AdapterError(
                path,
                f"{_WHAT}: stream {names[key]!r} holds {arr.size} values but the data "
                f"header says {npoints} points (truncated or corrupt)",
            )
    info = read_stream(ole, path, names["info"], _WHAT)
    if len(info) < 24:
        raise AdapterError(path, f"{_WHAT}: stream {names['info']!r} is shorter than 24 bytes")
    start, end, interval = struct.unpack_from("<3d", info, 0)
    if not np.all(np.isfinite(x)):
        raise AdapterError(path, f"{_WHAT}: non-finite wavelengths in {names['x']!r}")
    lo, hi = _WAVELENGTH_RANGE_NM
    if not (x.min() >= lo and x.max() <= hi):
        raise AdapterError(
            path,
            f"{_WHAT}: wavelengths {x.min():.6g} to {x.max():.6g} nm in {names['x']!r} are "
            f"outside {lo:g} to {hi:g} nm (corrupt stream?)",
        )
    step = np.diff(x)
    if x.size > 1 and not (np.all(step > 0) or np.all(step < 0)):
        raise AdapterError(
            path, f"{_WHAT}: the wavelengths of {names['x']!r} are not strictly monotonic"
        )
    for what, want, got in (("start", start, x[0]), ("end", end, x[-1])):
        if not abs(want - got) <= 1e-6 * max(1.0, abs(want)):
            raise AdapterError(
                path,
                f"{_WHAT}: the {what} wavelength {want:g} nm of {names['info']!r} disagrees "
                f"with {got:g} nm in {names['x']!r}",
            )
    props = _method(ole, path, base)
    mode = props.get("Measuring Mode", "")
    if mode.upper() not in _MODES:
        raise AdapterError(
            path,
            f"{_WHAT}: measuring mode {mode!r} (method property 'Measuring Mode:') has no "
            f"labbrdf quantity; expected one of {sorted(m.title() for m in _MODES)}",
        )
    quantity, scale = _MODES[mode.upper()]
    frame, dropped = spectrum_frame(
        path=path,
        sample=sample,
        instrument=INSTRUMENT,
        quantity=quantity,
        scale=scale,
        x_nm=x,
        y=y,
    )
    return (
        frame,
        dropped,
        {
            "storage": base,
            "points": int(npoints),
            "start_nm": float(start),
            "end_nm": float(end),
            "interval_nm": float(interval),
            "measuring_mode": mode,
            "method": props,
        },
    )


FORMATS = (
    Format(
        "shimadzu-uvprobe-text",
        'Shimadzu UVProbe ASCII export ("Wavelength nm." / "Abs.", "%T", "%R"; decimal commas)',
        (".txt", ".csv"),
        _sniff_text,
        read_uvprobe_text,
        ("absorbance", "transmittance", "reflectance"),
        keywords=(b'"Wavelength nm."',),
    ),
    Format(
        "shimadzu-uvprobe-spc",
        "Shimadzu UVProbe binary .spc (OLE2 compound document)",
        (".spc",),
        _sniff_spc,
        read_uvprobe_spc,
        ("absorbance", "transmittance", "reflectance"),
        keywords=("DataSpectrumStorage".encode("utf-16-le"),),
    ),
)
