"""Structure-aware polarized reflection and refraction at a facet.

Each ray carries a Mueller matrix ``M`` stored as an array of shape (4, 4, n): ``M[i]``
is row i for all rays. It maps the incident Stokes vector (in the incident frame) to the
ray's current Stokes vector in the ray's current frame ``{s, p = k x s, k}``.

A Fresnel matrix (Dong 2022 eq. (11); the transmission matrix with the correction of the
errata, see :func:`labbrdf.optics.mueller_transmission`) has four distinct numbers,

    [[A, B, 0, 0], [B, A, 0, 0], [0, 0, C, S], [0, 0, -S, C]],

and a frame rotation (eq. (17) corrected: M[0, 0] = 1) touches only rows 1 and 2; both are
applied as row updates, never as generic 4x4 products.

Conventions are those of :mod:`labbrdf.optics` (LB): at a facet with normal ``m`` the s
axis is ``k_in x m`` normalised, p = k x s for the incident and for the outgoing ray.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..optics import fresnel_cos

__all__ = [
    "apply_fresnel",
    "apply_scale",
    "cross",
    "fresnel_abcs",
    "rotate_frame",
    "s_axis",
]

F64 = NDArray[np.float64]


def cross(a: F64, b: F64) -> F64:
    """Cross product of (3, n) arrays."""
    return np.stack(
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    )


def s_axis(k: F64, m: F64, fallback: F64) -> F64:
    """Unit s axis ``k x m / |k x m|`` of the plane of incidence on a facet.

    Where ``k`` and ``m`` are parallel (normal incidence on the facet) every axis
    perpendicular to k is an s axis; ``fallback`` (the ray's current s) is used.
    """
    c = cross(k, m)
    norm = np.sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2])
    ok = norm > 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(ok, c / np.where(ok, norm, 1.0), fallback)
    return c


def rotate_frame(M: F64, k: F64, s_old: F64, s_new: F64) -> None:
    """Re-express the ray's Stokes rows in the frame with x axis ``s_new`` (in place).

    With ``p_old = k x s_old`` and ``s_new = cos(a) s_old + sin(a) p_old``, applies the
    rotation Mueller matrix ``[[1,0,0,0],[0,c,s,0],[0,-s,c,0],[0,0,0,1]]``, c = cos 2a,
    s = sin 2a (:func:`labbrdf.optics.mueller_rotation`) to rows 1 and 2 of M.
    """
    p_old = cross(k, s_old)
    ca = np.einsum("ij,ij->j", s_old, s_new)
    sa = np.einsum("ij,ij->j", p_old, s_new)
    c2 = ca * ca - sa * sa
    s2 = 2.0 * ca * sa
    r1 = M[1].copy()
    M[1] = c2 * r1 + s2 * M[2]
    M[2] = c2 * M[2] - s2 * r1


def apply_fresnel(M: F64, a: F64, b: F64, c: F64, s: F64) -> None:
    """Left-multiply M by the Fresnel-structured matrix (A, B, C, S) (in place)."""
    r0 = M[0].copy()
    M[0] = a * r0 + b * M[1]
    M[1] = b * r0 + a * M[1]
    r2 = M[2].copy()
    M[2] = c * r2 + s * M[3]
    M[3] = c * M[3] - s * r2


def apply_scale(M: F64, w: F64) -> None:
    """Multiply every element of ray i's matrix by w[i] (in place)."""
    M *= w


def fresnel_abcs(
    n1: complex | NDArray,
    n2: complex | NDArray,
    cos_i: F64,
    mirror: bool = False,
    opaque: NDArray[np.bool_] | None = None,
) -> tuple[tuple[F64, F64, F64, F64], tuple[F64, F64, F64, F64], F64]:
    """The four distinct numbers of the reflection and transmission Mueller matrices.

    Parameters
    ----------
    n1, n2 : complex or ndarray
        Indices of the incidence and transmission media [1] (scalars or one per ray).
    cos_i : ndarray
        Cosine of the local angle of incidence, in [0, 1] [1].
    mirror : bool
        Ideal mirror: ``rs = -1``, ``rp = +1`` (limit of a perfect conductor, LB signs).
    opaque : ndarray of bool, optional
        Rays whose second medium is opaque (substrate): no transmission.

    Returns
    -------
    refl : (A, B, C, S)
        ``A = (|rs|^2 + |rp|^2)/2``, ``B = (|rs|^2 - |rp|^2)/2``, ``C = Re(rs rp*)``,
        ``S = Im(rs rp*)`` (eq. (11)).
    trans : (A, B, C, S)
        Same from ts, tp, scaled by the beam factor ``Re(n2 cos_t)/Re(n1 cos_i)``; zero
        under total internal reflection and for an absorbing n2 (opaque substrate).
    cos_t : ndarray
        Real cosine of the refraction angle (0 under total internal reflection).
    """
    if mirror:
        one = np.ones_like(cos_i)
        zero = np.zeros_like(cos_i)
        return (one, zero, -one, zero), (zero, zero, zero, zero), zero
    rs, rp, ts, tp, cos_t = fresnel_cos(n1, n2, cos_i)
    rs2 = rs.real * rs.real + rs.imag * rs.imag
    rp2 = rp.real * rp.real + rp.imag * rp.imag
    x = rs * np.conj(rp)
    refl = (0.5 * (rs2 + rp2), 0.5 * (rs2 - rp2), x.real, x.imag)
    if opaque is None and (np.any(np.imag(n2) != 0) or np.any(np.imag(n1) != 0)):
        z = np.zeros_like(cos_i)
        return refl, (z, z, z, z), np.real(cos_t)
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = np.where(cos_i > 0, np.real(n2 * cos_t) / (np.real(n1) * cos_i), 0.0)
    if opaque is not None:
        factor = np.where(opaque, 0.0, factor)
    ts2 = ts.real * ts.real + ts.imag * ts.imag
    tp2 = tp.real * tp.real + tp.imag * tp.imag
    y = ts * np.conj(tp)
    trans = (
        0.5 * factor * (ts2 + tp2),
        0.5 * factor * (ts2 - tp2),
        factor * y.real,
        factor * y.imag,
    )
    return refl, trans, np.real(cos_t)
