"""Spectral bandwidth and angle spread: the averages, their limits, and the fitted dpol channel."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from labbrdf.films import FilmError, FilmModel, Layer, Stack, load_model
from labbrdf.films import incoherent as inc
from labbrdf.films.spreads import FWHM_PER_SIGMA, beam_sums
from labbrdf.fitting.film import fit_film
from labbrdf.nk.dispersion import Cauchy, Constant

N = [1.0, 2.1 + 0.002j, 1.46, 3.9 + 0.02j]
D = [500.0, 30.0]
FLAGS = [True, True]
WL = np.array([400.0, 550.0, 800.0])
TH = np.array([[55.0], [70.0]])


def _stack(**kw) -> Stack:
    """The stack of N, D with constant indices: holding them over the band is then exact."""
    layers = [Layer(Constant(n=z.real, k=z.imag), d, f"l{j}") for j, (z, d) in enumerate(
        zip(N[1:-1], D, strict=True))]  # fmt: skip
    return Stack(layers, Constant(n=N[-1].real, k=N[-1].imag), **kw)


def _dense(bandwidth_nm=0.0, angle_deg=0.0):
    """The Gaussian average by a fine trapezoid (801 nodes over +-9 sigma per variable),
    every node a plain coherent evaluation (broadcast over a node axis)."""
    x = np.linspace(-9.0, 9.0, 801)
    w = np.exp(-0.5 * x * x)
    w /= w.sum()
    lam = WL + (bandwidth_nm / FWHM_PER_SIGMA) * x[:, None, None] if bandwidth_nm else WL
    th = TH + angle_deg * x[:, None, None] if angle_deg else TH
    s = inc.intensity_sums(N, D, FLAGS, lam, th)
    return [np.tensordot(w, np.asarray(v), axes=(0, 0)) for v in s]


@pytest.mark.parametrize(("bw", "ang"), [(2.0, 0.0), (12.0, 0.0), (0.0, 0.3), (0.0, 1.5)])
def test_the_default_nodes_give_the_dense_gaussian_average(bw, ang):
    """Within 1e-6 of an 801-node trapezoid, as the thickness spread's average."""
    got = _stack(bandwidth_nm=bw, angle_spread_deg=ang).intensity_sums(WL, TH)
    for a, b in zip(got, _dense(bw, ang), strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-6)
    if bw > 5 or ang > 1:  # too few nodes miss the average: the node rule matters
        few = beam_sums(_stack().intensity_sums, WL, TH, bw, ang, 1400.0, points=5)
        assert np.max(np.abs(few.Rs - _dense(bw, ang)[0])) > 1e-5


def test_band_and_angle_together_are_the_product_average():
    """Both at once: the 2-D Gaussian average (201 x 201 trapezoid over +-8 sigma)."""
    x = np.linspace(-8.0, 8.0, 201)
    w = np.exp(-0.5 * x * x)
    w /= w.sum()
    lam = WL + (6.0 / FWHM_PER_SIGMA) * x[:, None, None, None]
    th = TH + 0.8 * x[None, :, None, None]
    ref = inc.intensity_sums(N, D, FLAGS, lam, th)
    got = _stack(bandwidth_nm=6.0, angle_spread_deg=0.8).intensity_sums(WL, TH)
    for a, b in zip(got, ref, strict=True):
        np.testing.assert_allclose(a, np.einsum("i,j,ij...->...", w, w, b), rtol=0, atol=1e-6)


def test_zero_band_and_spread_are_the_coherent_stack_exactly():
    plain = _stack().intensity_sums(WL, TH)
    zero = _stack(bandwidth_nm=0.0, angle_spread_deg=0.0, thickness_spread=0.0)
    for a, b in zip(zero.intensity_sums(WL, TH), plain, strict=True):
        np.testing.assert_array_equal(a, b)
    assert zero.depolarizing and not _stack().depolarizing
    dep = [_stack(bandwidth_nm=b).depolarization(WL, TH) for b in (2.0, 8.0)]
    assert np.all(dep[0] > 1e-5) and np.all(dep[1] > dep[0])
    st = _stack(bandwidth_nm=4.0, angle_spread_deg=0.5)
    back = Stack.from_dict(st.to_dict())
    np.testing.assert_array_equal(back.depolarization(WL, TH), st.depolarization(WL, TH))
    assert "bandwidth_nm=4" in repr(back) and "angle_spread_deg=0.5" in repr(back)
    assert (
        st.values()["stack.bandwidth_nm"] == 4.0 and st.units()["stack.angle_spread_deg"] == "deg"
    )
    assert st.with_values({"stack.bandwidth_nm": 1.0}).bandwidth_nm == 1.0


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"bandwidth_nm": 25.0}, "bandwidth_nm"),
        ({"bandwidth_nm": -1.0}, "bandwidth_nm"),
        ({"angle_spread_deg": 3.0}, "angle_spread_deg"),
        ({"angle_spread_deg": "wide"}, "angle_spread_deg: expected a number"),
    ],
)
def test_a_stack_refuses_bad_band_and_spread(kw, match):
    with pytest.raises(FilmError, match=match):
        _stack(**kw)


def test_the_average_refuses_what_it_cannot_compute():
    f = _stack().intensity_sums
    with pytest.raises(ValueError, match="bandwidth_nm"):
        beam_sums(f, WL, TH, 30.0)
    with pytest.raises(ValueError, match="reaches 90 deg"):
        beam_sums(f, WL, 80.0, 0.0, 1.5)
    with pytest.raises(ValueError, match="points"):
        beam_sums(f, WL, TH, 2.0, 0.0, 100.0, points=4)


def test_a_model_file_reads_band_and_spread(tmp_path):
    p = tmp_path / "m.toml"
    body = '[substrate]\nmaterial = "si"\n\n[[layer]]\nmaterial = "sio2"\nthickness_nm = 100\n'
    p.write_text("bandwidth_nm = [0, 10]\nangle_spread_deg = 0.3\n" + body)
    m = load_model(p)
    assert m.free == {"stack.bandwidth_nm": (0.0, 10.0)}
    assert m.stack.bandwidth_nm == 5.0 and m.stack.angle_spread_deg == 0.3
    p.write_text("angle_spread_deg = [0, 5]\n" + body)
    with pytest.raises(FilmError, match=r"m.toml, line 1: angle_spread_deg"):
        load_model(p)


def _frame(stack: Stack, seed: int) -> pd.DataFrame:
    """psi, Delta and depolarization rows of ``stack`` at two angles, with noise."""
    W, T = np.meshgrid(np.linspace(400.0, 1000.0, 11), [60.0, 70.0], indexing="ij")
    w, t = W.ravel(), T.ravel()
    psi, delta = stack.psi_delta(w, t)
    dpol = stack.depolarization(w, t)
    rng = np.random.default_rng(seed)
    parts = []
    for q, v, s, u in (("psi", psi, 0.02, "deg"), ("delta", delta, 0.05, "deg"),
                       ("depolarization", dpol, 0.002, "1")):  # fmt: skip
        parts.append(
            pd.DataFrame(
                {
                    "sample": "s",
                    "instrument": "sim",
                    "source": "x.dat",
                    "quantity": q,
                    "value": v + rng.normal(0, s, w.size),
                    "sigma": s,
                    "unit": u,
                    "wavelength_nm": w,
                    "theta_i_deg": t,
                    "theta_r_deg": t,
                    "phi_r_deg": 180.0,
                }
            )  # fmt: skip
        )
    return pd.concat(parts, ignore_index=True)


def test_the_depolarization_channel_is_fitted_when_the_model_can_depolarize(tmp_path):
    """A 6 nm band on a 300 nm film, recovered from psi, Delta and dpol within its interval.

    Local fit from 3 nm and 295 nm (the global stage finds the same point). z = (fit -
    truth) / stderr over noise seeds 1-16: 2.28, 2.79, 0.41, -1.39, -1.78, 1.88, -0.35,
    -0.28, -0.58, -0.71, 0.92, 0.11, -0.52, 0.55, 0.11, 0.93 (rms 1.25).
    """
    truth = Stack([Layer(Cauchy(A=2.1, B=0.02), 300.0, "film")], "si", bandwidth_nm=6.0)
    data = _frame(truth, 3)
    start = truth.with_values({"film.thickness_nm": 295.0, "stack.bandwidth_nm": 3.0})
    box = {"film.thickness_nm": (280.0, 320.0), "stack.bandwidth_nm": (0.0, 15.0)}
    fit = fit_film(FilmModel(start, box), data, method="LN_BOBYQA", ci="wald")
    p = fit.result.params["stack.bandwidth_nm"]
    assert abs(p.value - 6.0) < 1.96 * p.stderr
    stats = fit.channel_stats()
    assert stats["depolarization"]["n"] == 22 and fit.result.ndata == 66
    r = np.asarray(fit.result.residual)[fit.channels == 8]
    model = fit.stack.depolarization(fit.data.wavelength_nm, fit.data.theta_i_deg)[
        fit.channels == 8
    ]
    np.testing.assert_allclose(r, fit.data.value[fit.channels == 8] - model, atol=1e-12)
    assert stats["depolarization"]["chi2"] == pytest.approx(np.sum((r / 0.002) ** 2))
    text = fit.fit_report()
    assert (
        "depolarization channel: 22 rows, chi2 " in text and "MSE of psi and Delta alone" in text
    )
    off = fit_film(
        FilmModel(start, box), data, method="LN_BOBYQA", ci="wald", depolarization=False
    )
    assert "depolarization channel" not in off.fit_report()
    back = Stack.from_fit_json(fit.save_json(tmp_path / "fit.json"))  # the schema takes it
    assert back.bandwidth_nm == p.value
    # the same model without the band cannot depolarize: auto leaves the channel out
    plain = Stack([Layer(Cauchy(A=2.1, B=0.02), 300.0, "film")], "si")
    box = {"film.thickness_nm": (280.0, 320.0)}
    off = fit_film(FilmModel(plain, box), data, method="LN_BOBYQA", ci="wald")
    assert "depolarization" not in off.channel_stats() and off.result.ndata == 44
    on = fit_film(FilmModel(plain, box), data, method="LN_BOBYQA", ci="wald", depolarization=True)
    assert on.channel_stats()["depolarization"]["n"] == 22


def test_asking_for_the_channel_without_it_is_refused():
    st = Stack([Layer(Cauchy(A=2.1, B=0.02), 300.0, "film")], "si", bandwidth_nm=2.0)
    data = _frame(st, 1)
    box = {"film.thickness_nm": (280.0, 320.0)}
    with pytest.raises(FilmError, match="no depolarization rows"):
        fit_film(FilmModel(st, box), data[data.quantity != "depolarization"], depolarization=True)
    with pytest.raises(FilmError, match="expected 'auto', True or False"):
        fit_film(FilmModel(st, box), data, depolarization="yes")
