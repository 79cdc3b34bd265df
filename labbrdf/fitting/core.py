"""The fitter: :func:`fit` sets up the problem, searches it, and assembles the result.

``_problem`` checks the arguments and builds the search (the points,
:mod:`~labbrdf.fitting.parameters`, the weights, the :class:`Objective`, the energy
constraint of :mod:`~labbrdf.fitting.energy`); ``_search``
runs the nlopt stages and the polish; ``_finish`` turns the best point into a
:class:`FitResult` with its uncertainties, and profile intervals
(:mod:`~labbrdf.fitting.profiles`) replace the Wald ones where ``ci`` asks.
"""

from __future__ import annotations

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

from .. import parallel
from ..dataset import Measurement
from ..models import Model, Parameters
from ..models import get as get_model
from .data import FitData, FitError, as_fit_data, clean_fit_data
from .defaults import METHOD
from .energy import _energy_bound, _energy_check, _energy_cons, _energy_rho
from .intervals import CI_METHODS, refine_intervals, wald_params
from .objective import Objective
from .parameters import _apply_guess, _check_design, check_seed, setup_params
from .profiles import _profile_intervals
from .replicates import ONE_SEED_WARNING, run_replicates
from .result import FitResult
from .stages import _budgets, _search, _verdict, parse_method
from .uncertainty import jacobian, noise_meat, uncertainties
from .weighting import _weighting

__all__ = ["METHOD", "RELATIVE_FLOOR", "fit", "fit_replicates"]


#: default floor of ``weighting="relative"``, as a fraction of the largest value: a 1000:1
#: dynamic range, what BRDF instruments resolve between a specular peak and the floor
RELATIVE_FLOOR = 1e-3


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
        Unless it bounds one profiled amplitude, every stage must be in
        :data:`~labbrdf.fitting.stages.CONSTRAINED`.
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


def _profiles(
    pb: _Problem, res: FitResult, ci: str, seed: int, on_wald: Callable[[FitResult], None] | None
) -> bool:
    """Profile intervals in ``res`` where ``ci`` asks (:func:`.intervals.refine_intervals`)."""
    obj = Objective(pb.model, pb.fd, res.params, pb.weights)
    prof = partial(_profile_intervals, pb.model, pb.fd, res.params, pb.weights, pb.prof)
    return refine_intervals(res, obj, ci, lambda ks, d: prof(ks, res.chisqr, d, seed), on_wald)
