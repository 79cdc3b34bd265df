"""One film on a substrate: coherent (Airy) amplitudes, incoherent reflectance and Mueller matrix.

Pure NumPy (physics layer), in the conventions of :mod:`labbrdf.optics` (whose Fresnel
interface amplitudes it uses) and validated by its error policy: a ``ValueError`` names the
argument for non-finite input, an unphysical index, an angle outside [0, 90] deg, a
non-positive wavelength or a negative thickness. The coherent amplitudes are those of the one
multilayer, :func:`labbrdf.films.matrices.amplitudes`, with one layer; the incoherent sums
add the film's internal reflections in intensity.

References
----------
.. [1] M. Born, E. Wolf, *Principles of Optics*, 7th ed., Cambridge University Press (1999),
   section 1.6 (thin films).
.. [2] Z. Dong, P. Bai, W. Xu, Y. Liu, X. Sun, "Modeling and characteristic analysis methods
   for reflection polarization on coated surfaces", Acta Optica Sinica 42(22) 2224001
   (2022), doi:10.3788/AOS202242.2224001, eqs. (8), (11), (12), (13), (17); its errors
   are listed in ``docs/errata.md``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..optics import (
    ComplexArray,
    FloatArray,
    _amplitudes,
    _angle,
    _arrays,
    _cos_deg,
    _index,
    _mueller_sp,
    _nonneg,
    _physical_root,
)
from .matrices import amplitudes

__all__ = ["film_amplitudes", "film_mueller_incoherent", "film_reflectance_incoherent"]


def _film(n_ambient, n_film, n_substrate, thickness_nm, wavelength_nm, theta_i_deg):
    """Validated inputs -> interface amplitudes and the one-pass film phase ``beta``."""
    n0 = _index("n_ambient", n_ambient)
    n1 = _index("n_film", n_film)
    n2 = _index("n_substrate", n_substrate)
    d = _nonneg("thickness_nm", thickness_nm)
    lam = _nonneg("wavelength_nm", wavelength_nm, strict=True)
    cos_i = _cos_deg("theta_i_deg", theta_i_deg)
    kz0 = n0 * cos_i
    # the tangential component kx = n0 sin(theta_i) is conserved through the stack
    kz1 = _physical_root((n1 * n1 - n0 * n0) + kz0 * kz0)
    kz2 = _physical_root((n2 * n2 - n0 * n0) + kz0 * kz0)
    top = _amplitudes(n0, n1, kz0, kz1)  # ambient -> film
    back = _amplitudes(n1, n0, kz1, kz0)  # film -> ambient
    bottom = _amplitudes(n1, n2, kz1, kz2)  # film -> substrate
    beta = (2.0 * np.pi) * d / lam * kz1  # one-pass phase [rad], Im(beta) >= 0
    return top, back, bottom, beta


def film_amplitudes(
    n_ambient: ArrayLike,
    n_film: ArrayLike,
    n_substrate: ArrayLike,
    thickness_nm: ArrayLike,
    wavelength_nm: ArrayLike,
    theta_i_deg: ArrayLike,
) -> tuple[ComplexArray, ComplexArray]:
    """Coherent (Airy) reflection amplitudes of one film on a substrate.

    Parameters
    ----------
    n_ambient, n_film, n_substrate : array_like of complex
        Indices ``n + ik`` (``n, k >= 0``) of the ambient, the film and the substrate [1].
    thickness_nm : array_like of float
        Physical film thickness ``d`` >= 0 [nm].
    wavelength_nm : array_like of float
        Vacuum wavelength > 0 [nm].
    theta_i_deg : array_like of float
        Angle of incidence in the ambient, in [0, 90] [deg].

    Returns
    -------
    rs, rp : ndarray of complex
        ``r = (r01 + r12 exp(2 i beta)) / (1 + r01 r12 exp(2 i beta))`` [1], with
        ``beta = 2 pi d n_film cos(theta_film) / lambda`` and the LB interface amplitudes
        (Born and Wolf [1]_ section 1.6.4). Same convention as :func:`labbrdf.optics.fresnel`:
        ``d = 0`` gives the bare substrate.

    Raises
    ------
    ValueError
        For invalid input (module error policy), ``thickness_nm < 0`` or
        ``wavelength_nm <= 0``.

    Notes
    -----
    The Airy sum uses ``r10 = -r01`` and ``t01 t10 = 1 - r01^2``, which hold for both
    polarizations in the LB frames ({s, p, k} right-handed, s common to all rays in the
    plane of incidence). ``exp(2 i beta)`` follows from ``exp(-i omega t)``. Computed by
    :func:`labbrdf.films.matrices.amplitudes` (one layer), the one coherent multilayer of labbrdf.
    """
    media = [_index(k, v) for k, v in (("n_ambient", n_ambient), ("n_film", n_film))]
    media.append(_index("n_substrate", n_substrate))
    d = _nonneg("thickness_nm", thickness_nm)
    lam = _nonneg("wavelength_nm", wavelength_nm, strict=True)
    theta = _angle("theta_i_deg", theta_i_deg)
    rs, rp, _, _ = amplitudes(media, [d], lam, theta)
    return _arrays(rs, rp)


def _film_incoherent(n_ambient, n_film, n_substrate, thickness_nm, wavelength_nm, theta_i_deg):
    (r01s, r01p, t01s, t01p), (r10s, r10p, t10s, t10p), (r12s, r12p, _, _), beta = _film(
        n_ambient, n_film, n_substrate, thickness_nm, wavelength_nm, theta_i_deg
    )
    # round-trip intensity attenuation in the film; the s-p cross term carries the same
    # factor because both polarizations share the phase of kz1 (isotropic film)
    att = np.exp(-4.0 * beta.imag)
    xs = t01s * t10s * r12s  # amplitude gain of the first internal path, s
    xp = t01p * t10p * r12p
    gs = r10s * r12s  # one internal round trip
    gp = r10p * r12p
    rs_tot = np.abs(r01s) ** 2 + np.abs(xs) ** 2 * att / (1.0 - np.abs(gs) ** 2 * att)
    rp_tot = np.abs(r01p) ** 2 + np.abs(xp) ** 2 * att / (1.0 - np.abs(gp) ** 2 * att)
    coh = r01s * np.conj(r01p) + xs * np.conj(xp) * att / (1.0 - gs * np.conj(gp) * att)
    return rs_tot, rp_tot, coh


def film_reflectance_incoherent(
    n_ambient: ArrayLike,
    n_film: ArrayLike,
    n_substrate: ArrayLike,
    thickness_nm: ArrayLike,
    wavelength_nm: ArrayLike,
    theta_i_deg: ArrayLike,
) -> tuple[FloatArray, FloatArray]:
    """Incoherent (geometric-optics) reflectances of one film on a substrate.

    Parameters
    ----------
    n_ambient, n_film, n_substrate : array_like of complex
        Indices ``n + ik`` (``n, k >= 0``) of the ambient, the film and the substrate [1].
    thickness_nm : array_like of float
        Physical film thickness >= 0 [nm]; enters only through the film absorption.
    wavelength_nm : array_like of float
        Vacuum wavelength > 0 [nm].
    theta_i_deg : array_like of float
        Angle of incidence in the ambient, in [0, 90] [deg].

    Returns
    -------
    Rs, Rp : ndarray of float
        ``R = |r01|^2 + |t01 t10 r12|^2 A / (1 - |r10 r12|^2 A)`` [1]: the sum of the
        intensities of all multiply reflected rays, with the round-trip intensity
        attenuation ``A = exp(-4 Im(beta))`` (``beta`` as in :func:`film_amplitudes`).
        The limit a ray tracer without phase converges to (oracles README pitfall 15).

    Raises
    ------
    ValueError
        As :func:`film_amplitudes`.

    Notes
    -----
    ``|t01 t10|^2`` needs no beam-area factor: the factors of the two crossings cancel
    exactly. The model assumes a propagating wave in the film (no total internal
    reflection at the ambient-film interface).
    """
    rs_tot, rp_tot, _ = _film_incoherent(
        n_ambient, n_film, n_substrate, thickness_nm, wavelength_nm, theta_i_deg
    )
    return _arrays(rs_tot, rp_tot)


def film_mueller_incoherent(
    n_ambient: ArrayLike,
    n_film: ArrayLike,
    n_substrate: ArrayLike,
    thickness_nm: ArrayLike,
    wavelength_nm: ArrayLike,
    theta_i_deg: ArrayLike,
) -> FloatArray:
    """Partially depolarising Mueller matrix of the specular reflection of an incoherent film.

    Parameters
    ----------
    n_ambient, n_film, n_substrate, thickness_nm, wavelength_nm, theta_i_deg
        As :func:`film_reflectance_incoherent`.

    Returns
    -------
    ndarray of float, shape (..., 4, 4)
        ``M = M_r01 + sum_j M_t10 (A M_r12 M_r10)^j A M_r12 M_t01`` [1]: the incoherent sum
        of the Mueller matrices (:func:`labbrdf.optics.mueller_reflection`,
        :func:`labbrdf.optics.mueller_transmission`)
        of every path, from the frame of the incident ray to that of the specular ray. All
        terms are diagonal-Jones Mueller matrices, so the series sums in closed form:
        ``Rs``, ``Rp`` as :func:`film_reflectance_incoherent` and the S2/S3 block from
        ``C = r01s r01p* + xs xp* A / (1 - gs gp* A)``, ``x = t01 t10 r12``,
        ``g = r10 r12``. ``|C|^2 < Rs Rp`` in general: the sum of rays with different
        retardances depolarises.

    Raises
    ------
    ValueError
        As :func:`film_amplitudes`.

    Notes
    -----
    Matches the ``own_inc_series`` rows of the oracle table ``coated_smooth.csv``
    (``tests/test_optics_oracles.py``); this is
    the smooth limit of the coated-surface tracer (Dong 2022 [2]_ models the rough case).
    """
    rs_tot, rp_tot, coh = _film_incoherent(
        n_ambient, n_film, n_substrate, thickness_nm, wavelength_nm, theta_i_deg
    )
    return _mueller_sp(rs_tot, rp_tot, coh)
