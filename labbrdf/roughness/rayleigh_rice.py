"""Rayleigh-Rice scatter: the Mueller BRDF of a smooth rough surface from its PSD.

First-order vector perturbation theory (Rice 1951; Elson & Bennett 1979; Church, Jenkinson
& Zavada 1979) for a single interface between a lossless ambient (index 1) and a
substrate of complex index ``N = n + ik`` (conductor or dielectric). Physics layer: NumPy
only. Derivation, conventions and the checks: ``docs/rayleigh-rice.md``.

The BRDF of each polarization channel is (Stover, *Optical Scattering*, 3rd ed., eq. 5.13)

    f_ab = (16 pi^2 / lambda^4) cos(theta_i) cos(theta_s) Q_ab PSD2(fx, fy)   [sr^-1]

with ``Q_ab = |q_ab|^2`` and the spatial frequencies of the grating equation (Bragg)

    fx = (sin theta_s cos phi_s - sin theta_i) / lambda,   fy = sin theta_s sin phi_s / lambda.

The complex amplitude factors ``q_ab`` (a: incident, b: scattered polarization) are those of
Germer, Appl. Opt. 36, 8798 (1997), eqs. (4)-(7), with ``eps = N^2``,
``g(t) = sqrt(eps - sin^2 t)``::

    q_ss = (eps - 1) cos phi_s / [(cos ti + g(ti)) (cos ts + g(ts))]
    q_pp = (eps - 1) [eps sin ti sin ts - g(ti) g(ts) cos phi_s]
           / [(eps cos ti + g(ti)) (eps cos ts + g(ts))]
    q_ps = -(eps - 1) g(ti) sin phi_s / [(eps cos ti + g(ti)) (cos ts + g(ts))]   (p -> s)
    q_sp = -(eps - 1) g(ts) sin phi_s / [(cos ti + g(ti)) (eps cos ts + g(ts))]   (s -> p)

so the scattering Jones matrix acting on ``(Es, Ep)`` is
``sqrt(16 pi^2 cos ti cos ts PSD2 / lambda^4) [[q_ss, q_ps], [q_sp, q_pp]]`` and the Mueller
BRDF follows from it. At the specular direction ``q_ss = -r_s`` and ``q_pp = -r_p`` (the
Fresnel amplitudes of :mod:`labbrdf.optics`, a common sign that no Mueller element sees),
so ``Q_ss = R_s`` and ``Q_pp = R_p``.

Conventions
-----------
The ones of :mod:`labbrdf.optics` ("LB", the same as NIST SCATMECH's ``psps`` output):
source at azimuth 0, the detector at ``(theta_r, phi_r)`` with ``phi_r = pi`` the specular
half-plane, Stokes frames ``s = (-sin phi, cos phi, 0)``, ``p = k x s``, ``S1 = +1`` for s,
``exp(-i omega t)``, ``N = n + ik``. The papers' (and SCATMECH's) scatter azimuth is
``phi_s = phi_r - pi`` (0 forward). Lengths in metres, spatial frequencies in cycles/m, the
isotropic 2-D PSD in m^4 normalised so that ``sigma^2 = integral of PSD2 dfx dfy``.

References
----------
.. [1] S. O. Rice, "Reflection of electromagnetic waves from slightly rough surfaces",
   Commun. Pure Appl. Math. 4, 351-378 (1951).
.. [2] J. M. Elson, J. M. Bennett, "Vector scattering theory", Opt. Eng. 18, 116-124 (1979).
.. [3] E. L. Church, H. A. Jenkinson, J. M. Zavada, "Relationship between surface
   scattering and microtopographic features", Opt. Eng. 18, 125-136 (1979).
.. [4] T. A. Germer, "Angular dependence and polarization of out-of-plane optical scattering
   from particulate contamination, subsurface defects, and surface microroughness",
   Appl. Opt. 36, 8798-8805 (1997). doi:10.1364/AO.36.008798
.. [5] J. C. Stover, *Optical Scattering: Measurement and Analysis*, 3rd ed., SPIE (2012),
   chapter 5 (eqs. 5.13-5.17: the Rayleigh-Rice BRDF and its TIS).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "POLARIZATIONS",
    "PsdFunction",
    "bragg_frequencies",
    "brdf",
    "jones_factors",
    "mueller_brdf",
    "specular_loss",
    "tis",
    "tis_small_roughness",
]

#: a 2-D PSD: ``psd2d(fx, fy)`` [m^4] of spatial frequencies [cycles/m], broadcasting
PsdFunction = Callable[[NDArray[np.float64], NDArray[np.float64]], ArrayLike]

#: incident polarizations of :func:`brdf`: unpolarized, s, p
POLARIZATIONS = ("unpolarized", "s", "p")

Polarization = Literal["unpolarized", "s", "p"]

# coherency vector (Es Es*, Es Ep*, Ep Es*, Ep Ep*) -> Stokes (S0, S1, S2, S3), LB convention
_A = np.array([[1, 0, 0, 1], [1, 0, 0, -1], [0, 1, 1, 0], [0, 1j, -1j, 0]], dtype=complex)
_A_INV = np.linalg.inv(_A)


def _index(index: ArrayLike) -> NDArray[np.complex128]:
    n = np.asarray(index, dtype=complex)
    if np.any(~np.isfinite(n)) or np.any(n.real < 0) or np.any(n.imag < 0) or np.any(n == 0):
        raise ValueError(f"index must be finite n + ik with n >= 0, k >= 0, N != 0; got {index!r}")
    return n


def _angles(
    theta_i: ArrayLike, theta_r: ArrayLike, phi_r: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    ti, tr, pr = np.broadcast_arrays(
        np.asarray(theta_i, float), np.asarray(theta_r, float), np.asarray(phi_r, float)
    )
    for name, t in (("theta_i", ti), ("theta_r", tr)):
        if np.any(~np.isfinite(t)) or np.any((t < 0) | (t > math.pi / 2)):
            raise ValueError(f"{name} must be within [0, pi/2] [rad], got {t!r}")
    if np.any(~np.isfinite(pr)):
        raise ValueError(f"phi_r must be finite [rad], got {phi_r!r}")
    return ti, tr, pr


def _wavelength(wavelength: float) -> float:
    lam = float(wavelength)
    if not (math.isfinite(lam) and lam > 0):
        raise ValueError(f"wavelength must be finite and > 0 [m], got {wavelength!r}")
    return lam


def _root(w: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """``sqrt(w)`` with ``Im >= 0`` (a decaying or outgoing wave in the substrate)."""
    r = np.sqrt(w.astype(complex))
    return np.where((r.imag < 0) | ((r.imag == 0) & (r.real < 0)), -r, r)


def bragg_frequencies(
    theta_i: ArrayLike, theta_r: ArrayLike, phi_r: ArrayLike, wavelength: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The spatial frequencies (fx, fy) [cycles/m] that scatter ``theta_i`` into the detector.

    ``fx = (sin theta_r cos phi_s - sin theta_i) / lambda``, ``fy = sin theta_r sin phi_s /
    lambda`` with ``phi_s = phi_r - pi`` (the grating equation; x in the plane of incidence,
    towards the specular side).

    Parameters
    ----------
    theta_i, theta_r : array_like
        Angle of incidence and scatter polar angle [rad], in [0, pi/2].
    phi_r : array_like
        Outward detector azimuth, source at 0, specular half-plane at pi [rad].
    wavelength : float
        Vacuum wavelength [m].
    """
    ti, tr, pr = _angles(theta_i, theta_r, phi_r)
    lam = _wavelength(wavelength)
    ps = pr - math.pi
    return (np.sin(tr) * np.cos(ps) - np.sin(ti)) / lam, np.sin(tr) * np.sin(ps) / lam


def jones_factors(
    theta_i: ArrayLike, theta_r: ArrayLike, phi_r: ArrayLike, index: ArrayLike
) -> NDArray[np.complex128]:
    """The polarization amplitude factors ``[[q_ss, q_ps], [q_sp, q_pp]]`` [1].

    Germer (1997) eqs. (4)-(7) (module docstring), in the LB Stokes frames: the matrix acts
    on the incident ``(Es, Ep)`` and gives the scattered ``(Es, Ep)``. ``|q_ab|^2`` is
    Stover's ``Q_ab``.

    Parameters
    ----------
    theta_i, theta_r, phi_r : array_like
        Incidence, scatter polar angle and outward scatter azimuth (specular at pi) [rad].
    index : array_like of complex
        Substrate index ``N = n + ik`` [1] (ambient 1).

    Returns
    -------
    ndarray of complex, shape ``broadcast + (2, 2)``
    """
    ti, tr, pr = _angles(theta_i, theta_r, phi_r)
    eps = _index(index) ** 2
    ps = pr - math.pi
    ci, si, cs, ss = np.cos(ti), np.sin(ti), np.cos(tr), np.sin(tr)
    gi, gs = _root(eps - si * si + 0j), _root(eps - ss * ss + 0j)
    d_si, d_ss = ci + gi, cs + gs
    d_pi, d_ps = eps * ci + gi, eps * cs + gs
    e1 = eps - 1.0
    q = np.empty((*np.broadcast(ti, eps).shape, 2, 2), dtype=complex)
    q[..., 0, 0] = e1 * np.cos(ps) / (d_si * d_ss)
    q[..., 1, 1] = e1 * (eps * si * ss - gi * gs * np.cos(ps)) / (d_pi * d_ps)
    q[..., 0, 1] = -e1 * gi * np.sin(ps) / (d_pi * d_ss)
    q[..., 1, 0] = -e1 * gs * np.sin(ps) / (d_si * d_ps)
    return q


def _mueller_from_jones(j: NDArray[np.complex128]) -> NDArray[np.float64]:
    kron = (j[..., :, None, :, None] * np.conj(j)[..., None, :, None, :]).reshape(
        *j.shape[:-2], 4, 4
    )
    return np.real(_A @ kron @ _A_INV)


def _psd_at(psd2d: PsdFunction, fx: NDArray, fy: NDArray) -> NDArray[np.float64]:
    p = np.asarray(psd2d(fx, fy), dtype=float)
    p = np.broadcast_to(p, fx.shape)
    if np.any(~np.isfinite(p)) or np.any(p < 0):
        raise ValueError("psd2d returned a negative or non-finite value [m^4]")
    return p


def mueller_brdf(
    theta_i: ArrayLike,
    theta_r: ArrayLike,
    phi_r: ArrayLike,
    wavelength: float,
    index: ArrayLike,
    psd2d: PsdFunction,
) -> NDArray[np.float64]:
    """The Mueller BRDF (..., 4, 4) [sr^-1] of first-order vector perturbation theory.

    Parameters
    ----------
    theta_i, theta_r, phi_r : array_like
        Incidence, scatter polar angle and outward scatter azimuth (specular at pi) [rad];
        broadcast against each other (and ``index``).
    wavelength : float
        Vacuum wavelength [m].
    index : array_like of complex
        Substrate index ``N = n + ik`` [1].
    psd2d : callable
        ``psd2d(fx, fy)``: the surface's 2-D PSD [m^4] at spatial frequencies [cycles/m].

    Returns
    -------
    ndarray
        ``f_M`` from the incident ray's Stokes frame to the scattered ray's (LB); element
        ``[..., 0, 0]`` is the BRDF for unpolarized light.

    Notes
    -----
    The Jones matrix is ``sqrt(16 pi^2 cos ti cos tr PSD2 / lambda^4) q`` (Germer 1997,
    eq. (3); Stover eq. 5.13), the Mueller matrix its LB transform. Valid for
    ``4 pi sigma cos theta / lambda << 1`` and surface slopes << 1 (first order in the
    heights); the specular beam itself is not included.
    """
    ti, tr, pr = _angles(theta_i, theta_r, phi_r)
    lam = _wavelength(wavelength)
    q = jones_factors(ti, tr, pr, index)
    fx, fy = bragg_frequencies(ti, tr, pr, lam)
    scale = 16.0 * math.pi**2 / lam**4 * np.cos(ti) * np.cos(tr) * _psd_at(psd2d, fx, fy)
    m = _mueller_from_jones(q)
    return np.broadcast_to(scale, m.shape[:-2])[..., None, None] * m


def brdf(
    theta_i: ArrayLike,
    theta_r: ArrayLike,
    phi_r: ArrayLike,
    wavelength: float,
    index: ArrayLike,
    psd2d: PsdFunction,
    polarization: Polarization = "unpolarized",
) -> NDArray[np.float64]:
    """The BRDF [sr^-1] for one incident polarization, all scattered light detected.

    ``f = (16 pi^2 / lambda^4) cos ti cos tr Q PSD2(fx, fy)`` with ``Q = (Q_ss + Q_sp +
    Q_ps + Q_pp) / 2`` (unpolarized), ``Q_ss + Q_sp`` (s) or ``Q_pp + Q_ps`` (p); arguments
    as :func:`mueller_brdf`.
    """
    if polarization not in POLARIZATIONS:
        raise ValueError(f"polarization must be one of {POLARIZATIONS}, got {polarization!r}")
    ti, tr, pr = _angles(theta_i, theta_r, phi_r)
    lam = _wavelength(wavelength)
    q2 = np.abs(jones_factors(ti, tr, pr, index)) ** 2
    col = {"unpolarized": q2.sum(axis=(-2, -1)) / 2.0, "s": q2[..., :, 0].sum(-1)}
    qq = col.get(polarization, q2[..., :, 1].sum(-1))
    fx, fy = bragg_frequencies(ti, tr, pr, lam)
    return 16.0 * math.pi**2 / lam**4 * np.cos(ti) * np.cos(tr) * qq * _psd_at(psd2d, fx, fy)


def tis(
    theta_i: float,
    wavelength: float,
    index: complex,
    psd2d: PsdFunction,
    *,
    theta_min: float = 0.0,
    theta_max: float = math.pi / 2,
    polarization: Polarization = "unpolarized",
    n_theta: int = 256,
    n_phi: int = 256,
) -> float:
    """Total integrated scatter [1] into the polar band ``[theta_min, theta_max]``.

    ``TIS = integral of f cos(theta_r) dOmega`` over the band (full azimuth), by
    Gauss-Legendre in ``u = sin theta_r`` (``cos theta dOmega = u du dphi``) and the
    midpoint rule in azimuth (exact for a trigonometric polynomial of degree < n_phi).

    Parameters
    ----------
    theta_i : float
        Angle of incidence [rad].
    wavelength : float
        [m].
    index : complex
        Substrate index [1].
    psd2d : callable
        2-D PSD [m^4] (:func:`mueller_brdf`).
    theta_min, theta_max : float
        The collection band about the surface normal [rad], ``0 <= min < max <= pi/2``.
    polarization : {"unpolarized", "s", "p"}
    n_theta, n_phi : int
        Quadrature nodes; a PSD narrower than the band needs more ``n_theta``.

    Returns
    -------
    float
        The fraction of the incident power scattered into the band. Compare with
        :func:`tis_small_roughness` for the sigma of the spatial frequencies the band sees.
    """
    if not 0.0 <= theta_min < theta_max <= math.pi / 2:
        raise ValueError(
            f"expected 0 <= theta_min < theta_max <= pi/2 [rad], got {theta_min!r}, {theta_max!r}"
        )
    if n_theta < 2 or n_phi < 4:
        raise ValueError(f"n_theta >= 2 and n_phi >= 4 expected, got {n_theta}, {n_phi}")
    x, w = np.polynomial.legendre.leggauss(int(n_theta))
    u0, u1 = math.sin(theta_min), math.sin(theta_max)
    u = 0.5 * (u1 - u0) * x + 0.5 * (u1 + u0)
    wu = 0.5 * (u1 - u0) * w
    phi = (np.arange(int(n_phi)) + 0.5) * (2.0 * math.pi / n_phi)
    tr = np.arcsin(np.clip(u, 0.0, 1.0))[:, None]
    f = brdf(theta_i, tr, phi[None, :], wavelength, index, psd2d, polarization)
    return float(np.sum(f * (u * wu)[:, None]) * (2.0 * math.pi / n_phi))


def tis_small_roughness(
    sigma: ArrayLike, wavelength: float, theta_i: ArrayLike = 0.0, r0: ArrayLike = 1.0
) -> NDArray[np.float64]:
    """The small-roughness TIS ``R_0 (4 pi sigma cos theta_i / lambda)^2`` [1].

    Davies (1954), Bennett & Porteus (1961); Stover eq. 5.17. ``sigma`` [m] must be that of
    the spatial frequencies the collection band sees; the Rayleigh-Rice TIS tends to it when
    those frequencies scatter close to the specular direction (``f lambda << 1``). Equal to
    ``R_0 g`` of :func:`labbrdf.roughness.smoothness.total_integrated_scatter` with
    ``small_roughness=True``.
    """
    lam = _wavelength(wavelength)
    s = np.asarray(sigma, float)
    return np.asarray(
        np.asarray(r0, float)
        * (4.0 * math.pi * s * np.cos(np.asarray(theta_i, float)) / lam) ** 2,
        dtype=float,
    )


def specular_loss(sigma: ArrayLike, wavelength: float, theta_i: ArrayLike = 0.0) -> NDArray:
    """Specular reflectance relative to the smooth surface's, ``exp(-g)`` [1].

    ``g = (4 pi sigma cos theta_i / lambda)^2`` (Davies 1954); to first order ``1 - g``,
    whose deficit ``g`` is :func:`tis_small_roughness` ``/ R_0``: the power the specular beam
    loses is what Rayleigh-Rice scatters (for ``sigma`` of the scattering band).
    """
    return np.exp(-tis_small_roughness(sigma, wavelength, theta_i, 1.0))
