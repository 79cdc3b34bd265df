"""GGX microfacet distribution, Smith masking and visible-normal sampling.

All directions are unit vectors stored as arrays of shape (3, n), in a local frame whose
+z is the macroscopic normal on the side the ray is on.

References
----------
Dong et al., Acta Optica Sinica 42(22), 2224001 (2022), eqs. (14)-(15).
Walter B., Marschner S., Li H., Torrance K., "Microfacet models for refraction through
rough surfaces", EGSR 2007 (GGX, Smith G1).
Heitz E., "Sampling the GGX distribution of visible normals", JCGT 7(4) (2018).
Dupuy J., Benyoub A., "Sampling visible GGX normals with spherical caps", CGF 42(8) (2023).
Heitz E., Hanika J., d'Eon E., Dachsbacher C., "Multiple-scattering microfacet BSDFs with
the Smith model", ACM TOG 35(4) (2016) (height distribution, random walk).

Notes
-----
Eq. (14) of the 2022 paper omits alpha^2 in the numerator; :func:`ggx_d` uses
``D = alpha^2 / (pi cos^4 g (alpha^2 + tan^2 g)^2)``, which integrates to 1 over the
projected hemisphere. Eq. (15) samples ``D cos(theta_m)``; we sample the *visible*
normals ``D_wi(m) = G1(wi) max(0, wi.m) D(m) / cos(theta_i)`` instead (lower variance; the
weights below account for it). The spherical-cap construction is used because it is valid
for directions below the horizon too, which the multiple-scattering walk needs.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "ggx_d",
    "height_c1",
    "height_inv_c1",
    "sample_height",
    "sample_ggx_cos",
    "sample_vndf",
    "smith_g1",
    "smith_lambda",
]


def ggx_d(cos_m: ArrayLike, alpha: float) -> NDArray[np.float64]:
    """Isotropic GGX distribution of normals, corrected eq. (14) of Dong 2022.

    Parameters
    ----------
    cos_m : array_like
        Cosine of the angle between the facet normal and the macroscopic normal [1].
    alpha : float
        Roughness [1], > 0.

    Returns
    -------
    ndarray
        D(m) [sr^-1]; zero for cos_m <= 0.
    """
    c = np.asarray(cos_m, dtype=float)
    c2 = c * c
    with np.errstate(divide="ignore", invalid="ignore"):
        d = alpha**2 / (np.pi * (c2 * (alpha**2 - 1) + 1) ** 2)
    return np.where(c > 0, d, 0.0)


def smith_lambda(wz: ArrayLike, alpha: float | NDArray[np.float64]) -> NDArray[np.float64]:
    """Smith Lambda of GGX for a direction with cosine ``wz`` to the normal [1].

    For upward directions (wz > 0), ``Lambda = (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2``;
    for downward ones ``Lambda(w) = -1 - Lambda(-w)`` (Heitz et al. 2016), so that the
    height sampling of :func:`sample_height` works in both directions.
    """
    z = np.asarray(wz, dtype=float)
    z2 = np.maximum(z * z, 1e-300)
    t2 = np.maximum(1.0 - z2, 0.0) / z2
    lam = 0.5 * (-1.0 + np.sqrt(1.0 + alpha * alpha * t2))
    return np.where(z >= 0, lam, -1.0 - lam)


def smith_g1(wz: ArrayLike, alpha: float | NDArray[np.float64]) -> NDArray[np.float64]:
    """Smith masking ``G1 = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta))`` for wz > 0, else 0."""
    z = np.asarray(wz, dtype=float)
    lam = smith_lambda(np.abs(z), alpha)
    return np.where(z > 0, 1.0 / (1.0 + lam), 0.0)


def sample_ggx_cos(
    alpha: float, u1: NDArray[np.float64], u2: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Sample normals with pdf D(m) cos(theta_m), eq. (15) of Dong 2022.

    ``theta_m = arctan(alpha sqrt(u1 / (1 - u1)))``, ``phi_m = 2 pi u2``. Kept for the
    closed-form albedo test and the paper's algorithm; the tracer samples visible normals.
    """
    tan2 = alpha * alpha * u1 / (1.0 - u1)
    cos_t = 1.0 / np.sqrt(1.0 + tan2)
    sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
    phi = 2.0 * np.pi * u2
    return np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t])


def sample_vndf(
    wi: NDArray[np.float64],
    alpha: float | NDArray[np.float64],
    u1: NDArray[np.float64],
    u2: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Sample GGX visible normals for the direction ``wi`` (pointing away from the surface).

    Parameters
    ----------
    wi : ndarray, shape (3, n)
        Unit directions towards where the light comes from, in the local frame; wi_z may be
        negative (a ray travelling upwards inside the microsurface).
    alpha : float
        Roughness [1], >= 0 (0 returns the macroscopic normal).
    u1, u2 : ndarray, shape (n,)
        Uniform numbers in [0, 1).

    Returns
    -------
    ndarray, shape (3, n)
        Unit facet normals with pdf ``max(0, wi.m) D(m) / (projected area)``.

    Notes
    -----
    Stretch to the alpha = 1 configuration, sample the visible hemisphere by the spherical
    cap method (Dupuy & Benyoub 2023): ``h = c + v`` with ``c`` uniform on the cap
    ``z > -v_z``, then unstretch (Heitz 2018, section 3).
    """
    vx = alpha * wi[0]
    vy = alpha * wi[1]
    vz = wi[2]
    inv = 1.0 / np.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx * inv, vy * inv, vz * inv
    phi = 2.0 * np.pi * u1
    z = (1.0 - u2) * (1.0 + vz) - vz
    sin_t = np.sqrt(np.clip(1.0 - z * z, 0.0, 1.0))
    hx = alpha * (sin_t * np.cos(phi) + vx)
    hy = alpha * (sin_t * np.sin(phi) + vy)
    hz = np.maximum(z + vz, 1e-300)
    inv = 1.0 / np.sqrt(hx * hx + hy * hy + hz * hz)
    return np.stack([hx * inv, hy * inv, hz * inv])


def height_c1(h: ArrayLike) -> NDArray[np.float64]:
    """CDF of the uniform microsurface height distribution on [-1, 1] (Heitz 2016)."""
    return np.clip((np.asarray(h, dtype=float) + 1.0) * 0.5, 0.0, 1.0)


def height_inv_c1(u: ArrayLike) -> NDArray[np.float64]:
    """Inverse of :func:`height_c1`."""
    return np.clip(2.0 * np.asarray(u, dtype=float) - 1.0, -1.0, 1.0)


def sample_height(
    wz: NDArray[np.float64], lam: NDArray[np.float64], h: NDArray[np.float64], u: NDArray
) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
    """Next intersection height of a ray on the microsurface (Heitz et al. 2016, sec. 4).

    Parameters
    ----------
    wz : ndarray
        z component of the travel direction in the local frame [1].
    lam : ndarray
        ``smith_lambda(wz, alpha)``.
    h : ndarray
        Current height (+inf for a ray arriving from the bulk).
    u : ndarray
        Uniform numbers in [0, 1).

    Returns
    -------
    escaped : ndarray of bool
        The ray leaves the microsurface (only possible going up); probability
        ``G1(w, h) = C1(h)^Lambda(w)``.
    h_new : ndarray
        Height of the next intersection (meaningless where escaped).
    """
    c1 = height_c1(h)
    up = wz > 0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        g1 = np.where(up, c1**lam, 0.0)
        escaped = up & (u >= 1.0 - g1)
        ratio = np.where(lam != 0, (1.0 - u) ** (1.0 / np.where(lam != 0, lam, 1.0)), 1.0)
        h_new = height_inv_c1(c1 / ratio)
    return escaped, np.where(np.isfinite(h_new), h_new, h)
