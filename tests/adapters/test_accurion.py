"""Accurion EP4 ``.dat`` exports: both layouts, zones and positions, columns found by name,
and the errors of bad rows.

Spot values are checked against numbers read by hand from the real exports (the line checked
is quoted in a comment), at ``approx`` (rel 1e-12, see conftest.py): the files print at most
9 significant digits, so any parsing or unit slip shows at 1e-7 or worse, and 1e-12 leaves
room only for float64 round-off of the conversions. Bad input raises ``AdapterError`` naming
the file and, where it makes sense, the line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError
from labbrdf.adapters.accurion import read_accurion

ACC = "accurion-ep4-dat"


def _rows(m: labbrdf.Measurement, quantity: str, aoi: float, x: float, y: float):
    d = m.data
    sel = (
        (d["quantity"] == quantity)
        & np.isclose(d["theta_i_deg"], aoi, rtol=0, atol=1e-9)
        & np.isclose(d["x_mm"], x, rtol=0, atol=1e-9)
        & np.isclose(d["y_mm"], y, rtol=0, atol=1e-9)
    )
    return d[sel]


def test_post_synthesis_map_reads_zones_1_to_4_with_positions(real_exports: Path) -> None:
    m = labbrdf.read(real_exports / ACC / "post synthesis.dat")
    assert m.meta["format"] == "accurion-ep4"
    # 960 data lines, 160 per zone 0..5: zones 1-4 kept, two rows (psi, delta) each
    assert len(m) == 2 * 4 * 160
    assert m.meta["data_zones"] == [1, 2, 3, 4]
    # line 3: "658.0 2.0 50.000 143.615 34.702 4 34.626 63.213 30.000 63.213 000 -18.183
    # -30.305 0.000" (Lambda Bandwidth AOI Delta Psi Zone ... X_pos Y_pos Theta_pos)
    psi = _rows(m, "psi", 50.0, -18.183, -30.305)["value"].to_numpy()
    delta = _rows(m, "delta", 50.0, -18.183, -30.305)["value"].to_numpy()
    assert 34.702 in psi.tolist() and 143.615 in delta.tolist()
    assert set(m.data["wavelength_nm"]) == {658.0}
    assert sorted(set(m.data["theta_i_deg"])) == pytest.approx([50.0, 53.6, 57.2, 60.8, 64.4])


@pytest.mark.parametrize("cut", ["after the TAB behind Y_pos", "empty Zone", "empty X_pos"])
def test_row_with_an_empty_field_is_refused(real_exports: Path, tmp_path: Path, cut: str) -> None:
    raw = (real_exports / ACC / "post synthesis.dat").read_bytes()
    # line 3: "658.0 2.0 50.000 143.615 34.702 4 34.626 63.213 30.000 63.213 000 -18.183
    # -30.305 0.000" (... X_pos Y_pos Theta_pos)
    head = b"658.0\t2.0\t50.000\t143.615\t34.702\t4\t34.626\t63.213\t30.000\t63.213\t000\t"
    line3 = head + b"-18.183\t-30.305\t0.000"
    new = {
        "after the TAB behind Y_pos": head + b"-18.183\t-30.305\t",
        "empty Zone": line3.replace(b"\t4\t", b"\t\t"),
        "empty X_pos": head + b"\t-30.305\t0.000",
    }[cut]
    start = raw.index(line3)
    bad = tmp_path / "cut.dat"
    bad.write_bytes(raw[:start] + new + raw[start + len(line3) :])
    with pytest.raises(AdapterError, match=r"line 3: field \d+ \(\w+\) is empty"):
        labbrdf.read(bad)


def test_zone_numbers_are_kept_so_rows_of_one_spot_and_angle_differ(real_exports: Path) -> None:
    d = labbrdf.read(real_exports / "accurion-ep4-dat" / "15-1-1.dat").data
    assert "zone" in d.columns
    at50 = d[(d["theta_i_deg"] == 50.0) & (d["quantity"] == "psi")]
    # lines 3-6: zone 4 Psi 31.474, zone 2 31.291, ... (zones 0 and 5 are not data rows)
    assert sorted(at50["zone"]) == [1.0, 2.0, 3.0, 4.0]
    assert at50.loc[at50["zone"] == 2, "value"].item() == pytest.approx(31.291, abs=5e-4)
    assert at50.loc[at50["zone"] == 4, "value"].item() == pytest.approx(31.474, abs=5e-4)
    key = ["quantity", "wavelength_nm", "theta_i_deg", "x_mm", "y_mm", "zone"]
    assert not d.duplicated(key).any()


def test_accurion_old_layout_zone_rows_and_positions(real_exports, load):
    m = load(real_exports, f"{ACC}/15-1-1.dat")
    d = m.data
    # line 3: 658.0 2.0 50.000 169.624 31.474 4 ... 000 2.927 -6.980 -15.123 (Delta first)
    r = d[(d["quantity"] == "psi") & (d["value"] == 31.474)]
    assert len(r) == 1
    r = r.iloc[0]
    assert (r["theta_i_deg"], r["time_s"], r["x_mm"], r["y_mm"]) == (50.0, 2.927, -6.98, -15.123)
    assert m.meta["data_zones"] == [1, 2, 3, 4]
    dropped = {(x.get("zone"), x["count"]) for x in m.meta["dropped_rows"]}
    assert dropped == {(0, 11), (5, 11), (None, 3)}  # 3 = zone 4 NaN at 66/68/70 deg
    # 11 AOIs x 4 zones - 3 failed zones = 41 rows each of psi and delta
    assert (d.groupby("quantity", observed=True).size() == 41).all()


def test_accurion_zone5_is_peak_to_peak_spread_and_zone0_the_mean(real_exports, load):
    """Documented finding: zone 5 = max - min of the zone values, zone 0 = their mean."""
    m = load(real_exports, f"{ACC}/15-1-1.dat")
    d = m.data
    text = (real_exports / ACC / "15-1-1.dat").read_text()
    zone0 = {}
    for line in text.splitlines()[2:]:
        f = line.split("\t")
        if f[5] == "0" and f[4] != "NaN":
            zone0[float(f[2])] = float(f[4])
    for s in m.meta["zone_spread"]:
        psi = d[(d["quantity"] == "psi") & (d["theta_i_deg"] == s["aoi_deg"])]["value"]
        # 3 decimals printed: each zone value +-0.0005, the spread +-0.0005 -> 0.0015
        assert np.ptp(psi) == pytest.approx(s["psi_pp_deg"], abs=0.0015)
        if s["aoi_deg"] in zone0:
            assert psi.mean() == pytest.approx(zone0[s["aoi_deg"]], abs=0.001)


def test_accurion_new_layout_latin1_units_and_columns_by_name(real_exports, load, pick, approx):
    m = load(real_exports, f"{ACC}/Si3N4_on_4inBF33_W02_20240903-150451.ds.dat")
    assert m.meta["encoding"] == "latin-1" and "\u00b5m" in m.meta["units"]
    # line 3: 0  40.000  365.0  6.1  115908  417.6  409.8  179.785156  32.535931
    assert pick(m, "psi", 365.0, 40.0)["value"] == approx(32.535931)
    assert pick(m, "delta", 365.0, 40.0)["value"] == approx(179.785156)
    assert "x_mm" not in m.data.columns  # ROI_x/ROI_y are camera positions, not the stage
    assert m.data["sample"].iloc[0] == "Si3N4_on_4inBF33_W02_20240903-150451"


def test_accurion_corefine_spectroscopic_zones(real_exports, load):
    m = load(real_exports, f"{ACC}/corefine_PNIPAM_ellipsometry.dat")
    d = m.data
    # line 3: 380.0  6.0  40.000  162.859  41.174  4  ...  -8.000  -16.836
    rows = d[(d["quantity"] == "psi") & (d["wavelength_nm"] == 380.0) & (d["theta_i_deg"] == 40)]
    assert 41.174 in set(rows["value"]) and len(rows) == 4  # four zones
    assert (d["x_mm"] == -8.0).all()
    assert sorted(d["wavelength_nm"].unique())[::5] == [380.0, 665.0, 950.0]


def test_accurion_wvase_format_export(real_exports, load, pick, approx):
    m = load(real_exports, f"{ACC}/testData1_11nm_PNIPAM_on_Si_EP4.dat")
    # line 3: 658.0  55.0  27.700  170.200
    assert pick(m, "psi", 658.0, 55.0)["value"] == approx(27.7)
    assert pick(m, "delta", 658.0, 55.0)["value"] == approx(170.2)
    assert m.meta["variant"] == "ep4-wvase-format"
    assert m.data["sample"].iloc[0] == "04_12_1_PNIPAM_map_Polymer Brush_0.0x0.0y_WVASEformat"


def test_accurion_columns_matched_by_name_when_swapped(real_exports, tmp_path, load):
    src = (real_exports / ACC / "15-1-1.dat").read_text()
    out = []
    for line in src.splitlines():
        f = line.split("\t")
        f[3], f[4] = f[4], f[3]  # put Psi before Delta in header, units and data
        out.append("\t".join(f))
    p = tmp_path / "swapped.dat"
    p.write_text("\n".join(out))
    a = load(real_exports, f"{ACC}/15-1-1.dat").data
    b = labbrdf.read(p).data
    np.testing.assert_array_equal(a["value"], b["value"])
    assert list(a["quantity"]) == list(b["quantity"])


ACC_HEAD = b"#Lambda\tAOI\tDelta\tPsi\tZone\n#nm\tdeg\tdeg\tdeg\t-\n"


def test_accurion_bad_input(tmp_path, write, raises):
    def raises_acc(*a, **kw):
        return raises(*a, reader=read_accurion, **kw)

    row = b"500\t60\t150\t20\t1\n"
    raises_acc(
        write(tmp_path, "c.dat", ACC_HEAD.replace(b"\tPsi", b"\tPhi") + row),
        r"missing column\(s\) \['Psi'\]",
        1,
    )
    raises_acc(
        write(tmp_path, "u.dat", ACC_HEAD.replace(b"#nm", b"#um") + row),
        "column 'Lambda' has unit 'um', expected 'nm'",
        2,
    )
    raises_acc(
        write(tmp_path, "l.dat", ACC_HEAD.replace(b"\t-\n", b"\n") + row),
        "unit row has 4 entries for 5",
        2,
    )
    raises_acc(
        write(tmp_path, "d.dat", ACC_HEAD.replace(b"\tZone", b"\tAOI") + row), "duplicate", 1
    )
    raises_acc(
        write(tmp_path, "f.dat", ACC_HEAD + row + b"500\t60\t150\t20\n"), "expected 5 TAB", 4
    )
    raises_acc(write(tmp_path, "z.dat", ACC_HEAD + row + b"500\t60\t150\t20\t7\n"), "Zone", 4)
    raises_acc(
        write(tmp_path, "n.dat", ACC_HEAD + b"500\t60\tNaN\tNaN\t1\n"), "no valid Psi/Delta"
    )
    raises_acc(write(tmp_path, "p.dat", ACC_HEAD + b"500\t60\t150\t-2\t1\n"), "Psi must be", 3)
    raises_acc(write(tmp_path, "x.dat", ACC_HEAD + b"500\t60\t150\t2o\t1\n"), "'2o'", 3)
    raises_acc(write(tmp_path, "h.dat", ACC_HEAD), "no data rows")


def test_accurion_fallback_to_zone0_when_no_zone_rows(tmp_path, write):
    p = write(tmp_path, "z0.dat", ACC_HEAD + b"500\t60\t150\t20\t0\n500\t60\t0.2\t0.1\t5\n")
    m = read_accurion(p)
    assert m.meta["data_zones"] == [0] and len(m) == 2


def test_accurion_row_of_only_tabs_is_skipped_and_counted(tmp_path, write):
    # upstream corefine_polyBrush_ellipsometry.dat has such an empty first data row
    p = write(tmp_path, "t.dat", ACC_HEAD + b"\t\t\t\t\n500\t60\t150\t20\t1\n")
    m = read_accurion(p)
    assert len(m) == 2 and m.meta["blank_lines_skipped"] == 1
