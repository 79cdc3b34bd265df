"""Shimadzu UVProbe: the text export and the binary .spc (an OLE2 compound document)."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff
from labbrdf.adapters.shimadzu import read_uvprobe_spc, read_uvprobe_text
from labbrdf.adapters.spc import read_spc
from labbrdf.cli import main

FOLDER = "shimadzu-uvprobe"
STEM = "sa281-02-280K"


def write(tmp: Path, name: str, data: bytes) -> Path:
    p = tmp / name
    p.write_bytes(data)
    return p


# ----------------------------------------------------------------------------- real files


def test_real_spc_agrees_with_the_text_export_of_the_same_measurement(real_exports: Path) -> None:
    """The text has 3 decimals: the binary float64 values must round to them."""
    txt = labbrdf.read(real_exports / FOLDER / f"{STEM}.txt")
    spc = labbrdf.read(real_exports / FOLDER / f"{STEM}.spc")
    assert txt.meta["format"] == "shimadzu-uvprobe-text"
    assert spc.meta["format"] == "shimadzu-uvprobe-spc"
    a = txt.data.sort_values("wavelength_nm").reset_index(drop=True)
    b = spc.data.sort_values("wavelength_nm").reset_index(drop=True)
    assert len(a) == len(b) == 601
    np.testing.assert_array_equal(a["wavelength_nm"], b["wavelength_nm"])
    assert a["wavelength_nm"].iloc[0] == 300.0 and a["wavelength_nm"].iloc[-1] == 900.0
    # half a unit of the third decimal, plus float64 round-off of the printed value
    assert np.max(np.abs(a["value"] - b["value"])) <= 0.0005 + 1e-12
    assert set(a["quantity"]) == set(b["quantity"]) == {"absorbance"}
    assert spc.meta["data_sets"][0]["measuring_mode"] == "Absorbance"
    assert spc.meta["data_sets"][0]["method"]["Instrument Type"] == "UV-1600 Series"


def test_real_text_values_and_sample(real_exports: Path) -> None:
    m = read_uvprobe_text(real_exports / FOLDER / f"{STEM}.txt")
    d = m.data
    assert d["sample"].iloc[0] == "sa281-02-280K - RawData"
    # first row "300,00<TAB>0,322": decimal commas
    first = d[d["wavelength_nm"] == 300.0]["value"]
    assert list(first) == [0.322]


def test_real_files_are_claimed_by_their_own_sniffer_only(real_exports: Path) -> None:
    assert sniff(real_exports / FOLDER / f"{STEM}.txt") == ["shimadzu-uvprobe-text"]
    assert sniff(real_exports / FOLDER / f"{STEM}.spc") == ["shimadzu-uvprobe-spc"]


def test_real_spc_forced_as_galactic_names_an_ole2_document(real_exports: Path) -> None:
    with pytest.raises(AdapterError, match=r"byte 0: this is an OLE2 compound document") as exc:
        read_spc(real_exports / FOLDER / f"{STEM}.spc")
    msg = str(exc.value)
    assert "--format shimadzu-uvprobe-spc" in msg and "format='shimadzu-uvprobe-spc'" in msg


def test_real_files_ingest_from_the_cli(real_exports: Path, capsys) -> None:
    files = [str(real_exports / FOLDER / f"{STEM}.{e}") for e in ("txt", "spc")]
    assert main(["ingest", *files, "--json"]) == 0
    import json

    out = json.loads(capsys.readouterr().out)
    assert [r["format"] for r in out] == ["shimadzu-uvprobe-text", "shimadzu-uvprobe-spc"]
    assert [r["rows"] for r in out] == [601, 601]


# ----------------------------------------------------------------------------- text

TEXT = '"demo - RawData"\r\n"Wavelength nm."\t"{label}"\r\n{rows}'


def text(label: str = "Abs.", rows: str = "500,00\t0,250\r\n501,00\t0,500\r\n") -> bytes:
    return TEXT.format(label=label, rows=rows).encode("cp1252")


def test_synthetic_text_decimal_commas_and_points(tmp_path: Path) -> None:
    m = labbrdf.read(write(tmp_path, "a.txt", text(rows="500,00\t0,250\r\n501.5\t0.5\r\n")))
    assert m.meta["format"] == "shimadzu-uvprobe-text"
    assert list(m.data["wavelength_nm"]) == [500.0, 501.5]
    assert list(m.data["value"]) == [0.25, 0.5]


@pytest.mark.parametrize(
    ("label", "quantity", "value"),
    [("Abs.", "absorbance", 40.0), ("%T", "transmittance", 0.4), ("%R", "reflectance", 0.4)],
)
def test_synthetic_text_ordinate_labels(
    tmp_path: Path, label: str, quantity: str, value: float
) -> None:
    m = read_uvprobe_text(write(tmp_path, "t.txt", text(label, "400\t40,0\r\n")))
    assert m.quantities == [quantity]
    assert m.data["value"].iloc[0] == pytest.approx(value, rel=1e-15)


def test_synthetic_text_comma_separated_with_decimal_points(tmp_path: Path) -> None:
    raw = b'"s"\n"Wavelength nm.","%T"\n400.0,50.0\n401.0,51.0\n'
    m = labbrdf.read(write(tmp_path, "c.csv", raw))
    assert m.meta["format"] == "shimadzu-uvprobe-text"
    assert list(m.data["value"]) == [0.5, 0.51]


def test_synthetic_text_with_two_data_sets(tmp_path: Path) -> None:
    raw = text(rows="500\t1\r\n501\t2\r\n") + b"\r\n" + text(label="%T", rows="600\t50\r\n")
    m = read_uvprobe_text(write(tmp_path, "two.txt", raw))
    assert len(m) == 3 and sorted(m.quantities) == ["absorbance", "transmittance"]
    assert [b["line"] for b in m.meta["blocks"]] == [1, 6]


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (text("Energy"), r"line 2: ordinate 'Energy' has no labbrdf quantity"),
        (text(rows="500\t0,1\t7\r\n"), r"line 3: expected 2 fields"),
        (text(rows="500\t0,1\r\n501\tx\r\n"), r"line 4: Abs.: expected a number, found 'x'"),
        (text(rows="500\t1\r\n500\t2\r\n"), r"line 4: wavelength 500 nm repeats"),
        (text(rows="500\t1\r\n502\t2\r\n501\t3\r\n"), r"line 5: wavelength 501 nm repeats"),
        (text(rows="0\t1\r\n"), r"line 3: wavelength 0 nm is outside"),
        (text(rows=""), r"line 3: data set 'demo - RawData' has no data rows"),
        (b'"demo - RawData"\r\n', r"line 1: the file ends after the title"),
        (b'"demo"\r\n"Wavelength"\t"Abs."\r\n1\t2\r\n', r'line 2: expected the header "Wave'),
        (b"demo\r\n", r"line 1: expected a quoted data set title"),
        (text(rows="500\t1\r\n") + b"junk\r\n", r"line 4: expected 2 fields"),
        (text().replace(b"0,250", b"\x000,250"), r"binary content \(NUL byte\)"),
    ],
)
def test_text_errors_name_file_line_and_expectation(
    tmp_path: Path, data: bytes, match: str
) -> None:
    p = write(tmp_path, "bad.txt", data)
    with pytest.raises(AdapterError, match=match) as exc:
        read_uvprobe_text(p)
    assert str(p) in str(exc.value)


def test_real_text_cut_in_a_row_is_refused_at_that_line(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = (real_exports / FOLDER / f"{STEM}.txt").read_bytes()
    cut = raw[: raw.index(b"\t", len(raw) // 2) + 1]  # ends right after a TAB
    line = cut.count(b"\n") + 1
    with pytest.raises(AdapterError, match=rf"line {line}: expected 2 fields .* found 1"):
        read_uvprobe_text(write(tmp_path, "cut.txt", cut))


@pytest.mark.parametrize(
    ("nbytes", "line", "shown"),
    [
        (173, 11, "'0,'"),
        (174, 11, "'0,2'"),
        (172, 11, "'0'"),
        (169, 11, "'308,0'"),
        (168, 11, "'308,'"),
    ],
)
def test_real_text_cut_mid_number_is_refused_as_truncated(
    real_exports: Path, tmp_path: Path, nbytes: int, line: int, shown: str
) -> None:
    """``head -c 173`` ends in ``308,00<TAB>0,``: read as 0.0 for 0.289 before."""
    raw = (real_exports / FOLDER / f"{STEM}.txt").read_bytes()
    p = write(tmp_path, "cut.txt", raw[:nbytes])
    with pytest.raises(
        AdapterError, match=rf"line {line}: field \d {shown} .*looks truncated"
    ) as exc:
        read_uvprobe_text(p)
    assert str(p) in str(exc.value)


def test_real_text_cut_after_a_whole_number_reads_the_rows_before(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = (real_exports / FOLDER / f"{STEM}.txt").read_bytes()
    m = read_uvprobe_text(write(tmp_path, "cut.txt", raw[:176]))  # "308,00\t0,289"
    assert m.data["value"].iloc[-1] == 0.289 and len(m) == 9
    assert "warnings" not in m.meta


def test_text_whose_last_value_is_shorter_than_a_varying_column_is_warned_about(
    tmp_path: Path,
) -> None:
    rows = "500\t0,25\r\n501\t0,5\r\n502\t0,125\r\n503\t0,7"  # no line end
    p = write(tmp_path, "v.txt", text(rows=rows))
    with pytest.warns(labbrdf.adapters.AdapterWarning, match=r"line 6: .*may be truncated"):
        m = read_uvprobe_text(p)
    assert m.meta["warnings"] and str(p) in m.meta["warnings"][0]


def test_real_text_joined_with_itself_is_refused_at_the_second_copy(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = (real_exports / FOLDER / f"{STEM}.txt").read_bytes()
    line = raw.count(b"\n") + 1 + (not raw.endswith(b"\n"))
    for joined in (raw + raw, raw + b"\r\n" + raw):
        p = write(tmp_path, "twice.txt", joined)
        second = joined.index(b'"', len(raw) - 1)
        line = joined[:second].count(b"\n") + 1
        with pytest.raises(AdapterError, match=rf"line {line}: data set .* repeats the data set "
                           r"of line 1"):  # fmt: skip
            read_uvprobe_text(p)


def test_two_data_sets_of_one_title_on_other_wavelengths_are_kept(tmp_path: Path) -> None:
    raw = text(rows="500\t1\r\n501\t2\r\n") + text(rows="600\t1\r\n601\t2\r\n")
    assert len(read_uvprobe_text(write(tmp_path, "two.txt", raw))) == 4


# ----------------------------------------------------------------------------- binary

BASE = "DataStorage1/DataSetGroup/DataSet1"


def _page(title: str, pairs: list[tuple[str, str]]) -> bytes:
    out = struct.pack("<II", 1, 0) + bytes([len(title)]) + title.encode()
    out += struct.pack("<I", len(pairs))
    for k, v in pairs:
        out += bytes([len(k)]) + k.encode() + bytes([len(v)]) + v.encode()
    return out


def spc_streams(
    x: np.ndarray | None = None,
    y: np.ndarray | None = None,
    *,
    mode: str = "Absorbance",
    npoints: int | None = None,
    start_end: tuple[float, float] | None = None,
) -> dict[str, bytes]:
    x = np.array([900.0, 899.0, 898.0]) if x is None else x
    y = np.array([0.1, 0.2, 0.3]) if y is None else y
    se = (x[0], x[-1]) if start_end is None else start_end
    data = f"{BASE}/DataSpectrumStorage"
    return {
        f"{data}/Data/Data Header.1": struct.pack(
            "<ii", len(x) if npoints is None else npoints, 2
        ),
        f"{data}/Data/X Data.1": np.asarray(x, "<f8").tobytes(),
        f"{data}/Data/Y Data.1": np.asarray(y, "<f8").tobytes(),
        f"{data}/DataHeader/Header Info": struct.pack("<3d", se[0], se[1], 1.0) + b"\x00" * 8,
        f"{BASE}/MethodStorage/PageTexts0": _page(
            "[Instrument Properties]", [("Instrument Type:", "UV-1800"), ("Measuring Mode:", mode)]
        ),
    }


def test_synthetic_spc_reads_in_acquisition_order(tmp_path: Path, make_ole2) -> None:
    p = write(tmp_path, "s.spc", make_ole2(spc_streams()))
    assert sniff(p) == ["shimadzu-uvprobe-spc"]
    m = labbrdf.read(p)
    assert m.meta["format"] == "shimadzu-uvprobe-spc"
    assert list(m.data["wavelength_nm"]) == [900.0, 899.0, 898.0]
    assert list(m.data["value"]) == [0.1, 0.2, 0.3]
    assert m.data["sample"].iloc[0] == "s"


@pytest.mark.parametrize(
    ("mode", "quantity", "scale"),
    [("Transmittance", "transmittance", 0.01), ("Reflectance", "reflectance", 0.01)],
)
def test_synthetic_spc_percent_modes(
    tmp_path: Path, make_ole2, mode: str, quantity: str, scale: float
) -> None:
    y = np.array([50.0, 60.0, 70.0])
    m = read_uvprobe_spc(write(tmp_path, "t.spc", make_ole2(spc_streams(y=y, mode=mode))))
    assert m.quantities == [quantity]
    np.testing.assert_allclose(m.data["value"], y * scale, rtol=1e-15)


def test_synthetic_spc_with_two_data_sets(tmp_path: Path, make_ole2) -> None:
    streams = spc_streams()
    streams |= {
        k.replace("DataSet1", "DataSet2"): v for k, v in spc_streams(mode="Transmittance").items()
    }
    m = read_uvprobe_spc(write(tmp_path, "two.spc", make_ole2(streams)))
    assert sorted(set(m.data["sample"])) == ["two #1", "two #2"]


def _drop(streams: dict[str, bytes], suffix: str) -> dict[str, bytes]:
    return {k: v for k, v in streams.items() if not k.endswith(suffix)}


@pytest.mark.parametrize(
    ("streams", "match"),
    [
        ({"Workbook": b"x" * 100}, r"without the UVProbe data storage.*export it as text from UV"),
        (_drop(spc_streams(), "Y Data.1"), r"no stream '.*/Y Data.1'; export it as text"),
        (spc_streams(npoints=4), r"'.*/X Data.1' holds 3 values but the data header says 4"),
        (spc_streams(npoints=0), r"point count 0 in '.*Data Header.1': expected > 0"),
        (spc_streams(npoints=10**9), r"exceeds the limit of 2000000 points"),
        (spc_streams(mode="Energy"), r"measuring mode 'Energy' .* has no labbrdf quantity"),
        (_drop(spc_streams(), "PageTexts0"), r"measuring mode '' .* has no labbrdf quantity"),
        (spc_streams(x=np.array([900.0, 900.0, 898.0])), r"not strictly monotonic"),
        (spc_streams(x=np.array([0.5, 1.0, 2.0])), r"wavelengths 0.5 to 2 nm .* are outside"),
        (spc_streams(start_end=(800.0, 898.0)), r"start wavelength 800 nm of '.*Header Info'"),
        (spc_streams(y=np.array([np.nan] * 3)), r"no valid data points"),
    ],
)
def test_spc_errors_name_file_and_stream(tmp_path: Path, make_ole2, streams, match) -> None:
    p = write(tmp_path, "bad.spc", make_ole2(streams))
    with pytest.raises(AdapterError, match=match) as exc:
        read_uvprobe_spc(p)
    assert str(p) in str(exc.value)


def test_odd_sized_stream_is_refused(tmp_path: Path, make_ole2) -> None:
    streams = spc_streams()
    key = next(k for k in streams if k.endswith("X Data.1"))
    streams[key] += b"\x00"
    with pytest.raises(AdapterError, match=r"is 25 bytes, not a float64 array"):
        read_uvprobe_spc(write(tmp_path, "odd.spc", make_ole2(streams)))


@pytest.mark.parametrize("keep", [512, 1024, 1500, 2000])
def test_truncated_spc_is_refused_with_the_file_named(tmp_path: Path, make_ole2, keep) -> None:
    raw = make_ole2(spc_streams())
    p = write(tmp_path, "cut.spc", raw[:keep])
    with pytest.raises(AdapterError, match=r"cut.spc: .*(corrupt|truncated|no stream)"):
        read_uvprobe_spc(p)


def test_ole2_spc_without_uvprobe_streams_dispatches_to_uvprobe_not_galactic(
    tmp_path: Path, make_ole2
) -> None:
    """An OLE2 .spc goes to the extension's OLE2 format, whose error says what to do."""
    p = write(tmp_path, "other.spc", make_ole2({"Workbook": b"x" * 100}))
    with pytest.raises(AdapterError, match=r"export it as text from UVProbe"):
        labbrdf.read(p)


def test_not_an_ole2_file_is_refused_by_the_spc_reader(tmp_path: Path) -> None:
    p = write(tmp_path, "plain.spc", b"\x00\x4b" + b"\x00" * 600)
    with pytest.raises(AdapterError, match=r"byte 0: expected a Shimadzu UVProbe .spc"):
        read_uvprobe_spc(p)


def test_cli_ingest_of_a_broken_spc_exits_2_naming_the_file(tmp_path: Path, make_ole2, capsys):
    p = write(tmp_path, "broken.spc", make_ole2(spc_streams(mode="Energy")))
    assert main(["ingest", str(p)]) == 2
    err = capsys.readouterr().err
    assert str(p) in err and "measuring mode 'Energy'" in err and "Traceback" not in err


# ---------------------------------------------------------------- damaged OLE2 sector chains

_END = 0xFFFFFFFE


def _fat_entry(raw: bytes, sector: int) -> int:
    """Byte offset of FAT entry ``sector`` (the FAT sectors are listed from byte 76)."""
    fat_sector = struct.unpack_from("<I", raw, 76 + 4 * (sector // 128))[0]
    return 512 * (fat_sector + 1) + 4 * (sector % 128)


def _chain(raw: bytes, stream: str) -> list[int]:
    import olefile

    ole = olefile.OleFileIO(raw)
    sect = ole.direntries[ole._find(stream)].isectStart
    out = []
    while sect != _END:
        out.append(sect)
        sect = ole.fat[sect]
    return out


def _set(raw: bytes, at: int, value: int) -> bytes:
    return raw[:at] + struct.pack("<I", value) + raw[at + 4 :]


_Y = f"{BASE}/DataSpectrumStorage/Data/Y Data.1"
_X = f"{BASE}/DataSpectrumStorage/Data/X Data.1"


@pytest.mark.parametrize(
    ("sector", "value", "match"),
    [  # Y Data.1 holds sectors 20-29, X Data.1 sectors 30-39
        (22, 30, r"chain of stream '.*/Y Data.1' goes on past the 10 sector"),
        (25, 20, r"chain of stream '.*/Y Data.1' visits sector 20 twice \(a loop\)"),
        (39, 30, r"chain of stream '.*/X Data.1' visits sector 30 twice"),
    ],
)
def test_real_spc_with_a_4_byte_fat_edit_is_refused_not_read_as_other_numbers(
    real_exports: Path, tmp_path: Path, sector: int, value: int, match: str
) -> None:
    raw = (real_exports / FOLDER / f"{STEM}.spc").read_bytes()
    assert _chain(raw, _Y) == list(range(20, 30)) and _chain(raw, _X) == list(range(30, 40))
    p = write(tmp_path, f"{STEM}.spc", _set(raw, _fat_entry(raw, sector), value))
    with pytest.raises(AdapterError, match=match) as exc:
        labbrdf.read(p)
    assert str(p) in str(exc.value)


def _big_spc(make_ole2) -> bytes:
    """600 points: X and Y (4800 bytes each) lie in the FAT, not the mini stream."""
    x = np.linspace(900.0, 301.0, 600)
    return make_ole2(spc_streams(x=x, y=np.linspace(0.1, 1.0, 600)))


def test_synthetic_spc_with_a_looped_chain_is_refused(tmp_path: Path, make_ole2) -> None:
    raw = _big_spc(make_ole2)
    y = _chain(raw, _Y)
    p = write(tmp_path, "loop.spc", _set(raw, _fat_entry(raw, y[-1]), y[3]))
    with pytest.raises(AdapterError, match=rf"'.*/Y Data.1' visits sector {y[3]} twice"):
        read_uvprobe_spc(p)


def test_synthetic_spc_whose_chain_runs_into_another_stream_is_refused(
    tmp_path: Path, make_ole2
) -> None:
    """Y's second sector replaced by X's: the right length, but a sector of two streams."""
    raw = _big_spc(make_ole2)
    x, y = _chain(raw, _X), _chain(raw, _Y)
    raw = _set(raw, _fat_entry(raw, y[0]), x[1])
    raw = _set(raw, _fat_entry(raw, x[1]), _END)  # X now ends at its second sector too
    raw = _set(raw, _fat_entry(raw, x[0]), y[1])
    p = write(tmp_path, "cross.spc", raw)
    with pytest.raises(AdapterError, match=r"corrupt: .*(belongs to both|ends after|goes on)"):
        read_uvprobe_spc(p)


def test_spc_whose_tree_holds_an_unused_entry_names_the_file(tmp_path: Path, make_ole2) -> None:
    """olefile lists such a tree with its own OleFileError, which named no file."""
    raw = make_ole2(spc_streams())
    at = raw.index("PageTexts0".encode("utf-16-le")) + 66  # the entry's type byte
    p = write(tmp_path, "unused.spc", raw[:at] + b"\x00" + raw[at + 1 :])
    with pytest.raises(AdapterError, match=r"unused.spc: .*corrupt") as exc:
        labbrdf.read(p)
    assert "OleFileError" not in str(exc.value)
    assert main(["ingest", str(p)]) == 2
