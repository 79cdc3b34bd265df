"""Spectral bandwidth and angle spread: intensity sums averaged over the instrument's beam.

Pure NumPy (physics layer). A monochromator passes a band of wavelengths and a focused or
divergent beam a range of angles of incidence; the detector adds what each part of the
beam reflects, in intensity. Like a thickness spread (:mod:`labbrdf.films.nonuniform`),
both average the intensity sums ``R_s, R_p, X, T_s, T_p``
(:class:`~labbrdf.films.incoherent.IntensitySums`), and with them the Mueller matrix,
which is linear in them: the reflected light is partly depolarized [1]_.

References
----------
.. [1] H. Fujiwara, *Spectroscopic Ellipsometry: Principles and Applications*, Wiley (2007),
   section 5.5 (depolarization: incoherent sums of the light from parts of the spot or
   beam).
.. [2] L. N. Trefethen, J. A. C. Weideman, "The exponentially convergent trapezoidal
   rule", SIAM Rev. 56, 385 (2014).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .incoherent import IntensitySums

__all__ = [
    "FWHM_PER_SIGMA",
    "MAX_ANGLE_SPREAD_DEG",
    "MAX_BANDWIDTH_NM",
    "MAX_POINTS",
    "beam_sums",
    "gaussian_nodes",
]

MAX_BANDWIDTH_NM = 20.0
"""Largest spectral bandwidth (full width at half maximum) [nm]."""
MAX_ANGLE_SPREAD_DEG = 2.0
"""Largest 1-sigma spread of the angle of incidence [deg]."""
MAX_POINTS = 121
"""Most quadrature nodes of one average (each a stack evaluation)."""
FWHM_PER_SIGMA = 2.0 * np.sqrt(2.0 * np.log(2.0))
"""Full width at half maximum of a Gaussian in units of its sigma (2.3548)."""
_REACH = 7.0  # nodes over +-7 sigma: the Gaussian tail beyond holds 3e-12


def gaussian_nodes(phase_spread: float, points: int | None = None) -> tuple[NDArray, NDArray]:
    """Trapezoid nodes ``x`` (in sigma) over +-7 sigma and their normalised Gaussian weights.

    Parameters
    ----------
    phase_spread : float
        1-sigma spread ``phi`` of the round-trip phase through the coherent layers that the
        averaged variable causes [rad]: the node spacing is ``1 / (1 + 1.1 phi)`` sigma.
    points : int, optional
        Number of nodes instead (odd).

    Returns
    -------
    (ndarray, ndarray)
        Nodes and weights ``w_k`` proportional to ``exp(-x_k^2 / 2)``, summing to 1.

    Notes
    -----
    The trapezoid rule on the Gaussian weight converges geometrically for sums that
    oscillate with a film's phase; with spacing ``h`` its error on ``exp(i a x)`` is about
    ``2 exp(-2 pi^2 / h^2)`` [2]_, 3e-9 at ``h = 1``.
    """
    if points is None:
        h = 1.0 / (1.0 + 1.1 * float(phase_spread))
        points = int(min(2 * np.ceil(_REACH / h) + 1, MAX_POINTS))
    x = np.linspace(-_REACH, _REACH, points)
    w = np.exp(-0.5 * x * x)
    return x, w / w.sum()


def _check(value: float, top: float, what: str, unit: str) -> float:
    v = float(value)
    if not 0.0 <= v <= top:
        raise ValueError(f"{what}: expected a value in [0, {top:g}] {unit}, got {value!r}")
    return v


def beam_sums(
    sums: Callable[[NDArray, NDArray], IntensitySums],
    wavelength_nm: ArrayLike,
    theta_deg: ArrayLike,
    bandwidth_nm: float = 0.0,
    angle_spread_deg: float = 0.0,
    optical_thickness_nm: float = 0.0,
    points: int | None = None,
) -> IntensitySums:
    """Intensity sums averaged over a Gaussian spectral band and a Gaussian angle spread.

    Parameters
    ----------
    sums : callable
        ``sums(wavelength_nm, theta_deg)`` -> :class:`IntensitySums` of the stack (the
        arrays broadcast as the inputs do).
    wavelength_nm, theta_deg : array_like
        Centre wavelengths [nm] and angles of incidence [deg]; they broadcast.
    bandwidth_nm : float
        Full width at half maximum of the Gaussian spectral profile [nm], in [0,
        :data:`MAX_BANDWIDTH_NM`].
    angle_spread_deg : float
        1-sigma spread of the angle of incidence in the plane of incidence [deg], in [0,
        :data:`MAX_ANGLE_SPREAD_DEG`].
    optical_thickness_nm : float
        ``sum n_j d_j`` over the coherent layers [nm]: sets the number of nodes (the
        round-trip phase ``4 pi n d / lambda`` spreads by ``phi = 4 pi n d sigma_lambda /
        lambda^2`` over the band and by at most ``4 pi d sigma_theta / lambda`` over the
        angles, at the shortest wavelength; node spacing as :func:`gaussian_nodes`).
    points : int, optional
        Nodes per averaged variable (odd, at most :data:`MAX_POINTS`) instead.

    Returns
    -------
    IntensitySums
        ``sum_jk w_j w_k S(lambda + sigma_lambda x_j, theta + sigma_theta x_k)``; without
        bandwidth and angle spread, ``sums(wavelength_nm, theta_deg)`` itself.

    Raises
    ------
    ValueError
        A bandwidth or spread outside its range, a bad number of points, or an angle node
        at or beyond 90 deg (``theta + 7 sigma_theta``).

    Notes
    -----
    The two variables are independent: the average is the tensor product of the two
    one-dimensional rules. The angle spread is taken in the plane of incidence only; the
    rays of a cone that leave it also turn the s and p frames, an effect of the same
    (second) order in the cone's half-angle that this model leaves out. The caller decides
    what varies with the wavelength: ``labbrdf.films.Stack`` holds the materials'
    indices at the centre wavelength, so that only the layers' phases ``2 pi N d cos /
    lambda`` vary over the band (the index changes by ``dn/dlambda`` times a few nm,
    far less than the phase does).
    """
    bw = _check(bandwidth_nm, MAX_BANDWIDTH_NM, "bandwidth_nm", "nm")
    spread = _check(angle_spread_deg, MAX_ANGLE_SPREAD_DEG, "angle_spread_deg", "deg")
    if points is not None and (
        isinstance(points, bool)
        or not isinstance(points, int)
        or not 3 <= points <= MAX_POINTS
        or points % 2 == 0
    ):
        raise ValueError(f"points: expected an odd integer in [3, {MAX_POINTS}], got {points!r}")
    lam = np.asarray(wavelength_nm, float)
    th = np.asarray(theta_deg, float)
    if bw == 0.0 and spread == 0.0:
        return sums(lam, th)
    lam_min = float(np.min(lam))
    s_lam = bw / FWHM_PER_SIGMA
    s_th = np.radians(spread)
    if spread and float(np.max(np.abs(th))) + _REACH * spread >= 90.0:
        raise ValueError(
            f"angle_spread_deg: {spread:g} deg at {float(np.max(np.abs(th))):g} deg reaches "
            f"90 deg within {_REACH:g} sigma; expected a smaller spread or angle"
        )
    phase = 4.0 * np.pi * optical_thickness_nm / lam_min
    x_l, w_l = _rule(s_lam, phase * s_lam / lam_min, points)
    x_t, w_t = _rule(spread, phase * s_th, points)
    total: list | None = None
    for xl, wl in zip(x_l, w_l, strict=True):
        for xt, wt in zip(x_t, w_t, strict=True):
            s = sums(lam + s_lam * xl, th + spread * xt)
            terms = [wl * wt * np.asarray(v) for v in s]
            total = terms if total is None else [a + b for a, b in zip(total, terms, strict=True)]
    assert total is not None
    return IntensitySums(*total)


def _rule(sigma: float, phase_spread: float, points: int | None) -> tuple[NDArray, NDArray]:
    """One node at the centre for a variable that does not vary, else :func:`gaussian_nodes`."""
    if sigma == 0.0:
        return np.zeros(1), np.ones(1)
    return gaussian_nodes(phase_spread, points)
