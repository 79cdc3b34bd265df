"""Multiple scattering on a rough coating over a Lambertian base against invariants.

The white furnace (a lossless coating over a white base returns all the light: single
scattering returns 0.977 / 0.927 / 0.803 at alpha 0.05 / 0.1 / 0.2) within the estimate's
own standard error, and the counting multiple-scattering walk over every pooled bin
(z RMS bound 1.3 as in the tracer's other agreement tests, the albedo within 4 standard
errors). Few walks per table here (the model's defaults are 10-50 times more): the
tolerances come from the errors the estimate states for the walks it ran.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from labbrdf.tracer import Coating, Grid, Substrate, TraceConfig, trace
from labbrdf.tracer import coated_lambert_ms as ms
from labbrdf.tracer.agreement import pool_bins

#: walks per T table angle, for R and at the incidence (cheap; the model uses more)
RAYS = dict(table_rays=4_000, emission_rays=160_000)
FIRST_RAYS = 40_000


def _config(alpha: float, theta_i: float, albedo: float, k_coat: float = 0.0, **kw):
    return TraceConfig(
        theta_i_deg=theta_i,
        substrate=Substrate.lambertian(albedo),
        coating=Coating(n=1.5, k=k_coat, alpha=alpha, thickness_nm=1000.0),
        scattering="multiple",
        scalar=True,
        theta_step_deg=kw.pop("theta_step_deg", 3.0),
        phi_step_deg=kw.pop("phi_step_deg", 6.0),
        **kw,
    )


def _map(cfg: TraceConfig) -> tuple[np.ndarray, float]:
    """The model's S0 map of the configuration and the standard error of its albedo."""
    coat = cfg.coating
    body = ms.coated_lambert_ms(
        coat.n, coat.alpha, coat.k, coat.thickness_nm, cfg.wavelength_nm, **RAYS
    )
    albedo = float(cfg.substrate.albedo)
    grid = Grid(cfg.theta_step_deg, cfg.phi_step_deg)
    first, first_se = ms.first_surface_ms(cfg, FIRST_RAYS)
    f = first + body.bin_map(albedo, cfg.theta_i_deg, grid)
    return f, math.hypot(first_se, body.body_stderr(albedo, cfg.theta_i_deg))


def _furnace(alpha: float, theta_i: float) -> tuple[float, float]:
    cfg = _config(alpha, theta_i, 1.0)
    f, se = _map(cfg)
    omega = Grid(cfg.theta_step_deg, cfg.phi_step_deg).cos_solid_angle_sr
    return float((f * omega).sum()), se


@pytest.mark.parametrize("alpha", [0.05, 0.1, 0.2, 0.3])
def test_the_white_furnace_returns_all_the_light(alpha):
    """Lossless coating, white base: albedo 1 within 4 standard errors at 0-80 deg.

    The stated error is itself checked: it must be below 3e-3 at these walk counts
    (about 1e-3; the model's own counts give about 3e-4).
    """
    for theta_i in (0.0, 45.0, 80.0):
        albedo, se = _furnace(alpha, theta_i)
        assert se < 3e-3
        assert abs(albedo - 1.0) < 4 * se, (theta_i, albedo, se)


def test_the_furnace_fails_without_the_higher_orders(monkeypatch):
    """A walk cut after its first event (single scattering's T and R): energy is lost.

    At alpha 0.3 the cut walk loses ~4 % (the orders >= 2 of T and R), dozens of errors.
    """
    monkeypatch.setattr(ms, "MAX_EVENTS", 1)
    ms.coated_lambert_ms.cache_clear()
    try:
        albedo, se = _furnace(0.3, 45.0)
    finally:
        ms.coated_lambert_ms.cache_clear()
    assert 1.0 - albedo > 20 * se, (albedo, se)


@pytest.mark.parametrize(
    ("alpha", "albedo", "theta_i", "k_coat"),
    [(0.2, 0.8, 30.0, 0.0), (0.3, 0.6, 70.0, 0.002)],
)
def test_the_map_is_the_multiple_scattering_walks_expectation(alpha, albedo, theta_i, k_coat):
    """Against ``trace(scattering="multiple", estimator="counting")``, all bins pooled.

    On the layered model's 3 x 6 grid; the pole and the grazing row are the first and
    last groups. The model's errors (the higher orders counted, T and R estimated) are
    added to the counting walk's per group, the first as counting noise of the bins.
    """
    cfg = _config(alpha, theta_i, albedo, k_coat, rays=100_000, seed=5, estimator="counting")
    res = trace(cfg)
    f, f_se = _map(cfg)
    grid = res.grid
    omega = grid.cos_solid_angle_sr.ravel()
    groups = pool_bins(res.counts, 400)
    ng = int(groups.max()) + 1
    om = np.bincount(groups, weights=omega, minlength=ng)
    s = np.bincount(groups, weights=res.sums[..., 0, 0].ravel(), minlength=ng)
    ss = np.bincount(groups, weights=res.sumsq[..., 0, 0].ravel(), minlength=ng)
    n = res.rays
    counted = s / (n * om)
    se = np.sqrt(np.maximum(ss / n - (s / n) ** 2, 0.0) / n) / om
    model = np.bincount(groups, weights=f.ravel() * omega, minlength=ng) / om
    z = (model - counted) / se
    assert ng > 100
    assert np.sqrt(np.mean(z**2)) < 1.3, np.sqrt(np.mean(z**2))
    assert abs(z[0]) < 4 and abs(z[-1]) < 4  # the pole, the grazing row
    a_model = float((f.ravel() * omega).sum())
    assert abs(a_model - res.albedo()) < 4 * math.hypot(res.albedo_stderr(), f_se)


def test_single_scattering_is_far_from_the_walk():
    """The single-scattering closed form at alpha 0.3 misses the walk by > 10 errors.

    So the agreement above is a property of the multiple-scattering form.
    """
    from labbrdf.tracer.coated_lambert import coated_lambert

    cfg = _config(0.3, 30.0, 0.9, rays=40_000, seed=9, estimator="counting")
    res = trace(cfg)
    grid = res.grid
    single = coated_lambert(1.5, 0.3, 0.0, 1000.0).bin_map(0.9, 30.0, grid)
    a_single = float((single * grid.cos_solid_angle_sr).sum())
    assert res.albedo() - a_single > 10 * res.albedo_stderr()
