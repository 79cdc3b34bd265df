"""What the ellipsometer adapters (Woollam, Accurion EP4, Film Sense, SENTECH) share.

Every real export of these formats in ``shared/real-exports`` is read through
``labbrdf.read`` (dispatch by extension + sniffing) with the expected format and row count;
sniffers never raise; line endings, a BOM and the final newline change nothing; the fast and
slow block parsers agree; reading writes nothing; every reader refuses empty, binary and
missing files and another vendor's file. Each vendor's own checks are in its file
(``test_woollam.py``, ``test_accurion.py``, ``test_filmsense.py``, ``test_sentech.py``).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import READERS, AdapterError, sniff
from labbrdf.adapters._frame import group_angles
from labbrdf.adapters._numblock import _fast, _slow, parse_block, split_head
from labbrdf.adapters.accurion import read_accurion
from labbrdf.adapters.filmsense import read_filmsense
from labbrdf.adapters.sentech import read_sentech
from labbrdf.adapters.woollam import read_woollam

WVASE = "woollam-wvase-ascii"
CEASE = "woollam-completeease-ascii"
ACC = "accurion-ep4-dat"
FS = "filmsense-txt"
ST = "sentech-spectraray-ascii"

#: file -> (format name, instrument column, rows, quantities)
EXPECTED = {
    f"{WVASE}/w2_10102006.dat": ("woollam-wvase", 4056, {"psi", "delta"}),
    f"{WVASE}/wafer_2_01242007.dat": ("woollam-wvase", 6084, {"psi", "delta", "depolarization"}),
    f"{WVASE}/ta2o5_02262007_rp.dat": ("woollam-wvase", 676, {"reflectance"}),
    f"{WVASE}/w1_al2o3_20081120_anisotropy.dat": ("woollam-wvase", 24336, {"psi", "delta"}),
    f"{WVASE}/wvase_example.dat": ("woollam-wvase", 1370, {"psi", "delta", "depolarization"}),
    f"{CEASE}/complete_ease_example.dat": (
        "woollam-completeease",
        9792,
        {"psi", "delta", "depolarization"},
    ),
    f"{CEASE}/Woolam_staticTest.dat": (
        "woollam-completeease",
        1592,
        {"psi", "delta", "depolarization", "specular_intensity"},
    ),
    f"{CEASE}/Woolam_kineticTest.dat": ("woollam-completeease", 5572, {"psi", "delta"}),
    f"{ACC}/15-1-1.dat": ("accurion-ep4", 82, {"psi", "delta"}),
    f"{ACC}/corefine_PNIPAM_ellipsometry.dat": ("accurion-ep4", 616, {"psi", "delta"}),
    f"{ACC}/Si3N4_on_4inBF33_W02_20240903-150451.ds.dat": ("accurion-ep4", 228, {"psi", "delta"}),
    f"{ACC}/testData1_11nm_PNIPAM_on_Si_EP4.dat": ("accurion-ep4", 8, {"psi", "delta"}),
    f"{FS}/Filmsense_staticTest.txt": ("filmsense", 24, {"psi", "delta", "depolarization"}),
    f"{FS}/Filmsense_kineticTest.txt": ("filmsense", 168, {"psi", "delta", "depolarization"}),
    f"{ST}/Si_SiO2_theta_50_60_70.txt": ("sentech-spectraray", 13254, {"psi", "delta"}),
    f"{ST}/Wafer_MM_70.txt": (
        "sentech-spectraray",
        35344,
        {f"mueller_{i}{j}" for i in range(1, 5) for j in range(1, 5)},
    ),
}

# ----------------------------------------------------------------------------- dispatch


@pytest.mark.parametrize("rel", sorted(EXPECTED))
def test_every_real_file_dispatches_to_its_adapter_with_expected_rows(real_exports, rel, load):
    fmt, rows, quantities = EXPECTED[rel]
    assert sniff(real_exports / rel) == [fmt]
    m = load(real_exports, rel)
    assert len(m) == rows
    assert set(m.quantities) == quantities
    assert set(m.data["instrument"]) == {READERS[fmt].name}
    assert set(m.data["source"]) == {Path(rel).name}
    # every ellipsometer row is specular: theta_r = theta_i, phi_r = 180 deg
    d = m.data
    assert (d["theta_r_deg"] == d["theta_i_deg"]).all()
    assert (d["phi_r_deg"] == 180.0).all()
    # Delta canonical range
    delta = d.loc[d["quantity"] == "delta", "value"]
    assert ((delta >= 0) & (delta < 360)).all()


@pytest.mark.parametrize("rel", sorted(EXPECTED))
def test_meta_of_every_real_file_is_json_safe_and_names_the_source(real_exports, rel, load):
    import json

    m = load(real_exports, rel)
    assert m.meta["source_file"] == Path(rel).name
    json.dumps(m.meta, allow_nan=False)


def test_dat_and_txt_extensions_are_shared_so_sniffers_must_discriminate():
    dat = [n for n, f in READERS.items() if ".dat" in f.extensions]
    txt = [n for n, f in READERS.items() if ".txt" in f.extensions]
    assert {"woollam-wvase", "woollam-completeease", "accurion-ep4"} <= set(dat)
    assert {"filmsense", "sentech-spectraray"} <= set(txt)


@pytest.mark.parametrize(
    "name",
    ["woollam-wvase", "woollam-completeease", "accurion-ep4", "filmsense", "sentech-spectraray"],
)
def test_sniffers_never_raise_on_junk(name):
    for head in (b"", b"\x00\xff\xfe", b"\n\n\n", bytes(range(256)), b"VASEmethod[" * 1000):
        assert READERS[name].sniff(head) in (True, False)


# ----------------------------------------------------------------------------- line ends etc.


@pytest.mark.parametrize(
    "rel",
    [
        f"{WVASE}/w2_10102006.dat",
        f"{ACC}/Si3N4_on_4inBF33_W02_20240903-150451.ds.dat",
        f"{FS}/Filmsense_staticTest.txt",
        f"{ST}/Si_SiO2_theta_50_60_70.txt",
        f"{CEASE}/Woolam_staticTest.dat",
    ],
)
@pytest.mark.parametrize("eol", [b"\n", b"\r\n", b"\r"])
def test_line_endings_bom_and_final_newline_do_not_change_the_result(
    real_exports, tmp_path, rel, eol, load
):
    raw = (real_exports / rel).read_bytes()
    lines = raw.replace(b"\r\n", b"\n").split(b"\n")
    p = tmp_path / Path(rel).name
    p.write_bytes(b"\xef\xbb\xbf" + eol.join(lines) + eol)
    a = load(real_exports, rel).data
    b = labbrdf.read(p).data
    np.testing.assert_array_equal(a["value"].to_numpy(), b["value"].to_numpy())
    np.testing.assert_array_equal(a["wavelength_nm"].to_numpy(), b["wavelength_nm"].to_numpy())


@pytest.mark.parametrize("rel", sorted(r for r in EXPECTED if not r.startswith(FS)))
def test_fast_and_slow_parsers_agree_on_real_files(real_exports, rel):
    text = (real_exports / rel).read_text(encoding="latin-1")
    nhead = {FS: 2, ST: 1}.get(rel.split("/")[0], 4)
    if rel.startswith(ACC) or "complete_ease" in rel:
        nhead = 2 if rel.startswith(ACC) else 3
    if rel.startswith(CEASE) and "complete_ease" not in rel:
        nhead = 4 if "kinetic" in rel else 3
    _, body = split_head(text, nhead)
    sep = None if rel.startswith(ST) else "\t"
    ncols = 17 if rel.startswith(ST) else 14
    tagged = rel.startswith((WVASE, CEASE))
    fast = _fast(body, body.encode(), nhead + 1, ncols, sep, tagged, sep is not None)
    assert fast is not None
    slow = _slow(rel, body, nhead + 1, ncols, sep, tagged)
    np.testing.assert_array_equal(fast.values, slow.values)
    np.testing.assert_array_equal(fast.lines, slow.lines)
    if tagged and fast.tags is None:  # no tag in the block
        assert set(slow.tags) == {""}
    elif tagged:
        assert list(fast.tags) == list(slow.tags)
    if sep is not None:
        np.testing.assert_array_equal(fast.nfields, slow.nfields)


def test_reading_writes_nothing(real_exports, tmp_path):
    for rel in (
        f"{WVASE}/wvase_example.dat",
        f"{ACC}/15-1-1.dat",
        f"{FS}/Filmsense_staticTest.txt",
        f"{ST}/Wafer_MM_70.txt",
    ):
        shutil.copy(real_exports / rel, tmp_path)
    before = {p.name: (p.stat().st_mtime_ns, p.stat().st_size) for p in tmp_path.iterdir()}
    for p in sorted(tmp_path.iterdir()):
        labbrdf.read(p)
    after = {p.name: (p.stat().st_mtime_ns, p.stat().st_size) for p in tmp_path.iterdir()}
    assert before == after


def test_group_angles_groups_goniometer_readings_without_rounding_data():
    g = group_angles([64.999634, 64.999634, 69.999718, 70.0001, np.nan, 75.0])
    assert [x["nominal"] for x in g] == [65.0, 70.0, 75.0]
    assert g[1] == {"nominal": 70.0, "min": 69.999718, "max": 70.0001, "rows": 2}
    assert group_angles([]) == []


# ----------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "reader", [read_woollam, read_accurion, read_filmsense, read_sentech], ids=lambda f: f.__name__
)
def test_every_reader_rejects_empty_binary_and_missing_files(tmp_path, reader, write, raises):
    raises(write(tmp_path, "e.dat", b""), "empty", reader=reader)
    raises(write(tmp_path, "w.dat", b"  \r\n\t\n"), "empty", reader=reader)
    raises(write(tmp_path, "b.dat", b"\x00\x01\x02garbage\xff" * 20), "binary", 1, reader=reader)
    raises(
        write(tmp_path, "u16.dat", "; WAVELENGTH 50\n".encode("utf-16")),
        "binary",
        1,
        reader=reader,
    )
    raises(tmp_path / "nope.dat", "cannot be read", reader=reader)
    raises(tmp_path, "directory", reader=reader)


@pytest.mark.parametrize(
    "rel, fmt, match",
    [
        (f"{ST}/Wafer_MM_70.txt", "woollam-wvase", "no VASEmethod"),
        (f"{WVASE}/w2_10102006.dat", "accurion-ep4", "expected a '#' column-name row"),
        (f"{ACC}/15-1-1.dat", "filmsense", "expected 'Film_Sense_Data'"),
        (f"{FS}/Filmsense_staticTest.txt", "sentech-spectraray", "WAVELENGTH"),
        (f"{ACC}/testData1_11nm_PNIPAM_on_Si_EP4.dat", "woollam-completeease", "no VASEmethod"),
        (f"{CEASE}/complete_ease_example.dat", "sentech-spectraray", "WAVELENGTH"),
    ],
)
def test_file_of_another_vendor_forced_with_format_is_refused(
    real_exports, rel, fmt, match, raises
):
    e = raises(real_exports / rel, match, reader=labbrdf.read, format=fmt)
    assert e.line is not None


def test_categorical_frames_of_the_adapters_are_still_validated_row_by_row():
    from labbrdf.adapters._frame import build_frame, labels, measurement

    kw = dict(instrument="i", source="f", value=[1.0, 2.0], wavelength_nm=500.0)
    ok = measurement("f", build_frame(sample="s", quantity="psi", unit="deg", **kw), {})
    assert ok.data["sample"].dtype == object and len(ok) == 2
    with pytest.raises(AdapterError, match="'sample': expected a non-empty string in rows 0, 1"):
        measurement("f", build_frame(sample="", quantity="psi", unit="deg", **kw), {})
    q = labels(["psi", "reflectance"], [1, 1])
    with pytest.raises(AdapterError, match="'deg' does not fit quantity 'reflectance'.*rows 1"):
        measurement("f", build_frame(sample="s", quantity=q, unit="deg", **kw), {})
    with pytest.raises(AdapterError, match=r"unknown quantity \['rho'\] in rows 1"):
        measurement(
            "f",
            build_frame(sample="s", quantity=labels(["psi", "rho"], [1, 1]), unit="deg", **kw),
            {},
        )


def test_parse_block_reports_lines_in_slow_path_for_lone_cr_and_blank_lines():
    body = "1\t2\r\r3\t4\r\n\t\t\n5\tx"
    with pytest.raises(AdapterError, match="expected a number, found 'x'") as ei:
        parse_block("f", body, 10, 2)
    assert ei.value.line == 14  # lines 10, 11 (empty), 12, 13 (tabs only), 14
    b = parse_block("f", body[:-3], 10, 2)
    np.testing.assert_array_equal(b.lines, [10, 12])
    assert b.blank_lines == 2
