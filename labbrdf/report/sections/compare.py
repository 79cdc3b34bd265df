"""Section ``compare``: the 3- and 5-parameter models fitted to the same scans.

As Fig. 4 of Zou, Bai, Wu (2013), doi:10.3788/AOS201333.0612008.
"""

from __future__ import annotations

import numpy as np

from .. import figures
from ..builder import Unavailable, num, wl_label
from ..context import Context, curve_grid, model_curve, rmse_abs, rmse_paper, run_fits

__all__ = ["compare_section"]


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
    ctx.compare_fits = fits
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
                "redchi3": num(a.summary.get("redchi")),
                "redchi5": num(c.summary.get("redchi")),
                "flags5": "; ".join(
                    f"{p}: {', '.join(q['flags'])}" for p, q in c.params.items() if q["flags"]
                ),
            }
        )
        tr = a.data["theta_r_deg"].to_numpy(float)
        grid = curve_grid(tr)
        curves = {}
        if a.values:
            curves["smooth3 (3 parameters)"] = model_curve(a, theta_i, grid)
        if c.values:
            curves[f"five_param (G = {c.options.get('shadowing', 'ts')})"] = model_curve(
                c, theta_i, grid
            )
        panels.append(
            {
                "label": f"{a.sample}, {wl_label(a.wavelength_nm)}",
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
