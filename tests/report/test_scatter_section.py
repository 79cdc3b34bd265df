"""The report's ``scatter`` section: ABg and Harvey-Shack beside the physical models, the
TIS, and the designer's files written beside the page.

A synthetic ``.bsdf`` written from known ABg parameters with 2 % noise (recovered within 3
standard errors), its BTDF twin (only the transmission forms are fitted), and inputs
without a tabulated BSDF (the section is not available).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from labbrdf import models
from labbrdf.adapters import read
from labbrdf.adapters.zemax_bsdf import read_table
from labbrdf.bsdf_geometry import scatter_to_angles
from labbrdf.report.builder import Builder, write_report
from labbrdf.report.context import Context
from labbrdf.report.sections import run
from labbrdf.report.sections.scatter import scatter_section
from labbrdf.writers.zemax import model_to_bsdf, write_bsdf

TRUTH = {"A": 0.004, "B": 2e-4, "g": 1.6}
TI = np.array([10.0, 30.0, 50.0])
RAD = np.array([0.0, 0.5, 1, 2, 4, 8, 15, 25, 40, 60, 80])
AZ = np.arange(0, 181, 30.0)


def _abg_file(path: Path, scatter_type: str = "BRDF") -> Path:
    tr, pr, above = scatter_to_angles(TI[:, None, None], RAD[None, None, :], AZ[None, :, None])
    st = np.sin(np.radians(tr))
    d = np.hypot(
        st * np.cos(np.radians(pr)) + np.sin(np.radians(TI))[:, None, None],
        st * np.sin(np.radians(pr)),
    )
    f = TRUTH["A"] / (TRUTH["B"] + d ** TRUTH["g"])
    f = f * (1 + 0.02 * np.random.default_rng(3).standard_normal(f.shape))
    return write_bsdf(
        path,
        theta_i_deg=TI,
        radial_deg=RAD,
        azimuth_deg=AZ,
        values=np.where(above, f, 0.0)[None, None],
        symmetry="PlaneSymmetrical",
        scatter_type=scatter_type,
        digits=12,
    )


def _section(
    paths: list[Path], out: Path, model: str = "microfacet", **fit_options: Any
) -> tuple[dict, Builder]:
    from labbrdf.parallel import as_executor

    b = Builder("scatter test")
    ctx = Context(b=b, executor=as_executor("serial"), fit_options=fit_options)
    for p in paths:
        m = read(p)
        ctx.files.append({"path": str(p), "meta": m.meta})
        ctx.frames.append(m.data)
    run(ctx, [("scatter", "Scatter", lambda c: scatter_section(c, model, {}))])
    b.finish()
    write_report(out, b.results, "<html></html>", files=b.files)
    return b.results, b


@pytest.fixture(scope="module")
def brdf(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    """The section run once on the synthetic BRDF file; (results, report folder).

    With the report's own starting value for its microfacet (``--param alpha=0.3``): the
    Harvey fits (no alpha) and the section's microfacet (its own start) leave it alone.
    """
    tmp = tmp_path_factory.mktemp("scatter")
    res, _ = _section([_abg_file(tmp / "s.bsdf")], tmp / "out", params={"alpha": 0.3})
    return res, tmp / "out"


def test_abg_recovered_tis_and_designer_files(brdf: tuple[dict, Path]) -> None:
    res, out = brdf
    (sec,) = res["sections"]
    assert sec["status"] == "ok", sec["reason"]
    fits = res["tables"]["scatter_fits_s_555_0"]["rows"]
    assert [r["model"] for r in fits] == [
        "ABg",
        "ABg + Lambertian floor",
        "Harvey-Shack",
        "microfacet + Lambertian floor",
    ]
    abg = {
        r["param"]: r
        for r in res["tables"]["scatter_params_s_555_0"]["rows"]
        if r["model"] == "ABg"
    }
    for k, v in TRUTH.items():  # 2 % noise: within 3 standard errors
        assert abs(abg[k]["value"] - v) < 3 * abg[k]["stderr"], k
    # the file's own TIS line is the grid integral of what was written: ABg on the grid
    tis = [r for r in res["tables"]["scatter_tis_s_555_0"]["rows"] if r["model"] == "ABg"]
    assert len(tis) == 3
    assert all(r["ratio"] == pytest.approx(1.0, abs=0.02) for r in tis)
    names = sorted(p.name for p in (out / "designer").iterdir())
    assert names == sorted(
        ["s_555_0_abg.frs", "s_555_0_harvey_shack.frs"]
        + [f"s_555_0_{_best(fits)}.{e}" for e in ("bsdf", "anisotropicbsdf", "astm")]
    )
    linked = [it["name"] for it in sec["items"] if it["kind"] == "file"]
    assert sorted(linked) == names
    (check,) = [c for c in res["checks"] if c["id"] == "scatter.fits.success"]
    assert check["status"] == "pass" and check["value"] == 4


def _best(fits: list[dict]) -> str:
    best = min(
        (r for r in fits if not r["model"].startswith("microfacet")), key=lambda r: r["aic"]
    )
    return "harvey_shack" if best["model"].startswith("Harvey") else "abg"


def test_fred_script_evaluates_to_the_fitted_abg(brdf: tuple[dict, Path]) -> None:
    """The script's Acoef, Bcoef, G in FRED's ABg formula, written here independently:
    BSDF = A / (B + |beta - beta0|^g), beta the projected direction cosines."""
    res, out = brdf
    text = (out / "designer" / "s_555_0_abg.frs").read_text()
    coef = {
        k: float(re.search(rf"scat\.{k} = (\S+)", text).group(1))  # type: ignore[union-attr]
        for k in ("Acoef", "Bcoef", "G")
    }
    fitted = {
        r["param"]: r["value"]
        for r in res["tables"]["scatter_params_s_555_0"]["rows"]
        if r["model"] == "ABg"
    }
    ti, ts, ps = math.radians(30.0), math.radians(41.0), math.radians(150.0)
    d = math.hypot(math.sin(ts) * math.cos(ps) + math.sin(ti), math.sin(ts) * math.sin(ps))
    fred = coef["Acoef"] / (coef["Bcoef"] + d ** coef["G"])
    ours = float(models.get("abg").evaluate(ti, ts, ps, params=fitted))
    assert fred == pytest.approx(ours, rel=1e-6)  # the table rounds the values to 6 digits


def test_best_fit_table_reads_back(brdf: tuple[dict, Path]) -> None:
    res, out = brdf
    fits = res["tables"]["scatter_fits_s_555_0"]["rows"]
    path = out / "designer" / f"s_555_0_{_best(fits)}.bsdf"
    t = read_table(path)
    assert list(t.theta_i_deg) == list(TI)
    # the measurement stated no wavelength, so neither does the table written from its fit
    assert "wavelength_nm" not in path.read_text(encoding="ascii")
    assert np.all(np.asarray(t.values) >= 0) and np.asarray(t.values).max() > 1.0


def test_btdf_file_gets_the_transmission_forms_only(tmp_path: Path) -> None:
    res, _ = _section([_abg_file(tmp_path / "t.bsdf", "BTDF")], tmp_path / "out")
    (sec,) = res["sections"]
    assert sec["status"] == "ok", sec["reason"]
    fits = res["tables"]["scatter_fits_t_555_0_btdf"]["rows"]
    assert [r["model"] for r in fits] == [
        "ABg (BTDF)",
        "ABg + Lambertian floor (BTDF)",
        "Harvey-Shack (BTDF)",
    ]
    g = {
        r["param"]: r
        for r in res["tables"]["scatter_params_t_555_0_btdf"]["rows"]
        if r["model"] == "ABg (BTDF)"
    }
    assert abs(g["g"]["value"] - TRUTH["g"]) < 3 * g["g"]["stderr"]
    names = sorted(p.name for p in (tmp_path / "out" / "designer").iterdir())
    assert names == ["t_555_0_btdf_abg.frs", "t_555_0_btdf_harvey_shack.frs"]
    assert "scat.ApplyTrans = True" in (tmp_path / "out" / "designer" / names[0]).read_text()


def test_no_tabulated_file_not_available(tmp_path: Path) -> None:
    import labbrdf

    scan = Path(labbrdf.__file__).parent / "data" / "fixtures" / "specular" / "osr_specular.csv"
    res, _ = _section([scan], tmp_path / "out")
    (sec,) = res["sections"]
    assert sec["status"] == "not available"
    assert "no tabulated BSDF file among the inputs" in sec["reason"]


def test_tristimulus_file_fits_the_y_channel(tmp_path: Path) -> None:
    """X and Z at other scales than Y: fitting them together would mix three BSDFs."""
    mono = _abg_file(tmp_path / "y.bsdf")
    base = read_table(mono)
    values = np.asarray(base.values)[:, :1] * np.array([0.5, 1.0, 2.0])[None, :, None, None, None]
    path = write_bsdf(
        tmp_path / "xyz.bsdf",
        theta_i_deg=TI,
        radial_deg=RAD,
        azimuth_deg=AZ,
        values=values,
        symmetry="PlaneSymmetrical",
        spectral="XYZ",
        digits=12,
    )
    res, _ = _section([path], tmp_path / "out")
    (sec,) = res["sections"]
    assert any(it.get("label") == "tristimulus" for it in sec["items"])
    (abg, *_) = res["tables"]["scatter_fits_xyz_555_0"]["rows"]
    y = read(mono).data
    assert abg["ndata"] == int((y["value"] != 0).sum())  # one channel's points
    assert abg["redchi"] < 2 * 0.02**2  # relative weights: the 2 % noise, no channel mix
    rows = res["tables"]["scatter_params_xyz_555_0"]["rows"]
    a = next(r for r in rows if r["model"] == "ABg" and r["param"] == "A")
    assert abs(a["value"] - TRUTH["A"]) < 3 * a["stderr"]  # Y: the written scale


@pytest.mark.parametrize("name", ["../x.frs", "designer/x.frs", "", ".hidden", "a" * 130])
def test_a_linked_file_is_a_plain_new_name(name: str) -> None:
    b = Builder("t")
    with b.section("s", "S"):
        b.file("ok.frs", "fine", b"x")
        with pytest.raises(ValueError, match="expected a new plain file name"):
            b.file(name, "bad", b"x")
        with pytest.raises(ValueError, match="expected a new plain file name"):
            b.file("ok.frs", "twice", b"x")


def test_speos_file_gets_its_tis_table(tmp_path: Path) -> None:
    from labbrdf.writers.speos import model_to_speos

    path = model_to_speos(
        models.get("abg"),
        {"A": 0.01, "B": 0.01, "g": 1.8},
        tmp_path / "sp.anisotropicbsdf",
        theta_i_deg=[10.0, 40.0],
        theta_deg=np.arange(0, 91, 5.0),
        phi_deg=np.arange(0, 361, 30.0),
        wavelength_nm=633.0,
    )
    res, _ = _section([path], tmp_path / "out")
    (sec,) = res["sections"]
    assert sec["status"] == "ok", sec["reason"]
    tis = res["tables"]["scatter_tis_sp_633_0"]["rows"]
    abg = [r for r in tis if r["model"].startswith("ABg")]
    assert [r["theta_i_deg"] for r in abg] == [10.0, 40.0]
    assert all(r["ratio"] == pytest.approx(1.0, abs=1e-3) for r in abg)  # noiseless ABg


def test_a_designer_file_the_writer_refuses_is_a_note(tmp_path: Path) -> None:
    """Scatter above the incident power (TIS > 1): Speos refuses such a spectrum; the page
    says so and the other files are written."""
    m = models.get("abg")
    p = {"A": 0.5, "B": 1e-3, "g": 2.0}
    assert float(m.hemispherical(30.0, p)) > 1.0
    path = model_to_bsdf(
        m,
        p,
        tmp_path / "bright.bsdf",
        theta_i_deg=[30.0],
        radial_deg=RAD,
        azimuth_deg=AZ,
    )
    res, _ = _section([path], tmp_path / "out")
    (sec,) = res["sections"]
    assert sec["status"] == "ok", sec["reason"]
    notes = [it for it in sec["items"] if it["kind"] == "note" and "not written" in it["text"]]
    assert [n["label"].rsplit(".", 1)[1] for n in notes] == ["anisotropicbsdf"]
    assert "a Speos spectrum needs a reflectance in (0, 1]" in notes[0]["text"]
    names = sorted(q.suffix for q in (tmp_path / "out" / "designer").iterdir())
    assert ".bsdf" in names and ".astm" in names and ".anisotropicbsdf" not in names
