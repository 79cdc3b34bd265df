"""Weighted least squares as a function of a flat, bounded search vector.

Linear amplitudes are profiled out by exact bounded linear least squares; a model's
data-driven starting point is its own (:meth:`labbrdf.models.Model.guess`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import progress
from ..models import Model, Parameters
from .data import FitData, FitError

__all__ = ["Objective", "check_quantity"]

_PENALTY = 1e100  # objective value for non-finite model output (inf breaks local methods)


def _bounded_lsq(G: NDArray, g: NDArray, lo: NDArray, hi: NDArray) -> NDArray:
    """Minimise ``p^T G p - 2 g^T p`` subject to ``lo <= p <= hi`` (exact, small k).

    For positive definite G the minimiser is the unconstrained one when that is feasible;
    otherwise some coefficient sits at one of its bounds, and the rest solve the same
    problem one size smaller (recursion over 2k bound choices; k is 1 or 2 in our models).
    A singular G (a basis function that vanishes) falls back to the bounds enumeration.
    """
    k = g.size
    if k == 1:
        p = g[0] / G[0, 0] if G[0, 0] > 0 else 0.0
        return np.array([min(max(p, lo[0]), hi[0])])
    if k == 2:
        det = G[0, 0] * G[1, 1] - G[0, 1] * G[1, 0]
        if det > 0:
            p = np.array(
                [(g[0] * G[1, 1] - g[1] * G[0, 1]) / det, (g[1] * G[0, 0] - g[0] * G[1, 0]) / det]
            )
            if lo[0] <= p[0] <= hi[0] and lo[1] <= p[1] <= hi[1]:
                return p
        best2, best_val2 = (min(max(0.0, lo[0]), hi[0]), min(max(0.0, lo[1]), hi[1])), math.inf
        for j, o in ((0, 1), (1, 0)):
            for bound in (lo[j], hi[j]):
                if not math.isfinite(bound):
                    continue
                po = (g[o] - G[o, j] * bound) / G[o, o] if G[o, o] > 0 else 0.0
                po = min(max(po, lo[o]), hi[o])
                q = (bound, po) if j == 0 else (po, bound)
                val = (
                    G[0, 0] * q[0] * q[0]
                    + 2 * G[0, 1] * q[0] * q[1]
                    + G[1, 1] * q[1] * q[1]
                    - 2 * (g[0] * q[0] + g[1] * q[1])
                )
                if val < best_val2:
                    best2, best_val2 = q, val
        return np.array(best2, float)
    else:
        try:
            p = np.linalg.solve(G, g)
            if np.all(p >= lo) and np.all(p <= hi):
                return p
        except np.linalg.LinAlgError:
            pass
    best, best_val = np.clip(np.zeros(k), lo, hi), math.inf
    for j in range(k):
        rest = [i for i in range(k) if i != j]
        for bound in (lo[j], hi[j]):
            if not math.isfinite(bound):
                continue
            sub = _bounded_lsq(
                G[np.ix_(rest, rest)], g[rest] - G[rest, j] * bound, lo[rest], hi[rest]
            )
            p = np.empty(k)
            p[j] = bound
            p[rest] = sub
            val = p @ G @ p - 2.0 * g @ p
            if val < best_val:
                best, best_val = p, val
    return best


def check_quantity(model: Model, quantity: str) -> None:
    """Refuse data of a quantity the model does not describe (BTDF to a reflection model).

    Raises
    ------
    FitError
        Names the model, the quantity and what the model takes.
    """
    takes = getattr(model, "quantities", ("brdf", "specular_intensity"))
    if quantity not in takes:
        hint = (
            "; fit transmission data with a transmission form, e.g. abg with transmission=True"
            if quantity == "btdf"
            else ""
        )
        raise FitError(
            f"model {model.name!r} describes {list(takes)}, not {quantity!r} data{hint}"
        )


class Objective:
    """Weighted least squares of a model against data, as a function of a flat vector.

    The search vector holds the varying, non-profiled parameters, each mapped to [0, 1]
    across its bounds (on a log scale for ``log`` parameters; unmapped where a bound is
    infinite). Linear amplitudes listed in ``profile`` are solved for at every call by
    bounded linear least squares (exact, so their bounds hold).

    Parameters
    ----------
    model : Model
        The forward model.
    data : FitData
        Clean data (finite values).
    params : Parameters
        Initial values, bounds and ``vary`` flags.
    weights : ndarray
        Per-point weights ``1/sigma^2`` (ones when the data have no sigma).
    profile : sequence of str
        Linear parameters to profile out.
    linear_upper : callable, optional
        ``linear_upper(values) -> float``: an extra upper bound on the single profiled
        parameter (the energy constraint).
    absolute : bool
        The weights are ``1/sigma^2`` of the data's own sigma. Only then is a model's own
        variance (:meth:`~labbrdf.models.Model.point_variance`, a Monte Carlo model's
        noise) added to sigma^2: the weights become ``1 / (sigma^2 + var_model(p))`` at
        the parameters being tried. With uniform or relative weights the noise scale is
        estimated from the residuals, which then include the model's noise.
    """

    def __init__(
        self,
        model: Model,
        data: FitData,
        params: Parameters,
        weights: NDArray,
        profile: Sequence[str] = (),
        linear_upper: Callable[[dict[str, float]], float] | None = None,
        absolute: bool = False,
    ) -> None:
        check_quantity(model, data.quantity)
        self.model = model
        self.data = data
        self.params = params
        self.profile = tuple(profile)
        self.linear_upper = linear_upper
        self.names = [k for k in params.varying() if k not in self.profile]
        self.ti = np.radians(np.asarray(data.theta_i_deg, float))
        self.tr = np.radians(np.asarray(data.theta_r_deg, float))
        self.pr = np.radians(np.asarray(data.phi_r_deg, float))
        self.wl = None if data.wavelength_nm is None else np.asarray(data.wavelength_nm, float)
        self.y = np.asarray(data.value, float)
        self.w = np.asarray(weights, float)
        self.sw = np.sqrt(self.w)
        self.base = {k: p.value for k, p in params.items()}
        # a model that overrides point_variance has a noise of its own (not evaluated here:
        # a Monte Carlo model's first evaluation may fix its grid from the points it sees)
        self.model_noise = bool(absolute) and (
            type(model).point_variance is not Model.point_variance
        )
        ps = [params[k] for k in self.names]
        self._log = np.array([p.log for p in ps], bool)
        lo = np.array([p.min for p in ps])
        hi = np.array([p.max for p in ps])
        self._tlo = np.where(self._log, np.log(np.where(self._log, lo, 1.0)), lo)
        self._thi = np.where(self._log, np.log(np.where(self._log, hi, 1.0)), hi)
        self._scaled = np.isfinite(self._tlo) & np.isfinite(self._thi) & (self._thi > self._tlo)
        self._spec = [
            (k, bool(sc), float(a), float(b - a) if sc else 1.0, bool(lg))
            for k, sc, a, b, lg in zip(
                self.names, self._scaled, self._tlo, self._thi, self._log, strict=True
            )
        ]
        self._lin_lo = np.array([params[k].min for k in self.profile])
        self._lin_hi = np.array([params[k].max for k in self.profile])
        self.nfev = 0
        self.best_f = math.inf
        self.best_x: NDArray | None = None

    # ---- vector <-> values
    @property
    def n(self) -> int:
        """Length of the search vector (varying, non-profiled parameters)."""
        return len(self.names)

    def to_vector(self, values: Mapping[str, float]) -> NDArray[np.float64]:
        """Search vector of the parameter values ``values`` (name -> natural value)."""
        v = np.array([values[k] for k in self.names], float)
        t = np.where(self._log, np.log(np.where(self._log, v, 1.0)), v)
        span = np.where(self._scaled, self._thi - self._tlo, 1.0)
        return np.where(self._scaled, (t - self._tlo) / span, t)

    def from_vector(self, x: ArrayLike) -> dict[str, float]:
        """Every parameter's natural value at search vector ``x`` (profiled ones unsolved)."""
        vals = dict(self.base)
        for (k, scaled, lo, span, log), xi in zip(self._spec, np.asarray(x), strict=True):
            t = lo + float(xi) * span if scaled else float(xi)
            v = math.exp(t) if log else t
            if scaled and not 0.0 < xi < 1.0:  # exp(log(max)) can miss max by an ulp
                v = self.params[k].max if xi >= 1.0 else self.params[k].min
            vals[k] = v
        return vals

    def bounds(self) -> tuple[NDArray, NDArray]:
        """Lower and upper bounds of the search vector (0 and 1 where mapped)."""
        lo = np.where(self._scaled, 0.0, self._tlo)
        hi = np.where(self._scaled, 1.0, self._thi)
        return lo, hi

    def linear_basis_missing(self) -> bool:
        """True when the model gives no linear components (cannot profile)."""
        one = slice(0, 1)
        wl = None if self.wl is None else self.wl[one]
        comps = self.model.linear_components(
            self.base, self.ti[one], self.tr[one], self.pr[one], wl
        )
        return comps is None

    # ---- model
    def point_sw(self, vals: Mapping[str, float]) -> NDArray[np.float64]:
        """Square roots of the residual weights at parameter values ``vals``.

        ``sqrt(w)``, or with :attr:`model_noise` ``1 / sqrt(1/w + var_model(vals))``.
        """
        if not self.model_noise:
            return self.sw
        var = self.model.point_variance(vals, self.ti, self.tr, self.pr, self.wl)
        if var is None:
            return self.sw
        return 1.0 / np.sqrt(1.0 / self.w + np.asarray(var, float))

    def describe_weighting(self, weighting: str, vals: Mapping[str, float]) -> str:
        """``weighting`` (the words of the fit result) and how the model's noise entered.

        With :attr:`model_noise` the variance was added; a model with a variance fitted
        with uniform or relative weights has its noise in the residual scatter that scales
        the covariance, and the words give its median size relative to the model.
        """
        var = self.model.point_variance(vals, self.ti, self.tr, self.pr, self.wl)
        if var is None:
            return weighting
        if self.model_noise:
            return f"{weighting} + the model's Monte Carlo variance (in quadrature, per point)"
        f = np.abs(self.model_values(vals))
        ok = f > 0
        rel = float(np.median(np.sqrt(np.asarray(var, float)[ok]) / f[ok])) if ok.any() else 0.0
        return (
            f"{weighting}; the model's Monte Carlo error (median {100 * rel:.2g} % of the "
            "model) is part of the residual scatter that scales the covariance"
        )

    def model_values(self, vals: Mapping[str, float]) -> NDArray[np.float64]:
        """The model at every data point for full parameter values ``vals``.

        Callers wrap the search in ``np.errstate`` (grazing angles may overflow).
        """
        return np.asarray(self.model._evaluate(vals, self.ti, self.tr, self.pr, self.wl), float)

    def solve(self, vals: dict[str, float]) -> tuple[dict[str, float], float]:
        """Fill in the profiled parameters; return the values and chi-square."""
        vals, r = self.residuals(vals)
        return vals, float(r @ r)

    def residuals(self, vals: dict[str, float]) -> tuple[dict[str, float], NDArray[np.float64]]:
        """Fill in the profiled parameters; return the values and the weighted residuals.

        The residuals are ``sqrt(w) (y - f)``; chi-square is their sum of squares. With
        profiled amplitudes this is the variable-projection residual of Golub and Pereyra
        (1973): the amplitudes are the exact bounded linear least-squares solution at the
        nonlinear parameters ``vals``.
        """
        sw = self.point_sw(vals)
        if not self.profile:
            return vals, sw * (self.y - self.model_values(vals))
        comps = self.model.linear_components(vals, self.ti, self.tr, self.pr, self.wl)
        if comps is None:
            raise FitError(f"model {self.model.name!r} gave no linear components to profile")
        resid = self.y
        for k, b in comps.items():
            if k not in self.profile:
                resid = resid - vals[k] * b
        c = sw * resid
        hi = self._lin_hi
        if self.linear_upper is not None:
            hi = np.minimum(hi, self.linear_upper(vals))
        hi = np.maximum(hi, self._lin_lo)
        if len(self.profile) == 1:  # the common case, kept free of small-array overhead
            a = sw * comps[self.profile[0]]
            G, g = float(a @ a), float(a @ c)
            p0 = g / G if G > 0 else 0.0
            p0 = min(max(p0, float(self._lin_lo[0])), float(hi[0]))
            vals[self.profile[0]] = p0
            return vals, c - p0 * a
        A = np.stack([comps[k] for k in self.profile], axis=1) * sw[:, None]
        p = _bounded_lsq(A.T @ A, A.T @ c, self._lin_lo, hi)
        for k, v in zip(self.profile, p, strict=True):
            vals[k] = float(v)
        return vals, c - A @ p

    def __call__(self, x: NDArray, grad: NDArray | None = None) -> float:
        """chi-square at search vector ``x`` (nlopt signature; finite-difference gradient)."""
        f = self._f(x)
        if grad is not None and grad.size > 0:
            h = max(1e-6, self.model.fd_rel_step or 0.0)  # central, on the unit-box scale
            for j in range(x.size):
                xp, xm = np.array(x, float), np.array(x, float)
                xp[j] += h
                xm[j] -= h
                grad[j] = (self._f(xp) - self._f(xm)) / (2 * h)
        return f

    def _f(self, x: NDArray) -> float:
        self.nfev += 1
        progress.report(evaluations=self.nfev, best=self.best_f)
        _, chi2 = self.solve(self.from_vector(x))
        if not math.isfinite(chi2):
            return _PENALTY
        if chi2 < self.best_f:
            self.best_f, self.best_x = chi2, np.array(x, float)
        return chi2

    def residual_vector(self, x: NDArray) -> NDArray[np.float64]:
        """Weighted residuals at search vector ``x``, counted in :attr:`nfev` like a call.

        Non-finite residuals (model overflow at grazing angles) become ``sqrt(_PENALTY /
        m)`` each, so their chi-square is the penalty value the nlopt stages see.
        """
        self.nfev += 1
        progress.report(evaluations=self.nfev, best=self.best_f)
        _, r = self.residuals(self.from_vector(x))
        if not np.all(np.isfinite(r)):
            return np.full(r.size, math.sqrt(_PENALTY / max(r.size, 1)))
        chi2 = float(r @ r)
        if chi2 < self.best_f:
            self.best_f, self.best_x = chi2, np.array(x, float)
        return r
