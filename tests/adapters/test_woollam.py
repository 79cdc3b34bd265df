"""Woollam WVASE32 and CompleteEASE ASCII exports: psi/Delta, the eV axis, depolarisation,
RT and Mueller channels, the CompleteEASE variants, and the error of each bad row or header.

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
from labbrdf.adapters import READERS, AdapterError
from labbrdf.adapters.woollam import WVASE_HC_EV_NM, parse_method, read_woollam

WVASE = "woollam-wvase-ascii"
CEASE = "woollam-completeease-ascii"


def test_rtmethod_s_reflectance_at_45_deg(real_exports: Path) -> None:
    m = labbrdf.read(real_exports / WVASE / "ta2o5_02262007_rs.dat")
    d = m.data
    assert len(d) == 676 and set(d["quantity"]) == {"reflectance"}
    assert set(d["channel"]) == {"s"}
    # line 300: "sR	716.856299	45.000000	0.227157	0.0145431"
    row = d[np.isclose(d["wavelength_nm"], 716.856299, rtol=0, atol=1e-9)].iloc[0]
    assert row["value"] == pytest.approx(0.227157, rel=1e-12)
    assert row["sigma"] == pytest.approx(0.0145431, rel=1e-12)
    assert row["theta_i_deg"] == 45.0 == row["theta_r_deg"]


@pytest.mark.parametrize("spelling", [b"inf", b"1e999", b"-inf", b"Infinity"])
def test_completeease_dynamic_time_must_be_finite(
    real_exports: Path, tmp_path: Path, spelling: bytes
) -> None:
    raw = (real_exports / "woollam-completeease-ascii/Woolam_kineticTest.dat").read_bytes()
    # line 5: "370.324	70.000	30.0225	121.5848	0.0988	0.2195		0.0232" (time in min last)
    old = b"370.324\t70.000\t30.0225\t121.5848\t0.0988\t0.2195\t\t0.0232"
    bad = tmp_path / "kinetic.dat"
    bad.write_bytes(raw.replace(old, old[:-6] + spelling, 1))
    with pytest.raises(AdapterError, match=r"line 5: dynamic data: the time .* must be finite"):
        labbrdf.read(bad)


def test_wvase_mueller_converted_to_optics_convention_m12_positive(real_exports: Path) -> None:
    m = labbrdf.read(real_exports / WVASE / "wafer04_kingkong_al2o3_mueller_20081201.dat")
    d = m.data
    assert m.meta["mueller_convention"]["vendor"].startswith("Woollam: S1 = Ip - Is")
    # line 5: "mm12	245.732520	69.999718	-0.183029	-0.183029	0.00641494	0.00641494"
    row = d[(d["quantity"] == "mueller_12") & (d["wavelength_nm"] == 245.732520)]
    row = row[row["theta_i_deg"] == 69.999718].iloc[0]
    assert row["value"] == pytest.approx(+0.183029, rel=1e-12)
    assert row["sigma"] == pytest.approx(0.00641494, rel=1e-12)
    # mm33 (C = sin 2psi cos Delta) and mm34 (S) keep their sign
    mm34 = d[(d["quantity"] == "mueller_34") & (d["wavelength_nm"] == 245.732520)]
    raw = (real_exports / WVASE / "wafer04_kingkong_al2o3_mueller_20081201.dat").read_text()
    line = next(s for s in raw.splitlines() if s.startswith("mm34\t245.732520\t69.999718"))
    v = float(line.split("\t")[3])
    assert mm34[mm34["theta_i_deg"] == 69.999718]["value"].iloc[0] == pytest.approx(v, rel=1e-12)


def test_rp_angle_column_flat_from_0_to_50_deg_is_not_the_angle_of_incidence(
    real_exports: Path,
) -> None:
    m = labbrdf.read(real_exports / WVASE / "ots_sio2_1mm_02262007_rp.dat")
    d = m.data
    assert len(d) == 4056 and set(d["quantity"]) == {"reflectance"}
    assert set(d["channel"]) == {"p"}
    # no specular geometry is claimed: the angle of incidence is unknown
    assert d["theta_i_deg"].isna().all() and d["theta_r_deg"].isna().all()
    assert d["phi_r_deg"].isna().all()
    col = m.meta["angle_column"]
    assert col["values_deg"] == [0.0, 10.0, 20.0, 30.0, 40.0, 50.0]
    assert col["rows_per_value"] == [676] * 6
    assert col["is_angle_of_incidence"] is False
    assert m.meta["angles_deg"] == []
    assert m.meta["reflectance_kind"] == "single-polarisation (p) ellipsometer reflectance"
    # line 5: "pR	245.732520	0.000000	0.512108	0.0202422", still the first row
    assert d["value"].iloc[0] == pytest.approx(0.512108, rel=1e-12)
    assert d["wavelength_nm"].iloc[0] == pytest.approx(245.73252, rel=1e-12)
    # the blocks stay in file order: row 676 is the first of the 10 deg block (line 681)
    assert d["wavelength_nm"].iloc[676] == pytest.approx(245.73252, rel=1e-12)


def test_rp_and_rs_at_45_deg_keep_their_angle_and_say_single_polarisation(
    real_exports: Path,
) -> None:
    for name, ch in (("ta2o5_02262007_rp.dat", "p"), ("ta2o5_02262007_rs.dat", "s")):
        m = labbrdf.read(real_exports / WVASE / name)
        assert (m.data["theta_i_deg"] == 45.0).all()
        assert "angle_column" not in m.meta
        assert m.meta["reflectance_kind"] == f"single-polarisation ({ch}) ellipsometer reflectance"


def test_rt_reflectance_that_changes_with_angle_keeps_the_angles(tmp_path: Path) -> None:
    p = tmp_path / "rt_angles.dat"
    p.write_bytes(
        b"RT angles\nRTmethod[PolRT=-0.08, RevsRT=100, WVASE=3.616, Mon Feb 26 11:36:27 2007]\n"
        b"Original[rt_angles.dat]\nnm\n"
        b"pR\t500.0\t15.0\t0.30\t0.01\npR\t600.0\t15.0\t0.31\t0.01\n"
        b"pR\t500.0\t55.0\t0.12\t0.01\npR\t600.0\t55.0\t0.13\t0.01\n"
    )
    m = labbrdf.read(p)
    assert m.data["theta_i_deg"].tolist() == [15.0, 15.0, 55.0, 55.0]
    assert "angle_column" not in m.meta


def test_wvase_psi_delta_spot_values_and_raw_aoi(real_exports, load, pick, approx):
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


def test_wvase_ev_axis_gives_245_7_to_1697_8_nm_not_pyelli_scaling(
    real_exports, load, pick, approx
):
    m = load(real_exports, f"{WVASE}/wafer_2_01242007.dat")
    wl = m.data["wavelength_nm"]
    # pyElli 0.23.1 returns 905-6256 "nm" here (E * hc); the truth is lambda = hc / E
    assert wl.min() == pytest.approx(245.7, abs=0.05)
    assert wl.max() == pytest.approx(1697.8, abs=0.05)
    # line 5: 5.046137  64.999634  14.39738  148.72206  0.0276505  0.0910668
    psi = pick(m, "psi", 1240.0 / 5.046137, 64.999634)
    assert psi["value"] == approx(14.39738)
    assert m.meta["spectral_unit"] == "eV"


def test_wvase_ev_grid_matches_nm_grid_of_same_instrument_with_1240(real_exports, load):
    # the eV file's axis is WVASE's 1240/lambda of the nm files' axis: same 676 points
    ev = load(real_exports, f"{WVASE}/wafer_2_01242007.dat").data
    nm = load(real_exports, f"{WVASE}/w2_10102006.dat").data
    a = np.sort(ev["wavelength_nm"].unique())
    b = np.sort(nm["wavelength_nm"].unique())
    assert a.size == b.size == 676
    # 7 significant digits printed in the eV file -> agreement to ~1e-6 relative
    np.testing.assert_allclose(a, b, rtol=1e-6)
    assert WVASE_HC_EV_NM == 1240.0


def test_wvase_negative_delta_is_wrapped_and_range_kept_in_meta(real_exports, load, pick, approx):
    m = load(real_exports, f"{WVASE}/wafer_2_01242007.dat")
    # line 1249: 0.931065  69.999718  37.905373  -89.94648  0.00764872  0.0162453
    d = pick(m, "delta", 1240.0 / 0.931065, 69.999718)
    assert d["value"] == approx(360.0 - 89.94648)
    assert m.meta["delta_range_in_file"] == [-89.94648, 269.80878]
    assert m.meta["delta_range"] == "[0, 360)"


def test_wvase_depolarization_percent_becomes_fraction(real_exports, load, pick, approx):
    m = load(real_exports, f"{WVASE}/wafer_2_01242007.dat")
    # last line (no final newline): dpolE  0.730371  74.999962  -0.662477  1
    r = pick(m, "depolarization", 1240.0 / 0.730371, 74.999962)
    assert r["value"] == approx(-0.00662477) and r["sigma"] == approx(0.01)
    assert r["unit"] == "1"


def test_wvase_depolarization_block_on_its_own_angle_grid(real_exports, load, pick, approx):
    m = load(real_exports, f"{WVASE}/wvase_example.dat")
    d = m.data
    dep = d[d["quantity"] == "depolarization"]
    assert sorted(dep["theta_i_deg"].unique()) == [55.0, 56.0, 57.0, 58.0]
    assert dep["wavelength_nm"].max() == 1000.0
    # last line: dpolE  1000.000000  58.000000  -0.0295836  0.0770814
    r = pick(m, "depolarization", 1000.0, 58.0)
    assert r["value"] == approx(-0.000295836) and r["sigma"] == approx(0.000770814)
    assert sorted(d.loc[d["quantity"] == "psi", "theta_i_deg"].unique()) == [65.0, 70.0, 75.0]


def test_wvase_rtmethod_reflectance_is_p_channel_specular(real_exports, load, pick, approx):
    m = load(real_exports, f"{WVASE}/ta2o5_02262007_rp.dat")
    # line 5: pR  245.732520  45.000000  0.128525  0.0125705
    r = pick(m, "reflectance", 245.73252, 45.0)
    assert r["value"] == approx(0.128525) and r["sigma"] == approx(0.0125705)
    assert r["channel"] == "p" and r["theta_r_deg"] == 45.0 and r["phi_r_deg"] == 180.0
    assert m.meta["method"] == "RTmethod" and m.meta["settings"]["PolRT"] == -0.08


def test_wvase_generalized_ellipsometry_channels(real_exports, load, pick, approx):
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


def test_wvase_mueller_rows_from_a_synthetic_snippet(tmp_path, pick, approx):
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


def test_completeease_6_tagged_angstrom_and_dropped_inf_block(real_exports, load, pick, approx):
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


def test_completeease_3_static_triplets_take_the_measurement_angle(
    real_exports, load, pick, approx
):
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


def test_completeease_3_dynamic_time_in_seconds(real_exports, load, pick, approx):
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


WV_HEAD = (
    b"title\r\nVASEmethod[EllipsometerType=4, WVASE=3.616, Tue Oct 10 10:24:56 2006]\r\n"
    b"Original[x.dat]\r\nnm\r\n"
)


WV_ROW = b"500.0\t65.0\t20.0\t100.0\t0.01\t0.02\r\n"


def test_woollam_bad_rows_name_their_line(tmp_path, write, raises):
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


def test_woollam_bad_headers(tmp_path, write, raises):
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
