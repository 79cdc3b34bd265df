"""Avantes AvaSoft text exports: the real irradiance CSV (refused by name) and synthetic
files of the layouts public AvaSoft exports show (ASCII export of AvaSoft 7/8 and 6, ``;``
with decimal commas or points, ``,``; the Excel-style ``key-->`` CSV)."""

from __future__ import annotations

from pathlib import Path

import pytest

import labbrdf
from labbrdf.adapters import AdapterError, formats, sniff
from labbrdf.adapters.avantes import read_avasoft
from labbrdf.cli import main

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

REAL = ("avantes-avasoft", "avantes-avaspec-e-irrad.csv")


def write(tmp: Path, name: str, text: str) -> Path:
    p = tmp / name
    p.write_bytes(text.encode("cp1252"))
    return p


def ascii8(rows: str, mode: str = "Reflectance", unit: str = "[%]", title: str = "") -> str:
    """AvaSoft 7/8 ASCII export (``;``, padded fields)."""
    return (
        f"{title}\nIntegration time [ms]:  84.900\nAveraging Nr. [scans]: 10\n"
        "Smoothing Nr. [pixels]: 1\nData measured with spectrometer [name]: 1501154U1\n"
        f"Wave   ;Sample   ;Dark     ;Reference;{mode}\n"
        f"[nm]   ;[counts] ;[counts] ;[counts] ;{unit}\n\n{rows}"
    )


#: S, D, R with P = 100 (S - D) / (R - D): 50 %, 25 %; the last row has R - D <= 0
ROWS_POINT = (
    " 400.00;  200.000;  100.000;  300.000;50.00000\n"
    " 400.60;  200.000;  100.000;  500.000;25.00000\n"
    " 401.20;   10.000;   20.000;   15.000;200.00000\n"
)
ROWS_COMMA = ROWS_POINT.replace(".", ",")


def test_real_irradiance_csv_is_refused_by_name(real_exports: Path, capsys) -> None:
    p = real_exports.joinpath(*REAL)
    assert sniff(p) == ["avantes-avasoft"]
    with pytest.raises(
        AdapterError,
        match=r"line 2: an Avantes AvaSoft export in mode "
        r"'Irradiance' \(a radiometric quantity\).*Reflection, Transmission",
    ):
        labbrdf.read(p)
    assert main(["ingest", str(p)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and str(p) in err


@pytest.mark.parametrize("rows", [ROWS_POINT, ROWS_COMMA], ids=["point", "comma"])
def test_ascii_export_reflectance_in_percent(tmp_path: Path, rows: str) -> None:
    p = write(tmp_path, "feather.txt", ascii8(rows))
    assert sniff(p) == ["avantes-avasoft"]
    m = labbrdf.read(p)  # .txt: the content decides
    assert m.meta["format"] == "avantes-avasoft" and m.quantities == ["reflectance"]
    assert list(m.data["value"]) == [0.5, 0.25]
    assert list(m.data["wavelength_nm"]) == [400.0, 400.6]
    assert m.meta["dropped_points"] == 1 and "(lines 11)" in m.meta["notes"][0]
    assert m.meta["counts"]["reference"] == [300.0, 500.0, 15.0]
    assert m.meta["header"]["Data measured with spectrometer [name]"] == "1501154U1"
    assert "'Reflectance', line 6" in m.meta["quantity_from"]


def test_avasoft6_export_with_its_column_order_and_percent_unit(tmp_path: Path) -> None:
    text = (
        "M- \nIntegration time: 175 ms\nAverage: 20 scans\nNr of pixels used for smoothing: 0\n"
        "Data measured with spectrometer serial number: 0411041S1\n"
        "Wave   ;Dark     ;Ref      ;Sample   ;Transmittance\n"
        "[nm]   ;[counts] ;[counts] ;[counts] ;[% transmittance] \n"
        "299,87;100,0;300,0;200,0;50,000\n300,16;100,0;500,0;200,0;25,000\n"
    )
    m = labbrdf.read(write(tmp_path, "J_MUR_0001.ttt", text))
    assert m.quantities == ["transmittance"] and list(m.data["value"]) == [0.5, 0.25]
    assert m.meta["counts"]["sample"] == [200.0, 200.0]


def test_comma_separated_absorbance_export(tmp_path: Path) -> None:
    text = (
        "\nIntegration time [ms]: 10.000\nAveraging Nr. [scans]: 1\nSmoothing Nr. [pixels]: 0\n"
        "Data measured with spectrometer [name]: 0911147U1\n"
        "Wave   ,Sample   ,Dark     ,Reference,Absorbance\n"
        "[nm]   ,[counts] ,[counts] ,[counts] ,[AU]\n"
        "500.00,200.000,100.000,300.000,0.30103\n501.00,200.000,100.000,500.000,0.60206\n"
    )
    m = labbrdf.read(write(tmp_path, "abs.csv", text))
    assert m.quantities == ["absorbance"] and list(m.data["value"]) == [0.30103, 0.60206]


def test_excel_style_csv_with_two_channels(tmp_path: Path) -> None:
    text = (
        "Filename-->,R1.RFL8\nMode/Unit-->,Reflectance[%]\nInt.time[ms]-->,100\n"
        "NrOfAverages-->,10\nSmoothing-->,0\nWavelength[nm],1412092U1- leaf,1412093U2- leaf\n"
        "400.0,50,40\n401.0,25,20\n"
    )
    m = labbrdf.read(write(tmp_path, "leaf.csv", text))
    assert m.quantities == ["reflectance"] and len(m) == 4
    by = m.data.groupby("sample")["value"].apply(list).to_dict()
    assert by == {"1412092U1- leaf": [0.5, 0.25], "1412093U2- leaf": [0.4, 0.2]}


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (ascii8(ROWS_POINT, "Scope"), r"line 6: .* mode 'Scope' \(raw detector counts\)"),
        (
            ascii8(
                ROWS_POINT.replace(";50.", ";;50.")
                .replace(";25.", ";;25.")
                .replace(";200.00000", ";;200.0"),
                "",
                "",
            ),
            r"line 6: .* no processed column \(scope mode",
        ),
        (
            ascii8(ROWS_POINT, "Absolute Irradiance", "[µWatt/cm²/nm]"),
            r"mode 'Absolute Irradiance' \(a radiometric quantity\)",
        ),
        (ascii8(ROWS_POINT, "Reflectance", ""), r"line 6: mode 'Reflectance' with unit ''"),
        (ascii8(ROWS_POINT.replace("400.60", "399.00")), r"line 10: wavelength 399 nm does not"),
        (ascii8(ROWS_POINT.replace("25.00000", "25.0x")), r"line 10: Reflectance: expected a num"),
        (ascii8(ROWS_POINT + " 402.00; 1\n"), r"line 12: expected 5 ';'-separated numbers"),
        (ascii8("").replace("[nm]", "nm"), r"line 7: expected the unit line"),
        ("Filename-->,x\nInt.time[ms]-->,1\nWavelength[nm],a\n1,2\n", r"no 'Mode/Unit-->' line"),
    ],
)
def test_refusals_name_the_file_the_line_and_what_works(
    tmp_path: Path, text: str, match: str
) -> None:
    p = write(tmp_path, "s.txt", text)
    with pytest.raises(AdapterError, match=match) as exc:
        read_avasoft(p)
    assert str(p) in str(exc.value)


def test_the_registry_lists_the_new_formats() -> None:
    names = {f["name"] for f in formats()}
    assert {"avantes-avasoft", "oceanoptics-jaz", "oceanoptics-pi"} <= names
    assert main(["formats"]) == 0


_VARIANTS = {
    "ascii-point": ascii8(ROWS_POINT * 1),
    "ascii-comma": ascii8(ROWS_COMMA),
    "arrow": "Filename-->,R1\nMode/Unit-->,Transmittance[%]\nWavelength[nm],a\n"
    + "".join(f"{400 + i},{i}\n" for i in range(12)),
}
GARBAGE = [b"NaN", b"1e999", b",", b";", b"\t", b"\r\n", b"\n", b"\x00", b"\xff\xfe", b"abc"]


@pytest.mark.parametrize("variant", sorted(_VARIANTS))
def test_mutated_exports_raise_adaptererror_or_read(tmp_path: Path, variant: str) -> None:
    """Truncated, flipped or garbage-inserted files: AdapterError naming the file, or a
    measurement with no more points than the whole file (60 examples per variant)."""
    raw = _VARIANTS[variant].encode("cp1252")
    src = write(tmp_path, "orig.txt", _VARIANTS[variant])
    m0 = read_avasoft(src)
    n0 = len(m0) + m0.meta["dropped_points"]
    target = tmp_path / "mutated.txt"

    @settings(
        max_examples=60,
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=[HealthCheck.too_slow],
    )
    @given(data=st.data())
    def run(data: st.DataObject) -> None:
        op = data.draw(st.sampled_from(["truncate", "flip", "insert"]))
        buf = bytearray(raw)
        if op == "truncate":
            buf = buf[: data.draw(st.integers(0, len(buf) - 1))]
        elif op == "flip":
            for _ in range(data.draw(st.integers(1, 4))):
                buf[data.draw(st.integers(0, len(buf) - 1))] = data.draw(st.integers(0, 255))
        else:
            at = data.draw(st.integers(0, len(buf)))
            buf[at:at] = data.draw(st.sampled_from(GARBAGE))
        target.write_bytes(bytes(buf))
        try:
            m = read_avasoft(target)
        except AdapterError as exc:
            assert str(target) in str(exc)
            return
        if op == "truncate":
            assert len(m) + m.meta["dropped_points"] <= n0

    run()
