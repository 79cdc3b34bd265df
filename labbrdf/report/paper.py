"""Sections that compare with the 2013 paper: published tables, Table 3, errata checks.

Published numbers come from ``fixtures/published/zou2013_table{1,2,3}.csv`` (with their
citation headers); the notes they rely on are ``notes/models.md`` sections 1.2-1.4 (Table 3
reproduced at 46 deg, not 45; reciprocity only for k2 = 0; the true energy condition).

References
----------
.. [Zou2013] Zou X., Bai L., Wu Z., "Mirror reflectance spectrum modeling of smooth samples",
   Acta Optica Sinica 33(6), 0612008 (2013). doi:10.3788/AOS201333.0612008
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from . import figures
from ._common import Unavailable
from .sections import Context, FitRecord, _num

__all__ = ["errata_section", "hemispherical_section", "load_published"]

#: Energy-limit angles of the paper's own fits [deg], notes/models.md 1.4 (printed to 0.1)
ENERGY_LIMIT_DEG = {
    ("OSR", 360.0): 70.4,
    ("OSR", 500.0): 63.1,
    ("OSR", 550.0): 61.9,
    ("OSR", 860.0): 61.5,
    ("mirror", 360.0): 77.9,
    ("mirror", 500.0): 76.3,
    ("mirror", 550.0): 76.5,
    ("mirror", 860.0): 80.6,
}
#: entries the notes print one digit off: the root is 76.2498 deg, which rounds to 76.2
NOTES_MISROUNDED = {("mirror", 500.0)}
#: R(30, 50) and R(50, 30) [sr^-1] at 550 nm with the paper's fits, notes/models.md 1.3
RECIPROCITY_550 = {"OSR": (0.1209, 0.1059), "mirror": (0.0173, 0.0971)}


def _rename(df: pd.DataFrame) -> pd.DataFrame:
    ren = {}
    for c in df.columns:
        lc = str(c).strip().lower()
        for key in ("k1", "k2", "k3", "rmse", "sample"):
            if lc.startswith(key):
                ren[c] = key
        if lc.startswith("wavelength") or lc in ("lambda_nm", "wl_nm"):
            ren[c] = "wavelength_nm"
        if lc.startswith("integration"):
            ren[c] = "integration_pct"
        if lc.startswith("measured") or lc.startswith("hemispherical"):
            ren[c] = "measured_pct"
        if lc.startswith("error") or lc.startswith("relative"):
            ren[c] = "error_pct"
    return df.rename(columns=ren)


def load_published(ctx: Context, folder: Path) -> list[str]:
    """Read the published Tables 1-3 into ``ctx.published``; returns the files read."""
    read = []
    frames = []
    for n, default_sample in ((1, "OSR"), (2, "mirror")):
        p = folder / f"zou2013_table{n}.csv"
        if p.is_file():
            t = _rename(pd.read_csv(p, comment="#", skipinitialspace=True))
            if "sample" not in t.columns:
                t["sample"] = default_sample
            t["sample"] = t["sample"].astype(str)
            frames.append(t)
            read.append(p.name)
    if frames:
        ctx.published["params"] = pd.concat(frames, ignore_index=True)
    p = folder / "zou2013_table3.csv"
    if p.is_file():
        ctx.published["table3"] = _rename(pd.read_csv(p, comment="#", skipinitialspace=True))
        read.append(p.name)
    return read


def _paper_values(ctx: Context, sample: str, wl: float) -> dict[str, float] | None:
    t = ctx.published.get("params")
    if t is None:
        return None
    m = t[(t["sample"].str.lower() == sample.lower()) & np.isclose(t["wavelength_nm"], wl)]
    if not len(m):
        return None
    r = m.iloc[0]
    return {"k1": float(r["k1"]), "k2": float(r["k2"]), "k3": float(r["k3"])}


def _rho_sigma(rec: FitRecord, theta_deg: float) -> float | None:
    """1-sigma of rho(theta) from the fit covariance (finite-difference gradient)."""
    from labbrdf import integrate

    names = [k for k in ("k1", "k2", "k3") if rec.params.get(k, {}).get("stderr")]
    if not names:
        return None
    v = dict(rec.values)

    def rho(vals: dict[str, float]) -> float:
        return float(
            integrate.smooth3_hemispherical(theta_deg, vals["k1"], vals["k2"], vals["k3"])
        )

    grad = []
    for k in names:
        h = 1e-6 * max(abs(v[k]), 1e-3)
        up, dn = dict(v), dict(v)
        up[k] += h
        dn[k] -= h
        grad.append((rho(up) - rho(dn)) / (2 * h))
    se = np.array([rec.params[k]["stderr"] for k in names])
    corr = np.eye(len(names))
    summ = rec.summary.get("params", {})
    for i, a in enumerate(names):
        for j, c in enumerate(names):
            if i != j:
                r = (summ.get(a, {}).get("correl") or {}).get(c)
                corr[i, j] = float(r) if r is not None else 0.0
    cov = corr * np.outer(se, se)
    g = np.asarray(grad)
    var = float(g @ cov @ g)
    return math.sqrt(var) if var >= 0 else None


def hemispherical_section(ctx: Context, sample: str = "OSR") -> None:
    """Table 3 style: hemispherical integral of the fits against the spectrophotometer."""
    from labbrdf import integrate, models

    b = ctx.b
    recs = [r for r in ctx.fits.get("smooth3", []) if r.sample.lower() == sample.lower()]
    if not recs:
        raise Unavailable(f"no smooth3 fits of sample {sample}")
    d = ctx.data
    meas = d[
        (d["quantity"] == "hemispherical_reflectance")
        & (d["sample"].str.lower() == sample.lower())
    ]
    t3 = ctx.published.get("table3")
    m3 = models.get("smooth3")
    rows = []
    for r in sorted(recs, key=lambda x: x.wavelength_nm):
        wl = r.wavelength_nm
        row: dict[str, Any] = {"wavelength_nm": wl}
        ms = meas[np.isclose(meas["wavelength_nm"], wl)]
        srcs = sorted(set(ms["source"]))
        row["measured"] = float(ms["value"].mean()) if len(ms) else None
        row["measured_spread"] = float(ms["value"].max() - ms["value"].min()) if len(ms) else None
        row["sources"] = ", ".join(srcs)
        if t3 is not None:
            p3 = t3[np.isclose(t3["wavelength_nm"], wl)]
            row["t3_measured"] = _num(p3["measured_pct"].iloc[0]) if len(p3) else None
            row["t3_integration"] = _num(p3["integration_pct"].iloc[0]) if len(p3) else None
            row["t3_error"] = (
                _num(p3["error_pct"].iloc[0]) if len(p3) and "error_pct" in p3 else None
            )
        pv = _paper_values(ctx, sample, wl)
        for ang in (45, 46):
            row[f"paper_{ang}"] = (
                float(integrate.hemispherical_reflectance(m3, pv, ang)) if pv else None
            )
            row[f"ours_{ang}"] = (
                float(integrate.hemispherical_reflectance(m3, r.values, ang)) if r.values else None
            )
        row["ours_46_sigma"] = _rho_sigma(r, 46.0) if r.values else None
        if row["measured"] is not None and row["ours_46"] is not None:
            row["rel_err_46"] = 100.0 * (row["ours_46"] - row["measured"]) / row["measured"]
        else:
            row["rel_err_46"] = None
        rows.append(row)
    for row in rows:
        for k in ("t3_measured", "t3_integration"):
            if row.get(k) is not None:
                row[k] = row[k] / 100.0
    b.table(
        "hemispherical",
        f"Hemispherical reflectance of {sample}: model integral against the spectrophotometer "
        "(Table 3 style)",
        [
            ("wavelength_nm", "\u03bb [nm]", "g"),
            ("measured", "measured (fixture files) [%]", "%"),
            ("sources", "files", ""),
            ("t3_measured", "Table 3 measured [%]", "%"),
            ("t3_integration", "Table 3 integration [%]", "%"),
            ("t3_error", "Table 3 error [%]", ".4g"),
            ("paper_45", "paper fit, 45\u00b0 [%]", "%"),
            ("paper_46", "paper fit, 46\u00b0 [%]", "%"),
            ("ours_45", "our fit, 45\u00b0 [%]", "%"),
            ("ours_46", "our fit, 46\u00b0 [%]", "%"),
            ("ours_46_sigma", "\u03c3 our fit 46\u00b0 [%]", "%"),
            ("rel_err_46", "our 46\u00b0 vs measured [% rel.]", ".3g"),
        ],
        rows,
        caption="Measured: hemispherical reflectance of the spectrophotometer fixtures (the "
        "three published Table 3 values and the labelled synthetic interpolations through "
        "them). Modelled: rho(theta_i) = 2 pi int f cos sin d theta_r of smooth3 (closed "
        "form, notes/models.md 1.2) with the paper's Table 1 parameters and with ours, at "
        "45 deg (the geometry the paper names) and at 46 deg (where its 'integration result' "
        "is actually reproduced; see the errata). \u03c3 from the fit covariance.",
    )
    # figure
    meas_line = None
    for src, g in meas.groupby("source"):
        if len(g) > 5:
            g = g.sort_values("wavelength_nm")
            meas_line = {
                "label": f"measured ({src})",
                "wavelength": g["wavelength_nm"],
                "value": g["value"],
            }
            break
    pts = []
    wls = [row["wavelength_nm"] for row in rows]
    for key, label, mk in (
        ("t3_measured", "Table 3 measured", "s"),
        ("t3_integration", "Table 3 integration", "^"),
        ("paper_46", "paper fit at 46\u00b0", "o"),
        ("paper_45", "paper fit at 45\u00b0", "x"),
        ("ours_46", "our fit at 46\u00b0", "D"),
    ):
        xs = [w for w, row in zip(wls, rows, strict=True) if row.get(key) is not None]
        ys = [row[key] for row in rows if row.get(key) is not None]
        if xs:
            pts.append({"label": label, "wavelength": xs, "value": ys, "marker": mk})
    b.figure(
        "hemispherical",
        f"Hemispherical reflectance of {sample} against wavelength (Table 3)",
        "Measured: spectrophotometer (line: synthetic interpolation through the three "
        "published values; squares: Table 3 measured). Modelled: hemispherical integral of "
        "smooth3 with the paper's parameters at 45 and 46 deg and with our fit at 46 deg; "
        "triangles: the paper's printed integration result.",
        figures.hemispherical_figure(meas_line, pts),
    )
    # checks
    have46 = [
        row
        for row in rows
        if row.get("t3_integration") is not None and row.get("paper_46") is not None
    ]
    if have46:
        d46 = max(abs(row["paper_46"] - row["t3_integration"]) for row in have46) * 100
        d45 = min(abs(row["paper_45"] - row["t3_integration"]) for row in have46) * 100
        b.check(
            "hemispherical.table3_at_46deg",
            "the paper's own parameters reproduce its Table 3 'integration result' at "
            "\u03b8i = 46 deg",
            d46 <= 0.11,
            against="Zou 2013 Table 3 (integration column) and Table 1",
            value=d46,
            tolerance=0.11,
            justification="largest |rho_46 - printed| in %-points; notes/models.md 1.2 "
            "documents deviations +0.02/-0.10/-0.03 (not explained by quadrature or "
            "cut-off; rounding in the paper) plus 0.005 for the 2 printed decimals",
        )
        b.check(
            "hemispherical.table3_not_45deg",
            "at the stated \u03b8i = 45 deg the paper's parameters do NOT reproduce Table 3 "
            "(erratum confirmed)",
            d45 > 0.11,
            against="Zou 2013 Table 3 (integration column)",
            value=d45,
            tolerance=0.11,
            justification="smallest |rho_45 - printed| in %-points must exceed the 46-deg "
            "tolerance (notes/models.md 1.2: 45 deg is 1.4-2 points low)",
        )
    else:
        b.skip(
            "hemispherical.table3_at_46deg",
            "Table 3 reproduced at 46 deg",
            "published Tables 1 and 3 not found in fixtures/published",
        )
    both = [
        row
        for row in rows
        if row["measured"] is not None and row["ours_46"] is not None and row.get("ours_46_sigma")
    ]
    if both:
        zmax = max(abs(row["ours_46"] - row["measured"]) / row["ours_46_sigma"] for row in both)
        worst = max(abs(row["rel_err_46"]) for row in both)
        b.text(
            f"Our fits' hemispherical integrals differ from the spectrophotometer by up to "
            f"{worst:.3g} % (relative), against 3.65 % in the paper's Table 3. The +-2 deg "
            "scans hardly constrain the lobe shape (k2, k3: see the flags of the fits), and "
            "the integral depends on it: its 1-sigma uncertainty propagated from the fit "
            "covariance is given in the table. The check therefore asks for agreement within "
            "that uncertainty, not within the paper's 3.65 %."
        )
        b.check(
            "hemispherical.fit_vs_spectrophotometer",
            "hemispherical integral of our smooth3 fits (46 deg) agrees with the "
            "spectrophotometer within the fit's uncertainty",
            zmax <= 4.0,
            against="spectrophotometer fixtures (Table 3 measured values)",
            value=zmax,
            tolerance=4.0,
            justification="largest |rho_fit(46 deg) - measured| / sigma(rho_fit), sigma "
            "propagated from the fit covariance (the measured values carry no published "
            "uncertainty)",
        )
    else:
        b.skip(
            "hemispherical.fit_vs_spectrophotometer",
            "hemispherical integral agrees with the spectrophotometer",
            "no spectrophotometer value (or no integral uncertainty) at a fitted wavelength",
        )
    zs = []
    for row in rows:
        if None not in (row.get("paper_46"), row.get("ours_46")) and row.get("ours_46_sigma"):
            zs.append(abs(row["ours_46"] - row["paper_46"]) / row["ours_46_sigma"])
    if zs:
        b.check(
            "hemispherical.fit_vs_paper_fit",
            "our fit's hemispherical integral equals the paper fit's within its uncertainty",
            max(zs) <= 4.0,
            against="rho(46 deg) from the published Table 1 parameters",
            value=max(zs),
            tolerance=4.0,
            justification="largest |ours - paper| / \u03c3(ours), \u03c3 propagated from the "
            "fit covariance; the fixtures were generated from the published parameters",
        )


def errata_section(ctx: Context) -> None:
    """The paper errata the report depends on, with the checks that confirm them."""
    from labbrdf import integrate, models

    b = ctx.b
    rows = [
        {
            "where": "2013 Table 3",
            "printed": "'integration result' at theta_i = 45 deg",
            "correct": "reproduced at 46 deg with the proper 2 pi int f cos sin convention",
            "used": "hemispherical section: both angles shown",
        },
        {
            "where": "2013 eq. (8)",
            "printed": "energy conserved iff k1 <= 4/pi",
            "correct": "no k1 > 0 conserves energy at all angles; k1 <= 4/(pi max I/cos) on "
            "[0, theta_max] (notes 1.4)",
            "used": "energy checks: rho(theta_i) and the limit angle of every fit",
        },
        {
            "where": "2013 section 2",
            "printed": "the model is reciprocal",
            "correct": "reciprocal iff k2 = 0 (notes 1.3)",
            "used": "reciprocity defect of every fit",
        },
        {
            "where": "2013 eq. (5)",
            "printed": "(k' - sin g)",
            "correct": "(k' - sin g tan g)",
            "used": "not used by the report",
        },
        {
            "where": "2013 eq. (6)",
            "printed": "square missing inside the root",
            "correct": "see notes/models.md 3.4",
            "used": "ellipsometric inversion (optics)",
        },
        {
            "where": "2022 eq. (14)",
            "printed": "GGX D without alpha^2 in the numerator",
            "correct": "D = alpha^2 / (pi cos^4 g (alpha^2 + tan^2 g)^2)",
            "used": "tracer maps and validations",
        },
        {
            "where": "2022 eq. (17)",
            "printed": "rotation Mueller M[0,0] = 0",
            "correct": "M[0,0] = 1",
            "used": "tracer maps and validations",
        },
        {
            "where": "2022 eq. (12)",
            "printed": "-2 sqrt(Ts Tp) on the diagonal block",
            "correct": "+2 Re(t_s t_p*) scaled by the beam-area factor",
            "used": "tracer (coated surfaces)",
        },
        {
            "where": "2022 eq. (2)",
            "printed": "PSD exponent k_x^2 c_x + k_y^2 c_y",
            "correct": "k_x^2 c_x^2 + k_y^2 c_y^2",
            "used": "surface generation (not in maps)",
        },
        {
            "where": "2022 section 4",
            "printed": "maximum polarization at d = lambda/4",
            "correct": "cannot appear in incoherent ray optics (a lossless varnish's thickness "
            "only enters through absorption); needs coherent film amplitudes",
            "used": "coating-thickness factor study",
        },
    ]
    b.table(
        "errata",
        "Errata of the source papers that this report depends on",
        [
            ("where", "where", ""),
            ("printed", "printed", ""),
            ("correct", "correct", ""),
            ("used", "where it matters here", ""),
        ],
        rows,
        caption="From DESIGN.md 'Known errors in the source papers' and notes/models.md.",
    )
    t = ctx.published.get("params")
    if t is None:
        raise Unavailable("published Tables 1-2 not found (fixtures/published)")
    m = models.get("smooth3")
    erows, worst, worst_root = [], 0.0, 0.0
    for (sample, wl), ref in ENERGY_LIMIT_DEG.items():
        pv = _paper_values(ctx, sample, wl)
        if pv is None:
            continue
        ang = integrate.energy_limit_angle(m, pv)
        # independent of the closed form: rho at our angle by quadrature must be 1
        rho_q = float(integrate.hemispherical_reflectance(m, pv, ang, method="quadrature"))
        worst_root = max(worst_root, abs(rho_q - 1.0))
        if (sample, wl) not in NOTES_MISROUNDED:
            worst = max(worst, abs(ang - ref))
        erows.append(
            {
                "sample": sample,
                "wavelength_nm": wl,
                "k1": pv["k1"],
                "limit_deg": ang,
                "notes_deg": ref,
                "k1max_60": integrate.k1_max_energy(pv["k2"], pv["k3"], 60.0),
                "k1max_89": integrate.k1_max_energy(pv["k2"], pv["k3"], 89.0),
            }
        )
    b.table(
        "errata_energy",
        "Energy conservation of the paper's own fits (erratum of eq. 8)",
        [
            ("sample", "sample", ""),
            ("wavelength_nm", "\u03bb [nm]", "g"),
            ("k1", "k1 published", ".4f"),
            ("limit_deg", "\u03c1 = 1 reached at \u03b8i [deg]", ".3f"),
            ("notes_deg", "notes/models.md 1.4 [deg]", ".1f"),
            ("k1max_60", "k1 max for \u03c1 \u2264 1 up to 60\u00b0", ".4g"),
            ("k1max_89", "k1 max up to 89\u00b0", ".4g"),
        ],
        erows,
        caption="Modelled: smooth3 with the published Table 1-2 parameters. Eq. (8) of the "
        "paper claims energy conservation for k1 <= 4/pi; every published fit satisfies "
        "that and still reaches rho = 1 before grazing incidence.",
    )
    if erows:
        b.check(
            "errata.energy_limit_roots",
            "each angle where the paper's fits reach \u03c1 = 1 is a root by quadrature",
            worst_root <= 1e-6,
            against="adaptive Gauss-Legendre quadrature of the BRDF (not the closed form)",
            value=worst_root,
            tolerance=1e-6,
            justification="max |rho_quad(theta) - 1|; the quadrature is converged to 1e-6 "
            "relative",
        )
        b.check(
            "errata.energy_limit_angles",
            "the angles where the paper's fits reach \u03c1 = 1 match notes/models.md 1.4",
            worst <= 0.05,
            against="notes/models.md 1.4 (independent scipy-quad oracle script)",
            value=worst,
            tolerance=0.05,
            justification="largest difference [deg]; the notes print 0.1 deg (rounding bound "
            "0.05). Excluded: mirror 500 nm, which the notes print as 76.3 but whose root is "
            "76.2498 deg (checked by quadrature above), so the notes misround it.",
        )
    rrows, worst = [], 0.0
    for sample, (a_ref, b_ref) in RECIPROCITY_550.items():
        pv = _paper_values(ctx, sample, 550.0)
        if pv is None:
            continue
        fa = float(m.evaluate(math.radians(30), math.radians(50), params=pv))
        fb = float(m.evaluate(math.radians(50), math.radians(30), params=pv))
        worst = max(worst, abs(fa - a_ref), abs(fb - b_ref))
        rrows.append(
            {
                "sample": sample,
                "k2": pv["k2"],
                "f_30_50": fa,
                "f_50_30": fb,
                "notes_30_50": a_ref,
                "notes_50_30": b_ref,
            }
        )
    b.table(
        "errata_reciprocity",
        "Reciprocity of the paper's own fits at 550 nm (the paper claims reciprocity)",
        [
            ("sample", "sample", ""),
            ("k2", "k2 [rad]", ".5g"),
            ("f_30_50", "f(30\u00b0, 50\u00b0) [sr\u207b\u00b9]", ".4f"),
            ("f_50_30", "f(50\u00b0, 30\u00b0) [sr\u207b\u00b9]", ".4f"),
            ("notes_30_50", "notes 1.3 f(30, 50)", ".4f"),
            ("notes_50_30", "notes 1.3 f(50, 30)", ".4f"),
        ],
        rrows,
        caption="Modelled: smooth3 with the published parameters, in-plane (phi_r = 180 deg). "
        "Swapping incidence and detector changes the value unless k2 = 0.",
    )
    if rrows:
        b.check(
            "errata.reciprocity_values",
            "f(30, 50) and f(50, 30) of the paper's 550 nm fits match notes/models.md 1.3",
            worst <= 5e-5,
            against="notes/models.md 1.3",
            value=worst,
            tolerance=5e-5,
            justification="4 decimals printed: rounding bound 5e-5 sr^-1",
        )
