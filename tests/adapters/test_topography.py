"""Topography files: geometry checks, stated geometry, messages, line scans, memory."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from labbrdf.adapters._base import AdapterError
from labbrdf.adapters.topography import check_geometry, length_m, read_height_map
from labbrdf.cli import main
from labbrdf.roughness.synthetic import gaussian_surface

pytest.importorskip("SurfaceTopography")


def write_bcrf(path, z_nm, length_x, length_y=None, xunit="um", zunit="nm"):
    """A BCR-STM float file (the format SurfaceTopography reads as ``bcrf``)."""
    z = np.asarray(z_nm, dtype="<f4")
    ny, nx = z.shape  # rows = y, as the file stores them
    hdr = (
        f"fileformat = bcrf\nheadersize = 2048\nxpixels = {nx}\nypixels = {ny}\n"
        f"xlength = {length_x!r}\nylength = {length_y if length_y is not None else length_x!r}\n"
        f"xunit = {xunit}\nyunit = {xunit}\nzunit = {zunit}\nintelmode = 1\n"
    )
    with open(path, "wb") as f:
        f.write(hdr.encode().ljust(2048, b" "))
        f.write(z.tobytes())
    return path


def rough(n=64, seed=1):
    """Heights [nm] of a Gaussian surface, sigma 100 nm, c 4 pixels."""
    return np.asarray(gaussian_surface(n, float(n), 100.0, 4.0, rng=seed).z)


def run(argv, capsys):
    rc = main(argv)
    out = capsys.readouterr()
    return rc, out.out, out.err


# ---------------------------------------------------------------- geometry plausibility
@pytest.mark.parametrize(
    ("length", "unit", "match"),
    [
        (64 * 4.9e-33, "um", r"pixel size 4\.9e-39.*outside"),  # corrupt header
        (64 * 0.3125e6, "um", r"pixel size 0\.3125.*outside"),  # um read as m
        (64 * 1.0, "m", r"pixel size 1, 1 m.*outside"),
    ],
)
def test_implausible_pitch_is_refused_naming_the_numbers(tmp_path, capsys, length, unit, match):
    p = write_bcrf(tmp_path / "bad.bcrf", rough(), length, xunit=unit)
    with pytest.raises(AdapterError, match="bad.bcrf: " + match):
        read_height_map(p)
    rc, out, err = run(["surface", str(p)], capsys)
    assert rc == 2 and "bad.bcrf" in err and "--pixel-size" in err and out == ""


def test_stated_pixel_size_replaces_a_misread_one(tmp_path, capsys):
    """The confocal case: 312.5 nm pitch written, read a million times too large."""
    z = rough()
    p = write_bcrf(tmp_path / "conf.bcrf", z, 64 * 0.3125e6)
    rc, out, err = run(
        ["surface", str(p), "--pixel-size", "312.5nm", "--json", "--blocks", "0"], capsys
    )
    assert rc == 0, err
    d = json.loads(out)
    assert d["pixel_size"] == pytest.approx([312.5e-9, 312.5e-9])
    # the same heights on a 312.5 nm grid, read from a file that says so
    good = write_bcrf(tmp_path / "good.bcrf", z, 64 * 0.3125)
    ref = read_height_map(good)
    assert ref.pixel_size == pytest.approx((312.5e-9, 312.5e-9))
    assert ref.warnings == ()
    rc, out2, _ = run(["surface", str(good), "--json", "--blocks", "0"], capsys)
    assert json.loads(out2)["slope_rms"] == pytest.approx(d["slope_rms"], rel=1e-12)


def test_grid_of_long_thin_pixels_and_huge_maps_are_refused(tmp_path):
    z = np.zeros((9, 24576)) + np.arange(24576) % 7
    with pytest.raises(AdapterError, match=r"f.dat: lateral size 0\.009 x 24\.58 m \(9 x 24576"):
        check_geometry("f.dat", z, (1e-3, 1e-3))
    with pytest.raises(AdapterError, match=r"f.dat: pixels 1e-06 m x 0.0005 m differ"):
        check_geometry("f.dat", rough() * 1e-9, (1e-6, 5e-4))
    with pytest.raises(AdapterError, match="not positive and finite"):
        check_geometry("f.dat", rough() * 1e-9, (float("nan"), 1e-6))


def test_pitch_against_height_scale_warns(tmp_path, capsys):
    z = rough()
    steep = read_height_map(write_bcrf(tmp_path / "s.bcrf", z * 1e4, 64.0 * 1e-3))  # 1 nm px
    assert any("RMS slope along x" in w and "misread" in w for w in steep.warnings)
    flat = read_height_map(write_bcrf(tmp_path / "f.bcrf", z * 1e-6, 64.0 * 1e2))  # 100 um px
    assert any("outside 1e-07..10" in w for w in flat.warnings)
    rc, _, err = run(["surface", str(tmp_path / "f.bcrf"), "--blocks", "0"], capsys)
    assert rc == 0 and "warning: " in err and "f.bcrf" in err
    ok = read_height_map(write_bcrf(tmp_path / "o.bcrf", z, 64.0))
    assert ok.warnings == ()


def test_length_parser():
    assert length_m("312.5nm") == pytest.approx(312.5e-9)
    assert length_m("2 um") == pytest.approx(2e-6)
    assert length_m("3", "mm") == pytest.approx(3e-3)
    for bad in ("x", "-1um", "1 furlong", "nan"):
        with pytest.raises(ValueError, match="length"):
            length_m(bad)


# ------------------------------------------------------------------ unit and pixel size
def test_unitless_matrix_needs_unit_and_the_message_names_the_option(tmp_path, capsys):
    z = np.random.default_rng(0).standard_normal((20, 16))
    p = tmp_path / "m.asc"
    np.savetxt(p, z)
    rc, _, err = run(["surface", str(p), "--pixel-size", "1um"], capsys)
    assert rc == 2 and "m.asc" in err and "--unit" in err
    rc, _, err = run(["surface", str(p), "--unit", "um"], capsys)
    assert rc == 2 and "m.asc" in err and "--pixel-size" in err
    rc, out, err = run(
        ["surface", str(p), "--pixel-size", "1um", "--unit", "um", "--json"], capsys
    )
    assert rc == 0, err
    d = json.loads(out)
    assert d["pixel_size"] == pytest.approx([1e-6, 1e-6])
    rc, _, err = run(["surface", str(p), "--pixel-size", "1 furlong", "--unit", "um"], capsys)
    assert rc == 2 and "--pixel-size" in err and "unit" in err


def test_stated_unit_rescales_heights_of_a_file_with_a_unit(tmp_path):
    z = rough()
    p = write_bcrf(tmp_path / "u.bcrf", z, 64.0)
    a = read_height_map(p)
    b = read_height_map(p, unit="nm")  # the numbers are nm, not the file's um
    np.testing.assert_allclose(b.heights, a.heights * 1e-3, rtol=1e-12, equal_nan=True)
    assert b.pixel_size == pytest.approx(tuple(v * 1e-3 for v in a.pixel_size), rel=1e-12)
    assert b.meta["unit_stated"] == "nm"
    with pytest.raises(AdapterError, match="u.bcrf: unit 'parsec' unknown"):
        read_height_map(p, unit="parsec")


def test_trace_surface_takes_the_stated_pixel_size(tmp_path, capsys):
    z = rough()
    p = write_bcrf(tmp_path / "conf.bcrf", z, 64 * 0.3125e6)
    base = ["trace", "--substrate", "1.5+7j", "--theta-i", "30", "--wavelength", "633"]
    rc, _, err = run([*base, "--rays", "2000", "--surface", str(p)], capsys)
    assert rc == 2 and "conf.bcrf" in err and "pixel size" in err
    rc, out, err = run(
        [*base, "--rays", "2000", "--surface", str(p), "--pixel-size", "312.5nm", "--json"], capsys
    )
    assert rc == 0, err
    from labbrdf.tracer import Substrate

    ref = read_height_map(write_bcrf(tmp_path / "g.bcrf", z, 64 * 0.3125))
    alpha = Substrate.from_surface(ref.heights, ref.pixel_size).alpha
    assert json.loads(out)["config"]["substrate"]["alpha"] == pytest.approx(alpha, rel=1e-12)
    assert alpha > 0.05  # a rough surface, not the mirror a misread pitch gives


# ------------------------------------------------------------------------- messages
def test_corrupt_di_and_opdx_name_the_file_and_the_cause(tmp_path, capsys):
    di = tmp_path / "bad.di"
    di.write_bytes(b"garbage that is not a Nanoscope header\r\n" * 40)
    op = tmp_path / "bad.opdx"
    op.write_bytes(b"VCA DATA\x01\x00\x00\x55" + b"\x00" * 100)
    for p, fmt in ((di, "di"), (op, "opdx")):
        with pytest.raises(AdapterError) as e:
            read_height_map(p)
        msg = str(e.value)
        assert str(p) in msg and f"as {fmt}: " in msg and not msg.rstrip(")").endswith(": ")
        assert "tried XYZReader" not in msg
        rc, _, err = run(["surface", str(p)], capsys)
        assert rc == 2 and f"as {fmt}: " in err


def test_map_without_roughness_says_so_not_math_domain_error(tmp_path, capsys):
    p = write_bcrf(tmp_path / "flat.bcrf", np.full((32, 32), 7.0), 32.0)
    rc, _, err = run(["surface", str(p)], capsys)
    assert rc == 2 and "flat.bcrf" in err and "no roughness" in err
    assert "math domain" not in err
    from labbrdf.roughness.topography import roughness_statistics

    i, j = np.mgrid[0:32, 0:32]
    with pytest.raises(ValueError, match="no roughness"):
        roughness_statistics((3.0 * i + 2.0 * j + 5.0) * 1e-9, 1e-6)


# ------------------------------------------------------------------ non-uniform scans
def test_non_uniform_line_scan_is_interpolated_and_says_so(tmp_path, capsys):
    rng = np.random.default_rng(4)
    x = np.cumsum(rng.uniform(0.8, 1.2, 400))  # um, irregular as a stylus export
    z = 50 * np.sin(2 * np.pi * x / 40.0)  # nm
    p = tmp_path / "dektak.csv"
    p.write_text("\n".join(f"{a:.6f},{b:.6f}" for a, b in zip(x, z * 1e-3, strict=True)))
    hm = read_height_map(p, unit="um")
    assert hm.is_profile
    assert any(
        "non-uniform line scan (400 points" in w and "interpolated" in w for w in hm.warnings
    )
    step = float(np.min(np.diff(x))) * 1e-6  # the finest spacing: no segment is skipped
    assert hm.pixel_size[0] == pytest.approx(step)
    assert hm.points is not None and len(hm.points[0]) == 400
    # linear interpolation of the sine: RMS height 50/sqrt(2) nm within the interpolation
    # error of a 1-um step on a 40-um wavelength (< 0.5 %) and the partial last period
    sig = float(np.sqrt(np.nanmean((hm.heights - np.nanmean(hm.heights)) ** 2)))
    assert sig == pytest.approx(50e-9 / np.sqrt(2), rel=0.03)
    rc, out, err = run(["surface", str(p), "--unit", "um", "--json", "--blocks", "0"], capsys)
    assert rc == 0, err
    d = json.loads(out)
    assert d["kind"] == "profile" and any("interpolated" in w for w in d["geometry_warnings"])


# ---------------------------------------------------------------------- alpha names
def test_json_names_both_alphas_and_the_tracer_uses_the_ml_one(tmp_path, capsys):
    p = write_bcrf(tmp_path / "r.bcrf", rough(), 64.0)
    rc, out, _ = run(["surface", str(p), "--json", "--blocks", "0"], capsys)
    d = json.loads(out)
    assert "alpha" not in d and d["tracer_alpha"] == "alpha_ggx_ml"
    assert d["alpha_ggx_ml"] == d["slope_fits"]["ggx"]["alpha"]
    assert d["alpha_gaussian_acf"] == pytest.approx(np.sqrt(2) * d["sigma"] / d["c"], rel=1e-12)
    from labbrdf.tracer import Substrate

    hm = read_height_map(p)
    assert Substrate.from_surface(hm.heights, hm.pixel_size).alpha == pytest.approx(
        d["alpha_ggx_ml"], rel=1e-9
    )
    rc, out, _ = run(["surface", str(p), "--blocks", "0"], capsys)
    assert "alpha_ggx_ml (used by trace)" in out and "alpha_gaussian_acf" in out
    assert "bandwidth: no S-filter" in out


# --------------------------------------------------------------------------- memory
LIMIT_GIB = 3.0


def _limited(argv, limit_gib):
    code = textwrap.dedent(
        f"""
        import resource, sys
        lim = int({limit_gib} * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (lim, lim))
        from labbrdf.cli import main
        rc = main({argv!r})
        # VmHWM: this process's own peak (Linux carries ru_maxrss over from the parent)
        try:
            hwm = next(l for l in open("/proc/self/status") if l.startswith("VmHWM:"))
            peak_kib = int(hwm.split()[1])
        except (OSError, StopIteration):
            peak_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        sys.stderr.write("maxrss_kib %d\\n" % peak_kib)
        sys.exit(rc)
        """
    )
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=1500
    )


@pytest.fixture(scope="module")
def big_map(tmp_path_factory):
    n = 4096
    z = np.asarray(gaussian_surface(n, float(n), 100.0, 4.0, rng=3).z)
    return write_bcrf(tmp_path_factory.mktemp("big") / "big.bcrf", z, float(n))


@pytest.mark.slow
def test_4096_map_fits_in_a_bounded_address_space(big_map):
    """A 4096 x 4096 map (128 MiB of float64 heights) under RLIMIT_AS = 3 GiB: the whole
    address space, interpreter and libraries included (before: 5.8 GB resident)."""
    t = time.perf_counter()
    r = _limited(["surface", str(big_map), "--json", "--blocks", "0"], LIMIT_GIB)
    dt = time.perf_counter() - t
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["shape"] == [4096, 4096] and d["sigma"] == pytest.approx(100e-9, rel=0.02)
    rss = int(r.stderr.split("maxrss_kib")[1].split()[0]) * 1024
    heights = 4096 * 4096 * 8
    print(f"4096^2 surface: {dt:.1f} s, peak RSS {rss / 2**20:.0f} MiB = {rss / heights:.1f} x")
    assert rss < 14 * heights


@pytest.mark.slow
def test_out_of_memory_names_the_file_and_exits_2(big_map):
    r = _limited(["surface", str(big_map), "--blocks", "0"], 1.2)
    assert r.returncode == 2, r.stderr
    assert "big.bcrf" in r.stderr and "memory" in r.stderr.lower()
    assert "Traceback" not in r.stderr


# ---------------------------------------------------------------- Nanofocus .nms
def write_nms(path, z_u16, pitch_mm=312.5e-6, zmin_um=-2.3, zmax_um=4.1, cut=0):
    """A Nanofocus .nms confocal map as SurfaceTopography's NMSReader reads it.

    A 3468-byte header (z range as two little-endian doubles at byte 16 [um]; points
    nx, ny as uint32 and pitch dx, dy as doubles [mm] at byte 1368), then ny x nx uint16
    heights scaled between zmin and zmax. The format has no magic bytes.
    """
    ny, nx = z_u16.shape
    hdr = bytearray(3468)
    hdr[16:32] = np.array([zmin_um, zmax_um], "<f8").tobytes()
    hdr[1368:1376] = np.array([nx, ny], "<u4").tobytes()
    hdr[1376:1392] = np.array([pitch_mm, pitch_mm], "<f8").tobytes()
    data = bytes(hdr) + np.asarray(z_u16, "<u2").tobytes()
    path.write_bytes(data[: len(data) - cut])
    return path


def test_nms_map_is_read_by_the_nanofocus_reader_not_a_detected_one(tmp_path, capsys):
    """A real confocal map's z range (here -2.3..4.1 um) makes the header look like a MATLAB
    v4 file to detection, whose reader lists no channel: a bare IndexError before."""
    u = np.random.default_rng(2).integers(0, 2**16 - 2, size=(512, 512)).astype("<u2")
    p = write_nms(tmp_path / "conf.nms", u)
    hm = read_height_map(p)
    assert hm.meta["reader"] == "NMSReader" and hm.heights.shape == (512, 512)
    assert hm.pixel_size == pytest.approx((312.5e-9, 312.5e-9), rel=1e-12)
    expect_um = u.T / (2**16 - 2) * (4.1 - -2.3) + -2.3  # the reader's own scaling
    np.testing.assert_allclose(hm.heights, expect_um * 1e-6, rtol=1e-12, atol=1e-21)
    rc, out, err = run(["ingest", str(p)], capsys)
    assert rc == 0 and "512 x 512 points" in out and "NMSReader" in out, err


def test_truncated_nms_is_refused_with_the_nanofocus_reason(tmp_path, capsys):
    u = np.zeros((64, 64), "<u2")
    p = write_nms(tmp_path / "cut.nms", u, cut=1000)
    with pytest.raises(AdapterError, match=r"cut\.nms: .*as nms: .*too small"):
        read_height_map(p)
    for cmd in ("ingest", "surface"):
        rc, _, err = run([cmd, str(p)], capsys)
        assert rc == 2 and "cut.nms" in err and "as nms" in err and "Traceback" not in err


class _Failing:
    """A SurfaceTopography reader whose ``where`` raises ``exc`` (channels or topography)."""

    def __init__(self, exc, where):
        self.exc, self.where = exc, where

    @property
    def channels(self):
        if self.where == "channels":
            raise self.exc
        return [_Channel()]

    @property
    def default_channel(self):
        if self.where == "default_channel":
            raise self.exc
        return self.channels[0]

    def topography(self, **kw):
        raise self.exc


class _Channel:
    name, index, unit, physical_sizes, nb_grid_pts = "Height", 0, "um", (1.0, 1.0), (4, 4)


@pytest.mark.parametrize(
    "exc",
    [IndexError("list index out of range"), KeyError("xres"), TypeError("x"), ZeroDivisionError()],
)
@pytest.mark.parametrize("where", ["channels", "default_channel", "topography"])
def test_any_reader_error_names_the_file_and_the_reader(tmp_path, monkeypatch, capsys, exc, where):
    import SurfaceTopography

    p = write_bcrf(tmp_path / "any.bcrf", rough(16), 16.0)
    monkeypatch.setattr(SurfaceTopography, "open_topography", lambda *a, **k: _Failing(exc, where))
    with pytest.raises(AdapterError) as e:
        read_height_map(p)
    msg = str(e.value)
    assert msg.startswith(str(p)) and "_Failing" in msg and type(exc).__name__ in msg
    for cmd in ("ingest", "surface"):
        rc, _, err = run([cmd, str(p)], capsys)
        assert rc == 2 and "any.bcrf" in err and "Traceback" not in err


# ------------------------------------------------------------- Nanoscope Z scale
@pytest.mark.shared
def test_nanoscope_with_two_disagreeing_z_scales_says_which_is_used(
    real_exports, tmp_path, capsys
):
    """A mutant of the real di-1.di whose first image states an @4:Z scale 16 times its
    @2:Z scale (the header keeps its length, so every offset stays): the heights follow
    one of them, and the warning says which and that the file disagrees with itself."""
    src = real_exports / "topography" / "di-1.di"
    raw = src.read_bytes()
    old = (
        b"\\Tip x width correction factor sigma: 1\r\n\\Tip y width correction factor sigma: 1\r\n"
    )
    new = b"\\@4:Z scale: V [Sens. Zsens] (0.005035400 V/LSB) 46.56738 V\r\n"
    new += b"\\Note:" + b" " * (len(old) - len(new) - 8) + b"\r\n"
    assert len(new) == len(old) and raw.count(old) >= 1
    i = raw.index(old)
    mut = tmp_path / "mutant.di"
    mut.write_bytes(raw[:i] + new + raw[i + len(old) :])
    ref, hm = read_height_map(src), read_height_map(mut)
    assert not any("Z scale" in w for w in ref.warnings)
    (w,) = [w for w in hm.warnings if "Z scale" in w]
    assert "46.56738 V" in w and "2.910461 V" in w and "(16 times)" in w
    assert "heights use the @4:Z scale" in w and "disagrees with itself" in w
    ratio = np.nanstd(hm.heights) / np.nanstd(ref.heights)
    assert ratio == pytest.approx(46.56738 / 2.910461, rel=1e-6)
    rc, out, _ = run(["ingest", str(mut)], capsys)
    assert rc == 0 and "warning: the file states two Z scales" in out
    rc, out, _ = run(["ingest", "--json", str(mut)], capsys)
    assert any("Z scale" in x for x in json.loads(out)[0]["height_map"]["warnings"])
    rc, _, err = run(["surface", str(mut), "--blocks", "0"], capsys)
    assert rc == 0 and "two Z scales" in err
