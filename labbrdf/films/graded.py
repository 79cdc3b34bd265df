"""Graded layers: a material whose parameter varies through the thickness, in sublayers.

A film that is not homogeneous (an index gradient from deposition, an interface that mixes
gradually into the substrate) is a :class:`Graded` layer material: one parameter of a base
material (a dispersion model's ``A`` or ``n``, an :class:`~labbrdf.films.ema.Ema`'s
``fraction``) goes from ``top`` (at the ambient side) to ``bottom`` along a profile
``u ** shape`` of the depth fraction ``u`` (``shape = 1``: linear), and the stack computes the
layer as ``sublayers`` homogeneous slices of equal thickness, each at its mid-depth value.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..nk import dispersion as disp
from .ema import Ema
from .limits import FilmError

__all__ = ["MAX_SUBLAYERS", "Graded"]

MAX_SUBLAYERS = 200
"""Most slices one graded layer may be cut into (a stack evaluation is linear in them)."""


@dataclass(frozen=True)
class Graded:
    """A base material whose parameter ``parameter`` varies from ``top`` to ``bottom``.

    Parameters
    ----------
    base : Dispersion or Ema
        The material; its other parameters are uniform through the layer.
    parameter : str
        The parameter of ``base`` that varies (``"A"`` of a Cauchy, ``"n"`` of a constant,
        ``"fraction"`` of an EMA).
    top, bottom : float
        Its value at the top (ambient side) and at the bottom of the layer [its unit].
    shape : float
        Profile exponent > 0 [1]: the value at depth fraction ``u`` in [0, 1] is
        ``top + (bottom - top) u^shape``; 1 is linear.
    sublayers : int
        Number of homogeneous slices of equal thickness, in [1, :data:`MAX_SUBLAYERS`];
        slice ``j`` takes the value at its mid-depth ``u = (j + 1/2) / sublayers``.

    Notes
    -----
    The slicing is the staircase approximation of an inhomogeneous layer (Born & Wolf,
    *Principles of Optics*, sec. 1.6.5): it converges to the continuous profile as the
    number of slices grows, with an error of order ``(d / sublayers)^2`` for a smooth
    profile (the midpoint rule). The fitted parameters are ``<parameter>_top``,
    ``<parameter>_bottom`` and ``shape`` beside the base's others.
    """

    base: Any
    parameter: str
    top: float
    bottom: float
    shape: float = 1.0
    sublayers: int = 20
    name = "graded"

    def __post_init__(self) -> None:
        if not isinstance(self.base, (disp.Dispersion, Ema)) or isinstance(
            self.base, disp.Tabulated
        ):
            raise FilmError(
                f"graded: base must be a dispersion model or an ema, got {self.base!r:.60}"
            )
        if self.parameter not in self.base.params:
            raise FilmError(
                f"graded: {self.parameter!r} is not a parameter of {self.base.name}; "
                f"parameters: {sorted(self.base.params)}"
            )
        n = self.sublayers
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_SUBLAYERS:
            raise FilmError(f"graded: sublayers must be an integer in [1, {MAX_SUBLAYERS}]")
        for key in ("top", "bottom", "shape"):
            v = float(getattr(self, key))
            if not math.isfinite(v) or (key == "shape" and v <= 0):
                raise FilmError(f"graded: {key} must be finite (shape > 0), got {v}")
            object.__setattr__(self, key, v)
        self.at(0.0), self.at(1.0)  # both ends are valid materials

    def at(self, u: float) -> Any:
        """The base material at depth fraction ``u`` in [0, 1] (0: top)."""
        v = self.top + (self.bottom - self.top) * float(u) ** self.shape
        try:
            return _with(self.base, {self.parameter: v})
        except (disp.DispersionError, ValueError) as exc:
            raise FilmError(f"graded: {self.parameter} = {v:g}: {exc}") from None

    def slices(self) -> list[Any]:
        """The materials of the slices, top first."""
        n = self.sublayers
        return [self.at((j + 0.5) / n) for j in range(n)]

    @property
    def params(self) -> dict[str, float]:
        """name -> value: the base's, with the graded one as ``_top`` / ``_bottom``."""
        out = {k: v for k, v in self.base.params.items() if k != self.parameter}
        p = self.parameter
        return {**out, f"{p}_top": self.top, f"{p}_bottom": self.bottom, "shape": self.shape}

    def fixed_by_default(self) -> frozenset[str]:
        """The base's structural parameters, and the profile's ``shape``.

        The profile stays linear unless a box is written for ``shape``.
        """
        fixed = getattr(self.base, "fixed_by_default", None)
        return (fixed() if callable(fixed) else frozenset()) | {"shape"}

    def bounds(self) -> dict[str, tuple[float, float]]:
        """Default search box."""
        b = dict(self.base.bounds())
        box = b.pop(self.parameter, (min(self.top, self.bottom), max(self.top, self.bottom)))
        p = self.parameter
        return {**b, f"{p}_top": box, f"{p}_bottom": box, "shape": (0.2, 5.0)}

    def units(self) -> dict[str, str]:
        """Units of every parameter."""
        u = dict(self.base.units())
        unit = u.pop(self.parameter, "1")
        return {**u, f"{self.parameter}_top": unit, f"{self.parameter}_bottom": unit, "shape": "1"}

    def with_params(self, values: Mapping[str, float]) -> Graded:
        """A copy with parameters replaced."""
        p = self.parameter
        bad = sorted(set(values) - set(self.params))
        if bad:
            raise FilmError(
                f"graded: unknown parameter(s) {bad}; parameters: {sorted(self.params)}"
            )
        rest = {k: v for k, v in values.items() if k not in (f"{p}_top", f"{p}_bottom", "shape")}
        base = _with(self.base, rest) if rest else self.base
        return Graded(
            base,
            p,
            values.get(f"{p}_top", self.top),
            values.get(f"{p}_bottom", self.bottom),
            values.get("shape", self.shape),
            self.sublayers,
        )

    def nk(self, wavelength_nm: Any) -> np.ndarray:
        """The index at mid-depth (``u = 1/2``) [1]; not for an EMA base (needs its stack)."""
        return np.asarray(self.at(0.5).nk(wavelength_nm))

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe form."""
        return {
            "model": "graded",
            "base": self.base.to_dict(),
            "parameter": self.parameter,
            "top": self.top,
            "bottom": self.bottom,
            "shape": self.shape,
            "sublayers": self.sublayers,
        }


def _with(m: Any, values: Mapping[str, float]) -> Any:
    if isinstance(m, Ema):
        return m.with_params(values)
    return type(m).from_params({**m.params, **values})
