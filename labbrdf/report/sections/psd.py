"""Section ``psd``: the power spectral density of every height map of a sample group.

For each sample group (:func:`labbrdf.samples.pair_samples`) holding height maps or
profiles: the PSD of each map over its band (:func:`labbrdf.psd`, through
SurfaceTopography's periodogram), the composite over the union of the bands with the
overlaps checked for agreement (Duparre et al. 2002), and a K-correlation (ABC) model fitted
to it with 95 % intervals; a figure, a table of the bands and one of the fitted parameters.
Conventions and method: ``docs/psd.md``.
"""

from __future__ import annotations

import math
from pathlib import Path

from ...adapters import AdapterError
from ...adapters.topography import HeightMap
from ...roughness.psd_result import PSDResult, draw_psd, psd
from .. import figures
from ..builder import Unavailable, slug
from ..context import Context

__all__ = ["FIT_MODEL", "psd_section"]

#: the model fitted to every composite
FIT_MODEL = "k-correlation"


def _groups(ctx: Context) -> list[tuple[str, list[HeightMap]]]:
    """(sample name, its height maps) for every group holding maps; loose maps alone."""
    out: list[tuple[str, list[HeightMap]]] = []
    seen: set[str] = set()
    for g in ctx.samples:
        keys = {str(Path(p)) for p in g.paths}
        mine = [hm for hm in ctx.height_maps if str(Path(hm.path)) in keys]
        if mine:
            out.append((g.name, mine))
            seen.update(str(Path(hm.path)) for hm in mine)
    for hm in ctx.height_maps:
        if str(Path(hm.path)) not in seen:
            out.append((Path(hm.path).name, [hm]))
    return out


def psd_section(ctx: Context) -> None:
    """One part per sample group with height maps: figure, band table, fit table, notes."""
    b = ctx.b
    if not ctx.height_maps:
        raise Unavailable("no height map or profile among the input files")
    b.text(
        "Power spectral density (PSD) of each height map: mean plane removed, Hann window "
        "(SurfaceTopography's periodogram), averaged in logarithmic bins with the standard "
        "error of each bin. Spatial frequency f in cycles per metre; the 2-D PSD [m^4] is "
        "the azimuthal average of a map's spectrum (integral over the frequency plane = "
        "sigma^2), the 1-D PSD [m^3] the two-sided spectrum of profiles (used when a group "
        "holds a profile). Each map covers f from 1 / (its size) to 1 / (2 pixels). The "
        "maps of one sample are joined into one composite over the union of their bands "
        "(inverse-variance mean where they overlap; chi^2/dof > 4 = disagree), and a "
        f"{FIT_MODEL} (ABC) model A / (1 + (B f)^2)^((C+1)/2) is fitted to it in log space."
    )
    used: set[str] = set()
    for name, maps in _groups(ctx):
        sid = slug(name)
        while sid in used:
            sid += "_"
        used.add(sid)
        _group_part(ctx, name, sid, maps)


def _group_part(ctx: Context, name: str, sid: str, maps: list[HeightMap]) -> None:
    b = ctx.b
    b.heading(f"{name}: PSD of {len(maps)} map(s)", anchor=f"psd_{sid}")
    b.log(f"  psd {name} ({len(maps)} maps)")
    try:
        res = psd(maps, fit=FIT_MODEL, seed=ctx.seed)
    except (AdapterError, ValueError) as exc:
        try:
            res = psd(maps)
        except (AdapterError, ValueError):
            b.note("not available", str(exc))
            return
        b.note("fit", f"no {FIT_MODEL} fit: {exc}")
    _figure(ctx, name, sid, res)
    _band_table(ctx, sid, res)
    if res.fit is not None:
        _fit_table(ctx, sid, res)
        for n in res.fit.notes:
            b.note("fit", n)
    for o in res.overlaps:
        b.note("overlap", o.sentence())
    for w in res.warnings:
        if "DISAGREE" not in w:
            b.note("warning", w)


def _figure(ctx: Context, name: str, sid: str, res: PSDResult) -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.8))
    draw_psd(ax, res)
    ax.set_title(name, fontsize=10)
    fig.tight_layout()
    kind = "2-D (azimuthal average)" if res.kind == "2d" else "1-D (two-sided, profiles)"
    ctx.b.figure(
        f"psd_{sid}",
        f"{name}: surface PSD, composite and {FIT_MODEL} fit",
        f"Measured. {kind} PSD of each map (markers, 1-sigma bars: standard error of the "
        "bin mean), the composite over the maps (grey line, where several) and the fitted "
        "model over its band (dashed; model, not measurement). Log-log axes; f in 1/m.",
        figures.to_uri(fig),
    )


def _band_table(ctx: Context, sid: str, res: PSDResult) -> None:
    rows = []
    for r in res.map_rows():
        lo, hi = r["band_per_m"]
        rows.append(
            {
                "file": Path(r["source"]).name,
                "kind": r["kind"],
                "points": " x ".join(str(v) for v in r["points"]),
                "pixel": min(r["pixel_m"]) * 1e9,
                "f_min": lo,
                "f_max": hi,
                "periods": f"{1e6 / hi:.3g} - {1e6 / lo:.3g}",
                "sigma": r["sigma_band_m"] * 1e9,
                "slope": r["slope_rms_band"],
            }
        )
    ctx.b.table(
        f"psd_bands_{sid}",
        "Band of each map and what the PSD carries over it",
        [
            ("file", "file", ""),
            ("kind", "PSD", ""),
            ("points", "points", ""),
            ("pixel", "pixel [nm]", ".4g"),
            ("f_min", "f_min [1/m]", ".4g"),
            ("f_max", "f_max [1/m]", ".4g"),
            ("periods", "periods [\u00b5m]", ""),
            ("sigma", "sigma over the band [nm]", ".4g"),
            ("slope", "RMS slope over the band [1]", ".3g"),
        ],
        rows,
        caption="f_min = 1 / map size, f_max = 1 / (2 pixels). sigma and the RMS slope "
        "(continuum derivative, sqrt of the integral of (2 pi f)^2 PSD) by Parseval over "
        "the band, with the Hann window (which keeps the expected variance).",
    )


def _fit_table(ctx: Context, sid: str, res: PSDResult) -> None:
    fit = res.fit
    assert fit is not None
    rows = []
    for k, v in fit.values.items():
        lo, hi = fit.interval[k]
        rows.append(
            {
                "param": k,
                "value": v,
                "stderr": fit.stderr[k],
                "low": lo if math.isfinite(lo) else None,
                "high": hi if math.isfinite(hi) else None,
                "unit": fit.units[k],
            }
        )
    lo, hi = fit.band
    ctx.b.table(
        f"psd_fit_{sid}",
        f"{fit.model} fit over {lo:.4g} - {hi:.4g} 1/m",
        [
            ("param", "parameter", ""),
            ("value", "value", ".4g"),
            ("stderr", "standard error", ".2g"),
            ("low", "95 % low", ".4g"),
            ("high", "95 % high", ".4g"),
            ("unit", "unit", ""),
        ],
        rows,
        caption=f"{fit.ndata} bins, chi^2/dof {fit.redchi:.3g} (log residuals; the "
        "covariance is scaled by it when above 1). The model's sigma over the fitted band: "
        f"{fit.sigma_band * 1e9:.4g} nm (the measured PSD's over the same band: "
        f"{res.composite.band_sigma(lo, hi) * 1e9:.4g} nm); over all frequencies: "
        + (f"{fit.sigma_total * 1e9:.4g} nm." if math.isfinite(fit.sigma_total) else "diverges.")
        + " Blank interval: not determined by the data.",
    )
