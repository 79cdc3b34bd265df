"""A cubic B-spline in ``eps2`` with its Kramers-Kronig ``eps1`` (Johs & Hale 2008)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import BSpline as _ScipyBSpline

from ._kk import kk_eps1, panel_edges
from .base import (
    HC_EV_NM,
    ComplexArray,
    Dispersion,
    DispersionError,
    FloatArray,
    _sqrt_eps,
    _wavelength,
)


def knots(e_lo: float, e_hi: float, n: int) -> FloatArray:
    """The ``n + 4`` uniform knots [eV] of ``n`` cubic B-splines spanning ``[e_lo, e_hi]``."""
    return np.linspace(e_lo, e_hi, n + 4)


def basis(energy_ev: FloatArray, e_lo: float, e_hi: float, n: int) -> FloatArray:
    """The ``n`` cubic B-splines at ``energy_ev`` [eV] (last axis ``n``); 0 outside."""
    e = np.asarray(energy_ev, float)
    h = (e_hi - e_lo) / (n + 3)
    padded = e_lo + h * np.arange(-3, n + 7)  # 3 more knots each side: the base interval
    x = np.clip(e.ravel(), e_lo, e_hi)  # of scipy's design matrix is then [e_lo, e_hi]
    b = _ScipyBSpline.design_matrix(x, padded, 3).toarray()[:, 3 : n + 3]
    inside = ((e.ravel() > e_lo) & (e.ravel() < e_hi))[:, None]
    return np.asarray(np.where(inside, b, 0.0)).reshape(*e.shape, n)


@dataclass(frozen=True)
class BSpline(Dispersion):
    """``eps2`` a cubic B-spline of photon energy, ``eps1`` its Kramers-Kronig transform.

    ``eps2(E) = sum_j c_j B_j(E)`` with ``n`` cubic B-splines ``B_j`` on ``n + 4`` uniform
    knots from ``E_lo`` to ``E_hi`` (``eps2 = 0`` outside, twice continuously differentiable,
    ``>= 0`` for ``c_j >= 0``), and ``eps1 = eps_inf + (2/pi) P int_0^inf xi eps2(xi) /
    (xi^2 - E^2) d xi`` (B. Johs, J. S. Hale, "Dielectric function representation by
    B-splines", Phys. Status Solidi A 205, 715 (2008)). The number of coefficients is chosen
    by an information criterion (A. V. Likhachev, "Selecting the right number of knots for
    B-spline parameterization of the dielectric functions in spectroscopic ellipsometry data
    analysis", Thin Solid Films 636, 519 (2017)): :func:`labbrdf.nk.dispersion.bspline_fit.choose`.
    Parameters are named ``eps_inf, E_lo, E_hi, c1, c2, ...``.

    Parameters
    ----------
    eps_inf : float
        [1]
    E_lo, E_hi : float
        Support of ``eps2`` [eV], ``0 <= E_lo < E_hi``; held fixed in a fit (give them
        without a box).
    coefficients : tuple of float
        ``c_j >= 0`` [1].

    Notes
    -----
    Johs & Hale place the knots over the measured range and transform each basis function in
    closed form; here the knots span ``[E_lo, E_hi]`` with ``eps2`` vanishing at both ends, and
    ``eps1`` is the numerical principal value of ``labbrdf.nk.dispersion._kk.kk_eps1``
    with a panel per knot interval (where ``xi eps2`` is a quartic): it agrees with adaptive
    quadrature to 1e-9 (``tests/nk/test_dispersion_oscillators.py``).
    """

    name: ClassVar[str] = "bspline"
    BOUNDS: ClassVar[dict[str, tuple[float, float]]] = {
        "eps_inf": (0.5, 10.0),
        "E_lo": (0.0, 30.0),
        "E_hi": (0.1, 30.0),
        "c": (0.0, 50.0),
    }
    UNITS: ClassVar[dict[str, str]] = {"E_lo": "eV", "E_hi": "eV"}

    eps_inf: float = 1.0
    E_lo: float = 1.0
    E_hi: float = 8.0
    coefficients: tuple[float, ...] = field(default=(0.0, 1.0, 2.0, 3.0, 2.0, 1.0, 0.0))

    def __post_init__(self) -> None:
        c = tuple(float(x) for x in self.coefficients)
        if not c:
            raise DispersionError("bspline: needs at least one coefficient (c1)")
        if any(x < 0 for x in c):
            raise DispersionError(f"bspline: coefficients must be >= 0, got {c}")
        if not 0 <= self.E_lo < self.E_hi:
            raise DispersionError(
                f"bspline: needs 0 <= E_lo < E_hi, got E_lo = {self.E_lo}, E_hi = {self.E_hi}"
            )
        object.__setattr__(self, "coefficients", c)

    @property
    def params(self) -> dict[str, float]:
        """name -> value of every parameter (plain floats)."""
        out = {"eps_inf": float(self.eps_inf), "E_lo": float(self.E_lo), "E_hi": float(self.E_hi)}
        out.update({f"c{j}": c for j, c in enumerate(self.coefficients, 1)})
        return out

    @classmethod
    def from_params(cls, params: Mapping[str, float]) -> BSpline:
        """A model from ``params`` (name -> value); unknown names raise."""
        p = dict(params)
        head = {k: float(p.pop(k)) for k in ("eps_inf", "E_lo", "E_hi") if k in p}
        n = 0
        while f"c{n + 1}" in p:
            n += 1
        c = tuple(float(p.pop(f"c{j}")) for j in range(1, n + 1))
        if p:
            raise DispersionError(
                f"bspline: unknown parameter(s) {sorted(p)}; parameters are eps_inf, E_lo, "
                "E_hi and c1, c2, ... numbered from 1 without gaps"
            )
        return cls(**head, coefficients=c)

    def bounds(self) -> dict[str, tuple[float, float]]:
        """Default search box name -> (min, max) of every parameter."""
        return {k: self.BOUNDS[k if k[0] != "c" else "c"] for k in self.params}

    def units(self) -> dict[str, str]:
        """Units of every parameter."""
        return {k: self.UNITS.get(k, "1") for k in self.params}

    def fixed_by_default(self) -> frozenset[str]:
        """The knot range: a default fit varies the coefficients only."""
        return frozenset({"E_lo", "E_hi"})

    def eps2(self, energy_ev: FloatArray) -> FloatArray:
        """Imaginary part ``eps2`` [1] at photon energies [eV]."""
        b = basis(energy_ev, self.E_lo, self.E_hi, len(self.coefficients))
        return np.asarray(b @ np.asarray(self.coefficients))

    def eps(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Dielectric function ``eps = N^2`` [1] at vacuum wavelength(s) [nm]."""
        e = HC_EV_NM / _wavelength(wavelength_nm)
        upper = max(1e4, 100 * float(np.max(e, initial=0.0)))
        edges = panel_edges(upper, knots(self.E_lo, self.E_hi, len(self.coefficients)))
        eps1 = self.eps_inf + kk_eps1(self.eps2, e, edges)
        return np.asarray(eps1 + 1j * self.eps2(e))

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        return _sqrt_eps(self.eps(wavelength_nm))
