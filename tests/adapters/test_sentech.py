"""SENTECH SpectraRay ASCII exports: psi/Delta at several angles, the sixteen Mueller
elements in the optics convention, and the errors of bad input.

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
from labbrdf.adapters.sentech import read_sentech

ST = "sentech-spectraray-ascii"


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


def test_sentech_psi_delta_three_angles(real_exports, load, pick, approx):
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


def test_sentech_mueller_sixteen_elements_row_major(real_exports, load, pick, approx):
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


ST_HEAD = b"; WAVELENGTH 50.0 50.0 60.0 60.0\n"


def test_sentech_bad_input(tmp_path, write, raises):
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
