"""Report sections shared by the validation report and the user report.

Each section function takes the :class:`Context` and adds text, tables, figures and checks
to its :class:`~labbrdf.report._common.Builder`. A section whose inputs are missing raises
:class:`~labbrdf.report._common.Unavailable` (rendered "not available: <reason>", its checks
skipped).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ._common import Builder, Unavailable

__all__ = ["Context", "FitRecord", "fit_task", "params_of"]

#: quantities fitted as BRDF scans
SCAN_QUANTITIES = ("brdf", "specular_intensity")

#: default optimiser (DESIGN.md "Fitting")
METHOD = "GN_CRS2_LM+LN_BOBYQA"


@dataclass
class FitRecord:
    """One fit of one model to one (sample, wavelength) group."""

    model: str
    options: dict[str, Any]
    sample: str
    wavelength_nm: float
    data: pd.DataFrame
    summary: dict[str, Any]
    values: dict[str, float]
    params: dict[str, dict[str, Any]]
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
    #: further :func:`labbrdf.fit` keywords for every fit of the report (e.g. ``maxeval``)
    fit_options: dict[str, Any] = field(default_factory=dict)
    files: list[dict[str, Any]] = field(default_factory=list)
    frames: list[pd.DataFrame] = field(default_factory=list)
    fits: dict[str, list[FitRecord]] = field(default_factory=dict)
    published: dict[str, pd.DataFrame] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)

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


# --------------------------------------------------------------------------- helpers


def _num(x: Any) -> float | None:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def params_of(summary: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """Parameters of a ``FitResult.summary()`` as name -> {value, stderr, lo, hi, flags, units}.

    Accepts ``params`` as a mapping name -> dict or a list of dicts with ``name``.
    """
    raw = summary.get("params", {})
    items = raw.items() if isinstance(raw, Mapping) else ((p.get("name"), p) for p in raw)
    out: dict[str, dict[str, Any]] = {}
    for name, p in items:
        if not isinstance(p, Mapping):
            p = {"value": p}
        ci = p.get("ci95") or [p.get("ci95_lo"), p.get("ci95_hi")]
        ci = list(ci) if isinstance(ci, (list, tuple)) and len(ci) == 2 else [None, None]
        flags = p.get("flags") or []
        if isinstance(flags, str):
            flags = [flags] if flags else []
        out[str(name)] = {
            "value": _num(p.get("value")),
            "stderr": _num(p.get("stderr")),
            "lo": _num(ci[0]),
            "hi": _num(ci[1]),
            "flags": [str(f) for f in flags],
            "units": p.get("units", ""),
            "vary": p.get("vary", True),
        }
    return out


def _first(summary: Mapping[str, Any], *keys: str) -> Any:
    for k in keys:
        if k in summary and summary[k] is not None:
            return summary[k]
    return None


def rmse_paper(summary: Mapping[str, Any]) -> float | None:
    """The fit error in the paper's sense [%], whatever key the fitter used."""
    v = _first(summary, "rmse_paper", "rmse_pct", "rmse_percent", "rmse_rel_pct")
    if v is None and isinstance(summary.get("rmse"), Mapping):
        v = _first(summary["rmse"], "paper", "percent", "relative_pct")
    return _num(v)


def rmse_abs(summary: Mapping[str, Any]) -> float | None:
    """Absolute RMSE in the data's units."""
    v = _first(summary, "rmse_abs", "rmse_absolute")
    if v is None:
        r = summary.get("rmse")
        v = _first(r, "abs", "absolute") if isinstance(r, Mapping) else r
    return _num(v)


def fit_task(
    task: tuple[str, dict[str, Any], pd.DataFrame, str, int, dict[str, Any]],
) -> dict[str, Any]:
    """Fit one group (module level, so that process and dask schedulers can pickle it)."""
    import labbrdf
    from labbrdf import models

    name, options, df, method, seed, fit_options = task
    model = models.get(name, **options)
    res = labbrdf.fit(model, df, method=method, seed=seed, **fit_options)
    return dict(res.summary())


def _run(ctx: Context, func: Any, items: list[Any], desc: str) -> list[Any]:
    if ctx.scheduler in (None, "serial") or len(items) < 2:
        out = [func(it) for it in items]
        ctx.b.log(f"  {desc}: {len(items)} done")
        return out
    from labbrdf import parallel

    return parallel.run(
        func,
        items,
        scheduler=ctx.scheduler,
        workers=ctx.workers,
        progress=ctx.progress,
        desc=desc,
    )


def _slug(s: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in s)[:40] or "sample"


def _wl(x: float) -> str:
    return f"{x:g} nm"


# --------------------------------------------------------------------------- ingest


def _meta_header(meta: Mapping[str, Any], limit: int = 3) -> str:
    for key in ("header_lines", "header", "comments", "comment", "notes"):
        v = meta.get(key)
        if isinstance(v, str) and v.strip():
            return v.strip()[:300]
        if isinstance(v, list) and v:
            return " | ".join(str(x) for x in v[:limit])[:300]
        if isinstance(v, Mapping) and v:
            return " | ".join(f"{k}: {x}" for k, x in list(v.items())[:limit])[:300]
    return ""


def ingest(
    ctx: Context,
    paths: Sequence[str | os.PathLike[str]],
    root: Path | None = None,
    *,
    check_id: str = "ingest.read",
) -> None:
    """Read every file; a table of what each holds; a check that all were read."""
    import labbrdf
    from labbrdf import adapters

    b = ctx.b
    paths = [Path(p) for p in paths]
    if not paths:
        raise Unavailable("no input files")
    rows, failures = [], []
    for p in paths:
        name = str(p.relative_to(root)) if root is not None and p.is_relative_to(root) else p.name
        try:
            m = labbrdf.read(p)
        except Exception as exc:  # noqa: BLE001 - each failure is reported
            failures.append(f"{name}: {exc}")
            rows.append({"file": name, "status": "error", "error": str(exc)})
            continue
        fmt_name = m.meta.get("format") or m.meta.get("adapter") or ""
        if not fmt_name:
            try:
                cands = adapters.sniff(p)
                fmt_name = cands[0] if len(cands) == 1 else ""
            except Exception:  # noqa: BLE001 - format name is informative only
                fmt_name = ""
        s = m.summary()
        d = m.data
        ctx.frames.append(d)
        rec = {
            "file": name,
            "status": "read",
            "format": fmt_name,
            "sample": ", ".join(s["sample"]),
            "instrument": ", ".join(sorted(set(d["instrument"]))),
            "quantities": ", ".join(s["quantities"]),
            "rows": s["rows"],
            "wl_min": s["wavelength_nm"][0],
            "wl_max": s["wavelength_nm"][1],
            "theta_i": ", ".join(f"{t:g}" for t in s["theta_i_deg"]),
            "sigma": "yes" if d["sigma"].notna().any() else "no",
            "header": _meta_header(m.meta),
            "error": "",
        }
        ctx.files.append({**rec, "path": str(p), "meta": m.meta})
        rows.append(rec)
    b.table(
        "ingested_files",
        "Ingested files",
        [
            ("file", "file", ""),
            ("status", "status", ""),
            ("format", "format", ""),
            ("sample", "sample(s)", ""),
            ("instrument", "instrument", ""),
            ("quantities", "quantities", ""),
            ("rows", "rows", "d"),
            ("wl_min", "\u03bb min [nm]", ".6g"),
            ("wl_max", "\u03bb max [nm]", ".6g"),
            ("theta_i", "\u03b8i [deg]", ""),
            ("sigma", "\u03c3 given", ""),
            ("header", "header / comments (from the file)", ""),
            ("error", "error", ""),
        ],
        rows,
        caption="One row per input file: what the reader found in it. Text in the last "
        "columns is copied from the file and shown verbatim.",
    )
    b.check(
        check_id,
        "every input file reads into the common dataset",
        not failures,
        against="labbrdf.read (adapters) and the dataset schema",
        value=len(paths) - len(failures),
        tolerance=len(paths),
        justification="value = files read, tolerance = files given; all must read",
        reason="; ".join(failures)[:2000],
    )
    if not ctx.frames:
        raise Unavailable("no file could be read")


# --------------------------------------------------------------------------- fits


def run_fits(
    ctx: Context,
    models: Sequence[tuple[str, dict[str, Any]]],
    scans: pd.DataFrame | None = None,
    group: str = "all",
) -> dict[str, list[FitRecord]]:
    """Fit each model to each (sample, wavelength) group of the scan rows."""
    scans = ctx.scans() if scans is None else scans
    groups = [
        (str(s), float(w), g.reset_index(drop=True))
        for (s, w), g in scans.groupby(["sample", "wavelength_nm"], sort=True)
    ]
    out: dict[str, list[FitRecord]] = {}
    for name, options in models:
        tasks = [
            (name, dict(options), g, ctx.method, ctx.seed, dict(ctx.fit_options))
            for _, _, g in groups
        ]
        ctx.b.log(f"  fitting {name} to {len(tasks)} groups ({group})")
        summaries = _run(ctx, fit_task, tasks, f"fit {name}")
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


def _published_params(ctx: Context, sample: str, wl: float) -> dict[str, float | None]:
    """Published smooth3 parameters (Tables 1-2) for a sample and wavelength, if any."""
    t = ctx.published.get("params")
    if t is None:
        return {}
    m = t[(t["sample"].str.lower() == sample.lower()) & (np.isclose(t["wavelength_nm"], wl))]
    if not len(m):
        return {}
    r = m.iloc[0]
    return {k: _num(r.get(k)) for k in ("k1", "k2", "k3", "rmse")}


def fits_section(
    ctx: Context,
    models: Sequence[tuple[str, dict[str, Any]]],
    *,
    published_check: bool = False,
    chi2_models: Sequence[str] | None = None,
) -> None:
    """Tables 1-2 style parameter tables; success, chi-square and published-value checks.

    ``chi2_models``: models whose reduced chi-square is a check (default: all); for the
    others it is shown as a finding (e.g. five_param fitted to data made with smooth3).
    """
    from scipy import stats

    b = ctx.b
    ctx.fits.update(run_fits(ctx, models))
    for name, recs in ctx.fits.items():
        if not recs:
            continue
        pnames = list(recs[0].params)
        varying = [p for p in pnames if recs[0].params[p].get("vary", True)]
        has_pub = name == "smooth3" and "params" in ctx.published
        cols: list[tuple[str, str, str]] = [
            ("sample", "sample", ""),
            ("wavelength_nm", "\u03bb [nm]", "g"),
        ]
        for p in varying:
            u = recs[0].params[p].get("units") or ""
            unit = f" [{u}]" if u and u != "1" else ""
            cols += [
                (p, f"{p}{unit}", ".5g"),
                (f"{p}_stderr", f"\u03c3({p})", ".2g"),
                (f"{p}_lo", f"{p} 95% lo", ".5g"),
                (f"{p}_hi", f"{p} 95% hi", ".5g"),
            ]
            if has_pub:
                cols.append((f"{p}_pub", f"{p} published", ".5g"))
        cols += [("flags", "flags", ""), ("rmse_paper", "RMSE (paper's sense) [%]", ".4g")]
        if has_pub:
            cols.append(("rmse_pub", "RMSE published [%]", ".4g"))
        cols += [
            ("rmse_abs", "RMSE [data units]", ".3g"),
            ("redchi", "\u03c7\u00b2/\u03bd", ".4g"),
            ("nfev", "nfev", "d"),
            ("success", "success", ""),
        ]
        rows = []
        for r in recs:
            row: dict[str, Any] = {"sample": r.sample, "wavelength_nm": r.wavelength_nm}
            pub = _published_params(ctx, r.sample, r.wavelength_nm) if has_pub else {}
            flags = []
            for p in varying:
                q = r.params[p]
                row.update(
                    {
                        p: q["value"],
                        f"{p}_stderr": q["stderr"],
                        f"{p}_lo": q["lo"],
                        f"{p}_hi": q["hi"],
                        f"{p}_pub": pub.get(p),
                    }
                )
                flags += [f"{p}: {f}" for f in q["flags"]]
            row["flags"] = "; ".join(flags)
            row["rmse_paper"] = rmse_paper(r.summary)
            row["rmse_pub"] = pub.get("rmse")
            row["rmse_abs"] = rmse_abs(r.summary)
            row["redchi"] = _num(r.summary.get("redchi"))
            row["nfev"] = r.summary.get("nfev")
            row["success"] = bool(r.summary.get("success"))
            rows.append(row)
        opts = ", ".join(f"{k}={v}" for k, v in recs[0].options.items()) or "defaults"
        b.table(
            f"fit_{name}",
            f"Fitted {name} parameters per sample and wavelength ({opts})",
            cols,
            rows,
            caption=f"Measured: the scan rows of each (sample, wavelength). Modelled: {name} "
            f"fitted with nlopt {ctx.method} (seed {ctx.seed}). \u03c3 from the Jacobian at the "
            "optimum, 95% interval from the t distribution; flags mark parameters at a bound "
            "or not identifiable from the data."
            + (" 'published' columns: Zou, Bai, Wu 2013, Tables 1-2." if has_pub else ""),
        )
        bad = [
            f"{r.sample} {_wl(r.wavelength_nm)}: {r.summary.get('message', '')}"
            for r in recs
            if not r.summary.get("success")
        ]
        b.check(
            f"fits.{name}.success",
            f"every {name} fit converged",
            not bad,
            against="the optimiser's success flag",
            value=len(recs) - len(bad),
            tolerance=len(recs),
            justification="value = converged fits, tolerance = fits run",
            reason="; ".join(bad)[:1000],
        )
        # chi-square consistency where the files give sigma
        lohi = []
        worst = None
        ok = True
        for r in recs:
            red = _num(r.summary.get("redchi"))
            has_sigma = r.data["sigma"].notna().all()
            nfree = len(r.data) - len(varying)
            if red is None or not has_sigma or nfree < 1:
                continue
            lo = stats.chi2.ppf(0.0005, nfree) / nfree
            hi = stats.chi2.ppf(0.9995, nfree) / nfree
            lohi.append((lo, hi))
            if not lo <= red <= hi:
                ok = False
            if worst is None or abs(math.log(red)) > abs(math.log(worst)):
                worst = red
        if chi2_models is not None and name not in chi2_models:
            shown = "n/a" if worst is None else f"{worst:.4g}"
            b.text(
                f"{name}: reduced \u03c7\u00b2 up to {shown} (a finding, not a check: the "
                "data were not generated with this model)."
            )
        elif lohi:
            b.check(
                f"fits.{name}.chi2",
                f"{name}: reduced \u03c7\u00b2 of every fit consistent with the file's \u03c3",
                ok,
                against="the \u03c7\u00b2 distribution with \u03bd = N - n_par",
                value=worst,
                tolerance=[min(x for x, _ in lohi), max(y for _, y in lohi)],
                justification="two-sided 99.9% interval of \u03c7\u00b2/\u03bd per fit; a model "
                "that describes the data within their stated \u03c3 lands inside",
            )
        else:
            b.skip(
                f"fits.{name}.chi2",
                f"{name}: reduced \u03c7\u00b2 consistent with \u03c3",
                "the data carry no \u03c3 (or no redchi in the fit summary)",
            )
        if published_check and has_pub:
            _published_check(ctx, recs, varying)


def _published_check(ctx: Context, recs: Sequence[FitRecord], varying: Sequence[str]) -> None:
    worst, n, bad = 0.0, 0, []
    for r in recs:
        pub = _published_params(ctx, r.sample, r.wavelength_nm)
        for p in varying:
            se, v, pv = r.params[p]["stderr"], r.params[p]["value"], pub.get(p)
            if pv is None or v is None or not se:
                continue
            z = abs(v - pv) / se
            n += 1
            worst = max(worst, z)
            if z > 4:
                bad.append(
                    f"{r.sample} {_wl(r.wavelength_nm)} {p}: {v:.5g} vs {pv:.5g} ({z:.1f} \u03c3)"
                )
    if n == 0:
        ctx.b.skip(
            "fits.smooth3.published",
            "smooth3 recovers the published parameters",
            "no published value with a finite fitted \u03c3",
        )
        return
    ctx.b.check(
        "fits.smooth3.published",
        "smooth3 fits recover the published Tables 1-2 parameters (the fixtures' generating "
        "values)",
        not bad,
        against="Zou, Bai, Wu 2013, Tables 1-2",
        value=worst,
        tolerance=4.0,
        justification="largest |fit - published| / \u03c3(fit) over all parameters; the "
        "synthetic fixtures were generated from the published values, so each should lie "
        "within 4 \u03c3 (two-sided false-alarm rate 6e-5 per parameter)",
        reason="; ".join(bad)[:1000],
    )
