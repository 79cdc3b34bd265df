"""The search of a fit: nlopt stages, global then local in restarted rounds, and a polish.

``_search`` runs the stages :func:`parse_method` names, each from the best point of the
one before (``_run_stage``; a local stage in rounds, ``_run_local``), then the
Gauss-Newton polish (``_polish``); ``_budgets`` sets each stage's evaluations and
``_verdict`` says whether the stop codes mean converged (docs/models.md 5.1-5.2).

A model whose class sets ``least_squares_local = True`` (a smooth residual vector: the
film fit) has its :data:`LEAST_SQUARES_REPLACES` stage run as the least-squares polish
itself, from the global stage's best point (``_least_squares_local``); every other
model, and every other local algorithm named, runs as before.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import nlopt
import numpy as np
from numpy.typing import NDArray
from scipy import optimize

from .. import progress
from .data import FitError
from .defaults import METHOD
from .objective import Objective

__all__ = [
    "ALGORITHMS",
    "CHI2_TOL",
    "CONSTRAINED",
    "EXACT_RTOL",
    "LEAST_SQUARES",
    "LEAST_SQUARES_REPLACES",
    "LOCAL_ROUNDS",
    "parse_method",
]


#: every nlopt algorithm, by name (``GN_CRS2_LM`` ...), read from the nlopt module itself
ALGORITHMS: dict[str, int] = {
    name: getattr(nlopt, name)
    for name in dir(nlopt)
    if name.startswith(("GN_", "GD_", "LN_", "LD_", "AUGLAG", "G_MLSL"))
    and isinstance(getattr(nlopt, name), int)
}


#: algorithms that accept nonlinear inequality constraints (nlopt docs, "Algorithms")
CONSTRAINED = frozenset(
    {
        "GN_ORIG_DIRECT",
        "GN_ORIG_DIRECT_L",
        "GN_ISRES",
        "GN_AGS",
        "LN_COBYLA",
        "LD_MMA",
        "LD_CCSAQ",
        "LD_SLSQP",
        "AUGLAG",
        "AUGLAG_EQ",
        "LN_AUGLAG",
        "LN_AUGLAG_EQ",
        "LD_AUGLAG",
        "LD_AUGLAG_EQ",
    }
)


# default stage settings (tuned with benchmarks/bench_fit.py)
_GLOBAL_MAXEVAL_GUESSED = 30  # x (n + 1) when a data-driven starting point exists


_GLOBAL_MAXEVAL_BLIND = 100  # x (n + 1) otherwise


_LOCAL_MAXEVAL_PER_DIM = 400  # x n for one round of a local stage


#: a local stage that stops at its round budget restarts from its best point, with a fresh
#: trust region, up to this many rounds in all (a total of 5 x 400 n evaluations)
LOCAL_ROUNDS = 5


#: a round that lowers chi-square by less than this, in units of the noise scale (1 with
#: sigma, chi-square / nfree without), has converged in chi-square: far below the
#: Delta chi-square = t^2 (about 4) that sets the 95 % intervals, so the remaining motion
#: along a flat valley cannot change any reported number beyond its uncertainty
CHI2_TOL = 1e-6


#: a round whose residuals are below this fraction of the data's RMS has converged: the
#: model reproduces the data beyond the 6 significant digits instrument files print, so
#: what is left is round-off (noise-free data along a flat valley)
EXACT_RTOL = 1e-6


_LOCAL_XTOL_REL = 1e-10


_LOCAL_FTOL_REL = 1e-13


#: stop codes that mean converged. ROUNDOFF_LIMITED: the optimiser can no longer lower
#: chi-square at double precision (nlopt: "the optimization still typically returns a useful
#: result"); it happens where the optimum sits on a bound, which the at_bound flag then shows
_OK_CODES = (
    nlopt.SUCCESS,
    nlopt.STOPVAL_REACHED,
    nlopt.FTOL_REACHED,
    nlopt.XTOL_REACHED,
    nlopt.ROUNDOFF_LIMITED,
)


def parse_method(method: str) -> list[str]:
    """Split ``"GLOBAL+LOCAL"`` into checked nlopt algorithm names (one name = one stage).

    Names are case-insensitive and may carry nlopt's ``NLOPT_`` prefix.

    Raises
    ------
    FitError
        For an unknown name, listing the valid ones.
    """
    if not isinstance(method, str) or not method.strip():
        raise FitError(f"method must be a string such as {METHOD!r}, got {method!r}")
    stages = []
    for raw in method.split("+"):
        name = raw.strip().upper().removeprefix("NLOPT_")
        if name not in ALGORITHMS:
            raise FitError(
                f"unknown nlopt algorithm {raw.strip()!r} in method {method!r}; valid names "
                f"are {sorted(ALGORITHMS)}"
            )
        stages.append(name)
    return stages


def _is_global(name: str) -> bool:
    return name.startswith(("GN_", "GD_", "G_MLSL"))


def _needs_grad(name: str) -> bool:
    return name.startswith(("GD_", "LD_"))


def _run_stage(
    obj: Objective,
    name: str,
    budget: int,
    x: NDArray,
    seed: int,
    cons: Callable[[NDArray], float] | None,
) -> tuple[NDArray, dict[str, Any]]:
    """One nlopt stage from ``x``; returns the best point and a stage record."""
    n = obj.n
    opt = nlopt.opt(ALGORITHMS[name], n)
    lo, hi = obj.bounds()
    opt.set_lower_bounds(lo)
    opt.set_upper_bounds(hi)
    opt.set_min_objective(obj)
    opt.set_maxeval(budget)
    if not _is_global(name):
        opt.set_xtol_rel(max(_LOCAL_XTOL_REL, obj.model.fd_rel_step or 0.0))
        opt.set_ftol_rel(_LOCAL_FTOL_REL)
    if "MLSL" in name or "AUGLAG" in name:
        sub = nlopt.opt(nlopt.LD_LBFGS if _needs_grad(name) else nlopt.LN_BOBYQA, n)
        sub.set_xtol_rel(1e-8)
        sub.set_maxeval(_LOCAL_MAXEVAL_PER_DIM * n)
        opt.set_local_optimizer(sub)
    if cons is not None:

        def constraint(xx: NDArray, grad: NDArray) -> float:
            c = cons(xx)
            for j in range(grad.size):  # forward differences on the unit-box scale
                x2 = np.array(xx, float)
                x2[j] += 1e-7
                grad[j] = (cons(x2) - c) / 1e-7
            return c

        opt.add_inequality_constraint(constraint, 1e-10)
    nlopt.srand(seed)
    progress.report(stage=name, budget=budget)
    nfev0 = obj.nfev
    x0 = np.clip(x, lo, hi)
    try:
        x = opt.optimize(x0)
        code = opt.last_optimize_result()
        message = _code_message(code)
    except nlopt.RoundoffLimited:
        code, message = nlopt.ROUNDOFF_LIMITED, "roundoff limited (converged; best point kept)"
        x = obj.best_x if obj.best_x is not None else x0
    except (nlopt.runtime_error, RuntimeError) as exc:  # NLOPT_FAILURE: keep the best point
        code, message = nlopt.FAILURE, f"nlopt failure ({name}): {exc or 'generic'}"
        x = obj.best_x if obj.best_x is not None else x0
    nfev = obj.nfev - nfev0
    _, f = obj.solve(obj.from_vector(x))
    if cons is None and obj.best_x is not None and obj.best_f < f:
        x, f = obj.best_x, obj.best_f  # a stage may end on a worse point than it has seen
    info = {
        "algorithm": name,
        "nfev": nfev,
        "chisqr": float(f),
        "code": int(code),
        "message": message,
    }
    return np.asarray(x, float), info


#: stage code of a local stage that met :data:`CHI2_TOL` over a whole round (not an nlopt code)
CHI2_CONVERGED = 100


#: name of the stage record of the final polish (see :func:`_polish`)
POLISH = "polish (scipy least_squares, trf)"


#: residual vectors of the polish per search dimension as scipy counts them (``max_nfev``:
#: trial points, not the ``n`` extra vectors of each finite-difference Jacobian, which
#: ``nfev`` does count); Gauss-Newton from a point in the optimum's basin needs a handful
#: of iterations, a flat valley of noise-free data up to ~200
_POLISH_MAXEVAL_PER_DIM = 200


#: relative tolerances of the polish on chi-square change, step and scaled gradient
_POLISH_TOL = 1e-12


def _polish(
    obj: Objective, x: NDArray, nfree: int, weighted: bool, budget: int | None = None
) -> tuple[NDArray, dict]:
    """A bounded Gauss-Newton polish from ``x``: ends at a stationary point, not a stall.

    The nlopt local stage stops on the gain of its last steps (``ftol_rel``, ``xtol_rel``)
    or of its last round (:data:`CHI2_TOL`). Along a flat valley that point may lie far from
    the minimum: a derivative-free trust region that has shrunk makes tiny steps whatever
    the remaining descent (measured: five_param at OSR 860 nm stopped with a at its upper
    bound 118.58 against 118.4853 at the minimum, depending on the seed). This polish is
    scipy's trust-region reflective least squares (Branch, Coleman and Li 1999) on the
    weighted residual vector, with a finite-difference Jacobian, in the same bounded
    search box (amplitudes profiled as in the stages: variable projection). Its Gauss-Newton
    model sees the whole valley's curvature, and it stops on the scaled gradient, the step
    or the chi-square change (relative :data:`_POLISH_TOL`), i.e. at a first-order stationary
    point. The best point seen is kept, so the polish never raises chi-square. ``budget``
    caps its trial points below the default :data:`_POLISH_MAXEVAL_PER_DIM` ``x n``.
    """
    progress.report(stage="polish")
    nfev0 = obj.nfev
    lo, hi = obj.bounds()
    x0 = np.clip(np.asarray(x, float), lo, hi)
    f0 = obj.solve(obj.from_vector(x0))[1]
    budget = min(_POLISH_MAXEVAL_PER_DIM * obj.n, budget or _POLISH_MAXEVAL_PER_DIM * obj.n)
    tol = max(_POLISH_TOL, obj.model.fd_rel_step or 0.0)  # a Monte Carlo model's resolution
    try:
        res = optimize.least_squares(
            obj.residual_vector,
            x0,
            bounds=(lo, hi),
            method="trf",
            x_scale="jac",
            ftol=tol,
            xtol=tol,
            gtol=tol,
            max_nfev=budget,
            diff_step=obj.model.fd_rel_step,
        )
        status, why = int(res.status), str(res.message)
    except (ValueError, np.linalg.LinAlgError) as exc:  # non-finite start, singular step
        status, why = -1, f"failed ({exc})"
    x1, f1 = x0, f0
    if obj.best_x is not None and obj.best_f < f0:
        x1, f1 = np.asarray(obj.best_x, float), float(obj.best_f)
    scale = 1.0 if weighted else max(f1 / max(nfree, 1), 1e-300)
    gain = (f0 - f1) / scale
    if status > 0:
        msg = (
            f"polished to a stationary point ({why.rstrip('.')}; chi-square lowered by "
            f"{gain:.2g} noise units)"
        )
    elif status == 0:
        msg = (
            f"polish stopped at its budget of {budget} trial points ({gain:.2g} noise "
            "units gained): not converged"
        )
    else:
        msg = f"polish {why}; the best point found is kept"
    info = {
        "algorithm": POLISH,
        "nfev": obj.nfev - nfev0,
        "chisqr": f1,
        "code": status,
        "message": msg,
        "gain": float(gain),
    }
    return x1, info


#: the local stage that a model with ``least_squares_local`` runs as least squares: the
#: default method's (:data:`~labbrdf.fitting.defaults.METHOD`); another local algorithm
#: named explicitly runs as nlopt's
LEAST_SQUARES_REPLACES = "LN_BOBYQA"


def _least_squares_local(
    obj: Objective, x: NDArray, nfree: int, weighted: bool, budget: int
) -> tuple[NDArray, dict[str, Any]]:
    """The polish as the local stage: trust-region reflective least squares from ``x``.

    For a smooth residual vector the Gauss-Newton model crosses in a few Jacobians the
    valley that BOBYQA's interpolation model creeps along in thousands of evaluations
    (measured on a 6-parameter film fit of 2028 psi/Delta pairs: 6678 evaluations in all
    with BOBYQA's rounds and the polish, about 1000 with this stage; the same minimum).
    It stops at a first-order stationary point (:func:`_polish`), so no polish follows.
    ``budget`` (the stage's ``maxeval``) caps the polish's trial points where it is the
    smaller. Its stop code maps to nlopt's: a converged status to ``SUCCESS``, the budget
    to ``MAXEVAL_REACHED`` (not converged), a failure to ``FAILURE``.
    """
    x, info = _polish(obj, x, nfree, weighted, budget)
    status = info["code"]
    code = nlopt.SUCCESS if status > 0 else nlopt.MAXEVAL_REACHED if status == 0 else nlopt.FAILURE
    msg = info["message"].replace("polished to", "least squares converged to", 1)
    return x, {**info, "algorithm": LEAST_SQUARES, "code": int(code), "message": msg}


#: name of the stage record of a least-squares local stage (see :func:`_least_squares_local`)
LEAST_SQUARES = f"least squares (scipy trf) in place of {LEAST_SQUARES_REPLACES}"


def _run_local(
    obj: Objective,
    name: str,
    budget: int,
    x: NDArray,
    seed: int,
    cons: Callable[[NDArray], float] | None,
    nfree: int,
    weighted: bool,
    per_round: int | None = None,
) -> tuple[NDArray, dict[str, Any]]:
    """A local stage in rounds: restart from the best point while a round ends at maxeval.

    ``budget`` is the total for the stage; a round gets ``per_round`` evaluations (default
    ``400 n``, or the whole budget where that is smaller, so an explicit small ``maxeval``
    runs one round as nlopt would). Each round that stops at its maxeval is followed by a
    fresh one from its best point (a new trust region or simplex), until nlopt's own
    tolerances are met, a whole ``400 n`` round improves chi-square by less than
    :data:`CHI2_TOL` noise units or a round leaves residuals below :data:`EXACT_RTOL` of the
    data (converged: a flat valley, reported as such), or the total budget is spent
    (``maxeval reached``, not a success). A shorter round that gains nothing proves nothing
    (BOBYQA spends its first ``2 n + 1`` evaluations on its interpolation set), so the
    chi-square test skips it. Every round is recorded with its starting chi-square.
    """
    full = _LOCAL_MAXEVAL_PER_DIM * obj.n
    per_round = max(1, min(budget, full if per_round is None else per_round))
    rounds: list[dict[str, Any]] = []
    spent = 0
    while True:
        this = min(per_round, budget - spent)
        f_start = obj.solve(obj.from_vector(np.clip(x, *obj.bounds())))[1]
        x, info = _run_stage(obj, name, this, x, seed, cons)
        info["chisqr_start"] = float(f_start)
        rounds.append(info)
        spent += info["nfev"]
        if info["code"] != nlopt.MAXEVAL_REACHED:
            break
        scale = 1.0 if weighted else max(info["chisqr"] / max(nfree, 1), 1e-300)
        gain = (f_start - info["chisqr"]) / scale
        vals, _ = obj.solve(obj.from_vector(x))
        resid = obj.y - obj.model_values(vals)
        exact = float(np.sqrt(np.mean(resid**2)) / max(np.sqrt(np.mean(obj.y**2)), 1e-300))
        why = None
        if this >= full and math.isfinite(gain) and gain < CHI2_TOL:
            why = (
                f"converged in chi-square: the last round of {info['nfev']} evaluations "
                f"lowered it by {gain:.2g} noise units (< {CHI2_TOL:g}); flat valley"
            )
        elif exact < EXACT_RTOL:
            why = (
                f"converged: the model reproduces the data to {exact:.2g} of their RMS "
                f"(< {EXACT_RTOL:g}); what is left is round-off along a flat valley"
            )
        if why is not None:
            info = {**info, "code": CHI2_CONVERGED, "message": why}
            break
        if spent >= budget:
            info = {
                **info,
                "message": f"maxeval reached ({spent} evaluations in "
                f"{len(rounds)} rounds, chi-square still falling by {gain:.3g} noise "
                "units per round)",
            }
            break
    out = {**info, "nfev": spent, "rounds": rounds}
    return x, out


def _search(
    obj: Objective,
    x: NDArray,
    stages: list[str],
    budgets: list[int],
    seed: int,
    cons: Callable[[NDArray], float] | None,
    nfree: int,
    use_sigma: bool,
) -> tuple[NDArray, list[dict[str, Any]], int, str]:
    """Run the nlopt stages in turn from ``x``, then the polish (docs/models.md 5.2).

    Returns the best search vector, the per-stage records, the last stop code and the
    message.
    """
    stage_info: list[dict[str, Any]] = []
    last_code, message = nlopt.SUCCESS, "no search needed: only profiled parameters vary"
    lsq = cons is None and bool(getattr(obj.model, "least_squares_local", False))
    polished = False
    with np.errstate(all="ignore"):
        for name, budget in zip(stages, budgets, strict=True):
            if obj.n == 0:
                break
            polished = False
            if _is_global(name):
                x, info = _run_stage(obj, name, budget, x, seed, cons)
            elif lsq and name == LEAST_SQUARES_REPLACES:
                x, info = _least_squares_local(obj, x, nfree, use_sigma, budget)
                polished = True
            else:
                x, info = _run_local(obj, name, budget, x, seed, cons, nfree, use_sigma)
            stage_info.append(info)
            last_code, message = info["code"], info["message"]
        converged = last_code in _OK_CODES or last_code == CHI2_CONVERGED
        last_local = stages and not _is_global(stages[-1]) and not polished
        if obj.n and cons is None and last_local and converged:
            x, info = _polish(obj, x, nfree, use_sigma)
            stage_info.append(info)
            message = f"{message}; {info['message']}"
            if info["code"] == 0:
                last_code = nlopt.MAXEVAL_REACHED
    return x, stage_info, last_code, message


def _verdict(
    finite: bool, last_code: int, stages: list[str], nsearch: int, message: str
) -> tuple[bool, str]:
    """Whether the fit succeeded, and its message.

    Converged stop codes succeed; so does a last global stage that spent its budget (a
    global search has no other stop), and a fit with nothing to search. Non-finite values
    or chi-square fail.
    """
    if not finite:
        return False, "non-finite parameters or chi-square: " + message
    ok = (
        last_code in _OK_CODES
        or last_code == CHI2_CONVERGED
        or (bool(stages) and _is_global(stages[-1]) and last_code == nlopt.MAXEVAL_REACHED)
    )
    return ok or nsearch == 0, message


def _budgets(
    obj: Objective,
    stages: list[str],
    maxeval: int | Sequence[int | None] | None,
    constrained: bool,
    lin: list[str],
    guessed: bool,
) -> list[int]:
    """Check the stages against the search (bounds, constraints); evaluation budgets."""
    n = obj.n
    lo, hi = obj.bounds()
    for name in stages:
        if n and _is_global(name) and not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
            bad = [
                k
                for k, a, b in zip(obj.names, lo, hi, strict=True)
                if not (math.isfinite(a) and math.isfinite(b))
            ]
            raise FitError(
                f"global algorithm {name} needs finite bounds; set min and max of {bad}"
            )
        if n and constrained and name not in CONSTRAINED:
            raise FitError(
                f"energy_constraint with {name}: this algorithm takes no constraints and "
                f"the amplitudes {lin} cannot carry it as a bound; use one of "
                f"{sorted(CONSTRAINED)}"
            )
    if maxeval is None or isinstance(maxeval, int):
        given: list[int | None] = [maxeval] * len(stages)
    else:
        given = list(maxeval)
        if len(given) != len(stages):
            raise FitError(f"maxeval: {len(given)} budgets for {len(stages)} stage(s)")
    per = _GLOBAL_MAXEVAL_GUESSED if guessed else _GLOBAL_MAXEVAL_BLIND
    return [
        int(b)
        if b is not None
        else (per * (n + 1) if _is_global(s) else LOCAL_ROUNDS * _LOCAL_MAXEVAL_PER_DIM * n)
        for s, b in zip(stages, given, strict=True)
    ]


def _code_message(code: int) -> str:
    return {
        nlopt.SUCCESS: "success",
        nlopt.STOPVAL_REACHED: "stopval reached",
        nlopt.FTOL_REACHED: "ftol_rel reached",
        nlopt.XTOL_REACHED: "xtol_rel reached",
        nlopt.MAXEVAL_REACHED: "maxeval reached",
        nlopt.MAXTIME_REACHED: "maxtime reached",
    }.get(code, f"nlopt code {code}")
