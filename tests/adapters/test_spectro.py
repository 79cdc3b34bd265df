"""Spectrophotometer adapters (JASCO text and .jws, PerkinElmer .asc, Cary CSV, JCAMP-DX, SPC).

Real files come from ../shared/real-exports through the ``real_exports`` fixture (skipped
when absent); every spot value below is quoted from the file line it was checked against.
Synthetic files for the error paths are written into ``tmp_path``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import READERS, AdapterError, sniff
from labbrdf.adapters.cary import read_cary_csv
from labbrdf.adapters.jasco import read_jasco_jws, read_jasco_text
from labbrdf.adapters.jcamp import read_jcamp
from labbrdf.adapters.perkinelmer import read_perkinelmer_asc
from labbrdf.adapters.spc import read_spc

MINE = {
    "jasco-spectramanager-text": "jasco-spectramanager-text",
    "jasco-jws": "jasco-jws-binary",
    "perkinelmer-uvwinlab-asc": "perkinelmer-uvwinlab-asc",
    "agilent-cary-winuv-csv": "agilent-cary-winuv-csv",
    "jcamp-dx": "jcamp-dx",
    "galactic-spc": "galactic-spc",
}

# float32 holds 24 bits: relative round-off of one stored value
F32 = 2.0**-24


def _one(m: labbrdf.Measurement, wavelength: float, sample: str | None = None) -> float:
    d = m.data
    sel = np.isclose(d["wavelength_nm"], wavelength, rtol=0, atol=1e-9)
    if sample is not None:
        sel &= d["sample"] == sample
    assert sel.sum() == 1, f"{sel.sum()} rows at {wavelength} nm"
    return float(d.loc[sel, "value"].iloc[0])


def _common(m: labbrdf.Measurement, quantity: str, n: int, lo: float, hi: float) -> None:
    d = m.data
    assert len(d) == n
    assert set(d["quantity"].astype(str)) == {quantity}
    assert d["wavelength_nm"].min() == pytest.approx(lo, abs=1e-9)
    assert d["wavelength_nm"].max() == pytest.approx(hi, abs=1e-9)
    assert (d["unit"] == "1").all()
    assert d["theta_i_deg"].isna().all() and d["sigma"].isna().all()


# ------------------------------------------------------------------ JASCO text (real)


def test_jasco_text_v730_with_cp932_footer(real_exports: Path) -> None:
    m = read_jasco_text(real_exports / "jasco-spectramanager-text" / "uvvis_abs.txt")
    _common(m, "absorbance", 61, 400.0, 700.0)
    assert _one(m, 700) == -6.38777e-05  # line 19: "700\t-6.38777E-05"
    assert _one(m, 410) == 0.000211082  # line 77: "410\t0.000211082"
    assert _one(m, 400) == -0.00019697  # line 79: "400\t-0.00019697"
    assert m.meta["encoding"] == "cp932"
    # footer "[コメント情報]" / "試料名\ttest" and "[測定情報]" / "機種名\tV-730"
    assert set(m.data["sample"]) == {"test"}
    assert m.meta["footer"]["測定情報"]["機種名"] == "V-730"
    assert m.meta["footer_en"]["photometric mode"] == "Abs"
    assert m.meta["footer_en"]["number of points"] == "61"
    assert m.meta["header"]["SPECTROMETER/DATA SYSTEM"] == "JASCO Corp., V-730, Rev. 1.00"


def test_jasco_text_v570_without_footer(real_exports: Path) -> None:
    m = read_jasco_text(real_exports / "jasco-spectramanager-text" / "PbSe batch 1.txt")
    _common(m, "absorbance", 1801, 700.0, 2500.0)
    assert _one(m, 2500) == 0.10852  # line 19: "2500.0000\t0.10852"
    assert _one(m, 700) == 1.58144  # last line: "700.0000\t1.58144"
    assert set(m.data["sample"]) == {"PbSe batch 1"}  # TITLE is empty: the file stem
    assert m.meta["footer"] == {} and m.meta["encoding"] == "utf-8"


# ------------------------------------------------------------------ JASCO .jws (real)


def test_jws_absorbance_matches_its_text_export(real_exports: Path) -> None:
    """Same measurement in two files: the binary float32 and the 6-digit text agree."""
    b = read_jasco_jws(real_exports / "jasco-jws-binary" / "uvvis_abs.jws")
    t = read_jasco_text(real_exports / "jasco-spectramanager-text" / "uvvis_abs.txt")
    _common(b, "absorbance", 61, 400.0, 700.0)
    yb = b.data.sort_values("wavelength_nm")["value"].to_numpy()
    yt = t.data.sort_values("wavelength_nm")["value"].to_numpy()
    # the text prints 6 significant digits: half a unit of the 6th digit, plus float32
    np.testing.assert_allclose(yb, yt, rtol=5e-6 + F32, atol=0)
    assert b.meta["model"] == "V-730" and b.meta["serial"] == "H470561798"
    assert b.meta["time_utc"] == "2026-06-04T07:08:01+00:00"  # text: 26/06/04 16:08 JST


def test_jws_reflectance_uses_firstx_and_deltax_not_stale_lastx(real_exports: Path) -> None:
    m = read_jasco_jws(real_exports / "jasco-jws-binary" / "uvvis_refl.jws")
    _common(m, "reflectance", 11, 650.0, 700.0)
    assert m.meta["lastx_header_nm"] == 400.0 and not m.meta["lastx_consistent"]
    # bytes 0x740..0x743 = 9a 1a c8 42 = 100.05195617675781 (%R) at FIRSTX 700 nm
    assert _one(m, 700) == pytest.approx(100.05195617675781 / 100, rel=1e-15)


def test_jws_transmittance(real_exports: Path) -> None:
    m = read_jasco_jws(real_exports / "jasco-jws-binary" / "uvvis_trans.jws")
    _common(m, "transmittance", 61, 400.0, 700.0)
    # bytes 0x740..0x743 = 32 10 c8 42 = 100.03163146972656 (%T) at 700 nm
    assert _one(m, 700) == pytest.approx(100.03163146972656 / 100, rel=1e-15)


# ------------------------------------------------------------------ PerkinElmer (real)


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
    real_exports: Path, name: str, n: int, lo: float, hi: float, spot: dict, sphere: int
) -> None:
    m = read_perkinelmer_asc(real_exports / "perkinelmer-uvwinlab-asc" / name)
    # %T with the sphere stays transmittance (there is no hemispherical transmittance)
    _common(m, "transmittance", n, lo, hi)
    for wl, percent in spot.items():
        assert _one(m, wl) == pytest.approx(percent / 100, rel=1e-15)
    assert m.meta["sphere"] is bool(sphere)
    assert m.meta["instrument_model"] == "Lambda 1050" and m.meta["gr"]["npoints"] == n


# ------------------------------------------------------------------ Cary (real)


def test_cary_single_sample(real_exports: Path) -> None:
    m = read_cary_csv(real_exports / "agilent-cary-winuv-csv" / "CuPCtS_H2O_vis.csv")
    _common(m, "absorbance", 141, 200.0188751, 899.9957886)
    assert _one(m, 899.9957886) == 0.03348613903  # line 3: "899.9957886,0.03348613903,"
    assert _one(m, 200.0188751) == 0.6591586471  # line 143: "200.0188751,0.6591586471,"
    (s,) = m.meta["samples"]
    assert s["name"] == "sample1" and s["collection_time"] == "2014-01-15T16:59:54"
    assert s["parameters"]["Instrument"] == "Cary 50"
    assert s["parameters"]["UV-Vis Data Interval (nm)"] == "5.00"


FILTER_POINTS = {
    "600LP": 121,
    "600LP1": 196,  # scan stopped at 455 nm of 450 ("<Current Wavelength> , 455.0")
    "600LP2": 301,
    "550LP": 301,
    "600SP800N": 301,
    "600SP800N1": 301,
    "530SP": 301,
    "GSBS": 301,
    "550LP2": 301,
    "530SP2": 401,
    "530SP_HI": 101,
}


def test_cary_eleven_samples_ragged_mixed_modes(real_exports: Path) -> None:
    m = read_cary_csv(real_exports / "agilent-cary-winuv-csv" / "filters.csv")
    d = m.data
    assert d.groupby("sample", sort=False).size().to_dict() == FILTER_POINTS
    q = d.groupby("sample", sort=False)["quantity"].first().astype(str)
    assert q["600LP"] == "absorbance" and (q.drop("600LP") == "transmittance").all()
    # line 3: "800.0541382,0.02885507233,650.0537109,93.92353058,..."
    assert _one(m, 800.0541382, "600LP") == 0.02885507233
    assert _one(m, 650.0537109, "600LP1") == pytest.approx(0.9392353058, rel=1e-15)
    meta = {s["name"]: s for s in m.meta["samples"]}
    assert meta["600LP1"]["padding_rows"] == 401 - 196  # the longest column has 401 rows
    assert meta["600LP"]["collection_time"] == "2018-05-10T17:14:12"  # line 407
    assert meta["530SP_HI"]["collection_time"] == "2018-05-10T17:26:59"  # line 803
    assert m.meta["dropped_points"] == 0
    assert d["wavelength_nm"].min() == pytest.approx(199.9654236)


# ------------------------------------------------------------------ JCAMP-DX (real)


def test_jcamp_link_file_five_pac_blocks(real_exports: Path) -> None:
    m = read_jcamp(real_exports / "jcamp-dx" / "blckpac1.jdx")
    _common(m, "absorbance", 5 * 176, 350.0, 700.0)
    titles = [f"Aquation of trans-[Co(en)2Cl2]+ (t{k})" for k in range(1, 6)]
    assert list(m.data["sample"].unique()) == titles
    yfactor = 0.00000011920928955078  # "##YFACTOR= .00000011920928955078"
    # line 28: "  700.000000  -51473   -43386 ..."; line 63: "  350.000000  1622710"
    assert _one(m, 700, titles[0]) == pytest.approx(-51473 * yfactor, rel=1e-15)
    assert _one(m, 698, titles[0]) == pytest.approx(-43386 * yfactor, rel=1e-15)
    assert _one(m, 350, titles[0]) == pytest.approx(1622710 * yfactor, rel=1e-15)
    # line 299: "  350.000000  1483643" (block 5)
    assert _one(m, 350, titles[4]) == pytest.approx(1483643 * yfactor, rel=1e-15)
    assert m.meta["link"]["BLOCKS"] == "5" and len(m.meta["blocks"]) == 5


def test_jcamp_sqz_dif_dup_with_y_checks(real_exports: Path) -> None:
    m = read_jcamp(real_exports / "jcamp-dx" / "dupinc1.jdx")
    _common(m, "absorbance", 440, 250.0, 469.5)
    # line 19 "2500A1663l68k60..." with XFACTOR .1, YFACTOR .0001: 1.1663, 1.1295, 1.1035
    assert _one(m, 250.0) == pytest.approx(1.1663, rel=1e-12)
    assert _one(m, 250.5) == pytest.approx(1.1295, rel=1e-12)
    assert _one(m, 251.0) == pytest.approx(1.1035, rel=1e-12)
    # last line "4695A626" is the Y check of the point at 469.5 nm: 1626 * .0001
    assert _one(m, 469.5) == pytest.approx(0.1626, rel=1e-12)


def test_jcamp_against_the_jcamp_package(real_exports: Path) -> None:
    jcamp = pytest.importorskip("jcamp")
    for name in ("blckpac1.jdx", "dupinc1.jdx"):
        ours = read_jcamp(real_exports / "jcamp-dx" / name).data
        read = getattr(jcamp, "jcamp_readfile", None) or jcamp.readfile
        theirs = read(str(real_exports / "jcamp-dx" / name))
        parts = theirs.get("children", [theirs])
        y = np.concatenate([np.asarray(p["y"], float) for p in parts])
        np.testing.assert_allclose(ours["value"], y, rtol=1e-12)


# ------------------------------------------------------------------ SPC (real)


def test_spc_holmium(real_exports: Path) -> None:
    m = read_spc(real_exports / "galactic-spc" / "HOLMIUM.SPC")
    _common(m, "absorbance", 901, 250.0, 700.0)
    # first Y at byte 0x220: a8 a4 4a 00 = 4891816, exponent 10: 4891816 * 2**(10 - 32)
    assert _one(m, 250.0) == 4891816 * 2.0**-22
    # last Y at byte 0x1030: d4 09 04 00 = 264660
    assert _one(m, 700.0) == 264660 * 2.0**-22
    assert set(m.data["sample"]) == {"Holmium Oxide Glass, the UV standard"}
    assert m.meta["date"] == "1992-03-04T14:31:00" and m.meta["resolution"] == ".5"


def test_spc_and_jcamp_hold_the_same_holmium_spectrum(real_exports: Path) -> None:
    """dupinc1.jdx (250-469.5 nm, 4 decimals) is the same holmium glass scan as HOLMIUM.SPC.

    Two independent decoders (SQZ/DIF/DUP text, scaled int32 binary) must agree to the
    SPC quantum 2**-22 (the JCAMP values are exact 4-decimal numbers; the SPC integer is
    within one quantum of them, and the two files were rounded independently: 2 quanta).
    Two points differ by far more in the files themselves (dupinc1 was hand re-encoded
    with DXEDIT): 386 nm and 455 nm, where 0.984 vs 0.948 is a digit swap.
    """
    spc = read_spc(real_exports / "galactic-spc" / "HOLMIUM.SPC").data
    jdx = read_jcamp(real_exports / "jcamp-dx" / "dupinc1.jdx").data
    on = spc.set_index("wavelength_nm")["value"].loc[jdx["wavelength_nm"]].to_numpy()
    diff = np.abs(on - jdx["value"].to_numpy())
    off = jdx["wavelength_nm"].to_numpy()[diff > 2 * 2.0**-22]
    assert off.tolist() == [386.0, 455.0]
    assert diff.max() == pytest.approx(0.036, abs=1e-4)


def test_spc_against_spc_io(real_exports: Path) -> None:
    spc_io = pytest.importorskip("spc_io")
    import io

    raw = (real_exports / "galactic-spc" / "HOLMIUM.SPC").read_bytes()
    sub = spc_io.SPC.from_bytes_io(io.BytesIO(raw))[0]
    ours = read_spc(real_exports / "galactic-spc" / "HOLMIUM.SPC").data
    np.testing.assert_allclose(ours["wavelength_nm"], sub.xarray, rtol=1e-15)
    np.testing.assert_allclose(ours["value"], sub.yarray, rtol=F32)


# ------------------------------------------------------------------ dispatch


def _real_files(real_exports: Path) -> list[Path]:
    return sorted(p for p in real_exports.glob("*/*") if p.name != "PROVENANCE.md")


def test_dispatch_without_format_picks_our_adapter(real_exports: Path) -> None:
    n = 0
    for fmt, folder in MINE.items():
        for path in sorted((real_exports / folder).iterdir()):
            via_read = labbrdf.read(path)
            direct = READERS[fmt].read(path)
            assert via_read.data.equals(direct.data), path.name
            assert via_read.meta["format"] == fmt, path.name
            n += 1
    # 13 of the first collection + "F4-P3HT 1-10 0,5 mgml.Probe.Raw.asc" (added later)
    # + the legacy (OLE2) "legacy_trans_512.jws"
    assert n == 15


def test_our_sniffers_claim_exactly_our_own_real_files(real_exports: Path) -> None:
    """Sniffing is what separates .txt (JASCO, Film Sense, SENTECH) and .csv files."""
    for path in _real_files(real_exports):
        head = path.read_bytes()[:8192]
        claimed = {fmt for fmt in MINE if READERS[fmt].sniff(head)}
        owner = {fmt for fmt, folder in MINE.items() if folder == path.parent.name}
        assert claimed == owner, path.name
        if owner:
            assert set(sniff(path)) & set(READERS) >= owner


@pytest.mark.parametrize("fmt", sorted(MINE))
def test_forcing_our_format_on_other_real_files_raises(real_exports: Path, fmt: str) -> None:
    for path in _real_files(real_exports):
        if path.parent.name == MINE[fmt]:
            continue
        with pytest.raises(AdapterError, match=r"(line|byte) \d+|expected|no |not "):
            labbrdf.read(path, format=fmt)


@pytest.mark.parametrize("fmt", sorted(MINE))
def test_empty_missing_and_garbage_files_raise(tmp_path: Path, fmt: str) -> None:
    empty = tmp_path / "empty.x"
    empty.write_bytes(b"")
    with pytest.raises(AdapterError, match="the file is empty"):
        READERS[fmt].read(empty)
    with pytest.raises(AdapterError, match="cannot be read"):
        READERS[fmt].read(tmp_path / "missing.x")
    with pytest.raises(AdapterError, match="is a directory"):
        READERS[fmt].read(tmp_path)
    garbage = tmp_path / "garbage.x"
    garbage.write_bytes(np.random.default_rng(7).integers(0, 256, 4096, dtype=np.uint8).tobytes())
    with pytest.raises(AdapterError, match=str(garbage.name)):
        READERS[fmt].read(garbage)
