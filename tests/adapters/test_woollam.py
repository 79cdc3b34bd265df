"""Woollam WVASE32 / CompleteEASE: the real files added later, and hardening."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError

WVASE = "woollam-wvase-ascii"


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


def test_sentech_mueller_matches_psi_delta_of_the_same_wafer_in_optics_convention(
    real_exports: Path,
) -> None:
    """Wafer_MM_70.txt and Si_SiO2_theta_50_60_70.txt (70.2 deg) are the same wafer: after
    conversion M12 = cos 2psi, M33 = sin 2psi cos Delta, M34 = sin 2psi sin Delta as
    labbrdf.optics.mueller_reflection gives for tan psi = |rp/rs|, Delta = arg(rs rp*)."""
    from labbrdf.optics import mueller_reflection

    st = real_exports / "sentech-spectraray-ascii"
    mm = labbrdf.read(st / "Wafer_MM_70.txt").data
    pd_ = labbrdf.read(st / "Si_SiO2_theta_50_60_70.txt").data
    pd_ = pd_[pd_["theta_i_deg"] == 70.2]
    for wl in (500.08504, 1000.05418, 2000.35045):
        psi = np.radians(pd_[(pd_.quantity == "psi") & (pd_.wavelength_nm == wl)].value.iloc[0])
        de = np.radians(pd_[(pd_.quantity == "delta") & (pd_.wavelength_nm == wl)].value.iloc[0])
        # rs = 1, rp = tan psi exp(-i Delta): arg(rs rp*) = Delta
        ref = mueller_reflection(1.0, np.tan(psi) * np.exp(-1j * de))
        ref = ref / ref[0, 0]
        got = mm[mm.wavelength_nm == wl].set_index("quantity")["value"]
        for i, j in ((1, 2), (2, 1), (3, 3), (3, 4), (4, 3), (4, 4)):
            # two instruments' scans of one wafer: agree to 0.02 (5 digits printed)
            assert got[f"mueller_{i}{j}"] == pytest.approx(ref[i - 1, j - 1], abs=0.02), (wl, i, j)


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
