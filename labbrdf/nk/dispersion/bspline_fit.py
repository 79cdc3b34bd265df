"""A B-spline dielectric function fitted to tabulated ``eps``, its size chosen by AIC or BIC.

``eps`` of the B-spline model is linear in its ``eps_inf`` and coefficients (the
Kramers-Kronig transform is linear), so the fit to ``eps(E)`` (a point-by-point result, a
table) is a non-negative linear least-squares problem: no starting point, no optimiser path.
The number of coefficients ``n`` is chosen as Likhachev (Thin Solid Films 636, 519 (2017))
does, by the smallest information criterion over the candidates: with ``N`` residuals
(``eps1`` and ``eps2`` at each energy, divided by ``sigma``), ``p = n + 1`` parameters and
``chi2`` the weighted sum of squares, ``AIC = chi2 + 2 p`` and ``BIC = chi2 + p ln N`` (the
Gaussian log-likelihood with a known ``sigma``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import nnls

from ._kk import kk_eps1, panel_edges
from .base import DispersionError, FloatArray
from .bspline import BSpline, basis, knots

__all__ = ["BSplineChoice", "choose", "fit_eps"]


@dataclass(frozen=True)
class BSplineChoice:
    """The chosen B-spline and each candidate's ``n -> (chi2, AIC, BIC)``."""

    model: BSpline
    criterion: str
    scores: dict[int, tuple[float, float, float]]

    def __str__(self) -> str:
        rows = [f"{'n':>4} {'chi2':>12} {'AIC':>12} {'BIC':>12}"]
        for n, (chi2, aic, bic) in self.scores.items():
            mark = "  <- chosen" if n == len(self.model.coefficients) else ""
            rows.append(f"{n:>4} {chi2:>12.4g} {aic:>12.4g} {bic:>12.4g}{mark}")
        return f"B-spline size by {self.criterion.upper()}\n" + "\n".join(rows)


def _design(energy: FloatArray, e_lo: float, e_hi: float, n: int) -> FloatArray:
    """Columns ``[eps_inf, B_1 .. B_n]`` of the stacked ``[eps1; eps2]`` at ``energy``."""
    b = basis(energy, e_lo, e_hi, n)
    upper = max(1e4, 100 * float(energy.max()))
    edges = panel_edges(upper, knots(e_lo, e_hi, n))

    def column(j: int) -> Callable[[FloatArray], FloatArray]:
        return lambda x: np.asarray(basis(x, e_lo, e_hi, n)[:, j])

    k = np.stack([kk_eps1(column(j), energy, edges) for j in range(n)], axis=1)
    ones = np.concatenate([np.ones(energy.size), np.zeros(energy.size)])
    return np.column_stack([ones, np.vstack([k, b])])


def fit_eps(
    energy_ev: ArrayLike,
    eps: ArrayLike,
    n: int,
    e_lo: float,
    e_hi: float,
    sigma: float | ArrayLike = 1.0,
) -> tuple[BSpline, float]:
    """The B-spline of ``n`` coefficients closest to ``eps`` and its ``chi2``.

    Parameters
    ----------
    energy_ev : array_like
        Photon energies [eV].
    eps : array_like
        Complex dielectric function at those energies [1].
    n : int
        Number of coefficients (>= 1).
    e_lo, e_hi : float
        Support of ``eps2`` [eV]; wider than the data where ``eps2`` does not vanish there.
    sigma : float or array_like
        Standard deviation of ``eps1`` and ``eps2`` [1] (scalar or one per energy).
    """
    e = np.asarray(energy_ev, float).ravel()
    z = np.asarray(eps, complex).ravel()
    if e.size != z.size or e.size < 2 or n < 1 or not np.all(e > 0):
        raise DispersionError(
            "bspline fit: expected >= 2 energies > 0, eps of the same size, n >= 1"
        )
    s = np.broadcast_to(np.asarray(sigma, float), e.shape)
    w = 1 / np.concatenate([s, s])
    a = _design(e, e_lo, e_hi, n) * w[:, None]
    y = np.concatenate([z.real, z.imag]) * w
    x, rnorm = nnls(a, y, maxiter=50 * a.shape[1])
    return BSpline(float(x[0]), e_lo, e_hi, tuple(float(c) for c in x[1:])), float(rnorm**2)


def choose(
    energy_ev: ArrayLike,
    eps: ArrayLike,
    candidates: Iterable[int],
    e_lo: float,
    e_hi: float,
    sigma: float | ArrayLike = 1.0,
    criterion: str = "bic",
) -> BSplineChoice:
    """Fit each candidate size and keep the one of smallest ``criterion`` (``aic``, ``bic``)."""
    if criterion not in ("aic", "bic"):
        raise DispersionError(f"bspline fit: criterion must be 'aic' or 'bic', got {criterion!r}")
    m = 2 * np.asarray(energy_ev).size
    scores, models = {}, {}
    for n in sorted(set(candidates)):
        models[n], chi2 = fit_eps(energy_ev, eps, n, e_lo, e_hi, sigma)
        p = n + 1
        scores[n] = (chi2, chi2 + 2 * p, chi2 + p * float(np.log(m)))
    if not scores:
        raise DispersionError("bspline fit: no candidate sizes given")
    col = 1 if criterion == "aic" else 2
    best = min(scores, key=lambda n: scores[n][col])
    return BSplineChoice(models[best], criterion, scores)
