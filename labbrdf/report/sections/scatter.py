"""Section ``scatter``: a measured BSDF file handed to the optical designer.

For every tabulated BSDF among the inputs (Zemax/Radiant ``.bsdf``, Speos
``.anisotropicbsdf``, pgII, ASTM tables), the Harvey-family models that design programs take
(ABg, ABg with a Lambertian floor, Harvey-Shack; the transmission forms for a BTDF) are fitted
next to the physical models (microfacet with a Lambertian floor, and the report's own model
when it describes the data), with the one fitting core. The page shows the fits side by side
(chi2/nu, AIC, the parameters with their 95 % intervals and flags), the relative residual maps
of the best Harvey fit and of the physical model, the TIS of the measurement and of the fits
(:func:`labbrdf.fitting.scatter_tis.tis_comparison`) and the files for the designer, written
beside the page by :mod:`labbrdf.writers` (a FRED script of each Harvey fit; the best
Harvey fit tabulated as Zemax ``.bsdf``, Speos and ASTM tables).
"""

from __future__ import annotations

import functools
import re
import tempfile
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ... import models
from ...fitting import fit_many
from ..builder import Unavailable, wl_label
from ..context import BY, Context

__all__ = ["TABULATED_FORMATS", "scatter_section"]

#: reader formats of tabulated BSDF files (``meta["format"]``)
TABULATED_FORMATS = ("zemax-bsdf", "speos-bsdf", "pab-pgii", "astm-brdf")
#: the Harvey-family fits: (label, registry name, options)
HARVEY: tuple[tuple[str, str, dict[str, Any]], ...] = (
    ("ABg", "abg", {}),
    ("ABg + Lambertian floor", "abg", {"diffuse": True}),
    ("Harvey-Shack", "harvey_shack", {}),
)
#: the physical model fitted beside them: an ideal-mirror microfacet lobe with a Lambertian
#: floor, its scale free (the sample's specular reflectance, not a mirror's)
PHYSICAL = ("microfacet + Lambertian floor", "microfacet", {"ideal_mirror": True, "diffuse": True})
#: starting settings of the physical model's parameters (:func:`labbrdf.fitting.fit`)
PHYSICAL_PARAMS = {"scale": {"vary": True}}
#: the report's models also fitted here when asked (``--model``; microfacet is fitted anyway,
#: as :data:`PHYSICAL`; layered is slow and runs only when it is the report's model)
HEMISPHERE_MODELS = ("microfacet", "five_param", "layered", "rayleigh_rice")
#: the number of incidences shown in the residual maps
MAP_INCIDENCES = 4


def scatter_section(ctx: Context, model: str, options: Mapping[str, Any]) -> None:
    """Fit the Harvey family beside the physical models to each tabulated BSDF file."""
    files = _tabulated(ctx)
    ctx.b.text(
        "The Harvey-family models (ABg, its Lambertian floor, Harvey-Shack) are what optical "
        "design programs take as a parametric scatter model; they are fitted here with the "
        "same core, weights and masked zeros as the physical models beside them, so chi2/nu "
        "and AIC compare like with like (lower AIC: better, after the count of free "
        "parameters). The files for the designer are written beside this page."
    )
    fits = [g for f, rows in files for g in _one_file(ctx, f, rows, model, dict(options))]
    bad = [f"{g['label']} ({g['key']}): {g['res'].message}" for g in fits if not g["res"].success]
    ctx.b.check(
        "scatter.fits.success",
        "every Harvey-family and physical fit to the tabulated BSDF files converged",
        not bad,
        against="the optimiser's success flag",
        value=len(fits) - len(bad),
        tolerance=len(fits),
        justification="value = converged fits, tolerance = fits run",
        reason="; ".join(bad)[:1000],
    )


def _tabulated(ctx: Context) -> list[tuple[dict[str, Any], pd.DataFrame]]:
    """The tabulated BSDF files among the inputs and their BRDF/BTDF rows."""
    d = ctx.data
    out = []
    for f in ctx.files:
        if (f.get("meta") or {}).get("format") not in TABULATED_FORMATS or d is None:
            continue
        rows = d[(d["source"] == Path(f["path"]).name) & d["quantity"].isin(["brdf", "btdf"])]
        if len(rows):
            out.append((f, rows.reset_index(drop=True)))
    if not out:
        raise Unavailable(
            "no tabulated BSDF file among the inputs (Zemax .bsdf, Speos .anisotropicbsdf, "
            "pgII, ASTM): no ABg fit for the designer"
        )
    return out


def _candidates(
    ctx: Context, quantity: str, model: str, options: dict[str, Any]
) -> list[tuple[str, str, dict[str, Any], Any]]:
    """(label, name, options, starting params) of every model fitted to ``quantity`` rows.

    The report's ``--param`` starting values (``ctx.fit_options["params"]``) are its own
    model's: only that model's fit takes them.
    """
    if quantity == "btdf":  # only the transmission forms describe a BTDF
        return [(f"{lab} (BTDF)", n, {**o, "transmission": True}, None) for lab, n, o in HARVEY]
    out: list[tuple[str, str, dict[str, Any], Any]] = [
        (lab, n, dict(o), None) for lab, n, o in HARVEY
    ]
    out.append((PHYSICAL[0], PHYSICAL[1], dict(PHYSICAL[2]), PHYSICAL_PARAMS))
    if model in HEMISPHERE_MODELS and model != PHYSICAL[1]:  # layered: only when asked
        start = ctx.fit_options.get("params")
        out.append((f"{model} (the report's model)", model, options, start))
    return out


def _fits(
    ctx: Context, rows: pd.DataFrame, cands: Sequence[tuple[str, str, dict[str, Any], Any]]
) -> list[dict[str, Any]]:
    """Each candidate fitted per (sample, wavelength); one entry per fitted group."""
    extra = {k: v for k, v in ctx.fit_options.items() if k != "params"}
    kw = {"mask_zeros": True, "weighting": "auto", **extra}
    out = []
    for label, name, opts, params in cands:
        try:
            m = models.get(name, **opts)
        except models.ModelError as exc:
            ctx.b.note(label, f"not fitted: {exc}")
            continue
        _, results = fit_many(
            rows,
            m,
            params=params,
            by=list(BY),
            method=ctx.method,
            seed=ctx.seed,
            executor=ctx.executor,
            return_results=True,
            **kw,
        )
        ctx.b.log(f"  scatter: fitted {label} to {len(results)} group(s)")
        for key, res in results:
            out.append({"label": label, "name": name, "options": opts, "key": key, "res": res})
    return out


def _one_file(
    ctx: Context, f: dict[str, Any], rows: pd.DataFrame, model: str, options: dict[str, Any]
) -> list[dict[str, Any]]:
    """Fit, tabulate, map and export one file's BRDF and BTDF; its fits."""
    name = Path(f["path"]).name
    if "channel" in rows.columns and rows["channel"].notna().any():
        rows = rows[(rows["channel"] == "Y").to_numpy()]
        ctx.b.note(
            "tristimulus",
            f"{name} holds CIE X, Y, Z channels: the Y (luminance) channel is fitted and exported",
        )
    fits = []
    for quantity in ("brdf", "btdf"):
        part = rows[(rows["quantity"] == quantity).to_numpy()]
        if len(part):
            fits += _one_quantity(ctx, f, part, quantity, model, options)
    return fits


def _one_quantity(
    ctx: Context,
    f: dict[str, Any],
    rows: pd.DataFrame,
    quantity: str,
    model: str,
    options: dict[str, Any],
) -> list[dict[str, Any]]:
    """The fits of one quantity of one file, per (sample, wavelength), with their page."""
    name = Path(f["path"]).name
    ctx.b.heading(f"{name} ({quantity.upper()})", anchor=f"scatter-{_slug(name)}-{quantity}")
    fits = _fits(ctx, rows, _candidates(ctx, quantity, model, options))
    keys: list[dict[str, Any]] = []
    for fit in fits:
        if fit["key"] not in keys:
            keys.append(fit["key"])
    stated = (f.get("meta") or {}).get("wavelength_stated", True) is not False
    for key in keys:
        group = [g for g in fits if g["key"] == key]
        wl = wl_label(float(key.get("wavelength_nm", 0.0)), stated=stated)
        own = key.get("sample") == Path(name).stem
        tag = f"{name}, {wl}" if own else f"{name}, sample {key.get('sample')}, {wl}"
        sample = "" if own else f"_{key.get('sample', '')}"
        suffix = "_btdf" if quantity == "btdf" else ""
        ids = _slug(f"{Path(name).stem}{sample}_{key.get('wavelength_nm', '')}{suffix}")
        _table(ctx, tag, ids, group)
        best = _best_harvey(group)
        physical = [g for g in group if g["name"] not in ("abg", "harvey_shack")]
        shown = [g for g in (best, *physical[:1]) if g is not None]
        _maps(ctx, tag, ids, shown)
        _tis(ctx, f, tag, ids, shown)
        _designer_files(ctx, f, ids, group, best)
    return fits


def _best_harvey(group: Sequence[dict[str, Any]]) -> dict[str, Any] | None:
    """The Harvey-family fit with the lowest AIC (None if none was fitted)."""
    harvey = [g for g in group if g["name"] in ("abg", "harvey_shack")]
    return min(harvey, key=lambda g: float(g["res"].aic), default=None)


def _param_rows(label: str, summary: Mapping[str, Any]) -> list[dict[str, Any]]:
    """One row per varying parameter: value, standard error, 95 % interval, flags."""
    rows = []
    for k, p in summary["params"].items():
        if not p.get("vary", True):
            continue
        lo, hi = p.get("ci95") or [None, None]
        rows.append(
            {
                "model": label,
                "param": k,
                "value": p["value"],
                "stderr": p.get("stderr"),
                "lo": lo,
                "hi": hi,
                "units": p.get("units", ""),
                "flags": ", ".join(p.get("flags") or []),
            }
        )
    return rows


def _table(ctx: Context, tag: str, ids: str, group: Sequence[dict[str, Any]]) -> None:
    rows, params = [], []
    for g in group:
        s = g["res"].summary()
        params += _param_rows(g["label"], s)
        rows.append(
            {
                "model": g["label"],
                "nfree": sum(1 for p in s["params"].values() if p.get("vary", True)),
                "ndata": s["ndata"],
                "redchi": s["redchi"],
                "aic": s["aic"],
                "weighting": str(s.get("weighting") or "").split(":")[0],
            }
        )
    low = min((r["aic"] for r in rows), default=0.0)
    for r in rows:
        r["daic"] = r["aic"] - low
    best = next((r["model"] for r in rows if r["daic"] == 0.0), "")
    ctx.b.table(
        f"scatter_fits_{ids}",
        f"Harvey-family and physical fits side by side ({tag})",
        [
            ("model", "model", "s"),
            ("nfree", "free parameters", "d"),
            ("ndata", "points", "d"),
            ("redchi", "chi2/nu", ".4g"),
            ("aic", "AIC", ".1f"),
            ("daic", "ΔAIC", ".1f"),
            ("weighting", "weights", "s"),
        ],
        rows,
        caption=f"Lowest AIC: {best}. The same points and weights for every model; with "
        "relative weights chi2/nu is the mean squared relative residual.",
    )
    ctx.b.table(
        f"scatter_params_{ids}",
        f"Fitted parameters with 95 % intervals ({tag})",
        [
            ("model", "model", "s"),
            ("param", "parameter", "s"),
            ("value", "value", ".5g"),
            ("stderr", "standard error", ".2g"),
            ("lo", "95 % low", ".5g"),
            ("hi", "95 % high", ".5g"),
            ("units", "units", "s"),
            ("flags", "flags", "s"),
        ],
        params,
        caption="A, kd and b0 enter linearly and are profiled out. ABg and Harvey-Shack "
        "describe the scattered light only (the specular beam apart). A flagged parameter "
        "is not determined by these data (see the flags' meaning in the fit section).",
    )


def _panels(g: dict[str, Any], tis: Sequence[float]) -> list[dict[str, Any]]:
    """Residual-map panels of one fit at the incidences ``tis`` [deg]."""
    res = g["res"]
    m = models.get(g["name"], **g["options"])
    d = res.data
    ti = np.asarray(d.theta_i_deg, float)
    out = []
    for t in tis:
        sel = np.isclose(ti, t)
        tr = np.asarray(d.theta_r_deg, float)[sel]
        pr = np.asarray(d.phi_r_deg, float)[sel]
        v = np.asarray(d.value, float)[sel]
        f = np.asarray(
            m.evaluate(np.radians(t), np.radians(tr), np.radians(pr), params=res.values), float
        )
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.where(v > 0, (f - v) / v, np.nan)
        short = g["label"].split(" (")[0].replace("Lambertian floor", "floor")
        label = f"{short}\n\u03b8i = {t:g}\u00b0"
        out.append({"label": label, "theta_r": tr, "phi_r": pr, "measured": v, "model": f,
                    "residual": rel})  # fmt: skip
    return out


def _maps(ctx: Context, tag: str, ids: str, shown: Sequence[dict[str, Any]]) -> None:
    from .. import figures

    if not shown:
        return
    all_ti = np.unique(np.asarray(shown[0]["res"].data.theta_i_deg, float))
    pick = np.unique(np.linspace(0, all_ti.size - 1, min(MAP_INCIDENCES, all_ti.size)).round())
    tis = [float(all_ti[int(i)]) for i in pick]
    panels = [p for g in shown for p in _panels(g, tis)]
    ctx.b.figure(
        f"scatter_residuals_{ids}",
        f"Relative residual of the best Harvey fit and of the physical model ({tag})",
        "Each disc is the scatter hemisphere seen from above: x = \u03b8r cos \u03c6r, "
        "y = \u03b8r sin \u03c6r [deg], the source towards +x. One row per model (the "
        "Harvey fit with the lowest AIC, then the physical model), one column per angle of "
        "incidence. Colour: (model - measured) / measured [1], clipped to \u00b11, blank "
        "where the measurement is 0 (masked in the fits).",
        figures.brdf_residual_grid_figure(panels, title=tag),
    )


def _tis(
    ctx: Context, f: dict[str, Any], tag: str, ids: str, shown: Sequence[dict[str, Any]]
) -> None:
    """The file's TIS, the grid integrals of measurement and fit, the fit's hemisphere TIS."""
    fmt = (f.get("meta") or {}).get("format")
    if fmt not in ("zemax-bsdf", "speos-bsdf"):
        ctx.b.note(
            "TIS",
            f"{tag}: the grid-integral comparison needs the file's own regular grid (a .bsdf "
            "or Speos table); this format's scattered points are not integrated",
        )
        return
    rows = []
    for g in shown:
        m = models.get(g["name"], **g["options"])
        for r in _tis_rows(f, m, g).to_dict("records"):
            rows.append({"model": g["label"], **r})
    ctx.b.table(
        f"scatter_tis_{ids}",
        f"Total integrated scatter: measurement and fits ({tag})",
        [
            ("model", "model", "s"),
            ("theta_i_deg", "\u03b8i [deg]", "g"),
            ("tis_file", "file's TIS [1]", ".4g"),
            ("grid_measured", "grid integral, measured [1]", ".4g"),
            ("grid_model", "grid integral, fit [1]", ".4g"),
            ("ratio", "fit / measured (grid)", ".3f"),
            ("tis_model", "fit's TIS, whole hemisphere [1]", ".4g"),
        ],
        rows,
        caption="The grid integrals use the file's own nodes and cells for the measurement "
        "and the fit alike (the like-for-like comparison); the last column integrates the "
        "fit over the whole hemisphere (closed form for ABg and Harvey-Shack). A Speos file "
        "states its TIS (the spectrum's coefficient) at one incidence only.",
        details=True,
    )


def _tis_rows(f: dict[str, Any], m: models.Model, g: dict[str, Any]) -> pd.DataFrame:
    """:func:`tis_comparison` (``.bsdf``) or :func:`speos_tis_comparison` of one fit."""
    from ...fitting.scatter_tis import speos_tis_comparison, tis_comparison

    if f["meta"]["format"] == "zemax-bsdf":
        from ...adapters.zemax_bsdf import read_table

        return tis_comparison(m, g["res"].values, read_table(f["path"]))
    from ...adapters.speos_bsdf import read_speos_table

    wl = float(g["key"].get("wavelength_nm", np.nan))
    return speos_tis_comparison(m, g["res"].values, read_speos_table(f["path"]), wl)


def _designer_files(
    ctx: Context,
    f: dict[str, Any],
    stem: str,
    group: Sequence[dict[str, Any]],
    best: dict[str, Any] | None,
) -> None:
    """FRED scripts of the Harvey fits; the best one as .bsdf, Speos and ASTM tables."""
    from ...writers.fred import FRED_MODELS

    stated = (f.get("meta") or {}).get("wavelength_stated", True) is not False
    for g in group:
        if g["name"] in FRED_MODELS and not g["options"].get("diffuse"):
            res, label = g["res"], g["label"]
            _attach(
                ctx,
                f"{stem}_{g['name']}.frs",
                f"FRED script defining the fitted {label} scatter model (with its wavelength, "
                "domain, chi2/nu and standard errors as comments)",
                functools.partial(_fred, res, stated),
            )
    if best is None or best["options"].get("transmission"):
        return
    _tables(ctx, stem, best, stated)


def _attach(ctx: Context, name: str, label: str, write: Callable[[Path], Any]) -> None:
    """Write a designer's file now (into a scratch folder) and attach it to the page.

    A writer that refuses the fit (a Speos spectrum above 1, a model FRED cannot hold) is
    a note on the page, not a failed report.
    """
    with tempfile.TemporaryDirectory(prefix="labbrdf-designer-") as tmp:
        path = Path(tmp) / name
        try:
            write(path)
        except (ValueError, OSError) as exc:
            ctx.b.note(name, f"not written: {exc}")
            return
        content = path.read_bytes()
    ctx.b.file(name, label, content)


def _fred(res: Any, stated: bool, path: Path) -> Path:
    from ...writers.fred import write_fred_script

    return write_fred_script(res, path, wavelength_stated=stated)


def _tables(ctx: Context, stem: str, best: dict[str, Any], stated: bool) -> None:
    """The best Harvey fit tabulated for Zemax, Speos and ASTM readers.

    A measurement that states no wavelength gives a ``.bsdf`` that states none either
    (its 555 nm is the reader's photopic label: written as a wavelength comment it would be
    read back as a measured one); Speos and ASTM tables need a number and carry the label.
    """
    from ...writers.astm import model_to_astm
    from ...writers.speos import model_to_speos
    from ...writers.zemax import model_to_bsdf

    m = models.get(best["name"], **best["options"])
    vals = dict(best["res"].values)
    tis = sorted({float(t) for t in np.asarray(best["res"].data.theta_i_deg, float)})
    wls = best["res"].data.wavelength_nm
    wl = 555.0 if wls is None else float(np.asarray(wls, float).ravel()[0])
    what = f"the fitted {best['label']} (lowest AIC of the Harvey family)"
    radial = np.array([0, 0.5, 1, 2, 3, 5, 7.5, 10, 15, 20, 30, 40, 50, 60, 70, 80, 90.0])
    _attach(
        ctx,
        f"{stem}_{best['name']}.bsdf",
        f"Zemax/Radiant tabulated BSDF of {what}",
        lambda p: model_to_bsdf(
            m,
            vals,
            p,
            theta_i_deg=tis,
            radial_deg=radial,
            azimuth_deg=np.arange(0, 181, 5.0),
            wavelength_nm=wl if stated else None,
        ),  # fmt: skip
    )
    _attach(
        ctx,
        f"{stem}_{best['name']}.anisotropicbsdf",
        f"Speos anisotropic BSDF text of {what}",
        lambda p: model_to_speos(m, vals, p, theta_i_deg=tis, wavelength_nm=wl),
    )
    _attach(
        ctx,
        f"{stem}_{best['name']}.astm",
        f"ASTM E1392-style table of {what} (plane of incidence)",
        lambda p: model_to_astm(m, vals, p, theta_i_deg=tis, wavelength_nm=wl),
    )


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", str(text)).strip("_")[:80] or "x"
