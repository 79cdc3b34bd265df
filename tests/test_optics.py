"""Oracle-free tests of labbrdf.optics: invariants, limits, shapes, errors (film functions too).

Tolerances are stated next to each assertion in units of the float64 epsilon ``EPS`` and
follow from the number of rounding operations. The inverse problem (psi, Delta to n, k) is
tested with :mod:`labbrdf.ellipsometry` in ``tests/test_ellipsometry.py``.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from labbrdf import optics
from labbrdf.films import onefilm

EPS = np.finfo(float).eps
N_AL = 1.55 + 7.71j
N_CU = 0.23 + 3.63j
N_SI = 3.88 + 0.02j
THETA = np.linspace(0.0, 90.0, 181)
#: a spread of substrates: dielectrics (also below the ambient), weak absorbers, metals
MEDIA = [1.5, 1.0001, 4.0, 0.5, 1.5 + 1e-4j, N_SI, N_AL, N_CU, 0.05 + 4.0j, 2.0 + 0.5j]


# --------------------------------------------------------------------------------------
# Fresnel: analytic limits and invariants
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("n2", MEDIA)
def test_normal_incidence_gives_rs_equal_minus_rp_and_the_textbook_reflectance(n2):
    rs, rp, ts, tp = optics.fresnel(1.0, n2, 0.0)
    r0 = (1.0 - n2) / (1.0 + n2)
    # a handful of complex operations on O(1) numbers: a few eps
    assert abs(rs - r0) <= 8 * EPS
    assert abs(rp + rs) <= 8 * EPS
    Rs, Rp = optics.reflectance(1.0, n2, 0.0)
    assert abs(Rs - Rp) <= 8 * EPS
    assert abs(ts - tp) <= 8 * EPS  # both 2/(1 + N)


def test_normal_incidence_glass_reflectance_is_four_percent_exactly_representable():
    Rs, Rp = optics.reflectance(1.0, 1.5, 0.0)
    assert Rs == pytest.approx(0.04, rel=4 * EPS)
    assert Rp == pytest.approx(0.04, rel=4 * EPS)


@pytest.mark.parametrize(("n1", "n2"), [(1.0, 1.5), (1.5, 1.0), (1.0, 4.0), (1.33, 1.5)])
def test_rp_vanishes_at_brewster_angle(n1, n2):
    theta_b = np.degrees(np.arctan(n2 / n1))
    _, rp, _, _ = optics.fresnel(n1, n2, theta_b)
    # theta_b carries ~2 eps relative error from arctan and the degree conversion; rp
    # changes by |drp/dtheta| per radian there (central difference), plus a few eps of
    # round-off in rp itself.
    h = 1e-6
    _, rp_hi, _, _ = optics.fresnel(n1, n2, theta_b + h)
    _, rp_lo, _, _ = optics.fresnel(n1, n2, theta_b - h)
    slope = abs(rp_hi - rp_lo) / np.radians(2 * h)
    assert abs(rp) <= slope * 4 * EPS * np.radians(theta_b) + 8 * EPS
    # and it is a genuine zero crossing: rp changes sign across the Brewster angle
    assert np.sign(rp_hi.real) != np.sign(rp_lo.real)


def test_total_internal_reflection_has_unit_modulus_and_an_evanescent_branch():
    theta_c = np.degrees(np.arcsin(1.0 / 1.5))
    theta = np.linspace(theta_c + 0.01, 90.0, 500)
    rs, rp, _, _, cos_t = optics.fresnel_cos(1.5, 1.0, np.cos(np.radians(theta)))
    # |r| = |a - ib| / |a + ib| with a, b computed once: a few eps
    np.testing.assert_allclose(np.abs(rs), 1.0, rtol=0, atol=4 * EPS)
    np.testing.assert_allclose(np.abs(rp), 1.0, rtol=0, atol=4 * EPS)
    # physical branch: purely imaginary cos_t with a decaying field (Im > 0)
    assert np.all(cos_t.real == 0)
    assert np.all(cos_t.imag > 0)
    Ts, Tp = optics.transmittance(1.5, 1.0, theta)
    assert np.all(Ts == 0) and np.all(Tp == 0)


def test_signed_zero_extinction_does_not_flip_the_evanescent_branch():
    # N = 1 - 0j has k = -0.0 (accepted: it is not < 0); np.sqrt(-x - 0j) = -i sqrt(x)
    # would give a growing wave and |t| > 0 with the wrong phase.
    a = optics.fresnel(1.5, complex(1.0, 0.0), 60.0)
    b = optics.fresnel(1.5, complex(1.0, -0.0), 60.0)
    for x, y in zip(a, b, strict=True):
        assert x == y
    _, _, _, _, cos_t = optics.fresnel_cos(1.5, complex(1.0, -0.0), 0.5)
    assert cos_t.imag > 0


def test_weakly_absorbing_incidence_medium_is_continuous_with_the_lossless_one():
    # coating (k = 1e-9) to air, the tracer's upward crossing. kx = n1 sin(theta) is then
    # complex and Im(kz2^2) < 0: the principal root would pick the growing evanescent wave
    # above the critical angle (an O(1) change of the phases). First-order perturbation:
    # |d kz2| = |d(kz2^2)| / (2 |kz2|) <= 3e-9 / (2 * 0.05) away (>= 0.5 deg) from the
    # critical angle, and r moves by at most a few times that.
    theta_c = np.degrees(np.arcsin(1 / 1.5))
    theta = np.concatenate([np.linspace(0, theta_c - 0.5, 50), np.linspace(theta_c + 0.5, 90, 50)])
    cos_i = np.cos(np.radians(theta))
    lossy = optics.fresnel_cos(1.5 + 1e-9j, 1.0, cos_i)
    lossless = optics.fresnel_cos(1.5, 1.0, cos_i)
    for a, b in zip(lossy, lossless, strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-6)


@pytest.mark.parametrize("n2", [N_AL, N_CU, N_SI, 0.05 + 4.0j, 1.5 + 1e-4j])
def test_absorbing_substrate_uses_the_decaying_branch(n2):
    _, _, _, _, cos_t = optics.fresnel_cos(1.0, n2, np.cos(np.radians(THETA)))
    kz = n2 * cos_t
    assert np.all(kz.imag > 0)
    assert np.all(kz.real >= 0)


@pytest.mark.parametrize("n2", [1.5, N_AL, N_CU, 4.0, 0.5])
def test_grazing_incidence_reflects_everything_with_rs_rp_minus_one(n2):
    rs, rp, _, _ = optics.fresnel(1.0, n2, 90.0)
    # cos(90 deg) evaluates to 6.1e-17, so r = -1 + O(1e-16 / |N cos_t|)
    assert abs(rs + 1) <= 4e-16 / abs(np.sqrt(n2 * n2 - 1 + 0j)) + 4 * EPS
    assert abs(rp + 1) <= 4e-16 * abs(n2) ** 2 / abs(np.sqrt(n2 * n2 - 1 + 0j)) + 4 * EPS


@pytest.mark.parametrize(
    ("n1", "n2", "theta"),
    [
        (1.0, 1.5, THETA),  # air to glass, all angles
        (1.5, 1.0, np.linspace(0.0, 41.8, 100)),  # glass to air below the critical angle
        (1.5, 1.0, np.linspace(41.82, 90.0, 100)),  # ... and above it (T = 0)
        (1.33, 2.4, THETA),
        (1.0, N_AL, THETA),  # absorbing substrate, lossless ambient: Poynting T
        (1.0, N_SI, THETA),
        (1.5, 1.5 + 0.3j, THETA),
    ],
)
def test_reflectance_plus_transmittance_is_one_with_a_lossless_ambient(n1, n2, theta):
    Rs, Rp = optics.reflectance(n1, n2, theta)
    Ts, Tp = optics.transmittance(n1, n2, theta)
    # each of R, T is a few operations on O(1) numbers; the beam-area factor divides by
    # Re(n1 cos_i), which near 90 deg multiplies the round-off of |t|^2 (itself O(cos_i^2))
    np.testing.assert_allclose(Rs + Ts, 1.0, rtol=0, atol=16 * EPS)
    np.testing.assert_allclose(Rp + Tp, 1.0, rtol=0, atol=16 * EPS)


def test_fresnel_cos_is_the_same_computation_as_fresnel():
    n2 = np.array([1.5, N_AL, 0.5])[:, None]
    a = optics.fresnel(1.0, n2, THETA)
    b = optics.fresnel_cos(1.0, n2, np.cos(np.radians(THETA)))
    for x, y in zip(a, b[:4], strict=True):
        np.testing.assert_array_equal(x, y)


def test_identical_media_reflect_nothing_even_at_exact_grazing():
    rs, rp, ts, tp, _ = optics.fresnel_cos(1.5, 1.5, np.array([0.0, 0.3, 1.0]))
    np.testing.assert_array_equal(rs, 0)
    np.testing.assert_array_equal(rp, 0)
    np.testing.assert_array_equal(ts, 1)
    np.testing.assert_array_equal(tp, 1)


def test_swapping_media_reverses_the_sign_of_r_stokes_relations():
    # r' = -r and t t' = 1 - r^2 (Stokes relations), the identities the Airy sum uses
    theta = np.linspace(0, 40, 41)
    rs, rp, ts, tp, cos_t = optics.fresnel_cos(1.0, 1.5, np.cos(np.radians(theta)))
    rs2, rp2, ts2, tp2, _ = optics.fresnel_cos(1.5, 1.0, cos_t.real)
    np.testing.assert_allclose(rs2, -rs, rtol=0, atol=8 * EPS)
    np.testing.assert_allclose(rp2, -rp, rtol=0, atol=8 * EPS)
    np.testing.assert_allclose(ts * ts2, 1 - rs**2, rtol=0, atol=8 * EPS)
    np.testing.assert_allclose(tp * tp2, 1 - rp**2, rtol=0, atol=8 * EPS)


def test_transmission_factor_is_snell_beam_ratio_for_lossless_media():
    cos_i = np.cos(np.radians(30.0))
    _, _, _, _, cos_t = optics.fresnel_cos(1.0, 1.5, cos_i)
    expected = 1.5 * np.sqrt(1 - (np.sin(np.radians(30.0)) / 1.5) ** 2) / cos_i
    assert optics.transmission_factor(1.0, 1.5, cos_i, cos_t) == pytest.approx(
        expected, rel=8 * EPS
    )
    assert optics.transmission_factor(1.0, 1.5, 0.0, cos_t) == 0.0


# --------------------------------------------------------------------------------------
# Mueller algebra
# --------------------------------------------------------------------------------------


def _jones_to_mueller(j: np.ndarray) -> np.ndarray:
    """Independent Jones -> Mueller conversion in the LB Stokes basis (s, p).

    S = [|Es|^2+|Ep|^2, |Es|^2-|Ep|^2, 2 Re(Es Ep*), 2 Im(Es* Ep)] = A (E x E*) with
    E x E* = [Es Es*, Es Ep*, Ep Es*, Ep Ep*]; M = A (J x J*) A^-1. S3 = 2 Im(Es* Ep) is
    +1 for a field turning from s to p under exp(-i omega t) (Es = 1, Ep = i).
    """
    a = np.array([[1, 0, 0, 1], [1, 0, 0, -1], [0, 1, 1, 0], [0, 1j, -1j, 0]])
    m = a @ np.kron(j, j.conj()) @ np.linalg.inv(a)
    assert np.allclose(m.imag, 0, atol=1e-14)
    return m.real


@pytest.mark.parametrize("n2", [1.5, N_AL, 0.5])
@pytest.mark.parametrize("theta", [0.0, 20.0, 45.0, 70.0, 89.0])
def test_mueller_reflection_equals_the_mueller_matrix_of_the_jones_matrix(n2, theta):
    rs, rp, _, _ = optics.fresnel(1.0, n2, theta)
    m = optics.mueller_reflection(rs, rp)
    expected = _jones_to_mueller(np.diag([complex(rs), complex(rp)]))
    np.testing.assert_allclose(m, expected, rtol=0, atol=8 * EPS)


def test_mirror_at_normal_incidence_flips_s2_and_s3():
    rs, rp, _, _ = optics.fresnel(1.0, N_AL, 0.0)
    m = optics.mueller_reflection(rs, rp)
    r = abs(rs) ** 2
    np.testing.assert_allclose(np.diag(m), [r, r, -r, -r], rtol=4 * EPS)


def test_mueller_reflection_sign_of_m23_is_that_of_im_rs_rp_conj():
    # Al at 45 deg: M23 = +0.15713 in the LB tables (oracles README section 2)
    rs, rp, _, _ = optics.fresnel(1.0, N_AL, 45.0)
    m = optics.mueller_reflection(rs, rp)
    assert m[2, 3] == pytest.approx(0.15713, abs=5e-6)
    assert m[2, 2] == pytest.approx(-0.88713, abs=5e-6)


@pytest.mark.parametrize("theta", [0.0, 30.0, 56.0, 70.0, 89.0])
def test_reflection_plus_transmission_mueller_conserves_s0_at_lossless_interface(theta):
    cos_i = np.cos(np.radians(theta))
    rs, rp, ts, tp, cos_t = optics.fresnel_cos(1.0, 1.5, cos_i)
    factor = optics.transmission_factor(1.0, 1.5, cos_i, cos_t)
    total = optics.mueller_reflection(rs, rp) + optics.mueller_transmission(ts, tp, factor)
    # first row [1, 0, 0, 0]: intensity conserved for every input Stokes vector
    np.testing.assert_allclose(total[0], [1, 0, 0, 0], rtol=0, atol=16 * EPS)


def test_mueller_transmission_diagonal_block_is_plus_sqrt_ts_tp_not_minus():
    # Dong 2022 eq. (12) prints -2 sqrt(Ts Tp); derived from ts, tp it is +
    cos_i = np.cos(np.radians(40.0))
    _, _, ts, tp, cos_t = optics.fresnel_cos(1.0, 1.5, cos_i)
    factor = optics.transmission_factor(1.0, 1.5, cos_i, cos_t)
    m = optics.mueller_transmission(ts, tp, factor)
    Ts, Tp = optics.transmittance(1.0, 1.5, 40.0)
    assert m[2, 2] == pytest.approx(np.sqrt(Ts * Tp), rel=8 * EPS)
    assert m[3, 3] == m[2, 2]
    assert m[2, 3] == 0 and m[3, 2] == 0  # ts, tp real and in phase for a dielectric
    np.testing.assert_allclose(m[0, :2], [(Ts + Tp) / 2, (Ts - Tp) / 2], rtol=8 * EPS)
    expected = float(factor) * _jones_to_mueller(np.diag([complex(ts), complex(tp)]))
    np.testing.assert_allclose(m, expected, rtol=0, atol=8 * EPS)


def test_mueller_of_a_product_of_jones_matrices_is_the_product_of_muellers():
    rs1, rp1, _, _ = optics.fresnel(1.0, N_AL, 50.0)
    rs2, rp2, _, _ = optics.fresnel(1.0, N_CU, 20.0)
    lhs = optics.mueller_reflection(rs1, rp1) @ optics.mueller_reflection(rs2, rp2)
    rhs = optics.mueller_reflection(rs1 * rs2, rp1 * rp2)
    np.testing.assert_allclose(lhs, rhs, rtol=0, atol=8 * EPS)


def test_rotation_matrix_keeps_intensity_and_has_m00_one():
    m = optics.mueller_rotation(np.linspace(-180, 180, 37))
    np.testing.assert_array_equal(m[:, 0, 0], 1.0)  # Dong 2022 eq. (17) prints 0
    np.testing.assert_array_equal(m[:, 3, 3], 1.0)
    np.testing.assert_array_equal(m[:, 0, 1:], 0.0)


def test_rotation_sense_s_polarised_light_reads_minus_s2_in_the_frame_rotated_by_45():
    # s' = (s + p)/sqrt2: E = s = (s' - p')/sqrt2, so S2' = 2 Re(Es' Ep'*) = -1
    s = optics.mueller_rotation(45.0) @ np.array([1.0, 1.0, 0.0, 0.0])
    np.testing.assert_allclose(s, [1, 0, -1, 0], rtol=0, atol=2 * EPS)
    # direct construction with a field vector in the rotated frame
    a = np.radians(30.0)
    e = np.array([0.6, 0.8j])  # some elliptical state (Es, Ep)
    e_rot = np.array([np.cos(a) * e[0] + np.sin(a) * e[1], -np.sin(a) * e[0] + np.cos(a) * e[1]])

    def stokes(f):
        return np.array(
            [
                abs(f[0]) ** 2 + abs(f[1]) ** 2,
                abs(f[0]) ** 2 - abs(f[1]) ** 2,
                2 * (f[0] * f[1].conj()).real,
                2 * (f[0].conj() * f[1]).imag,
            ]
        )

    np.testing.assert_allclose(
        optics.mueller_rotation(30.0) @ stokes(e), stokes(e_rot), rtol=0, atol=4 * EPS
    )


def test_rotations_compose_and_invert():
    a, b = 17.0, -52.0
    np.testing.assert_allclose(
        optics.mueller_rotation(a) @ optics.mueller_rotation(b),
        optics.mueller_rotation(a + b),
        rtol=0,
        atol=4 * EPS,
    )
    np.testing.assert_allclose(
        optics.mueller_rotation(a) @ optics.mueller_rotation(-a), np.eye(4), rtol=0, atol=4 * EPS
    )


def test_dop_of_known_states():
    stokes = np.array(
        [[1, 0, 0, 0], [1, 1, 0, 0], [2, 0, 0, -2], [1, 0.3, 0.4, 0], [4, 0, 0, 0]], float
    )
    np.testing.assert_allclose(optics.dop(stokes), [0, 1, 1, 0.5, 0], rtol=2 * EPS)


def test_dop_of_zero_intensity_is_nan_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = optics.dop(np.zeros((3, 4)))
    assert np.all(np.isnan(out))


# --------------------------------------------------------------------------------------
# ellipsometry
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1.5, N_AL, N_CU, N_SI])
def test_normal_incidence_gives_psi_45_delta_180(n):
    psi, delta = optics.psi_delta(n, 0.0)
    assert psi == pytest.approx(45.0, abs=8 * EPS * 45)
    assert delta == pytest.approx(180.0, abs=8 * EPS * 180)


def test_delta_is_180_below_and_0_above_brewster_for_a_dielectric_even_with_signed_zero_k():
    for n in (1.5, complex(1.5, -0.0)):
        _, delta = optics.psi_delta(n, [30.0, 70.0])
        np.testing.assert_array_equal(delta, [180.0, 0.0])


def test_delta_wrap_maps_a_rounding_negative_zero_to_0_not_360():
    # np.mod(-1e-20, 360) rounds to 360.0, outside [0, 360)
    np.testing.assert_array_equal(
        optics._wrap360(np.array([-1e-20, -0.0, 360.0, -90.0, 725.0])), [0, 0, 0, 270, 5]
    )


def test_delta_of_bare_absorbers_lies_between_0_and_180():
    for n in (N_AL, N_CU, N_SI, 0.05 + 4.0j):
        _, delta = optics.psi_delta(n, np.linspace(1, 89, 89))
        assert np.all((delta > 0) & (delta < 180))


def test_tan_psi_squared_is_rp_over_rs():
    psi, _ = optics.psi_delta(N_CU, THETA)
    Rs, Rp = optics.reflectance(1.0, N_CU, THETA)
    np.testing.assert_allclose(np.tan(np.radians(psi)) ** 2, Rp / Rs, rtol=16 * EPS)


def test_psi_delta_depends_only_on_the_relative_index():
    a = optics.psi_delta(N_AL * 1.33, 60.0, n_ambient=1.33)
    b = optics.psi_delta(N_AL, 60.0)
    np.testing.assert_allclose(a, b, rtol=16 * EPS)


# --------------------------------------------------------------------------------------
# Berger's corrected real form
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("n2", [N_AL, N_CU, N_SI, 1.5, 0.05 + 4.0j, 4.0j, 1.0 + 1e-9j])
def test_berger_form_equals_fresnel_reflectances(n2):
    f_perp, f_par = optics.berger_reflectances(n2.real, n2.imag, THETA)
    Rs, Rp = optics.reflectance(1.0, n2, THETA)
    # two closed forms of the same quantities, each a few tens of operations
    np.testing.assert_allclose(f_perp, Rs, rtol=64 * EPS, atol=4 * EPS)
    np.testing.assert_allclose(f_par, Rp, rtol=64 * EPS, atol=4 * EPS)


def test_berger_garbled_numerator_differs_from_the_corrected_form_away_from_45_deg():
    # docs/models.md 3.4: (a - sin g) instead of (a - sin g tan g) errs by 43 % for Cu at
    # 75 deg and coincides at 45 deg; our function must not be the garbled one.
    n, k = N_CU.real, N_CU.imag
    for g, differs in ((45.0, False), (75.0, True)):
        f_perp, f_par = optics.berger_reflectances(n, k, g)
        s = np.sin(np.radians(g))
        a_b = np.sqrt(N_CU**2 - s**2)
        a, b = a_b.real, a_b.imag
        garbled = f_perp * ((a - s) ** 2 + b**2) / ((a + s * np.tan(np.radians(g))) ** 2 + b**2)
        assert (abs(garbled - f_par) > 0.1 * f_par) == differs


# --------------------------------------------------------------------------------------
# shapes: scalar, ndarray and (2, 3, 1) broadcast give the same numbers
# --------------------------------------------------------------------------------------

_THETA_GRID = np.array([[[5.0], [30.0], [60.0]], [[0.0], [45.0], [89.0]]])  # (2, 3, 1)
_N_ROW = np.array([1.5, N_AL, 0.7, 2.0 + 0.1j])  # (4,)

_CASES = {
    "fresnel": lambda n, t: optics.fresnel(1.0, n, t),
    "fresnel_cos": lambda n, t: optics.fresnel_cos(1.0, n, np.cos(np.radians(t))),
    "reflectance": lambda n, t: optics.reflectance(1.0, n, t),
    "transmittance": lambda n, t: optics.transmittance(1.0, n, t),
    "psi_delta": lambda n, t: optics.psi_delta(n, t),
    "berger": lambda n, t: optics.berger_reflectances(np.real(n), np.imag(n), t),
    "film_amplitudes": lambda n, t: onefilm.film_amplitudes(1.0, 1.38, n, 120.0, 600.0, t),
    "film_incoherent": lambda n, t: onefilm.film_reflectance_incoherent(
        1.0, 1.38, n, 120.0, 600.0, t
    ),
    "film_mueller": lambda n, t: (onefilm.film_mueller_incoherent(1.0, 1.38, n, 120.0, 600.0, t),),
    "mueller_reflection": lambda n, t: (
        optics.mueller_reflection(*optics.fresnel(1.0, n, t)[:2]),
    ),
}


@pytest.mark.parametrize("name", sorted(_CASES))
def test_scalar_ndarray_and_broadcast_inputs_agree(name):
    func = _CASES[name]
    grid = func(_N_ROW, _THETA_GRID)
    for out in grid:
        assert out.shape[:3] == (2, 3, 4)
    for i, j, k in np.ndindex(2, 3, 4):
        scalar = func(_N_ROW[k], float(_THETA_GRID[i, j, 0]))
        for a, b in zip(grid, scalar, strict=True):
            assert isinstance(b, np.ndarray)
            # numpy's SIMD loops for complex exp and division may round 1 ulp differently
            # from the scalar path; a few eps of the O(1) results allows that, nothing more
            np.testing.assert_allclose(a[i, j, k], b, rtol=4 * EPS, atol=4 * EPS)
    flat = func(_N_ROW, np.full(4, 30.0))
    for a, b in zip(func(_N_ROW, _THETA_GRID), flat, strict=True):
        np.testing.assert_allclose(a[0, 1], b, rtol=4 * EPS, atol=4 * EPS)


def test_mueller_rotation_and_dop_shapes():
    assert optics.mueller_rotation(10.0).shape == (4, 4)
    assert optics.mueller_rotation(np.zeros((2, 3, 1))).shape == (2, 3, 1, 4, 4)
    assert optics.dop(np.ones((2, 3, 1, 4))).shape == (2, 3, 1)
    assert optics.dop([1.0, 0.0, 0.0, 0.0]).shape == ()
    m = optics.mueller_transmission(np.ones((2, 1)), np.ones(3), np.ones((2, 3)))
    assert m.shape == (2, 3, 4, 4)


def test_no_runtime_warning_at_the_edges_of_the_valid_domain():
    theta_c = float(np.degrees(np.arcsin(1.0 / 1.5)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for n1, n2 in ((1.0, 1.5), (1.5, 1.0), (1.0, 1.0), (1.5, 1.5 + 0j), (1.0, 4.0j)):
            theta = np.array([0.0, theta_c, 45.0, 90.0])
            optics.fresnel(n1, n2, theta)
            optics.transmittance(n1, n2, theta)
            optics.fresnel_cos(n1, n2, np.array([0.0, 1.0]))
        optics.psi_delta(4.0j, [0.0, 90.0])
        optics.berger_reflectances(1.0, 0.0, [0.0, 90.0])
        optics.berger_reflectances(0.0, 3.0, [0.0, 90.0])
        onefilm.film_mueller_incoherent(1.0, 1.5, N_AL, [0.0, 1e7], 650.0, 90.0)


# --------------------------------------------------------------------------------------
# error paths
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: optics.fresnel(1.0, 1.5 - 0.1j, 30.0), r"n2: the extinction coefficient k"),
        (lambda: optics.fresnel(-1.0, 1.5, 30.0), r"n1: the real part n .* must be >= 0"),
        (lambda: optics.fresnel(1.0, 0.0, 30.0), r"n2: the index N = n \+ ik must not be 0"),
        (lambda: optics.fresnel(1.0, np.nan, 30.0), r"n2: expected finite values"),
        (lambda: optics.fresnel(1.0, "glass", 30.0), r"n2: expected a number"),
        (lambda: optics.fresnel(1.0, 1.5, 91.0), r"theta_i_deg: expected an angle in \[0, 90\]"),
        (lambda: optics.fresnel(1.0, 1.5, -1.0), r"theta_i_deg: expected an angle in \[0, 90\]"),
        (lambda: optics.fresnel(1.0, 1.5, np.inf), r"theta_i_deg: expected finite values"),
        (lambda: optics.fresnel(1.0, 1.5, 30 + 1j), r"theta_i_deg: expected real values"),
        (lambda: optics.berger_reflectances(1.5 + 1j, 1.0, 30.0), r"n: expected real values"),
        (lambda: optics.reflectance(1.0, 1.5, [10, 100]), r"theta_i_deg: expected an angle"),
        (lambda: optics.transmittance(1.0 - 1j, 1.5, 10), r"n1: the extinction coefficient"),
        (lambda: optics.mueller_reflection(np.nan, 0.1), r"rs: expected finite values"),
        (lambda: optics.mueller_reflection(0.1, np.inf), r"rp: expected finite values"),
        (lambda: optics.mueller_transmission(1.0, 1.0, -0.5), r"factor: expected values >= 0"),
        (lambda: optics.mueller_transmission(np.nan, 1.0, 1.0), r"ts: expected finite"),
        (lambda: optics.mueller_transmission(1.0, np.nan, 1.0), r"tp: expected finite"),
        (lambda: optics.mueller_rotation(np.nan), r"angle_deg: expected finite values"),
        (lambda: optics.dop([1.0, 0.0, 0.0]), r"stokes: expected shape \(\.\.\., 4\)"),
        (lambda: optics.dop(1.0), r"stokes: expected shape \(\.\.\., 4\)"),
        (lambda: optics.dop([-1.0, 0.0, 0.0, 0.0]), r"stokes: expected S0 >= 0"),
        (lambda: optics.dop([1.0, np.nan, 0.0, 0.0]), r"stokes: expected finite values"),
        (lambda: optics.psi_delta(1.5 - 1e-3j, 60.0), r"n: the extinction coefficient k"),
        (lambda: optics.psi_delta(1.5, 95.0), r"theta_deg: expected an angle in \[0, 90\]"),
        (lambda: optics.psi_delta(1.5, 60.0, n_ambient=1.0 + 0.1j), r"n_ambient: expected a real"),
        (
            lambda: optics.psi_delta(1.5, 60.0, n_ambient=0.0),
            r"n_ambient: expected a real index > 0",
        ),
        (lambda: optics.psi_delta(1.33, 60.0, n_ambient=1.33), r"n: equals n_ambient"),
        (lambda: optics.berger_reflectances(-1.0, 1.0, 30.0), r"n: expected values >= 0"),
        (lambda: optics.berger_reflectances(1.0, -1.0, 30.0), r"k: expected values >= 0"),
        (lambda: optics.berger_reflectances(0.0, 0.0, 30.0), r"n, k: the index N = n \+ ik"),
        (lambda: optics.berger_reflectances(1.0, 1.0, 90.5), r"theta_deg: expected an angle"),
        (
            lambda: onefilm.film_amplitudes(1, 1.5, 2, -1.0, 600, 0),
            r"thickness_nm: expected values >= 0",
        ),
        (
            lambda: onefilm.film_amplitudes(1, 1.5, 2, 10, 0.0, 0),
            r"wavelength_nm: expected values > 0",
        ),
        (lambda: onefilm.film_amplitudes(1, 1.5 - 1j, 2, 10, 600, 0), r"n_film: the extinction"),
        (lambda: onefilm.film_amplitudes(1, 1.5, -2, 10, 600, 0), r"n_substrate: the real part"),
        (lambda: onefilm.film_amplitudes(0, 1.5, 2, 10, 600, 0), r"n_ambient: the index"),
        (
            lambda: onefilm.film_amplitudes(1, 1.5, 2, 10, 600, 120),
            r"theta_i_deg: expected an angle",
        ),
        (lambda: onefilm.film_reflectance_incoherent(1, 1.5, 2, np.nan, 600, 0), r"thickness_nm"),
        (lambda: onefilm.film_mueller_incoherent(1, 1.5, 2, 10, -600, 0), r"wavelength_nm"),
    ],
)
def test_invalid_input_raises_value_error_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()
