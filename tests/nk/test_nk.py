"""Dataset layer of the optical constants (labbrdf.nk)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

import labbrdf
from labbrdf import ellipsometry as ell
from labbrdf import nk, optics
from labbrdf.dataset import Measurement
from labbrdf.films import onefilm


def _synthetic(big_n=(2.0 + 3.0j), wl=(400.0, 500.0, 600.0), theta=(65.0, 70.0, 75.0), sig=0.02):
    rows = []
    for w in wl:
        for t in theta:
            psi, delta = optics.psi_delta(big_n, t)
            for q, v in (("psi", float(psi)), ("delta", float(delta))):
                rows.append(
                    dict(sample="s", instrument="x", source="f.dat", quantity=q, value=v,
                         sigma=sig, unit="deg", wavelength_nm=w, theta_i_deg=t,
                         theta_r_deg=t, phi_r_deg=180.0)
                )  # fmt: skip
    return pd.DataFrame(rows)


def test_nk_table_columns_and_values():
    t = nk.nk_table(_synthetic())
    assert list(t.columns[:9]) == [
        "sample", "source", "wavelength_nm", "theta_i_deg",
        "n", "k", "n_sigma", "k_sigma", "cond",
    ]  # fmt: skip
    assert len(t) == 9 and t.attrs["unpaired"] == 0
    np.testing.assert_allclose(t["n"], 2.0, rtol=1e-12)
    np.testing.assert_allclose(t["k"], 3.0, rtol=1e-12)
    assert (t["n_sigma"] > 0).all()


def test_combined_and_json_shapes_and_nan_to_null():
    df = _synthetic(sig=np.nan)
    out = nk.nk_json(df)
    text = json.dumps(out, allow_nan=False)  # no NaN anywhere
    assert set(out) == {"wavelength_nm", "theta_i_deg", "n", "k", "n_sigma", "k_sigma", "combined"}
    assert len({len(out[c]) for c in out if c != "combined"}) == 1 and len(out["n"]) == 9
    assert set(out["combined"]) == {
        "wavelength_nm", "n", "k", "n_sigma", "k_sigma", "chi2", "dof", "p_value",
        "angle_dependent",
    }  # fmt: skip
    assert out["combined"]["wavelength_nm"] == [400.0, 500.0, 600.0]
    assert out["n_sigma"][0] is None and out["combined"]["chi2"][0] is None
    assert "NaN" not in text


def test_mixed_samples_are_grouped():
    a = _synthetic()
    b = _synthetic(big_n=1.5 + 0.0j).assign(sample="glass", source="g.dat")
    out = nk.nk_json(pd.concat([a, b], ignore_index=True))
    assert sorted(g["sample"] for g in out["groups"]) == ["glass", "s"]
    c = nk.combined_table(pd.concat([a, b], ignore_index=True))
    assert len(c) == 6
    np.testing.assert_allclose(c.loc[c["sample"] == "glass", "n"], 1.5, rtol=1e-10)


def test_nk_at_interpolates_and_refuses_extrapolation():
    c = nk.combined_table(_synthetic())
    at = nk.nk_at(c, [450.0, 600.0])
    np.testing.assert_allclose(at["n"], 2.0, rtol=1e-12)
    with pytest.raises(ValueError, match=r"outside the measured range \[400, 600\] nm"):
        nk.nk_at(c, 650.0)


def test_compare_reflectance_with_exact_synthetic_rows():
    c = nk.combined_table(_synthetic())
    rs, rp = optics.reflectance(1.0, 2 + 3j, 45.0)
    rows = [
        dict(sample="r", instrument="x", source="r.dat", quantity="reflectance", value=v,
             sigma=1e-3, unit="1", wavelength_nm=w, theta_i_deg=45.0, theta_r_deg=45.0,
             phi_r_deg=180.0, channel=ch)
        for w in (450.0, 700.0) for ch, v in (("s", float(rs)), ("p", float(rp)))
    ]  # fmt: skip
    spectro = dict(
        sample="r", instrument="y", source="sp.csv", quantity="reflectance", value=10 / 18,
        sigma=np.nan, unit="1", wavelength_nm=500.0, theta_i_deg=np.nan,
        theta_r_deg=np.nan, phi_r_deg=np.nan, channel=None,
    )  # fmt: skip
    cmp = nk.compare_reflectance(c, pd.DataFrame(rows + [spectro]))
    assert cmp.attrs["outside_range"] == 2 and len(cmp) == 3
    np.testing.assert_allclose(cmp["difference"], 0.0, atol=1e-12)
    assert (cmp["predicted_sigma"] > 0).all()
    sp = cmp[cmp["source"] == "sp.csv"].iloc[0]
    assert sp["theta_i_deg"] == 0.0 and sp["difference_sigma"] == sp["predicted_sigma"]


def test_microfacet_albedo_tends_to_fresnel_for_a_smooth_surface():
    rho, sig = nk.microfacet_hemispherical(2.0, 3.0, 0.01, 30.0, n_sigma=0.01, k_sigma=0.01)
    fr = ell.fresnel_reflectances(2.0, 3.0, 30.0, n_sigma=0.01, k_sigma=0.01)
    assert rho == pytest.approx(fr.r, abs=2e-3)
    assert sig == pytest.approx(fr.r_sigma, rel=0.05)


# --------------------------------------------------------------------------------------
# real exports
# --------------------------------------------------------------------------------------


def _combined_real(real_exports, name):
    m = labbrdf.read(real_exports / "woollam-wvase-ascii" / name)
    return nk.combined_table(m)


def test_ta_metal_is_consistent_across_angles(real_exports):
    c = _combined_real(real_exports, "w2_10102006.dat")
    assert (c["n_angles"] == 3).all() and (c["method"] == "sigma").all()
    ratio = float((c["chi2"] / c["dof"]).median())
    flagged = float(c["angle_dependent"].mean())
    pooled = float(c["chi2"].sum() / c["dof"].sum())
    print(f"Ta: median chi2/dof {ratio:.2f}, pooled {pooled:.2f}, flagged {flagged:.1%}")
    assert ratio < 2.0 and flagged < 0.2


@pytest.mark.parametrize("name", ["wafer_2_01242007.dat", "w1_al2o3_20081120_anisotropy.dat"])
def test_oxide_covered_samples_are_angle_dependent(real_exports, name):
    c = _combined_real(real_exports, name)
    flagged = float(c["angle_dependent"].mean())
    print(f"{name}: median chi2/dof {(c['chi2'] / c['dof']).median():.3g}, flagged {flagged:.1%}")
    assert flagged > 0.9


def test_real_ta_json_round_trip(real_exports):
    m = labbrdf.read(real_exports / "woollam-wvase-ascii" / "w2_10102006.dat")
    out = json.loads(json.dumps(nk.nk_json(m), allow_nan=False))
    assert len(out["n"]) == 2028 and len(out["combined"]["n"]) == 676


def test_measurement_input_and_unpaired_rows():
    df = _synthetic()
    df = df.drop(index=df.index[-1])  # the last delta: its psi has no partner
    t = nk.nk_table(Measurement(df, {}))
    assert len(t) == 8 and t.attrs["unpaired"] == 1


# --------------------------------------------------------------------------------------
# a film: pseudo-constants of a stack are reported as such
# --------------------------------------------------------------------------------------


def _film_rows(wl=(400.0, 500.0, 600.0, 700.0), theta=(60.0, 65.0, 70.0, 75.0), sig=0.01):
    """psi/Delta of 100 nm of n = 2.1 on n = 3.9 + 0.02i (exact, Airy), sigma ``sig``."""
    rows = []
    for w in wl:
        for t in theta:
            rs, rp = onefilm.film_amplitudes(1.0, 2.1, 3.9 + 0.02j, 100.0, w, t)
            rho = complex(rp / rs)
            psi = float(np.degrees(np.arctan(abs(rho))))
            delta = -float(np.degrees(np.angle(rho))) % 360.0  # Nebraska, as optics
            for q, v in (("psi", psi), ("delta", delta)):
                rows.append(
                    dict(sample="film", instrument="x", source="film.dat", quantity=q,
                         value=v, sigma=sig, unit="deg", wavelength_nm=w, theta_i_deg=t,
                         theta_r_deg=t, phi_r_deg=180.0)
                )  # fmt: skip
    return pd.DataFrame(rows)


def test_film_pseudo_constants_are_not_combined():
    c = nk.combined_table(_film_rows())
    assert c["angle_dependent"].all() and not c["combined"].any()
    assert c[["n", "k", "n_sigma", "k_sigma", "nk_cov"]].isna().all().all()
    # the per-wavelength statistics stay: chi2/dof far above 1
    assert (c["chi2"] / c["dof"] > 100).all()
    v = nk.angle_verdict(c)
    assert v.kind == "stack" and v.fraction == 1.0 and "pseudo-constants of a stack" in v.text
    out = nk.nk_json(_film_rows())
    assert out["combined"]["n"] == [None] * 4 and len(out["n"]) == 16  # per angle: kept


def test_bulk_sample_is_combined_and_judged_bulk():
    c = nk.combined_table(_synthetic())
    assert c["combined"].all() and nk.angle_verdict(c).kind == "bulk"


def test_chance_agreement_in_a_stack_is_not_given():
    # one wavelength where the film's angles agree (one angle only there) among many
    # where they disagree: the group is a stack, so that wavelength gets no n, k either
    rows = pd.concat(
        [_film_rows(), _synthetic(wl=(800.0,), theta=(65.0, 70.0)).assign(
            sample="film", source="film.dat")],
        ignore_index=True,
    )  # fmt: skip
    c = nk.combined_table(rows)
    at800 = c[c["wavelength_nm"] == 800.0].iloc[0]
    assert not at800["angle_dependent"] and not at800["combined"] and np.isnan(at800["n"])


def _partly():
    """A film's psi/Delta at 400 nm, a bulk material's at 500-700 nm, in one file."""
    return pd.concat(
        [_film_rows(wl=(400.0,)), _synthetic(wl=(500.0, 600.0, 700.0)).assign(
            sample="film", source="film.dat")],
        ignore_index=True,
    )  # fmt: skip


def test_partly_angle_dependent_sample_carries_the_scatter_in_its_sigmas():
    plain = nk.combined_table(_synthetic(wl=(500.0, 600.0, 700.0)))  # the bulk part alone
    c = nk.combined_table(_partly())
    v = nk.angle_verdict(c)
    assert v.kind == "partly" and v.fraction == pytest.approx(0.25)
    assert c["combined"].all()
    birge = float(np.sqrt(c["chi2"].iloc[0] / c["dof"].iloc[0]))
    assert birge > 10 and c["sigma_scale"].tolist() == pytest.approx([birge, 1, 1, 1])
    # the film's wavelength: the same mean, sigmas times the Birge ratio
    t = nk.nk_table(_partly())
    g = t[t["wavelength_nm"] == 400.0]
    cov = np.stack([np.stack([g["n_sigma"] ** 2, g["nk_cov"]], -1),
                    np.stack([g["nk_cov"], g["k_sigma"] ** 2], -1)], -2)  # fmt: skip
    raw = ell.combine_angles(g["n"], g["k"], g["theta_i_deg"], cov)
    assert c["n"].iloc[0] == pytest.approx(raw.n, rel=1e-12)
    assert c["n_sigma"].iloc[0] == pytest.approx(raw.n_sigma * birge, rel=1e-12)
    assert c["nk_cov"].iloc[0] == pytest.approx(raw.nk_cov * birge**2, rel=1e-12)
    np.testing.assert_allclose(c["n_sigma"].iloc[1:], plain["n_sigma"], rtol=1e-12)
    at = nk.nk_at(c, [550.0, 650.0])
    np.testing.assert_allclose(at["n"], 2.0, rtol=1e-12)


def test_angle_verdict_untested_with_one_angle():
    c = nk.combined_table(_synthetic(theta=(70.0,)))
    v = nk.angle_verdict(c)
    assert v.kind == "untested" and "one angle" in v.text and c["combined"].all()


def _refl_rows(wl, theta=65.0):
    rs, rp = optics.reflectance(1.0, 2 + 3j, theta)
    return pd.DataFrame(
        [
            dict(sample="film", instrument="x", source="r.dat", quantity="reflectance",
                 value=float(v), sigma=1e-3, unit="1", wavelength_nm=w, theta_i_deg=theta,
                 theta_r_deg=theta, phi_r_deg=180.0, channel=ch)
            for w in wl for ch, v in (("s", rs), ("p", rp))
        ]
    )  # fmt: skip


def test_compare_reflectance_refuses_a_stack():
    c = nk.combined_table(_film_rows())
    with pytest.raises(ValueError, match="pseudo-constants of a stack.*does not apply"):
        nk.compare_reflectance(c, _refl_rows([450.0, 550.0]))


def test_nk_at_refuses_a_stack_and_can_return_nan():
    c = nk.combined_table(_film_rows())
    with pytest.raises(ValueError, match=r"at 450 nm no n, k.*pseudo-constants of a stack"):
        nk.nk_at(c, 450.0)
    assert np.isnan(nk.nk_at(c, [450.0, 500.0], on_angle_dependent="nan")["n"]).all()


def test_oxide_coated_wafer_gives_no_constants(real_exports):
    m = labbrdf.read(real_exports / "woollam-wvase-ascii" / "w1_12082006.dat")
    c = nk.combined_table(m, on_ill_conditioned="ignore")
    assert nk.angle_verdict(c).kind == "stack"
    assert not c["combined"].any() and c["n"].isna().all()
    with pytest.raises(ValueError, match="pseudo-constants of a stack"):
        nk.nk_at(c, 500.0)
