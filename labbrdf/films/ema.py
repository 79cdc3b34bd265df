"""Bruggeman effective-medium layers of two or three materials, as ellipsometry programs use.

An interface or roughness layer of WVASE / CompleteEASE is an effective-medium
approximation (EMA) of named constituents with a free volume fraction: the film material
with void at a rough surface, the film and the substrate at an interface. :class:`Ema` is
that layer material: two or three constituents, each a dispersion model or table, ``void``,
or a reference ``@NAME`` to the material of another layer of the stack (``@substrate``,
``@ambient`` too), so that the mixture follows that layer's fitted parameters.

:func:`bruggeman_mix` is the physics: the symmetric Bruggeman equation of ``n``
constituents, closed form for two (:func:`labbrdf.films.matrices.bruggeman`) and a
continuation from that root for three.

References
----------
.. [1] D. A. G. Bruggeman, Ann. Phys. 416, 636-664 (1935).
.. [2] D. E. Aspnes, J. B. Theeten, F. Hottier, Phys. Rev. B 20, 3292 (1979) (roughness
   and interface layers of ellipsometry as Bruggeman mixtures).
.. [3] R. Jansson, H. Arwin, "Selection of the physically correct solution in the n-media
   Bruggeman effective medium approximation", Opt. Commun. 106, 133-138 (1994): the root of
   the ``n``-th degree polynomial that continues the physical two-media root.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..nk import dispersion as disp
from .limits import FilmError
from .matrices import bruggeman

__all__ = ["Ema", "bruggeman_mix"]

VOID = "void"
_CONTINUATION_STEPS = 16
_NEWTON_STEPS = 8


def _residual(eps: NDArray, eps_i: Sequence[NDArray], f: Sequence[NDArray]):
    """``G(e) = sum f_i (e_i - e)/(e_i + 2 e)`` and ``dG/de``."""
    g = sum(fi * (ei - eps) / (ei + 2.0 * eps) for fi, ei in zip(f, eps_i, strict=True))
    dg = sum(-3.0 * fi * ei / (ei + 2.0 * eps) ** 2 for fi, ei in zip(f, eps_i, strict=True))
    return g, dg


def bruggeman_mix(eps: Sequence[ArrayLike], fractions: Sequence[ArrayLike]) -> NDArray:
    """Bruggeman effective dielectric function of two or three constituents.

    Parameters
    ----------
    eps : sequence of array_like of complex
        Dielectric functions ``eps_i = N_i^2`` of the constituents [1] (``Im >= 0``),
        broadcasting together.
    fractions : sequence of array_like of float
        Volume fractions ``f_i`` in [0, 1], one per constituent, summing to 1 [1].

    Returns
    -------
    ndarray of complex
        The ``eps`` solving ``sum_i f_i (eps_i - eps) / (eps_i + 2 eps) = 0`` [1]_ (spheres
        in 3-D) that is physical. Two constituents: the closed form of
        :func:`labbrdf.films.matrices.bruggeman`. Three: the root continued from the
        two-constituent root of the two largest fractions as the third fraction grows
        from 0 to its value (Newton steps along the path), the selection of Jansson &
        Arwin [3]_.

    Raises
    ------
    ValueError
        Not 2 or 3 constituents, fractions outside [0, 1] or not summing to 1, non-finite
        input, ``Im(eps) < 0``, or a continuation that does not converge.
    """
    if len(eps) != len(fractions) or len(eps) not in (2, 3):
        raise ValueError(
            f"eps, fractions: expected 2 or 3 constituents with one fraction each, got "
            f"{len(eps)} and {len(fractions)}"
        )
    e = [np.asarray(x, complex) for x in eps]
    f = [np.asarray(x, float) for x in fractions]
    if any(np.any((x < 0) | (x > 1)) for x in f) or not np.allclose(sum(f), 1.0, atol=1e-12):
        raise ValueError("fractions: expected volume fractions in [0, 1] that sum to 1")
    if len(e) == 2:
        return bruggeman(e[0], e[1], f[0])
    e = list(np.broadcast_arrays(*e, *f)[:3])
    f = [np.broadcast_to(x, e[0].shape) for x in f]
    # the third constituent is the one of smallest fraction (ties: the last)
    order = np.argsort(np.stack([np.mean(x) for x in f]), kind="stable")[::-1]
    a, b, c = (int(j) for j in order)
    pair = f[a] + f[b]
    safe = np.where(pair > 0, pair, 1.0)
    x = np.where(pair > 0, bruggeman(e[a], e[b], np.clip(f[a] / safe, 0.0, 1.0)), e[c])
    for t in np.linspace(0.0, 1.0, _CONTINUATION_STEPS + 1)[1:]:
        fc = t * f[c]
        fa = np.where(pair > 0, f[a] / safe * (1.0 - fc), 0.0)
        fb = 1.0 - fc - fa
        for _ in range(_NEWTON_STEPS):
            g, dg = _residual(x, [e[a], e[b], e[c]], [fa, fb, fc])
            x = x - g / dg
    g, _ = _residual(x, [e[a], e[b], e[c]], [f[a], f[b], f[c]])
    if not np.all(np.isfinite(x)) or np.max(np.abs(g), initial=0.0) > 1e-9:
        raise ValueError("bruggeman_mix: the three-constituent root did not converge")
    return np.asarray(x)


def _component(c: Any) -> disp.Dispersion | str:
    """A constituent: a dispersion, ``void`` (``N = 1``) or ``@NAME`` (kept as a reference)."""
    if isinstance(c, disp.Dispersion):
        return c
    if isinstance(c, str) and c.strip().lower() == VOID:
        return disp.Constant(1.0, 0.0)
    if isinstance(c, str) and re.fullmatch(r"@[\w.-]+", c.strip()):
        return c.strip()
    raise FilmError(
        f"ema: constituent {c!r}: expected a material, 'void' or '@LAYER' (a layer's name, "
        "@substrate or @ambient)"
    )


@dataclass(frozen=True)
class Ema:
    """Bruggeman effective medium of two or three constituents (a layer material).

    Parameters
    ----------
    components : sequence
        2 or 3 constituents: a :class:`~labbrdf.nk.dispersion.Dispersion`, ``"void"``
        (``N = 1``) or ``"@NAME"``, the material of the layer ``NAME`` of the stack
        (``@substrate``, ``@ambient``). :func:`~labbrdf.films.as_material` reads names and
        dicts of constituents too (``"ema(@film, void)"``).
    fraction : float
        Volume fraction of the second constituent, in [0, 1] [1] (WVASE's "% material 2").
    fraction3 : float
        Volume fraction of the third constituent [1] (three constituents only); the first
        takes ``1 - fraction - fraction3``.

    Notes
    -----
    A constituent's own parameters stay as given; ``@NAME`` follows the referenced layer's
    material, fitted or not. Evaluated by :meth:`labbrdf.Stack.indices` with
    :func:`bruggeman_mix`.
    """

    components: tuple[disp.Dispersion | str, ...]
    fraction: float = 0.5
    fraction3: float = 0.0
    name = "ema"

    def __post_init__(self) -> None:
        comps = tuple(_component(c) for c in self.components)
        object.__setattr__(self, "components", comps)
        if len(comps) not in (2, 3):
            raise FilmError(f"ema: expected 2 or 3 constituents, got {len(comps)}")
        f2, f3 = float(self.fraction), float(self.fraction3)
        if len(comps) == 2 and f3 != 0.0:
            raise FilmError("ema: fraction3 needs a third constituent")
        if not (0.0 <= f2 <= 1.0 and 0.0 <= f3 <= 1.0 and f2 + f3 <= 1.0 + 1e-12):
            raise FilmError(
                f"ema: fractions must be in [0, 1] with fraction + fraction3 <= 1, got "
                f"{f2:g} and {f3:g}"
            )
        object.__setattr__(self, "fraction", f2)
        object.__setattr__(self, "fraction3", f3)

    @property
    def references(self) -> list[str]:
        """The layer names the constituents refer to (``@NAME`` without the ``@``)."""
        return [c[1:] for c in self.components if isinstance(c, str)]

    @property
    def params(self) -> dict[str, float]:
        """name -> value."""
        out = {"fraction": self.fraction}
        return out if len(self.components) == 2 else {**out, "fraction3": self.fraction3}

    def bounds(self) -> dict[str, tuple[float, float]]:
        """Default search box."""
        return {k: (0.0, 1.0) for k in self.params}

    def units(self) -> dict[str, str]:
        """Units of every parameter."""
        return dict.fromkeys(self.params, "1")

    def with_params(self, values: Mapping[str, float]) -> Ema:
        """A copy with ``fraction`` / ``fraction3`` replaced."""
        bad = sorted(set(values) - set(self.params))
        if bad:
            raise FilmError(f"ema: unknown parameter(s) {bad}; parameters: {sorted(self.params)}")
        p = {**self.params, **values}
        return Ema(self.components, p["fraction"], p.get("fraction3", 0.0))

    def mix(self, eps: Sequence[ArrayLike]) -> NDArray:
        """The mixture's ``eps`` from its constituents' (in order) [1]."""
        f2, f3 = self.fraction, self.fraction3
        fr = [1.0 - f2, f2] if len(eps) == 2 else [max(1.0 - f2 - f3, 0.0), f2, f3]
        return bruggeman_mix(eps, fr)

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe form."""
        comps = [c if isinstance(c, str) else c.to_dict() for c in self.components]
        return {"model": "ema", "components": comps, **self.params}

    def __str__(self) -> str:
        names = [c if isinstance(c, str) else c.name for c in self.components]
        return f"ema({', '.join(names)})"
