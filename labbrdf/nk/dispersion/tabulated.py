"""Tabulated n, k interpolated in wavelength: the reference tables shipped, or given columns."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import ComplexArray, Dispersion, DispersionError, FloatArray, _wavelength

#: shipped reference tables: name -> (file under labbrdf/data/nk, citation)
REFERENCE_TABLES: dict[str, tuple[str, str]] = {
    "si": (
        "si_green2008.csv",
        "M. A. Green, Sol. Energy Mater. Sol. Cells 92, 1305 (2008), "
        "tabulated n, k of crystalline Si at 300 K, doi:10.1016/j.solmat.2008.06.009",
    ),
    "sio2": (
        "sio2_malitson1965.csv",
        "I. H. Malitson, J. Opt. Soc. Am. 55, 1205 (1965), eq. (2) (fused silica, 20 C), "
        "doi:10.1364/JOSA.55.001205; k = 0",
    ),
}


def parse_nk_table(text: str, source: str) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Columns wavelength [nm], n, k (k optional) of a comment-#'d, comma/space table.

    Parameters
    ----------
    text : str
        The table: ``wavelength_nm n [k]`` per line, comma, semicolon or whitespace
        separated, ``#`` comments, optional header lines before the data.
    source : str
        Where the text comes from, named in every error.

    Returns
    -------
    (ndarray, ndarray, ndarray)
        Wavelength [nm] (sorted, increasing), n [1], k [1] (0 where the table has none).

    Raises
    ------
    DispersionError
        Not such a table; names ``source`` and the line.
    """
    wl: list[float] = []
    n: list[float] = []
    k: list[float] = []
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.replace(",", " ").replace(";", " ").split()
        try:
            vals = [float(p) for p in parts]
        except ValueError:
            if not wl:  # a header line before the data
                continue
            raise DispersionError(
                f"{source}, line {lineno}: expected numbers 'wavelength_nm n [k]', got {raw!r}"
            ) from None
        if len(vals) not in (2, 3):
            raise DispersionError(
                f"{source}, line {lineno}: expected 2 or 3 columns (wavelength_nm n [k]), "
                f"got {len(vals)}"
            )
        if not all(math.isfinite(v) for v in vals) or vals[0] <= 0 or vals[1] < 0:
            raise DispersionError(
                f"{source}, line {lineno}: expected wavelength > 0, n >= 0, k >= 0, finite"
            )
        if len(vals) == 3 and vals[2] < 0:
            raise DispersionError(f"{source}, line {lineno}: k must be >= 0 (N = n + ik)")
        wl.append(vals[0])
        n.append(vals[1])
        k.append(vals[2] if len(vals) == 3 else 0.0)
    if len(wl) < 2:
        raise DispersionError(f"{source}: expected at least 2 rows 'wavelength_nm n [k]'")
    order = np.argsort(wl, kind="stable")
    w = np.asarray(wl)[order]
    if np.any(np.diff(w) == 0):
        raise DispersionError(f"{source}: repeated wavelength {w[:-1][np.diff(w) == 0][0]} nm")
    return w, np.asarray(n)[order], np.asarray(k)[order]


@dataclass(frozen=True, eq=False)
class Tabulated(Dispersion):
    """Tabulated ``n, k`` interpolated linearly in wavelength.

    Build with :meth:`reference` (the shipped tables, :data:`REFERENCE_TABLES`),
    :func:`labbrdf.nk.tabulated_from_file` (a two/three-column ``wavelength_nm n [k]`` text
    file, or any ellipsometer export whose two-phase pseudo-constants are the material's,
    e.g. a bare substrate) or directly from arrays. Outside the table's range :meth:`nk` raises
    (never extrapolates).

    Parameters
    ----------
    wavelength_nm, n, k : array_like
        Strictly increasing wavelengths [nm] and the index there [1].
    source : str
        Where the table comes from (file name or citation), named in every error.
    """

    name: ClassVar[str] = "tabulated"

    wavelength_nm: Any
    n: Any
    k: Any
    source: str = "table"
    key: str = ""

    def __post_init__(self) -> None:
        w = np.asarray(self.wavelength_nm, float)
        n = np.asarray(self.n, float)
        k = np.asarray(self.k, float)
        if w.ndim != 1 or w.shape != n.shape or w.shape != k.shape or w.size < 2:
            raise DispersionError(f"{self.source}: wavelength, n, k must be 1-D, same length >= 2")
        if np.any(np.diff(w) <= 0):
            raise DispersionError(f"{self.source}: wavelengths must increase strictly")
        if np.any(k < 0) or np.any(n < 0):
            raise DispersionError(f"{self.source}: n and k must be >= 0")
        for f_, v in (("wavelength_nm", w), ("n", n), ("k", k)):
            object.__setattr__(self, f_, v)

    @property
    def params(self) -> dict[str, float]:
        """name -> value of every parameter (plain floats)."""
        return {}

    @classmethod
    def from_params(cls, params: Mapping[str, float]) -> Tabulated:
        """A model from ``params`` (name -> value); unknown names raise."""
        raise DispersionError(
            "tabulated: has no parameters; build it with Tabulated.reference(name) or "
            "labbrdf.nk.tabulated_from_file(path)"
        )

    @property
    def range_nm(self) -> tuple[float, float]:
        """(shortest, longest) wavelength of the table [nm]."""
        return float(self.wavelength_nm[0]), float(self.wavelength_nm[-1])

    def covers(self, wavelength_nm: ArrayLike) -> bool:
        """Whether every wavelength lies inside the table."""
        lam = np.asarray(wavelength_nm, float)
        lo, hi = self.range_nm
        return bool(np.all((lam >= lo) & (lam <= hi)))

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        lam = _wavelength(wavelength_nm)
        if not self.covers(lam):
            lo, hi = self.range_nm
            raise DispersionError(
                f"{self.source}: the table covers {lo:g}-{hi:g} nm, asked for "
                f"{float(lam.min()):g}-{float(lam.max()):g} nm (no extrapolation)"
            )
        n = np.interp(lam, self.wavelength_nm, self.n)
        k = np.interp(lam, self.wavelength_nm, self.k)
        return np.asarray(n + 1j * k)

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe form (inverse: :func:`from_dict`)."""
        if self.key.startswith("reference:"):
            return {"model": "tabulated", "reference": self.key.split(":", 1)[1]}
        if self.key.startswith("file:"):
            return {"model": "tabulated", "file": self.key.split(":", 1)[1]}
        return {
            "model": "tabulated",
            "wavelength_nm": self.wavelength_nm.tolist(),
            "n": self.n.tolist(),
            "k": self.k.tolist(),
            "source": self.source,
        }

    @classmethod
    def reference(cls, name: str) -> Tabulated:
        """A shipped reference table: ``"si"`` (Green 2008) or ``"sio2"`` (Malitson 1965).

        See ``labbrdf/data/nk/README.md`` for provenance and the exact source of each.
        """
        key = name.lower().strip()
        if key not in REFERENCE_TABLES:
            raise DispersionError(
                f"unknown reference table {name!r}; shipped tables: {sorted(REFERENCE_TABLES)}"
            )
        fname, cite = REFERENCE_TABLES[key]
        text = resources.files("labbrdf").joinpath("data", "nk", fname).read_text("utf-8")
        w, n, k = parse_nk_table(text, f"labbrdf/data/nk/{fname}")
        return cls(w, n, k, source=f"{fname} ({cite})", key=f"reference:{key}")
