"""Dispersion models: a material's complex index ``N = n + ik`` as a function of wavelength.

Physics layer: NumPy only, and no file is read here (a table from a file or an ellipsometer
export is built by :func:`labbrdf.nk.tabulated_from_file`). Each model is a small frozen
dataclass of named parameters with

* ``.nk(wavelength_nm) -> complex ndarray`` (``n + ik``, ``k >= 0``, vacuum wavelength in
  nm) and ``.eps(wavelength_nm)`` (``eps = N^2``);
* ``.params`` (name -> value) and ``Model.from_params(mapping)``;
* ``.bounds()`` (name -> (min, max)): the default search box of a fit;
* ``.to_dict()`` / :func:`from_dict` (JSON-safe, used by model files and fit results).

:data:`MODELS` maps registry names to the classes. Photon energy ``E [eV] = HC_EV_NM /
lambda [nm]``. The time dependence is ``exp(-i omega t)`` (labbrdf's convention), so a
passive medium has ``Im(eps) >= 0``; oscillator formulas written for ``exp(+i omega t)`` in
their papers are conjugated here (each docstring says so).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from importlib import resources
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "HC_EV_NM",
    "MODELS",
    "REFERENCE_TABLES",
    "Cauchy",
    "Constant",
    "Dispersion",
    "DispersionError",
    "Drude",
    "Lorentz",
    "Sellmeier",
    "Tabulated",
    "TaucLorentz",
    "from_dict",
    "parse_nk_table",
]

#: h c [eV nm] (CODATA 2018, exact): E [eV] = HC_EV_NM / lambda [nm]
HC_EV_NM = 1239.8419843320026

ComplexArray = NDArray[np.complex128]
FloatArray = NDArray[np.float64]


class DispersionError(ValueError):
    """Invalid dispersion parameters, an unknown model, or a table that misses a wavelength."""


def _wavelength(wavelength_nm: ArrayLike) -> FloatArray:
    lam = np.asarray(wavelength_nm, dtype=float)
    if not np.all(np.isfinite(lam)) or np.any(lam <= 0):
        raise DispersionError("wavelength_nm: expected finite values > 0 [nm]")
    return lam


def _sqrt_eps(eps: ArrayLike) -> ComplexArray:
    """``N = sqrt(eps)`` with ``n >= 0`` and ``k >= 0`` (for ``Im(eps) >= 0``)."""
    e = np.asarray(eps, complex)
    n = np.sqrt(e)
    return np.asarray(np.where(n.imag < 0, -n, n))


class Dispersion(ABC):
    """Base of the dispersion models: parameters, ``nk``, ``eps``, bounds, dict form."""

    #: registry name
    name: ClassVar[str] = ""
    #: default search box of a fit: name -> (min, max) in the parameter's units
    BOUNDS: ClassVar[dict[str, tuple[float, float]]] = {}
    #: units of each parameter (labbrdf spelling)
    UNITS: ClassVar[dict[str, str]] = {}

    @abstractmethod
    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""

    def eps(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Dielectric function ``eps = N^2`` [1]."""
        n = self.nk(wavelength_nm)
        return np.asarray(n * n)

    @property
    def params(self) -> dict[str, float]:
        """name -> value of every parameter (plain floats)."""
        return {f.name: float(getattr(self, f.name)) for f in fields(self)}  # type: ignore[arg-type]

    @classmethod
    def from_params(cls, params: Mapping[str, float]) -> Dispersion:
        """A model of this class from ``params`` (name -> value); unknown names raise."""
        known = {f.name for f in fields(cls)}  # type: ignore[arg-type]
        bad = sorted(set(params) - known)
        if bad:
            raise DispersionError(
                f"{cls.name}: unknown parameter(s) {bad}; parameters are {sorted(known)}"
            )
        return cls(**{k: float(v) for k, v in params.items()})

    def bounds(self) -> dict[str, tuple[float, float]]:
        """Default search box name -> (min, max) of every parameter."""
        return {k: self.BOUNDS[k] for k in self.params}

    def units(self) -> dict[str, str]:
        """Units of every parameter."""
        return {k: self.UNITS.get(k, "1") for k in self.params}

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe form ``{"model": name, **params}`` (inverse: :func:`from_dict`)."""
        return {"model": self.name, **self.params}


# --------------------------------------------------------------------------------------
# constant index
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Constant(Dispersion):
    """A wavelength-independent index ``N = n + ik`` (an ambient, or a quick trial layer).

    Parameters
    ----------
    n : float
        Refractive index, > 0 [1].
    k : float
        Extinction coefficient, >= 0 [1].
    """

    name: ClassVar[str] = "constant"
    BOUNDS: ClassVar[dict[str, tuple[float, float]]] = {"n": (1.0, 5.0), "k": (0.0, 5.0)}

    n: float = 1.0
    k: float = 0.0

    def __post_init__(self) -> None:
        if not (self.n > 0 and self.k >= 0 and math.isfinite(self.n) and math.isfinite(self.k)):
            raise DispersionError(f"constant: needs n > 0 and k >= 0, got n={self.n}, k={self.k}")

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        lam = _wavelength(wavelength_nm)
        return np.full(lam.shape, complex(self.n, self.k))


# --------------------------------------------------------------------------------------
# Cauchy with an Urbach tail
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Cauchy(Dispersion):
    """Cauchy index with an Urbach absorption tail (the WVASE "Cauchy + Urbach" layer).

    ``n = A + B / lambda^2 + C / lambda^4`` with ``lambda`` in micrometres (A. L. Cauchy,
    *Memoire sur la dispersion de la lumiere* (1836); the form and the micrometre scale of
    the J. A. Woollam WVASE manual), and
    ``k = k_amp exp(exponent (E - band_edge))``, ``E = HC_EV_NM / lambda [nm]`` [eV]
    (F. Urbach, Phys. Rev. 92, 1324 (1953)).

    Parameters
    ----------
    A : float
        [1]
    B : float
        [um^2]
    C : float
        [um^4]
    k_amp : float
        Extinction coefficient at the band edge, >= 0 [1]; 0 for a transparent layer.
    exponent : float
        Urbach exponent [1/eV].
    band_edge : float
        [eV].
    """

    name: ClassVar[str] = "cauchy"
    BOUNDS: ClassVar[dict[str, tuple[float, float]]] = {
        "A": (1.0, 3.5),
        "B": (-0.05, 0.3),
        "C": (-0.01, 0.05),
        "k_amp": (0.0, 0.5),
        "exponent": (0.1, 10.0),
        "band_edge": (1.0, 8.0),
    }
    UNITS: ClassVar[dict[str, str]] = {
        "B": "um^2",
        "C": "um^4",
        "exponent": "eV-1",
        "band_edge": "eV",
    }

    A: float = 1.45
    B: float = 0.004
    C: float = 0.0
    k_amp: float = 0.0
    exponent: float = 1.5
    band_edge: float = 4.0

    def __post_init__(self) -> None:
        if self.k_amp < 0:
            raise DispersionError(f"cauchy: k_amp must be >= 0, got {self.k_amp}")

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        lam = _wavelength(wavelength_nm)
        um2 = (lam / 1000.0) ** 2
        n = self.A + self.B / um2 + self.C / (um2 * um2)
        e = HC_EV_NM / lam
        k = self.k_amp * np.exp(self.exponent * (e - self.band_edge))
        return np.asarray(n + 1j * k)


# --------------------------------------------------------------------------------------
# Sellmeier
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Sellmeier(Dispersion):
    """Three-term Sellmeier index of a transparent material.

    ``n^2 = A + sum_j B_j lambda^2 / (lambda^2 - C_j)``, ``lambda`` in micrometres
    (W. Sellmeier, Ann. Phys. Chem. 219, 272 (1871)); ``k = 0``. The defaults are
    Malitson's coefficients for fused silica at 20 C (I. H. Malitson, "Interspecimen
    comparison of the refractive index of fused silica", J. Opt. Soc. Am. 55, 1205 (1965),
    eq. (2); valid 0.21-3.71 um), with ``C_j`` the squares of his resonance wavelengths.

    Parameters
    ----------
    A : float
        [1]
    B1, B2, B3 : float
        [1]
    C1, C2, C3 : float
        Squared resonance wavelengths [um^2].
    """

    name: ClassVar[str] = "sellmeier"
    BOUNDS: ClassVar[dict[str, tuple[float, float]]] = {
        "A": (1.0, 5.0),
        "B1": (0.0, 5.0),
        "B2": (0.0, 5.0),
        "B3": (0.0, 5.0),
        "C1": (0.0, 0.1),
        "C2": (0.0, 0.5),
        "C3": (0.0, 500.0),
    }
    UNITS: ClassVar[dict[str, str]] = {"C1": "um^2", "C2": "um^2", "C3": "um^2"}

    A: float = 1.0
    B1: float = 0.6961663
    B2: float = 0.4079426
    B3: float = 0.8974794
    C1: float = 0.0684043**2
    C2: float = 0.1162414**2
    C3: float = 9.896161**2

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        lam = _wavelength(wavelength_nm)
        l2 = (lam / 1000.0) ** 2
        with np.errstate(divide="ignore", invalid="ignore"):
            n2 = (
                self.A
                + self.B1 * l2 / (l2 - self.C1)
                + self.B2 * l2 / (l2 - self.C2)
                + self.B3 * l2 / (l2 - self.C3)
            )
        if not np.all(np.isfinite(n2)):
            raise DispersionError("sellmeier: a wavelength sits on a resonance (lambda^2 = C_j)")
        return _sqrt_eps(n2 + 0j)


# --------------------------------------------------------------------------------------
# Tauc-Lorentz
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class TaucLorentz(Dispersion):
    """Tauc-Lorentz dielectric function of an amorphous semiconductor or dielectric.

    G. E. Jellison Jr., F. A. Modine, "Parameterization of the optical functions of
    amorphous materials in the interband region", Appl. Phys. Lett. 69, 371 (1996);
    erratum Appl. Phys. Lett. 69, 2137 (1996). For ``E > Eg``

    ``eps2 = A E0 C (E - Eg)^2 / ((E^2 - E0^2)^2 + C^2 E^2) / E``,

    0 below ``Eg``, and ``eps1 = eps_inf + (2/pi) P int_Eg^inf xi eps2(xi)/(xi^2 - E^2)
    d xi`` in the closed form of the paper's eq. (6) (with the erratum), written with
    ``alpha = sqrt(4 E0^2 - C^2)``, ``gamma^2 = E0^2 - C^2/2`` and
    ``zeta^4 = (E^2 - gamma^2)^2 + alpha^2 C^2 / 4``.

    Parameters
    ----------
    eps_inf : float
        [1]
    A : float
        Oscillator amplitude [eV].
    E0 : float
        Peak transition energy [eV].
    C : float
        Broadening [eV], ``0 < C < 2 E0``.
    Eg : float
        Optical (Tauc) gap [eV], ``0 <= Eg``.

    Notes
    -----
    The two logarithms of eq. (6) in ``|E - Eg|`` are combined into
    ``-(E - Eg)^2 / E ln|E - Eg| + (E + Eg)^2 / E ln(E + Eg) - Eg ln((E0^2 - Eg^2)^2 +
    Eg^2 C^2)`` (times ``A E0 C / (pi zeta^4)``), the same function, finite at ``E = Eg``
    where the paper's two terms are separately infinite.
    """

    name: ClassVar[str] = "tauc_lorentz"
    BOUNDS: ClassVar[dict[str, tuple[float, float]]] = {
        "eps_inf": (0.5, 5.0),
        "A": (1.0, 500.0),
        "E0": (1.0, 12.0),
        "C": (0.1, 10.0),
        "Eg": (0.0, 8.0),
    }
    UNITS: ClassVar[dict[str, str]] = {"A": "eV", "E0": "eV", "C": "eV", "Eg": "eV"}

    eps_inf: float = 1.0
    A: float = 100.0
    E0: float = 5.0
    C: float = 1.0
    Eg: float = 3.0

    def __post_init__(self) -> None:
        if not (0 < self.C < 2 * self.E0):
            raise DispersionError(
                f"tauc_lorentz: needs 0 < C < 2 E0, got C = {self.C}, E0 = {self.E0}"
            )
        if self.Eg < 0 or self.A < 0:
            raise DispersionError("tauc_lorentz: needs Eg >= 0 and A >= 0")

    def eps(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Dielectric function ``eps = N^2`` [1] at vacuum wavelength(s) [nm]."""
        e = HC_EV_NM / _wavelength(wavelength_nm)
        a, e0, c, eg = self.A, self.E0, self.C, self.Eg
        alpha = math.sqrt(4 * e0**2 - c**2)
        gamma2 = e0**2 - c**2 / 2
        zeta4 = (e**2 - gamma2) ** 2 + alpha**2 * c**2 / 4
        above = e > eg
        eps2 = np.where(
            above, a * e0 * c * (e - eg) ** 2 / ((e**2 - e0**2) ** 2 + c**2 * e**2) / e, 0.0
        )
        a_ln = (eg**2 - e0**2) * e**2 + eg**2 * c**2 - e0**2 * (e0**2 + 3 * eg**2)
        a_atan = (e**2 - e0**2) * (e0**2 + eg**2) + eg**2 * c**2
        t1 = (
            a
            * c
            * a_ln
            / (2 * math.pi * zeta4 * alpha * e0)
            * math.log((e0**2 + eg**2 + alpha * eg) / (e0**2 + eg**2 - alpha * eg))
        )
        t2 = (
            -a
            * a_atan
            / (math.pi * zeta4 * e0)
            * (math.pi - math.atan((2 * eg + alpha) / c) + math.atan((alpha - 2 * eg) / c))
        )
        t3 = (
            2
            * a
            * e0
            / (math.pi * zeta4 * alpha)
            * eg
            * (e**2 - gamma2)
            * (math.pi + 2 * math.atan(2 * (gamma2 - eg**2) / (alpha * c)))
        )
        d = np.abs(e - eg)
        xlog = np.where(d > 0, d**2 * np.log(np.where(d > 0, d, 1.0)), 0.0)
        t45 = (
            a
            * e0
            * c
            / (math.pi * zeta4)
            * (
                -xlog / e
                + (e + eg) ** 2 / e * np.log(e + eg)
                - (eg * math.log((e0**2 - eg**2) ** 2 + eg**2 * c**2) if eg > 0 else 0.0)
            )
        )
        eps1 = self.eps_inf + t1 + t2 + t3 + t45
        return np.asarray(eps1 + 1j * eps2)

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        return _sqrt_eps(self.eps(wavelength_nm))


# --------------------------------------------------------------------------------------
# Drude and Lorentz oscillators
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Drude(Dispersion):
    """Drude free-carrier dielectric function.

    ``eps = eps_inf - omega_p^2 / (E^2 + i gamma E)`` with energies in eV (P. Drude, Ann.
    Phys. 306, 566 (1900); the form of M. Dressel, G. Gruener, *Electrodynamics of Solids*,
    Cambridge (2002), eq. (5.1.5), for ``exp(-i omega t)``).

    Parameters
    ----------
    eps_inf : float
        [1]
    omega_p : float
        Plasma energy [eV].
    gamma : float
        Damping (scattering rate) [eV], > 0.
    """

    name: ClassVar[str] = "drude"
    BOUNDS: ClassVar[dict[str, tuple[float, float]]] = {
        "eps_inf": (0.5, 10.0),
        "omega_p": (0.1, 30.0),
        "gamma": (0.001, 5.0),
    }
    UNITS: ClassVar[dict[str, str]] = {"omega_p": "eV", "gamma": "eV"}

    eps_inf: float = 1.0
    omega_p: float = 9.0
    gamma: float = 0.1

    def __post_init__(self) -> None:
        if not self.gamma > 0:
            raise DispersionError(f"drude: gamma must be > 0, got {self.gamma}")

    def eps(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Dielectric function ``eps = N^2`` [1] at vacuum wavelength(s) [nm]."""
        e = HC_EV_NM / _wavelength(wavelength_nm)
        return np.asarray(self.eps_inf - self.omega_p**2 / (e * e + 1j * self.gamma * e))

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        return _sqrt_eps(self.eps(wavelength_nm))


@dataclass(frozen=True)
class Lorentz(Dispersion):
    """Sum of Lorentz oscillators.

    ``eps = eps_inf + sum_j A_j E_j^2 / (E_j^2 - E^2 - i G_j E)`` with energies in eV
    (H. A. Lorentz, *The Theory of Electrons* (1909); the form of F. Wooten, *Optical
    Properties of Solids*, Academic Press (1972), eq. (3.23), for ``exp(-i omega t)``).
    Parameters are named ``A1, E1, G1, A2, E2, G2, ...``.

    Parameters
    ----------
    eps_inf : float
        [1]
    oscillators : tuple of (A, E, G)
        Dimensionless strength ``A_j >= 0``, centre ``E_j > 0`` [eV] and broadening
        ``G_j >= 0`` [eV] of each oscillator.
    """

    name: ClassVar[str] = "lorentz"
    BOUNDS: ClassVar[dict[str, tuple[float, float]]] = {
        "eps_inf": (0.5, 10.0),
        "A": (0.0, 50.0),
        "E": (0.05, 20.0),
        "G": (0.0, 10.0),
    }
    UNITS: ClassVar[dict[str, str]] = {"E": "eV", "G": "eV"}

    eps_inf: float = 1.0
    oscillators: tuple[tuple[float, float, float], ...] = field(default=((1.0, 10.0, 0.1),))

    def __post_init__(self) -> None:
        osc = tuple(tuple(float(x) for x in o) for o in self.oscillators)
        for j, o in enumerate(osc, 1):
            if len(o) != 3:
                raise DispersionError(f"lorentz: oscillator {j} needs (A, E, G), got {o}")
            if o[0] < 0 or o[1] <= 0 or o[2] < 0:
                raise DispersionError(
                    f"lorentz: oscillator {j} needs A >= 0, E > 0, G >= 0, got {o}"
                )
        object.__setattr__(self, "oscillators", osc)

    @property
    def params(self) -> dict[str, float]:
        """name -> value of every parameter (plain floats)."""
        out = {"eps_inf": float(self.eps_inf)}
        for j, (a, e, g) in enumerate(self.oscillators, 1):
            out.update({f"A{j}": a, f"E{j}": e, f"G{j}": g})
        return out

    @classmethod
    def from_params(cls, params: Mapping[str, float]) -> Lorentz:
        """A model from ``params`` (name -> value); unknown names raise."""
        p = dict(params)
        eps_inf = float(p.pop("eps_inf", 1.0))
        n = 0
        while f"A{n + 1}" in p or f"E{n + 1}" in p or f"G{n + 1}" in p:
            n += 1
        osc = []
        for j in range(1, n + 1):
            missing = [f"{s}{j}" for s in "AEG" if f"{s}{j}" not in p]
            if missing:
                raise DispersionError(f"lorentz: oscillator {j} lacks {missing}")
            osc.append((float(p.pop(f"A{j}")), float(p.pop(f"E{j}")), float(p.pop(f"G{j}"))))
        if p:
            raise DispersionError(
                f"lorentz: unknown parameter(s) {sorted(p)}; parameters are eps_inf and "
                "A1, E1, G1, A2, ... numbered from 1 without gaps"
            )
        if not osc:
            raise DispersionError("lorentz: needs at least one oscillator (A1, E1, G1)")
        return cls(eps_inf=eps_inf, oscillators=tuple(osc))

    def bounds(self) -> dict[str, tuple[float, float]]:
        """Default search box name -> (min, max) of every parameter."""
        return {k: self.BOUNDS[k.rstrip("0123456789")] for k in self.params}

    def units(self) -> dict[str, str]:
        """Units of every parameter."""
        return {k: self.UNITS.get(k.rstrip("0123456789"), "1") for k in self.params}

    def eps(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Dielectric function ``eps = N^2`` [1] at vacuum wavelength(s) [nm]."""
        e = HC_EV_NM / _wavelength(wavelength_nm)
        out = np.full(e.shape, self.eps_inf, complex)
        for a, e0, g in self.oscillators:
            out = out + a * e0**2 / (e0**2 - e * e - 1j * g * e)
        return out

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        return _sqrt_eps(self.eps(wavelength_nm))


# --------------------------------------------------------------------------------------
# Tabulated
# --------------------------------------------------------------------------------------

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


#: registry name -> class
MODELS: dict[str, type[Dispersion]] = {
    c.name: c for c in (Constant, Cauchy, Sellmeier, TaucLorentz, Drude, Lorentz, Tabulated)
}


def from_dict(d: Mapping[str, Any]) -> Dispersion:
    """Inverse of ``Dispersion.to_dict()``; also accepts a bare complex index ``{"n", "k"}``.

    Raises
    ------
    DispersionError
        Unknown model or parameter names.
    """
    d = dict(d)
    name = str(d.pop("model", "")).lower()
    if name not in MODELS:
        raise DispersionError(f"unknown dispersion model {name!r}; models: {sorted(MODELS)}")
    if name == "tabulated":
        if "reference" in d:
            return Tabulated.reference(str(d["reference"]))
        if "file" in d:
            raise DispersionError(
                f"tabulated: {d['file']!r} is a file; read it with "
                "labbrdf.nk.tabulated_from_file (labbrdf.films.as_material does)"
            )
        if "wavelength_nm" in d:
            return Tabulated(
                d["wavelength_nm"],
                d["n"],
                d.get("k", [0.0] * len(d["n"])),
                str(d.get("source", "table")),
            )
        raise DispersionError("tabulated: give 'reference' (si, sio2) or 'file'")
    return MODELS[name].from_params(d)
