"""A low-rank basis of the height-dependent escape ``c^Lambda(theta_o)`` over output rows.

In the Heitz et al. (2016) walk a vertex at height ``h`` on the top microsurface sends
its reflected (air side) or refracted (from below) branch out of the microsurface with
the probability ``c^Lambda(w_o)``, ``c = C1(h)`` the height's CDF on the air side. The
branch's expectation over the vertex's visible normal is the single-event BRDF or BTDF
from the vertex's direction with the masking ``G1(w_in) c^Lambda(w_o)``: the separable
kernel with ``G1(w_o)`` replaced by ``c^Lambda(w_o)``. For an isotropic interface
``Lambda(w_o)`` depends on the output polar angle alone, so per output row

    c^Lambda(theta_o) ~ sum_k U_k(c) V_k(row),   k < LEVELS,

with ``V`` the leading right singular vectors of the matrix ``c_j^Lambda(row)`` over a
grid of ``c`` (rows: the cos-weighted mean over the operator's polar nodes of each row)
and ``U_k(c)`` the projection of one vertex's row vector onto them (exact per vertex: no
binning of heights). A vertex is then recorded ``LEVELS`` times, with the weights
``U_k(c)``, into the cells of level ``k``, and one operator without the exit masking
(:mod:`.operator`, ``masking="incident"``) serves every level, its output rows scaled by
``V_k`` (:func:`.estimator.exit_map`).

Notes
-----
Two approximations, both documented in ``docs/tracer.md``: the rank (with 6 levels the
projection's residual, over every ``c``, is below 2.5e-3 in the rows up to 75 deg and
2e-2 in the grazing rows at alpha 0.2 on the 1-degree grid; 1.8e-2 / 0.13 at alpha
0.6, 3e-4 / 1e-3 at alpha 0.2 on the 3 x 6 degree grid)
and the factor's separation from the kernel inside a polar row with several nodes (the
row's mean factor multiplies the row's kernel).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from ..microfacet import ggx
from .binning import Grid
from .evaluate import bin_nodes

__all__ = ["LEVELS", "level_weights", "row_basis"]

#: rank of the expansion (levels of cells per operator)
LEVELS = 6
#: the c grid of the singular value decomposition (dense near c = 0, where c^L is steep)
_C_GRID = np.linspace(0.0, 1.0, 2001) ** 2

F64 = NDArray[np.float64]


def _row_nodes(grid: Grid, alpha: float) -> tuple[F64, F64]:
    """Smith Lambda (n_theta, n) at the operator's polar nodes and their row weights."""
    theta, _, w = bin_nodes(grid, int(np.ceil(grid.theta_step_deg - 1e-9)), 1)
    lam = ggx.smith_lambda(np.cos(theta), alpha)
    return np.asarray(lam, float), w[:, :, 0]


def _factor(lam: F64, w: F64, c: F64) -> F64:
    """Row factors (n, n_theta): the weighted mean over each row's nodes of ``c^Lambda``."""
    with np.errstate(divide="ignore"):
        x = np.power(c[:, None, None], lam[None])
    return np.asarray((x * w[None]).sum(axis=-1), float)


@lru_cache(maxsize=16)
def row_basis(theta_step_deg: float, phi_step_deg: float, alpha: float) -> F64:
    """``V``: (LEVELS, n_theta) orthonormal row vectors of the expansion (module doc)."""
    lam, w = _row_nodes(Grid(theta_step_deg, phi_step_deg), alpha)
    a = _factor(lam, w, _C_GRID)
    # the right singular vectors of a: the eigenvectors of a^T a (n_theta x n_theta), the
    # largest first (their eigenvalues span < 1e-8: squaring the condition costs nothing)
    _, vec = np.linalg.eigh(a.T @ a)
    return np.asarray(vec[:, ::-1][:, :LEVELS].T, float)


def level_weights(grid: Grid, alpha: float, c: F64) -> F64:
    """``U_k(c)``: (n, LEVELS) weights of vertices at air-side height CDF ``c``."""
    v = row_basis(grid.theta_step_deg, grid.phi_step_deg, float(alpha))
    lam, w = _row_nodes(grid, float(alpha))
    return _factor(lam, w, np.clip(np.asarray(c, float), 0.0, 1.0)) @ v.T
