"""Closed-form single-scattering Mueller BRDF/BTDF of one rough interface, bin-averaged.

Pure vectorised physics for the ``estimator="evaluated"`` path (derivation in
``docs/tracer.md``). Directions are unit vectors of shape (3, ...), +z the macroscopic
normal; Stokes frames follow the tracer (LB convention, meridional output frames
``s = phi_hat(phi) = (-sin phi, cos phi, 0)``, see :mod:`.binning`).

Reflection (Walter et al. 2007 eq. (20) with the Fresnel Mueller matrix, Dong 2022
eq. (11)), for an incident propagation direction ``k`` (pointing down) and an exit
direction ``w_o`` (up), ``w_i = -k``, half vector ``m = (w_i + w_o) / |w_i + w_o|``:

    F_r(w_i, w_o) = R(s_loc -> phi_hat(phi_o)) F(w_i . m) R(s_in -> s_loc)
                    D(m) G1(w_i) G1(w_o) / (4 cos theta_i cos theta_o)       [sr^-1]

Transmission from inside a dielectric of index ``n1`` into a medium ``n2`` (Walter et al.
2007 eq. (21)), incident propagation direction ``k_u`` (up), exit ``w_o`` (up); the
refracting normal on the incident side is ``m = (n2 w_o - n1 k_u) / |n2 w_o - n1 k_u|``
(Snell: ``n1 k_u - n2 w_o`` is parallel to the normal), with ``c_i = -k_u . m``,
``c_t = -w_o . m``:

    F_t(k_u, w_o) = R(...) T(c_i) R(...) D(-m) G1(k_u) G1(w_o)
                    n2^2 c_i c_t / (cos theta_u cos theta_o (n1 c_i - n2 c_t)^2)

``T`` is the Fresnel transmission Mueller matrix including the beam factor
``Re(n2 cos_t) / (n1 cos_i)`` (:func:`.interfaces.fresnel_abcs`), so F_t is the power
(not radiance) transfer function, as the tracer's ray weights are.

``G1`` is the separable Smith masking of ``scattering="single"`` (the oracles' model).
With ``scattering="multiple"`` the walk's single events carry the height-correlated
masking instead (:func:`correlated_reflection`, :func:`correlated_transmission`), passed
as ``g2_of``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray
from scipy.special import beta

from .binning import Grid
from .interfaces import apply_fresnel, rotate_frame, s_axis

__all__ = [
    "bin_nodes",
    "cell_centroids",
    "cell_nodes",
    "correlated_reflection",
    "correlated_transmission",
    "reflection_mueller",
    "transmission_mueller",
]

F64 = NDArray[np.float64]
# (cos_i) -> (A, B, C, S) of the Fresnel matrix at the facet
Abcs = Callable[[F64], tuple[F64, F64, F64, F64]]
# (direction (3, n), direction's cosine to its own side's normal) -> D or G1
DFunc = Callable[[F64], F64]
# (direction in, direction out), both as seen from their own side (z > 0) -> G2
G2Func = Callable[[F64, F64], F64]


def correlated_reflection(lambda_of: DFunc) -> G2Func:
    """Height-correlated masking-shadowing of a reflection, ``1 / (1 + L_i + L_o)``.

    The single-scattering term of the Heitz et al. (2016) walk on an uncorrelated Smith
    microsurface (sec. 4; Heitz 2014, eq. (99)): the first hit's height has the CDF
    ``C1(h)^(1 + L_i)``, the reflected ray leaves with ``C1(h)^L_o``, and the visible
    normal carries ``G1(w_i) = 1 / (1 + L_i)``.

    Parameters
    ----------
    lambda_of : callable
        Smith Lambda of directions (3, n) with z > 0.
    """

    def g2(w_i: F64, w_o: F64) -> F64:
        return 1.0 / (1.0 + lambda_of(w_i) + lambda_of(w_o))

    return g2


def correlated_transmission(lambda_of: DFunc) -> G2Func:
    """Height-correlated masking of a refraction, ``B(1 + L_i, 1 + L_o)`` (Beta function).

    From the Heitz et al. (2016) walk (sec. 4-5): a ray arriving from one side's bulk first
    hits at a height ``h`` whose ``x = C1(h)`` has the density ``(1 + L_i) x^L_i``; the
    refracted ray is on the other side of the height field, where the same point lies at
    ``-h`` and ``C1(-h) = 1 - x``, and leaves with ``(1 - x)^L_o``. With the visible
    normal's ``1 / (1 + L_i)``,

        G2_T = int_0^1 x^L_i (1 - x)^L_o dx = B(1 + L_i, 1 + L_o),

    which is ``G1(w_i)`` for ``L_o = 0`` and below ``G1(w_i) G1(w_o)`` otherwise (the
    two sides' masking are anti-correlated in height).

    Parameters
    ----------
    lambda_of : callable
        Smith Lambda of directions (3, n) with z > 0 (the incident direction mirrored to
        its own side, as :func:`transmission_mueller` passes it).
    """

    def g2(w_i: F64, w_o: F64) -> F64:
        return np.asarray(beta(1.0 + lambda_of(w_i), 1.0 + lambda_of(w_o)), float)

    return g2


def bin_nodes(grid: Grid, n_theta: int, n_phi: int) -> tuple[F64, F64, F64]:
    """Gauss-Legendre nodes of the cos-weighted average over each bin.

    The bin average of the counting estimator, ``W / (N Omega_cos)`` (:mod:`.binning`),
    is the average of ``f`` with the weight ``cos(theta) dOmega = sin(theta) cos(theta)
    dtheta dphi``. A product Gauss-Legendre rule in theta and phi with that weight folded
    into the node weights is used (not a rule in sin^2 theta: f is not smooth in
    sin^2 theta at the pole, where it goes like its square root).

    Returns
    -------
    theta : ndarray, shape (n_theta_bins, n_theta) [rad]
        Polar nodes of each polar row.
    dphi : ndarray, shape (n_phi,) [rad]
        Azimuth offsets of the nodes from the bin centre.
    weight : ndarray, shape (n_theta_bins, n_theta, n_phi)
        Weights of the node pairs, summing to 1 in each row.
    """
    x, w = np.polynomial.legendre.leggauss(n_theta)
    t = np.radians(grid.theta_edges_deg)
    lo, hi = t[:-1, None], t[1:, None]
    theta = lo + (hi - lo) * (x[None, :] + 1) / 2
    wt = w[None, :] * np.sin(theta) * np.cos(theta)
    wt = wt / wt.sum(axis=1, keepdims=True)
    xp, wp = np.polynomial.legendre.leggauss(n_phi)
    dphi = xp * np.radians(grid.phi_step_deg) / 2
    weight = wt[:, :, None] * (wp[None, None, :] / 2)
    return theta, dphi, weight


def cell_centroids(grid: Grid) -> F64:
    """Polar angle [rad] of each cell's cos-weighted centroid (midpoint in sin^2 theta).

    Used for the internal up-going cells of the exit operator: the centroid of the first
    cell is off the pole, where the meridional frame is defined.
    """
    t = np.radians(grid.theta_edges_deg)
    return np.arcsin(np.sqrt((np.sin(t[:-1]) ** 2 + np.sin(t[1:]) ** 2) / 2))


def cell_nodes(grid: Grid, rows: int, n_sub: int) -> tuple[NDArray[np.int64], F64, F64]:
    """Polar nodes of the internal cells: ``n_sub`` per cell in the first ``rows`` rows.

    Rows ``>= rows`` keep one node, the cell's centroid (:func:`cell_centroids`). In the
    first ``rows`` polar rows each cell is averaged over ``n_sub`` Gauss-Legendre nodes in
    ``sin^2 theta``, i.e. uniformly in cos-weighted solid angle, as the walk's rays fill a
    cell that is small against the spread of the light inside the coating. The azimuth
    keeps the cell's centre, as the centroid does (sub-nodes across it moved the rows
    near the pole by < 0.1 %, docs/tracer.md).

    Returns
    -------
    row : ndarray of int, shape (q,)
        Polar row of each node.
    theta : ndarray, shape (q,) [rad]
        Polar angle of each node.
    weight : ndarray, shape (q,)
        Node weights, summing to 1 over each row's nodes.
    """
    rows = min(max(rows, 0), grid.n_theta)
    x, w = np.polynomial.legendre.leggauss(n_sub)
    s2 = np.sin(np.radians(grid.theta_edges_deg)) ** 2
    lo, hi = s2[:rows, None], s2[1 : rows + 1, None]
    th = np.arcsin(np.sqrt(lo + (hi - lo) * (x[None, :] + 1) / 2))  # (rows, n_sub)
    row = np.concatenate([np.repeat(np.arange(rows), n_sub), np.arange(rows, grid.n_theta)])
    theta = np.concatenate([th.ravel(), cell_centroids(grid)[rows:]])
    weight = np.concatenate([np.tile(w / 2, rows), np.ones(grid.n_theta - rows)])
    return row, theta, weight


def _phi_hat(w: F64) -> F64:
    phi = np.arctan2(w[1], w[0])
    return np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)])


def reflection_mueller(
    k_in: F64,
    s_in: F64,
    w_o: F64,
    abcs: Abcs,
    d_of: DFunc,
    g1_of: DFunc,
    g2_of: G2Func | None = None,
) -> F64:
    """Point Mueller BRDF of reflection on a rough interface seen from above [sr^-1].

    Parameters
    ----------
    k_in : ndarray, shape (3,) or (3, n)
        Incident propagation direction (k_z < 0).
    s_in : ndarray, shape (3,) or (3, n)
        x axis of the incident Stokes frame.
    w_o : ndarray, shape (3, n)
        Exit directions (w_z > 0).
    abcs : callable
        ``cos_i -> (A, B, C, S)`` of the facet's Fresnel reflection matrix.
    d_of, g1_of : callable
        ``D(m)`` of upward normals (3, n) [sr^-1] and Smith ``G1(w)`` of upward
        directions (3, n).
    g2_of : callable or None
        Joint masking-shadowing ``G2(w_i, w_o)`` in place of ``G1(w_i) G1(w_o)``
        (:func:`correlated_reflection`); None: separable.

    Returns
    -------
    ndarray, shape (4, 4, n)
        Mueller BRDF from the incident frame to ``phi_hat(phi_o)``.
    """
    n = w_o.shape[1]
    k = np.broadcast_to(np.asarray(k_in, float).reshape(3, -1), (3, n)).copy()
    s = np.broadcast_to(np.asarray(s_in, float).reshape(3, -1), (3, n)).copy()
    wi = -k
    h = wi + w_o
    h = h / np.sqrt((h * h).sum(axis=0))
    cos_i = np.clip((wi * h).sum(axis=0), 0.0, 1.0)
    M = np.zeros((4, 4, n))
    for i in range(4):
        M[i, i] = 1.0
    s_loc = s_axis(k, h, s)
    rotate_frame(M, k, s, s_loc)
    apply_fresnel(M, *abcs(cos_i))
    rotate_frame(M, w_o, s_loc, _phi_hat(w_o))
    with np.errstate(divide="ignore", invalid="ignore"):
        g2 = g1_of(wi) * g1_of(w_o) if g2_of is None else g2_of(wi, w_o)
        scale = d_of(h) * g2 / (4.0 * wi[2] * w_o[2])
    scale = np.where((w_o[2] > 0) & (h[2] > 0), scale, 0.0)
    return M * scale


def transmission_mueller(
    k_u: F64,
    w_o: F64,
    n1: float,
    n2: float,
    abcs_t: Abcs,
    d_of: DFunc,
    g1_of: DFunc,
    g2_of: G2Func | None = None,
) -> F64:
    """Point Mueller BTDF from inside a dielectric (index n1) up into n2 [sr^-1].

    Parameters
    ----------
    k_u : ndarray, shape (3, n)
        Incident propagation directions, up-going (k_z > 0) below the interface; their
        Stokes frame is the meridional ``phi_hat(phi_u)``.
    w_o : ndarray, shape (3, n)
        Exit directions above the interface (w_z > 0).
    n1, n2 : float
        Real indices below and above [1].
    abcs_t : callable
        ``cos_i -> (A, B, C, S)`` of the Fresnel transmission matrix n1 -> n2 with the
        beam factor (zero beyond the critical angle).
    d_of, g1_of : callable
        ``D`` and ``G1`` of the interface as seen from *above* (normals and directions
        with z > 0); the lower side's D and G1 follow from them (see the code).
    g2_of : callable or None
        Joint masking ``G2(k_u, w_o)`` in place of ``G1(k_u) G1(w_o)``
        (:func:`correlated_transmission`); None: separable.

    Returns
    -------
    ndarray, shape (4, 4, n)
        Mueller BTDF from ``phi_hat(phi_u)`` to ``phi_hat(phi_o)``.
    """
    n = w_o.shape[1]
    v = n2 * w_o - n1 * k_u
    m = v / np.sqrt((v * v).sum(axis=0))  # points down, into the incident medium
    c_i = -(k_u * m).sum(axis=0)
    c_t = -(w_o * m).sum(axis=0)
    valid = (c_i > 0) & (c_t > 0) & (m[2] < 0) & (w_o[2] > 0) & (k_u[2] > 0)
    c_i = np.clip(c_i, 0.0, 1.0)
    M = np.zeros((4, 4, n))
    for i in range(4):
        M[i, i] = 1.0
    s_u = _phi_hat(k_u)
    s_loc = s_axis(k_u, m, s_u)
    rotate_frame(M, k_u, s_u, s_loc)
    apply_fresnel(M, *abcs_t(c_i))
    rotate_frame(M, w_o, s_loc, _phi_hat(w_o))
    with np.errstate(divide="ignore", invalid="ignore"):
        jac = n2 * n2 * c_i * c_t / (k_u[2] * w_o[2] * (n1 * c_i - n2 * c_t) ** 2)
        # the lower side of the height field: a facet with downward normal m is the
        # facet with upward normal -m, and the masking of the direction w_i = -k_u
        # below is that of k_u above (the mirror image z -> -z of the slope
        # distribution is its point reflection through the origin)
        g2 = g1_of(k_u) * g1_of(w_o) if g2_of is None else g2_of(k_u, w_o)
        scale = d_of(-m) * g2 * jac
    scale = np.where(valid, scale, 0.0)
    return M * scale
