"""A rough clear coating over a Lambertian base in single scattering, without rays.

The tracer's walk over a Lambertian base (:mod:`.walk`, ``Substrate.lambertian``) is a
renewal process: every ray that reaches the base is re-emitted with the cosine law,
unpolarized, whatever way it came. So what the base emits is, at every visit, the same
cosine distribution scaled by a power; only the powers depend on the incidence and the
albedo. With

* ``T(theta)`` the power a ray from the air at polar angle ``theta`` carries through the
  rough top to the base: the visible-normal average of the Fresnel transmittance (with its
  beam factor), the Smith ``G1`` of the refracted direction and the Beer-Lambert factor
  of its path down (the walk's entry, :func:`entry_transmittance`);
* ``R`` the power of the base's cosine emission that the top sends back to the base
  (internal reflection, total internal reflection included, with ``G1`` of the reflected
  direction and Beer-Lambert both ways; :func:`internal_reflectance`);
* ``a`` the albedo,

the power reaching the base after ``j`` visits is ``T(theta_i) a^(j-1) R^(j-1)``, and the
S0 BRDF of the light that went through the coating is the geometric series

    f_d(theta_i, theta_o) = a T(theta_i) T(theta_o) / (pi n^2 (1 - a R))        [sr^-1],

where ``T(theta_o) / (pi n^2)`` is the exit of a unit cosine emission through the top
towards ``theta_o`` by the reciprocity of the rough-dielectric BTDF (Walter et al. 2007,
eq. (21): ``f_t(i, o) / n_o^2 = f_t(o, i) / n_i^2``). This is the form of the classical
coated-diffuse models (Wolff 1994; Weidlich and Wilkie 2007), here with the tracer's own
rough-interface transmittances, so it is the expectation of the tracer's single-scattering
walk, not an approximation of it: the walk estimates the same integrals by sampling.
The BRDF adds the first surface's closed-form reflection
(:func:`.estimator.first_surface_map`).

The averages over visible normals are product midpoint rules in the two uniform numbers
that :func:`labbrdf.microfacet.ggx.sample_visible` maps to a normal (the tracer's own
sampling map, so the quadrature and the walk integrate the same function);
``T`` is tabulated on a grid in ``theta`` and interpolated with a cubic spline.
The quadrature's error is below 1e-4 of ``T`` and ``R`` (``docs/tracer.md``), far below
the walk's Monte Carlo error.

References
----------
.. [1] Walter B., Marschner S. R., Li H., Torrance K. E., "Microfacet models for refraction
   through rough surfaces", Proc. EGSR 2007, eqs. (21), (33), (34).
   doi:10.2312/EGWR/EGSR07/195-206
.. [2] Weidlich A., Wilkie A., "Arbitrarily layered micro-facet surfaces", Proc. GRAPHITE
   2007, sec. 4 (the geometric series of internal reflections over a diffuse base).
   doi:10.1145/1321261.1321292
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from ..microfacet import ggx
from .binning import Grid
from .evaluate import bin_nodes
from .interfaces import fresnel_abcs

__all__ = [
    "CoatedLambert",
    "coated_lambert",
    "entry_transmittance",
    "first_surface_s0",
    "internal_reflectance",
]

F64 = NDArray[np.float64]

#: the visible-normal rule: midpoints in the azimuth, Gauss-Legendre in the cap
NODES = (32, 64)
#: polar angles of the interpolation table of T(theta) [deg]
TABLE_DEG = np.linspace(0.0, 90.0, 46)
#: polar angles of the base's cosine emission in R: midpoints in sin^2 theta
EMISSION_NODES = 64


def beer_lambert(kz: F64, k_coat: float, thickness_nm: float, wavelength_nm: float) -> F64:
    """Beer-Lambert factor of one crossing of the coating along ``|kz|`` [1]."""
    if k_coat == 0 or thickness_nm == 0:
        return np.ones_like(kz)
    return np.exp(-4 * np.pi * k_coat * thickness_nm / (wavelength_nm * np.abs(kz)))


def _square(nodes: int | tuple[int, int]) -> tuple[F64, F64, F64]:
    """A product rule on the unit square: (azimuth numbers, cap numbers, weights).

    Midpoints in the first number (the azimuth of the cap: periodic, where the midpoint
    rule converges fastest), Gauss-Legendre in the second.
    """
    n1, n2 = (nodes, nodes) if isinstance(nodes, int) else nodes
    x2, w2 = _gauss(n2)
    a, b = np.meshgrid((np.arange(n1) + 0.5) / n1, x2, indexing="ij")
    w = np.broadcast_to(w2[None, :] / n1, a.shape)
    return a.ravel(), b.ravel(), w.ravel()


def _gauss(n: int) -> tuple[F64, F64]:
    """Gauss-Legendre nodes and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return (x + 1.0) / 2.0, w / 2.0


def entry_transmittance(
    theta_rad: F64,
    n_coat: float,
    alpha: float,
    absorption: tuple[float, float, float] = (0.0, 0.0, 550.0),
    nodes: int | tuple[int, int] = NODES,
) -> F64:
    """Power from the air at ``theta`` that reaches the base through the rough top [1].

    The walk's entry (:mod:`.walk`): a GGX visible normal for the incidence, the Fresnel
    transmittance ``A_t`` (unpolarized, with the beam factor) into the coating, Smith
    ``G1`` of the refracted direction (it must leave the top's microsurface downwards)
    and Beer-Lambert along it, averaged over the visible normals.

    Parameters
    ----------
    theta_rad : ndarray
        Polar angles in the air [rad], in [0, pi/2].
    n_coat : float
        Real index of the coating [1].
    alpha : float
        GGX roughness of the top [1], > 0.
    absorption : (float, float, float)
        ``(k_coat [1], thickness [nm], wavelength [nm])`` of the Beer-Lambert factor.
    nodes : int
        Midpoints per axis of the visible-normal rule.

    Returns
    -------
    ndarray
        ``T(theta)`` [1], the shape of ``theta_rad``.
    """
    th = np.asarray(theta_rad, float)
    u1, u2, wq = _square(nodes)
    t = np.clip(th.ravel(), 0.0, np.pi / 2)[:, None]
    shape = (t.shape[0], u1.size)
    wi = np.stack(
        [np.broadcast_to(np.sin(t), shape), np.zeros(shape), np.broadcast_to(np.cos(t), shape)]
    ).reshape(3, -1)
    m = ggx.sample_visible(wi, alpha, np.tile(u1, t.shape[0]), np.tile(u2, t.shape[0]))
    ci = np.clip((wi * m).sum(axis=0), 0.0, 1.0)
    _, tr, cos_t = fresnel_abcs(1.0, n_coat, ci)
    eta = 1.0 / n_coat
    kt = -eta * wi + (eta * ci - cos_t) * m
    kt = kt / np.sqrt((kt * kt).sum(axis=0))
    w = tr[0] * ggx.smith_g1(-kt[2], alpha) * beer_lambert(kt[2], *absorption)
    return np.asarray((w.reshape(shape) @ wq).reshape(th.shape), float)


def internal_reflectance(
    n_coat: float,
    alpha: float,
    absorption: tuple[float, float, float] = (0.0, 0.0, 550.0),
    nodes: int | tuple[int, int] = NODES,
    emission_nodes: int = EMISSION_NODES,
) -> float:
    """Power of the base's cosine emission that the rough top returns to the base [1].

    Up through the coating (Beer-Lambert), a GGX visible normal of the top seen from
    below, the Fresnel reflectance ``A_r`` (total internal reflection included), Smith
    ``G1`` of the reflected direction (down; a reflection that points up is lost, as in
    the walk) and Beer-Lambert down. The emission is isotropic in azimuth, so the polar
    angle alone is integrated: Gauss-Legendre in ``cos theta`` with the cosine law's
    density ``2 cos theta``.
    """
    mu, wm = _gauss(emission_nodes)
    ws = 2.0 * mu * wm  # the cosine law: 2 mu d mu
    u1, u2, wq = _square(nodes)
    shape = (mu.size, u1.size)
    st = np.broadcast_to(np.sqrt(1.0 - mu * mu)[:, None], shape).ravel()
    ct = np.broadcast_to(mu[:, None], shape).ravel()
    k = np.stack([st, np.zeros_like(st), ct])  # up-going under the top
    # the walk's lower side: the visible normal of (-kx, -ky, kz), mirrored in z
    wi = np.stack([-k[0], -k[1], k[2]])
    m = ggx.sample_visible(wi, alpha, np.tile(u1, mu.size), np.tile(u2, mu.size))
    m[2] = -m[2]
    ci = np.clip(-(k * m).sum(axis=0), 0.0, 1.0)
    refl, _, _ = fresnel_abcs(n_coat, 1.0, ci)
    kr = k + 2.0 * ci * m
    kr = kr / np.sqrt((kr * kr).sum(axis=0))
    w = (
        refl[0]
        * ggx.smith_g1(-kr[2], alpha)
        * beer_lambert(kr[2], *absorption)
        * beer_lambert(k[2], *absorption)
    )
    return float(ws @ w.reshape(shape) @ wq)


def first_surface_s0(n_coat: float, alpha: float, theta_i_deg: float, grid: Grid) -> F64:
    """S0 of the rough top's single reflection, bin-averaged on ``grid`` [sr^-1].

    The M00 element of :func:`.estimator.first_surface_map` for a GGX top of index
    ``n_coat`` in air, without the Mueller algebra: unpolarized light's M00 is the
    unpolarized Fresnel reflectance ``A`` (the frame rotations leave it alone), so the
    point BRDF is ``A(cos_i) D(h) G1(w_i) G1(w_o) / (4 cos theta_i cos theta_o)`` (Walter
    et al. 2007, eq. (20); the unpolarized Fresnel reflectance in real arithmetic),
    averaged with the same nodes (:func:`.estimator.first_surface_nodes`,
    :func:`.bin_nodes`) over the half plane ``phi`` in [0, 180] deg and mirrored. 9-15
    times faster than the Mueller map, equal to it to round-off.

    Parameters
    ----------
    n_coat : float
        Real index of the coating [1].
    alpha : float
        GGX roughness of the top [1].
    theta_i_deg : float
        Incidence [deg].
    grid : Grid
        The bins.

    Returns
    -------
    ndarray, shape (n_theta, n_phi)
    """
    from .estimator import first_surface_nodes

    n = first_surface_nodes(alpha, min(grid.theta_step_deg, grid.phi_step_deg))
    wo, w = _half_plane_nodes(grid.theta_step_deg, grid.phi_step_deg, n)
    nt, npf = grid.n_theta, grid.n_phi
    half = npf // 2 + 1
    th = math.radians(theta_i_deg)
    wi = np.array([math.sin(th), 0.0, math.cos(th)]).reshape(3, 1, 1, 1, 1)
    h = wi + wo
    h = h / np.sqrt((h * h).sum(axis=0))
    cos_i = np.clip((wi * h).sum(axis=0), 0.0, 1.0)
    refl = _unpolarized_reflectance(n_coat, cos_i)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = (
            refl
            * ggx.d(h[2], alpha)
            * ggx.smith_g1(wi[2], alpha)
            * ggx.smith_g1(wo[2], alpha)
            / (4.0 * wi[2] * wo[2])
        )
    f = np.where((wo[2] > 0) & (h[2] > 0), f, 0.0)
    rows = (f * w).sum(axis=(2, 3))
    out = np.empty((nt, npf))
    out[:, :half] = rows
    rest = np.arange(half, npf)
    out[:, half:] = out[:, npf - rest]
    return out


@lru_cache(maxsize=16)
def _half_plane_nodes(theta_step: float, phi_step: float, n: int) -> tuple[F64, F64]:
    """The half plane's node directions and weights of :func:`first_surface_s0`.

    Exit directions (3, n_theta, half, n, n) and weights (n_theta, 1, n, n); kept, as they
    depend on the grid only.
    """
    grid = Grid(theta_step, phi_step)
    theta, dphi, w = bin_nodes(grid, n, n)
    half = grid.n_phi // 2 + 1
    t = theta[:, None, :, None]
    p = np.radians(grid.phi_centres_deg)[:half][None, :, None, None] + dphi[None, None, None, :]
    wo = np.stack(np.broadcast_arrays(np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)))
    wo.flags.writeable = False
    w = np.ascontiguousarray(w[:, None, :, :])
    w.flags.writeable = False
    return wo, w


def _unpolarized_reflectance(n: float, c: F64) -> F64:
    """``(|r_s|^2 + |r_p|^2) / 2`` from air onto a real index ``n`` >= 1 at ``cos_i`` ``c``.

    The real-index case of :func:`.interfaces.fresnel_abcs`' ``A`` (no total internal
    reflection from the air side), in real arithmetic (Born and Wolf, sec. 1.5.2).
    """
    if n < 1.0:
        return np.asarray(fresnel_abcs(1.0, n, c.ravel())[0][0].reshape(c.shape), float)
    ct = np.sqrt(1.0 - (1.0 - c * c) / (n * n))
    rs = (c - n * ct) / (c + n * ct)
    rp = (n * c - ct) / (n * c + ct)
    return np.asarray(0.5 * (rs * rs + rp * rp), float)


@dataclass(frozen=True)
class CoatedLambert:
    """The parts of the coated Lambertian base that do not depend on the albedo.

    Attributes
    ----------
    n_coat, alpha : float
        Coating index and top roughness [1].
    reflectance : float
        ``R`` of :func:`internal_reflectance` [1].
    spline : CubicSpline
        ``T(theta)`` of :func:`entry_transmittance` over ``theta`` [deg].
    """

    n_coat: float
    alpha: float
    reflectance: float
    spline: CubicSpline

    def transmittance(self, theta_deg: F64) -> F64:
        """``T(theta)`` [1] at polar angles [deg] (cubic spline of the table)."""
        return np.asarray(self.spline(np.clip(theta_deg, 0.0, 90.0)), float)

    def brdf(self, albedo: float, theta_i_deg: F64, theta_o_deg: F64) -> F64:
        """S0 BRDF of the light that went through the coating [sr^-1] at point pairs."""
        t_i = self.transmittance(np.asarray(theta_i_deg, float))
        t_o = self.transmittance(np.asarray(theta_o_deg, float))
        return self._factor(albedo) * t_i * t_o

    def bin_map(self, albedo: float, theta_i_deg: float, grid: Grid) -> F64:
        """Cos-weighted bin averages on ``grid`` (n_theta, n_phi) [sr^-1], as the tracer's.

        ``T(theta_o)`` does not depend on the azimuth: each polar row is one
        Gauss-Legendre average (4 nodes per row, cos-weighted as :func:`.bin_nodes`).
        """
        theta, _, w = bin_nodes(grid, 4, 1)
        row = (self.transmittance(np.degrees(theta)) * w[:, :, 0]).sum(axis=1)
        t_i = float(self.transmittance(np.array(theta_i_deg)))
        return np.repeat((self._factor(albedo) * t_i * row)[:, None], grid.n_phi, axis=1)

    def _factor(self, albedo: float) -> float:
        if not 0.0 <= albedo <= 1.0:
            raise ValueError(f"albedo must be in [0, 1], got {albedo!r}")
        return albedo / (math.pi * self.n_coat**2 * (1.0 - albedo * self.reflectance))


@lru_cache(maxsize=32)
def coated_lambert(
    n_coat: float,
    alpha: float,
    k_coat: float = 0.0,
    thickness_nm: float = 0.0,
    wavelength_nm: float = 550.0,
) -> CoatedLambert:
    """:class:`CoatedLambert` of a coating (cached: a fit revisits its parameters).

    Parameters
    ----------
    n_coat : float
        Real index of the coating [1], > 1 is not required (any n > 0).
    alpha : float
        GGX roughness of the coating's top [1], > 0.
    k_coat, thickness_nm, wavelength_nm : float
        Beer-Lambert absorption of the coating (extinction coefficient [1], thickness
        [nm], wavelength [nm]).
    """
    if not (math.isfinite(n_coat) and n_coat > 0):
        raise ValueError(f"n_coat must be > 0, got {n_coat!r}")
    if not (math.isfinite(alpha) and alpha > 0):
        raise ValueError(f"alpha must be > 0, got {alpha!r}")
    ab = (float(k_coat), float(thickness_nm), float(wavelength_nm))
    table = entry_transmittance(np.radians(TABLE_DEG), n_coat, alpha, ab)
    refl = internal_reflectance(n_coat, alpha, ab)
    return CoatedLambert(float(n_coat), float(alpha), refl, CubicSpline(TABLE_DEG, table))
