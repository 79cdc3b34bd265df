"""``labbrdf fit`` on a BTDF file: a transmission form fits it, a reflection model says why."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from labbrdf.bsdf_geometry import scatter_to_angles
from labbrdf.cli import main
from labbrdf.writers.zemax import write_bsdf


@pytest.fixture
def btdf_file(tmp_path: Path) -> Path:
    """A noiseless ABg BTDF (A = 0.004, B = 2e-4, g = 1.6) on a small grid."""
    ti, rad, az = (
        np.array([0.0, 30.0]),
        np.array([0.0, 1, 3, 8, 20, 45, 70]),
        np.arange(0, 181, 45.0),
    )
    tr, pr, above = scatter_to_angles(ti[:, None, None], rad[None, None, :], az[None, :, None])
    st = np.sin(np.radians(tr))
    d = np.hypot(
        st * np.cos(np.radians(pr)) + np.sin(np.radians(ti))[:, None, None],
        st * np.sin(np.radians(pr)),
    )
    f = np.where(above, 0.004 / (2e-4 + d**1.6), 0.0)
    return write_bsdf(
        tmp_path / "btdf.bsdf",
        theta_i_deg=ti,
        radial_deg=rad,
        azimuth_deg=az,
        values=f[None, None],
        symmetry="PlaneSymmetrical",
        scatter_type="BTDF",
        digits=12,
    )


def test_transmission_form_fits_a_btdf_file(btdf_file: Path, capsys) -> None:
    argv = ["fit", str(btdf_file), "--model", "abg", "--param", "transmission=true", "--json"]
    assert main(argv) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["params"]["g"]["value"] == pytest.approx(1.6, rel=1e-4)
    assert row["params"]["B"]["value"] == pytest.approx(2e-4, rel=1e-3)


def test_reflection_model_on_a_btdf_file_says_why(btdf_file: Path, capsys) -> None:
    assert (
        main(["fit", str(btdf_file), "--model", "microfacet", "--param", "ideal_mirror=true"]) != 0
    )
    err = capsys.readouterr().err
    assert "'microfacet' describes ['brdf', 'specular_intensity'], not 'btdf' data" in err
    assert "Traceback" not in err
