"""Section ``fits``: every model fitted per sample and wavelength (Tables 1-2 of Zou 2013).

Zou X., Bai L., Wu Z., "Mirror reflectance spectrum modeling of smooth samples", Acta Optica
Sinica 33(6), 0612008 (2013), doi:10.3788/AOS201333.0612008.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from scipy import stats

from ..builder import num, wl_label
from ..context import Context, FitRecord, rmse_abs, rmse_paper, run_fits
from ..published import published_params
from ..roughness import rayleigh_flags

__all__ = ["fits_section"]


def fits_section(
    ctx: Context,
    model_specs: Sequence[tuple[str, dict[str, Any]]],
    *,
    published_check: bool = False,
    chi2_models: Sequence[str] | None = None,
) -> None:
    """Tables 1-2 style parameter tables; success, chi-square and published-value checks.

    ``model_specs``: (registry name, options) of each model to fit. ``chi2_models``: models
    whose reduced chi-square is a check (default: all); for the others it is shown as a
    finding (e.g. five_param fitted to data made with smooth3).
    """
    b = ctx.b
    ctx.fits.update(run_fits(ctx, model_specs))
    for name, recs in ctx.fits.items():
        if not recs:
            continue
        pnames = list(recs[0].params)
        varying = [p for p in pnames if recs[0].params[p].get("vary", True)]
        has_pub = name == "smooth3" and "params" in ctx.published
        opts = ", ".join(f"{k}={v}" for k, v in recs[0].options.items()) or "defaults"
        b.table(
            f"fit_{name}",
            f"Fitted {name} parameters per sample and wavelength ({opts})",
            _columns(recs, varying, has_pub),
            [_row(ctx, r, varying, has_pub) for r in recs],
            caption=f"Measured: the scan rows of each (sample, wavelength). Modelled: {name} "
            f"fitted with nlopt {ctx.method} (seed {ctx.seed}). \u03c3 from the Jacobian at the "
            "optimum, 95% interval from the t distribution; flags mark parameters at a bound "
            "or not identifiable from the data."
            + (" 'published' columns: Zou, Bai, Wu 2013, Tables 1-2." if has_pub else ""),
        )
        _success_check(ctx, name, recs)
        _chi2_check(ctx, name, recs, varying, chi2_models)
        if published_check and has_pub:
            _published_check(ctx, recs, varying)


def _columns(
    recs: Sequence[FitRecord], varying: Sequence[str], has_pub: bool
) -> list[tuple[str, str, str]]:
    """The parameter table's columns: each varying parameter with its sigma and interval."""
    cols: list[tuple[str, str, str]] = [
        ("sample", "sample", ""),
        ("wavelength_nm", "\u03bb [nm]", "g"),
    ]
    for p in varying:
        u = recs[0].params[p].get("units") or ""
        unit = f" [{u}]" if u and u != "1" else ""
        cols += [
            (p, f"{p}{unit}", ".5g"),
            (f"{p}_stderr", f"\u03c3({p})", ".2g"),
            (f"{p}_lo", f"{p} 95% lo", ".5g"),
            (f"{p}_hi", f"{p} 95% hi", ".5g"),
        ]
        if has_pub:
            cols.append((f"{p}_pub", f"{p} published", ".5g"))
    cols += [("flags", "flags", ""), ("rmse_paper", "RMSE (paper's sense) [%]", ".4g")]
    if has_pub:
        cols.append(("rmse_pub", "RMSE published [%]", ".4g"))
    cols += [
        ("rmse_abs", "RMSE [data units]", ".3g"),
        ("redchi", "\u03c7\u00b2/\u03bd", ".4g"),
        ("weighting", "weighting", ""),
        ("nfev", "nfev", "d"),
        ("status", "status", ""),
    ]
    return cols


def _row(ctx: Context, r: FitRecord, varying: Sequence[str], has_pub: bool) -> dict[str, Any]:
    """One fit's line of the parameter table."""
    row: dict[str, Any] = {"sample": r.sample, "wavelength_nm": r.wavelength_nm}
    pub = published_params(ctx.published, r.sample, r.wavelength_nm) if has_pub else {}
    flags = []
    for p in varying:
        q = r.params[p]
        row.update(
            {
                p: q["value"],
                f"{p}_stderr": q["stderr"],
                f"{p}_lo": q["lo"],
                f"{p}_hi": q["hi"],
                f"{p}_pub": pub.get(p),
            }
        )
        flags += [f"{p}: {f}" for f in q["flags"]]
    if r.model == "smooth3":  # the model assumes a smooth sample (Zou 2013 sec. 3)
        src, th = r.data["source"].astype(str).unique(), r.data["theta_i_deg"]
        flags += rayleigh_flags(ctx, list(src), r.wavelength_nm, th.to_numpy(float))
    row["flags"] = "; ".join(flags)
    row["rmse_paper"] = rmse_paper(r.summary)
    row["rmse_pub"] = pub.get("rmse")
    row["rmse_abs"] = rmse_abs(r.summary)
    row["redchi"] = num(r.summary.get("redchi"))
    row["weighting"] = str(r.summary.get("weighting") or "").split(":")[0]
    row["nfev"] = r.summary.get("nfev")
    row["success"] = bool(r.summary.get("success"))
    row["status"] = r.summary.get("status") or ("ok" if row["success"] else "failed")
    return row


def _success_check(ctx: Context, name: str, recs: Sequence[FitRecord]) -> None:
    bad = [
        f"{r.sample} {wl_label(r.wavelength_nm)}: {r.summary.get('message', '')}"
        for r in recs
        if not r.summary.get("success")
    ]
    ctx.b.check(
        f"fits.{name}.success",
        f"every {name} fit converged",
        not bad,
        against="the optimiser's success flag",
        value=len(recs) - len(bad),
        tolerance=len(recs),
        justification="value = converged fits, tolerance = fits run",
        reason="; ".join(bad)[:1000],
    )


def _chi2_check(
    ctx: Context,
    name: str,
    recs: Sequence[FitRecord],
    varying: Sequence[str],
    chi2_models: Sequence[str] | None,
) -> None:
    """Chi-square consistency where the files give sigma (a finding for other models)."""
    b = ctx.b
    lohi = []
    worst = None
    ok = True
    for r in recs:
        red = num(r.summary.get("redchi"))
        has_sigma = r.data["sigma"].notna().all()
        nfree = len(r.data) - len(varying)
        if red is None or not has_sigma or nfree < 1:
            continue
        lo = stats.chi2.ppf(0.0005, nfree) / nfree
        hi = stats.chi2.ppf(0.9995, nfree) / nfree
        lohi.append((lo, hi))
        if not lo <= red <= hi:
            ok = False
        if worst is None or abs(math.log(red)) > abs(math.log(worst)):
            worst = red
    if chi2_models is not None and name not in chi2_models:
        shown = "n/a" if worst is None else f"{worst:.4g}"
        b.text(
            f"{name}: reduced \u03c7\u00b2 up to {shown} (a finding, not a check: the "
            "data were not generated with this model)."
        )
    elif lohi:
        b.check(
            f"fits.{name}.chi2",
            f"{name}: reduced \u03c7\u00b2 of every fit consistent with the file's \u03c3",
            ok,
            against="the \u03c7\u00b2 distribution with \u03bd = N - n_par",
            value=worst,
            tolerance=[min(x for x, _ in lohi), max(y for _, y in lohi)],
            justification="two-sided 99.9% interval of \u03c7\u00b2/\u03bd per fit; a model "
            "that describes the data within their stated \u03c3 lands inside",
        )
    else:
        b.skip(
            f"fits.{name}.chi2",
            f"{name}: reduced \u03c7\u00b2 consistent with \u03c3",
            "the data carry no \u03c3 (or no redchi in the fit summary)",
        )


def _published_check(ctx: Context, recs: Sequence[FitRecord], varying: Sequence[str]) -> None:
    worst, n, bad = 0.0, 0, []
    for r in recs:
        pub = published_params(ctx.published, r.sample, r.wavelength_nm)
        for p in varying:
            se, v, pv = r.params[p]["stderr"], r.params[p]["value"], pub.get(p)
            if pv is None or v is None or not se:
                continue
            z = abs(v - pv) / se
            n += 1
            worst = max(worst, z)
            if z > 4:
                bad.append(
                    f"{r.sample} {wl_label(r.wavelength_nm)} {p}: "
                    f"{v:.5g} vs {pv:.5g} ({z:.1f} \u03c3)"
                )
    if n == 0:
        ctx.b.skip(
            "fits.smooth3.published",
            "smooth3 recovers the published parameters",
            "no published value with a finite fitted \u03c3",
        )
        return
    ctx.b.check(
        "fits.smooth3.published",
        "smooth3 fits recover the published Tables 1-2 parameters (the fixtures' generating "
        "values)",
        not bad,
        against="Zou, Bai, Wu 2013, Tables 1-2",
        value=worst,
        tolerance=4.0,
        justification="largest |fit - published| / \u03c3(fit) over all parameters; the "
        "synthetic fixtures were generated from the published values, so each should lie "
        "within 4 \u03c3 (two-sided false-alarm rate 6e-5 per parameter)",
        reason="; ".join(bad)[:1000],
    )
