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
    with pytest.raises(AdapterError, match=rf"line {line}: the last line, .* stops after 1 f"):
        read_columns(p, "wavelength_nm,absorbance")


# ------------------------------------------------------------- preambles, cuts, repeats

#: a header-less OceanView export: a title line, then wavelength and value
OCEANVIEW_TITLED = "Data from ambient_0_40.txt Node\n" + "".join(
    f"{400 + 0.375 * i:.3f}\t{0.5 + i / 1000:.5f}\n" for i in range(6)
)
#: a LI-COR LI-1800 .PRN (PC1800): seven quoted header lines, then blank-separated
#: wavelength [nm] and value in E-notation
LICOR_PRN = (
    '"FILE:RRD1"\r\n"REM: REF RED ADAX 1  "\r\n"LIMS: 350- 360NM"\r\n"INT:  2NM"\r\n'
    '"DATE:05/30 14:52"\r\n"MIN:  354NM  4.504E-02"\r\n"MAX:  352NM  5.089E-02"\r\n'
    + "".join(f" {350 + 2 * i}  {v}\r\n" for i, v in enumerate(
        ["4.522E-02", "5.089E-02", "4.504E-02", "4.573E-02", "4.701E-02", "4.862E-02"]))
)  # fmt: skip
#: an ASD ViewSpec Pro text export: a text header with blank lines and "key = value"
#: lines, a column header, then TAB-separated wavelength and value (trailing blank)
ASD_TXT = (
    "\nText conversion of header file C:\\data\\reflec_panels__00150.asd\n"
    " ----------------------------------------\n\n"
    "The instrument number was  18875/1\nxmin = 350 xmax= 2500\n"
    "VNIR channel 1 wavelength = 350 wavelength step = 1\n\n"
    "Signal (A)  0.000E00\nTemp (C)  0.0\n\n"
    "Wavelength\treflec_panels-00150.asd\n"
    "350\t 4.34852393157055E-02 \n351\t 4.38144056313948E-02 \n"
    "352\t 0.044143130242638 \n353\t 4.33517275465499E-02 \n"
)


@pytest.mark.parametrize(
    ("name", "text", "skip", "first", "n"),
    [
        ("oceanview.txt", OCEANVIEW_TITLED, "1", 400.0, 6),
        ("RRD1.PRN", LICOR_PRN, "7", 350.0, 6),
        ("panel.asd.txt", ASD_TXT, "12", 350.0, 4),
    ],
)
@pytest.mark.parametrize("how", ["count", "auto"])
def test_leading_lines_are_skipped_when_asked(
    tmp_path: Path, name: str, text: str, skip: str, first: float, n: int, how: str
) -> None:
    p = write(tmp_path, name, text)
    with pytest.raises(AdapterError, match=r"line [12]: expected numbers.*--skip-lines"):
        read_columns(p, "wavelength_nm,reflectance")  # a header is never read as data
    spec = f"wavelength_nm,reflectance,skip_lines={skip if how == 'count' else 'auto'}"
    m = labbrdf.read(p, columns=spec)
    assert len(m) == n and m.data["wavelength_nm"].iloc[0] == first
    assert m.meta["skipped_lines"] == int(skip)
    assert m.meta["preamble"][int(skip) - 1] == text.splitlines()[int(skip) - 1]
    assert f"data from line {int(skip) + 1}" in m.meta["notes"][0]
    assert read_columns(p, "wavelength_nm,reflectance", skip_lines=int(skip)).data.equals(m.data)


def test_real_values_after_a_preamble_are_the_files(tmp_path: Path) -> None:
    m = read_columns(write(tmp_path, "p.PRN", LICOR_PRN), "wavelength_nm,reflectance,skip_lines=7")
    assert list(m.data["value"][:2]) == [4.522e-02, 5.089e-02]
    m = read_columns(
        write(tmp_path, "a.txt", ASD_TXT), "wavelength_nm,reflectance,skip_lines=auto"
    )
    assert m.data["value"].iloc[2] == 0.044143130242638


@pytest.mark.parametrize(
    ("spec", "text", "match"),
    [
        ("wavelength_nm,absorbance,skip_lines=x", "400,1\n", r"skip_lines='x': expected a number"),
        ("wavelength_nm,absorbance,skip_lines=-1", "400,1\n", r"expected a number of lines"),
        ("wavelength_nm,absorbance,skips=1", "400,1\n", r"unknown setting 'skips'"),
        ("wavelength_nm,absorbance,skip_lines=1,skip_lines=2", "400,1\n", r"a repeated setting"),
        ("wavelength_nm,absorbance,skip_lines=5", "t\n400,1\n", r"skips every line: .* only 2"),
        ("wavelength_nm,absorbance,skip_lines=auto", "a\nb c\n", r"no line holds 2 numbers"),
        ("wavelength_nm,absorbance,skip_lines=1", "t\nu\n400,1\n", r"line 2: expected numbers"),
    ],
)
def test_bad_skip_settings_and_unskipped_text_are_refused(
    tmp_path: Path, spec: str, text: str, match: str
) -> None:
    with pytest.raises(AdapterError, match=match):
        read_columns(write(tmp_path, "s.txt", text), spec)


def test_cli_skip_lines(tmp_path: Path, capsys) -> None:
    p = write(tmp_path, "ov.txt", OCEANVIEW_TITLED)
    args = ["ingest", str(p), "--columns", "wavelength_nm,absorbance", "--json"]
    assert main([*args, "--skip-lines", "auto"]) == 0
    out = capsys.readouterr()
    assert json.loads(out.out)[0]["rows"] == 6 and "line 1 skipped as a preamble" in out.err
    assert main(["ingest", str(p), "--skip-lines", "1"]) == 2
    assert "--skip-lines skips the leading lines of a file read with --columns" in (
        capsys.readouterr().err
    )


def test_a_title_line_gets_the_skip_lines_hint_without_columns(tmp_path: Path) -> None:
    p = write(tmp_path, "ov.txt", OCEANVIEW_TITLED)
    with pytest.raises(AdapterError, match=r"after 1 line\(s\) of text .* --skip-lines 1"):
        labbrdf.read(p)


def test_a_comment_line_keeps_the_declare_the_columns_hint(tmp_path: Path) -> None:
    """A leading '#' line (which the columns reader skips) used to lose the hint."""
    p = write(tmp_path, "c.txt", "# MoS2, 2015\n340,0.1308\n340.5,0.1304\n")
    with pytest.raises(AdapterError, match=r"bare numbers: declare the columns with --columns"):
        labbrdf.read(p)


def test_the_table_twice_is_refused_where_the_copy_starts(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = (real_exports / REAL).read_bytes()
    p = tmp_path / "twice.txt"
    p.write_bytes(raw + raw)
    line = raw.count(b"\n") + 1
    with pytest.raises(AdapterError, match=rf"line {line}: wavelength_nm 340 starts the column "
                       r"again .* twice"):  # fmt: skip
        read_columns(p, "wavelength_nm,absorbance")


@pytest.mark.parametrize(
    ("tail", "match"),
    [
        ("750,0.", r"'0\.' on the last line, which has no line end, ends without its digits"),
        ("75", r"'75' .* 0 decimals where every other row .* at least 1 decimal"),
    ],
)
def test_a_cut_last_number_is_refused(tmp_path: Path, tail: str, match: str) -> None:
    rows = "".join(f"{700 + i}.5,0.{i + 1}\n" for i in range(8))
    p = write(tmp_path, "cut.csv", rows + tail)
    with pytest.raises(AdapterError, match=rf"line 9: field .*{match}"):
        read_columns(p, "wavelength_nm,absorbance")


def test_real_file_cut_in_its_last_number_is_warned_about(
    real_exports: Path, tmp_path: Path
) -> None:
    """Its absorbance column drops trailing zeros (0.13 beside 0.1308): a shorter last value
    may be real, so the cut ``0.00`` (of ``0.0001``) is warned about, naming the line."""
    raw = (real_exports / REAL).read_bytes()
    cut = raw[: raw.rindex(b"749.5,0.0001") + len(b"749.5,0.00")]
    p = tmp_path / "cut.txt"
    p.write_bytes(cut)
    line = cut.count(b"\n") + 1
    with pytest.warns(labbrdf.adapters.AdapterWarning, match=rf"line {line}: .*may be truncated"):
        m = read_columns(p, "wavelength_nm,absorbance")
    assert m.meta["warnings"]
