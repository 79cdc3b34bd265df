"""The state one report's sections share: the :class:`Context` and its fit records.

Each section function (:mod:`labbrdf.report.sections`) takes the :class:`Context` and adds
text, tables, figures and checks to its :class:`~labbrdf.report.builder.Builder`. Fits run
through the batch fitter :func:`labbrdf.fitting.fit_many` on the report's
:class:`~labbrdf.parallel.Executor` and are kept as :class:`FitRecord` s
(:func:`fit_records`). The published tables of Zou, Bai, Wu (2013) are read by
:mod:`labbrdf.report.published` into ``Context.published``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypedDict

import numpy as np
import pandas as pd

from .. import models
from .._plotting import curve_grid
from ..adapters.topography import HeightMap
from ..fitting import METHOD, FitError, FitResult, fit_many
from ..parallel import Executor
from ..samples import SampleGroup
from ..tracer import TraceResult
from .builder import Builder, Unavailable, num

__all__ = [
    "SCAN_QUANTITIES",
    "Context",
    "FitRecord",
    "ParamRecord",
    "curve_grid",
    "fit_records",
    "model_curve",
    "params_of",
    "rmse_abs",
    "rmse_paper",
    "run_fits",
]

#: quantities fitted as BRDF scans
SCAN_QUANTITIES = ("brdf", "specular_intensity")

#: the groups of a report's fits: one fit per sample and wavelength
BY = ("sample", "wavelength_nm")


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
    #: where the fits and tracer runs go (default: ``labbrdf.parallel.DEFAULT_SCHEDULER``)
    executor: Executor = field(default_factory=Executor)
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
    #: user report: the height maps and profiles :func:`labbrdf.adapters.read_inputs` read
    #: among the inputs (section ``surface``)
    height_maps: list[HeightMap] = field(default_factory=list)
    #: user report: the input files grouped by sample (:func:`labbrdf.samples.pair_samples`)
    samples: list[SampleGroup] = field(default_factory=list)
    #: user report: combined n, k per ellipsometer file (section ``nk``), by file name
    nk_combined: dict[str, pd.DataFrame] = field(default_factory=dict)
    #: user report: the film stack fitted per psi/Delta file (section ``film``), by file name
    film_fits: dict[str, Any] = field(default_factory=dict)
    #: user report: the wavelength [nm] the user gave for files that state none (a .bsdf)
    wavelength_nm: float | None = None
    #: user report: each height map's sigma and band, by path (section ``smoothness``)
    map_roughness: dict[str, Any] = field(default_factory=dict)

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


def fit_records(
    name: str,
    options: Mapping[str, Any],
    rows: pd.DataFrame,
    table: pd.DataFrame,
    results: Sequence[tuple[dict[str, Any], FitResult]],
    by: Sequence[str] = BY,
    group: str | Sequence[str] = "all",
) -> list[FitRecord]:
    """The :class:`FitRecord` s of a :func:`labbrdf.fitting.fit_many` run, in table order.

    Parameters
    ----------
    name, options :
        The model's registry name and options (a record rebuilds its model from them).
    rows : DataFrame
        The rows that were fitted; each record keeps those of its group.
    table, results :
        What ``fit_many(rows, ..., by=by, return_results=True)`` returned.
    by : sequence of str
        The grouping columns of that run.
    group : str or sequence of str
        The records' group label, one for all or one per result.

    Raises
    ------
    FitError
        A group could not be fitted (too few points, ...): a report shows every group's
        fit or none, naming the group and the reason.
    """
    failed = table[~table["success"].astype(bool) & table["message"].str.startswith("not fitted")]
    if len(failed):
        r = failed.iloc[0]
        where = ", ".join(f"{c}={r[c]}" for c in by)
        raise FitError(f"{name}: group {where}: {r['message']}")
    labels = [group] * len(results) if isinstance(group, str) else list(group)
    out = []
    for (key, res), label in zip(results, labels, strict=True):
        mask = np.ones(len(rows), bool)
        for c, v in key.items():
            mask &= (rows[c] == v).to_numpy()
        summ = dict(res.summary())
        ps = params_of(summ)
        out.append(
            FitRecord(
                name,
                dict(options),
                str(key["sample"]),
                float(key["wavelength_nm"]),
                rows[mask].reset_index(drop=True),
                summ,
                {k: v["value"] for k, v in ps.items() if v["value"] is not None},
                ps,
                label,
            )
        )
    return out


def run_fits(
    ctx: Context,
    model_specs: Sequence[tuple[str, dict[str, Any]]],
    scans: pd.DataFrame | None = None,
    group: str = "all",
) -> dict[str, list[FitRecord]]:
    """Fit each (model name, options) to each (sample, wavelength) group of the scan rows."""
    scans = ctx.scans() if scans is None else scans
    out: dict[str, list[FitRecord]] = {}
    for name, options in model_specs:
        table, results = fit_many(
            scans,
            models.get(name, **options),
            by=BY,
            method=ctx.method,
            seed=ctx.seed,
            executor=ctx.executor,
            return_results=True,
            **ctx.fit_options,
        )
        ctx.b.log(f"  fitted {name} to {len(table)} groups ({group})")
        out[name] = fit_records(name, options, scans, table, results, BY, group)
    return out


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
