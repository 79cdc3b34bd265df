"""Lorentz oscillators (optionally over a Drude term)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import HC_EV_NM, ComplexArray, Dispersion, DispersionError, _sqrt_eps, _wavelength


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
