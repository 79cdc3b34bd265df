"""n, k of a fitted film stack at any wavelengths, with their first-order uncertainties.

The index of each layer (and of the substrate) is a function of the fitted parameters;
its standard error is the first-order propagation ``sqrt(g^T C g)`` of the fit's
covariance ``C`` through the central-difference gradient ``g`` of n (and of k) in each
varying parameter (the delta method; e.g. Bevington & Robinson, *Data Reduction and
Error Analysis*, 3rd ed., eq. 3.13). A table or a fixed parameter contributes nothing.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy import special

if TYPE_CHECKING:
    from .film import FilmFit

__all__ = ["nk_at_table", "nk_entry", "nk_with_sigma"]


def _gradients(fit: FilmFit, wl: NDArray) -> dict[str, list[NDArray]]:
    """d(n + ik)/d(parameter) of each medium on ``wl``, one array per varying parameter."""
    res = fit.result
    names = list(res.var_names)
    vals = {k: res.params[k].value for k in names}
    base = fit.stack.nk(wl)
    grads: dict[str, list[NDArray]] = {lay: [] for lay in base}
    for k in names:
        q = res.params[k]
        h = 1e-6 * max(abs(q.value), 1e-3)
        up, dn = dict(vals), dict(vals)
        up[k] = q.value + h if q.value + h <= q.max else q.value
        dn[k] = q.value - h if q.value - h >= q.min else q.value
        step = up[k] - dn[k]
        try:
            a = fit.model.stack.with_values(up).nk(wl)
            b = fit.model.stack.with_values(dn).nk(wl)
        except ValueError:
            a, b, step = base, base, 1.0
        for lay in base:
            g = (np.asarray(a[lay]) - np.asarray(b[lay])) / step if step else 0 * base[lay]
            grads[lay].append(np.asarray(g, complex))
    return grads


def nk_with_sigma(fit: FilmFit, wavelength_nm: ArrayLike) -> dict[str, dict[str, NDArray]]:
    """n, k of every medium of the best-fit stack and their standard errors.

    Parameters
    ----------
    fit : FilmFit
    wavelength_nm : array_like
        Vacuum wavelengths [nm], inside every table of the stack.

    Returns
    -------
    dict
        medium name (each layer's, ``"substrate"``) -> ``{"n", "k", "n_stderr",
        "k_stderr"}`` arrays [1] on ``wavelength_nm``. A stderr is 0 where n (k) depends on
        no varying parameter and NaN where the covariance is not available. From the files'
        sigmas: multiply by :attr:`FilmFit.misfit_scale` where chi-square rejects the model.

    Raises
    ------
    ValueError
        A wavelength outside a table of the stack (the table's own error).
    """
    wl = np.atleast_1d(np.asarray(wavelength_nm, float))
    res = fit.result
    names = list(res.var_names)
    cov = None if res.covar is None else np.asarray(res.covar, float)
    usable = cov is not None and cov.shape == (len(names), len(names))
    base = fit.stack.nk(wl)
    grads = _gradients(fit, wl)
    out: dict[str, dict[str, NDArray]] = {}
    for lay, nk in base.items():
        nk = np.asarray(nk, complex)
        entry = {"n": nk.real.astype(float), "k": nk.imag.astype(float)}
        g = np.stack(grads[lay], axis=-1) if names else np.zeros((wl.size, 0), complex)
        for part, gv in (("n", g.real), ("k", g.imag)):
            zero = ~np.any(gv != 0, axis=-1)
            if usable and cov is not None:
                var = np.einsum("ij,jk,ik->i", gv, cov, gv)
                se = np.sqrt(np.where(var >= 0, var, np.nan))
            else:
                se = np.full(wl.size, np.nan)
            entry[f"{part}_stderr"] = np.where(zero, 0.0, se)
        out[lay] = entry
    return out


def nk_entry(fit: FilmFit, wl: float) -> dict[str, dict[str, Any]]:
    """n, k of every medium at one wavelength [nm] with stderr and 95 % intervals.

    The summary's ``nk_at_<WL>nm`` entries: ``n, k, n_stderr, k_stderr`` (None where not
    available), ``n_ci95, k_ci95`` (Student t with the fit's degrees of freedom) and,
    where chi-square rejects the model, ``*_stderr_scaled`` and ``*_ci95_scaled`` (times
    :attr:`FilmFit.misfit_scale`).
    """
    t = float(special.stdtrit(max(fit.result.nfree, 1), 0.975))
    scale = fit.misfit_scale
    out: dict[str, dict[str, Any]] = {}
    for lay, arr in nk_with_sigma(fit, [wl]).items():
        entry: dict[str, Any] = {"n": float(arr["n"][0]), "k": float(arr["k"][0])}
        for part in ("n", "k"):
            se = float(arr[f"{part}_stderr"][0])
            v = entry[part]
            ok = math.isfinite(se)
            entry[f"{part}_stderr"] = se if ok else None
            entry[f"{part}_ci95"] = [v - t * se, v + t * se] if ok else None
            if scale is not None and ok:
                entry[f"{part}_stderr_scaled"] = se * scale
                entry[f"{part}_ci95_scaled"] = [v - t * se * scale, v + t * se * scale]
        out[lay] = entry
    return out


def nk_at_table(fit: FilmFit, wavelength_nm: ArrayLike) -> pd.DataFrame:
    """n, k of every medium with their standard errors, one column each.

    Parameters
    ----------
    fit : FilmFit
    wavelength_nm : array_like
        Vacuum wavelengths [nm].

    Returns
    -------
    pandas.DataFrame
        ``wavelength_nm`` then, per medium, ``<name>_n, <name>_n_stderr, <name>_k,
        <name>_k_stderr`` [1]; where chi-square rejects the model (:attr:`FilmFit.misfit_scale`)
        also ``<name>_n_stderr_scaled, <name>_k_stderr_scaled``.
    """
    wl = np.atleast_1d(np.asarray(wavelength_nm, float))
    scale = fit.misfit_scale
    cols: dict[str, Any] = {"wavelength_nm": wl}
    for name, arr in nk_with_sigma(fit, wl).items():
        for part in ("n", "k"):
            cols[f"{name}_{part}"] = arr[part]
            cols[f"{name}_{part}_stderr"] = arr[f"{part}_stderr"]
            if scale is not None:
                cols[f"{name}_{part}_stderr_scaled"] = arr[f"{part}_stderr"] * scale
    return pd.DataFrame(cols)
