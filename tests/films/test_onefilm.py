"""Oracle-free tests of labbrdf.films.onefilm: one film on a substrate, analytic limits.

Tolerances are stated next to each assertion in units of the float64 epsilon ``EPS``.
Shapes and error paths are tested beside the Fresnel functions in ``tests/test_optics.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf import optics
from labbrdf.films import onefilm

EPS = np.finfo(float).eps
N_AL = 1.55 + 7.71j
N_CU = 0.23 + 3.63j
N_SI = 3.88 + 0.02j
THETA = np.linspace(0.0, 90.0, 181)


def test_absentee_half_wave_film_equals_the_bare_substrate_at_normal_incidence():
    # n_f d = lambda/2: exp(2 i beta) = exp(2 pi i) = 1 up to the rounding of 2 pi d n/lambda
    wl = 650.0
    for n_film, n_sub in ((1.5, N_AL), (2.1, 1.5), (1.38, N_SI)):
        rs, rp = onefilm.film_amplitudes(1.0, n_film, n_sub, wl / (2 * n_film), wl, 0.0)
        r0s, r0p, _, _ = optics.fresnel(1.0, n_sub, 0.0)
        assert abs(rs - r0s) <= 32 * EPS
        assert abs(rp - r0p) <= 32 * EPS


def test_zero_thickness_film_is_the_bare_substrate_at_every_angle():
    rs, rp = onefilm.film_amplitudes(1.0, 1.5, N_AL, 0.0, 650.0, THETA)
    r0s, r0p, _, _ = optics.fresnel(1.0, N_AL, THETA)
    np.testing.assert_allclose(rs, r0s, rtol=0, atol=16 * EPS)
    np.testing.assert_allclose(rp, r0p, rtol=0, atol=16 * EPS)


def test_quarter_wave_antireflection_film_cancels_reflection_at_normal_incidence():
    # n_f = sqrt(n_s), n_f d = lambda/4: r = 0 (Born and Wolf 1.6.4)
    n_sub = 2.25
    rs, rp = onefilm.film_amplitudes(1.0, 1.5, n_sub, 650.0 / (4 * 1.5), 650.0, 0.0)
    assert abs(rs) <= 16 * EPS and abs(rp) <= 16 * EPS


@pytest.mark.parametrize("theta", [0.0, 30.0, 60.0, 85.0])
def test_free_standing_lossless_film_follows_the_fabry_perot_formula(theta):
    # film between equal lossless media: the Airy formula of a plane-parallel plate (Born and
    # Wolf section 7.6.1, with r' = -r):
    # R = 4 R01 sin^2(beta) / ((1 - R01)^2 + 4 R01 sin^2(beta)), for s and p separately
    n_film, wl = 2.0, 600.0
    d = np.linspace(0.0, 1000.0, 101)
    rs, rp = onefilm.film_amplitudes(1.0, n_film, 1.0, d, wl, theta)
    r01s, r01p = optics.reflectance(1.0, n_film, theta)
    cos1 = np.sqrt(1 - (np.sin(np.radians(theta)) / n_film) ** 2)
    s2 = np.sin(2 * np.pi * d * n_film * cos1 / wl) ** 2
    for r, r01 in ((rs, r01s), (rp, r01p)):
        fp = 4 * r01 * s2 / ((1 - r01) ** 2 + 4 * r01 * s2)
        # beta ~ 2 pi n d / lambda up to ~20 rad: its rounding (a few eps times beta) moves
        # R by dR/dbeta <= 1 times that
        np.testing.assert_allclose(np.abs(r) ** 2, fp, rtol=0, atol=64 * EPS)


def test_incoherent_lossless_film_does_not_depend_on_thickness():
    a = onefilm.film_reflectance_incoherent(1.0, 1.5, N_AL, 10.0, 650.0, THETA)
    b = onefilm.film_reflectance_incoherent(1.0, 1.5, N_AL, 1e5, 650.0, THETA)
    np.testing.assert_allclose(a, b, rtol=0, atol=4 * EPS)


def test_incoherent_film_index_matched_to_ambient_is_the_bare_substrate():
    Rs, Rp = onefilm.film_reflectance_incoherent(1.0, 1.0, N_CU, 500.0, 650.0, THETA)
    r0s, r0p = optics.reflectance(1.0, N_CU, THETA)
    np.testing.assert_allclose(Rs, r0s, rtol=0, atol=8 * EPS)
    np.testing.assert_allclose(Rp, r0p, rtol=0, atol=8 * EPS)


def test_thick_absorbing_incoherent_film_hides_the_substrate():
    # k = 0.1, d = 100 um: round trip attenuation exp(-4 pi k 2 d / lambda) underflows
    Rs, Rp = onefilm.film_reflectance_incoherent(1.0, 1.5 + 0.1j, N_AL, 1e5, 650.0, THETA)
    r01s, r01p = optics.reflectance(1.0, 1.5 + 0.1j, THETA)
    np.testing.assert_array_equal(Rs, r01s)
    np.testing.assert_array_equal(Rp, r01p)


def test_incoherent_film_mueller_equals_the_explicit_series_of_interface_muellers():
    # the closed form against the tracer's own algebra: M_r01 + sum_j M_t10 (A M_r12
    # M_r10)^j A M_r12 M_t01 with 4x4 matmuls and beam-area factors, absorbing film
    n0, n1, n2, d, wl = 1.0, 1.5 + 0.002j, N_AL, 800.0, 650.0
    for theta in (0.0, 35.0, 70.0):
        cos0 = np.cos(np.radians(theta))
        kz0 = n0 * cos0
        kz1 = np.sqrt(n1 * n1 - n0 * n0 + kz0 * kz0)
        kz2 = np.sqrt(n2 * n2 - n0 * n0 + kz0 * kz0)

        def amps(na, nb, ka, kb):
            rs = (ka - kb) / (ka + kb)
            rp = (nb**2 * ka - na**2 * kb) / (nb**2 * ka + na**2 * kb)
            return rs, rp, 2 * ka / (ka + kb), 2 * na * nb * ka / (nb**2 * ka + na**2 * kb)

        r01s, r01p, t01s, t01p = amps(n0, n1, kz0, kz1)
        r10s, r10p, t10s, t10p = amps(n1, n0, kz1, kz0)
        r12s, r12p, _, _ = amps(n1, n2, kz1, kz2)
        f01 = (kz1.real) / kz0.real
        f10 = kz0.real / kz1.real
        a = np.exp(-4 * np.pi * 2 * d * kz1.imag / wl)
        m_r01 = optics.mueller_reflection(r01s, r01p)
        m_t01 = optics.mueller_transmission(t01s, t01p, f01)
        m_t10 = optics.mueller_transmission(t10s, t10p, f10)
        m_r12 = optics.mueller_reflection(r12s, r12p)
        m_r10 = optics.mueller_reflection(r10s, r10p)
        total = m_r01.copy()
        path = a * m_r12 @ m_t01
        for _ in range(400):
            total += m_t10 @ path
            path = a * m_r12 @ m_r10 @ path
        expected = onefilm.film_mueller_incoherent(n0, n1, n2, d, wl, theta)
        # the remaining tail after 400 round trips is < (0.93 * 0.04)^400, i.e. 0
        np.testing.assert_allclose(total, expected, rtol=0, atol=64 * EPS)


def test_incoherent_film_mueller_depolarises_and_matches_its_reflectances():
    m = onefilm.film_mueller_incoherent(1.0, 1.5, N_AL, 500.0, 650.0, THETA[1:-1])
    Rs, Rp = onefilm.film_reflectance_incoherent(1.0, 1.5, N_AL, 500.0, 650.0, THETA[1:-1])
    np.testing.assert_allclose(m[:, 0, 0], (Rs + Rp) / 2, rtol=4 * EPS)
    np.testing.assert_allclose(m[:, 0, 1], (Rs - Rp) / 2, rtol=0, atol=4 * EPS)
    # |C|^2 <= Rs Rp (Cauchy-Schwarz over the paths), strictly for oblique incidence
    c2 = m[:, 2, 2] ** 2 + m[:, 2, 3] ** 2
    assert np.all(c2 <= Rs * Rp * (1 + 8 * EPS))
    s_out = m @ np.array([1.0, 0.0, 1.0, 0.0])  # light polarised along s + p
    assert np.all(optics.dop(s_out[10:]) < 1 - 1e-6)
