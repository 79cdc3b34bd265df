"""The film fit through the one fitting core: recovery, coverage, joint files, MSE, errors."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from labbrdf.dataset import Measurement, make_frame
from labbrdf.films import FilmError, FilmModel, Layer, Stack, load_model
from labbrdf.fitting.film import fit_film, woollam_mse
from labbrdf.nk.dispersion import Cauchy

WL = np.linspace(300, 1000, 60)
THETA = np.array([55.0, 65.0, 75.0])


def _rows(quantity, w, t, value, sigma, channel=None):
    d = {
        "sample": "s",
        "instrument": "sim",
        "source": f"{quantity}.dat",
        "quantity": quantity,
        "value": value,
        "sigma": sigma,
        "unit": "deg" if quantity in ("psi", "delta") else "1",
        "wavelength_nm": w,
        "theta_i_deg": t,
        "theta_r_deg": t,
        "phi_r_deg": 180.0,
    }
    if channel is not None:
        d["channel"] = channel
    return pd.DataFrame(d)


def _psi_delta(stack, rng, wl=WL, theta=THETA):
    W, T = np.meshgrid(wl, theta, indexing="ij")
    w, t = W.ravel(), T.ravel()
    psi, delta = stack.psi_delta(w, t)
    # an ellipsometer's sigmas: larger in the UV, as in the shared WVASE files
    sp = 0.01 + 0.02 * (w < 400)
    sd = 0.03 + 0.05 * (w < 400)
    return pd.concat(
        [
            _rows("psi", w, t, psi + rng.normal(0, sp), sp),
            _rows("delta", w, t, np.mod(delta + rng.normal(0, sd), 360.0), sd),
        ],
        ignore_index=True,
    )


TRUE = Stack([Layer(Cauchy(A=1.46, B=0.004), 105.0, "film")], "si")
TRUTH = {"film.thickness_nm": 105.0, "film.A": 1.46, "film.B": 0.004}


@pytest.mark.slow
def test_recovered_parameters_lie_in_their_95_percent_intervals_whatever_the_box():
    """Seeded replicates with the files' kind of sigmas: coverage >= 90 % per parameter."""
    n_rep = 40
    inside = dict.fromkeys(TRUTH, 0)
    for seed in range(n_rep):
        rng = np.random.default_rng(seed)
        data = _psi_delta(TRUE, rng)
        box = {  # a different starting box every replicate; the fit starts mid-box
            "film.thickness_nm": (0.0, rng.uniform(150, 400)),
            "film.A": (rng.uniform(1.2, 1.4), rng.uniform(1.6, 2.2)),
            "film.B": (0.0, rng.uniform(0.01, 0.05)),
        }
        f = fit_film(FilmModel(TRUE, box), data, seed=seed)
        assert f.result.success
        assert f.result.redchi < 1.5  # the global stage found the right interference order
        for k, v in TRUTH.items():
            lo, hi = f.result.params[k].ci95
            inside[k] += lo <= v <= hi
    for k, n in inside.items():
        assert n >= 0.9 * n_rep, f"{k}: {n}/{n_rep} replicates inside their 95 % interval"


def test_delta_residuals_are_wrapped_so_a_branch_jump_costs_nothing():
    rng = np.random.default_rng(7)
    data = _psi_delta(TRUE, rng)
    shifted = data.copy()
    d = shifted["quantity"] == "delta"
    # the same measurement written in (-180, 180] instead of [0, 360)
    shifted.loc[d, "value"] = (shifted.loc[d, "value"] + 180.0) % 360.0 - 180.0
    box = {"film.thickness_nm": (50.0, 150.0), "film.A": (1.3, 1.7), "film.B": (0.0, 0.02)}
    a = fit_film(FilmModel(TRUE, box), data, seed=1)
    b = fit_film(FilmModel(TRUE, box), shifted, seed=1)
    assert a.result.chisqr == pytest.approx(b.result.chisqr, rel=1e-9)
    assert a.result.params["film.thickness_nm"].value == pytest.approx(
        b.result.params["film.thickness_nm"].value, rel=1e-9
    )


def test_mse_is_woollams_form_and_chi2_nu_is_its_square():
    rng = np.random.default_rng(3)
    data = _psi_delta(TRUE, rng)
    box = {"film.thickness_nm": (50.0, 150.0), "film.A": (1.3, 1.7), "film.B": (0.0, 0.02)}
    f = fit_film(FilmModel(TRUE, box), data, seed=0)
    # recompute from the definition with the wrapped Delta difference
    best = f.stack
    psi_d = data[data.quantity == "psi"]
    del_d = data[data.quantity == "delta"]
    psi_m, _ = best.psi_delta(psi_d.wavelength_nm.to_numpy(), psi_d.theta_i_deg.to_numpy())
    _, del_m = best.psi_delta(del_d.wavelength_nm.to_numpy(), del_d.theta_i_deg.to_numpy())
    dd = (del_m - del_d.value.to_numpy() + 180) % 360 - 180
    s = np.sum(((psi_m - psi_d.value) / psi_d.sigma) ** 2) + np.sum((dd / del_d.sigma) ** 2)
    n_pairs, m = len(psi_d), 3
    mse = np.sqrt(s / (2 * n_pairs - m))
    assert f.mse == pytest.approx(mse, rel=1e-6)
    assert f.summary()["redchi"] == pytest.approx(mse**2, rel=1e-6)
    assert 0.8 < f.mse < 1.2  # honest sigmas give MSE near 1
    assert woollam_mse(10.0, 5, 5) != woollam_mse(10.0, 5, 5)  # no degrees of freedom: NaN


def test_joint_fit_of_psi_delta_and_polarised_reflectance_files():
    rng = np.random.default_rng(11)
    pd_rows = _psi_delta(TRUE, rng)
    W, T = np.meshgrid(WL, np.array([60.0, 70.0]), indexing="ij")
    rs, rp = TRUE.reflectance(W.ravel(), T.ravel())
    refl = pd.concat(
        [
            _rows(
                "reflectance", W.ravel(), T.ravel(), rs + rng.normal(0, 0.005, rs.size), 0.005, "s"
            ),
            _rows(
                "reflectance", W.ravel(), T.ravel(), rp + rng.normal(0, 0.005, rp.size), 0.005, "p"
            ),
        ],
        ignore_index=True,
    )
    box = {"film.thickness_nm": (0.0, 300.0), "film.A": (1.3, 1.8), "film.B": (0.0, 0.03)}
    f = fit_film(FilmModel(TRUE, box), [pd_rows, refl], seed=2)
    s = f.summary()
    assert set(s["channels"]) == {"psi", "delta", "R_s", "R_p"}
    assert s["channels"]["R_s"]["n"] == W.size
    for k, v in TRUTH.items():
        lo, hi = s["layers"][0]["parameters"][k.split(".")[1]]["ci95"]
        assert lo <= v <= hi
    assert 0.8 < s["redchi"] < 1.2


def test_thin_film_flags_the_thickness_index_trade_off():
    thin = Stack([Layer(Cauchy(A=1.46, B=0.0036), 2.0, "oxide")], "si")
    rng = np.random.default_rng(5)
    data = _psi_delta(thin, rng)
    f = fit_film(
        FilmModel(thin, {"oxide.thickness_nm": (0.0, 10.0), "oxide.A": (1.2, 2.0)}), data, seed=0
    )
    notes = " ".join(f.notes())
    assert "trade off" in notes and "oxide.thickness_nm" in notes
    assert abs(f.result.params["oxide.A"].correl["oxide.thickness_nm"]) > 0.95


def test_profile_intervals_bracket_the_estimate_and_summary_is_json(tmp_path):
    rng = np.random.default_rng(9)
    data = _psi_delta(TRUE, rng, wl=np.linspace(400, 900, 20))
    box = {"film.thickness_nm": (50.0, 150.0), "film.A": (1.3, 1.7)}
    fm = FilmModel(TRUE.with_values({"film.B": 0.004}), box)
    f = fit_film(fm, data, seed=0, ci="profile")
    q = f.result.params["film.thickness_nm"]
    assert q.ci95[0] < q.value < q.ci95[1]
    out = f.save_json(tmp_path / "fit.json")
    doc = json.loads(out.read_text())
    assert doc["ci_method"] == "profile"
    assert doc["layers"][0]["nk_at_633nm"]["n"] == pytest.approx(1.46 + 0.004 / 0.633**2, abs=1e-3)
    again = Stack.from_fit_json(out)
    assert again.layers[0].thickness_nm == pytest.approx(q.value)


def test_rows_without_sigma_need_a_default_sigma():
    rng = np.random.default_rng(1)
    data = _psi_delta(TRUE, rng)
    W = WL
    rs, _ = TRUE.reflectance(W, 0.0)
    refl = _rows("reflectance", W, np.nan, rs, np.nan)  # a spectrophotometer, no sigma
    box = {"film.thickness_nm": (50.0, 150.0)}
    with pytest.raises(FilmError, match="60 reflectance row\\(s\\) have no sigma"):
        fit_film(FilmModel(TRUE, box), [data, refl])
    f = fit_film(FilmModel(TRUE, box), [data, refl], default_sigma={"reflectance": 0.002})
    assert f.summary()["channels"]["R"]["n"] == 60


def test_substrate_table_that_misses_the_data_wavelengths_is_refused(tmp_path):
    rng = np.random.default_rng(1)
    data = _psi_delta(TRUE, rng, wl=np.linspace(260, 1000, 20))
    data.loc[data.wavelength_nm == 260, "wavelength_nm"] = 200.0  # outside the Si table
    p = tmp_path / "m.toml"
    p.write_text(
        '[substrate]\nmaterial = "si"\n\n[[layer]]\nmaterial = "cauchy"\nthickness_nm = [0, 200]\n'
    )
    with pytest.raises(
        FilmError, match="m.toml: substrate material si_green2008.csv.*250-1450 nm.*200-1000"
    ):
        fit_film(p, data)
    f = fit_film(load_model(p), data, wavelength_range_nm=(250, 1000), maxeval=[200, 400])
    assert f.summary()["wavelength_range_nm"][0] >= 250


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"free": {"film.Q": (0, 1)}}, "unknown parameter"),
        ({"free": {"film.A": (1.7, 1.3)}}, "bounds"),
        ({"wavelength_range_nm": (2000, 3000)}, "no psi, delta"),
    ],
)
def test_bad_fit_requests_raise_film_errors(kw, match):
    data = _psi_delta(TRUE, np.random.default_rng(0))
    with pytest.raises(FilmError, match=match):
        fit_film(TRUE, data, **kw)


def test_cross_polarisation_rows_are_left_out_and_odd_channels_refused():
    rng = np.random.default_rng(2)
    data = _psi_delta(TRUE, rng, wl=np.linspace(400, 900, 10))
    data["channel"] = None
    cross = data.copy()
    cross["channel"] = "ps"  # generalised ellipsometry: not a two-phase psi/Delta
    cross["value"] = 0.0
    box = {"film.thickness_nm": (50.0, 150.0)}
    f = fit_film(FilmModel(TRUE, box), pd.concat([data, cross], ignore_index=True))
    assert f.result.ndata == len(data)
    odd = _rows("reflectance", np.array([500.0]), 60.0, np.array([0.3]), 0.01, "x")
    with pytest.raises(FilmError, match="channel \\['x'\\]; expected s, p or none"):
        fit_film(FilmModel(TRUE, box), [data, odd])


def test_fit_film_refuses_files_that_state_different_samples_unless_told():
    """Two files, two stated sample names: no joint fit unless ``one_sample=True``."""
    wl = np.linspace(400.0, 900.0, 12)
    stack = Stack([Layer(Cauchy(A=1.46, B=0.004), 100.0, "film")], "si")

    def rows(sample: str, source: str, angle: float) -> Measurement:
        psi, delta = stack.psi_delta(wl, np.full(wl.size, angle))
        return Measurement(
            pd.concat(
                [
                    make_frame(
                        sample=sample,
                        instrument="sim",
                        source=source,
                        quantity=q,
                        value=v,
                        unit="deg",
                        wavelength_nm=wl,
                        sigma=0.05,
                        theta_i_deg=angle,
                    )
                    for q, v in (("psi", psi), ("delta", np.mod(delta, 360.0)))
                ],
                ignore_index=True,
            ),
            {},
        )

    data = [rows("wafer-A", "a.dat", 60.0), rows("wafer-B", "b.dat", 70.0)]
    with pytest.raises(FilmError, match=r"a.dat states 'wafer-A'; b.dat states 'wafer-B'"):
        fit_film(stack, data, method="LN_BOBYQA")
    fit = fit_film(stack, data, method="LN_BOBYQA", one_sample=True)
    assert fit.sources == ["a.dat", "b.dat"]
    # a reader's file-name fallback is no stated name: a.dat's rows named "b" pair anyway
    same = [rows("wafer-A", "a.dat", 60.0), rows("b", "b.dat", 70.0)]
    assert fit_film(stack, same, method="LN_BOBYQA").sources == ["a.dat", "b.dat"]
