"""`export --from-fit FIT.json` (what `fit --json` prints) and the wavelength it records."""

from __future__ import annotations

import json

import numpy as np
import pytest

import labbrdf
from labbrdf.cli import main
from labbrdf.dataset import Measurement, write_csv
from labbrdf.writers.zemax import model_to_bsdf


@pytest.fixture(scope="module")
def scan_fit(fixtures_dir, tmp_path_factory):
    """``fit --json`` of smooth3 on the OSR scan at its two shortest wavelengths."""
    d = labbrdf.read(fixtures_dir / "specular" / "osr_specular.csv").data
    wls = np.sort(d["wavelength_nm"].unique())[:2]
    tmp = tmp_path_factory.mktemp("from_fit")
    p = tmp / "osr.csv"
    write_csv(Measurement(d[d["wavelength_nm"].isin(wls)].reset_index(drop=True), {}), p)
    return tmp, p, wls


def _fit_json(capsys, path, *argv) -> list:
    capsys.readouterr()
    assert main(["fit", str(path), "--model", "smooth3", "--json", *argv]) == 0
    return json.loads(capsys.readouterr().out)


def test_a_fit_is_exported_with_its_values_and_wavelength(scan_fit, capsys):
    tmp, p, wls = scan_fit
    recs = _fit_json(capsys, p)
    assert all(r["model"] == "smooth3" and r["wavelength_stated"] for r in recs)
    fj = tmp / "fit.json"
    fj.write_text(json.dumps(recs))
    out = tmp / "m.bsdf"
    argv = ["export", "--from-fit", str(fj), "--theta-i", "20", "40", "-o", str(out)]
    assert main(argv) == 2  # two groups: which one?
    assert "2 fitted groups" in capsys.readouterr().err
    assert main([*argv, "--wavelength", f"{wls[1]:.17g}"]) == 0
    back = labbrdf.read(out)
    assert back.meta["wavelength_stated"] and back.meta["wavelength_nm"] == wls[1]
    # the file holds the fitted model's values (written to 6 digits)
    vals = {k: v["value"] for k, v in recs[1]["params"].items()}
    d = back.data
    want = labbrdf.models.get("smooth3").evaluate(
        np.radians(d["theta_i_deg"]), np.radians(d["theta_r_deg"]),
        np.radians(d["phi_r_deg"]), params=vals)  # fmt: skip
    np.testing.assert_allclose(d["value"], want, rtol=1e-5, atol=1e-9)


def test_a_fit_of_a_file_stating_no_wavelength_records_the_given_one(tmp_path, capsys):
    src = tmp_path / "label.bsdf"  # no wavelength comment: 555 nm is a label
    values = {"k1": 0.5, "k2": 0.0, "k3": 0.2}
    grid = {"theta_i_deg": [20, 40], "radial_deg": range(0, 41, 4), "azimuth_deg": [0, 90, 180]}
    model_to_bsdf(labbrdf.models.get("smooth3"), values, src, **grid)
    recs = _fit_json(capsys, src)
    assert recs[0]["wavelength_stated"] is False
    fj = tmp_path / "fit.json"
    fj.write_text(json.dumps(recs))
    out = tmp_path / "m.bsdf"
    base = ["export", "--from-fit", str(fj), "--theta-i", "30", "-o", str(out)]
    assert main(base) == 0
    assert "no wavelength" in capsys.readouterr().out
    assert labbrdf.read(out).meta["wavelength_stated"] is False  # not the 555 nm label
    assert main([*base, "--wavelength", "633", "--overwrite"]) == 0
    assert labbrdf.read(out).meta["wavelength_nm"] == 633.0


@pytest.mark.parametrize(
    ("content", "extra", "match"),
    [
        ("{not json", [], "not a fit JSON"),
        ("[]", [], "no fitted group"),
        ('[{"group": {}, "params": {"k1": {"value": 1}}}]', [], "expected what `labbrdf fit"),
        ('[{"model": "smooth3", "params": {"k1": {"value": 99}}}]', [], "k1"),
        ('[{"model": "smooth3", "params": {"k1": {"value": 1}}}]', ["--param", "k1=1"],
         "drop --param"),
    ],
)  # fmt: skip
def test_bad_fit_json_exits_2(tmp_path, capsys, content, extra, match):
    fj = tmp_path / "fit.json"
    fj.write_text(content)
    argv = ["export", "--from-fit", str(fj), "--theta-i", "30", "-o", str(tmp_path / "m.bsdf")]
    assert main([*argv, *extra]) == 2
    err = capsys.readouterr().err
    assert match in err and "Traceback" not in err


def test_model_export_records_the_wavelength(tmp_path):
    out = tmp_path / "m.bsdf"
    argv = ["export", "--model", "smooth3", "--theta-i", "30", "-o", str(out)]
    assert main([*argv, "--wavelength", "550"]) == 0
    assert labbrdf.read(out).meta["wavelength_nm"] == 550.0
