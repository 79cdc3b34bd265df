"""Kramers-Kronig ``eps1`` of a model given by its ``eps2``: a fixed-node principal value.

Used by the models whose ``eps1`` has no convenient closed form (Cody-Lorentz, B-spline).
The nodes depend only on the model's parameters, never on the energies asked for, so
``eps1`` is a smooth function of the parameters (what a fit's finite differences need).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from .base import FloatArray

#: Gauss-Legendre nodes per panel
_ORDER = 8
#: log-spaced panels between 1e-3 eV and the upper limit
_LOG_PANELS = 40
_GL_X, _GL_W = np.polynomial.legendre.leggauss(_ORDER)


def _nodes(edges: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Gauss-Legendre nodes and weights of the panels between consecutive ``edges``."""
    a, b = edges[:-1, None], edges[1:, None]
    x = (a + b) / 2 + (b - a) / 2 * _GL_X
    w = (b - a) / 2 * _GL_W
    return x.ravel(), w.ravel()


def panel_edges(upper: float, breaks: Iterable[float], kinks: Iterable[float] = ()) -> FloatArray:
    """Panel edges on ``[0, upper]`` [eV]: log-spaced, plus ``breaks`` (peaks, knots).

    Around each of ``kinks`` (where ``eps2`` has a jump in slope) the panels shrink
    geometrically, 0.5 eV to 3e-5 eV: for ``E`` just beside a kink the subtracted integrand
    varies on the scale of ``E``'s distance to the kink, which these panels resolve.
    """
    graded = [k + s * 0.5 * 2.0**-j for k in kinks for s in (-1, 1) for j in range(15)]
    e = np.concatenate(
        [[0.0, upper], np.geomspace(1e-3, upper, _LOG_PANELS), list(breaks), list(kinks), graded]
    )
    e = np.unique(e[(e >= 0) & (e <= upper)])
    return np.asarray(e[np.concatenate([[True], np.diff(e) > 1e-9 * upper])])


def kk_eps1(
    eps2: Callable[[FloatArray], FloatArray],
    energy_ev: FloatArray,
    edges: FloatArray,
    tail: float = 0.0,
) -> FloatArray:
    """``(2/pi) P int_0^inf xi eps2(xi) / (xi^2 - E^2) d xi`` at each ``E`` [eV].

    The pole is subtracted: with ``g(xi) = xi eps2(xi)`` and ``M = edges[-1]``,
    ``P int_0^M g/(xi^2 - E^2) = int_0^M (g(xi) - g(E))/(xi^2 - E^2) + g(E) ln((M - E)/(M +
    E)) / (2 E)``; the first integrand is as smooth as ``g`` and is integrated by
    Gauss-Legendre on the panels ``edges`` (put a panel edge at every kink of ``eps2``).
    Beyond ``M``, ``eps2 ~ tail / xi^3`` adds ``tail (1/(3 M^3) + E^2/(5 M^5))``; the
    left-out next order is ``(E0/M)^2`` smaller for a peak at ``E0`` (1e-15 at ``M = 10^4``).

    Parameters
    ----------
    eps2 : callable
        ``eps2(xi)`` [1] at energies ``xi`` [eV] (an array).
    energy_ev : ndarray
        Energies ``E`` [eV], ``0 < E < M``.
    edges : ndarray
        Increasing panel edges from 0 to ``M`` [eV] (:func:`panel_edges`).
    tail : float
        ``lim xi^3 eps2(xi)`` [eV^3] of the high-energy tail.

    Returns
    -------
    ndarray
        ``eps1(E) - eps_inf`` [1], the shape of ``energy_ev``.
    """
    e = np.asarray(energy_ev, float)
    flat = e.ravel()
    x, w = _nodes(edges)
    gx = x * eps2(x)
    ge = flat * eps2(flat)
    upper = float(edges[-1])
    out = np.empty_like(flat)
    for i in range(0, flat.size, 256):  # bounded memory: 256 energies x nodes at a time
        ee, gg = flat[i : i + 256, None], ge[i : i + 256, None]
        den = x * x - ee * ee
        safe = np.where(den == 0, 1.0, den)
        integrand = np.where(den == 0, 0.0, (gx - gg) / safe)
        out[i : i + 256] = integrand @ w
    out += ge * np.log((upper - flat) / (upper + flat)) / (2 * flat)
    out += tail * (1 / (3 * upper**3) + flat**2 / (5 * upper**5))
    return np.asarray((2 / np.pi) * out).reshape(e.shape)
