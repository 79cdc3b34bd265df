"""Incoherent thick layers and backside reflection: against tmm, phase averages, limits, I/O."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from labbrdf.films import FilmError, FilmModel, Layer, Stack, load_model
from labbrdf.films import incoherent as inc
from labbrdf.films import matrices as stk
from labbrdf.fitting.film import fit_film
from labbrdf.nk.dispersion import Cauchy

ANGLES = np.arange(0.0, 81.0, 10.0)


def _tmm_inc(pol, n, d, coherent, theta_deg, lam):
    tmm = pytest.importorskip("tmm")
    c = ["i"] + ["c" if x else "i" for x in coherent] + ["i"]
    out = tmm.inc_tmm(pol, n, [np.inf, *d, np.inf], c, np.radians(theta_deg), lam)
    return out["R"], out["T"]


STACKS = [
    # a film on 1 mm glass in air, backside reflection
    ([1.0, 2.0, 1.52, 1.0], [100.0, 1e6], [True, False]),
    # an absorbing film on glass, with an AR film on the back
    ([1.0, 2.3 + 0.05j, 1.46, 1.38, 1.0], [80.0, 5e5, 110.0], [True, False, True]),
    # a weakly absorbing thick layer between two coherent stacks, on silicon
    (
        [1.0, 1.45, 1.6 + 2e-5j, 2.0 + 0.01j, 1.7, 3.9 + 0.02j],
        [120.0, 2e5, 60.0, 300.0],
        [True, False, True, True],
    ),
    # two incoherent layers, the lower one strongly absorbing
    ([1.0, 1.5, 1.8, 1.3 + 1e-3j, 1.0], [1e5, 90.0, 4e4], [False, True, False]),
]


@pytest.mark.parametrize(("n", "d", "coherent"), STACKS)
def test_reflectance_and_transmittance_agree_with_tmm_inc_tmm(n, d, coherent):
    for lam in (450.0, 633.0, 1100.0):
        sums = inc.intensity_sums(n, d, coherent, lam, ANGLES)
        for j, th in enumerate(ANGLES):
            for pol, r, t in (("s", sums.Rs, sums.Ts), ("p", sums.Rp, sums.Tp)):
                r_ref, t_ref = _tmm_inc(pol, n, d, coherent, th, lam)
                assert r[j] == pytest.approx(r_ref, abs=1e-10), (lam, th, pol)
                assert t[j] == pytest.approx(t_ref, abs=1e-10), (lam, th, pol)


def test_the_film_on_glass_of_the_literature_example():
    """100 nm of n = 2 on 1 mm of n = 1.52 at 550 nm: the backside adds 0.032 to R."""
    thick = Stack([Layer(2.0, 100.0, "film")], 1.52, substrate_thickness_nm=1e6)
    semi = Stack([Layer(2.0, 100.0, "film")], 1.52)
    assert thick.reflectance(550.0, 0.0)[0] == pytest.approx(0.1722, abs=5e-5)
    assert semi.reflectance(550.0, 0.0)[0] == pytest.approx(0.1405, abs=5e-5)
    assert thick.reflectance(550.0, 70.0)[1] == pytest.approx(0.0506, abs=5e-5)
    assert thick.transmittance(550.0, 0.0)[0] == pytest.approx(0.8278, abs=5e-5)
    r_ref, t_ref = _tmm_inc("p", [1.0, 2.0, 1.52, 1.0], [100.0, 1e6], [True, False], 70.0, 550.0)
    assert thick.reflectance(550.0, 70.0)[1] == pytest.approx(r_ref, abs=1e-12)
    assert thick.transmittance(550.0, 70.0)[1] == pytest.approx(t_ref, abs=1e-12)


@pytest.mark.parametrize("theta", [0.0, 35.0, 57.0, 70.0, 80.0])
def test_the_cross_term_is_the_phase_average_of_the_coherent_one(theta):
    """Averaging r_s r_p* of the coherent stack over the substrate's phase gives X.

    Independent of the geometric series: 128 coherent evaluations over one period of the
    lossless substrate's round-trip phase; the aliased terms are of order |r' r|^128.
    """
    lam, n_glass = 633.0, 1.52
    n = [1.0, 2.1, 1.38, n_glass, 1.0]
    kz = np.sqrt(n_glass**2 - np.sin(np.radians(theta)) ** 2)
    period = lam / (2.0 * kz)  # substrate thickness that adds 2 pi to the round trip
    d_sub = 1e4 + period * np.arange(128) / 128  # thin enough that its phase is exact
    rs, rp, _, _ = stk.amplitudes(n, [90.0, 40.0, d_sub], lam, theta)
    sums = inc.intensity_sums(n, [90.0, 40.0, 1e6], [True, True, False], lam, theta)
    assert sums.Rs == pytest.approx(np.mean(np.abs(rs) ** 2), abs=1e-12)
    assert sums.Rp == pytest.approx(np.mean(np.abs(rp) ** 2), abs=1e-12)
    x = np.mean(rs * np.conj(rp))
    assert abs(sums.X - x) < 1e-12
    psi, delta, depol = inc.ellipsometry(sums)
    m = inc.mueller(sums)
    n_, c_, s_ = m[0, 1] / m[0, 0], m[2, 2] / m[0, 0], m[2, 3] / m[0, 0]
    assert np.cos(2 * np.radians(psi)) == pytest.approx(n_, abs=1e-12)
    assert np.degrees(np.arctan2(s_, c_)) % 360 == pytest.approx(delta, abs=1e-9)
    assert depol == pytest.approx(1 - np.sqrt(n_**2 + c_**2 + s_**2), abs=1e-12)
    if theta > 0:
        assert depol > 1e-4  # the backside depolarizes off normal incidence


def test_a_coherent_stack_gives_its_amplitude_products_and_no_depolarization():
    n, d = [1.0, 1.46, 2.0 + 0.1j, 3.9 + 0.02j], [120.0, 35.0]
    sums = inc.intensity_sums(n, d, [True, True], 500.0, ANGLES)
    rs, rp, _, _ = stk.amplitudes(n, d, 500.0, ANGLES)
    ts_, tp_ = stk.transmittance(n, d, 500.0, ANGLES)
    np.testing.assert_allclose(sums.Rs, np.abs(rs) ** 2, rtol=0, atol=1e-14)
    np.testing.assert_allclose(sums.X, rs * np.conj(rp), rtol=0, atol=1e-14)
    np.testing.assert_allclose(sums.Tp, tp_, rtol=0, atol=1e-14)
    np.testing.assert_allclose(sums.Ts, ts_, rtol=0, atol=1e-14)
    psi, delta, depol = inc.ellipsometry(sums)
    psi0, delta0 = stk.ellipsometry(n, d, 500.0, ANGLES)
    np.testing.assert_allclose(psi, psi0, rtol=0, atol=1e-10)
    np.testing.assert_allclose(delta, delta0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(depol, 0.0, atol=1e-7)


def test_an_opaque_thick_substrate_has_no_backside():
    """k > 0 attenuates the round trip: 1 mm of k = 1e-2 at 600 nm is exp(-209) per pass."""
    lossy = Stack([Layer(2.0, 100.0)], complex(1.5, 1e-2), substrate_thickness_nm=1e6)
    semi = Stack([Layer(2.0, 100.0)], complex(1.5, 1e-2))
    np.testing.assert_allclose(lossy.reflectance(600.0, ANGLES), semi.reflectance(600.0, ANGLES))
    np.testing.assert_allclose(lossy.transmittance(600.0, ANGLES), 0.0, atol=1e-15)
    # a thin absorbing substrate: one pass of attenuation P = exp(-4 pi k d / lambda)
    thin = Stack([], complex(1.5, 1e-5), substrate_thickness_nm=1e5)
    p = np.exp(-4 * np.pi * 1e-5 * 1e5 / 600.0)
    r = ((1.5 - 1.0) / 2.5) ** 2
    t_ref = (1 - r) ** 2 * p / (1 - r**2 * p**2)
    assert thin.transmittance(600.0, 0.0)[0] == pytest.approx(t_ref, rel=1e-6)  # k^2 / n^2


def test_stack_with_a_thick_substrate_serialises_and_varies():
    s = Stack(
        [Layer(Cauchy(A=1.9), 100.0, "film"), Layer(1.5, 2e5, "sheet", coherent=False)],
        1.52,
        substrate_thickness_nm=1e6,
    )
    assert not s.coherent
    back = Stack.from_dict(s.to_dict())
    assert back.substrate_thickness_nm == 1e6 and not back.layers[1].coherent
    np.testing.assert_array_equal(back.psi_delta(600.0, 65.0), s.psi_delta(600.0, 65.0))
    v = s.with_values({"substrate.thickness_nm": 2e6, "film.A": 2.0})
    assert v.substrate_thickness_nm == 2e6 and not v.layers[1].coherent
    assert "substrate.thickness_nm" in s.values() and s.units()["substrate.thickness_nm"] == "nm"
    assert "incoherent" in repr(s) and "substrate_thickness_nm" in repr(s)
    assert "coherent" not in Stack([Layer(1.5, 10.0)], "si").to_dict()["layers"][0]
    with pytest.raises(FilmError, match="no amplitudes"):
        s.amplitudes(600.0, 65.0)
    with pytest.raises(FilmError, match="substrate_thickness_nm"):
        Stack([], 1.5, substrate_thickness_nm=-1.0)
    with pytest.raises(FilmError, match="coherent must be"):
        Layer(1.5, 10.0, "x", coherent="no")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="one flag per layer"):
        inc.intensity_sums([1.0, 1.5, 1.0], [10.0], [], 500.0, 0.0)
    free = FilmModel.default(s).free  # a thick layer's thickness enters only by absorption
    assert "film.thickness_nm" in free and "sheet.thickness_nm" not in free


MODEL = """\
wavelength_nm = [400, 1000]

[substrate]
material = "sio2"
thickness_nm = 1e6

[[layer]]
name = "film"
material = "cauchy"
A = [1.6, 2.4]
B = 0.01
thickness_nm = [50, 200]

[[layer]]
name = "sheet"
material = "sio2"
thickness_nm = 5e5
coherent = false
"""


def test_model_file_reads_a_thick_substrate_and_an_incoherent_layer(tmp_path):
    p = tmp_path / "glass.toml"
    p.write_text(MODEL)
    m = load_model(p)
    assert m.stack.substrate_thickness_nm == 1e6
    assert [lay.coherent for lay in m.stack.layers] == [True, False]
    assert set(m.free) == {"film.A", "film.C", "film.thickness_nm"}  # C unwritten: free


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (lambda t: t.replace("coherent = false", 'coherent = "no"'), r"line 18: coherent must"),
        (lambda t: t.replace("thickness_nm = 1e6", "thickness_nm = 0"), r"line 5: thickness_nm"),
        (
            lambda t: t.replace("thickness_nm = 1e6", "thickness_nm = 1e6\ncoherent = false"),
            r"line 6: 'coherent' is a layer key",
        ),
        (lambda t: t.replace("thickness_nm = 1e6", "thickness_nm = 1e9"), r"line 5: .*1e\+07"),
    ],
)
def test_bad_incoherent_keys_name_the_file_and_line(tmp_path, edit, match):
    p = tmp_path / "bad.toml"
    p.write_text(edit(MODEL))
    with pytest.raises(FilmError, match=match):
        load_model(p)


def _rt_rows(stack, wl, rng, sigma):
    rows = []
    r, _ = stack.reflectance(wl, 0.0)
    t, _ = stack.transmittance(wl, 0.0)
    for q, v in (("reflectance", r), ("transmittance", t)):
        rows.append(
            pd.DataFrame(
                {
                    "sample": "glass",
                    "instrument": "sim",
                    "source": f"{q}.csv",
                    "quantity": q,
                    "value": v + rng.normal(0, sigma, wl.size),
                    "sigma": sigma,
                    "unit": "1",
                    "wavelength_nm": wl,
                    "theta_i_deg": 0.0,
                    "theta_r_deg": 0.0,
                    "phi_r_deg": 0.0,
                }
            )
        )
    return pd.concat(rows, ignore_index=True)


def test_film_on_glass_is_fitted_from_spectrophotometer_r_and_t(tmp_path):
    """The thick-substrate model recovers the film; the semi-infinite one misses it."""
    truth = Stack([Layer(Cauchy(A=2.05, B=0.012), 140.0, "film")], "sio2", 1.0, 1e6)
    wl = np.linspace(400.0, 1000.0, 61)
    data = _rt_rows(truth, wl, np.random.default_rng(5), 0.002)
    box = {"film.thickness_nm": (50.0, 250.0), "film.A": (1.6, 2.4)}
    fit = fit_film(FilmModel(truth, box), data, seed=1)
    s = fit.summary()
    for key, v in (("thickness_nm", 140.0), ("A", 2.05)):
        lo, hi = s["layers"][0]["parameters"][key]["ci95"]
        assert lo <= v <= hi
    assert s["redchi"] < 1.5
    back = Stack.from_fit_json(fit.save_json(tmp_path / "fit.json"))
    assert back.substrate_thickness_nm == 1e6
    assert "1e+06 (fixed)" in fit.fit_report().split("substrate: ")[1]  # the glass shown
    semi = Stack(truth.layers, "sio2")
    assert fit_film(FilmModel(semi, box), data, seed=1).summary()["redchi"] > 50
