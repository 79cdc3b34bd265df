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
3. *Scatter* a hitting ray: a visible GGX normal (Heitz 2018 / Dupuy & Benyoub 2023), the
   frame rotated to the facet's s axis, Fresnel reflection (conductor; ideal mirror; or
   coherent film) or, at the dielectric top interface, reflection or refraction chosen with
   the probability equal to the reflected fraction of the ray's current Stokes vector for
   unpolarized input (the paper's step 3 uses ``(Rs + Rp)/2``, which is the same for an
   unpolarized ray), the Mueller weight divided by that probability. A refracted ray
   changes side and its height changes sign (Heitz 2016, dielectric walk).
4. *Terminate*: after ``max_bounces`` events, or below the weight threshold ``tau``
   (``termination="threshold"``, Dong 2022 sec. 2.3) or by Russian roulette.

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

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..microfacet import ggx
from ..microfacet.height import sample_height
from .binning import Grid, bin_exits
from .config import TraceConfig
from .exit_sampled import exit_is_sampled, record_up
from .interfaces import apply_fresnel, fresnel_abcs, rotate_frame, s_axis

__all__ = ["BlockTally", "GroupTally", "run_unit", "trace_block", "trace_group"]

TOP, SUB = 0, 1


@dataclass
class BlockTally:
    """What one block contributes (folded by the driver in block order)."""

    block: int
    rays: int
    sums: NDArray[np.float64]  # (n_bins, 16) summed exit Mueller elements
    sumsq: NDArray[np.float64]  # (n_bins, 16) summed squares (per-ray variance)
    counts: NDArray[np.int64]  # (n_bins,) exiting rays
    exited: float
    absorbed: float
    terminated: float
    hemi: NDArray[np.float64]  # (16,) summed exit Mueller over the hemisphere
    events: int
    # estimator="evaluated": Mueller sums of the rays reaching the top interface from
    # below, per (batch, internal cell), flat key batch * n_bins + cell; rays per batch
    cell_keys: NDArray[np.int64] | None = None
    cell_sums: NDArray[np.float64] | None = None  # (len(cell_keys), 16)
    batch_rays: NDArray[np.int64] | None = None  # (batches,)


def _grid(cfg: TraceConfig) -> Grid:
    return Grid(cfg.theta_step_deg, cfg.phi_step_deg)


class _Setup:
    """Per-run constants derived from the config."""

    def __init__(self, cfg: TraceConfig) -> None:
        sub, coat = cfg.substrate, cfg.coating
        self.single = cfg.scattering == "single"
        self.layered = coat is not None and not cfg.coherent
        self.coherent = bool(cfg.coherent)
        self.mirror = sub.mirror
        self.n_sub = complex(sub.n, sub.k)
        self.alpha_sub = coat.alpha if (coat is not None and cfg.coherent) else sub.alpha
        self.alpha_top = coat.alpha if coat is not None else 0.0
        self.n_coat = coat.n if coat is not None else 1.0
        self.k_coat = coat.k if coat is not None else 0.0
        self.d = coat.thickness_nm if coat is not None else 0.0
        self.lam = cfg.wavelength_nm
        self.coat = coat
        self.n_above_sub = self.n_coat if self.layered else 1.0
        # tabulated substrate distribution (None: GGX everywhere, the original path)
        self.ndf_sub = None if cfg.coherent else sub.ndf
        # tabulated top interface (seen from above; from below: its point reflection)
        self.ndf_top = coat.ndf if (coat is not None and self.layered) else None
        self.evaluated = cfg.resolved_estimator == "evaluated"
        # evaluated, nearly smooth top: the exit is the walk's own facet (exit_sampled)
        self.sampled_exit = (
            self.evaluated
            and self.layered
            and exit_is_sampled(_grid(cfg), self.n_coat, self.alpha_top)
        )
        self.scalar = bool(cfg.scalar)
        # Lambertian base instead of the conductor's microsurface (None: the conductor)
        self.albedo = sub.albedo

    def lambda_of(
        self,
        k: NDArray[np.float64],
        kz_loc: NDArray[np.float64],
        on_sub: NDArray[np.bool_],
        alpha: NDArray[np.float64],
        below: NDArray[np.bool_] | None = None,
    ) -> NDArray[np.float64]:
        """Smith Lambda of the travel directions (GGX, or the interfaces' tables)."""
        lam = ggx.smith_lambda(kz_loc, alpha)
        if self.ndf_sub is not None and on_sub.any():
            # the substrate is always seen from above: its local frame is the global one
            lam[on_sub] = self.ndf_sub.smith_lambda(k[:, on_sub])
        if self.ndf_top is not None and not on_sub.all():
            top = ~on_sub
            lam[top] = self.ndf_top.smith_lambda(self._top_dirs(k, top, below))
        return lam

    @staticmethod
    def _top_dirs(
        k: NDArray[np.float64], top: NDArray[np.bool_], below: NDArray[np.bool_] | None
    ) -> NDArray[np.float64]:
        """Directions of top-interface rays in the frame of the table seen from above.

        The lower side of a height field, seen through the point reflection r -> -r, has
        the same slope distribution as the upper side: a direction k below is -k above.
        """
        d = k[:, top]
        if below is None:
            return d
        return np.where(below[top], -d, d)

    def g1_of(
        self,
        k: NDArray[np.float64],
        kz_loc: NDArray[np.float64],
        on_sub: NDArray[np.bool_],
        alpha: NDArray[np.float64],
        below: NDArray[np.bool_] | None = None,
    ) -> NDArray[np.float64]:
        """Smith G1 of the travel directions (GGX, or the interfaces' tables)."""
        g = ggx.smith_g1(kz_loc, alpha)
        if self.ndf_sub is not None and on_sub.any():
            g[on_sub] = self.ndf_sub.smith_g1(k[:, on_sub])
        if self.ndf_top is not None and not on_sub.all():
            top = ~on_sub
            g[top] = self.ndf_top.smith_g1(self._top_dirs(k, top, below))
        return g

    def beer_lambert(self, kz: NDArray[np.float64]) -> NDArray[np.float64] | None:
        if self.k_coat == 0 or self.d == 0:
            return None
        return np.exp(-4 * np.pi * self.k_coat * self.d / (self.lam * np.abs(kz)))

    def substrate_abcs(
        self, cos_i: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray]:
        out = self._substrate_abcs(cos_i)
        return _scalar(out) if self.scalar else out

    def _substrate_abcs(
        self, cos_i: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray]:
        if self.coherent:
            from ..films.onefilm import film_amplitudes

            theta = np.degrees(np.arccos(np.clip(cos_i, 0.0, 1.0)))
            coat = self.coat
            assert coat is not None  # TraceConfig refuses coherent=True without a coating
            rs, rp = film_amplitudes(
                1.0, complex(coat.n, coat.k), self.n_sub, coat.thickness_nm, self.lam, theta
            )
            rs2 = np.abs(rs) ** 2
            rp2 = np.abs(rp) ** 2
            x = rs * np.conj(rp)
            return 0.5 * (rs2 + rp2), 0.5 * (rs2 - rp2), x.real, x.imag
        refl, _, _ = fresnel_abcs(self.n_above_sub, self.n_sub, cos_i, mirror=self.mirror)
        return refl

    def layered_abcs(
        self, cos_i: NDArray[np.float64], on_top: NDArray[np.bool_], below: NDArray[np.bool_]
    ) -> tuple[tuple, tuple, NDArray[np.float64], NDArray[np.float64]]:
        """Reflection/transmission numbers for a mix of top-interface and substrate rays."""
        refl, tr, cos_t, eta = self._layered_abcs(cos_i, on_top, below)
        if self.scalar:
            refl, tr = _scalar(refl), _scalar(tr)
        return refl, tr, cos_t, eta

    def _layered_abcs(
        self, cos_i: NDArray[np.float64], on_top: NDArray[np.bool_], below: NDArray[np.bool_]
    ) -> tuple[tuple, tuple, NDArray[np.float64], NDArray[np.float64]]:
        nc = self.n_coat
        n1 = np.where(on_top & below, nc, np.where(on_top, 1.0, nc)).astype(np.complex128)
        n2 = np.where(on_top, np.where(below, 1.0, nc), 0.0).astype(np.complex128)
        if not self.mirror:
            n2 = np.where(on_top, n2, self.n_sub)
        else:
            n2 = np.where(on_top, n2, 1.0 + 0.0j)  # placeholder, overridden below
        refl, tr, cos_t = fresnel_abcs(n1, n2, cos_i, opaque=~on_top)
        if self.mirror:
            sub = ~on_top
            refl = (
                np.where(sub, 1.0, refl[0]),
                np.where(sub, 0.0, refl[1]),
                np.where(sub, -1.0, refl[2]),
                np.where(sub, 0.0, refl[3]),
            )
        eta = np.where(on_top, n1.real / np.where(on_top, n2.real, 1.0), 1.0)
        return refl, tr, cos_t, eta


@dataclass
class _Rays:
    """The live rays of a block, one column each (the state of the module docstring)."""

    k: NDArray[np.float64]  # (3, n) direction
    s: NDArray[np.float64]  # (3, n) Stokes frame x axis
    M: NDArray[np.float64]  # (4, 4, n) Mueller matrix
    iface: NDArray[np.int8]  # TOP or SUB
    below: NDArray[np.bool_]  # under the top interface, inside the coating
    h: NDArray[np.float64]  # height on the microsurface (+inf: arriving from the bulk)
    fresh: NDArray[np.bool_]  # single scattering: not yet hit at this interface
    bounces: NDArray[np.int32]  # facet events so far
    rid: NDArray[np.int64]  # global ray index

    @classmethod
    def launch(cls, cfg: TraceConfig, su: _Setup, block: int, n: int) -> _Rays:
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
class _Ledger:
    """A block's running sums: the energy ledger, the exiting rays and the deposits."""

    booked: float = 0.0  # evaluated: the sampled weight of the branches not followed
    absorbed: float = 0.0
    terminated: float = 0.0
    events: int = 0
    ex_k: list[NDArray] = field(default_factory=list)
    ex_s: list[NDArray] = field(default_factory=list)
    ex_M: list[NDArray] = field(default_factory=list)
    dep_key: list[NDArray] = field(default_factory=list)
    dep_rows: list[NDArray] = field(default_factory=list)

    def exit(self, k: NDArray, s: NDArray, M: NDArray) -> None:
        """Keep exiting rays for the binning."""
        self.ex_k.append(k)
        self.ex_s.append(s)
        self.ex_M.append(M)


@dataclass
class _Hit:
    """Step 3's facet event of every live ray, before the Fresnel weights."""

    m: NDArray[np.float64]  # (3, n) facet normal
    cos_i: NDArray[np.float64]  # cosine of incidence on the facet
    kr: NDArray[np.float64]  # (3, n) mirror direction
    s_loc: NDArray[np.float64]  # (3, n) the facet's s axis, the ray's new frame
    on_top: NDArray[np.bool_]
    alpha: NDArray[np.float64]  # GGX alpha of the interface hit
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
    su = _Setup(cfg)
    grid = _grid(cfg)
    n = cfg.block_size(block)
    rng = np.random.default_rng(np.random.SeedSequence([cfg.seed, block]))
    rays = _Rays.launch(cfg, su, block, n)
    led = _Ledger()
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
    return _block_tally(cfg, grid, block, n, led, su.evaluated)


def _bare_base(
    albedo: float, evaluated: bool, rng: np.random.Generator, rays: _Rays, led: _Ledger
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
    su: _Setup, rng: np.random.Generator, rays: _Rays, led: _Ledger
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Step 1: which rays leave their microsurface; returns (leave, alive)."""
    k, M, iface, below = rays.k, rays.M, rays.iface, rays.below
    m_ = int(k.shape[1])
    alive = np.ones(m_, dtype=bool)
    kz_loc = np.where(below, -k[2], k[2])
    alpha = np.where(iface == TOP, su.alpha_top, su.alpha_sub)
    if su.single:
        leave = ~rays.fresh
        if leave.any():
            back = leave & (kz_loc <= 0)
            led.terminated += float(M[0, 0, back].sum())
            alive &= ~back
            go = leave & ~back
            g = np.where(go, su.g1_of(k, kz_loc, iface == SUB, alpha, below), 1.0)
            led.terminated += float((M[0, 0] * (1.0 - g))[go].sum())
            M *= g
            leave = go
    else:
        lam = su.lambda_of(k, kz_loc, iface == SUB, alpha, below)
        leave, h_new = sample_height(kz_loc, lam, rays.h, rng.random(m_))
        rays.h = np.where(leave, rays.h, h_new)
    return leave, alive


def _route(
    su: _Setup,
    rng: np.random.Generator,
    rays: _Rays,
    led: _Ledger,
    leave: NDArray[np.bool_],
    alive: NDArray[np.bool_],
) -> None:
    """Step 2: leaving rays exit, or cross the coating to the other interface (in place)."""
    if not leave.any():
        return
    iface, below = rays.iface, rays.below
    out = leave & (((iface == TOP) & ~below) | ((iface == SUB) & (not su.layered)))
    if out.any():
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


def _facet_hit(su: _Setup, rng: np.random.Generator, rays: _Rays) -> _Hit:
    """Step 3, first half: a visible facet normal for every ray, its frame rotated to it."""
    k, s, M, below = rays.k, rays.s, rays.M, rays.below
    u = rng.random((3, k.shape[1]))
    on_top = rays.iface == TOP
    a = np.where(on_top, su.alpha_top, su.alpha_sub)
    wi = -k
    wi[2] = np.where(below, k[2], wi[2])
    m = ggx.sample_visible(wi, a, u[0], u[1])
    if su.ndf_sub is not None and not on_top.all():
        on_sub = ~on_top
        m[:, on_sub] = su.ndf_sub.sample_visible(wi[:, on_sub], rng)
    m[2] = np.where(below, -m[2], m[2])
    if su.ndf_top is not None and on_top.any():
        # from below: the point reflection of the table's visible normals for k
        sign = np.where(below[on_top], -1.0, 1.0)
        m[:, on_top] = sign * su.ndf_top.sample_visible(-k[:, on_top] * sign, rng)
    cos_i = np.clip(-(k[0] * m[0] + k[1] * m[1] + k[2] * m[2]), 0.0, 1.0)
    s_loc = s_axis(k, m, s)
    rotate_frame(M, k, s, s_loc)
    kr = k + 2.0 * cos_i * m
    return _Hit(m=m, cos_i=cos_i, kr=kr, s_loc=s_loc, on_top=on_top, alpha=a, u=u[2])


def _scatter(
    su: _Setup,
    cfg: TraceConfig,
    grid: Grid,
    rng: np.random.Generator,
    rays: _Rays,
    led: _Ledger,
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


def _substrate_event(su: _Setup, M: NDArray[np.float64], hit: _Hit, led: _Ledger) -> bool:
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
    g = su.g1_of(krn, krn[2], ~hit.on_top, hit.alpha)
    led.booked += float((M[0, 0] * g).sum())
    led.terminated += float((M[0, 0] * (1.0 - g)).sum())
    return True


def _layered_event(
    su: _Setup,
    cfg: TraceConfig,
    grid: Grid,
    rays: _Rays,
    led: _Ledger,
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
    s0 = M[0, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        pr = np.where(s0 > 0, (refl[0] * s0 + refl[1] * M[1, 0]) / s0, refl[0])
        pr = np.where(on_top, np.clip(pr, 0.0, 1.0), 1.0)  # opaque substrate
        if su.evaluated:
            # no random branch: refract into the coating from air (the reflection is
            # evaluated), reflect at the top from below (the transmission is applied by
            # the exit operator), both with their Mueller weights
            trans = on_top & ~below
            wr = np.where(trans, 0.0, 1.0)
            wt = np.where(trans, 1.0, 0.0)
            up_ = on_top & below
            if up_.any():
                record_up(
                    grid,
                    cfg.batches,
                    rays.rid,
                    (k, hit.s_loc, hit.m),
                    M,
                    (tr, cos_t, eta),
                    up_,
                    (su.sampled_exit, su.alpha_top, su.scalar),
                    (led.dep_key, led.dep_rows, raw),
                )
        else:
            trans = hit.u >= pr
            wr = np.where(trans, 0.0, 1.0 / np.where(trans, 1.0, pr))
            wt = np.where(trans, 1.0 / np.where(trans, 1.0 - pr, 1.0), 0.0)
    if su.evaluated:
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


def _block_tally(
    cfg: TraceConfig, grid: Grid, block: int, n: int, led: _Ledger, evaluated: bool
) -> BlockTally:
    """Bin the exits (and fold the deposits of the evaluated walk) into the block's tally."""
    cell_keys = cell_sums = batch_rays = None
    if evaluated:
        cell_keys, cell_sums, batch_rays = _cell_tally(
            cfg, grid, block, n, led.dep_key, led.dep_rows
        )
    sums, sumsq, counts, hemi = _bin_exit_rays(grid, led.ex_k, led.ex_s, led.ex_M)
    return BlockTally(
        block=block,
        rays=n,
        sums=sums,
        sumsq=sumsq,
        counts=counts,
        exited=float(hemi[0]) + led.booked,
        absorbed=led.absorbed,
        terminated=led.terminated,
        hemi=hemi,
        events=led.events,
        cell_keys=cell_keys,
        cell_sums=cell_sums,
        batch_rays=batch_rays,
    )


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
    su: _Setup,
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
        su.g1_of(k_o, k_o[2], np.zeros_like(on_top), np.full(k.shape[1], su.alpha_top)),
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


def _cell_tally(
    cfg: TraceConfig,
    grid: Grid,
    block: int,
    n: int,
    dep_key: list[NDArray],
    dep_rows: list[NDArray],
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.int64]]:
    """Evaluated estimator: the recorded up-going rays summed per (batch, cell).

    Returns the occupied keys, their (n_keys, 16) Mueller sums and the rays per batch.
    """
    batch_rays = np.bincount(
        (cfg.block_rays * block + np.arange(n)) % cfg.batches, minlength=cfg.batches
    ).astype(np.int64)
    if not dep_key:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 16)), batch_rays
    key = np.concatenate(dep_key)
    rows_d = np.concatenate(dep_rows, axis=1)
    nkeys = 2 * cfg.batches * grid.n_bins  # cells for the operator, then sampled exits
    cnt = np.bincount(key, minlength=nkeys)
    cell_keys = np.flatnonzero(cnt)
    dense = np.empty((16, nkeys))
    for e in range(16):
        dense[e] = np.bincount(key, weights=rows_d[e], minlength=nkeys)
    return cell_keys, dense[:, cell_keys].T.copy(), batch_rays


def _bin_exit_rays(
    grid: Grid, ex_k: list[NDArray], ex_s: list[NDArray], ex_M: list[NDArray]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
    """Bin the exited rays in the LB exit frames ``phi_hat(phi)``.

    Returns the per-bin sums and sums of squares (n_bins, 16), the counts and the
    hemispherical sum (16,).
    """
    if not ex_k:
        nb = grid.n_bins
        return np.zeros((nb, 16)), np.zeros((nb, 16)), np.zeros(nb, dtype=np.int64), np.zeros(16)
    ke = np.concatenate(ex_k, axis=1)
    se = np.concatenate(ex_s, axis=1)
    Me = np.concatenate(ex_M, axis=2)
    idx, phi = grid.index(ke)
    s_det = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)])
    rotate_frame(Me, ke, se, s_det)
    rows = Me.reshape(16, -1)
    sums, sumsq, counts = bin_exits(grid, idx, rows)
    return sums, sumsq, counts, rows.sum(axis=1)


def _cross(
    su: _Setup,
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

    Beer-Lambert along the way; a ray reaching a Lambertian base is re-emitted there
    (:func:`_base_event`) and crosses back up in the same step, with the attenuation of
    its new direction, to arrive at the top interface from below. With multiple
    scattering the arrival height on the next microsurface is drawn (always a hit: the ray
    travels towards it).

    Returns
    -------
    absorbed : float
        The M00 lost on the way (Beer-Lambert, the base's 1 - albedo).
    base : ndarray of int
        The rays that had a base event (one event each).
    """
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
        a_new = np.where(up, su.alpha_top, su.alpha_sub)
        lam_new = su.lambda_of(k[:, ci], kz_new, ~up, a_new, up)
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


def _scalar(abcs: tuple) -> tuple:
    """Scalar mode: the unpolarized reflectance A alone, B = C = S = 0.

    With the rows 1-3 of M zeroed after each vertex the ray then carries only S0, weighted
    by ``(|r_s|^2 + |r_p|^2) / 2`` (or the transmittance) at every vertex, which is what
    a scalar (unpolarized) code computes.
    """
    z = np.zeros_like(abcs[0])
    return abcs[0], z, z, z


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
    nb = _grid(cfg).n_bins
    sums, sumsq = np.zeros((nb, 16)), np.zeros((nb, 16))
    counts = np.zeros(nb, dtype=np.int64)
    hemi = np.zeros(16)
    exited = absorbed = terminated = 0.0
    events = 0
    bh = np.zeros((len(blocks), 16))
    br = np.zeros(len(blocks), dtype=np.int64)
    ev = cfg.resolved_estimator == "evaluated"
    cells = np.zeros((2 * cfg.batches * nb, 16)) if ev else None
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
