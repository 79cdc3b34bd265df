"""The rayleigh_rice BRDF model: registry, options, and recovery of a K-correlation PSD."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from labbrdf import adapters, models
from labbrdf.adapters.zemax_bsdf import WAVELENGTH_COMMENT
from labbrdf.bsdf_geometry import scatter_to_angles
from labbrdf.cli import main
from labbrdf.fitting import fit
from labbrdf.roughness import rayleigh_rice as rr
from labbrdf.writers.zemax import write_bsdf

TRUE = {"A": 3e-4, "B": 12.0, "C": 1.6}
WL_NM = 633.0
AL = {"n": 1.55, "k": 7.71}


@pytest.fixture(scope="module")
def noisy_bsdf(tmp_path_factory):
    """A .bsdf of known K-correlation parameters on Al with 2 % Gaussian noise (seeded).

    Radial angles 0.5 to 60 deg see spatial frequencies ~1e4 to 2.5e6 cycles/m, both
    sides of the knee 1/B ~ 8e4 and the power-law slope: A, B and C are all identified.
    """
    m = models.get("rayleigh_rice", **AL)
    ti = np.array([20.0, 50.0])
    rad = np.array([0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 60.0])
    az = np.array([0.0, 45.0, 90.0, 135.0, 180.0])
    tr, pr, above = scatter_to_angles(ti[:, None, None], rad[None, None, :], az[None, :, None])
    f = m.evaluate(
        np.radians(np.broadcast_to(ti[:, None, None], tr.shape)),
        np.radians(np.where(above, tr, 0.0)),
        np.radians(pr),
        wavelength=WL_NM,
        params=TRUE,
    )
    rng = np.random.default_rng(29)
    vals = np.where(above, f * (1.0 + 0.02 * rng.standard_normal(f.shape)), 0.0)
    path = tmp_path_factory.mktemp("rr") / "kcorr.bsdf"
    return write_bsdf(
        path,
        theta_i_deg=ti,
        radial_deg=rad,
        azimuth_deg=az,
        values=vals[None, None],
        symmetry="PlaneSymmetrical",
        comments=[f"{WAVELENGTH_COMMENT}{WL_NM:g}"],
        digits=8,
    )


def test_registry_and_evaluate_matches_physics():
    m = models.get("rayleigh_rice", **AL, wavelength_nm=WL_NM)
    assert "rayleigh_rice" in models.names()
    ti, tr, pr = 0.3, np.array([0.1, 0.5, 1.2]), np.array([0.0, 2.0, math.pi])
    got = m.evaluate(ti, tr, pr, params=TRUE)
    want = rr.brdf(ti, tr, pr, WL_NM * 1e-9, complex(1.55, 7.71), m.psd2d(TRUE))
    np.testing.assert_allclose(got, want, rtol=1e-14)
    mm = m.mueller(ti, tr, pr, params=TRUE)
    np.testing.assert_allclose(mm[..., 0, 0], want, rtol=1e-12)
    assert m.is_reciprocal()


def test_gaussian_psd_integrates_to_sigma_squared():
    m = models.get("rayleigh_rice", **AL, psd="gaussian")
    psd = m.psd2d({"sigma": 2e-3, "corr_length": 4.0})
    f = np.linspace(0.0, 3.0 / (math.pi * 4e-6), 20001)
    s2 = np.trapezoid(2 * math.pi * f * psd(f, 0.0 * f), f)
    assert s2 == pytest.approx((2e-9) ** 2, rel=1e-6)


@pytest.mark.parametrize(
    "opts, match",
    [
        ({}, "substrate index"),
        ({**AL, "psd": "lorentz"}, "psd"),
        ({**AL, "polarization": "x"}, "polarization"),
        ({"n": -1.0}, "n, k"),
        ({**AL, "wavelength_nm": -5.0}, "wavelength_nm"),
        ({**AL, "colour": 1}, "unknown options"),
    ],
)
def test_bad_options(opts, match):
    with pytest.raises(models.ModelError, match=match):
        models.get("rayleigh_rice", **opts)


def test_no_wavelength_is_an_error():
    m = models.get("rayleigh_rice", **AL)
    with pytest.raises(models.ModelError, match="wavelength_nm"):
        m.evaluate(0.1, 0.2, 0.0)


def test_recovery_of_k_correlation_within_three_standard_errors(noisy_bsdf):
    data = adapters.read(noisy_bsdf)
    assert np.allclose(data.data["wavelength_nm"], WL_NM)
    res = fit(models.get("rayleigh_rice", **AL), data, mask_zeros=True, weighting="relative")
    assert res.success
    for name, true in TRUE.items():
        p = res.params[name]
        assert p.stderr is not None and p.stderr > 0
        assert abs(p.value - true) <= 3 * p.stderr, (name, p.value, p.stderr, true)
    # the noise is 2 %: the relative-weighted residual says so
    assert 0.01 < math.sqrt(res.redchi) < 0.03


def test_cli_fit_with_index_options(noisy_bsdf, capsys):
    argv = ["fit", str(noisy_bsdf), "--model", "rayleigh_rice", "--param", "n=1.55"]
    argv += ["--param", "k=7.71", "--json"]
    assert main(argv) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["success"]
    assert abs(row["params"]["C"]["value"] - TRUE["C"]) <= 3 * row["params"]["C"]["stderr"]


def test_cli_without_an_index_is_a_usage_error(noisy_bsdf, capsys):
    assert main(["fit", str(noisy_bsdf), "--model", "rayleigh_rice"]) == 2
    err = capsys.readouterr().err
    assert "substrate index" in err and "Traceback" not in err


@pytest.mark.shared
def test_cli_fit_of_a_real_bsdf_with_the_index_of_a_real_ellipsometer_file(real_exports, capsys):
    """End to end on real files: the Radiant vinyl .bsdf (no wavelength stated: 555 nm is
    said) with the Ta n, k of a WVASE file. The vinyl is rough, so only that it runs and
    takes the ellipsometer's index is checked, not the PSD."""
    bsdf = real_exports / "zemax-bsdf" / "test_13_planesymmetric_brdf_zemax.bsdf"
    psi = real_exports / "woollam-wvase-ascii" / "w2_10102006.dat"
    argv = ["fit", str(bsdf), "--model", "rayleigh_rice", "--nk-from", str(psi)]
    argv += ["--wavelength", "555", "--theta-i-range", "45", "--json"]
    assert main(argv) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["success"] and set(row["params"]) == {"A", "B", "C"}


def test_free_index_adds_the_substrate_parameters(noisy_bsdf):
    fixed = models.get("rayleigh_rice", **AL, wavelength_nm=WL_NM)
    free = models.get("rayleigh_rice", **AL, wavelength_nm=WL_NM, free_index=True)
    assert set(free.params) == {"A", "B", "C", "n_sub", "k_sub"}
    ti, tr, pr = 0.4, np.array([0.2, 0.9]), np.array([0.5, math.pi])
    np.testing.assert_array_equal(
        free.evaluate(ti, tr, pr, params=TRUE), fixed.evaluate(ti, tr, pr, params=TRUE)
    )
    other = free.evaluate(ti, tr, pr, params={**TRUE, "n_sub": 1.5, "k_sub": 0.0})
    assert not np.allclose(other, fixed.evaluate(ti, tr, pr, params=TRUE))
    res = fit(free, adapters.read(noisy_bsdf), mask_zeros=True, weighting="relative")
    assert res.success and {"n_sub", "k_sub"} <= set(res.params)
