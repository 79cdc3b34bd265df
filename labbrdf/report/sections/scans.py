"""Section ``scans``: measured scans with the fitted model curves (Figs. 2-3 of Zou 2013)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import figures
from ..builder import Unavailable, slug, wl_label
from ..context import Context, curve_grid, model_curve

__all__ = ["scans_section"]


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
                grid = curve_grid(tr)
                curves, resid = {}, {}
                for n, o in others.items():
                    if o is None or not o.values:
                        continue
                    curves[n] = model_curve(o, float(ti), grid)
                    fit_at = model_curve(o, float(ti), tr)
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
            panels.append({"label": f"{s}, {wl_label(r.wavelength_nm)}", "series": series})
        uri = figures.scan_figure(panels, title=f"{s}: measured scans and fitted models")
        b.figure(
            f"scans_{slug(s)}",
            f"Specular scans of sample {s} and fitted models (Figs. 2-3 style)",
            "Measured: BRDF [sr^-1] against detector angle theta_r in the specular half-plane "
            "(phi_r = 180 deg), one marker per incidence angle, error bars = 1 sigma from the "
            f"file. Modelled: {', '.join(n for n in model_names if recs.get(n))} fitted per "
            "wavelength (solid, in the colour of the incidence angle: first model; dashed "
            "black: second). Bottom: residuals (measured - model)/model [%] (filled markers: "
            "first model).",
            uri,
        )
