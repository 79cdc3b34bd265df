"""Section ``hemispherical``: the fits' hemispherical integral against the spectrophotometer.

Compared with the paper's Table 3 [Zou2013]_. Published numbers come from
``fixtures/published/zou2013_table{1,3}.csv`` (with their citation headers); that Table 3
is reproduced at 46 deg, not 45, is derived in ``docs/errata.md``.

References
----------
.. [Zou2013] Zou X., Bai L., Wu Z., "Mirror reflectance spectrum modeling of smooth samples",
   Acta Optica Sinica 33(6), 0612008 (2013). doi:10.3788/AOS201333.0612008
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from ... import integrate, models
from .. import figures
from ..builder import Unavailable, num
from ..context import Context, FitRecord
from ..published import paper_values

__all__ = ["hemispherical_section"]


def _rho_sigma(rec: FitRecord, theta_deg: float) -> float | None:
    """1-sigma of rho(theta) from the fit covariance (finite-difference gradient)."""
    names = [k for k in ("k1", "k2", "k3") if k in rec.params and rec.params[k]["stderr"]]
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
    summ = rec.summary["params"]
    for i, a in enumerate(names):
        for j, c in enumerate(names):
            if i != j:
                r = summ[a]["correl"].get(c)
                corr[i, j] = float(r) if r is not None else 0.0
    cov = corr * np.outer(se, se)
    g = np.asarray(grad)
    var = float(g @ cov @ g)
    return math.sqrt(var) if var >= 0 else None


def _row(
    ctx: Context,
    r: FitRecord,
    meas: pd.DataFrame,
    t3: pd.DataFrame | None,
    m3: models.Model,
    sample: str,
) -> dict[str, Any]:
    """One fitted wavelength: measured, Table 3 and the paper's and our integrals."""
    wl = r.wavelength_nm
    row: dict[str, Any] = {"wavelength_nm": wl}
    ms = meas[np.isclose(meas["wavelength_nm"], wl)]
    srcs = sorted(set(ms["source"]))
    row["measured"] = float(ms["value"].mean()) if len(ms) else None
    row["measured_spread"] = float(ms["value"].max() - ms["value"].min()) if len(ms) else None
    row["sources"] = ", ".join(srcs)
    if t3 is not None:
        p3 = t3[np.isclose(t3["wavelength_nm"], wl)]
        row["t3_measured"] = num(p3["measured_pct"].iloc[0]) if len(p3) else None
        row["t3_integration"] = num(p3["integration_pct"].iloc[0]) if len(p3) else None
        row["t3_error"] = num(p3["error_pct"].iloc[0]) if len(p3) and "error_pct" in p3 else None
    pv = paper_values(ctx.published, sample, wl)
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
    return row


def _table(ctx: Context, sample: str, rows: list[dict[str, Any]]) -> None:
    ctx.b.table(
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
        "form, docs/models.md 1.2) with the paper's Table 1 parameters and with ours, at "
        "45 deg (the geometry the paper names) and at 46 deg (where its 'integration result' "
        "is actually reproduced; see the errata). \u03c3 from the fit covariance.",
    )


def _figure(ctx: Context, sample: str, meas: pd.DataFrame, rows: list[dict[str, Any]]) -> None:
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
    ctx.b.figure(
        "hemispherical",
        f"Hemispherical reflectance of {sample} against wavelength (Table 3)",
        "Measured: spectrophotometer (line: synthetic interpolation through the three "
        "published values; squares: Table 3 measured). Modelled: hemispherical integral of "
        "smooth3 with the paper's parameters at 45 and 46 deg and with our fit at 46 deg; "
        "triangles: the paper's printed integration result.",
        figures.hemispherical_figure(meas_line, pts),
    )


def _table3_checks(ctx: Context, rows: list[dict[str, Any]]) -> None:
    """The paper's parameters reproduce its Table 3 at 46 deg, and not at the stated 45."""
    b = ctx.b
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
            justification="largest |rho_46 - printed| in %-points; docs/models.md 1.2 "
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
            "tolerance (docs/models.md 1.2: 45 deg is 1.4-2 points low)",
        )
    else:
        b.skip(
            "hemispherical.table3_at_46deg",
            "Table 3 reproduced at 46 deg",
            "published Tables 1 and 3 not found in fixtures/published",
        )


def _fit_checks(ctx: Context, rows: list[dict[str, Any]]) -> None:
    """Our fits' integral against the spectrophotometer and the paper fit's, within sigma."""
    b = ctx.b
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


def hemispherical_section(ctx: Context, sample: str = "OSR") -> None:
    """Table 3 style: hemispherical integral of the fits against the spectrophotometer."""
    recs = [r for r in ctx.fits.get("smooth3", []) if r.sample.lower() == sample.lower()]
    if not recs:
        raise Unavailable(f"no smooth3 fits of sample {sample}")
    d = ctx.data
    if d is None:
        raise Unavailable("no data ingested")
    meas = d[
        (d["quantity"] == "hemispherical_reflectance")
        & (d["sample"].str.lower() == sample.lower())
    ]
    t3 = ctx.published.get("table3")
    m3 = models.get("smooth3")
    rows = [
        _row(ctx, r, meas, t3, m3, sample) for r in sorted(recs, key=lambda x: x.wavelength_nm)
    ]
    for row in rows:
        for k in ("t3_measured", "t3_integration"):
            if row.get(k) is not None:
                row[k] = row[k] / 100.0
    _table(ctx, sample, rows)
    _figure(ctx, sample, meas, rows)
    _table3_checks(ctx, rows)
    _fit_checks(ctx, rows)
