"""Pseudo-constant tables from a dataset's psi/Delta rows: per point, combined over angles, JSON.

The dataset layer of :mod:`labbrdf.ellipsometry`: it pairs the ``psi`` and ``delta`` rows of
a :class:`~labbrdf.dataset.Measurement` (or its tidy DataFrame), inverts every point to the
two-phase pseudo-index ``<N> = n + ik`` with propagated uncertainties, combines the angles
of incidence per wavelength (predicted reflectances are :mod:`labbrdf.nk.compare`).

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
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import pandas as pd

from .. import ellipsometry as ell
from ..dataset import Measurement
from ..jsonsafe import jsonable

__all__ = [
    "POSITION_TOL_MM",
    "AngleVerdict",
    "angle_verdict",
    "combined_table",
    "nk_json",
    "nk_table",
    "ordinary_psi_delta",
]


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
            c: jsonable(g[c].tolist())
            for c in ["wavelength_nm", "theta_i_deg", "n", "k", "n_sigma", "k_sigma"] + extra
        }
        obj["combined"] = {c: jsonable(cg[c].tolist()) for c in _JSON_COMBINED + extra}
        groups.append({"sample": sample, "source": source, "data": obj})
    if len(groups) == 1:
        return groups[0]["data"]
    return {"groups": groups}


def _angle_dependent_message(wavelength_nm: np.ndarray) -> str:
    w = ", ".join(f"{v:g}" for v in np.unique(wavelength_nm)[:5])
    return (
        f"at {w} nm no n, k: the angles of incidence disagree at most of the sample's "
        "wavelengths, so its two-phase values are pseudo-constants of a stack (a film or "
        "roughness), not a material's n, k; fit a stack model to get the layers' constants"
    )
