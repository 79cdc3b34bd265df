r"""Predict, then measure: the tracer's pBRDF from a height map and an ellipsometer's n, k.

Dong et al. (2022) predict the polarized BRDF of a rough sample from two measurements that
know nothing of the BRDF, a profiler's roughness and the materials' optical constants, and
compare the DOP of the prediction with an imaging ellipsometer's (their Fig. 6). This module
does that with **no fitted parameter** on a lab's files of one sample:

* :func:`ellipsometer_dop`: the specular DOP for unpolarized light from each psi (and the
  depolarization channel where the file has one at the same wavelength and angle),
  :func:`labbrdf.specular_dop.specular_dop`;
* :func:`specular_dop_comparison`: the tracer's DOP in the specular bin at the ellipsometer's
  angles and (a few of its) wavelengths, the substrate's n, k from the psi/Delta file
  (:func:`labbrdf.nk.nk_at`) and its GGX alpha from the height map (the maximum-likelihood
  fit of :func:`labbrdf.roughness.topography.fit_slope_distribution`), with the batch errors of the
  evaluated estimator (:meth:`labbrdf.TraceResult.dop_stderr`);
* :func:`predict_brdf`: the tracer's S0 (unpolarized incidence) at every point of a measured
  ``.bsdf`` file, with its Monte Carlo error, the grid integral (TIS) of both, and a sentence
  saying where and by how much the prediction misses.
* :func:`film_coating`: for a coated sample, the coating and the substrate index of its
  one-layer film fit at the ``.bsdf`` wavelength (``predict_brdf(..., film=fit)``;
  conformal: the coating's top as rough as the map, incoherent as ``labbrdf trace
  --coating-from`` builds it);
* :func:`slope_table`: the map's measured slope table, which ``predict_brdf(..., ndf=)``
  traces instead of GGX (docs/prediction.md says why GGX is the default).

The workflow layer draws it (:mod:`labbrdf.report.sections.prediction`); nothing here is
fitted, so a disagreement is a finding about the model (single scattering, GGX, a
two-phase n, k) or about the samples, not a fit residual.

What is compared
----------------
The tracer returns bin averages on its (theta_r, phi_r) grid (``step_deg`` bins, the cos-
weighted average of f over the bin); a ``.bsdf`` file holds point values on its scatter grid.
Each file point takes the value of the tracer bin it falls in (as
:func:`labbrdf.writers.zemax.binned_to_bsdf` writes a trace), so where f curves strongly across
a bin (a lobe narrower than a few bins) the two differ by about
``(step / lobe width)^2 / 24`` (docs/tracer.md). Prediction and measurement are integrated by
the same first-order grid rule (:func:`labbrdf.integrate.grid_integral`) on the file's own
grid, so their TIS compare like with like; the tracer's own hemispherical albedo is given
beside it (it includes the directions the file's grid does not cover).

"Consistent within the Monte Carlo error" means, per point (:attr:`BrdfPrediction.consistent`),
``|f_pred - f_meas| <= 3 SE + 1e-5 |f_meas|``, and per region (the specular lobe, the rest;
:meth:`BrdfPrediction.regions`, which the verdict uses) ``|ratio - 1| <= 3 SE + 1e-5`` for the
ratio of the region's grid integrals, SE from the batch spread of the integral itself (the
points' errors are correlated). ``1e-5`` is the rounding of a six-digit file. The
measurement's own error is unknown (``.bsdf`` files carry none), so a real measurement is
judged by the size of the ratio, not by this test.
"""

from __future__ import annotations

import builtins
import math
import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from .adapters import zemax_bsdf
from .bsdf_geometry import grid_integral, scatter_to_angles, scatter_to_direction
from .errors import SampleError
from .microfacet import TabulatedNDF
from .nk import ordinary_psi_delta
from .roughness.topography import SlopeFit
from .sample import film_coating, roughness_alpha, slope_table, substrate_nk
from .specular_dop import specular_dop
from .tracer import Coating, Substrate, TraceConfig, TraceResult, trace

__all__ = [
    "DEFAULT_RAYS",
    "MAX_WAVELENGTHS",
    "BrdfPrediction",
    "DopComparison",
    "PredictionError",
    "ellipsometer_dop",
    "film_coating",
    "predict_brdf",
    "roughness_alpha",
    "slope_table",
    "specular_dop_comparison",
    "substrate_nk",
]

#: rays per tracer run: the evaluated estimator's specular DOP and lobe converge fast (a
#: bare substrate's single scattering is closed form and has no Monte Carlo error at all)
DEFAULT_RAYS = 32_768
#: wavelengths of an ellipsometer file traced for the DOP comparison (evenly spread)
MAX_WAVELENGTHS = 4
#: relative rounding of a six-digit ``.bsdf`` value, allowed on top of 3 SE
FILE_ROUNDING = 1e-5
#: smallest half-width of the "specular lobe" cone about the specular direction [deg]
MIN_LOBE_DEG = 3.0

MapFn = Callable[..., Iterable[Any]]


#: inputs that cannot make a prediction (the message names the file and what is missing):
#: the errors of a sample that cannot be built from its files
PredictionError = SampleError


# --------------------------------------------------------------------------- inputs


def _psi_rows(data: pd.DataFrame) -> pd.DataFrame:
    sel = ordinary_psi_delta(data)
    psi = sel[sel["quantity"].astype(str) == "psi"]
    if psi.empty:
        src = ", ".join(sorted(set(data["source"].astype(str))))[:200] if len(data) else "-"
        raise PredictionError(f"{src}: no psi rows (ordinary ellipsometry) in the data")
    return psi


def ellipsometer_dop(data: pd.DataFrame, *, depolarizer: str = "mixed") -> pd.DataFrame:
    """Specular DOP for unpolarized light from every psi row of a dataset.

    Parameters
    ----------
    data : pandas.DataFrame
        A labbrdf dataset with psi rows (and, optionally, ``depolarization`` rows).
    depolarizer : {"mixed", "retardance"}
        How the depolarizing part acts (:func:`labbrdf.specular_dop.specular_dop`).

    Returns
    -------
    pandas.DataFrame
        One row per psi: ``sample, source, wavelength_nm, theta_i_deg, psi_deg,
        psi_sigma_deg, depolarization, depolarization_sigma, dop, dop_sigma`` [deg or 1].
        ``depolarization`` is that of the same file, wavelength and angle (to 1e-3 nm and
        1e-3 deg), NaN where the file has none there (then the DOP is that of a
        non-depolarizing sample); a NaN psi sigma propagates as 0.

    Notes
    -----
    ``depolarization`` is returned as the file has it, but the DOP takes a negative value
    as 0: ``d = 1 - P`` scatters about 0 on a non-depolarizing sample (a WVASE file of a
    tantalum-oxide wafer has 839 of 2028 points below 0, down to -6 %, sigma 1 %), and
    ``(1 - d) |cos 2psi|`` with ``d < 0`` could exceed 1.

    Raises
    ------
    PredictionError
        No psi rows.
    """
    psi = _psi_rows(data)
    keys = ["source", "_wl", "_th"]
    out = psi.assign(
        _wl=psi["wavelength_nm"].round(3), _th=psi["theta_i_deg"].round(3)
    ).reset_index(drop=True)
    dep = data[data["quantity"].astype(str) == "depolarization"]
    if len(dep):
        dep = (
            dep.assign(_wl=dep["wavelength_nm"].round(3), _th=dep["theta_i_deg"].round(3))
            .groupby(keys, sort=False)[["value", "sigma"]]
            .first()
            .rename(columns={"value": "depolarization", "sigma": "depolarization_sigma"})
        )
        out = out.join(dep, on=keys)
    else:
        out = out.assign(depolarization=np.nan, depolarization_sigma=np.nan)
    d = out["depolarization"].to_numpy(float)
    sd = out["depolarization_sigma"].to_numpy(float)
    s_psi = out["sigma"].to_numpy(float)
    r = specular_dop(
        out["value"].to_numpy(float),
        psi_sigma_deg=np.where(np.isfinite(s_psi), s_psi, 0.0),
        depolarization=np.where(np.isfinite(d), np.clip(d, 0.0, 1.0), 0.0),
        depolarization_sigma=np.where(np.isfinite(sd), sd, 0.0),
        depolarizer=depolarizer,  # type: ignore[arg-type]
    )
    return pd.DataFrame(
        {
            "sample": out["sample"].astype(str),
            "source": out["source"].astype(str),
            "wavelength_nm": out["wavelength_nm"].to_numpy(float),
            "theta_i_deg": out["theta_i_deg"].to_numpy(float),
            "psi_deg": out["value"].to_numpy(float),
            "psi_sigma_deg": s_psi,
            "depolarization": d,
            "depolarization_sigma": sd,
            "dop": r.dop,
            "dop_sigma": r.sigma,
        }
    )


# --------------------------------------------------------------------------- tracer runs


def _config(
    wavelength_nm: float,
    theta_i_deg: float,
    n: float,
    k: float,
    alpha: float,
    coating: Coating | None,
    rays: int,
    seed: int,
    step_deg: float,
    ndf: TabulatedNDF | None = None,
) -> TraceConfig:
    # evaluated wherever it applies (a GGX first interface, or a bare substrate's table);
    # a measured table on a coating's top is counted
    return TraceConfig(
        wavelength_nm=float(wavelength_nm),
        theta_i_deg=float(theta_i_deg),
        substrate=Substrate(n=float(n), k=float(k), alpha=float(alpha), ndf=ndf),
        coating=coating,
        rays=int(rays),
        seed=int(seed),
        scattering="single",
        estimator="auto",
        theta_step_deg=float(step_deg),
        phi_step_deg=float(step_deg),
    )


def _bin(res: TraceResult, theta_deg: NDArray, phi_deg: NDArray) -> tuple[NDArray, NDArray]:
    """Indices of the tracer bins holding the directions (theta, phi) [deg]."""
    te, pe = res.theta_r_edges_deg, res.phi_r_edges_deg
    i = np.clip(np.searchsorted(te, theta_deg, side="right") - 1, 0, te.size - 2)
    phi = pe[0] + np.mod(phi_deg - pe[0], 360.0)
    j = np.clip(np.searchsorted(pe, phi, side="right") - 1, 0, pe.size - 2)
    return i, j


@dataclass
class DopComparison:
    """Specular DOP of the ellipsometer beside the tracer's, per wavelength and angle.

    Attributes
    ----------
    table : pandas.DataFrame
        ``wavelength_nm, theta_i_deg, dop_ellipsometer, dop_ellipsometer_sigma,
        depolarization, dop_tracer, dop_tracer_stderr, n, k, z`` (z = difference over the
        combined 1-sigma errors; NaN where both are 0).
    ellipsometer : pandas.DataFrame
        :func:`ellipsometer_dop` of every psi row (the lines of the figure).
    alpha : float
        GGX roughness used [1].
    rays : int
        Rays per tracer run.
    """

    table: pd.DataFrame
    ellipsometer: pd.DataFrame
    alpha: float
    rays: int
    coating: dict[str, Any] | None = None


def _pick_wavelengths(wl: NDArray, wanted: Sequence[float] | None, most: int) -> NDArray:
    u = np.unique(np.round(wl, 3))
    if wanted is not None:
        return np.asarray(wanted, float)
    if u.size <= most:
        return u
    return u[np.unique(np.linspace(0, u.size - 1, most).round().astype(int))]


def specular_dop_comparison(
    data: pd.DataFrame,
    alpha: float,
    *,
    wavelengths_nm: Sequence[float] | None = None,
    max_wavelengths: int = MAX_WAVELENGTHS,
    coating: Coating | None = None,
    rays: int = DEFAULT_RAYS,
    seed: int = 0,
    step_deg: float = 1.0,
    depolarizer: str = "mixed",
    map: MapFn = builtins.map,  # noqa: A002
) -> DopComparison:
    """The tracer's specular DOP at the ellipsometer's angles beside the ellipsometer's.

    Parameters
    ----------
    data : pandas.DataFrame
        psi/Delta rows of ONE file of the sample (the substrate's n, k come from them).
    alpha : float
        GGX roughness of the substrate [1], e.g. :func:`roughness_alpha` of its height map.
    wavelengths_nm : sequence of float, optional
        Wavelengths to trace [nm]; default ``max_wavelengths`` measured ones evenly spread.
    coating : Coating, optional
        A coating over the substrate (e.g. :func:`labbrdf.sample.coating_from_fit`); the
        psi/Delta then still give the substrate.
    rays, seed, step_deg :
        Tracer rays per run, seed and bin width [deg] (the specular bin is the one holding
        (theta_i, 180 deg)).
    depolarizer : {"mixed", "retardance"}
        See :func:`labbrdf.specular_dop.specular_dop`.
    map : callable
        Ordered map for the tracer's work units (:func:`labbrdf.trace`).

    Returns
    -------
    DopComparison

    Raises
    ------
    PredictionError
        See :func:`substrate_nk` and :func:`ellipsometer_dop`.
    """
    ell = ellipsometer_dop(data, depolarizer=depolarizer)
    if ell["source"].nunique() != 1:
        raise PredictionError(
            f"expected the psi/Delta of one file, got {sorted(ell['source'].unique())[:4]}"
        )
    wls = _pick_wavelengths(ell["wavelength_nm"].to_numpy(float), wavelengths_nm, max_wavelengths)
    nk = substrate_nk(data, wls)
    rows = []
    for w, n, k in zip(wls, nk["n"], nk["k"], strict=True):
        at = ell[np.isclose(ell["wavelength_nm"], w, atol=1e-3)]
        for th in sorted(at["theta_i_deg"].round(3).unique()):
            e = at[np.isclose(at["theta_i_deg"], th, atol=1e-3)].iloc[0]
            res = trace(
                _config(w, th, n, k, alpha, coating, rays, seed, step_deg),
                map=map,
            )
            i, j = _bin(res, np.asarray(th), np.asarray(180.0))
            d, se = float(res.dop()[i, j]), float(res.dop_stderr()[i, j])
            err = math.hypot(se, float(e["dop_sigma"]))
            rows.append(
                {
                    "wavelength_nm": float(w),
                    "theta_i_deg": float(th),
                    "dop_ellipsometer": float(e["dop"]),
                    "dop_ellipsometer_sigma": float(e["dop_sigma"]),
                    "depolarization": float(e["depolarization"]),
                    "dop_tracer": d,
                    "dop_tracer_stderr": se,
                    "n": float(n),
                    "k": float(k),
                    "z": (d - float(e["dop"])) / err if err > 0 else math.nan,
                }
            )
    return DopComparison(
        table=pd.DataFrame(rows),
        ellipsometer=ell,
        alpha=float(alpha),
        rays=int(rays),
        coating=None if coating is None else coating.to_dict(),
    )


# --------------------------------------------------------------------------- BRDF


@dataclass
class BrdfPrediction:
    """The tracer's BRDF (unpolarized S0) at the points of a measured ``.bsdf`` file.

    Arrays are shaped ``(aoi, azimuth, radial)`` on the file's scatter grid; points below
    the horizon hold 0 in both ``measured`` and ``predicted`` and False in ``above``.

    Attributes
    ----------
    path : str
        The ``.bsdf`` file.
    wavelength_nm, n, k, n_sigma, k_sigma, alpha, alpha_u : float
        Wavelength [nm], substrate index and GGX roughness used, with their 1-sigma [1].
    theta_i_deg, azimuth_deg, radial_deg : ndarray
        The file's grid [deg].
    symmetry : str
        The file's symmetry keyword.
    theta_r_deg, phi_r_deg, above, radial_off_deg :
        Each point's direction [deg], whether it is above the horizon, and its angle from
        the specular direction [deg].
    measured, predicted, predicted_stderr : ndarray
        BRDF [sr^-1] and the prediction's Monte Carlo standard error.
    tis_measured, tis_predicted, tis_predicted_stderr : ndarray (aoi,)
        Grid integrals (:func:`labbrdf.integrate.grid_integral`) on the file's grid [1].
    tis_file : ndarray (aoi,)
        The file's own TIS lines [1].
    albedo, albedo_stderr : ndarray (aoi,)
        The tracer's directional-hemispherical reflectance [1].
    uncovered_fraction : ndarray (aoi,)
        Projected solid angle the grid does not cover, as a fraction of pi sr.
    lobe_deg : float
        Half-width of the cone called the specular lobe [deg].
    rays, seconds : int, float
        Rays per incidence and the tracers' total time [s].
    coating : dict or None
        The coating used, if any.
    slopes : {"ggx", "measured"}
        The substrate's facets: GGX of ``alpha``, or the height map's measured slope table.
    index_from : {"psi/Delta", "film fit", "given"}
        Where the substrate's n, k came from: the two-phase inversion of the psi/Delta, the
        substrate of a film fit, or the caller.
    """

    path: str
    wavelength_nm: float
    n: float
    k: float
    n_sigma: float
    k_sigma: float
    alpha: float
    alpha_u: float
    theta_i_deg: NDArray[np.float64]
    azimuth_deg: NDArray[np.float64]
    radial_deg: NDArray[np.float64]
    symmetry: str
    theta_r_deg: NDArray[np.float64]
    phi_r_deg: NDArray[np.float64]
    above: NDArray[np.bool_]
    radial_off_deg: NDArray[np.float64]
    measured: NDArray[np.float64]
    predicted: NDArray[np.float64]
    predicted_stderr: NDArray[np.float64]
    tis_measured: NDArray[np.float64]
    tis_predicted: NDArray[np.float64]
    tis_predicted_stderr: NDArray[np.float64]
    tis_file: NDArray[np.float64]
    albedo: NDArray[np.float64]
    albedo_stderr: NDArray[np.float64]
    uncovered_fraction: NDArray[np.float64]
    lobe_deg: float
    rays: int
    seconds: float
    coating: dict[str, Any] | None = None
    slopes: str = "ggx"
    index_from: str = "psi/Delta"
    region_table: pd.DataFrame = field(default_factory=pd.DataFrame, repr=False)
    results: list[TraceResult] = field(default_factory=list, repr=False)

    @property
    def consistent(self) -> NDArray[np.bool_]:
        """Per point: ``|pred - meas| <= 3 SE + 1e-5 |meas|`` (module docstring)."""
        tol = 3.0 * self.predicted_stderr + FILE_ROUNDING * np.abs(self.measured)
        return ~self.above | (np.abs(self.predicted - self.measured) <= tol)

    def regions(self) -> pd.DataFrame:
        """Per incidence: the prediction against the measurement in the lobe and off it.

        Returns
        -------
        pandas.DataFrame
            ``theta_i_deg, region ("specular lobe" | "off specular"), points,
            scatter_measured, scatter_predicted, scatter_predicted_stderr`` (the region's
            grid integral ``int f cos(theta_r) d omega`` [1] and the prediction's batch
            error), ``ratio`` = predicted / measured scatter of the region and
            ``ratio_stderr`` (Monte Carlo 1 sigma), ``ratio_lo, ratio_hi`` (10 and 90 %
            quantiles of the point ratios), ``consistent`` (``|ratio - 1| <= 3
            ratio_stderr + 1e-5``).
        """
        return self.region_table.copy()

    def verdict(self) -> str:
        """A plain sentence: where and by how much the prediction misses (or that it does not).

        Per incidence and region (:meth:`regions`): "on the measurement" when the
        integrated ratio is 1 within 3 Monte Carlo sigma (and the file's rounding), "within
        X %" when it misses by less than 10 %, else "N % low" / "N % high".
        """
        parts = []
        for ti, g in self.region_table.groupby("theta_i_deg", sort=True):
            bits = []
            for _, r in g.iterrows():
                if r["points"] == 0 or not np.isfinite(r["ratio"]):
                    continue
                where = (
                    f"in the specular lobe (within {self.lobe_deg:.3g} deg of specular)"
                    if r["region"] == "specular lobe"
                    else "off specular"
                )
                ratio, se = float(r["ratio"]), float(r["ratio_stderr"])
                how = f"(integrated ratio {ratio:.3f} +- {se:.3f}, Monte Carlo 1 sigma)"
                if r["consistent"]:
                    bits.append(f"on the measurement {where} {how}")
                elif abs(ratio - 1.0) < 0.1:
                    bits.append(f"within {_pct_ceiling(abs(ratio - 1.0))} % {where} {how}")
                else:
                    word = "low" if ratio < 1.0 else "high"
                    bits.append(f"{abs(ratio - 1.0) * 100:.0f} % {word} {where} {how}")
            if bits:
                parts.append(f"at {float(ti):g} deg the prediction is " + " and ".join(bits))
        if not parts:
            return "No measured point above 0 to compare with."
        s = "; ".join(parts)
        return s[0].upper() + s[1:] + "."


def _pct_ceiling(x: float) -> str:
    for v in (1, 2, 5, 10):
        if x <= v / 100:
            return str(v)
    return f"{x * 100:.0f}"


def _read_table(bsdf: Any) -> tuple[zemax_bsdf.BsdfTable, str]:
    if isinstance(bsdf, (str, os.PathLike)):
        return zemax_bsdf.read_table(bsdf), str(bsdf)
    return zemax_bsdf._table_of(bsdf), "<table>"


def _geometry(ti: NDArray, az: NDArray, rad: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """theta_r, phi_r, above-horizon and angle from specular [deg] of every grid point."""
    tr, pr, above = scatter_to_angles(ti[:, None, None], rad[None, None, :], az[None, :, None])
    d = scatter_to_direction(ti[:, None, None], rad[None, None, :], az[None, :, None])
    spec = scatter_to_direction(ti[:, None, None], np.zeros((1, 1, 1)), np.zeros((1, 1, 1)))
    off = np.degrees(np.arccos(np.clip(np.sum(d * spec, axis=0), -1.0, 1.0)))
    return tr, pr, above, off


def _sampled(
    runs: Sequence[TraceResult], tr: NDArray, pr: NDArray, above: NDArray
) -> tuple[NDArray, NDArray]:
    """Each run's S0 and its standard error in the bins of the grid points [sr^-1]."""
    pred = np.zeros(tr.shape)
    se = np.zeros(tr.shape)
    for a, res in enumerate(runs):
        i, j = _bin(res, np.where(above[a], tr[a], 0.0), pr[a])
        pred[a] = np.where(above[a], res.s0()[i, j], 0.0)
        se[a] = np.where(above[a], res.mueller_stderr[..., 0, 0][i, j], 0.0)
    return pred, se


def _batch_integrals(
    res: TraceResult, a: int, tr: NDArray, pr: NDArray, above: NDArray, geo: dict[str, Any]
) -> tuple[NDArray, NDArray]:
    """Per tracer batch: S0 on incidence ``a``'s grid points (B, az, rad) and weights (B,)."""
    i, j = _bin(res, np.where(above[a], tr[a], 0.0), pr[a])
    if res.batch_mueller is None:
        return np.where(above[a], res.s0()[i, j], 0.0)[None], np.ones(1)
    s0_b = res.batch_mueller[:, :, :, 0, 0].astype(float)[:, i, j]
    return np.where(above[a], s0_b, 0.0), res.block_rays.astype(float)


def _integral_and_se(
    vals_b: NDArray, w: NDArray, mask: NDArray, geo: dict[str, Any], a: int
) -> tuple[float, float]:
    """Grid integral of the batch mean over ``mask`` and its batch standard error [1].

    ``sqrt(sum_b N_b (I_b - I)^2 / (N (B - 1)))``, as :meth:`labbrdf.TraceResult.dop_stderr`
    does for the DOP: the points' errors are correlated (one batch moves a whole lobe), so
    they are not added in quadrature.
    """
    g = {**geo, "theta_i_deg": geo["theta_i_deg"][a : a + 1]}
    ib = grid_integral(np.where(mask, vals_b, 0.0)[None, :, None], **g)["integral"][0, :, 0]
    mean = float(np.sum(w * ib) / w.sum())
    if w.size < 2:
        return mean, 0.0
    return mean, math.sqrt(float(np.sum(w * (ib - mean) ** 2)) / w.sum() / (w.size - 1))


def _regions(
    runs: Sequence[TraceResult],
    arrays: dict[str, NDArray],
    geo: dict[str, Any],
    lobe: float,
) -> tuple[pd.DataFrame, NDArray]:
    """The region table (:meth:`BrdfPrediction.regions`) and the whole grid's TIS SE."""
    tr, pr, above = arrays["tr"], arrays["pr"], arrays["above"]
    meas, pred, off = arrays["meas"], arrays["pred"], arrays["off"]
    rows, tis_se = [], np.zeros(len(runs))
    for a, res in enumerate(runs):
        vals_b, w = _batch_integrals(res, a, tr, pr, above, geo)
        tis_se[a] = _integral_and_se(vals_b, w, np.ones(vals_b.shape[1:], bool), geo, a)[1]
        for region, sel in (("specular lobe", off[a] <= lobe), ("off specular", off[a] > lobe)):
            m = sel & above[a] & (meas[a] > 0)
            g = {**geo, "theta_i_deg": geo["theta_i_deg"][a : a + 1]}
            im = float(
                grid_integral(np.where(m, meas[a], 0.0)[None, None, None], **g)["integral"].item()
            )
            se = _integral_and_se(vals_b, w, m, geo, a)[1]
            ip = float(
                grid_integral(np.where(m, pred[a], 0.0)[None, None, None], **g)["integral"].item()
            )
            pts = pred[a][m] / meas[a][m] if m.any() else np.array([np.nan])
            ratio = ip / im if im > 0 else math.nan
            rse = se / im if im > 0 else math.nan
            rows.append(
                {
                    "theta_i_deg": float(geo["theta_i_deg"][a]),
                    "region": region,
                    "points": int(m.sum()),
                    "scatter_measured": im,
                    "scatter_predicted": ip,
                    "scatter_predicted_stderr": se,
                    "ratio": ratio,
                    "ratio_stderr": rse,
                    "ratio_lo": float(np.quantile(pts, 0.1)),
                    "ratio_hi": float(np.quantile(pts, 0.9)),
                    "consistent": bool(abs(ratio - 1.0) <= 3.0 * rse + FILE_ROUNDING),
                }
            )
    return pd.DataFrame(rows), tis_se


def _checked_table(
    bsdf: Any, wavelength_nm: float | None
) -> tuple[zemax_bsdf.BsdfTable, str, float]:
    """The ``.bsdf`` table, its name and wavelength [nm], refused if it cannot be predicted."""
    t, path = _read_table(bsdf)
    if t.scatter_type != "BRDF":
        raise PredictionError(f"{path}: {t.scatter_type} data; the tracer predicts a BRDF")
    if t.values.shape[0] != 1 or t.values.shape[1] != 1:
        raise PredictionError(
            f"{path}: {t.values.shape[0]} rotation(s) x {t.values.shape[1]} channel(s) "
            f"({t.spectral}); a prediction at one wavelength needs one rotation, Monochrome"
        )
    wl = wavelength_nm if wavelength_nm is not None else t.wavelength_nm
    if wl is None:
        raise PredictionError(
            f"{path}: the file states no wavelength (no '#labbrdf wavelength_nm' or "
            "'#Wavelength (nm) =' comment); give the wavelength of the measurement"
        )
    return t, path, float(wl)


def _alpha_of(roughness: SlopeFit | float) -> tuple[float, float]:
    """The GGX alpha and its uncertainty (NaN for a bare number) [1]."""
    if isinstance(roughness, SlopeFit):
        return float(roughness.alpha), float(roughness.alpha_u)
    return float(roughness), math.nan


def _substrate_and_coating(
    path: str,
    data: pd.DataFrame | None,
    wl: float,
    roughness: SlopeFit | float,
    coating: Coating | None,
    substrate_index: complex | None,
    film: Any,
    ndf: TabulatedNDF | None,
) -> tuple[dict[str, Any], Coating | None, str]:
    """The substrate's n, k (with sigmas), the coating and where the index came from."""
    index_from = "psi/Delta"
    if film is not None:
        if coating is not None or substrate_index is not None:
            raise PredictionError(
                f"{path}: give the coating once: a film fit, or a coating and substrate index"
            )
        coating, substrate_index = film_coating(film, wl, roughness, ndf=ndf)
        index_from = "film fit"
    elif substrate_index is not None:
        index_from = "given"
    if substrate_index is not None:
        nk: dict[str, Any] = {"n": [substrate_index.real], "k": [substrate_index.imag]}
        nk.update(n_sigma=[math.nan], k_sigma=[math.nan])
    elif data is None:
        raise PredictionError(f"{path}: give the psi/Delta rows or the substrate index")
    else:
        nk = substrate_nk(data, [wl])
    return nk, coating, index_from


def predict_brdf(
    bsdf: str | os.PathLike[str] | zemax_bsdf.BsdfTable,
    data: pd.DataFrame | None,
    roughness: SlopeFit | float,
    *,
    wavelength_nm: float | None = None,
    coating: Coating | None = None,
    substrate_index: complex | None = None,
    film: Any = None,
    ndf: TabulatedNDF | None = None,
    rays: int = DEFAULT_RAYS,
    seed: int = 0,
    step_deg: float = 1.0,
    map: MapFn = builtins.map,  # noqa: A002
) -> BrdfPrediction:
    """The tracer's prediction of a measured ``.bsdf`` BRDF, with no fitted parameter.

    Parameters
    ----------
    bsdf : path-like or BsdfTable
        The measured BRDF (one rotation, monochrome, ``BRDF``).
    data : pandas.DataFrame or None
        psi/Delta rows of the same sample (the substrate's n, k, :func:`substrate_nk`);
        not used (may be None) when ``substrate_index`` is given.
    roughness : SlopeFit or float
        The substrate's GGX alpha [1] (:func:`roughness_alpha` of its height map, whose
        ``alpha_u`` is carried along).
    wavelength_nm : float, optional
        Wavelength of the BRDF [nm]; default the one the file states (a ``#labbrdf
        wavelength_nm`` or ``#Wavelength (nm) =`` comment).
    coating : Coating, optional
        A coating over the substrate (:func:`film_coating`).
    substrate_index : complex, optional
        The substrate's ``n + ik`` [1] at the wavelength, e.g. a film fit's substrate
        (:func:`film_coating`), instead of the two-phase n, k of ``data``.
    film : labbrdf.FilmFit, optional
        A one-layer film fit of the sample: the coating and the substrate index at the
        file's wavelength (:func:`film_coating`, conformal: the coating's top gets the
        substrate's roughness); instead of ``coating`` and ``substrate_index``.
    ndf : TabulatedNDF, optional
        The height map's measured slope table (:func:`slope_table`) on the substrate
        instead of GGX with ``roughness``'s alpha (which still sets the specular lobe's
        width).
    rays, seed, step_deg :
        Rays per incidence, seed, tracer bin width [deg].
    map : callable
        Ordered map for the tracer's work units.

    Returns
    -------
    BrdfPrediction

    Raises
    ------
    PredictionError
        A file with several rotations, tristimulus channels or BTDF data; no wavelength;
        no n, k at the wavelength; ``film`` with ``coating`` or ``substrate_index``, or a
        film fit that gives no coating there (:func:`film_coating`).
    labbrdf.adapters.AdapterError
        A file that is not a readable ``.bsdf``.
    """
    t, path, wl = _checked_table(bsdf, wavelength_nm)
    nk, coating, index_from = _substrate_and_coating(
        path, data, float(wl), roughness, coating, substrate_index, film, ndf
    )
    alpha, alpha_u = _alpha_of(roughness)
    ti = np.asarray(t.theta_i_deg, float)
    az, rad = np.asarray(t.azimuth_deg, float), np.asarray(t.radial_deg, float)
    tr, pr, above, off = _geometry(ti, az, rad)
    meas = np.where(above, t.values[0, 0], 0.0)
    n0, k0 = float(nk["n"][0]), float(nk["k"][0])
    runs = [
        trace(_config(float(wl), th, n0, k0, alpha, coating, rays, seed, step_deg, ndf), map=map)
        for th in ti
    ]
    pred, se = _sampled(runs, tr, pr, above)
    geo: dict[str, Any] = {"theta_i_deg": ti, "azimuth_deg": az, "radial_deg": rad}
    geo["symmetry"] = t.symmetry
    gm = grid_integral(meas[None, None], **geo)
    gp = grid_integral(pred[None, None], **geo)
    lobe = max(MIN_LOBE_DEG, 2.0 * math.degrees(math.atan(alpha)))
    pts = {"tr": tr, "pr": pr, "above": above, "meas": meas, "pred": pred, "off": off}
    region_table, tis_se = _regions(runs, pts, geo, lobe)
    return BrdfPrediction(
        path=path,
        wavelength_nm=float(wl),
        n=n0,
        k=k0,
        n_sigma=float(nk["n_sigma"][0]),
        k_sigma=float(nk["k_sigma"][0]),
        alpha=alpha,
        alpha_u=alpha_u,
        theta_i_deg=ti,
        azimuth_deg=az,
        radial_deg=rad,
        symmetry=t.symmetry,
        theta_r_deg=np.where(above, tr, np.nan),
        phi_r_deg=pr,
        above=above,
        radial_off_deg=off,
        measured=meas,
        predicted=pred,
        predicted_stderr=se,
        tis_measured=gm["integral"][0, 0],
        tis_predicted=gp["integral"][0, 0],
        tis_predicted_stderr=tis_se,
        tis_file=np.asarray(t.tis, float)[0, 0],
        albedo=np.array([r.albedo() for r in runs]),
        albedo_stderr=np.array([r.albedo_stderr() for r in runs]),
        uncovered_fraction=gm["uncovered_fraction"],
        lobe_deg=lobe,
        rays=int(rays),
        seconds=float(sum(r.seconds for r in runs)),
        coating=None if coating is None else coating.to_dict(),
        slopes="ggx" if ndf is None else "measured",
        index_from=index_from,
        region_table=region_table,
        results=runs,
    )
