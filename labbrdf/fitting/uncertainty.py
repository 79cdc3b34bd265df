"""Covariance, standard errors, correlations and identifiability flags from the Jacobian."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .objective import Objective

__all__ = [
    "AT_BOUND_FRAC",
    "COND_MAX",
    "CORREL_MAX",
    "REL_STDERR_MAX",
    "REL_STDERR_POOR",
    "at_bound",
    "jacobian",
    "noise_meat",
    "uncertainties",
]

#: |correlation| above which both parameters are flagged "not identifiable"
CORREL_MAX = 0.99
#: relative standard error above which a parameter is flagged "not identifiable"
REL_STDERR_MAX = 1.0
#: relative standard error above which a parameter is flagged "poorly determined" (fewer
#: than about two significant digits are supported by the data)
REL_STDERR_POOR = 0.05
#: condition number of the correlation form of J^T W J above which it counts as singular
COND_MAX = 1e10
#: a parameter within this fraction of its bound span from a bound is "at bound"
AT_BOUND_FRAC = 1e-6


def jacobian(obj: Objective, vals: dict[str, float], names: list[str]) -> NDArray:
    """Weighted residual Jacobian d(sw * (y - f))/dp in the parameters' natural scale.

    Central differences, step ``6e-6 * max(|p|, 1e-3 * span)`` (6e-6 ~ eps^(1/3), the
    step that balances truncation and round-off), or the model's ``fd_rel_step`` of the
    span where that is larger (a Monte Carlo model); one-sided inward at a bound so the
    model is never evaluated outside the parameter box. The weights are those at ``vals``
    (:meth:`Objective.point_sw`).
    """
    J = np.empty((obj.y.size, len(names)))
    f0 = obj.model_values(vals)
    sw = obj.point_sw(vals)
    rel = obj.model.fd_rel_step
    for j, k in enumerate(names):
        p = obj.params[k]
        v = vals[k]
        span = p.max - p.min
        h = 6e-6 * max(abs(v), 1e-3 * span if math.isfinite(span) else 1e-3)
        if rel is not None and math.isfinite(span):
            h = max(h, rel * span)
        up, dn = v + h <= p.max, v - h >= p.min
        vp, vm = dict(vals), dict(vals)
        if up and dn:
            vp[k], vm[k] = v + h, v - h
            d = (obj.model_values(vp) - obj.model_values(vm)) / (2 * h)
        elif up:
            vp[k] = v + h
            d = (obj.model_values(vp) - f0) / h
        else:
            vm[k] = v - h
            d = (f0 - obj.model_values(vm)) / h
        J[:, j] = -sw * d
    return J


def noise_meat(obj: Objective, vals: dict[str, float], J: NDArray) -> NDArray | None:
    """``J^T S C S J`` of the sandwich covariance, for a model with correlated noise.

    ``S = diag(sqrt(w_eff))`` are the residual weights actually used (data sigma and the
    model's variance in quadrature, :meth:`Objective.point_sw`) and
    ``C = diag(sigma^2) + sum_k n_k n_k^T`` the true covariance of data minus model, with
    the model's noise components ``n_k`` (:meth:`labbrdf.models.Model.point_noise`).
    Weighted least squares with weights that are not ``C^-1`` has the parameter covariance
    ``H^-1 (J^T S C S J) H^-1``, ``H = J^T J`` (the sandwich, e.g. White 1980): the
    quadrature weights treat the noise of neighbouring points as independent, the
    sandwich does not. None where the weights are not the data's sigma, the model has
    no noise components or J is not finite.
    """
    if not obj.model_noise or not np.all(np.isfinite(J)):
        return None
    comps = obj.model.point_noise(vals, obj.ti, obj.tr, obj.pr, obj.wl)
    if comps is None:
        return None
    sw = obj.point_sw(vals)
    data_part = sw * sw / obj.w  # sigma^2 w_eff
    g = J.T @ (np.asarray(comps, float) * sw).T  # (n, K)
    return np.asarray((J * data_part[:, None]).T @ J + g @ g.T, float)


def uncertainties(
    J: NDArray,
    names: list[str],
    values: dict[str, float],
    scale: float,
    nfree: int,
    meat: NDArray | None = None,
) -> tuple[
    NDArray | None,
    dict[str, float | None],
    dict[str, dict[str, float]],
    dict[str, list[str]],
    float | None,
]:
    """Covariance, stderr, correlations and identifiability reasons from J.

    With ``meat`` (:func:`noise_meat`) the covariance is the sandwich
    ``H^-1 meat H^-1`` instead of ``scale H^-1``.
    """
    n = len(names)
    reasons: dict[str, list[str]] = {k: [] for k in names}
    stderr: dict[str, float | None] = {k: None for k in names}
    correl: dict[str, dict[str, float]] = {k: {} for k in names}
    if not np.all(np.isfinite(J)):
        for k in names:
            reasons[k].append("not identifiable: non-finite Jacobian at the optimum")
        return None, stderr, correl, reasons, None
    H = J.T @ J
    d = np.sqrt(np.diag(H))
    for j, k in enumerate(names):
        if d[j] == 0:
            reasons[k].append("not identifiable: the data do not depend on it")
    ok = d > 0
    idx = np.flatnonzero(ok)
    covar = np.full((n, n), np.nan)
    cond = None
    if idx.size:
        C = H[np.ix_(idx, idx)] / np.outer(d[idx], d[idx])
        evals, evecs = np.linalg.eigh(C)
        cond = float(evals[-1] / evals[0]) if evals[0] > 0 else math.inf
        if not cond < COND_MAX:
            for e_i, v in zip(evals, evecs.T, strict=True):
                if e_i <= evals[-1] / COND_MAX:
                    for jj in np.flatnonzero(np.abs(v) > 0.1):
                        k = names[idx[jj]]
                        reasons[k].append(
                            f"not identifiable: J^T W J is (near) singular, condition number "
                            f"{cond:.3g} > {COND_MAX:.0e}"
                        )
        Ci = np.linalg.pinv(C, rcond=1.0 / COND_MAX, hermitian=True)
        sub = Ci / np.outer(d[idx], d[idx]) * scale
        if meat is not None:
            sub = sub @ meat[np.ix_(idx, idx)] @ sub / (scale * scale)
        covar[np.ix_(idx, idx)] = sub
    for j, k in enumerate(names):
        if not ok[j] or not covar[j, j] > 0 or any("singular" in r for r in reasons[k]):
            continue
        se = math.sqrt(covar[j, j])
        stderr[k] = se
        v = values[k]
        if se > REL_STDERR_MAX * abs(v):
            reasons[k].append(
                f"not identifiable: stderr {se:.3g} exceeds {REL_STDERR_MAX:g} x |value| "
                f"{abs(v):.3g}"
            )
        elif se > REL_STDERR_POOR * abs(v):
            reasons[k].append(
                f"poorly determined: stderr {se:.3g} is {100 * se / abs(v):.3g} % of the value"
            )
        for i, k2 in enumerate(names):
            if i != j and _var_ok(covar, i):
                c = covar[i, j] / math.sqrt(covar[i, i] * covar[j, j])
                correl[k][k2] = float(c)
                if abs(c) > CORREL_MAX:
                    reasons[k].append(
                        f"not identifiable: |correl({k}, {k2})| = {abs(c):.4f} > {CORREL_MAX}"
                    )
    return covar, stderr, correl, reasons, cond


def _var_ok(covar: NDArray, i: int) -> bool:
    return bool(np.isfinite(covar[i, i]) and covar[i, i] > 0)


def at_bound(q: Any, bound: float) -> bool:
    """Whether ``q`` ended within :data:`AT_BOUND_FRAC` of its box from ``bound``.

    On the scale the parameter was searched on: a log-scale parameter (``q.log``) is at its
    bound when ``log q`` is within that fraction of ``log(max / min)``, so a value of 1e-4 in
    a box [1e-12, 1e4] is not at its lower bound, as it would be on the linear scale.
    """
    if q.log and q.min > 0 and q.value > 0:
        tol = AT_BOUND_FRAC * math.log(q.max / q.min)
        return math.isfinite(tol) and abs(math.log(q.value / bound)) <= tol
    tol = AT_BOUND_FRAC * (q.max - q.min)
    return math.isfinite(tol) and abs(q.value - bound) <= tol
