"""The report's ``brdf`` section: measured BRDF files (``.bsdf``) fitted per incidence.

The real Radiant export (``real_exports`` fixture, skipped where absent) and a synthetic
file written from a known microfacet; a dataset without BRDF rows skips the section.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from labbrdf import models
from labbrdf.adapters import zemax_bsdf as z
from labbrdf.report.user import user_report
from labbrdf.writers.zemax import model_to_bsdf, write_bsdf

MICRO = {"n": 1.5, "k": 0.0, "diffuse": True}
TRUTH = {"alpha": 0.2, "scale": 1.0, "kd": 0.1}
#: multiplicative noise of the synthetic file [1] (standard deviation of log value)
NOISE = 0.02


def _report(paths: list[Path], out: Path, model: str = "microfacet", **kw: Any) -> dict:
    opts = MICRO if model == "microfacet" else {}
    user_report(paths, model, out, options=opts, progress=False, **kw)
    return json.loads((out / "results.json").read_text())


def _section(res: dict, sid: str = "brdf") -> dict:
    return next(s for s in res["sections"] if s["id"] == sid)


def _check(res: dict, cid: str) -> dict:
    return next(c for c in res["checks"] if c["id"] == cid)


# --------------------------------------------------------------------------- real file


@pytest.fixture(scope="module")
def real(real_exports: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    f = real_exports / "zemax-bsdf" / "test_13_planesymmetric_brdf_zemax.bsdf"
    if not f.is_file():
        pytest.skip(f"{f} absent")
    return _report([f], tmp_path_factory.mktemp("rb") / "out"), f


def test_real_file_section_and_fits(real: tuple[dict, Path]) -> None:
    res, f = real
    sec = _section(res)
    assert sec["status"] == "ok"
    rows = res["tables"]["brdf_fits"]["rows"]
    per = [r for r in rows if r["theta_i"] != "joint"]
    assert len(per) == 13 and len(rows) == 14
    assert all(r["status"] != "failed" for r in rows)
    assert all(r["weighting"].startswith("relative") for r in rows)
    assert _check(res, "brdf.fits.success")["status"] == "pass"
    # three figures: selected maps, all residual maps, in-plane cuts
    assert sum(1 for k in res["figures"] if k.startswith("brdf_")) == 3


def test_real_file_energy_table(real: tuple[dict, Path]) -> None:
    res, f = real
    rows = res["tables"]["brdf_energy"]["rows"]
    m = z.read_zemax_bsdf(f)
    tis = {e["theta_i_deg"]: e["tis"] for e in m.meta["tis"]}
    assert len(rows) == 13
    for r in rows:
        assert r["tis"] == tis[r["theta_i"]]
        assert 0 < r["grid"] < r["tis"]
        assert 0 < r["uncovered"] < 1
        assert 0 < r["model"] <= 1
    assert _check(res, "brdf.energy")["status"] == "pass"
    assert res["tables"]["brdf_reciprocity"]["rows"][-1]["rel"] < 1e-12


# --------------------------------------------------------------------------- synthetic


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    d = tmp_path_factory.mktemp("syn")
    m = models.get("microfacet", **MICRO)
    clean = model_to_bsdf(
        m,
        TRUTH,
        d / "clean.bsdf",
        theta_i_deg=[20.0, 50.0],
        radial_deg=np.arange(0.0, 85.0, 5.0),
        azimuth_deg=np.arange(0.0, 181.0, 15.0),
    )
    t = z.read_table(clean)
    rng = np.random.default_rng(1)
    noisy = t.values * np.exp(NOISE * rng.standard_normal(t.values.shape))
    path = write_bsdf(
        d / "micro.bsdf",
        theta_i_deg=t.theta_i_deg,
        radial_deg=t.radial_deg,
        azimuth_deg=t.azimuth_deg,
        values=noisy,
        symmetry="PlaneSymmetrical",
    )
    return _report([path], d / "out"), path


def test_synthetic_alpha_recovered(synthetic: tuple[dict, Path]) -> None:
    res, _ = synthetic
    rows = res["tables"]["brdf_fits"]["rows"]
    assert len(rows) == 3 and all(r["status"] == "ok" for r in rows)
    # the table names the fitted distribution, the default GGX included
    assert res["tables"]["brdf_fits"]["title"].startswith("microfacet (GGX)")
    for r in rows:
        # alpha: the 95 % interval holds the generating value (2 % log-normal noise, seed 1)
        assert r["alpha_lo"] <= TRUTH["alpha"] <= r["alpha_hi"], r
        # kd: within twice the interval's half-width (about 4 sigma; at 95 % one of six
        # intervals misses the truth by chance about a quarter of the time)
        half = 0.5 * (r["kd_hi"] - r["kd_lo"])
        assert abs(r["kd"] - TRUTH["kd"]) <= 2.0 * half, r


def test_synthetic_energy_bookkeeping(synthetic: tuple[dict, Path]) -> None:
    """model rho = grid integral of the data + what the model puts outside the grid.

    The part outside the grid is taken from the generating model (its rho minus its own
    grid quadrature). What remains is the misfit of the fit on the grid: with 2 % noise on
    ~200 points per angle the fitted integral is good to a few 0.1 %; 1 % relative allows
    for the parameter errors (the intervals above are a few % of alpha).
    """
    from labbrdf import integrate

    res, path = synthetic
    m = models.get("microfacet", **MICRO)
    t = z.read_table(path)
    for r in res["tables"]["brdf_energy"]["rows"]:
        ti = r["theta_i"]
        rho_true = float(integrate.hemispherical_reflectance(m, TRUTH, [ti])[0])
        tr, pr, above = z.scatter_to_angles(ti, t.radial_deg[None, :], t.azimuth_deg[:, None])
        f = np.where(
            above, m.evaluate(np.radians(ti), np.radians(tr), np.radians(pr), params=TRUTH), 0.0
        )
        grid_true = float(
            z.grid_integral(
                {
                    "values": f[None, None, None],
                    "theta_i_deg": [ti],
                    "azimuth_deg": t.azimuth_deg,
                    "radial_deg": t.radial_deg,
                    "symmetry": "PlaneSymmetrical",
                }
            )["integral"].ravel()[0]
        )
        outside = rho_true - grid_true
        assert outside > 0
        assert r["model"] == pytest.approx(r["grid"] + outside, rel=0.01)
        assert r["model_outside"] == pytest.approx(outside, rel=0.05)


# --------------------------------------------------------------------------- no brdf rows


def test_in_plane_only_rows_have_cuts_not_maps(fixtures_dir: Path, tmp_path: Path) -> None:
    res = _report(
        [fixtures_dir / "specular" / "mirror_specular.csv"],
        tmp_path / "o",
        "smooth3",
        selection={"wavelength": (500.0, 600.0)},
    )
    sec = _section(res)
    assert sec["status"] == "ok", sec["reason"]
    notes = [it for it in sec["items"] if it["kind"] == "note"]
    assert any("plane of incidence" in it["text"] for it in notes)
    assert any(k.startswith("brdf_cuts_") for k in res["figures"])
    assert not any(k.startswith("brdf_maps_") for k in res["figures"])
    # no .bsdf file: the energy table has the model integral only; an in-plane scan does
    # not constrain the model over the hemisphere, so the energy check is skipped
    assert all(r.get("tis") is None for r in res["tables"]["brdf_energy"]["rows"])
    assert _check(res, "brdf.energy")["status"] == "skipped"


def test_no_brdf_rows_skipped(fixtures_dir: Path, tmp_path: Path) -> None:
    res = _report(
        [fixtures_dir / "spectrophotometer" / "osr_sphere_cary.csv"], tmp_path / "o", "smooth3"
    )
    sec = _section(res)
    assert sec["status"] == "not available"
    assert "no BRDF rows" in sec["reason"]
    c = _check(res, "brdf.available")
    assert c["status"] == "skipped"
    assert not any(x["section"] == "brdf" and x["status"] == "pass" for x in res["checks"])


def test_energy_check_fails_for_a_model_above_one(tmp_path: Path) -> None:
    """A file made from a microfacet with rho > 1 (scale 10 held fixed, kd 1) fails the check.

    Scale 10 is the top of its bounds: a start beyond them is refused.
    """
    m = models.get("microfacet", **MICRO)
    p = {"alpha": 0.3, "scale": 10.0, "kd": 1.0}
    rho = float(integrate_rho(m, p, 30.0))
    assert rho > 1.0
    path = model_to_bsdf(
        m,
        p,
        tmp_path / "bright.bsdf",
        theta_i_deg=[30.0],
        radial_deg=np.arange(0.0, 85.0, 10.0),
        azimuth_deg=np.arange(0.0, 181.0, 30.0),
    )
    res = _report([path], tmp_path / "o", start={"scale": 10.0})
    assert _check(res, "brdf.energy")["status"] == "fail"


def integrate_rho(m: Any, p: dict, ti: float) -> float:
    from labbrdf import integrate

    return float(integrate.hemispherical_reflectance(m, p, [ti])[0])
