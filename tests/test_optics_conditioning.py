"""Near normal incidence psi/Delta do not determine n, k: the inversion says so."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from labbrdf import ellipsometry, optics


@pytest.mark.parametrize("n", [1.5 + 0j, 3.9 + 0.02j, 2.3 + 3.0j])
@pytest.mark.parametrize("theta", [2.0, 10.0, 45.0, 75.0])
def test_condition_number_agrees_with_the_jacobian_of_ellipsometry(n, theta):
    # two derivations: the closed form here, complex differentiation of the inversion there
    psi, delta = optics.psi_delta(n, theta)
    a = optics.nk_condition_number(psi, delta, theta)
    b = ellipsometry.condition_number(psi, delta, theta)
    assert a == pytest.approx(b, rel=1e-9)


def test_inversion_near_normal_incidence_warns_with_the_condition_number():
    psi, delta = optics.psi_delta(1.5 + 0j, 1e-6)
    with pytest.warns(optics.IllConditionedWarning, match=r"condition number up to 2\.54e\+15"):
        got = optics.nk_from_psi_delta(psi, delta, 1e-6)
    assert abs(got - 1.5) > 0.1  # what the warning is about: the index is lost


def test_well_conditioned_inversion_is_silent_and_exact():
    psi, delta = optics.psi_delta(1.5 + 0j, 45.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = optics.nk_from_psi_delta(psi, delta, 45.0)
    assert got == pytest.approx(1.5, rel=1e-12)


def test_threshold_is_crossed_where_the_documented_angle_says():
    # NK_COND_MAX = 300: for glass below about 4 deg (the condition number grows as 1/theta^2)
    th = np.array([3.0, 5.0])
    psi, delta = optics.psi_delta(1.5 + 0j, th)
    cond = optics.nk_condition_number(psi, delta, th)
    assert cond[0] > optics.NK_COND_MAX > cond[1]
