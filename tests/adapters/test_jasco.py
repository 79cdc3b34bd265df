"""JASCO Spectra Manager text: a UTF-8 BOM or CR-only line ends are recognised."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff
from labbrdf.adapters.jasco import read_jasco_jws

TXT = "jasco-spectramanager-text"


@pytest.mark.parametrize("variant", ["bom", "cr", "bom+cr"])
def test_bom_and_cr_only_line_ends_are_recognised(
    real_exports: Path, tmp_path: Path, variant: str
) -> None:
    src = real_exports / TXT / "PbSe batch 1.txt"
    raw = src.read_bytes().replace(b"\r\n", b"\n")
    if "cr" in variant:
        raw = raw.replace(b"\n", b"\r")
    if "bom" in variant:
        raw = b"\xef\xbb\xbf" + raw
    path = tmp_path / "PbSe.txt"
    path.write_bytes(raw)
    assert sniff(path) == ["jasco-spectramanager-text"]
    m = labbrdf.read(path)
    assert m.data["value"].equals(labbrdf.read(src).data["value"])


# ------------------------------------------------------------- legacy (OLE2) .jws


LEGACY = "jasco-jws-binary/legacy_trans_512.jws"
_INVALID = -np.finfo(np.float32).tiny  # JASCO's invalid-point marker, -FLT_MIN


def legacy_streams(
    y=(50.0, 40.0, 30.0),
    *,
    first: float = 4000.0,
    delta: float = 1000.0,
    last: float | None = None,
    xcode: int = 0x10000100,
    ycode: int = 0,
    npoints: int | None = None,
    channels: int = 1,
) -> dict[str, bytes]:
    n = len(y) if npoints is None else npoints
    last = first + delta * (n - 1) if last is None else last
    info = struct.pack("<6I3d", 3, 1, 0, channels, 1, n, first, last, delta)
    info += struct.pack(f"<{channels + 1}I", xcode, *([ycode] * channels))
    info = info.ljust(96, b"\x00")
    return {"DataInfo": info, "Y-Data": np.asarray(y, "<f4").tobytes(), "Header": b"\x00" * 64}


def test_real_legacy_jws_is_ftir_transmittance_converted_to_nm(real_exports: Path) -> None:
    m = labbrdf.read(real_exports / LEGACY)
    d = m.data
    assert m.meta["format"] == "jasco-jws" and m.quantities == ["transmittance"]
    assert m.meta["x_unit_in_file"] == "1/cm" and m.meta["npoints"] == 7573
    # lambda = 1e7 / nu: the first wavenumber 499.47 1/cm is 20021 nm
    first = m.meta["firstx_in_file"]
    assert d["wavelength_nm"].max() == pytest.approx(1e7 / first, rel=1e-12)
    # percent in the file (up to 27.7 %): fractions in the dataset
    assert 0 < d["value"].max() < 0.3
    assert m.meta["invalid_marker_points"] + len(d) == 7573


def test_synthetic_legacy_jws_wavenumber_and_invalid_marker(tmp_path: Path, make_ole2) -> None:
    p = tmp_path / "ftir.jws"
    p.write_bytes(make_ole2(legacy_streams((50.0, _INVALID, 30.0))))
    assert sniff(p) == ["jasco-jws"]
    m = labbrdf.read(p)
    # 4000 and 6000 1/cm: 2500 and 1666.67 nm; the marked point is dropped and counted
    assert list(m.data["wavelength_nm"]) == pytest.approx([2500.0, 1e7 / 6000.0], rel=1e-15)
    assert list(m.data["value"]) == pytest.approx([0.5, 0.3], rel=1e-7)
    assert m.meta["invalid_marker_points"] == 1 and m.meta["dropped_points"] == 1


def test_synthetic_legacy_jws_in_nm_absorbance(tmp_path: Path, make_ole2) -> None:
    p = tmp_path / "uv.jws"
    streams = legacy_streams((0.5, 0.25), first=400.0, delta=1.0, xcode=0x10000103, ycode=3)
    p.write_bytes(make_ole2(streams))
    m = read_jasco_jws(p)
    assert m.quantities == ["absorbance"] and list(m.data["wavelength_nm"]) == [400.0, 401.0]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"xcode": 0x10000999}, r"x-axis code 0x10000999 in DataInfo: expected"),
        ({"ycode": 14}, r"channel code 14 in DataInfo has no labbrdf quantity"),
        ({"npoints": 4}, r"'Y-Data' is 12 bytes but 1 channel\(s\) of NPOINTS 4 need 16"),
        ({"npoints": 0}, r"NPOINTS 0: expected > 0"),
        ({"npoints": 10**9}, r"exceeds the limit of 2000000 points"),
        ({"last": 9999.0}, r"disagrees with LASTX 9999"),
        ({"delta": 0.0}, r"DELTAX 0.0: expected finite"),
        ({"channels": 0}, r"DataInfo says 0 channels"),
        ({"first": 100.0, "delta": -1000.0}, r"the X axis reaches -1900 <= 0"),
    ],
)
def test_legacy_jws_errors_name_file_and_field(
    tmp_path: Path, make_ole2, kwargs: dict, match: str
) -> None:
    p = tmp_path / "bad.jws"
    p.write_bytes(make_ole2(legacy_streams(**kwargs)))
    with pytest.raises(AdapterError, match=match) as exc:
        read_jasco_jws(p)
    assert str(p) in str(exc.value)


def test_legacy_jws_without_its_streams_is_refused(tmp_path: Path, make_ole2) -> None:
    p = tmp_path / "other.jws"
    p.write_bytes(make_ole2({"Workbook": b"x" * 10}))
    with pytest.raises(AdapterError, match=r"1.x .jws: no stream 'DataInfo'"):
        labbrdf.read(p)


@pytest.mark.parametrize("keep", [512, 1024, 1500])
def test_truncated_legacy_jws_is_refused(tmp_path: Path, make_ole2, keep: int) -> None:
    p = tmp_path / "cut.jws"
    p.write_bytes(make_ole2(legacy_streams())[:keep])
    with pytest.raises(AdapterError, match=r"cut.jws: .*(corrupt|truncated)"):
        read_jasco_jws(p)
