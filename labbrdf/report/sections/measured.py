"""Section ``measured``: a figure of every quantity ingested, one subsection per file.

Ellipsometric angles (psi, Delta) and depolarisation against wavelength per angle of
incidence (against the angle where a file has one wavelength), with the file's 1-sigma error
bars; reflectance, transmittance, absorbance and other spectra; imaging-ellipsometer stage
maps (``x_mm``, ``y_mm``) when a file holds several spots; Mueller-matrix elements as a 4x4
grid of spectra; kinetic series (``time_s``) as value against time at a few wavelengths;
BRDF rows against the detector angle.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd

from .. import figures
from ..builder import Unavailable, slug
from ..context import Context
from ..inputs import file_frames

__all__ = ["QUANTITY_LABELS", "measured_section", "read_failures"]

#: axis labels of the known quantities (the unit column is appended in brackets)
QUANTITY_LABELS = {
    "psi": "\u03a8",
    "delta": "\u0394",
    "depolarization": "depolarisation",
    "reflectance": "reflectance",
    "transmittance": "transmittance",
    "absorbance": "absorbance",
    "specular_intensity": "specular intensity",
    "hemispherical_reflectance": "hemispherical reflectance",
    "brdf": "BRDF",
}

#: at most this many series per panel (evenly picked), to keep legends readable
MAX_SERIES = 12
#: stage positions closer than this are one spot [mm]
SPOT_TOL_MM = 0.5


def read_failures(ctx: Context) -> list[tuple[str, str]]:
    """``(file, error)`` of every file the ingest section could not read."""
    t = ctx.b.results["tables"].get("ingested_files")
    if not t:
        return []
    return [(str(r["file"]), str(r["error"])) for r in t["rows"] if r.get("status") == "error"]


def _label(q: str, unit: str) -> str:
    base = QUANTITY_LABELS.get(q, q.replace("_", " "))
    return f"{base} [{unit}]" if unit else base


def _unit(g: pd.DataFrame) -> str:
    u = g["unit"].dropna().astype(str).unique() if "unit" in g.columns else []
    return str(u[0]) if len(u) else ""


def _has(g: pd.DataFrame, col: str) -> bool:
    return col in g.columns and bool(g[col].notna().any())


def _pick(values: list[Any], n: int) -> list[Any]:
    if len(values) <= n:
        return values
    idx = np.unique(np.round(np.linspace(0, len(values) - 1, n)).astype(int))
    return [values[i] for i in idx]


def _channel(g: pd.DataFrame) -> pd.Series:
    if "channel" not in g.columns:
        return pd.Series([""] * len(g), index=g.index)
    return g["channel"].astype(object).where(g["channel"].notna(), "").astype(str)


def _spots(g: pd.DataFrame) -> pd.Series | None:
    """A spot label per row when the rows come from more than one stage position."""
    if not (_has(g, "x_mm") and _has(g, "y_mm")):
        return None
    key = (
        (g["x_mm"] / SPOT_TOL_MM).round().astype("Int64").astype(str)
        + ","
        + (g["y_mm"] / SPOT_TOL_MM).round().astype("Int64").astype(str)
    )
    return key if key.nunique() > 1 else None


def _times(g: pd.DataFrame) -> list[float]:
    if not _has(g, "time_s"):
        return []
    t = sorted(float(x) for x in g["time_s"].dropna().unique())
    return t if len(t) > 1 else []


def _series(
    g: pd.DataFrame, x: str, keys: list[str], fmt: Mapping[str, str]
) -> list[dict[str, Any]]:
    """Series of ``value`` against column ``x``, one per combination of ``keys``.

    Repeated points (several spots or zones at one x) are averaged; their standard
    deviation then replaces the file's sigma as the error bar.
    """
    out = []
    groups = list(g.groupby(keys, sort=True, dropna=False)) if keys else [((), g)]
    for key, s in _pick(groups, MAX_SERIES):
        key = key if isinstance(key, tuple) else (key,)
        agg = s.groupby(x, sort=True).agg(
            y=("value", "mean"), sd=("value", "std"), sig=("sigma", "mean"), n=("value", "size")
        )
        repeated = bool((agg["n"] > 1).any())
        err = agg["sd"] if repeated else agg["sig"]
        label = ", ".join(
            fmt[k].format(v) for k, v in zip(keys, key, strict=True) if str(v) not in ("", "nan")
        )
        out.append(
            {
                "label": label,
                "x": agg.index.to_numpy(float),
                "y": agg["y"].to_numpy(float),
                "yerr": err.to_numpy(float) if err.notna().any() else None,
            }
        )
    return out


_FMT = {
    "sample": "{}",
    "theta_i_deg": "\u03b8i {:.4g}\u00b0",
    "wavelength_nm": "{:.4g} nm",
    "channel": "{}",
    "time_s": "t {:.4g} s",
}


def _spectral_panels(
    g: pd.DataFrame, quantities: list[str], split_channels: bool = True
) -> tuple[list[dict[str, Any]], str]:
    """Panels of each quantity against wavelength (or angle); the x description."""
    g = g.assign(theta_i_deg=g["theta_i_deg"].round(2), channel=_channel(g))
    n_wl = g["wavelength_nm"].round(6).nunique()
    by_wl = n_wl > 1
    x = "wavelength_nm" if by_wl else "theta_i_deg"
    xlabel = "wavelength [nm]" if by_wl else "angle of incidence \u03b8i [deg]"
    if not by_wl and g["theta_i_deg"].nunique() <= 1:
        x, xlabel = "wavelength_nm", "wavelength [nm]"
    keys = ["theta_i_deg"] if by_wl else ["wavelength_nm"]
    if g["sample"].nunique() > 1:  # several samples in one file: one line each
        keys = ["sample"] + keys
    times = _times(g)
    if times:
        g = g[g["time_s"].isin(_pick(times, 3))]
        keys = keys + ["time_s"]
    panels = []
    for q in quantities:
        gq = g[g["quantity"] == q]
        if gq.empty:
            continue
        chans = sorted(gq["channel"].unique()) if split_channels else [None]
        for ch in chans:
            gc = gq if ch is None else gq[gq["channel"] == ch]
            k = keys if ch is not None else keys + ["channel"]
            if gc[k[0]].isna().all():
                k = k[1:]
            title = QUANTITY_LABELS.get(q, q) + (f" (channel {ch})" if ch else "")
            panels.append(
                {
                    "title": title,
                    "xlabel": xlabel,
                    "ylabel": _label(q, _unit(gc)),
                    "series": _series(gc, x, k, _FMT),
                }
            )
    return panels, xlabel


def _ranges(g: pd.DataFrame, wl_stated: bool = True) -> str:
    wl = g["wavelength_nm"]
    th = sorted({round(float(t), 2) for t in g["theta_i_deg"].dropna()})
    parts = [
        f"\u03bb {wl.min():.4g}-{wl.max():.4g} nm ({wl.round(6).nunique()} wavelengths)"
        if wl_stated
        else f"wavelength not stated (labelled {wl.min():.4g} nm)"
    ]
    if th:
        parts.append(
            "\u03b8i "
            + (", ".join(f"{t:g}" for t in th) if len(th) <= 8 else f"{th[0]:g}-{th[-1]:g}")
            + " deg"
        )
    else:
        parts.append("no angle of incidence in the file")
    return "; ".join(parts)


def _kinetic_panels(g: pd.DataFrame, quantities: list[str]) -> list[dict[str, Any]]:
    wls = sorted(g["wavelength_nm"].round(6).unique())
    pick = _pick(wls, 3)
    g = g.assign(_wl=g["wavelength_nm"].round(6), theta_i_deg=g["theta_i_deg"].round(2))
    panels = []
    for q in quantities:
        gq = g[(g["quantity"] == q) & g["_wl"].isin(pick)]
        if gq.empty:
            continue
        series = _series(gq, "time_s", ["wavelength_nm", "theta_i_deg"], _FMT)
        for x in series:  # the change since the first time, so that drifts are visible
            y0 = float(x["y"][0])
            x["y"] = x["y"] - y0
            x["label"] = f"{x['label']} (start {y0:.4g})"
        panels.append(
            {
                "title": QUANTITY_LABELS.get(q, q) + ": change since the first time",
                "xlabel": "time [s]",
                "ylabel": "change of " + _label(q, _unit(gq)),
                "series": series,
            }
        )
    return panels


def _map_panels(g: pd.DataFrame, q: str, spots: pd.Series) -> tuple[list[dict[str, Any]], str]:
    gq = g[g["quantity"] == q].assign(
        _spot=spots, _wl=g["wavelength_nm"].round(6), _th=g["theta_i_deg"].round(2)
    )
    gq = gq[gq["quantity"] == q]
    if gq["_wl"].nunique() == 1:
        key, label, members = "_th", "\u03b8i {:g}\u00b0", sorted(gq["_th"].dropna().unique())
        what = "one panel per angle of incidence"
    else:
        th = sorted(gq["_th"].dropna().unique())
        mid = th[len(th) // 2] if th else None
        if mid is not None:
            gq = gq[gq["_th"] == mid]
        key, label, members = "_wl", "{:g} nm", sorted(gq["_wl"].unique())
        what = "one panel per wavelength" + (
            f" at \u03b8i {mid:g}\u00b0" if mid is not None else ""
        )
    panels = []
    for m in _pick(members, 8):
        s = (
            gq[gq[key] == m]
            .groupby("_spot")
            .agg(x=("x_mm", "mean"), y=("y_mm", "mean"), v=("value", "mean"))
        )
        panels.append(
            {
                "title": f"{QUANTITY_LABELS.get(q, q)} at " + label.format(m),
                "x": s["x"].to_numpy(float),
                "y": s["y"].to_numpy(float),
                "value": s["v"].to_numpy(float),
                "label": _label(q, _unit(gq)),
            }
        )
    return panels, what


def _mueller_panels(g: pd.DataFrame) -> list[dict[str, Any]]:
    g = g.assign(theta_i_deg=g["theta_i_deg"].round(2))
    panels = []
    for i in range(1, 5):
        for j in range(1, 5):
            q = f"mueller_{i}{j}"
            gq = g[g["quantity"] == q]
            panels.append(
                {
                    "title": f"M{i}{j}" + ("" if len(gq) else " (not in the file)"),
                    "xlabel": "wavelength [nm]" if i == 4 else "",
                    "ylabel": f"M{i}{j} [{_unit(gq) or '1'}]" if j == 1 else "",
                    "series": _series(gq, "wavelength_nm", ["theta_i_deg"], _FMT)
                    if len(gq)
                    else [],
                }
            )
    return panels


def _brdf_panels(g: pd.DataFrame, q: str, wl_stated: bool = True) -> list[dict[str, Any]]:
    gq = g[g["quantity"] == q].assign(theta_i_deg=g["theta_i_deg"].round(2))
    panels = []
    for wl in _pick(sorted(gq["wavelength_nm"].unique()), 3):
        s = gq[gq["wavelength_nm"] == wl]
        ser = _series(s, "theta_r_deg", ["theta_i_deg"], _FMT)
        for x in ser:
            x["style"] = "points"
        panels.append(
            {
                "title": f"{QUANTITY_LABELS.get(q, q)} at {wl:g} nm"
                if wl_stated
                else f"{QUANTITY_LABELS.get(q, q)}, wavelength not stated",
                "xlabel": "detector angle \u03b8r [deg] (all azimuths)",
                "ylabel": _label(q, _unit(s)),
                "logy": bool((s["value"] > 0).all()),
                "series": ser,
            }
        )
    return panels


def _file(ctx: Context, i: int, src: str, g: pd.DataFrame, meta: Mapping[str, Any]) -> set[str]:
    """The subsection of one file; returns the quantities shown."""
    b = ctx.b
    fid = f"measured_{i}_{slug(src)}"
    quantities = list(dict.fromkeys(g["quantity"]))
    names = sorted({str(s) for s in g["sample"]})
    samples = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
    instr = ", ".join(sorted({str(s) for s in g["instrument"]}))
    b.heading(f"{src}: {samples}", anchor=fid)
    spots = _spots(g)
    times = _times(g)
    extra = []
    if spots is not None:
        extra.append(f"{spots.nunique()} stage positions (spots)")
    if times:
        extra.append(f"kinetic series of {len(times)} times, {times[0]:g}-{times[-1]:g} s")
    if meta.get("reflectance_kind"):
        extra.append(str(meta["reflectance_kind"]))
    b.text(
        f"{instr}: {', '.join(quantities)}; "
        f"{_ranges(g, meta.get('wavelength_stated') is not False)}; {len(g)} rows; "
        "1-sigma given: "
        + ("yes" if g["sigma"].notna().any() else "no")
        + (f"; {'; '.join(extra)}" if extra else "")
        + "."
    )
    shown: set[str] = set()
    ell = [q for q in ("psi", "delta") if q in quantities]
    mueller = [q for q in quantities if q.startswith("mueller_")]
    brdf = [q for q in quantities if q in ("brdf", "btdf", "bsdf")]
    other = [q for q in quantities if q not in ell and q not in mueller and q not in brdf]
    err = (
        "Error bars: the file's 1-sigma where given; the standard deviation where several "
        "spots or zones share a point (their mean is drawn)."
    )
    if ell:
        panels, xlab = _spectral_panels(g, ell)
        b.figure(
            f"{fid}_ellipsometric",
            f"{src}: measured ellipsometric angles \u03a8 and \u0394",
            f"Measured \u03a8 and \u0394 [deg] against {xlab}, one line per "
            + ("angle of incidence" if "wavelength" in xlab else "wavelength")
            + (", at the first, middle and last time of the series" if times else "")
            + f". {err} Nothing modelled.",
            figures.panels_figure(panels, ncols=2 if len(panels) <= 4 else 3),
        )
        shown.update(ell)
    if other:
        panels, xlab = _spectral_panels(g, other)
        b.figure(
            f"{fid}_spectra",
            f"{src}: measured {', '.join(QUANTITY_LABELS.get(q, q) for q in other)}",
            f"Measured {', '.join(other)} against {xlab}"
            + (
                " per angle of incidence and polarisation channel"
                if g["theta_i_deg"].notna().any()
                else ""
            )
            + f". Units as the axis labels say (1 = fraction). {err} Nothing modelled.",
            figures.panels_figure(panels, ncols=min(3, len(panels))),
        )
        shown.update(other)
    if mueller:
        b.figure(
            f"{fid}_mueller",
            f"{src}: measured Mueller-matrix elements (4\u00d74 grid of spectra)",
            "Measured normalised Mueller-matrix elements M_ij [1] against wavelength [nm], one "
            "line per angle of incidence; row i, column j of the grid is M_ij. Elements the "
            "file does not hold (e.g. M11 = 1 by normalisation) are empty panels.",
            figures.panels_figure(_mueller_panels(g), ncols=4, panel_size=(2.9, 2.2)),
            details=True,
        )
        shown.update(mueller)
    if brdf:
        for q in brdf:
            b.figure(
                f"{fid}_{q}",
                f"{src}: measured {q.upper()}",
                f"Measured {q} [sr^-1] against the detector angle \u03b8r [deg], all azimuths "
                "together, one colour per angle of incidence, at up to three wavelengths.",
                figures.panels_figure(
                    _brdf_panels(g, q, meta.get("wavelength_stated") is not False)
                ),
            )
        shown.update(brdf)
    if times:
        panels = _kinetic_panels(g, [q for q in quantities if not q.startswith("mueller_")])
        if panels:
            b.figure(
                f"{fid}_kinetic",
                f"{src}: kinetic series, value against time",
                "Measured values minus their value at the first time (given in the legend), "
                "against time [s], at three wavelengths (first, middle, last "
                f"of the file's {g['wavelength_nm'].round(6).nunique()}), per angle of "
                "incidence. Error bars: the file's 1-sigma where given.",
                figures.panels_figure(panels, ncols=min(3, len(panels))),
            )
    if spots is not None:
        for q in [q for q in quantities if not q.startswith("mueller_")]:
            panels, what = _map_panels(g, q, spots)
            b.figure(
                f"{fid}_map_{q}",
                f"{src}: stage map of {QUANTITY_LABELS.get(q, q)}",
                f"Measured {q} [{_unit(g[g['quantity'] == q])}] at each stage position "
                f"(x, y [mm]; positions within {SPOT_TOL_MM:g} mm are one spot, zones and "
                f"repeats averaged), {what}.",
                figures.map_figure(panels),
                details=True,
            )
    return shown


def measured_section(ctx: Context) -> None:
    """A subsection per ingested file with a figure of every quantity it holds."""
    b = ctx.b
    frames = file_frames(ctx)
    failures = read_failures(ctx)
    for name, why in failures:
        b.note("not shown", f"file {name} could not be read: {why}")
    if not frames:
        raise Unavailable("no file could be read" if failures else "no data ingested")
    b.text(
        f"{len(frames)} file(s): one subsection each, with what was measured, its ranges and "
        "row count, and a figure of every quantity. Large panel sets (maps, Mueller grids) "
        "are folded; click to open."
    )
    missing = []
    for i, (src, g, meta) in enumerate(frames):
        shown = _file(ctx, i, src, g, meta)
        lost = sorted(set(g["quantity"]) - shown)
        if lost:
            missing.append(f"{src}: {', '.join(lost)}")
    b.check(
        "measured.figures",
        "every ingested quantity of every file has a figure",
        not missing,
        against="the quantities of the ingested rows",
        value=len(frames),
        justification="value = files shown; every (file, quantity) must be drawn",
        reason="; ".join(missing),
        substantive=False,
    )
