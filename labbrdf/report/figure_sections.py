"""Figure sections: measured scans with model curves (Figs. 2-3), parameter spectra, and the
3- vs 5-parameter comparison (Fig. 4) of Zou, Bai, Wu 2013."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from . import figures
from ._common import Unavailable
from .sections import (
    Context,
    FitRecord,
    _num,
    _published_params,
    _slug,
    _wl,
    rmse_abs,
    rmse_paper,
    run_fits,
)

__all__ = ["compare_section", "scans_section", "spectra_section"]


# --------------------------------------------------------------------------- figures


def _curve_grid(theta_r: np.ndarray) -> np.ndarray:
    lo, hi = float(np.min(theta_r)), float(np.max(theta_r))
    pad = 0.05 * max(hi - lo, 0.5)
    return np.linspace(max(0.0, lo - pad), min(89.9, hi + pad), 121)


def _model_curve(
    rec: FitRecord, theta_i: float, theta_r_deg: np.ndarray, phi_r_deg: float = 180.0
) -> np.ndarray:
    from labbrdf import models

    m = models.get(rec.model, **rec.options)
    return m.evaluate(
        math.radians(theta_i),
        np.radians(theta_r_deg),
        math.radians(phi_r_deg),
        wavelength=rec.wavelength_nm,
        params=rec.values,
    )


def scans_section(ctx: Context, model_names: Sequence[str]) -> None:
    """Figs. 2-3 style: measured points and fitted curves per theta_i and wavelength."""
    b = ctx.b
    recs = {n: ctx.fits.get(n, []) for n in model_names}
    base = next((v for v in recs.values() if v), None)
    if not base:
        raise Unavailable("no fits to plot")
    samples = sorted({r.sample for r in base})
    for s in samples:
        panels = []
        for r in [x for x in base if x.sample == s]:
            series = []
            others = {
                n: next(
                    (x for x in recs[n] if x.sample == s and x.wavelength_nm == r.wavelength_nm),
                    None,
                )
                for n in recs
            }
            for ti, g in r.data.groupby("theta_i_deg", sort=True):
                g = g[np.isclose(g["phi_r_deg"].fillna(180.0), 180.0)]
                if not len(g):
                    continue
                tr = g["theta_r_deg"].to_numpy(float)
                grid = _curve_grid(tr)
                curves, resid = {}, {}
                for n, o in others.items():
                    if o is None or not o.values:
                        continue
                    curves[n] = _model_curve(o, float(ti), grid)
                    fit_at = _model_curve(o, float(ti), tr)
                    with np.errstate(divide="ignore", invalid="ignore"):
                        resid[n] = 100.0 * (g["value"].to_numpy() - fit_at) / fit_at
                sig = g["sigma"].to_numpy(float)
                series.append(
                    {
                        "theta_i": float(ti),
                        "theta_r": tr,
                        "value": g["value"].to_numpy(float),
                        "sigma": sig if np.isfinite(sig).all() else None,
                        "curve_theta_r": grid,
                        "curves": curves,
                        "residual": resid,
                    }
                )
            panels.append({"label": f"{s}, {_wl(r.wavelength_nm)}", "series": series})
        uri = figures.scan_figure(panels, title=f"{s}: measured scans and fitted models")
        b.figure(
            f"scans_{_slug(s)}",
            f"Specular scans of sample {s} and fitted models (Figs. 2-3 style)",
            "Measured: BRDF [sr^-1] against detector angle theta_r in the specular half-plane "
            "(phi_r = 180 deg), one marker per incidence angle, error bars = 1 sigma from the "
            f"file. Modelled: {', '.join(n for n in model_names if recs.get(n))} fitted per "
            "wavelength (solid, in the colour of the incidence angle: first model; dashed "
            "black: second). Bottom: residuals (measured - model)/model [%] (filled markers: "
            "first model).",
            uri,
        )


def spectra_section(ctx: Context, model_name: str = "smooth3") -> None:
    """Fitted parameters against wavelength with 95% intervals (and published values)."""
    recs = ctx.fits.get(model_name) or []
    if not recs:
        raise Unavailable(f"no {model_name} fits")
    if len({r.wavelength_nm for r in recs}) < 2:
        raise Unavailable("fewer than two wavelengths: no spectrum to draw")
    pnames = [p for p in recs[0].params if recs[0].params[p].get("vary", True)]
    units = {p: (recs[0].params[p].get("units") or "1") for p in pnames}
    for s in sorted({r.sample for r in recs}):
        rr = sorted((r for r in recs if r.sample == s), key=lambda r: r.wavelength_nm)
        wl = [r.wavelength_nm for r in rr]
        series = [
            {
                "label": f"{s}: fit (95% interval)",
                "wavelength": wl,
                "values": {p: [r.params[p]["value"] for r in rr] for p in pnames},
                "lo": {
                    p: [r.params[p]["lo"] if r.params[p]["lo"] is not None else np.nan for r in rr]
                    for p in pnames
                },
                "hi": {
                    p: [r.params[p]["hi"] if r.params[p]["hi"] is not None else np.nan for r in rr]
                    for p in pnames
                },
            }
        ]
        pubs = [_published_params(ctx, s, w) for w in wl]
        if model_name == "smooth3" and any(pubs):
            series.append(
                {
                    "label": "published (Zou 2013)",
                    "style": "published",
                    "wavelength": wl,
                    "values": {
                        p: [pp.get(p, np.nan) if pp.get(p) is not None else np.nan for pp in pubs]
                        for p in pnames
                    },
                }
            )
        ctx.b.figure(
            f"spectra_{model_name}_{_slug(s)}",
            f"{model_name} parameters of {s} against wavelength",
            "Modelled: each marker is the parameter fitted at one wavelength, with its 95% "
            "interval; stars: the published values where they exist. Measured: the scans "
            "the fits used (previous figures).",
            figures.spectra_figure(pnames, units, series, title=f"{s}: {model_name}"),
        )


# --------------------------------------------------------------------------- compare


def compare_section(ctx: Context, theta_i: float = 45.0, sample: str | None = None) -> None:
    """3- vs 5-parameter models fitted to the same in-plane scans at one incidence (Fig. 4)."""
    scans = ctx.scans()
    sel = scans[np.isclose(scans["theta_i_deg"], theta_i)]
    if sample is not None:
        sel = sel[sel["sample"].str.lower() == sample.lower()]
    if not len(sel):
        raise Unavailable(
            f"no scans at theta_i = {theta_i:g} deg" + (f" for sample {sample}" if sample else "")
        )
    fits = run_fits(
        ctx, [("smooth3", {}), ("five_param", {})], scans=sel, group=f"theta_i={theta_i:g}"
    )
    ctx.extra["compare_fits"] = fits
    s3, f5 = fits["smooth3"], fits["five_param"]
    rows, panels = [], []
    for a, c in zip(s3, f5, strict=True):
        rows.append(
            {
                "sample": a.sample,
                "wavelength_nm": a.wavelength_nm,
                "n": len(a.data),
                "rmse3": rmse_abs(a.summary),
                "rmse5": rmse_abs(c.summary),
                "rmsep3": rmse_paper(a.summary),
                "rmsep5": rmse_paper(c.summary),
                "redchi3": _num(a.summary.get("redchi")),
                "redchi5": _num(c.summary.get("redchi")),
                "flags5": "; ".join(
                    f"{p}: {', '.join(q['flags'])}" for p, q in c.params.items() if q["flags"]
                ),
            }
        )
        tr = a.data["theta_r_deg"].to_numpy(float)
        grid = _curve_grid(tr)
        curves = {}
        if a.values:
            curves["smooth3 (3 parameters)"] = _model_curve(a, theta_i, grid)
        if c.values:
            curves[f"five_param (G = {c.options.get('shadowing', 'ts')})"] = _model_curve(
                c, theta_i, grid
            )
        panels.append(
            {
                "label": f"{a.sample}, {_wl(a.wavelength_nm)}",
                "theta_r": tr,
                "value": a.data["value"].to_numpy(float),
                "curve_theta_r": grid,
                "curves": curves,
            }
        )
    ctx.b.table(
        "compare_3_5",
        f"3- vs 5-parameter fits of the same scans at \u03b8i = {theta_i:g} deg",
        [
            ("sample", "sample", ""),
            ("wavelength_nm", "\u03bb [nm]", "g"),
            ("n", "points", "d"),
            ("rmse3", "RMSE smooth3 [sr\u207b\u00b9]", ".3g"),
            ("rmse5", "RMSE five_param [sr\u207b\u00b9]", ".3g"),
            ("rmsep3", "RMSE smooth3 [%]", ".4g"),
            ("rmsep5", "RMSE five_param [%]", ".4g"),
            ("redchi3", "\u03c7\u00b2/\u03bd smooth3", ".4g"),
            ("redchi5", "\u03c7\u00b2/\u03bd five_param", ".4g"),
            ("flags5", "five_param flags", ""),
        ],
        rows,
        caption="Measured: the in-plane scans at this incidence angle only (as the paper did "
        "for Fig. 4). Modelled: smooth3 and five_param fitted to the same points. The "
        "paper normalised the BRDF before fitting the five-parameter model; here both "
        "models are fitted to the BRDF in sr^-1, so their RMSEs compare directly.",
    )
    ctx.b.figure(
        "compare_3_5",
        f"smooth3 vs five_param at \u03b8i = {theta_i:g} deg (Fig. 4 style)",
        "Measured: stars, BRDF [sr^-1] against theta_r [deg] in the specular half-plane. "
        "Modelled: solid = smooth3 fit, dashed = five_param fit (shadowing as labelled), "
        "each fitted to these points alone.",
        figures.compare_models_figure(panels),
    )
