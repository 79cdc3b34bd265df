"""Zemax / Radiant .bsdf reader: real file, round trips through the writer, geometry, errors,
fuzz."""

from __future__ import annotations

import math
import random
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff
from labbrdf.adapters import zemax_bsdf as zb
from labbrdf.writers.zemax import write_bsdf

REAL = "zemax-bsdf/test_13_planesymmetric_brdf_zemax.bsdf"
AOI = [15, 20, 25, 30, 35, 40, 45, 50, 55, 60, 65, 70, 75]
AZ = list(range(0, 181, 10))
RAD = [0, 5, 10, 15, 20, 30, 40, 50, 60, 70, 80]


@pytest.fixture(scope="module")
def real(real_exports: Path) -> Path:
    p = real_exports / REAL
    if not p.is_file():
        pytest.skip(f"{p} absent")
    return p


def cos_theta_r(ts: float, r: float, a: float) -> float:
    """Spherical law of cosines (independent of the module's vector code)."""
    t, r, a = map(math.radians, (ts, r, a))
    return math.cos(t) * math.cos(r) + math.sin(t) * math.sin(r) * math.cos(a)


def row(m: labbrdf.dataset.Measurement, ti: float, tr: float, pr: float):
    d = m.data
    sel = d[
        (d.theta_i_deg == ti)
        & (np.abs(d.theta_r_deg - tr) < 1e-9)
        & (np.minimum(np.abs(d.phi_r_deg - pr), 360 - np.abs(d.phi_r_deg - pr)) < 1e-9)
    ]
    return sel


# ------------------------------------------------------------------------------ real file


def test_real_counts_and_ranges(real):
    m = labbrdf.read(real)
    assert m.meta["format"] == "zemax-bsdf"
    assert m.meta["symmetry"] == "PlaneSymmetrical" and "phi_r -> 360 - phi_r" in m.meta["mirror"]
    below = {t: sum(cos_theta_r(t, r, a) <= 1e-12 for a in AZ for r in RAD) for t in AOI}
    per = m.data.groupby("theta_i_deg").size().to_dict()
    # the pole (radial 0) is one direction: one row per incidence, not one per azimuth
    assert per == {float(t): 19 * 11 - below[t] - 18 for t in AOI}
    assert per[15.0] == 186 and per[75.0] == 135
    assert m.meta["dropped_below_horizon"] == sum(below.values()) == 352
    assert m.meta["pole"]["repeats_left_out"] == 13 * 18
    assert m.meta["pole"]["max_spread_sr-1"] == 0.0  # the file repeats one value
    assert len(m) == 13 * 19 * 11 - 352 - 13 * 18 == 2131
    assert m.data.theta_r_deg.min() == 0.0 and 89.8 < m.data.theta_r_deg.max() < 90.0
    assert set(m.data.quantity.astype(str)) == {"brdf"} and set(m.data.unit) == {"sr-1"}
    assert m.meta["wavelength_stated"] is False and (m.data.wavelength_nm == 555.0).all()
    # PlaneSymmetrical: only the measured half, phi_r in [0, 180]
    assert m.data.phi_r_deg.max() <= 180.0


def test_real_spot_values(real):
    m = labbrdf.read(real)
    # line 19 (AOI 15, azimuth 0): "6.375E-02	6.180E-02	5.879E-02	5.529E-02	5.190E-02 ...
    #   ... 3.304E-02	3.219E-02"
    assert row(m, 15, 15, 180).value.tolist() == [0.06375]  # specular, written per azimuth
    assert row(m, 15, 5, 180).value.tolist() == [0.05879]  # radial 10: theta_s - r
    (v,) = row(m, 15, 5, 0).value  # radial 20 crosses the normal: |15 - 20|, phi 0
    assert v == 0.05190
    assert row(m, 15, 65, 0).value.tolist() == [0.03219]  # radial 80
    # line 37 (AOI 15, azimuth 180): "... 4.977E-02	4.729E-02	4.650E-02	0.000E+00	0.000E+00"
    assert row(m, 15, 75, 180).value.tolist() == [0.04650]  # radial 60: theta_s + r
    assert row(m, 15, 85, 180).value.tolist() == [0.0]  # radial 70: a zero kept as data
    assert row(m, 15, 95 - 0, 180).empty  # radial 80 is below the horizon: dropped
    # line 28 (AOI 15, azimuth 90): "6.375E-02	6.302E-02	6.136E-02	5.852E-02	5.517E-02
    #   4.881E-02 ..."; radial 30 off the plane: x = -sin15 cos30, y = sin30, z = cos15 cos30
    x, y, z = -math.sin(math.radians(15)) * math.cos(math.radians(30)), 0.5, 0
    z = math.cos(math.radians(15)) * math.cos(math.radians(30))
    tr, pr = math.degrees(math.acos(z)), math.degrees(math.atan2(y, x))
    assert 33.2 < tr < 33.3 and 114.0 < pr < 114.2
    assert row(m, 15, tr, pr).value.tolist() == [0.04881]


def test_real_tis_and_grid_integral(real):
    m = labbrdf.read(real)
    tis = m.meta["tis"]
    assert len(tis) == 13
    assert tis[0] == {"theta_i_deg": 15.0, "rotation_deg": 0.0, "channel": "", "tis": 0.134506}
    # line 38 "TIS 0.1321704", line 258 "TIS 0.2571892"
    assert tis[1]["tis"] == 0.1321704 and tis[-1] == {
        "theta_i_deg": 75.0,
        "rotation_deg": 0.0,
        "channel": "",
        "tis": 0.2571892,
    }
    g = zb.grid_integral(zb.read_table(real))
    ratio = g["ratio"].ravel()
    assert np.all((ratio > 1.02) & (ratio < 1.21)), ratio
    assert np.allclose(zb.grid_integral(m)["integral"], g["integral"], rtol=0, atol=1e-15)
    assert np.all(np.diff(g["uncovered_fraction"]) > 0)  # the far side grows with AOI


def test_real_mirror(real):
    m = labbrdf.read(real)
    full = zb.mirror_plane_symmetric(m)
    in_plane = (m.data.phi_r_deg % 180 == 0) | (m.data.theta_r_deg == 0)
    assert len(full) == len(m) + int((~in_plane).sum()) == full.meta["mirrored"] + len(m)
    assert (full.data.iloc[len(m) :].phi_r_deg > 180).all()
    # line 28 (AOI 15, azimuth 90, radial 30) 4.881E-02 and its mirror image
    pr = next(iter(row(m, 15, 33.2, 0).phi_r_deg), None)  # nothing at phi 0 there
    assert pr is None
    d = m.data
    (src,) = d[(d.value == 0.04881) & (d.theta_i_deg == 15)].itertuples()
    assert row(full, 15, src.theta_r_deg, 360 - src.phi_r_deg).value.tolist() == [0.04881]
    assert row(m, 15, src.theta_r_deg, 360 - src.phi_r_deg).empty
    with pytest.raises(ValueError, match="already mirrored"):
        zb.mirror_plane_symmetric(full)
    with pytest.raises(ValueError, match="rows are not those read"):
        zb.grid_integral(full)


# ------------------------------------------------------------------------------ geometry


@pytest.mark.parametrize("ts", [0.0, 15.0, 45.0, 80.0])
@pytest.mark.parametrize("r", [0.0, 5.0, 30.0, 60.0])
def test_in_plane(ts, r):
    tr, pr, above = zb.scatter_to_angles(ts, r, 0.0)  # towards the normal
    if r <= ts:
        assert tr == pytest.approx(ts - r, abs=1e-12) and (pr == 180.0 or r == ts)
    else:
        assert tr == pytest.approx(r - ts, abs=1e-12) and pr == 0.0
    tr, pr, above = zb.scatter_to_angles(ts, r, 180.0)  # away from the normal
    assert tr == pytest.approx(ts + r, abs=1e-12) and pr == 180.0 or ts + r == 0
    assert bool(above) == (ts + r < 90)


def test_specular_and_symmetric_pairs():
    tr, pr, _ = zb.scatter_to_angles(np.array([0.0, 20.0, 70.0]), 0.0, 123.0)
    assert tr.tolist() == [0.0, 20.0, 70.0] and pr[1:].tolist() == [180.0, 180.0]
    rng = np.random.default_rng(1)
    ts, r, a = rng.uniform(0, 89, 200), rng.uniform(0, 90, 200), rng.uniform(0, 180, 200)
    t1, p1, _ = zb.scatter_to_angles(ts, r, a)
    t2, p2, _ = zb.scatter_to_angles(ts, r, 360.0 - a)
    np.testing.assert_allclose(t1, t2, atol=1e-12)
    np.testing.assert_allclose(np.mod(p1 + p2, 360.0), 0.0, atol=1e-9)
    # law of cosines, independently
    np.testing.assert_allclose(
        np.cos(np.radians(t1)), [cos_theta_r(*x) for x in zip(ts, r, a, strict=True)], atol=1e-12
    )


def test_direction_round_trip():
    rng = np.random.default_rng(7)
    ts = rng.uniform(0, 89.9, 1000)
    v = rng.normal(size=(3, 1000))
    v[2] = np.abs(v[2])
    v /= np.linalg.norm(v, axis=0)
    tr = np.degrees(np.arctan2(np.hypot(v[0], v[1]), v[2]))
    pr = np.mod(np.degrees(np.arctan2(v[1], v[0])), 360)
    r, a = zb.angles_to_scatter(ts, tr, pr)
    back = zb.scatter_to_direction(ts, r, a)
    np.testing.assert_allclose(back, v, atol=1e-12)


# ------------------------------------------------------------------------------ writer


def _random_values(rng, shape):
    return rng.lognormal(-2.0, 2.0, size=shape)


VARIANTS = [
    dict(symmetry="PlaneSymmetrical", az=np.arange(0, 181, 30.0), rot=(0,), nch=1),
    dict(symmetry="Asymmetrical", az=np.arange(0, 360, 45.0), rot=(0,), nch=1),
    dict(symmetry="Asymmetrical4D", az=np.arange(0, 360, 60.0), rot=(0, 45, 90), nch=1),
    dict(symmetry="Asymmetrical", az=np.arange(0, 360, 90.0), rot=(0,), nch=3),
    dict(symmetry="Asymmetrical4D", az=np.arange(0, 360, 90.0), rot=(-30, 30), nch=3, t="BTDF"),
]


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("var", range(len(VARIANTS)))
def test_round_trip(tmp_path, var, seed):
    v = VARIANTS[var]
    rng = np.random.default_rng(seed)
    ti, rad = np.array([0.0, 10.0, 60.0]), np.array([0.0, 2.0, 7.5, 30.0, 85.0])
    shape = (len(v["rot"]), v["nch"], ti.size, v["az"].size, rad.size)
    vals = _random_values(rng, shape)
    tis = rng.uniform(0, 1, shape[:3])
    digits = int(rng.integers(2, 10))
    p = write_bsdf(
        tmp_path / "x.bsdf",
        theta_i_deg=ti,
        radial_deg=rad,
        azimuth_deg=v["az"],
        values=vals,
        tis=tis,
        symmetry=v["symmetry"],
        scatter_type=v.get("t", "BRDF"),
        rotation_deg=v["rot"],
        comments=["made by a test"],
        digits=digits,
    )
    rounded = np.vectorize(lambda x: float(f"{x:.{digits - 1}E}"))
    t = zb.read_table(p)
    assert np.array_equal(t.values, rounded(vals))
    assert np.array_equal(t.tis, rounded(tis))
    assert (t.symmetry, t.comments) == (v["symmetry"], ["made by a test"])
    m = labbrdf.read(p)
    _, _, above = zb.scatter_to_angles(
        ti[:, None, None], rad[None, None, :], v["az"][None, :, None]
    )
    # the pole (radial 0) once per block, not once per azimuth
    pole_repeats = (v["az"].size - 1) * ti.size
    assert len(m) == (above.sum() - pole_repeats) * shape[0] * shape[1]
    q = "btdf" if v.get("t") == "BTDF" else "brdf"
    assert set(m.data.quantity.astype(str)) == {q}
    if v["nch"] == 3:
        assert sorted(set(m.data.channel)) == ["X", "Y", "Z"]
    if len(v["rot"]) > 1:
        assert sorted(set(m.data.sample_rotation_deg)) == sorted(map(float, v["rot"]))
    # the pole's random per-azimuth values become their cell-weighted mean: same integral
    # up to the rounding of that mean
    assert np.allclose(
        zb.grid_integral(m)["integral"], zb.grid_integral(t)["integral"], rtol=1e-13, atol=0
    )


# ------------------------------------------------------------------------------ errors

GOOD = """#comment
Source  Measured
Symmetry  PlaneSymmetrical
SpectralContent  Monochrome
ScatterType  BRDF
SampleRotation  1
0
AngleOfIncidence  2
10 20
ScatterAzimuth 2
0 180
ScatterRadial 3
0 5 10

Monochrome
DataBegin
TIS 0.5
1 2 3
1 2 3
TIS 0.25
4 5 6
4 5 6
DataEnd
"""


def _write(tmp_path, text, name="e.bsdf"):
    p = tmp_path / name
    p.write_bytes(text.encode("utf-8"))
    return p


def test_reading_needs_neither_scipy_nor_the_writer(tmp_path):
    # the reader (pole average included) runs on numpy alone: scipy's libraries do not fit
    # in the address space a memory-capped reader is given (tests/adapters/test_memory_caps)
    p = _write(tmp_path, GOOD)
    code = (
        "import sys, labbrdf\n"
        f"m = labbrdf.read({str(p)!r})\n"
        "assert m.meta['pole']['repeats_left_out'] == 2, m.meta['pole']\n"
        "print(sorted(k for k in ('scipy', 'labbrdf.writers.zemax') if k in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == "[]"


def test_good_minimal_file(tmp_path):
    t = zb.read_table(_write(tmp_path, GOOD))
    assert t.values[0, 0, 1, 1].tolist() == [4, 5, 6] and t.tis.ravel().tolist() == [0.5, 0.25]
    # tabs, CRLF, no DataEnd, no comment
    alt = GOOD.replace(" ", "\t").replace("\n", "\r\n").replace("DataEnd\r\n", "")
    t2 = zb.read_table(_write(tmp_path, alt, "f.bsdf"))
    assert np.array_equal(t.values, t2.values)


def test_pole_is_one_row_per_incidence_with_the_cap_average(tmp_path):
    # GOOD's pole values are equal per block (1 and 4): kept once, unchanged
    m = labbrdf.read(_write(tmp_path, GOOD))
    pole = m.data[m.data.theta_r_deg == m.data.theta_i_deg]
    assert pole.value.tolist() == [1.0, 4.0] and len(m) == 2 * (2 * 3 - 1)
    assert m.meta["pole"]["repeats_left_out"] == 2
    # azimuths 0 and 180 of a PlaneSymmetrical file: cells of 90 deg each, so the mean
    m = labbrdf.read(_write(tmp_path, GOOD.replace("4 5 6\n4 5 6", "4 5 6\n8 5 6"), "b.bsdf"))
    pole = m.data[m.data.theta_r_deg == m.data.theta_i_deg]
    assert pole.value.tolist() == [1.0, 6.0]
    assert m.meta["pole"]["max_spread_sr-1"] == 4.0
    # unequal cells (azimuths 0, 30, 180: widths 15, 90, 75 deg) weight the values
    text = GOOD.replace("ScatterAzimuth 2\n0 180", "ScatterAzimuth 3\n0 30 180")
    text = text.replace("1 2 3\n1 2 3", "1 2 3\n1 2 3\n7 2 3")
    text = text.replace("4 5 6\n4 5 6", "4 5 6\n4 5 6\n4 5 6")
    m = labbrdf.read(_write(tmp_path, text, "c.bsdf"))
    pole = m.data[m.data.theta_r_deg == m.data.theta_i_deg]
    assert np.allclose(pole.value, [(1 * 15 + 1 * 90 + 7 * 75) / 180, 4.0], rtol=1e-15)
    # back on the grid: the pole value at every azimuth
    t = zb._table_from_measurement(m)
    assert np.allclose(t.values[0, 0, 0, :, 0], (15 + 90 + 7 * 75) / 180, rtol=1e-15)


@pytest.mark.parametrize(
    ("comment", "wl"),
    [("#Wavelength (nm) = 550.0", 550.0), ("#labbrdf wavelength_nm 632.8", 632.8)],
)
def test_wavelength_comment_is_read(tmp_path, comment, wl):
    m = labbrdf.read(_write(tmp_path, f"{comment}\n{GOOD}"))
    assert (m.data.wavelength_nm == wl).all() and m.meta["wavelength_stated"] is True
    m = labbrdf.read(_write(tmp_path, GOOD, "none.bsdf"))
    assert m.meta["wavelength_stated"] is False


@pytest.mark.parametrize(
    ("comments", "msg", "line"),
    [
        ("#Wavelength (nm) = green", "wavelength comment: expected an ASCII decimal", 1),
        ("#Wavelength (nm) = -550", "expected a wavelength > 0", 1),
        ("#Wavelength (nm) = 550\n#Wavelength (nm) = 600", "earlier one 550 nm", 2),
    ],
)
def test_bad_wavelength_comment_names_the_line(tmp_path, comments, msg, line):
    p = _write(tmp_path, f"{comments}\n{GOOD}")
    with pytest.raises(AdapterError, match=msg) as exc:
        labbrdf.read(p)
    assert exc.value.line == line and exc.value.path == str(p)


HUGE = (
    "ScatterAzimuth 2000\n"
    + " ".join(f"{x:.4f}" for x in np.linspace(0, 180, 2000))
    + "\nScatterRadial 2000\n"
    + " ".join(f"{x:.4f}" for x in np.linspace(0, 90, 2000))
)

BAD = [
    ("ScatterRadial 3\n0 5 10", "ScatterRadial 4\n0 5 10", "ScatterRadial 4: expected 4 values"),
    ("ScatterRadial 3\n0 5 10", "ScatterRadial 2\n0 5 10", "expected 2 values, found 3"),
    ("AngleOfIncidence  2", "AngleOfIncidence  x", "expected a count"),
    ("1 2 3\n1 2 3\nTIS 0.25", "1 2 3\nTIS 0.25", "expected 2 rows of 3 values, found 1"),
    ("4 5 6\n4 5 6\nDataEnd", "4 5 6\n4 5 6\n4 5 6\nDataEnd", "expected the end of the file"),
    ("4 5 6\n4 5 6", "4 5 6\n4 5", "expected 3 values in the row, found 2"),
    ("4 5 6\n4 5 6", "4 5 6\n4 5 6 7", "expected 3 values in the row, found 4"),
    ("4 5 6\n4 5 6", "4 5 6\n4 x 6", "found the character 'x'"),
    ("4 5 6\n4 5 6", "4 5 6\n4 \uff15 6", "found the character"),
    ("4 5 6\n4 5 6", "4 5 6\n4 nan 6", "found the character 'n'"),
    ("4 5 6\n4 5 6", "4 5 6\n4 inf 6", "found the character 'i'"),
    ("4 5 6\n4 5 6", "4 5 6\n4 1e999 6", "not a finite number"),
    ("4 5 6\n4 5 6", "4 5 6\n4 1.2.3 6", "expected an ASCII decimal number"),
    ("TIS 0.25", "TIS nan", "expected an ASCII decimal number"),
    ("DataBegin\n", "", "expected 'DataBegin'"),
    ("Symmetry  PlaneSymmetrical", "Symmetry  Isotropic", "unknown keyword 'Isotropic'"),
    ("ScatterType  BRDF", "ScatterType  BSDF", "unknown keyword 'BSDF'"),
    ("SpectralContent  Monochrome", "SpectralContent  RGB", "unknown keyword 'RGB'"),
    ("ScatterType  BRDF\n", "", "missing header line 'ScatterType"),
    ("Source  Measured", "Source  Measured\nColour blue", "unknown header keyword 'Colour'"),
    ("Source  Measured", "Source  Measured\nSource  Measured", "given twice"),
    ("0 180", "0 270", "ScatterAzimuth: values must lie in"),
    ("10 20", "20 10", "strictly increasing"),
    ("AngleOfIncidence  2", "AngleOfIncidence  999999", "outside 1..100000"),
    ("ScatterAzimuth 2\n0 180\nScatterRadial 3\n0 5 10", HUGE, "more than the file"),
]


@pytest.mark.parametrize(("old", "new", "msg"), BAD)
def test_errors(tmp_path, old, new, msg):
    assert old in GOOD
    p = _write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(AdapterError, match=msg.replace("(", r"\(")) as exc:
        labbrdf.read(p)
    assert exc.value.path == str(p)


def test_error_lines(tmp_path):
    with pytest.raises(AdapterError) as exc:
        zb.read_table(_write(tmp_path, GOOD.replace("4 5 6\n4 5 6", "4 5 6\n4 x 6")))
    assert exc.value.line == 22
    with pytest.raises(AdapterError) as exc:
        zb.read_table(_write(tmp_path, GOOD.replace("1 2 3\n1 2 3", "1 2 3\n1 2")))
    assert exc.value.line == 19


def test_xyz_sections(tmp_path):
    rng = np.random.default_rng(3)
    vals = _random_values(rng, (1, 3, 1, 2, 2))
    p = write_bsdf(
        tmp_path / "c.bsdf",
        theta_i_deg=[30],
        radial_deg=[0, 10],
        azimuth_deg=[0, 180],
        values=vals,
        symmetry="PlaneSymmetrical",
        channels=("X", "Y", "Z"),
    )
    text = p.read_text()
    assert [ln for ln in text.splitlines() if ln.startswith("Tristimulus")] == [
        "TristimulusX",
        "TristimulusY",
        "TristimulusZ",
    ]
    bad = _write(tmp_path, text.replace("TristimulusY", "TristimulusZ", 1), "d.bsdf")
    with pytest.raises(AdapterError, match="expected the section line 'TristimulusY'"):
        labbrdf.read(bad)


# ------------------------------------------------------------------------------ sniff, fuzz


def test_sniff(tmp_path, fixtures_dir):
    p = _write(tmp_path, GOOD, "noext.txt")
    assert sniff(p) == ["zemax-bsdf"]
    rng = random.Random(0)
    for _ in range(200):
        head = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 300)))
        assert zb._sniff(head) in (True, False)
    files = sorted(f for f in fixtures_dir.rglob("*") if f.is_file())
    for f in [f for f in files if f.suffix != ".bsdf"][:40]:
        assert not zb._sniff(f.read_bytes()[:8192]), f
    for f in [f for f in files if f.suffix == ".bsdf"]:  # the bundled predict-measure set
        assert zb._sniff(f.read_bytes()[:8192]), f


def _mutate(raw: bytes, rng: random.Random) -> bytes:
    b = bytearray(raw)
    kind = rng.randrange(5)
    if kind == 0:
        for _ in range(rng.randrange(1, 8)):
            b[rng.randrange(len(b))] = rng.randrange(256)
    elif kind == 1:
        lines = bytes(b).split(b"\n")
        i = rng.randrange(len(lines))
        fields = lines[i].split(b"\t")
        if len(fields) > 1:
            del fields[rng.randrange(len(fields))]
        lines[i] = b"\t".join(fields)
        b = bytearray(b"\n".join(lines))
    elif kind == 2:
        lines = bytes(b).split(b"\n")
        i = rng.randrange(len(lines))
        lines.insert(i, lines[i])
        b = bytearray(b"\n".join(lines))
    elif kind == 3:
        lines = bytes(b).split(b"\n")
        del lines[rng.randrange(len(lines))]
        b = bytearray(b"\n".join(lines))
    else:
        cut = rng.randrange(len(b))
        b = b[:cut]
    return bytes(b)


def test_fuzz_real_file(real, tmp_path):
    raw = real.read_bytes()
    outcomes = {"ok": 0, "error": 0}
    for seed in range(300):
        p = tmp_path / f"f{seed}.bsdf"
        p.write_bytes(_mutate(raw, random.Random(seed)))
        try:
            m = zb.read_zemax_bsdf(p)
        except AdapterError:
            outcomes["error"] += 1
        else:
            assert len(m) > 0
            outcomes["ok"] += 1
        p.unlink()
    assert outcomes["error"] > 100 and outcomes["ok"] > 0, outcomes


FIT_VARIANTS = [
    dict(symmetry="PlaneSymmetrical", az=np.arange(0, 181, 15.0), rot=(0,), ch=("",)),
    dict(symmetry="Asymmetrical", az=np.arange(0, 360, 20.0), rot=(0,), ch=("",)),
    dict(symmetry="Asymmetrical4D", az=np.arange(0, 360, 30.0), rot=(0, 45), ch=("",)),
    dict(symmetry="Asymmetrical", az=np.arange(0, 360, 30.0), rot=(0,), ch=("X", "Y", "Z")),
]


@pytest.mark.parametrize("var", range(len(FIT_VARIANTS)))
def test_every_variant_written_from_a_model_is_fitted_back(tmp_path, var):
    # a microfacet BRDF (GGX alpha per channel and rotation, known n, k) with 2 % seeded
    # multiplicative noise, written in each variant, read back and fitted per group with
    # relative weights: alpha comes back within 3 standard errors (99.7 % for each group)
    from labbrdf.fitting import fit_many

    rng = np.random.default_rng(var)
    v = FIT_VARIANTS[var]
    model = labbrdf.models.get("microfacet", n=1.5, k=0.0)
    ti, rad = np.array([20.0, 50.0]), np.arange(0.0, 41.0, 4.0)
    alphas = {}
    vals = np.zeros((len(v["rot"]), len(v["ch"]), ti.size, v["az"].size, rad.size))
    for r, rot in enumerate(v["rot"]):
        for c, ch in enumerate(v["ch"]):
            alpha = 0.1 + 0.05 * c + 0.002 * rot
            alphas[(float(rot), ch)] = alpha
            tr, pr, above = zb.scatter_to_angles(
                ti[:, None, None], rad[None, None, :], v["az"][None, :, None]
            )
            f = model.evaluate(
                np.radians(np.broadcast_to(ti[:, None, None], tr.shape)),
                np.radians(np.where(above, tr, 0.0)),
                np.radians(pr),
                params={"alpha": alpha},
            )
            noise = np.exp(0.02 * rng.standard_normal(f.shape))
            vals[r, c] = np.where(above, f * noise, 0.0)
    p = write_bsdf(
        tmp_path / "m.bsdf",
        theta_i_deg=ti,
        radial_deg=rad,
        azimuth_deg=v["az"],
        values=vals,
        symmetry=v["symmetry"],
        rotation_deg=v["rot"],
        channels=v["ch"] if len(v["ch"]) == 3 else None,
        digits=8,
    )
    d = labbrdf.read(p).data
    by = ["sample", "wavelength_nm"]
    if len(v["ch"]) == 3:
        by.append("channel")
    if len(v["rot"]) > 1:
        by.append("sample_rotation_deg")
    table = fit_many(d, model, by=by, scheduler="serial", progress=False, mask_zeros=True,
                     weighting="relative")  # fmt: skip
    assert len(table) == len(alphas) and table["success"].all()
    for row in table.to_dict("records"):
        truth = alphas[(float(row.get("sample_rotation_deg", 0.0)), row.get("channel", ""))]
        assert abs(row["alpha"] - truth) <= 3 * row["alpha_stderr"]
        assert 0.5e-2 < row["redchi"] ** 0.5 < 4e-2  # the 2 % relative noise, estimated
