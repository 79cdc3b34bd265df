"""Fit an analytic PSD model (:mod:`labbrdf.roughness.psd_models`) to a measured PSD.

Why not :func:`labbrdf.fitting.fit`: the package's fitting core is built around BRDF data
(its :class:`~labbrdf.fitting.data.FitData` holds incidence and detector angles, its
:class:`~labbrdf.fitting.objective.Objective` calls a reflectance model of them, its
guesses, energy constraint and replicates are those of BRDF models). A PSD is a function
of one spatial frequency spanning decades in value, so it is fitted here in log space with
the same machinery and conventions as the core:

* the same optimiser chain (``labbrdf.fitting.defaults.METHOD``: nlopt ``GN_CRS2_LM``
  inside the bounds, then ``LN_BOBYQA`` from its best point, seeded with ``nlopt.srand``),
  then scipy ``least_squares`` (trf) as the core's polish;
* the same uncertainties: the covariance from the Jacobian at the optimum by
  :func:`labbrdf.fitting.uncertainty.uncertainties` (its identifiability flags included)
  and 95 % Wald intervals ``value +- t(0.975, dof) stderr``, as ``ci="wald"``.

The residual of bin ``i`` is ``(ln PSD_i - b_i - ln <model>_i) / s_i``: ``<model>_i`` the
model averaged over the periodogram frequencies the bin averages (:meth:`Spectrum.bin_points
<labbrdf.roughness.psd.Spectrum.bin_points>`: a bin-centre value is biased where the PSD
curves), ``s_i = max(u_i / PSD_i, sqrt(psi'(n_i)))`` the relative error of the bin, and
``b_i = psi(n_i) - ln n_i`` the bias of the log of a mean of ``n_i`` exponentially
distributed periodogram values (psi the digamma function; a bin of two values is 0.27
low in the log on average). Every decade counts alike. Positive scale parameters
(``A``, ``B``, ``sigma``, ``corr_length``, ``K``) are searched as logarithms over the
guess times or divided by :data:`SEARCH_FACTOR`; exponents (``C``, ``n``) linearly in their
bounds. Intervals are computed on the searched scale and mapped back (asymmetric for the
log ones); ``stderr`` of a log parameter is ``value x stderr(ln value)``.

Notes
-----
The bin uncertainties of a windowed PSD are somewhat too small (the window correlates
neighbouring frequencies) and an analytic model is never exact over decades: the
covariance is scaled by ``max(1, chi^2 / dof)`` (the Birge ratio), where the core uses 1
for data with sigmas.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import nlopt
import numpy as np
from numpy.typing import NDArray
from scipy import optimize, special

from labbrdf.fitting.uncertainty import uncertainties
from labbrdf.jsonsafe import jsonable

from .psd import Spectrum
from .psd_models import PSDModel, band_sigma, get

__all__ = ["SEARCH_FACTOR", "PSDFit", "fit_psd"]

#: positive scale parameters are searched within guess / SEARCH_FACTOR .. guess * SEARCH_FACTOR
SEARCH_FACTOR = 1e3
_GLOBAL_EVALS_PER_DIM = 200
_LOCAL_EVALS_PER_DIM = 400
_LOG_PARAMS = frozenset({"A", "B", "sigma", "corr_length", "K"})


@dataclass(frozen=True)
class PSDFit:
    """A fitted PSD model over a stated band.

    Attributes
    ----------
    model : str
        Registry name (:data:`labbrdf.roughness.psd_models.PSD_MODELS`).
    kind : str
        ``"2d"`` or ``"1d"``: which form of the model was fitted (the parameters are
        always those of the 2-D form).
    values, stderr : dict
        Fitted parameters and their standard errors (units in :attr:`units`).
    interval : dict
        name -> (low, high), the 95 % interval.
    units : dict
        name -> unit.
    band : (float, float)
        The frequencies fitted [1/m] (the bins inside it).
    ndata, nfree : int
        Bins fitted and degrees of freedom.
    chisqr, redchi : float
        Of the log residuals.
    sigma_band : float
        The fitted model's RMS height over the fitted band [m] (closed form, 2-D).
    sigma_total : float
        Over all frequencies [m] (``inf`` where it diverges).
    flags : dict
        name -> identifiability remarks.
    success : bool
    message : str
    notes : tuple of str
        What the data do not determine (a knee outside the band).
    """

    model: str
    kind: str
    values: dict[str, float]
    stderr: dict[str, float | None]
    interval: dict[str, tuple[float, float]]
    units: dict[str, str]
    band: tuple[float, float]
    ndata: int
    nfree: int
    chisqr: float
    redchi: float
    sigma_band: float
    sigma_total: float
    flags: dict[str, list[str]] = field(default_factory=dict)
    success: bool = True
    message: str = ""
    notes: tuple[str, ...] = ()

    def curve(self, f: Any) -> NDArray[np.float64]:
        """The fitted PSD at ``f`` [1/m], in the fitted form (1-D [m^3] or 2-D [m^4])."""
        m = get(self.model)
        fn = m.psd_1d if self.kind == "1d" else m.psd_2d
        return fn(np.asarray(f, float), *self.values.values())

    def rows(self) -> list[tuple[str, str, str, str]]:
        """(name, value +- stderr, 95 % interval, unit) as text, one row per parameter."""
        out = []
        for k, v in self.values.items():
            se = self.stderr.get(k)
            lo, hi = self.interval.get(k, (math.nan, math.nan))
            val = f"{v:.4g}" + (f" +- {se:.2g}" if se is not None else "")
            out.append((k, val, f"[{lo:.4g}, {hi:.4g}]", self.units[k]))
        return out

    def __str__(self) -> str:
        lo, hi = self.band
        head = (
            f"{self.model} fit ({self.kind} PSD) over {lo:.4g}-{hi:.4g} 1/m: {self.ndata} bins, "
            f"chi^2/dof {self.redchi:.3g}; sigma over the band {self.sigma_band * 1e9:.4g} nm"
        )
        body = [f"  {n} = {v} {u}  95 % {i}" for n, v, i, u in self.rows()]
        return "\n".join([head, *body, *(f"  note: {n}" for n in self.notes)])

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe dict."""
        return jsonable(
            {
                "model": self.model,
                "kind": self.kind,
                "values": self.values,
                "stderr": self.stderr,
                "interval_95": {k: list(v) for k, v in self.interval.items()},
                "units": self.units,
                "band_per_m": list(self.band),
                "ndata": self.ndata,
                "nfree": self.nfree,
                "chisqr": self.chisqr,
                "redchi": self.redchi,
                "sigma_band_m": self.sigma_band,
                "sigma_total_m": self.sigma_total,
                "flags": self.flags,
                "success": self.success,
                "message": self.message,
                "notes": list(self.notes),
            }
        )


class _LogObjective:
    """Weighted log residuals of a model form against binned data, on the search scale."""

    def __init__(self, model: PSDModel, spectrum: Spectrum, sel: NDArray[np.bool_]) -> None:
        self.fn = model.psd_1d if spectrum.kind == "1d" else model.psd_2d
        self.names = model.param_names
        self.is_log = np.array([n in _LOG_PARAMS for n in self.names])
        p, u, n = spectrum.psd[sel], spectrum.u[sel], np.maximum(spectrum.n[sel], 1)
        # the log of a mean of n exponential values is biased by psi(n) - ln n, with
        # standard deviation sqrt(psi'(n)) (a Gamma variable); removed and used as a floor
        self.f = spectrum.f[sel]
        self.lp = np.log(p) - (special.digamma(n) - np.log(n))
        self.w = 1.0 / np.maximum(u / p, np.sqrt(special.polygamma(1, n)))
        # the model averaged over the grid values of each bin, as the data are
        fq, wq, iq = spectrum.bin_points()
        rows = np.flatnonzero(sel)
        keep = np.isin(iq, rows)
        self.fq, self.wq = fq[keep], wq[keep]
        self.iq = np.searchsorted(rows, iq[keep])
        self.nbins = rows.size

    def model(self, vals: NDArray) -> NDArray:
        """The model's mean over each fitted bin's grid frequencies."""
        m = self.fn(self.fq, *vals) * self.wq
        return np.bincount(self.iq, weights=m, minlength=self.nbins)

    def values(self, x: NDArray) -> NDArray:
        return np.where(self.is_log, np.exp(x), x)

    def residual(self, x: NDArray) -> NDArray:
        with np.errstate(all="ignore"):
            r = (self.lp - np.log(self.model(self.values(x)))) * self.w
        return np.where(np.isfinite(r), r, 1e150)

    def chisqr(self, x: NDArray, grad: NDArray | None = None) -> float:
        r = self.residual(x)
        return float(r @ r)


def _select(spectrum: Spectrum, f_min: float | None, f_max: float | None) -> NDArray:
    lo = spectrum.band[0] if f_min is None else float(f_min)
    hi = spectrum.band[1] if f_max is None else float(f_max)
    return (spectrum.f >= lo) & (spectrum.f <= hi) & (spectrum.psd > 0) & (spectrum.u > 0)


def _box(model: PSDModel, obj: _LogObjective, guess: tuple[float, ...]) -> tuple[NDArray, ...]:
    x0, lo, hi = [], [], []
    for name, g, (b_lo, b_hi) in zip(model.param_names, guess, model.bounds, strict=True):
        if name in _LOG_PARAMS:
            c = math.log(max(g, 1e-300))
            span = math.log(SEARCH_FACTOR)
            lo.append(max(c - span, math.log(b_lo)))
            hi.append(c + span if math.isinf(b_hi) else min(c + span, math.log(b_hi)))
            x0.append(c)
        else:
            lo.append(b_lo)
            hi.append(b_hi)
            x0.append(min(max(g, b_lo), b_hi))
    return np.array(x0), np.array(lo), np.array(hi)


def _search(obj: _LogObjective, x0: NDArray, lo: NDArray, hi: NDArray, seed: int) -> NDArray:
    n = x0.size
    x = np.clip(x0, lo, hi)
    for alg, budget in (
        (nlopt.GN_CRS2_LM, _GLOBAL_EVALS_PER_DIM * (n + 1)),
        (nlopt.LN_BOBYQA, _LOCAL_EVALS_PER_DIM * n),
    ):
        opt = nlopt.opt(alg, n)
        opt.set_lower_bounds(lo)
        opt.set_upper_bounds(hi)
        opt.set_min_objective(obj.chisqr)
        opt.set_maxeval(budget)
        if alg == nlopt.LN_BOBYQA:
            opt.set_xtol_rel(1e-10)
        nlopt.srand(seed)
        try:
            x = opt.optimize(x)
        except nlopt.RoundoffLimited:
            pass
    pol = optimize.least_squares(
        obj.residual,
        x,
        bounds=(lo, hi),
        method="trf",
        x_scale="jac",
        xtol=1e-12,
        ftol=1e-12,
        gtol=1e-12,
        max_nfev=200 * n,
    )
    return np.asarray(pol.x if pol.cost * 2 <= obj.chisqr(x) else x, float)


def fit_psd(
    spectrum: Spectrum,
    model: str = "k-correlation",
    *,
    f_min: float | None = None,
    f_max: float | None = None,
    seed: int = 0,
) -> PSDFit:
    """Fit a PSD model to a binned PSD over a stated band.

    Parameters
    ----------
    spectrum : Spectrum
        A map's or a composite PSD (:mod:`labbrdf.roughness.psd`): its ``kind`` says
        whether the model's 2-D or its profile form is fitted.
    model : str
        ``"k-correlation"`` (default), ``"gaussian"``, ``"exponential"`` or ``"fractal"``.
    f_min, f_max : float, optional
        Band to fit [1/m]; default the spectrum's band.
    seed : int
        nlopt's random seed (the global stage): the fit is reproducible.

    Returns
    -------
    PSDFit

    Raises
    ------
    ValueError
        Unknown model, fewer bins in the band than parameters + 1.
    """
    m = get(model)
    sel = _select(spectrum, f_min, f_max)
    f, p = spectrum.f[sel], spectrum.psd[sel]
    k = len(m.param_names)
    if f.size < k + 2:
        raise ValueError(
            f"{f.size} PSD bins in the band, a {model} fit of {k} parameters needs at "
            f"least {k + 2}"
        )
    obj = _LogObjective(m, spectrum, sel)
    p2 = p if spectrum.kind == "2d" else _as_2d_level(m, p, f)
    x0, lo, hi = _box(m, obj, m.guess(f, p2))
    x = _search(obj, x0, lo, hi, seed)
    return _finish(m, spectrum.kind, obj, x, (float(f[0]), float(f[-1])))


def _as_2d_level(m: PSDModel, p: NDArray, f: NDArray) -> NDArray:
    """A 2-D-like spectrum from a 1-D one for the first guess: ``PSD2 ~ PSD1 / (2 f)``."""
    del m
    return p / (2.0 * f)


def _exp(v: float) -> float:
    return math.exp(v) if v < 709.0 else math.inf


def _jacobian(obj: _LogObjective, x: NDArray) -> NDArray:
    r0 = obj.residual(x)
    J = np.empty((r0.size, x.size))
    for j in range(x.size):
        h = 1e-6 * max(abs(x[j]), 1.0)
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        J[:, j] = (obj.residual(xp) - obj.residual(xm)) / (2 * h)
    return -J  # residual = data - model: d(model)/dx has the other sign (irrelevant to J^T J)


def _finish(
    m: PSDModel, kind: str, obj: _LogObjective, x: NDArray, band: tuple[float, float]
) -> PSDFit:
    names = list(m.param_names)
    chisqr = obj.chisqr(x)
    ndata = obj.f.size
    nfree = ndata - len(names)
    redchi = chisqr / nfree
    J = _jacobian(obj, x)
    search_vals = {k: float(v) for k, v in zip(names, x, strict=True)}
    _, se_x, _, reasons, _ = uncertainties(J, names, search_vals, max(1.0, redchi), nfree)
    tq = float(special.stdtrit(nfree, 0.975))
    vals = obj.values(x)
    values: dict[str, float] = {}
    stderr: dict[str, float | None] = {}
    interval: dict[str, tuple[float, float]] = {}
    for j, k in enumerate(names):
        v, s = float(vals[j]), se_x[k]
        values[k] = v
        if s is None:
            stderr[k], interval[k] = None, (math.nan, math.nan)
        elif obj.is_log[j]:
            stderr[k] = v * s
            # beyond a factor e per standard error the interval says nothing (the core's
            # "not identifiable" limit, stderr > |value|): left undetermined
            interval[k] = (
                (_exp(x[j] - tq * s), _exp(x[j] + tq * s)) if s <= 1.0 else (math.nan, math.nan)
            )
            if s > 1.0:
                reasons[k] = [*reasons[k], f"not identifiable: stderr of ln({k}) is {s:.3g} > 1"]
        else:
            stderr[k] = s
            interval[k] = (v - tq * s, v + tq * s)
    # remarks about log parameters speak of ln(value): keep only the structural ones
    flags = {
        k: [r for r in rs if "correl" in r or "singular" in r or f"ln({k})" in r]
        for k, rs in reasons.items()
    }
    flags = {k: r for k, r in flags.items() if r}
    params = tuple(values.values())
    notes = _knee_notes(m.name, values, band) + _misfit_notes(redchi, nfree)
    return PSDFit(
        model=m.name,
        kind=kind,
        values=values,
        stderr=stderr,
        interval=interval,
        units=dict(zip(names, m.units, strict=True)),
        band=band,
        ndata=ndata,
        nfree=nfree,
        chisqr=chisqr,
        redchi=redchi,
        sigma_band=band_sigma(m.name, params, band[0], band[1], profile=kind == "1d"),
        sigma_total=m.total_sigma(params),
        flags=flags,
        success=bool(np.isfinite(chisqr)),
        message="converged" if np.isfinite(chisqr) else "non-finite chi-square",
        notes=notes,
    )


#: upper-tail probability below which chi^2/dof says the model does not describe the spectrum
MISFIT_P = 1e-3


def _misfit_notes(redchi: float, nfree: int) -> tuple[str, ...]:
    """Say so when chi^2/dof exceeds what the bins' own uncertainties allow.

    The bins' log values have the stated standard errors; for a model that describes the
    spectrum, chi^2 follows the chi-square law with ``nfree`` degrees of freedom, so a
    value beyond its upper :data:`MISFIT_P` point means a model of the wrong shape: its
    parameters are then a compromise over the band, and the intervals (scaled by
    sqrt(chi^2/dof)) do not include that bias.
    """
    if nfree < 1 or not math.isfinite(redchi):
        return ()
    limit = float(special.chdtri(nfree, MISFIT_P)) / nfree
    if redchi <= limit:
        return ()
    return (
        f"chi^2/dof {redchi:.3g} is beyond what the bins' uncertainties allow ({limit:.3g} "
        f"at p = {MISFIT_P:g}): the model does not describe this spectrum; its parameters are "
        "a compromise over the band, biased beyond their (scaled) intervals; use the measured "
        "sigma over the band, or another model or band",
    )


def _knee_notes(name: str, values: dict[str, float], band: tuple[float, float]) -> tuple[str, ...]:
    """Say so when a correlation model's knee lies outside the fitted band."""
    length = {"k-correlation": "B", "gaussian": "corr_length", "exponential": "corr_length"}
    if name not in length:
        return ()
    knee = 1.0 / values[length[name]]
    if knee < band[0]:
        return (
            f"the knee 1/{length[name]} = {knee:.3g} 1/m lies below the fitted band "
            f"({band[0]:.3g}-{band[1]:.3g} 1/m): the data show only the power-law side; "
            "the plateau and the correlation length are not determined (fit 'fractal')",
        )
    if knee > band[1]:
        return (
            f"the knee 1/{length[name]} = {knee:.3g} 1/m lies above the fitted band: the data "
            "show only the plateau; the slope is not determined",
        )
    return ()
