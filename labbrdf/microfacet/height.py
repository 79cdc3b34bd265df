"""The microsurface height distribution of the Smith model and the height walk.

Physics layer: numpy only. The uniform height distribution on [-1, 1] and the sampling of
a ray's next intersection height on an uncorrelated Smith microsurface (Heitz, Hanika,
d'Eon, Dachsbacher, "Multiple-scattering microfacet BSDFs with the Smith model", ACM TOG
35(4) (2016), sec. 4), for any distribution's Lambda.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["height_c1", "height_inv_c1", "sample_height"]


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
        The distribution's Smith Lambda of the travel direction.
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
