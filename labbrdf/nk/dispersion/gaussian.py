"""Gaussian oscillators with their Kramers-Kronig-consistent ``eps1`` (Dawson function)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import dawsn

from .base import HC_EV_NM, ComplexArray, Dispersion, DispersionError, _sqrt_eps, _wavelength


@dataclass(frozen=True)
class Gaussian(Dispersion):
    """Sum of Gaussian oscillators (the Gaussian of WVASE's general oscillator layer).

    For each oscillator ``(A, En, Br)``, with ``sigma = Br / (2 sqrt(ln 2))`` (``Br`` is the
    full width at half maximum),

    ``eps2 = A [exp(-((E - En)/sigma)^2) - exp(-((E + En)/sigma)^2)]`` and
    ``eps1 = eps_inf + (2 A / sqrt(pi)) [D((E + En)/sigma) - D((E - En)/sigma)]``

    with Dawson's integral ``D`` (``scipy.special.dawsn``): the Kramers-Kronig transform of
    the odd ``eps2`` (D. De Sousa Meneses, M. Malki, P. Echegut, "Structure and lattice
    dynamics of binary lead silicate glasses investigated by infrared spectroscopy",
    J. Non-Cryst. Solids 352, 769 (2006), eqs. (5)-(6); J. A. Woollam Co., *Guide to Using
    WVASE32*, Gen-Osc Gaussian). Parameters are named ``A1, En1, Br1, A2, ...``.

    Parameters
    ----------
    eps_inf : float
        [1]
    oscillators : tuple of (A, En, Br)
        Amplitude ``A >= 0`` [1], centre ``En > 0`` [eV] and width ``Br > 0`` [eV].
    """

    name: ClassVar[str] = "gaussian"
    BOUNDS: ClassVar[dict[str, tuple[float, float]]] = {
        "eps_inf": (0.5, 10.0),
        "A": (0.0, 50.0),
        "En": (0.05, 20.0),
        "Br": (0.01, 10.0),
    }
    UNITS: ClassVar[dict[str, str]] = {"En": "eV", "Br": "eV"}

    eps_inf: float = 1.0
    oscillators: tuple[tuple[float, float, float], ...] = field(default=((1.0, 5.0, 1.0),))

    def __post_init__(self) -> None:
        osc = tuple(tuple(float(x) for x in o) for o in self.oscillators)
        for j, o in enumerate(osc, 1):
            if len(o) != 3:
                raise DispersionError(f"gaussian: oscillator {j} needs (A, En, Br), got {o}")
            if o[0] < 0 or o[1] <= 0 or o[2] <= 0:
                raise DispersionError(
                    f"gaussian: oscillator {j} needs A >= 0, En > 0, Br > 0, got {o}"
                )
        if not osc:
            raise DispersionError("gaussian: needs at least one oscillator (A1, En1, Br1)")
        object.__setattr__(self, "oscillators", osc)

    @property
    def params(self) -> dict[str, float]:
        """name -> value of every parameter (plain floats)."""
        out = {"eps_inf": float(self.eps_inf)}
        for j, (a, en, br) in enumerate(self.oscillators, 1):
            out.update({f"A{j}": a, f"En{j}": en, f"Br{j}": br})
        return out

    @classmethod
    def from_params(cls, params: Mapping[str, float]) -> Gaussian:
        """A model from ``params`` (name -> value); unknown names raise."""
        p = dict(params)
        eps_inf = float(p.pop("eps_inf", 1.0))
        n = 0
        while any(f"{s}{n + 1}" in p for s in ("A", "En", "Br")):
            n += 1
        osc = []
        for j in range(1, n + 1):
            missing = [f"{s}{j}" for s in ("A", "En", "Br") if f"{s}{j}" not in p]
            if missing:
                raise DispersionError(f"gaussian: oscillator {j} lacks {missing}")
            osc.append((float(p.pop(f"A{j}")), float(p.pop(f"En{j}")), float(p.pop(f"Br{j}"))))
        if p:
            raise DispersionError(
                f"gaussian: unknown parameter(s) {sorted(p)}; parameters are eps_inf and "
                "A1, En1, Br1, A2, ... numbered from 1 without gaps"
            )
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
        for a, en, br in self.oscillators:
            s = br / (2 * math.sqrt(math.log(2)))
            lo, hi = (e - en) / s, (e + en) / s
            eps2 = a * (np.exp(-(lo**2)) - np.exp(-(hi**2)))
            eps1 = 2 * a / math.sqrt(math.pi) * (dawsn(hi) - dawsn(lo))
            out = out + eps1 + 1j * eps2
        return out

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        return _sqrt_eps(self.eps(wavelength_nm))
