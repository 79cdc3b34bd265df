"""Profile-likelihood 95 % intervals: chi-square minimised with one parameter held.

``_profile_interval`` steps out from the optimum until the profiled chi-square
(``_profile_chi2``) passes ``chi2_min + delta``, then finds the crossing with Brent's
method (docs/models.md 5.3); ``_profile_intervals`` does it for every parameter asked.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy import optimize

from .. import progress
from ..models import Model, Parameters
from .data import FitData
from .objective import Objective
from .parameters import _copy_params
from .stages import _LOCAL_MAXEVAL_PER_DIM, _OK_CODES, _polish, _run_stage


def _profile_intervals(
    model: Model,
    fd: FitData,
    out: Parameters,
    weights: NDArray,
    prof: list[str],
    varying: list[str],
    chisqr: float,
    delta: float,
    seed: int,
) -> list[str]:
    """Replace each varying parameter's Wald interval by its profile interval, in place.

    Returns a warning for each parameter whose profile interval was not found (its Wald
    interval is kept).
    """
    warn = []
    with np.errstate(all="ignore"):
        for i, k in enumerate(varying):
            progress.report(phase=f"profile interval of {k}", done=i, total=len(varying))
            try:
                out[k].ci95 = _profile_interval(
                    model, fd, out, weights, prof, k, chisqr, delta, int(seed)
                )
            except (ValueError, RuntimeError) as exc:  # keep the Wald interval
                warn.append(f"{k}: profile interval not found ({exc}); Wald interval kept")
    return warn


def _profile_chi2(
    model: Model,
    fd: FitData,
    best: Parameters,
    weights: NDArray,
    prof: list[str],
    name: str,
    value: float,
    seed: int,
) -> float:
    """Minimum chi-square over the other parameters with ``name`` held at ``value``.

    One BOBYQA stage from the optimum's other values, polished like the fit itself.
    """
    pf = _copy_params(best)
    pf[name].value, pf[name].vary = float(value), False
    obj = Objective(model, fd, pf, weights, [k for k in prof if k != name])
    if obj.n == 0:
        return obj.solve(dict(obj.base))[1]
    n = obj.n
    x, info = _run_stage(
        obj, "LN_BOBYQA", _LOCAL_MAXEVAL_PER_DIM * n, obj.to_vector(obj.base), seed, None
    )
    if info["code"] in _OK_CODES:  # finish a stall along a valley, as fit() does
        _polish(obj, x, max(len(fd) - n, 1), True)
    return min(info["chisqr"], obj.best_f)


def _profile_interval(
    model: Model,
    fd: FitData,
    best: Parameters,
    weights: NDArray,
    prof: list[str],
    name: str,
    chi2_min: float,
    delta: float,
    seed: int,
) -> tuple[float, float]:
    """Where the profiled chi-square crosses ``chi2_min + delta`` on each side (or a bound).

    Steps outward from the optimum (first step t x stderr, then doubling) until the profile
    exceeds the level, then solves for the crossing with Brent's method to 1e-3 stderr.
    """
    q = best[name]
    v0 = q.value
    se = q.stderr if q.stderr is not None and q.stderr > 0 else 1e-3 * max(abs(v0), 1e-3)

    def g(v: float) -> float:
        return _profile_chi2(model, fd, best, weights, prof, name, v, seed) - chi2_min - delta

    ends = []
    for sign, bound in ((-1.0, q.min), (1.0, q.max)):
        a, step = v0, math.sqrt(delta) * se if delta > 0 else se
        for _ in range(60):
            b = v0 + sign * step
            if (b - bound) * sign >= 0:
                b = bound
            gb = g(b)
            if gb > 0:
                ends.append(optimize.brentq(g, a, b, xtol=1e-3 * se) if a != b else b)
                break
            if b == bound:
                ends.append(bound)
                break
            a, step = b, 2 * step
        else:
            raise RuntimeError(f"no crossing within {step:.3g} of the optimum")
    return ends[0], ends[1]
