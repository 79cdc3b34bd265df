"""Ellipsometer adapters: Woollam (WVASE32, CompleteEASE), Accurion EP4, Film Sense, SENTECH.

Every real export of these formats in ``shared/real-exports`` is read through
``labbrdf.read`` (dispatch by extension + sniffing) and checked against numbers read by hand
from the file: the line checked is quoted in a comment. Values are compared with
``rel=1e-12``: the files print at most 9 significant digits, so any parsing or unit slip
shows at 1e-7 or worse, and 1e-12 leaves room only for float64 round-off of the
conversions (eV -> nm, % -> fraction, arccos). Bad input of every kind must raise
``AdapterError`` naming the file and, where it makes sense, the line.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import READERS, AdapterError, sniff
from labbrdf.adapters._numblock import _fast, _slow, group_angles, parse_block, split_head
from labbrdf.adapters.accurion import read_accurion
from labbrdf.adapters.filmsense import filmsense_psi_delta, read_filmsense
from labbrdf.adapters.sentech import read_sentech
from labbrdf.adapters.woollam import WVASE_HC_EV_NM, parse_method, read_woollam

REL = 1e-12

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

_CACHE: dict[str, labbrdf.Measurement] = {}


def load(real_exports: Path, rel: str) -> labbrdf.Measurement:
    if rel not in _CACHE:
        _CACHE[rel] = labbrdf.read(real_exports / rel)
    return _CACHE[rel]


def pick(m: labbrdf.Measurement, quantity: str, wl: float, aoi: float | None = None, **kw):
    """The single row of ``quantity`` at wavelength ``wl`` (and AOI, channel, time...)."""
    d = m.data
    sel = (d["quantity"] == quantity) & np.isclose(d["wavelength_nm"], wl, rtol=1e-9, atol=0)
    if aoi is not None:
        sel &= np.isclose(d["theta_i_deg"], aoi, rtol=1e-9, atol=0)
    for k, v in kw.items():
        col = d[k]
        sel &= np.isclose(col, v, rtol=1e-9, atol=0) if isinstance(v, float) else col == v
    rows = d[sel]
    assert len(rows) == 1, f"{len(rows)} rows match {quantity} {wl} {aoi} {kw}"
    return rows.iloc[0]


def approx(x: float) -> object:
    return pytest.approx(x, rel=REL, abs=1e-15)


# ----------------------------------------------------------------------------- dispatch


@pytest.mark.parametrize("rel", sorted(EXPECTED))
def test_every_real_file_dispatches_to_its_adapter_with_expected_rows(real_exports, rel):
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
def test_meta_of_every_real_file_is_json_safe_and_names_the_source(real_exports, rel):
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


# ----------------------------------------------------------------------------- WVASE


def test_wvase_psi_delta_spot_values_and_raw_aoi(real_exports):
    m = load(real_exports, f"{WVASE}/w2_10102006.dat")
    # line 5: 245.732520  64.999634  26.418438  112.59465  0.0293538  0.0781373
    psi = pick(m, "psi", 245.73252, 64.999634)
    delta = pick(m, "delta", 245.73252, 64.999634)
    assert psi["value"] == approx(26.418438) and psi["sigma"] == approx(0.0293538)
    assert delta["value"] == approx(112.59465) and delta["sigma"] == approx(0.0781373)
    assert psi["theta_i_deg"] == 64.999634  # never rounded
    assert [g["nominal"] for g in m.meta["angles_deg"]] == [65.0, 70.0, 75.0]
    assert m.meta["original_file"] == "w2_10102006.dat"
    assert m.meta["settings"]["Revs"] == 40 and m.meta["flags"] == ["Isotropic"]
    assert m.meta["datetime"] == "2006-10-10T10:24:56"
    assert m.data["sample"].iloc[0] == "10102006 Ta Metal 02"
    wl = m.data["wavelength_nm"]
    assert (wl.min(), wl.max()) == (245.73252, 1697.766406)


def test_wvase_ev_axis_gives_245_7_to_1697_8_nm_not_pyelli_scaling(real_exports):
    m = load(real_exports, f"{WVASE}/wafer_2_01242007.dat")
    wl = m.data["wavelength_nm"]
    # pyElli 0.23.1 returns 905-6256 "nm" here (E * hc); the truth is lambda = hc / E
    assert wl.min() == pytest.approx(245.7, abs=0.05)
    assert wl.max() == pytest.approx(1697.8, abs=0.05)
    # line 5: 5.046137  64.999634  14.39738  148.72206  0.0276505  0.0910668
    psi = pick(m, "psi", 1240.0 / 5.046137, 64.999634)
    assert psi["value"] == approx(14.39738)
    assert m.meta["spectral_unit"] == "eV"


def test_wvase_ev_grid_matches_nm_grid_of_same_instrument_with_1240(real_exports):
    # the eV file's axis is WVASE's 1240/lambda of the nm files' axis: same 676 points
    ev = load(real_exports, f"{WVASE}/wafer_2_01242007.dat").data
    nm = load(real_exports, f"{WVASE}/w2_10102006.dat").data
    a = np.sort(ev["wavelength_nm"].unique())
    b = np.sort(nm["wavelength_nm"].unique())
    assert a.size == b.size == 676
    # 7 significant digits printed in the eV file -> agreement to ~1e-6 relative
    np.testing.assert_allclose(a, b, rtol=1e-6)
    assert WVASE_HC_EV_NM == 1240.0


def test_wvase_negative_delta_is_wrapped_and_range_kept_in_meta(real_exports):
    m = load(real_exports, f"{WVASE}/wafer_2_01242007.dat")
    # line 1249: 0.931065  69.999718  37.905373  -89.94648  0.00764872  0.0162453
    d = pick(m, "delta", 1240.0 / 0.931065, 69.999718)
    assert d["value"] == approx(360.0 - 89.94648)
    assert m.meta["delta_range_in_file"] == [-89.94648, 269.80878]
    assert m.meta["delta_range"] == "[0, 360)"


def test_wvase_depolarization_percent_becomes_fraction(real_exports):
    m = load(real_exports, f"{WVASE}/wafer_2_01242007.dat")
    # last line (no final newline): dpolE  0.730371  74.999962  -0.662477  1
    r = pick(m, "depolarization", 1240.0 / 0.730371, 74.999962)
    assert r["value"] == approx(-0.00662477) and r["sigma"] == approx(0.01)
    assert r["unit"] == "1"


def test_wvase_depolarization_block_on_its_own_angle_grid(real_exports):
    m = load(real_exports, f"{WVASE}/wvase_example.dat")
    d = m.data
    dep = d[d["quantity"] == "depolarization"]
    assert sorted(dep["theta_i_deg"].unique()) == [55.0, 56.0, 57.0, 58.0]
    assert dep["wavelength_nm"].max() == 1000.0
    # last line: dpolE  1000.000000  58.000000  -0.0295836  0.0770814
    r = pick(m, "depolarization", 1000.0, 58.0)
    assert r["value"] == approx(-0.000295836) and r["sigma"] == approx(0.000770814)
    assert sorted(d.loc[d["quantity"] == "psi", "theta_i_deg"].unique()) == [65.0, 70.0, 75.0]


def test_wvase_rtmethod_reflectance_is_p_channel_specular(real_exports):
    m = load(real_exports, f"{WVASE}/ta2o5_02262007_rp.dat")
    # line 5: pR  245.732520  45.000000  0.128525  0.0125705
    r = pick(m, "reflectance", 245.73252, 45.0)
    assert r["value"] == approx(0.128525) and r["sigma"] == approx(0.0125705)
    assert r["channel"] == "p" and r["theta_r_deg"] == 45.0 and r["phi_r_deg"] == 180.0
    assert m.meta["method"] == "RTmethod" and m.meta["settings"]["PolRT"] == -0.08


def test_wvase_generalized_ellipsometry_channels(real_exports):
    m = load(real_exports, f"{WVASE}/w1_al2o3_20081120_anisotropy.dat")
    d = m.data
    assert sorted(d["channel"].unique()) == ["pp", "ps", "sp"]
    assert (d.groupby("channel").size() == 8112).all()
    # line 5: AnE  245.732520  54.999866  40.1182  174.368  0.0116855  0.0148134
    r = pick(m, "psi", 245.73252, 54.999866, channel="pp")
    assert r["value"] == approx(40.1182) and r["sigma"] == approx(0.0116855)
    # line 6630: Aps  1239.375586  69.999718  0.804105  -20.1198  0.0022253  0.543494
    r = pick(m, "delta", 1239.375586, 69.999718, channel="ps")
    assert r["value"] == approx(360.0 - 20.1198) and r["sigma"] == approx(0.543494)
    assert [g["nominal"] for g in m.meta["angles_deg"]] == [55, 60, 65, 70, 75, 80]


def test_wvase_mueller_rows_from_a_synthetic_snippet(tmp_path):
    # formats.md 1: mmIJ x AOI value value sigma sigma (not in a real file here)
    p = tmp_path / "mm.dat"
    p.write_bytes(
        b"Synthetic Mueller\r\n"
        b"VASEmethod[EllipsometerType=6, WVASE=3.9, Mon Jan 01 10:00:00 2024]\r\n"
        b"Original[mm.dat]\r\nnm\r\n"
        b"mm12\t500.0\t65.0\t-0.51\t-0.51\t0.001\t0.001\r\n"
        b"mm33\t500.0\t65.0\t0.82\t0.82\t0.002\t0.002\r\n"
        b"mm44\t600.0\t65.0\t0.79\t0.79\t0.003\t0.003"
    )
    m = labbrdf.read(p)
    assert m.quantities == ["mueller_12", "mueller_33", "mueller_44"]
    r = pick(m, "mueller_33", 500.0, 65.0)
    assert r["value"] == approx(0.82) and r["sigma"] == approx(0.002) and r["unit"] == "1"


def test_wvase_rtmethod_channels_u_p_s_from_a_synthetic_snippet(tmp_path):
    p = tmp_path / "rt.dat"
    p.write_bytes(
        b"RT test\nRTmethod[PolRT=90.02, RevsRT=100, WVASE=3.616, Mon Feb 26 11:36:27 2007]\n"
        b"Original[rt.dat]\nnm\n"
        b"sR\t500.0\t45.0\t0.40\t0.01\nuR\t500.0\t45.0\t0.25\t0.01\n"
        b"pR\t500.0\t45.0\t0.10\t0.01\n"
    )
    d = labbrdf.read(p).data
    assert dict(zip(d["channel"], d["value"], strict=True)) == {"s": 0.4, "u": 0.25, "p": 0.1}
    assert set(d["quantity"]) == {"reflectance"}


def test_woollam_formats_list_only_schema_quantities():
    from labbrdf.dataset import QUANTITIES

    for name in (
        "woollam-wvase",
        "woollam-completeease",
        "accurion-ep4",
        "filmsense",
        "sentech-spectraray",
    ):
        assert set(READERS[name].quantities) <= set(QUANTITIES)


def test_parse_method_handles_completeease_quirks():
    line = (
        "VASEmethod[EllipsometerType=4 , CompleteEASE=6.37, AcqTime=15.000, ZoneAve=1, "
        "Acq. Parameters=DEFAULT.parms,WinCorrected=1]"
    )
    out = parse_method(line)
    assert out["settings"] == {
        "EllipsometerType": 4,
        "CompleteEASE": 6.37,
        "AcqTime": 15.0,
        "ZoneAve": 1,
        "Acq. Parameters": "DEFAULT.parms",
        "WinCorrected": 1,
    }
    assert out["software"] == "CompleteEASE 6.37" and out["simulated"] is False
    sim = parse_method("VASEmethod[Simulation for si.mod, WVASE=3.6]")
    assert sim["simulated"] is True
    with pytest.raises(ValueError, match="not a VASEmethod"):
        parse_method("nm")


# ----------------------------------------------------------------------------- CompleteEASE


def test_completeease_6_tagged_angstrom_and_dropped_inf_block(real_exports):
    m = load(real_exports, f"{CEASE}/complete_ease_example.dat")
    # line 4: E  1930.000000  50.000000  40.014217  142.127655  0.008585  0.034774
    r = pick(m, "psi", 193.0, 50.0)
    assert r["value"] == approx(40.014217) and r["sigma"] == approx(0.008585)
    # line 6532: dPolE  1930.000000  50.000000  1.800296  0.165269
    r = pick(m, "depolarization", 193.0, 50.0)
    assert r["value"] == approx(0.01800296) and r["sigma"] == approx(0.00165269)
    wl = m.data["wavelength_nm"]
    assert (wl.min(), wl.max()) == (193.0, 1700.0)
    # the uR block (lines 3268-6531) is all inf: dropped, and the drop is recorded
    assert m.meta["dropped_rows"] == [
        {
            "tag": "uR",
            "quantity": "specular_intensity",
            "count": 3264,
            "reason": "value is inf: not measured",
        }
    ]
    assert m.meta["spectral_unit"] == "Angstrom" and m.meta["variant"] == "completeease-tagged"


def test_completeease_3_static_triplets_take_the_measurement_angle(real_exports):
    m = load(real_exports, f"{CEASE}/Woolam_staticTest.dat")
    # line 4: 370.324  70.000  21.4553  145.7525  0.0140  0.0318  <TAB>
    assert pick(m, "delta", 370.324, 70.0)["value"] == approx(145.7525)
    # line 5: dPolE  370.324  0.000  -5.2834  1.0000  -> AOI of line 4
    r = pick(m, "depolarization", 370.324, 70.0)
    assert r["value"] == approx(-0.052834)
    # line 6: uR  370.324  0.000  0.6504  1.0000  -> relative intensity, not reflectance
    r = pick(m, "specular_intensity", 370.324, 70.0)
    assert r["value"] == approx(0.6504) and r["channel"] == "u"
    assert (m.data["theta_i_deg"] == 70.0).all()
    assert m.meta["aoi_reassigned"]["rows"] == 796
    assert m.data["sample"].iloc[0] == "Woolam_staticTest"  # empty title -> file stem


def test_completeease_3_dynamic_time_in_seconds(real_exports):
    m = load(real_exports, f"{CEASE}/Woolam_kineticTest.dat")
    d = m.data
    assert d["time_s"].nunique() == 7
    # line 5: 370.324  70.000  30.0225  121.5848  0.0988  0.2195  <empty>  0.0232
    r = pick(m, "psi", 370.324, 70.0, time_s=0.0232 * 60)
    assert r["value"] == approx(30.0225)
    # last line: 999.935  70.000  9.3100  146.0579  0.0330  0.1966  <empty>  0.2756
    r = pick(m, "delta", 999.935, 70.0, time_s=0.2756 * 60)
    assert r["value"] == approx(146.0579)
    assert m.meta["time_unit_in_file"] == "min" and m.meta["dynamic"] is True
    assert (d.groupby("time_s").size() == 2 * 398).all()


# ----------------------------------------------------------------------------- Accurion


def test_accurion_old_layout_zone_rows_and_positions(real_exports):
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


def test_accurion_zone5_is_peak_to_peak_spread_and_zone0_the_mean(real_exports):
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


def test_accurion_new_layout_latin1_units_and_columns_by_name(real_exports):
    m = load(real_exports, f"{ACC}/Si3N4_on_4inBF33_W02_20240903-150451.ds.dat")
    assert m.meta["encoding"] == "latin-1" and "\u00b5m" in m.meta["units"]
    # line 3: 0  40.000  365.0  6.1  115908  417.6  409.8  179.785156  32.535931
    assert pick(m, "psi", 365.0, 40.0)["value"] == approx(32.535931)
    assert pick(m, "delta", 365.0, 40.0)["value"] == approx(179.785156)
    assert "x_mm" not in m.data.columns  # ROI_x/ROI_y are camera positions, not the stage
    assert m.data["sample"].iloc[0] == "Si3N4_on_4inBF33_W02_20240903-150451"


def test_accurion_corefine_spectroscopic_zones(real_exports):
    m = load(real_exports, f"{ACC}/corefine_PNIPAM_ellipsometry.dat")
    d = m.data
    # line 3: 380.0  6.0  40.000  162.859  41.174  4  ...  -8.000  -16.836
    rows = d[(d["quantity"] == "psi") & (d["wavelength_nm"] == 380.0) & (d["theta_i_deg"] == 40)]
    assert 41.174 in set(rows["value"]) and len(rows) == 4  # four zones
    assert (d["x_mm"] == -8.0).all()
    assert sorted(d["wavelength_nm"].unique())[::5] == [380.0, 665.0, 950.0]


def test_accurion_wvase_format_export(real_exports):
    m = load(real_exports, f"{ACC}/testData1_11nm_PNIPAM_on_Si_EP4.dat")
    # line 3: 658.0  55.0  27.700  170.200
    assert pick(m, "psi", 658.0, 55.0)["value"] == approx(27.7)
    assert pick(m, "delta", 658.0, 55.0)["value"] == approx(170.2)
    assert m.meta["variant"] == "ep4-wvase-format"
    assert m.data["sample"].iloc[0] == "04_12_1_PNIPAM_map_Polymer Brush_0.0x0.0y_WVASEformat"


def test_accurion_columns_matched_by_name_when_swapped(real_exports, tmp_path):
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


# ----------------------------------------------------------------------------- Film Sense


def test_filmsense_psi_delta_inverts_the_ncs_definition():
    psi = np.linspace(0.5, 89.5, 37)[:, None]
    delta = np.linspace(0.0, 359.0, 41)[None, :]
    p2, d = np.radians(2 * psi), np.radians(delta)
    n, c, s = np.cos(p2) + 0 * d, np.sin(p2) * np.cos(d), np.sin(p2) * np.sin(d)
    psi_b, delta_b = filmsense_psi_delta(n, c, s)
    # float64 round-off of arccos near N = +-1 costs ~1e-8 deg at psi = 0.5 deg
    np.testing.assert_allclose(psi_b, psi + 0 * delta, atol=1e-9)
    dd = (delta_b - delta + 180) % 360 - 180
    np.testing.assert_allclose(dd, 0, atol=1e-9)


def test_filmsense_static_values_and_negative_aoi(real_exports):
    m = load(real_exports, f"{FS}/Filmsense_staticTest.txt")
    # LED line 3: 367.20 ...; N C S P I line 11: 0.60270 -0.74368 0.28928 0.99845 16.5071
    psi = pick(m, "psi", 367.2)["value"]
    delta = pick(m, "delta", 367.2)["value"]
    assert psi == approx(0.5 * math.degrees(math.acos(0.60270)))
    assert delta == approx(math.degrees(math.atan2(0.28928, -0.74368)))
    assert pick(m, "depolarization", 367.2)["value"] == approx(1 - 0.99845)
    assert (m.data["theta_i_deg"] == 70.012).all()
    assert m.meta["aoi_in_file"] == -70.012
    assert m.meta["software_fit"]["Thick(nm).1"] == 1.5973
    assert m.meta["date"] == "2024-07-19 16:35"


def _nebraska_delta_film_on_substrate(n_film, d_nm, n_sub, k_sub, wl_nm, aoi_deg):
    """Delta [deg] of ambient/film/substrate, Nebraska: exp(+i w t), N = n - ik.

    Independent textbook formulas (Azzam & Bashara eqs. 4.35-4.37), written for this test.
    """
    n0, n1, n2 = 1.0, n_film, n_sub - 1j * k_sub
    s0 = math.sin(math.radians(aoi_deg))
    c0 = math.cos(math.radians(aoi_deg))
    c1 = np.sqrt(1 - (n0 * s0 / n1) ** 2 + 0j)
    c2 = np.sqrt(1 - (n0 * s0 / n2) ** 2 + 0j)
    rp01 = (n1 * c0 - n0 * c1) / (n1 * c0 + n0 * c1)
    rp12 = (n2 * c1 - n1 * c2) / (n2 * c1 + n1 * c2)
    rs01 = (n0 * c0 - n1 * c1) / (n0 * c0 + n1 * c1)
    rs12 = (n1 * c1 - n2 * c2) / (n1 * c1 + n2 * c2)
    e = np.exp(-2j * 2 * math.pi * d_nm / wl_nm * n1 * c1)
    rp = (rp01 + rp12 * e) / (1 + rp01 * rp12 * e)
    rs = (rs01 + rs12 * e) / (1 + rs01 * rs12 * e)
    return math.degrees(np.angle(rp / rs)) % 360


def test_filmsense_delta_sign_is_nebraska_by_a_fresnel_check(real_exports):
    m = load(real_exports, f"{FS}/Filmsense_staticTest.txt")
    measured = pick(m, "delta", 946.73)["value"]  # line 18: 0.95782 -0.28679 0.01824 ...
    # Si at 946.73 nm: n = 3.58, k ~ 1e-3 (nearly transparent); the software's own fit is
    # 1.5973 nm of film (footer), taken as SiO2 n = 1.45
    expected = _nebraska_delta_film_on_substrate(1.45, 1.5973, 3.58, 1e-3, 946.73, 70.012)
    # the opposite convention gives 360 - 176.3 = 183.7 deg, 7 deg away; +-1 deg covers
    # the uncertainty of the film index and thickness (dDelta/dd ~ 2.3 deg/nm)
    assert measured == pytest.approx(expected, abs=1.0)
    assert measured < 180.0
    delta = m.data.loc[m.data["quantity"] == "delta", "value"]
    assert ((delta > 0) & (delta < 180)).all()


def test_filmsense_dynamic_wide_rows(real_exports):
    m = load(real_exports, f"{FS}/Filmsense_kineticTest.txt")
    d = m.data
    assert sorted(d["time_s"].unique()) == [4.953, 14.858, 24.766, 34.663, 44.57, 54.475, 64.379]
    # line 12: 4.953  0.58698  -0.69405  0.41683  0.99839  14.1911 (UV = 367.20 nm)
    r = pick(m, "psi", 367.2, time_s=4.953)
    assert r["value"] == approx(0.5 * math.degrees(math.acos(0.58698)))
    r = pick(m, "delta", 367.2, time_s=4.953)
    assert r["value"] == approx(math.degrees(math.atan2(0.41683, -0.69405)))
    # line 18, IR950 columns: 64.379 ... 0.95681 -0.28507 0.05692 0.99936 12.0183
    r = pick(m, "psi", 946.73, time_s=64.379)
    assert r["value"] == approx(0.5 * math.degrees(math.acos(0.95681)))
    assert m.meta["per_time_point"]["Thick(nm).2"][-1] == 3.3601


# ----------------------------------------------------------------------------- SENTECH


def test_sentech_psi_delta_three_angles(real_exports):
    m = load(real_exports, f"{ST}/Si_SiO2_theta_50_60_70.txt")
    # line 2: 190.13558 45.74309 168.36886 55.11351 170.81765 56.03301 118.52958
    for aoi, psi, delta in (
        (50.2, 45.74309, 168.36886),
        (60.2, 55.11351, 170.81765),
        (70.2, 56.03301, 118.52958),
    ):
        assert pick(m, "psi", 190.13558, aoi)["value"] == approx(psi)
        assert pick(m, "delta", 190.13558, aoi)["value"] == approx(delta)
    # line 3: 190.59492 47.53618 187.30627 ...: Delta above 180 stays
    assert pick(m, "delta", 190.59492, 50.2)["value"] == approx(187.30627)
    wl = m.data["wavelength_nm"]
    assert (wl.min(), wl.max()) == (190.13558, 3484.48151)
    assert m.meta["kind"] == "psi_delta"


def test_sentech_mueller_sixteen_elements_row_major(real_exports):
    m = load(real_exports, f"{ST}/Wafer_MM_70.txt")
    # line 2: 190.13558 1.00000 0.51251 0.01932 -0.25386 0.42243 0.88447 -0.01350 0.06720
    #         -0.00949 0.09000 -0.48318 0.75947 0.03951 0.27812 -1.00000 0.01332
    row = [
        1.0,
        0.51251,
        0.01932,
        -0.25386,
        0.42243,
        0.88447,
        -0.0135,
        0.0672,
        -0.00949,
        0.09,
        -0.48318,
        0.75947,
        0.03951,
        0.27812,
        -1.0,
        0.01332,
    ]
    # converted to the labbrdf.optics convention (S1 = Is - Ip): the elements with exactly
    # one index 2 change sign (SpectraRay writes M12 = -cos 2psi)
    flip = {"mueller_12", "mueller_21", "mueller_23", "mueller_24", "mueller_32", "mueller_42"}
    for k, v in enumerate(row):
        q = f"mueller_{k // 4 + 1}{k % 4 + 1}"
        assert pick(m, q, 190.13558)["value"] == approx(-v if q in flip else v)
    assert (m.data["theta_i_deg"] == 70.2).all()
    assert m.meta["kind"] == "mueller"


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
    real_exports, tmp_path, rel, eol
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

WV_HEAD = (
    b"title\r\nVASEmethod[EllipsometerType=4, WVASE=3.616, Tue Oct 10 10:24:56 2006]\r\n"
    b"Original[x.dat]\r\nnm\r\n"
)
WV_ROW = b"500.0\t65.0\t20.0\t100.0\t0.01\t0.02\r\n"
ACC_HEAD = b"#Lambda\tAOI\tDelta\tPsi\tZone\n#nm\tdeg\tdeg\tdeg\t-\n"
FS_STATIC = (
    b"Film_Sense_Data\n8\t1\t-70.0\t0\t0\t19\n"
    + b"".join(b"%d.0\t1\t2\t3\t4\t5\t6\n" % (400 + 50 * k) for k in range(8))
    + b"".join(b"0.6\t-0.7\t0.38\t0.999\t16\n" for _ in range(8))
    + b"1\nFit_Diff\t0.004"
)
ST_HEAD = b"; WAVELENGTH 50.0 50.0 60.0 60.0\n"


def write(tmp_path: Path, name: str, data: bytes) -> Path:
    p = tmp_path / name
    p.write_bytes(data)
    return p


def raises(path: Path, match: str, line: int | None = None, reader=labbrdf.read, **kw):
    with pytest.raises(AdapterError, match=match) as ei:
        reader(path, **kw)
    assert str(path) in str(ei.value)
    if line is not None:
        assert ei.value.line == line, str(ei.value)
    return ei.value


@pytest.mark.parametrize(
    "reader", [read_woollam, read_accurion, read_filmsense, read_sentech], ids=lambda f: f.__name__
)
def test_every_reader_rejects_empty_binary_and_missing_files(tmp_path, reader):
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
def test_file_of_another_vendor_forced_with_format_is_refused(real_exports, rel, fmt, match):
    e = raises(real_exports / rel, match, reader=labbrdf.read, format=fmt)
    assert e.line is not None


def test_woollam_bad_rows_name_their_line(tmp_path):
    raises(write(tmp_path, "t.dat", WV_HEAD + WV_ROW + b"500.0\t65.0\t20"), "missing field", 6)
    raises(
        write(tmp_path, "x.dat", WV_HEAD + WV_ROW + b"500.0\t65.0\t2x.0\t1\t1\t1\r\n"),
        "expected a number, found '2x.0'",
        6,
    )
    raises(
        write(tmp_path, "f.dat", WV_HEAD + WV_ROW * 3 + WV_ROW[:-2] + b"\t7\t8\t9\r\n"),
        "expected at most 8 numeric fields|too many fields",
        8,
    )
    raises(
        write(tmp_path, "g.dat", WV_HEAD + b"ARpp\t500\t65\t0.1\t0.01\r\n"),
        "unsupported data tag 'ARpp'",
        5,
    )
    raises(
        write(tmp_path, "p.dat", WV_HEAD + WV_ROW + b"500.0\t65.0\t95.0\t1\t1\t1\r\n"),
        r"psi must be within \[0, 90\]",
        6,
    )
    raises(
        write(tmp_path, "a.dat", WV_HEAD + b"500.0\t95.0\t20.0\t1\t1\t1\r\n"),
        "angle of incidence",
        5,
    )
    raises(
        write(tmp_path, "s.dat", WV_HEAD + b"500.0\t65.0\t20.0\t1\t-1\t1\r\n"), "sigma must be", 5
    )
    raises(
        write(tmp_path, "c.dat", WV_HEAD + b"500,0\t65.0\t20.0\t1\t1\t1\r\n"),
        "expected a number, found '500,0'",
        5,
    )
    ev = WV_HEAD.replace(b"\r\nnm\r\n", b"\r\neV\r\n")
    raises(write(tmp_path, "z.dat", ev + b"0\t65.0\t20.0\t1\t1\t1\r\n"), "spectral value", 5)
    raises(write(tmp_path, "i.dat", WV_HEAD + b"uR\t500\t65\tinf\t1\r\n"), "no finite data")


def test_woollam_bad_headers(tmp_path):
    raises(
        write(tmp_path, "u.dat", WV_HEAD.replace(b"\r\nnm\r\n", b"\r\nfurlongs\r\n") + WV_ROW),
        "expected the spectral unit line",
        4,
    )
    raises(write(tmp_path, "n.dat", WV_HEAD.replace(b"\r\nnm\r\n", b"\r\n")), "spectral unit")
    raises(write(tmp_path, "h.dat", WV_HEAD), "no data rows")
    raises(
        write(tmp_path, "m.dat", b"a\r\nb\r\nc\r\nnm\r\n" + WV_ROW),
        "no VASEmethod",
        reader=read_woollam,
    )
    dyn = WV_HEAD.replace(b"nm\r\n", b"Dynamic\r\nnm\r\n")
    raises(write(tmp_path, "d.dat", dyn + WV_ROW), "time", 6)
    raises(
        write(tmp_path, "e.dat", b"\x81\x40 title\r\n" + WV_HEAD[7:] + WV_ROW),
        "byte 0x81 is not valid",
        1,
    )


def test_accurion_bad_input(tmp_path):
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


def test_accurion_fallback_to_zone0_when_no_zone_rows(tmp_path):
    p = write(tmp_path, "z0.dat", ACC_HEAD + b"500\t60\t150\t20\t0\n500\t60\t0.2\t0.1\t5\n")
    m = read_accurion(p)
    assert m.meta["data_zones"] == [0] and len(m) == 2


def test_accurion_row_of_only_tabs_is_skipped_and_counted(tmp_path):
    # upstream corefine_polyBrush_ellipsometry.dat has such an empty first data row
    p = write(tmp_path, "t.dat", ACC_HEAD + b"\t\t\t\t\n500\t60\t150\t20\t1\n")
    m = read_accurion(p)
    assert len(m) == 2 and m.meta["blank_lines_skipped"] == 1


def test_filmsense_bad_input(tmp_path):
    lines = FS_STATIC.split(b"\n")
    assert len(read_filmsense(write(tmp_path, "ok.txt", FS_STATIC))) == 24  # the base is valid
    raises(
        write(tmp_path, "m.txt", b"Film_Sense\n" + b"\n".join(lines[1:])),
        "Film_Sense_Data",
        1,
        reader=read_filmsense,
    )
    del_ncs = b"\n".join(lines[:12] + lines[13:])  # one N C S P I line missing
    raises(
        write(tmp_path, "d.txt", del_ncs), "N C S P I line: expected 5", 18, reader=read_filmsense
    )
    dup_ncs = b"\n".join(lines[:12] + [lines[12]] + lines[12:])
    raises(write(tmp_path, "u.txt", dup_ncs), "unexpected data row", 19, reader=read_filmsense)
    raises(
        write(tmp_path, "n.txt", FS_STATIC.replace(b"0.6\t-0.7", b"1.6\t-0.7", 1)),
        r"N must be within \[-1, 1\]",
        11,
        reader=read_filmsense,
    )
    raises(
        write(tmp_path, "c.txt", FS_STATIC.replace(b"\n8\t1\t", b"\n8.5\t1\t")),
        "positive integer counts",
        2,
        reader=read_filmsense,
    )
    raises(
        write(tmp_path, "e.txt", b"\n".join(lines[:6])),
        "file ends early",
        7,
        reader=read_filmsense,
    )
    raises(
        write(tmp_path, "l.txt", FS_STATIC.replace(b"450.0\t1\t2\t3\t4\t5\t6", b"450.0\t1")),
        "expected 7 numbers like the first LED line",
        4,
        reader=read_filmsense,
    )


def test_filmsense_dynamic_bad_input(real_exports, tmp_path):
    src = (real_exports / FS / "Filmsense_kineticTest.txt").read_bytes()
    raises(
        write(tmp_path, "a.txt", src.replace(b"\tIR850_S\t", b"\tIR850_X\t")),
        "column 'IR850_S' missing",
        11,
        reader=read_filmsense,
    )
    raises(
        write(tmp_path, "b.txt", src.replace(b"Time\t", b"Tim\t")),
        "starting with 'Time'",
        11,
        reader=read_filmsense,
    )
    lines = src.split(b"\n")
    raises(
        write(tmp_path, "c.txt", b"\n".join(lines[:-1])),
        "file ends early",
        18,
        reader=read_filmsense,
    )
    raises(
        write(tmp_path, "d.txt", src + b"\n" + lines[-1]),
        "unexpected data row",
        19,
        reader=read_filmsense,
    )


def test_sentech_bad_input(tmp_path):
    row = b"500.0 20.0 150.0 30.0 120.0 \n"
    raises(
        write(tmp_path, "h.txt", b"WAVELENGTH 50 50\n" + row), "WAVELENGTH", 1, reader=read_sentech
    )
    raises(
        write(tmp_path, "o.txt", b"; WAVELENGTH 50.0 60.0 60.0\n500 1 2 3\n"),
        "cannot tell what the 3 columns hold",
        1,
    )
    raises(write(tmp_path, "p.txt", b"; WAVELENGTH 50.0 60.0\n500 1 2\n"), "cannot tell", 1)
    mm_head = b"; WAVELENGTH" + b" 70.0" * 16 + b"\n"
    raises(write(tmp_path, "a.txt", mm_head + b"500" + b" 0.5" * 16 + b"\n"), "ambiguous", 1)
    m = read_sentech(
        write(tmp_path, "k.txt", mm_head + b"500" + b" 20.0 100.0" * 8 + b"\n"), kind="psi_delta"
    )
    assert len(m) == 16 and m.quantities == ["psi", "delta"]
    raises(write(tmp_path, "m.txt", ST_HEAD + row + b"510.0 20.0 150.0 30.0\n"), "expected 5", 3)
    raises(
        write(tmp_path, "c.txt", ST_HEAD + b"500.0 20,5 150.0 30.0 120.0\n"),
        "expected a number, found '20,5'",
        2,
    )
    raises(
        write(tmp_path, "x.txt", ST_HEAD + row + row.replace(b"500.0 20.0", b"510 20 7 7")),
        "expected at most 5",
        3,
    )
    raises(write(tmp_path, "s.txt", ST_HEAD + b"500.0 95.0 150.0 30.0 120.0\n"), "psi must", 2)
    raises(write(tmp_path, "g.txt", b"; WAVELENGTH 50 95\n500 1 2\n"), r"\[0, 90\]", 1)
    raises(
        write(tmp_path, "k2.txt", ST_HEAD + row),
        "needs 16 columns",
        1,
        reader=read_sentech,
        kind="mueller",
    )
    raises(
        write(tmp_path, "k3.txt", ST_HEAD + row),
        "kind must be one of",
        reader=read_sentech,
        kind="rho",
    )
    raises(
        write(tmp_path, "k4.txt", b"; WAVELENGTH 50 60\n500 1 2\n"),
        "equal pairs",
        1,
        reader=read_sentech,
        kind="psi_delta",
    )
    raises(write(tmp_path, "n.txt", ST_HEAD), "no data rows", reader=read_sentech)


def test_categorical_frames_of_the_adapters_are_still_validated_row_by_row():
    from labbrdf.adapters._numblock import build_frame, labels, measurement

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
