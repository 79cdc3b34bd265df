"""Zemax / Radiant "BSDF Data Interchange" tabular text files (``.bsdf``): the reader.

The format (Radiant Imaging, "BSDF Data Interchange File Format Specification", 2008; the
"Zemax Tabular BSDF data file format" article of the Zemax knowledge base) is a header::

    #<comment lines anywhere>
    Source  Measured
    Symmetry  PlaneSymmetrical | Asymmetrical | Asymmetrical4D
    SpectralContent  Monochrome | XYZ
    ScatterType  BRDF | BTDF
    SampleRotation  <n>         then n rotations [deg]
    AngleOfIncidence  <n>       then n angles [deg]
    ScatterAzimuth  <n>         then n azimuths [deg]
    ScatterRadial  <n>          then n radial angles [deg]

followed, per spectral channel (``Monochrome``, or ``TristimulusX``, ``TristimulusY``,
``TristimulusZ``), by the channel's name, ``DataBegin``, then for every sample rotation and
every angle of incidence (rotation outermost) a ``TIS <value>`` line and one row per azimuth
with one value per radial angle, and an optional ``DataEnd``. Cells are separated by tabs or
spaces.

Geometry (see ``docs/bsdf.md``; the functions are in :mod:`labbrdf.bsdf_geometry`): the
scatter angles are given about the specular direction (the direction of direct transmission
for BTDF): radial 0 is the specular direction, azimuth 0 points from the specular direction
towards the sample normal, azimuths increase counter-clockwise. The specification does not
say from which side "counter-clockwise" is seen; labbrdf takes it as seen by an observer
looking back at the sample along the specular direction, so azimuth 90 is the +y side when
the source is at phi_i = 0. Every point is converted exactly (unit vectors, no small-angle
approximation) to the dataset's ``theta_i_deg``, ``theta_r_deg``, ``phi_r_deg``.
The writer is :mod:`labbrdf.writers.zemax`; the grid quadrature is
:func:`labbrdf.integrate.grid_integral`.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..bsdf_geometry import (
    SYMMETRIES,
    angles_to_scatter,
    azimuth_weights,
    scatter_to_angles,
    scatter_to_direction,
)
from ..dataset import Measurement
from ._base import AdapterError, Format, decode, read_bytes, split_lines
from ._numblock import build_frame

__all__ = [
    "FORMATS",
    "BsdfTable",
    "angles_to_scatter",
    "grid_integral",
    "mirror_plane_symmetric",
    "read_table",
    "read_zemax_bsdf",
    "scatter_to_angles",
    "scatter_to_direction",
    "stated_wavelength",
]

INSTRUMENT = "zemax-bsdf"
SPECTRAL = {"Monochrome": ("Monochrome",), "XYZ": ("TristimulusX", "TristimulusY", "TristimulusZ")}
#: channel column value per section name (Monochrome files have no channel column)
_CHANNEL = {"Monochrome": "", "TristimulusX": "X", "TristimulusY": "Y", "TristimulusZ": "Z"}
SCATTER_TYPES = {"BRDF": "brdf", "BTDF": "btdf"}

#: Wavelength written in the dataset when the file states none [nm]: the photopic peak.
#: The format has no wavelength field; Monochrome data of the imaging sphere are luminance
#: (photopic) data and XYZ data are tristimulus values, so 555 nm is a label, not a
#: measurement. ``meta["wavelength_stated"]`` is False; pass ``wavelength_nm=`` to override.
DEFAULT_WAVELENGTH_NM = 555.0

#: Hard caps: values per list, and values in the whole file.
MAX_LIST = 100_000
MAX_POINTS = 50_000_000

#: The header's list keywords, in the order the writer puts them.
HEADER_LISTS = ("SampleRotation", "AngleOfIncidence", "ScatterAzimuth", "ScatterRadial")
_HEADER_WORDS = ("Source", "Symmetry", "SpectralContent", "ScatterType")
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)
_INT = re.compile(r"\+?\d+", re.ASCII)
_NOT_NUMERIC = re.compile(r"[^0-9eE+\-. \t\n]")
_SNIFF = re.compile(rb"^\s*(Source|Symmetry|SpectralContent|ScatterType)\s", re.MULTILINE)


# ------------------------------------------------------------------------------ table


@dataclass
class BsdfTable:
    """The numbers of a ``.bsdf`` file on its own grid.

    Attributes
    ----------
    symmetry, spectral, scatter_type : str
        Header keywords (``spectral`` is ``Monochrome`` or ``XYZ``).
    rotation_deg, theta_i_deg, azimuth_deg, radial_deg : ndarray
        The header lists [deg].
    values : ndarray
        ``(rotation, channel, aoi, azimuth, radial)`` BSDF [sr^-1], as written (values
        below the horizon included).
    tis : ndarray
        ``(rotation, channel, aoi)`` total integrated scatter from the ``TIS`` lines.
    comments : list of str
        Comment lines (without ``#``).
    source : str
        The ``Source`` keyword.
    wavelength_nm : float or None
        The wavelength a comment states [nm] (see :func:`stated_wavelength`), else None.
    """

    symmetry: str
    spectral: str
    scatter_type: str
    rotation_deg: NDArray[np.float64]
    theta_i_deg: NDArray[np.float64]
    azimuth_deg: NDArray[np.float64]
    radial_deg: NDArray[np.float64]
    values: NDArray[np.float64]
    tis: NDArray[np.float64]
    comments: list[str] = field(default_factory=list)
    source: str = "Measured"
    wavelength_nm: float | None = None

    @property
    def channels(self) -> tuple[str, ...]:
        """Section names: ``("Monochrome",)`` or ``("TristimulusX", ...)``."""
        return SPECTRAL[self.spectral]


class _Lines:
    """Cursor over the significant lines (not blank, not ``#``) with their 1-based numbers."""

    def __init__(self, lines: list[str]) -> None:
        self.items = [(n, s) for n, s in ((i + 1, ln.strip()) for i, ln in enumerate(lines)) if s]
        self.comment_lines = [(n, s[1:].strip()) for n, s in self.items if s.startswith("#")]
        self.comments = [c for _, c in self.comment_lines]
        self.items = [(n, s) for n, s in self.items if not s.startswith("#")]
        self.pos = 0

    def peek(self) -> tuple[int, str] | None:
        return self.items[self.pos] if self.pos < len(self.items) else None

    def next(self) -> tuple[int, str] | None:
        item = self.peek()
        self.pos += item is not None
        return item

    def last_line(self) -> int | None:
        return self.items[-1][0] if self.items else None


def _num(path: str | os.PathLike[str], text: str, line: int, what: str) -> float:
    """One finite ASCII decimal number, else AdapterError."""
    if not _NUMBER.fullmatch(text):
        raise AdapterError(path, f"{what}: expected an ASCII decimal number, found {text!r}", line)
    v = float(text)
    if not math.isfinite(v):
        raise AdapterError(path, f"{what}: {text!r} is not a finite number", line)
    return v


def _count(path: str | os.PathLike[str], text: str, line: int, key: str) -> int:
    if not _INT.fullmatch(text):
        raise AdapterError(path, f"{key}: expected a count (ASCII integer), found {text!r}", line)
    n = int(text)
    if not 1 <= n <= MAX_LIST:
        raise AdapterError(path, f"{key}: count {n} outside 1..{MAX_LIST}", line)
    return n


def _header_list(
    path: str | os.PathLike[str], cur: _Lines, key: str, n: int, rest: list[str], line: int
) -> NDArray[np.float64]:
    """The ``n`` numbers after a list keyword (same line or following lines)."""
    toks: list[tuple[int, str]] = [(line, t) for t in rest]
    while len(toks) < n:
        item = cur.peek()
        if item is None or not _NUMBER.match(item[1].split()[0]):
            found = len(toks)
            raise AdapterError(
                path, f"{key} {n}: expected {n} values, found {found}", item[0] if item else line
            )
        cur.next()
        toks.extend((item[0], t) for t in item[1].split())
    if len(toks) != n:
        raise AdapterError(path, f"{key} {n}: expected {n} values, found {len(toks)}", toks[-1][0])
    return np.array([_num(path, t, ln, key) for ln, t in toks])


def _check_list(
    path: str | os.PathLike[str], key: str, a: NDArray[np.float64], lo: float, hi: float
) -> None:
    if a.min() < lo or a.max() > hi:
        raise AdapterError(path, f"{key}: values must lie in [{lo:g}, {hi:g}] deg")
    if a.size > 1 and not np.all(np.diff(a) > 0):
        raise AdapterError(path, f"{key}: values must be strictly increasing")


def _parse_header(path: str | os.PathLike[str], cur: _Lines) -> dict[str, Any]:
    head: dict[str, Any] = {}
    while True:
        item = cur.peek()
        if item is None:
            raise AdapterError(path, "no data section: expected 'Monochrome' or 'TristimulusX'")
        n, s = item
        key, *rest = s.split()
        if key in SPECTRAL["Monochrome"] + SPECTRAL["XYZ"] or key == "DataBegin":
            break
        cur.next()
        if key in head:
            raise AdapterError(path, f"header keyword {key!r} given twice", n)
        if key in _HEADER_WORDS:
            if len(rest) != 1:
                raise AdapterError(path, f"{key}: expected one keyword after it", n)
            head[key] = (rest[0], n)
        elif key in HEADER_LISTS:
            if not rest:
                raise AdapterError(path, f"{key}: expected a count after it", n)
            count = _count(path, rest[0], n, key)
            head[key] = _header_list(path, cur, key, count, rest[1:], n)
        else:
            raise AdapterError(
                path,
                f"unknown header keyword {key!r}; expected one of "
                f"{list(_HEADER_WORDS + HEADER_LISTS)}",
                n,
            )
    return head


def _keyword(
    path: str | os.PathLike[str], head: dict[str, Any], key: str, allowed: Iterable[str]
) -> str:
    if key not in head:
        raise AdapterError(path, f"missing header line '{key} <{'|'.join(allowed)}>'")
    word, n = head[key]
    # the specification spells "ASymmetrical" in one place: accept either capitalisation
    canon = {a.lower(): a for a in allowed}
    if word.lower() not in canon or (key != "Symmetry" and word not in canon.values()):
        raise AdapterError(
            path, f"{key}: unknown keyword {word!r}; expected one of {list(allowed)}", n
        )
    return canon[word.lower()]


def _check_size(path: str | os.PathLike[str], shape: tuple[int, ...], nbytes: int) -> None:
    total = math.prod(shape)
    # every value needs at least one digit and one separator
    if total > MAX_POINTS or 2 * total > nbytes:
        raise AdapterError(
            path,
            f"the header announces {total} values ({' x '.join(map(str, shape))}), more than "
            f"the file of {nbytes} bytes can hold (or the cap of {MAX_POINTS})",
        )


def _block_rows(
    path: str | os.PathLike[str], cur: _Lines, nrows: int, ncols: int, where: str
) -> tuple[list[str], list[int]]:
    rows: list[str] = []
    lines: list[int] = []
    for _ in range(nrows):
        item = cur.peek()
        if item is None or not _is_data(item[1]):
            raise AdapterError(
                path,
                f"{where}: expected {nrows} rows of {ncols} values, found {len(rows)} rows",
                item[0] if item else cur.last_line(),
            )
        cur.next()
        rows.append(item[1])
        lines.append(item[0])
    return rows, lines


_STRUCTURE = ("TIS", "DataBegin", "DataEnd", *SPECTRAL["Monochrome"], *SPECTRAL["XYZ"])


def _is_data(s: str) -> bool:
    """Any line but a structure keyword is a data row (its numbers are checked later)."""
    return s.split(None, 1)[0] not in _STRUCTURE


def _parse_numbers(
    path: str | os.PathLike[str], rows: list[str], lines: list[int], ncols: int
) -> NDArray[np.float64]:
    """Vectorised parse of rows of ``ncols`` numbers; strict, with the line of any error."""
    text = "\n".join(rows)
    bad = _NOT_NUMERIC.search(text)
    if bad is not None:
        i = text.count("\n", 0, bad.start())
        raise AdapterError(
            path, f"expected numbers, found the character {bad.group()!r}", lines[i]
        )
    counts = np.fromiter((len(r.split()) for r in rows), dtype=np.int64, count=len(rows))
    wrong = np.flatnonzero(counts != ncols)
    if wrong.size:
        i = int(wrong[0])
        raise AdapterError(
            path, f"expected {ncols} values in the row, found {counts[i]}", lines[i]
        )
    toks = text.split()
    try:
        vals = np.array(toks, dtype=np.float64)
    except ValueError:
        vals = None
    if vals is None or not np.isfinite(vals).all():
        for row, ln in zip(rows, lines, strict=True):
            for t in row.split():
                _num(path, t, ln, "value")
        raise AdapterError(path, "unreadable numbers in the data section")  # pragma: no cover
    return vals.reshape(len(rows), ncols)


def _parse_data(path: str | os.PathLike[str], cur: _Lines, t: BsdfTable) -> None:
    nrot, nch, naoi, naz, nrad = t.values.shape
    for c, name in enumerate(t.channels):
        item = cur.next()
        if item is None or item[1] != name:
            raise AdapterError(
                path,
                f"expected the section line {name!r}",
                item[0] if item else cur.last_line(),
            )
        item = cur.next()
        if item is None or item[1] != "DataBegin":
            raise AdapterError(path, "expected 'DataBegin'", item[0] if item else cur.last_line())
        rows: list[str] = []
        lines: list[int] = []
        for k in range(nrot * naoi):
            r, a = divmod(k, naoi)
            where = (
                f"{name} block {k + 1} (rotation {t.rotation_deg[r]:g}, "
                f"incidence {t.theta_i_deg[a]:g})"
            )
            item = cur.next()
            parts = item[1].split() if item else []
            if not parts or parts[0] != "TIS" or len(parts) != 2:
                found = "end of file" if item is None else repr(item[1][:40])
                raise AdapterError(
                    path,
                    f"{where}: expected 'TIS <value>' followed by {naz} rows of {nrad} values, "
                    f"found {found}",
                    item[0] if item else cur.last_line(),
                )
            assert item is not None  # parts is empty without an item
            t.tis[r, c, a] = _num(path, parts[1], item[0], "TIS")
            br, bl = _block_rows(path, cur, naz, nrad, where)
            rows += br
            lines += bl
        vals = _parse_numbers(path, rows, lines, nrad).reshape(nrot, naoi, naz, nrad)
        t.values[:, c] = vals
        item = cur.peek()
        if item is not None and item[1] == "DataEnd":
            cur.next()
    item = cur.peek()
    if item is not None:
        raise AdapterError(
            path, f"expected the end of the file after the data, found {item[1][:40]!r}", item[0]
        )


def read_table(path: str | os.PathLike[str]) -> BsdfTable:
    """Read a ``.bsdf`` file into a :class:`BsdfTable` (its own grid, nothing dropped).

    Raises
    ------
    AdapterError
        A header whose counts do not match its lists, a missing or unknown keyword, a block
        with the wrong number of rows or values, a non-number (ASCII decimals only), NaN or
        infinity, a missing ``DataBegin``, or more values announced than the file can hold.
    """
    raw = read_bytes(path)
    text, _ = decode(raw, path)
    cur = _Lines(split_lines(text))
    head = _parse_header(path, cur)
    symmetry = _keyword(path, head, "Symmetry", SYMMETRIES)
    spectral = _keyword(path, head, "SpectralContent", tuple(SPECTRAL))
    scatter = _keyword(path, head, "ScatterType", tuple(SCATTER_TYPES))
    for key in HEADER_LISTS[1:]:
        if key not in head:
            raise AdapterError(path, f"missing header line '{key} <count>' and its values")
    rot = head.get("SampleRotation", np.zeros(1))
    aoi, az, rad = (head[k] for k in HEADER_LISTS[1:])
    _check_list(path, "SampleRotation", rot, -360.0, 360.0)
    _check_list(path, "AngleOfIncidence", aoi, 0.0, 90.0)
    _check_list(path, "ScatterAzimuth", az, 0.0, 180.0 if symmetry == SYMMETRIES[0] else 360.0)
    _check_list(path, "ScatterRadial", rad, 0.0, 180.0)
    shape = (rot.size, len(SPECTRAL[spectral]), aoi.size, az.size, rad.size)
    _check_size(path, shape, len(raw))
    t = BsdfTable(
        symmetry=symmetry,
        spectral=spectral,
        scatter_type=scatter,
        rotation_deg=rot,
        theta_i_deg=aoi,
        azimuth_deg=az,
        radial_deg=rad,
        values=np.empty(shape),
        tis=np.empty(shape[:3]),
        comments=cur.comments,
        source=head["Source"][0] if "Source" in head else "",
        wavelength_nm=stated_wavelength(path, cur.comment_lines),
    )
    _parse_data(path, cur, t)
    return t


# ------------------------------------------------------------------------------ reader


def _pole_repeats(shape: tuple[int, ...], radial_deg: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The grid points that repeat the pole: radial 0 at every azimuth but the first.

    At radial angle 0 every azimuth names the same direction (the specular one, or that of
    direct transmission), so the file writes that one point once per azimuth.
    """
    rep = np.zeros(shape, dtype=bool)
    if radial_deg.size and radial_deg[0] == 0.0:
        rep[..., 1:, 0] = True
    return rep


def _table_frame(
    t: BsdfTable, path: str | os.PathLike[str], wavelength_nm: float
) -> tuple[pd.DataFrame, int, int]:
    """Rows above the horizon in the dataset schema, and the counts left out.

    Returns the frame, the number of points below the horizon, and the number of repeated
    pole points (the pole is one row per block).
    """
    nrot, nch, naoi, naz, nrad = t.values.shape
    full = t.values.shape
    theta_r, phi_r, above_f = (
        np.broadcast_to(x, full).reshape(-1)
        for x in scatter_to_angles(
            t.theta_i_deg[:, None, None], t.radial_deg[None, None, :], t.azimuth_deg[None, :, None]
        )
    )
    above = np.asarray(above_f, dtype=bool)
    repeat = _pole_repeats(full, t.radial_deg).reshape(-1)
    keep = np.flatnonzero(above & ~repeat)
    values = t.values.copy()
    if repeat.any():
        # one value for the one direction: the file's, or, where the azimuths of a block
        # disagree, their mean weighted by the azimuth cells (the average over the polar
        # cap, so grid_integral is unchanged; meta["pole"] reports the largest spread)
        pole = values[..., 0]
        w = azimuth_weights(t.azimuth_deg, t.symmetry)
        values[..., 0, 0] = np.where(
            np.all(pole == pole[..., :1], axis=-1), pole[..., 0], (pole @ w) / w.sum()
        )
    ti = np.broadcast_to(t.theta_i_deg[:, None, None], full).reshape(-1)
    optional: dict[str, Any] = {}
    if nrot > 1 or t.rotation_deg[0] != 0:
        optional["sample_rotation_deg"] = np.repeat(t.rotation_deg, nch * naoi * naz * nrad)[keep]
    if t.spectral == "XYZ":
        codes = np.repeat(np.tile(np.arange(nch, dtype=np.int8), nrot), naoi * naz * nrad)
        optional["channel"] = pd.Categorical.from_codes(codes[keep], categories=["X", "Y", "Z"])
    frame = build_frame(
        sample=Path(path).stem,
        instrument=INSTRUMENT,
        source=os.path.basename(os.fspath(path)),
        quantity=SCATTER_TYPES[t.scatter_type],
        value=values.reshape(-1)[keep],
        unit="sr-1",
        wavelength_nm=wavelength_nm,
        theta_i_deg=ti[keep],
        theta_r_deg=theta_r[keep],
        phi_r_deg=phi_r[keep],
        **optional,
    )
    return frame, int((~above).sum()), int((above & repeat).sum())


def _pole_meta(t: BsdfTable, repeats: int) -> dict[str, Any]:
    """What became of the pole (radial 0) points: one row kept per block."""
    if not repeats:
        return {"repeats_left_out": 0}
    pole = t.values[..., 0]
    spread = np.max(np.abs(pole - pole[..., :1]))
    return {
        "repeats_left_out": repeats,
        "rule": "radial 0 is one direction at every azimuth: one row per incidence (and "
        "rotation, channel), with the file's value, or, where the azimuths' values differ, "
        "their mean weighted by the azimuth cell widths",
        "max_spread_sr-1": float(spread),
    }


def _tis_meta(t: BsdfTable) -> list[dict[str, Any]]:
    out = []
    for r, rot in enumerate(t.rotation_deg):
        for c, name in enumerate(t.channels):
            for a, ti in enumerate(t.theta_i_deg):
                out.append(
                    {
                        "theta_i_deg": float(ti),
                        "rotation_deg": float(rot),
                        "channel": _CHANNEL[name],
                        "tis": float(t.tis[r, c, a]),
                    }
                )
    return out


def read_zemax_bsdf(
    path: str | os.PathLike[str], *, wavelength_nm: float | None = None
) -> Measurement:
    """Read a Zemax / Radiant ``.bsdf`` tabular file into a :class:`Measurement`.

    Parameters
    ----------
    path : str or path-like
        The file.
    wavelength_nm : float, optional
        Wavelength to record [nm]. The format has no wavelength field: by default the one a
        comment states (:func:`stated_wavelength`), else :data:`DEFAULT_WAVELENGTH_NM`
        (555 nm, a photopic label) with ``meta["wavelength_stated"]`` False.

    Returns
    -------
    Measurement
        One row per grid point above the horizon, the pole (radial 0, the same direction
        at every azimuth) once per incidence: quantity ``brdf`` or ``btdf`` [sr-1],
        ``theta_i_deg``, ``theta_r_deg``, ``phi_r_deg`` from the exact conversion of the
        scatter angles; ``channel`` ``X``/``Y``/``Z`` for tristimulus files;
        ``sample_rotation_deg`` when the file has a rotation other than 0. PlaneSymmetrical
        files keep the measured half only (azimuths 0..180, i.e. phi_r in [0, 180] or 180..,
        see :func:`mirror_plane_symmetric`). ``meta`` holds the header, ``tis`` (one entry
        per block), ``grid`` (the file's lists), ``dropped_below_horizon`` and
        ``zero_values_kept`` (zeros above the horizon, kept as data), ``pole`` (the
        repeated pole points left out) and ``wavelength_stated`` (False when no comment
        states the wavelength: then the 555 nm label is written, see
        :data:`DEFAULT_WAVELENGTH_NM`).

    Raises
    ------
    AdapterError
        See :func:`read_table`.
    """
    t = read_table(path)
    if wavelength_nm is None:
        wavelength_nm = t.wavelength_nm
    stated = wavelength_nm is not None
    wl = float(wavelength_nm) if wavelength_nm is not None else DEFAULT_WAVELENGTH_NM
    if not (math.isfinite(wl) and wl > 0):
        raise AdapterError(path, f"wavelength_nm={wavelength_nm!r}: expected a finite number > 0")
    frame, dropped, repeats = _table_frame(t, path, wl)
    meta: dict[str, Any] = {
        "format": "zemax-bsdf",
        "source_keyword": t.source,
        "symmetry": t.symmetry,
        "spectral_content": t.spectral,
        "scatter_type": t.scatter_type,
        "wavelength_stated": stated,
        "wavelength_nm": wl,
        "grid": {
            "rotation_deg": t.rotation_deg.tolist(),
            "theta_i_deg": t.theta_i_deg.tolist(),
            "azimuth_deg": t.azimuth_deg.tolist(),
            "radial_deg": t.radial_deg.tolist(),
            "channels": [_CHANNEL[c] for c in t.channels],
        },
        "tis": _tis_meta(t),
        "dropped_below_horizon": dropped,
        "pole": _pole_meta(t, repeats),
        "zero_values_kept": int((frame["value"].to_numpy() == 0).sum()),
        "comments": t.comments,
    }
    if t.symmetry == "PlaneSymmetrical":
        meta["mirror"] = (
            "the other half of the scatter hemisphere is the mirror image of the rows given, "
            "phi_r -> 360 - phi_r (see mirror_plane_symmetric)"
        )
    try:
        return Measurement(frame, meta)
    except ValueError as exc:
        raise AdapterError(path, f"invalid data: {exc}") from None


#: comment labbrdf writes for the wavelength of a model it exports (the format has no field)
WAVELENGTH_COMMENT = "labbrdf wavelength_nm "

#: wavelength comments read, ``#labbrdf wavelength_nm 550`` (ours) and ``#Wavelength (nm) =
#: 550.0`` (the Speos-to-Zemax converter's); the value is checked by :func:`_num`
_WAVELENGTH_COMMENTS = re.compile(
    r"(?:labbrdf\s+wavelength_nm|wavelength\s*\(nm\)\s*[=:])\s*(?P<v>\S+)\s*",
    re.IGNORECASE | re.ASCII,
)


def stated_wavelength(
    path: str | os.PathLike[str], comment_lines: Sequence[tuple[int, str]]
) -> float | None:
    """The wavelength [nm] a file's comments state, or None when none does.

    The format has no wavelength field; two comments carry one: ``#labbrdf wavelength_nm W``
    (written by :func:`write_bsdf`) and ``#Wavelength (nm) = W`` (written by the
    Speos-to-Zemax converter).

    Parameters
    ----------
    path : path-like
        The file (for error messages).
    comment_lines : sequence of (int, str)
        ``(line number, comment without '#')``.

    Raises
    ------
    AdapterError
        A wavelength comment whose value is not a number > 0 [nm], or two comments that
        state different wavelengths (the line of the offending comment is named).
    """
    found: float | None = None
    for line, c in comment_lines:
        m = _WAVELENGTH_COMMENTS.fullmatch(c)
        if m is None:
            continue
        w = _num(path, m["v"], line, "wavelength comment")
        if w <= 0:
            raise AdapterError(
                path, f"wavelength comment: expected a wavelength > 0 [nm], found {w:g}", line
            )
        if found is not None and w != found:
            raise AdapterError(
                path,
                f"wavelength comment states {w:g} nm, an earlier one {found:g} nm: "
                "expected one wavelength per file",
                line,
            )
        found = w
    return found


def mirror_plane_symmetric(m: Measurement) -> Measurement:
    """The full hemisphere of a PlaneSymmetrical measurement: rows plus their mirror images.

    Rows off the plane of incidence (0 < phi_r < 180 or 180 < phi_r < 360, and theta_r > 0)
    are copied with ``phi_r -> 360 - phi_r``; rows in the plane are their own mirror image
    and are not duplicated. ``meta["mirrored"]`` is set to the number of rows added.

    Raises
    ------
    ValueError
        ``meta["symmetry"]`` is not ``PlaneSymmetrical`` or the data are already mirrored.
    """
    if m.meta.get("symmetry") != "PlaneSymmetrical":
        raise ValueError("mirror_plane_symmetric needs meta['symmetry'] == 'PlaneSymmetrical'")
    if "mirrored" in m.meta:
        raise ValueError("the measurement is already mirrored")
    d = m.data
    phi = d["phi_r_deg"].to_numpy()
    tol = 1e-9
    in_plane = (
        (np.abs(phi) < tol)
        | (np.abs(phi - 180.0) < tol)
        | (np.abs(phi - 360.0) < tol)
        | (d["theta_r_deg"].to_numpy() < tol)
    )
    extra = d[~in_plane].copy()
    extra["phi_r_deg"] = np.mod(360.0 - extra["phi_r_deg"].to_numpy(), 360.0)
    data = pd.concat(
        [
            d.assign(quantity=d["quantity"].astype(str)),
            extra.assign(quantity=extra["quantity"].astype(str)),
        ],
        ignore_index=True,
    )
    meta = dict(m.meta)
    meta["mirrored"] = int(len(extra))
    return Measurement(data, meta)


# ------------------------------------------------------------------------------ quadrature


def _table_of(obj: BsdfTable | Measurement | Mapping[str, Any]) -> BsdfTable:
    if isinstance(obj, BsdfTable):
        return obj
    if isinstance(obj, Measurement):
        return _table_from_measurement(obj)
    v = np.asarray(obj["values"], dtype=float)
    theta_i = np.atleast_1d(np.asarray(obj["theta_i_deg"], float))
    az = np.atleast_1d(np.asarray(obj["azimuth_deg"], float))
    rad = np.atleast_1d(np.asarray(obj["radial_deg"], float))
    v = v.reshape((-1, v.shape[-4] if v.ndim >= 4 else 1, theta_i.size, az.size, rad.size))
    spectral = "XYZ" if v.shape[1] == 3 else "Monochrome"
    return BsdfTable(
        symmetry=obj.get("symmetry", "Asymmetrical"),
        spectral=spectral,
        scatter_type=obj.get("scatter_type", "BRDF"),
        rotation_deg=np.arange(v.shape[0], dtype=float),
        theta_i_deg=theta_i,
        azimuth_deg=az,
        radial_deg=rad,
        values=v,
        tis=np.full(v.shape[:3], np.nan),
    )


def _table_from_measurement(m: Measurement) -> BsdfTable:
    """Put the rows of a reader's Measurement back on the file's grid (0 below the horizon).

    The reader writes the rows in the file's order (rotation, channel, incidence, azimuth,
    radial), skipping the points below the horizon and the pole's repeats (its one row is
    copied back to every azimuth); this checks that the rows are still
    those (same count, same angles to 1e-9 deg) and refuses a filtered or mirrored table.
    """
    g = m.meta.get("grid")
    if not g:
        raise ValueError("the measurement has no meta['grid'] (not read from a .bsdf file)")
    rot, aoi = np.array(g["rotation_deg"], float), np.array(g["theta_i_deg"], float)
    az, rad = np.array(g["azimuth_deg"], float), np.array(g["radial_deg"], float)
    nch = len(g["channels"])
    shape = (rot.size, nch, aoi.size, az.size, rad.size)
    _, _, ai, zi, qi = np.indices(shape).reshape(5, -1)
    theta_r, phi_r, above = scatter_to_angles(aoi[ai], rad[qi], az[zi])
    repeat = _pole_repeats(shape, rad).reshape(-1)
    if not (m.meta.get("pole") or {}).get("repeats_left_out"):
        repeat[:] = False  # read before the pole was kept once
    kept = above & ~repeat
    d = m.data
    same = len(d) == int(kept.sum()) and "mirrored" not in m.meta
    if same:
        dphi = np.abs(d["phi_r_deg"].to_numpy() - phi_r[kept])
        same = bool(
            np.all(np.abs(d["theta_r_deg"].to_numpy() - theta_r[kept]) < 1e-9)
            and np.all(np.minimum(dphi, 360.0 - dphi) < 1e-9)
            and np.all(d["theta_i_deg"].to_numpy() == aoi[ai[kept]])
        )
    if not same:
        raise ValueError(
            "the rows are not those read from the file (filtered, mirrored or reordered); "
            "pass the BsdfTable of read_table() instead"
        )
    v = np.zeros(shape)
    v.reshape(-1)[kept] = d["value"].to_numpy()
    if repeat.any():
        v[..., 1:, 0] = v[..., :1, 0]  # the pole, at every azimuth of the grid
    return BsdfTable(
        symmetry=m.meta.get("symmetry", "Asymmetrical"),
        spectral=m.meta.get("spectral_content", "Monochrome"),
        scatter_type=m.meta.get("scatter_type", "BRDF"),
        rotation_deg=rot,
        theta_i_deg=aoi,
        azimuth_deg=az,
        radial_deg=rad,
        values=v,
        tis=np.array([e["tis"] for e in m.meta.get("tis", [])] or np.nan, float).reshape(shape[:3])
        if m.meta.get("tis")
        else np.full(shape[:3], np.nan),
    )


def grid_integral(obj: BsdfTable | Measurement | Mapping[str, Any]) -> dict[str, Any]:
    """Hemispherical integral ``int f cos(theta_r) d omega`` of each block on its own grid.

    The ``.bsdf`` face of :func:`labbrdf.integrate.grid_integral`, which holds the
    quadrature rule and its limits.

    Parameters
    ----------
    obj : BsdfTable, Measurement or mapping
        A table from :func:`read_table`, a Measurement from :func:`read_zemax_bsdf`, or a
        mapping with ``values`` ``(rotation, channel, aoi, azimuth, radial)`` [sr^-1],
        ``theta_i_deg``, ``azimuth_deg``, ``radial_deg`` [deg] and optional ``symmetry``.

    Returns
    -------
    dict
        ``integral`` ``(rotation, channel, aoi)`` [1]; ``uncovered_fraction`` ``(aoi,)``: the
        fraction of the projected solid angle of the hemisphere (pi sr) that the grid does
        not cover; ``tis`` (the file's values, NaN when unknown) and ``ratio`` = tis /
        integral.
    """
    from ..bsdf_geometry import grid_integral as quadrature

    t = _table_of(obj)
    return quadrature(
        t.values,
        t.theta_i_deg,
        t.azimuth_deg,
        t.radial_deg,
        symmetry=t.symmetry,
        tis=t.tis,
    )


# ------------------------------------------------------------------------------ registry


def _sniff(head: bytes) -> bool:
    """Two of the header keywords at line starts within the first bytes; never raises."""
    try:
        found = {m.group(1) for m in _SNIFF.finditer(head[:4096])}
        return len(found) >= 3 or (len(found) >= 2 and b"AngleOfIncidence" in head)
    except Exception:  # pragma: no cover - defensive: a sniffer must not raise
        return False


FORMATS = (
    Format(
        "zemax-bsdf",
        "Zemax / Radiant BSDF Data Interchange tabular text (.bsdf): BRDF/BTDF on a "
        "specular-centred grid",
        (".bsdf",),
        _sniff,
        read_zemax_bsdf,
        ("brdf", "btdf"),
        keywords=(b"AngleOfIncidence", b"ScatterAzimuth", b"ScatterRadial"),
    ),
)
