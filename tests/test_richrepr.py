"""What datasets, fits and traces show of themselves in a notebook."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import pytest

import labbrdf
from labbrdf import Substrate, TraceConfig
from labbrdf.dataset import DatasetError


def test_a_measurement_shows_its_summary_and_first_rows(fixtures_dir) -> None:
    m = labbrdf.read(fixtures_dir / "ellipsometry" / "al_bare_wvase.dat")
    page = m._repr_html_()
    assert "labbrdf Measurement" in page and "psi, delta" in page and "<table" in page
    assert "65, 70, 75" in page


def test_a_sample_name_is_escaped_not_rendered(fixtures_dir) -> None:
    m = labbrdf.read(fixtures_dir / "specular" / "osr_specular.csv")
    data = m.data.copy()
    data["sample"] = "<script>x</script>"
    page = labbrdf.Measurement(data, m.meta)._repr_html_()
    assert "<script>" not in page and "&lt;script&gt;" in page


def test_a_measurement_plots_one_line_per_angle(fixtures_dir) -> None:
    m = labbrdf.read(fixtures_dir / "ellipsometry" / "al_bare_wvase.dat")
    ax = m.plot("psi")
    assert len(ax.lines) == 3 and ax.get_xlabel() == "wavelength [nm]"
    with pytest.raises(DatasetError, match="not in this measurement"):
        m.plot("brdf")


def test_a_trace_shows_what_was_traced_and_its_albedo() -> None:
    r = labbrdf.trace(
        TraceConfig(
            wavelength_nm=650,
            theta_i_deg=45,
            rays=2000,
            seed=1,
            substrate=Substrate(n=1.55, k=7.71, alpha=0.2),
            scattering="single",
            estimator="counting",
        )
    )
    page = r._repr_html_()
    assert "labbrdf TraceResult" in page and "albedo" in page and "counting" in page
    assert f"{r.albedo():.6g}" in page


def test_a_fit_shows_its_parameters(fixtures_dir) -> None:
    scan = labbrdf.read(fixtures_dir / "specular" / "osr_specular.csv")
    res = labbrdf.fit("smooth3", scan.data[scan.data.wavelength_nm == 550])
    page = res._repr_html_()
    assert "k1" in page and "k3" in page
