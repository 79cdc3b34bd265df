"""The exit through a rough top interface as a linear operator on internal up-going cells.

The weighted walk of ``estimator="evaluated"`` records, just below the top interface,
every up-going ray's Mueller matrix in the meridional frame ``phi_hat(phi_u)`` of its
direction, summed in cells of the exit grid (polar cells 0..90 deg, the same azimuth
cells). The exit BRDF is then

    f(bin o) = (1 / N) sum_cells T10(o, u) W(u),

``T10(o, u)`` the cos-weighted bin average of the closed-form BTDF
(:func:`.evaluate.transmission_mueller`) from the cell's centroid direction. The interface
is statistically isotropic, so in meridional frames ``T10`` depends on the polar bin, the
polar cell and the azimuth difference only: the azimuth sum is a circular convolution,
done with real FFTs. Mirror symmetry about the plane of incidence gives
``T10(-dphi) = P T10(dphi) P``, ``P = diag(1, 1, -1, -1)``, so only ``dphi`` in [0, 180]
deg is evaluated.

Storage: the spectrum in complex64 (float32 parts), shape (n_freq, 4 n_theta, 4 n_cells):
91 x 91 x 181 x 16 x 8 bytes = 192 MB for the 1-degree grid. The cell discretisation
(each ray treated as if it left from its cell's centroid, or, where cells are wide
against the exit lobe, as spread evenly over its cell's polar extent: :func:`cell_rule`)
is the operator's only approximation (docs/tracer.md).
"""

from __future__ import annotations

import hashlib
import json
import time
from collections import OrderedDict
from collections.abc import Generator, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from contextlib import contextmanager
from contextvars import ContextVar, copy_context
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..microfacet import ggx
from . import cache as _cache
from .binning import Grid
from .cache import cache_dir
from .evaluate import (
    bin_nodes,
    cell_nodes,
    correlated_transmission,
    reflection_mueller,
    transmission_mueller,
)
from .exit_sampled import lobe_width_rad
from .interfaces import fresnel_abcs

__all__ = [
    "ExitOperator",
    "build_exit_operator",
    "cache_dir",
    "exit_operator",
    "exit_operators",
    "memory_cache",
]

# part of the cache key: bump when the operator's definition or its file format changes
VERSION = 3

#: operators kept in memory inside :func:`memory_cache` (None outside: the disk cache)
_MEMORY: ContextVar[OrderedDict[str, ExitOperator] | None] = ContextVar(
    "labbrdf_tracer_operator_memory", default=None
)
#: operators :func:`memory_cache` keeps (the most recently used): the four of one
#: parameter set with multiple scattering (:func:`.estimator.exit_map`)
MEMORY_OPERATORS = 4

#: polar sub-cell nodes per unit of (the cell's image in the air / the exit lobe)
CELL_NODES_PER_LOBE = 2.5
#: at most this many polar sub-cell nodes
CELL_MAX_NODES = 6

#: the masking of the operator's kernel: separable ``G1 G1`` (single scattering), the
#: height-correlated ``B(1 + L_i, 1 + L_o)`` of the multiple-scattering walk's single
#: refraction (:func:`.evaluate.correlated_transmission`), or ``G1(w_in)`` alone (the exit
#: masking applied per output row by the caller, :mod:`.height_basis`)
MASKINGS = ("separable", "correlated", "incident")
#: the kernel: transmission from below (the exit), or reflection of rays going down on
#: the air side (the multiple-scattering walk's later vertices)
#: the air side of rays going up that hit the microsurface again ("reflection_away",
#: the multiple-scattering walk's later vertices; masking "incident" only)
KINDS = ("transmission", "reflection", "reflection_away")

PARITY = np.array([1, 1, -1, -1])[:, None] * np.array([1, 1, -1, -1])[None, :]


@dataclass(frozen=True)
class ExitOperator:
    """Spectrum of ``T10`` over the azimuth difference, complex64.

    Attributes
    ----------
    spectrum : ndarray, shape (n_phi // 2 + 1, 4 n_theta, 4 n_cells), complex64
        ``rfft`` over ``dphi`` of ``T10[o_theta, i, u_theta, k, dphi]`` [sr^-1].
    n_theta, n_phi : int
        Grid size (bins and cells share it).
    seconds : float
        Build time [s].
    """

    spectrum: NDArray[np.complex64]
    n_theta: int
    n_phi: int
    seconds: float

    @property
    def nbytes(self) -> int:
        """Size of the stored spectrum [bytes]."""
        return int(self.spectrum.nbytes)

    def apply(
        self, cells: NDArray[np.float64], rows: NDArray[np.float64] | None = None
    ) -> NDArray[np.float64]:
        """Exit BRDF sums of up-going cell sums.

        Parameters
        ----------
        cells : ndarray, shape (B, n_theta, n_phi, 4, 4)
            Summed Mueller weights of the rays reaching the interface from below, per
            batch and cell, in the cells' meridional frames.
        rows : ndarray, shape (L, n_theta), optional
            Weights per output row of ``L`` groups of batches (``B = L x B'``, group
            major): the result is ``sum_l rows[l, o] (T10 cells[l B' + b])(o)``. The sum
            is taken on the spectrum, before the inverse FFT (linear), so only ``B'``
            inverse transforms are done (:mod:`.height_basis`'s levels).

        Returns
        -------
        ndarray, shape (B, n_theta, n_phi, 4, 4), or (B', ...) with ``rows``
            ``sum_cells T10 W`` per bin [sr^-1 x rays]; divide by the rays.
        """
        b, nt, npf = cells.shape[0], self.n_theta, self.n_phi
        used = np.flatnonzero(np.any(cells != 0, axis=(0, 2, 3, 4)))
        levels = 1 if rows is None else rows.shape[0]
        out = np.zeros((b // levels, nt, npf, 4, 4))
        if used.size == 0:
            return out
        if used.size > 0.7 * nt:  # a column copy would cost more than it saves
            used = np.arange(nt)
        spec_in = np.fft.rfft(cells[:, used], axis=2)  # (B, u, F, 4, 4)
        nf = spec_in.shape[2]
        # (F, 4u, 4B): rows (u, k), columns (b, j); one strided copy that also casts
        x = np.empty((nf, used.size * 4, b * 4), dtype=np.complex64)
        x.reshape(nf, used.size, 4, b, 4)[...] = spec_in.transpose(2, 1, 3, 0, 4)
        if used.size == nt:
            op = self.spectrum
        else:
            cols = (used[:, None] * 4 + np.arange(4)[None, :]).ravel()
            op = self.spectrum[:, :, cols]
        y = np.matmul(op, x).astype(np.complex128)  # (F, 4 nt, 4B)
        if rows is None:
            y = y.reshape(nf, nt, 4, b, 4).transpose(3, 1, 0, 2, 4)  # (B, nt, F, 4, 4)
        else:
            y = y.reshape(nf, nt, 4, levels, b // levels, 4)
            y = np.einsum("lr,frilbj->brfij", rows, y)  # (B', nt, F, 4, 4)
        out[...] = np.fft.irfft(y, n=npf, axis=2)
        return out


def build_exit_operator(
    grid: Grid,
    n_below: float,
    alpha: float,
    *,
    n_above: float = 1.0,
    nodes: tuple[int, int] = (1, 1),
    masking: str = "separable",
    kind: str = "transmission",
) -> ExitOperator:
    """Build ``T10`` for a GGX interface from a dielectric ``n_below`` into ``n_above``.

    ``kind="reflection"``: the same operator for the reflection on the interface's air
    side of rays going down (cells of their directions mirrored to z > 0, in the
    meridional frames of their azimuth), with the Fresnel reflection ``n_above ->
    n_below`` (:func:`.evaluate.reflection_mueller`).

    Parameters
    ----------
    grid : Grid
        Exit grid (also the grid of the internal cells).
    n_below, n_above : float
        Real indices below (the coating) and above [1].
    alpha : float
        GGX roughness of the interface [1], > 0.
    nodes : (int, int)
        Gauss-Legendre nodes per output bin in sin^2 theta and phi.
    masking : {"separable", "correlated", "incident"}
        :data:`MASKINGS`: ``G1(k_u) G1(w_o)``, the height-correlated ``G2_T``, or
        ``G1(k_u)`` alone.
    kind : {"transmission", "reflection"}
        :data:`KINDS`.

    Returns
    -------
    ExitOperator
    """
    if not alpha > 0:
        raise ValueError(f"the exit operator needs a rough interface, got alpha={alpha!r}")
    if masking not in MASKINGS:
        raise ValueError(f"masking must be one of {MASKINGS}, got {masking!r}")
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    t0 = time.perf_counter()
    nt, npf = grid.n_theta, grid.n_phi
    half = npf // 2 + 1
    theta_o, dphi_o, w = bin_nodes(grid, *nodes)
    q_row, q_theta, q_w = cell_nodes(grid, *_cell_rule(grid, n_below, alpha, n_above, kind))
    step = np.radians(grid.phi_step_deg)
    ni, nj = w.shape[1:]

    def abcs_t(c: NDArray[np.float64]) -> tuple:
        return fresnel_abcs(n_below, n_above, c)[1]

    def d_of(m: NDArray[np.float64]) -> NDArray[np.float64]:
        return ggx.d(m[2], alpha)

    def g1_of(v: NDArray[np.float64]) -> NDArray[np.float64]:
        return ggx.smith_g1(v[2], alpha)

    def lambda_of(v: NDArray[np.float64]) -> NDArray[np.float64]:
        return ggx.smith_lambda(np.abs(v[2]), alpha)

    g2_of = {
        "separable": None,
        "correlated": correlated_transmission(lambda_of),
        "incident": _incident(alpha, kind == "reflection_away"),
    }[masking]

    def kernel(ku: NDArray[np.float64], wo: NDArray[np.float64]) -> NDArray[np.float64]:
        if kind == "transmission":
            return transmission_mueller(ku, wo, n_below, n_above, abcs_t, d_of, g1_of, g2_of)
        k_in = ku * np.array([1.0, 1.0, 1.0 if kind == "reflection_away" else -1.0])[:, None]
        s_in = np.broadcast_to(np.array([0.0, 1.0, 0.0])[:, None], ku.shape)

        def abcs_r(c: NDArray[np.float64]) -> tuple:
            return fresnel_abcs(n_above, n_below, c)[0]

        return reflection_mueller(k_in, s_in, wo, abcs_r, d_of, g1_of, g2_of)

    # per output row: every (node, internal node, azimuth difference in [0, 180] deg)
    # point; with one node per cell the same points, in the same order, as the centroids
    grids = np.meshgrid(np.arange(ni * nj), np.arange(q_row.size), np.arange(half), indexing="ij")
    a, iq, dj = (g.ravel() for g in grids)
    ai, aj = a // nj, a % nj
    flat = q_row[iq] * half + dj
    tu = q_theta[iq]
    ku = np.stack([np.sin(tu), np.zeros_like(tu), np.cos(tu)])
    ph = dj * step + dphi_o[aj]
    cos_ph, sin_ph = np.cos(ph), np.sin(ph)
    wq = q_w[iq]
    spec = np.empty((half, nt * 4, nt * 4), dtype=np.complex64)
    for io in range(nt):
        th = theta_o[io, ai]
        sin_th = np.sin(th)
        wo = np.stack([sin_th * cos_ph, sin_th * sin_ph, np.cos(th)])
        M = kernel(ku, wo)
        rows = M.reshape(16, -1) * (w[io, ai, aj] * wq)
        T = np.empty((16, nt * half))
        for e in range(16):
            T[e] = np.bincount(flat, weights=rows[e], minlength=nt * half)
        T4 = T.reshape(4, 4, nt, half)
        # full circle from the half: T(-dphi) = P T(dphi) P, dphi = (npf - j) step for
        # j = half .. npf - 1 (slices: the same values as the index list npf - j)
        full = np.empty((4, 4, nt, npf))
        full[..., :half] = T4
        full[..., half:] = T4[..., npf - half : 0 : -1] * PARITY[:, :, None, None]
        sp = np.fft.rfft(full, axis=-1)  # (i, k, u, F)
        # straight into the (F, 4 rows, 4 nt) slab seen as (F, i, u, k): one strided copy
        spec[:, io * 4 : io * 4 + 4, :].reshape(half, 4, nt, 4)[...] = sp.transpose(3, 0, 2, 1)
    return ExitOperator(spec, nt, npf, time.perf_counter() - t0)


def _incident(alpha: float, away: bool):  # noqa: ANN202
    """``g2_of`` of the masking "incident": the visible-normal weight of the direction.

    Towards the surface: ``G1(w_i)``. A ray travelling away from it (``w_i`` below the
    horizon) that hits it again: its visible normals are normalised by the projected area
    ``|cos theta_i| Lambda(-w_i)`` (Heitz et al. 2016, sec. 4) instead of ``cos theta_i
    (1 + Lambda(w_i))``, so the factor over ``cos theta_i`` is ``-1 / Lambda(-w_i)``.
    """

    def g2(w_i: NDArray[np.float64], w_o: NDArray[np.float64]) -> NDArray[np.float64]:
        if away:
            with np.errstate(divide="ignore"):
                return np.asarray(-1.0 / ggx.smith_lambda(np.abs(w_i[2]), alpha), float)
        return np.asarray(ggx.smith_g1(np.abs(w_i[2]), alpha), float)

    return g2


def _cell_rule(
    grid: Grid, n_below: float, alpha: float, n_above: float, kind: str
) -> tuple[int, int]:
    """:func:`cell_rule` of an operator kind.

    A reflection's lobe is ``2 alpha`` wide and its cells are seen without the
    refraction's magnification ``n_below / n_above``.
    """
    if kind == "transmission":
        return cell_rule(grid, n_below, alpha, n_above)
    ratio = np.radians(grid.theta_step_deg) / (2.0 * alpha)
    n = int(min(CELL_MAX_NODES, np.ceil(CELL_NODES_PER_LOBE * ratio - 1e-9)))
    return (0, 1) if n <= 1 else (grid.n_theta, n)


def cell_rule(grid: Grid, n_below: float, alpha: float, n_above: float = 1.0) -> tuple[int, int]:
    """Rows of internal cells averaged over polar sub-cell nodes, and nodes per cell.

    Where a cell is wide against the exit lobe, treating all its rays as if they left
    from its centroid is wrong near the pole: the first cell is a cap around the pole
    whose centroid is off it, and the output bins there see every internal cell of the
    first rows from close by (``docs/tracer.md``). There every cell is averaged over
    ``n`` polar nodes (:func:`.evaluate.cell_nodes`), ``n = ceil(CELL_NODES_PER_LOBE x``
    the cell's polar width as seen in the air, ``n_below / n_above x step``, over the
    lobe width :func:`.exit_sampled.lobe_width_rad`), at most :data:`CELL_MAX_NODES`.
    All rows are averaged, not only those near the pole: a seam between averaged and
    centroid cells biased the output rows it feeds (docs/tracer.md). Where ``n = 1`` (for
    ``n_below = 1.5``: 1-degree cells at ``alpha >= 0.14``, 3-degree cells at ``alpha >=
    0.4``) the operator is the centroid rule's, bit for bit.

    Returns
    -------
    (rows, n) : (int, int)
        Rows averaged (0 or all) and nodes per cell.
    """
    image = np.radians(grid.theta_step_deg) * n_below / n_above
    ratio = image / lobe_width_rad(n_below, n_above, alpha)
    n = int(min(CELL_MAX_NODES, np.ceil(CELL_NODES_PER_LOBE * ratio - 1e-9)))
    if n <= 1:
        return 0, 1
    return grid.n_theta, n


@contextmanager
def memory_cache(store: OrderedDict[str, ExitOperator] | None = None) -> Iterator[None]:
    """Within this block :func:`exit_operator` keeps operators in memory, not on disk.

    For callers that trace many different coating (n, alpha) pairs, each at a few
    incidences, such as a fit that varies the coating's roughness: on disk every operator
    would be a new file that is never read again (3.8 MB each on a 3 x 6 degree grid,
    192 MB on the 1-degree grid). The last :data:`MEMORY_OPERATORS` operators are kept,
    so the incidences of one parameter set share its builds. Blocks share operators only
    through a ``store`` (an OrderedDict the caller keeps from one block to the next).
    """
    token = _MEMORY.set(OrderedDict() if store is None else store)
    try:
        yield
    finally:
        _MEMORY.reset(token)


def _key(
    grid: Grid,
    n_below: float,
    alpha: float,
    n_above: float,
    nodes: tuple,
    masking: str,
    kind: str = "transmission",
) -> str:
    spec: dict[str, object] = {
        "version": VERSION,
        "theta_step_deg": float(grid.theta_step_deg),
        "phi_step_deg": float(grid.phi_step_deg),
        "n_below": float(n_below),
        "n_above": float(n_above),
        "alpha": float(alpha),
        "nodes": [int(v) for v in nodes],
        "distribution": "ggx",
        "cell_rule": list(_cell_rule(grid, n_below, alpha, n_above, kind)),
    }
    if masking != "separable":  # the separable exit operators keep the keys they had
        spec["masking"] = masking
    if kind != "transmission":
        spec["kind"] = kind
    return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:32]


def exit_operator(
    grid: Grid,
    n_below: float,
    alpha: float,
    *,
    n_above: float = 1.0,
    nodes: tuple[int, int] = (1, 1),
    cache: bool = True,
    masking: str = "separable",
    kind: str = "transmission",
) -> ExitOperator:
    """:func:`build_exit_operator`, cached under :func:`cache_dir`.

    The cache key is a hash of everything the operator depends on (grid, indices, alpha,
    quadrature, masking, kind, format version); :mod:`labbrdf.tracer.cache` keeps the
    file: verified on load (key, shape, dtype and a digest of the contents), private to
    the user, written atomically and bounded by a size cap with least-recently-used
    eviction. A file that fails a check is rebuilt with a
    :class:`~labbrdf.tracer.cache.CacheWarning` naming it; a cache folder that cannot be
    written only costs the rebuild next time. Inside :func:`memory_cache` the operator is
    kept in memory instead.
    """
    if not cache:
        return build_exit_operator(
            grid, n_below, alpha, n_above=n_above, nodes=nodes, masking=masking, kind=kind
        )
    memory = _MEMORY.get()
    if memory is not None:
        key = _key(grid, n_below, alpha, n_above, nodes, masking, kind)
        op = memory.get(key)
        if op is None:
            op = build_exit_operator(
                grid, n_below, alpha, n_above=n_above, nodes=nodes, masking=masking, kind=kind
            )
            memory[key] = op
            while len(memory) > MEMORY_OPERATORS:
                memory.popitem(last=False)
        memory.move_to_end(key)
        return op
    key = _key(grid, n_below, alpha, n_above, nodes, masking, kind)
    nt, npf = grid.n_theta, grid.n_phi
    t0 = time.perf_counter()
    spec = _cache.load(key, (npf // 2 + 1, 4 * nt, 4 * nt), np.complex64)
    if spec is not None:
        return ExitOperator(spec, nt, npf, time.perf_counter() - t0)
    op = build_exit_operator(
        grid, n_below, alpha, n_above=n_above, nodes=nodes, masking=masking, kind=kind
    )
    _cache.store(key, op.spectrum)
    return op


def exit_operators(
    grid: Grid,
    n_below: float,
    alpha: float,
    requests: Sequence[tuple[str, str]],
    *,
    n_above: float = 1.0,
    nodes: tuple[int, int] = (1, 1),
) -> Generator[ExitOperator, None, None]:
    """:func:`exit_operator` of each ``(masking, kind)`` request, in order, one ahead.

    While the caller uses operator ``k`` (its products are BLAS and FFT calls that release
    the GIL), operator ``k + 1`` is built, or loaded, and stored in one worker thread, in
    a copy of the caller's context (so inside :func:`memory_cache` too). Each operator is
    built alone, as :func:`exit_operator` builds it: the results do not depend on the
    overlap. At most two operators are held at once (the one in use and the next).
    """

    def get(request: tuple[str, str]) -> ExitOperator:
        masking, kind = request
        return exit_operator(
            grid, n_below, alpha, n_above=n_above, nodes=nodes, masking=masking, kind=kind
        )

    if len(requests) < 2:
        for request in requests:
            yield get(request)
        return
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="labbrdf-operator") as pool:

        def ahead(request: tuple[str, str]) -> Future[ExitOperator]:
            ctx = copy_context()
            return pool.submit(lambda: ctx.run(get, request))

        pending = ahead(requests[0])
        for nxt in (*requests[1:], None):
            op = pending.result()
            if nxt is not None:
                pending = ahead(nxt)
            yield op
            del op
