"""Dispersion models: published values, Kramers-Kronig consistency, tables, round trips, errors."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from labbrdf.films import as_material
from labbrdf.nk import dispersion as disp
from labbrdf.nk import tabulated_from_file
from labbrdf.nk.dispersion import (
    HC_EV_NM,
    Cauchy,
    DispersionError,
    Drude,
    Lorentz,
    Sellmeier,
    Tabulated,
    TaucLorentz,
)

EXAMPLES = [
    Cauchy(A=1.9, B=0.02, C=0.001, k_amp=0.01, exponent=2.0, band_edge=4.0),
    Sellmeier(),
    TaucLorentz(eps_inf=1.2, A=150.0, E0=4.5, C=1.5, Eg=3.2),
    Drude(eps_inf=1.5, omega_p=8.0, gamma=0.2),
    Lorentz(eps_inf=1.1, oscillators=((2.0, 6.0, 0.5), (0.3, 3.0, 0.2))),
]


def _kk_eps1(eps2, eps_inf: float, e: float, e_lo: float, e_hi: float) -> float:
    """eps1(E) = eps_inf + (2/pi) P int xi eps2(xi)/(xi^2 - E^2) dxi, by quadrature."""
    # xi eps2/(xi^2 - E^2) = [xi eps2/(xi + E)] / (xi - E): Cauchy principal value weight
    pv, _ = integrate.quad(
        lambda x: x * eps2(x) / (x + e), e_lo, e_hi, weight="cauchy", wvar=e, limit=400
    )
    return eps_inf + 2 / np.pi * pv


def test_sellmeier_defaults_give_malitsons_fused_silica():
    # Malitson 1965 Table 3 (measured): n = 1.45846 at the He d line 587.56 nm,
    # 1.45702 at 656.27 nm (C line)
    n = Sellmeier().nk([587.56, 656.27]).real
    np.testing.assert_allclose(n, [1.45846, 1.45637], atol=6e-5)


def test_sio2_table_agrees_with_the_sellmeier_formula_it_was_generated_from():
    t = Tabulated.reference("sio2")
    nodes = t.wavelength_nm
    exact = Sellmeier().nk(nodes).real
    np.testing.assert_allclose(t.n, exact, rtol=0, atol=5e-7)  # printed to 6 decimals
    # between nodes: linear interpolation error <= h^2/8 max|n''| (h = 5 nm), plus rounding
    mid = (nodes[1:] + nodes[:-1]) / 2
    h = np.diff(nodes)
    # |n''| falls with wavelength here, so its maximum on a segment is at the left node
    s = Sellmeier()
    left, dx = nodes[:-1], 0.01
    curv = np.abs(s.nk(left + dx).real - 2 * s.nk(left).real + s.nk(left - dx).real) / dx**2
    err = np.abs(t.nk(mid).real - Sellmeier().nk(mid).real)
    assert np.all(err <= h**2 / 8 * curv + 5e-7)
    assert np.all(t.nk(mid).imag == 0)


def test_si_table_reproduces_greens_published_values_at_its_nodes():
    t = Tabulated.reference("si")
    got = t.nk([300.0, 630.0, 1000.0])
    np.testing.assert_allclose(got.real, [4.976, 3.879, 3.572], atol=1e-12)
    np.testing.assert_allclose(got.imag, [4.234, 1.6444e-02, 5.0930e-04], rtol=1e-12)
    assert t.range_nm == (250.0, 1450.0)
    assert "Green" in t.source


def test_table_outside_its_range_raises_naming_the_table_and_range():
    with pytest.raises(DispersionError, match="si_green2008.csv.*250-1450 nm.*193"):
        Tabulated.reference("si").nk([193.0, 500.0])


def test_unknown_reference_table_lists_the_shipped_ones():
    with pytest.raises(DispersionError, match="shipped tables: \\['si', 'sio2'\\]"):
        Tabulated.reference("gaas")


def test_cauchy_urbach_formula_in_micrometres_and_electronvolts():
    c = EXAMPLES[0]
    lam = 500.0
    n = c.A + c.B / 0.25 + c.C / 0.0625
    k = c.k_amp * np.exp(c.exponent * (HC_EV_NM / lam - c.band_edge))
    assert c.nk(lam) == pytest.approx(n + 1j * k, rel=1e-14)


def test_tauc_lorentz_eps1_is_the_kramers_kronig_transform_of_eps2():
    tl = EXAMPLES[2]

    def eps2(x):
        return tl.eps(HC_EV_NM / x).imag

    for e in (1.0, 2.5, 3.19, 3.21, 4.5, 7.0):
        expected = _kk_eps1(eps2, tl.eps_inf, e, tl.Eg, 2000.0)
        # the tail beyond 2000 eV adds (2/pi) int A E0 C / xi^4 ~ 1e-9
        assert tl.eps(HC_EV_NM / e).real == pytest.approx(expected, abs=1e-6)
    assert tl.eps(HC_EV_NM / 3.0).imag == 0.0  # below the gap
    assert np.isfinite(tl.eps(HC_EV_NM / tl.Eg).real)  # finite at E = Eg


def test_lorentz_obeys_kramers_kronig_and_drude_is_its_published_form():
    lo = EXAMPLES[4]

    def eps2(x):
        return lo.eps(HC_EV_NM / x).imag

    for e in (1.0, 2.0, 4.0):
        # truncating the tail at 1e4 eV leaves (2/pi) sum A E0^2 G / 3 xi^3 ~ 1e-12
        expected = _kk_eps1(eps2, lo.eps_inf, e, 1e-6, 1e4)
        assert lo.eps(HC_EV_NM / e).real == pytest.approx(expected, abs=1e-6)
    d = EXAMPLES[3]
    e = 2.0
    assert d.eps(HC_EV_NM / e) == pytest.approx(
        d.eps_inf - d.omega_p**2 / (e**2 + 1j * d.gamma * e), rel=1e-14
    )
    assert d.eps(HC_EV_NM / e).imag > 0  # absorbing with exp(-i omega t)


@pytest.mark.parametrize("model", EXAMPLES, ids=lambda m: m.name)
def test_every_model_is_passive_and_round_trips_through_its_dict(model):
    lam = np.linspace(200, 2000, 50)
    nk = model.nk(lam)
    assert np.all(nk.imag >= 0) and np.all(nk.real >= 0)
    again = disp.from_dict(model.to_dict())
    np.testing.assert_array_equal(again.nk(lam), nk)
    assert type(model).from_params(model.params).params == model.params
    assert set(model.bounds()) == set(model.params)
    assert disp.MODELS[model.name] is type(model)


def test_tauc_lorentz_matches_pyelli():
    elli = pytest.importorskip("elli")
    tl = EXAMPLES[2]
    ref = elli.TaucLorentz(Eg=tl.Eg).add(A=tl.A, E=tl.E0, C=tl.C)
    lam = np.linspace(200, 1600, 30)
    np.testing.assert_allclose(
        tl.eps(lam) - tl.eps_inf, ref.dielectric_function(lam), rtol=1e-10, atol=1e-12
    )


def test_tabulated_from_a_three_and_a_two_column_file(tmp_path):
    p = tmp_path / "film.csv"
    p.write_text("# my film\nwavelength_nm,n,k\n400,2.0,0.1\n800,1.8,0.0\n")
    t = tabulated_from_file(p)
    assert t.nk(600.0) == pytest.approx(1.9 + 0.05j)
    p2 = tmp_path / "glass.txt"
    p2.write_text("500 1.5\n600 1.49\n")
    assert tabulated_from_file(p2).nk(550.0) == pytest.approx(1.495 + 0j)
    assert as_material(t.to_dict(), tabulated_from_file).nk(600.0) == t.nk(600.0)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("400 2.0 0.1\n500 x 0.1\n", "line 2: expected numbers"),
        ("400 2.0 0.1\n500 2.0 -0.1\n", "line 2: k must be >= 0"),
        ("400 2.0 0.1 7\n", "line 1: expected 2 or 3 columns"),
        ("400 2.0\n400 2.1\n", "repeated wavelength 400"),
        ("400 2.0\n", "at least 2 rows"),
    ],
)
def test_bad_table_file_names_file_and_line(tmp_path, text, match):
    p = tmp_path / "bad.txt"
    p.write_text(text)
    with pytest.raises(DispersionError, match=match) as exc:
        tabulated_from_file(p)
    assert "bad.txt" in str(exc.value)


def test_missing_file_raises_a_dispersion_error(tmp_path):
    with pytest.raises(DispersionError, match="cannot read"):
        tabulated_from_file(tmp_path / "absent.txt")


@pytest.mark.shared
def test_tabulated_from_a_bare_tantalum_ellipsometer_file(real_exports):
    t = tabulated_from_file(real_exports / "woollam-wvase-ascii" / "w2_10102006.dat")
    lo, hi = t.range_nm
    assert lo < 300 and hi > 1600
    n633 = t.nk(633.0)
    # a metal: k > n > 0 in the visible (tantalum: n about 1-2, k about 2-4 at 633 nm)
    assert 0.5 < n633.real < 3 and 1.5 < n633.imag < 5


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: Cauchy(k_amp=-1), "k_amp"),
        (lambda: TaucLorentz(C=12.0, E0=5.0), "C < 2 E0"),
        (lambda: Drude(gamma=0.0), "gamma"),
        (lambda: Lorentz(oscillators=((1.0, -2.0, 0.1),)), "oscillator 1"),
        (lambda: Lorentz.from_params({"eps_inf": 1, "A1": 1, "E1": 2}), "lacks \\['G1'\\]"),
        (lambda: Cauchy.from_params({"A": 1.5, "Q": 2}), "unknown parameter"),
        (lambda: disp.from_dict({"model": "nope"}), "unknown dispersion model"),
        (lambda: Cauchy().nk([-5.0]), "wavelength_nm"),
        (lambda: Sellmeier(C1=0.25).nk(500.0), "resonance"),
    ],
)
def test_invalid_parameters_raise_clear_errors(build, match):
    with pytest.raises(DispersionError, match=match):
        build()


def test_pseudo_constants_of_a_stack_are_refused_as_a_table(real_exports) -> None:
    coated = real_exports / "woollam-wvase-ascii" / "w1_12082006.dat"
    with pytest.raises(DispersionError, match="pseudo-constants of a stack"):
        tabulated_from_file(coated)


def test_every_model_module_of_the_package_is_in_the_registry():
    import importlib
    import inspect
    import pkgutil

    from labbrdf.nk import dispersion as package
    from labbrdf.nk.dispersion import registry

    defined = {}
    for info in pkgutil.iter_modules(package.__path__):
        mod = importlib.import_module(f"{package.__name__}.{info.name}")
        for cls in vars(mod).values():
            if (
                inspect.isclass(cls)
                and issubclass(cls, disp.Dispersion)
                and cls is not disp.Dispersion
                and cls.__module__ == mod.__name__
            ):
                defined[info.name] = cls.__name__
    assert defined == registry._MODULES
    assert list(disp.MODELS) == [
        "constant",
        "cauchy",
        "sellmeier",
        "tauc_lorentz",
        "drude",
        "lorentz",
        "cody_lorentz",
        "gaussian",
        "bspline",
        "sum",
        "tabulated",
    ]
