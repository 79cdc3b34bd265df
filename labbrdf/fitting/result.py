"""FitResult: lmfit's attribute names, a JSON-safe summary, a text report and an HTML view."""

from __future__ import annotations

import html
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._plotting import curve_grid, draw_scan, legend_outside
from ..jsonsafe import jsonable
from ..models import ModelError, Parameters
from ..models import get as get_model
from .data import FitData

__all__ = ["FitResult"]


def _decimals(stderr: float) -> int:
    """Decimals that keep two significant digits of ``stderr``."""
    return max(0, 1 - math.floor(math.log10(stderr)))


def _fmt_unc(value: float, stderr: float | None) -> str:
    """``value +/- stderr`` with as many digits as the uncertainty supports (2 significant)."""
    if stderr is None or not math.isfinite(stderr) or stderr <= 0:
        return f"{value:.7g} +/- (not estimated)"
    dec = _decimals(stderr)
    if dec > 12:
        return f"{value:.10g} +/- {stderr:.2g}"
    return f"{value:.{dec}f} +/- {stderr:.{dec}f}"


def _fmt_ci(ci: tuple[float, float] | None, stderr: float | None) -> str:
    """``[lo, hi]`` to the decimals of :func:`_fmt_unc`."""
    if ci is None or stderr is None or not (math.isfinite(stderr) and stderr > 0):
        return ""
    dec = min(_decimals(stderr), 12)
    return f"[{ci[0]:.{dec}f}, {ci[1]:.{dec}f}]"


@dataclass
class FitResult:
    """Outcome of :func:`fit`, with lmfit's attribute names.

    Attributes
    ----------
    model : str
        Registry name of the model.
    options : dict
        The model options (``G``, the five-parameter shadowing choice, lives here).
    method : str
        The algorithm stages joined by ``+``.
    seed : int
        Seed given to ``nlopt.srand`` before each stage.
    params : Parameters
        Fitted values with ``stderr``, ``ci95`` (95% interval, see ``ci_method``, clipped
        to the bounds) and ``correl``.
    init_values : dict
        Starting values.
    var_names : list of str
        The varying parameters (profiled ones included), the order of ``covar``.
    covar : ndarray or None
        Covariance of the varying parameters.
    flags : dict
        name -> list of ``"at_bound"``, ``"not_identifiable"`` (relative stderr above
        :data:`REL_STDERR_MAX`, |correlation| above :data:`CORREL_MAX`, singular or
        ill-conditioned J^T W J, or no effect on the data) or ``"poorly_determined"``
        (relative stderr above :data:`REL_STDERR_POOR`).
    flag_reasons : dict
        name -> list of human-readable reasons for the flags.
    profiled : list of str
        Linear parameters solved by bounded linear least squares.
    nfev, ndata, nvarys, nfree : int
        Objective evaluations, points, varying parameters, ``ndata - nvarys``.
    chisqr, redchi, aic, bic : float
        chi-square (weighted by 1/sigma^2 when the data have sigma), ``chisqr/nfree``,
        Akaike and Bayesian information criteria (lmfit's definitions).
    rmse : float
        Root-mean-square residual ``sqrt(mean((y - f)^2))`` [data units].
    rmse_pct : float or None
        The paper's "RMSE / %" (Tables 1-2): ``100 sqrt(mean(((y - f) / y)^2))`` [%]; None
        when a measured value is 0.
    weighted : bool
        Whether the data carried sigma (weights 1/sigma^2, covariance not rescaled).
    weighting : str
        The weighting used, in words (``uniform``, ``1/sigma^2 ...``, ``relative: ...``).
    nmasked : int
        Points with value 0 excluded as instrument-masked (``mask_zeros``).
    outside_domain : str
        Why the points lie outside the model's domain (a specular-plane model fitted to
        out-of-plane points: :meth:`labbrdf.models.Model.outside_domain`); "" when inside.
    success : bool
        The last stage converged and every parameter and chisqr is finite.
    message : str
    elapsed_s : float
        Wall time of the fit [s].
    ndropped : int
        Points dropped by ``nan_policy='omit'``.
    stages : list of dict
        Per stage: algorithm, nfev, chisqr, nlopt return code and message; a local stage
        also lists its ``rounds`` (restarts from the best point, each with the chi-square
        it started from, see :func:`labbrdf.fit`). A final record with algorithm
        ``"polish (scipy least_squares, trf)"`` describes the polish of a converged local
        stage (code: the scipy status, > 0 converged, 0 budget spent).
    energy : dict or None
        The energy constraint: incidence grid [deg] and max rho at the optimum.
    warnings : list of str
        Notes on the data or the fit (dropped points, intervals not found).
    ci_method : str
        What was asked: ``wald`` (value +- t stderr, Student t with ``nfree`` degrees of
        freedom), ``profile`` (profile of chi-square) or ``auto`` (Wald, and the profile
        where it can change the interval); see :func:`labbrdf.fitting.fit`.
    ci_methods : dict
        name -> ``"wald"`` or ``"profile"``: the interval each varying parameter carries.
    ci_reasons : dict
        name -> why its profile was computed (``ci="auto"``: the rule of
        :func:`labbrdf.fitting.intervals.profile_reasons`; ``"requested"`` with
        ``ci="profile"``).
    cond : float or None
        Condition number of the scaled Jacobian at the optimum.
    nlopt_version : str or None
        The nlopt library that ran the fit (its search paths differ between releases).
    residual : ndarray
        ``y - f`` at the optimum [data units].
    best_fit : ndarray
        The model at the data points [data units].
    data : FitData or None
        The points fitted (after dropping and masking), for :meth:`plot`.
    replicates : list of dict or None
        Seed replicates of a stochastic model (:func:`labbrdf.fitting.fit_replicates`):
        per fit its model ``seed`` and the varying parameters' values; None otherwise.
    seed_spread : dict or None
        name -> standard deviation (ddof 1) of the replicate estimates, s_between.

    Notes
    -----
    The 2013 paper reports "RMSE / %" without a formula (its fits used a Matlab toolbox,
    its ref. [22]); we read it as the relative root-mean-square residual in percent, the
    reading under which its "less than 5 %" engineering criterion makes sense for a
    relative measurement. ``rmse`` gives the absolute figure in the data's units.
    """

    model: str
    options: dict[str, Any]
    method: str
    seed: int
    params: Parameters
    init_values: dict[str, float]
    var_names: list[str]
    covar: NDArray | None
    flags: dict[str, list[str]]
    flag_reasons: dict[str, list[str]]
    profiled: list[str]
    nfev: int
    ndata: int
    nvarys: int
    nfree: int
    chisqr: float
    redchi: float
    aic: float
    bic: float
    rmse: float
    rmse_pct: float | None
    weighted: bool
    success: bool
    message: str
    elapsed_s: float
    quantity: str = "brdf"
    unit: str = "sr-1"
    ndropped: int = 0
    weighting: str = "uniform"
    outside_domain: str = ""
    nmasked: int = 0
    stages: list[dict[str, Any]] = field(default_factory=list)
    energy: dict[str, Any] | None = None
    warnings: list[str] = field(default_factory=list)
    ci_method: str = "wald"
    ci_methods: dict[str, str] = field(default_factory=dict)
    ci_reasons: dict[str, str] = field(default_factory=dict)
    cond: float | None = None
    nlopt_version: str | None = None
    residual: NDArray | None = field(default=None, repr=False)
    best_fit: NDArray | None = field(default=None, repr=False)
    data: FitData | None = field(default=None, repr=False)
    replicates: list[dict[str, float]] | None = None
    seed_spread: dict[str, float] | None = None

    @property
    def G(self) -> Any:
        """The shadowing-function choice G of the five-parameter model (None otherwise).

        Read from the model option ``shadowing`` (or ``G``).
        """
        return self.options.get("shadowing", self.options.get("G"))

    @property
    def values(self) -> dict[str, float]:
        """name -> fitted value."""
        return self.params.values()

    def plot(self, ax: Any = None) -> Any:
        """The fit against its data: scans with residuals, or maps over the hemisphere.

        In-plane data (every point in the plane of incidence, phi_r = 0 or 180 deg): one
        colour and marker per (incidence angle, detector azimuth) scan, the measured
        points against theta_r with their file sigmas, the fitted model as a line (the
        report's scan figures draw the same way), and below the residuals ``y - f``
        (:attr:`residual`) at the points; more scans than seven are coloured by their
        angle of incidence (a colour bar) and the legend, below the axes, names the
        styles.

        Hemispherical data (any other azimuth): per angle of incidence a row of three
        maps of the projected hemisphere, measured, model and relative residual
        ``(model - measured) / measured``, drawn as ``labbrdf fit --residual-maps`` draws
        them (``labbrdf._brdf_maps.draw_brdf_maps``): thousands of scans of a few
        points each would be unreadable as lines, and slow to draw.

        Parameters
        ----------
        ax : pair of matplotlib Axes, optional
            In-plane data: the data axes and the residual axes; default a new figure
            with the residuals in a short panel below the data. Hemispherical data: not
            accepted (the maps make their own figure).

        Returns
        -------
        matplotlib Figure
            In the package's style (:mod:`labbrdf.figstyle`: readable at 96 dpi).

        Raises
        ------
        ValueError
            The result carries no data (built by hand) or is a film fit (its points
            mix psi, Delta, R and T, which have no common axis); ``ax`` given for
            hemispherical data.

        Notes
        -----
        The model line is evaluated on 121 detector angles across the measured ones when
        the model is in the registry (:func:`labbrdf.models.get` with :attr:`options`);
        a model from outside the registry is drawn through its values at the data points.
        The maps show the model at the data points (:attr:`best_fit`).
        """
        from ..figstyle import rc_context

        with rc_context():
            if self._hemispherical():
                if ax is not None:
                    raise ValueError(
                        "ax: hemispherical data are drawn as maps in a figure of their own; "
                        "call plot() without ax"
                    )
                return self._plot_maps()
            return self._plot_scans(ax)

    def _hemispherical(self) -> bool:
        """Whether the fitted points leave the plane of incidence (phi_r not 0 or 180 deg)."""
        d = self._plot_data()
        pr = np.mod(np.asarray(d.phi_r_deg, float), 360.0)
        return bool(np.any((np.abs(pr) > 1e-6) & (np.abs(pr - 180.0) > 1e-6)))

    def _plot_maps(self) -> Any:
        """Measured, model and residual maps per angle of incidence (hemispherical data)."""
        import matplotlib.pyplot as plt

        from .._brdf_maps import draw_brdf_maps, map_panels, maps_size
        from ..figstyle import PAGE_WIDTH_IN

        d = self._plot_data()
        y = np.asarray(d.value, float)
        panels = map_panels(
            np.broadcast_to(np.asarray(d.theta_i_deg, float), y.shape),
            np.broadcast_to(np.asarray(d.theta_r_deg, float), y.shape),
            np.broadcast_to(np.asarray(d.phi_r_deg, float), y.shape),
            y,
            np.asarray(self.best_fit, float),
            f"{self.model} (one fit, all incidences)",
        )
        fig = plt.figure(figsize=maps_size(panels, PAGE_WIDTH_IN), layout="constrained")
        draw_brdf_maps(fig, panels)
        fig.suptitle(f"{self.model}: chisqr {self.chisqr:.6g}, redchi {self.redchi:.4g}")
        return fig

    def _plot_scans(self, ax: Any) -> Any:
        """Scans with model lines and residuals below (in-plane data)."""
        series = self._scan_series()
        if ax is None:
            import matplotlib.pyplot as plt

            from ..figstyle import PANEL_MIN_IN

            fig, ax = plt.subplots(
                2,
                1,
                sharex=True,
                figsize=(2.4 * PANEL_MIN_IN[0], 5.6),
                gridspec_kw={"height_ratios": [3, 1.2]},
                layout="constrained",
            )
        axes = np.asarray(ax, dtype=object).ravel()
        if axes.size != 2:
            raise ValueError(f"ax: expected two Axes (data, residuals), got {axes.size}")
        scale = draw_scan(axes[0], axes[1], series)
        axes[0].set_ylabel(f"{self.quantity} [{self.unit}]")
        axes[1].set_ylabel(f"residual [{self.unit}]")
        axes[0].set_title(f"{self.model}: chisqr {self.chisqr:.6g}, redchi {self.redchi:.4g}")
        legend_outside(axes[0], scale, ncol=3)
        return axes[0].figure

    def _plot_data(self) -> FitData:
        """:attr:`data`, or the reason it cannot be drawn."""
        d = self.data
        if d is None or self.best_fit is None or self.residual is None:
            raise ValueError(
                "this FitResult carries no data to plot (it was not made by labbrdf.fit)"
            )
        if d.quantity == "film":
            raise ValueError(
                "a film fit mixes psi, Delta, R and T in one residual vector: plot its "
                "channels from FilmFit.data instead"
            )
        return d

    def _scan_series(self) -> list[dict[str, Any]]:
        """The data, model and residual of each (theta_i, phi_r) scan, for :meth:`plot`."""
        d = self._plot_data()
        try:
            model = get_model(self.model, **self.options)
        except ModelError:
            model = None  # not a registry model: draw it through the data points
        ti = np.asarray(d.theta_i_deg, float)
        tr = np.asarray(d.theta_r_deg, float)
        pr = np.asarray(d.phi_r_deg, float)
        y = np.asarray(d.value, float)
        sig = np.asarray(d.sigma, float)
        wl = None if d.wavelength_nm is None else np.asarray(d.wavelength_nm, float)
        keys = sorted(set(zip(ti.round(6).tolist(), pr.round(6).tolist(), strict=True)))
        several_phi = len({k[1] for k in keys}) > 1
        series = []
        for t_i, p_r in keys:
            sel = (ti.round(6) == t_i) & (pr.round(6) == p_r)
            order = np.argsort(tr[sel], kind="stable")
            x = tr[sel][order]
            if model is not None:
                grid = curve_grid(x)
                wavelength = None if wl is None else float(np.nanmean(wl[sel]))
                curve = np.asarray(
                    model.evaluate(
                        np.radians(t_i),
                        np.radians(grid),
                        np.radians(p_r),
                        wavelength=wavelength,
                        params=self.values,
                    ),
                    float,
                )
            else:
                grid, curve = x, np.asarray(self.best_fit, float)[sel][order]
            s = sig[sel][order]
            label = f"{t_i:g}\u00b0" + (f", \u03c6r {p_r:g}\u00b0" if several_phi else "")
            series.append(
                {
                    "theta_i": t_i,
                    "label": label,
                    "theta_r": x,
                    "value": y[sel][order],
                    "sigma": s if np.isfinite(s).all() else None,
                    "curve_theta_r": grid,
                    "curves": {"model": curve},
                    "residual": {"y - f": np.asarray(self.residual, float)[sel][order]},
                }
            )
        return series

    @property
    def at_bound(self) -> list[str]:
        """The varying parameters that ended at a bound of their box (flag ``at_bound``)."""
        return [k for k in self.var_names if "at_bound" in self.flags.get(k, [])]

    @property
    def status(self) -> str:
        """``ok``, or why a fit is not a plain success.

        ``failed``; ``outside the model's domain`` (the points lie where the model does not
        apply: :meth:`labbrdf.models.Model.outside_domain`); ``at bound: NAMES``
        (converged, but the optimum may lie outside the box).
        """
        if not self.success:
            return "failed"
        if self.outside_domain:
            return "outside the model's domain"
        return f"at bound: {', '.join(self.at_bound)}" if self.at_bound else "ok"

    def _success_text(self) -> str:
        """``success`` as a person should read it: with the domain and the bounds."""
        if self.success and self.outside_domain:
            return f"True, but outside the model's domain (see Warnings) ({self.message})"
        if self.success and self.at_bound:
            return (
                f"True, but {', '.join(self.at_bound)} at a bound of its box: the best fit "
                f"may lie outside it; widen the bound, fix the parameter or change the model "
                f"({self.message})"
            )
        return f"{self.success} ({self.message})"

    def summary(self) -> dict[str, Any]:
        """Plain-Python, JSON-safe dict (NaN/inf as None) for reports and the CLI."""
        params = {}
        for k, p in self.params.items():
            params[k] = {
                "value": p.value,
                "stderr": p.stderr,
                "ci95": list(p.ci95) if p.ci95 is not None else None,
                "min": p.min,
                "max": p.max,
                "vary": p.vary,
                "units": p.units,
                "init_value": self.init_values.get(k),
                "profiled": k in self.profiled,
                "ci_method": self.ci_methods.get(k, self.ci_method) if p.vary else None,
                "ci_reason": self.ci_reasons.get(k),
                "flags": list(self.flags.get(k, [])),
                "at_bound": "at_bound" in self.flags.get(k, []),
                "flag_reasons": list(self.flag_reasons.get(k, [])),
                "correl": dict(p.correl) if p.correl else {},
            }
        out = {
            "model": self.model,
            "options": self.options,
            "G": self.G,
            "method": self.method,
            "seed": self.seed,
            "params": params,
            "var_names": self.var_names,
            "nfev": self.nfev,
            "ndata": self.ndata,
            "nvarys": self.nvarys,
            "nfree": self.nfree,
            "chisqr": self.chisqr,
            "redchi": self.redchi,
            "aic": self.aic,
            "bic": self.bic,
            "rmse": self.rmse,
            "rmse_pct": self.rmse_pct,
            "quantity": self.quantity,
            "unit": self.unit,
            "weighted": self.weighted,
            "success": self.success,
            "status": self.status,
            "at_bound": self.at_bound,
            "outside_domain": self.outside_domain or None,
            "message": self.message,
            "elapsed_s": self.elapsed_s,
            "ndropped": self.ndropped,
            "weighting": self.weighting,
            "nmasked": self.nmasked,
            "stages": self.stages,
            "energy": self.energy,
            "warnings": self.warnings,
            "cond": self.cond,
            "ci_method": self.ci_method,
            "ci_methods": self.ci_methods,
            "ci_reasons": self.ci_reasons,
            "nlopt_version": self.nlopt_version,
            "replicates": self.replicates,
            "seed_spread": self.seed_spread,
        }
        return jsonable(out)

    def _param_lines(self) -> list[tuple[str, str, str, str]]:
        rows = []
        for k, p in self.params.items():
            if not p.vary:
                rows.append((k, f"{p.value:.7g} (fixed)", "", ""))
                continue
            ci = _fmt_ci(p.ci95, p.stderr)
            note = ", ".join(self.flags.get(k, []))
            if k in self.profiled:
                note = ", ".join(x for x in (note, "profiled") if x)
            rows.append((k, _fmt_unc(p.value, p.stderr), ci, note))
        return rows

    def fit_report(self, min_correl: float = 0.1) -> str:
        """lmfit-like text report: Model, Fit Statistics, Variables, Correlations, Warnings."""
        unit = self.unit
        lines = [
            "[[Model]]",
            f"    {self.model} {self.options or ''}".rstrip(),
            "[[Fit Statistics]]",
            f"    # fitting method   = {self.method} (seed {self.seed})",
            f"    # function evals   = {self.nfev}",
            f"    # data points      = {self.ndata}"
            + (f" ({self.ndropped} dropped: NaN/inf)" if self.ndropped else ""),
            f"    # variables        = {self.nvarys}",
            f"    chi-square         = {self.chisqr:.6g}"
            + (
                ""
                if self.weighted
                else f" (no sigma in the data: {self.weighting.split(':')[0]} weights)"
            ),
            f"    reduced chi-square = {self.redchi:.6g}",
            f"    Akaike info crit   = {self.aic:.6g}",
            f"    Bayesian info crit = {self.bic:.6g}",
            f"    RMSE               = {self.rmse:.4g} [{unit}]",
            "    RMSE (paper, %)    = "
            + ("n/a" if self.rmse_pct is None else f"{self.rmse_pct:.4g}"),
            f"    weighting          = {self.weighting}",
            f"    success            = {self._success_text()}",
            f"    elapsed            = {self.elapsed_s * 1e3:.1f} ms",
            "[[Variables]]",
        ]
        for k, val, ci, note in self._param_lines():
            s = f"    {k + ':':<6} {val}"
            if ci:
                how = self.ci_methods.get(k, self.ci_method)
                s += f"  95%{' (profile)' if how == 'profile' else ''} {ci}"
            if note:
                s += f"  ({note})"
            lines.append(s)
        pairs = []
        for k in self.var_names:
            for j, c in (self.params[k].correl or {}).items():
                if k < j and abs(c) >= min_correl:
                    pairs.append((abs(c), f"    C({k}, {j}) = {c:+.4f}"))
        if pairs:
            lines.append(f"[[Correlations]] (unreported correlations are < {min_correl:.3f})")
            lines += [s for _, s in sorted(pairs, reverse=True)]
        notes = [f"{k}: {r}" for k, rs in self.flag_reasons.items() for r in rs]
        if self.ci_method == "auto":
            notes += [f"{k}: profile interval, {r}" for k, r in self.ci_reasons.items()]
        notes += self.warnings
        if self.replicates:
            for k, sb in (self.seed_spread or {}).items():
                vals = ", ".join(f"{r[k]:.6g}" for r in self.replicates)
                notes.append(f"{k}: seed replicates {vals} (s_between {sb:.3g})")
        if self.energy:
            notes.append(
                f"energy constraint: max rho = {self.energy['max_rho']:.6g} over "
                f"theta_i {self.energy['theta_i_deg'][0]:.4g}-"
                f"{self.energy['theta_i_deg'][-1]:.4g} deg"
            )
        if notes:
            lines.append("[[Warnings]]")
            lines += [f"    {n}" for n in notes]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        e = html.escape
        stats_rows = [
            ("method", self.method),
            ("seed", self.seed),
            ("nfev", self.nfev),
            ("data points", self.ndata),
            ("variables", self.nvarys),
            ("chi-square", f"{self.chisqr:.6g}"),
            ("reduced chi-square", f"{self.redchi:.6g}"),
            ("RMSE", f"{self.rmse:.4g} {self.unit}"),
            ("RMSE (paper, %)", "n/a" if self.rmse_pct is None else f"{self.rmse_pct:.4g}"),
            ("weighting", self.weighting),
            ("success", self._success_text()),
            ("elapsed", f"{self.elapsed_s * 1e3:.1f} ms"),
        ]
        h = [f"<h4>Fit of {e(self.model)} {e(str(self.options or ''))}</h4>", "<table><tbody>"]
        h += [f"<tr><th>{e(str(a))}</th><td>{e(str(b))}</td></tr>" for a, b in stats_rows]
        h += [
            "</tbody></table>",
            "<table><thead><tr><th>name</th><th>value +/- stderr</th>"
            "<th>95% interval</th><th>flags</th></tr></thead><tbody>",
        ]
        for k, val, ci, note in self._param_lines():
            h.append(
                f"<tr><td>{e(k)}</td><td>{e(val)}</td><td>{e(ci)}</td><td>{e(note)}</td></tr>"
            )
        h.append("</tbody></table>")
        notes = [f"{k}: {r}" for k, rs in self.flag_reasons.items() for r in rs] + self.warnings
        if notes:
            h.append("<ul>" + "".join(f"<li>{e(n)}</li>" for n in notes) + "</ul>")
        return "\n".join(h)

    def __str__(self) -> str:
        return self.fit_report()
