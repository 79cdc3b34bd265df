"""Ocean Optics OceanView / SpectraSuite text exports."""

from __future__ import annotations

from pathlib import Path

import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff
from labbrdf.adapters import oceanoptics as oo
from labbrdf.adapters.oceanoptics import read_jaz, read_oceanoptics
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


# ------------------------------------------------------------------ declared sizes first


def test_a_huge_declared_pixel_count_is_refused_before_the_data_are_read(
    tmp_path: Path, monkeypatch
) -> None:
    p = write(tmp_path, "s_Absorbance.txt", oceanview(pixels="4400000"))
    monkeypatch.setattr(oo, "read_bytes", _must_not_read)
    with pytest.raises(AdapterError, match=r"line 8: Number of Pixels in Spectrum = 4400000 "):
        read_oceanoptics(p)


def test_more_data_than_the_declared_count_is_refused_from_the_file_size(
    tmp_path: Path, monkeypatch
) -> None:
    rows = "".join(f"{400 + i / 100:.2f}\t0.5\n" for i in range(20000))
    p = write(tmp_path, "s_Absorbance.txt", oceanview(rows, pixels="3"))
    monkeypatch.setattr(oo, "read_bytes", _must_not_read)
    with pytest.raises(AdapterError, match=r"line 8: .* is 3 but \d+ bytes of data follow"):
        read_oceanoptics(p)


def test_the_first_row_beyond_the_declared_count_is_refused_at_its_line(tmp_path: Path) -> None:
    p = write(tmp_path, "s.txt", oceanview("400\t1\n401\t2\n402\t3\n403\t4\n", pixels="2"))
    with pytest.raises(AdapterError, match=r"line 12: more data rows than the declared 2"):
        read_oceanoptics(p)


def _must_not_read(path):  # the whole file must not be read before the header is checked
    raise AssertionError("the data were read before the declared size was checked")


# ------------------------------------------------------------------ header-less OceanView


def test_headerless_export_is_read_when_forced_and_the_title_names_the_mode(
    tmp_path: Path,
) -> None:
    p = write(tmp_path, "run1.txt", "Transmission\n400.0\t50\n401.0\t25,5\n")
    assert sniff(p) == []  # no marker: never claimed by content
    m = labbrdf.read(p, format="oceanoptics-text")
    assert m.quantities == ["transmittance"] and list(m.data["value"]) == [0.5, 0.255]
    assert m.meta["quantity_from"] == "the title line"


def test_headerless_export_without_a_mode_points_to_columns(tmp_path: Path, capsys) -> None:
    p = write(tmp_path, "run1.txt", "sample 3\n400.0\t0.5\n401.0\t0.25\n")
    with pytest.raises(AdapterError, match=r"header-less export .* --columns .* title line"):
        labbrdf.read(p, format="oceanoptics-text")
    assert main(["ingest", str(p), "--format", "oceanoptics-text"]) == 2
    err = capsys.readouterr().err
    assert "--columns" in err and "Traceback" not in err


# ------------------------------------------------------------------------------------ Jaz

JAZ = ("oceanoptics-jaz", "oo-reflectance.jaz")


def jaz(
    rows: str, *, title: str = "Jaz Data File", pixels: int | None = None, cols="W\tD\tR\tS\tP"
):
    n = rows.count("\n") if pixels is None else pixels
    return (
        f"{title}\n++++++++++\nDate: Mon Sep 17 14:58:29 2018\nUser: jaz\n"
        "Dark Spectrum Present: Yes\nReference Spectrum Present: Yes\n"
        "Processed Spectrum Present: Yes\nSpectrometers: JAZA0001\n"
        f"Number of Pixels in Processed Spectrum: {n}\n"
        f">>>>>Begin Processed Spectral Data<<<<<\n{cols}\n{rows}"
        ">>>>>End Processed Spectral Data<<<<<\n"
    )


#: wavelength, dark, reference, sample: P = 100 (S - D) / (R - D) = 50, 25; the first row
#: is all zero (no ratio)
JAZ_ROWS = "400.0\t0\t0\t0\t0\n401.0\t100\t300\t200\t50.000000\n402.0\t100\t500\t200\t25.000000\n"


def test_real_jaz_file_reads_its_processed_column_as_reflectance(real_exports: Path) -> None:
    p = real_exports.joinpath(*JAZ)
    assert sniff(p) == ["oceanoptics-jaz"]
    m = labbrdf.read(p)
    assert m.meta["format"] == "oceanoptics-jaz" and m.quantities == ["reflectance"]
    # 2048 pixels, 11 without a ratio (R - D <= 0: the two all-zero rows, UV noise)
    assert len(m) == 2037 and m.meta["dropped_points"] == 11
    assert "11 rows dropped" in m.meta["notes"][0] and "lines 19, 20, 21" in m.meta["notes"][0]
    s = m.data.set_index("wavelength_nm")["value"]
    for wl, percent in ((400, 11.5), (550, 40.2), (700, 49.4)):  # PROVENANCE.md
        near = s.index[abs(s.index - wl).argmin()]
        assert s[near] == pytest.approx(percent / 100, abs=0.001)
    assert s[195.653656] == 35.433079 * 0.01  # line 33 as written, percent to fraction
    counts = m.meta["counts"]
    assert len(counts["dark"]) == 2048 and counts["sample"][2] == 909.919617
    assert m.meta["quantity_from"].startswith("the file name; the processing")


def test_jaz_percent_ratio_without_a_mode_in_the_name_is_refused(
    real_exports: Path, tmp_path: Path
) -> None:
    p = write(tmp_path, "SPECTRUM0001.jaz", real_exports.joinpath(*JAZ).read_bytes())
    with pytest.raises(AdapterError, match=r"percent ratio .* reflectance or transmittance"):
        labbrdf.read(p)


def test_synthetic_jaz_transmittance_and_absorbance(tmp_path: Path) -> None:
    m = labbrdf.read(write(tmp_path, "filter_Transmission.jaz", jaz(JAZ_ROWS)))
    assert m.quantities == ["transmittance"] and list(m.data["value"]) == [0.5, 0.25]
    assert m.meta["dropped_points"] == 1
    # absorbance: the processing itself says so, whatever the file name
    rows = "401.0\t100\t300\t200\t0.301030\n402.0\t100\t500\t200\t0.602060\n"
    m = labbrdf.read(write(tmp_path, "x.jaz", jaz(rows)))
    assert m.quantities == ["absorbance"]
    assert list(m.data["value"]) == [0.30103, 0.60206]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"title": "Jaz Irradiance File"}, r"line 1: a Jaz irradiance file"),
        ({"cols": "W\tS"}, r"line 11: columns 'W S' and no processed column P: raw"),
        ({"cols": "W\tP\tD\tR\tS"}, r"line 11: column line .*expected 'W<TAB>D"),
        ({"pixels": 4}, r"line 9: Number of Pixels in Processed Spectrum is 4 but the file"),
    ],
)
def test_jaz_refusals_name_the_line(tmp_path: Path, kwargs: dict, match: str) -> None:
    rows = JAZ_ROWS if "cols" not in kwargs else "400\t1\n"
    with pytest.raises(AdapterError, match=match):
        read_jaz(write(tmp_path, "s_Reflectance.jaz", jaz(rows, **kwargs)))


def test_jaz_row_whose_processed_value_contradicts_its_counts_is_refused(tmp_path: Path) -> None:
    rows = JAZ_ROWS.replace("25.000000", "26.000000")
    with pytest.raises(AdapterError, match=r"line 14: P = 26 agrees neither with 100 \(S - D\)"):
        read_jaz(write(tmp_path, "s_Reflectance.jaz", jaz(rows)))


# ----------------------------------------------------------------------------- Raspberry Pi


def test_real_pi_file_is_refused_by_name(real_exports: Path, capsys) -> None:
    p = real_exports / "oceanoptics-pi" / "oo-spectrum.pi"
    assert sniff(p) == ["oceanoptics-pi"]
    with pytest.raises(AdapterError, match=r"Raspberry Pi spectrum .* raw detector intensit"):
        labbrdf.read(p)
    assert main(["ingest", str(p)]) == 2
    err = capsys.readouterr().err
    assert "oceanoptics-text" in err and "Traceback" not in err and err.count("\n") == 1


def test_real_jaz_file_cut_in_its_last_number_is_refused(
    real_exports: Path, tmp_path: Path
) -> None:
    """Without its end marker and cut in the last P, the file still has its 2048 rows and
    53.1989 agrees with the counts within their rounding: the precision of the column
    (6 decimals on every row) is what says it is cut."""
    raw = real_exports.joinpath(*JAZ).read_bytes()
    body = raw[: raw.index(b">>>>>End")].rstrip()
    assert body.endswith(b"\t53.198986")
    p = write(tmp_path, "cut_Reflection.jaz", body[:-2])
    with pytest.raises(AdapterError, match=r"cut_Reflection.jaz, line 2066: field 5 '53\.1989'"):
        labbrdf.read(p)
    m = labbrdf.read(write(tmp_path, "whole_Reflection.jaz", body))  # complete: no doubt
    assert "warnings" not in m.meta and len(m.meta["counts"]["dark"]) == 2048
