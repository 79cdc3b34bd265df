"""PerkinElmer UV WinLab ASCII ``.asc`` exports: real files, reflectance, sphere and absorbance
scale, and the errors of bad input.

Real files come from ../shared/real-exports through the ``real_exports`` fixture (skipped
when absent); every spot value is quoted from the file line it was checked against. The
synthetic files are built by the small writers here: each writes a valid file, and the
error tests break one thing at a time and check the AdapterError names the file and the
line (text) or byte offset (binary) and what was expected.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError
from labbrdf.adapters.perkinelmer import read_perkinelmer_asc

PE = "perkinelmer-uvwinlab-asc"


def test_lambda950_absorbance_file_with_comma_and_spaces_in_its_name(real_exports: Path) -> None:
    m = labbrdf.read(real_exports / PE / "F4-P3HT 1-10 0,5 mgml.Probe.Raw.asc")
    assert m.meta["format"] == "perkinelmer-uvwinlab-asc"
    d = m.data
    assert len(d) == 2181  # header line 86: "2181"
    assert set(d["quantity"]) == {"absorbance"}
    # line 91: "2500.000000	0.012944"
    row = d[np.isclose(d["wavelength_nm"], 2500.0, rtol=0, atol=1e-9)]
    assert row["value"].tolist() == [pytest.approx(0.012944, rel=1e-12)]
    assert d["wavelength_nm"].min() == 320.0


@pytest.mark.parametrize(
    ("name", "n", "lo", "hi", "spot", "sphere"),
    [
        # "1900.000000\t99.999792" (line 91), "500.000000\t100.014483" (last line)
        ("3DM_test01.Probe.Raw.asc", 281, 500, 1900, {1900: 99.999792, 500: 100.014483}, 0),
        # "1200.000000\t89.940565" (line 91), "200.000000\t0.040434" (last line)
        ("KTF-D.Probe.Raw.asc", 1001, 200, 1200, {1200: 89.940565, 200: 0.040434}, 0),
        # "1200.000000\t183.367051" (line 91), "1190.000000\t-49.448635" (line 92)
        ("sphere_test01.Probe.Raw.asc", 41, 800, 1200, {1200: 183.367051, 1190: -49.448635}, 1),
    ],
)
def test_perkinelmer_real_files(
    real_exports: Path,
    name: str,
    n: int,
    lo: float,
    hi: float,
    spot: dict,
    sphere: int,
    value_at,
    check_spectrum,
) -> None:
    m = read_perkinelmer_asc(real_exports / "perkinelmer-uvwinlab-asc" / name)
    # %T with the sphere stays transmittance (there is no hemispherical transmittance)
    check_spectrum(m, "transmittance", n, lo, hi)
    for wl, percent in spot.items():
        assert value_at(m, wl) == pytest.approx(percent / 100, rel=1e-15)
    assert m.meta["sphere"] is bool(sphere)
    assert m.meta["instrument_model"] == "Lambda 1050" and m.meta["gr"]["npoints"] == n


def pe(
    rows: str = "600.000000\t50.0\r\n590.000000\t51.0\r\n",
    *,
    accessory: str = "uv/vis/nir detector",
    gr: tuple[str, ...] = ("nm", "%R", "1.0", "0.0", "600.000000", "-10.000000", "2"),
) -> bytes:
    lines = ["PE UV       SUBTECH     SPECTRUM    ASCII       PEDS        4.00        "]
    lines += ["   -1", "MySample.Sample.Raw.asc", "24/02/27", "14:41:25.00"]
    lines += ["x"] * 19 + [accessory] + ["0"] * 5
    lines += ["#HDR", "-1", "-1", "#GR", *gr, "8", "52.0", "50.0", "#DATA"]
    return ("\r\n".join(lines) + "\r\n" + rows).encode("ascii")


def test_perkinelmer_reflectance_sphere_absorbance_scale(tmp_path: Path, write) -> None:
    m = read_perkinelmer_asc(write(tmp_path, "a.asc", pe()))
    assert set(m.data["quantity"].astype(str)) == {"reflectance"}
    assert list(m.data["value"]) == [0.5, 0.51] and set(m.data["sample"]) == {"MySample"}
    m = read_perkinelmer_asc(write(tmp_path, "b.asc", pe(accessory="150mm sphere / down")))
    assert set(m.data["quantity"].astype(str)) == {"hemispherical_reflectance"}
    gr = ("nm", "A", "2.0", "0.5", "600", "-10", "2")
    m = read_perkinelmer_asc(write(tmp_path, "c.asc", pe(gr=gr)))
    assert set(m.data["quantity"].astype(str)) == {"absorbance"}
    assert list(m.data["value"]) == [100.5, 102.5]  # y * scale + offset, no percent


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (b"PE IR SPECTRUM\r\n", r"line 1: expected the magic 'PE UV SUBTECH"),
        (pe().replace(b"#GR", b"#GX"), r"no '#GR' line found"),
        (pe().replace(b"#DATA", b"#DAT"), r"no '#DATA' line found"),
        (pe(gr=("nm", "%R")), r"line 34: the #GR block has 5 lines"),
        (pe(gr=("%R", "nm", "1", "0", "600", "-10", "2")), r"line 35: x unit '%R'"),
        (pe(gr=("cm-1", "%R", "1", "0", "600", "-10", "2")), r"line 35: x unit 'cm-1'"),
        (pe(gr=("nm", "%Q", "1", "0", "600", "-10", "2")), r"line 36: y unit '%Q'"),
        (pe(gr=("nm", "%R", "1", "0", "600", "-10", "2.5")), r"NPOINTS '2.5': expected a"),
        (pe(gr=("nm", "%R", "1", "0", "600", "-10", "3")), r"NPOINTS is 3 but #DATA has 2"),
        (pe("600.000000\t50.0\t1\r\n"), r"line 46: expected 'x<TAB>y'"),
        (pe("600\t50\r\n580\t51\r\n"), r"line 47: X 580.0 is not on the FIRSTX"),
        (pe("600\t50\r\n590\tabc\r\n"), r"line 47: Y: expected a number"),
    ],
)
def test_perkinelmer_errors(tmp_path: Path, data: bytes, match: str, write) -> None:
    p = write(tmp_path, "bad.asc", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_perkinelmer_asc(p)
    assert str(p) in str(exc.value)


def test_utf16_perkinelmer_text_is_refused_as_the_wrong_encoding(tmp_path: Path, write) -> None:
    p = write(tmp_path, "utf16.txt", pe().decode("latin-1").encode("utf-16"))
    with pytest.raises(AdapterError, match=r"line 1: binary content \(NUL byte\)"):
        read_perkinelmer_asc(p)


def test_perkinelmer_blank_line_in_data_and_negative_wavelength(tmp_path: Path, write) -> None:
    m = read_perkinelmer_asc(write(tmp_path, "a.asc", pe("600\t50\r\n\r\n590\t51\r\n")))
    assert len(m) == 2
    gr = ("nm", "%R", "1", "0", "-10", "-10", "2")
    bad = write(tmp_path, "b.asc", pe("-10\t50\r\n-20\t51\r\n", gr=gr))
    with pytest.raises(AdapterError, match=r"invalid data: column 'wavelength_nm': expected"):
        read_perkinelmer_asc(bad)
