"""The tracer's coating from a film fit: labbrdf.nk.coating_from_fit and trace --coating-from."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf import films
from labbrdf.cli import main
from labbrdf.dispersion import Cauchy
from labbrdf.nk import coating_from_fit

CAUCHY = {"A": 1.52, "B": 0.006, "C": 0.0}
D_NM = 250.0
WL = np.arange(450.0, 751.0, 25.0)


@pytest.fixture(scope="module")
def fit_json(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A film fit (thickness and A free) to exact psi/Delta of Cauchy on n = 1.7 glass."""
    truth = films.Stack([films.Layer(Cauchy(**CAUCHY), D_NM, "coat")], 1.7)
    rows = []
    for th in (50.0, 60.0, 70.0):
        psi, delta = truth.psi_delta(WL, th)
        for q, v, s in (("psi", psi, 0.02), ("delta", delta, 0.05)):
            rows.append(
                pd.DataFrame({"sample": "g", "instrument": "x", "source": "g.dat",
                              "quantity": q, "value": v, "sigma": s, "unit": "deg",
                              "wavelength_nm": WL, "theta_i_deg": th, "theta_r_deg": th,
                              "phi_r_deg": 180.0})
            )  # fmt: skip
    start = truth.with_values({"coat.thickness_nm": 200.0, "coat.A": 1.5})
    model = films.FilmModel(start, {"coat.thickness_nm": (150.0, 350.0), "coat.A": (1.4, 1.7)})
    fit = films.fit_film(model, pd.concat(rows, ignore_index=True))
    return fit.save_json(tmp_path_factory.mktemp("fit") / "fit.json")


def test_coating_index_and_thickness_of_the_fit(fit_json: Path) -> None:
    big_n, d = coating_from_fit(fit_json, 633.0)
    lam_um = 0.633
    n_true = CAUCHY["A"] + CAUCHY["B"] / lam_um**2  # Cauchy, written out
    assert d == pytest.approx(D_NM, abs=0.05)
    assert big_n.real == pytest.approx(n_true, abs=1e-4) and big_n.imag == 0.0


def test_outside_the_fitted_range_is_refused(fit_json: Path) -> None:
    with pytest.raises(ValueError, match=r"outside the fitted range \[450, 750\] nm"):
        coating_from_fit(fit_json, 1064.0)


def test_a_stack_of_two_layers_is_not_one_coating(fit_json: Path, tmp_path: Path) -> None:
    doc = json.loads(fit_json.read_text())
    doc["stack"]["layers"].append(dict(doc["stack"]["layers"][0], name="second"))
    two = tmp_path / "two.json"
    two.write_text(json.dumps(doc))
    with pytest.raises(ValueError, match=r"one coating.*2 layer\(s\) \['coat', 'second'\]"):
        coating_from_fit(two, 633.0)


def test_a_file_that_is_not_a_fit(tmp_path: Path) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text('{"a": 1,\n "b": }')
    with pytest.raises(ValueError, match=r"bad.json, line 2: not JSON"):
        coating_from_fit(bad, 633.0)
    other = tmp_path / "other.json"
    other.write_text("{}")
    with pytest.raises(ValueError, match="not a film fit"):
        coating_from_fit(other, 633.0)


BASE = ["trace", "--substrate", "1.5+7j", "--alpha", "0.2", "--theta-i", "45"]
BASE += ["--wavelength", "633", "--rays", "2000", "--single-scattering", "--json"]


def test_trace_takes_the_coating_from_the_fit(fit_json: Path, capsys) -> None:
    assert main([*BASE, "--coating-from", str(fit_json)]) == 0
    s = json.loads(capsys.readouterr().out)
    big_n, d = coating_from_fit(fit_json, 633.0)
    argv = [*BASE, "--coating", f"{big_n.real!r}", "--thickness", f"{d!r}"]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["albedo"] == s["albedo"]  # the same coating


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--coating", "1.5"], "give the coating once"),
        (["--thickness", "100"], "give the coating once"),
        (["--wavelength", "1064"], "outside the fitted range"),
    ],
)
def test_trace_coating_from_errors_are_exit_2(fit_json: Path, capsys, extra, message) -> None:
    assert main([*BASE, "--coating-from", str(fit_json), *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_trace_coating_from_a_missing_file_is_exit_2(tmp_path: Path, capsys) -> None:
    assert main([*BASE, "--coating-from", str(tmp_path / "none.json")]) == 2
    assert "none.json" in capsys.readouterr().err
