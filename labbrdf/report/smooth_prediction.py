"""The prediction section's theory choice by the Rayleigh criterion, and its Rayleigh-Rice part.

A sample smooth by the Rayleigh criterion (the verdict section ``smoothness`` tabulates:
:func:`labbrdf.report.roughness.judge`, sigma of the roughness that scatters against
``lambda / (8 cos theta_i)``) scatters as first-order perturbation theory says; the
microfacet tracer's facets need ``k sigma > 1``. Per measured ``.bsdf``:

* smooth at every angle of incidence: Rayleigh-Rice from the composite PSD of the sample's
  height maps, the spectrum the PSD section shows (:mod:`labbrdf.rr_prediction`), no
  tracer; for a coated sample with a film fit, Rayleigh-Rice of the fitted stack with every
  interface carrying the map's roughness (correlated: a conformal coating);
* rough at every angle: the tracer (as before), no Rayleigh-Rice;
* anything else (undecided within sigma's uncertainty, or smooth at some angles and rough at
  others, or outside the map's band): both, and the page says which applies where.

The Rayleigh-Rice part also solves the inverse problem: the ``rayleigh_rice`` model
(K-correlation PSD, the psi/Delta's n, k or the film fit's stack fixed) fitted to the
measured BRDF, its PSD drawn beside the height maps' over their common frequencies.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..adapters import zemax_bsdf
from ..errors import LabbrdfError
from ..prediction import PredictionError
from ..roughness.rr_stack import stack_layers
from ..rr_prediction import (
    MapPsd,
    RrPrediction,
    bragg_band,
    group_psd,
    predict_rr_brdf,
    psd_agreement,
)
from . import figures
from .context import Context
from .roughness import judge, map_roughness

__all__ = [
    "FIT_FLOOR",
    "THEORIES",
    "Theory",
    "choose",
    "choose_theory",
    "given_wavelength",
    "rr_part",
]

#: the section's choices: Rayleigh-Rice, the microfacet tracer, or both
THEORIES = ("rayleigh-rice", "tracer", "both")

#: measured points below this fraction of the file's peak are left out of the inverse fit
FIT_FLOOR = 1e-6


@dataclass(frozen=True)
class Theory:
    """Which theory predicts one ``.bsdf`` file, and the page's sentence saying why."""

    choice: str
    text: str
    rows: tuple[dict[str, Any], ...] = ()


def choose(verdicts: Sequence[str]) -> str:
    """``rayleigh-rice`` if all verdicts are smooth, ``tracer`` if all are rough, else both."""
    v = set(verdicts)
    if v == {"smooth"}:
        return "rayleigh-rice"
    if v == {"rough"}:
        return "tracer"
    return "both"


def _angles_text(rows: Sequence[dict[str, Any]], verdict: str) -> str:
    return ", ".join(f"{r['theta_i']:g}" for r in rows if r["rayleigh"] == verdict)


def _why(choice: str, rows: Sequence[dict[str, Any]]) -> str:
    if choice == "rayleigh-rice":
        return (
            "Smooth at every angle: first-order perturbation (Rayleigh-Rice) theory applies and "
            "predicts the scatter from the height map's PSD; the microfacet tracer, whose "
            "facets need k sigma > 1, is not used."
        )
    if choice == "tracer":
        return (
            "Rough at every angle: the microfacet tracer applies (geometric optics on facets); "
            "Rayleigh-Rice, first order in k sigma, does not."
        )
    parts = [
        f"{word} at {a} deg"
        for word in ("smooth", "rough", "undecided")
        if (a := _angles_text(rows, word))
    ]
    other = [r for r in rows if r["rayleigh"] not in ("smooth", "rough", "undecided")]
    if other:
        angles = ", ".join(f"{r['theta_i']:g}" for r in other)
        parts.append(f"not judged at {angles} deg")
    return (
        f"Between the two ({'; '.join(parts)}): both predictions are shown. Rayleigh-Rice "
        "applies where the verdict is smooth, the tracer where it is rough; where it is "
        "undecided (sigma's 95 % interval straddles the threshold) neither is assured."
    )


def given_wavelength(ctx: Context, path: Path) -> float | None:
    """The wavelength [nm] ``report --wavelength`` gave a ``.bsdf`` that states none."""
    given = [
        float(r["meta"]["wavelength_nm"])
        for r in ctx.files
        if (r.get("meta") or {}).get("wavelength_given")
        and Path(str(r["path"])).name == Path(path).name
    ]
    return given[0] if given else None


def choose_theory(
    ctx: Context, hm: Any, path: Path, *, coated: bool = False, stack: Any = None
) -> Theory:
    """The theory for one measured ``.bsdf`` of the sample whose height map is ``hm``.

    ``coated``: the sample has a film fit, whose ``stack`` (a ``labbrdf.films.Stack``)
    Rayleigh-Rice takes if it can (coherent layers); else only the tracer predicts it.
    """
    name = Path(path).name
    try:
        t = zemax_bsdf.read_table(path)
    except (LabbrdfError, ValueError, OSError):
        return Theory("tracer", f"{name}: not read, so not judged by the Rayleigh criterion.")
    m = map_roughness(ctx).get(str(hm.path))
    wl_file = t.wavelength_nm if t.wavelength_nm is not None else given_wavelength(ctx, path)
    if wl_file is None or m is None:
        why = "states no wavelength" if wl_file is None else "has no usable height map"
        return Theory(
            "tracer",
            f"{name} {why}: the Rayleigh criterion cannot be applied; the microfacet tracer's "
            "prediction is tried.",
        )
    wl = float(wl_file)
    rows = tuple(judge(m, wl, float(ti)) for ti in t.theta_i_deg)
    choice = choose([r["rayleigh"] for r in rows])
    sig = [r["sigma_nm"] for r in rows if "sigma_nm" in r]
    sig_text = (
        f"sigma of the roughness that scatters {min(sig):.3g} to {max(sig):.3g} nm"
        if sig
        else "no sigma in the band that scatters"
    )
    thr = [r["thr_rayleigh"] for r in rows]
    text = (
        f"Theory for {name} at {wl:g} nm, by the Rayleigh criterion (section smoothness): "
        f"{sig_text} from {m.name}, against lambda / (8 cos theta_i) = {min(thr):.3g} to "
        f"{max(thr):.3g} nm over the file's {len(rows)} angles of incidence. " + _why(choice, rows)
    )
    if coated and choice != "tracer":
        why = _stack_refused(stack, wl)
        if why:
            text += (
                f" The sample is coated (a film fit) and {why}: only the tracer's prediction "
                "is shown."
            )
            choice = "tracer"
        else:
            text += (
                " The sample is coated (a film fit): Rayleigh-Rice is that of the fitted "
                "stack, every interface carrying the height map's roughness with the same "
                "heights (correlated: a conformal coating; docs: rayleigh-rice)."
            )
    return Theory(choice, text, rows)


def _stack_refused(stack: Any, wavelength_nm: float) -> str:
    """Why Rayleigh-Rice cannot take the film fit's stack ("" when it can)."""
    if stack is None:
        return "its stack is not at hand"
    try:
        stack_layers(stack, wavelength_nm)
    except (LabbrdfError, ValueError) as exc:
        return f"Rayleigh-Rice of rough interfaces cannot take its stack ({exc})"
    return ""


# --------------------------------------------------------------------------- drawing


def _cuts(ctx: Context, sid: str, p: RrPrediction) -> None:
    panels = []
    n = p.theta_i_deg.size
    for a in sorted({int(round(v)) for v in np.linspace(0, n - 1, min(n, 4))}):
        pr = np.mod(p.phi_r_deg[a], 360.0)
        fwd = p.above[a] & (np.abs(pr - 180.0) < 0.5)
        back = p.above[a] & (np.minimum(pr, 360.0 - pr) < 0.5) & ~fwd
        x = np.concatenate([p.theta_r_deg[a][fwd], -p.theta_r_deg[a][back]])
        order = np.argsort(x)
        ym = np.concatenate([p.measured[a][fwd], p.measured[a][back]])[order]
        yp = np.concatenate([p.predicted[a][fwd], p.predicted[a][back]])[order]
        x = x[order]
        panels.append(
            {
                "title": f"\u03b8i = {p.theta_i_deg[a]:g}\u00b0",
                "xlabel": "signed \u03b8r [deg] (+: specular side)",
                "ylabel": "BRDF [sr\u207b\u00b9]",
                "logy": True,
                "series": [
                    {"label": "measured", "x": x[ym > 0], "y": ym[ym > 0], "style": "points"},
                    {
                        "label": "Rayleigh-Rice (no fit)",
                        "x": x,
                        "y": np.where(yp > 0, yp, np.nan),
                        "style": "line",
                    },
                ],
            }
        )
    ctx.b.figure(
        f"prediction_rr_cuts_{sid}",
        f"In-plane cuts, measured and Rayleigh-Rice, {Path(p.path).name}",
        "The plane of incidence at the file's points: measured (phi_r = 180 deg positive, "
        "0 deg negative) and the Rayleigh-Rice BRDF from the height maps' PSD and "
        + ("the film fit's stack" if p.coating else "the psi/Delta's n, k")
        + " (line; absent where the point's spatial frequency lies outside the maps' band, "
        "where the PSD is taken as 0).",
        figures.panels_figure(panels, ncols=min(4, len(panels)), panel_size=(4.0, 3.0)),
    )


def _table(ctx: Context, sid: str, p: RrPrediction) -> None:
    ctx.b.table(
        f"prediction_rr_tis_{sid}",
        "Rayleigh-Rice: TIS on the file's grid, measured and predicted",
        [
            ("theta_i_deg", "AOI [deg]", ".4g"),
            ("tis_measured", "TIS measured (grid) [1]", ".4g"),
            ("tis_predicted", "TIS Rayleigh-Rice (grid) [1]", ".4g"),
            ("ratio", "predicted / measured", ".3g"),
            ("points", "measured points > 0", "d"),
            ("in_band", "of them in the map's band", "d"),
            ("band_ratio", "predicted / measured, in the band", ".3g"),
        ],
        p.table().to_dict("records"),
        caption="Both TIS columns are the same grid quadrature "
        "(labbrdf.integrate.grid_integral) of the file's points; 'in the map's band': points "
        "whose spatial (Bragg) frequency the height map resolves (elsewhere its PSD is 0); "
        "the last column integrates those points only.",
    )


def _inverse(ctx: Context, sid: str, p: RrPrediction, psd: MapPsd, stack: Any = None) -> None:
    """The ``rayleigh_rice`` model fitted to the .bsdf; its PSD beside the maps'."""
    from .. import adapters
    from ..fitting import fit
    from ..models.rayleigh_rice import RayleighRice

    b = ctx.b
    name = Path(p.path).name
    try:
        data = adapters.read(p.path).data
        rows = data[data["quantity"] == "brdf"]
        off = ~(
            np.isclose(rows["theta_r_deg"], rows["theta_i_deg"], atol=0.5)
            & (np.abs(np.mod(rows["phi_r_deg"], 360.0) - 180.0) < 0.5)
        )
        # points below 1e-6 of the peak carry only the file's rounding
        rows = rows[off & (rows["value"] >= FIT_FLOOR * rows["value"].max())]
        if stack is None:
            model = RayleighRice(n=p.n, k=p.k, wavelength_nm=p.wavelength_nm)
        else:
            model = RayleighRice(film=stack, wavelength_nm=p.wavelength_nm)
        res = fit(model, rows, weighting="relative")
        band = bragg_band(
            rows["theta_i_deg"], rows["theta_r_deg"], rows["phi_r_deg"], p.wavelength_nm
        )
    except (LabbrdfError, ValueError) as exc:
        b.note(f"{name}: PSD not recovered from the BRDF", str(exc))
        return
    agree = psd_agreement(model.psd2d(res.values), "k-correlation", psd, band)
    b.text(
        "The inverse problem: the rayleigh_rice model (K-correlation PSD, "
        f"{'the stack' if stack is not None else 'n, k'} fixed as above) "
        f"fitted to the {len(rows)} measured points of {name} off the specular direction and "
        f"above {FIT_FLOOR:g} of the peak (relative weighting). " + agree.sentence()
    )
    b.table(
        f"prediction_rr_fit_{sid}",
        "K-correlation PSD recovered from the BRDF",
        [
            ("name", "parameter", ""),
            ("value", "value", ".4g"),
            ("stderr", "SE", ".2g"),
            ("units", "units", ""),
        ],
        [
            {"name": k, "value": v.value, "stderr": v.stderr, "units": v.units}
            for k, v in res.params.items()
        ],
        caption="A / (1 + (B f)^2)^((C+1)/2) (labbrdf.roughness.psd_models), A in um^4, B in "
        f"um; rms relative residual {math.sqrt(res.redchi):.3g}.",
    )
    if agree.f.size:
        b.figure(
            f"prediction_rr_psd_{sid}",
            f"PSD from the BRDF and from the height map, {name}",
            "Isotropic 2-D PSD over the frequencies both see: the height maps' (points, the "
            "composite of section psd) and the K-correlation "
            "PSD fitted to the measured BRDF (line). " + agree.sentence(),
            figures.to_uri(agree.plot()),
        )


def rr_part(ctx: Context, sid: str, maps: Any, path: Path, frame: Any, film: Any = None) -> None:
    """Rayleigh-Rice prediction of one ``.bsdf`` from the maps' composite PSD, and the inverse.

    ``maps``: the sample's areal height maps (or one); ``film``: its film fit, whose stack
    replaces the psi/Delta's n, k (:func:`labbrdf.rr_prediction.predict_rr_brdf`).
    """
    b = ctx.b
    name = Path(path).name
    maps = list(maps) if isinstance(maps, (list, tuple)) else [maps]
    stack = None if film is None else film.stack
    data = getattr(film, "data", None)
    span = None
    if data is not None and "wavelength_nm" in data and len(data):
        w = np.asarray(data["wavelength_nm"], float)
        span = (float(np.nanmin(w)), float(np.nanmax(w)))
    try:
        psd = group_psd(maps)
        p = predict_rr_brdf(
            path,
            frame,
            psd,
            wavelength_nm=given_wavelength(ctx, path),
            stack=stack,
            stack_range=span,
        )
    except (PredictionError, LabbrdfError, ValueError) as exc:
        b.note(f"{name}: no Rayleigh-Rice prediction", str(exc))
        return
    b.text(
        f"Rayleigh-Rice prediction of {name} at {p.wavelength_nm:g} nm, no parameter fitted: "
        + _optics_text(p)
        + "; "
        + _psd_text(psd)
        + " "
        + p.verdict()
    )
    _cuts(ctx, sid, p)
    _table(ctx, sid, p)
    _inverse(ctx, sid, p, psd, stack)


def _optics_text(p: RrPrediction) -> str:
    if not p.coating:
        return f"substrate n + ik = {p.n:.4g} + {p.k:.4g}i from the psi/Delta"
    return (
        f"the film fit's stack (top first: {p.coating}; substrate n + ik = {p.n:.4g} + "
        f"{p.k:.4g}i), every interface with the maps' roughness, correlated"
    )


def _psd_text(psd: MapPsd) -> str:
    names = [Path(s.strip()).name for s in psd.source.split(",")]
    what = (
        f"the PSD of {names[0]}"
        if len(names) == 1
        else f"the composite PSD of {len(names)} maps ({', '.join(names)})"
    )
    gaps = "".join(
        f" and in the gap {lo:.3g} to {hi:.3g} cycles/m that no map covers" for lo, hi in psd.gaps
    )
    return (
        f"{what}, the spectrum of section psd (SurfaceTopography's periodogram of each "
        f"plane-levelled map, Hann window), over the band {psd.f_min:.3g} to "
        f"{psd.f_max:.3g} cycles/m (periods {1e6 / psd.f_max:.3g} to {1e6 / psd.f_min:.3g} um; "
        f"sigma over the band {psd.sigma() * 1e9:.3g} nm), 0 outside it{gaps}."
    )
