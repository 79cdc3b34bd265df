"""Film Sense ``.txt`` exports: the NCS-to-psi/Delta inversion and its Delta sign, static and
dynamic files, and header field counts enforced (a lost field must not shift the AOI).

Spot values are checked against numbers read by hand from the real exports (the line checked
is quoted in a comment), at ``approx`` (rel 1e-12, see conftest.py): the files print at most
9 significant digits, so any parsing or unit slip shows at 1e-7 or worse, and 1e-12 leaves
room only for float64 round-off of the conversions. Bad input raises ``AdapterError`` naming
the file and, where it makes sense, the line.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from labbrdf.adapters import AdapterError
from labbrdf.adapters.filmsense import filmsense_psi_delta, read_filmsense

FS = "filmsense-txt"


def test_line2_with_a_field_deleted_is_refused_not_read_as_a_2_deg_aoi(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = (real_exports / FS / "Filmsense_staticTest.txt").read_bytes()
    # line 2: "8	1	-70.012	-0.002	-0.003	19.0913"; sed '2s/-70.012\t//'
    bad = tmp_path / "static.txt"
    bad.write_bytes(raw.replace(b"8\t1\t-70.012\t", b"8\t1\t", 1))
    with pytest.raises(AdapterError, match=r"line 2: count line .*expected 6 .* found 5"):
        read_filmsense(bad)


def test_led_line_with_a_field_deleted_is_refused(real_exports: Path, tmp_path: Path) -> None:
    raw = (real_exports / FS / "Filmsense_kineticTest.txt").read_bytes()
    # line 3: "367.20	14.32	3.39	2.48	1.218	1.363	0.059"
    bad = tmp_path / "kinetic.txt"
    bad.write_bytes(raw.replace(b"367.20\t14.32\t", b"367.20\t", 1))
    with pytest.raises(AdapterError, match=r"line 3: LED line: expected 7 numbers .* found 6"):
        read_filmsense(bad)


def test_dynamic_line2_with_a_field_deleted_is_refused(real_exports: Path, tmp_path: Path) -> None:
    raw = (real_exports / FS / "Filmsense_kineticTest.txt").read_bytes()
    bad = tmp_path / "kinetic.txt"
    bad.write_bytes(raw.replace(b"8\t7\t-70.012\t", b"8\t7\t", 1))  # line 2
    with pytest.raises(AdapterError, match=r"line 2: count line .*expected 4 .* found 3"):
        read_filmsense(bad)


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


def test_filmsense_static_values_and_negative_aoi(real_exports, load, pick, approx):
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


def test_filmsense_delta_sign_is_nebraska_by_a_fresnel_check(real_exports, load, pick):
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


def test_filmsense_dynamic_wide_rows(real_exports, load, pick, approx):
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


FS_STATIC = (
    b"Film_Sense_Data\n8\t1\t-70.0\t0\t0\t19\n"
    + b"".join(b"%d.0\t1\t2\t3\t4\t5\t6\n" % (400 + 50 * k) for k in range(8))
    + b"".join(b"0.6\t-0.7\t0.38\t0.999\t16\n" for _ in range(8))
    + b"1\nFit_Diff\t0.004"
)


def test_filmsense_bad_input(tmp_path, write, raises):
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


def test_filmsense_dynamic_bad_input(real_exports, tmp_path, write, raises):
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
