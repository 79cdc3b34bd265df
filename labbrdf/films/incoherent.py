"""Stacks with thick (incoherent) layers: intensity addition between coherent sub-stacks.

Pure NumPy (physics layer), in the conventions of :mod:`labbrdf.films.matrices`, whose
coherent recursion computes every coherent sub-stack. A layer thicker than the coherence
length of the light (a glass substrate of 1 mm under a thin film, a thick polymer sheet) is
*incoherent*: the phases of the waves that cross it many times are averaged out, so the
intensities of its multiply reflected waves add, while the thin layers above and below it
stay coherent. This is the method of Katsidis & Siapkas [1]_ and of Byrnes' ``inc_tmm``
[2]_, written with field-amplitude products, which also gives the s-p cross term
``X = <r_s r_p*>`` of the reflected light and with it the ellipsometric angles and the
depolarization that the backside reflection causes (Mueller form [3]_).

A stack is ``indices = [N_0, N_1, ..., N_L, N_exit]`` with ``thicknesses_nm = [d_1, ...,
d_L]`` and ``coherent = [c_1, ..., c_L]``; a film on a glass slide in air with backside
reflection is ``[1, N_film, N_glass, 1]``, ``[d_film, d_glass]``, ``[True, False]``.

References
----------
.. [1] C. C. Katsidis, D. I. Siapkas, "General transfer-matrix method for optical multilayer
   systems with coherent, partially coherent, and incoherent interference", Appl. Opt. 41,
   3978-3987 (2002), eqs. (19)-(25) (the intensity transfer matrix of an incoherent layer).
.. [2] S. J. Byrnes, "Multilayer optical calculations", arXiv:1603.02720 (2016), section 5
   (incoherent and partly incoherent stacks).
.. [3] H. Fujiwara, *Spectroscopic Ellipsometry: Principles and Applications*, Wiley (2007),
   sections 3.4 (Mueller matrices, depolarization) and 5.5 (backside reflection).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..optics import _mueller_sp
from .matrices import _normal_components, _power_factors, _recursion, _validated

__all__ = ["IntensitySums", "ellipsometry", "intensity_sums", "mueller"]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


class IntensitySums(NamedTuple):
    """Incoherent sums of the reflected and transmitted light of a stack.

    ``Rs``, ``Rp``: reflectances [1]; ``X``: the s-p cross term ``sum r_s r_p*`` over all
    reflected paths [1] (``r_s r_p*`` for a coherent stack); ``Ts``, ``Tp``: power
    transmittances into the exit medium [1].
    """

    Rs: FloatArray
    Rp: FloatArray
    X: ComplexArray
    Ts: FloatArray
    Tp: FloatArray


def _sub_stack(n, kz, d, lam, lo, hi, from_below=True):
    """Forward (from above) and, if asked, backward (from below) amplitudes of media lo..hi."""
    media, kzs, thick = n[lo : hi + 1], kz[lo : hi + 1], d[lo : hi - 1]
    down = _recursion(media, kzs, thick, lam)
    up = _recursion(media[::-1], kzs[::-1], thick[::-1], lam) if from_below else down
    return down, up


def intensity_sums(
    indices: Sequence[ArrayLike],
    thicknesses_nm: Sequence[ArrayLike],
    coherent: Sequence[bool],
    wavelength_nm: ArrayLike,
    theta_deg: ArrayLike,
) -> IntensitySums:
    """Reflectance, transmittance and the s-p cross term of a stack with incoherent layers.

    Parameters
    ----------
    indices, thicknesses_nm, wavelength_nm, theta_deg
        As :func:`labbrdf.films.matrices.amplitudes`: ``[N_0, N_1, ..., N_L, N_exit]``;
        the ambient ``N_0`` must be lossless.
    coherent : sequence of bool
        One flag per layer: ``False`` for a thick layer whose multiple reflections add in
        intensity.

    Returns
    -------
    IntensitySums
        ``Rs``, ``Rp``, ``X``, ``Ts``, ``Tp``. With every layer coherent, ``Rs = |r_s|^2``,
        ``X = r_s r_p*`` and ``T`` is :func:`labbrdf.films.matrices.transmittance`.

    Raises
    ------
    ValueError
        As :func:`labbrdf.films.matrices.amplitudes`, a wrong number of flags or an
        absorbing ambient.

    Notes
    -----
    The stack is cut at its incoherent layers into coherent sub-stacks, each computed by the
    coherent recursion from above (``r, t``) and from below (``r', t'``). From the bottom
    up, an incoherent layer of one-pass intensity attenuation ``P = exp(-2 Im beta)``
    (``beta = 2 pi d N cos(theta) / lambda``) under a sub-stack adds, for each product
    ``<a b*>`` (``a, b`` = s or p),

        R = r_a r_b* + (t_a t_b*)(t'_a t'_b*) P^2 R_below / (1 - (r'_a r'_b*) P^2 R_below)
        T = (t_a t_b*) P T_below / (1 - (r'_a r'_b*) P^2 R_below)

    the geometric series of the waves that cross the layer ``2j + 1`` times: their
    mutual interference terms vanish on average over the layer's phase, and the phase of
    ``e^{i beta}`` is common to s and p in an isotropic layer, so only ``P`` remains in
    the cross term. For ``R_s``, ``R_p``, ``T_s``, ``T_p`` this is the intensity transfer
    matrix of Katsidis & Siapkas [1]_ (eqs. 19-25) and tmm's ``inc_tmm`` [2]_; working
    with field amplitudes, the power factors ``Re(N cos theta)`` of the inner media
    cancel, and only those of the ambient and the exit medium remain in ``T``.
    """
    n, d, lam, th = _validated(indices, thicknesses_nm, wavelength_nm, theta_deg)
    flags = [bool(c) for c in coherent]
    if len(flags) != len(d):
        raise ValueError(f"coherent: expected one flag per layer ({len(d)}), got {len(flags)}")
    if np.any(np.asarray(indices[0]).imag != 0):
        raise ValueError("indices[0] (ambient): expected a lossless (real) ambient")
    kz = _normal_components(n, th)
    cuts = [0] + [j + 1 for j, c in enumerate(flags) if not c] + [len(n) - 1]
    (rs, rp, ts, tp), _ = _sub_stack(n, kz, d, lam, cuts[-2], cuts[-1], False)
    r_ss, r_pp, r_sp = np.abs(rs) ** 2, np.abs(rp) ** 2, rs * np.conj(rp)
    t_ss, t_pp = np.abs(ts) ** 2, np.abs(tp) ** 2
    for k in range(len(cuts) - 3, -1, -1):
        j = cuts[k + 1]  # the incoherent medium under sub-stack k
        p1 = np.exp(-4.0 * np.pi * d[j - 1] / lam * kz[j].imag)  # |exp(i beta)|^2
        p2 = p1 * p1
        (rs, rp, ts, tp), (us, up, vs, vp) = _sub_stack(n, kz, d, lam, cuts[k], j)
        den_s = 1.0 - np.abs(us) ** 2 * p2 * r_ss
        den_p = 1.0 - np.abs(up) ** 2 * p2 * r_pp
        den_x = 1.0 - us * np.conj(up) * p2 * r_sp
        t_ss = np.abs(ts) ** 2 * p1 * t_ss / den_s
        t_pp = np.abs(tp) ** 2 * p1 * t_pp / den_p
        r_ss = np.abs(rs) ** 2 + np.abs(ts * vs) ** 2 * p2 * r_ss / den_s
        r_pp = np.abs(rp) ** 2 + np.abs(tp * vp) ** 2 * p2 * r_pp / den_p
        r_sp = rs * np.conj(rp) + (ts * vs) * np.conj(tp * vp) * p2 * r_sp / den_x
    f_s, f_p = _power_factors(n[0], n[-1], kz[0], kz[-1])
    return IntensitySums(
        np.asarray(r_ss), np.asarray(r_pp), np.asarray(r_sp),
        np.asarray(t_ss * f_s), np.asarray(t_pp * f_p),
    )  # fmt: skip


def ellipsometry(
    sums: IntensitySums,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """psi, Delta and depolarization of the reflected light from its intensity sums.

    Parameters
    ----------
    sums : IntensitySums
        From :func:`intensity_sums`.

    Returns
    -------
    psi_deg : ndarray of float
        ``arctan sqrt(R_p / R_s)`` in [0, 90] [deg], i.e. ``N = cos 2 psi = M12/M11`` for
        the matrix of :func:`mueller` (Woollam writes ``mm12 = -N``).
    delta_deg : ndarray of float
        ``arg X`` in [0, 360) [deg], i.e. ``tan Delta = S / C`` with ``C = M33/M11``,
        ``S = M34/M11`` (Nebraska convention, 180 at normal incidence).
    depolarization : ndarray of float
        ``1 - sqrt(N^2 + C^2 + S^2) = 1 - sqrt(1 - 4 (R_s R_p - |X|^2) / (R_s + R_p)^2)``
        in [0, 1] [1]: 0 for a coherent stack, the degree of depolarization of the
        reflected light for an incident light polarized at 45 deg.

    Notes
    -----
    This is how an ellipsometer that measures ``N, C, S`` (a rotating compensator, or
    WVASE's depolarization channel) reports a depolarizing sample [3]_: psi from ``N``,
    Delta from ``(C, S)``, and the depolarization beside them. A rotating-analyzer
    instrument, which measures only ``N`` and ``C``, reports ``cos Delta = C / sin 2 psi``
    instead; that differs where the depolarization is not small.
    """
    rs, rp, x = sums.Rs, sums.Rp, sums.X
    psi = np.degrees(np.arctan2(np.sqrt(rp), np.sqrt(rs)))
    delta = np.mod(np.degrees(np.angle(x)), 360.0)
    delta = np.where(delta >= 360.0, 0.0, delta)
    total = rs + rp
    with np.errstate(divide="ignore", invalid="ignore"):
        pol2 = 1.0 - 4.0 * (rs * rp - np.abs(x) ** 2) / (total * total)
        depol = np.where(total > 0, 1.0 - np.sqrt(np.clip(pol2, 0.0, 1.0)), 0.0)
    return np.asarray(psi), np.asarray(delta), np.asarray(depol)


def mueller(sums: IntensitySums) -> FloatArray:
    """Mueller matrix of the specular reflection, from the incoherent sums.

    Parameters
    ----------
    sums : IntensitySums
        From :func:`intensity_sums`.

    Returns
    -------
    ndarray of float, shape (..., 4, 4)
        ``1/2 [[Rs+Rp, Rs-Rp, 0, 0], [Rs-Rp, Rs+Rp, 0, 0], [0, 0, 2 Re X, 2 Im X],
        [0, 0, -2 Im X, 2 Re X]]`` [1] (the frames of :func:`labbrdf.optics.mueller_reflection`):
        the incoherent sum of the Mueller matrices of the front-side reflection and of every
        path through the incoherent layers [3]_.
    """
    return _mueller_sp(sums.Rs, sums.Rp, sums.X)
