"""Property sections: energy conservation and reciprocity of every fitted model, and the
sample colour from spectrophotometer reflectance (CIE 1931 2 deg observer, D65, sRGB)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from . import figures
from ._common import Unavailable
from .sections import (
    Context,
    _slug,
    _wl,
)

__all__ = ["colour_section", "physics_section"]


# --------------------------------------------------------------------------- physics


def physics_section(ctx: Context, angles_deg: Sequence[float] | None = None) -> None:
    """Energy conservation and reciprocity of every fitted model (findings + checks)."""
    from labbrdf import integrate, models

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
                    f"{name} {r.sample} {_wl(r.wavelength_nm)}: is_reciprocal="
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
        "no k1 > 0 conserves energy at all angles (notes/models.md 1.3-1.4); the five-"
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


# --------------------------------------------------------------------------- colour

CMFS_NAME = "CIE 1931 2 Degree Standard Observer"


def colour_section(ctx: Context) -> None:
    """Sample colour from the spectrophotometer reflectance (CIE 1931 2 deg, D65, sRGB)."""
    import colour

    d = ctx.data
    if d is None:
        raise Unavailable("no data ingested")
    spec = d[d["quantity"].isin(["hemispherical_reflectance", "reflectance"])]
    spec = spec[spec["theta_i_deg"].isna() | (spec["theta_i_deg"] < 10)] if len(spec) else spec
    if not len(spec):
        raise Unavailable(
            "no spectrophotometer reflectance (hemispherical_reflectance or "
            "near-normal reflectance) ingested"
        )
    b = ctx.b
    shape = colour.SpectralShape(360, 780, 1)
    grid = np.asarray(shape.wavelengths, float)
    # observer and illuminant on the computation grid up front, so colour-science has
    # nothing to re-align (and no warnings to print)
    cmfs = colour.MSDS_CMFS[CMFS_NAME].copy().align(shape)
    ill = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    white = colour.sd_to_XYZ(colour.SpectralDistribution(np.ones_like(grid), grid), cmfs, ill)
    rows = []
    for (sample, src), g in spec.groupby(["sample", "source"], sort=True):
        g = g.groupby("wavelength_nm", as_index=False)["value"].mean()
        wl = g["wavelength_nm"].to_numpy(float)
        v = g["value"].to_numpy(float)
        # linear interpolation between the measured points, end values held outside them
        # (np.interp), evaluated on the uniform 1 nm grid
        used = colour.SpectralDistribution(np.interp(grid, wl, v), grid, name=str(sample))
        xyz = colour.sd_to_XYZ(used, cmfs, ill)
        rgb = np.asarray(colour.XYZ_to_sRGB(xyz / 100.0), float)
        rgb_c = np.clip(rgb, 0.0, 1.0)
        hexc = "#" + "".join(f"{int(round(255 * x)):02x}" for x in rgb_c)
        inside = (wl >= 360) & (wl <= 780)
        note = (
            f"{inside.sum()} measured point(s) in 360-780 nm ({wl.min():g}-{wl.max():g} nm "
            "measured); linear interpolation between them, constant extrapolation (end "
            "values held) outside"
        )
        few = inside.sum() < 10 or wl.min() > 400 or wl.max() < 700
        rows.append(
            {
                "sample": str(sample),
                "source": str(src),
                "points": int(len(wl)),
                "wl_min": float(wl.min()),
                "wl_max": float(wl.max()),
                "X": float(xyz[0]),
                "Y": float(xyz[1]),
                "Z": float(xyz[2]),
                "R": float(rgb[0]),
                "G": float(rgb[1]),
                "B": float(rgb[2]),
                "hex": hexc,
                "in_gamut": bool(np.all((rgb >= 0) & (rgb <= 1))),
                "method": note,
                "reliable": not few,
            }
        )
        b.swatch(f"colour_{_slug(str(sample))}_{_slug(str(src))}", hexc)
        b.text(
            f"{sample} ({src}): sRGB {hexc}. {note}."
            + (
                " Too few points or too narrow a range for a trustworthy colour: the "
                "swatch is indicative only."
                if few
                else ""
            )
        )
        b.figure(
            f"colour_spectrum_{_slug(str(sample))}_{_slug(str(src))}",
            f"Reflectance spectrum of {sample} used for its colour ({src})",
            "Measured: the spectrophotometer reflectance points [%]. Modelled: none; the line "
            "is the spectrum handed to colour-science after linear interpolation and constant "
            "extrapolation to 360-780 nm.",
            figures.spectrum_figure(
                wl, v, np.asarray(used.wavelengths), np.asarray(used.values), title=f"{sample}"
            ),
        )
    b.table(
        "colour",
        "Sample colour (CIE 1931 2\u00b0 observer, D65, sRGB)",
        [
            ("sample", "sample", ""),
            ("source", "file", ""),
            ("points", "points", "d"),
            ("wl_min", "\u03bb min [nm]", "g"),
            ("wl_max", "\u03bb max [nm]", "g"),
            ("X", "X", ".4g"),
            ("Y", "Y", ".4g"),
            ("Z", "Z", ".4g"),
            ("R", "sR", ".3f"),
            ("G", "sG", ".3f"),
            ("B", "sB", ".3f"),
            ("hex", "sRGB hex", ""),
            ("in_gamut", "in sRGB gamut", ""),
            ("reliable", "enough spectral data", ""),
            ("method", "interpolation / extrapolation", ""),
        ],
        rows,
        caption="colour.sd_to_XYZ with the CIE 1931 2 degree observer and illuminant D65 "
        "(Y = 100 for a perfect reflector), colour.XYZ_to_sRGB of XYZ/100; sR, sG, sB are "
        "the encoded sRGB values before clipping to [0, 1] for the swatch.",
    )
    b.check(
        "colour.white",
        "a perfect reflector (R = 1) maps to Y = 100 in the colour pipeline",
        abs(float(white[1]) - 100.0) < 1e-6,
        against="CIE colorimetry normalisation (k = 100 / sum(S ybar))",
        value=float(white[1]),
        tolerance=1e-6,
        justification="float64 round-off of the normalisation sum",
    )
