"""The ``surface`` section of the user report and the Gaussian-ACF validation check."""

from __future__ import annotations

import json
import math
from pathlib import Path
from types import SimpleNamespace

import pytest

from labbrdf.report import user_report
from labbrdf.report.builder import Builder
from labbrdf.report.context import Context
from labbrdf.report.sections import surface as surf

pytest.importorskip("SurfaceTopography")


def _checks(res: dict) -> dict[str, dict]:
    return {c["id"]: c for c in res["checks"]}


@pytest.fixture(scope="module")
def topo_report(real_exports: Path, tmp_path_factory: pytest.TempPathFactory) -> dict:
    d = real_exports / "topography"
    if not (d / "di-1.di").is_file() or not (d / "opdx-3.opdx").is_file():
        pytest.skip(f"{d} lacks di-1.di / opdx-3.opdx")
    out = tmp_path_factory.mktemp("topo") / "rep"
    code = user_report([d / "di-1.di", d / "opdx-3.opdx"], "smooth3", out, progress=False)
    res = json.loads((out / "results.json").read_text())
    return {"code": code, "res": res, "dir": d, "html": (out / "index.html").read_text()}


def test_section_present_and_passes(topo_report: dict) -> None:
    res = topo_report["res"]
    sec = {s["id"]: s for s in res["sections"]}
    assert sec["surface"]["status"] == "ok"
    assert topo_report["code"] == 0
    assert _checks(res)["ingest.topography"]["status"] == "pass"
    files = {r["file"]: r for r in res["tables"]["ingested_height_maps"]["rows"]}
    assert files["di-1.di"]["kind"] == "areal map"
    assert files["opdx-3.opdx"]["kind"] == "profile"
    assert "surface_di_1_di" in res["figures"]
    assert "surface_tracer_di_1_di" in res["figures"]
    assert "surface_tracer_opdx_3_opdx" not in res["figures"]


@pytest.mark.parametrize("name", ["di-1.di", "opdx-3.opdx"])
def test_sigma_matches_roughness_statistics(topo_report: dict, name: str) -> None:
    from labbrdf.adapters.topography import read_height_map
    from labbrdf.roughness.topography import roughness_statistics

    hm = read_height_map(topo_report["dir"] / name)
    st = roughness_statistics(hm.heights, hm.pixel_size)
    sid = name.replace("-", "_").replace(".", "_")
    rows = {r["key"]: r for r in topo_report["res"]["tables"][f"surface_stats_{sid}"]["rows"]}
    assert rows["sigma"]["value"] * 1e-9 == pytest.approx(st.sigma, rel=1e-12)
    assert rows["sigma"]["u"] * 1e-9 == pytest.approx(st.uncertainty["sigma"], rel=1e-12)
    fits = {r["model"]: r for r in topo_report["res"]["tables"][f"surface_fits_{sid}"]["rows"]}
    assert fits["ggx"]["alpha"] == pytest.approx(st.slope_fits.ggx.alpha, rel=1e-12)


def test_tracer_albedos_for_map_not_profile(topo_report: dict) -> None:
    rows = topo_report["res"]["tables"]["surface_tracer_albedo"]["rows"]
    di = {r["case"]: r for r in rows if r["file"] == "di-1.di"}
    assert set(di) == {"measured", "ggx"}
    for r in di.values():
        assert 0.0 < r["albedo"] < 1.0 and r["rays"] == surf.TRACE_RAYS
        assert r["albedo_u"] < 0.5 / math.sqrt(r["rays"])
    (prof,) = [r for r in rows if r["file"] == "opdx-3.opdx"]
    assert prof["albedo"] is None and "profile" in prof["reason"]
    assert "assume" in topo_report["html"] and "isotropic" in topo_report["html"]


def test_corrupt_topography_file_is_a_failed_ingest(tmp_path: Path) -> None:
    bad = tmp_path / "broken.di"
    bad.write_bytes(b"\\*File list\r\n\\Version: 0x0\r\ngarbage" + bytes(range(256)) * 4)
    code = user_report([bad], "smooth3", tmp_path / "rep", progress=False)
    res = json.loads((tmp_path / "rep" / "results.json").read_text())
    assert code == 1
    c = _checks(res)["ingest.unreadable"]
    assert c["status"] == "fail" and "broken.di" in c["reason"]
    assert "SurfaceTopography" in c["reason"]
    assert "ingested_height_maps" not in res["tables"]
    assert not any(ch["id"].endswith(".completed") for ch in res["checks"])


def _acf_checks() -> dict[str, dict]:
    b = Builder("t")
    with b.section("surface", "t"):
        surf.gaussian_acf_section(Context(b))
    return _checks(b.results)


def test_acf_check_passes_with_corrected_exponent() -> None:
    c = _acf_checks()
    assert c["surface.gaussian_acf"]["status"] == "pass"
    assert c["surface.printed_exponent_fails"]["status"] == "pass"
    assert c["surface.printed_exponent_fails"]["value"] > 1.0


def test_acf_check_fails_with_printed_exponent(monkeypatch: pytest.MonkeyPatch) -> None:
    def printed(n: int, length: float, sigma: float, c: tuple, seed: int) -> SimpleNamespace:
        return SimpleNamespace(z=surf.printed_psd_surface(n, length, sigma, c, seed))

    monkeypatch.setattr(surf, "gaussian_surface", printed)
    c = _acf_checks()
    assert c["surface.gaussian_acf"]["status"] == "fail"
    assert c["surface.gaussian_acf"]["value"] > 1.0


@pytest.mark.parametrize("seed", range(5))
def test_acf_tolerance_holds_over_seeds(seed: int) -> None:
    L, N = surf.ACF_LENGTH_UM, surf.ACF_GRID
    from labbrdf.roughness.synthetic import gaussian_surface

    for sigma, cx, cy in surf.ACF_CASES:
        tol = surf.ACF_TOL_FACTOR * math.sqrt(cx * cy) / L
        z = gaussian_surface(N, L, sigma, (cx, cy), 1000 + seed).z
        assert max(surf.acf_deviation(z, L / N, (cx, cy))) <= tol
        zp = surf.printed_psd_surface(N, L, sigma, (cx, cy), 1000 + seed)
        assert min(surf.acf_deviation(zp, L / N, (cx, cy))) > tol


def test_wvase_dat_stays_optical_beside_a_height_map(
    real_exports: Path, fixtures_dir: Path, tmp_path: Path
) -> None:
    di = real_exports / "topography" / "di-1.di"
    if not di.is_file():
        pytest.skip(f"{di} absent")
    wvase = fixtures_dir / "ellipsometry" / "al_bare_wvase.dat"
    out = tmp_path / "rep"
    user_report([wvase, di], "smooth3", out, progress=False)
    res = json.loads((out / "results.json").read_text())
    optical = [r["file"] for r in res["tables"]["ingested_files"]["rows"]]
    maps = [r["file"] for r in res["tables"]["ingested_height_maps"]["rows"]]
    assert optical == [wvase.name] and maps == [di.name]
    c = _checks(res)
    assert c["ingest.read"]["status"] == "pass" and c["ingest.topography"]["status"] == "pass"


# ----------------------------------------------------------------- the tracer's substrate


def _group_ctx(hm_path: Path, psi_paths: list[Path]) -> tuple[Context, object]:
    """A report context holding one height map and psi/Delta files, all one sample."""
    from labbrdf import read
    from labbrdf.adapters.topography import read_height_map
    from labbrdf.parallel import as_executor
    from labbrdf.samples import pair_samples

    ctx = Context(Builder("t", progress=False), executor=as_executor("serial", progress=False))
    hm = read_height_map(hm_path)
    ctx.height_maps.append(hm)
    ctx.frames.extend(read(p).data for p in psi_paths)
    given = [[hm_path, *psi_paths]] if psi_paths else []
    ctx.samples[:] = pair_samples([hm_path, *psi_paths], given)
    return ctx, hm


@pytest.fixture()
def real_files(real_exports: Path) -> SimpleNamespace:
    w = real_exports / "woollam-wvase-ascii"
    ns = SimpleNamespace(
        di=real_exports / "topography" / "di-1.di",
        ta=w / "w2_10102006.dat",  # bare tantalum
        coated=w / "w1_12082006.dat",  # Ta2O5 on Ta: its angles disagree
    )
    for p in vars(ns).values():
        if not p.is_file():
            pytest.skip(f"{p} absent")
    return ns


def test_the_tracer_maps_take_the_groups_measured_index_as_trace_nk_from(
    real_files: SimpleNamespace, monkeypatch: pytest.MonkeyPatch
) -> None:
    from labbrdf import trace
    from labbrdf.sample import trace_config_from_inputs

    ctx, hm = _group_ctx(real_files.di, [real_files.coated, real_files.ta])
    index, whence = surf.substrate_index(ctx, hm)
    # the stack's file is passed over (saying why), the bare one is taken
    assert "w2_10102006.dat" in whence and whence.startswith("measured")
    monkeypatch.setattr(surf, "TRACE_RAYS", 4000)
    r_meas, _, _ = surf._trace_pair(ctx, hm, 0.3, index)
    cfg = trace_config_from_inputs(
        surf.TRACE_WAVELENGTH_NM,
        surf.TRACE_THETA_I_DEG,
        nk_from=real_files.ta,
        surface=real_files.di,
        rays=4000,
        seed=ctx.seed,
        theta_step_deg=surf.TRACE_STEP_DEG,
        phi_step_deg=surf.TRACE_STEP_DEG,
    )
    assert complex(cfg.substrate.n, cfg.substrate.k) == index
    assert r_meas.albedo() == trace(cfg).albedo()


def test_the_tracer_maps_fall_back_to_the_stated_default_saying_why(
    real_files: SimpleNamespace,
) -> None:
    ctx, hm = _group_ctx(real_files.di, [real_files.coated])
    index, whence = surf.substrate_index(ctx, hm)
    assert index == complex(*surf.SUBSTRATE_NK)
    assert "not measured" in whence and "w1_12082006.dat" in whence and "--nk-from" in whence
    alone, hm = _group_ctx(real_files.di, [])
    assert "no psi/Delta file" in surf.substrate_index(alone, hm)[1]
    given = surf.substrate_index(ctx, hm, (str(real_files.ta), 1.5 + 2.0j))
    assert given == (1.5 + 2.0j, "measured: the bulk n, k of w2_10102006.dat (--nk-from)")


def test_report_nk_from_a_file_without_an_index_exits_2_before_any_work(
    real_files: SimpleNamespace, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from labbrdf.cli import main

    out = tmp_path / "rep"
    code = main(
        ["report", str(real_files.di), "--nk-from", str(real_files.coated), "-o", str(out)]
    )
    err = capsys.readouterr().err
    last = err.strip().splitlines()[-1]  # after the inversion's own warning
    assert code == 2 and "w1_12082006.dat" in last and "stack" in last
    assert "Traceback" not in err and not out.exists()
