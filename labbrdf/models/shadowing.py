"""Shadowing/masking functions G for the five-parameter BRDF (pluggable).

Physics layer: numpy only. Every function here takes the model's own angles and returns
G in [0, 1]; all are symmetric under the exchange of source and detector.

A user-supplied shadowing function must have the signature of :data:`ShadowingFunction`:
``G(theta_i, theta_r, phi_r, cos_alpha, cos_gamma) -> ndarray`` (radians; ``cos_alpha = N.H``
is the facet tilt, ``cos_gamma = L.H`` the local incidence angle on the facet).

References
----------
.. [1] Blinn J. F., "Models of light reflection for computer synthesized pictures",
   Computer Graphics 11(2), 192-198 (1977). doi:10.1145/965141.563893
.. [2] Maxwell J. R., Beard J., Weiner S., Ladd D., Ladd S., "Bidirectional reflectance model
   validation and utilization", Environmental Research Institute of Michigan, AFAL-TR-73-303
   (1973); as in NIST SCATMECH ``Maxwell_Beard_Shadow_Function``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["ShadowingFunction", "g_maxwell_beard", "g_none", "g_torrance_sparrow"]

#: signature of a pluggable shadowing function
ShadowingFunction = Callable[[NDArray, NDArray, NDArray, NDArray, NDArray], NDArray]


def g_torrance_sparrow(
    theta_i: NDArray, theta_r: NDArray, cos_alpha: NDArray, cos_gamma: NDArray
) -> NDArray[np.float64]:
    """V-groove (Torrance-Sparrow) geometric attenuation in Blinn's form, eq. (5) of [1]_.

    ``G = min(1, 2 cos(alpha) cos(theta_r) / cos(gamma), 2 cos(alpha) cos(theta_i) / cos(gamma))``
    with N.H = cos(alpha), V.H = L.H = cos(gamma), N.L = cos(theta_i), N.V = cos(theta_r).

    Parameters
    ----------
    theta_i, theta_r : ndarray
        Polar angles of source and detector [rad].
    cos_alpha : ndarray
        Cosine of the facet tilt (N.H) [1].
    cos_gamma : ndarray
        Cosine of the local incidence angle on the facet (L.H) [1], > 0.

    Returns
    -------
    ndarray
        G [1] in [0, 1].
    """
    ratio = 2.0 * cos_alpha / cos_gamma
    return np.minimum(1.0, np.minimum(ratio * np.cos(theta_r), ratio * np.cos(theta_i)))


def g_none(
    theta_i: NDArray, theta_r: NDArray, cos_alpha: NDArray, cos_gamma: NDArray
) -> NDArray[np.float64]:
    """No shadowing, ``G = 1`` (the specular hemispherical integral then diverges at grazing)."""
    return np.ones(np.broadcast(theta_i, theta_r, cos_alpha, cos_gamma).shape)


def g_maxwell_beard(
    cos_alpha: NDArray, cos_gamma: NDArray, omega: float, tau: float
) -> NDArray[np.float64]:
    """Maxwell-Beard shadowing with facet tilt alpha as theta_N and gamma as beta, [2]_.

    ``G = [1 + (alpha / Omega) exp(-2 gamma / tau)] / (1 + alpha / Omega)``

    Parameters
    ----------
    cos_alpha, cos_gamma : ndarray
        Cosines of the facet tilt and of the local incidence angle [1].
    omega, tau : float
        Empirical constants [rad], > 0.

    Returns
    -------
    ndarray
        G [1] in (0, 1].
    """
    alpha = np.arccos(np.clip(cos_alpha, -1.0, 1.0))
    gamma = np.arccos(np.clip(cos_gamma, -1.0, 1.0))
    x = alpha / omega
    return (1.0 + x * np.exp(-2.0 * gamma / tau)) / (1.0 + x)
