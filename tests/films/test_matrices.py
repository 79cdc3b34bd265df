"""Coherent layer-stack optics: analytic limits, invariants, and pyElli / tmm on random stacks."""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf import optics
from labbrdf.films import matrices as stack
from labbrdf.films import onefilm

TOL = 1e-10  # both peers and labbrdf are exact to round-off for these well-conditioned stacks


def _random_stack(rng: np.random.Generator, n_layers: int, absorbing: bool):
    n = rng.uniform(1.2, 4.0, n_layers + 1)
    k = rng.uniform(0.0, 0.5, n_layers + 1) if absorbing else np.zeros(n_layers + 1)
    media = [1.0] + list(n + 1j * k)
    d = list(rng.uniform(1.0, 400.0, n_layers))
    return media, d


def _dangle(a, b):
    return np.abs((np.asarray(a) - np.asarray(b) + 180.0) % 360.0 - 180.0)


# ---- analytic limits


def test_one_layer_is_the_airy_formula_of_its_interfaces():
    lam, th, d = np.array([350.0, 633.0, 1200.0]), 55.0, 87.0
    n0, n1, n2 = 1.0, 2.1 + 0.03j, 3.9 + 0.2j
    rs01, rp01, _, _ = optics.fresnel(n0, n1, th)
    kz1 = np.sqrt(n1**2 - np.sin(np.radians(th)) ** 2)
    cos1 = kz1 / n1
    # interface film -> substrate from the film's cos (complex angle)
    kz2 = np.sqrt(n2**2 - np.sin(np.radians(th)) ** 2)
    rs12 = (kz1 - kz2) / (kz1 + kz2)
    rp12 = (n2**2 * kz1 - n1**2 * kz2) / (n2**2 * kz1 + n1**2 * kz2)
    beta = 2 * np.pi * d * n1 * cos1 / lam
    ph = np.exp(2j * beta)
    rs = (rs01 + rs12 * ph) / (1 + rs01 * rs12 * ph)
    rp = (rp01 + rp12 * ph) / (1 + rp01 * rp12 * ph)
    got = stack.amplitudes([n0, n1, n2], [d], lam, th)
    np.testing.assert_allclose(got[0], rs, rtol=0, atol=1e-13)
    np.testing.assert_allclose(got[1], rp, rtol=0, atol=1e-13)


def test_quarter_wave_coating_at_normal_incidence_gives_the_textbook_reflectance():
    n0, n1, ns, lam = 1.0, 1.38, 1.52, 550.0
    rs_, rp_ = stack.reflectance([n0, n1, ns], [lam / (4 * n1)], lam, 0.0)
    expected = ((n0 * ns - n1**2) / (n0 * ns + n1**2)) ** 2  # Born & Wolf 1.6 eq. (67)
    assert rs_ == pytest.approx(expected, abs=1e-14)
    assert rp_ == pytest.approx(expected, abs=1e-14)


def test_half_wave_layer_is_absent_at_its_design_wavelength():
    n1, lam, th = 2.0, 600.0, 0.0
    with_layer = stack.amplitudes([1.0, n1, 3.5 + 0.1j], [lam / (2 * n1)], lam, th)
    bare = stack.amplitudes([1.0, 3.5 + 0.1j], [], lam, th)
    np.testing.assert_allclose(with_layer[0], bare[0], atol=1e-14)


def test_zero_thickness_or_index_matched_layers_change_nothing():
    lam, th = np.linspace(300, 1000, 7), np.array([[0.0], [45.0], [80.0]])
    bare = stack.amplitudes([1.0, 1.5 + 0.01j, 3.8 + 0.02j], [30.0], lam, th)
    zero = stack.amplitudes([1.0, 2.2, 1.5 + 0.01j, 3.8 + 0.02j], [0.0, 30.0], lam, th)
    matched = stack.amplitudes([1.0, 1.5 + 0.01j, 1.5 + 0.01j, 3.8 + 0.02j], [10.0, 20.0], lam, th)
    for a, b, c in zip(bare, zero, matched, strict=True):
        np.testing.assert_allclose(b, a, atol=1e-13)
        np.testing.assert_allclose(c, a, atol=1e-13)


def test_bare_substrate_psi_delta_equal_the_optics_core():
    lam, th = 633.0, np.array([45.0, 65.0, 75.0])
    psi, delta = stack.ellipsometry([1.0, 3.88 + 0.02j], [], lam, th)
    psi0, delta0 = optics.psi_delta(3.88 + 0.02j, th)
    np.testing.assert_allclose(psi, psi0, atol=1e-12)
    np.testing.assert_allclose(delta, delta0, atol=1e-12)


def test_normal_incidence_delta_is_180_degrees():
    _, delta = stack.ellipsometry([1.0, 1.46, 3.9 + 0.02j], [100.0], 500.0, 0.0)
    assert delta == pytest.approx(180.0, abs=1e-9)


@pytest.mark.parametrize("n_layers", [1, 2, 3, 4])
def test_lossless_stacks_conserve_energy(n_layers):
    rng = np.random.default_rng(n_layers)
    media, d = _random_stack(rng, n_layers, absorbing=False)
    lam = np.linspace(300, 1500, 13)[:, None]
    th = np.linspace(0, 85, 9)[None, :]
    rs, rp = stack.reflectance(media, d, lam, th)
    ts, tp = stack.transmittance(media, d, lam, th)
    np.testing.assert_allclose(rs + ts, 1.0, atol=1e-12)
    np.testing.assert_allclose(rp + tp, 1.0, atol=1e-12)


def test_thick_absorbing_layer_does_not_overflow_and_hides_the_substrate():
    rs, rp = stack.reflectance([1.0, 0.2 + 3.5j, 1.5], [5000.0], 500.0, 70.0)
    rs0, rp0 = stack.reflectance([1.0, 0.2 + 3.5j], [], 500.0, 70.0)
    assert np.isfinite(rs) and np.isfinite(rp)
    assert rs == pytest.approx(rs0, abs=1e-14) and rp == pytest.approx(rp0, abs=1e-14)


def test_grid_broadcasting_gives_one_value_per_wavelength_and_angle():
    lam = np.linspace(400, 800, 5)
    n_film = 1.5 + 0.004 / (lam / 1000) ** 2
    psi, delta = stack.ellipsometry(
        [1.0, n_film[:, None], 3.9 + 0.02j], [50.0], lam[:, None], np.array([[65.0, 70.0]])
    )
    assert psi.shape == delta.shape == (5, 2)
    psi1, _ = stack.ellipsometry([1.0, n_film[2], 3.9 + 0.02j], [50.0], lam[2], 70.0)
    assert psi[2, 1] == pytest.approx(float(psi1), abs=1e-13)


def test_optics_film_amplitudes_is_the_stack_with_one_layer():
    args = (1.0, 1.7 + 0.01j, 3.6 + 0.1j, 120.0, np.array([450.0, 700.0]), 63.0)
    rs, rp = onefilm.film_amplitudes(*args)
    s = stack.amplitudes([args[0], args[1], args[2]], [args[3]], args[4], args[5])
    np.testing.assert_array_equal(rs, s[0])
    np.testing.assert_array_equal(rp, s[1])


# ---- Bruggeman


def test_bruggeman_end_members_and_symmetry():
    ea, eb = (3.9 + 0.02j) ** 2, 1.0
    assert stack.bruggeman(ea, eb, 1.0) == pytest.approx(ea, abs=1e-12)
    assert stack.bruggeman(ea, eb, 0.0) == pytest.approx(eb, abs=1e-12)
    f = np.linspace(0, 1, 11)
    np.testing.assert_allclose(
        stack.bruggeman(ea, eb, f), stack.bruggeman(eb, ea, 1 - f), atol=1e-12
    )


def test_bruggeman_solves_its_equation_and_lies_within_the_wiener_bounds():
    rng = np.random.default_rng(3)
    ea = (rng.uniform(1.3, 4, 50) + 1j * rng.uniform(0, 3, 50)) ** 2
    eb = (rng.uniform(1.0, 2, 50) + 1j * rng.uniform(0, 0.1, 50)) ** 2
    f = rng.uniform(0, 1, 50)
    e = stack.bruggeman(ea, eb, f)
    g = f * (ea - e) / (ea + 2 * e) + (1 - f) * (eb - e) / (eb + 2 * e)
    np.testing.assert_allclose(g, 0, atol=1e-12)
    assert np.all(e.imag >= 0)
    # lossless: between the series and parallel (Wiener) bounds
    ea_r, eb_r = ea.real.clip(1.0), eb.real.clip(1.0)
    er = stack.bruggeman(ea_r, eb_r, f).real
    lower = 1 / (f / ea_r + (1 - f) / eb_r)
    upper = f * ea_r + (1 - f) * eb_r
    assert np.all(er >= lower - 1e-12) and np.all(er <= upper + 1e-12)


# ---- errors


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: stack.amplitudes([1.0], [], 500.0, 0.0), "at least 2 media"),
        (lambda: stack.amplitudes([1.0, 1.5, 3.0], [], 500.0, 0.0), "one thickness per layer"),
        (lambda: stack.amplitudes([1.0, 1.5, 3.0], [-1.0], 500.0, 0.0), "thicknesses_nm"),
        (lambda: stack.amplitudes([1.0, 1.5 - 0.1j, 3.0], [1.0], 500.0, 0.0), "layer 1"),
        (lambda: stack.amplitudes([1.0, 1.5, 3.0], [1.0], 0.0, 0.0), "wavelength_nm"),
        (lambda: stack.amplitudes([1.0, 1.5, 3.0], [1.0], 500.0, 91.0), "theta_deg"),
        (lambda: stack.amplitudes([1.0, 1.5, np.nan], [1.0], 500.0, 0.0), "substrate"),
        (lambda: stack.transmittance([1.0 + 0.1j, 3.0], [], 500.0, 0.0), "lossless"),
        (lambda: stack.bruggeman(2.0, 1.0, 1.5), "fraction"),
        (lambda: stack.bruggeman(2.0 - 1j, 1.0, 0.5), "Im\\(eps\\)"),
        (lambda: stack.bruggeman(np.inf, 1.0, 0.5), "eps_a"),
    ],
)
def test_invalid_input_raises_value_error_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()


# ---- peers (optional): random stacks, 1-4 layers, absorbing or not, 0-85 deg


def _cases():
    for n_layers in (1, 2, 3, 4):
        for absorbing in (False, True):
            yield n_layers, absorbing


@pytest.mark.parametrize(("n_layers", "absorbing"), list(_cases()))
def test_amplitudes_and_power_match_tmm_on_random_stacks(n_layers, absorbing):
    tmm = pytest.importorskip("tmm")
    rng = np.random.default_rng(100 * n_layers + absorbing)
    for _ in range(5):
        media, d = _random_stack(rng, n_layers, absorbing)
        lam = float(rng.uniform(250, 1700))
        th = float(rng.uniform(0, 85))
        rs, rp, ts, tp = stack.amplitudes(media, d, lam, th)
        Ts, Tp = stack.transmittance(media, d, lam, th)
        for pol, r, t, T in (("s", rs, ts, Ts), ("p", rp, tp, Tp)):
            ref = tmm.coh_tmm(pol, media, [np.inf, *d, np.inf], np.radians(th), lam)
            assert abs(r - ref["r"]) < TOL
            assert abs(t - ref["t"]) < TOL
            assert abs(abs(r) ** 2 - ref["R"]) < TOL
            assert abs(T - ref["T"]) < TOL


@pytest.mark.parametrize(("n_layers", "absorbing"), list(_cases()))
def test_psi_delta_and_reflectance_match_pyelli_on_random_stacks(n_layers, absorbing):
    elli = pytest.importorskip("elli")
    rng = np.random.default_rng(200 + 10 * n_layers + absorbing)
    lam = np.linspace(250, 1700, 7)
    for _ in range(3):
        media, d = _random_stack(rng, n_layers, absorbing)
        th = float(rng.uniform(1, 85))  # pyElli's 2x2 solver: 0 deg has no s/p plane

        def mat(n):
            return elli.IsotropicMaterial(elli.ConstantRefractiveIndex(n=n))

        layers = [elli.Layer(mat(n), t) for n, t in zip(media[1:-1], d, strict=True)]
        res = elli.Structure(elli.AIR, layers, mat(media[-1])).evaluate(
            lam, th, solver=elli.Solver2x2
        )
        psi, delta = stack.ellipsometry(media, d, lam, th)
        rs, rp = stack.reflectance(media, d, lam, th)
        np.testing.assert_allclose(psi, res.psi, rtol=0, atol=TOL)
        assert np.all(_dangle(delta, res.delta) < TOL)
        np.testing.assert_allclose(rp, res.R_matrix[:, 0, 0], rtol=0, atol=TOL)
        np.testing.assert_allclose(rs, res.R_matrix[:, 1, 1], rtol=0, atol=TOL)
