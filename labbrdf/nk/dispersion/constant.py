"""A wavelength-independent index ``N = n + ik``."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from .base import ComplexArray, Dispersion, DispersionError, _wavelength


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
