"""Multiple scattering over a Lambertian base, tabulated over the top's roughness.

:mod:`.coated_lambert_ms` estimates ``T(theta)``, ``R`` and the first surface's higher
orders with Heitz walks [1]_ at every new ``(n_coat, alpha)``: about 4 s of CPU, which a
fit pays at almost every evaluation (its finite differences and its global stage visit a
new ``alpha_top`` nearly every time). The walks depend on ``alpha`` smoothly, so here they
are run once on nodes uniform in ``ln alpha`` spanning the ``layered`` model's bounds of
``alpha_top`` (:data:`ALPHA_RANGE`, one node beyond each end), with the same fixed seeds
at every node (common random numbers), and interpolated with a cubic spline in
``ln alpha`` (twice continuously differentiable: a fit's finite differences see no
jumps). An evaluation is then a few spline evaluations.

* ``T(theta)`` at :data:`.coated_lambert.TABLE_DEG` and ``R``: one table per coating
  (index, absorption) and seed (:func:`ms_table`);
* the first surface's orders >= 2, binned: one table per coating, incidence, grid and
  seed (:func:`higher_orders_table`).

Both are kept in memory (bounded :func:`functools.lru_cache`) and on disk through
:mod:`labbrdf.tracer.cache` (verified on load; the key hashes every input, the walk
counts, the nodes and the source of the walk, so a file from other code or other inputs is
never read as this one).

Errors. The spline's interpolation error, measured against the smooth single-scattering
closed forms tabulated the same way (``docs/tracer.md``), is at most 1.9e-4 in ``T`` and
2.4e-4 in ``R`` (both near ``alpha`` 1; in ``T`` below 2.5e-5 up to ``alpha`` 0.6): below
the walks' own Monte Carlo error at these walk counts (:data:`NODE_RAYS`; ``R`` 1.1e-3,
``T`` 3e-5-3e-4) except in ``T`` near ``alpha`` 1, where it is of that order. The walks
per node are fewer than the direct form's: the Monte Carlo error of a fitted parameter is
measured by seed replicates (``layered``'s ``seed``: every walk's seed moves with it),
which the fit adds to its error (:func:`labbrdf.fitting.combine_replicates`).

References
----------
.. [1] Heitz E., Hanika J., d'Eon E., Dachsbacher C., "Multiple-scattering microfacet
   BSDFs with the Smith model", ACM TOG 35(4), 58 (2016), sec. 4-5.
   doi:10.1145/2897824.2925943
"""

from __future__ import annotations

import hashlib
import inspect
import math
from collections.abc import Callable
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from . import cache as _cache
from . import coated_lambert_ms as _ms
from .binning import Grid
from .coated_lambert import TABLE_DEG
from .coated_lambert_ms import CoatedLambertMS

__all__ = [
    "ALPHA_RANGE",
    "NODE_RAYS",
    "NODE_STEP",
    "alpha_nodes",
    "clear_memory",
    "higher_orders_table",
    "in_range",
    "ms_table",
    "tabulated_first_surface",
    "tabulated_ms",
]

F64 = NDArray[np.float64]

#: the range of ``alpha`` the tables cover: the ``layered`` model's bounds of alpha_top
ALPHA_RANGE = (0.02, 1.0)
#: node spacing in ``ln alpha`` (interpolation error: module docstring)
NODE_STEP = 0.25
#: walks per node: per table angle of T, for R (a square number), per incidence for the
#: higher orders
NODE_RAYS = (2_500, 160_000, 40_000)
#: the seed of seed 0; seed ``s`` walks with ``SEED + 1000 s`` (+1, +2, +3 per walk)
SEED = _ms.SEED
#: format tag of the disk cache's keys (bumped when the tables change meaning)
_FORMAT = "coated-lambert-ms-table 1"


def alpha_nodes() -> F64:
    """The nodes ``ln alpha`` [1]: step :data:`NODE_STEP`, one beyond each end of the range."""
    lo, hi = (math.log(a) for a in ALPHA_RANGE)
    n = math.ceil((hi - lo) / NODE_STEP - 1e-9)
    return np.asarray(lo + NODE_STEP * np.arange(-1, n + 1), float)


def in_range(alpha: float) -> bool:
    """Whether ``alpha`` lies inside :data:`ALPHA_RANGE` (where the tables apply)."""
    return ALPHA_RANGE[0] <= alpha <= ALPHA_RANGE[1]


def _walk_seed(seed: int) -> int:
    return SEED + 1000 * int(seed)


@lru_cache(maxsize=1)
def _code_digest() -> str:
    """A digest of the walk's source: a table built by other code is another table.

    The walk, its distribution, heights and Fresnel numbers, the binning of the higher
    orders and this module (a changed source only costs a rebuild).
    """
    import sys

    from ..microfacet import ggx, height, interface
    from . import binning, interfaces

    h = hashlib.blake2b(digest_size=16)
    for mod in (_ms, ggx, height, interface, interfaces, binning, sys.modules[__name__]):
        h.update(inspect.getsource(mod).encode())
    return h.hexdigest()


def _key(*parts: object) -> str:
    """32 hex digits of everything a table depends on."""
    text = repr((_FORMAT, _code_digest(), *parts))
    return hashlib.blake2b(text.encode(), digest_size=16).hexdigest()


def _cached(key: str, shape: tuple[int, ...], build: Callable[[], F64]) -> F64:
    """The array of ``key`` from the disk cache, or built and stored."""
    got = _cache.load(key, shape, np.float64)
    if got is not None:
        return np.asarray(got, float)
    out = np.ascontiguousarray(build(), float)
    if out.shape != shape:
        raise AssertionError(f"table shape {out.shape} != {shape}")
    _cache.store(key, out)
    return out


def _node_tr(n_coat: float, alpha: float, absorption: tuple, seed: int, rays: tuple) -> F64:
    """``[T (46), se of T (46), R, se of R]`` at one node, walks of seed ``seed``."""
    ws = _walk_seed(seed)
    t, t_se = _ms.transmittance_table(n_coat, alpha, absorption, rays[0], ws)
    r, r_se = _ms.internal_reflectance_ms(n_coat, alpha, absorption, rays[1], ws)
    return np.concatenate([t, t_se, [r, r_se]])


def ms_table(
    n_coat: float,
    k_coat: float = 0.0,
    thickness_nm: float = 0.0,
    wavelength_nm: float = 550.0,
    seed: int = 0,
) -> tuple[CubicSpline, CubicSpline, F64, F64]:
    """Splines in ``ln alpha`` of ``T`` (at :data:`.coated_lambert.TABLE_DEG`) and ``R``.

    Parameters
    ----------
    n_coat : float
        Real index of the coating [1].
    k_coat, thickness_nm, wavelength_nm : float
        Beer-Lambert absorption (extinction coefficient [1], thickness [nm], wavelength
        [nm]).
    seed : int
        Replicate seed of the walks.

    A clear coating (``k_coat`` or ``thickness_nm`` 0) has one table whatever the
    wavelength (the walks do not depend on it).

    Returns
    -------
    spline_t, spline_r : CubicSpline
        ``T`` (46 values) and ``R`` against ``ln alpha``.
    t_se, r_se : ndarray
        Their standard errors at the nodes (nodes, 46) and (nodes,) [1].
    """
    ab = (float(k_coat), float(thickness_nm), float(wavelength_nm))
    if k_coat == 0 or thickness_nm == 0:  # no absorption: one table for every wavelength
        ab = (0.0, 0.0, 550.0)
    return _ms_table(float(n_coat), ab, int(seed), tuple(map(float, alpha_nodes())), NODE_RAYS)


@lru_cache(maxsize=8)
def _ms_table(
    n_coat: float, ab: tuple[float, float, float], seed: int, nodes: tuple, rays: tuple
) -> tuple[CubicSpline, CubicSpline, F64, F64]:
    """:func:`ms_table`, kept per inputs, nodes and walk counts."""
    x = np.asarray(nodes, float)
    m = TABLE_DEG.size

    def build() -> F64:
        return np.stack([_node_tr(n_coat, math.exp(v), ab, seed, rays) for v in x])

    arr = _cached(_key("tr", n_coat, ab, seed, nodes, rays), (x.size, 2 * m + 2), build)
    return (
        CubicSpline(x, arr[:, :m], axis=0),
        CubicSpline(x, arr[:, 2 * m]),
        arr[:, m : 2 * m],
        arr[:, 2 * m + 1],
    )


def higher_orders_table(
    n_coat: float, theta_i_deg: float, grid_deg: tuple[float, float], seed: int = 0
) -> tuple[CubicSpline, F64]:
    """Spline in ``ln alpha`` of the first surface's orders >= 2, binned [sr^-1].

    :func:`.coated_lambert_ms.higher_orders_map` at every node, on the grid of steps
    ``grid_deg`` (theta, phi) [deg]; returns the spline (values (n_theta, n_phi)) and the
    standard error of the higher orders' albedo at the nodes [1].
    """
    grid = (float(grid_deg[0]), float(grid_deg[1]))
    args = (float(n_coat), float(theta_i_deg), grid, int(seed))
    return _higher_orders_table(*args, tuple(map(float, alpha_nodes())), NODE_RAYS)


#: higher-order tables kept in memory: a joint fit of 13 incidences keeps each of its own;
#: at most ~10 MB each (18 nodes of a 1 x 2 degree grid, spline coefficients)
_HIGHER_KEPT = 16


@lru_cache(maxsize=_HIGHER_KEPT)
def _higher_orders_table(
    n_coat: float,
    theta_i_deg: float,
    grid_deg: tuple[float, float],
    seed: int,
    nodes: tuple,
    rays: tuple,
) -> tuple[CubicSpline, F64]:
    """:func:`higher_orders_table`, kept per inputs, nodes and walk counts."""
    grid = Grid(*grid_deg)
    x = np.asarray(nodes, float)
    size = grid.n_theta * grid.n_phi

    def build() -> F64:
        rows = []
        for v in x:
            hi, se = _ms.higher_orders_map(
                n_coat, math.exp(v), theta_i_deg, grid, rays[2], _walk_seed(seed)
            )
            rows.append(np.concatenate([hi.ravel(), [se]]))
        return np.stack(rows)

    key = _key("hi", n_coat, theta_i_deg, grid_deg, seed, nodes, rays)
    arr = _cached(key, (x.size, size + 1), build)
    maps = arr[:, :size].reshape(x.size, grid.n_theta, grid.n_phi)
    return CubicSpline(x, maps, axis=0), arr[:, size]


def clear_memory() -> None:
    """Forget the tables kept in memory (the disk cache is left alone)."""
    _ms_table.cache_clear()
    _higher_orders_table.cache_clear()


def tabulated_ms(
    n_coat: float,
    alpha: float,
    k_coat: float = 0.0,
    thickness_nm: float = 0.0,
    wavelength_nm: float = 550.0,
    seed: int = 0,
) -> CoatedLambertMS:
    """:class:`.coated_lambert_ms.CoatedLambertMS` from the tables at ``alpha`` (in range).

    ``T`` and ``R`` are the splines' values; their standard errors are those of the
    nearest node (the walks are the same at every node).

    Raises
    ------
    ValueError
        ``alpha`` outside :data:`ALPHA_RANGE`.
    """
    if not in_range(alpha):
        raise ValueError(f"alpha {alpha!r} is outside the tabulated range {ALPHA_RANGE}")
    st, sr, t_se, r_se = ms_table(n_coat, k_coat, thickness_nm, wavelength_nm, seed)
    x = math.log(alpha)
    j = int(np.argmin(np.abs(alpha_nodes() - x)))
    table = np.asarray(st(x), float)
    return CoatedLambertMS(
        float(n_coat),
        float(alpha),
        float(sr(x)),
        CubicSpline(TABLE_DEG, table),
        (t_se[j], float(r_se[j])),
    )


def tabulated_first_surface(
    first_single: F64, n_coat: float, alpha: float, theta_i_deg: float, grid: Grid, seed: int = 0
) -> F64:
    """The first surface's map with all orders [sr^-1] from the higher-order table.

    ``first_single``: the single event's closed-form map on ``grid`` (n_theta, n_phi);
    multiplied by :func:`.coated_lambert_ms.height_correlation`, plus the tabulated
    orders >= 2 at ``alpha`` (as :func:`.coated_lambert_ms.first_surface_ms`).
    """
    if not in_range(alpha):
        raise ValueError(f"alpha {alpha!r} is outside the tabulated range {ALPHA_RANGE}")
    spline, _ = higher_orders_table(
        float(n_coat), float(theta_i_deg), (grid.theta_step_deg, grid.phi_step_deg), seed
    )
    row = _ms.height_correlation(alpha, theta_i_deg, grid)
    return np.asarray(first_single * row[:, None] + spline(math.log(alpha)), float)
