"""Batch fits: one fit per group of a dataset, on an :class:`labbrdf.parallel.Executor`.

The one batch fitter of the package: the ``labbrdf fit`` command (``--nk-from`` included,
with a model per wavelength, :func:`fit_many_nk`) and the reports fit through
:func:`fit_many`; :func:`fit_records` gives its table as JSON-ready records.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import pandas as pd

from .. import parallel  # imports only labbrdf.errors: usable from every layer
from ..dataset import Measurement
from ..models import Model
from ..models import get as get_model
from .core import METHOD, fit
from .data import FitData, FitError, select_rows, several_groups_message
from .parameters import check_seed, setup_params
from .replicates import check_replicates
from .result import FitResult
from .stages import parse_method

__all__ = ["auto_weighting", "fit_many", "fit_many_nk", "fit_records", "group_keys"]


def _sort_key(key: Any) -> tuple[Any, ...]:
    key = key if isinstance(key, tuple) else (key,)
    return tuple((v != v, str(type(v)), v if v == v else 0) for v in key)  # NaN last


def _fit_chunk(
    payload: tuple[list[tuple[int, Model, FitData]], dict[str, Any], bool],
) -> list[tuple[int, dict[str, Any], FitResult | None]]:
    """Worker: fit each group of a chunk; a group whose data cannot be fitted gives a row."""
    groups, kw, keep = payload
    out: list[tuple[int, dict[str, Any], FitResult | None]] = []
    for i, model, fd in groups:
        try:
            res = fit(model, fd, **kw)
            out.append((i, res.summary(), res if keep else None))
        except FitError as exc:
            out.append((i, {"success": False, "message": f"not fitted: {exc}"}, None))
    return out


def _groups(
    d: pd.DataFrame, by: list[str], qty: str, unt: str
) -> tuple[list[tuple[Any, ...]], list[FitData | str]]:
    """The key of every group of ``d`` by ``by`` (sorted, NaN last), and its FitData.

    A group that holds several samples or wavelengths (columns not in ``by``) gets the
    reason it is not fitted instead of a FitData.
    """
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
    return keys, groups


def _row(row: dict[str, Any], s: dict[str, Any], param_names: list[str]) -> dict[str, Any]:
    """One table row: the group keys ``row`` and the columns of a fit summary ``s``."""
    for name in param_names:
        ps = (s.get("params") or {}).get(name) or {}
        ci = ps.get("ci95") or [None, None]
        row[name] = ps.get("value", np.nan)
        row[f"{name}_stderr"] = ps.get("stderr")
        row[f"{name}_ci95_lo"], row[f"{name}_ci95_hi"] = ci
        row[f"{name}_ci"] = ps.get("ci_method")  # wald or profile: which interval it is
        row[f"{name}_flags"] = ";".join(ps.get("flags", []))
        if s.get("replicates"):
            row[f"{name}_seed_spread"] = (s.get("seed_spread") or {}).get(name)
            vals = [r.get(name) for r in s["replicates"]]
            row[f"{name}_replicates"] = ";".join(f"{v:.10g}" for v in vals if v is not None)
    if s.get("replicates"):
        row["replicates"] = len(s["replicates"])
    for col in ("rmse", "rmse_pct", "chisqr", "redchi", "aic", "bic", "ndata", "nfev"):
        row[col] = s.get(col)
    row["weighting"] = str(s.get("weighting") or "").split(":")[0]
    row["success"] = bool(s.get("success", False))
    row["status"] = s.get("status") or ("ok" if row["success"] else "failed")
    row["message"] = s.get("message", "")
    row["elapsed_s"] = s.get("elapsed_s")
    return row


def _todo(
    groups: list[FitData | str],
    keys: list[tuple[Any, ...]],
    by: list[str],
    model: Model | Callable[[dict[str, Any]], Model],
    fit_kw: dict[str, Any],
) -> list[tuple[int, Model, FitData]]:
    """(group index, model, points) of every fittable group; a callable gives each model."""
    todo: list[tuple[int, Model, FitData]] = []
    for i, g in enumerate(groups):
        if isinstance(g, FitData):
            if isinstance(model, Model):
                m = model
            else:
                m = model(dict(zip(by, map(_plain, keys[i]), strict=True)))
                setup_params(m, fit_kw.get("params"), fit_kw.get("fix"))
            todo.append((i, m, g))
    return todo


def group_keys(
    data: Measurement | pd.DataFrame,
    by: Sequence[str] = ("sample", "wavelength_nm"),
    *,
    quantity: str | None = None,
    unit: str | None = None,
) -> list[dict[str, Any]]:
    """The groups :func:`fit_many` would fit, without fitting any: one key per table row.

    Parameters
    ----------
    data : Measurement or DataFrame
        Dataset-schema rows.
    by : sequence of str
        Grouping columns, as for :func:`fit_many`.
    quantity, unit : str, optional
        As for :func:`fit_many` (which rows are fittable).

    Returns
    -------
    list of dict
        ``{column: value}`` of ``by`` for every group, in :func:`fit_many`'s table order
        (groups that cannot be fitted, e.g. of several samples, included).

    Raises
    ------
    FitError
        An unknown column in ``by``, or no fittable rows.
    """
    df = data.data if isinstance(data, Measurement) else data
    by = [by] if isinstance(by, str) else list(by)
    missing = [c for c in by if c not in getattr(df, "columns", ())]
    if missing:
        raise FitError(f"by: unknown column(s) {missing}; columns are {list(df.columns)}")
    d, _, _ = select_rows(df, quantity, unit)
    keys = sorted(d.groupby(by, sort=True, dropna=False).indices, key=_sort_key)
    return [
        dict(zip(by, map(_plain, k if isinstance(k, tuple) else (k,)), strict=True)) for k in keys
    ]


def _param_names(todo: list[tuple[int, Model, FitData]]) -> list[str]:
    """The parameter names of the groups' models, in first-seen order."""
    names: dict[str, None] = {}
    for _, m, _ in todo:
        names.update(dict.fromkeys(m.params))
    return list(names)


def _plain(v: Any) -> Any:
    return v.item() if isinstance(v, np.generic) else v


def fit_many(
    data: Measurement | pd.DataFrame,
    model: Model | str | Callable[[dict[str, Any]], Model],
    *,
    by: Sequence[str] = ("sample", "wavelength_nm"),
    method: str = METHOD,
    seed: int = 0,
    executor: parallel.Executor | str | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: bool | None = None,
    chunks: int | None = None,
    return_results: bool = False,
    replicates: int | None = None,
    **fit_kw: Any,
) -> pd.DataFrame | tuple[pd.DataFrame, list[tuple[dict[str, Any], FitResult]]]:
    """Fit one model to every group of a dataset; a parameter table like Tables 1-2 of 2013.

    Parameters
    ----------
    data : Measurement or DataFrame
        Dataset-schema rows. The fittable rows are selected once for the whole table, as
        in :func:`fit` (a table that mixes quantities or units needs ``quantity=`` /
        ``unit=``); groups without fittable rows get no row.
    model : Model, str or callable
        The model (or its registry name) of every group; or ``model(key)``, called here
        once per group with the group's key (``{column: value}`` of ``by``), giving the
        model of that group (e.g. a microfacet model with the index n, k at the group's
        wavelength).
    by : sequence of str
        Grouping columns; one fit per group, in sorted group order.
    method, seed :
        As for :func:`fit`. Every group uses the same ``seed``, so a row equals
        ``fit(model, group, seed=seed)`` whatever the scheduler and worker count.
    executor : Executor or str, optional
        Where the fits run (:class:`labbrdf.parallel.Executor`, or a scheduler name:
        ``serial``, ``processes``, ``local``, ``tcp://host:port``); default
        ``labbrdf.parallel.DEFAULT_SCHEDULER``.
    scheduler, workers :
        The older spelling of ``executor``: a scheduler name and a worker count, turned
        into an Executor once by :func:`labbrdf.parallel.as_executor` (``scheduler`` not
        together with ``executor``, ``workers`` not with an Executor).
    progress : bool, optional
        Progress bar on stderr, counting chunks of groups (default: the Executor's
        setting; on with a scheduler name or no executor).
    chunks : int, optional
        Number of tasks the groups are split into (default ``4 x`` the executor's
        workers), so that per-task overhead stays small against 1-10 ms fits.
    return_results : bool
        Also return the :class:`FitResult` of every fitted group, as a list of
        ``(group key dict, FitResult)`` in table order (groups that could not be fitted are
        left out).
    replicates : int, optional
        Seed replicates of a stochastic model per group, as for :func:`fit` (None: the
        model's ``default_replicates``); each task carries its
        seeds, so the table does not depend on the executor. R > 1 adds the columns
        ``<name>_seed_spread`` (s_between), ``<name>_replicates`` (the R estimates,
        ``;``-joined) and ``replicates``.
    **fit_kw :
        Any other :func:`fit` keyword (``fix``, ``energy_constraint``, ``quantity`` ...).

    Returns
    -------
    pandas.DataFrame, or (DataFrame, list) with ``return_results``
        One row per group: the group keys; per parameter ``<name>``, ``<name>_stderr``,
        ``<name>_ci95_lo``, ``<name>_ci95_hi``, ``<name>_flags`` (``;``-joined); then
        ``rmse``, ``rmse_pct``, ``chisqr``, ``redchi``, ``aic``, ``bic``, ``ndata``,
        ``nfev``, ``weighting``, ``success``, ``status`` (:attr:`FitResult.status`),
        ``message``, ``elapsed_s``; a group not fitted: ``success=False``, why in ``message``.
    """
    if progress is None and not isinstance(executor, parallel.Executor):
        progress = True  # a scheduler name or no executor: a bar, as ``labbrdf fit`` shows
    ex = parallel.as_executor(executor, scheduler=scheduler, workers=workers, progress=progress)
    if isinstance(model, str):
        model = get_model(model)
    model_of: Callable[[dict[str, Any]], Model] | None = (
        None if isinstance(model, Model) else model
    )
    parse_method(method)
    check_seed(seed)
    if isinstance(data, Measurement):
        data = data.data
    if not isinstance(data, pd.DataFrame):
        raise FitError(f"data: expected a Measurement or DataFrame, got {type(data).__name__}")
    by = [by] if isinstance(by, str) else list(by)
    missing = [c for c in by if c not in data.columns]
    if missing:
        raise FitError(f"by: unknown column(s) {missing}; columns are {list(data.columns)}")
    if isinstance(model, Model):
        setup_params(model, fit_kw.get("params"), fit_kw.get("fix"))  # fail early on names
    d, qty, unt = select_rows(data, fit_kw.pop("quantity", None), fit_kw.pop("unit", None))
    keys, groups = _groups(d, by, qty, unt)
    kw = dict(fit_kw, method=method, seed=seed, replicates=replicates)
    todo = _todo(groups, keys, by, model if model_of is None else model_of, fit_kw)
    for _, m, _ in todo if replicates is not None and replicates != 1 else ():
        check_replicates(replicates, m)  # before any fit runs
    if chunks is None:
        chunks = 4 * ex.nworkers
    nchunks = max(1, min(int(chunks), len(todo)))
    payloads = [(todo[c::nchunks], kw, return_results) for c in range(nchunks)]
    payloads = payloads if todo else []
    name = getattr(model, "name", None) or (todo[0][1].name if todo else "model")
    done = ex.map(_fit_chunk, payloads, desc=f"fit {name}")
    summaries: dict[int, dict[str, Any]] = {i: s for chunk in done for i, s, _ in chunk}
    fitted = {i: r for chunk in done for i, _, r in chunk if r is not None}
    param_names = list(model.params) if isinstance(model, Model) else _param_names(todo)
    rows = []
    results: list[tuple[dict[str, Any], FitResult]] = []
    for i, key in enumerate(keys):
        row: dict[str, Any] = {b: _plain(v) for b, v in zip(by, key, strict=True)}
        if i in fitted:
            results.append((dict(row), fitted[i]))
        s = summaries.get(i) or {"success": False, "message": f"not fitted: {groups[i]}"}
        rows.append(_row(row, s, param_names))
    out = pd.DataFrame(rows)
    num = [c for c in out.columns if c.endswith(("_stderr", "_ci95_lo", "_ci95_hi"))]
    num += ["rmse", "rmse_pct", "chisqr", "redchi", "aic", "bic", "elapsed_s"] + param_names
    out[num] = out[num].astype(float)
    return (out, results) if return_results else out


def auto_weighting(data: Measurement | pd.DataFrame) -> str | None:
    """The weighting of a batch when none is asked for: the data's sigmas, if all have one.

    Parameters
    ----------
    data : Measurement or DataFrame
        The rows to be fitted.

    Returns
    -------
    None or "relative"
        None (``1/sigma^2``, as :func:`fit`'s ``weighting="auto"``) when every row has a
        finite sigma > 0; else ``"relative"`` (sigma_i = max(|y_i|, floor x max|y|)): rows without
        sigma (a ``.bsdf`` has none) are fitted with relative weights, not uniform ones.
    """
    df = data.data if isinstance(data, Measurement) else data
    sig = df["sigma"].to_numpy(float)
    every = bool(sig.size) and bool(np.all(np.isfinite(sig) & (sig > 0)))
    return None if every else "relative"


def _metas(data: Measurement) -> list[dict[str, Any]]:
    """The per-file metas of a (concatenated) Measurement, each with its ``source``."""
    parts = data.meta.get("parts")
    if not parts:
        return [data.meta]
    return [{**p.get("meta", {}), "source": p.get("source")} for p in parts]


def fit_many_nk(
    data: Measurement,
    model: str,
    nk_from: str | os.PathLike[str] | pd.DataFrame,
    *,
    options: dict[str, Any] | None = None,
    wavelength_nm: float | None = None,
    source: str | os.PathLike[str] | None = None,
    by: Sequence[str] = ("sample", "wavelength_nm"),
    **kw: Any,
) -> tuple[pd.DataFrame, list[tuple[dict[str, Any], FitResult]]]:
    """:func:`fit_many` with a sample's measured index: a model per wavelength.

    Each wavelength's groups are fitted with the registry model ``model`` whose ``n``,
    ``k`` are the bulk index of ``nk_from`` at that wavelength
    (:func:`labbrdf.nk.bulk_index_at`), or at ``wavelength_nm`` for every group.

    Parameters
    ----------
    data : Measurement
        The measured rows (its per-file metas say which files state no wavelength).
    model : str
        A registry model that takes ``n``, ``k`` (``microfacet``).
    nk_from : path-like or pandas.DataFrame
        An ellipsometer file (:func:`labbrdf.nk.read_nk`) or its combined table.
    options : dict, optional
        The model's other options.
    wavelength_nm : float, optional
        Take n, k at this wavelength [nm] for every group; needed when a file states no
        wavelength (a Zemax ``.bsdf``: its ``wavelength_nm`` is a label).
    source : str or path-like, optional
        What a table came from, for messages.
    by : sequence of str
        Grouping columns, as for :func:`fit_many` (the fits run wavelength first).
    **kw
        Any other :func:`fit_many` keyword (``return_results`` is always on).

    Returns
    -------
    table : pandas.DataFrame
        :func:`fit_many`'s table with the columns ``n``, ``k`` used by each group, ordered
        by ``by``.
    results : list of (dict, FitResult)
        The fitted groups, keys of ``by``, in table order.

    Raises
    ------
    labbrdf.errors.SetupError
        The model takes no index, or a file states no wavelength and ``wavelength_nm``
        is not given (the message names the keywords).
    labbrdf.nk.NkError
        No bulk n, k at a wavelength (outside the file's range, a stack, a film).
    """
    from .. import models
    from ..errors import SetupError, escaped
    from ..nk import bulk_index_at, read_nk

    if "n" not in models.option_names(model):
        raise SetupError(f"{{nk_from}}: model {model!r} takes no index n, k")
    if isinstance(nk_from, pd.DataFrame):
        table, where = nk_from, source if source is not None else "n, k"
    else:
        table, where = read_nk(nk_from), source if source is not None else nk_from
    unstated = [
        str(m.get("source", "?")) for m in _metas(data) if m.get("wavelength_stated") is False
    ]
    if unstated and wavelength_nm is None:
        raise SetupError(
            f"{{nk_from}}: {escaped(', '.join(unstated))} state(s) no wavelength (the format "
            "has no field for it); say at which wavelength to take n, k with {wavelength_nm} NM"
        )
    by = [by] if isinstance(by, str) else list(by)
    # one batch, a model per wavelength (the index at that wavelength), wavelength first:
    # the table lists each wavelength's groups together
    index_at = {
        wl: bulk_index_at(table, float(wavelength_nm or wl), source=where)
        for wl in data.data["wavelength_nm"].unique()
    }

    def model_at(key: dict[str, Any]) -> Model:
        n, k = index_at[key["wavelength_nm"]]
        return get_model(model, **{**(options or {}), "n": n, "k": k})

    by_wl = ["wavelength_nm", *(b for b in by if b != "wavelength_nm")]
    out, results = fit_many(data, model_at, **{**kw, "by": by_wl, "return_results": True})
    nk_cols = pd.DataFrame([index_at[w] for w in out["wavelength_nm"]], columns=["n", "k"])
    out = pd.concat([out, nk_cols], axis=1)
    if "wavelength_nm" not in by:
        out = out.drop(columns="wavelength_nm")
        results = [({b: g[b] for b in by}, r) for g, r in results]
    out = out[[*by, *(c for c in out.columns if c not in by)]]
    return out, results


def _same_key(a: dict[str, Any], b: dict[str, Any]) -> bool:
    def eq(x: Any, y: Any) -> bool:
        return x == y or (x != x and y != y)  # NaN group keys are equal

    return a.keys() == b.keys() and all(eq(a[k], b[k]) for k in a)


def fit_records(
    table: pd.DataFrame, results: list[tuple[dict[str, Any], FitResult]], by: Sequence[str]
) -> list[dict[str, Any]]:
    """One JSON-ready record per row of a :func:`fit_many` table, failed groups included.

    Parameters
    ----------
    table : pandas.DataFrame
        The table of :func:`fit_many` (or :func:`fit_many_nk`).
    results : list of (dict, FitResult)
        Its fitted groups in table order (``return_results=True``).
    by : sequence of str
        The grouping columns of the table.

    Returns
    -------
    list of dict
        Per row: ``model`` and ``options`` (what was fitted: ``labbrdf export --from-fit``
        rebuilds it), ``group`` (``{column: value}`` of ``by``), ``params`` (per parameter
        ``value``, ``stderr``, ``ci95``, ``at_bound``), ``rmse``, ``redchi``,
        ``weighting``, ``nmasked``, ``flags`` (per flagged parameter), ``nfev``,
        ``replicates`` and ``seed_spread`` (seed replicates, else None), ``success``,
        ``message``. A group that could not be fitted has ``success`` false,
        empty ``params``, ``rmse`` and ``nfev`` None and the reason in ``message``.
        Values are plain Python (NaN stays NaN: :func:`labbrdf.jsonsafe.jsonable` makes
        it JSON's null).
    """
    by = [by] if isinstance(by, str) else list(by)
    out: list[dict[str, Any]] = []
    j = 0
    for row in table.to_dict("records"):
        key = {b: row[b] for b in by}
        if j < len(results) and _same_key(results[j][0], key):
            s = results[j][1].summary()
            j += 1
            out.append(
                {
                    "model": s["model"],
                    "options": s["options"],
                    "group": results[j - 1][0],
                    "params": {
                        name: {
                            "value": p["value"],
                            "stderr": p.get("stderr"),
                            "ci95": p.get("ci95"),
                            "at_bound": p.get("at_bound", False),
                        }
                        for name, p in s["params"].items()
                    },
                    "rmse": s["rmse"],
                    "redchi": s["redchi"],
                    "aic": s["aic"],
                    "bic": s["bic"],
                    "ndata": s["ndata"],
                    "weighting": s["weighting"],
                    "nmasked": s["nmasked"],
                    "flags": {k: v["flags"] for k, v in s["params"].items() if v["flags"]},
                    "ci_methods": s["ci_methods"],  # which interval each "ci95" is
                    "ci_reasons": s["ci_reasons"],
                    "nfev": s["nfev"],
                    "replicates": s["replicates"],
                    "seed_spread": s["seed_spread"],
                    "success": s["success"],
                    "message": row.get("message", ""),
                }
            )
        else:
            out.append(
                {
                    "group": key,
                    "params": {},
                    "rmse": None,
                    "nfev": None,
                    "success": False,
                    "message": row.get("message", ""),
                }
            )
    return out
