"""The fitter: nlopt stages (global then local) over an Objective, then uncertainties."""

from __future__ import annotations

import copy
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import nlopt
import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy import optimize

from .. import parallel, progress
from ..dataset import Measurement
from ..models import Model, ModelError, Parameters
from ..models import get as get_model
from .data import FitData, FitError, as_fit_data, clean_fit_data
from .defaults import MAX_SEED, METHOD
from .intervals import CI_METHODS, refine_intervals, wald_params
from .objective import Objective
from .replicates import ONE_SEED_WARNING, run_replicates
from .result import FitResult
from .uncertainty import jacobian, noise_meat, uncertainties
from .weighting import _weighting

__all__ = [
    "ALGORITHMS",
    "CHI2_TOL",
    "EXACT_RTOL",
    "CONSTRAINED",
    "LOCAL_ROUNDS",
    "MAX_SEED",
    "METHOD",
    "RELATIVE_FLOOR",
    "check_seed",
    "fit",
    "fit_replicates",
    "parse_method",
    "setup_params",
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
#: default floor of ``weighting="relative"``, as a fraction of the largest value: a 1000:1
#: dynamic range, what BRDF instruments resolve between a specular peak and the floor
RELATIVE_FLOOR = 1e-3
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


def _energy_rho(
    model: Model, energy: bool | Callable[..., ArrayLike]
) -> Callable[[dict[str, float], NDArray], NDArray]:
    if callable(energy):
        return lambda vals, th: np.asarray(energy(vals, th), float)
    try:
        from ..integrate import hemispherical_reflectance
    except ImportError as exc:  # pragma: no cover - integrate ships with labbrdf
        raise FitError("energy_constraint=True needs labbrdf.integrate") from exc
    return lambda vals, th: np.asarray(hemispherical_reflectance(model, vals, th), float)


def check_seed(seed: Any) -> int:
    """``seed`` as an int, if it is an integer in ``[0, MAX_SEED]``; else :class:`FitError`."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise FitError(f"seed must be an integer in [0, {MAX_SEED}]; got {seed!r}")
    if not 0 <= seed <= MAX_SEED:
        raise FitError(f"seed must be an integer in [0, {MAX_SEED}]; got {seed}")
    return int(seed)


def _copy_params(p: Parameters) -> Parameters:
    """A copy whose Parameter objects are new (fields are immutable or replaced, not mutated)."""
    return Parameters({k: copy.copy(q) for k, q in p.items()})


def setup_params(
    model: Model, params: Parameters | Mapping[str, float] | None, fix: Mapping[str, float] | None
) -> Parameters:
    """The model's parameters with ``params`` (values or Parameters) and ``fix`` applied.

    Internal API of :mod:`labbrdf.fitting`; raises :class:`FitError` naming unknown or
    inconsistent parameter names, and a value given in ``params`` or ``fix`` that is not
    finite or lies outside the parameter's bounds (:meth:`Parameter.check
    <labbrdf.models.Parameter.check>`: the model's, or those given in ``params``).
    """
    p = _copy_params(model.params)
    given: list[tuple[str, str, Any]] = []  # (argument, name, value) to check in bounds
    if params is not None:
        for k, v in params.items():
            if k not in p:
                raise FitError(
                    f"params: model {model.name!r} has no parameter {k!r}; "
                    f"parameters are {list(p)}"
                )
            if isinstance(v, Mapping) or hasattr(v, "vary"):
                src = v if isinstance(v, Mapping) else v.__dict__
                for a in ("value", "min", "max", "vary", "log"):
                    if a in src:
                        setattr(p[k], a, src[a])
                if "value" in src:
                    given.append(("params", k, src["value"]))
            else:
                given.append(("params", k, v))
    for k, v in (fix or {}).items():
        if k not in p:
            raise FitError(
                f"fix: model {model.name!r} has no parameter {k!r}; parameters are {list(p)}"
            )
        given.append(("fix", k, v))
        p[k].vary = False
    for arg, k, v in given:
        try:
            p[k].value = p[k].check(v)
        except ModelError as exc:
            raise FitError(f"{arg}: model {model.name!r}: {exc}") from None
    for k, q in p.items():
        if not math.isfinite(q.value):
            raise FitError(f"parameter {k!r}: initial value {q.value!r} is not finite")
        if q.vary:
            if q.min >= q.max:
                raise FitError(f"parameter {k!r}: min {q.min} must be < max {q.max} to vary")
            if q.log and not q.min > 0:
                raise FitError(f"parameter {k!r}: a log-scale search needs min > 0, got {q.min}")
            q.value = min(max(q.value, q.min), q.max)
    return p


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


def _polish(obj: Objective, x: NDArray, nfree: int, weighted: bool) -> tuple[NDArray, dict]:
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
    point. The best point seen is kept, so the polish never raises chi-square.
    """
    progress.report(stage="polish")
    nfev0 = obj.nfev
    lo, hi = obj.bounds()
    x0 = np.clip(np.asarray(x, float), lo, hi)
    f0 = obj.solve(obj.from_vector(x0))[1]
    budget = _POLISH_MAXEVAL_PER_DIM * obj.n
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


def fit(
    model: Model | str,
    data: Measurement | pd.DataFrame | FitData,
    *,
    method: str = METHOD,
    seed: int = 0,
    params: Parameters | Mapping[str, Any] | None = None,
    fix: Mapping[str, float] | None = None,
    profile: bool | None = None,
    energy_constraint: bool | Callable[..., ArrayLike] = False,
    maxeval: int | Sequence[int | None] | None = None,
    quantity: str | None = None,
    unit: str | None = None,
    use_sigma: bool | None = None,
    nan_policy: str = "raise",
    guess: bool = True,
    ci: str = "wald",
    weighting: str | None = "auto",
    relative_floor: float = RELATIVE_FLOOR,
    mask_zeros: bool = True,
    replicates: int | None = None,
    on_wald: Callable[[FitResult], None] | None = None,
) -> FitResult:
    """Fit a reflectance/BRDF model: an nlopt global stage inside the bounds, then a local one.

    Parameters
    ----------
    model : Model or str
        A model instance or a registry name (``"smooth3"``).
    data : Measurement, DataFrame or FitData
        Rows with quantity ``brdf`` or ``specular_intensity`` (angles [deg]); one sample and
        one wavelength (see :func:`fit_many` for batches).
    method : str
        nlopt algorithm names joined by ``+``, run in turn, each from the best point of the
        previous one. Global stages need finite bounds on every varying parameter.
    seed : int
        Passed to ``nlopt.srand`` before every stage: the fit is reproducible. An integer
        in ``[0, MAX_SEED]``.
    params : Parameters or mapping, optional
        Initial values (name -> value) or per-parameter settings
        (name -> {"value", "min", "max", "vary", "log"}) overriding the model's defaults.
    fix : mapping, optional
        name -> value to hold fixed (the CLI's ``--fix NAME=VALUE``).
    profile : bool, optional
        Solve the linear amplitudes (``Model.linear``) by bounded linear least squares at
        every step. None: whenever the model has linear components and one of them varies.
    energy_constraint : bool or callable
        Keep rho(theta_i) <= 1 over the measured incidence range (docs/models.md 5.5): True
        (:func:`labbrdf.integrate.hemispherical_reflectance`) or ``rho(values, theta_i_deg)``.
        Unless it bounds one profiled amplitude, every stage must be in :data:`CONSTRAINED`.
    maxeval : int or sequence, optional
        Evaluation budget per stage (one for all, or one per stage). Default ``30 (n + 1)``
        for a global stage from the model's guess, ``100 (n + 1)`` without one,
        ``LOCAL_ROUNDS x 400 n`` for a local stage run in restarted rounds (n searched
        parameters; docs/models.md 5.1). The polish is not counted in it.
    quantity, unit : str, optional
        Which rows to fit when the data mix quantities or units.
    use_sigma : bool, optional
        False: ignore the sigmas. With ``weighting=None``, True/None: ``1/sigma^2``.
    nan_policy : {"raise", "omit"}
        Points with NaN/inf values or angles raise, or are dropped and counted in
        ``FitResult.ndropped``.
    guess : bool
        Start the varying parameters not given in ``params`` from the model's data-driven
        guess (kept in the global stage's population).
    ci : {"wald", "auto", "profile"}
        95% intervals value +- t stderr, or the profile of chi-square (docs/models.md 5.3)
        for every varying parameter or (``"auto"``) where it can change the Wald interval;
        ``FitResult.ci_methods`` says which. Not combined with ``energy_constraint``.
    weighting : {"auto", "sigma", "relative", "uniform", None}
        ``"auto"`` (default, as the CLI and the report): ``1/sigma^2`` with sigmas, else
        ``"relative"``: sigma_i = max(|y_i|, ``relative_floor x max|y|``), covariance
        rescaled by ``redchi``; None: ``use_sigma`` decides (docs/models.md 5.4: why).
    relative_floor : float
        The floor of ``weighting="relative"`` as a fraction of the largest value.
    mask_zeros : bool
        Exclude points whose value is exactly 0 (instrument-masked directions), counted in
        ``FitResult.nmasked`` and named in ``warnings`` (default, as the CLI and report).
    replicates : int, optional
        R > 1: a stochastic model fitted with R seeds, combined (:func:`fit_replicates`);
        None: the model's ``default_replicates`` (1 for a deterministic model).
    on_wald : callable, optional
        Called with the Wald answer (a FitResult of its own) before profile intervals are
        computed, when some are (a command line prints it first).

    Returns
    -------
    FitResult

    Raises
    ------
    FitError
        Unknown method or parameter name, too few points, only specular points for smooth3's
        shape parameters, NaN/inf data, mixed quantities, bad sigma, bad ``replicates``.
    labbrdf.models.ModelError
        Unknown model name.

    Notes
    -----
    Stages, budgets, polish, uncertainties, weights, energy constraint: docs/models.md 5.
    """
    # every argument but the model, the data and the count: the same for each replicate
    kw = {k: v for k, v in locals().items() if k not in ("model", "data", "replicates")}
    kw.pop("on_wald")  # the Wald answer first: a single fit's, not a replicate's
    check_seed(seed)
    model = get_model(model) if isinstance(model, str) else model
    R = getattr(model, "default_replicates", 1) if replicates is None else replicates
    if R != 1:  # a non-Model is refused by _problem
        return fit_replicates(model, data, R, **kw)
    t0 = time.perf_counter()
    pb = _problem(model, data, **{k: v for k, v in kw.items() if k != "seed"})
    x, stage_info, last_code, message = _search(
        pb.obj, pb.x0, pb.stages, pb.budgets, int(seed), pb.cons, pb.nfree, pb.use_sigma
    )
    res = _finish(pb, x, stage_info, last_code, message, seed=seed, ci=ci, t0=t0)
    if ci != "wald" and _profiles(pb, res, ci, int(seed), on_wald):
        res.elapsed_s = time.perf_counter() - t0
    return res


@dataclass
class _Problem:
    """What :func:`fit` searches: the points, the parameters, the weights and the objective."""

    model: Model
    stages: list[str]
    fd: FitData
    ndropped: int
    nmasked: int
    p: Parameters
    weights: NDArray
    use_sigma: bool
    weighting: str
    varying: list[str]
    prof: list[str]
    rho_fn: Callable[[dict[str, float], NDArray], NDArray] | None
    th_grid: NDArray
    obj: Objective
    cons: Callable[[NDArray], float] | None
    budgets: list[int]

    @property
    def x0(self) -> NDArray:
        """The starting search vector."""
        return self.obj.to_vector(self.p.values())

    @property
    def nfree(self) -> int:
        """Degrees of freedom: points less varying parameters."""
        return len(self.fd) - len(self.varying)


def fit_replicates(
    model: Model | str,
    data: Any,
    replicates: int,
    *,
    executor: parallel.Executor | str | None = "serial",
    **fit_kw: Any,
) -> FitResult:
    """Fit a stochastic model with ``replicates`` model seeds and combine the estimates.

    Replicate r (0-based) fits ``model.reseeded(s0 + r)``, s0 the model's own seed
    (option ``seed``, 0 when absent), with every other :func:`fit` argument unchanged;
    :func:`labbrdf.fitting.combine_replicates` makes the result.

    Parameters
    ----------
    model : Model or str
        A stochastic model (``model.stochastic``) or its registry name.
    data :
        As for :func:`fit`.
    replicates : int
        R >= 2 independent seeds.
    executor : Executor or str, optional
        Where the R fits run (:class:`labbrdf.parallel.Executor` or a scheduler name;
        default serial). Each task carries its seed, so the result does not depend on it.
    **fit_kw
        Any other :func:`fit` keyword (``ci`` must be ``"wald"``).

    Returns
    -------
    FitResult
        See :func:`labbrdf.fitting.combine_replicates`.

    Raises
    ------
    FitError
        ``replicates`` not an integer >= 2, a deterministic model, or ``ci="profile"``.
    """
    return run_replicates(fit, model, data, replicates, executor=executor, **fit_kw)


def _problem(
    model: Model | str,
    data: Measurement | pd.DataFrame | FitData,
    *,
    method: str,
    params: Parameters | Mapping[str, Any] | None,
    fix: Mapping[str, float] | None,
    profile: bool | None,
    energy_constraint: bool | Callable[..., ArrayLike],
    maxeval: int | Sequence[int | None] | None,
    quantity: str | None,
    unit: str | None,
    use_sigma: bool | None,
    nan_policy: str,
    guess: bool,
    ci: str,
    weighting: str | None,
    relative_floor: float,
    mask_zeros: bool,
) -> _Problem:
    """Check :func:`fit`'s arguments and set up its search (arguments as there)."""
    if isinstance(model, str):
        model = get_model(model)
    if not isinstance(model, Model):
        raise FitError(f"model: expected a Model or a model name, got {type(model).__name__}")
    stages = parse_method(method)
    if ci not in CI_METHODS:
        raise FitError(f"ci must be one of {', '.join(map(repr, CI_METHODS))}, got {ci!r}")
    if ci != "wald" and energy_constraint not in (False, None):
        raise FitError(f"ci={ci!r} is not combined with energy_constraint; use ci='wald'")
    fd, ndropped, nmasked = _select_points(data, quantity, unit, nan_policy, mask_zeros)
    p = setup_params(model, params, fix)
    guessed = guess and _apply_guess(model, fd, p, set(params or ()))
    weights, sigma, how = _weighting(fd, use_sigma, weighting, relative_floor)
    varying = p.varying()
    _check_design(model, fd, varying)
    lin = [k for k in model.linear if k in varying]
    prof, rho_fn, th_grid = _profiling(model, fd, lin, profile, energy_constraint)
    linear_upper = _energy_bound(rho_fn, prof[0], th_grid) if rho_fn and prof else None
    obj = Objective(model, fd, p, weights, prof, linear_upper, absolute=sigma)
    if prof and obj.linear_basis_missing():
        raise FitError(
            f"model {model.name!r} declares linear parameters but gives no "
            "linear components; pass profile=False"
        )
    cons = _energy_cons(obj, rho_fn, th_grid) if rho_fn is not None and not prof else None
    budgets = _budgets(obj, stages, maxeval, cons is not None, lin, guessed)
    return _Problem(
        model=model,
        stages=stages,
        fd=fd,
        ndropped=ndropped,
        nmasked=nmasked,
        p=p,
        weights=weights,
        use_sigma=sigma,
        weighting=how,
        varying=varying,
        prof=prof,
        rho_fn=rho_fn,
        th_grid=th_grid,
        obj=obj,
        cons=cons,
        budgets=budgets,
    )


def _finish(
    pb: _Problem,
    x: NDArray,
    stage_info: list[dict[str, Any]],
    last_code: int,
    message: str,
    *,
    seed: int,
    ci: str,
    t0: float,
) -> FitResult:
    """The final values and statistics at the best search vector ``x``, as a FitResult."""
    model, obj, fd, p, varying, prof = pb.model, pb.obj, pb.fd, pb.p, pb.varying, pb.prof
    use_sigma, rho_fn, th_grid = pb.use_sigma, pb.rho_fn, pb.th_grid
    n_pts, nvarys = len(fd), len(varying)
    with np.errstate(all="ignore"):
        vals, chisqr = obj.solve(obj.from_vector(x) if obj.n else dict(obj.base))
        best = obj.model_values(vals)
        finite = all(math.isfinite(v) for v in vals.values()) and math.isfinite(chisqr)
        J = jacobian(obj, vals, varying) if finite else np.full((n_pts, nvarys), np.nan)
    resid = obj.y - best
    nfree = n_pts - nvarys
    redchi = chisqr / nfree
    covar, stderr, correl, reasons, cond = uncertainties(
        J, varying, vals, 1.0 if use_sigma else redchi, nfree, noise_meat(obj, vals, J)
    )
    out, flags = wald_params(p, vals, stderr, correl, reasons, nfree)
    warn = [f"{pb.ndropped} point(s) with NaN/inf values dropped (nan_policy='omit')"] * (
        pb.ndropped > 0
    ) + [f"{pb.nmasked} point(s) with value 0 excluded as instrument-masked (mask_zeros)"] * (
        pb.nmasked > 0
    )
    warn += [ONE_SEED_WARNING] * bool(model.stochastic)
    domain = model.outside_domain(fd.theta_i_deg, fd.phi_r_deg) or ""  # warned, not refused
    warn += [f"outside the model's domain: {domain}"] * bool(domain)
    success, message = _verdict(finite, last_code, pb.stages, obj.n, message)
    energy_info = None
    if rho_fn is not None:
        energy_info, success, message = _energy_check(rho_fn, vals, th_grid, success, message)
    y = obj.y
    rmse_pct = float(100 * np.sqrt(np.mean((resid / y) ** 2))) if np.all(y != 0) else None
    log_l = n_pts * math.log(max(chisqr, 1e-300) / n_pts)
    return FitResult(
        model=model.name,
        options=dict(model.describe()["options"]),
        method="+".join(pb.stages),
        seed=int(seed),
        params=out,
        init_values=p.values(),
        var_names=varying,
        covar=covar,
        flags=flags,
        flag_reasons={k: r for k, r in reasons.items() if r},
        profiled=list(prof),
        nfev=sum(s["nfev"] for s in stage_info),
        ndata=n_pts,
        nvarys=nvarys,
        nfree=nfree,
        chisqr=float(chisqr),
        redchi=float(redchi),
        aic=float(log_l + 2 * nvarys),
        bic=float(log_l + math.log(n_pts) * nvarys),
        rmse=float(np.sqrt(np.mean(resid**2))),
        rmse_pct=rmse_pct,
        weighted=bool(use_sigma),
        weighting=obj.describe_weighting(pb.weighting, vals),
        nmasked=pb.nmasked,
        success=bool(success),
        message=message,
        elapsed_s=time.perf_counter() - t0,
        quantity=fd.quantity,
        unit=fd.unit,
        ndropped=pb.ndropped,
        stages=stage_info,
        energy=energy_info,
        warnings=warn,
        outside_domain=domain,
        ci_method=ci,
        ci_methods=dict.fromkeys(varying, "wald"),
        cond=cond,
        nlopt_version=".".join(
            str(v) for v in (nlopt.version_major(), nlopt.version_minor(), nlopt.version_bugfix())
        ),
        residual=resid,
        best_fit=best,
        data=fd,
    )


def _select_points(
    data: Measurement | pd.DataFrame | FitData,
    quantity: str | None,
    unit: str | None,
    nan_policy: str,
    mask_zeros: bool,
) -> tuple[FitData, int, int]:
    """The points a fit uses, the number dropped as NaN/inf and the number masked as 0."""
    fd, ndropped = clean_fit_data(as_fit_data(data, quantity, unit), nan_policy)
    if not mask_zeros:
        return fd, ndropped, 0
    zero = np.asarray(fd.value) == 0.0
    nmasked = int(zero.sum())
    if nmasked == len(fd):
        raise FitError(f"data: all {nmasked} points are 0 (masked); nothing to fit")
    if nmasked:
        fd = fd.take(~zero)
    return fd, ndropped, nmasked


def _profiling(
    model: Model,
    fd: FitData,
    lin: list[str],
    profile: bool | None,
    energy_constraint: bool | Callable[..., ArrayLike],
) -> tuple[list[str], Callable[[dict[str, float], NDArray], NDArray] | None, NDArray]:
    """Which linear amplitudes are profiled, and the energy constraint rho(theta) <= 1.

    Returns the profiled names, ``rho(values, theta_i_deg)`` (None without the constraint)
    and the incidence angles [deg] it is checked on. With the constraint on, profiling is
    kept only for a single amplitude: rho <= 1 is then an upper bound on it (a box).
    """
    if profile and not lin:
        raise FitError(
            f"profile=True but model {model.name!r} has no varying linear "
            f"parameters (linear: {list(model.linear)})"
        )
    profile = bool(lin) if profile is None else profile
    rho_fn: Callable[[dict[str, float], NDArray], NDArray] | None = None
    th_grid: NDArray = np.empty(0)
    if energy_constraint is not False and energy_constraint is not None:
        ti = np.asarray(fd.theta_i_deg, float)
        th_grid = np.unique(np.concatenate([np.linspace(ti.min(), ti.max(), 7), ti]))
        rho_fn = _energy_rho(model, energy_constraint)
        profile = profile and len(lin) == 1
    return (lin if profile else []), rho_fn, th_grid


def _energy_cons(
    obj: Objective, rho_fn: Callable[[dict[str, float], NDArray], NDArray], th_grid: NDArray
) -> Callable[[NDArray], float]:
    """The nlopt inequality constraint ``max rho(theta) - 1 <= 0`` on the search vector."""

    def cons(xx: NDArray) -> float:
        return float(np.max(rho_fn(obj.from_vector(xx), th_grid)) - 1.0)

    return cons


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
    with np.errstate(all="ignore"):
        for name, budget in zip(stages, budgets, strict=True):
            if obj.n == 0:
                break
            if _is_global(name):
                x, info = _run_stage(obj, name, budget, x, seed, cons)
            else:
                x, info = _run_local(obj, name, budget, x, seed, cons, nfree, use_sigma)
            stage_info.append(info)
            last_code, message = info["code"], info["message"]
        converged = last_code in _OK_CODES or last_code == CHI2_CONVERGED
        if obj.n and cons is None and stages and not _is_global(stages[-1]) and converged:
            x, info = _polish(obj, x, nfree, use_sigma)
            stage_info.append(info)
            message = f"{message}; {info['message']}"
            if info["code"] == 0:
                last_code = nlopt.MAXEVAL_REACHED
    return x, stage_info, last_code, message


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


def _profiles(
    pb: _Problem, res: FitResult, ci: str, seed: int, on_wald: Callable[[FitResult], None] | None
) -> bool:
    """Profile intervals in ``res`` where ``ci`` asks (:func:`.intervals.refine_intervals`)."""
    obj = Objective(pb.model, pb.fd, res.params, pb.weights)
    prof = partial(_profile_intervals, pb.model, pb.fd, res.params, pb.weights, pb.prof)
    return refine_intervals(res, obj, ci, lambda ks, d: prof(ks, res.chisqr, d, seed), on_wald)


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


def _energy_check(
    rho_fn: Callable[[dict[str, float], NDArray], NDArray],
    vals: dict[str, float],
    th_grid: NDArray,
    success: bool,
    message: str,
) -> tuple[dict[str, Any], bool, str]:
    """The energy record of a constrained fit; a violated constraint makes it fail."""
    rho_max = float(np.max(rho_fn(vals, th_grid)))
    info = {"theta_i_deg": th_grid.tolist(), "max_rho": rho_max, "active": rho_max > 1 - 1e-6}
    if rho_max > 1 + 1e-6:
        return info, False, f"energy constraint violated (max rho {rho_max:.6g}); " + message
    return info, success, message


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


def _apply_guess(model: Model, fd: FitData, p: Parameters, given: set[str]) -> bool:
    """Start varying parameters not set by the caller at the model's own guess."""
    with np.errstate(all="ignore"):
        g = model.guess(
            np.radians(np.asarray(fd.theta_i_deg, dtype=float)),
            np.radians(np.asarray(fd.theta_r_deg, dtype=float)),
            np.asarray(fd.value, dtype=float),
        )
    if not g:
        return False
    used = False
    for k, v in g.items():
        q = p[k]
        if q.vary and k not in given and math.isfinite(v) and q.min < v < q.max:
            q.value = float(v)
            used = True
    return used


def _check_design(model: Model, fd: FitData, varying: list[str]) -> None:
    """Refuse designs that cannot identify the free parameters."""
    if not varying:
        raise FitError("nothing to fit: every parameter is fixed")
    n_pts, nvarys = len(fd), len(varying)
    if n_pts <= nvarys:
        raise FitError(
            f"data: {n_pts} point(s) for {nvarys} free parameter(s) {varying}; "
            f"need at least {nvarys + 1} to fit and estimate uncertainties"
        )
    shape = [k for k in model.specular_line_shape if k in varying]
    on_line = np.abs(np.asarray(fd.theta_r_deg) - np.asarray(fd.theta_i_deg)) < 1e-9
    if shape and on_line.all():
        raise FitError(
            f"data: all {n_pts} points lie on the specular line theta_r == theta_i, where "
            f"{model.name} identifies only k1 exp(-k2^2/k3^2) (docs/models.md 1.1); "
            f"add off-specular points or fix {list(model.specular_line_shape)}, "
            "e.g. fix={'k2': 0.0, 'k3': 0.4}"
        )


def _energy_bound(
    rho_fn: Callable[[dict[str, float], NDArray], NDArray], k_lin: str, th_grid: NDArray
) -> Callable[[dict[str, float]], float]:
    """Upper bound on the one profiled amplitude from rho(theta) <= 1 (rho is linear in it)."""

    def upper(vals: dict[str, float]) -> float:
        r1 = rho_fn({**vals, k_lin: 1.0}, th_grid)
        r0 = rho_fn({**vals, k_lin: 0.0}, th_grid)
        if not (np.all(np.isfinite(r1)) and np.all(np.isfinite(r0))):
            return 0.0
        slope = r1 - r0
        with np.errstate(divide="ignore", invalid="ignore"):
            ub = np.where(slope > 0, (1.0 - r0) / slope, np.inf)
        return float(np.min(ub))

    return upper


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
