"""Cody-Lorentz, Gaussian, sums, B-splines: Kramers-Kronig, limits, round trips, fits, errors."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import integrate

from labbrdf.films import FilmError, FilmModel, Layer, Stack, as_material, load_model
from labbrdf.films.materials import _with_params
from labbrdf.nk import dispersion as disp
from labbrdf.nk.dispersion import (
    HC_EV_NM,
    BSpline,
    CodyLorentz,
    DispersionError,
    Drude,
    Gaussian,
    Lorentz,
    Sum,
    TaucLorentz,
    bspline_fit,
)

CL = CodyLorentz(eps_inf=1.3, A=80.0, E0=3.8, C=1.8, Eg=1.6, Ep=0.9, Et=1.75, Eu=0.04)
CL_NARROW = CodyLorentz(eps_inf=2.0, A=50.0, E0=3.5, C=0.3, Eg=1.5, Ep=0.8, Et=1.5, Eu=0.02)
GAUSS = Gaussian(eps_inf=1.5, oscillators=((2.0, 4.0, 1.0), (0.5, 1.0, 0.3)))
SPLINE = BSpline(1.3, 1.0, 8.0, (0.0, 1.0, 2.0, 3.0, 2.0, 1.0, 0.0))
TCO = Sum(2.1, (TaucLorentz(0.0, 60.0, 5.0, 1.5, 3.6), Drude(0.0, 1.8, 0.12)))
NEW = [CL, GAUSS, SPLINE, TCO]


def _eps2(model):
    if hasattr(model, "eps2"):  # the function eps().imag returns, without the eps1 work
        return lambda x: float(model.eps2(np.asarray(x, float)))
    return lambda x: model.eps(HC_EV_NM / x).imag


def _pv(eps2, e: float, kinks: list[float], upper: float) -> float:
    """(2/pi) P int_0^upper xi eps2/(xi^2 - E^2): QUADPACK, the pole by its Cauchy weight."""
    edges = sorted({1e-9, *[k for k in kinks if k != e], e - 0.5, e + 0.5, upper})
    edges = [x for x in edges if 1e-9 <= x <= upper]
    total = 0.0
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        if a < e < b:
            f = lambda x: x * eps2(x) / (x + e)  # noqa: E731
            v, _ = integrate.quad(f, a, b, weight="cauchy", wvar=e, limit=400, epsabs=1e-12)
        else:
            g = lambda x: x * eps2(x) / (x * x - e * e)  # noqa: E731
            v, _ = integrate.quad(g, a, b, limit=400, epsabs=1e-12)
        total += v
    return 2 / math.pi * total


# Each model's eps1 against an adaptive principal value of its own eps2. The models' fixed
# Gauss-Legendre panels are exact to ~1e-9 (measured: 3e-10 Cody-Lorentz, 2e-9 B-spline);
# QUADPACK's tolerance is 1e-12 per segment; the truncation at `upper` leaves
# (2/pi) int_upper^inf tail/xi^4 (Cody-Lorentz: A E0 C / 3 upper^3 = 2e-8 at 2000 eV,
# Gaussian and B-spline: 0). So 1e-7 holds with margin and fails for any error of the
# transform's form (a wrong sign or factor moves eps1 by O(1)).
KK_CASES = [
    (CL, [CL.Eg, CL.Et, CL.E0], 2000.0, (0.5, 1.6, 1.74, 1.76, 2.5, 3.8, 6.0)),
    (CL_NARROW, [1.5, 3.5], 2000.0, (0.7, 1.49, 1.52, 3.4, 3.6, 5.0)),
    (GAUSS, [1.0, 4.0], 60.0, (0.3, 1.0, 2.0, 3.9, 6.0)),
    (SPLINE, list(np.linspace(1.0, 8.0, 11)), 20.0, (0.5, 1.2, 3.3, 4.5, 7.9, 9.0)),
]


@pytest.mark.parametrize(
    ("model", "kinks", "upper", "energies"),
    KK_CASES,
    ids=["cody_lorentz", "cody_lorentz_no_tail", "gaussian", "bspline"],
)
def test_eps1_is_the_kramers_kronig_transform_of_eps2(model, kinks, upper, energies):
    eps2 = _eps2(model)
    for e in energies:
        expected = model.eps_inf + _pv(eps2, e, kinks, upper)
        assert model.eps(HC_EV_NM / e).real == pytest.approx(expected, abs=1e-7), e


def test_cody_lorentz_eps2_is_the_papers_piecewise_form_continuous_at_et():
    e = np.array([1.0, 1.7, 2.0, 3.0, 5.0])
    band = (e - CL.Eg) ** 2 / ((e - CL.Eg) ** 2 + CL.Ep**2)
    lor = CL.A * CL.E0 * CL.C * e / ((e**2 - CL.E0**2) ** 2 + CL.C**2 * e**2)
    et = CL.Et
    g_t = (et - CL.Eg) ** 2 / ((et - CL.Eg) ** 2 + CL.Ep**2)
    e1 = et * g_t * CL.A * CL.E0 * CL.C * et / ((et**2 - CL.E0**2) ** 2 + CL.C**2 * et**2)
    urbach = e1 / e * np.exp((e - et) / CL.Eu)
    expected = np.where(e > et, band * lor, urbach)
    np.testing.assert_allclose(CL.eps(HC_EV_NM / e).imag, expected, rtol=1e-13)
    below, above = CL.eps2(np.array([et - 1e-9, et + 1e-9]))
    assert below == pytest.approx(above, rel=1e-6)
    # Et = Eg: no Urbach tail; eps2 = 0 below the gap
    assert np.all(CL_NARROW.eps2(np.array([0.5, 1.0, 1.5])) == 0.0)
    # far above E0 the band edge is 1 and eps2 -> A E0 C / E^3 (the tail kk_eps1 adds)
    big = 1e3
    assert CL.eps2(np.array(big)) * big**3 == pytest.approx(CL.A * CL.E0 * CL.C, rel=1e-4)


def test_gaussian_peaks_at_en_with_its_full_width_at_half_maximum_br():
    g = Gaussian(eps_inf=1.0, oscillators=((3.0, 5.0, 0.8),))
    half = g.eps(HC_EV_NM / np.array([4.6, 5.0, 5.4])).imag
    # the antisymmetric partner exp(-((E + En)/sigma)^2) is 1e-95 here
    np.testing.assert_allclose(half, [1.5, 3.0, 1.5], rtol=1e-12)
    # eps1 at E = 0: the Dawson terms give eps_inf + (4 A / sqrt(pi)) D(En / sigma)
    s = 0.8 / (2 * math.sqrt(math.log(2)))
    e = 1e-6
    d = (4 * 3.0 / math.sqrt(math.pi)) * float(
        integrate.quad(lambda t: math.exp(t * t - (5.0 / s) ** 2), 0, 5.0 / s)[0]
    )
    assert g.eps(HC_EV_NM / e).real == pytest.approx(1.0 + d, rel=1e-8)


def test_a_sum_is_the_sum_of_its_terms_with_one_eps_inf():
    lam = np.linspace(250, 2500, 40)
    tl, dr = TCO.terms
    expected = 2.1 + tl.eps(lam) + dr.eps(lam)
    np.testing.assert_allclose(TCO.eps(lam), expected, rtol=1e-15, atol=4e-15)  # sum order
    # a term's own eps_inf is set to 0 and hidden
    s = Sum(1.0, (TaucLorentz(eps_inf=3.0), Gaussian(eps_inf=2.0)))
    assert [t.params["eps_inf"] for t in s.terms] == [0.0, 0.0]
    assert sorted(k for k in s.params if "eps_inf" in k) == ["eps_inf"]
    assert set(s.params) == set(s.bounds()) == set(s.units())
    assert s.units()["tauc_lorentz1_E0"] == "eV" and s.units()["gaussian2_A1"] == "1"
    # the free-carrier term makes the oxide metallic in the infrared, the band edge absorbs in UV
    n_ir, n_uv = TCO.nk([2500.0, 250.0])
    assert n_ir.imag > 0.1 and n_uv.imag > 0.1 and TCO.nk(550.0).imag < 0.05


@pytest.mark.parametrize("model", NEW, ids=lambda m: m.name)
def test_new_models_are_passive_and_round_trip_through_their_dicts(model):
    lam = np.linspace(200, 2000, 50)
    nk = model.nk(lam)
    assert np.all(nk.imag >= 0) and np.all(nk.real >= 0)
    again = disp.from_dict(model.to_dict())
    np.testing.assert_array_equal(again.nk(lam), nk)
    assert type(model).from_params(model.params).params == model.params
    assert set(model.bounds()) == set(model.params)
    assert disp.MODELS[model.name] is type(model)


def test_peers_agree_where_installed():
    elli = pytest.importorskip("elli")
    lam = np.linspace(250, 1600, 30)
    g = GAUSS
    ref = elli.Gaussian()
    for a, en, br in g.oscillators:
        ref = ref.add(A=a, E=en, sigma=br)  # pyElli's sigma is the full width at half maximum
    np.testing.assert_allclose(g.eps(lam) - g.eps_inf, ref.dielectric_function(lam), rtol=1e-12)
    e = HC_EV_NM / lam
    p = CL.params
    e2 = elli.CodyLorentz.eps2(
        e, Eg=p["Eg"], A=p["A"], Et=p["Et"], gamma=p["C"], Ep=p["Ep"], E0=p["E0"], Eu=p["Eu"]
    )
    np.testing.assert_allclose(CL.eps(lam).imag, e2, rtol=1e-12)


def test_a_sum_is_a_material_by_name_in_python_toml_and_with_parameters(tmp_path):
    m = as_material("tauc_lorentz+drude")
    assert isinstance(m, Sum) and [t.name for t in m.terms] == ["tauc_lorentz", "drude"]
    m2 = _with_params(m, {"drude2_omega_p": 1.5, "eps_inf": 2.0})
    assert m2.params["drude2_omega_p"] == 1.5 and m2.params["tauc_lorentz1_A"] == 100.0
    assert isinstance(as_material("sum"), Sum)
    p = tmp_path / "ito.toml"
    p.write_text(
        '[substrate]\nmaterial = "sio2"\n\n[[layer]]\nname = "ito"\n'
        'material = "tauc_lorentz+drude"\nthickness_nm = [50, 300]\neps_inf = 2.1\n'
        "drude2_omega_p = [0.5, 3.0]\ndrude2_gamma = 0.12\n"
    )
    fm = load_model(p)
    # the one rule: what is not written is fitted in its default box
    taucs = {f"ito.tauc_lorentz1_{k}" for k in ("A", "E0", "C", "Eg")}
    assert set(fm.free) == {"ito.thickness_nm", "ito.drude2_omega_p", *taucs}
    assert fm.stack.layers[0].material.params["drude2_gamma"] == 0.12
    p.write_text(p.read_text().replace("drude2_gamma", "drude3_gamma"))
    with pytest.raises(FilmError, match="line 10: unknown parameter 'drude3_gamma'"):
        load_model(p)


def _psi_delta_rows(stack: Stack, wl: np.ndarray) -> pd.DataFrame:
    """Noise-free psi and Delta at 60 and 70 deg with an ellipsometer's sigmas."""
    w, t = (a.ravel() for a in np.meshgrid(wl, [60.0, 70.0], indexing="ij"))
    psi, delta = stack.psi_delta(w, t)
    base = {"sample": "s", "instrument": "sim", "source": "sim.dat", "unit": "deg"}
    geom = {"wavelength_nm": w, "theta_i_deg": t, "theta_r_deg": t, "phi_r_deg": 180.0}
    return pd.concat(
        [
            pd.DataFrame({**base, "quantity": "psi", "value": psi, "sigma": 0.02, **geom}),
            pd.DataFrame({**base, "quantity": "delta", "value": delta, "sigma": 0.05, **geom}),
        ],
        ignore_index=True,
    )


FITS = [
    (
        Stack([Layer(CL, 80.0, "asi")], "si"),
        {"asi.thickness_nm": 80.0, "asi.A": 80.0, "asi.E0": 3.8},
    ),
    (
        Stack([Layer(GAUSS, 120.0, "g")], "si"),
        {"g.thickness_nm": 120.0, "g.A1": 2.0, "g.En1": 4.0},
    ),
    (
        Stack([Layer(TCO, 150.0, "ito")], "sio2"),
        {"ito.thickness_nm": 150.0, "ito.drude2_omega_p": 1.8, "ito.tauc_lorentz1_A": 60.0},
    ),
    (
        Stack([Layer(SPLINE, 90.0, "bs")], "si"),
        {"bs.thickness_nm": 90.0, "bs.c3": 2.0, "bs.c4": 3.0},
    ),
]


@pytest.mark.parametrize(
    ("stack", "truth"), FITS, ids=["cody_lorentz", "gaussian", "sum", "bspline"]
)
def test_film_fit_recovers_the_model_that_made_the_data(stack, truth):
    from labbrdf.fitting.film import fit_film

    data = _psi_delta_rows(stack, np.linspace(300, 1000, 36))
    box = {k: (0.8 * v, 1.2 * v) for k, v in truth.items()}
    f = fit_film(FilmModel(stack, box), data, method="LN_BOBYQA")
    # noise-free data: the minimum is the truth; BOBYQA stops within a small fraction
    # of each standard error of it
    for k, v in truth.items():
        q = f.result.params[k]
        assert abs(q.value - v) < 0.05 * q.stderr, (k, q.value, v, q.stderr)


def test_bspline_size_chosen_by_bic_and_aic_recovers_a_spline_model():
    true = BSpline(1.5, 1.0, 9.0, (0.0, 0.5, 2.0, 4.0, 3.0, 1.5, 0.5, 0.0))
    e = np.linspace(1.2, 6.5, 60)
    rng = np.random.default_rng(1)
    sig = 0.01
    noisy = true.eps(HC_EV_NM / e) + sig * (rng.normal(size=60) + 1j * rng.normal(size=60))
    for crit in ("bic", "aic"):
        ch = bspline_fit.choose(e, noisy, range(5, 12), 1.0, 9.0, sig, crit)
        assert len(ch.model.coefficients) == 8, str(ch)
        np.testing.assert_allclose(ch.model.coefficients, true.coefficients, atol=0.05)
        assert ch.model.eps_inf == pytest.approx(1.5, abs=0.01)
        chi2 = ch.scores[8][0]
        assert 120 - 9 - 5 * math.sqrt(2 * 111) < chi2 < 111 + 5 * math.sqrt(2 * 111)
    assert "<- chosen" in str(ch) and "AIC" in str(ch)
    n_res = 2 * e.size
    for n, (chi2, aic, bic) in ch.scores.items():
        assert (aic, bic) == pytest.approx((chi2 + 2 * (n + 1), chi2 + (n + 1) * np.log(n_res)))
    # exact data: the spline is recovered to the kk accuracy
    exact, chi2 = bspline_fit.fit_eps(e, true.eps(HC_EV_NM / e), 8, 1.0, 9.0, 1e-6)
    np.testing.assert_allclose(exact.coefficients, true.coefficients, atol=1e-6)


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: CodyLorentz(Et=1.0, Eg=1.5), "Et >= Eg"),
        (lambda: CodyLorentz(Eu=0.0), "Eu > 0"),
        (lambda: CodyLorentz(A=-1.0), "A >= 0"),
        (lambda: Gaussian(oscillators=((1.0, 2.0, 0.0),)), "oscillator 1 needs"),
        (lambda: Gaussian(oscillators=((1.0, 2.0),)), "needs \\(A, En, Br\\)"),
        (lambda: Gaussian(oscillators=()), "at least one"),
        (lambda: Gaussian.from_params({"A1": 1, "En1": 2}), "lacks \\['Br1'\\]"),
        (lambda: Gaussian.from_params({"A1": 1, "En1": 2, "Br1": 1, "X": 1}), "unknown"),
        (lambda: BSpline(coefficients=(1.0, -1.0)), ">= 0"),
        (lambda: BSpline(coefficients=()), "at least one"),
        (lambda: BSpline(E_lo=3.0, E_hi=2.0), "E_lo < E_hi"),
        (lambda: BSpline.from_params({"c1": 1, "c3": 2}), "unknown.*c3"),
        (lambda: Sum.of("tauc_lorentz+cauchy"), "'cauchy' cannot be a term"),
        (lambda: Sum.of("drude+sum"), "'sum' cannot be a term"),
        (lambda: Sum.of("drude+tabulated"), "'tabulated' cannot be a term"),
        (lambda: Sum(terms=()), "at least one term"),
        (lambda: Sum.from_params({"drude1_eps_inf": 1.0}), "own eps_inf excluded"),
        (lambda: Sum.from_params({"A": 1.0}), "<model><j>_<parameter>"),
        (lambda: Sum.from_params({"drude1_gamma": 1, "lorentz1_A1": 1}), "term 1 is both"),
        (lambda: Sum.from_params({"drude2_gamma": 1.0}), "numbered \\[2\\]"),
        (lambda: Sum.from_params({"nope1_x": 1.0}), "'nope' cannot be a term"),
        (lambda: as_material("drude+glass"), "'glass' cannot be a term"),
        (lambda: bspline_fit.choose([1, 2], [1, 2], [3], 0.5, 3, criterion="x"), "aic' or 'bic"),
        (lambda: bspline_fit.choose([1, 2], [1, 2], [], 0.5, 3), "no candidate"),
        (lambda: bspline_fit.fit_eps([1.0], [1.0], 3, 0.5, 3), ">= 2 energies"),
    ],
)
def test_invalid_oscillator_models_raise_clear_errors(build, match):
    with pytest.raises(DispersionError, match=match):
        build()


def test_lorentz_is_a_valid_term_and_a_sums_kramers_kronig_is_its_terms():
    s = Sum(1.2, (Lorentz(oscillators=((1.0, 3.0, 0.4),)), GAUSS))
    eps2 = _eps2(s)
    for e in (1.0, 2.9, 4.2):
        expected = 1.2 + _pv(eps2, e, [1.0, 3.0, 4.0], 1e4)
        # Lorentz tail beyond 1e4 eV: (2/pi) A E0^2 G / (3 xi^3) ~ 1e-12
        assert s.eps(HC_EV_NM / e).real == pytest.approx(expected, abs=1e-7)


def test_bspline_basis_is_scipys_cubic_basis_elements_on_uniform_knots():
    from scipy.interpolate import BSpline as ScipyBSpline

    e = np.linspace(0.5, 8.5, 301)
    t = np.linspace(1.0, 8.0, 7 + 4)
    expected = sum(
        c * np.nan_to_num(ScipyBSpline.basis_element(t[j : j + 5], extrapolate=False)(e))
        for j, c in enumerate(SPLINE.coefficients)
    )
    np.testing.assert_allclose(SPLINE.eps2(e), expected, rtol=1e-12, atol=1e-14)


def test_kk_helper_gives_the_lorentz_oscillators_closed_form_with_its_tail():
    from labbrdf.nk.dispersion._kk import kk_eps1, panel_edges

    a, e0, g = 2.0, 3.0, 0.5

    def eps2(x):
        return a * e0**2 * g * x / ((e0**2 - x**2) ** 2 + g**2 * x**2)

    e = np.array([0.5, 2.9, 3.0, 4.0, 8.0])
    exact = (a * e0**2 / (e0**2 - e**2 - 1j * g * e)).real
    edges = panel_edges(100.0, e0 + g * np.linspace(-4, 4, 17))
    # beyond 100 eV the tail A E0^2 G / xi^3 is worth 2e-6; the left-out next term of the
    # expansion, (2/pi) A E0^2 G (2 E0^2 + E^2) / (5 xi^5), at most 2e-9
    got = kk_eps1(eps2, e, edges, tail=a * e0**2 * g)
    np.testing.assert_allclose(got, exact, atol=1e-8)
    assert np.max(np.abs(kk_eps1(eps2, e, edges) - exact)) > 1e-6  # without its tail


def test_a_sum_layer_is_fitted_from_the_command_line(tmp_path, capsys):
    from labbrdf.cli import main
    from labbrdf.dataset import Measurement, write

    df = _psi_delta_rows(FITS[2][0], np.linspace(300, 1000, 24))
    df["quantity"] = df["quantity"].astype("category")
    p = tmp_path / "ito.parquet"
    write(Measurement(df, {}), p)
    fixed = ":".join(f"{k}={v:g}" for k, v in TCO.params.items() if k not in ("drude2_omega_p",))
    spec = f"ito:tauc_lorentz+drude:100..200:{fixed}:drude2_omega_p=1..3"
    code = main(["film", str(p), "--substrate", "sio2", "--layer", spec, "--ci", "wald"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "layer ito (sum)" in out
    line = next(x for x in out.splitlines() if "drude2_omega_p" in x)
    assert float(line.split()[1]) == pytest.approx(1.8, abs=1e-3)
    code = main(["film", str(p), "--layer", "ito:drude+cauchy:100"])
    err = capsys.readouterr().err
    assert code == 2 and "'cauchy' cannot be a term" in err and "Traceback" not in err


def test_a_default_fit_leaves_the_b_spline_knot_range_fixed():
    spline_sum = Sum(1.0, (SPLINE, Drude(0.0, 1.0, 0.1)))
    fm = FilmModel.default(Stack([Layer(SPLINE, 90.0, "bs"), Layer(spline_sum, 10.0, "t")], "si"))
    assert {"bs.c1", "bs.eps_inf", "t.bspline1_c7", "t.drude2_gamma"} <= set(fm.free)
    assert not {"bs.E_lo", "bs.E_hi", "t.bspline1_E_lo", "t.bspline1_E_hi"} & set(fm.free)
