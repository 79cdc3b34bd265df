"""The ``.bsdf`` file's text read into its own grid: header, lists and data blocks.

The layout is described in :mod:`labbrdf.adapters.zemax_bsdf`, which turns the
:class:`BsdfTable` read here into dataset rows. Here: the header (keywords and the four angle
lists with their counts, checked against caps and against the file's size before anything
is allocated), the wavelength comments (the format has no wavelength field), and the data
blocks, one ``TIS`` line and one row per azimuth each, parsed by
``labbrdf.adapters._numblock.parse_rows``. Every error names the file and the line.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..bsdf_geometry import SYMMETRIES
from ._base import DECIMAL, AdapterError, decode, read_bytes, split_lines
from ._numblock import finite_number, parse_rows

__all__ = [
    "HEADER_LISTS",
    "MAX_LIST",
    "MAX_POINTS",
    "SCATTER_TYPES",
    "SPECTRAL",
    "WAVELENGTH_COMMENT",
    "BsdfTable",
    "read_table",
    "stated_wavelength",
]

#: The section names of each ``SpectralContent``.
SPECTRAL = {"Monochrome": ("Monochrome",), "XYZ": ("TristimulusX", "TristimulusY", "TristimulusZ")}
#: ``ScatterType`` -> the dataset's quantity.
SCATTER_TYPES = {"BRDF": "brdf", "BTDF": "btdf"}

#: Hard caps: values per list, and values in the whole file.
MAX_LIST = 100_000
MAX_POINTS = 50_000_000

#: The header's list keywords, in the order the writer puts them.
HEADER_LISTS = ("SampleRotation", "AngleOfIncidence", "ScatterAzimuth", "ScatterRadial")
_HEADER_WORDS = ("Source", "Symmetry", "SpectralContent", "ScatterType")
_INT = re.compile(r"\+?\d+", re.ASCII)


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
        if item is None or not DECIMAL.match(item[1].split()[0]):
            found = len(toks)
            raise AdapterError(
                path, f"{key} {n}: expected {n} values, found {found}", item[0] if item else line
            )
        cur.next()
        toks.extend((item[0], t) for t in item[1].split())
    if len(toks) != n:
        raise AdapterError(path, f"{key} {n}: expected {n} values, found {len(toks)}", toks[-1][0])
    return np.array([finite_number(path, t, ln, key) for ln, t in toks])


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
            t.tis[r, c, a] = finite_number(path, parts[1], item[0], "TIS")
            br, bl = _block_rows(path, cur, naz, nrad, where)
            rows += br
            lines += bl
        vals = parse_rows(path, rows, lines, nrad).reshape(nrot, naoi, naz, nrad)
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


#: comment labbrdf writes for the wavelength of a model it exports (the format has no field)
WAVELENGTH_COMMENT = "labbrdf wavelength_nm "

#: wavelength comments read, ``#labbrdf wavelength_nm 550`` (ours) and ``#Wavelength (nm) =
#: 550.0`` (the Speos-to-Zemax converter's); the value is checked by
#: :func:`~labbrdf.adapters._numblock.finite_number`
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
        w = finite_number(path, m["v"], line, "wavelength comment")
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
