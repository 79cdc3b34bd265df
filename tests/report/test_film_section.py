"""Section film of the user report: a stack fitted to angle-dependent psi/Delta."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf.cli import main
from labbrdf.dataset import Measurement, make_frame, write_csv
from labbrdf.report.sections.film import default_film_model, film_model_of
from labbrdf.report.user import user_report

# the synthetic sample: 120 nm of Cauchy n = 1.46 + 0.004/lambda^2 [um] on n = 3.9 + 0.02i
D_NM, A, B = 120.0, 1.46, 0.004
N_SUB = 3.9 + 0.02j
WL = np.arange(400.0, 901.0, 20.0)
ANGLES = (55.0, 65.0, 75.0)

MODEL = """\
[substrate]
material = "constant"
n = 3.9
k = 0.02

[[layer]]
name = "oxide"
material = "cauchy"
thickness_nm = [60, 200]
A = [1.3, 1.7]
B = [0.0, 0.02]
C = 0
"""


def _airy(wl: np.ndarray, theta_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """r_s, r_p of one film (Airy summation, written out here as an independent check)."""
    n1 = A + B / (wl / 1000.0) ** 2
    s0 = np.sin(np.radians(theta_deg))
    c0 = np.cos(np.radians(theta_deg)) + 0j
    c1 = np.sqrt(1 - (s0 / n1) ** 2 + 0j)
    c2 = np.sqrt(1 - (s0 / N_SUB) ** 2 + 0j)
    rs01 = (c0 - n1 * c1) / (c0 + n1 * c1)
    rs12 = (n1 * c1 - N_SUB * c2) / (n1 * c1 + N_SUB * c2)
    rp01 = (n1 * c0 - c1) / (n1 * c0 + c1)
    rp12 = (N_SUB * c1 - n1 * c2) / (N_SUB * c1 + n1 * c2)
    ph = np.exp(4j * np.pi * D_NM * n1 * c1 / wl)
    rs = (rs01 + rs12 * ph) / (1 + rs01 * rs12 * ph)
    rp = (rp01 + rp12 * ph) / (1 + rp01 * rp12 * ph)
    return rs, rp


def _files(tmp: Path) -> tuple[Path, Path]:
    ell, refl = [], []
    for th in ANGLES:
        rs, rp = _airy(WL, th)
        rho = rp / rs  # with N = n + ik; the Nebraska Delta is -arg(rho) (labbrdf.optics)
        psi = np.degrees(np.arctan(np.abs(rho)))
        delta = -np.degrees(np.angle(rho)) % 360.0
        for q, v, s in (("psi", psi, 0.02), ("delta", delta, 0.05)):
            ell.append(
                make_frame(sample="wafer A", instrument="synthetic", source="wafer_psi.csv",
                           quantity=q, value=v, sigma=s, unit="deg", wavelength_nm=WL,
                           theta_i_deg=th, theta_r_deg=th, phi_r_deg=180.0)
            )  # fmt: skip
        for ch, r in (("s", rs), ("p", rp)):
            f = make_frame(sample="wafer A", instrument="synthetic", source="wafer_R.csv",
                           quantity="reflectance", value=np.abs(r) ** 2, sigma=0.002, unit="1",
                           wavelength_nm=WL, theta_i_deg=th, theta_r_deg=th,
                           phi_r_deg=180.0)  # fmt: skip
            refl.append(f.assign(channel=ch))

    pe, pr = tmp / "wafer_psi.csv", tmp / "wafer_R.csv"
    write_csv(Measurement(pd.concat(ell, ignore_index=True), {}), pe)
    write_csv(Measurement(pd.concat(refl, ignore_index=True), {}), pr)
    return pe, pr


@pytest.fixture(scope="module")
def fitted(tmp_path_factory: pytest.TempPathFactory) -> dict:
    tmp = tmp_path_factory.mktemp("film")
    pe, pr = _files(tmp)
    model = tmp / "stack.toml"
    model.write_text(MODEL)
    out = tmp / "rep"
    code = user_report([pe, pr], "smooth3", out, progress=False, film_model=model)
    res = json.loads((out / "results.json").read_text())
    res["_code"] = code
    return res


def test_film_fit_recovers_the_synthetic_stack(fitted: dict) -> None:
    sec = {s["id"]: s for s in fitted["sections"]}
    assert sec["film"]["status"] == "ok"
    rows = {r["parameter"]: r for r in fitted["tables"]["film_0_wafer_psi_csv_params"]["rows"]}
    assert set(rows) == {"oxide.thickness_nm", "oxide.A", "oxide.B"}
    # noise-free data: the global optimum is the truth, to the optimiser's tolerance
    assert rows["oxide.thickness_nm"]["value"] == pytest.approx(D_NM, abs=0.05)
    assert rows["oxide.A"]["value"] == pytest.approx(A, abs=1e-3)
    assert rows["oxide.B"]["value"] == pytest.approx(B, abs=5e-4)
    for r in rows.values():
        assert r["ci_lo"] <= r["value"] <= r["ci_hi"]
    # noise-free and well determined: chi2 is quadratic over the intervals, no profile
    assert {r["interval"] for r in rows.values()} == {"wald"}


def test_reflectance_predicted_by_the_stack_agrees(fitted: dict) -> None:
    # R was not fitted: it is predicted from the stack fitted to psi/Delta alone
    chk = [c for c in fitted["checks"] if c["id"].startswith("film.reflectance")]
    assert len(chk) == 1 and chk[0]["status"] == "pass"
    row = fitted["tables"]["film_reflectance_comparison"]["rows"][0]
    assert row["quantity"] == "R_p/s" and row["points"] == 2 * len(ANGLES) * len(WL)
    assert abs(row["mean_diff"]) < 1e-3 and row["rms_diff"] < 2e-3
    # the bare-substrate Fresnel comparison of section nk is not applicable here
    nk = [c for c in fitted["checks"] if c["id"].startswith("nk.reflectance")]
    assert nk and all(c["status"] == "skipped" for c in nk)
    assert fitted["_code"] == 0
    figs = set(fitted["figures"])
    assert {"film_0_wafer_psi_csv_psi_delta", "film_0_wafer_psi_csv_nk"} <= figs


def test_a_wrong_stack_fails_the_reflectance_check(tmp_path: Path) -> None:
    # the substrate a bit off (n = 3.6): psi/Delta are fitted as well as they can be, and
    # the reflectance predicted from that stack disagrees with the measured one
    pe, pr = _files(tmp_path)
    model = tmp_path / "wrong.toml"
    model.write_text(MODEL.replace("n = 3.9", "n = 3.0"))
    code = user_report([pe, pr], "smooth3", tmp_path / "rep", progress=False, film_model=model)
    res = json.loads((tmp_path / "rep" / "results.json").read_text())
    chk = next(c for c in res["checks"] if c["id"].startswith("film.reflectance"))
    assert chk["status"] == "fail" and code == 1


def test_no_model_says_how_to_give_one(tmp_path: Path) -> None:
    pe, pr = _files(tmp_path)
    user_report([pe, pr], "smooth3", tmp_path / "rep", progress=False)
    res = json.loads((tmp_path / "rep" / "results.json").read_text())
    film = next(s for s in res["sections"] if s["id"] == "film")
    assert film["status"] == "not available"
    assert "--film-model FILE.toml" in film["reason"] and "--film-default" in film["reason"]
    assert res["summary"]["exit_code"] == 0


def test_default_model_is_cauchy_on_silicon_with_thickness_free() -> None:
    fm = default_film_model()
    assert [lay.material.name for lay in fm.stack.layers] == ["cauchy"]
    assert fm.stack.substrate.name == "tabulated" and "Si" in fm.stack.substrate.source
    assert fm.free["film.thickness_nm"] == (0.0, 1000.0)
    assert {"film.A", "film.B"} <= set(fm.free) and "film.C" not in fm.free
    assert fm.wavelength_range_nm == (250.0, 1450.0)
    assert film_model_of(None) == (None, "")
    assert film_model_of(fm) == (fm, fm.source)


@pytest.mark.parametrize(
    ("text", "line", "what"),
    [
        (MODEL.replace("A = [1.3, 1.7]", "A = [1.7, 1.3]"), 10, "impossible bounds"),
        (MODEL.replace('material = "cauchy"', 'material = "cauchyy"'), 8, "unknown material"),
        (MODEL.replace("B = [0.0, 0.02]", "Q = 1"), 11, "unknown parameter"),
    ],
)
def test_report_with_a_broken_model_file_is_exit_2(
    tmp_path: Path, capsys, text: str, line: int, what: str
) -> None:
    pe, pr = _files(tmp_path)
    model = tmp_path / "broken.toml"
    model.write_text(text)
    out = tmp_path / "rep"
    argv = ["report", str(pe), str(pr), "-o", str(out), "--quiet", "--film-model", str(model)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"{model}, line {line}" in err and what in err
    assert "Traceback" not in err and not out.exists()


def test_report_with_a_missing_model_file_is_exit_2(tmp_path: Path, capsys) -> None:
    pe, pr = _files(tmp_path)
    out = tmp_path / "rep"
    argv = ["report", str(pe), "-o", str(out), "--film-model", str(tmp_path / "none.toml")]
    assert main(argv) == 2
    assert "none.toml" in capsys.readouterr().err and not out.exists()


def test_film_model_and_default_exclude_each_other(tmp_path: Path, capsys) -> None:
    pe, _ = _files(tmp_path)
    model = tmp_path / "stack.toml"
    model.write_text(MODEL)
    argv = ["report", str(pe), "-o", str(tmp_path / "rep"), "--film-model", str(model)]
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--film-default"])
    assert exc.value.code == 2 and "not allowed with" in capsys.readouterr().err


def test_a_model_file_inside_the_report_folder_is_never_replaced(tmp_path: Path, capsys) -> None:
    pe, _ = _files(tmp_path)
    out = tmp_path / "rep"
    out.mkdir()
    model = out / "stack.toml"
    model.write_text(MODEL)
    argv = ["report", str(pe), "-o", str(out), "--overwrite", "--film-model", str(model)]
    assert main(argv) == 2
    assert "stack.toml" in capsys.readouterr().err
    assert model.read_text() == MODEL


def test_film_default_fits_the_stated_default(tmp_path: Path) -> None:
    pe, _ = _files(tmp_path)
    out = tmp_path / "rep"
    assert main(["report", str(pe), "-o", str(out), "--quiet", "--film-default"]) in (0, 1)
    res = json.loads((out / "results.json").read_text())
    assert res["meta"]["film_model"] == default_film_model().source
    rows = res["tables"]["film_0_wafer_psi_csv_params"]["rows"]
    assert {r["parameter"] for r in rows} == {"film.thickness_nm", "film.A", "film.B"}


def test_a_wrapping_delta_curve_is_drawn_with_a_gap_not_a_vertical_line() -> None:
    import numpy as np

    from labbrdf.report.sections.film import _break_at_wraps

    x = np.array([1.0, 2.0, 3.0, 4.0])
    xb, yb = _break_at_wraps(x, np.array([350.0, 355.0, 2.0, 8.0]))
    assert np.isnan(yb[2]) and np.isnan(xb[2]) and len(yb) == 5
    xb, yb = _break_at_wraps(x, np.array([10.0, 20.0, 30.0, 40.0]))
    assert not np.isnan(yb).any()
