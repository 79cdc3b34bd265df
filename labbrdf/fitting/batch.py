"""Batch fits: one fit per group of a dataset, on the executor of :mod:`labbrdf.parallel`."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

from ..dataset import Measurement
from ..models import Model
from ..models import get as get_model
from .core import fit, parse_method, setup_params
from .data import FitData, FitError, select_rows, several_groups_message
from .result import FitResult

__all__ = ["fit_many"]


def _sort_key(key: Any) -> tuple[Any, ...]:
    key = key if isinstance(key, tuple) else (key,)
    return tuple((v != v, str(type(v)), v if v == v else 0) for v in key)  # NaN last


def _fit_chunk(
    payload: tuple[Model, list[tuple[int, FitData]], dict[str, Any], bool],
) -> list[tuple[int, dict[str, Any], FitResult | None]]:
    """Worker: fit each group of a chunk; a group whose data cannot be fitted gives a row."""
    model, groups, kw, keep = payload
    out: list[tuple[int, dict[str, Any], FitResult | None]] = []
    for i, fd in groups:
        try:
            res = fit(model, fd, **kw)
            out.append((i, res.summary(), res if keep else None))
        except FitError as exc:
            out.append((i, {"success": False, "message": f"not fitted: {exc}"}, None))
    return out


def _plain(v: Any) -> Any:
    return v.item() if isinstance(v, np.generic) else v


def fit_many(
    data: Measurement | pd.DataFrame,
    model: Model | str,
    *,
    by: Sequence[str] = ("sample", "wavelength_nm"),
    method: str = "GN_CRS2_LM+LN_BOBYQA",
    seed: int = 0,
    scheduler: str = "processes",
    workers: int | None = None,
    progress: bool = True,
    chunks: int | None = None,
    return_results: bool = False,
    **fit_kw: Any,
) -> pd.DataFrame | tuple[pd.DataFrame, list[tuple[dict[str, Any], FitResult]]]:
    """Fit one model to every group of a dataset; a parameter table like Tables 1-2 of 2013.

    Parameters
    ----------
    data : Measurement or DataFrame
        Dataset-schema rows. The fittable rows are selected once for the whole table, as
        in :func:`fit` (a table that mixes quantities or units needs ``quantity=`` /
        ``unit=``); groups without fittable rows get no row.
    model : Model or str
    by : sequence of str
        Grouping columns; one fit per group, in sorted group order.
    method, seed :
        As for :func:`fit`. Every group uses the same ``seed``, so a row equals
        ``fit(model, group, seed=seed)`` whatever the scheduler and worker count.
    scheduler, workers, progress :
        Passed to :func:`labbrdf.parallel.run` (``serial``, ``processes``, ``local``,
        ``tcp://host:port``); the progress bar counts chunks of groups.
    chunks : int, optional
        Number of tasks the groups are split into (default ``4 x workers``, serial: 1),
        so that per-task overhead stays small against 1-10 ms fits.
    return_results : bool
        Also return the :class:`FitResult` of every fitted group, as a list of
        ``(group key dict, FitResult)`` in table order (groups that could not be fitted are
        left out).
    **fit_kw :
        Any other :func:`fit` keyword (``fix``, ``energy_constraint``, ``quantity`` ...).

    Returns
    -------
    pandas.DataFrame, or (DataFrame, list) with ``return_results``
        One row per group: the group keys; per parameter ``<name>``, ``<name>_stderr``,
        ``<name>_ci95_lo``, ``<name>_ci95_hi``, ``<name>_flags`` (``;``-joined); then
        ``rmse``, ``rmse_pct``, ``chisqr``, ``redchi``, ``ndata``, ``nfev``, ``success``,
        ``message``, ``elapsed_s``. A group that cannot be fitted (too few points, ...) gets
        ``success=False`` and the reason in ``message``.
    """
    if isinstance(model, str):
        model = get_model(model)
    parse_method(method)
    if isinstance(data, Measurement):
        data = data.data
    if not isinstance(data, pd.DataFrame):
        raise FitError(f"data: expected a Measurement or DataFrame, got {type(data).__name__}")
    by = [by] if isinstance(by, str) else list(by)
    missing = [c for c in by if c not in data.columns]
    if missing:
        raise FitError(f"by: unknown column(s) {missing}; columns are {list(data.columns)}")
    setup_params(model, fit_kw.get("params"), fit_kw.get("fix"))  # fail early on names
    d, qty, unt = select_rows(data, fit_kw.pop("quantity", None), fit_kw.pop("unit", None))
    arrays = {
        c: d[c].to_numpy()
        for c in ("theta_i_deg", "theta_r_deg", "value", "sigma", "phi_r_deg", "wavelength_nm")
        if c in d.columns
    }
    codes = {
        k: pd.factorize(d[k], use_na_sentinel=False)[0]
        for k in ("sample", "wavelength_nm")
        if k in d.columns and k not in by
    }
    keys: list[tuple[Any, ...]] = []
    groups: list[FitData | str] = []
    for key, idx in sorted(
        d.groupby(by, sort=True, dropna=False).indices.items(), key=lambda kv: _sort_key(kv[0])
    ):
        keys.append(key if isinstance(key, tuple) else (key,))
        several = [(k, np.unique(c[idx]).size) for k, c in codes.items()]
        several = [(k, m) for k, m in several if m > 1]
        groups.append(
            several_groups_message(*several[0])
            if several
            else FitData.from_arrays(arrays, idx, qty, unt)
        )
    kw = dict(fit_kw, method=method, seed=seed)
    todo = [(i, g) for i, g in enumerate(groups) if isinstance(g, FitData)]
    from .. import parallel  # imports only labbrdf.errors: usable from every layer

    if chunks is None:
        nw = workers or max(1, os.cpu_count() or 1)
        chunks = 1 if scheduler == "serial" else 4 * nw
    nchunks = max(1, min(int(chunks), len(todo)))
    payloads = [(model, todo[c::nchunks], kw, return_results) for c in range(nchunks)]
    payloads = payloads if todo else []
    done = parallel.run(
        _fit_chunk,
        payloads,
        scheduler=scheduler,
        workers=workers,
        progress=progress,
        desc=f"fit {model.name}",
    )
    summaries: dict[int, dict[str, Any]] = {i: s for chunk in done for i, s, _ in chunk}
    fitted = {i: r for chunk in done for i, _, r in chunk if r is not None}
    rows = []
    results: list[tuple[dict[str, Any], FitResult]] = []
    for i, key in enumerate(keys):
        row: dict[str, Any] = {b: _plain(v) for b, v in zip(by, key, strict=True)}
        if i in fitted:
            results.append((dict(row), fitted[i]))
        g = groups[i]
        s = summaries.get(i) or {"success": False, "message": f"not fitted: {g}"}
        for name in model.params:
            ps = (s.get("params") or {}).get(name) or {}
            ci = ps.get("ci95") or [None, None]
            row[name] = ps.get("value", np.nan)
            row[f"{name}_stderr"] = ps.get("stderr")
            row[f"{name}_ci95_lo"], row[f"{name}_ci95_hi"] = ci
            row[f"{name}_flags"] = ";".join(ps.get("flags", []))
        for col in ("rmse", "rmse_pct", "chisqr", "redchi", "ndata", "nfev"):
            row[col] = s.get(col)
        row["success"] = bool(s.get("success", False))
        row["message"] = s.get("message", "")
        row["elapsed_s"] = s.get("elapsed_s")
        rows.append(row)
    out = pd.DataFrame(rows)
    num = [c for c in out.columns if c.endswith(("_stderr", "_ci95_lo", "_ci95_hi"))]
    num += ["rmse", "rmse_pct", "chisqr", "redchi", "elapsed_s"] + list(model.params)
    out[num] = out[num].astype(float)
    return (out, results) if return_results else out
