"""Section ``nk``: optical constants from psi/Delta and the cross-instrument comparison.

Per file with psi/Delta rows: the two-phase pseudo-constants of every point
(:func:`labbrdf.nk.nk_table`), their per-wavelength combination over the angles of incidence
with the angle-to-angle consistency test (:func:`labbrdf.nk.combined_table`), and a plain
flag where the angles disagree. From the combined ``n, k``: the Fresnel reflectances
``R_s, R_p`` and their mean at normal incidence, compared with measured reflectance rows
(:func:`labbrdf.nk.compare_reflectance`) of the same file or of the same sample
(:mod:`labbrdf.report.pairing`: a sample name the files state, or the user's mapping).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from ... import ellipsometry as ell
from ... import nk as nkmod
from .. import figures
from ..agreement import P_AGREE, chi_square
from ..builder import Unavailable, slug
from ..context import Context
from ..inputs import file_frames
from ..pairing import how_to_pair, same_sample
from ..roughness import SpecularLoss, specular_loss_for

__all__ = ["nk_section"]

_SERIES = ("time_s", "x_mm", "y_mm")


def _n_members(comb: pd.DataFrame) -> int:
    return len(nkmod.series_members(comb))


def _nk_figure(src: str, c: pd.DataFrame) -> str:
    return figures.panels_figure(nkmod.nk_panels(c, max_series=6), ncols=2)


def _pseudo_figure(points: pd.DataFrame) -> str:
    return figures.panels_figure(nkmod.nk_panels(points, max_series=8), ncols=2)


def _at(c: pd.DataFrame, wl: float) -> dict[str, float | None]:
    """Combined n, k at the wavelength nearest ``wl`` (None where the angles disagree)."""
    if c.empty:
        return {"n": None, "k": None}
    i = int(np.argmin(np.abs(c["wavelength_nm"].to_numpy(float) - wl)))
    r = c.iloc[i]
    n, k = float(r["n"]), float(r["k"])
    return {
        "wl": float(r["wavelength_nm"]),
        "n": n if np.isfinite(n) else None,
        "k": k if np.isfinite(k) else None,
    }


def _combined_ok(c: pd.DataFrame) -> np.ndarray:
    """Rows of a combined table with one n, k (the angles agree, or a single angle)."""
    return np.isfinite(c["n"].to_numpy(float)) & np.isfinite(c["k"].to_numpy(float))


def _compare(
    ctx: Context,
    tag: str,
    src: str,
    comb: pd.DataFrame,
    refl: pd.DataFrame,
    rsrc: str,
    rows_out: list[dict[str, Any]],
) -> None:
    """Fresnel prediction from ``comb`` against the reflectance rows of ``rsrc``."""
    b = ctx.b
    first = nkmod.series_members(comb)[0][1]
    try:
        cmp = nkmod.compare_reflectance(first, refl)
    except ValueError as exc:
        b.note("not compared", f"{rsrc} against n, k of {src}: {exc}")
        b.skip(
            f"nk.reflectance.{tag}",
            f"{rsrc}: measured R agrees with Fresnel R from n, k of {src}",
            str(exc),
        )
        return
    rough = _with_roughness(ctx, rsrc, cmp)
    if rough is not None:
        cmp = rough[0]
    z = cmp["z"].to_numpy(float)
    nz, chi2, p = chi_square(z)
    has_sigma = bool(cmp["measured_sigma"].notna().any())
    chan = sorted({str(x) for x in cmp["channel"] if x is not None and str(x) not in ("", "nan")})
    kind = f"R_{'/'.join(chan)}" if chan else "(R_s + R_p)/2"
    rows_out.append(
        {
            "nk_file": src,
            "refl_file": rsrc,
            "quantity": kind,
            "theta_i": ", ".join(f"{t:g}" for t in sorted(cmp["theta_i_deg"].round(2).unique())),
            "points": len(cmp),
            "wl_min": float(cmp["wavelength_nm"].min()),
            "wl_max": float(cmp["wavelength_nm"].max()),
            "mean_diff": float(cmp["difference"].mean()),
            "rms_diff": float(np.sqrt(np.mean(cmp["difference"] ** 2))),
            "median_sigma": float(np.nanmedian(cmp["difference_sigma"])),
            "chi2_dof": chi2 / nz if nz else None,
            "p_value": p if nz else None,
            "outside": int(cmp.attrs.get("outside_range", 0)),
            "prediction": "Fresnel" if rough is None else f"Fresnel x exp(-g), {rough[1].map}",
        }
    )
    x = cmp["wavelength_nm"].to_numpy(float)
    series_m, series_d = [], []
    cmp = cmp.assign(_ch=cmp["channel"].astype(object).where(cmp["channel"].notna(), ""))
    for (ch, th), g in cmp.groupby(["_ch", cmp["theta_i_deg"].round(2)], sort=True):
        lab = f"{ch or 'unpolarised'} \u03b8i {th:g}\u00b0"
        series_m.append(
            {
                "label": f"measured {lab}",
                "x": g["wavelength_nm"],
                "y": g["measured"],
                "yerr": g["measured_sigma"].to_numpy(float),
                "style": "points" if len(g) < 30 else "line",
            }
        )
        series_m.append(
            {
                "label": f"{'Fresnel' if rough is None else 'Fresnel x exp(-g)'} from n, k {lab}",
                "x": g["wavelength_nm"],
                "y": g["predicted"],
                "band": g["predicted_sigma"].to_numpy(float),
            }
        )
        series_d.append(
            {
                "label": lab,
                "x": g["wavelength_nm"],
                "y": g["difference"],
                "band": g["difference_sigma"].to_numpy(float),
            }
        )
    b.figure(
        f"nk_{tag}_refl",
        f"Reflectance of {rsrc} against the Fresnel prediction from n, k of {src}",
        f"Measured: {kind} [1] from {rsrc} ({len(x)} points, {x.min():.4g}-{x.max():.4g} nm). "
        f"Modelled: Fresnel reflectance of a bare half-space with the combined n, k of {src} "
        "(two-phase model)"
        + ("" if rough is None else f" times the specular loss exp(-g) of {rough[1].map}")
        + ", band = propagated 1-sigma. Right: measured - predicted with "
        "the combined 1-sigma band"
        + ("" if has_sigma else " (the prediction's sigma alone: the file gives none)")
        + ".",
        figures.reflectance_comparison_figure(series_m, series_d, panel_size=(5.0, 3.2)),
    )
    agree = nz > 0 and p >= P_AGREE
    why = _roughness_words(rough, cmp, agree)
    if why and rough is None:
        b.note("roughness?", f"{rsrc}: {why}")
    b.check(
        f"nk.reflectance.{tag}",
        f"{rsrc}: measured {kind} agrees with the Fresnel prediction from n, k of {src}"
        + ("" if rough is None else f" times the specular loss exp(-g) of {rough[1].map}"),
        agree,
        against="Fresnel equations (two-phase) with the ellipsometric n, k"
        + ("" if rough is None else ", times exp(-g) from the paired height map's sigma"),
        value=p if nz else None,
        tolerance=P_AGREE,
        justification=(
            f"chi-square test of z = difference / sigma over {nz} points "
            f"(chi2/dof {chi2 / nz:.3g}); value = p-value, fails below the tolerance"
            if nz
            else "no point with a finite uncertainty"
        )
        + (f"; {why}" if why else ""),
    )


def _with_roughness(
    ctx: Context, rsrc: str, cmp: pd.DataFrame
) -> tuple[pd.DataFrame, SpecularLoss] | None:
    """The comparison against Fresnel times the specular loss of the paired height map.

    None when no height map is of the same sample as ``rsrc``. The loss is the smoothness
    section's (:func:`~labbrdf.report.roughness.specular_loss_for`); its 1-sigma
    (from sigma's) joins the prediction's in quadrature. Rows outside the map's band are
    dropped (no loss predicted there).
    """
    sl = specular_loss_for(ctx, rsrc, cmp["wavelength_nm"], cmp["theta_i_deg"])
    if sl is None or not np.isfinite(sl.loss).any():
        return None
    pred0 = cmp["predicted"].to_numpy(float)
    pred = pred0 * sl.loss
    psig = np.hypot(cmp["predicted_sigma"].to_numpy(float) * sl.loss, pred0 * sl.u_loss)
    msig = cmp["measured_sigma"].to_numpy(float)
    diff = cmp["measured"].to_numpy(float) - pred
    dsig = np.where(np.isnan(msig), psig, np.hypot(msig, psig))
    with np.errstate(divide="ignore", invalid="ignore"):
        z = diff / dsig
    out = cmp.assign(
        predicted=pred,
        predicted_sigma=psig,
        difference=diff,
        difference_sigma=dsig,
        z=z,
        specular_loss=sl.loss,
        g=sl.g,
    )
    out.attrs.update(cmp.attrs)
    return out[np.isfinite(sl.loss)].reset_index(drop=True), sl


def _roughness_words(
    rough: tuple[pd.DataFrame, SpecularLoss] | None, cmp: pd.DataFrame, agree: bool
) -> str:
    """What roughness has to do with the comparison, for the check's text ("" if nothing)."""
    if rough is not None:
        sl = rough[1]
        return (
            f"the prediction is the smooth Fresnel R times the specular loss exp(-g) of the "
            f"paired height map {sl.map} (g = (4 pi sigma cos theta / lambda)^2, sigma "
            f"{np.nanmin(sl.sigma_nm):.3g}-{np.nanmax(sl.sigma_nm):.3g} nm, exp(-g) "
            f"{np.nanmin(sl.loss):.3g}-{np.nanmax(sl.loss):.3g})"
        )
    below = float(np.nanmean(cmp["difference"].to_numpy(float))) < 0
    if agree or not below:
        return ""
    return (
        "the measured R lies below the smooth Fresnel value: surface roughness is a possible "
        "cause (a specular loss exp(-g)); give the sample's height map (paired by sample "
        "name or --same-sample) to account for it"
    )


def _r0_figure(ctx: Context, i: int, src: str, comb: pd.DataFrame) -> None:
    """The predicted normal-incidence Fresnel reflectance from the combined n, k."""
    b = ctx.b
    first = nkmod.series_members(comb)[0][1]
    ok = _combined_ok(first)
    if not ok.any():
        b.note(
            "no reflectance prediction",
            f"{src}: the angles of incidence disagree at every wavelength; pseudo-constants "
            "of a stack predict no reflectance of the sample.",
        )
        return
    r_ok = ell.fresnel_reflectances(
        np.maximum(first["n"].to_numpy(float)[ok], 0.0),
        np.maximum(first["k"].to_numpy(float)[ok], 0.0),
        np.zeros(int(ok.sum())),
        n_sigma=first["n_sigma"].to_numpy(float)[ok],
        k_sigma=first["k_sigma"].to_numpy(float)[ok],
        nk_cov=first["nk_cov"].to_numpy(float)[ok],
    )

    def full(v: np.ndarray) -> np.ndarray:  # NaN (a gap) where the angles disagree
        out = np.full(len(first), np.nan)
        out[ok] = v
        return out

    rs, rp, rm, rm_sigma = (full(v) for v in (r_ok.rs, r_ok.rp, r_ok.r, r_ok.r_sigma))
    x = first["wavelength_nm"].to_numpy(float)
    b.figure(
        f"nk_{i}_{slug(src)}_r0",
        f"{src}: predicted normal-incidence reflectance",
        "Modelled from the combined n, k (two-phase Fresnel, bare half-space): R_s, R_p and "
        "their mean (R_s = R_p at normal incidence) [1] against wavelength [nm], band = "
        "propagated 1-sigma. Meaningful for a bulk material only (see the verdict).",
        figures.panels_figure(
            [
                {
                    "title": "Fresnel R at 0\u00b0",
                    "xlabel": "wavelength [nm]",
                    "ylabel": "R [1]",
                    "series": [
                        {"label": "R_s", "x": x, "y": rs},
                        {"label": "R_p", "x": x, "y": rp},
                        {"label": "(R_s + R_p)/2", "x": x, "y": rm, "band": rm_sigma},
                    ],
                }
            ],
            ncols=1,
            panel_size=(5.5, 3.2),
        ),
        details=True,
    )


_INTRO = (
    "Two-phase (bare substrate, ambient n = 1) pseudo-optical constants <N> = n + ik of "
    "every psi/Delta point, combined per wavelength over the angles of incidence "
    "(inverse-covariance weighted mean where the file gives sigmas). The consistency "
    "of the angles is a chi-square test (p-value); a bulk, clean, isotropic material "
    "gives the same n, k at every angle, while a film or roughness makes the pseudo "
    "constants depend on the angle. Where the angles disagree the values are "
    "pseudo-constants of a stack, not a material's n, k: they are not combined into one "
    "value, and no reflectance is predicted from them (a fitted stack model does that: "
    "section film, with --film-model)."
)


def _file_text(ctx: Context, pts: pd.DataFrame, comb: pd.DataFrame, verdict: str) -> None:
    """The paragraph on one file: points, angles, verdict, ill-conditioned points, series."""
    cond_bad = int((pts["cond"] > ell_cond_limit()).sum())
    n_ang = int(pts["theta_i_deg"].round(2).nunique())
    ctx.b.text(
        f"{len(pts)} psi/Delta pairs at {n_ang} angle(s), {len(comb)} combined "
        f"(wavelength{', series member' if _n_members(comb) > 1 else ''}) rows. "
        f"Verdict: {verdict}."
        + (
            f" {cond_bad} point(s) are ill-conditioned (condition number above "
            f"{ell_cond_limit():g}): their n, k carry large uncertainties."
            if cond_bad
            else ""
        )
        + (
            f" The file is a series of {_n_members(comb)} members (times or spots); "
            "the figure shows up to six of them."
            if _n_members(comb) > 1
            else ""
        )
    )


def _constants_figures(
    ctx: Context, tag: str, src: str, pts: pd.DataFrame, comb: pd.DataFrame, stack_like: bool
) -> None:
    """The combined n, k (where any), their table and the pseudo-constants per angle."""
    b = ctx.b
    if bool(_combined_ok(comb).any()):
        b.figure(
            f"nk_{tag}_combined",
            f"{src}: combined optical constants n and k",
            "Derived from measured psi/Delta: n [1] and k [1] against wavelength [nm], "
            "combined over the angles of incidence; band = 1-sigma (propagated from the "
            "file's sigmas, or the angle-to-angle scatter where that is larger or sigmas "
            "are missing), times sqrt(chi2/dof) where the angles disagree.",
            _nk_figure(src, comb),
            details=stack_like,
        )
    cols = [k for k in _SERIES if k in comb.columns]
    b.table(
        f"nk_{tag}",
        f"{src}: combined n, k per wavelength",
        [(c, c, ".6g") for c in cols]
        + [
            ("wavelength_nm", "\u03bb [nm]", ".6g"),
            ("n", "n", ".5g"),
            ("n_sigma", "\u03c3n", ".2g"),
            ("k", "k", ".5g"),
            ("k_sigma", "\u03c3k", ".2g"),
            ("chi2", "\u03c7\u00b2", ".3g"),
            ("dof", "dof", "d"),
            ("p_value", "p", ".2g"),
            ("angle_dependent", "angle-dependent", ""),
            ("n_angles", "angles", "d"),
        ],
        comb.to_dict("records"),
        caption="n, k combined over the angles of incidence; chi2/dof and p test their "
        f"agreement; angle-dependent = p < {ell.P_ANGLE_DEPENDENT:g} (sigmas times "
        "sqrt(chi2/dof) there; no n, k at all for a sample whose angles disagree at most "
        "wavelengths: pseudo-constants of a stack).",
        details=True,
    )
    b.figure(
        f"nk_{tag}_pseudo",
        f"{src}: pseudo-constants per angle of incidence",
        "Derived from measured psi/Delta, one line per angle of incidence: two-phase "
        "pseudo n and k [1] against wavelength [nm] with propagated 1-sigma error bars. "
        "Lines that do not overlap mean the sample is not a bare bulk material.",
        _pseudo_figure(pts),
        details=not stack_like,
    )


def _k_physical(ctx: Context, tag: str, src: str, comb: pd.DataFrame) -> None:
    """Check k >= 0 within 3 sigma where the angles agree (skipped where they never do)."""
    b = ctx.b
    nk_ok = comb["combined"].to_numpy(bool) & ~comb["angle_dependent"].to_numpy(bool)
    nk_ok &= comb["dof"].to_numpy(int) > 0
    if nk_ok.any():
        c_ok = comb[nk_ok]
        neg = c_ok["k"].to_numpy(float) < -3 * np.nan_to_num(c_ok["k_sigma"].to_numpy(float))
        b.check(
            f"nk.k_physical.{tag}",
            f"{src}: k >= 0 within 3 sigma where the angles agree",
            not neg.any(),
            against="absorbing or transparent media have k >= 0",
            value=int(neg.sum()),
            tolerance=0,
            justification=f"value = wavelengths with k < -3 sigma among {len(c_ok)} "
            "where the angle test passes",
        )
    else:
        b.skip(
            f"nk.k_physical.{tag}",
            f"{src}: k >= 0 within 3 sigma where the angles agree",
            "no wavelength where the angles agree (or only one angle, or they agree at "
            "a few wavelengths by chance in a sample whose angles disagree elsewhere): "
            "pseudo-constants of a layered sample need not have k >= 0",
        )


def _summary_row(
    src: str, rows: pd.DataFrame, pts: pd.DataFrame, comb: pd.DataFrame, short: str
) -> dict[str, Any]:
    """One file's line of the summary table: n, k near 500 nm and the angle agreement."""
    dof = comb["dof"].to_numpy(int)
    tested = dof > 0
    frac_dep = float(comb.loc[tested, "angle_dependent"].mean()) if tested.any() else None
    chi = comb.loc[tested, "chi2"].to_numpy(float) / np.maximum(dof[tested], 1)
    a500 = _at(comb, 500.0)
    return {
        "file": src,
        "sample": ", ".join(sorted({str(s) for s in rows["sample"]})),
        "points": len(pts),
        "angles": int(pts["theta_i_deg"].round(2).nunique()),
        "wl_min": float(comb["wavelength_nm"].min()),
        "wl_max": float(comb["wavelength_nm"].max()),
        "wl_500": a500.get("wl"),
        "n_500": a500["n"],
        "k_500": a500["k"],
        "chi2_dof": float(np.median(chi)) if len(chi) else None,
        "frac_dep": frac_dep,
        "verdict": short,
    }


def _file_section(
    ctx: Context, i: int, src: str, g: pd.DataFrame, cmp_rows: list[dict[str, Any]]
) -> tuple[pd.DataFrame, dict[str, Any]] | None:
    """One psi/Delta file: its constants, figures, checks and own reflectance comparison.

    Returns the combined table and the summary row, or None where no constants follow.
    """
    b = ctx.b
    tag = f"{i}_{slug(src)}"
    rows = nkmod.ordinary_psi_delta(g)
    b.heading(f"{src}: optical constants", anchor=f"nk_{tag}")
    try:
        pts = nkmod.nk_table(rows, on_ill_conditioned="ignore")
        comb = nkmod.combined_table(pts)
    except (ValueError, KeyError) as exc:
        b.note("no optical constants", f"{src}: {exc}")
        b.skip(f"nk.constants.{tag}", f"{src}: optical constants", str(exc))
        return None
    av = nkmod.angle_verdict(comb)
    _file_text(ctx, pts, comb, av.text)
    stack_like = not bool(_combined_ok(comb).any()) or av.kind == "stack"
    if stack_like:
        b.text(
            f"The values of {src} are pseudo-constants of a stack, one per angle of "
            "incidence (figure below), not a material's optical constants: they are not "
            "combined where the angles disagree, and give no reflectance prediction."
        )
    _constants_figures(ctx, tag, src, pts, comb, stack_like)
    _k_physical(ctx, tag, src, comb)
    row = _summary_row(src, rows, pts, comb, av.short)
    _r0_figure(ctx, i, src, comb)
    # the file's own reflectance rows
    if (g["quantity"] == "reflectance").any():
        _compare(ctx, f"{tag}_own", src, comb, g, src, cmp_rows)
    return comb, row


def _summary_table(ctx: Context, summary: list[dict[str, Any]]) -> None:
    ctx.b.table(
        "nk_summary",
        "Optical constants per file",
        [
            ("file", "file", ""),
            ("points", "psi/\u0394 pairs", "d"),
            ("angles", "angles", "d"),
            ("wl_min", "\u03bb min [nm]", ".5g"),
            ("wl_max", "\u03bb max [nm]", ".5g"),
            ("wl_500", "\u03bb\u2248500 [nm]", ".5g"),
            ("n_500", "n there", ".4g"),
            ("k_500", "k there", ".4g"),
            ("chi2_dof", "median \u03c7\u00b2/dof", ".3g"),
            ("frac_dep", "fraction angle-dependent", ".2f"),
            ("verdict", "verdict", ""),
        ],
        summary,
        caption="n, k at the measured wavelength nearest 500 nm; chi2/dof of the angle "
        "agreement, median over wavelengths; the verdict in full is in each file's text.",
    )


def _pairs(
    ctx: Context,
    ellips: list[tuple[str, pd.DataFrame, Any]],
    refl: list[tuple[str, pd.DataFrame, Any]],
    combined: dict[str, pd.DataFrame],
) -> list[tuple[str, str, pd.DataFrame]]:
    """(n, k file, reflectance file, its rows) of the cross-instrument comparisons.

    An ellipsometer file of the same sample (:func:`labbrdf.report.pairing.same_sample`:
    a sample name both files state, or the user's mapping); a note for a reflectance file
    with none, saying how to pair it.

    Notes
    -----
    Files are never paired because the report holds one ellipsometer file: a spectrophotometer
    file of another sample would then be judged against the wrong n, k. Where that count
    alone would have paired two files, the note names both and the mapping that pairs them.
    """
    pairs = []
    lone = list(combined) if len(combined) == 1 else []
    unpaired: list[str] = []
    for rs, rg, _ in refl:
        # a file with both is compared with its own n, k in its file's part
        match = [s for s in combined if s != rs and same_sample(ctx, s, rs)]
        if not match and rs not in combined:
            unpaired.append(rs)
        for s in match:
            pairs.append((s, rs, rg))
    if unpaired:
        files = ", ".join(unpaired)
        ctx.b.note(
            "not compared",
            f"reflectance of {files}: no ellipsometer file of the same sample (no sample name "
            "both state, no mapping given)"
            + (
                f"; {lone[0]} is the only ellipsometer file of the report, which does not "
                f"make it the same sample: {how_to_pair(ctx, [lone[0], *unpaired])}"
                if lone
                else f"; {how_to_pair(ctx, ['ELLIPSOMETER_FILE', *unpaired])}"
            ),
        )
    return pairs


def _comparison_table(ctx: Context, cmp_rows: list[dict[str, Any]]) -> None:
    ctx.b.table(
        "nk_reflectance_comparison",
        "Measured reflectance against the Fresnel prediction from ellipsometric n, k",
        [
            ("nk_file", "n, k from", ""),
            ("refl_file", "reflectance from", ""),
            ("quantity", "compared", ""),
            ("theta_i", "\u03b8i [deg]", ""),
            ("points", "points", "d"),
            ("wl_min", "\u03bb min [nm]", ".5g"),
            ("wl_max", "\u03bb max [nm]", ".5g"),
            ("mean_diff", "mean diff [1]", ".3g"),
            ("rms_diff", "rms diff [1]", ".3g"),
            ("median_sigma", "median \u03c3 diff [1]", ".2g"),
            ("chi2_dof", "\u03c7\u00b2/dof", ".3g"),
            ("p_value", "p", ".2g"),
            ("outside", "rows outside n, k range", "d"),
            ("prediction", "prediction", ""),
        ],
        cmp_rows,
        caption="diff = measured - predicted; sigma diff adds the measurement's and the "
        "prediction's 1-sigma in quadrature (the prediction's alone where the file has "
        "none: a lower bound). Spectrophotometer rows without an angle are taken at "
        "normal incidence. Where a height map of the sample is given, the prediction is "
        "the smooth Fresnel R times the specular loss exp(-g) from the map's sigma (section "
        "'Roughness against wavelength').",
    )


def nk_section(ctx: Context) -> None:
    """Optical constants per psi/Delta file and their reflectance predictions."""
    b = ctx.b
    frames = file_frames(ctx)
    if not frames:
        raise Unavailable("no data ingested")
    ellips = [(s, g, m) for s, g, m in frames if len(nkmod.ordinary_psi_delta(g))]
    refl = [(s, g, m) for s, g, m in frames if (g["quantity"] == "reflectance").any()]
    if not ellips:
        b.skip(
            "nk.constants",
            "optical constants from psi/Delta",
            "no psi/Delta rows: no optical constants",
        )
        raise Unavailable(
            "no psi/Delta rows ingested: no optical constants, no Fresnel prediction"
        )
    b.text(_INTRO)
    summary: list[dict[str, Any]] = []
    cmp_rows: list[dict[str, Any]] = []
    combined: dict[str, pd.DataFrame] = {}
    for i, (src, g, _meta) in enumerate(ellips):
        done = _file_section(ctx, i, src, g, cmp_rows)
        if done is not None:
            combined[src], row = done
            ctx.nk_combined[src] = combined[src]
            summary.append(row)
    b.heading("Summary and reflectance predictions", anchor="nk_summary")
    _summary_table(ctx, summary)
    # cross-instrument comparisons
    for j, (s, rs, rg) in enumerate(_pairs(ctx, ellips, refl, combined)):
        _compare(ctx, f"x{j}_{slug(rs)}", s, combined[s], rg, rs, cmp_rows)
    if not refl:
        b.note(
            "not compared", "no reflectance rows ingested: nothing to compare the predictions with"
        )
        b.skip(
            "nk.reflectance",
            "measured reflectance agrees with Fresnel R from n, k",
            "no reflectance rows",
        )
    if cmp_rows:
        _comparison_table(ctx, cmp_rows)


def ell_cond_limit() -> float:
    """Condition number above which a pseudo-n, k point counts as ill-conditioned [1]."""
    return float(ell.COND_WARN)
