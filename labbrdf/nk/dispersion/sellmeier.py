"""Sellmeier index of a transparent dielectric."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import ComplexArray, Dispersion, DispersionError, _sqrt_eps, _wavelength


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
