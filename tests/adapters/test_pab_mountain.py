"""pab-opto pgII gonio-photometer ASCII (Mountain) files, built from the format's public
description (the pabopto2bsdf manual's minimal example and its header entries)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff

#: the manual's minimal file: incident (82.5, 180), DSF values
MINIMAL = (
    "#incident_angle 82.5 180\n#format: theta phi DSF\n"
    "84.968\t125.790\t0.009744\n84.889\t125.610\t0.007737\n84.805\t125.427\t0.008569\n"
)


def _write(tmp_path: Path, text: str, name: str = "f30_Rvis.txt") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_minimal_dsf_file_reads_as_brdf_with_the_cosine_taken_out(tmp_path: Path) -> None:
    p = _write(tmp_path, MINIMAL)
    assert sniff(p) == ["pab-pgii"]
    m = labbrdf.read(p)
    d = m.data
    assert m.meta["format"] == "pab-pgii" and m.meta["value_kind"] == "dsf"
    assert set(d["quantity"]) == {"brdf"} and set(d["theta_i_deg"]) == {82.5}
    # DSF = BSDF |cos theta|: BSDF = 0.009744 / cos(84.968 deg)
    assert d["value"].iloc[0] == pytest.approx(0.009744 / np.cos(np.radians(84.968)), rel=1e-12)
    # the source's azimuth (inphi 180) is the dataset's phi_r 0
    np.testing.assert_allclose(d["phi_r_deg"], np.array([125.790, 125.610, 125.427]) + 180.0)
    assert m.meta["wavelength_stated"] is False


def test_full_header_bsdf_xyz_and_the_specular_direction(tmp_path: Path) -> None:
    # incident from (30, 45): the specular direction is (30, 225), phi_r 180
    text = (
        '#sample_name "white paint"\n#format: theta phi BSDF\n#intheta 30\n#inphi 45\n'
        "#upphi 0\n#colorimetry: CIE-XYZ\n"
        "30\t225\t1.0\t2.0\t3.0\n10\t45\t0.1\t0.2\t0.3\n"
    )
    d = labbrdf.read(_write(tmp_path, text)).data
    assert list(d["channel"]) == ["X", "Y", "Z"] * 2
    np.testing.assert_allclose(d["phi_r_deg"], [180.0] * 3 + [0.0] * 3)
    np.testing.assert_allclose(d["value"], [1.0, 2.0, 3.0, 0.1, 0.2, 0.3])


def test_back_side_directions_are_btdf_from_the_back_normal(tmp_path: Path) -> None:
    text = "#format: theta phi BTDF\n#incident_angle 20 0\n160\t180\t0.5\n180\t0\t0.7\n"
    d = labbrdf.read(_write(tmp_path, text, "f20_Tvis.txt")).data
    assert set(d["quantity"]) == {"btdf"}
    np.testing.assert_allclose(d["theta_r_deg"], [20.0, 0.0])


def test_dsf_at_grazing_exit_is_dropped_and_counted(tmp_path: Path) -> None:
    text = "#format: theta phi DSF\n#intheta 10\n90\t0\t0.01\n45\t0\t0.02\n"
    m = labbrdf.read(_write(tmp_path, text))
    assert len(m) == 1 and m.meta["dropped_points"] == 1


@pytest.mark.parametrize(
    ("text", "match", "line"),
    [
        ("#format: theta phi XYZ\n#intheta 10\n1 2 3\n", "#format: expected", 1),
        ("#format: theta phi BSDF\n1 2 3\n", "missing the incident angle", None),
        ("#format: theta phi BSDF\n#intheta 10\n1 2 3\n4 5\n", "expected 3 values", 4),
        ("#format: theta phi BSDF\n#intheta 10\n1 2 x\n", "found the character", 3),
        ("#format: theta phi BSDF\n#intheta 10\n1 2 3\n#late\n", "before the data", 4),
        ("#format: theta phi BSDF\n#intheta 10\n10 0 1\n170 0 1\n", "mix front", 3),
        ("#format: theta phi BTDF\n#intheta 10\n10 0 1\n", "states BTDF", 3),
        ("#format: theta phi BSDF\n#intheta 95\n10 0 1\n", "front incidence", 2),
        ("#format: theta phi BSDF\n#intheta 10\n#colorimetry: RGB\n1 2 3\n", "colorimetry", 3),
        ("#format: theta phi BSDF\n#intheta 10\n", "no data lines", None),
        ("#format: theta phi BSDF\n#incident_angle 10\n1 2 3\n", "theta and phi", 2),
    ],
)
def test_bad_pgii_files_name_the_file_and_line(
    tmp_path: Path, text: str, match: str, line: int | None
) -> None:
    p = _write(tmp_path, text)
    with pytest.raises(AdapterError, match=match) as exc:
        labbrdf.read(p, format="pab-pgii")
    assert exc.value.path == str(p)
    if line is not None:
        assert exc.value.line == line
