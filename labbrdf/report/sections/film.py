"""Section ``film``: a stack model fitted to each angle-dependent psi/Delta file.

Where the angles of incidence of a psi/Delta file disagree (:func:`labbrdf.nk.angle_verdict`
``stack`` or ``partly``), its two-phase pseudo-constants are those of a stack and give
neither a material's n, k nor a reflectance (section ``nk``). Given a film model (a TOML
file, :func:`labbrdf.films.load_model`, or the stated default :func:`default_film_model`),
this section fits it to the file's psi/Delta at every angle (:func:`labbrdf.fit_film`),
for the files of the model's sample only (:func:`_applies_to`: never a file the model reads
as its substrate's table, a bare wafer; ``--film-files`` where the sample groups do not say)
and shows the model, the parameters with their intervals, psi and Delta against wavelength
per angle with the fit and the residuals, each layer's n, k with its uncertainty band, and
the reflectance comparison redone with the fitted stack: the measured reflectance of the
same sample (:mod:`labbrdf.report.pairing`; not used by the fit) against the stack's R_s, R_p
(:meth:`labbrdf.FilmFit.compare_reflectance`), inside the fitted wavelength range.

Uncertainties of derived curves (n, k of a layer, predicted R) are first-order: central
differences of the curve in each varying parameter, combined with the fit's covariance
``J C J^T``, times ``sqrt(chi2/nu)`` where chi-square rejects the film model
(:attr:`labbrdf.FilmFit.misfit_scale`).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ... import films
from ... import nk as nkmod
from ...fitting.film import FilmFit, fit_film
from ...fitting.film_display import intervals_text
from ...fitting.film_verdict import MSE_WRONG_MODEL
from .. import figures
from ..agreement import P_AGREE, chi_square
from ..builder import Unavailable, slug
from ..context import Context
from ..inputs import file_frames
from ..pairing import how_to_pair, same_sample, sample_groups_of

__all__ = ["default_film_model", "film_model_of", "film_section"]

#: most wavelengths on which layer n, k and their bands are drawn
_NK_POINTS = 120
#: most angles of incidence (or channel-angle pairs) drawn per figure, one colour each
_MAX_ANGLES = 6
_COLOURS = ("C0", "C1", "C2", "C3", "C4", "C5")


def _describe(m: Any) -> str:
    """A material in a few words: its model name and, for a table, its source."""
    src = getattr(m, "source", "")
    if m.name == "constant":
        v = complex(np.asarray(m.nk(500.0)).ravel()[0])
        return f"n = {v.real:.4g}" + (f" + {v.imag:.4g}i" if v.imag else "")
    return f"{m.name} {src}".strip()


def default_film_model() -> films.FilmModel:
    """The stated default: :meth:`labbrdf.films.FilmModel.cauchy_on_silicon`.

    One transparent Cauchy layer (thickness free in [0, 1000] nm) on crystalline silicon,
    fitted over the silicon table's 250-1450 nm; used only when asked for
    (``labbrdf report --film-default``).
    """
    return films.FilmModel.cauchy_on_silicon()


def _propagated(
    fit: FilmFit, curve: Callable[[films.Stack], np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """``curve`` of the best-fit stack and its first-order 1-sigma from the covariance."""
    res = fit.result
    base = np.asarray(curve(fit.stack), float)
    names = list(res.var_names)
    cov = None if res.covar is None else np.asarray(res.covar, float)
    if not names or cov is None or cov.shape != (len(names), len(names)):
        return base, np.full(base.shape, np.nan)
    vals = {k: res.params[k].value for k in names}
    jac = []
    for k in names:
        q = res.params[k]
        h = 1e-5 * max(abs(q.value), 1e-3)
        up, dn = dict(vals), dict(vals)
        up[k] = min(q.value + h, q.max)
        dn[k] = max(q.value - h, q.min)
        step = up[k] - dn[k]
        try:
            a = np.asarray(curve(fit.model.stack.with_values(up)), float)
            b = np.asarray(curve(fit.model.stack.with_values(dn)), float)
        except ValueError:
            return base, np.full(base.shape, np.nan)
        jac.append((a - b) / step if step > 0 else np.zeros_like(base))
    j = np.stack([x.ravel() for x in jac], axis=-1)
    var = np.einsum("ij,jk,ik->i", j, cov, j).reshape(base.shape)
    return base, np.sqrt(np.maximum(var, 0.0))


def _param_rows(summary: dict[str, Any]) -> list[dict[str, Any]]:
    """The varying parameters of a :meth:`labbrdf.FilmFit.summary`, one row each."""
    groups = [(lay["name"], lay["parameters"]) for lay in summary["layers"]]
    groups.append(("substrate", summary["substrate"]["parameters"]))
    rows = []
    for owner, params in groups:
        for name, d in params.items():
            if not d.get("vary"):
                continue
            ci = d.get("ci95") or [None, None]
            cis = d.get("ci95_scaled") or [None, None]
            lo, hi = d.get("bounds") or [None, None]
            rows.append(
                {
                    "parameter": f"{owner}.{name}",
                    "value": d["value"],
                    "stderr": d.get("stderr"),
                    "ci_lo": ci[0],
                    "ci_hi": ci[1],
                    "interval": d.get("ci_method") or "",
                    "ci_lo_scaled": cis[0],
                    "ci_hi_scaled": cis[1],
                    "units": d.get("units", ""),
                    "min": lo,
                    "max": hi,
                    "flags": ", ".join(d.get("flags", [])),
                }
            )
    return rows


def _break_at_wraps(x: np.ndarray, delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A Delta curve [deg] with a gap where it wraps between 360 and 0 (no vertical line)."""
    jumps = np.flatnonzero(np.abs(np.diff(delta)) > 180.0) + 1
    return np.insert(x, jumps, np.nan), np.insert(delta, jumps, np.nan)


def _psi_delta_figure(fit: FilmFit) -> str:
    d = fit.data
    ell = d[d["quantity"].astype(str).isin(["psi", "delta"])]
    th_all = sorted(ell["theta_i_deg"].round(2).unique())
    if len(th_all) > _MAX_ANGLES:
        pick = np.linspace(0, len(th_all) - 1, _MAX_ANGLES).round().astype(int)
        th_all = [th_all[i] for i in sorted(set(pick))]
    panels = []
    for q, unit in (("psi", "\u03c8"), ("delta", "\u0394")):
        series, resid = [], []
        rows = ell[ell["quantity"].astype(str) == q]
        for col, th in zip(_COLOURS, th_all, strict=False):
            g = rows[rows["theta_i_deg"].round(2) == th].sort_values("wavelength_nm")
            if g.empty:
                continue
            x = g["wavelength_nm"].to_numpy(float)
            psi_m, delta_m = fit.stack.psi_delta(x, g["theta_i_deg"].to_numpy(float))
            model = psi_m if q == "psi" else delta_m
            meas = g["value"].to_numpy(float)
            r = meas - model
            if q == "delta":
                r = (r + 180.0) % 360.0 - 180.0
            lab = f"\u03b8i {th:g}\u00b0"
            series.append({"label": lab, "x": x, "y": meas, "style": "points", "colour": col})
            xl, yl = _break_at_wraps(x, model) if q == "delta" else (x, model)
            series.append({"label": "", "x": xl, "y": yl, "style": "line", "colour": "k"})
            resid.append(
                {"label": lab, "x": x, "y": r, "band": g["sigma"].to_numpy(float), "colour": col}
            )
        panels.append(
            {
                "title": f"{unit}: measured (points) and fit (lines)",
                "xlabel": "wavelength [nm]",
                "ylabel": f"{unit} [deg]",
                "series": series,
            }
        )
        panels.append(
            {
                "title": f"{unit} residual (measured - fit), band = file's 1-sigma",
                "xlabel": "wavelength [nm]",
                "ylabel": f"\u0394{unit} [deg]" if q == "psi" else "\u0394\u0394 [deg]",
                "series": resid,
            }
        )
    return figures.panels_figure(panels, ncols=2, panel_size=(5.6, 3.4))


def _nk_figure(fit: FilmFit) -> str:
    wl_all = np.unique(fit.data["wavelength_nm"].to_numpy(float))
    wl = np.linspace(wl_all.min(), wl_all.max(), min(_NK_POINTS, len(wl_all)))
    names = [lay.name for lay in fit.stack.layers] + ["substrate"]
    panels = []
    for part in ("n", "k"):
        series = []
        for name in names:

            def curve(s: films.Stack, name: str = name, part: str = part) -> np.ndarray:
                v = s.nk(wl)[name]
                return np.asarray(v.real if part == "n" else v.imag, float)

            y, sig = _propagated(fit, curve)
            sig = sig * (fit.misfit_scale or 1.0)
            series.append({"label": name, "x": wl, "y": y, "band": sig})
        panels.append(
            {
                "title": f"{part} of each layer (fitted stack)",
                "xlabel": "wavelength [nm]",
                "ylabel": f"{part} [1]",
                "series": series,
            }
        )
    return figures.panels_figure(panels, ncols=2)


def _reflectance(
    ctx: Context, tag: str, src: str, fit: FilmFit, rsrc: str, rows: pd.DataFrame
) -> dict[str, Any] | None:
    """Measured reflectance of ``rsrc`` against the fitted stack's R_s, R_p (or mean)."""
    b = ctx.b
    name = f"{rsrc}: measured reflectance agrees with the stack fitted to {src}"
    r = rows[rows["quantity"] == "reflectance"]
    lo, hi = _fit_range(fit)
    r = r[(r["wavelength_nm"] >= lo) & (r["wavelength_nm"] <= hi)]
    if r.empty:
        b.skip(f"film.reflectance.{tag}", name, f"no reflectance row in {lo:g}-{hi:g} nm")
        return None
    try:
        cmp = fit.compare_reflectance(r)
    except ValueError as exc:
        b.skip(f"film.reflectance.{tag}", name, str(exc))
        return None
    wl = cmp["wavelength_nm"].to_numpy(float)
    theta = np.nan_to_num(cmp["theta_i_deg"].to_numpy(float), nan=0.0)
    ch = cmp["channel"].astype(object).where(cmp["channel"].notna(), "").astype(str).to_numpy()
    meas, msig = cmp["measured"].to_numpy(float), cmp["measured_sigma"].to_numpy(float)
    pred, pred_sigma = cmp["predicted"].to_numpy(float), cmp["predicted_sigma"].to_numpy(float)
    diff, dsig = cmp["difference"].to_numpy(float), cmp["difference_sigma"].to_numpy(float)
    z = cmp["z"].to_numpy(float)
    nz, chi2, p = chi_square(z)
    chans = sorted({c for c in ch if c})
    kind = f"R_{'/'.join(chans)}" if chans else "(R_s + R_p)/2"
    series_m, series_d = [], []
    frame = pd.DataFrame(
        {"wl": wl, "th": np.round(theta, 2), "ch": ch, "m": meas, "p": pred, "ps": pred_sigma,
         "d": diff, "ds": dsig, "ms": msig}
    )  # fmt: skip
    groups = list(frame.groupby(["ch", "th"], sort=True))
    if len(groups) > _MAX_ANGLES:
        keep = np.linspace(0, len(groups) - 1, _MAX_ANGLES).round().astype(int)
        groups = [groups[i] for i in sorted(set(keep))]
    for col, ((c, th), g) in zip(_COLOURS, groups, strict=False):
        g = g.sort_values("wl")
        lab = f"{c or 'unpolarised'} \u03b8i {th:g}\u00b0"
        series_m.append(
            {"label": lab, "x": g["wl"], "y": g["m"], "style": "points", "colour": col}
        )
        series_m.append(
            {"label": "", "x": g["wl"], "y": g["p"], "band": g["ps"].to_numpy(), "colour": "k"}
        )
        series_d.append(
            {"label": lab, "x": g["wl"], "y": g["d"], "band": g["ds"].to_numpy(), "colour": col}
        )
    b.figure(
        f"film_{tag}_refl",
        f"Reflectance of {rsrc} against the stack fitted to {src}",
        f"Measured: {kind} [1] of {rsrc} ({len(cmp)} points, not used by the fit; coloured, "
        f"at most {_MAX_ANGLES} channel-angle pairs drawn). Modelled (black lines): the "
        f"stack fitted to the psi/Delta of {src}, coherent transfer matrices, band = "
        "1-sigma propagated from the fit's covariance (times sqrt(chi2/nu) where chi-square "
        "rejects the film model). Right: measured - predicted "
        "with the measurement's and the prediction's 1-sigma in quadrature.",
        figures.reflectance_comparison_figure(series_m, series_d, panel_size=(5.6, 3.4)),
    )
    b.check(
        f"film.reflectance.{tag}",
        name,
        nz > 0 and p >= P_AGREE,
        against="coherent transfer-matrix reflectance of the stack fitted to psi/Delta",
        value=p if nz else None,
        tolerance=P_AGREE,
        justification=(
            f"chi-square test of z = difference / sigma over {nz} points (chi2/dof "
            f"{chi2 / nz:.3g}, mean difference {float(np.mean(diff)):+.3g}, median "
            f"measured/predicted {float(np.median(meas / pred)):.4g}); value = p-value, "
            "fails below the tolerance"
        )
        if nz
        else "no point with a finite uncertainty",
    )
    return {
        "ellipsometer_file": src,
        "refl_file": rsrc,
        "quantity": kind,
        "points": len(cmp),
        "mean_diff": float(np.mean(diff)),
        "rms_diff": float(np.sqrt(np.mean(diff**2))),
        "ratio": float(np.median(meas / pred)),
        "chi2_dof": chi2 / nz if nz else None,
        "p_value": p if nz else None,
    }


def _fit_range(fit: FilmFit) -> tuple[float, float]:
    w = fit.data["wavelength_nm"].to_numpy(float)
    return float(w.min()), float(w.max())


def _flagged(
    ellips: list[tuple[str, pd.DataFrame]],
) -> list[tuple[str, pd.DataFrame, nkmod.AngleVerdict]]:
    """(file, rows, angle verdict) of each psi/Delta file whose angles disagree."""
    flagged = []
    for src, g in ellips:
        try:
            comb = nkmod.combined_table(nkmod.ordinary_psi_delta(g), on_ill_conditioned="ignore")
        except ValueError:
            continue
        verdict = nkmod.angle_verdict(comb)
        if verdict.kind in ("stack", "partly"):
            flagged.append((src, g, verdict))
    return flagged


def _table_files(model: films.FilmModel) -> list[Path]:
    """The files a film model reads as tables (its substrate's, its layers')."""
    media = [model.stack.substrate, *(lay.material for lay in model.stack.layers)]
    out = []
    for m in media:
        f = m.to_dict().get("file") if hasattr(m, "to_dict") else None
        if f:
            out.append(Path(str(f)))
    return out


def _is_table(ctx: Context, src: str, tables: list[Path]) -> bool:
    """Whether the input file named ``src`` is one of the model's table files.

    By the resolved path where the report's groups know the input's path, else by name.
    """
    inputs = [p for g in ctx.samples for p in g.paths if Path(p).name == src]
    for t in tables:
        if t.name != src:
            continue
        if not inputs or any(os.path.samefile(p, t) for p in inputs if p.exists() and t.exists()):
            return True
    return False


def _applies_to(
    ctx: Context,
    model: films.FilmModel,
    flagged: list[tuple[str, pd.DataFrame, nkmod.AngleVerdict]],
    film_files: list[str] | None,
) -> list[tuple[str, pd.DataFrame, nkmod.AngleVerdict]]:
    """The flagged files the film model is of, saying why any other is left out.

    Never a file the model reads as a table (its substrate's file is a bare substrate, not
    a coated sample). Of the rest: the files given in ``film_files`` where given; else the
    files of the samples whose groups hold more than one file (the sample names the files
    state or ``--same-sample``) where there are such; else every flagged file.
    """
    tables = _table_files(model)
    out, left = [], []
    for src, g, v in flagged:
        if _is_table(ctx, src, tables):
            left.append(f"{src} (the model reads it as a table: a bare substrate, not a film)")
        else:
            out.append((src, g, v))
    if film_files is not None:
        keep = {Path(f).name for f in film_files}
        left += [f"{s} (not among --film-files)" for s, _g, _v in out if s not in keep]
        out = [x for x in out if x[0] in keep]
    else:
        grouped = {Path(p).name for g in sample_groups_of(ctx) if g.paired for p in g.paths}
        if any(s in grouped for s, _g, _v in out):
            left += [
                f"{s} (of no sample group holding other files; name it with --film-files)"
                for s, _g, _v in out
                if s not in grouped
            ]
            out = [x for x in out if x[0] in grouped]
    if left:
        ctx.b.note(
            "film model not applied",
            "the film model is of its sample's files only; not fitted to: " + "; ".join(left),
        )
    return out


def _model_text(ctx: Context, model: films.FilmModel, how: str) -> None:
    """The film model in words: its layers, what is fitted, the fit window."""
    free = ", ".join(f"{k} in [{lo:g}, {hi:g}]" for k, (lo, hi) in model.free.items())
    ctx.b.text(
        f"Film model ({how or model.source}): ambient {_describe(model.stack.ambient)} / "
        + " / ".join(f"{lay.name} ({_describe(lay.material)})" for lay in model.stack.layers)
        + f" / substrate ({_describe(model.stack.substrate)}). Fitted: {free or 'nothing'}"
        + (
            f"; fit window {model.wavelength_range_nm[0]:g}-{model.wavelength_range_nm[1]:g} nm"
            if model.wavelength_range_nm
            else ""
        )
        + ". Each file's psi and Delta at all its angles are fitted together (global then "
        "local optimiser, weighted by the file's sigmas); intervals are 95 %. The measured "
        "reflectance of the same sample is not fitted: it is predicted from the stack."
    )


def _fit_shown(
    ctx: Context, tag: str, src: str, verdict: nkmod.AngleVerdict, fit: FilmFit
) -> None:
    """One fit: its summary in words, the parameter table, psi/Delta and n, k figures."""
    b = ctx.b
    s = fit.summary()
    b.text(
        f"Verdict of section nk: {verdict.text}. Fit of {s['ndata']} values "
        f"({s['wavelength_range_nm'][0]:.4g}-{s['wavelength_range_nm'][1]:.4g} nm), "
        f"{s['nvarys']} parameters: chi2/nu {s['redchi']:.4g}, Woollam MSE "
        f"{s['mse']:.4g}; {s['message']}."
        + (" Notes: " + "; ".join(s["notes"]) + "." if s["notes"] else "")
    )
    if s.get("verdict"):
        wrong = s["mse"] > MSE_WRONG_MODEL
        b.note("parameters not meaningful" if wrong else "model incomplete", s["verdict"])
    b.table(
        f"film_{tag}_params",
        f"{src}: fitted parameters",
        [
            ("parameter", "parameter", ""),
            ("value", "value", ".6g"),
            ("stderr", "\u03c3", ".2g"),
            ("ci_lo", "95 % low", ".6g"),
            ("ci_hi", "95 % high", ".6g"),
            ("interval", "interval", ""),
            ("ci_lo_scaled", "95 % low, scaled", ".6g"),
            ("ci_hi_scaled", "95 % high, scaled", ".6g"),
            ("units", "units", ""),
            ("min", "box min", ".4g"),
            ("max", "box max", ".4g"),
            ("flags", "flags", ""),
        ],
        _param_rows(s),
        caption=f"95 % intervals from the files' sigmas: {intervals_text(s)}; 'scaled': times "
        "sqrt(chi2/nu), given where chi-square rejects the film model (p < 0.01), which "
        "then misses the data by more than the sigmas; units [1] where none is given.",
    )
    b.figure(
        f"film_{tag}_psi_delta",
        f"{src}: psi and Delta against wavelength per angle, with the fit",
        "Measured psi and Delta [deg] (coloured points, one colour per angle of "
        f"incidence, at most {_MAX_ANGLES} angles spread over the range) and the fitted "
        "stack's (black lines) against wavelength [nm]; right: measured - fit, band = the "
        "file's 1-sigma.",
        _psi_delta_figure(fit),
    )
    b.figure(
        f"film_{tag}_nk",
        f"{src}: n and k of each layer of the fitted stack",
        "Modelled: n [1] and k [1] of each layer and of the substrate against wavelength "
        "[nm], band = 1-sigma propagated from the fit's covariance, times sqrt(chi2/nu) "
        "where chi-square rejects the film model (zero for fixed parameters and tables).",
        _nk_figure(fit),
    )


def _fit_file(
    ctx: Context,
    i: int,
    src: str,
    g: pd.DataFrame,
    verdict: nkmod.AngleVerdict,
    model: films.FilmModel,
    ellips: list[tuple[str, pd.DataFrame]],
    refl: list[tuple[str, pd.DataFrame]],
    cmp_rows: list[dict[str, Any]],
) -> None:
    """Fit ``model`` to one file, show it, and compare the stack with measured reflectance.

    Reflectance of the same file or of the same sample
    (:func:`labbrdf.report.pairing.same_sample`: a sample name both files state, or the
    user's mapping); the comparison rows are added to ``cmp_rows``. A reflectance file of
    no sample of a fitted file gets a note saying how to pair it (one psi/Delta file in a
    report does not make its reflectance files the same sample). A model that cannot be
    fitted is a failed check.
    """
    b = ctx.b
    tag = f"{i}_{slug(src)}"
    b.heading(f"{src}: film fit", anchor=f"film_{tag}")
    try:
        fit = fit_film(model, nkmod.ordinary_psi_delta(g), method=ctx.method, seed=ctx.seed)
    except ValueError as exc:
        b.note("no film fit", f"{src}: {exc}")
        b.check(
            f"film.fit.{tag}",
            f"{src}: the film model can be fitted",
            False,
            against="the film model and the file's psi/Delta",
            justification=str(exc),
        )
        return
    _fit_shown(ctx, tag, src, verdict, fit)
    ctx.film_fits[src] = fit
    own = dict(ellips)
    apart: list[str] = []
    for j, (rs, rg) in enumerate(refl):
        if not same_sample(ctx, src, rs):
            if len(ellips) == 1 and rs not in own:
                apart.append(rs)
            continue
        row = _reflectance(ctx, f"{tag}_r{j}_{slug(rs)}", src, fit, rs, rg)
        if row is not None:
            cmp_rows.append(row)
    if apart:
        b.note(
            "not compared",
            f"reflectance of {', '.join(apart)} with the stack fitted to {src}: no sample "
            f"name both state and no mapping pairs them ({src} being the report's only "
            f"psi/Delta file does not make it the same sample); {how_to_pair(ctx, [src, *apart])}",
        )


def film_section(
    ctx: Context,
    model: films.FilmModel | None,
    *,
    how: str = "",
    film_files: list[str] | None = None,
) -> None:
    """Fit ``model`` to the angle-dependent psi/Delta files of its sample; redo their R check.

    Parameters
    ----------
    ctx : Context
    model : FilmModel or None
        The film model; None: the section is not available (says how to give one).
    how : str
        How the model was given (shown with it), e.g. the model file's path.
    film_files : list of str, optional
        The files the model is of (file names or paths); default: see :func:`_applies_to`
        (never a file the model reads as its substrate's table).
    """
    b = ctx.b
    frames = file_frames(ctx)
    ellips = [(s, g) for s, g, _m in frames if len(nkmod.ordinary_psi_delta(g))]
    if not ellips:
        raise Unavailable("no psi/Delta rows ingested: no film to fit")
    flagged = _flagged(ellips)
    if not flagged:
        raise Unavailable(
            "no psi/Delta file whose angles of incidence disagree: no stack to fit "
            "(section nk gives the optical constants)"
        )
    if model is None:
        names = ", ".join(s for s, _g, _v in flagged)
        raise Unavailable(
            f"{names}: pseudo-constants of a stack, and no film model given: give one with "
            "--film-model FILE.toml, or --film-default for one transparent Cauchy layer on "
            "crystalline silicon (thickness free)"
        )
    flagged = _applies_to(ctx, model, flagged, film_files)
    if not flagged:
        raise Unavailable(
            "the film model applies to no psi/Delta file of the report: its substrate's file "
            "is a bare substrate, and --film-files names the files of the coated sample"
        )
    _model_text(ctx, model, how)
    refl = [(s, g) for s, g, _m in frames if (g["quantity"] == "reflectance").any()]
    cmp_rows: list[dict[str, Any]] = []
    for i, (src, g, verdict) in enumerate(flagged):
        _fit_file(ctx, i, src, g, verdict, model, ellips, refl, cmp_rows)
    if cmp_rows:
        b.table(
            "film_reflectance_comparison",
            "Measured reflectance against the fitted stacks",
            [
                ("ellipsometer_file", "stack fitted to", ""),
                ("refl_file", "reflectance from", ""),
                ("quantity", "compared", ""),
                ("points", "points", "d"),
                ("mean_diff", "mean diff [1]", ".3g"),
                ("rms_diff", "rms diff [1]", ".3g"),
                ("ratio", "median measured/predicted", ".4g"),
                ("chi2_dof", "\u03c7\u00b2/dof", ".3g"),
                ("p_value", "p", ".2g"),
            ],
            cmp_rows,
            caption="diff = measured - predicted; sigma of the difference: the measurement's "
            "and the prediction's 1-sigma in quadrature.",
        )


def film_model_of(
    model: str | os.PathLike[str] | films.FilmModel | None,
) -> tuple[films.FilmModel | None, str]:
    """The film model of a report, and how it was given.

    ``None``: no model; a :class:`~labbrdf.films.FilmModel` (e.g.
    :func:`default_film_model`): itself; a path: a TOML model file
    (:func:`labbrdf.films.load_model`; its errors name the file and the line).
    """
    if model is None:
        return None, ""
    if isinstance(model, films.FilmModel):
        return model, model.source
    return films.load_model(model, nkmod.tabulated_from_file), f"model file {model}"
