"""Section ``prediction``: predict, then measure (user report).

For every sample (files grouped by :mod:`labbrdf.samples`: the sample names the files state,
or ``--same-sample``) that has an areal height map, a psi/Delta file and a measured ``.bsdf``,
the tracer predicts with NO parameter fitted to the BRDF (:mod:`labbrdf.prediction`): the
roughness from the height map, the substrate's n, k from the psi/Delta. Where section
``film`` fitted a one-layer stack to the sample's psi/Delta (:attr:`Context.film_fits`), that
layer is the tracer's coating (its index at the ``.bsdf`` wavelength and its thickness,
incoherent as ``labbrdf trace --coating-from`` builds it) and the fit's substrate the
substrate: the two-phase n, k of a coated sample's psi/Delta are no material's. The height
map is taken as measured on the coating's top and the coating as conformal (the substrate
below has the same roughness).

The roughness is, by default, the GGX alpha of the map's slopes (maximum likelihood); with
``slopes="measured"`` (``--prediction-slopes measured``) the map's own slope table
(:meth:`labbrdf.Substrate.from_surface`, as ``labbrdf trace --surface``). GGX is the default
because the section is a test of a model with stated parameters: the alpha comes with its
uncertainty and a smooth tail, while the table of a finite map is its pixel-scale slopes,
with an empty tail beyond the steepest sampled slope and, on a coating's top, only the
noisier counting estimator (the evaluated one needs a GGX top). The measured table is the
check of GGX itself: where the two predictions differ, the slope distribution matters.

Each measured ``.bsdf`` is first judged by the Rayleigh criterion
(:mod:`labbrdf.report.smooth_prediction`): smooth at all its angles, it is predicted by
Rayleigh-Rice from the composite PSD of the sample's height maps (the spectrum of section
``psd``; with the PSD recovered from the BRDF beside it), for a coated sample through its
film fit's stack, and the tracer is not run; rough, by the tracer; in between, by both.

For the tracer, the section draws

* the specular DOP for unpolarized light, ellipsometer (|cos 2psi|, with its depolarization
  channel) beside the tracer's specular bin with its batch error, per wavelength against
  the angle of incidence (Dong et al. 2022, Fig. 6), and a table;
* the predicted BRDF beside the measured one: hemisphere maps and relative residuals, the
  in-plane cuts with the prediction's Monte Carlo band, the TIS of each by the same grid
  quadrature, and a sentence saying where and by how much the prediction misses.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ...prediction import (
    BrdfPrediction,
    DopComparison,
    PredictionError,
    predict_brdf,
    roughness_alpha,
    slope_table,
    specular_dop_comparison,
)
from .. import figures
from ..builder import Unavailable, slug
from ..context import Context
from ..smooth_prediction import choose_theory, rr_part
from ..tracing import rays_of, tracer_map

__all__ = ["SLOPES", "prediction_section", "sample_inputs"]

#: |z| above which a tracer DOP is called inconsistent with the ellipsometer's
DOP_Z_MAX = 3.0
#: the roughness models the section offers (module docstring)
SLOPES = ("ggx", "measured")


def _frame_of(ctx: Context, path: Path) -> pd.DataFrame | None:
    """The ingested rows of one file (by its ``source`` name); None if none or ambiguous.

    Two inputs of the same name in different folders cannot be told apart by their rows'
    ``source``, so neither is used rather than the wrong one.
    """
    found = [f for f in ctx.frames if len(f) and set(f["source"].astype(str)) == {path.name}]
    return found[0] if len(found) == 1 else None


def sample_inputs(ctx: Context) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """The sample groups that can be predicted, and the others with what they lack.

    Returns
    -------
    (ready, lacking)
        ``ready``: ``{"name", "reason", "height_map", "psi_delta" (path, frame),
        "film" (its film fit or None), "bsdf" [paths]}``; ``lacking``: ``{"sample",
        "files", "missing"}``.
    """
    maps = {str(Path(h.path)): h for h in ctx.height_maps if not h.is_profile}
    bsdf = {
        str(Path(f["path"]))
        for f in ctx.files
        if (f.get("meta") or {}).get("format") == "zemax-bsdf"
    }
    ready, lacking = [], []
    for g in ctx.samples:
        paths = [Path(p) for p in g.paths]
        hms = [maps[str(p)] for p in paths if str(p) in maps]
        psi = []
        for p in paths:
            fr = _frame_of(ctx, p)
            if fr is not None and (fr["quantity"].astype(str) == "psi").any():
                psi.append((p, fr))
        # a psi/Delta file with a film fit first: its stack is the sample's
        psi.sort(key=lambda pf: pf[0].name not in ctx.film_fits)
        bs = [p for p in paths if str(p) in bsdf]
        missing = [
            what
            for what, have in (
                ("an areal height map", hms),
                ("a psi/Delta file", psi),
                ("a .bsdf BRDF", bs),
            )
            if not have
        ]
        if missing:
            lacking.append(
                {
                    "sample": g.name,
                    "files": ", ".join(p.name for p in paths),
                    "missing": ", ".join(missing),
                }
            )
            continue
        ready.append(
            {
                "name": g.name,
                "reason": g.reason,
                "height_map": hms[0],
                "height_maps": hms,
                "psi_delta": psi[0],
                "film": ctx.film_fits.get(psi[0][0].name),
                "bsdf": bs,
                "unused": [Path(h.path).name for h in hms[1:]] + [p.name for p, _ in psi[1:]],
            }
        )
    return ready, lacking


def prediction_section(ctx: Context, *, slopes: str = "ggx") -> None:
    """One part per sample with a height map, psi/Delta and a measured BRDF.

    Parameters
    ----------
    ctx : Context
    slopes : {"ggx", "measured"}
        The roughness traced: the GGX alpha of the height map's slopes, or their measured
        table (module docstring).

    Raises
    ------
    ValueError
        ``slopes`` of another value.
    """
    if slopes not in SLOPES:
        raise ValueError(f"slopes: expected one of {', '.join(SLOPES)}, got {slopes!r}")
    b = ctx.b
    ready, lacking = sample_inputs(ctx)
    if not ready:
        why = "; ".join(f"{r['sample']} lacks {r['missing']}" for r in lacking) or "no samples"
        raise Unavailable(
            "needs an areal height map, a psi/Delta file and a .bsdf BRDF of ONE sample "
            f"(paired by the sample names in the files or --same-sample); {why}"
        )
    rough = (
        "the GGX roughness alpha of the maximum-likelihood fit of the height map's slopes "
        "(the measured slope table: --prediction-slopes measured)"
        if slopes == "ggx"
        else "the height map's measured slope table (its GGX alpha, the maximum-likelihood "
        "fit, only sets the width of the specular lobe in the tables)"
    )
    b.text(
        "Predict, then measure: the Monte Carlo polarization tracer (single scattering; "
        "evaluated estimator, counted where a coating's top is a measured table) predicts "
        "the sample's BRDF and specular DOP with no parameter fitted to them. The roughness "
        f"is {rough}; the substrate's n, k are the two-phase inversion of the psi/Delta, "
        "combined over the angles of incidence, or, where section film fitted a one-layer "
        "stack to the sample's psi/Delta, the stack's substrate, with its layer as an "
        "incoherent coating (conformal: the height map is taken as measured on the "
        "coating's top, the substrate below as equally rough). A disagreement is therefore "
        "a finding about the model (single scattering, the slope distribution, the stack) "
        "or the samples, not a fit residual. Monte Carlo errors are the spread of the "
        f"tracer's 8 independent batches ({rays_of(ctx)} rays per run; a bare substrate's "
        "single scattering is closed form and has none). Which theory predicts each measured "
        "BRDF is chosen by the Rayleigh criterion of section smoothness at the file's "
        "wavelength and angles: a smooth sample is predicted by Rayleigh-Rice (first-order "
        "perturbation theory) from the composite PSD of its height maps (section psd's), "
        "through its film fit's stack where it has one, instead of the tracer, a sample in "
        "between by both (docs/rayleigh-rice.md)."
    )
    if lacking:
        b.table(
            "prediction_not_predicted",
            "Samples without a prediction",
            [("sample", "sample", ""), ("files", "files", ""), ("missing", "missing", "")],
            lacking,
        )
    for s in ready:
        _one_sample(ctx, s, slopes)


def _one_sample(ctx: Context, s: dict[str, Any], slopes: str = "ggx") -> None:
    b = ctx.b
    sid = slug(s["name"])
    hm = s["height_map"]
    psi_path, frame = s["psi_delta"]
    film = s.get("film")
    b.heading(f"Sample {s['name']}", anchor=f"prediction-{sid}")
    try:
        fit = roughness_alpha(hm)
        ndf = slope_table(hm) if slopes == "measured" else None
    except PredictionError as exc:
        b.note("not predicted", str(exc))
        return
    b.text(
        f"Files: {Path(hm.path).name} (height map), {psi_path.name} (psi/Delta), "
        f"{', '.join(p.name for p in s['bsdf'])} (measured BRDF); {s['reason']}. GGX alpha "
        f"from the height map: {fit.alpha:.4g} +- {fit.alpha_u:.2g}"
        + ("; traced: the map's measured slope table." if ndf is not None else ".")
        + (
            f" Not used (the first height map and psi/Delta file are): {', '.join(s['unused'])}."
            if s["unused"]
            else ""
        )
        + (
            " Rayleigh-Rice, where it applies, takes the composite PSD of all "
            f"{len(s['height_maps'])} height maps."
            if len(s.get("height_maps", ())) > 1
            else ""
        )
    )
    if film is not None:
        b.text(
            f"{psi_path.name} has a film fit (section film): the substrate is the fit's, the "
            "coating its layer (per .bsdf file below)."
        )
        b.note(
            "specular DOP not compared",
            f"{psi_path.name} is the psi/Delta of a coated sample: the ellipsometer's "
            "|cos 2psi| is the coherent film's, while the tracer's coating is incoherent "
            "(intensities add, which depolarizes), so the two DOPs differ by construction.",
        )
    stack = None if film is None else getattr(film, "stack", None)
    theories = [choose_theory(ctx, hm, p, coated=film is not None, stack=stack) for p in s["bsdf"]]
    if film is None and all(t.choice == "rayleigh-rice" for t in theories):
        b.text(
            "The sample is smooth (below): its specular reflection is the Fresnel reflection "
            f"of its n, k, whose DOP is the |cos 2psi| of {psi_path.name} itself, so the "
            "tracer's specular DOP is not computed."
        )
    elif film is None:
        try:
            dop = specular_dop_comparison(
                frame, fit.alpha, rays=rays_of(ctx), seed=ctx.seed, map=tracer_map(ctx)
            )
        except PredictionError as exc:
            b.note("specular DOP not predicted", str(exc))
        else:
            _dop_part(ctx, sid, dop)
    for path, theory in zip(s["bsdf"], theories, strict=True):
        b.text(theory.text)
        if theory.choice in ("tracer", "both"):
            _tracer_brdf(ctx, sid, path, frame, fit, film, ndf)
        if theory.choice in ("rayleigh-rice", "both"):
            maps = s.get("height_maps") or [hm]
            rr_part(ctx, f"{sid}_{slug(path.name)}", maps, path, frame, film)


def _tracer_brdf(
    ctx: Context, sid: str, path: Path, frame: Any, fit: Any, film: Any, ndf: Any
) -> None:
    """The microfacet tracer's prediction of one ``.bsdf`` file and its part of the page."""
    given = [
        r["meta"]["wavelength_nm"]
        for r in ctx.files
        if r.get("meta", {}).get("wavelength_given") and Path(str(r["path"])).name == path.name
    ]
    try:
        pred = predict_brdf(
            path,
            frame,
            fit,
            film=film,
            wavelength_nm=given[0] if given else None,
            ndf=ndf,
            rays=rays_of(ctx),
            seed=ctx.seed,
            map=tracer_map(ctx),
        )
    except (PredictionError, ValueError) as exc:
        ctx.b.note(f"{path.name} not predicted", str(exc))
        return
    _brdf_part(ctx, f"{sid}_{slug(path.name)}", pred)


# --------------------------------------------------------------------------- DOP


def _dop_part(ctx: Context, sid: str, c: DopComparison) -> None:
    b = ctx.b
    t = c.table
    panels = []
    for wl, g in t.groupby("wavelength_nm", sort=True):
        e = c.ellipsometer[np.isclose(c.ellipsometer["wavelength_nm"], wl, atol=1e-3)]
        panels.append(
            {
                "title": f"{wl:g} nm",
                "xlabel": "angle of incidence [deg]",
                "ylabel": "specular DOP, unpolarized incidence [1]",
                "series": [
                    {
                        "label": "ellipsometer |cos 2psi| (+-1 sigma)",
                        "x": e["theta_i_deg"],
                        "y": e["dop"],
                        "band": e["dop_sigma"],
                        "style": "line",
                    },
                    {
                        "label": "tracer, specular bin (+-1 SE)",
                        "x": g["theta_i_deg"],
                        "y": g["dop_tracer"],
                        "yerr": g["dop_tracer_stderr"],
                        "style": "points",
                    },
                ],
            }
        )
    b.figure(
        f"prediction_dop_{sid}",
        "Specular DOP: ellipsometer against the tracer's prediction",
        "Degree of polarization of the specular reflection for unpolarized light (Dong et "
        "al. 2022, Fig. 6). Line (measured): from the ellipsometer's psi, DOP = |cos 2psi| (times "
        "1 - depolarization where the file has a depolarization channel at that angle: a "
        "partial depolarizer mixed in; a negative depolarization, noise about 0, counts as "
        "0), band +-1 sigma from sigma(psi). Points (modelled): the tracer's "
        "DOP in the bin holding the specular direction, with the batch standard error. For "
        "a bare substrate in single scattering the specular facets are the mean plane, so the "
        "tracer gives |cos 2psi| of the same n, k: a difference is the ellipsometer's "
        "depolarization or the bin average, not the n, k.",
        figures.panels_figure(panels, ncols=min(4, len(panels)), panel_size=(4.0, 3.0)),
    )
    rows = t.to_dict("records")
    b.table(
        f"prediction_dop_{sid}",
        "Specular DOP, ellipsometer and tracer",
        [
            ("wavelength_nm", "wavelength [nm]", ".6g"),
            ("theta_i_deg", "AOI [deg]", ".4g"),
            ("n", "n", ".4g"),
            ("k", "k", ".4g"),
            ("dop_ellipsometer", "DOP ellipsometer", ".4f"),
            ("dop_ellipsometer_sigma", "u", ".2g"),
            ("depolarization", "depolarization", ".3g"),
            ("dop_tracer", "DOP tracer", ".4f"),
            ("dop_tracer_stderr", "SE", ".2g"),
            ("z", "z", ".2f"),
        ],
        rows,
        caption="z = (tracer - ellipsometer) / sqrt(SE^2 + u^2); NaN where both are 0.",
    )
    z = np.abs(t["z"].to_numpy(float))
    zmax = float(np.nanmax(z)) if np.isfinite(z).any() else 0.0
    b.check(
        f"prediction.dop.{sid}",
        "the tracer's specular DOP agrees with the ellipsometer's",
        zmax <= DOP_Z_MAX,
        against="DOP = |cos 2psi| (x (1 - depolarization)) from the psi/Delta file",
        value=zmax,
        tolerance=DOP_Z_MAX,
        justification="|z| <= 3 at every wavelength and angle: three combined standard errors",
    )


# --------------------------------------------------------------------------- BRDF


def _brdf_part(ctx: Context, sid: str, p: BrdfPrediction) -> None:
    b = ctx.b
    name = Path(p.path).name
    b.text(f"{name} at {p.wavelength_nm:g} nm: {_inputs_text(p)}")
    b.text(p.verdict())
    _maps(ctx, sid, p)
    _cuts(ctx, sid, p)
    _tables(ctx, sid, p)
    reg = p.regions()
    worst = float(np.nanmax(np.abs(reg["ratio"].to_numpy(float) - 1.0)))
    b.check(
        f"prediction.brdf.{sid}",
        f"the prediction of {name} agrees with the measurement within its Monte Carlo error",
        bool(reg["consistent"].all()),
        against=f"{name} (measured BRDF, no parameter fitted to it)",
        value=worst,
        tolerance="3 SE + 1e-5",
        justification="integrated scatter of the specular lobe and of the rest, per angle "
        "of incidence: |ratio - 1| <= 3 Monte Carlo SE + the file's rounding",
    )


def _inputs_text(p: BrdfPrediction) -> str:
    """Which substrate, coating and roughness went into a prediction, in words."""
    rough = (
        f"the height map's measured slope table (GGX alpha {p.alpha:.4g})"
        if p.slopes == "measured"
        else f"GGX alpha = {p.alpha:.4g}"
    )
    if p.index_from == "film fit" and p.coating is not None:
        c = p.coating
        return (
            f"substrate n + ik = {p.n:.4g} + {p.k:.4g}i (the film fit's substrate); coating "
            f"n + ik = {c['n']:.4g} + {c['k']:.4g}i, {c['thickness_nm']:.4g} nm thick (the "
            "film fit's layer, incoherent); both interfaces rough as the height map "
            f"(conformal coating, the map taken as measured on its top): {rough}; "
            f"{p.rays} rays per angle of incidence, {p.seconds:.1f} s of tracing."
        )
    return (
        f"bare substrate n + ik = {p.n:.4g} + {p.k:.4g}i (+- {p.n_sigma:.2g}, "
        f"{p.k_sigma:.2g}) from the psi/Delta, {rough}; {p.rays} rays per angle of "
        f"incidence, {p.seconds:.1f} s of tracing."
    )


def _pick(n: int, most: int = 4) -> list[int]:
    return sorted({int(round(v)) for v in np.linspace(0, n - 1, min(n, most))})


def _maps(ctx: Context, sid: str, p: BrdfPrediction) -> None:
    panels = []
    for a in _pick(p.theta_i_deg.size):
        m = p.above[a]
        meas, pred = p.measured[a][m], p.predicted[a][m]
        with np.errstate(divide="ignore", invalid="ignore"):
            res = np.where(meas > 0, (pred - meas) / meas, np.nan)
        panels.append(
            {
                "label": f"\u03b8i = {p.theta_i_deg[a]:g}\u00b0",
                "theta_r": p.theta_r_deg[a][m],
                "phi_r": p.phi_r_deg[a][m],
                "measured": meas,
                "model": pred,
                "model_label": "tracer prediction (no fit)",
                "residual_label": "(prediction - measured) / measured",
                "residual": res,
            }
        )
    ctx.b.figure(
        f"prediction_maps_{sid}",
        f"Measured and predicted BRDF, {Path(p.path).name}",
        "Projected hemisphere (x = theta_r cos phi_r, y = theta_r sin phi_r [deg]) at the "
        "file's grid points: measured BRDF, the tracer's prediction (no parameter fitted; "
        "log colour scale shared in a row) and the relative residual (prediction - "
        "measured) / measured, clipped to +-1. Up to four angles of incidence.",
        figures.brdf_maps_figure(panels),
    )


def _cuts(ctx: Context, sid: str, p: BrdfPrediction) -> None:
    panels = []
    for a in _pick(p.theta_i_deg.size):
        ti = float(p.theta_i_deg[a])
        pr = np.mod(p.phi_r_deg[a], 360.0)
        fwd = p.above[a] & (np.abs(pr - 180.0) < 0.5)
        back = p.above[a] & (np.minimum(pr, 360.0 - pr) < 0.5) & ~fwd
        x = np.concatenate([p.theta_r_deg[a][fwd], -p.theta_r_deg[a][back]])
        y = np.concatenate([p.measured[a][fwd], p.measured[a][back]])
        res = p.results[a]
        s0, se = res.s0(), res.mueller_stderr[..., 0, 0]
        th = res.theta_r_deg
        j180 = int(np.argmin(np.abs(res.phi_r_deg - 180.0)))
        gx = np.concatenate([-th[::-1], th])
        gy = np.concatenate([s0[::-1, 0], s0[:, j180]])
        gs = np.concatenate([se[::-1, 0], se[:, j180]])
        ok = y > 0
        panels.append(
            {
                "title": f"\u03b8i = {ti:g}\u00b0",
                "xlabel": "signed \u03b8r [deg] (+: specular side)",
                "ylabel": "BRDF [sr\u207b\u00b9]",
                "logy": True,
                "series": [
                    {"label": "measured", "x": x[ok], "y": y[ok], "style": "points"},
                    {
                        "label": "prediction (+-2 SE)",
                        "x": gx,
                        "y": np.where(gy > 0, gy, np.nan),
                        "band": 2.0 * gs,
                        "style": "line",
                    },
                ],
            }
        )
    ctx.b.figure(
        f"prediction_cuts_{sid}",
        f"In-plane cuts, measured and predicted, {Path(p.path).name}",
        "The plane of incidence: measured points (phi_r = 180 deg positive, 0 deg negative) "
        "and the tracer's bins along it (line, band +-2 Monte Carlo SE).",
        figures.panels_figure(panels, ncols=min(4, len(panels)), panel_size=(4.0, 3.0)),
    )


def _tables(ctx: Context, sid: str, p: BrdfPrediction) -> None:
    b = ctx.b
    rows = [
        {
            "theta_i_deg": float(ti),
            "tis_measured": float(p.tis_measured[a]),
            "tis_predicted": float(p.tis_predicted[a]),
            "tis_predicted_u": float(p.tis_predicted_stderr[a]),
            "ratio": float(p.tis_predicted[a] / p.tis_measured[a])
            if p.tis_measured[a] > 0
            else None,
            "tis_file": float(p.tis_file[a]),
            "albedo": float(p.albedo[a]),
            "albedo_u": float(p.albedo_stderr[a]),
            "uncovered": float(p.uncovered_fraction[a]),
        }
        for a, ti in enumerate(p.theta_i_deg)
    ]
    b.table(
        f"prediction_tis_{sid}",
        "Total integrated scatter: measured and predicted on the file's grid",
        [
            ("theta_i_deg", "AOI [deg]", ".4g"),
            ("tis_measured", "TIS measured (grid) [1]", ".4f"),
            ("tis_predicted", "TIS predicted (grid) [1]", ".4f"),
            ("tis_predicted_u", "SE", ".2g"),
            ("ratio", "predicted / measured", ".3f"),
            ("tis_file", "TIS in the file [1]", ".4f"),
            ("albedo", "tracer albedo (hemisphere) [1]", ".4f"),
            ("albedo_u", "SE", ".2g"),
            ("uncovered", "grid leaves uncovered [1]", ".3f"),
        ],
        rows,
        caption="Both TIS columns are the same first-order grid quadrature "
        "(labbrdf.integrate.grid_integral) of the file's points, so they compare like with "
        "like; the tracer's albedo also counts the directions the grid does not cover.",
    )
    b.table(
        f"prediction_regions_{sid}",
        "Specular lobe and off specular: integrated predicted / measured",
        [
            ("theta_i_deg", "AOI [deg]", ".4g"),
            ("region", "region", ""),
            ("points", "points", "d"),
            ("ratio", "predicted / measured", ".3f"),
            ("ratio_stderr", "SE", ".2g"),
            ("ratio_lo", "point ratio 10 %", ".3f"),
            ("ratio_hi", "point ratio 90 %", ".3f"),
            ("consistent", "within 3 SE", ""),
        ],
        p.regions().to_dict("records"),
        caption=f"Specular lobe: the file's points within {p.lobe_deg:.3g} deg of the "
        "specular direction (2 atan(alpha), at least 3 deg). Ratio of the grid integrals of "
        "the region; SE from the tracer's batches.",
    )
