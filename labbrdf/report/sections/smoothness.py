"""Section ``smoothness``: a height map's roughness against the wavelength of the light.

Shown when a height map and reflectance data of one sample are given (files paired by
:func:`labbrdf.samples.pair_samples`: a stated sample name or ``--same-sample``). For each
such map and each (wavelength, angle of incidence) of the sample's reflectance: the
Rayleigh parameter g, the Rayleigh and Fraunhofer verdicts with sigma's uncertainty, the
Davies specular loss exp(-g), and, where an ellipsometer file of the same sample gives bulk
n, k (section ``nk``) or a fitted film stack (section ``film``), the measured specular
reflectance divided by their prediction;
for a ``.bsdf`` file of the sample, its measured TIS against ``1 - exp(-g)``. Physics:
:mod:`labbrdf.roughness.smoothness`; derivation and the bandwidth caveat: ``docs/smoothness.md``.

sigma is that of the roughness that scatters (spatial periods from
``lambda / (1 + sin theta_i)`` up to the map size): the levelled map is S-filtered
(ISO 16610-61 Gaussian, 50 % at the cut-off) at that period when the map resolves it;
its uncertainty is the full map's jackknife uncertainty scaled by the ratio of the sigmas.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ... import nk as nkmod
from ...samples import SampleGroup
from .. import figures
from ..builder import Unavailable, slug
from ..context import Context
from ..roughness import MapRoughness, groups_with_maps, judge

__all__ = ["MAX_WAVELENGTHS", "smoothness_section"]

#: most wavelengths per map in the table (evenly picked from the sample's)
MAX_WAVELENGTHS = 8

#: quantities compared: absolute specular reflectance (not a sphere's total, which holds the
#: scatter; not a scan's relative specular intensity)
REFLECTANCE = ("reflectance",)


def _pick(values: np.ndarray, n: int = MAX_WAVELENGTHS) -> np.ndarray:
    u = np.unique(values[np.isfinite(values)])
    if len(u) <= n:
        return u
    return u[np.unique(np.round(np.linspace(0, len(u) - 1, n)).astype(int))]


def _ratios(ctx: Context, group: SampleGroup, rows: pd.DataFrame) -> pd.DataFrame | None:
    """Measured / predicted reflectance, the prediction from an ellipsometer file of the group.

    The bulk n, k of section ``nk`` (Fresnel), else the film stack of section ``film``
    (transfer matrices); the first that predicts the rows.
    """
    names = {Path(p).name for p in group.paths}
    r = rows[rows["quantity"] == "reflectance"]
    candidates: list[tuple[str, Any]] = [
        (f"{src} (bulk n, k)", lambda comb=comb: nkmod.compare_reflectance(comb, r))
        for src, comb in ctx.nk_combined.items()
        if src in names
    ]
    candidates += [
        (f"{src} (film stack)", lambda fit=fit: fit.compare_reflectance(r))
        for src, fit in ctx.film_fits.items()
        if src in names
    ]
    for label, compare in candidates:
        try:
            c = compare()
        except ValueError:
            continue
        c = c.assign(nk_file=label)
        with np.errstate(divide="ignore", invalid="ignore"):
            c["ratio"] = c["measured"] / c["predicted"]
            rel = np.hypot(
                np.nan_to_num(c["measured_sigma"] / c["measured"]),
                np.nan_to_num(c["predicted_sigma"] / c["predicted"]),
            )
        c["u_ratio"] = c["ratio"] * rel
        return c
    return None


def _nearest(c: pd.DataFrame | None, wl: float, theta: float) -> dict[str, Any]:
    if c is None or c.empty:
        return {}
    at = c[np.isclose(c["theta_i_deg"], theta, atol=0.05)]
    if at.empty:
        return {}
    i = int(np.argmin(np.abs(at["wavelength_nm"].to_numpy(float) - wl)))
    r = at.iloc[i]
    if abs(float(r["wavelength_nm"]) - wl) > 1.0:
        return {}
    return {"ratio": float(r["ratio"]), "u_ratio": float(r["u_ratio"]), "nk_file": r["nk_file"]}


_COLUMNS = [  # the map is the table's title (and the rows' "map" key in results.json)
    ("wavelength_nm", "\u03bb [nm]", ".5g"),
    ("theta_i", "\u03b8i [deg]", ".3g"),
    ("shortest_nm", "shortest scattering period [nm]", ".4g"),
    ("coverage", "map's band", ""),
    ("sigma_nm", "\u03c3 [nm]", ".4g"),
    ("u_sigma_nm", "u(\u03c3) [nm]", ".2g"),
    ("g", "g [1]", ".3g"),
    ("u_g", "u(g) [1]", ".2g"),
    ("thr_rayleigh", "\u03bb/(8 cos\u03b8) [nm]", ".4g"),
    ("rayleigh", "Rayleigh", ""),
    ("thr_fraunhofer", "\u03bb/(32 cos\u03b8) [nm]", ".4g"),
    ("fraunhofer", "Fraunhofer", ""),
    ("loss", "exp(-g) predicted", ".4g"),
    ("ratio", "R measured / R Fresnel", ".4g"),
    ("u_ratio", "u(ratio)", ".2g"),
    ("nk_file", "prediction from", ""),
]


def _figure(m: MapRoughness, wl: np.ndarray, thetas: Sequence[float], c: Any) -> str:
    grid = np.geomspace(float(wl.min()), float(wl.max()), 25) if wl.max() > wl.min() else wl
    g_series, l_series = [], []
    for t in thetas:
        rows = [judge(m, float(w), t) for w in grid]
        g = np.array([r.get("g", np.nan) for r in rows], float)
        lab = f"\u03b8i {t:g} deg"
        g_series.append({"label": f"g, {lab}", "x": grid, "y": g, "style": "line"})
        l_series.append({"label": f"exp(-g), {lab}", "x": grid, "y": np.exp(-g), "style": "line"})
        if c is not None:
            at = c[np.isclose(c["theta_i_deg"], t, atol=0.05)]
            if len(at):
                l_series.append(
                    {
                        "label": f"measured / Fresnel, {lab}",
                        "x": at["wavelength_nm"].to_numpy(float),
                        "y": at["ratio"].to_numpy(float),
                        "yerr": at["u_ratio"].to_numpy(float),
                        "style": "points",
                    }
                )
    for name, level_g in (("Rayleigh", (math.pi / 2) ** 2), ("Fraunhofer", (math.pi / 8) ** 2)):
        flat = np.full(len(grid), level_g)
        g_series.append({"label": f"{name} limit g = {level_g:.3g}", "x": grid, "y": flat})
    return figures.panels_figure(
        [
            {
                "title": f"{m.name}: Rayleigh parameter",
                "xlabel": "wavelength [nm]",
                "ylabel": "g [1]",
                "logy": True,
                "series": g_series,
            },
            {
                "title": "specular loss",
                "xlabel": "wavelength [nm]",
                "ylabel": "R_s / R_0 [1]",
                "series": l_series,
            },
        ],
        ncols=2,
        panel_size=(5.2, 3.4),
    )


def _sentence(rows: list[dict[str, Any]], m: MapRoughness, sample: str) -> str:
    judged = [r for r in rows if "g" in r]
    if not judged:
        return (
            f"{m.name} ({m.long_nm:.4g} nm across) is smaller than the shortest period of "
            f"roughness that scatters light at {sample}'s wavelengths: its sigma says nothing "
            "about their specular loss."
        )
    ray = sorted({r["rayleigh"] for r in judged})
    fr = sorted({r["fraunhofer"] for r in judged})
    wl = [r["wavelength_nm"] for r in judged]
    lo, hi = min(r["sigma_nm"] for r in judged), max(r["sigma_nm"] for r in judged)
    sig = f"{lo:.3g}" if f"{lo:.3g}" == f"{hi:.3g}" else f"{lo:.3g}..{hi:.3g}"
    worst = min(r["loss"] for r in judged)
    text = (
        f"Sample {sample}: with sigma = {sig} nm from {m.name}, the surface is "
        f"{' / '.join(ray)} by the Rayleigh criterion and {' / '.join(fr)} by the "
        f"Fraunhofer criterion at {min(wl):.4g}-{max(wl):.4g} nm; the predicted specular "
        f"loss 1 - exp(-g) is at most {100 * (1 - worst):.3g} %."
    )
    if any(r["coverage"] == "misses short periods" for r in judged):
        text += (
            f" The map does not resolve periods below {m.short_nm:.4g} nm (2 pixels), "
            "so roughness between the shortest scattering period and that is missing "
            "from sigma: g and the loss are lower bounds."
        )
    return text


def _tis_rows(
    ctx: Context, group: SampleGroup, m: MapRoughness, data: pd.DataFrame
) -> list[dict[str, Any]]:
    names = {Path(p).name for p in group.paths}
    rows = []
    for rec in ctx.files:
        name = Path(str(rec.get("path", ""))).name
        meta = rec.get("meta") or {}
        tis = meta.get("tis")
        if name not in names or not isinstance(tis, list):
            continue
        if meta.get("wavelength_stated") is False:  # a placeholder is no wavelength
            ctx.b.note(
                "TIS not compared",
                f"{name} states no wavelength ({float(meta.get('wavelength_nm', 0)):g} nm is "
                "the format's placeholder), so its TIS is not compared with the height map's: "
                "the Rayleigh factor depends on the wavelength; give it with labbrdf report "
                "--wavelength NM (Python: user_report(..., wavelength_nm=NM))",
            )
            continue
        wls = data.loc[data["source"] == name, "wavelength_nm"].dropna().unique()
        if len(wls) != 1:
            continue
        for t in tis:
            j = judge(m, float(wls[0]), float(t["theta_i_deg"]))
            rows.append(
                {
                    "file": name,
                    "wavelength_nm": float(wls[0]),
                    "theta_i": float(t["theta_i_deg"]),
                    "coverage": j["coverage"],
                    "tis": float(t["tis"]),
                    "tis_r0": float(-np.expm1(-j["g"])) if "g" in j else None,
                    "tis_r0_small": j.get("g"),
                }
            )
    return rows


def smoothness_section(ctx: Context) -> None:
    """Rayleigh criterion, specular loss and TIS for each height map paired with data."""
    b = ctx.b
    if not ctx.height_maps:
        raise Unavailable("no height map among the input files")
    pairs = groups_with_maps(ctx)
    if not pairs:
        raise Unavailable(
            "no height map shares a sample with reflectance data: pair them by the sample "
            "name in the files or with --same-sample MAP,DATA"
        )
    data = ctx.data
    if data is None:
        raise Unavailable("no optical data ingested")
    b.text(
        "The Rayleigh parameter g = (4 pi sigma cos theta_i / lambda)^2 (Davies 1954) is the "
        "variance of the reflected phase. Smooth by the Rayleigh criterion when sigma < "
        "lambda / (8 cos theta_i) (Ulaby, Moore & Fung, as Zou et al. 2013 sec. 3 use it), "
        "by the stricter Fraunhofer criterion when sigma < lambda / (32 cos theta_i). A "
        "verdict takes sigma +- 2 u(sigma): 'undecided' when that interval straddles the "
        "threshold. The specular reflectance of Gaussian heights is R_0 exp(-g) (Davies), "
        "the total integrated scatter R_0 (1 - exp(-g)) ~ R_0 g (Bennett & Porteus 1961). "
        "sigma is that of the roughness that scatters: spatial periods from lambda / (1 + "
        "sin theta_i) (grating equation) up to the map size; finer roughness is removed "
        "with the ISO 16610-61 Gaussian S-filter at that period where the map resolves it, "
        "and where the map does not resolve it, sigma misses those periods (then g and the "
        "loss are lower bounds)."
    )
    for group, maps, optical in pairs:
        rows_g = data[data["source"].isin(optical)]
        refl = rows_g[rows_g["quantity"].isin(REFLECTANCE)]
        c = _ratios(ctx, group, refl) if len(refl) else None
        for m in maps:
            sid = slug(f"{group.name}_{m.name}")
            b.heading(f"{group.name}: {m.name}", anchor=f"smoothness_{sid}")
            b.note("sample", f"{', '.join(Path(p).name for p in group.paths)} ({group.reason})")
            b.note("height map band", m.stats.bandwidth)
            if refl.empty:
                b.note("reflectance", "no specular reflectance rows among the sample's files")
                thetas: list[float] = []
                wl = np.array([])
            else:
                th = refl["theta_i_deg"].to_numpy(float)
                thetas = sorted({round(float(t), 3) for t in th[np.isfinite(th)]}) or [0.0]
                wl = _pick(refl["wavelength_nm"].to_numpy(float))
            rows = []
            for t in thetas:
                for w in wl:
                    r = judge(m, float(w), t)
                    r.update(_nearest(c, float(w), t))
                    rows.append(r)
            if rows and not any("g" in r for r in rows):
                b.text(_sentence(rows, m, group.name))
            elif rows:
                b.table(
                    f"smoothness_{sid}",
                    f"{group.name}: {m.name} against the wavelength",
                    _COLUMNS,
                    rows,
                    caption="Predicted from the height map alone (no fitted parameter). "
                    "u = standard uncertainty; verdicts at sigma +- 2u. 'misses short "
                    "periods': the map's pixel is too coarse for the finest roughness that "
                    "scatters, sigma is a lower bound. Spectrophotometer rows without an "
                    "angle are taken at normal incidence, and their reflectance as specular "
                    "(with an integrating sphere it includes the scatter). The ratio divides "
                    "by the reflectance predicted from an ellipsometer file of the same "
                    "sample: its bulk n, k (section nk, Fresnel) or its fitted film stack "
                    "(section film).",
                )
                b.text(_sentence(rows, m, group.name))
                b.figure(
                    f"smoothness_{sid}",
                    f"{group.name}: Rayleigh parameter and specular loss against wavelength",
                    "Modelled from the height map: g with the Rayleigh ((pi/2)^2) and "
                    "Fraunhofer ((pi/8)^2) levels, and exp(-g); measured (points): "
                    "reflectance divided by the prediction from the sample's bulk n, k or "
                    "film stack, where the files give them.",
                    _figure(m, np.asarray(wl, float), thetas, c),
                )
                if c is None:
                    b.note(
                        "measured ratio",
                        "no bulk n, k or film stack of this sample among the files: the "
                        "measured reflectance is not divided by a prediction",
                    )
            tis = _tis_rows(ctx, group, m, data)
            if tis:
                b.table(
                    f"smoothness_tis_{sid}",
                    f"{group.name}: measured TIS against the height map",
                    [
                        ("file", "file", ""),
                        ("wavelength_nm", "\u03bb [nm]", ".5g"),
                        ("theta_i", "\u03b8i [deg]", ".3g"),
                        ("coverage", "map's band", ""),
                        ("tis", "TIS measured [1]", ".4g"),
                        ("tis_r0", "TIS / R_0 = 1 - exp(-g)", ".4g"),
                        ("tis_r0_small", "TIS / R_0 ~ g", ".4g"),
                    ],
                    tis,
                    caption="Measured: the file's TIS lines (the BSDF integrated over the "
                    "hemisphere). Predicted: Bennett-Porteus per unit R_0, the smooth "
                    "surface's reflectance (not in the file); the measured TIS also holds "
                    "any scatter that is not from topography (bulk, contamination).",
                )
