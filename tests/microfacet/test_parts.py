"""The pieces the distribution modules share."""

from __future__ import annotations

import math

import numpy as np
import pytest

from labbrdf.microfacet import beckmann, ggx, parts


@pytest.mark.parametrize("s0", [1e-9, 0.3, 1e9])
def test_score_root_finds_the_root_from_either_side(s0):
    root = parts.score_root(lambda s: math.log(s / 0.037), s0, 1e-12, 1e12)
    assert root == pytest.approx(0.037, rel=1e-12)


@pytest.mark.parametrize("dist", [ggx, beckmann])
def test_g1_is_one_over_one_plus_lambda_above_and_zero_below(dist):
    wz = np.array([-0.5, 0.0, 0.2, 0.7, 1.0])
    lam = dist.smith_lambda(wz, 0.3)
    np.testing.assert_array_equal(lam[0], -1.0 - dist.smith_lambda(0.5, 0.3))
    g1 = parts.smith_g1(dist.smith_lambda, wz, 0.3)
    np.testing.assert_array_equal(g1[:2], 0.0)
    np.testing.assert_allclose(g1[2:], 1.0 / (1.0 + lam[2:]), rtol=1e-15)
    assert g1[-1] == 1.0  # Lambda vanishes at the pole


def test_tan2_is_finite_at_the_horizon():
    z, t2 = parts.tan2([0.0, 0.6, 1.0])
    assert np.isfinite(t2).all() and t2[0] > 1e290
    np.testing.assert_allclose(t2[1:], [0.64 / 0.36, 0.0])
