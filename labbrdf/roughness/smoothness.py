"""Roughness against wavelength: the Rayleigh criterion and the Davies/Bennett-Porteus loss.

Pure NumPy functions linking a surface's RMS height sigma to what light of wavelength
lambda at incidence theta_i sees (derivation and caveats: ``docs/smoothness.md``):

* the Rayleigh parameter ``g = (4 pi sigma cos theta_i / lambda)^2`` (Davies 1954): the
  variance of the phase difference [rad^2] between rays reflected at heights a distance
  sigma apart;
* the Rayleigh criterion: smooth when ``sigma < lambda / (8 cos theta_i)`` (a phase spread
  below pi/2, as Ulaby, Moore & Fung 1982 state it, the form Zou et al. 2013 sec. 3 use)
  and its stricter Fraunhofer form ``sigma < lambda / (32 cos theta_i)`` (pi/8);
* the specular loss ``R_s / R_0 = exp(-g)`` of a surface with Gaussian heights (Davies
  1954) and the total integrated scatter ``TIS = R_0 (1 - exp(-g)) ~ R_0 g`` (Bennett &
  Porteus 1961), ``R_0`` the reflectance of the same material perfectly smooth;
* the shortest spatial period of roughness that scatters light into propagating
  directions, ``lambda / (1 + sin theta_i)`` (grating equation): sigma must be that of the
  roughness between this period and the longest one the instrument separates from the
  specular beam; a height map's sigma covers only its own band (pixel or S-filter cut-off
  to map size), and :func:`band_coverage` says how the two bands overlap.

Lengths: ``sigma`` and ``wavelength`` in one unit (both nm, or both m); angles in radians.

References
----------
H. Davies, "The reflection of electromagnetic waves from a rough surface", Proc. IEE 101
(1954) 209-214.
H. E. Bennett, J. O. Porteus, "Relation between surface roughness and specular
reflectance at normal incidence", J. Opt. Soc. Am. 51 (1961) 123-129.
F. T. Ulaby, R. K. Moore, A. K. Fung, Microwave Remote Sensing vol. II (1982), sec. 12-2.
X. Zou, L. Bai, Z. Wu, "Mirror reflectance spectrum modeling of smooth samples", Acta
Optica Sinica 33 (2013) 0612008, sec. 3 (the criterion, their ref. 21 being Ulaby et al.).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "CRITERIA",
    "COVERAGE_FACTOR",
    "band_coverage",
    "rayleigh_parameter",
    "rayleigh_parameter_uncertainty",
    "shortest_scattering_period",
    "smooth_threshold",
    "specular_loss",
    "total_integrated_scatter",
    "verdict",
]

#: phase-spread denominators: smooth when sigma < lambda / (D cos theta_i)
CRITERIA: dict[str, float] = {"rayleigh": 8.0, "fraunhofer": 32.0}

#: coverage factor of the interval sigma +- k u(sigma) a verdict is decided on (about 95 %)
COVERAGE_FACTOR = 2.0

Criterion = Literal["rayleigh", "fraunhofer"]


def _cos(theta_i: ArrayLike) -> NDArray[np.float64]:
    t = np.asarray(theta_i, dtype=float)
    if np.any(~np.isfinite(t)) or np.any(np.abs(t) >= math.pi / 2):
        raise ValueError(f"theta_i must be finite and within (-pi/2, pi/2) [rad], got {theta_i!r}")
    return np.cos(t)


def _positive(x: ArrayLike, name: str, zero_ok: bool = False) -> NDArray[np.float64]:
    a = np.asarray(x, dtype=float)
    bad = ~np.isfinite(a) | ((a < 0) if zero_ok else (a <= 0))
    if np.any(bad):
        what = ">= 0" if zero_ok else "> 0"
        raise ValueError(f"{name} must be finite and {what}, got {x!r}")
    return a


def rayleigh_parameter(
    sigma: ArrayLike, wavelength: ArrayLike, theta_i: ArrayLike = 0.0
) -> NDArray[np.float64]:
    """The Rayleigh parameter ``g = (4 pi sigma cos theta_i / lambda)^2`` [1].

    Parameters
    ----------
    sigma : array_like
        RMS height [length, same unit as ``wavelength``], >= 0.
    wavelength : array_like
        Vacuum wavelength of the light [length] (in a non-vacuum ambient, the wavelength
        in it), > 0.
    theta_i : array_like
        Angle of incidence [rad], |theta_i| < pi/2.

    Returns
    -------
    ndarray
        ``g`` [rad^2], broadcast over the inputs: the variance of the reflected phase,
        ``(2 k sigma cos theta_i)^2`` with ``k = 2 pi / lambda`` (Davies 1954).
    """
    s = _positive(sigma, "sigma", zero_ok=True)
    lam = _positive(wavelength, "wavelength")
    return np.asarray((4.0 * math.pi * s * _cos(theta_i) / lam) ** 2, dtype=float)


def rayleigh_parameter_uncertainty(
    sigma: ArrayLike, u_sigma: ArrayLike, wavelength: ArrayLike, theta_i: ArrayLike = 0.0
) -> NDArray[np.float64]:
    """Standard uncertainty of ``g`` from that of sigma: ``u(g) = 2 g u(sigma) / sigma``.

    First-order propagation (``g`` is proportional to sigma^2); the wavelength and angle
    are taken as exact. [rad^2]
    """
    s = _positive(sigma, "sigma", zero_ok=True)
    u = _positive(u_sigma, "u_sigma", zero_ok=True)
    lam = _positive(wavelength, "wavelength")
    k = 4.0 * math.pi * _cos(theta_i) / lam
    return np.asarray(2.0 * k * k * s * u, dtype=float)


def smooth_threshold(
    wavelength: ArrayLike, theta_i: ArrayLike = 0.0, criterion: Criterion = "rayleigh"
) -> NDArray[np.float64]:
    """Largest RMS height that still counts as smooth: ``lambda / (D cos theta_i)``.

    Parameters
    ----------
    wavelength : array_like
        [length], > 0.
    theta_i : array_like
        [rad].
    criterion : {"rayleigh", "fraunhofer"}
        ``D = 8`` (Rayleigh, phase spread below pi/2; Ulaby, Moore & Fung 1982 as Zou et
        al. 2013 sec. 3 use it) or ``D = 32`` (Fraunhofer, below pi/8).

    Returns
    -------
    ndarray
        The threshold [length]. At it, ``g = (pi / 2)^2 = 2.47`` (Rayleigh) or
        ``(pi / 8)^2 = 0.154`` (Fraunhofer).
    """
    if criterion not in CRITERIA:
        raise ValueError(f"criterion {criterion!r} unknown; use one of {sorted(CRITERIA)}")
    lam = _positive(wavelength, "wavelength")
    return np.asarray(lam / (CRITERIA[criterion] * _cos(theta_i)), dtype=float)


def verdict(
    sigma: ArrayLike,
    u_sigma: ArrayLike,
    wavelength: ArrayLike,
    theta_i: ArrayLike = 0.0,
    criterion: Criterion = "rayleigh",
    k: float = COVERAGE_FACTOR,
) -> NDArray[np.str_]:
    """Smooth, rough or undecided, with sigma's uncertainty.

    The interval ``[sigma - k u, sigma + k u]`` is compared with
    :func:`smooth_threshold`: wholly below it, ``"smooth"``; wholly at or above it,
    ``"rough"``; straddling it, ``"undecided"``.

    Parameters
    ----------
    sigma, u_sigma : array_like
        RMS height and its standard uncertainty [length] (``u_sigma`` NaN: taken as 0,
        i.e. the verdict of the value alone).
    wavelength, theta_i, criterion :
        As for :func:`smooth_threshold`.
    k : float
        Coverage factor (default 2, about 95 % for a normal distribution).

    Returns
    -------
    ndarray of str
    """
    s = _positive(sigma, "sigma", zero_ok=True)
    u = np.asarray(u_sigma, dtype=float)
    if np.any(u < 0) or np.any(np.isinf(u)):
        raise ValueError(f"u_sigma must be finite and >= 0 (or NaN), got {u_sigma!r}")
    if not (math.isfinite(k) and k >= 0):
        raise ValueError(f"k must be finite and >= 0, got {k!r}")
    u = np.where(np.isnan(u), 0.0, u)
    thr = smooth_threshold(wavelength, theta_i, criterion)
    lo, hi = s - k * u, s + k * u
    out = np.where(hi < thr, "smooth", np.where(lo >= thr, "rough", "undecided"))
    return np.asarray(out, dtype=str)


def specular_loss(g: ArrayLike) -> NDArray[np.float64]:
    """Specular reflectance relative to the smooth surface's, ``R_s / R_0 = exp(-g)`` [1].

    Davies (1954) for Gaussian heights, in the Kirchhoff (tangent-plane)
    approximation: valid for correlation lengths much longer than the wavelength.
    """
    return np.asarray(np.exp(-_positive(g, "g", zero_ok=True)), dtype=float)


def total_integrated_scatter(
    r0: ArrayLike, g: ArrayLike, *, small_roughness: bool = False
) -> NDArray[np.float64]:
    """Total integrated scatter ``TIS = R_0 (1 - exp(-g))``, or ``R_0 g`` [1].

    Parameters
    ----------
    r0 : array_like
        Reflectance of the perfectly smooth surface (Fresnel) [1].
    g : array_like
        Rayleigh parameter (:func:`rayleigh_parameter`) [1].
    small_roughness : bool
        Return the first-order form ``R_0 g`` (Bennett & Porteus 1961, at normal
        incidence ``R_0 (4 pi sigma / lambda)^2``), valid for ``g << 1``.

    Notes
    -----
    The scattered power is what the specular beam loses (Davies' exp(-g)); Bennett and
    Porteus measure it over the hemisphere outside a small cone about the specular
    direction, so sigma must be that of the roughness whose spatial periods scatter
    outside that cone and into propagating directions (see
    :func:`shortest_scattering_period`).
    """
    r = _positive(r0, "r0", zero_ok=True)
    gg = _positive(g, "g", zero_ok=True)
    if small_roughness:
        return np.asarray(r * gg, dtype=float)
    return np.asarray(-r * np.expm1(-gg), dtype=float)


def shortest_scattering_period(
    wavelength: ArrayLike, theta_i: ArrayLike = 0.0
) -> NDArray[np.float64]:
    """Shortest spatial period of roughness that scatters into the ambient [length].

    A sinusoidal height component of period ``d`` diffracts the incident plane wave into
    ``sin theta_s = sin theta_i - m lambda / d`` (grating equation, first order ``m = 1``
    towards the source); the order propagates while ``|sin theta_s| <= 1``, i.e. for
    ``d >= lambda / (1 + sin theta_i)``. Finer roughness scatters no light (it acts as a
    graded layer on the specular reflectance instead).
    """
    lam = _positive(wavelength, "wavelength")
    t = np.asarray(theta_i, dtype=float)
    _cos(t)
    return np.asarray(lam / (1.0 + np.sin(np.abs(t))), dtype=float)


def band_coverage(
    shortest: ArrayLike, map_short: float, map_long: float
) -> tuple[NDArray[np.str_], NDArray[np.float64]]:
    """How a height map's band covers the roughness that scatters at one geometry.

    Parameters
    ----------
    shortest : array_like
        :func:`shortest_scattering_period` at each (wavelength, angle) [length].
    map_short, map_long : float
        The map's band: shortest period it resolves (2 pixels, or the S-filter cut-off)
        and longest (the map size) [length].

    Returns
    -------
    coverage : ndarray of str
        ``"none"``: the map is shorter than the shortest scattering period, so it holds
        none of the roughness that scatters (its sigma is roughness too fine to scatter);
        ``"misses short periods"``: the map does not resolve periods between ``shortest``
        and ``map_short``, so its sigma misses them (a lower bound for scatter);
        ``"band-limited"``: the map resolves finer roughness than scatters, and sigma is
        to be taken from the band ``[shortest, map_long]`` only (S-filter at
        ``shortest``).
    lower : ndarray
        The lower end of the band the comparison covers [length]: ``max(shortest,
        map_short)`` (NaN for ``"none"``); the upper end is ``map_long``.
    """
    d = _positive(shortest, "shortest")
    a = float(_positive(map_short, "map_short"))
    b = float(_positive(map_long, "map_long"))
    if not a < b:
        raise ValueError(f"map_short {map_short!r} must be below map_long {map_long!r}")
    cov = np.where(d >= b, "none", np.where(d < a, "misses short periods", "band-limited"))
    lower = np.where(d >= b, np.nan, np.maximum(d, a))
    return np.asarray(cov, dtype=str), np.asarray(lower, dtype=float)
