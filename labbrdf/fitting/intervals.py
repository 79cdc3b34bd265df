"""A fit's 95 % intervals: the Wald ones, and which of them the profile of chi-square can change.

:func:`wald_params` gives every varying parameter its Wald interval; with ``ci="auto"``
or ``"profile"`` :func:`refine_intervals` replaces some or all of them by the profile's
(the rule of ``ci="auto"`` below, :func:`profile_reasons`).

A fit's Wald interval, value +- t stderr, is exact where chi-square is quadratic in the
parameters over the interval; the profile interval (the values where chi-square, minimised
over the other parameters, rises by ``delta = t^2 s``, s = 1 with the data's sigmas, else
chi2/nu) is then the same interval. The profile costs a local fit per step and is worth
computing only where the two can differ. :func:`profile_reasons` names those parameters:

- the Wald interval reaches a bound of the parameter's box (clipped: the profile is not);
- no standard error (a singular or non-finite J^T W J), or a correlation above
  :data:`~labbrdf.fitting.uncertainty.CORREL_MAX` with another parameter;
- chi-square is not quadratic over the interval: at each end of the Wald interval the
  rise of chi-square along the quadratic profile path (the others moved by
  ``delta_k Sigma[:, k] / Sigma[k, k]``, the minimiser of the quadratic form with parameter
  k held), after one Gauss-Newton step of the others from there, lies outside
  ``[RISE_LOW, RISE_HIGH] x delta``.

The band follows from how far an interval's end may move unnoticed. If the profile rises
as ``r delta (x / x_w)^2`` near the end ``x_w`` of the Wald half-width, it crosses
``delta`` at ``x_w / sqrt(r)``; the end moves by at most :data:`END_SHIFT_MAX` of the
half-width when ``1/(1 + s)^2 <= r <= 1/(1 - s)^2``. The rise measured is that of a point
on (or one step off) the path, never below the profile's (which minimises over the
others), so a rise above the band may only mean that the path missed the valley: that
parameter is profiled although it need not be (costly, never wrong). A rise below the
band is the profile's too: the interval is wider than Wald's.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray
from scipy import special

from ..models import Parameters
from .objective import Objective
from .result import FitResult
from .uncertainty import AT_BOUND_FRAC, CORREL_MAX, at_bound, jacobian

__all__ = [
    "CI_METHODS",
    "END_SHIFT_MAX",
    "RISE_HIGH",
    "RISE_LOW",
    "profile_reasons",
    "refine_intervals",
    "wald_params",
]

#: the interval choices of a fit: Wald first then the profile where it can change the
#: answer (``auto``), Wald only, or the profile of every varying parameter
CI_METHODS = ("auto", "wald", "profile")
#: the largest move of an interval's end, as a fraction of the Wald half-width, that
#: ``ci="auto"`` leaves uncomputed (a tenth: below the two significant digits of the
#: stderr that the interval is printed to, for half-widths of about 2 stderr)
END_SHIFT_MAX = 0.1
#: chi-square rise at a Wald end, over ``delta``, above which the end moves inward by
#: more than :data:`END_SHIFT_MAX`
RISE_HIGH = 1.0 / (1.0 - END_SHIFT_MAX) ** 2
#: ... and below which it moves outward by more than :data:`END_SHIFT_MAX`
RISE_LOW = 1.0 / (1.0 + END_SHIFT_MAX) ** 2


def wald_params(
    p: Parameters,
    vals: dict[str, float],
    stderr: dict[str, float | None],
    correl: dict[str, dict[str, float]],
    reasons: dict[str, list[str]],
    nfree: int,
) -> tuple[Parameters, dict[str, list[str]]]:
    """Parameters with fitted values, stderr, 95% intervals, correlations; the flags."""
    tq = float(special.stdtrit(nfree, 0.975))  # Student t 97.5 % quantile
    out = Parameters({k: copy.copy(q) for k, q in p.items()})
    flags: dict[str, list[str]] = {}
    for k, q in out.items():
        q.value = vals[k]
        if not q.vary:
            continue
        fl = []
        for side in ("min", "max"):
            if at_bound(q, getattr(q, side)):
                fl.append("at_bound")
                reasons[k].insert(
                    0, f"at bound: {q.value:.6g} at its {side} {getattr(q, side):.6g}"
                )
        if any(r.startswith("not identifiable") for r in reasons[k]):
            fl.append("not_identifiable")
        elif any(r.startswith("poorly determined") for r in reasons[k]):
            fl.append("poorly_determined")
        if fl:
            flags[k] = fl
        se = stderr[k]
        q.stderr = se
        if se is not None:
            q.ci95 = (max(q.value - tq * se, q.min), min(q.value + tq * se, q.max))
        q.correl = correl[k] or None
    return out, flags


def refine_intervals(
    res: FitResult,
    obj: Objective,
    ci: str,
    profile: Callable[[list[str], float], list[str]],
    on_wald: Callable[[FitResult], None] | None = None,
) -> bool:
    """Replace Wald intervals of ``res`` by profile ones: all (``"profile"``) or by the rule.

    Parameters
    ----------
    res : FitResult
        A fit with Wald intervals; its ``params``, ``warnings``, ``ci_methods`` and
        ``ci_reasons`` are updated in place.
    obj : Objective
        The fit's objective without profiled amplitudes, on ``res.params``.
    ci : {"auto", "profile"}
    profile : callable
        ``profile(names, delta)`` puts the profile intervals of ``names`` (level chi2_min +
        delta) into ``res.params`` and returns a warning per interval not found.
    on_wald : callable, optional
        Called with a copy of the Wald answer (``ci_method`` ``"wald"``, ``ci_reasons``
        naming the parameters about to be profiled) before any profile is computed.

    Returns
    -------
    bool
        Whether any profile was computed.
    """
    if not (math.isfinite(res.chisqr) and all(math.isfinite(v) for v in res.values.values())):
        return False
    scale = 1.0 if res.weighted else res.redchi
    delta = float(special.stdtrit(res.nfree, 0.975)) ** 2 * scale
    why = (
        dict.fromkeys(res.var_names, "requested")
        if ci == "profile"
        else profile_reasons(obj, res.params, res.var_names, res.covar, res.chisqr, delta)
    )
    res.ci_reasons = why
    if not why:
        return False
    if on_wald is not None:
        params = Parameters({k: copy.copy(q) for k, q in res.params.items()})
        wald_res = dataclasses.replace(  # the Wald answer, saying what will be profiled
            res,
            params=params,
            warnings=list(res.warnings),
            ci_method="wald",
            ci_methods=dict(res.ci_methods),
        )
        on_wald(wald_res)
    wald = {k: res.params[k].ci95 for k in why}
    res.warnings += profile(list(why), delta)
    for k in why:  # an interval not found keeps its Wald tuple (and a warning says so)
        res.ci_methods[k] = "wald" if res.params[k].ci95 is wald[k] else "profile"
    return True


def profile_reasons(
    obj: Objective,
    params: Parameters,
    names: list[str],
    covar: NDArray | None,
    chisqr: float,
    delta: float,
) -> dict[str, str]:
    """The parameters whose profile interval can differ from their Wald interval, and why.

    Parameters
    ----------
    obj : Objective
        The fit's objective without profiled amplitudes (every name a plain parameter).
    params : Parameters
        The fitted parameters with ``stderr``, Wald ``ci95`` and ``correl``.
    names : list of str
        The varying parameters, the order of ``covar``.
    covar : ndarray or None
        Their covariance.
    chisqr : float
        chi-square at the optimum.
    delta : float
        The rise of chi-square that defines the profile interval.

    Returns
    -------
    dict
        name -> the reason in words, for each parameter to profile (the rest keep Wald).
    """
    out = {}
    for j, k in enumerate(names):
        why = _static_reason(params, k)
        if why is None and covar is not None:
            why = _curvature_reason(obj, params, names, covar, j, chisqr, delta)
        if why is not None:
            out[k] = why
    return out


def _static_reason(params: Parameters, k: str) -> str | None:
    """Why parameter ``k`` needs its profile, read from the Wald answer alone (or None)."""
    q = params[k]
    if q.stderr is None or not math.isfinite(q.stderr) or q.ci95 is None:
        return "no standard error"
    if q.ci95[0] <= q.min or q.ci95[1] >= q.max:
        return "its Wald interval reaches a bound"
    c = max((abs(v) for v in (q.correl or {}).values()), default=0.0)
    if c > CORREL_MAX:
        return f"a correlation of {c:.4f} (> {CORREL_MAX})"
    return None


def _curvature_reason(
    obj: Objective,
    params: Parameters,
    names: list[str],
    covar: NDArray,
    j: int,
    chisqr: float,
    delta: float,
) -> str | None:
    """Why chi-square is not quadratic over ``names[j]``'s Wald interval (or None)."""
    if not (covar[j, j] > 0 and np.all(np.isfinite(covar[:, j]))):
        return "no standard error"
    k = names[j]
    q = params[k]
    path = covar[:, j] / covar[j, j]
    for end in q.ci95 or ():
        rise = _rise(obj, params, names, path * (end - q.value), k) - chisqr
        ratio = rise / delta
        if not (RISE_LOW <= ratio <= RISE_HIGH):  # NaN included
            return (
                f"chi2 not quadratic over its Wald interval: rises by {ratio:.3g} x the "
                f"level at {end:.6g}"
            )
    return None


def _rise(obj: Objective, params: Parameters, names: list[str], step: NDArray, k: str) -> float:
    """chi-square at the optimum moved by ``step``, after a Gauss-Newton step of the others.

    Another parameter that ends on a bound of its box stays there, as in a bounded profile
    (its gradient pushes it outward, where the box stops it); the step is clipped to the
    boxes and a parameter it takes to a bound stays there too.
    """
    vals = {n: p.value for n, p in params.items()}
    for n, s in zip(names, step, strict=True):
        p = params[n]
        if n == k or _inside(p.value, p.min, p.max):
            vals[n] = min(max(vals[n] + float(s), p.min), p.max)
    with np.errstate(all="ignore"):
        _, r = obj.residuals(dict(vals))
        chi2 = float(r @ r)
        others = [n for n in names if n != k and _inside(vals[n], params[n].min, params[n].max)]
        if not others or not math.isfinite(chi2):
            return chi2
        J = jacobian(obj, vals, others)  # d(sw (y - f))/dp: the residuals move by J dp
        if not np.all(np.isfinite(J)):
            return chi2
        dp = np.linalg.lstsq(J, -r, rcond=None)[0]
        moved = dict(vals)
        for n, d in zip(others, dp, strict=True):
            p = params[n]
            moved[n] = min(max(moved[n] + float(d), p.min), p.max)
        _, r2 = obj.residuals(moved)
        chi2_gn = float(r2 @ r2)
    return min(chi2, chi2_gn) if math.isfinite(chi2_gn) else chi2


def _inside(v: float, lo: float, hi: float) -> bool:
    """Whether ``v`` is off both bounds (by more than ``AT_BOUND_FRAC`` of the span)."""
    tol = AT_BOUND_FRAC * (hi - lo) if math.isfinite(hi - lo) else 0.0
    return lo + tol < v < hi - tol
