"""The state one report's sections share: the :class:`Context`, fit records, published tables.

Each section function (:mod:`labbrdf.report.sections`) takes the :class:`Context` and adds
text, tables, figures and checks to its :class:`~labbrdf.report.builder.Builder`. Fits run
through :func:`labbrdf.fitting.fit` and are kept as :class:`FitRecord` s built from
:meth:`labbrdf.FitResult.summary` (a plain dict, so that it travels between
processes). The published tables of Zou, Bai, Wu (2013) are read here
(:func:`load_published`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypedDict, TypeVar

import numpy as np
import pandas as pd

from .. import models, parallel
from ..adapters.topography import HeightMap
from ..fitting import fit
from ..tracer import TraceResult
from .builder import Builder, Unavailable, num

__all__ = [
    "METHOD",
    "SCAN_QUANTITIES",
    "Context",
    "FitRecord",
    "ParamRecord",
    "curve_grid",
    "fit_task",
    "load_published",
    "model_curve",
    "paper_values",
    "params_of",
    "published_params",
    "rmse_abs",
    "rmse_paper",
    "run_fits",
    "run_tasks",
]

#: quantities fitted as BRDF scans
SCAN_QUANTITIES = ("brdf", "specular_intensity")

#: default optimiser: a global stage then a local one (docs/models.md, "Fitting")
METHOD = "GN_CRS2_LM+LN_BOBYQA"

_T = TypeVar("_T")
_R = TypeVar("_R")


class ParamRecord(TypedDict):
    """One fitted parameter as the report shows it (from ``FitResult.summary()["params"]``)."""

    value: float | None
    stderr: float | None
    lo: float | None
    hi: float | None
    flags: list[str]
    units: str
    vary: bool


@dataclass
class FitRecord:
    """One fit of one model to one (sample, wavelength) group."""

    model: str
    options: dict[str, Any]
    sample: str
    wavelength_nm: float
    data: pd.DataFrame
    #: :meth:`labbrdf.FitResult.summary` of the fit
    summary: dict[str, Any]
    values: dict[str, float]
    params: dict[str, ParamRecord]
    group: str = "all"


@dataclass
class Context:
    """State shared by the sections of one report."""

    b: Builder
    quick: bool = False
    scheduler: str | None = None
    workers: int | None = None
    progress: bool = False
    method: str = METHOD
    seed: int = 0
    #: further :func:`labbrdf.fitting.fit` keywords for every fit of the report (``maxeval``)
    fit_options: dict[str, Any] = field(default_factory=dict)
    files: list[dict[str, Any]] = field(default_factory=list)
    frames: list[pd.DataFrame] = field(default_factory=list)
    fits: dict[str, list[FitRecord]] = field(default_factory=dict)
    published: dict[str, pd.DataFrame] = field(default_factory=dict)
    #: validation report only: tracer scale (``validate.SCALES``), fixture and oracle folders
    scale: dict[str, int] = field(default_factory=dict)
    fixtures: Path | None = None
    shared: Path | None = None
    #: results kept for later sections (and tests): the compare fits, the factor-study runs
    compare_fits: dict[str, list[FitRecord]] = field(default_factory=dict)
    factor_runs: list[tuple[str, str, TraceResult]] = field(default_factory=list)
    #: user report: height maps and profiles read from topography files (section ``surface``)
    height_maps: list[HeightMap] = field(default_factory=list)

    @property
    def data(self) -> pd.DataFrame | None:
        """All ingested rows, or None."""
        if not self.frames:
            return None
        return pd.concat(
            [f.assign(quantity=f["quantity"].astype(str)) for f in self.frames],
            ignore_index=True,
        )

    def scans(self) -> pd.DataFrame:
        """Rows that can be fitted as BRDF scans (quantity brdf, else specular_intensity)."""
        d = self.data
        if d is None:
            raise Unavailable("no data ingested")
        for q in SCAN_QUANTITIES:
            s = d[d["quantity"] == q]
            if len(s):
                return s.reset_index(drop=True)
        raise Unavailable(f"no rows with quantity {' or '.join(SCAN_QUANTITIES)} ingested")


# --------------------------------------------------------------------------- fit summaries


def params_of(summary: Mapping[str, Any]) -> dict[str, ParamRecord]:
    """The parameters of a ``FitResult.summary()`` as name -> :class:`ParamRecord`."""
    out: dict[str, ParamRecord] = {}
    for name, p in summary["params"].items():
        lo, hi = p["ci95"] or (None, None)
        out[str(name)] = {
            "value": num(p["value"]),
            "stderr": num(p["stderr"]),
            "lo": num(lo),
            "hi": num(hi),
            "flags": [str(f) for f in p["flags"]],
            "units": p["units"],
            "vary": p["vary"],
        }
    return out


def rmse_paper(summary: Mapping[str, Any]) -> float | None:
    """The fit error in the paper's sense [%] (``FitResult.rmse_pct``)."""
    return num(summary["rmse_pct"])


def rmse_abs(summary: Mapping[str, Any]) -> float | None:
    """Absolute RMSE in the data's units (``FitResult.rmse``)."""
    return num(summary["rmse"])


# --------------------------------------------------------------------------- fits


def fit_task(
    task: tuple[str, dict[str, Any], pd.DataFrame, str, int, dict[str, Any]],
) -> dict[str, Any]:
    """Fit one group (module level, so that process and dask schedulers can pickle it)."""
    name, options, df, method, seed, fit_options = task
    model = models.get(name, **options)
    res = fit(model, df, method=method, seed=seed, **fit_options)
    return dict(res.summary())


def run_tasks(ctx: Context, func: Callable[[_T], _R], items: list[_T], desc: str) -> list[_R]:
    """``[func(it) for it in items]`` on the report's scheduler (in this process if none)."""
    if ctx.scheduler in (None, "serial") or len(items) < 2:
        out = [func(it) for it in items]
        ctx.b.log(f"  {desc}: {len(items)} done")
        return out
    return parallel.run(
        func,
        items,
        scheduler=ctx.scheduler,
        workers=ctx.workers,
        progress=ctx.progress,
        desc=desc,
    )


def run_fits(
    ctx: Context,
    model_specs: Sequence[tuple[str, dict[str, Any]]],
    scans: pd.DataFrame | None = None,
    group: str = "all",
) -> dict[str, list[FitRecord]]:
    """Fit each (model name, options) to each (sample, wavelength) group of the scan rows."""
    scans = ctx.scans() if scans is None else scans
    groups = [
        (str(s), float(w), g.reset_index(drop=True))
        for (s, w), g in scans.groupby(["sample", "wavelength_nm"], sort=True)
    ]
    out: dict[str, list[FitRecord]] = {}
    for name, options in model_specs:
        tasks = [
            (name, dict(options), g, ctx.method, ctx.seed, dict(ctx.fit_options))
            for _, _, g in groups
        ]
        ctx.b.log(f"  fitting {name} to {len(tasks)} groups ({group})")
        summaries = run_tasks(ctx, fit_task, tasks, f"fit {name}")
        recs = []
        for (s, w, g), summ in zip(groups, summaries, strict=True):
            ps = params_of(summ)
            recs.append(
                FitRecord(
                    name,
                    dict(options),
                    s,
                    w,
                    g,
                    summ,
                    {k: v["value"] for k, v in ps.items() if v["value"] is not None},
                    ps,
                    group,
                )
            )
        out[name] = recs
    return out


def curve_grid(theta_r: np.ndarray) -> np.ndarray:
    """121 detector angles [deg] spanning the measured ones with a 5 % margin."""
    lo, hi = float(np.min(theta_r)), float(np.max(theta_r))
    pad = 0.05 * max(hi - lo, 0.5)
    return np.linspace(max(0.0, lo - pad), min(89.9, hi + pad), 121)


def model_curve(
    rec: FitRecord, theta_i: float, theta_r_deg: np.ndarray, phi_r_deg: float = 180.0
) -> np.ndarray:
    """The fitted model of ``rec`` at ``theta_r_deg`` (in-plane by default) [sr^-1]."""
    m = models.get(rec.model, **rec.options)
    return np.asarray(
        m.evaluate(
            math.radians(theta_i),
            np.radians(theta_r_deg),
            math.radians(phi_r_deg),
            wavelength=rec.wavelength_nm,
            params=rec.values,
        )
    )


# --------------------------------------------------------------------------- published


def _rename(df: pd.DataFrame) -> pd.DataFrame:
    ren = {}
    for c in df.columns:
        lc = str(c).strip().lower()
        for key in ("k1", "k2", "k3", "rmse", "sample"):
            if lc.startswith(key):
                ren[c] = key
        if lc.startswith("wavelength") or lc in ("lambda_nm", "wl_nm"):
            ren[c] = "wavelength_nm"
        if lc.startswith("integration"):
            ren[c] = "integration_pct"
        if lc.startswith("measured") or lc.startswith("hemispherical"):
            ren[c] = "measured_pct"
        if lc.startswith("error") or lc.startswith("relative"):
            ren[c] = "error_pct"
    return df.rename(columns=ren)


def load_published(ctx: Context, folder: Path) -> list[str]:
    """Read the published Tables 1-3 into ``ctx.published``; returns the files read.

    The files are ``zou2013_table{1,2,3}.csv`` of the fixtures' ``published/`` folder, with
    their citation headers: Zou X., Bai L., Wu Z., "Mirror reflectance spectrum modeling of
    smooth samples", Acta Optica Sinica 33(6), 0612008 (2013), doi:10.3788/AOS201333.0612008.
    """
    read = []
    frames = []
    for n, default_sample in ((1, "OSR"), (2, "mirror")):
        p = folder / f"zou2013_table{n}.csv"
        if p.is_file():
            t = _rename(pd.read_csv(p, comment="#", skipinitialspace=True))
            if "sample" not in t.columns:
                t["sample"] = default_sample
            t["sample"] = t["sample"].astype(str)
            frames.append(t)
            read.append(p.name)
    if frames:
        ctx.published["params"] = pd.concat(frames, ignore_index=True)
    p = folder / "zou2013_table3.csv"
    if p.is_file():
        ctx.published["table3"] = _rename(pd.read_csv(p, comment="#", skipinitialspace=True))
        read.append(p.name)
    return read


def published_params(ctx: Context, sample: str, wl: float) -> dict[str, float | None]:
    """Published smooth3 k1, k2, k3 and RMSE (Tables 1-2) of a sample and wavelength.

    Empty when the tables or the row are missing; a blank cell is None.
    """
    t = ctx.published.get("params")
    if t is None:
        return {}
    m = t[(t["sample"].str.lower() == sample.lower()) & (np.isclose(t["wavelength_nm"], wl))]
    if not len(m):
        return {}
    r = m.iloc[0]
    return {k: num(r.get(k)) for k in ("k1", "k2", "k3", "rmse")}


def paper_values(ctx: Context, sample: str, wl: float) -> dict[str, float] | None:
    """The paper's smooth3 parameters (k1, k2, k3) of a sample and wavelength, or None."""
    t = ctx.published.get("params")
    if t is None:
        return None
    m = t[(t["sample"].str.lower() == sample.lower()) & np.isclose(t["wavelength_nm"], wl)]
    if not len(m):
        return None
    r = m.iloc[0]
    return {"k1": float(r["k1"]), "k2": float(r["k2"]), "k3": float(r["k3"])}
