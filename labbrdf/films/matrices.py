"""Transfer matrices of a layer stack: ambient / N layers / substrate.

Pure NumPy (physics layer). One implementation of the coherent multilayer: every other
coherent film computation in labbrdf (:func:`labbrdf.films.onefilm.film_amplitudes`,
the :class:`~labbrdf.Stack`) calls :func:`amplitudes`.

Conventions are those of :mod:`labbrdf.optics` (docs/conventions.md): ``exp(-i omega t)``,
``N = n + ik`` with ``k >= 0``, LB interface amplitudes
``rs = (kz1 - kz2)/(kz1 + kz2)``, ``rp = (n2^2 kz1 - n1^2 kz2)/(n2^2 kz1 + n1^2 kz2)``
(``kz = N cos(theta)``), ``tp`` the ratio of the p electric-field amplitudes, and the
Nebraska ellipsometric angles ``tan(psi) = |rp/rs|``, ``Delta = arg(rs rp*)`` in
[0, 360) deg (180 deg at normal incidence).

Every function broadcasts its inputs with NumPy rules: pass ``wavelength_nm[:, None]`` and
``theta_deg[None, :]`` (and indices of shape ``(n_wl, 1)``) for a wavelength x angle grid.

References
----------
.. [1] M. Born, E. Wolf, *Principles of Optics*, 7th ed., Cambridge University Press (1999),
   section 1.6.5 (characteristic matrix of a stratified medium).
.. [2] R. M. A. Azzam, N. M. Bashara, *Ellipsometry and Polarized Light*, North-Holland
   (1977), section 4.6 (scattering matrix of a multilayer; eqs. 4.110-4.113).
.. [3] S. J. Byrnes, "Multilayer optical calculations", arXiv:1603.02720 (2016), eqs. for
   the transmitted power ``T`` of s and p waves.
.. [4] D. A. G. Bruggeman, "Berechnung verschiedener physikalischer Konstanten von
   heterogenen Substanzen", Ann. Phys. 416, 636-664 (1935); D. E. Aspnes, J. B. Theeten,
   F. Hottier, "Investigation of effective-medium models of microscopic surface roughness
   by spectroscopic ellipsometry", Phys. Rev. B 20, 3292 (1979).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..optics import _amplitudes, _angle, _index, _nonneg, _physical_root

__all__ = [
    "amplitudes",
    "bruggeman",
    "ellipsometry",
    "reflectance",
    "transmittance",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def _validated(
    indices: Sequence[ArrayLike],
    thicknesses_nm: Sequence[ArrayLike],
    wavelength_nm: ArrayLike,
    theta_deg: ArrayLike,
) -> tuple[list[ComplexArray], list[FloatArray], FloatArray, FloatArray]:
    idx = list(indices)
    thk = list(thicknesses_nm)
    if len(idx) < 2:
        raise ValueError(
            f"indices: expected ambient, layers and substrate (at least 2 media), got {len(idx)}"
        )
    if len(thk) != len(idx) - 2:
        raise ValueError(
            f"thicknesses_nm: expected one thickness per layer ({len(idx) - 2}), got {len(thk)}"
        )
    names = ["ambient"] + [f"layer {j + 1}" for j in range(len(idx) - 2)] + ["substrate"]
    n = [
        _index(f"indices[{j}] ({nm})", v) for j, (v, nm) in enumerate(zip(idx, names, strict=True))
    ]
    d = [_nonneg(f"thicknesses_nm[{j}]", v) for j, v in enumerate(thk)]
    lam = _nonneg("wavelength_nm", wavelength_nm, strict=True)
    th = _angle("theta_deg", theta_deg)
    return n, d, lam, th


def _stack(
    indices: Sequence[ArrayLike],
    thicknesses_nm: Sequence[ArrayLike],
    wavelength_nm: ArrayLike,
    theta_deg: ArrayLike,
) -> tuple[ComplexArray, ComplexArray, ComplexArray, ComplexArray, ComplexArray, ComplexArray]:
    """rs, rp, ts, tp and the normal wave-vector components of ambient and substrate."""
    n, d, lam, th = _validated(indices, thicknesses_nm, wavelength_nm, theta_deg)
    kz = _normal_components(n, th)
    rs, rp, ts, tp = _recursion(n, kz, d, lam)
    return rs, rp, ts, tp, kz[0], kz[-1]


def _normal_components(n: list[ComplexArray], theta_deg: FloatArray) -> list[ComplexArray]:
    """``kz_j = N_j cos(theta_j)`` of every medium, from the angle in the first one."""
    cos_i = np.cos(np.radians(theta_deg))
    n0 = n[0]
    kz0 = n0 * cos_i
    # the tangential component kx = n0 sin(theta) is conserved: kz_j^2 = n_j^2 - kx^2
    return [kz0] + [_physical_root((nj * nj - n0 * n0) + kz0 * kz0) for nj in n[1:]]


def _recursion(
    n: Sequence[ComplexArray],
    kz: Sequence[ComplexArray],
    d: Sequence[FloatArray],
    lam: FloatArray,
) -> tuple[ComplexArray, ComplexArray, ComplexArray, ComplexArray]:
    """rs, rp, ts, tp of media ``n`` (normal components ``kz``, layer thicknesses ``d``)."""
    # start from the bottom interface and add one layer at a time (Azzam & Bashara [2]
    # section 4.6): the scattering-matrix form of the characteristic-matrix product of
    # Born & Wolf [1] 1.6.5, identical algebraically, and free of the overflow of
    # exp(-i beta) that the plain matrix product meets in thick absorbing layers
    last = len(n) - 1
    rs, rp, ts, tp = _amplitudes(n[last - 1], n[last], kz[last - 1], kz[last])
    for j in range(last - 1, 0, -1):  # layer j between media j-1 (above) and j+1 (below)
        beta = (2.0 * np.pi) * d[j - 1] / lam * kz[j]  # one-pass phase, Im(beta) >= 0
        ph1 = np.exp(1j * beta)
        ph2 = ph1 * ph1
        a_rs, a_rp, a_ts, a_tp = _amplitudes(n[j - 1], n[j], kz[j - 1], kz[j])
        den_s = 1.0 + a_rs * rs * ph2
        den_p = 1.0 + a_rp * rp * ph2
        ts = a_ts * ts * ph1 / den_s
        tp = a_tp * tp * ph1 / den_p
        rs = (a_rs + rs * ph2) / den_s
        rp = (a_rp + rp * ph2) / den_p
    return rs, rp, ts, tp


def amplitudes(
    indices: Sequence[ArrayLike],
    thicknesses_nm: Sequence[ArrayLike],
    wavelength_nm: ArrayLike,
    theta_deg: ArrayLike,
) -> tuple[ComplexArray, ComplexArray, ComplexArray, ComplexArray]:
    """Coherent reflection and transmission amplitudes of a layer stack.

    Parameters
    ----------
    indices : sequence of array_like of complex
        ``[N_ambient, N_1, ..., N_L, N_substrate]``, each ``n + ik`` with ``n, k >= 0`` [1];
        each entry broadcasts with the wavelength and the angle (dispersion: an array over
        wavelength).
    thicknesses_nm : sequence of array_like of float
        ``[d_1, ..., d_L]``, physical thickness of each layer, >= 0 [nm] (empty for a bare
        substrate).
    wavelength_nm : array_like of float
        Vacuum wavelength > 0 [nm].
    theta_deg : array_like of float
        Angle of incidence in the ambient, in [0, 90] [deg].

    Returns
    -------
    rs, rp, ts, tp : ndarray of complex
        Amplitude ratios of the reflected and transmitted (into the substrate) electric
        fields [1], LB convention (module docstring). A layer of zero thickness, or one
        whose index equals its neighbour's, changes nothing.

    Raises
    ------
    ValueError
        Wrong number of thicknesses, non-finite input, ``n < 0`` or ``k < 0``, ``N = 0``,
        a negative thickness, a non-positive wavelength or an angle outside [0, 90].

    Notes
    -----
    Layer by layer from the substrate up, ``r = (r_ab + r' e^{2i beta}) /
    (1 + r_ab r' e^{2i beta})`` and ``t = t_ab t' e^{i beta} / (1 + r_ab r' e^{2i beta})``
    with ``beta = 2 pi d N cos(theta_layer) / lambda`` (Azzam & Bashara [2]_ eqs.
    4.110-4.113), the closed form of the 2 x 2 transfer-matrix product of Born & Wolf [1]_
    1.6.5: the recursion of the Airy formula of one film, which it reduces to for L = 1.
    """
    rs, rp, ts, tp, _, _ = _stack(indices, thicknesses_nm, wavelength_nm, theta_deg)
    return np.asarray(rs), np.asarray(rp), np.asarray(ts), np.asarray(tp)


def ellipsometry(
    indices: Sequence[ArrayLike],
    thicknesses_nm: Sequence[ArrayLike],
    wavelength_nm: ArrayLike,
    theta_deg: ArrayLike,
) -> tuple[FloatArray, FloatArray]:
    """Ellipsometric angles of a layer stack, Nebraska convention.

    Parameters
    ----------
    indices, thicknesses_nm, wavelength_nm, theta_deg
        As :func:`amplitudes`.

    Returns
    -------
    psi_deg : ndarray of float
        ``arctan |rp/rs|`` in [0, 90] [deg].
    delta_deg : ndarray of float
        ``arg(rs rp*)`` in [0, 360) [deg]: 180 at normal incidence (the convention of
        :func:`labbrdf.optics.psi_delta`, pyElli and WVASE).

    Raises
    ------
    ValueError
        As :func:`amplitudes`.
    """
    rs, rp, _, _, _, _ = _stack(indices, thicknesses_nm, wavelength_nm, theta_deg)
    psi = np.degrees(np.arctan2(np.abs(rp), np.abs(rs)))
    delta = np.mod(np.degrees(np.angle(rs * np.conj(rp))), 360.0)
    delta = np.where(delta >= 360.0, 0.0, delta)  # np.mod(-1e-20, 360) rounds to 360
    return np.asarray(psi), np.asarray(delta)


def reflectance(
    indices: Sequence[ArrayLike],
    thicknesses_nm: Sequence[ArrayLike],
    wavelength_nm: ArrayLike,
    theta_deg: ArrayLike,
) -> tuple[FloatArray, FloatArray]:
    """Specular reflectances ``R_s = |rs|^2``, ``R_p = |rp|^2`` of a layer stack [1].

    Parameters
    ----------
    indices, thicknesses_nm, wavelength_nm, theta_deg
        As :func:`amplitudes`.

    Returns
    -------
    R_s, R_p : ndarray of float
        Fractions in [0, 1].

    Raises
    ------
    ValueError
        As :func:`amplitudes`.
    """
    rs, rp, _, _, _, _ = _stack(indices, thicknesses_nm, wavelength_nm, theta_deg)
    return np.asarray(np.abs(rs) ** 2), np.asarray(np.abs(rp) ** 2)


def transmittance(
    indices: Sequence[ArrayLike],
    thicknesses_nm: Sequence[ArrayLike],
    wavelength_nm: ArrayLike,
    theta_deg: ArrayLike,
) -> tuple[FloatArray, FloatArray]:
    """Power transmittances ``T_s``, ``T_p`` into the substrate [1].

    Parameters
    ----------
    indices, thicknesses_nm, wavelength_nm, theta_deg
        As :func:`amplitudes`. The ambient must be lossless (real index) for ``T`` to be a
        ratio of powers.

    Returns
    -------
    T_s, T_p : ndarray of float
        ``T_s = |ts|^2 Re(N_sub cos th_sub) / Re(N_0 cos th_0)`` and
        ``T_p = |tp|^2 Re(N_sub conj(cos th_sub)) / Re(N_0 conj(cos th_0))`` (Byrnes [3]_):
        the power that crosses into the substrate; ``R + T = 1`` for lossless layers.
        0 at grazing incidence.

    Raises
    ------
    ValueError
        As :func:`amplitudes`, or an absorbing ambient.
    """
    if np.any(np.asarray(indices[0]).imag != 0):
        raise ValueError("indices[0] (ambient): transmittance needs a lossless (real) ambient")
    _, _, ts, tp, kz0, kzs = _stack(indices, thicknesses_nm, wavelength_nm, theta_deg)
    f_s, f_p = _power_factors(indices[0], indices[-1], kz0, kzs)
    return np.asarray(np.abs(ts) ** 2 * f_s), np.asarray(np.abs(tp) ** 2 * f_p)


def _power_factors(
    n_in: ArrayLike, n_out: ArrayLike, kz_in: ComplexArray, kz_out: ComplexArray
) -> tuple[FloatArray, FloatArray]:
    """``T / |t|^2`` for s and p (Byrnes [3]_); 0 where nothing enters (grazing)."""
    n0 = np.asarray(n_in, complex)
    ns = np.asarray(n_out, complex)
    cos0 = kz_in / n0
    coss = kz_out / ns
    with np.errstate(divide="ignore", invalid="ignore"):
        den_s = np.real(n0 * cos0)
        den_p = np.real(n0 * np.conj(cos0))
        f_s = np.where(den_s > 0, np.real(ns * coss) / den_s, 0.0)
        f_p = np.where(den_p > 0, np.real(ns * np.conj(coss)) / den_p, 0.0)
    return np.asarray(f_s), np.asarray(f_p)


def bruggeman(eps_a: ArrayLike, eps_b: ArrayLike, fraction: ArrayLike) -> ComplexArray:
    """Bruggeman effective dielectric function of a two-component mixture.

    Parameters
    ----------
    eps_a, eps_b : array_like of complex
        Dielectric functions ``eps = N^2`` of the two components [1] (``Im(eps) >= 0``).
    fraction : array_like of float
        Volume fraction of component ``a``, in [0, 1] [1].

    Returns
    -------
    ndarray of complex
        ``eps`` solving ``f (eps_a - eps)/(eps_a + 2 eps) + (1 - f)(eps_b - eps)/(eps_b +
        2 eps) = 0`` (Bruggeman 1935 [4]_, spherical inclusions in 3-D), i.e. the root of
        ``2 eps^2 - B eps - eps_a eps_b = 0`` with ``B = (3f - 1) eps_a + (2 - 3f) eps_b``
        that is physical: the larger imaginary part (a passive medium), and for lossless
        components the positive root. The surface-roughness layer of Aspnes et al. [4]_ is
        this mixture with ``f = 0.5`` of the material below and the ambient.

    Raises
    ------
    ValueError
        Non-finite input, ``Im(eps) < 0`` or a fraction outside [0, 1].
    """
    ea = np.asarray(eps_a, complex)
    eb = np.asarray(eps_b, complex)
    f = np.asarray(fraction, float)
    for name, v in (("eps_a", ea), ("eps_b", eb), ("fraction", f)):
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{name}: expected finite values, got NaN or inf")
    if np.any(ea.imag < 0) or np.any(eb.imag < 0):
        raise ValueError("eps_a, eps_b: expected Im(eps) >= 0 (passive media, N = n + ik)")
    if np.any((f < 0) | (f > 1)):
        raise ValueError("fraction: expected a volume fraction in [0, 1]")
    b = (3.0 * f - 1.0) * ea + (2.0 - 3.0 * f) * eb
    root = np.sqrt(b * b + 8.0 * ea * eb)
    e1 = (b + root) / 4.0
    e2 = (b - root) / 4.0
    tie = np.isclose(e1.imag, e2.imag, rtol=0.0, atol=1e-14 * (np.abs(e1) + np.abs(e2)))
    pick1 = np.where(tie, e1.real >= e2.real, e1.imag > e2.imag)
    return np.asarray(np.where(pick1, e1, e2))
