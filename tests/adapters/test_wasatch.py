"""Wasatch ENLIGHTEN column-ordered CSV: the real %T file and synthetic variants."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff
from labbrdf.adapters.wasatch import read_enlighten

REAL = "wasatch-enlighten/wasatch-enlighten-transmission.csv"


def test_real_transmission_file_is_read_as_fraction(real_exports: Path) -> None:
    p = real_exports / REAL
    assert sniff(p) == ["wasatch-enlighten"]
    m = labbrdf.read(p)
    d = m.data
    assert len(d) == 1024 and set(d["quantity"]) == {"transmittance"}
    # Processed is %T: 24.0 at 247.94 nm, 3.65099 at 550.17 nm, 104.1078 at 709.67 nm
    at = dict(zip(d["wavelength_nm"], d["value"], strict=True))
    assert at[247.94] == pytest.approx(0.24, rel=1e-12)
    assert at[550.17] == pytest.approx(0.0365099, rel=1e-12)
    assert at[709.67] == pytest.approx(1.041078, rel=1e-12)
    assert m.meta["technique"] == "Transmission" and m.meta["percent"] is True


def _enlighten(technique: str, rows: str, *, pixels: int = 3, columns: str | None = None) -> str:
    head = (
        "ENLIGHTEN Version,4.1.6\nSerial Number,WP-01234\nLabel,leaf 7\n"
        f"Technique,{technique}\nInterpolated,False\nPixel Count,{pixels}\n\n"
    )
    return (
        head
        + (columns or "Pixel,Wavelength,Wavenumber,Processed,Raw,Dark,Reference")
        + "\n"
        + rows
    )


ROWS = "0,400.00,NA,0.50000,1,1,1\n1,401.00,NA,0.25000,1,1,1\n2,402.00,NA,NA,1,1,1\n"


def test_absorbance_is_read_as_is_and_na_points_dropped(tmp_path: Path) -> None:
    p = tmp_path / "abs.csv"
    p.write_text(_enlighten("Absorbance", ROWS))
    m = labbrdf.read(p)
    d = m.data
    assert d["quantity"].tolist() == ["absorbance", "absorbance"]
    assert d["value"].tolist() == [0.5, 0.25] and set(d["sample"]) == {"leaf 7"}
    assert m.meta["dropped_points"] == 1


def test_reflectance_percent_is_divided_and_minimal_columns_suffice(tmp_path: Path) -> None:
    p = tmp_path / "r.csv"
    p.write_text(_enlighten("Reflectance", "500.5,42.0\n501.5,43.0\n", pixels=2,
                            columns="Wavelength,Processed"))  # fmt: skip
    assert read_enlighten(p).data["value"].tolist() == pytest.approx([0.42, 0.43])


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (_enlighten("Scope", ROWS), r"line 4: Technique 'Scope' has no labbrdf quantity"),
        (_enlighten("Raman", ROWS), r"Technique 'Raman' has no labbrdf quantity"),
        (_enlighten("Relative Irradiance", ROWS), r"'Relative Irradiance' has no labbrdf"),
        (_enlighten("Absorbance", ROWS, pixels=4), r"line 6: Pixel Count is 4 but the file has 3"),
        (_enlighten("Absorbance", "0,400,1\n", columns="Pixel,Wavenumber,Processed", pixels=1),
         r"no Wavelength column"),
        (_enlighten("Absorbance", "0,400.00,NA,0.5,1\n", pixels=1), r"line 9: expected 7 comma"),
        (_enlighten("Absorbance", ROWS.replace("401.00", "399.00")), r"399 nm does not increase"),
        ("Dash Output v2.1,ENLIGHTEN version: 1.6.2,Row,Pixel Data,WP-00591\n1,2\n",
         r"row-ordered \(Dash\) CSV.*save the spectrum as column-ordered CSV"),
    ],
)  # fmt: skip
def test_what_cannot_be_read_is_refused_by_name(tmp_path: Path, text: str, match: str) -> None:
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(AdapterError, match=match) as info:
        labbrdf.read(p)
    assert str(p) in str(info.value)


def test_truncated_real_file_is_refused(real_exports: Path, tmp_path: Path) -> None:
    raw = (real_exports / REAL).read_bytes()
    p = tmp_path / "cut.csv"
    cut = raw.rfind(b"\n", 0, len(raw) - 1) + 1  # the last row gone, line ends intact
    p.write_bytes(raw[:cut])
    with pytest.raises(AdapterError, match="Pixel Count is 1024 but the file has 1023"):
        read_enlighten(p)
    assert np.isfinite(read_enlighten(real_exports / REAL).data["value"]).all()
