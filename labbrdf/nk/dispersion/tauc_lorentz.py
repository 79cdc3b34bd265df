"""Tauc-Lorentz oscillator of an amorphous semiconductor or dielectric."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import HC_EV_NM, ComplexArray, Dispersion, DispersionError, _sqrt_eps, _wavelength


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
