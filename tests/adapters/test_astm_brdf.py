"""ASTM E1392-style BRDF tables, written in the tests from the layout libbsdf's reader takes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff

D = np.pi / 180.0


def _table(
    rows: list[tuple[float, ...]], vars_: str = "450nm,550nm", count: int | None = None
) -> str:
    head = 'NAME "in-plane paint"\n'
    if count is not None:
        head += f"NUM_POINTS {count}\n"
    head += f"VARS theta_i,phi_i,theta_s,phi_s,{vars_}\n"
    return head + "".join(",".join(f"{v:.9g}" for v in r) + "\n" for r in rows)


ROWS = [
    (30 * D, 0.0, 30 * D, 180 * D, 0.9, 1.1),  # specular
    (30 * D, 0.0, 10 * D, 0.0, 0.2, 0.25),  # towards the source
    (30 * D, 0.0, 60 * D, 180 * D, 0.3, 0.35),
]


def test_in_plane_spectral_table_reads_per_wavelength(tmp_path: Path) -> None:
    p = tmp_path / "paint.astm"
    p.write_text(_table(ROWS, count=3))
    assert sniff(p) == ["astm-brdf"]
    m = labbrdf.read(p)
    d = m.data
    assert m.meta["wavelength_stated"] is True
    assert list(d["wavelength_nm"]) == [450.0, 550.0] * 3
    np.testing.assert_allclose(d["theta_i_deg"], 30.0)
    np.testing.assert_allclose(d["theta_r_deg"], [30, 30, 10, 10, 60, 60], rtol=1e-8)
    np.testing.assert_allclose(d["phi_r_deg"], [180, 180, 0, 0, 180, 180], atol=1e-6)
    np.testing.assert_allclose(d["value"], [0.9, 1.1, 0.2, 0.25, 0.3, 0.35])


def test_incident_azimuth_is_taken_out(tmp_path: Path) -> None:
    rows = [(20 * D, 90 * D, 20 * D, 270 * D, 1.0)]
    p = tmp_path / "rot.astm"
    p.write_text(_table(rows, vars_="Y"))
    m = labbrdf.read(p)
    assert m.data["phi_r_deg"].iloc[0] == pytest.approx(180.0)
    assert m.meta["wavelength_stated"] is False


def test_xyz_columns_are_channels(tmp_path: Path) -> None:
    p = tmp_path / "xyz.astm"
    p.write_text(_table([(0.1, 0.0, 0.2, 3.0, 1.0, 2.0, 3.0)], vars_="X,Y,Z"))
    assert list(labbrdf.read(p).data["channel"]) == ["X", "Y", "Z"]


@pytest.mark.parametrize(
    ("text", "match", "line"),
    [
        (_table(ROWS, vars_="R,G,B").replace(",0.9,1.1", ",0.9,1.1,1"), "R,G,B", 2),
        (_table(ROWS, count=4), "NUM_POINTS '4': the file has 3", 2),
        (_table(ROWS).replace(",0.2,0.25", ",0.2"), "expected 6 comma-separated", 4),
        (_table(ROWS).replace(",0.2,0.25", ",0.2,x"), "column 6: expected a number", 4),
        (_table([(30.0, 0.0, 30.0, 180.0, 1.0, 1.0)]), "above 2 pi", 3),
        (_table([(0.5, 0.0, 1.7, 0.0, 1.0, 1.0)]), "theta_s in", 3),
        ("NAME x\n1,2,3\n", "missing the 'VARS", None),
        (_table(ROWS, vars_="450nm,green"), "expected a wavelength", 2),
        (_table([]), "no data rows", None),
    ],
)
def test_bad_astm_tables_name_the_file_and_line(
    tmp_path: Path, text: str, match: str, line: int | None
) -> None:
    p = tmp_path / "bad.astm"
    p.write_text(text)
    with pytest.raises(AdapterError, match=match) as exc:
        labbrdf.read(p, format="astm-brdf")
    assert exc.value.path == str(p)
    if line is not None:
        assert exc.value.line == line
