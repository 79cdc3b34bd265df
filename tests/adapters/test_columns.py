"""Generic headerless columns, read only with declared columns (``--columns``/``columns=``)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError
from labbrdf.adapters.columns import parse_columns, read_columns
from labbrdf.cli import main

REAL = "generic-columns/MoS2_fromCzech2015.txt"


def write(tmp: Path, name: str, data: str) -> Path:
    p = tmp / name
    p.write_bytes(data.encode())
    return p


def test_real_headerless_csv_reads_with_declared_columns(real_exports: Path) -> None:
    m = labbrdf.read(real_exports / REAL, columns="wavelength_nm,absorbance")
    d = m.data
    assert m.meta["format"] == "columns" and m.meta["separator"] == ","
    assert len(d) == 821
    assert d["wavelength_nm"].iloc[0] == 340.0 and d["wavelength_nm"].iloc[-1] == 750.0
    np.testing.assert_allclose(np.diff(d["wavelength_nm"]), 0.5, rtol=0, atol=1e-12)
    assert d["value"].iloc[0] == 0.1308  # first line "340,0.1308"


def test_real_file_without_columns_says_how_to_declare_them(real_exports: Path) -> None:
    with pytest.raises(AdapterError, match=r"bare numbers: declare the columns with --columns"):
        labbrdf.read(real_exports / REAL)
    with pytest.raises(
        AdapterError, match=r"not declared; declare them with --columns .* columns="
    ):
        labbrdf.read(real_exports / REAL, format="columns")


def test_cli_ingest_with_columns(real_exports: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "mos2.parquet"
    code = main(
        [
            "ingest",
            str(real_exports / REAL),
            "--columns",
            "wavelength_nm,absorbance",
            "--json",
            "-o",
            str(out),
        ]
    )
    assert code == 0
    rows = json.loads(capsys.readouterr().out)
    assert rows[0]["format"] == "columns" and rows[0]["rows"] == 821
    assert out.exists()


def test_cli_ingest_without_columns_exits_2_with_the_option_named(
    real_exports: Path, capsys
) -> None:
    assert main(["ingest", str(real_exports / REAL)]) == 2
    err = capsys.readouterr().err
    assert "--columns" in err and "Traceback" not in err


def test_cli_columns_with_another_format_is_refused(tmp_path: Path, capsys) -> None:
    p = write(tmp_path, "a.txt", "400\t1\n")
    assert (
        main(["ingest", str(p), "--format", "jcamp-dx", "--columns", "wavelength_nm,absorbance"])
        == 2
    )
    assert "declare the columns of format 'columns', not of 'jcamp-dx'" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("text", "columns", "sep"),
    [
        ("400\t1,5\n401\t2,5\n", "wavelength_nm,absorbance", "TAB"),
        ("400;1,5\n401;2,5\n", "wavelength_nm,absorbance", ";"),
        ("400  1.5\n 401 2.5 \n", "wavelength_nm,absorbance", "blanks"),
        ("# comment\n400,1.5\n\n401,2.5\n", ["wavelength_nm", "absorbance"], ","),
    ],
)
def test_separators_and_decimal_commas(tmp_path: Path, text: str, columns, sep: str) -> None:
    m = read_columns(write(tmp_path, "a.txt", text), columns)
    assert m.meta["separator"] == sep
    assert list(m.data["value"]) == [1.5, 2.5] and list(m.data["wavelength_nm"]) == [400, 401]


def test_several_ordinates_units_and_skip(tmp_path: Path) -> None:
    text = "0.5,9,50,10\n0.6,9,40,20\n"
    m = read_columns(
        write(tmp_path, "a.csv", text),
        "wavelength_um,skip,transmittance_percent,reflectance_percent",
    )
    t = m.data[m.data["quantity"] == "transmittance"]
    r = m.data[m.data["quantity"] == "reflectance"]
    assert list(t["wavelength_nm"]) == [500.0, 600.0]
    assert list(t["value"]) == [0.5, 0.4] and list(r["value"]) == [0.1, 0.2]


def test_wavenumber_and_energy_axes_convert_to_wavelength(tmp_path: Path) -> None:
    m = read_columns(
        write(tmp_path, "ir.txt", "4000 0.5\n10000 0.25\n"), "wavenumber_cm-1,absorbance"
    )
    assert list(m.data["wavelength_nm"]) == pytest.approx([2500.0, 1000.0], rel=1e-15)
    # hc = 1239.841984 eV nm: 2 eV is 619.92 nm
    m = read_columns(write(tmp_path, "ev.txt", "2 0.5\n3 0.25\n"), "energy_ev,absorbance")
    assert m.data["wavelength_nm"].iloc[0] == pytest.approx(1239.8419843320026 / 2, rel=1e-15)


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("wavelength_nm,counts", r"unknown column 'counts'"),
        ("absorbance", r"exactly one abscissa .* found none"),
        ("wavelength_nm,energy_ev,absorbance", r"exactly one abscissa"),
        ("wavelength_nm,skip", r"at least one ordinate"),
        ("wavelength_nm,absorbance,absorbance", r"an ordinate is repeated"),
    ],
)
def test_bad_declarations_are_refused(spec: str, match: str) -> None:
    with pytest.raises(AdapterError, match=match):
        parse_columns(spec)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("wavelength,abs\n400,1\n", r"line 1: expected numbers, found the text 'wavelength,abs'"),
        ("400,1\n401,2,3\n", r"line 2: expected 2 fields .* found 3"),
        ("400,1\n401,x\n", r"line 2: absorbance: expected a number, found 'x'"),
        ("400,1\n400,2\n", r"line 2: wavelength_nm 400 repeats"),
        ("400,1\n-1,2\n", r"line 2: wavelength_nm -1: expected a positive value"),
        ("# only a comment\n\n", r"no data rows"),
        ("400,1\n4\x0001,2\n", r"line 2: binary content"),
    ],
)
def test_file_errors_name_file_line_and_expectation(tmp_path: Path, text: str, match: str) -> None:
    p = write(tmp_path, "bad.csv", text)
    with pytest.raises(AdapterError, match=match) as exc:
        read_columns(p, "wavelength_nm,absorbance")
    assert str(p) in str(exc.value)


def test_truncated_real_file_is_refused_at_the_cut_line(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = (real_exports / REAL).read_bytes()
    cut = raw[: raw.index(b",", len(raw) // 2) + 1]  # "NNN," without the value
    p = tmp_path / "cut.txt"
    p.write_bytes(cut)
    line = cut.count(b"\n") + 1
    with pytest.raises(AdapterError, match=rf"line {line}: absorbance: expected a number"):
        read_columns(p, "wavelength_nm,absorbance")
