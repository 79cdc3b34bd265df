"""What every dispersion model is: the :class:`Dispersion` base class, its error, ``HC_EV_NM``.

A model is a small frozen dataclass of named parameters; :mod:`labbrdf.nk.dispersion`
describes the interface and lists the models.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import fields
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["HC_EV_NM", "Dispersion", "DispersionError"]


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

    def fixed_by_default(self) -> frozenset[str]:
        """Parameters a default fit leaves fixed (structure, not optics: B-spline knots)."""
        return frozenset()

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe form ``{"model": name, **params}`` (inverse: :func:`from_dict`)."""
        return {"model": self.name, **self.params}
