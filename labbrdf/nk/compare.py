"""Reflectances predicted from pseudo-constants, compared with measured reflectance rows."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from .. import ellipsometry as ell
from ..dataset import Measurement
from .lookup import _single, nk_at
from .tables import _frame, combined_table


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
    from .. import integrate, models  # the physics/model layer, imported where needed

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
