"""Ocean Optics OceanView / SpectraSuite text exports."""

from __future__ import annotations

from pathlib import Path

import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff
from labbrdf.adapters.oceanoptics import read_oceanoptics
from labbrdf.cli import main

FOLDER = "oceanoptics-oceanview"
REAL = "ambient_0_40_Absorbance_10-54-38-373.txt"


def write(tmp: Path, name: str, data: str | bytes) -> Path:
    p = tmp / name
    p.write_bytes(data.encode() if isinstance(data, str) else data)
    return p


def oceanview(
    rows: str = "400.1\t0.5\n400.5\t0,25\n401.0\t-0\n",
    *,
    node: str = "Data from sample_Absorbance_10-00-00-000.txt Node",
    pixels: str = "3",
    xmode: str = "Wavelengths",
    tail: str = "",
) -> str:
    return (
        f"{node}\n\rDate: Fri Aug 25 10:54:38 EDT 2023\nUser: lab\nSpectrometer: FLMS00001\n"
        f"Integration Time (sec): 1.0E-3\nXAxis mode: {xmode}\n"
        f"Number of Pixels in Spectrum: {pixels}\n>>>>>Begin Spectral Data<<<<<\n{rows}{tail}"
    )


def test_real_file_reads_with_its_header(real_exports: Path) -> None:
    p = real_exports / FOLDER / REAL
    assert sniff(p) == ["oceanoptics-text"]
    m = labbrdf.read(p)
    d = m.data
    assert m.meta["format"] == "oceanoptics-text" and m.quantities == ["absorbance"]
    assert len(d) == 2048 == int(m.meta["header"]["Number of Pixels in Spectrum"])
    assert d["wavelength_nm"].iloc[0] == 179.23 and d["wavelength_nm"].iloc[-1] == 872.675
    assert d["value"].iloc[3] == -0.67432  # "180.373<TAB>-0.67432"
    assert m.meta["header"]["Spectrometer"] == "FLMS04918"
    assert m.meta["quantity_from"] == "the 'Data from' line"


def test_real_file_ingests_from_the_cli(real_exports: Path, capsys) -> None:
    assert main(["ingest", str(real_exports / FOLDER / REAL)]) == 0
    assert "oceanoptics-text" in capsys.readouterr().out


def test_synthetic_absorbance_with_decimal_comma(tmp_path: Path) -> None:
    m = labbrdf.read(write(tmp_path, "s.txt", oceanview()))
    assert m.meta["format"] == "oceanoptics-text"
    assert list(m.data["value"]) == [0.5, 0.25, 0.0]
    assert list(m.data["wavelength_nm"]) == [400.1, 400.5, 401.0]


@pytest.mark.parametrize(
    ("node", "name", "quantity"),
    [
        ("Data from x_Transmission_1.txt Node", "a.txt", "transmittance"),
        ("Data from x_Reflection_1.txt Node", "a.txt", "reflectance"),
        ("Data from x.txt Node", "run_Transmission_2.txt", "transmittance"),
    ],
)
def test_percent_modes_from_the_node_or_the_file_name(
    tmp_path: Path, node: str, name: str, quantity: str
) -> None:
    m = read_oceanoptics(
        write(tmp_path, name, oceanview("500\t50\n501\t25\n", node=node, pixels="2"))
    )
    assert m.quantities == [quantity]
    assert list(m.data["value"]) == [0.5, 0.25]
    assert m.meta["percent"] is True


def test_spectrasuite_processed_block_with_end_marker(tmp_path: Path) -> None:
    raw = (
        "SpectraSuite Data File\n++++++++++++++++++++++++++++++++++++\nDate: x\n"
        "Spectrometers: USB4000\nNumber of Pixels in Processed Spectrum: 2\n"
        ">>>>>Begin Processed Spectral Data<<<<<\n500.0\t1.5\n501.0\t1.25\n"
        ">>>>>End Processed Spectral Data<<<<<\n"
    )
    m = labbrdf.read(write(tmp_path, "film_Absorbance_0001.txt", raw))
    assert m.meta["format"] == "oceanoptics-text" and list(m.data["value"]) == [1.5, 1.25]


@pytest.mark.parametrize(
    ("kwargs", "name", "match"),
    [
        ({"node": "Data from x_Scope_1.txt Node"}, "a.txt", r"'Scope'.*no labbrdf quantity"),
        ({"node": "Data from x.txt Node"}, "a.txt", r"processing mode .* is named neither"),
        ({"pixels": "4"}, "s_Absorbance.txt", r"line 8: Number of Pixels in Spectrum is 4 but"),
        ({"xmode": "Pixels"}, "s_Absorbance.txt", r"line 7: XAxis mode 'Pixels': only Wavel"),
        ({"rows": "400\t1\n399\t2\n401\t3\n"}, "s.txt", r"line 11: wavelength 399 nm does not"),
        ({"rows": "400\t1\n401\tx\n402\t3\n"}, "s.txt", r"line 11: value: expected a number"),
        ({"rows": "400\t1\t2\n"}, "s.txt", r"line 10: expected 2 TAB-separated fields"),
        ({"rows": ""}, "s.txt", r"line 9: no data rows after the spectral data marker"),
        ({"tail": ">>>>>End Spectral Data<<<<<\nmore\n"}, "s.txt", r"line 14: text after the end"),
    ],
)
def test_errors_name_file_line_and_expectation(
    tmp_path: Path, kwargs: dict, name: str, match: str
) -> None:
    p = write(tmp_path, name, oceanview(**kwargs))
    with pytest.raises(AdapterError, match=match) as exc:
        read_oceanoptics(p)
    assert str(p) in str(exc.value)


def test_missing_marker_is_refused(tmp_path: Path) -> None:
    p = write(tmp_path, "s.txt", oceanview().replace(">>>>>Begin Spectral Data<<<<<", "data"))
    with pytest.raises(AdapterError, match=r"no '>>>>>Begin Spectral Data<<<<<' line"):
        read_oceanoptics(p)


def test_truncated_real_file_is_refused_by_the_pixel_count(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = (real_exports / FOLDER / REAL).read_bytes()
    p = write(tmp_path, REAL, raw[: raw.rindex(b"\n", 0, len(raw) - 1000) + 1])
    with pytest.raises(AdapterError, match=r"line 13: Number of Pixels in Spectrum is 2048 but"):
        read_oceanoptics(p)
