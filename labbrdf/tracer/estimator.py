"""The evaluated estimator: closed-form first surface + weighted walk + exit operator.

See ``docs/tracer.md`` for the derivation. Per bin o (cos-weighted bin averages),

    f(o) = F_r,first(o) + (1 / N) sum_cells T10(o, u) W(u),

``F_r,first`` the first interface's single-scattering Mueller BRDF (no noise),
``W(u)`` the summed Mueller weights of the walk's rays reaching the top interface from
below, cell u (:mod:`.walk`, ``estimator="evaluated"``), ``T10`` the exit operator
(:mod:`.operator`). Batches (ray index modulo ``config.batches``) give the standard
errors: the batch estimates ``f_b`` share ``F_r,first`` and differ only in the walk.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from ..microfacet.interface import ClosedForm
from .binning import Grid
from .config import TraceConfig
from .evaluate import (
    bin_nodes,
    correlated_reflection,
    reflection_mueller,
    transmission_mueller,
)
from .operator import PARITY, ExitOperator, exit_operators
from .setup import WalkSetup, scalar_abcs

#: the operator kinds of the later vertices' levels, in the order of the levels
VERTEX_KINDS = ("transmission", "reflection", "reflection_away")

__all__ = [
    "exit_map",
    "first_surface_map",
    "first_surface_nodes",
    "first_surface_point",
    "masking_of",
    "nee_exit",
]


def masking_of(cfg: TraceConfig) -> str:
    """The masking of the evaluated single events: ``"separable"`` or ``"correlated"``.

    The multiple-scattering walk's single reflection and single refraction carry the
    height-correlated masking (:func:`.evaluate.correlated_reflection`,
    :func:`.evaluate.correlated_transmission`); single scattering the separable one.
    """
    return "separable" if cfg.scattering == "single" else "correlated"


def first_surface_nodes(alpha: float, step_deg: float) -> int:
    """Gauss-Legendre nodes per bin axis for the first-surface average.

    The lobe's angular scale is ~alpha rad; with ``h = step / alpha`` the product rule's
    error falls like ``h^(2n)``: 4 nodes suffice to 1e-8 for h <= 0.2, more are used for
    sharper lobes (capped at 16).
    """
    h = np.radians(step_deg) / max(alpha, 1e-6)
    return int(min(16, max(4, np.ceil(4 * h / 0.2))))


def _first_surface(cfg: TraceConfig) -> tuple:  # noqa: ANN401
    """(abcs, D, G1, alpha for the node count) of the config's first interface."""
    su = WalkSetup(cfg)
    if su.top is not None:
        face = su.top
        n_c = su.n_coat

        def abcs(c: NDArray) -> tuple:
            from .interfaces import fresnel_abcs

            return fresnel_abcs(1.0, n_c, c)[0]

    else:
        face = su.sub
        abcs = su.substrate_abcs  # type: ignore[assignment]
    if cfg.scalar:
        abcs = _scalar_abcs(abcs)
    return abcs, face.d, face.smith_g1, face.alpha


def _masking(cfg: TraceConfig, masking: str) -> object:
    """The ``g2_of`` of the first interface for :func:`.evaluate.reflection_mueller`."""
    if masking == "separable":
        return None
    if masking != "correlated":
        raise ValueError(f"masking must be 'separable' or 'correlated', got {masking!r}")
    su = WalkSetup(cfg)
    face = su.top if su.top is not None else su.sub

    def lam(v: NDArray) -> NDArray:
        return face.smith_lambda(np.stack([v[0], v[1], np.abs(v[2])]))

    return correlated_reflection(lam)


def first_surface_point(
    cfg: TraceConfig, theta_r_deg: NDArray[np.float64], phi_r_deg: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Point Mueller BRDF of the first interface's single reflection [sr^-1].

    Parameters
    ----------
    cfg : TraceConfig
    theta_r_deg, phi_r_deg : ndarray, shape (n,)
        Exit directions [deg] (theta_r > 0: the meridional frame needs an azimuth).

    Returns
    -------
    ndarray, shape (n, 4, 4)
    """
    t, p = np.radians(np.asarray(theta_r_deg, float)), np.radians(np.asarray(phi_r_deg, float))
    if _bare_base(cfg):
        return _lambert(cfg, t.shape)
    abcs, d_of, g1_of, _ = _first_surface(cfg)
    th = np.radians(cfg.theta_i_deg)
    wo = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])
    M = reflection_mueller(
        np.array([-np.sin(th), 0.0, -np.cos(th)]), np.array([0.0, 1.0, 0.0]), wo, abcs, d_of, g1_of
    )
    out = np.moveaxis(M, 2, 0)
    if cfg.scalar:
        m00 = out[:, 0, 0].copy()
        out[...] = 0.0
        out[:, 0, 0] = m00
    return out


def first_surface_map(
    cfg: TraceConfig, chunk: int = 200_000, masking: str = "separable"
) -> NDArray[np.float64]:
    """Bin-averaged Mueller BRDF of the first interface's single reflection [sr^-1].

    ``masking``: ``"separable"`` (``G1 G1``) or ``"correlated"`` (``1 / (1 + L_i +
    L_o)``, the multiple-scattering walk's single event, :func:`masking_of`).

    Returns
    -------
    ndarray, shape (n_theta, n_phi, 4, 4)
    """
    su = WalkSetup(cfg)
    grid = Grid(cfg.theta_step_deg, cfg.phi_step_deg)
    if _bare_base(cfg):
        return _lambert(cfg, (grid.n_theta, grid.n_phi))
    # a slope table's D is piecewise smooth between its cells (no h^(2n) law for the
    # node count) and need not be symmetric about the plane of incidence
    table = not isinstance(su.sub if su.top is None else su.top, ClosedForm)
    th = np.radians(cfg.theta_i_deg)
    k_in = np.array([-np.sin(th), 0.0, -np.cos(th)])
    s_in = np.array([0.0, 1.0, 0.0])
    abcs, d_of, g1_of, alpha = _first_surface(cfg)
    g2_of = _masking(cfg, masking)
    n = first_surface_nodes(alpha, min(cfg.theta_step_deg, cfg.phi_step_deg))
    if table:
        n = 6
    theta, dphi, w = bin_nodes(grid, n, n)
    nt, npf = grid.n_theta, grid.n_phi
    phi_c = np.radians(grid.phi_centres_deg)
    # the incidence plane is a mirror plane of an isotropic interface: evaluate phi in
    # [0, 180] deg and mirror the rest; a slope table need not be symmetric: all of it
    half = npf if table else npf // 2 + 1
    it, jp, a, b = np.meshgrid(
        np.arange(nt), np.arange(half), np.arange(n), np.arange(n), indexing="ij"
    )
    it, jp, a, b = it.ravel(), jp.ravel(), a.ravel(), b.ravel()
    out = np.zeros((16, nt * half))
    flat = it * half + jp
    for s0 in range(0, it.size, chunk):
        sl = slice(s0, s0 + chunk)
        t = theta[it[sl], a[sl]]
        p = phi_c[jp[sl]] + dphi[b[sl]]
        wo = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])
        M = reflection_mueller(k_in, s_in, wo, abcs, d_of, g1_of, g2_of)  # type: ignore[arg-type]
        rows = M.reshape(16, -1) * w[it[sl], a[sl], b[sl]]
        for e in range(16):
            out[e] += np.bincount(flat[sl], weights=rows[e], minlength=nt * half)
    f = np.empty((nt, npf, 4, 4))
    f[:, :half] = out.T.reshape(nt, half, 4, 4)
    if half < npf:
        rest = np.arange(half, npf)
        f[:, half:] = f[:, npf - rest] * PARITY
    if cfg.scalar:
        m00 = f[..., 0, 0].copy()
        f[...] = 0.0
        f[..., 0, 0] = m00
    return f


def _bare_base(cfg: TraceConfig) -> bool:
    return cfg.coating is None and cfg.substrate.albedo is not None


def _lambert(cfg: TraceConfig, shape: tuple[int, ...]) -> NDArray[np.float64]:
    """A bare Lambertian base: ``albedo / pi * diag(1, 0, 0, 0)`` [sr^-1], exactly.

    A constant's cos-weighted bin average is the constant, so bins and points agree.
    """
    assert cfg.substrate.albedo is not None
    f = np.zeros((*shape, 4, 4))
    f[..., 0, 0] = cfg.substrate.albedo / np.pi
    return f


def _scalar_abcs(abcs):  # noqa: ANN001, ANN202
    def inner(c: NDArray) -> tuple:
        return scalar_abcs(abcs(c))

    return inner


def exit_map(
    cfg: TraceConfig, cells: NDArray[np.float64]
) -> tuple[NDArray[np.float64], dict[str, float]]:
    """Exit sums per batch from the walk's records under the top interface.

    Parameters
    ----------
    cells : ndarray, shape (channels, batches, n_theta, n_phi, 4, 4)
        ``cells[0]``: the internal cell sums for the exit operator; ``cells[1]``: the
        sampled exits' weight sums per output bin (:mod:`.exit_sampled`); multiple
        scattering through the operator: then the levels (:mod:`.height_basis`) of the
        later vertices from below and from above (:func:`.walk._vertex_escapes`).

    Returns
    -------
    sums : ndarray, shape (batches, n_theta, n_phi, 4, 4) [sr^-1 x rays]
    info : dict
        ``operator_seconds``, ``operator_mb``, ``exit_sampled`` (1: no operator used).
    """
    su = WalkSetup(cfg)
    grid = Grid(cfg.theta_step_deg, cfg.phi_step_deg)
    # the sampled exits are weight sums per output bin: the bin average of the BRDF is
    # the sum over the cos-weighted solid angle
    out = cells[1] / grid.cos_solid_angle_sr[None, :, :, None, None]
    info = {"operator_seconds": 0.0, "operator_mb": 0.0, "exit_sampled": 1.0}
    # one output node per degree of bin width (a coarse bin is not one point)
    nodes = (int(np.ceil(cfg.theta_step_deg - 1e-9)), int(np.ceil(cfg.phi_step_deg - 1e-9)))
    requests = [] if su.sampled_exit else [(masking_of(cfg), "transmission")]
    if cells.shape[0] > 2:
        requests += [("incident", kind) for kind in VERTEX_KINDS]
    # the next operator is built while the products of the current one run
    ops = exit_operators(grid, su.n_coat, su.alpha_top, requests, nodes=nodes)
    try:
        if not su.sampled_exit:
            op_sums, info = _operator_map(cfg, next(ops), cells[0])
            out = out + op_sums
        if cells.shape[0] > 2:
            out = out + _vertex_map(cfg, su, ops, cells[2:], info)
    finally:
        ops.close()
    if cfg.scalar:
        m00 = out[..., 0, 0].copy()
        out[...] = 0.0
        out[..., 0, 0] = m00
    return out, info


def _operator_map(
    cfg: TraceConfig, op: ExitOperator, cells: NDArray[np.float64]
) -> tuple[NDArray[np.float64], dict[str, float]]:
    """The exit operator applied to the internal cell sums (B, n_theta, n_phi, 4, 4)."""
    info = {"operator_seconds": op.seconds, "operator_mb": op.nbytes / 1e6}
    if cfg.scalar:
        # the scalar walk carries M00 alone; the operator's (0, 0) element is the scalar
        # transmission (A of the transmission matrix: B = 0 leaves M00 unrotated)
        cells = cells.copy()
        cells[..., 1:, :] = 0.0
        cells[..., :, 1:] = 0.0
    return op.apply(cells), info


def _vertex_map(
    cfg: TraceConfig,
    su: WalkSetup,
    ops: Iterator[ExitOperator],
    levels: NDArray[np.float64],
    info: dict[str, float],
) -> NDArray[np.float64]:
    """The later vertices' escapes: ``sum_k V_k(row) Op(level k)`` [sr^-1 x rays].

    ``levels``: (2 LEVELS, B, ...), the transmission levels then the reflection levels
    (:mod:`.height_basis`); ``ops`` gives the operators of :data:`VERTEX_KINDS` in order
    (masking "incident"): they carry ``G1`` of the vertex's direction only, the rows'
    ``V_k`` the escape ``c^Lambda(theta_o)``. ``info`` gains the build seconds.
    """
    from .height_basis import LEVELS, row_basis

    v = row_basis(cfg.theta_step_deg, cfg.phi_step_deg, float(su.alpha_top))
    out = np.zeros(levels.shape[1:])
    for j in range(len(VERTEX_KINDS)):
        op = next(ops)
        info["operator_seconds"] = info.get("operator_seconds", 0.0) + op.seconds
        info["operator_mb"] = info.get("operator_mb", 0.0) + op.nbytes / 1e6
        # the levels as more batches: one pass over the operator for all of them
        c = levels[j * LEVELS : (j + 1) * LEVELS]
        c = c.reshape(-1, *c.shape[2:])
        if cfg.scalar:
            c = c.copy()
            c[..., 1:, :] = 0.0
            c[..., :, 1:] = 0.0
        out += op.apply(c, rows=v)
    return out


def nee_exit(
    cfg: TraceConfig, bins: list[tuple[int, int]], nodes: int = 3
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Exit part of selected bins by direct evaluation per recorded ray (next-event style).

    The independent check of the exit operator: every up-going ray recorded below the top
    interface is carried through the closed-form BTDF (:func:`.evaluate.transmission_mueller`)
    from its *exact* direction to ``nodes x nodes`` Gauss-Legendre points of each bin, with
    no cells and no FFT. Costs per bin, so only for a few bins.

    Returns
    -------
    mean : ndarray, shape (len(bins), 4, 4)
        Exit Mueller BRDF of each bin [sr^-1].
    stderr : ndarray, shape (len(bins), 4, 4)
        Its standard error from the batches of ``cfg`` [sr^-1].
    """
    from .interfaces import fresnel_abcs
    from .walk import trace_block

    if cfg.resolved_estimator != "evaluated" or cfg.coating is None or cfg.coherent:
        raise ValueError("nee_exit needs an evaluated run with an incoherent coating")
    if cfg.scattering != "single":
        raise ValueError(
            "nee_exit checks the single-scattering exit operator; with multiple "
            "scattering the later vertices' levels are not evaluated per bin"
        )
    su = WalkSetup(cfg)
    if su.sampled_exit:
        raise ValueError(
            "nee_exit checks the exit operator; this coating's top is too smooth for it "
            "(its exit is sampled, see labbrdf.tracer.exit_sampled)"
        )
    grid = Grid(cfg.theta_step_deg, cfg.phi_step_deg)
    theta, dphi, w = bin_nodes(grid, nodes, nodes)
    phi_c = np.radians(grid.phi_centres_deg)
    nc = su.n_coat

    def abcs_t(c: NDArray) -> tuple:
        a, b, c_, s = fresnel_abcs(nc, 1.0, c)[1]
        if cfg.scalar:
            z = np.zeros_like(a)
            return a, z, z, z
        return a, b, c_, s

    assert su.top is not None
    d_of, g1_of = su.top.d, su.top.smith_g1
    nb = cfg.batches
    acc = np.zeros((nb, len(bins), 4, 4))
    omega = grid.cos_solid_angle_sr
    for block in range(cfg.n_blocks):
        raw: list = []
        tally = trace_block(cfg, block, raw=raw)
        _add_sampled(acc, tally, grid, bins, omega)
        if not raw:
            continue
        rid = np.concatenate([r[0] for r in raw])
        ku = np.concatenate([r[1] for r in raw], axis=1)
        rows = np.concatenate([r[2] for r in raw], axis=1).reshape(4, 4, -1)
        batch = rid % nb
        for q, (i, j) in enumerate(bins):
            for a in range(nodes):
                for b in range(nodes):
                    t, p = theta[i, a], phi_c[j] + dphi[b]
                    wo = np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])
                    T = transmission_mueller(
                        ku,
                        np.repeat(wo[:, None], ku.shape[1], axis=1),
                        nc,
                        1.0,
                        abcs_t,
                        d_of,
                        g1_of,
                    )
                    contrib = np.einsum("ikn,kjn->nij", T, rows) * w[i, a, b]
                    for bb in range(nb):
                        acc[bb, q] += contrib[batch == bb].sum(axis=0)
    # rays per batch (ray j in batch j % nb), counted without an array of all rays
    n_b = (cfg.rays // nb + (np.arange(nb) < cfg.rays % nb)).astype(float)
    per = acc / n_b[:, None, None, None]
    mean = acc.sum(axis=0) / cfg.rays
    var = (n_b[:, None, None, None] * (per - mean) ** 2).sum(axis=0) / cfg.rays / (nb - 1)
    return mean, np.sqrt(var)


def _add_sampled(
    acc: NDArray[np.float64],
    tally: object,
    grid: Grid,
    bins: list[tuple[int, int]],
    omega: NDArray[np.float64],
) -> None:
    """Add a block's sampled exits (rays near the pole, :mod:`.exit_sampled`) to ``acc``.

    They do not go through the operator, so the direct evaluation takes them as they are.
    """
    keys, sums = tally.cell_keys, tally.cell_sums  # type: ignore[attr-defined]
    nb, nbins = acc.shape[0], grid.n_bins
    if keys is None or keys.size == 0:
        return
    ex = keys >= nb * nbins
    batch, flat = keys[ex] // nbins - nb, keys[ex] % nbins
    for q, (i, j) in enumerate(bins):
        hit = flat == i * grid.n_phi + j
        for b, row in zip(batch[hit], sums[ex][hit], strict=True):
            acc[b, q] += row.reshape(4, 4) / omega[i, j]
