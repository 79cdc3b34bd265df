"""Form of a height map: the share a quadric carries and its shape, against exact surfaces."""

from __future__ import annotations

import math

import numpy as np
import pytest

from labbrdf.roughness.form import FORM_DOMINATES, FORMS, check_form
from labbrdf.roughness.topography import level

N, PX, R = 200, 1e-6, 10e-3


def grid() -> tuple[np.ndarray, np.ndarray]:
    x, y = np.meshgrid(np.arange(N) * PX, np.arange(N) * PX, indexing="ij")
    return x - x.mean(), y - y.mean()


def rough(seed: int = 0, sigma: float = 2e-9) -> np.ndarray:
    return sigma * np.random.default_rng(seed).standard_normal((N, N))


@pytest.mark.parametrize("axis_deg", [0.0, 30.0, -60.0, 90.0])
def test_a_cylinder_is_named_with_its_radius_and_axis(axis_deg):
    x, y = grid()
    t = math.radians(axis_deg)
    across = -math.sin(t) * x + math.cos(t) * y  # distance from the axis
    z = np.sqrt(R**2 - across**2) + rough()
    fc = check_form(z, PX, 1)
    assert fc is not None and fc.dominated and fc.shape == "cylinder"
    # a circle of radius R over +-100 um is a parabola to (100 um / R)^2 = 1e-4 relative
    assert fc.radii_m[0] == pytest.approx(R, rel=1e-3)
    assert fc.axis_deg == pytest.approx(axis_deg if axis_deg != -90 else 90.0, abs=0.1)
    assert "cylinder of radius 10 mm" in fc.message() and "--form quadric" in fc.message()


def test_a_sphere_and_a_saddle():
    x, y = grid()
    sphere = check_form(np.sqrt(R**2 - x**2 - y**2), PX, 1)
    assert sphere.shape == "sphere" and sphere.radii_m == pytest.approx((R, R), rel=1e-3)
    saddle = check_form((x**2 - y**2) / (2 * R), PX, 1)
    assert saddle.shape == "saddle" and saddle.radii_m == pytest.approx((R, R), rel=1e-9)


def test_the_share_is_the_variance_the_quadric_removes():
    x, y = grid()
    curv, noise = x**2 / (2 * R), rough(1, sigma=5e-8)
    fc = check_form(curv + noise, PX, 1)
    expect = 1 - np.mean(level(curv + noise, 2) ** 2) / np.mean(level(curv + noise, 1) ** 2)
    assert fc.share == pytest.approx(expect, rel=1e-12)
    assert fc.dominated is (fc.share >= FORM_DOMINATES)
    flat = check_form(rough(2), PX, 1)  # white noise: the quadric takes ~6/N^2 of it
    assert flat.share < 1e-3 and not flat.dominated


def test_a_profile_is_an_arc_and_a_quadric_levelling_has_nothing_to_check():
    x = (np.arange(3000) - 1500.0) * PX
    fc = check_form(x**2 / (2 * R), PX, 0)
    assert fc.shape == "arc" and fc.radii_m[0] == pytest.approx(R, rel=1e-9)
    assert math.isnan(fc.axis_deg) and fc.to_dict()["axis_deg"] is None
    assert check_form(x**2, PX, FORMS["quadric"]) is None
