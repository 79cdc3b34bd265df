"""Multiple scattering over a Lambertian base, tabulated in the top's roughness.

The spline in ``ln alpha`` against a smooth function tabulated the same way (the
single-scattering closed forms: the bound 3e-4 is the interpolation error measured over the
whole range, 2e-4; linear interpolation misses by 3.7e-3), the tables against the direct
walks between two nodes (z over every angle, with the errors the walks state), the white
furnace through the tables, smoothness in ``alpha`` (no jumps under a fit's finite
differences) and the disk cache (reused, a damaged file rebuilt). Few nodes (a narrow
range) keep the real walks cheap.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from labbrdf.tracer import Coating, Grid, Substrate, TraceConfig
from labbrdf.tracer import coated_lambert_ms as ms
from labbrdf.tracer import coated_lambert_table as tb
from labbrdf.tracer.cache import CacheWarning
from labbrdf.tracer.coated_lambert import (
    TABLE_DEG,
    entry_transmittance,
    first_surface_s0,
    internal_reflectance,
)
from labbrdf.tracer.estimator import first_surface_map

AB = (0.0, 1000.0, 550.0)
#: a narrow range: four nodes (0.218, 0.28, 0.36, 0.462), about 2 s of walks
NARROW = (0.28, 0.36)


@pytest.fixture
def fresh(monkeypatch):
    """Empty in-memory tables before and after (the disk cache is the session's)."""
    tb.clear_memory()
    yield monkeypatch
    tb.clear_memory()


def _smooth_walks(monkeypatch, calls: list[float] | None = None) -> None:
    """Replace the walks by the single-scattering closed forms (smooth, no error)."""

    def t_table(n, alpha, ab, rays, seed):
        if calls is not None:
            calls.append(alpha)
        return entry_transmittance(np.radians(TABLE_DEG), n, alpha, ab), np.zeros(46)

    def r_ms(n, alpha, ab, rays, seed):
        return internal_reflectance(n, alpha, ab), 0.0

    monkeypatch.setattr(ms, "transmittance_table", t_table)
    monkeypatch.setattr(ms, "internal_reflectance_ms", r_ms)


def test_the_spline_interpolates_a_smooth_table_between_nodes(fresh):
    """Midway between the nodes from alpha 0.1 up: within 3e-4 of the function."""
    fresh.setenv("LABBRDF_CACHE_MAX_BYTES", "0")  # the stand-in walks are not stored
    _smooth_walks(fresh)
    x = tb.alpha_nodes()
    assert math.exp(x[0]) < tb.ALPHA_RANGE[0] and math.exp(x[-1]) > tb.ALPHA_RANGE[1]
    mid = np.exp((x[:-1] + x[1:]) / 2)
    for a in mid[(mid >= 0.1) & (mid <= tb.ALPHA_RANGE[1])]:  # the largest errors
        got = tb.tabulated_ms(1.5, float(a), *AB)
        want_t = entry_transmittance(np.radians(TABLE_DEG), 1.5, a, AB)
        assert np.abs(got.transmittance(TABLE_DEG) - want_t).max() < 3e-4, a
        assert abs(got.reflectance - internal_reflectance(1.5, a, AB)) < 3e-4, a


def test_outside_the_range_the_tables_refuse():
    with pytest.raises(ValueError, match="outside the tabulated range"):
        tb.tabulated_ms(1.5, 1.5)
    assert not tb.in_range(0.01) and tb.in_range(0.02) and tb.in_range(1.0)


def _between(fresh) -> float:
    fresh.setattr(tb, "ALPHA_RANGE", NARROW)
    x = tb.alpha_nodes()
    assert x.size == 4
    return float(np.exp((x[1] + x[2]) / 2))  # 0.3175: between two nodes


def test_the_tables_are_the_direct_walks_between_nodes(fresh):
    """T at 46 angles, R and the higher orders' albedo: |z| < 4 each, z RMS of T < 1.5.

    The direct walks run with the tables' walk counts and seed at an alpha between two
    nodes; z uses both stated errors as if independent (common random numbers make the
    difference smaller: the test is conservative there and sharp on a misplaced node).
    """
    a = _between(fresh)
    rays = tb.NODE_RAYS
    tab = tb.tabulated_ms(1.5, a, *AB)
    t, t_se = ms.transmittance_table(1.5, a, AB, rays[0], tb.SEED)
    r, r_se = ms.internal_reflectance_ms(1.5, a, AB, rays[1], tb.SEED)
    tab_t_se, tab_r_se = tab.stderr
    z = (tab.transmittance(TABLE_DEG) - t) / np.hypot(t_se, tab_t_se)
    assert np.abs(z).max() < 4 and np.sqrt(np.mean(z**2)) < 1.5, z
    assert abs(tab.reflectance - r) < 4 * math.hypot(r_se, tab_r_se)
    grid = Grid(3.0, 6.0)
    spline, hi_se = tb.higher_orders_table(1.5, 45.0, (3.0, 6.0))
    hi, se = ms.higher_orders_map(1.5, a, 45.0, grid, rays[2], tb.SEED)
    omega = grid.cos_solid_angle_sr
    albedo_tab = float((spline(math.log(a)) * omega).sum())
    assert abs(albedo_tab - float((hi * omega).sum())) < 4 * math.hypot(se, hi_se.max())


def test_the_white_furnace_through_the_tables(fresh):
    """A lossless coating over a white base returns 1 within 4 stated errors."""
    a = _between(fresh)
    grid = Grid(3.0, 6.0)
    omega = grid.cos_solid_angle_sr
    body = tb.tabulated_ms(1.5, a, *AB)
    for theta_i in (20.0, 60.0):
        single = first_surface_s0(1.5, a, theta_i, grid)
        first = tb.tabulated_first_surface(single, 1.5, a, theta_i, grid)
        albedo = float(((first + body.bin_map(1.0, theta_i, grid)) * omega).sum())
        _, hi_se = tb.higher_orders_table(1.5, theta_i, (3.0, 6.0))
        se = math.hypot(body.body_stderr(1.0, theta_i), hi_se.max())
        assert se < 3e-3
        assert abs(albedo - 1.0) < 4 * se, (theta_i, albedo, se)


def test_the_tabulated_map_is_smooth_in_alpha(fresh):
    """Finite differences at steps 1e-3 and 1e-5 agree to 1e-3 of the slope's scale.

    The direct walks jump by single rays changing bins at such steps; a spline does not.
    """
    a = _between(fresh)
    grid = Grid(3.0, 6.0)
    omega = grid.cos_solid_angle_sr

    def albedo(alpha: float) -> float:
        body = tb.tabulated_ms(1.5, alpha, *AB).bin_map(0.3, 45.0, grid)
        first = tb.tabulated_first_surface(
            first_surface_s0(1.5, alpha, 45.0, grid), 1.5, alpha, 45.0, grid
        )
        return float(((first + body) * omega).sum())

    slopes = [(albedo(a * (1 + h)) - albedo(a)) / (a * h) for h in (1e-3, 1e-5)]
    assert abs(slopes[1]) > 1e-2  # the albedo does move with alpha
    assert abs(slopes[0] - slopes[1]) < 1e-3 * abs(slopes[1]), slopes


@pytest.mark.parametrize(
    ("n", "alpha", "theta_i", "steps"),
    [(1.5, 0.35, 15.0, (3.0, 6.0)), (2.2, 0.05, 60.0, (3.0, 6.0)), (1.2, 0.6, 0.0, (2.0, 4.0))],
)
def test_the_s0_map_is_the_mueller_maps_m00(n, alpha, theta_i, steps):
    """The S0-only first surface equals the Mueller map's M00 to round-off."""
    cfg = TraceConfig(
        theta_i_deg=theta_i,
        substrate=Substrate.lambertian(0.5),
        coating=Coating(n=n, alpha=alpha, thickness_nm=1000.0),
        theta_step_deg=steps[0],
        phi_step_deg=steps[1],
    )
    want = first_surface_map(cfg)[..., 0, 0]
    got = first_surface_s0(n, alpha, theta_i, Grid(*steps))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * want.max())


def test_the_disk_cache_is_reused_and_a_damaged_file_rebuilt(fresh, tmp_path):
    """A second process reads the file instead of walking; a damaged file is not trusted.

    Other walk counts are another key (another file), never the first file.
    """
    fresh.setenv("XDG_CACHE_HOME", str(tmp_path))
    fresh.setattr(tb, "ALPHA_RANGE", NARROW)
    calls: list[float] = []
    _smooth_walks(fresh, calls)
    first = tb.ms_table(1.5, *AB)[1](math.log(0.3))
    assert len(calls) == 4
    files = list((tmp_path / "labbrdf" / "tracer").glob("exit-*.op"))
    assert len(files) == 1
    tb.clear_memory()
    with warnings.catch_warnings():
        warnings.simplefilter("error", CacheWarning)
        again = tb.ms_table(1.5, *AB)[1](math.log(0.3))
    assert len(calls) == 4 and again == first
    tb.ms_table(1.5, 0.0, 1000.0, 555.0)  # a clear coating: the same table at any wavelength
    assert len(calls) == 4
    raw = bytearray(files[0].read_bytes())
    raw[-5] ^= 0xFF
    files[0].write_bytes(bytes(raw))
    tb.clear_memory()
    with pytest.warns(CacheWarning, match=files[0].name):
        rebuilt = tb.ms_table(1.5, *AB)[1](math.log(0.3))
    assert len(calls) == 8 and rebuilt == first
    fresh.setattr(tb, "NODE_RAYS", (100, 400, 100))
    tb.ms_table(1.5, *AB)
    assert len(calls) == 12
    assert len(list((tmp_path / "labbrdf" / "tracer").glob("exit-*.op"))) == 2


def test_outside_the_tables_the_model_walks_directly(fresh):
    """An alpha_top beyond the tabulated range is the direct walks' form, not extrapolated."""
    from labbrdf import models

    fresh.setattr(tb, "ALPHA_RANGE", NARROW)
    for name, rays in (("TABLE_RAYS", 200), ("EMISSION_RAYS", 2_500), ("HIGHER_ORDER_RAYS", 500)):
        fresh.setattr(ms, name, rays)
    ms.coated_lambert_ms.cache_clear()
    try:
        lay = models.get("layered", base="diffuse", scattering="multiple", grid="3x6")
        p = {"alpha_top": 0.5, "albedo": 0.4}
        got = lay.hemispherical([30.0], p)
        cfg = TraceConfig(
            theta_i_deg=30.0,
            substrate=Substrate.lambertian(0.4),
            coating=Coating(n=1.5, alpha=0.5, thickness_nm=1000.0),
            theta_step_deg=3.0,
            phi_step_deg=6.0,
        )
        grid = Grid(3.0, 6.0)
        body = ms.coated_lambert_ms(1.5, 0.5, 0.0, 1000.0, 550.0).bin_map(0.4, 30.0, grid)
        want = float(((ms.first_surface_ms(cfg)[0] + body) * grid.cos_solid_angle_sr).sum())
    finally:
        ms.coated_lambert_ms.cache_clear()
    assert got is not None
    assert got[0] == pytest.approx(want, rel=1e-12)
