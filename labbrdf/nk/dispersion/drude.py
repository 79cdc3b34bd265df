"""Drude free-electron dielectric function of a metal."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import HC_EV_NM, ComplexArray, Dispersion, DispersionError, _sqrt_eps, _wavelength


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
