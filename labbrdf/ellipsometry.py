"""The ellipsometric inversion: optical constants from psi, Delta with propagated uncertainties.

Physics layer on top of :mod:`labbrdf.optics` (NumPy and SciPy only, no pandas). The optics
core computes the forward quantities (Fresnel amplitudes, psi and Delta of a given index);
everything that goes back from measured psi, Delta to an index lives here: the two-phase
(ambient / bulk substrate, no film) inversion of every measured point with its first-order
covariance, the ONE condition number of that inversion with its ONE set of thresholds
(:data:`COND_WARN`, :data:`COND_MAX`, :class:`IllConditionedWarning`) that every caller uses,
the inverse-covariance combination of several angles of incidence with a chi-square
consistency test, and Fresnel reflectance predictions with propagated sigma.

Conventions are those of :mod:`labbrdf.optics`: Nebraska psi, Delta (``Delta = 180 deg`` at
normal incidence), ``N = n + ik`` with ``k >= 0``, angles in degrees at the public API.

Uncertainty model
-----------------
``sigma(psi)`` and ``sigma(Delta)`` are taken as independent 1-sigma errors (instrument files
give no psi-Delta correlation), optionally with an independent error of the angle of
incidence. They are propagated to first order, ``C = J diag(sigma^2) J^T``, through the
analytic Jacobian ``J`` of the closed-form inversion (complex differentiation: ``N`` is an
analytic function of ``rho``, so ``dn = Re(dN)`` and ``dk = Im(dN)``). The derivation is in
``docs/ellipsometry.md``.

References
----------
.. [1] R. M. A. Azzam, N. M. Bashara, *Ellipsometry and Polarized Light*, North-Holland
   (1977), section 4.3, eq. (4.94) (two-phase inversion).
.. [2] H. Fujiwara, *Spectroscopic Ellipsometry: Principles and Applications*, Wiley (2007),
   section 5.3.2, eq. (5.95) (pseudo-dielectric function ``<eps>``).
.. [3] M. Born, E. Wolf, *Principles of Optics*, 7th ed., Cambridge University Press (1999),
   section 1.5.2 (Fresnel formulae).
.. [4] P. R. Bevington, D. K. Robinson, *Data Reduction and Error Analysis for the Physical
   Sciences*, 3rd ed., McGraw-Hill (2003), sections 3.2 (error propagation) and 4.1
   (weighted mean); the matrix form is the generalised-least-squares mean.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import optics
from .optics import _angle, _finite, _physical_root, _real_index

__all__ = [
    "COND_MAX",
    "COND_WARN",
    "P_ANGLE_DEPENDENT",
    "CombinedNK",
    "IllConditionedWarning",
    "PseudoNK",
    "Reflectances",
    "combine_angles",
    "condition_number",
    "fresnel_reflectances",
    "nk_from_psi_delta",
    "nk_jacobian",
    "normal_reflectance",
    "pseudo_nk",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Above this condition number [1/rad] the inversion warns (:class:`IllConditionedWarning`):
#: with a psi/Delta accuracy of 0.02 deg (3.5e-4 rad, a typical absolute accuracy of a
#: rotating-element ellipsometer) the relative error of ``|N|`` reaches 1 %. Reached below
#: about 20 deg for Si or Ta, 12 deg for glass. Justification: ``docs/ellipsometry.md``.
COND_WARN = 30.0
#: Above this condition number [1/rad] the inversion is refused where the caller asks for
#: ``on_ill_conditioned="raise"`` (the default of :func:`pseudo_nk`): 0.02 deg of psi or
#: Delta then moves ``|N|`` by more than 10 %, and the index is not determined by the data.
#: Reached below about 6 deg for Si or Ta, 4 deg for glass; the condition number grows as
#: ``1/theta^2`` towards normal incidence.
COND_MAX = 300.0
#: p-value below which the pseudo-constants of several angles are flagged angle-dependent.
P_ANGLE_DEPENDENT = 0.01

OnIll = Literal["raise", "warn", "ignore"]


class IllConditionedWarning(UserWarning):
    """The inversion psi, Delta -> n, k is ill-conditioned (near normal incidence)."""


# --------------------------------------------------------------------------------------
# inversion and its Jacobian
# --------------------------------------------------------------------------------------


def _on_ill(on_ill: str) -> OnIll:
    if on_ill not in ("raise", "warn", "ignore"):
        raise ValueError(
            f"on_ill_conditioned: expected 'raise', 'warn' or 'ignore'; got {on_ill!r}"
        )
    return on_ill  # type: ignore[return-value]


def _check_conditioning(cond: FloatArray, theta_deg: FloatArray, on_ill: OnIll) -> None:
    """Apply the one threshold set (:data:`COND_WARN`, :data:`COND_MAX`) to ``cond``.

    ``theta_deg`` broadcasts against ``cond`` (it names the angle of the worst point). A
    non-finite condition number (``N = 0``) counts as ill-conditioned. ``stacklevel=3``:
    the warning points at the caller of the public function that calls this.
    """
    if _on_ill(on_ill) == "ignore" or cond.size == 0:
        return
    flat = np.ravel(cond)
    worst = int(np.argmax(np.where(np.isnan(flat), np.inf, flat)))
    c_max = float(flat[worst])
    t_at = float(np.ravel(np.broadcast_to(theta_deg, cond.shape))[worst])
    if not c_max <= COND_MAX and on_ill == "raise":
        raise ValueError(
            f"psi/Delta inversion is ill-conditioned: condition number {c_max:.3g} > "
            f"{COND_MAX:g} at theta_i = {t_at:.4g} deg (near normal incidence every sample "
            "gives psi = 45, Delta = 180 deg); measure at a larger angle or pass "
            "on_ill_conditioned='warn'"
        )
    if not c_max <= COND_WARN:
        nbad = int(np.count_nonzero(~(flat <= COND_WARN)))
        warnings.warn(
            f"psi/Delta inversion is ill-conditioned at {nbad} point(s): condition number up "
            f"to {c_max:.3g} (> {COND_WARN:g}) at theta_i = {t_at:.4g} deg; n, k are "
            "sensitive to small psi/Delta errors",
            IllConditionedWarning,
            stacklevel=3,
        )


def nk_from_psi_delta(
    psi_deg: ArrayLike,
    delta_deg: ArrayLike,
    theta_deg: ArrayLike,
    n_ambient: ArrayLike = 1.0,
    *,
    on_ill_conditioned: OnIll = "warn",
) -> ComplexArray:
    """Two-phase (bare substrate) inversion of psi, Delta to ``N = n + ik``.

    Parameters
    ----------
    psi_deg : array_like of float
        Ellipsometric psi in [0, 90] [deg].
    delta_deg : array_like of float
        Ellipsometric Delta in the Nebraska convention [deg]; any finite value (taken
        modulo 360).
    theta_deg : array_like of float
        Angle of incidence in the open interval (0, 90) [deg]: at 0 and 90 deg every
        substrate gives the same (psi, Delta).
    n_ambient : array_like of float, optional
        Real index of the lossless ambient, > 0 [1]. Default 1.
    on_ill_conditioned : {"warn", "raise", "ignore"}
        The condition number (:func:`condition_number`) is checked against the one
        threshold set: above :data:`COND_WARN` an :class:`IllConditionedWarning` names it
        and the angle (default ``"warn"``; near normal incidence every sample gives
        psi -> 45, Delta -> 180 deg and the index is not determined by the data);
        ``"raise"`` also refuses points above :data:`COND_MAX` with a ``ValueError``, as
        :func:`pseudo_nk` does by default; ``"ignore"`` checks nothing.

    Returns
    -------
    ndarray of complex
        The (pseudo-)index ``N = n + ik`` [1]:
        ``N^2 = n0^2 sin^2(theta) [1 + tan^2(theta) ((1 - rho)/(1 + rho))^2]`` with the LB
        ``rho = tan(psi) exp(-i Delta)`` (Azzam and Bashara [1]_ section 4.3;
        docs/models.md section 3.1). Any overlayer or roughness makes it a pseudo-index.

    Raises
    ------
    ValueError
        For non-finite input, ``psi`` outside [0, 90], ``theta`` outside (0, 90), a
        non-real ``n_ambient``, ``(psi, Delta) = (45, 180)`` (``rho = -1``: an infinite
        index), an unknown ``on_ill_conditioned``, or an ill-conditioned point with
        ``on_ill_conditioned="raise"``.

    Notes
    -----
    The root of ``N^2`` is taken with ``Re(N) + Im(N) >= 0`` (branch cut on the negative
    imaginary axis of ``N^2``). For physical data (``Im(N^2) >= 0``) it is the principal
    root with ``n, k >= 0``, as in docs/models.md 3.1. When noise pushes ``Im(N^2)``
    slightly negative, a dielectric-like point (``Re N^2 > 0``) comes back with a small
    ``k < 0`` (reported, not clipped: docs/models.md 3.2), and a metal-like point (``Re N^2 < 0``,
    ``n`` near 0) with a small ``n < 0`` instead of a sign-flipped ``k``.
    """
    on_ill = _on_ill(on_ill_conditioned)
    psi = np.radians(_finite("psi_deg", psi_deg, np.float64))
    if np.any((psi < 0) | (psi > np.pi / 2)):
        raise ValueError("psi_deg: expected psi in [0, 90] deg")
    delta = np.radians(_finite("delta_deg", delta_deg, np.float64))
    theta = np.radians(_angle("theta_deg", theta_deg, open_ends=True))
    n0 = _real_index("n_ambient", n_ambient)
    if np.any((psi == np.pi / 4) & (np.mod(np.degrees(delta), 360.0) == 180.0)):
        raise ValueError("psi_deg, delta_deg: (45, 180) deg means rho = -1, an infinite index")
    rho = np.tan(psi) * np.exp(-1j * delta)
    sin_t = np.sin(theta)
    u = (1.0 - rho) / (1.0 + rho)
    eps = (n0 * sin_t) ** 2 * (1.0 + np.tan(theta) ** 2 * u * u)
    big_n = np.asarray(_physical_root(eps + 0j))
    if on_ill != "ignore":
        cond = condition_number(psi_deg, delta_deg, theta_deg, n0)
        _check_conditioning(cond, np.degrees(theta), on_ill)
    return big_n


def _inputs(psi_deg: ArrayLike, delta_deg: ArrayLike, theta_deg: ArrayLike) -> tuple:
    psi = np.asarray(psi_deg, dtype=float)
    delta = np.asarray(delta_deg, dtype=float)
    theta = np.asarray(theta_deg, dtype=float)
    return np.broadcast_arrays(psi, delta, theta)


def nk_jacobian(
    psi_deg: ArrayLike,
    delta_deg: ArrayLike,
    theta_deg: ArrayLike,
    n_ambient: ArrayLike = 1.0,
) -> tuple[ComplexArray, ComplexArray, ComplexArray, ComplexArray]:
    """The two-phase index and its complex derivatives with respect to psi, Delta, theta.

    Parameters
    ----------
    psi_deg, delta_deg : array_like of float
        Ellipsometric angles, Nebraska convention [deg].
    theta_deg : array_like of float
        Angle of incidence in (0, 90) [deg].
    n_ambient : array_like of float, optional
        Real index of the lossless ambient [1]. Default 1.

    Returns
    -------
    N : ndarray of complex
        ``n + ik`` from :func:`nk_from_psi_delta` [1].
    dN_dpsi, dN_ddelta, dN_dtheta : ndarray of complex
        Derivatives of ``N`` [1/deg]. The real part is the derivative of ``n``, the imaginary
        part that of ``k``.

    Notes
    -----
    With the LB ``rho = tan(psi) exp(-i Delta)``, ``u = (1 - rho)/(1 + rho)`` and
    ``eps = N^2 = n0^2 sin^2(theta) [1 + tan^2(theta) u^2]`` (Azzam and Bashara [1]_
    eq. (4.94), Fujiwara [2]_ eq. (5.95)), the chain rule gives

    * ``dN/drho = n0^2 sin^2 tan^2 u (-2/(1 + rho)^2) / N``,
    * ``drho/dpsi = exp(-i Delta)/cos^2(psi)``, ``drho/dDelta = -i rho``,
    * ``dN/dtheta = n0^2 [2 sin cos + (4 sin^3/cos + 2 sin^5/cos^3) u^2] / (2N)``.

    Every step is analytic in ``rho`` (or real in theta), so these are exact complex
    derivatives; they are checked against central differences in the tests.
    """
    psi, delta, theta = _inputs(psi_deg, delta_deg, theta_deg)
    big_n = nk_from_psi_delta(psi, delta, theta, n_ambient, on_ill_conditioned="ignore")
    p, d, t = np.radians(psi), np.radians(delta), np.radians(theta)
    rho = np.tan(p) * np.exp(-1j * d)
    u = (1.0 - rho) / (1.0 + rho)
    s, c = np.sin(t), np.cos(t)
    n0sq = np.asarray(n_ambient, dtype=float) ** 2
    deps_drho = n0sq * (s * s) * np.tan(t) ** 2 * 2.0 * u * (-2.0 / (1.0 + rho) ** 2)
    dn_drho = deps_drho / (2.0 * big_n)
    deg = np.pi / 180.0
    dn_dpsi = dn_drho * np.exp(-1j * d) / np.cos(p) ** 2 * deg
    dn_ddelta = dn_drho * (-1j * rho) * deg
    deps_dt = n0sq * (2.0 * s * c + (4.0 * s**3 / c + 2.0 * s**5 / c**3) * u * u)
    dn_dtheta = deps_dt / (2.0 * big_n) * deg
    return big_n, dn_dpsi, dn_ddelta, dn_dtheta


def condition_number(
    psi_deg: ArrayLike,
    delta_deg: ArrayLike,
    theta_deg: ArrayLike,
    n_ambient: ArrayLike = 1.0,
) -> FloatArray:
    """Relative condition number of the inversion (psi, Delta) -> N [1/rad].

    The one condition number of the psi/Delta inversion in labbrdf: :func:`nk_from_psi_delta`,
    :func:`pseudo_nk` (its ``cond``), the nk table and report all use it.

    Parameters
    ----------
    psi_deg, delta_deg : array_like of float
        Ellipsometric angles, Nebraska convention [deg].
    theta_deg : array_like of float
        Angle of incidence in (0, 90) [deg].
    n_ambient : array_like of float, optional
        Real index of the ambient [1]. Default 1.

    Returns
    -------
    ndarray of float
        ``kappa = ||J||_2 / |N|`` with ``J`` the real 2x2 Jacobian of ``(n, k)`` with respect
        to ``(psi, Delta)`` in radians: the largest relative change of ``N`` per radian of
        psi/Delta error. ``||J||_2 = |dN/dpsi|`` exactly, because the two columns of ``J``
        are orthogonal with length ratio ``|dN/dDelta| / |dN/dpsi| = sin(psi) cos(psi)
        <= 1/2``.

    Notes
    -----
    Towards normal incidence every substrate gives ``rho -> -1`` (psi -> 45, Delta -> 180)
    and ``kappa`` grows as ``1/theta^2`` (``docs/ellipsometry.md``). See :data:`COND_WARN`
    and :data:`COND_MAX` for the thresholds.
    """
    big_n, dn_dpsi, _, _ = nk_jacobian(psi_deg, delta_deg, theta_deg, n_ambient)
    return _kappa(big_n, dn_dpsi)


def _kappa(big_n: ComplexArray, dn_dpsi_deg: ComplexArray) -> FloatArray:
    """``|dN/dpsi| / |N|`` per radian, from the per-degree derivative of :func:`nk_jacobian`."""
    return np.asarray(np.abs(dn_dpsi_deg) * (180.0 / np.pi) / np.abs(big_n))


@dataclass(frozen=True)
class PseudoNK:
    """Two-phase pseudo-optical constants of each point, with first-order uncertainties.

    Attributes
    ----------
    n, k : ndarray of float
        Real and imaginary part of the pseudo-index ``<N> = n + ik`` [1].
    n_sigma, k_sigma : ndarray of float
        1-sigma uncertainties [1]; NaN where the input sigma is NaN.
    nk_cov : ndarray of float
        Covariance of n and k [1]; NaN where the input sigma is NaN.
    cond : ndarray of float
        Condition number of :func:`condition_number` [1/rad].
    """

    n: FloatArray
    k: FloatArray
    n_sigma: FloatArray
    k_sigma: FloatArray
    nk_cov: FloatArray
    cond: FloatArray

    def covariance(self) -> FloatArray:
        """The ``(..., 2, 2)`` covariance matrices of ``(n, k)`` [1]."""
        return np.stack(
            [
                np.stack([self.n_sigma**2, self.nk_cov], axis=-1),
                np.stack([self.nk_cov, self.k_sigma**2], axis=-1),
            ],
            axis=-2,
        )


def pseudo_nk(
    psi_deg: ArrayLike,
    delta_deg: ArrayLike,
    theta_deg: ArrayLike,
    psi_sigma_deg: ArrayLike = np.nan,
    delta_sigma_deg: ArrayLike = np.nan,
    *,
    theta_sigma_deg: ArrayLike = 0.0,
    n_ambient: float = 1.0,
    on_ill_conditioned: OnIll = "raise",
) -> PseudoNK:
    """Two-phase pseudo-optical constants per point with propagated uncertainties.

    Parameters
    ----------
    psi_deg, delta_deg : array_like of float
        Ellipsometric angles, Nebraska convention [deg].
    theta_deg : array_like of float
        Angle of incidence in (0, 90) [deg].
    psi_sigma_deg, delta_sigma_deg : array_like of float, optional
        1-sigma errors of psi and Delta [deg], independent. NaN (default): unknown, and
        every output sigma is NaN.
    theta_sigma_deg : array_like of float, optional
        1-sigma error of the angle of incidence [deg], independent of psi/Delta. Default 0.
    n_ambient : float, optional
        Real index of the ambient [1]. Default 1.
    on_ill_conditioned : {"raise", "warn", "ignore"}
        What to do when a point's condition number (:func:`condition_number`) exceeds
        :data:`COND_MAX`: raise a ``ValueError`` naming the condition number and the angle
        (default), or only warn. Points above :data:`COND_WARN` always warn
        (:class:`IllConditionedWarning`) unless ``"ignore"``. The same rule as
        :func:`nk_from_psi_delta`, whose default is ``"warn"``.

    Returns
    -------
    PseudoNK
        ``n, k, n_sigma, k_sigma, nk_cov, cond`` broadcast over the inputs.

    Raises
    ------
    ValueError
        For invalid input (as :func:`nk_from_psi_delta`), or an
        ill-conditioned point with ``on_ill_conditioned="raise"``.

    Notes
    -----
    ``<N>`` is the index of the bare substrate that reproduces (psi, Delta) at that angle
    (Fujiwara [2]_ section 5.3.2); an overlayer or roughness makes it depend on the angle.
    Covariance ``C = J diag(s_psi^2, s_Delta^2, s_theta^2) J^T`` (Bevington [4]_ eq. (3.13))
    with the analytic ``J`` of :func:`nk_jacobian`.
    """
    psi, delta, theta = _inputs(psi_deg, delta_deg, theta_deg)
    big_n, d_psi, d_delta, d_theta = nk_jacobian(psi, delta, theta, n_ambient)
    cond = _kappa(big_n, d_psi)
    _check_conditioning(cond, theta, on_ill_conditioned)
    s_psi = np.asarray(psi_sigma_deg, dtype=float)
    s_delta = np.asarray(delta_sigma_deg, dtype=float)
    s_theta = np.asarray(theta_sigma_deg, dtype=float)
    for name, s in (
        ("psi_sigma_deg", s_psi),
        ("delta_sigma_deg", s_delta),
        ("theta_sigma_deg", s_theta),
    ):
        if np.any(s < 0) or np.any(np.isinf(s)):
            raise ValueError(f"{name}: expected finite values >= 0 (NaN: unknown)")
    cols = [(d_psi, s_psi), (d_delta, s_delta), (d_theta, s_theta)]
    var_n = sum((d.real * s) ** 2 for d, s in cols)
    var_k = sum((d.imag * s) ** 2 for d, s in cols)
    cov = sum(d.real * d.imag * s * s for d, s in cols)
    return PseudoNK(
        n=np.asarray(big_n.real, dtype=float),
        k=np.asarray(big_n.imag, dtype=float),
        n_sigma=np.asarray(np.sqrt(var_n), dtype=float),
        k_sigma=np.asarray(np.sqrt(var_k), dtype=float),
        nk_cov=np.asarray(cov, dtype=float),
        cond=np.asarray(cond, dtype=float),
    )


# --------------------------------------------------------------------------------------
# several angles of incidence
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CombinedNK:
    """Combined estimate of ``(n, k)`` at one wavelength from several points.

    Attributes
    ----------
    n, k : float
        Combined pseudo-index [1].
    n_sigma, k_sigma, nk_cov : float
        Its 1-sigma uncertainties and covariance [1] (NaN when they cannot be estimated).
    chi2 : float
        Angle-to-angle consistency chi-square [1]; NaN for the scatter rule.
    dof : int
        Degrees of freedom of the test [1]: ``2 (m - 1)`` (sigma rule) or ``m - 2``
        (scatter rule); 0 when there is nothing to test.
    p_value : float
        Probability of a statistic at least as large for angle-independent constants [1];
        NaN when ``dof = 0``.
    angle_dependent : bool
        ``p_value < alpha`` (default :data:`P_ANGLE_DEPENDENT`).
    method : str
        ``"sigma"`` (inverse-covariance weighting), ``"scatter"`` (no sigma: mean and
        scatter) or ``"single"`` (one point).
    n_points, n_angles : int
        Number of points and of distinct angles of incidence combined.
    """

    n: float
    k: float
    n_sigma: float
    k_sigma: float
    nk_cov: float
    chi2: float
    dof: int
    p_value: float
    angle_dependent: bool
    method: str
    n_points: int
    n_angles: int


def _scatter_test(theta: FloatArray, y: FloatArray) -> float:
    """Two-sided p-value of the least-squares slope of ``y`` against ``theta``."""
    from scipy import stats  # here, not at the top: scipy.stats costs ~1 s to import

    res = stats.linregress(theta, y)
    if res.stderr == 0:
        return 0.0 if res.slope != 0 else 1.0
    tstat = res.slope / res.stderr
    return float(2.0 * stats.t.sf(abs(tstat), theta.size - 2))


def combine_angles(
    n: ArrayLike,
    k: ArrayLike,
    theta_deg: ArrayLike,
    cov: ArrayLike | None = None,
    *,
    alpha: float = P_ANGLE_DEPENDENT,
) -> CombinedNK:
    """Combine the pseudo-constants of several angles at one wavelength.

    Parameters
    ----------
    n, k : array_like of float, shape (m,)
        Pseudo-index of each point [1].
    theta_deg : array_like of float, shape (m,)
        Angle of incidence of each point [deg].
    cov : array_like of float, shape (m, 2, 2), optional
        Covariance of ``(n, k)`` of each point [1] (:meth:`PseudoNK.covariance`). None or
        any NaN: the scatter rule is used.
    alpha : float, optional
        Significance level of the ``angle_dependent`` flag. Default 0.01.

    Returns
    -------
    CombinedNK

    Notes
    -----
    *Sigma rule* (every point has a covariance): the generalised-least-squares mean
    ``x = W^-1 sum C_i^-1 x_i``, ``W = sum C_i^-1``, with covariance ``W^-1``
    (Bevington [4]_ eq. (4.17) in matrix form), and ``chi2 = sum (x_i - x)^T C_i^-1
    (x_i - x)`` with ``2 (m - 1)`` degrees of freedom. A film or roughness makes the
    pseudo-constants angle-dependent and ``chi2`` large; so does an error of the angle of
    incidence or a sigma that leaves out systematic errors (the instrument's sigmas are
    usually repeatability only).

    *Scatter rule* (no sigma): ``x`` is the plain mean, its covariance the sample
    covariance over ``m`` (needs ``m >= 2``). Angle dependence is tested by the
    least-squares slope of ``n`` and of ``k`` against theta, each with a two-sided t-test
    on ``m - 2`` degrees of freedom (needs ``m >= 3`` and two distinct angles); the
    reported p-value is the Bonferroni ``min(1, 2 min(p_n, p_k))``, and ``chi2`` is NaN.
    """
    n = np.atleast_1d(np.asarray(n, dtype=float))
    k = np.atleast_1d(np.asarray(k, dtype=float))
    theta = np.atleast_1d(np.asarray(theta_deg, dtype=float))
    if not (n.shape == k.shape == theta.shape) or n.ndim != 1 or n.size == 0:
        raise ValueError("n, k, theta_deg: expected equal-length 1-d arrays with >= 1 point")
    m = n.size
    n_angles = int(np.unique(theta).size)
    c = None if cov is None else np.asarray(cov, dtype=float).reshape(m, 2, 2)
    nan = float("nan")
    if m == 1:
        s_n, s_k, s_nk = (nan, nan, nan) if c is None else (c[0, 0, 0], c[0, 1, 1], c[0, 0, 1])
        return CombinedNK(
            float(n[0]), float(k[0]), float(np.sqrt(s_n)), float(np.sqrt(s_k)), float(s_nk),
            nan, 0, nan, False, "single", 1, 1,
        )  # fmt: skip
    x = np.stack([n, k], axis=-1)
    if c is not None and np.all(np.isfinite(c)):
        from scipy import stats  # here, not at the top: scipy.stats costs ~1 s to import

        w_i = np.linalg.pinv(c, hermitian=True)
        w = w_i.sum(axis=0)
        cov_mean = np.linalg.pinv(w, hermitian=True)
        mean = cov_mean @ np.einsum("mij,mj->i", w_i, x)
        r = x - mean
        chi2 = float(np.einsum("mi,mij,mj->", r, w_i, r))
        dof = 2 * (m - 1)
        p = float(stats.chi2.sf(chi2, dof))
        return CombinedNK(
            float(mean[0]), float(mean[1]),
            float(np.sqrt(cov_mean[0, 0])), float(np.sqrt(cov_mean[1, 1])),
            float(cov_mean[0, 1]), chi2, dof, p, bool(p < alpha), "sigma", m, n_angles,
        )  # fmt: skip
    mean = x.mean(axis=0)
    cov_mean = np.cov(x, rowvar=False) / m
    if m >= 3 and n_angles >= 2:
        p_n = _scatter_test(theta, n)
        p_k = _scatter_test(theta, k)
        p = min(1.0, 2.0 * min(p_n, p_k))
        dof = m - 2
    else:
        p, dof = nan, 0
    return CombinedNK(
        float(mean[0]), float(mean[1]),
        float(np.sqrt(cov_mean[0, 0])), float(np.sqrt(cov_mean[1, 1])), float(cov_mean[0, 1]),
        nan, dof, p, bool(p < alpha), "scatter", m, n_angles,
    )  # fmt: skip


# --------------------------------------------------------------------------------------
# Fresnel predictions
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Reflectances:
    """Fresnel power reflectances with propagated 1-sigma uncertainties.

    Attributes
    ----------
    rs, rp, r : ndarray of float
        ``|rs|^2``, ``|rp|^2`` and their mean (unpolarised light) [1].
    rs_sigma, rp_sigma, r_sigma : ndarray of float
        1-sigma uncertainties [1]; NaN where the sigma of n or k is NaN.
    """

    rs: FloatArray
    rp: FloatArray
    r: FloatArray
    rs_sigma: FloatArray
    rp_sigma: FloatArray
    r_sigma: FloatArray


def _amplitude_derivatives(
    big_n: ComplexArray, theta_deg: FloatArray, n_ambient: float
) -> tuple[ComplexArray, ComplexArray]:
    """``drs/dN``, ``drp/dN`` of the LB amplitudes of :func:`labbrdf.optics.fresnel`.

    With ``m = N/n0``, ``c = cos theta``, ``w = m cos_t = sqrt(m^2 - sin^2 theta)``:
    ``rs = (c - w)/(c + w)`` and ``rp = (m^2 c - w)/(m^2 c + w)`` give
    ``drs/dm = -2 c m / (w (c + w)^2)`` and ``drp/dm = 2 m c (2 w^2 - m^2) / (w (m^2 c + w)^2)``
    (at normal incidence ``-2/(1 + m)^2`` and ``2/(1 + m)^2``).
    """
    m = big_n / n_ambient
    t = np.radians(theta_deg)
    c, s = np.cos(t), np.sin(t)
    w = np.sqrt(m * m - s * s + 0j)
    w = np.where(w.real + w.imag < 0, -w, w)  # the physical root, as optics._physical_root
    with np.errstate(divide="ignore", invalid="ignore"):
        drs = -2.0 * c * m / (w * (c + w) ** 2)
        drp = 2.0 * m * c * (2.0 * w * w - m * m) / (w * (m * m * c + w) ** 2)
    return drs / n_ambient, drp / n_ambient


def _sigma_from_gradient(
    g_n: FloatArray, g_k: FloatArray, s_n: FloatArray, s_k: FloatArray, cov: FloatArray
) -> FloatArray:
    var = (g_n * s_n) ** 2 + (g_k * s_k) ** 2 + 2.0 * g_n * g_k * cov
    return np.sqrt(np.maximum(var, 0.0))


def fresnel_reflectances(
    n: ArrayLike,
    k: ArrayLike,
    theta_i_deg: ArrayLike,
    *,
    n_sigma: ArrayLike = np.nan,
    k_sigma: ArrayLike = np.nan,
    nk_cov: ArrayLike = 0.0,
    n_ambient: float = 1.0,
) -> Reflectances:
    """Fresnel ``R_s``, ``R_p`` and their mean from ``(n, k)`` with propagated sigma.

    Parameters
    ----------
    n, k : array_like of float
        Substrate index ``N = n + ik`` (``n, k >= 0``) [1].
    theta_i_deg : array_like of float
        Angle of incidence in [0, 90] [deg].
    n_sigma, k_sigma : array_like of float, optional
        1-sigma uncertainties of n and k [1]; NaN (default): unknown.
    nk_cov : array_like of float, optional
        Covariance of n and k [1]. Default 0.
    n_ambient : float, optional
        Real index of the ambient [1]. Default 1.

    Returns
    -------
    Reflectances

    Notes
    -----
    Values from :func:`labbrdf.optics.reflectance` (Born and Wolf [3]_ 1.5.2). First-order
    propagation with ``dR/dn = 2 Re(r* dr/dN)``, ``dR/dk = -2 Im(r* dr/dN)`` (``R = |r|^2``
    and ``dr/dk = i dr/dN`` for the analytic ``r(N)``), ``dr/dN`` in closed form.
    """
    n_arr, k_arr, th = np.broadcast_arrays(
        np.asarray(n, dtype=float), np.asarray(k, dtype=float), np.asarray(theta_i_deg, float)
    )
    big_n = n_arr + 1j * k_arr
    rs, rp, _, _ = optics.fresnel(n_ambient, big_n, th)
    drs, drp = _amplitude_derivatives(big_n, th, n_ambient)
    s_n, s_k, cov = (np.asarray(v, dtype=float) for v in (n_sigma, k_sigma, nk_cov))
    out = {}
    grads = {}
    for name, r, dr in (("rs", rs, drs), ("rp", rp, drp)):
        prod = np.conj(r) * dr
        g_n, g_k = 2.0 * prod.real, -2.0 * prod.imag
        grads[name] = (g_n, g_k)
        out[name] = np.abs(r) ** 2
        out[name + "_sigma"] = _sigma_from_gradient(g_n, g_k, s_n, s_k, cov)
    g_n = 0.5 * (grads["rs"][0] + grads["rp"][0])
    g_k = 0.5 * (grads["rs"][1] + grads["rp"][1])
    return Reflectances(
        rs=np.asarray(out["rs"]),
        rp=np.asarray(out["rp"]),
        r=np.asarray(0.5 * (out["rs"] + out["rp"])),
        rs_sigma=np.asarray(out["rs_sigma"]),
        rp_sigma=np.asarray(out["rp_sigma"]),
        r_sigma=np.asarray(_sigma_from_gradient(g_n, g_k, s_n, s_k, cov)),
    )


def normal_reflectance(
    n: ArrayLike,
    k: ArrayLike,
    *,
    n_sigma: ArrayLike = np.nan,
    k_sigma: ArrayLike = np.nan,
    nk_cov: ArrayLike = 0.0,
    n_ambient: float = 1.0,
) -> tuple[FloatArray, FloatArray]:
    """Normal-incidence reflectance ``((n - n0)^2 + k^2)/((n + n0)^2 + k^2)`` with sigma.

    Parameters
    ----------
    n, k : array_like of float
        Substrate index ``N = n + ik`` [1].
    n_sigma, k_sigma, nk_cov : array_like of float, optional
        Uncertainties and covariance of n, k [1]; NaN sigma (default): unknown.
    n_ambient : float, optional
        Real index of the ambient ``n0`` [1]. Default 1.

    Returns
    -------
    R, R_sigma : ndarray of float
        Reflectance and its first-order 1-sigma uncertainty [1] (Born and Wolf [3]_
        eq. 1.5 (64) with a complex index), from :func:`fresnel_reflectances` at 0 deg.
    """
    res = fresnel_reflectances(
        n, k, 0.0, n_sigma=n_sigma, k_sigma=k_sigma, nk_cov=nk_cov, n_ambient=n_ambient
    )
    return res.r, res.r_sigma
