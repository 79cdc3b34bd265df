"""Optical constants from a dataset's psi/Delta rows: tables, JSON and model predictions.

The dataset layer of :mod:`labbrdf.ellipsometry`: it pairs the ``psi`` and ``delta`` rows of
a :class:`~labbrdf.dataset.Measurement` (or its tidy DataFrame), inverts every point to the
two-phase pseudo-index ``<N> = n + ik`` with propagated uncertainties, combines the angles
of incidence per wavelength, and predicts reflectances (Fresnel, microfacet) to compare with
measured reflectance rows.

The two-phase inversion treats the sample as a bare, clean, isotropic half-space. Where the
angles of incidence disagree, the sample is a stack (a film or roughness), its
pseudo-constants depend on the angle, and they are reported as what they are: per-angle
values, never combined into one "n, k" and never used to predict a reflectance; where the
angles disagree at some wavelengths only, the combined sigmas carry the scatter
(:func:`combined_table`, Notes).

Grouping
--------
Points are grouped by ``sample`` and ``source``. Within one file, a kinetic series
(``time_s``) or a map (``x_mm``, ``y_mm``) is grouped further, but only when it really is
one: ``time_s`` when some (wavelength, angle) was measured at more than one time, and the
stage position when some (wavelength, angle) was measured at more than one spot. Stage
positions closer than :data:`POSITION_TOL_MM` (chained) count as one spot, because stage
read-backs jitter by about 0.01 mm from angle to angle. Wavelengths are matched after
rounding to 1e-6 nm.

Only ordinary psi/Delta rows are used: rows without a ``channel`` (missing or empty) or with
channel ``pp``
(generalized ellipsometry's ``ps``/``sp`` channels are cross-polarization ratios, not a
two-phase quantity).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from . import adapters
from . import dispersion as disp
from . import ellipsometry as ell
from .dataset import Measurement
from .errors import LabbrdfError

__all__ = [
    "POSITION_TOL_MM",
    "AngleVerdict",
    "NkError",
    "angle_verdict",
    "bulk_index_at",
    "coating_from_fit",
    "coating_of_stack",
    "combined_table",
    "compare_reflectance",
    "microfacet_hemispherical",
    "model_with_nk",
    "nk_at",
    "nk_json",
    "nk_panels",
    "nk_table",
    "ordinary_psi_delta",
    "tabulated_from_file",
    "plot_table",
    "series_members",
    "read_nk",
]

#: largest n,k table (or ellipsometer file) that :func:`tabulated_from_file` reads [bytes]:
#: a table of a million rows is ~40 MB
MAX_TABLE_BYTES = 64 << 20

#: Stage positions closer than this (chained, per coordinate) are the same spot [mm].
POSITION_TOL_MM = 0.5

_WL_DECIMALS = 6
_POINT_COLUMNS = [
    "sample",
    "source",
    "wavelength_nm",
    "theta_i_deg",
    "n",
    "k",
    "n_sigma",
    "k_sigma",
    "cond",
    "nk_cov",
    "psi_deg",
    "delta_deg",
]
_COMBINED_COLUMNS = [
    "wavelength_nm",
    "n",
    "k",
    "n_sigma",
    "k_sigma",
    "nk_cov",
    "chi2",
    "dof",
    "p_value",
    "angle_dependent",
    "method",
    "n_points",
    "n_angles",
]
#: combined columns left NaN where the angles disagree (combined_table, Notes)
_NOT_COMBINED = ("n", "k", "n_sigma", "k_sigma", "nk_cov")
_JSON_COMBINED = [
    "wavelength_nm",
    "n",
    "k",
    "n_sigma",
    "k_sigma",
    "chi2",
    "dof",
    "p_value",
    "angle_dependent",
]


def _frame(data: Measurement | pd.DataFrame) -> pd.DataFrame:
    if isinstance(data, Measurement):
        return data.data
    if isinstance(data, pd.DataFrame):
        return data
    raise TypeError(f"expected a labbrdf Measurement or a DataFrame; got {type(data).__name__}")


def _cluster(values: np.ndarray, tol: float) -> np.ndarray:
    """Integer labels of 1-d single-linkage clusters (gap > ``tol`` starts a new one)."""
    labels = np.full(values.shape, -1, dtype=np.int64)
    ok = np.isfinite(values)
    if not ok.any():
        return labels
    uniq = np.unique(values[ok])
    ids = np.concatenate([[0], np.cumsum(np.diff(uniq) > tol)])
    labels[ok] = ids[np.searchsorted(uniq, values[ok])]
    return labels


def _series_keys(df: pd.DataFrame) -> list[str]:
    """The extra group keys of one (sample, source): time and/or spot, where they vary."""
    keys: list[str] = []
    base = ["_wl", "theta_i_deg"]
    if {"x_mm", "y_mm"} <= set(df.columns):
        if df.groupby(base, dropna=False)[["_x", "_y"]].nunique().to_numpy().max(initial=0) > 1:
            keys += ["x_mm", "y_mm"]
    if "time_s" in df.columns:
        by = base + (["_x", "_y"] if keys else [])
        if df.groupby(by, dropna=False)["time_s"].nunique().max() > 1:
            keys.insert(0, "time_s")
    return keys


def ordinary_psi_delta(df: pd.DataFrame) -> pd.DataFrame:
    """The psi/Delta rows of ordinary ellipsometry: no channel, or the ``pp`` channel.

    Generalised ellipsometry's cross channels (``ps``, ``sp``) are not a sample's psi and
    Delta; they are left out wherever psi/Delta are inverted or fitted.
    """
    rows = df[df["quantity"].isin(["psi", "delta"])]
    if "channel" in rows.columns:
        ch = rows["channel"].astype(object)
        rows = rows[ch.isna() | ch.isin(["", "pp"])]
    return rows


def nk_table(
    data: Measurement | pd.DataFrame,
    *,
    theta_sigma_deg: float = 0.0,
    n_ambient: float = 1.0,
    on_ill_conditioned: ell.OnIll = "raise",
) -> pd.DataFrame:
    """Two-phase pseudo-optical constants of every psi/Delta point of a dataset.

    Parameters
    ----------
    data : Measurement or pandas.DataFrame
        A labbrdf dataset; its ``psi`` and ``delta`` rows are used (others are ignored).
    theta_sigma_deg : float, optional
        1-sigma error of the angle of incidence [deg], propagated with the file's sigmas.
        Default 0 (the file's sigmas alone).
    n_ambient : float, optional
        Real index of the ambient [1]. Default 1.
    on_ill_conditioned : {"raise", "warn", "ignore"}
        Passed to :func:`labbrdf.ellipsometry.pseudo_nk`.

    Returns
    -------
    pandas.DataFrame
        One row per (psi, Delta) pair: ``sample, source, wavelength_nm, theta_i_deg, n, k,
        n_sigma, k_sigma, cond, nk_cov, psi_deg, delta_deg`` [1 or deg], plus ``time_s``,
        ``x_mm``, ``y_mm`` where they identify a series (module Grouping). Sigmas are NaN
        where the file has none. ``attrs["unpaired"]`` counts psi or delta rows without a
        partner (dropped).

    Raises
    ------
    ValueError
        No psi/Delta rows, or an invalid or ill-conditioned point (see ``pseudo_nk``).

    Notes
    -----
    psi and delta rows are paired on every identifying column and, among rows that share
    them (e.g. the nulling zones of an Accurion file), by order of appearance.
    """
    df = _frame(data)
    sel = ordinary_psi_delta(df)
    if sel.empty:
        raise ValueError("no psi/delta rows (ordinary ellipsometry) in the data")
    sel = sel.assign(_wl=sel["wavelength_nm"].round(_WL_DECIMALS))
    keys = ["sample", "source", "_wl", "theta_i_deg"]
    keys += [c for c in ("time_s", "x_mm", "y_mm") if c in sel.columns]
    cols = keys + ["wavelength_nm", "value", "sigma"]
    psi = sel.loc[sel["quantity"] == "psi", cols]
    delta = sel.loc[sel["quantity"] == "delta", cols]
    psi = psi.assign(_i=psi.groupby(keys, dropna=False, sort=False).cumcount())
    delta = delta.assign(_i=delta.groupby(keys, dropna=False, sort=False).cumcount())
    pair = psi.merge(
        delta.drop(columns="wavelength_nm"), on=keys + ["_i"], suffixes=("_psi", "_delta")
    )
    pair = pair[np.isfinite(pair["value_psi"]) & np.isfinite(pair["value_delta"])]
    unpaired = len(psi) + len(delta) - 2 * len(pair)
    if pair.empty:
        raise ValueError("no psi row has a matching delta row")
    res = ell.pseudo_nk(
        pair["value_psi"].to_numpy(float),
        pair["value_delta"].to_numpy(float),
        pair["theta_i_deg"].to_numpy(float),
        pair["sigma_psi"].to_numpy(float),
        pair["sigma_delta"].to_numpy(float),
        theta_sigma_deg=theta_sigma_deg,
        n_ambient=n_ambient,
        on_ill_conditioned=on_ill_conditioned,
    )
    out = pd.DataFrame(
        {
            "sample": pair["sample"].astype(object).to_numpy(),
            "source": pair["source"].astype(object).to_numpy(),
            "wavelength_nm": pair["wavelength_nm"].to_numpy(float),
            "theta_i_deg": pair["theta_i_deg"].to_numpy(float),
            "n": res.n,
            "k": res.k,
            "n_sigma": res.n_sigma,
            "k_sigma": res.k_sigma,
            "cond": res.cond,
            "nk_cov": res.nk_cov,
            "psi_deg": pair["value_psi"].to_numpy(float),
            "delta_deg": pair["value_delta"].to_numpy(float),
        }
    )
    extra = [c for c in ("time_s", "x_mm", "y_mm") if c in pair.columns]
    if extra:
        probe = out.assign(
            _wl=out["wavelength_nm"].round(_WL_DECIMALS),
            **{c: pair[c].to_numpy(float) for c in extra},
        )
        parts = []
        for _, g in probe.groupby(["sample", "source"], sort=False):
            if {"x_mm", "y_mm"} <= set(g.columns):
                g = g.assign(
                    _x=_cluster(g["x_mm"].to_numpy(float), POSITION_TOL_MM),
                    _y=_cluster(g["y_mm"].to_numpy(float), POSITION_TOL_MM),
                )
            parts.append(_series_keys(g))
        used = [c for c in extra if any(c in p for p in parts)]
        for c in used:
            out[c] = pair[c].to_numpy(float)
    out = out.sort_values(["sample", "source", "wavelength_nm", "theta_i_deg"], kind="stable")
    out = out.reset_index(drop=True)
    out.attrs["unpaired"] = int(unpaired)
    return out


def _group_keys(table: pd.DataFrame) -> list[str]:
    return ["sample", "source"] + [c for c in ("time_s", "x_mm", "y_mm") if c in table.columns]


def _spot_labels(table: pd.DataFrame) -> pd.DataFrame:
    """Replace jittering stage positions by cluster labels for grouping."""
    if not {"x_mm", "y_mm"} <= set(table.columns):
        return table
    t = table.copy()
    for c in ("x_mm", "y_mm"):
        lab = np.empty(len(t), dtype=float)
        for _, idx in t.groupby(["sample", "source"], sort=False).groups.items():
            pos = t.index.get_indexer(idx)
            values = t[c].to_numpy(float)[pos]
            ids = _cluster(values, POSITION_TOL_MM)
            # label each cluster by its mean position (a readable key)
            for i in np.unique(ids):
                m = ids == i
                lab[pos[m]] = np.nan if i < 0 else round(float(values[m].mean()), 3)
        t[c] = lab
    return t


def combined_table(
    data: Measurement | pd.DataFrame,
    *,
    alpha: float = ell.P_ANGLE_DEPENDENT,
    **nk_options: Any,
) -> pd.DataFrame:
    """Per-wavelength combination of all angles of incidence.

    Parameters
    ----------
    data : Measurement or pandas.DataFrame
        A dataset with psi/delta rows, or a table from :func:`nk_table`.
    alpha : float, optional
        Significance level of ``angle_dependent``. Default 0.01.
    **nk_options
        Passed to :func:`nk_table` when ``data`` is a dataset.

    Returns
    -------
    pandas.DataFrame
        One row per (sample, source[, time_s, x_mm, y_mm], wavelength):
        ``wavelength_nm, n, k, n_sigma, k_sigma, nk_cov, chi2, dof, p_value,
        angle_dependent, method, n_points, n_angles`` after the group keys; see
        :func:`labbrdf.ellipsometry.combine_angles` for the sigma and scatter rules. A
        wavelength mixing points with and without sigma uses the scatter rule. Two last
        columns: ``sigma_scale``, the factor the sigmas were multiplied by (the Birge ratio
        ``sqrt(chi2/dof)`` where the angles disagree under the sigma rule, else 1), and
        ``combined``, false where ``n, k, n_sigma, k_sigma, nk_cov`` are NaN: everywhere in
        a group whose :func:`angle_verdict` is ``stack`` (Notes).

    Notes
    -----
    Where the angles of incidence disagree at most wavelengths of a group (verdict
    ``stack``), the two-phase pseudo-constants are those of a stack (a film or roughness on
    the substrate), which depend on the angle; they are no material's constants. Their
    inverse-covariance mean would be one more angle-dependent number, with a sigma that
    only measures how well each angle is measured, not how far apart the angles are (on an
    oxide-coated wafer: n = -0.705 with sigma 3e-4 at 500 nm, chi2/dof 1.5e4). It is
    therefore not given, at any wavelength of the group (the few where the angles agree do
    so by chance): the per-angle pseudo-constants stay in :func:`nk_table`, and a stack
    model (:mod:`labbrdf.films`) gives the layers' constants. In other groups, a
    wavelength whose angles disagree keeps its mean, with the sigmas multiplied by the
    Birge ratio ``sqrt(chi2/dof)`` (R. T. Birge, Phys. Rev. 40, 207 (1932)) so that they
    cover the angle-to-angle scatter (sigmas that leave out systematic errors, or a film
    that matters at some wavelengths only); the scatter rule's sigma is the scatter
    already.
    """
    table = data if "n" in _frame(data).columns else nk_table(data, **nk_options)
    table = _spot_labels(_frame(table))
    keys = _group_keys(table)
    table = table.assign(_wl=table["wavelength_nm"].round(_WL_DECIMALS))
    rows = []
    for key, g in table.groupby(keys + ["_wl"], sort=True, dropna=False):
        cov = np.stack(
            [
                np.stack([g["n_sigma"] ** 2, g["nk_cov"]], axis=-1),
                np.stack([g["nk_cov"], g["k_sigma"] ** 2], axis=-1),
            ],
            axis=-2,
        )
        c = ell.combine_angles(
            g["n"].to_numpy(float),
            g["k"].to_numpy(float),
            g["theta_i_deg"].to_numpy(float),
            cov,
            alpha=alpha,
        )
        row = dict(zip(keys, key[:-1], strict=True))
        row["wavelength_nm"] = float(g["wavelength_nm"].mean())
        row.update({f: getattr(c, f) for f in _COMBINED_COLUMNS[1:]})
        rows.append(row)
    out = pd.DataFrame(rows, columns=keys + _COMBINED_COLUMNS)
    out = out.astype({"dof": "int64", "angle_dependent": bool, "n_points": "int64"})
    # no n, k anywhere in a stack-like group; elsewhere the sigmas of a wavelength whose
    # angles disagree carry their scatter (Birge ratio) (Notes)
    given = np.ones(len(out), dtype=bool)
    for _, idx in out.groupby(keys, sort=False, dropna=False).groups.items():
        if angle_verdict(out.loc[idx], alpha=alpha).kind == "stack":
            given[out.index.get_indexer(idx)] = False
    flagged = out["angle_dependent"].to_numpy(bool)
    chi2 = out["chi2"].to_numpy(float)
    dof = out["dof"].to_numpy(float)
    scale = np.ones(len(out))
    birge = given & flagged & np.isfinite(chi2) & (dof > 0)  # the sigma rule's chi2
    scale[birge] = np.sqrt(chi2[birge] / dof[birge])
    for col in ("n_sigma", "k_sigma"):
        out[col] = out[col].to_numpy(float) * scale
    out["nk_cov"] = out["nk_cov"].to_numpy(float) * scale**2
    scale[~given] = np.nan
    out.loc[~given, list(_NOT_COMBINED)] = np.nan
    out["sigma_scale"] = scale
    out["combined"] = given
    return out


@dataclass(frozen=True)
class AngleVerdict:
    """How the angles of incidence of one sample agree, over its wavelengths.

    Attributes
    ----------
    kind : {"untested", "bulk", "partly", "stack"}
        ``untested``: one angle, or too few points without sigmas; ``bulk``: flagged at no
        more wavelengths than chance explains; ``partly``: more than chance, at most half;
        ``stack``: more than half (a film or roughness: pseudo-constants of a stack).
    tested : int
        Wavelengths with an angle-consistency test.
    fraction : float or None
        Fraction of the tested wavelengths where the angles disagree [1].
    chance : float or None
        Fraction expected by chance: ``alpha`` plus a binomial 3-sigma margin [1].
    text, short : str
        The verdict in a sentence and in a few words.
    """

    kind: Literal["untested", "bulk", "partly", "stack"]
    tested: int
    fraction: float | None
    chance: float | None
    text: str
    short: str


def angle_verdict(combined: pd.DataFrame, *, alpha: float = ell.P_ANGLE_DEPENDENT) -> AngleVerdict:
    """Whether one sample's pseudo-constants depend on the angle of incidence.

    Parameters
    ----------
    combined : pandas.DataFrame
        The :func:`combined_table` rows of one sample (one group).
    alpha : float, optional
        The significance level the table was flagged with. Default 0.01.

    Returns
    -------
    AngleVerdict

    Notes
    -----
    Each tested wavelength is flagged with probability ``alpha`` by chance alone, so a
    bulk material shows a flagged fraction near ``alpha``; the fraction is compared with
    ``alpha + 3 sqrt(alpha (1 - alpha) / m)`` over ``m`` tested wavelengths (binomial
    3-sigma). Above one half the sample is a stack: the few wavelengths where its angles
    happen to agree are chance, not a material's constants.
    """
    dof = combined["dof"].to_numpy(int)
    tested = dof > 0
    m = int(tested.sum())
    if not m:
        n_max = int(combined["n_angles"].max()) if len(combined) else 0
        text = (
            "one angle of incidence per wavelength"
            if n_max < 2
            else f"{n_max} angles per wavelength and no sigmas in the file: too few for the "
            "scatter test"
        ) + ": the angle-to-angle consistency cannot be tested"
        return AngleVerdict("untested", 0, None, None, text, "not testable")
    frac = float(combined["angle_dependent"].to_numpy(bool)[tested].mean())
    chance = alpha + 3.0 * math.sqrt(alpha * (1.0 - alpha) / m)
    said = (
        f"the angles disagree (p < {alpha:g}) at {100 * frac:.0f}% of the {m} wavelengths, "
        f"{100 * alpha:g}% expected by chance"
    )
    if frac > 0.5:
        return AngleVerdict(
            "stack", m, frac, chance,
            said + ": angle-dependent, a film or roughness, not a bulk material; the values "
            "are pseudo-constants of a stack",
            "angle-dependent: film or roughness",
        )  # fmt: skip
    if frac > chance:
        return AngleVerdict(
            "partly", m, frac, chance,
            said + ": angle-dependent over part of the spectrum (a film or roughness, not a "
            "bulk material, there); elsewhere consistent with a bulk material",
            "partly angle-dependent",
        )  # fmt: skip
    return AngleVerdict(
        "bulk", m, frac, chance, said + ": consistent with a bulk material", "consistent with bulk"
    )


def _json_value(v: Any) -> Any:
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return None if not math.isfinite(float(v)) else float(v)
    return v


def _json_list(s: pd.Series) -> list:
    return [_json_value(v) for v in s.tolist()]


def nk_json(
    data: Measurement | pd.DataFrame,
    *,
    alpha: float = ell.P_ANGLE_DEPENDENT,
    **nk_options: Any,
) -> dict[str, Any]:
    """JSON-safe optical constants: every point and the per-wavelength combination.

    Parameters
    ----------
    data : Measurement or pandas.DataFrame
        A dataset with psi/delta rows, or a table from :func:`nk_table`.
    alpha : float, optional
        Significance level of ``angle_dependent``. Default 0.01.
    **nk_options
        Passed to :func:`nk_table`.

    Returns
    -------
    dict
        For one (sample, source): ``{"wavelength_nm", "theta_i_deg", "n", "k", "n_sigma",
        "k_sigma"}`` as equal-length lists (one entry per measured point) and
        ``"combined": {"wavelength_nm", "n", "k", "n_sigma", "k_sigma", "chi2", "dof",
        "p_value", "angle_dependent"}`` (one entry per wavelength). A kinetic series or a
        map adds ``time_s`` / ``x_mm``, ``y_mm`` lists at both levels. NaN becomes None
        (``null``). Several (sample, source) pairs: ``{"groups": [{"sample": ...,
        "source": ..., "data": <the object above>}, ...]}``.
    """
    table = data if "n" in _frame(data).columns else nk_table(data, **nk_options)
    table = _frame(table)
    combined = combined_table(table, alpha=alpha)
    extra = [c for c in ("time_s", "x_mm", "y_mm") if c in table.columns]
    groups = []
    for (sample, source), g in table.groupby(["sample", "source"], sort=False):
        cg = combined[(combined["sample"] == sample) & (combined["source"] == source)]
        obj: dict[str, Any] = {
            c: _json_list(g[c])
            for c in ["wavelength_nm", "theta_i_deg", "n", "k", "n_sigma", "k_sigma"] + extra
        }
        obj["combined"] = {c: _json_list(cg[c]) for c in _JSON_COMBINED + extra}
        groups.append({"sample": sample, "source": source, "data": obj})
    if len(groups) == 1:
        return groups[0]["data"]
    return {"groups": groups}


def _single(
    table: pd.DataFrame, sample: str | None, source: str | None, what: str
) -> pd.DataFrame:
    if sample is not None:
        table = table[table["sample"] == sample]
    if source is not None:
        table = table[table["source"] == source]
    pairs = table[["sample", "source"]].drop_duplicates()
    if len(pairs) != 1:
        found = [tuple(r) for r in pairs.itertuples(index=False)]
        raise ValueError(
            f"{what}: expected one (sample, source), found {len(pairs)}: {found[:5]}; "
            "pass sample= and source="
        )
    series = [c for c in ("time_s", "x_mm", "y_mm") if c in table.columns]
    if series and len(table[series].drop_duplicates()) > 1:
        raise ValueError(f"{what}: the table holds a series ({series}); select one member")
    return table


def nk_at(
    table: pd.DataFrame,
    wavelength_nm: float | Sequence[float] | np.ndarray,
    *,
    sample: str | None = None,
    source: str | None = None,
    on_angle_dependent: Literal["raise", "nan"] = "raise",
) -> dict[str, np.ndarray]:
    """Combined ``n, k`` and uncertainties at given wavelengths, by linear interpolation.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`combined_table` (or an :func:`nk_table`, combined first).
    wavelength_nm : float or array_like
        Wavelength(s) [nm], within the measured range.
    sample, source : str, optional
        Select one (sample, source) when the table holds several.
    on_angle_dependent : {"raise", "nan"}, optional
        What to do at a wavelength that needs a node without combined n, k (a sample whose
        angles disagree, :func:`combined_table`): raise (default) or return NaN.

    Returns
    -------
    dict
        ``{"wavelength_nm", "n", "k", "n_sigma", "k_sigma", "nk_cov"}`` as float arrays
        shaped like ``wavelength_nm`` (for the tracer's ``Substrate(n=, k=)`` or
        ``models.get("microfacet", n=, k=)``).

    Raises
    ------
    ValueError
        A wavelength outside the measured range (no extrapolation), an ambiguous table,
        or (``on_angle_dependent="raise"``) a wavelength without combined n, k.

    Notes
    -----
    Linear interpolation between the two neighbouring measured wavelengths; the sigmas
    and the covariance are interpolated the same way (exact at the nodes, an
    approximation in between that neglects the interpolation error itself).
    """
    if "theta_i_deg" in table.columns:
        table = combined_table(table)
    t = _single(table, sample, source, "nk_at").sort_values("wavelength_nm")
    wl = t["wavelength_nm"].to_numpy(float)
    x = np.asarray(wavelength_nm, dtype=float)
    lo, hi = float(wl[0]), float(wl[-1])
    if not np.all(np.isfinite(x)) or np.any((x < lo) | (x > hi)):
        bad = x[~((x >= lo) & (x <= hi))]
        raise ValueError(
            f"wavelength_nm: {bad.ravel()[:5].tolist()} outside the measured range "
            f"[{lo:.6g}, {hi:.6g}] nm; n, k are not extrapolated"
        )
    out = {"wavelength_nm": x}
    for c in ("n", "k", "n_sigma", "k_sigma", "nk_cov"):
        out[c] = np.interp(x, wl, t[c].to_numpy(float))
    if on_angle_dependent == "raise":
        bad = ~(np.isfinite(out["n"]) & np.isfinite(out["k"]))
        if bad.any():
            raise ValueError(_angle_dependent_message(x[bad]))
    return out


class NkError(LabbrdfError, ValueError):
    """n, k that a file cannot give: no psi/Delta, outside its range, not a bulk index.

    The message starts with the file it is about.
    """


def read_nk(path: str | os.PathLike[str]) -> pd.DataFrame:
    """The per-wavelength combined n, k of an ellipsometer file (its psi/Delta inverted).

    Parameters
    ----------
    path : path-like
        Any export :func:`labbrdf.read` reads that holds ordinary psi/Delta rows.

    Returns
    -------
    pandas.DataFrame
        The file's :func:`combined_table`, for :func:`bulk_index_at` or :func:`nk_at`.

    Raises
    ------
    labbrdf.AdapterError
        The file cannot be read.
    NkError
        It holds no psi/Delta to invert (the message names the file).
    """
    from . import adapters  # the readers, imported where needed

    m = adapters.read(path)
    try:
        return combined_table(m)
    except ValueError as exc:
        raise NkError(f"{path}: {exc}") from None


def bulk_index_at(
    table: pd.DataFrame, wavelength_nm: float, *, source: str | os.PathLike[str] = "n, k"
) -> tuple[float, float]:
    """The bulk index ``(n, k)`` of a combined table at one wavelength, checked physical.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`combined_table` (e.g. of :func:`read_nk`) of one sample.
    wavelength_nm : float
        Vacuum wavelength [nm] inside the measured range (linear interpolation,
        :func:`nk_at`).
    source : str or path-like, optional
        What the table came from (its file), the start of every error message.

    Returns
    -------
    n, k : float
        Refractive index and extinction coefficient [1], ``n > 0`` and ``k >= 0``.

    Raises
    ------
    NkError
        The wavelength lies outside the table, the sample's angles disagree there (a
        stack), or the two-phase pseudo-index is not a material's (``n <= 0`` or
        ``k < 0``: a film on the sample, whose pseudo-index can leave the physical
        half-plane).
    """
    try:
        at = nk_at(table, wavelength_nm)
    except ValueError as exc:
        raise NkError(f"{source}: {exc}") from None
    n, k = float(at["n"]), float(at["k"])
    if not (n > 0 and k >= 0):
        raise NkError(
            f"{source}: the pseudo-index at {wavelength_nm:g} nm is n={n:.4g}, "
            f"k={k:.4g}, not a physical bulk index (a film on the sample?)"
        )
    return n, k


def model_with_nk(
    name: str,
    nk_from: str | os.PathLike[str] | pd.DataFrame,
    wavelength_nm: float,
    *,
    source: str | os.PathLike[str] | None = None,
    **options: Any,
) -> Any:
    """A registry model whose index is a sample's bulk n, k at one wavelength.

    Parameters
    ----------
    name : str
        A model that takes an index ``n``, ``k`` (``microfacet``, see
        :func:`labbrdf.models.option_names`).
    nk_from : path-like or pandas.DataFrame
        An ellipsometer file (:func:`read_nk`) or its combined table.
    wavelength_nm : float
        Vacuum wavelength [nm] at which the index is taken (:func:`bulk_index_at`).
    source : str or path-like, optional
        What a table came from, for messages (default: the file, or ``"n, k"``).
    **options
        The model's other options.

    Returns
    -------
    labbrdf.models.Model

    Raises
    ------
    labbrdf.errors.SetupError
        The model takes no index (the message names the keyword ``{nk_from}``).
    NkError
        No bulk n, k at that wavelength (the message starts with the file).
    labbrdf.ModelError
        An unknown model or a bad option.
    """
    from . import models
    from .errors import SetupError

    if "n" not in models.option_names(name):
        raise SetupError(f"{{nk_from}}: model {name!r} takes no index n, k")
    if isinstance(nk_from, pd.DataFrame):
        table, where = nk_from, source if source is not None else "n, k"
    else:
        table, where = read_nk(nk_from), source if source is not None else nk_from
    n, k = bulk_index_at(table, wavelength_nm, source=where)
    return models.get(name, **{**options, "n": n, "k": k})


def _angle_dependent_message(wavelength_nm: np.ndarray) -> str:
    w = ", ".join(f"{v:g}" for v in np.unique(wavelength_nm)[:5])
    return (
        f"at {w} nm no n, k: the angles of incidence disagree at most of the sample's "
        "wavelengths, so its two-phase values are pseudo-constants of a stack (a film or "
        "roughness), not a material's n, k; fit a stack model to get the layers' constants"
    )


def compare_reflectance(
    nk: pd.DataFrame,
    reflectance: Measurement | pd.DataFrame,
    *,
    sample: str | None = None,
    source: str | None = None,
    theta_if_missing_deg: float = 0.0,
    n_ambient: float = 1.0,
) -> pd.DataFrame:
    """Measured specular reflectance against the Fresnel prediction from ``n, k``.

    Parameters
    ----------
    nk : pandas.DataFrame
        A :func:`combined_table` or :func:`nk_table` of one (sample, source) (or select one).
    reflectance : Measurement or pandas.DataFrame
        Data with ``quantity == "reflectance"`` rows: ellipsometer ``sR``/``pR``/``uR``
        (``channel`` ``s``/``p``/``u`` and ``theta_i_deg``) or spectrophotometer
        reflectance (no channel, ``theta_i_deg`` NaN).
    sample, source : str, optional
        Select the (sample, source) of ``nk``.
    theta_if_missing_deg : float, optional
        Angle of incidence used where ``theta_i_deg`` is NaN (spectrophotometers) [deg].
        Default 0 (normal incidence; at the usual 8 deg the difference is below 1e-3 of R).
    n_ambient : float, optional
        Real index of the ambient [1]. Default 1.

    Returns
    -------
    pandas.DataFrame
        One row per reflectance row inside the wavelength range of ``nk``: ``sample,
        source, wavelength_nm, theta_i_deg, channel, measured, measured_sigma, predicted,
        predicted_sigma, difference, difference_sigma, z`` [1]. ``predicted`` is ``R_s``,
        ``R_p`` or their mean for channel ``s``, ``p``, anything else;
        ``difference = measured - predicted``; ``difference_sigma`` adds the two sigmas in
        quadrature, and is the predicted sigma alone (a lower bound) where the measurement
        has none. ``attrs["outside_range"]`` counts the rows outside the ``nk`` range
        (dropped: no extrapolation), ``attrs["angle_dependent"]`` the rows at wavelengths
        without combined n, k (dropped: pseudo-constants of a stack predict no
        reflectance, :func:`combined_table`).

    Raises
    ------
    ValueError
        No reflectance rows, none inside the ``nk`` range, or none at a wavelength with
        combined n, k (a sample whose angles of incidence disagree).
    """
    df = _frame(reflectance)
    rows = df[df["quantity"] == "reflectance"]
    if rows.empty:
        raise ValueError("no reflectance rows in the data to compare with")
    nkc = combined_table(nk) if "theta_i_deg" in nk.columns else nk
    nkc = _single(nkc, sample, source, "compare_reflectance")
    wl = rows["wavelength_nm"].to_numpy(float)
    lo, hi = nkc["wavelength_nm"].min(), nkc["wavelength_nm"].max()
    inside = (wl >= lo) & (wl <= hi)
    rows = rows[inside]
    if rows.empty:
        raise ValueError(f"no reflectance row within the n, k range [{lo:.6g}, {hi:.6g}] nm")
    at = nk_at(nkc, rows["wavelength_nm"].to_numpy(float), on_angle_dependent="nan")
    usable = np.isfinite(at["n"]) & np.isfinite(at["k"])
    if not usable.any():
        raise ValueError(
            "no combined n, k at the wavelengths compared: the angles of incidence disagree "
            "at most of the sample's wavelengths, so its values are pseudo-constants of a "
            "stack (a film or roughness), not a material's n, k, and the Fresnel "
            "reflectance of a bare half-space does not apply; a fitted stack model "
            "predicts the reflectance"
        )
    rows = rows[usable]
    at = {c: v[usable] for c, v in at.items()}
    theta = rows["theta_i_deg"].to_numpy(float)
    theta = np.where(np.isnan(theta), theta_if_missing_deg, theta)
    pred = ell.fresnel_reflectances(
        np.maximum(at["n"], 0.0),
        np.maximum(at["k"], 0.0),
        theta,
        n_sigma=at["n_sigma"],
        k_sigma=at["k_sigma"],
        nk_cov=at["nk_cov"],
        n_ambient=n_ambient,
    )
    if "channel" in rows.columns:
        channel = rows["channel"].astype(object).to_numpy()
    else:
        channel = np.full(len(rows), None, dtype=object)
    is_s = channel == "s"
    is_p = channel == "p"
    predicted = np.where(is_s, pred.rs, np.where(is_p, pred.rp, pred.r))
    predicted_sigma = np.where(is_s, pred.rs_sigma, np.where(is_p, pred.rp_sigma, pred.r_sigma))
    measured = rows["value"].to_numpy(float)
    measured_sigma = rows["sigma"].to_numpy(float)
    diff = measured - predicted
    diff_sigma = np.where(
        np.isnan(measured_sigma), predicted_sigma, np.hypot(measured_sigma, predicted_sigma)
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        z = diff / diff_sigma
    out = pd.DataFrame(
        {
            "sample": rows["sample"].astype(object).to_numpy(),
            "source": rows["source"].astype(object).to_numpy(),
            "wavelength_nm": rows["wavelength_nm"].to_numpy(float),
            "theta_i_deg": theta,
            "channel": channel,
            "measured": measured,
            "measured_sigma": measured_sigma,
            "predicted": predicted,
            "predicted_sigma": predicted_sigma,
            "difference": diff,
            "difference_sigma": diff_sigma,
            "z": z,
        }
    )
    out.attrs["outside_range"] = int((~inside).sum())
    out.attrs["angle_dependent"] = int((~usable).sum())
    return out


def microfacet_hemispherical(
    n: float,
    k: float,
    alpha: float,
    theta_i_deg: float | Sequence[float] | np.ndarray,
    *,
    n_sigma: float = float("nan"),
    k_sigma: float = float("nan"),
    nk_cov: float = 0.0,
    rtol: float = 1e-6,
) -> tuple[np.ndarray, np.ndarray]:
    """Directional-hemispherical reflectance of the GGX microfacet pBRDF for ``N = n + ik``.

    Parameters
    ----------
    n, k : float
        Substrate index [1] (e.g. from :func:`nk_at`).
    alpha : float
        GGX roughness of ``models.get("microfacet")`` [1].
    theta_i_deg : float or array_like
        Angle(s) of incidence in [0, 90) [deg].
    n_sigma, k_sigma, nk_cov : float, optional
        Uncertainties and covariance of n, k [1]; NaN sigma (default): the returned sigma
        is NaN and no extra quadratures are run.
    rtol : float, optional
        Quadrature tolerance of :func:`labbrdf.integrate.hemispherical_reflectance`.

    Returns
    -------
    rho, rho_sigma : ndarray of float
        Albedo (scale 1) [1] and its first-order 1-sigma uncertainty [1], from central
        differences of the quadrature in n and k with steps ``h = 0.01 max(|N|, 1)``:
        the truncation error is O(h^2) relative, and the quadrature error ``rtol``
        divided by ``h`` stays below 1e-3 of the derivative for ``rtol = 1e-6``.
    """
    from . import integrate, models  # the physics/model layer, imported where needed

    theta = np.asarray(theta_i_deg, dtype=float)

    def albedo(nn: float, kk: float) -> np.ndarray:
        model = models.get("microfacet", n=nn, k=kk)
        return integrate.hemispherical_reflectance(
            model, {"alpha": alpha, "scale": 1.0}, theta, rtol=rtol
        )

    rho = albedo(n, k)
    if not (np.isfinite(n_sigma) and np.isfinite(k_sigma)):
        return rho, np.full(rho.shape, np.nan)
    h = 0.01 * max(abs(complex(n, k)), 1.0)
    hn = min(h, n) if n > 0 else h  # stay at n >= 0 (one-sided if needed)
    hk = min(h, k) if k > 0 else h
    g_n = (albedo(n + h, k) - albedo(n - hn, k)) / (h + hn)
    g_k = (albedo(n, k + h) - albedo(n, k - hk)) / (h + hk)
    var = (g_n * n_sigma) ** 2 + (g_k * k_sigma) ** 2 + 2.0 * g_n * g_k * nk_cov
    return rho, np.sqrt(np.maximum(var, 0.0))


def coating_from_fit(path: str | os.PathLike[str], wavelength_nm: float) -> tuple[complex, float]:
    """The coating of a one-layer film fit: its index at a wavelength and its thickness.

    Parameters
    ----------
    path : path-like
        A film fit's JSON (:meth:`labbrdf.FilmFit.save_json`, ``labbrdf film
        --fit-json FIT.json``) whose stack has exactly one layer over the substrate
        (the tracer's one coating).
    wavelength_nm : float
        Vacuum wavelength [nm], inside the fitted wavelength range.

    Returns
    -------
    N : complex
        The layer's fitted index ``n + ik`` at ``wavelength_nm`` [1].
    thickness_nm : float
        Its fitted thickness [nm].

    Raises
    ------
    ValueError
        The file is not a film fit (:class:`labbrdf.films.FilmError`, naming the file and
        line), its stack has no layer, several layers or a roughness layer, or the
        wavelength lies outside the fitted range (a dispersion model is not extrapolated
        beyond the data that fixed it).
    """
    from .films import read_fit_json  # the film objects, imported where needed

    stack, fitted = read_fit_json(path)
    layer_n, thickness, _ = coating_of_stack(
        stack,
        wavelength_nm,
        fitted,
        where=str(path),
        hint="fit one layer, or give --coating and --thickness",
    )
    return layer_n, thickness


def coating_of_stack(
    stack: Any,
    wavelength_nm: float,
    fitted_range_nm: tuple[float, float],
    *,
    where: str,
    hint: str = "fit one layer",
) -> tuple[complex, float, complex]:
    """The tracer's coating and substrate from a fitted one-layer stack, at one wavelength.

    Parameters
    ----------
    stack : labbrdf.films.Stack
        The fitted stack (the ``stack`` of a :class:`labbrdf.FilmFit`), one layer over the
        substrate.
    wavelength_nm : float
        Vacuum wavelength [nm], inside ``fitted_range_nm``.
    fitted_range_nm : (float, float)
        The wavelengths the fit saw [nm]; a dispersion model is not extrapolated beyond
        the data that fixed it.
    where : str
        The fit's origin (a file), named in the errors.
    hint : str
        What to do about a stack of another shape, appended to that error.

    Returns
    -------
    layer_index : complex
        The layer's ``n + ik`` at ``wavelength_nm`` [1].
    thickness_nm : float
        Its thickness [nm].
    substrate_index : complex
        The stack's substrate ``n + ik`` at ``wavelength_nm`` [1].

    Raises
    ------
    ValueError
        No layer, several layers or a roughness layer, or a wavelength outside the fitted
        range.
    """
    from .films import Roughness

    names = [lay.name for lay in stack.layers]
    if len(stack.layers) != 1 or isinstance(stack.layers[0].material, Roughness):
        raise ValueError(
            f"{where}: the tracer has one coating over the substrate; this fit's stack has "
            f"{len(names)} layer(s) {names} ({hint})"
        )
    wl = float(wavelength_nm)
    lo, hi = float(fitted_range_nm[0]), float(fitted_range_nm[1])
    if not (math.isfinite(wl) and lo <= wl <= hi):
        raise ValueError(
            f"{where}: {wl:g} nm is outside the fitted range [{lo:g}, {hi:g}] nm; the layer's "
            "dispersion is not extrapolated"
        )
    layer = stack.layers[0]
    at = stack.nk(wl)
    return (
        complex(np.asarray(at[layer.name]).ravel()[0]),
        float(layer.thickness_nm),
        complex(np.asarray(at["substrate"]).ravel()[0]),
    )


_SERIES = ("time_s", "x_mm", "y_mm")


def series_members(table: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    """(label, rows) per member of a series (time or spot) of an n, k table, or the whole.

    The label names the member (``"time 12"``, ``"x 3 y 4"``), empty when the table is no
    series (module Grouping).
    """
    keys = [k for k in _SERIES if k in table.columns]
    if not keys:
        return [("", table)]
    out = []
    for key, g in table.groupby(keys, sort=True, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        lab = ", ".join(f"{k.split('_')[0]} {v:g}" for k, v in zip(keys, key, strict=True))
        out.append((lab, g))
    return out


def nk_panels(table: pd.DataFrame, *, max_series: int | None = None) -> list[dict[str, Any]]:
    """The two panels (n, k against wavelength) that draw an n, k table.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`combined_table` (one line per series member, shaded +-1 sigma band) or an
        :func:`nk_table` (one series per angle of incidence, 1-sigma error bars).
    max_series : int, optional
        Draw at most this many members or angles (the first ones).

    Returns
    -------
    list of dict
        Panel descriptions (``title``, ``xlabel``, ``ylabel``, ``series``), as the
        report's ``panels_figure`` and :func:`plot_table` draw them.
    """
    if not {"wavelength_nm", "n", "k", "n_sigma", "k_sigma"} <= set(table.columns):
        raise ValueError(
            "not an n, k table: expected the columns wavelength_nm, n, k, n_sigma, k_sigma "
            f"(of nk_table or combined_table), got {list(table.columns)}"
        )
    per_angle = "theta_i_deg" in table.columns
    if per_angle:
        p = table.assign(theta=table["theta_i_deg"].round(2))
        groups = [(f"\u03b8i {th:g}\u00b0", g) for th, g in p.groupby("theta", sort=True)]
    else:
        groups = series_members(table)
    groups = groups[:max_series] if max_series is not None else groups
    by_wl = table["wavelength_nm"].round(6).nunique() > 1
    panels = []
    for q in ("n", "k"):
        series = []
        for lab, g in groups:
            s: dict[str, Any] = {
                "label": lab,
                "x": g["wavelength_nm"].to_numpy(float),
                "y": g[q].to_numpy(float),
            }
            if per_angle:
                s["yerr"] = g[f"{q}_sigma"].to_numpy(float)
                s["style"] = "points" if g["wavelength_nm"].nunique() < 3 else "line"
            else:
                s["band"] = g[f"{q}_sigma"].to_numpy(float)
                s["style"] = "line" if by_wl else "points"
            series.append(s)
        panels.append(
            {
                "title": f"pseudo-{q} per angle of incidence" if per_angle else f"combined {q}",
                "xlabel": "wavelength [nm]",
                "ylabel": f"<{q}> [1]" if per_angle else f"{q} [1]",
                "series": series,
            }
        )
    return panels


def plot_table(table: pd.DataFrame, ax: Any = None) -> Any:
    """n and k against wavelength with their 1-sigma uncertainties, for notebooks.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`combined_table` (lines with shaded +-1 sigma bands, one per series member)
        or an :func:`nk_table` (the pseudo-constants, one series per angle of incidence,
        with 1-sigma error bars). The report's n, k figures draw the same panels
        (:func:`nk_panels`).
    ax : pair of matplotlib Axes, optional
        Where to draw n and k; default a new figure with two side-by-side axes.

    Returns
    -------
    numpy.ndarray of matplotlib Axes
        The n and the k axes.

    Raises
    ------
    ValueError
        The table lacks the n, k columns.

    Examples
    --------
    >>> from labbrdf import nk  # doctest: +SKIP
    >>> nk.plot_table(nk.combined_table(measurement))  # doctest: +SKIP
    """
    from ._plotting import draw_panel  # matplotlib only when drawing

    panels = nk_panels(table)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(1, 2, figsize=(9.2, 3.4), layout="constrained")
    axes = np.asarray(ax, dtype=object).ravel()
    if axes.size != 2:
        raise ValueError(f"ax: expected two Axes (n, k), got {axes.size}")
    for a, panel in zip(axes, panels, strict=True):
        draw_panel(a, panel)
    return axes


# --------------------------------------------------------------------------- tables from files


def tabulated_from_file(
    path: str | os.PathLike[str], *, theta_deg: float | None = None
) -> disp.Tabulated:
    """Tabulated ``n, k`` of a material, read from a file.

    Parameters
    ----------
    path : path-like
        A text table ``wavelength_nm n [k]`` (comma, semicolon or whitespace separated,
        ``#`` comments, an optional header line; :func:`labbrdf.dispersion.parse_nk_table`),
        or any ellipsometer export labbrdf reads: its psi/Delta are inverted to two-phase
        pseudo-constants (:func:`nk_table`) and averaged over the angles of incidence with
        the inverse-variance weights of :func:`combined_table` (a bare, smooth substrate:
        the pseudo-constants are the material's).
    theta_deg : float, optional
        Use only this angle of incidence of an ellipsometer file.

    Returns
    -------
    labbrdf.dispersion.Tabulated
        Keyed ``file:PATH`` (its ``to_dict`` names the file).

    Raises
    ------
    labbrdf.dispersion.DispersionError
        The file cannot be read as either, is not a regular file (a device, a FIFO: refused
        before it is opened) or is larger than :data:`MAX_TABLE_BYTES`; names the file (and
        the line of a table).
    """
    from .outputs import InputFileError, read_input_file

    p = Path(path)
    try:
        raw = read_input_file(p, max_bytes=MAX_TABLE_BYTES, what="n,k table or ellipsometer file")
    except InputFileError as exc:
        raise disp.DispersionError(str(exc)) from None
    text = raw.decode("utf-8", errors="replace")
    try:
        w, n, k = disp.parse_nk_table(text, str(p))
    except disp.DispersionError as table_error:
        w, n, k = _pseudo_constants(p, theta_deg, table_error)
    return disp.Tabulated(w, n, k, source=str(p), key=f"file:{p}")


def _pseudo_constants(
    path: Path, theta_deg: float | None, table_error: disp.DispersionError
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Pseudo-constants of an ellipsometer file, combined over angles."""
    try:
        meas = adapters.read(path)
    except ValueError as exc:
        raise disp.DispersionError(
            f"{path}: neither an n,k table ({table_error}) nor an ellipsometer file ({exc})"
        ) from None
    df = meas.data
    if theta_deg is not None:
        keep = (~df["quantity"].isin(["psi", "delta"])) | (
            np.abs(df["theta_i_deg"] - theta_deg) < 1e-3
        )
        df = df[keep]
    try:
        table = combined_table(df, on_ill_conditioned="ignore")
    except ValueError as exc:
        raise disp.DispersionError(f"{path}: no pseudo-constants ({exc})") from None
    if "combined" in table and not bool(table["combined"].all()):
        raise disp.DispersionError(
            f"{path}: its angles of incidence disagree (pseudo-constants of a stack, not a "
            "material's constants); fit the stack with `labbrdf film` and use its layers"
        )
    table = table.sort_values("wavelength_nm").drop_duplicates("wavelength_nm")
    n = table["n"].to_numpy(float)
    k = table["k"].to_numpy(float)
    if np.any(n < 0) or np.any(k < 0):
        raise disp.DispersionError(
            f"{path}: the pseudo-constants have n < 0 or k < 0 at some wavelengths; they "
            "are not a material's constants (a film or a rough surface)"
        )
    return table["wavelength_nm"].to_numpy(float), n, k
