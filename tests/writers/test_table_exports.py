"""Speos, ASTM and pgII exports: a model written and read back by the readers."""

from __future__ import annotations

import numpy as np
import pytest

import labbrdf
from labbrdf import models
from labbrdf.adapters.speos_bsdf import read_speos_table
from labbrdf.outputs import OutputError, write_policy
from labbrdf.writers.speos import model_to_speos, write_speos_bsdf


def test_model_written_as_speos_reads_back_to_the_model(tmp_path):
    model = models.get("five_param")
    ti = np.array([20.0, 50.0])
    p = model_to_speos(
        model, None, tmp_path / "m.anisotropicbsdf", theta_i_deg=ti, wavelength_nm=633.0
    )
    m = labbrdf.read(p)
    assert m.meta["format"] == "speos-bsdf"
    assert set(m.data["wavelength_nm"]) == {633.0}
    d = m.data
    # the model at the angles the reader reports: the writer's phi = phi_r - 180 and the
    # reader's phi_r = phi + 180 must be inverse, and the spectrum scale must cancel
    want = model.evaluate(
        np.radians(d.theta_i_deg), np.radians(d.theta_r_deg), np.radians(d.phi_r_deg)
    )
    np.testing.assert_allclose(d.value, want, rtol=1e-12)
    # the spectrum is the first table's hemispherical reflectance; against the model's own
    # integral: trapezoid on 1 x 5 deg steps, second order (h^2/12 of the curvature)
    t = read_speos_table(p)
    rho = labbrdf.integrate.hemispherical_reflectance(model, None, ti[:1])
    np.testing.assert_allclose(t.coefficient_pct[0] / 100, rho, rtol=0.02)


def test_speos_writer_refuses_bad_grids_and_existing_files(tmp_path):
    kw = dict(theta_i_deg=[10.0], theta_deg=[0.0, 45.0, 90.0], phi_deg=[0.0, 180.0, 360.0])
    good = np.full((1, 3, 3), 0.1)
    p = write_speos_bsdf(tmp_path / "a.anisotropicbsdf", values=good, **kw)
    with write_policy(overwrite=False), pytest.raises(OutputError, match="exists"):
        write_speos_bsdf(p, values=good, **kw)
    with pytest.raises(ValueError, match="shape"):
        write_speos_bsdf(tmp_path / "b.anisotropicbsdf", values=good[:, :2], **kw)
    with pytest.raises(ValueError, match="theta_deg"):
        write_speos_bsdf(
            tmp_path / "b.anisotropicbsdf", values=good, **dict(kw, theta_deg=[0, 95, 96])
        )
    with pytest.raises(ValueError, match="reflectance in"):
        write_speos_bsdf(tmp_path / "b.anisotropicbsdf", values=good * 100, **kw)
    assert not (tmp_path / "b.anisotropicbsdf").exists()


def test_cli_exports_a_model_as_speos_and_it_reads_back(tmp_path, capsys):
    from labbrdf.cli import main

    out = tmp_path / "m.anisotropicbsdf"
    argv = ["export", "--format", "speos-bsdf", "--model", "five_param", "--theta-i", "30",
            "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    assert main(argv) == 2  # never over an existing file without --overwrite
    assert "exists" in capsys.readouterr().err
    d = labbrdf.read(out).data
    model = models.get("five_param")
    want = model.evaluate(
        np.radians(d.theta_i_deg), np.radians(d.theta_r_deg), np.radians(d.phi_r_deg)
    )
    np.testing.assert_allclose(d.value, want, rtol=1e-12)
    trace = ["export", "--format", "astm-brdf", "--trace", str(out), "-o",
             str(tmp_path / "t.astm")]  # fmt: skip
    assert main(trace) == 2
    assert "zemax-bsdf or speos-bsdf" in capsys.readouterr().err


def test_binned_brdf_written_as_speos_reads_back_bin_by_bin(tmp_path):
    from labbrdf.writers.speos import binned_to_speos

    te = np.linspace(0.0, 90.0, 19)  # 5-deg bins
    pe = np.linspace(0.0, 360.0, 37)  # 10-deg bins, source at 0
    tc, pc = 0.5 * (te[1:] + te[:-1]), 0.5 * (pe[1:] + pe[:-1])
    # a lobe towards the specular side (phi_r 180) that tells the azimuth origin apart
    v = 0.05 + 0.2 * np.cos(np.radians(tc))[:, None] * (1 - np.cos(np.radians(pc)))[None]
    p = binned_to_speos(tmp_path / "t.anisotropicbsdf", theta_i_deg=40.0, values=v,
                        theta_edges_deg=te, phi_edges_deg=pe)  # fmt: skip
    d = labbrdf.read(p).data
    assert len(d) == v.size
    i = np.searchsorted(te, d["theta_r_deg"]) - 1
    j = np.searchsorted(pe, d["phi_r_deg"]) - 1
    np.testing.assert_allclose(d["value"], v[i, j], rtol=1e-12)


def test_model_written_as_astm_reads_back_to_the_model(tmp_path):
    from labbrdf.writers.astm import model_to_astm

    model = models.get("five_param")
    p = model_to_astm(
        model, None, tmp_path / "m.astm", theta_i_deg=[20.0, 60.0], wavelength_nm=633.0
    )
    m = labbrdf.read(p)
    assert m.meta["format"] == "astm-brdf" and set(m.data["wavelength_nm"]) == {633.0}
    d = m.data
    assert len(d) == 2 * 90 * 2
    want = model.evaluate(
        np.radians(d.theta_i_deg), np.radians(d.theta_r_deg), np.radians(d.phi_r_deg)
    )
    np.testing.assert_allclose(d.value, want, rtol=1e-12)
    with write_policy(overwrite=False), pytest.raises(OutputError):
        model_to_astm(model, None, p, theta_i_deg=[20.0], wavelength_nm=633.0)


def test_cli_exports_an_astm_table_and_needs_its_wavelength(tmp_path, capsys):
    from labbrdf.cli import main

    out = tmp_path / "m.astm"
    base = ["export", "--format", "astm-brdf", "--model", "five_param", "--theta-i", "30",
            "-o", str(out)]  # fmt: skip
    assert main(base) == 2
    assert "needs --wavelength" in capsys.readouterr().err
    assert main([*base, "--wavelength", "550"]) == 0
    assert labbrdf.read(out).meta["format"] == "astm-brdf"


def test_model_written_as_pgii_reads_back_to_the_model(tmp_path):
    from labbrdf.writers.pgii import model_to_pgii

    model = models.get("five_param")
    p = model_to_pgii(model, None, tmp_path / "f40_Rvis.txt", theta_i_deg=40.0)
    m = labbrdf.read(p)
    assert m.meta["format"] == "pab-pgii" and len(m) == 90 * 72
    d = m.data
    want = model.evaluate(
        np.radians(d.theta_i_deg), np.radians(d.theta_r_deg), np.radians(d.phi_r_deg)
    )
    np.testing.assert_allclose(d.value, want, rtol=1e-12)
