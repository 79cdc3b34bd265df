"""Predict, then measure, for a smooth sample: Rayleigh-Rice from a height map's PSD.

The smooth-surface counterpart of :mod:`labbrdf.prediction` (the microfacet tracer's). A
sample that is smooth by the Rayleigh criterion (:mod:`labbrdf.roughness.smoothness`) scatters as
first-order perturbation theory says (:mod:`labbrdf.roughness.rayleigh_rice`): its BRDF at
every point of a measured ``.bsdf`` follows, with **no fitted parameter**, from

* the isotropic 2-D PSD of its height maps (:func:`group_psd`: the composite that
  :func:`labbrdf.psd` and the report's PSD section compute, SurfaceTopography's periodogram
  of each plane-levelled map with a Hann window, joined over the union of the maps' bands;
  the PSD is taken as 0 outside the band, from ``1 / size`` of the largest map to the
  Nyquist frequency ``1 / (2 pixel)`` of the finest, and in any gap between maps, and the
  points whose Bragg frequency lies there are counted, not guessed);
* the substrate's n, k from the sample's psi/Delta (:func:`labbrdf.prediction.substrate_nk`),
  or, for a coated sample, the film fit's stack, whose interfaces all carry the map's
  roughness (correlated: a conformal coating, :mod:`labbrdf.roughness.rr_stack`).

Prediction and measurement are integrated by the same grid rule
(:func:`labbrdf.integrate.grid_integral`), so their TIS compare like with like.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from .adapters import zemax_bsdf
from .adapters.topography import HeightMap
from .bsdf_geometry import scatter_to_angles
from .errors import LabbrdfError
from .films.stack import Stack
from .integrate import grid_integral
from .prediction import PredictionError, _checked_table, substrate_nk
from .roughness.psd import Spectrum
from .roughness.rayleigh_rice import bragg_frequencies, brdf
from .roughness.rr_stack import stack_brdf, stack_layers

__all__ = [
    "MapPsd",
    "PsdAgreement",
    "RrPrediction",
    "bragg_band",
    "group_psd",
    "map_psd",
    "predict_rr_brdf",
    "psd_agreement",
]


@dataclass(frozen=True)
class MapPsd:
    """The isotropic 2-D PSD of a sample's height maps (one map, or their composite).

    Attributes
    ----------
    f : ndarray
        Spatial frequencies [cycles/m], increasing, all within the band.
    psd : ndarray
        Azimuthally averaged 2-D PSD [m^4] (``sigma^2 = integral PSD 2 pi f df``).
    f_min, f_max : float
        The band [cycles/m]: ``1 / size`` of the largest map to ``1 / (2 pixel)`` of the
        finest.
    source : str
        The height maps' files (comma separated).
    gaps : tuple of (float, float)
        Frequency ranges [cycles/m] inside the band that no map covers (PSD 0 there).
    spectrum : Spectrum, optional
        The :func:`labbrdf.psd` composite it was made from (its band sigma is used).
    notes : tuple of str
        The composite's members and overlaps (:func:`labbrdf.roughness.psd.composite`).
    """

    f: NDArray[np.float64]
    psd: NDArray[np.float64]
    f_min: float
    f_max: float
    source: str
    gaps: tuple[tuple[float, float], ...] = ()
    spectrum: Spectrum | None = field(default=None, repr=False)
    notes: tuple[str, ...] = ()

    def sigma(self, f_lo: float | None = None, f_hi: float | None = None) -> float:
        """RMS height [m] of the PSD over ``[f_lo, f_hi]`` (default the band).

        The composite's :meth:`~labbrdf.roughness.psd.Spectrum.band_sigma` (a single map's
        unbinned periodogram; bins by the trapezoid rule for several, gaps left out), the
        number the PSD section states; else the trapezoid rule over the bins.
        """
        lo = self.f_min if f_lo is None else max(f_lo, self.f_min)
        hi = self.f_max if f_hi is None else min(f_hi, self.f_max)
        if not lo < hi:
            return 0.0
        if self.spectrum is not None:
            return self.spectrum.band_sigma(lo, hi)
        f = np.concatenate([[lo], self.f[(self.f > lo) & (self.f < hi)], [hi]])
        y = self._interp(f) * 2.0 * math.pi * f
        return float(math.sqrt(max(np.trapezoid(y, f), 0.0)))

    def covers(self, f: ArrayLike) -> NDArray[np.bool_]:
        """Whether a map resolves each frequency [cycles/m]: in the band, in no gap."""
        f = np.asarray(f, float)
        inside = (f >= self.f_min) & (f <= self.f_max)
        for lo, hi in self.gaps:
            inside &= ~((f > lo) & (f < hi))
        return np.asarray(inside)

    def _interp(self, f: NDArray) -> NDArray[np.float64]:
        """Log-log interpolation inside the band (end values held to its edges), 0 outside."""
        f = np.asarray(f, float)
        lf = np.log(np.clip(f, self.f[0], self.f[-1]))
        v = np.exp(np.interp(lf, np.log(self.f), np.log(self.psd)))
        return np.where(self.covers(f), v, 0.0)

    def psd2d(self, fx: NDArray, fy: NDArray) -> NDArray[np.float64]:
        """``PSD2(fx, fy)`` [m^4] of the isotropic PSD, 0 outside the map's band."""
        return self._interp(np.hypot(fx, fy))


def group_psd(maps: Sequence[HeightMap]) -> MapPsd:
    """The composite isotropic PSD of one sample's areal height maps (module docstring).

    The same spectrum as ``labbrdf psd MAP...`` and the report's PSD section
    (:func:`labbrdf.roughness.psd_result.psd`, 2-D, its default levelling, window and bins).

    Raises
    ------
    PredictionError
        No map, a profile, a map with undefined points (the area PSD needs them all), or
        no positive PSD value.
    """
    from .roughness.psd_result import psd

    if not maps:
        raise PredictionError("no height map for the PSD")
    for hm in maps:
        z = np.asarray(hm.heights, float)
        if z.ndim != 2:
            raise PredictionError(f"{hm.path}: a profile; the PSD prediction needs an areal map")
        if not np.isfinite(z).all():
            raise PredictionError(
                f"{hm.path}: {int((~np.isfinite(z)).sum())} undefined points; the area PSD "
                "needs a complete map"
            )
    try:
        res = psd(list(maps), kind="2d")
    except (LabbrdfError, ValueError) as exc:
        raise PredictionError(str(exc)) from None
    comp = res.composite
    ok = np.isfinite(comp.f) & np.isfinite(comp.psd) & (comp.psd > 0) & (comp.f > 0)
    if not ok.any():
        raise PredictionError(f"{', '.join(str(hm.path) for hm in maps)}: no positive PSD value")
    return MapPsd(
        f=comp.f[ok],
        psd=comp.psd[ok],
        f_min=float(comp.band[0]),
        f_max=float(comp.band[1]),
        source=", ".join(str(hm.path) for hm in maps),
        gaps=_gaps([s.band for s in res.spectra]),
        spectrum=comp,
        notes=tuple(comp.notes),
    )


def _gaps(bands: Sequence[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    """The ranges inside the union of the bands that no band covers."""
    out, reach = [], 0.0
    for lo, hi in sorted(bands):
        if reach and lo > reach:
            out.append((reach, lo))
        reach = max(reach, hi)
    return tuple(out)


def map_psd(hm: HeightMap) -> MapPsd:
    """The isotropic PSD of one areal height map: :func:`group_psd` of ``[hm]``."""
    return group_psd([hm])


@dataclass
class RrPrediction:
    """The Rayleigh-Rice prediction of a measured ``.bsdf`` (no fitted parameter).

    Arrays are ``(aoi, azimuth, radial)`` on the file's grid; angles [deg]; BRDF [sr^-1].
    """

    path: str
    wavelength_nm: float
    n: float
    k: float
    psd: MapPsd
    theta_i_deg: NDArray[np.float64]
    theta_r_deg: NDArray[np.float64]
    phi_r_deg: NDArray[np.float64]
    above: NDArray[np.bool_]
    in_band: NDArray[np.bool_]
    measured: NDArray[np.float64]
    predicted: NDArray[np.float64]
    tis_measured: NDArray[np.float64]
    tis_predicted: NDArray[np.float64]
    band_measured: NDArray[np.float64]
    band_predicted: NDArray[np.float64]
    #: the film stack's layers (``name d nm, n + ik``, top first) of a coated sample, or ""
    coating: str = ""

    def table(self) -> pd.DataFrame:
        """Per incidence: both grid TIS, their ratio, how many points the map's band sees."""
        rows = []
        for a, ti in enumerate(self.theta_i_deg):
            m = self.above[a] & (self.measured[a] > 0)
            rows.append(
                {
                    "theta_i_deg": float(ti),
                    "tis_measured": float(self.tis_measured[a]),
                    "tis_predicted": float(self.tis_predicted[a]),
                    "ratio": float(self.tis_predicted[a] / self.tis_measured[a])
                    if self.tis_measured[a] > 0
                    else math.nan,
                    "points": int(m.sum()),
                    "in_band": int((m & self.in_band[a]).sum()),
                    "band_ratio": float(self.band_predicted[a] / self.band_measured[a])
                    if self.band_measured[a] > 0
                    else math.nan,
                }
            )
        return pd.DataFrame(rows)

    def verdict(self) -> str:
        """A sentence: how far the prediction is from the measurement, per incidence."""
        parts = []
        for r in self.table().to_dict("records"):
            if r["in_band"] == 0:
                parts.append(
                    f"at {r['theta_i_deg']:g} deg no measured point scatters from the map's "
                    "band: nothing to compare"
                )
                continue
            parts.append(
                f"at {r['theta_i_deg']:g} deg the predicted TIS on the file's grid is "
                f"{r['ratio']:.3g} x the measured one; over the {r['in_band']} of the "
                f"{r['points']} measured points that scatter from spatial frequencies in the "
                f"map's band, {r['band_ratio']:.3g} x"
            )
        return "Rayleigh-Rice from the height map's PSD: " + "; ".join(parts) + "."


def predict_rr_brdf(
    bsdf: str | os.PathLike[str] | zemax_bsdf.BsdfTable,
    data: pd.DataFrame | None,
    psd: MapPsd,
    *,
    wavelength_nm: float | None = None,
    substrate_index: complex | None = None,
    stack: Stack | None = None,
    stack_range: tuple[float, float] | None = None,
) -> RrPrediction:
    """The Rayleigh-Rice BRDF (unpolarized) at every point of a measured ``.bsdf``.

    Parameters
    ----------
    bsdf : path-like or BsdfTable
        The measured BRDF (one rotation, Monochrome, BRDF).
    data : pandas.DataFrame or None
        psi/Delta rows of the same sample (:func:`labbrdf.prediction.substrate_nk`); not
        used when ``substrate_index`` is given.
    psd : MapPsd
        The sample's PSD (:func:`map_psd`).
    wavelength_nm : float, optional
        Default: the one the file states.
    substrate_index : complex, optional
        ``n + ik`` instead of the psi/Delta's.
    stack : labbrdf.films.Stack, optional
        A coated sample's film stack (a film fit's): its layers and substrate replace the
        psi/Delta's n, k, and every interface carries the map's roughness, correlated (a
        conformal coating: :func:`labbrdf.roughness.rr_stack.stack_brdf`).
    stack_range : (float, float), optional
        The wavelengths [nm] the film fit was made over; a ``.bsdf`` outside them is
        refused (a dispersion model is not extrapolated beyond the data that fixed it).

    Raises
    ------
    PredictionError
        As :func:`labbrdf.prediction.predict_brdf` (no wavelength, no n, k there, a file
        with several rotations or channels).
    """
    t, path, wl = _checked_table(bsdf, wavelength_nm)
    if stack is not None and stack_range is not None:
        lo, hi = stack_range
        if not lo <= wl <= hi:
            raise PredictionError(
                f"{path}: {wl:g} nm lies outside the film fit's wavelengths {lo:g}-{hi:g} nm; "
                "expected a film fit that covers the BRDF's wavelength"
            )
    layers, coating = _layers(stack, wl, path)
    if layers is not None:
        index = complex(layers[0][-1])
    elif substrate_index is None:
        if data is None:
            raise PredictionError(f"{path}: give the psi/Delta rows or the substrate index")
        nk: dict[str, Any] = substrate_nk(data, [wl])
        index = complex(float(nk["n"][0]), float(nk["k"][0]))
    else:
        index = complex(substrate_index)
    ti = np.asarray(t.theta_i_deg, float)
    az, rad = np.asarray(t.azimuth_deg, float), np.asarray(t.radial_deg, float)
    tr, pr, above = scatter_to_angles(ti[:, None, None], rad[None, None, :], az[None, :, None])
    tib = np.broadcast_to(ti[:, None, None], tr.shape)
    trs = np.where(above, tr, 0.0)
    lam = wl * 1e-9
    args = (np.radians(tib), np.radians(trs), np.radians(pr))
    fx, fy = bragg_frequencies(*args, lam)
    fr = np.hypot(fx, fy)
    in_band = above & psd.covers(fr)
    if layers is None:
        f = brdf(*args, lam, index, psd.psd2d)
    else:
        f = stack_brdf(*args, lam, *layers, psd.psd2d, "correlated")
    pred = np.where(above, f, 0.0)
    meas = np.where(above, t.values[0, 0], 0.0)
    geo: dict[str, Any] = {"theta_i_deg": ti, "azimuth_deg": az, "radial_deg": rad}
    geo["symmetry"] = t.symmetry
    return RrPrediction(
        path=path,
        wavelength_nm=float(wl),
        n=index.real,
        k=index.imag,
        psd=psd,
        theta_i_deg=ti,
        theta_r_deg=np.where(above, tr, np.nan),
        phi_r_deg=pr,
        above=above,
        in_band=in_band,
        measured=meas,
        predicted=pred,
        tis_measured=_tis(meas, geo),
        tis_predicted=_tis(pred, geo),
        band_measured=_tis(np.where(in_band, meas, 0.0), geo),
        band_predicted=_tis(np.where(in_band, pred, 0.0), geo),
        coating=coating,
    )


def _layers(
    stack: Stack | None, wavelength_nm: float, path: str
) -> tuple[tuple[NDArray, NDArray] | None, str]:
    """The stack's indices and thicknesses [m] at the wavelength, and the layers in words."""
    if stack is None:
        return None, ""
    try:
        n, d = stack_layers(stack, wavelength_nm)
    except (ValueError, LabbrdfError) as exc:
        raise PredictionError(f"{path}: the film stack: {exc}") from None
    words = [
        f"{lay.name} {dd * 1e9:.4g} nm, {nn.real:.4g} + {nn.imag:.3g}i"
        for lay, nn, dd in zip(stack.layers, n[1:-1], d, strict=True)
    ]
    return (n, d), "; ".join(words)


def _tis(values: NDArray, geo: dict[str, Any]) -> NDArray[np.float64]:
    """Grid integral of ``(aoi, azimuth, radial)`` values per incidence [1]."""
    return np.asarray(grid_integral(values[None, None], **geo)["integral"][0, 0], dtype=float)


@dataclass(frozen=True)
class PsdAgreement:
    """A PSD recovered from a BRDF (a ``rayleigh_rice`` fit) beside a height map's PSD.

    Attributes
    ----------
    f : ndarray
        The map's frequencies [cycles/m] inside the common band.
    psd_map, psd_brdf : ndarray
        The map's PSD and the fitted model's at ``f`` [m^4].
    f_lo, f_hi : float
        The common band [cycles/m]: the map's band intersected with the frequencies the
        fitted BRDF points see.
    form : str
        The fitted PSD form.
    source : str
        The height maps' files (comma separated).
    """

    f: NDArray[np.float64]
    psd_map: NDArray[np.float64]
    psd_brdf: NDArray[np.float64]
    f_lo: float
    f_hi: float
    form: str
    source: str

    def ratio_quantiles(self) -> tuple[float, float, float]:
        """10 %, 50 % and 90 % quantiles of PSD(BRDF) / PSD(map) over the common band."""
        if self.f.size == 0:
            return (math.nan, math.nan, math.nan)
        r = self.psd_brdf / self.psd_map
        lo, med, hi = np.quantile(r, [0.1, 0.5, 0.9])
        return float(lo), float(med), float(hi)

    def sentence(self) -> str:
        """How the two PSDs agree, in numbers."""
        if not self.f_lo < self.f_hi:
            return (
                "The height map's band and the spatial frequencies the BRDF sees do not "
                "overlap: the two PSDs cannot be compared."
            )
        if self.f.size == 0:
            return (
                "No frequency bin of the height map's PSD lies among the spatial "
                f"frequencies the BRDF sees ({self.f_lo:.3g} to {self.f_hi:.3g} cycles/m "
                "within the map's band): the two PSDs cannot be compared."
            )
        lo, med, hi = self.ratio_quantiles()
        return (
            f"Over their common frequencies, {self.f_lo:.3g} to {self.f_hi:.3g} cycles/m "
            f"({self.f.size} of the map's frequency bins), the PSD recovered from the BRDF "
            f"({self.form}) is {med:.3g} times the height map's (median; 10 to 90 % of the "
            f"bins: {lo:.3g} to {hi:.3g})."
        )

    def plot(self, ax: Any = None) -> Any:
        """Both PSDs on log-log axes over the common band; returns the matplotlib Figure."""
        from matplotlib.figure import Figure

        fig = Figure(figsize=(5.5, 3.8)) if ax is None else ax.figure
        ax = fig.add_subplot(1, 1, 1) if ax is None else ax
        names = ", ".join(Path(x.strip()).name for x in self.source.split(","))
        ax.loglog(self.f, self.psd_map, "o", ms=3, label=f"height maps ({names})")
        ax.loglog(self.f, self.psd_brdf, "-", label=f"from the BRDF ({self.form} fit)")
        ax.set_xlabel("spatial frequency f [cycles/m]")
        ax.set_ylabel("isotropic 2-D PSD [m$^4$]")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
        fig.tight_layout()
        return fig


def bragg_band(
    theta_i_deg: ArrayLike, theta_r_deg: ArrayLike, phi_r_deg: ArrayLike, wavelength_nm: float
) -> tuple[float, float]:
    """Smallest and largest |f| [cycles/m] that measured directions see (Bragg)."""
    fx, fy = bragg_frequencies(
        np.radians(np.asarray(theta_i_deg, float)),
        np.radians(np.asarray(theta_r_deg, float)),
        np.radians(np.asarray(phi_r_deg, float)),
        wavelength_nm * 1e-9,
    )
    fr = np.hypot(fx, fy)
    fr = fr[fr > 0]
    if fr.size == 0:
        raise PredictionError("no measured direction off the specular one")
    return float(fr.min()), float(fr.max())


def psd_agreement(psd2d: Any, form: str, psd: MapPsd, band: tuple[float, float]) -> PsdAgreement:
    """Compare a fitted PSD (``psd2d(fx, fy)`` [m^4]) with a map's over their common band.

    ``band`` is what the BRDF sees (:func:`bragg_band`); the common band is its
    intersection with the map's ``[f_min, f_max]``.
    """
    lo, hi = max(band[0], psd.f_min), min(band[1], psd.f_max)
    sel = (psd.f >= lo) & (psd.f <= hi)
    f = psd.f[sel]
    fit = np.asarray(psd2d(f, np.zeros_like(f)), dtype=float)
    return PsdAgreement(f, psd.psd[sel], fit, lo, hi, form, psd.source)
