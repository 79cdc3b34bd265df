"""The per-block random walk: all rays of a block advance together, one event per step.

State of a ray: direction ``k`` (3,), Stokes frame x axis ``s`` (3,), Mueller matrix
``M`` (4, 4), the interface it is on (``TOP`` = air/coating, ``SUB`` = substrate), the side
of that interface (``below``: inside the coating, under the top interface), its height on
the microsurface ``h`` (multiple scattering; +inf when it arrives from the bulk) and the
number of facet events.

One step, for every live ray:

1. *Leave or hit.* ``scattering="multiple"``: the next intersection height on the
   microsurface (Heitz et al. 2016, uniform height distribution, uncorrelated Smith
   masking); the ray leaves with probability ``C1(h)^Lambda``. ``scattering="single"``:
   a ray leaves right after its single facet event, weighted by ``G1(w_o)``; a ray whose
   outgoing direction points back into the surface is terminated.
2. *Route* a leaving ray: up out of the top interface (or out of a bare substrate) ->
   exit and binning; down out of the top interface -> across the coating to the substrate;
   up out of the substrate under a coating -> across the coating to the top interface from
   below. Crossing the coating multiplies M by the Beer-Lambert factor
   ``exp(-4 pi k_c d / (lambda |cos theta|))``. A Lambertian base (``Substrate.lambertian``)
   has no microsurface: a ray reaching it is re-emitted at once (``albedo * diag(1, 0, 0,
   0)``, cosine-distributed direction) and crosses back up in the same step; a bare base
   sends every ray straight out.
3. *Scatter* a hitting ray: a visible normal of its interface's distribution (GGX in
   closed form, Heitz 2018 / Dupuy & Benyoub 2023; a slope table, measured or Beckmann,
   by exact rejection), the frame rotated to the facet's s axis, Fresnel reflection
   (conductor; ideal mirror; or coherent film) or, at the dielectric top interface,
   reflection or refraction chosen with the probability equal to the reflected fraction
   of the ray's current Stokes vector for unpolarized input (the paper's step 3 uses
   ``(Rs + Rp)/2``, which is the same for an unpolarized ray), the Mueller weight divided
   by that probability. A refracted ray changes side and its height changes sign (Heitz
   2016, dielectric walk).
   With ``estimator="evaluated"`` and multiple scattering under a coating, each vertex on
   the top also records what it sends into the air (:func:`_vertex_escapes`), and the
   walk's own exits into the air only close the ledger (``docs/tracer.md``).
4. *Terminate*: after ``max_bounces`` events, or below the weight threshold ``tau``
   (``termination="threshold"``, Dong 2022 sec. 2.3) or by Russian roulette.

Each interface carries one distribution object (:mod:`labbrdf.microfacet.interface`, built
in :class:`~labbrdf.tracer.setup.WalkSetup`): the walk asks the interface a ray is on for
the Smith Lambda and G1 of its travel direction and for its visible normals, and never
needs to know which distribution it is. The block's sums are kept in
:class:`~labbrdf.tracer.tally.Ledger` and tallied by :mod:`labbrdf.tracer.tally`.

Energy ledger (unpolarized input, per ray exact): every change of ``M00`` is booked:
exit -> exited; Fresnel loss at the substrate and Beer-Lambert loss -> absorbed (the
dielectric interface conserves M00 to round-off by the choice of probability, and its
round-off is booked as absorbed too); masking in single mode, max_bounces, threshold and
roulette kills -> terminated; a roulette survivor's boost is booked as negative terminated.
So exited + absorbed + terminated = rays to round-off.

Notes
-----
Geometric model of the coating (position-free, Guo et al. 2018 style): the layers are
laterally infinite and the interfaces statistically independent; only directions matter.
A ray crossing the coating travels ``d / |cos theta|`` with ``theta`` the angle of its
direction to the macroscopic normal (the mean planes are parallel, a distance d apart).
Fresnel coefficients at the coating interfaces use the real part of the coating index;
its ``k`` only enters the Beer-Lambert factor. The paper's threshold tau is applied to the
intensity of the unpolarized-input Stokes vector (M00).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..microfacet.height import height_c1, sample_height
from .binning import Grid
from .config import TraceConfig
from .exit_sampled import deposit_branch, deposit_cells, record_up
from .height_basis import LEVELS, level_weights
from .interfaces import apply_fresnel, rotate_frame, s_axis
from .medium import traverse
from .setup import WalkSetup, grid_of
from .tally import BlockTally, Ledger, block_tally

__all__ = ["BlockTally", "GroupTally", "run_unit", "trace_block", "trace_group"]

TOP, SUB = 0, 1


@dataclass
class _Rays:
    """The live rays of a block, one column each (the state of the module docstring)."""

    k: NDArray[np.float64]  # (3, n) direction
    s: NDArray[np.float64]  # (3, n) Stokes frame x axis
    M: NDArray[np.float64]  # (4, 4, n) Mueller matrix
    iface: NDArray[np.int8]  # TOP or SUB
    below: NDArray[np.bool_]  # under the top interface, inside the coating
    h: NDArray[np.float64]  # height on the microsurface (+inf: arriving from the bulk)
    fresh: NDArray[np.bool_]  # not yet hit on this visit of the interface
    bounces: NDArray[np.int32]  # facet events so far
    rid: NDArray[np.int64]  # global ray index

    @classmethod
    def launch(cls, cfg: TraceConfig, su: WalkSetup, block: int, n: int) -> _Rays:
        """The ``n`` incident rays of block ``block``, on the first interface."""
        k, s, M = _launch(cfg.theta_i_deg, n)
        return cls(
            k=k,
            s=s,
            M=M,
            iface=np.full(n, TOP if su.layered else SUB, dtype=np.int8),
            below=np.zeros(n, dtype=bool),
            h=np.full(n, np.inf),
            fresh=np.ones(n, dtype=bool),
            bounces=np.zeros(n, dtype=np.int32),
            rid=cfg.block_rays * block + np.arange(n, dtype=np.int64),
        )

    def keep(self, alive: NDArray[np.bool_]) -> None:
        """Drop the rays that are not ``alive``."""
        if not alive.all():
            self.k, self.s, self.M = self.k[:, alive], self.s[:, alive], self.M[:, :, alive]
            self.iface, self.below, self.h = self.iface[alive], self.below[alive], self.h[alive]
            self.fresh, self.bounces = self.fresh[alive], self.bounces[alive]
            self.rid = self.rid[alive]


@dataclass
class _Hit:
    """Step 3's facet event of every live ray, before the Fresnel weights."""

    m: NDArray[np.float64]  # (3, n) facet normal
    cos_i: NDArray[np.float64]  # cosine of incidence on the facet
    kr: NDArray[np.float64]  # (3, n) mirror direction
    s_loc: NDArray[np.float64]  # (3, n) the facet's s axis, the ray's new frame
    on_top: NDArray[np.bool_]
    u: NDArray[np.float64]  # the uniform draw of the reflect/refract choice


def trace_block(
    cfg: TraceConfig, block: int, *, raw: list[tuple[NDArray, NDArray, NDArray]] | None = None
) -> BlockTally:
    """Trace the rays of block ``block`` with generator ``SeedSequence([seed, block])``.

    The steps are those of the module docstring, one function each: :func:`_leave_or_hit`,
    :func:`_route`, :func:`_scatter` (with :func:`_substrate_event` or
    :func:`_layered_event`) and :func:`_weight_cut`.

    Parameters
    ----------
    cfg : TraceConfig
    block : int
        Block index in ``range(cfg.n_blocks)``.
    raw : list or None
        Evaluated estimator: if given, every recorded up-going ray is also appended as
        ``(global ray index, direction (3, n), Mueller rows (16, n) in its meridional
        frame)``, for checks of the exit operator by direct evaluation.

    Returns
    -------
    BlockTally
    """
    if not 0 <= block < cfg.n_blocks:
        raise ValueError(f"block must be in [0, {cfg.n_blocks}), got {block!r}")
    su = WalkSetup(cfg)
    grid = grid_of(cfg)
    n = cfg.block_size(block)
    rng = np.random.default_rng(np.random.SeedSequence([cfg.seed, block]))
    rays = _Rays.launch(cfg, su, block, n)
    led = Ledger()
    if su.albedo is not None and not su.layered:
        _bare_base(su.albedo, su.evaluated, rng, rays, led)
    while rays.k.shape[1]:
        leave, alive = _leave_or_hit(su, rng, rays, led)
        _route(su, rng, rays, led, leave, alive)
        # max bounces: a ray that would need one more event is terminated
        over = alive & (rays.bounces >= cfg.max_bounces)
        if over.any():
            led.terminated += float(rays.M[0, 0, over].sum())
            alive &= ~over
        rays.keep(alive)
        if rays.k.shape[1] == 0:
            break
        if _scatter(su, cfg, grid, rng, rays, led, raw):
            break
        alive, led.terminated = _weight_cut(cfg, rng, rays.M, led.terminated)
        rays.keep(alive)
    return block_tally(cfg, grid, block, n, led, su.evaluated, su.channels)


def _bare_base(
    albedo: float, evaluated: bool, rng: np.random.Generator, rays: _Rays, led: Ledger
) -> None:
    """A bare Lambertian base: one base event, then every ray leaves."""
    k, s, M = rays.k, rays.s, rays.M
    led.absorbed += _base_event(albedo, rng, np.arange(k.shape[1]), k, s, M)
    led.events += k.shape[1]
    if evaluated:
        led.booked += float(M[0, 0].sum())  # its BRDF albedo / pi is the closed form
    else:
        led.exit(k, s, M)
    rays.k = k[:, :0]


def _leave_or_hit(
    su: WalkSetup, rng: np.random.Generator, rays: _Rays, led: Ledger
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Step 1: which rays leave their microsurface; returns (leave, alive)."""
    k, M, iface, below = rays.k, rays.M, rays.iface, rays.below
    m_ = int(k.shape[1])
    alive = np.ones(m_, dtype=bool)
    kz_loc = np.where(below, -k[2], k[2])
    if su.single:
        leave = ~rays.fresh
        if leave.any():
            back = leave & (kz_loc <= 0)
            led.terminated += float(M[0, 0, back].sum())
            alive &= ~back
            go = leave & ~back
            g = np.where(go, su.g1_of(k, iface == SUB, below), 1.0)
            led.terminated += float((M[0, 0] * (1.0 - g))[go].sum())
            M *= g
            leave = go
    else:
        lam = su.lambda_of(k, iface == SUB, below)
        leave, h_new = sample_height(kz_loc, lam, rays.h, rng.random(m_))
        rays.h = np.where(leave, rays.h, h_new)
    return leave, alive


def _leave_prob(lam: NDArray[np.float64], h: NDArray[np.float64]) -> NDArray[np.float64]:
    """``C1(h)^Lambda`` of up-going directions, 0 where it is not finite."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        g = height_c1(h) ** lam
    return np.where(np.isfinite(g), np.clip(g, 0.0, 1.0), 0.0)


def _vertex_escapes(
    su: WalkSetup,
    cfg: TraceConfig,
    grid: Grid,
    rays: _Rays,
    led: Ledger,
    raw: list[tuple[NDArray, NDArray, NDArray]] | None,
    hit: _Hit,
    fresnel: tuple,
) -> None:
    """Evaluated multiple scattering: what each vertex on the top sends into the air.

    * first vertex from the air, reflected: nothing (the closed-form first surface with
      the height-correlated masking);
    * first vertex from the coating's bulk, refracted: the ray is recorded in its cell
      for the exit operator built with the height-correlated ``G2_T``;
    * every later vertex: its reflected (air side) or refracted (from below) branch
      leaves at once with ``c^Lambda(w)``, ``c = C1(h)`` of the vertex's height on the
      air side. The ray is recorded in the cell of its direction, in the levels of
      :mod:`.height_basis` with the weights ``U_k(c)``, for the operators of those
      vertices (:func:`.estimator.exit_map`).

    A nearly smooth top (``su.sampled_exit``, no operators): the branch of every vertex
    but the first from the air, Fresnel-weighted, times its ``c^Lambda(w)``, is deposited
    into its exit bin (:func:`.exit_sampled.deposit_branch`).
    """
    k, M, fresh = rays.k, rays.M, rays.fresh
    air = hit.on_top & ~rays.below
    under = hit.on_top & rays.below
    into = (led.dep_key, led.dep_rows)
    if su.sampled_exit:
        _vertex_branches(su, cfg, grid, rays, into, hit, fresnel, (air & ~fresh, under))
        return
    if (under & fresh).any():
        deposit_cells(grid, cfg.batches, k, hit.s_loc, M, under & fresh, rays.rid, *into, raw)
    # rays travelling towards the mean plane (up from below, down on the air side), and
    # on the air side rays going up that hit again, have operators; under the top a ray
    # going down that hits again has its sampled branch binned (rare: docs/tracer.md)
    towards = np.where(rays.below, k[2] > 0, k[2] < 0)
    away = ~fresh & ~towards
    none = np.zeros_like(air)
    _vertex_branches(su, cfg, grid, rays, into, hit, fresnel, (none, under & away))
    for sel, h, ch in (
        (under & ~fresh & towards, -rays.h, 2),
        (air & ~fresh & towards, rays.h, 2 + LEVELS),
        (air & away, rays.h, 2 + 2 * LEVELS),
    ):
        if not sel.any():
            continue
        i = np.flatnonzero(sel)
        u = level_weights(grid, su.alpha_top, height_c1(h[i]))  # (n, LEVELS)
        kc = k[:, i].copy()
        kc[2] = np.abs(kc[2])  # a down-going ray's cell: its direction mirrored up
        cell, phi = grid.index(kc)
        Mc = M[:, :, i].copy()
        s_det = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)])
        rotate_frame(Mc, k[:, i], hit.s_loc[:, i], s_det)
        rows = Mc.reshape(16, -1)
        batch = rays.rid[i] % cfg.batches
        for lvl in range(LEVELS):
            into[0].append(((ch + lvl) * cfg.batches + batch) * grid.n_bins + cell)
            into[1].append(rows * u[:, lvl])


def _vertex_branches(
    su: WalkSetup,
    cfg: TraceConfig,
    grid: Grid,
    rays: _Rays,
    into: tuple[list[NDArray], list[NDArray]],
    hit: _Hit,
    fresnel: tuple,
    sels: tuple[NDArray[np.bool_], NDArray[np.bool_]],
) -> None:
    """The sampled exit of :func:`_vertex_escapes`: each vertex's leaving branch, binned."""
    refl, tr, cos_t, eta = fresnel
    k, M = rays.k, rays.M
    assert su.top is not None
    for sel, is_refl in zip(sels, (True, False), strict=True):
        if not sel.any():
            continue
        i = np.flatnonzero(sel)
        if is_refl:
            d, abcs, h = hit.kr[:, i], refl, rays.h[i]
        else:
            e = eta[i] if np.ndim(eta) else eta
            d = e * k[:, i] + (e * hit.cos_i[i] - cos_t[i]) * hit.m[:, i]
            abcs, h = tr, -rays.h[i]
        d = d / np.sqrt((d * d).sum(axis=0))
        g = np.where(d[2] > 0, _leave_prob(su.top.smith_lambda(d), h), 0.0)
        deposit_branch(
            grid, cfg.batches, d, hit.s_loc[:, i], M[:, :, i], tuple(a[i] for a in abcs),
            g, rays.rid[i], into, su.scalar,
        )  # fmt: skip


def _route(
    su: WalkSetup,
    rng: np.random.Generator,
    rays: _Rays,
    led: Ledger,
    leave: NDArray[np.bool_],
    alive: NDArray[np.bool_],
) -> None:
    """Step 2: leaving rays exit, or cross the coating to the other interface (in place)."""
    if not leave.any():
        return
    iface, below = rays.iface, rays.below
    out = leave & (((iface == TOP) & ~below) | ((iface == SUB) & (not su.layered)))
    if out.any():
        if su.ms_evaluated:
            # evaluated multiple scattering: every vertex has already sent its expected
            # escape to the map (_vertex_escapes); the walk's own exits close the ledger
            led.booked += float(rays.M[0, 0, out].sum())
        else:
            led.exit(rays.k[:, out], rays.s[:, out], rays.M[:, :, out])
        alive &= ~out
    if su.layered:
        cross_ = leave & ~out
        if cross_.any():
            ab, ev = _cross(
                su, rng, np.nonzero(cross_)[0], rays.k, rays.s, rays.M, iface, below, rays.h
            )
            led.absorbed += ab
            led.events += ev.size
            rays.bounces[ev] += 1
            rays.fresh[cross_] = True


def _facet_hit(su: WalkSetup, rng: np.random.Generator, rays: _Rays) -> _Hit:
    """Step 3, first half: a visible facet normal for every ray, its frame rotated to it."""
    k, s, M, below = rays.k, rays.s, rays.M, rays.below
    u = rng.random((3, k.shape[1]))
    on_top = rays.iface == TOP
    m = su.sample(k, ~on_top, below, u[:2], rng)
    cos_i = np.clip(-(k[0] * m[0] + k[1] * m[1] + k[2] * m[2]), 0.0, 1.0)
    s_loc = s_axis(k, m, s)
    rotate_frame(M, k, s, s_loc)
    kr = k + 2.0 * cos_i * m
    return _Hit(m=m, cos_i=cos_i, kr=kr, s_loc=s_loc, on_top=on_top, u=u[2])


def _scatter(
    su: WalkSetup,
    cfg: TraceConfig,
    grid: Grid,
    rng: np.random.Generator,
    rays: _Rays,
    led: Ledger,
    raw: list[tuple[NDArray, NDArray, NDArray]] | None,
) -> bool:
    """Step 3: scatter every live ray at its facet (in place); True ends the walk."""
    led.events += rays.k.shape[1]
    hit = _facet_hit(su, rng, rays)
    M = rays.M
    m00 = M[0, 0].copy()
    trans: NDArray[np.bool_] | None = None
    kill_all = False
    if not su.layered:
        kill_all = _substrate_event(su, M, hit, led)
        knew = hit.kr
    else:
        knew, trans, m00 = _layered_event(su, cfg, grid, rays, led, raw, hit, m00)
    rays.k = knew / np.sqrt(knew[0] * knew[0] + knew[1] * knew[1] + knew[2] * knew[2])
    rays.s = hit.s_loc
    led.absorbed += float((m00 - M[0, 0]).sum())
    rays.bounces += 1
    if kill_all:
        return True
    rays.fresh[:] = False
    if trans is not None and trans.any():
        rays.below = rays.below ^ trans
        rays.h = np.where(trans, -rays.h, rays.h)
    return False


def _substrate_event(su: WalkSetup, M: NDArray[np.float64], hit: _Hit, led: Ledger) -> bool:
    """Step 3 on a bare substrate: Fresnel reflection (in place); True ends the walk."""
    A, B, C, S = su.substrate_abcs(hit.cos_i)
    apply_fresnel(M, A, B, C, S)
    if su.scalar:
        M[1:] = 0.0
    if not su.evaluated:
        return False
    # the first (and only followed) event: its reflection is evaluated in closed form;
    # the sampled weight only closes the energy ledger
    krn = hit.kr / np.sqrt((hit.kr * hit.kr).sum(axis=0))
    g = su.g1_of(krn, ~hit.on_top)
    led.booked += float((M[0, 0] * g).sum())
    led.terminated += float((M[0, 0] * (1.0 - g)).sum())
    return True


def _layered_event(
    su: WalkSetup,
    cfg: TraceConfig,
    grid: Grid,
    rays: _Rays,
    led: Ledger,
    raw: list[tuple[NDArray, NDArray, NDArray]] | None,
    hit: _Hit,
    m00: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """Step 3 under or on a coating: reflect or refract (in place on M).

    Returns the new (unnormalised) directions, the refracted rays and ``m00`` less the
    weight of the evaluated walk's branch not followed.
    """
    k, M, below, on_top, cos_i = rays.k, rays.M, rays.below, hit.on_top, hit.cos_i
    refl, tr, cos_t, eta = su.layered_abcs(cos_i, on_top, below)
    if su.ms_evaluated:
        # the counting walk's random branch below; first what the vertex sends into the air
        _vertex_escapes(su, cfg, grid, rays, led, raw, hit, (refl, tr, cos_t, eta))
    s0 = M[0, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        pr = np.where(s0 > 0, (refl[0] * s0 + refl[1] * M[1, 0]) / s0, refl[0])
        pr = np.where(on_top, np.clip(pr, 0.0, 1.0), 1.0)  # opaque substrate
        if su.evaluated and not su.ms_evaluated:
            # no random branch: refract into the coating from air (the reflection is
            # evaluated), reflect at the top from below (the transmission is applied by
            # the exit operator), both with their Mueller weights
            trans = on_top & ~below
            wr = np.where(trans, 0.0, 1.0)
            wt = np.where(trans, 1.0, 0.0)
            up_ = on_top & below
            if up_.any():
                assert su.top is not None  # rays below a top interface: a layered run
                record_up(
                    grid,
                    cfg.batches,
                    rays.rid,
                    (k, hit.s_loc, hit.m),
                    M,
                    (tr, cos_t, eta),
                    up_,
                    (su.sampled_exit, su.top, su.scalar),
                    (led.dep_key, led.dep_rows, raw),
                )
        else:
            trans = hit.u >= pr
            wr = np.where(trans, 0.0, 1.0 / np.where(trans, 1.0, pr))
            wt = np.where(trans, 1.0 / np.where(trans, 1.0 - pr, 1.0), 0.0)
    if su.evaluated and not su.ms_evaluated:
        w_o, g = _other_branch(
            su, k, hit.m, hit.kr, M, cos_i, (refl, tr, cos_t, eta), on_top, below
        )
        led.booked += float((w_o * g).sum())
        led.terminated += float((w_o * (1.0 - g)).sum())
        m00 = m00 - w_o
    apply_fresnel(
        M,
        refl[0] * wr + tr[0] * wt,
        refl[1] * wr + tr[1] * wt,
        refl[2] * wr + tr[2] * wt,
        refl[3] * wr + tr[3] * wt,
    )
    if su.scalar:
        M[1:] = 0.0
    if not trans.any():
        return hit.kr, trans, m00
    kt = eta * k + (eta * cos_i - cos_t) * hit.m
    return np.where(trans, kt, hit.kr), trans, m00


def _launch(
    theta_i_deg: float, n: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Incident rays: direction, Stokes frame ``phi_hat(phi_i = 0)``, identity Mueller."""
    th = np.radians(theta_i_deg)
    k = np.zeros((3, n))
    k[0] = -np.sin(th)
    k[2] = -np.cos(th)
    s = np.zeros((3, n))
    s[1] = 1.0
    M = np.zeros((4, 4, n))
    for i in range(4):
        M[i, i] = 1.0
    return k, s, M


def _other_branch(
    su: WalkSetup,
    k: NDArray[np.float64],
    m: NDArray[np.float64],
    kr: NDArray[np.float64],
    M: NDArray[np.float64],
    cos_i: NDArray[np.float64],
    fresnel: tuple,
    on_top: NDArray[np.bool_],
    below: NDArray[np.bool_],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Evaluated walk: the branch not followed, sampled, for the ledger only.

    The reflected ray of the entry, the transmitted ray of an internal top event; both
    leave into the air with Smith G1 of their direction. Returns its M00 weight (before
    masking; 0 for substrate events) and that G1 (0 where there is no such branch).
    """
    refl, tr, cos_t, eta = fresnel
    entry = on_top & ~below
    up_ = on_top & below
    other = np.where(entry, 1.0, 0.0), np.where(up_, 1.0, 0.0)
    w_o = (refl[0] * other[0] + tr[0] * other[1]) * M[0, 0] + (
        refl[1] * other[0] + tr[1] * other[1]
    ) * M[1, 0]
    kt_ = eta * k + (eta * cos_i - cos_t) * m
    k_o = np.where(entry, kr, kt_)
    k_o = k_o / np.sqrt((k_o * k_o).sum(axis=0))
    g = np.where(
        entry | up_,
        su.g1_of(k_o, np.zeros_like(on_top)),
        0.0,
    )
    return w_o, g


def _weight_cut(
    cfg: TraceConfig, rng: np.random.Generator, M: NDArray[np.float64], terminated: float
) -> tuple[NDArray[np.bool_], float]:
    """Step 4: the weight threshold ``tau`` or Russian roulette (in place on M).

    Returns the rays that live on and ``terminated`` with the killed weight (and a
    roulette survivor's boost, negative) added.
    """
    alive = np.ones(M.shape[2], dtype=bool)
    if cfg.tau > 0:
        low = M[0, 0] < cfg.tau
        if low.any():
            if cfg.termination == "threshold":
                terminated += float(M[0, 0, low].sum())
                alive &= ~low
            else:
                idx = np.nonzero(low)[0]
                p = M[0, 0, idx] / cfg.tau
                survive = rng.random(idx.size) < p
                dead = idx[~survive]
                live = idx[survive]
                terminated += float(M[0, 0, dead].sum())
                before = M[0, 0, live].copy()
                M[:, :, live] /= p[survive]
                terminated += float((before - M[0, 0, live]).sum())
                alive[dead] = False
    else:
        dead = ~(M[0, 0] > 0)
        if dead.any():
            terminated += float(M[0, 0, dead].sum())
            alive &= ~dead
    return alive, terminated


def _cross(
    su: WalkSetup,
    rng: np.random.Generator,
    ci: NDArray[np.int64],
    k: NDArray[np.float64],
    s: NDArray[np.float64],
    M: NDArray[np.float64],
    iface: NDArray[np.int8],
    below: NDArray[np.bool_],
    h: NDArray[np.float64],
) -> tuple[float, NDArray[np.int64]]:
    """Carry the rays ``ci`` across the coating to the other interface (in place).

    A scattering coating (``Coating.medium``) sends each ray to the top or the base as its
    free flights and scattering events in the medium fall, a Lambertian base re-emitting
    it (:func:`labbrdf.tracer.medium.traverse`). A clear coating: Beer-Lambert along the
    way; a ray reaching a Lambertian base is re-emitted there (:func:`_base_event`) and
    crosses back up in the same step, with the attenuation of its new direction, to
    arrive at the top interface from below. With multiple
    scattering the arrival height on the next microsurface is drawn (always a hit: the ray
    travels towards it).

    Returns
    -------
    absorbed : float
        The M00 lost on the way (Beer-Lambert, the base's 1 - albedo).
    base : ndarray of int
        The rays that had a base event (one event each).
    """
    if su.medium is not None:
        # a scattering coating (labbrdf.tracer.medium): a ray goes wherever the medium
        # sends it, to the top from below or to the base (re-emitted there and crossing
        # again if it is Lambertian)
        albedo = su.albedo
        emit = None if albedo is None else (lambda i: _base_event(albedo, rng, i, k, s, M))
        absorbed, up, base = traverse(su.medium, su.a_abs, rng, ci, k, s, M, emit)
    else:
        absorbed = 0.0
        att = su.beer_lambert(k[2, ci])
        if att is not None:
            absorbed += float((M[0, 0, ci] * (1.0 - att)).sum())
            M[:, :, ci] *= att
        up = iface[ci] == SUB
        base = ci[:0]
        if su.albedo is not None and not up.all():
            base = ci[~up]
            absorbed += _base_event(su.albedo, rng, base, k, s, M)
            att = su.beer_lambert(k[2, base])
            if att is not None:
                absorbed += float((M[0, 0, base] * (1.0 - att)).sum())
                M[:, :, base] *= att
            up[:] = True
    iface[ci] = np.where(up, TOP, SUB)
    below[ci] = up
    if not su.single:
        kz_new = np.where(up, -k[2, ci], k[2, ci])
        lam_new = su.lambda_of(k[:, ci], ~up, up)
        _, h[ci] = sample_height(kz_new, lam_new, np.full(ci.size, np.inf), rng.random(ci.size))
    return absorbed, base


def _base_event(
    albedo: float,
    rng: np.random.Generator,
    idx: NDArray[np.int64],
    k: NDArray[np.float64],
    s: NDArray[np.float64],
    M: NDArray[np.float64],
) -> float:
    """Re-emit the rays ``idx`` from a Lambertian base (in place); returns the M00 absorbed.

    The base is flat and depolarizing: ``M <- albedo * diag(1, 0, 0, 0) M`` (only the
    intensity row survives, scaled by the albedo) and the new direction is drawn from the
    cosine (Lambert) distribution over the upper hemisphere, ``cos theta = sqrt(1 - u1)``,
    ``phi = 2 pi u2`` (Malley's method), so the reflected radiance is isotropic: the BRDF
    is ``albedo / pi``. The Stokes frame is the meridional ``phi_hat(phi)`` (any frame
    serves for an unpolarized ray).
    """
    u = rng.random((2, idx.size))
    r = np.sqrt(u[0])
    phi = 2.0 * np.pi * u[1]
    absorbed = float(((1.0 - albedo) * M[0, 0, idx]).sum())
    row = albedo * M[0][:, idx]
    M[:, :, idx] = 0.0
    M[0][:, idx] = row
    k[:, idx] = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1.0 - u[0])])
    s[:, idx] = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)])
    return absorbed


@dataclass
class GroupTally:
    """The folded tallies of one fold group of consecutive blocks (see ``fold_blocks``).

    ``sums`` etc. are ``((0 + t_first) + t_next) + ...`` in block order; ``block_hemi`` and
    ``block_rays`` keep the per-block hemispherical sums for the block-to-block error.
    Only the bins that rays left through are kept (``bins``): every other bin's sums are
    exactly zero, so adding the sparse tally gives the same bits as adding the dense one,
    and far less has to travel back from a worker.
    """

    group: int
    blocks: tuple[int, ...]
    bins: NDArray[np.int64]  # flat indices of the bins with exiting rays
    sums: NDArray[np.float64]  # (len(bins), 16)
    sumsq: NDArray[np.float64]  # (len(bins), 16)
    counts: NDArray[np.int64]  # (len(bins),)
    exited: float
    absorbed: float
    terminated: float
    hemi: NDArray[np.float64]
    events: int
    block_hemi: NDArray[np.float64]  # (n, 16) per-block hemispherical sums
    block_rays: NDArray[np.int64]  # (n,)
    cell_keys: NDArray[np.int64] | None = None  # evaluated: see BlockTally
    cell_sums: NDArray[np.float64] | None = None
    batch_rays: NDArray[np.int64] | None = None


def trace_group(cfg: TraceConfig, group: int) -> GroupTally:
    """Trace fold group ``group`` and add its blocks' tallies in block order."""
    if not 0 <= group < cfg.n_groups:
        raise ValueError(f"group must be in [0, {cfg.n_groups}), got {group!r}")
    blocks = tuple(cfg.group_blocks(group))
    nb = grid_of(cfg).n_bins
    sums, sumsq = np.zeros((nb, 16)), np.zeros((nb, 16))
    counts = np.zeros(nb, dtype=np.int64)
    hemi = np.zeros(16)
    exited = absorbed = terminated = 0.0
    events = 0
    bh = np.zeros((len(blocks), 16))
    br = np.zeros(len(blocks), dtype=np.int64)
    ev = cfg.resolved_estimator == "evaluated"
    cells = np.zeros((WalkSetup(cfg).channels * cfg.batches * nb, 16)) if ev else None
    brays = np.zeros(cfg.batches, dtype=np.int64) if ev else None
    for i, b in enumerate(blocks):
        t = trace_block(cfg, b)
        if cells is not None:
            assert t.cell_keys is not None and t.cell_sums is not None
            assert brays is not None and t.batch_rays is not None
            cells[t.cell_keys] = cells[t.cell_keys] + t.cell_sums
            brays = brays + t.batch_rays
        sums = sums + t.sums
        sumsq = sumsq + t.sumsq
        counts = counts + t.counts
        hemi = hemi + t.hemi
        exited = exited + t.exited
        absorbed = absorbed + t.absorbed
        terminated = terminated + t.terminated
        events += t.events
        bh[i] = t.hemi
        br[i] = t.rays
    nz = np.flatnonzero(counts)
    ck = cs = None
    if cells is not None:
        ck = np.flatnonzero(np.any(cells != 0, axis=1))
        cs = cells[ck]
    return GroupTally(
        group,
        blocks,
        nz,
        sums[nz],
        sumsq[nz],
        counts[nz],
        exited,
        absorbed,
        terminated,
        hemi,
        events,
        bh,
        br,
        ck,
        cs,
        brays,
    )


def run_unit(cfg: TraceConfig, groups: list[int] | tuple[int, ...]) -> list[GroupTally]:
    """Work unit: trace the listed fold groups (picklable, for ``map``)."""
    return [trace_group(cfg, g) for g in groups]


def _unit(args: tuple[TraceConfig, tuple[int, ...]]) -> list[GroupTally]:
    """Single-argument form of :func:`run_unit` for ``map(func, items)``."""
    cfg, groups = args
    return run_unit(cfg, groups)
