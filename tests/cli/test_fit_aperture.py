"""``labbrdf fit --aperture``: the aperture a file states or the option gives, the fit
without it beside, and the refusals (a cone out of range, a model that cannot be averaged,
files that disagree)."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from labbrdf import models
from labbrdf.cli import main
from labbrdf.models.aperture import Apertured

SMOOTH = {"A": 2e-5, "B": 1e-4, "g": 2.0}  # shoulder B^(1/g) = 0.57 deg


def _scan(path: Path, header: str = "# detector_half_angle_deg: 1\n") -> Path:
    """In-plane scans of a smooth ABg sample through a 1 deg detector cone, 2 % noise."""
    off = np.array([-30, -15, -8, -5, -3, -2, -1.5, -1, -0.75, -0.5, -0.25, 0.0])
    off = np.concatenate([off, -off[-2::-1]])
    ti = np.repeat([10.0, 30.0], off.size)
    sc = np.tile(off, 2) + ti  # signed detector angle: < 0 on the source's side
    truth = Apertured(models.get("abg"), detector_deg=1.0, nodes=(32, 96))
    tr, pr = np.abs(sc), np.where(sc >= 0, 180.0, 0.0)
    y = truth.evaluate(np.radians(ti), np.radians(tr), np.radians(pr), params=SMOOTH)
    y = y * (1 + 0.02 * np.random.default_rng(5).standard_normal(y.size))
    rows = "".join(
        f"633,{a:.17g},{b:.17g},{v:.17g},{0.02 * v:.17g}\n"
        for a, b, v in zip(ti, sc, y, strict=True)
    )
    path.write_text(
        "# labbrdf specular-scan v1\n# sample: smooth\n# quantity: brdf\n"
        + header
        + "wavelength_nm,theta_i_deg,theta_r_deg,value,sigma\n"
        + rows
    )
    return path


def _fit_json(capsys, *argv: str) -> dict:
    assert main(["fit", *argv, "--model", "abg", "--scheduler", "serial", "--json"]) == 0
    (rec,) = json.loads(capsys.readouterr().out)
    return rec


@pytest.fixture(scope="module")
def stated(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    """The JSON record of ``fit s.csv --model abg`` (the file states a 1 deg detector)."""
    tmp = tmp_path_factory.mktemp("aperture")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        argv = ["fit", str(_scan(tmp / "s.csv")), "--model", "abg", "--scheduler", "serial"]
        code = main([*argv, "--json"])
    assert code == 0
    (rec,) = json.loads(out.getvalue())
    return rec, tmp


def test_the_files_aperture_is_used_and_the_moves_reported(stated: tuple[dict, Path]) -> None:
    rec, _ = stated
    ap = rec["aperture"]
    assert (ap["detector_deg"], ap["beam_deg"]) == (1.0, 0.0)
    assert ap["source"] == "stated by s.csv"
    assert rec["options"] == {"detector_deg": 1.0, "beam_deg": 0.0}
    for k, v in SMOOTH.items():  # through the aperture: the sample's values
        p = rec["params"][k]
        assert abs(p["value"] - v) < 3 * p["stderr"], k
    # without it the instrument's width is read as the sample's shoulder
    assert ap["moves"]["B"]["shift_sigma"] > 10 and ap["moves"]["B"]["shift_rel"] > 0.3
    assert ap["redchi_without"] > 5 > 1.5 > rec["redchi"]


def test_option_overrides_the_file_and_zero_fits_without(tmp_path: Path, capsys) -> None:
    rec = _fit_json(capsys, str(_scan(tmp_path / "s.csv")), "--aperture", "0")
    ap = rec["aperture"]
    assert ap["detector_deg"] == 0.0 and ap["moves"] == {}
    assert ap["source"] == "--aperture, overriding 1, 0 deg stated by s.csv"
    assert rec["options"] == {}
    assert rec["params"]["B"]["value"] > 1.3 * SMOOTH["B"]  # the biased shoulder


def test_text_report_names_the_aperture(tmp_path: Path, capsys) -> None:
    path = _scan(tmp_path / "s.csv", header="")
    argv = ["fit", str(path), "--model", "abg", "--aperture", "1,0", "--scheduler", "serial"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "aperture: detector 1 deg, beam 0 deg (half-angles; --aperture)" in out
    assert "chi2/nu without the aperture" in out and "shift_sigma" in out


@pytest.mark.parametrize(
    ("value", "why"),
    [
        ("-1", "each half-angle must be in [0, 20] deg"),
        ("45", "each half-angle must be in [0, 20] deg"),
        ("nan", "each half-angle must be in [0, 20] deg"),
        ("1,2,3", "expected DETECTOR_DEG or DETECTOR_DEG,BEAM_DEG"),
        ("one", "expected DETECTOR_DEG or DETECTOR_DEG,BEAM_DEG"),
    ],
)
def test_bad_cone_exits_2(tmp_path: Path, capsys, value: str, why: str) -> None:
    path = _scan(tmp_path / "s.csv", header="")
    with pytest.raises(SystemExit) as exc:
        main(["fit", str(path), "--model", "abg", f"--aperture={value}"])
    assert exc.value.code == 2
    assert f"error: argument --aperture: {value!r}: {why}" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("model", "extra", "message"),
    [
        ("smooth3", [], "describes the plane of incidence only"),
        ("layered", ["--param", "n=1.5", "--param", "k=7"], "is a Monte Carlo estimate"),
    ],
)
def test_model_that_cannot_be_apertured_exits_2(
    tmp_path: Path, capsys, model: str, extra: list, message: str
) -> None:
    path = _scan(tmp_path / "s.csv")
    assert main(["fit", str(path), "--model", model, *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"labbrdf fit: --aperture: model {model!r}") and message in err
    assert "\n" not in err and "Traceback" not in err


def test_files_stating_different_apertures_exit_2(tmp_path: Path, capsys) -> None:
    a = _scan(tmp_path / "a.csv")
    b = _scan(tmp_path / "b.csv", header="# detector_half_angle_deg: 2\n")
    assert main(["fit", str(a), str(b), "--model", "abg"]) == 2
    err = capsys.readouterr().err.strip()
    assert "the files state different apertures (a.csv: 1, 0 deg; b.csv: 2, 0 deg)" in err
    assert "\n" not in err


def test_bad_stated_half_angle_names_the_file(tmp_path: Path, capsys) -> None:
    path = _scan(tmp_path / "s.csv", header="# beam_half_angle_deg: 30\n")
    assert main(["fit", str(path), "--model", "abg"]) == 2
    err = capsys.readouterr().err
    assert "s.csv" in err
    assert "'# beam_half_angle_deg: 30': expected a half-angle in [0, 20]" in err


def test_export_from_an_apertured_fit_writes_the_samples_model(
    stated: tuple[dict, Path], tmp_path: Path, capsys
) -> None:
    from labbrdf.adapters.zemax_bsdf import read_table

    rec, _ = stated
    fit_json = tmp_path / "fit.json"
    fit_json.write_text(json.dumps([rec]))
    out = tmp_path / "sample.bsdf"
    argv = ["export", "--from-fit", str(fit_json), "--theta-i", "10", "-o", str(out)]
    assert main(argv) == 0, capsys.readouterr().err
    text = out.read_text()
    assert "1 deg detector and 0 deg beam aperture (half-angles); the sample's model" in text
    table = read_table(out)
    values = {k: v["value"] for k, v in rec["params"].items()}
    at_specular = float(np.asarray(table.values).ravel()[0])  # radial 0: the specular peak
    want = models.get("abg").evaluate(np.radians(10.0), np.radians(10.0), np.pi, params=values)
    assert at_specular == pytest.approx(float(want), rel=1e-5)


def test_nk_from_model_that_cannot_be_apertured_exits_2_before_reading(
    tmp_path: Path, capsys
) -> None:
    """With --nk-from the model is built per wavelength; it is checked on a stand-in index
    before the index file is read (this one is not an n, k file at all)."""
    nk = tmp_path / "nk.csv"
    nk.write_text("not read\n")
    argv = ["fit", str(_scan(tmp_path / "s.csv")), "--model", "layered", "--nk-from", str(nk)]
    assert main([*argv, "--wavelength", "633"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("labbrdf fit: --aperture: model 'layered' is a Monte Carlo estimate")
