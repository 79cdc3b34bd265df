"""Cauchy index with an Urbach absorption tail (the WVASE "Cauchy + Urbach" layer)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import HC_EV_NM, ComplexArray, Dispersion, DispersionError, _wavelength


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

    def fixed_by_default(self) -> frozenset[str]:
        """The Urbach absorption, fixed unless a box is written.

        ``k_amp = 0`` keeps the layer transparent, and the exponent and band edge mean
        nothing without it.
        """
        return frozenset({"k_amp", "exponent", "band_edge"})

    def nk(self, wavelength_nm: ArrayLike) -> ComplexArray:
        """Complex index ``n + ik`` (``k >= 0``) at vacuum wavelength(s) [nm]."""
        lam = _wavelength(wavelength_nm)
        um2 = (lam / 1000.0) ** 2
        n = self.A + self.B / um2 + self.C / (um2 * um2)
        e = HC_EV_NM / lam
        k = self.k_amp * np.exp(self.exponent * (e - self.band_edge))
        return np.asarray(n + 1j * k)
