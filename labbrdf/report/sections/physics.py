"""Section ``physics``: energy conservation and reciprocity of every fitted model."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ... import integrate, models
from ..builder import Unavailable, wl_label
from ..context import Context

__all__ = ["physics_section"]


def physics_section(ctx: Context, angles_deg: Sequence[float] | None = None) -> None:
    """Energy conservation and reciprocity of every fitted model (findings + checks)."""
    b = ctx.b
    if not any(ctx.fits.values()):
        raise Unavailable("no fits")
    rows = []
    consistent, mismatches = 0, []
    # scan step of the energy-limit search (then refined by Brent's method to 1e-6 deg);
    # a coarse scan only risks missing a crossing that re-crosses within one step
    step = 15.0 if ctx.quick else 5.0
    for name, recs in ctx.fits.items():
        for r in recs:
            if not r.values:
                continue
            m = models.get(name, **r.options)
            ti = sorted({float(x) for x in r.data["theta_i_deg"].dropna()})
            if angles_deg is not None:
                ti = sorted(set(ti) | {float(a) for a in angles_deg})
            rho = np.atleast_1d(integrate.hemispherical_reflectance(m, r.values, ti))
            lim = integrate.energy_limit_angle(m, r.values, step_deg=step)
            rd = integrate.reciprocity_defect(m, r.values)
            recip = bool(m.is_reciprocal(r.values))
            agrees = (rd.max_rel < 1e-12) == recip
            consistent += agrees
            if not agrees:
                mismatches.append(
                    f"{name} {r.sample} {wl_label(r.wavelength_nm)}: is_reciprocal="
                    f"{recip}, defect {rd.max_rel:.3g}"
                )
            rows.append(
                {
                    "model": name,
                    "sample": r.sample,
                    "wavelength_nm": r.wavelength_nm,
                    "theta_i": ", ".join(f"{t:g}" for t in ti),
                    "rho": [float(x) for x in rho],
                    "rho_max": float(np.max(rho)),
                    "energy_ok": bool(np.all(rho <= 1.0)),
                    "limit_deg": lim,
                    "recip": recip,
                    "defect_abs": rd.max_abs,
                    "defect_rel": rd.max_rel,
                    "defect_at": f"({rd.theta_i_deg:g}, {rd.theta_r_deg:g}, {rd.phi_r_deg:g})",
                }
            )
    b.table(
        "physics",
        "Energy conservation and reciprocity of every fitted model",
        [
            ("model", "model", ""),
            ("sample", "sample", ""),
            ("wavelength_nm", "\u03bb [nm]", "g"),
            ("theta_i", "\u03b8i [deg]", ""),
            ("rho", "\u03c1(\u03b8i) [%]", "%"),
            ("energy_ok", "\u03c1 \u2264 1 at these \u03b8i", ""),
            ("limit_deg", "\u03c1 \u2264 1 up to \u03b8i [deg]", ".4g"),
            ("recip", "reciprocal", ""),
            ("defect_abs", "max |f(i,r) - f(r,i)| [sr\u207b\u00b9]", ".3g"),
            ("defect_rel", "relative defect", ".3g"),
            ("defect_at", "at (\u03b8i, \u03b8r, \u03c6r) [deg]", ""),
        ],
        rows,
        caption="Modelled only: directional-hemispherical reflectance \u03c1 of each fitted "
        "model (closed form for smooth3, quadrature otherwise) at the measured incidence "
        "angles, the largest incidence angle up to which \u03c1 \u2264 1 (first crossing on a "
        f"{step:g} deg scan, refined by Brent's method to 1e-6 deg), and the reciprocity "
        "defect on a 5 deg x 15 deg grid up to 85 deg. These are properties of the fitted "
        "models (findings), not software checks: smooth3 is reciprocal only for k2 = 0 and "
        "no k1 > 0 conserves energy at all angles (docs/models.md 1.3-1.4); the five-"
        "parameter diffuse term k_d/cos \u03b8i is not reciprocal for k_d > 0.",
    )
    b.check(
        "physics.reciprocity_consistent",
        "numerical reciprocity defect agrees with each model's analytic reciprocity "
        "condition (smooth3: k2 = 0; five_param: k_d = 0)",
        not mismatches,
        against="Model.is_reciprocal (analytic) vs integrate.reciprocity_defect (numerical)",
        value=consistent,
        tolerance=len(rows),
        justification="reciprocal models must give a relative defect < 1e-12 (float64 "
        "round-off), non-reciprocal ones a larger defect",
        reason="; ".join(mismatches)[:1000],
    )
