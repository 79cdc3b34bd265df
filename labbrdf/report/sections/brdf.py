"""Section ``brdf``: measured BRDF files (Zemax/Radiant ``.bsdf`` and any ``brdf`` rows).

Fits per angle of incidence and jointly, hemisphere maps of measurement, model and residual,
in-plane cuts, an energy table (the file's TIS, the quadrature of the measured grid and the
hemispherical integral of each fitted model) and the reciprocity of the joint fit.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ... import integrate, models
from ...fitting import fit_many
from ..builder import Unavailable, num, wl_label
from ..context import BY, Context, FitRecord, fit_records

__all__ = ["brdf_section", "brdf_fit_options", "energy_rows"]

#: rows closer than this to the plane of incidence count as in-plane [deg]
IN_PLANE_TOL_DEG = 1e-6
#: direction pairs (theta_a, theta_b, phi) [deg] of the reciprocity table
RECIP_PAIRS = ((15.0, 45.0, 180.0), (30.0, 60.0, 180.0), (20.0, 70.0, 90.0), (45.0, 10.0, 135.0))


def brdf_rows(ctx: Context) -> pd.DataFrame:
    """The ingested rows with quantity ``brdf``; :class:`Unavailable` when there are none."""
    d = ctx.data
    rows = d[d["quantity"] == "brdf"] if d is not None else None
    if rows is None or not len(rows):
        raise Unavailable("no BRDF rows ingested (quantity 'brdf'), so there is nothing to fit")
    return rows.reset_index(drop=True)


def brdf_fit_options(ctx: Context, rows: pd.DataFrame) -> dict[str, Any]:
    """The :func:`labbrdf.fitting.fit` keywords the CLI would use for these rows.

    :func:`labbrdf.fitting.fit`'s defaults, which are the CLI's: zeros masked (instrument
    floor, not a measurement of 0), the file's sigma where every row has one, else weights
    relative to the data (``weighting="auto"``).
    """
    return {"mask_zeros": True, "weighting": "auto", **ctx.fit_options}


def _label(ti: float | None) -> str:
    return "joint" if ti is None else f"{ti:g}"


def run_brdf_fits(
    ctx: Context, model: str, options: Mapping[str, Any], rows: pd.DataFrame
) -> list[tuple[float | None, FitRecord]]:
    """Fit ``model`` per (sample, wavelength, theta_i) and jointly per (sample, wavelength).

    Returns (theta_i or None for the joint fit, record) for each (sample, wavelength) in
    order: its fits per incidence, then its joint fit.
    """
    kw = brdf_fit_options(ctx, rows)
    m = models.get(model, **options)
    recs: dict[tuple[str, float], list[tuple[float | None, FitRecord]]] = {}
    for by in ([*BY, "theta_i_deg"], list(BY)):
        table, results = fit_many(
            rows,
            m,
            by=by,
            method=ctx.method,
            seed=ctx.seed,
            executor=ctx.executor,
            return_results=True,
            **kw,
        )
        tis = [float(k["theta_i_deg"]) if "theta_i_deg" in k else None for k, _ in results]
        labels = [f"theta_i={_label(ti)}" for ti in tis]
        ctx.b.log(f"  fitted {model} to {len(table)} BRDF groups by {', '.join(by)}")
        recs_by = fit_records(model, options, rows, table, results, by, labels)
        for ti, rec in zip(tis, recs_by, strict=True):
            recs.setdefault((rec.sample, rec.wavelength_nm), []).append((ti, rec))
    return [x for key in sorted(recs) for x in recs[key]]


def _evaluate(rec: FitRecord, ti: Any, tr: Any, pr: Any) -> np.ndarray:
    """The fitted model of ``rec`` at angles [deg] (broadcast) [sr^-1]."""
    m = models.get(rec.model, **rec.options)
    return np.asarray(
        m.evaluate(
            np.radians(ti),
            np.radians(tr),
            np.radians(pr),
            wavelength=rec.wavelength_nm,
            params=rec.values,
        ),
        float,
    )


def _bsdf_file(ctx: Context, sample: str) -> dict[str, Any] | None:
    """The ingested ``.bsdf`` file record of a sample (reader's meta), if any."""
    for f in ctx.files:
        meta = f.get("meta") or {}
        if meta.get("format") == "zemax-bsdf" and Path(f["path"]).stem == sample:
            return f
    return None


def _model_on_grid(rec: FitRecord, meta: Mapping[str, Any], ti: float) -> float | None:
    """Quadrature of the fitted model on the file's own grid at one incidence [1]."""
    from ...adapters import zemax_bsdf as z

    g = meta["grid"]
    az, rad = np.array(g["azimuth_deg"], float), np.array(g["radial_deg"], float)
    tr, pr, above = z.scatter_to_angles(ti, rad[None, :], az[:, None])
    f = np.where(above, _evaluate(rec, ti, np.where(above, tr, 0.0), pr), 0.0)
    res = z.grid_integral(
        {
            "values": f[None, None, None],
            "theta_i_deg": [ti],
            "azimuth_deg": az,
            "radial_deg": rad,
            "symmetry": meta.get("symmetry", "Asymmetrical"),
        }
    )
    return num(res["integral"].ravel()[0])


def energy_rows(
    ctx: Context, fits: Sequence[tuple[float | None, FitRecord]]
) -> list[dict[str, Any]]:
    """One row per per-incidence fit: TIS, grid integral, uncovered fraction, model integrals."""
    from ...adapters import zemax_bsdf as z

    grids: dict[str, dict[str, Any]] = {}
    rows = []
    for ti, rec in fits:
        if ti is None:
            continue
        row: dict[str, Any] = {
            "sample": rec.sample,
            "wavelength_nm": rec.wavelength_nm,
            "theta_i": ti,
        }
        f = _bsdf_file(ctx, rec.sample)
        if f is not None:
            if rec.sample not in grids:
                t = z.read_table(f["path"])
                gi = z.grid_integral(t)
                grids[rec.sample] = {"t": t, "gi": gi}
            t, gi = grids[rec.sample]["t"], grids[rec.sample]["gi"]
            k = np.flatnonzero(np.isclose(t.theta_i_deg, ti))
            if k.size and t.values.shape[:2] == (1, 1):
                a = int(k[0])
                row["tis"] = num(gi["tis"][0, 0, a])
                row["grid"] = num(gi["integral"][0, 0, a])
                row["uncovered"] = num(gi["uncovered_fraction"][a])
                row["model_grid"] = _model_on_grid(rec, f["meta"], ti)
        m = models.get(rec.model, **rec.options)
        rho = num(np.atleast_1d(integrate.hemispherical_reflectance(m, rec.values, [ti]))[0])
        row["model"] = rho
        if rho is not None and row.get("grid") is not None:
            row["model_minus_grid"] = rho - row["grid"]
            if row.get("model_grid") is not None:
                row["model_outside"] = rho - row["model_grid"]
        if row.get("tis") is not None and row.get("grid"):
            row["tis_over_grid"] = row["tis"] / row["grid"]
        if rho is not None and row.get("tis") is not None:
            row["model_minus_tis"] = rho - row["tis"]
        row["energy_ok"] = rho is not None and rho <= 1.0
        g = rec.data
        row["off_plane"] = bool(
            np.ptp(
                g["theta_r_deg"].to_numpy(float)
                * np.sin(np.radians(g["phi_r_deg"].to_numpy(float)))
            )
            > IN_PLANE_TOL_DEG
        )
        rows.append(row)
    return rows


def brdf_section(ctx: Context, model: str, options: Mapping[str, Any]) -> None:
    """Fits per incidence and joint, maps, in-plane cuts, energy and reciprocity of BRDF rows.

    Parameters
    ----------
    ctx : Context
        The report's context (ingested frames and files).
    model : str
        Registry name of the model to fit.
    options : mapping
        Model options (e.g. ``{"n": 1.5, "k": 0, "diffuse": True}``).
    """
    b = ctx.b
    rows = brdf_rows(ctx)
    kw = brdf_fit_options(ctx, rows)
    weighting = kw.get("weighting", "auto")
    if weighting == "auto":
        weighting = "sigma" if rows["sigma"].notna().all() else "relative"
    b.text(
        f"{len(rows)} BRDF rows [sr\u207b\u00b9] in {rows['sample'].nunique()} sample(s). "
        f"{model} is fitted to each angle of incidence on its own and to all angles jointly "
        f"(per sample and wavelength), with weighting '{weighting}' and zeros masked "
        "(zeros are the instrument's floor, not measured values)"
        + (
            "; the rows carry no \u03c3, so residuals are relative to the data."
            if weighting == "relative"
            else "."
        )
        + " The joint fit is the fit of section fits (the same weighting, masked points, "
        "method and seed as there and as labbrdf fit and labbrdf.fit); each per-angle fit "
        "sees one angle of incidence only, so its values differ from the joint ones by design."
    )
    for f in ctx.files:
        meta = f.get("meta") or {}
        if meta.get("format") == "zemax-bsdf" and meta.get("wavelength_stated") is False:
            b.text(
                f"{f['file']}: the .bsdf format has no wavelength field; "
                f"{wl_label(float(meta.get('wavelength_nm', 555.0)))} is a label only "
                "(it matters for models whose index n, k depends on wavelength)."
            )
    fits = run_brdf_fits(ctx, model, options, rows)
    _fits_table(ctx, model, options, fits)
    for (s, w), grp in _by_sample(fits).items():
        _maps(ctx, s, w, grp, rows)
        _cuts(ctx, s, w, grp)
    _energy(ctx, fits)
    _reciprocity(ctx, fits)


def _by_sample(
    fits: Sequence[tuple[float | None, FitRecord]],
) -> dict[tuple[str, float], list[tuple[float | None, FitRecord]]]:
    out: dict[tuple[str, float], list[tuple[float | None, FitRecord]]] = {}
    for ti, rec in fits:
        out.setdefault((rec.sample, rec.wavelength_nm), []).append((ti, rec))
    return out


def _fits_table(
    ctx: Context,
    model: str,
    options: Mapping[str, Any],
    fits: Sequence[tuple[float | None, FitRecord]],
) -> None:
    b = ctx.b
    first = fits[0][1]
    varying = [p for p, q in first.params.items() if q.get("vary", True)]
    cols: list[tuple[str, str, str]] = _group_cols(fits) + [
        ("theta_i", "\u03b8i [deg]", ""),
        ("npoints", "points", "d"),
    ]
    for p in varying:
        u = first.params[p].get("units") or ""
        unit = f" [{u}]" if u and u != "1" else ""
        cols += [
            (p, f"{p}{unit}", ".4g"),
            (f"{p}_lo", f"{p} 95% lo", ".4g"),
            (f"{p}_hi", f"{p} 95% hi", ".4g"),
        ]
    cols += [
        ("flags", "flags", ""),
        ("redchi", "\u03c7\u00b2/\u03bd", ".3g"),
        ("weighting", "weighting", ""),
        ("nmasked", "masked", "d"),
        ("nfev", "nfev", "d"),
        ("status", "status", ""),
    ]
    out = []
    for ti, r in fits:
        row: dict[str, Any] = {
            "sample": r.sample,
            "wavelength_nm": r.wavelength_nm,
            "theta_i": _label(ti),
            "npoints": len(r.data),
        }
        flags = []
        for p in varying:
            q = r.params[p]
            row.update({p: q["value"], f"{p}_lo": q["lo"], f"{p}_hi": q["hi"]})
            flags += [f"{p}: {f}" for f in q["flags"]]
        row["flags"] = "; ".join(flags)
        row["redchi"] = num(r.summary.get("redchi"))
        row["weighting"] = str(r.summary.get("weighting") or "").split(":")[0]
        row["nmasked"] = r.summary.get("nmasked")
        row["nfev"] = r.summary.get("nfev")
        row["success"] = bool(r.summary.get("success"))
        row["status"] = r.summary.get("status") or ("ok" if row["success"] else "failed")
        out.append(row)
    opts = ", ".join(f"{k}={v}" for k, v in options.items()) or "defaults"
    # the model's own label where it has one (microfacet names its distribution, GGX too)
    label = getattr(models.get(model, **options), "label", model)
    b.table(
        "brdf_fits",
        f"{label} ({opts}) fitted per angle of incidence and jointly{_one_group(ctx, fits)}",
        cols,
        out,
        caption=f"Measured: the BRDF rows of each incidence angle \u03b8i ('joint': all angles "
        f"together). Modelled: {model} fitted with nlopt {ctx.method} (seed {ctx.seed}). "
        "95% interval from the t distribution with \u03c3 from the Jacobian at the optimum; "
        "'masked' counts zero values left out; weighting 'relative': \u03c3 = max(|y|, "
        "floor x max|y|) (the fit's relative_floor), so \u03c7\u00b2/\u03bd is the mean squared "
        "relative residual, not a goodness of fit against a stated \u03c3.",
    )
    bad = [
        f"{r.sample} \u03b8i={_label(ti)}: {r.summary.get('message', '')}"
        for ti, r in fits
        if not r.summary.get("success")
    ]
    b.check(
        "brdf.fits.success",
        f"every {model} fit to the BRDF rows converged (per incidence and joint)",
        not bad,
        against="the optimiser's success flag",
        value=len(fits) - len(bad),
        tolerance=len(fits),
        justification="value = converged fits, tolerance = fits run",
        reason="; ".join(bad)[:1000],
    )


def _group_cols(fits: Sequence[tuple[float | None, FitRecord]]) -> list[tuple[str, str, str]]:
    """Sample and wavelength columns, only when the fits span more than one of them."""
    if len({(r.sample, r.wavelength_nm) for _, r in fits}) < 2:
        return []
    return [("sample", "sample", ""), ("wavelength_nm", "\u03bb [nm]", "g")]


def _one_group(ctx: Context, fits: Sequence[tuple[float | None, FitRecord]]) -> str:
    """Title suffix "(sample, wavelength)" when all fits share them, else empty."""
    keys = {(r.sample, r.wavelength_nm) for _, r in fits}
    if len(keys) != 1:
        return ""
    s, w = next(iter(keys))
    return f" ({s}, {_wl_text(ctx, s, w)})"


def _wl_text(ctx: Context, sample: str, wl: float) -> str:
    """``"550 nm"``, or "wavelength not stated" for a label.

    The label case: every file of the sample at ``wl`` states no wavelength (a .bsdf file
    without a wavelength comment).
    """
    unstated = {
        Path(str(f.get("path", ""))).name
        for f in ctx.files
        if (f.get("meta") or {}).get("wavelength_stated") is False
    }
    d = ctx.data
    if not unstated or d is None:
        return wl_label(wl)
    g = d[(d["sample"] == sample) & (d["wavelength_nm"] == wl)]
    return wl_label(wl, stated=not (len(g) and g["source"].isin(unstated).all()))


def _select(n: int) -> list[int]:
    """Indices of the first, middle and last of ``n`` items."""
    return sorted({0, n // 2, n - 1})


def _map_panel(rec: FitRecord, ti: float, g: pd.DataFrame) -> dict[str, Any]:
    v = g["value"].to_numpy(float)
    tr = g["theta_r_deg"].to_numpy(float)
    pr = g["phi_r_deg"].to_numpy(float)
    f = _evaluate(rec, ti, tr, pr)
    with np.errstate(divide="ignore", invalid="ignore"):
        res = np.where(v > 0, (f - v) / v, np.nan)
    return {
        "label": f"\u03b8i = {ti:g}\u00b0",
        "theta_r": tr,
        "phi_r": pr,
        "measured": v,
        "model": f,
        "residual": res,
    }


def _maps(
    ctx: Context,
    sample: str,
    wl: float,
    grp: Sequence[tuple[float | None, FitRecord]],
    rows: pd.DataFrame,
) -> None:
    from .. import figures

    per = [(ti, r) for ti, r in grp if ti is not None]
    if not per:
        return
    panels = [_map_panel(r, ti, r.data) for ti, r in per]
    off_plane = [
        np.ptp(p["theta_r"] * np.sin(np.radians(p["phi_r"]))) > IN_PLANE_TOL_DEG for p in panels
    ]
    if not any(off_plane):
        ctx.b.note(
            "hemisphere maps",
            f"{sample}, {_wl_text(ctx, sample, wl)}: every row lies in the plane of incidence, "
            "so there is no hemisphere to map; see the in-plane cuts",
        )
        return
    panels = [p for p, ok in zip(panels, off_plane, strict=True) if ok]
    half = bool(np.all(np.concatenate([p["phi_r"] for p in panels]) <= 180.0 + 1e-9))
    cover = (
        "The rows cover \u03c6r in [0, 180] deg only (a PlaneSymmetrical file: the other half "
        "is the mirror image); that half is shown, not mirrored."
        if half
        else "Full hemisphere as measured."
    )
    geo = (
        "Each disc is the scatter hemisphere seen from above: x = \u03b8r cos \u03c6r, "
        "y = \u03b8r sin \u03c6r [deg]; the source is towards +x (\u03c6r = 0), the specular "
        "direction at (-\u03b8i, 0); circles at \u03b8r = 30, 60, 90 deg. "
    )
    sel = _select(len(panels))
    tag = f"{sample}, {_wl_text(ctx, sample, wl)}"
    ctx.b.figure(
        f"brdf_maps_{_slug(sample, wl)}",
        f"Measured BRDF, per-incidence fit and relative residual ({tag})",
        geo
        + cover
        + " Columns: measured BRDF and the fitted model at the same directions on one log10 "
        "colour scale per row [sr\u207b\u00b9]; relative residual (model - measured) / "
        "measured [1], clipped to \u00b11, blank where the measurement is 0. Rows: the "
        "first, middle and last angle of incidence; all angles in the next figure.",
        figures.brdf_maps_figure([panels[i] for i in sel], title=tag),
    )
    if len(panels) > len(sel):
        ctx.b.figure(
            f"brdf_residuals_{_slug(sample, wl)}",
            f"Relative residual of the per-incidence fit at every angle of incidence ({tag})",
            geo + cover + " Colour: (model - measured) / measured [1], clipped to \u00b11.",
            figures.brdf_residual_grid_figure(panels, title=tag),
        )


def _slug(sample: str, wl: float) -> str:
    from ..builder import slug

    return f"{slug(sample)}_{wl:g}".replace(".", "p")


def _cuts(
    ctx: Context, sample: str, wl: float, grp: Sequence[tuple[float | None, FitRecord]]
) -> None:
    from .. import figures

    joint = next((r for ti, r in grp if ti is None), None)
    panels = []
    for ti, r in grp:
        if ti is None:
            continue
        g = r.data
        pr = np.mod(g["phi_r_deg"].to_numpy(float), 360.0)
        tr = g["theta_r_deg"].to_numpy(float)
        fwd = np.abs(pr - 180.0) < IN_PLANE_TOL_DEG
        back = (np.minimum(pr, 360.0 - pr) < IN_PLANE_TOL_DEG) & ~fwd
        x = np.concatenate([tr[fwd], -tr[back]])
        y = np.concatenate([g["value"].to_numpy(float)[fwd], g["value"].to_numpy(float)[back]])
        if not x.size:
            continue
        grid = np.linspace(-89.0, 89.0, 357)
        grid = grid[(grid >= x.min() - 5) & (grid <= x.max() + 5)]
        gp = np.where(grid >= 0, 180.0, 0.0)
        curves = {"per-incidence fit": _evaluate(r, ti, np.abs(grid), gp)}
        if joint is not None:
            curves["joint fit"] = _evaluate(joint, ti, np.abs(grid), gp)
        panels.append(
            {
                "label": f"\u03b8i = {ti:g}\u00b0",
                "x": x,
                "y": y,
                "grid": grid,
                "curves": curves,
                "specular": ti,
            }
        )
    if not panels:
        ctx.b.note("in-plane cuts", "no rows in the plane of incidence (\u03c6r = 0 or 180 deg)")
        return
    tag = f"{sample}, {_wl_text(ctx, sample, wl)}"
    ctx.b.figure(
        f"brdf_cuts_{_slug(sample, wl)}",
        f"In-plane cuts with the fitted models ({tag})",
        "Measured rows in the plane of incidence (points) and the fitted models (lines) per "
        "angle of incidence. x: signed \u03b8r [deg], positive on the specular side "
        "(\u03c6r = 180), negative towards the source (\u03c6r = 0); the dotted line marks the "
        "specular direction. y: BRDF [sr\u207b\u00b9], log scale; zeros (masked in the fits) "
        "are not drawn.",
        figures.brdf_cuts_figure(panels, title=tag),
    )


def _energy(ctx: Context, fits: Sequence[tuple[float | None, FitRecord]]) -> None:
    b = ctx.b
    rows = energy_rows(ctx, fits)
    has_file = any(r.get("tis") is not None for r in rows)
    cols: list[tuple[str, str, str]] = _group_cols(fits) + [("theta_i", "\u03b8i [deg]", "g")]
    if has_file:
        cols += [
            ("tis", "file TIS [1]", ".4f"),
            ("grid", "grid integral of data [1]", ".4f"),
            ("uncovered", "hemisphere not covered [1]", ".3f"),
            ("tis_over_grid", "TIS / grid", ".3f"),
            ("model_grid", "model on the grid [1]", ".4f"),
        ]
    cols += [("model", "model \u03c1 (hemisphere) [1]", ".4f")]
    if has_file:
        cols += [
            ("model_outside", "model \u03c1 - model on grid [1]", ".4f"),
            ("model_minus_grid", "model \u03c1 - grid [1]", ".4f"),
            ("model_minus_tis", "model \u03c1 - TIS [1]", ".4f"),
        ]
    cols += [("off_plane", "data off the plane", ""), ("energy_ok", "\u03c1 \u2264 1", "")]
    b.table(
        "brdf_energy",
        "Energy per angle of incidence: file TIS, grid integral of the data, model integral"
        + _one_group(ctx, fits),
        cols,
        rows,
        caption="All values are fractions of the incident power. 'file TIS': the value the "
        "instrument wrote for the block (its own definition and native sampling). 'grid "
        "integral': \u222b f cos\u03b8r d\u03c9 of the measured values on the file's grid "
        "(cells bounded by the midpoints between nodes, exact solid angles, a "
        "PlaneSymmetrical half counted twice); 'hemisphere not covered': the fraction of the "
        "projected solid angle (\u03c0 sr) beyond the largest radial angle or below the "
        "horizon, where the grid has no cell. 'model on the grid': the per-incidence fit "
        "through the same quadrature; 'model \u03c1': the fit's directional-hemispherical "
        "reflectance over the whole hemisphere (adaptive Gauss-Legendre, 1e-6 relative). "
        "Not forced to agree: model \u03c1 - grid = (model on grid - grid), the misfit, plus "
        "(model \u03c1 - model on grid), what the model puts into the uncovered part near "
        "grazing and the quadrature error of the grid.",
    )
    if has_file:
        b.text(_energy_sentence(rows))
    # the check covers the angles whose rows leave the plane of incidence: there the fit is
    # constrained over the hemisphere; an in-plane scan leaves the off-plane part of the
    # model (and so rho) an extrapolation, shown in the table as a finding
    covered = [r for r in rows if r["off_plane"]]
    found = [
        f"{r['sample']} \u03b8i={r['theta_i']:g}: \u03c1={r['model']:.4g}"
        for r in rows
        if not r["off_plane"] and not r["energy_ok"] and r.get("model") is not None
    ]
    if found:
        b.text(
            "Finding, not a check: at these angles the rows lie in the plane of incidence only, "
            "so the fitted model's hemispherical integral extrapolates off the plane and "
            "exceeds 1: " + "; ".join(found) + "."
        )
    if not covered:
        b.skip(
            "brdf.energy",
            "model integral \u2264 1 (energy) at every measured angle of incidence",
            "every angle's rows lie in the plane of incidence: the data do not constrain the "
            "model over the hemisphere (the table shows \u03c1 as a finding)",
            against="directional-hemispherical reflectance of each per-incidence fit",
        )
        return
    bad = [
        f"{r['sample']} \u03b8i={r['theta_i']:g}: \u03c1={r['model']}"
        for r in covered
        if not r["energy_ok"]
    ]
    worst = max((r["model"] for r in covered if r.get("model") is not None), default=None)
    b.check(
        "brdf.energy",
        "model integral \u2264 1 (energy) at every measured angle of incidence with rows off "
        "the plane of incidence",
        not bad,
        against="directional-hemispherical reflectance of each per-incidence fit",
        value=worst,
        tolerance=1.0,
        justification="a passive surface reflects at most the incident power; the quadrature "
        "is accurate to 1e-6 relative, far below any margin that matters here; "
        f"{len(covered)} of {len(rows)} angles have rows off the plane",
        reason="; ".join(bad)[:1000],
    )


def _span(rows: Sequence[Mapping[str, Any]], key: str) -> str:
    v = [r[key] for r in rows if r.get(key) is not None]
    return f"{min(v):+.4f} to {max(v):+.4f}" if v else "n/a"


def _energy_sentence(rows: Sequence[Mapping[str, Any]]) -> str:
    """Why the energy columns differ, with this report's numbers."""
    misfit = [
        r["model_grid"] - r["grid"]
        for r in rows
        if r.get("model_grid") is not None and r.get("grid") is not None
    ]
    outside = [r["model_outside"] for r in rows if r.get("model_outside") is not None]
    dominated = sum(abs(a) > abs(b) for a, b in zip(misfit, outside, strict=True))
    unc = _span(rows, "uncovered").replace("+", "")
    return (
        "Why the columns differ: model \u03c1 - grid = (model on grid - grid) + (model \u03c1 - "
        "model on grid). The first term is the misfit on the measured directions ("
        + (f"{min(misfit):+.4f} to {max(misfit):+.4f}" if misfit else "n/a")
        + "); the second is what the model puts where the grid has no cells ("
        + _span(rows, "model_outside")
        + f"): the uncovered part of the hemisphere ({unc} of it) grows with \u03b8i because "
        "the radial range about the specular direction leaves more of the horizon side out. "
        f"Here the misfit is the larger term at {dominated} of {len(misfit)} angles (relative "
        "weighting gives the many low off-specular points as much weight as the peak). "
        "The file's TIS is the instrument's own integral (finer native sampling, its own "
        "treatment of the horizon), so it need not equal either; TIS / grid shows by how much."
    )


def _reciprocity(ctx: Context, fits: Sequence[tuple[float | None, FitRecord]]) -> None:
    b = ctx.b
    rows = []
    recips = []
    for ti, r in fits:
        if ti is not None or not r.values:
            continue
        m = models.get(r.model, **r.options)
        recip = bool(m.is_reciprocal(r.values))
        recips.append(recip)
        for a, c, ph in RECIP_PAIRS:
            fab = float(_evaluate(r, a, c, ph))
            fba = float(_evaluate(r, c, a, ph))
            scale = max(abs(fab), abs(fba))
            rows.append(
                {
                    "sample": r.sample,
                    "wavelength_nm": r.wavelength_nm,
                    "pair": f"({a:g}, {c:g}, {ph:g})",
                    "f_ab": fab,
                    "f_ba": fba,
                    "rel": abs(fab - fba) / scale if scale > 0 else 0.0,
                }
            )
        rd = integrate.reciprocity_defect(m, r.values)
        rows.append(
            {
                "sample": r.sample,
                "wavelength_nm": r.wavelength_nm,
                "pair": f"grid max at ({rd.theta_i_deg:g}, {rd.theta_r_deg:g}, {rd.phi_r_deg:g})",
                "f_ab": None,
                "f_ba": None,
                "rel": rd.max_rel,
            }
        )
    if not rows:
        b.note("reciprocity", "no joint fit with values")
        return
    b.table(
        "brdf_reciprocity",
        "Reciprocity of the joint fit: f(a \u2192 b) against f(b \u2192 a)",
        [
            ("sample", "sample", ""),
            ("wavelength_nm", "\u03bb [nm]", "g"),
            ("pair", "(\u03b8a, \u03b8b, \u03c6) [deg]", ""),
            ("f_ab", "f(\u03b8i=\u03b8a, \u03b8r=\u03b8b) [sr\u207b\u00b9]", ".5g"),
            ("f_ba", "f(\u03b8i=\u03b8b, \u03b8r=\u03b8a) [sr\u207b\u00b9]", ".5g"),
            ("rel", "relative difference [1]", ".2g"),
        ],
        rows,
        caption="Modelled only: the joint fit evaluated with incidence and scatter directions "
        "swapped (same relative azimuth \u03c6); the last row per fit is the largest "
        "relative defect on a 5 deg x 15 deg grid up to 85 deg "
        "(labbrdf.integrate.reciprocity_defect).",
    )
    name = fits[0][1].model
    general = models.MODELS[name].reciprocity_note if name in models.MODELS else ""
    b.text(
        (general + " " if general else "")
        + (
            "For the fitted parameters the defect is float round-off: the joint fit is reciprocal."
            if all(recips)
            else "The fitted parameters are not reciprocal; the defect above is a property of "
            "the model, not of the data."
        )
    )
