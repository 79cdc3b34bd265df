"""Seed replicates: a stochastic model fitted over independent Monte Carlo seeds, combined.

A model evaluated by Monte Carlo with common random numbers (one seed per fit,
:attr:`labbrdf.models.Model.stochastic`) is a deterministic but rough function of its
parameters: the estimate carries a Monte Carlo error that the per-bin noise propagated
through the covariance does not describe (docs/models.md 7). Fitting the same data with R
independent seeds and averaging measures and reduces it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy import special

from .. import parallel
from ..models import Model
from ..models import get as get_model
from .data import FitError
from .result import FitResult

__all__ = ["MAX_REPLICATES", "check_replicates", "combine_replicates", "run_replicates"]

#: the most seed replicates of one fit: each replicate is a whole fit of a Monte Carlo model
#: (its traces, its result), made and kept at once, so the count is bounded; the seed spread
#: is measured to a few per cent by far fewer (its relative error is 1 / sqrt(2 (R - 1)))
MAX_REPLICATES = 1000


ONE_SEED_WARNING = (
    "one Monte Carlo seed: the standard errors leave out the estimate's spread over seeds "
    "(common random numbers make the map rough in the parameters); fit with replicates >= 2"
)


#: one fit of one replicate: ``fit(model, data, replicates=1, **kw)``
FitOne = Callable[..., FitResult]


def _fit_one(task: tuple[FitOne, Model, Any, dict[str, Any]]) -> FitResult:
    fit, model, data, kw = task
    return fit(model, data, replicates=1, **kw)


def check_replicates(replicates: Any, model: Model | None) -> None:
    """Refuse a count that is not an integer in [2, MAX_REPLICATES], or a deterministic model.

    Raises
    ------
    FitError
        With the count and, for a deterministic ``model``, its name.
    """
    if isinstance(replicates, bool) or not isinstance(replicates, (int, np.integer)):
        raise FitError(f"replicates must be an integer >= 1; got {replicates!r}")
    if replicates < 2:
        raise FitError(f"replicates must be >= 2 for seed replicates; got {replicates}")
    if replicates > MAX_REPLICATES:
        raise FitError(f"replicates must be at most {MAX_REPLICATES}; got {replicates}")
    if model is not None and not getattr(model, "stochastic", False):
        raise FitError(
            f"model {model.name!r} is deterministic (no Monte Carlo seed): "
            f"replicates={replicates} would repeat the same fit; use replicates=1"
        )


def run_replicates(
    fit: FitOne,
    model: Model | str,
    data: Any,
    replicates: int,
    *,
    executor: parallel.Executor | str | None = "serial",
    **fit_kw: Any,
) -> FitResult:
    """Fit ``model`` with ``replicates`` model seeds through ``fit`` and combine the estimates.

    The engine of :func:`labbrdf.fitting.fit_replicates`, which passes
    :func:`labbrdf.fitting.fit` as ``fit``: this module stays below the fitting core.

    Parameters
    ----------
    fit : callable
        ``fit(model, data, replicates=1, **fit_kw)`` -> FitResult, a module-level function
        (it is sent to the executor's workers).
    model, data, replicates, executor, **fit_kw :
        As for :func:`labbrdf.fitting.fit_replicates`.

    Returns
    -------
    FitResult
        See :func:`combine_replicates`.

    Raises
    ------
    FitError
        ``replicates`` not an integer >= 2, a deterministic model, or ``ci="profile"``.
    """
    m = get_model(model) if isinstance(model, str) else model
    if not isinstance(m, Model):
        raise FitError(f"model: expected a Model or a model name, got {type(m).__name__}")
    check_replicates(replicates, m)
    if fit_kw.get("ci", "wald") != "wald":
        raise FitError("seed replicates combine Wald errors: use ci='wald' with replicates > 1")
    t0 = time.perf_counter()
    s0 = int(m.options.get("seed", 0))
    tasks = [(fit, m.reseeded(s0 + r), data, fit_kw) for r in range(int(replicates))]
    results = parallel.as_executor(executor).map(_fit_one, tasks)
    out = combine_replicates(list(results), [s0 + r for r in range(int(replicates))])
    out.elapsed_s = time.perf_counter() - t0  # wall time of the R fits
    return out


def combine_replicates(results: list[FitResult], seeds: list[int]) -> FitResult:
    """One FitResult from R fits of the same data with independent model seeds.

    Parameters
    ----------
    results : list of FitResult
        The R >= 2 fits, same data, model and varying parameters; ``results[0]`` carries
        the statistics (chi-square, residuals) of the returned result.
    seeds : list of int
        The model seed of each fit.

    Returns
    -------
    FitResult
        ``results[0]`` (modified in place) with every varying parameter's value the mean
        of the R estimates, the covariance ``mean_r C_r + S / R`` (``C_r`` the fits'
        covariances, ``S`` the sample covariance of the R estimate vectors, ddof 1),
        hence the standard error ``sqrt(mean_r stderr_r^2 + s_between^2 / R)``; Wald
        intervals on that error; ``replicates`` (seed and values per fit),
        ``seed_spread`` (s_between per parameter), the summed ``nfev`` and
        ``elapsed_s``, and a note in ``weighting``.

    Notes
    -----
    Write the estimate of replicate r as ``theta + e_D + e_r``: ``e_D`` the data-noise
    error, common to all replicates because they fit the same data, ``e_r`` the Monte Carlo
    error of seed r, independent between seeds with variance ``v_MC``. The mean has
    variance ``v_D + v_MC / R``. The spread between replicates contains no ``e_D``:
    ``s_between^2`` estimates ``v_MC`` without bias. Each fit's reported ``stderr_r^2``
    estimates ``v_D`` plus the per-bin Monte Carlo noise propagated through the sandwich
    covariance, which is a part of ``v_MC``: the combination therefore counts that part
    once more and is conservative by that term, while the part the per-bin noise misses,
    the roughness of the common-random-number map in the parameters, enters through
    ``s_between`` (docs/models.md 7, seed replicates).
    ``chisqr``, residuals and best fit are those of the first replicate at its own
    optimum, not at the mean.
    """
    if len(results) < 2 or len(results) != len(seeds):
        raise FitError("combine_replicates needs R >= 2 results, one seed per result")
    base = results[0]
    names = list(base.var_names)
    if any(list(r.var_names) != names for r in results):
        raise FitError("seed replicates varied different parameters; cannot combine them")
    R = len(results)
    est = np.array([[r.params[k].value for k in names] for r in results], dtype=float)
    mean = est.mean(axis=0)
    spread_cov = np.atleast_2d(np.cov(est, rowvar=False, ddof=1)) if names else np.zeros((0, 0))
    covs = [r.covar for r in results]
    params = base.params.copy()
    covar = None
    if names and all(c is not None and np.all(np.isfinite(c)) for c in covs):
        covar = np.mean(np.array(covs, dtype=float), axis=0) + spread_cov / R
    sd = np.sqrt(np.diag(covar)) if covar is not None else None
    tq = float(special.stdtrit(base.nfree, 0.975)) if base.nfree > 0 else math.nan
    for i, k in enumerate(names):
        p = params[k]
        p.value = float(mean[i])
        if sd is None:
            p.stderr, p.ci95, p.correl = None, None, None
            continue
        p.stderr = float(sd[i])
        lo, hi = p.value - tq * p.stderr, p.value + tq * p.stderr
        p.ci95 = (max(lo, p.min), min(hi, p.max)) if math.isfinite(tq) else None
        assert covar is not None
        p.correl = {
            o: float(covar[i, j] / (sd[i] * sd[j]))
            for j, o in enumerate(names)
            if j != i and sd[i] > 0 and sd[j] > 0
        }
    spread = {k: float(math.sqrt(spread_cov[i, i])) for i, k in enumerate(names)}
    note = (
        f"; {R} seed replicates (model seeds {seeds[0]}-{seeds[-1]}): values are their "
        "mean, stderr = sqrt(mean stderr_r^2 + s_between^2 / R)"
    )
    base.params = params
    base.covar = covar
    base.replicates = [
        {"seed": int(s), **{k: float(v) for k, v in zip(names, row, strict=True)}}
        for s, row in zip(seeds, est, strict=True)
    ]
    base.seed_spread = spread
    base.nfev = int(sum(r.nfev for r in results))
    base.elapsed_s = float(sum(r.elapsed_s for r in results))
    base.success = all(r.success for r in results)
    if not base.success:
        base.message = "; ".join(
            f"seed {s}: {r.message}" for s, r in zip(seeds, results, strict=True) if not r.success
        )
    base.weighting += note
    base.warnings = [w for w in base.warnings if w != ONE_SEED_WARNING]
    return base
