"""The command line on a lab's measured files: BRDF fits, optical constants, export,
selection options and a closed output pipe."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.cli import main
from labbrdf.selection import Range, SelectionError, parse_range, select

BSDF = "zemax-bsdf/test_13_planesymmetric_brdf_zemax.bsdf"
TA = "woollam-wvase-ascii/w2_10102006.dat"


def _json(capsys: pytest.CaptureFixture[str]) -> object:
    return json.loads(capsys.readouterr().out)


# ------------------------------------------------------------------ selection


def test_parse_range_forms():
    assert parse_range("400:700") == Range(400.0, 700.0)
    assert parse_range("400:").hi == np.inf
    assert parse_range(":700").lo == -np.inf
    r = parse_range("550")
    assert r.lo < 550 < r.hi and r.hi - r.lo == pytest.approx(2e-6)


@pytest.mark.parametrize("bad", ["700:400", "a:b", "１２:20", "nan", "1e999", "1:2:3"])
def test_parse_range_refuses(bad):
    with pytest.raises(SelectionError):
        parse_range(bad, "--wavelength-range")


def test_select_empty_result_names_what_the_data_hold(fixtures_dir: Path):
    m = labbrdf.read(fixtures_dir / "specular" / "osr_specular.csv")
    assert set(select(m, wavelength="500:560").wavelength_nm) == {500.0, 550.0}
    with pytest.raises(SelectionError, match="360 to 860"):
        select(m, wavelength="1000:2000")
    with pytest.raises(SelectionError, match="OSR"):
        select(m, sample="mirror")


def test_cli_selection_error_is_exit_2(fixtures_dir: Path, capsys):
    scan = str(fixtures_dir / "specular" / "osr_specular.csv")
    assert main(["fit", scan, "--model", "smooth3", "--wavelength-range", "1000:", "--json"]) == 2
    assert "no row left" in capsys.readouterr().err


# ------------------------------------------------------------------ BRDF fits


@pytest.mark.slow
def test_fit_measured_bsdf_per_incidence_with_microfacet(real_exports: Path, capsys):
    path = str(real_exports / BSDF)
    argv = ["fit", path, "--model", "microfacet", "--param", "n=1.5", "--param", "k=0",
            "--param", "diffuse=true", "--by", "theta_i_deg", "--scheduler", "serial",
            "--json"]  # fmt: skip
    assert main(argv) == 0
    out = _json(capsys)
    assert [g["group"]["theta_i_deg"] for g in out] == list(range(15, 80, 5))
    assert all(g["success"] for g in out)
    # the file has no sigma: relative weights, and the zeros the sphere wrote next to the
    # horizon are excluded by the documented rule (88 zeros over the 13 blocks)
    assert {g["weighting"] for g in out} == {"relative: sigma = max(|y|, 0.001 x max|y|)"}
    assert sum(g["nmasked"] for g in out) == 88
    for g in out:
        lo, hi = g["params"]["alpha"]["ci95"]
        assert lo <= g["params"]["alpha"]["value"] <= hi


def test_exported_model_is_fitted_back_exactly(tmp_path: Path, capsys):
    out = tmp_path / "vinyl.bsdf"
    argv = ["export", "--model", "microfacet", "--param", "n=1.5", "--param", "k=0",
            "--param", "diffuse=true", "--param", "alpha=0.25", "--param", "kd=0.1",
            "--theta-i", "15", "45", "75", "--radial", "0:80:5", "--azimuth", "0:180:10",
            "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    capsys.readouterr()
    assert main(argv) == 2  # never over an existing file without --overwrite
    assert "exists" in capsys.readouterr().err
    fit = ["fit", str(out), "--model", "microfacet", "--param", "n=1.5", "--param", "k=0",
           "--param", "diffuse=true", "--scheduler", "serial", "--json"]  # fmt: skip
    assert main(fit) == 0
    (g,) = _json(capsys)
    # written to 6 significant digits: the fit recovers the truth to that precision
    assert g["params"]["alpha"]["value"] == pytest.approx(0.25, rel=1e-5)
    assert g["params"]["kd"]["value"] == pytest.approx(0.1, rel=1e-5)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--param", "alpha=0.2"], "microfacet needs exactly one of"),
        (["--param", "n=1.5", "--param", "beta=1"], "parameters are"),
        (["--param", "n=1.5", "--radial", "0:x:1"], "START:STOP:STEP"),
        (["--param", "n=1.5", "--nk-from", "x.dat"], "needs --wavelength"),
        (["--param", "n=1.5", "--format", "csv"], "export writes zemax-bsdf"),
        (["--param", "n=1.5", "--format", "speos-bsdf"], "writes a .anisotropicbsdf file"),
    ],
)
def test_export_errors_are_exit_2(tmp_path: Path, capsys, argv, message):
    base = ["export", "--model", "microfacet", "--theta-i", "30", "-o", str(tmp_path / "o.bsdf")]
    assert main(base + argv) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "o.bsdf").exists()


def test_fit_with_an_unknown_model_option_is_exit_2(fixtures_dir: Path, capsys):
    scan = str(fixtures_dir / "specular" / "osr_specular.csv")
    assert main(["fit", scan, "--model", "five_param", "--param", "shadowing=xyz"]) == 2
    assert "shadowing" in capsys.readouterr().err


# ------------------------------------------------------------------ optical constants


def test_nk_json_on_the_ta_file(real_exports: Path, capsys):
    assert main(["nk", str(real_exports / TA), "--wavelength-range", "500:510", "--json"]) == 0
    out = _json(capsys)
    keys = ("wavelength_nm", "theta_i_deg", "n", "k", "n_sigma", "k_sigma")
    lengths = {len(out[k]) for k in keys}
    assert len(lengths) == 1 and lengths.pop() > 0
    assert all(500 <= w <= 510 for w in out["wavelength_nm"])
    assert {"wavelength_nm", "n", "k", "chi2", "angle_dependent"} <= set(out["combined"])
    # tantalum near 500 nm: n ~ 2.3, k ~ 3.0 (pseudo-constants of the metal)
    assert np.median(out["combined"]["n"]) == pytest.approx(2.3, abs=0.1)
    assert np.median(out["combined"]["k"]) == pytest.approx(3.0, abs=0.1)


def test_nk_writes_csv_and_refuses_files_without_psi_delta(
    real_exports: Path, fixtures_dir: Path, tmp_path: Path, capsys
):
    out = tmp_path / "nk.csv"
    assert (
        main(["nk", str(real_exports / TA), "--wavelength-range", "500:510", "-o", str(out)]) == 0
    )
    head = out.read_text().splitlines()[0].split(",")
    assert {"wavelength_nm", "theta_i_deg", "n", "k", "n_sigma", "k_sigma"} <= set(head)
    capsys.readouterr()
    scan = str(fixtures_dir / "specular" / "osr_specular.csv")
    assert main(["nk", scan]) == 2
    assert capsys.readouterr().err.strip()


def test_fit_nk_from_a_psi_delta_file(real_exports: Path, tmp_path: Path, capsys):
    # a microfacet BRDF at 500 nm written with the Ta file's own n, k is fitted back with
    # --nk-from that file: the index comes from the ellipsometer, alpha from the BRDF
    from labbrdf.nk import combined_table, nk_at
    from labbrdf.writers.zemax import model_to_bsdf

    at = nk_at(combined_table(labbrdf.read(real_exports / TA)), 500.0)
    m = labbrdf.models.get("microfacet", n=float(at["n"]), k=float(at["k"]))
    path = tmp_path / "ta.bsdf"
    model_to_bsdf(m, {"alpha": 0.15}, path, theta_i_deg=[30, 60], radial_deg=np.arange(0, 41, 2),
                  azimuth_deg=np.arange(0, 181, 10), wavelength_nm=500.0)  # fmt: skip
    argv = ["fit", str(path), "--model", "microfacet", "--nk-from", str(real_exports / TA),
            "--scheduler", "serial", "--json"]  # fmt: skip
    assert main(argv) == 0
    (g,) = _json(capsys)
    assert g["params"]["alpha"]["value"] == pytest.approx(0.15, rel=1e-5)


def test_fit_nk_from_needs_a_wavelength_for_files_that_state_none(real_exports: Path, capsys):
    argv = ["fit", str(real_exports / BSDF), "--model", "microfacet", "--nk-from",
            str(real_exports / TA), "--scheduler", "serial"]  # fmt: skip
    assert main(argv) == 2
    assert "with --wavelength NM" in capsys.readouterr().err


# ------------------------------------------------------------------ pipes


def test_closed_output_pipe_is_not_a_traceback(fixtures_dir: Path):
    scan = str(fixtures_dir / "specular" / "osr_specular.csv")
    p = subprocess.Popen(
        [sys.executable, "-m", "labbrdf.cli", "fit", scan, "--model", "smooth3", "--json",
         "--scheduler", "serial"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    assert p.stdout is not None and p.stderr is not None
    p.stdout.close()  # the reader goes away before we write
    err = p.stderr.read().decode()
    p.wait(timeout=60)
    assert "Traceback" not in err
    assert p.returncode == 141


# ------------------------------------------------------------------ topography


def test_surface_json_and_png_on_the_afm_file(real_exports: Path, tmp_path: Path, capsys):
    png = tmp_path / "di.png"
    path = str(real_exports / "topography" / "di-1.di")
    assert main(["surface", path, "--blocks", "0", "--json", "--png", str(png)]) == 0
    d = _json(capsys)
    assert d["kind"] == "areal" and d["channel"] == "Height"
    # 512 x 512 points over 500 nm: heights of nanometres, lengths of tens of nanometres
    assert 1e-9 < d["sigma"] < 1e-7
    assert 1e-8 < d["c"] < 5e-7
    assert d["slope_fits"]["best"] in ("ggx", "beckmann")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_surface_of_an_unreadable_file_is_exit_2(tmp_path: Path, capsys):
    bad = tmp_path / "x.opdx"
    bad.write_bytes(b"not a profile")
    assert main(["surface", str(bad)]) == 2
    assert str(bad) in capsys.readouterr().err


def test_trace_takes_nk_from_an_ellipsometer_and_slopes_from_a_height_map(
    real_exports: Path, capsys
):
    argv = ["trace", "--nk-from", str(real_exports / TA), "--surface",
            str(real_exports / "topography" / "di-1.di"), "--theta-i", "45",
            "--wavelength", "600", "--rays", "20000", "--scheduler", "serial",
            "--json"]  # fmt: skip
    assert main(argv) == 0
    s = _json(capsys)
    # tantalum absorbs: the albedo lies well below 1, and the energy ledger closes
    assert 0.2 < s["albedo"] < 0.9
    e = s["energy"]
    assert e["exited"] + e["absorbed"] + e["terminated"] == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--alpha", "0.2"], "--substrate N+Kj or --nk-from"),
        (["--substrate", "1.5+0j"], "--alpha A or --surface"),
    ],
)
def test_trace_needs_an_index_and_a_roughness(capsys, argv, message):
    base = ["trace", "--theta-i", "45", "--wavelength", "600", "--rays", "100"]
    assert main(base + argv) == 2
    assert message in capsys.readouterr().err


def test_ingest_selects_rows_and_refuses_an_empty_selection(fixtures_dir: Path, tmp_path, capsys):
    scan = str(fixtures_dir / "specular" / "osr_specular.csv")
    out = tmp_path / "sel.csv"
    argv = ["ingest", scan, "--wavelength-range", "500:560", "--theta-i-range", "45"]
    assert main([*argv, "-o", str(out)]) == 0
    d = labbrdf.read(out).data
    assert set(d.wavelength_nm) == {500.0, 550.0} and set(d.theta_i_deg) == {45.0}
    assert len(d) == 2 * 21
    capsys.readouterr()
    assert main(["ingest", scan, "--sample", "mirror"]) == 2
    assert "no row left" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("cmd", "out"),
    [
        (["nk", "{TA}", "-o"], "{TA}"),
        (["nk", "{TA}", "-o"], "nk.txt"),
        (["surface", "{DI}", "--png"], "map.jpg"),
        (["export", "--model", "smooth3", "--theta-i", "30", "-o"], "out.csv"),
        (["export", "--model", "smooth3", "--theta-i", "30", "-o"], "dir/"),
    ],
)
def test_new_writers_refuse_inputs_and_wrong_suffixes(real_exports, tmp_path, capsys, cmd, out):
    ta, di = str(real_exports / TA), str(real_exports / "topography" / "di-1.di")
    target = out.format(TA=ta) if "{TA}" in out else str(tmp_path / out)
    argv = [c.format(TA=ta, DI=di) for c in cmd] + [target]
    before = {
        p: p.stat().st_mtime_ns
        for p in (real_exports / TA, real_exports / "topography" / "di-1.di")
    }
    assert main(argv) == 2
    assert capsys.readouterr().err.strip()
    assert {p: p.stat().st_mtime_ns for p in before} == before
    assert sorted(tmp_path.iterdir()) == []


def test_report_takes_model_options_and_a_selection(real_exports: Path, tmp_path: Path):
    out = tmp_path / "r"
    argv = ["report", str(real_exports / BSDF), "--model", "microfacet", "--param", "n=1.5",
            "--param", "k=0", "--param", "diffuse=true", "--theta-i-range", "40:50",
            "-o", str(out), "--quiet"]  # fmt: skip
    assert main(argv) == 0
    res = json.loads((out / "results.json").read_text())
    checks = {c["id"]: c["status"] for c in res["checks"]}
    assert checks["fits.microfacet.success"] == "pass"
    assert res["meta"]["options"] == {"n": 1.5, "k": 0.0, "diffuse": True}


@pytest.mark.slow
def test_trace_exported_as_bsdf_is_read_back_and_fitted(tmp_path: Path, capsys, trace_sample):
    from labbrdf.tracer import TraceResult

    run, out = tmp_path / "al.npz", tmp_path / "al.bsdf"
    assert main([*trace_sample, "--rays", "400000", "--seed", "1",
                 "--single-scattering", "-o", str(run), "--scheduler", "serial"]) == 0  # fmt: skip
    assert main(["export", "--trace", str(run), "--radial", "0:60:3", "--azimuth", "0:350:10",
                 "-o", str(out)]) == 0  # fmt: skip
    capsys.readouterr()
    res, m = TraceResult.load(run), labbrdf.read(out)
    d = m.data
    assert m.meta["wavelength_stated"] and set(d.wavelength_nm) == {650.0}
    # every written point is the S0 of the bin its direction falls in, to the 6 digits written
    s0, te, pe = res.s0(), res.theta_r_edges_deg, res.phi_r_edges_deg
    i = np.searchsorted(te, d.theta_r_deg.to_numpy(), side="right") - 1
    phi = pe[0] + np.mod(d.phi_r_deg.to_numpy() - pe[0], 360.0)
    j = np.searchsorted(pe, phi, side="right") - 1
    np.testing.assert_allclose(d.value.to_numpy(), s0[i, j], rtol=5e-6, atol=1e-12)
    # the same run for Speos: the bins as written, at their centres
    sp = tmp_path / "al.anisotropicbsdf"
    assert main(["export", "--format", "speos-bsdf", "--trace", str(run), "-o", str(sp)]) == 0
    capsys.readouterr()
    ds = labbrdf.read(sp).data
    assert len(ds) == s0.size
    i = np.searchsorted(te, ds.theta_r_deg.to_numpy(), side="right") - 1
    j = np.searchsorted(pe, pe[0] + np.mod(ds.phi_r_deg.to_numpy() - pe[0], 360.0), "right") - 1
    np.testing.assert_allclose(ds.value.to_numpy(), np.nan_to_num(s0)[i, j], rtol=1e-12)
    # single scattering is the microfacet model: alpha comes back to the bins' smearing
    # (1 deg bins against a lobe ~ 2 alpha = 23 deg wide: about 1 %)
    fit = ["fit", str(out), "--model", "microfacet", "--param", "n=1.55", "--param", "k=7.71",
           "--weighting", "uniform", "--scheduler", "serial", "--json"]  # fmt: skip
    assert main(fit) == 0
    (g,) = _json(capsys)
    assert g["params"]["alpha"]["value"] == pytest.approx(0.2, rel=0.015)


def test_hemispherical_of_microfacet_from_ellipsometer_nk(real_exports: Path, capsys):
    # a nearly smooth microfacet surface reflects what Fresnel gives at normal incidence for
    # the ellipsometer's n, k (single scattering loses < 0.1 % at alpha 0.01)
    from labbrdf.ellipsometry import normal_reflectance
    from labbrdf.nk import combined_table, nk_at

    ta = str(real_exports / TA)
    argv = ["hemispherical", "--model", "microfacet", "--nk-from", ta, "--wavelength", "550",
            "--param", "alpha=0.01", "--theta-i", "0", "--json"]  # fmt: skip
    assert main(argv) == 0
    (row,) = _json(capsys)
    at = nk_at(combined_table(labbrdf.read(ta)), 550.0)
    r0, _ = normal_reflectance(float(at["n"]), float(at["k"]))
    assert row["rho"] == pytest.approx(float(r0), rel=1e-3)


def test_trace_coating_roughness_from_its_own_height_map(real_exports: Path, capsys):
    # the coating's top interface takes the ML GGX alpha of its own measured map
    from labbrdf.adapters.topography import read_height_map
    from labbrdf.roughness.topography import fit_slope_distribution, level, slopes

    di = real_exports / "topography" / "di-1.di"
    argv = ["trace", "--substrate", "1.55+7.71j", "--alpha", "0.1", "--coating", "1.5",
            "--thickness", "500", "--coating-surface", str(di), "--theta-i", "45",
            "--wavelength", "650", "--rays", "2000", "--scheduler", "serial",
            "--json"]  # fmt: skip
    assert main(argv) == 0
    s = _json(capsys)
    hm = read_height_map(di)
    sx, sy = slopes(level(hm.heights, 1), hm.pixel_size)
    assert s["config"]["coating"]["alpha"] == pytest.approx(
        fit_slope_distribution(sx, sy).ggx.alpha
    )
    assert s["config"]["substrate"]["alpha"] == 0.1
    capsys.readouterr()
    argv[argv.index("--coating-surface")] = "--coating-alpha"
    argv[argv.index(str(di))] = "0.2"
    assert main(argv + ["--coating-surface", str(di)]) == 2
    assert "once" in capsys.readouterr().err


@pytest.mark.slow
def test_bsdf_fits_are_consistent_once_vignetted_grazing_directions_are_left_out(
    real_exports: Path, capsys
):
    # The imaging sphere's values beyond theta_r = 70 deg are partly vignetted (next to the
    # horizon some are a third of their neighbours). With them, relative weighting lets
    # them decide several angles (chi2/nu 0.2-0.6, alpha at its bound at 65 deg); without
    # them every angle fits to a few % and alpha, kd change smoothly with the angle.
    argv = ["fit", str(real_exports / BSDF), "--model", "microfacet", "--param", "n=1.5",
            "--param", "k=0", "--param", "diffuse=true", "--by", "theta_i_deg",
            "--theta-r", ":70", "--scheduler", "serial", "--json"]  # fmt: skip
    assert main(argv) == 0
    out = _json(capsys)
    assert len(out) == 13 and all(g["success"] for g in out)
    alpha = np.array([g["params"]["alpha"]["value"] for g in out])
    kd = np.array([g["params"]["kd"]["value"] for g in out])
    assert all(np.sqrt(g["redchi"]) < 0.25 for g in out)
    assert np.all(np.diff(alpha) <= 0.01) and 0.2 < alpha.min() < alpha.max() < 0.35
    assert 0.09 < kd.min() < kd.max() < 0.14
