"""A rough clear coating over a Lambertian base with multiple scattering on the top.

The renewal form of :mod:`.coated_lambert` does not need single scattering: the base
forgets where its light came from, so with multiple scattering on the top's microsurface
(the walk of Heitz et al. 2016 [1]_ that :mod:`.walk` runs with ``scattering="multiple"``)
the light through the coating is still

    f_d(theta_i, theta_o) = a T(theta_i) T(theta_o) / (pi n^2 (1 - a R))        [sr^-1],

with ``T(theta)`` now the power from the air at ``theta`` that the whole microsurface walk
delivers into the coating (all orders, Beer-Lambert down along the direction it leaves
the microsurface with) and ``R`` the power of the base's cosine emission that the walk on
the top's lower side returns to the base (all orders, total internal reflection
included). The exit uses the reciprocity of the walk's BTDF, as the single-scattering form
does (Walter et al. 2007, eq. (21); the Heitz walk is reciprocal, [1]_ sec. 5). The first
surface reflects with the single-scattering closed form
(:func:`.estimator.first_surface_map`) plus the walk's higher orders, binned.

``T`` and ``R`` are Monte Carlo estimates of the same walk, not closed forms. Each is
estimated with:

* the *escape estimator*: at every vertex both branches (reflection and refraction, with
  their unpolarized Fresnel weights) book the probability ``C1(h)^Lambda(w)`` that they
  leave the microsurface from the vertex's height ([1]_ sec. 4); the walk goes on with the
  part that does not leave, in the branch chosen with probability proportional to that
  part. Only the visible normals (and the branch) are random: no ray is lost to or counted
  by a leave-or-hit draw;
* fixed seeds (common random numbers), so ``T`` and ``R`` are deterministic, nearly
  smooth functions of ``alpha`` and ``n``;
* a per-ray standard error, kept with the result (:attr:`CoatedLambertMS.stderr`).

Notes
-----
The walk here is scalar: each vertex weighs the unpolarized Fresnel numbers ``A``, as
the tracer's ``scalar=True`` mode does. Single scattering on unpolarized light is exact in
S0 either way; from the second vertex of one microsurface walk on, the polarized walk
differs by the correlation of the partial polarization of the first event with the second
event's Fresnel numbers (a second-order effect on the higher orders).

The first surface's single event: :func:`.estimator.first_surface_map` uses the
separable masking ``G1 G1``, the multiple-scattering walk the height-correlated
``1 / (1 + Lambda_i + Lambda_o)`` ([1]_ sec. 4); its reflection is higher by the factor
``1 + Lambda_i Lambda_o / (1 + Lambda_i + Lambda_o)`` (:func:`height_correlation`,
applied per polar row), which matters where both directions are grazing.

References
----------
.. [1] Heitz E., Hanika J., d'Eon E., Dachsbacher C., "Multiple-scattering microfacet
   BSDFs with the Smith model", ACM TOG 35(4), 58 (2016), sec. 4-5.
   doi:10.1145/2897824.2925943
.. [2] Walter B., Marschner S. R., Li H., Torrance K. E., "Microfacet models for refraction
   through rough surfaces", Proc. EGSR 2007, eq. (21). doi:10.2312/EGWR/EGSR07/195-206
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from ..microfacet import ggx
from ..microfacet.height import height_c1, sample_height
from ..microfacet.interface import ClosedForm
from .binning import Grid
from .coated_lambert import TABLE_DEG, CoatedLambert, beer_lambert
from .config import TraceConfig
from .estimator import first_surface_map
from .evaluate import bin_nodes
from .interfaces import fresnel_abcs

__all__ = [
    "CoatedLambertMS",
    "Escapes",
    "coated_lambert_ms",
    "first_surface_ms",
    "height_correlation",
    "higher_orders_map",
    "top_walk",
]

F64 = NDArray[np.float64]

#: rays per table angle of T(theta) and for R (the error they give: docs/tracer.md)
TABLE_RAYS = 20_000
EMISSION_RAYS = 1_000_000
#: walks at the incidence for the first surface's higher orders (counted into bins)
HIGHER_ORDER_RAYS = 200_000
#: the seed of every walk (common random numbers)
SEED = 20_160_058
#: walk length cap (events); weights below ROULETTE go through Russian roulette
MAX_EVENTS = 200
ROULETTE = 1e-3


@dataclass
class Escapes:
    """Where the walks left the top's microsurface (one row per escape).

    Attributes
    ----------
    ray : ndarray of int
        Index of the launched ray.
    k : ndarray, shape (3, m)
        Direction it left with.
    weight : ndarray
        Power it carried out [1] (per launched ray of unit power).
    below : ndarray of bool
        Left on the coating's side (into the coating) rather than into the air.
    order : ndarray of int
        Events on the microsurface before it left (1: single scattering).
    """

    ray: NDArray[np.int64]
    k: F64
    weight: F64
    below: NDArray[np.bool_]
    order: NDArray[np.int64]


def top_walk(
    k: F64, below: NDArray[np.bool_], n_coat: float, alpha: float, seed: int = SEED
) -> Escapes:
    """Heitz walks of rays arriving at the rough top, with the escape estimator [1].

    Parameters
    ----------
    k : ndarray, shape (3, n)
        Unit travel directions, towards the mean plane (down from the air, up from the
        coating).
    below : ndarray of bool, shape (n,)
        The rays that arrive from the coating's side.
    n_coat : float
        Real index of the coating [1].
    alpha : float
        GGX roughness of the top [1].
    seed : int
        Seed of the walk's generator.

    Returns
    -------
    Escapes
    """
    top = ClosedForm(ggx, alpha)
    rng = np.random.default_rng(seed)
    n = k.shape[1]
    k = np.array(k, float)
    below = np.array(below, bool)
    ray = np.arange(n)
    w = np.ones(n)
    kz = np.where(below, -k[2], k[2])
    u = np.asarray(rng.random(n), float)
    _, h = sample_height(kz, top.smith_lambda(k, below), np.full(n, np.inf), u)
    out: list[tuple] = []
    for order in range(1, MAX_EVENTS + 1):
        if ray.size == 0:
            break
        k, below, h, w, keep = _event(top, n_coat, rng, (k, below, h, w), order, ray, out)
        ray = ray[keep]
        w, live = _roulette(rng, w)
        ray, k, below, h, w = ray[live], k[:, live], below[live], h[live], w[live]
    if not out:
        return Escapes(np.zeros(0, np.int64), np.zeros((3, 0)), np.zeros(0), np.zeros(0, bool),
                       np.zeros(0, np.int64))  # fmt: skip
    cols = list(zip(*out, strict=True))
    return Escapes(
        np.concatenate(cols[0]),
        np.concatenate(cols[1], axis=1),
        np.concatenate(cols[2]),
        np.concatenate(cols[3]),
        np.concatenate(cols[4]),
    )


def _event(
    top: ClosedForm,
    n_coat: float,
    rng: np.random.Generator,
    state: tuple[F64, NDArray[np.bool_], F64, F64],
    order: int,
    ray: NDArray[np.int64],
    out: list[tuple],
) -> tuple[F64, NDArray[np.bool_], F64, F64, NDArray[np.bool_]]:
    """One vertex for every live ray: book both branches' escapes, follow one branch."""
    k, below, h, w = state
    u = rng.random((4, k.shape[1]))
    m = top.sample_visible(k, below, u[0], u[1], rng)
    cos_i = np.clip(-(k * m).sum(axis=0), 0.0, 1.0)
    n1 = np.where(below, n_coat, 1.0)
    n2 = np.where(below, 1.0, n_coat)
    refl, tr, cos_t = fresnel_abcs(n1.astype(complex), n2.astype(complex), cos_i)
    eta = n1 / n2
    kr = _unit(k + 2.0 * cos_i * m)
    kt = _unit(eta * k + (eta * cos_i - cos_t) * m)
    branches = []
    for d, side, hh, f in ((kr, below, h, refl[0]), (kt, ~below, -h, tr[0])):
        lam = top.smith_lambda(d, side)
        up = np.where(side, -d[2], d[2]) > 0
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            g = np.where(up, height_c1(hh) ** lam, 0.0)
        esc = w * f * g
        sel = esc > 0
        out.append((ray[sel], d[:, sel], esc[sel], side[sel], np.full(sel.sum(), order)))
        branches.append((d, side, hh, f * (1.0 - g), lam, g))
    stay_r, stay_t = branches[0][3], branches[1][3]
    total = stay_r + stay_t
    keep = total > 0
    pick_t = u[2] * total >= stay_r
    d = np.where(pick_t, branches[1][0], branches[0][0])
    side = np.where(pick_t, branches[1][1], branches[0][1])
    hh = np.where(pick_t, branches[1][2], branches[0][2])
    lam = np.where(pick_t, branches[1][4], branches[0][4])
    g = np.where(pick_t, branches[1][5], branches[0][5])
    kz = np.where(side, -d[2], d[2])
    _, h_new = sample_height(kz, lam, hh, u[3] * (1.0 - g))
    w_new = w * total
    return d[:, keep], side[keep], h_new[keep], w_new[keep], keep


def _roulette(rng: np.random.Generator, w: F64) -> tuple[F64, NDArray[np.bool_]]:
    """Russian roulette below :data:`ROULETTE` (unbiased: survivors carry the threshold)."""
    low = w < ROULETTE
    if not low.any():
        return w, np.ones(w.size, bool)
    survive = rng.random(w.size) * ROULETTE < w
    live = ~low | survive
    return np.where(low, ROULETTE, w), live


def _unit(v: F64) -> F64:
    return np.asarray(v / np.sqrt((v * v).sum(axis=0)), float)


def _per_ray(esc: Escapes, sel: NDArray[np.bool_], weight: F64, n: int) -> F64:
    """Each launched ray's booked power (escapes in ``sel``, times ``weight``)."""
    return np.asarray(
        np.bincount(esc.ray[sel], weights=(esc.weight * weight)[sel], minlength=n), float
    )


def _from_above(theta_deg: F64, rays: int) -> tuple[F64, NDArray[np.bool_]]:
    """``rays`` down-going directions at each polar angle, flattened.

    From the azimuth phi_i = 0 as the tracer launches (:func:`.walk._launch`): travelling
    towards -x, so the specular direction is at phi = 180 deg.
    """
    th = np.repeat(np.radians(theta_deg), rays)
    k = np.stack([-np.sin(th), np.zeros_like(th), -np.cos(th)])
    return k, np.zeros(th.size, bool)


def transmittance_table(
    n_coat: float,
    alpha: float,
    absorption: tuple[float, float, float],
    rays: int = TABLE_RAYS,
    seed: int = SEED,
) -> tuple[F64, F64]:
    """``T(theta)`` at :data:`TABLE_DEG` with all orders, and its standard error [1]."""
    k, below = _from_above(TABLE_DEG, rays)
    esc = top_walk(k, below, n_coat, alpha, seed)
    per = _per_ray(esc, esc.below, beer_lambert(esc.k[2], *absorption), k.shape[1])
    per = per.reshape(TABLE_DEG.size, rays)
    return per.mean(axis=1), per.std(axis=1, ddof=1) / math.sqrt(rays)


def internal_reflectance_ms(
    n_coat: float,
    alpha: float,
    absorption: tuple[float, float, float],
    rays: int = EMISSION_RAYS,
    seed: int = SEED,
) -> tuple[float, float]:
    """``R`` with all orders and its standard error [1]: the base's cosine emission.

    Stratified cosine-law directions (Malley's method on a regular grid of the unit
    square, jittered), Beer-Lambert up, the walk on the top's lower side, Beer-Lambert
    down along each reflected escape. ``seed``: the walks use ``seed + 1`` and ``seed + 2``.
    """
    rng = np.random.default_rng(seed + 1)
    side = int(math.isqrt(rays))
    a, b = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
    u0 = (a.ravel() + rng.random(side * side)) / side
    u1 = (b.ravel() + rng.random(side * side)) / side
    r = np.sqrt(u0)
    phi = 2.0 * np.pi * u1
    k = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1.0 - u0)])
    esc = top_walk(k, np.ones(k.shape[1], bool), n_coat, alpha, seed + 2)
    att = beer_lambert(k[2], *absorption)
    per = att * _per_ray(esc, esc.below, beer_lambert(esc.k[2], *absorption), k.shape[1])
    return float(per.mean()), float(per.std(ddof=1) / math.sqrt(per.size))


def higher_orders_map(
    n_coat: float, alpha: float, theta_i_deg: float, grid: Grid, rays: int, seed: int = SEED
) -> tuple[F64, float]:
    """The first surface's reflection of order >= 2: bin averages [sr^-1].

    Counted into the bins of ``grid`` (cos-weighted averages, like the tracer's maps)
    from ``rays`` walks at the incidence; returns the map (n_theta, n_phi) and the
    standard error of its albedo [1] (per-ray totals). The walks use ``seed + 3``.
    """
    k, below = _from_above(np.array([theta_i_deg]), rays)
    esc = top_walk(k, below, n_coat, alpha, seed + 3)
    sel = ~esc.below & (esc.order >= 2) & (esc.k[2] > 0)
    idx, _ = grid.index(esc.k[:, sel])
    s = np.bincount(idx, weights=esc.weight[sel], minlength=grid.n_bins)
    omega = grid.cos_solid_angle_sr.ravel()
    mean = s / rays
    tot = np.bincount(esc.ray[sel], weights=esc.weight[sel], minlength=rays)
    return (mean / omega).reshape(grid.n_theta, grid.n_phi), float(tot.std() / math.sqrt(rays))


def first_surface_ms(cfg: TraceConfig, rays: int | None = None) -> tuple[F64, float]:
    """The first surface's S0 map with all orders [sr^-1], and the error of its albedo.

    :func:`.estimator.first_surface_map` (single event, closed form) times
    :func:`height_correlation`, plus :func:`higher_orders_map` from ``rays`` walks
    (None: :data:`HIGHER_ORDER_RAYS`).

    Returns
    -------
    map : ndarray, shape (n_theta, n_phi)
    albedo_stderr : float
        Standard error of the higher orders' albedo (bins pooled) [1].
    """
    grid = Grid(cfg.theta_step_deg, cfg.phi_step_deg)
    coat = cfg.coating
    if coat is None:
        raise ValueError("first_surface_ms needs a coating")
    row = height_correlation(coat.alpha, cfg.theta_i_deg, grid)
    first = first_surface_map(cfg)[..., 0, 0] * row[:, None]
    hi, se = higher_orders_map(
        coat.n, coat.alpha, cfg.theta_i_deg, grid, rays or HIGHER_ORDER_RAYS
    )
    return np.asarray(first + hi, float), se


def height_correlation(alpha: float, theta_i_deg: float, grid: Grid) -> F64:
    """Per polar row: the walk's single reflection over the separable one [1].

    The first facet event of the Heitz walk leaves with the height-correlated
    masking-shadowing ``1 / (1 + Lambda_i + Lambda_o)`` ([1]_ sec. 4; Heitz 2014, eq.
    (99)), the closed form :func:`.estimator.first_surface_map` with the separable
    ``G1(w_i) G1(w_o)``: the ratio is ``1 + Lambda_i Lambda_o / (1 + Lambda_i +
    Lambda_o)``, a function of ``theta_o`` alone, averaged over each row with the cos
    weight (8 Gauss-Legendre nodes; the BRDF's variation across the row is neglected).

    Returns
    -------
    ndarray, shape (n_theta,)
    """
    theta, _, w = bin_nodes(grid, 8, 1)
    li = float(ggx.smith_lambda(np.cos(np.radians(theta_i_deg)), alpha))
    lo = ggx.smith_lambda(np.cos(theta), alpha)
    ratio = 1.0 + li * lo / (1.0 + li + lo)
    return np.asarray((ratio * w[:, :, 0]).sum(axis=1), float)


@dataclass(frozen=True)
class CoatedLambertMS(CoatedLambert):
    """:class:`.coated_lambert.CoatedLambert` with multiple scattering on the top.

    Attributes
    ----------
    stderr : tuple of ndarray and float
        Standard errors of the ``T`` table (at :data:`TABLE_DEG`) and of ``R`` [1].
    """

    stderr: tuple[F64, float] = (np.zeros(0), 0.0)

    def body_stderr(self, albedo: float, theta_i_deg: float) -> float:
        """Standard error of the albedo of the light through the coating [1].

        First-order propagation of the errors of ``T(theta_i)``, the exit integral
        ``(2 / n^2) int T mu d mu`` (table errors independent) and ``R``.
        """
        t_se, r_se = self.stderr
        mu = np.cos(np.radians(TABLE_DEG))
        wq = np.abs(np.gradient(mu * mu)) / self.n_coat**2  # d(mu^2) / n^2 per node
        exit_ = float((self.spline(TABLE_DEG) * wq).sum())
        exit_se = float(np.sqrt(((t_se * wq) ** 2).sum()))
        t_i = float(self.transmittance(np.array(theta_i_deg)))
        t_i_se = float(np.interp(theta_i_deg, TABLE_DEG, t_se))
        q = 1.0 - albedo * self.reflectance
        body = albedo * t_i * exit_ / q
        rel = np.hypot(np.hypot(t_i_se / t_i, exit_se / exit_), albedo * r_se / q)
        return float(body * rel)


@lru_cache(maxsize=32)
def coated_lambert_ms(
    n_coat: float,
    alpha: float,
    k_coat: float = 0.0,
    thickness_nm: float = 0.0,
    wavelength_nm: float = 550.0,
    table_rays: int | None = None,
    emission_rays: int | None = None,
) -> CoatedLambertMS:
    """:class:`CoatedLambertMS` of a coating (cached: a fit revisits its parameters).

    Parameters as :func:`.coated_lambert.coated_lambert`, and the walks per table angle
    of ``T`` and for ``R`` (None: :data:`TABLE_RAYS`, :data:`EMISSION_RAYS`).
    """
    if not (math.isfinite(n_coat) and n_coat > 0):
        raise ValueError(f"n_coat must be > 0, got {n_coat!r}")
    if not (math.isfinite(alpha) and alpha > 0):
        raise ValueError(f"alpha must be > 0, got {alpha!r}")
    ab = (float(k_coat), float(thickness_nm), float(wavelength_nm))
    table, t_se = transmittance_table(n_coat, alpha, ab, table_rays or TABLE_RAYS)
    refl, r_se = internal_reflectance_ms(n_coat, alpha, ab, emission_rays or EMISSION_RAYS)
    return CoatedLambertMS(
        float(n_coat), float(alpha), refl, CubicSpline(TABLE_DEG, table), (t_se, r_se)
    )
