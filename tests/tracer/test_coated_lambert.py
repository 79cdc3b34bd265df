"""The closed form of a rough coating over a Lambertian base against independent checks.

The smooth-interface limit (a Fresnel formula and the internal hemispherical reflectance
written here), the counting walk over every pooled bin of the hemisphere (no bin left out:
the pole and the grazing rows are in the first and last groups), and the quadrature's
convergence. Statistical tolerances: z over the pooled groups (RMS bound 1.3 as in the
tracer's other agreement tests), the albedo within 4 standard errors.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from labbrdf.tracer import Coating, Substrate, TraceConfig, trace
from labbrdf.tracer.agreement import pool_bins
from labbrdf.tracer.coated_lambert import (
    coated_lambert,
    entry_transmittance,
    internal_reflectance,
)
from labbrdf.tracer.estimator import first_surface_map


def _fresnel(n1: float, n2: float, cos_i: float) -> float:
    """(|r_s|^2 + |r_p|^2) / 2 of a lossless interface, 1 beyond the critical angle."""
    sin2_t = (n1 / n2) ** 2 * (1.0 - cos_i * cos_i)
    if sin2_t >= 1.0:
        return 1.0
    cos_t = np.sqrt(1.0 - sin2_t)
    rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t)
    rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t)
    return 0.5 * (rs * rs + rp * rp)


def test_a_nearly_smooth_top_gives_the_fresnel_slab():
    """alpha 0.005: T(theta) -> 1 - F(theta) and R -> the internal diffuse reflectance.

    The rough interface departs from the smooth one linearly in alpha (Smith G1 and the
    spread of facet angles near the critical angle); at alpha 0.005 by < 1e-3. The kink
    of R at the critical angle is then sharp: 256 emission angles resolve it.
    """
    n = 1.5
    theta = np.radians([0.0, 30.0, 60.0, 80.0])
    t = entry_transmittance(theta, n, 0.005)
    smooth = np.array([1.0 - _fresnel(1.0, n, np.cos(x)) for x in theta])
    np.testing.assert_allclose(t, smooth, rtol=1e-3)
    r_i, _ = integrate.quad(
        lambda x: _fresnel(n, 1.0, np.cos(x)) * np.sin(2 * x),
        0.0,
        np.pi / 2,
        points=[np.arcsin(1 / n)],
    )
    assert internal_reflectance(n, 0.005, emission_nodes=256) == pytest.approx(r_i, abs=1e-3)


def test_the_quadrature_is_converged():
    """The default rules against finer ones: T to 2e-4, R to 5e-4 (relative).

    At the model's lowest roughness (0.02) and at the vinyl's (0.3).
    """
    theta = np.radians([0.0, 45.0, 85.0])
    for alpha in (0.02, 0.3):
        t0 = entry_transmittance(theta, 1.5, alpha)
        t1 = entry_transmittance(theta, 1.5, alpha, nodes=(64, 128))
        np.testing.assert_allclose(t0, t1, rtol=2e-4)
        r0 = internal_reflectance(1.5, alpha)
        r1 = internal_reflectance(1.5, alpha, emission_nodes=128)
        assert r0 == pytest.approx(r1, rel=5e-4)


@pytest.mark.parametrize(
    ("alpha", "albedo", "theta_i", "k_coat"),
    [(0.1, 0.9, 60.0, 0.0), (0.3, 0.5, 0.0, 0.002)],
)
def test_the_closed_form_is_the_walks_expectation(alpha, albedo, theta_i, k_coat):
    """Against the counting walk on the layered model's 3 x 6 grid, every bin pooled.

    The pole (where the exit operator is biased) and the grazing rows are included; the
    albedo (all bins) within 4 standard errors of the walk's. A missing ``n^2`` or a
    single pass through the coating (no ``1 / (1 - a R)``) fails both by far.
    """
    cfg = TraceConfig(
        rays=100_000,
        theta_i_deg=theta_i,
        substrate=Substrate.lambertian(albedo),
        coating=Coating(n=1.5, k=k_coat, alpha=alpha, thickness_nm=1000.0),
        scattering="single",
        estimator="counting",
        scalar=True,
        theta_step_deg=3.0,
        phi_step_deg=6.0,
        seed=21,
    )
    res = trace(cfg)
    grid = res.grid
    body = coated_lambert(1.5, alpha, k_coat, 1000.0, cfg.wavelength_nm)
    f = first_surface_map(cfg)[..., 0, 0] + body.bin_map(albedo, theta_i, grid)
    omega = grid.cos_solid_angle_sr.ravel()
    groups = pool_bins(res.counts, 400)
    ng = int(groups.max()) + 1
    om = np.bincount(groups, weights=omega, minlength=ng)
    s = np.bincount(groups, weights=res.sums[..., 0, 0].ravel(), minlength=ng)
    ss = np.bincount(groups, weights=res.sumsq[..., 0, 0].ravel(), minlength=ng)
    n = res.rays
    counted = s / (n * om)
    se = np.sqrt(np.maximum(ss / n - (s / n) ** 2, 0.0) / n) / om
    closed = np.bincount(groups, weights=f.ravel() * omega, minlength=ng) / om
    z = (closed - counted) / se
    assert ng > 100
    assert np.sqrt(np.mean(z**2)) < 1.3, np.sqrt(np.mean(z**2))
    assert abs(z[0]) < 4 and abs(z[-1]) < 4  # the pole, the grazing row
    albedo_closed = float((f.ravel() * omega).sum())
    assert abs(albedo_closed - res.albedo()) < 4 * res.albedo_stderr()
