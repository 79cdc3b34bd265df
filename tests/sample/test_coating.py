"""The tracer's coating from a film fit: sample.coating_from_fit and trace --coating-from."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf import films
from labbrdf.cli import main
from labbrdf.fitting.film import fit_film
from labbrdf.nk.dispersion import Cauchy
from labbrdf.sample import coating_from_fit, coating_of_stack, trace_config_from_inputs
from labbrdf.sample.coating import CoatingWarning

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
    fit = fit_film(model, pd.concat(rows, ignore_index=True))
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


def _with_stack(fit_json: Path, tmp_path: Path, stack: films.Stack, name: str) -> Path:
    """The fit JSON with its stack replaced (the fitted range kept)."""
    doc = json.loads(fit_json.read_text())
    doc["stack"] = stack.to_dict()
    out = tmp_path / name
    out.write_text(json.dumps(doc))
    return out


def test_a_graded_coating_is_refused_naming_the_layer(fit_json: Path, tmp_path: Path, capsys):
    graded = films.Graded(Cauchy(**CAUCHY), "A", top=1.50, bottom=1.56, sublayers=10)
    st = films.Stack([films.Layer(graded, D_NM, "coat")], 1.7)
    with pytest.raises(
        ValueError, match=r"layer 'coat' is graded \(A from 1.5 at the top to 1.56"
    ):
        coating_of_stack(st, 633.0, (450.0, 750.0), where="fit")
    path = _with_stack(fit_json, tmp_path, st, "graded.json")
    assert main([*BASE, "--coating-from", str(path)]) == 2
    err = capsys.readouterr().err
    assert "one homogeneous layer" in err and len(err.strip().splitlines()) == 1
    flat = films.Graded(Cauchy(**CAUCHY), "A", top=1.52, bottom=1.52, sublayers=10)
    same = coating_of_stack(
        films.Stack([films.Layer(flat, D_NM, "coat")], 1.7), 633.0, (450.0, 750.0), where="f"
    )
    plain = films.Stack([films.Layer(Cauchy(**CAUCHY), D_NM, "coat")], 1.7)
    assert same == coating_of_stack(plain, 633.0, (450.0, 750.0), where="f")


def test_a_backside_left_out_is_said(fit_json: Path, tmp_path: Path):
    st = films.Stack([films.Layer(Cauchy(**CAUCHY), D_NM, "coat")], 1.7, 1.0, 1e6)
    with pytest.warns(CoatingWarning, match=r"1e\+06 nm thick.*semi-infinite"):
        coating_of_stack(st, 633.0, (450.0, 750.0), where="fit")
    path = _with_stack(fit_json, tmp_path, st, "glass.json")
    with pytest.warns(CoatingWarning, match="left out of the prediction"):
        cfg = trace_config_from_inputs(
            633.0, 45.0, substrate_index=1.7, alpha=0.2, coating_from=path
        )
    assert cfg.coating is not None and cfg.coating.thickness_nm == D_NM


# ---------------------------------------------------- a hand-edited fit JSON: its schema


def _layer(d: dict) -> dict:
    return d["stack"]["layers"][0]


#: (edit of the fit JSON, the key the message names): the wrong types met as TypeError or
#: AttributeError inside the film objects before the fit JSON had a schema, and others
WRONG = {
    "stack-array": (lambda d: d.__setitem__("stack", []), "stack: expected an object"),
    "layers-number": (
        lambda d: d["stack"].__setitem__("layers", 5),
        "stack.layers: expected an array",
    ),
    "layer-string": (
        lambda d: d["stack"].__setitem__("layers", ["x"]),
        r"stack.layers\[0\]: expected an object",
    ),
    "thickness-array": (
        lambda d: _layer(d).__setitem__("thickness_nm", [1]),
        r"thickness_nm: expected a number",
    ),
    "thickness-null": (
        lambda d: _layer(d).__setitem__("thickness_nm", None),
        r"thickness_nm: expected a number, got null",
    ),
    "parameter-null": (
        lambda d: _layer(d)["material"].__setitem__("A", None),
        r"material.A: expected a number",
    ),
    "name-object": (lambda d: _layer(d).__setitem__("name", {}), r"name: expected a string"),
    "range-null": (
        lambda d: d.__setitem__("wavelength_range_nm", [None, 700]),
        r"wavelength_range_nm\[0\]",
    ),
    "table-without-n": (
        lambda d: _layer(d).__setitem__(
            "material", {"model": "tabulated", "wavelength_nm": [1, 2]}
        ),
        "a tabulated material gives one of",
    ),
    "nan-thickness": (
        lambda d: _layer(d).__setitem__("thickness_nm", float("nan")),
        "finite number, got nan",
    ),
    "unknown-key": (lambda d: _layer(d).__setitem__("thick", 1), "unknown key 'thick'"),
    "negative-index": (
        lambda d: _layer(d)["material"].__setitem__("A", -1.0),
        r"stack: the coat index at 450 nm is \(-",
    ),
    "huge-absorption": (
        lambda d: _layer(d)["material"].__setitem__("k_amp", 1e308),
        r"the coat index .*\|n \+ ik\| <= 10000",
    ),
    "huge-int": (lambda d: _layer(d).__setitem__("thickness_nm", 10**400), "finite number"),
}


def _edited(fit_json: Path, tmp_path: Path, edit) -> Path:
    doc = json.loads(fit_json.read_text())
    edit(doc)
    p = tmp_path / "edited.json"
    p.write_text(json.dumps(doc))
    return p


@pytest.mark.parametrize("case", sorted(WRONG))
def test_a_wrong_type_in_a_fit_json_names_the_file_and_the_key(fit_json, tmp_path, case):
    edit, key = WRONG[case]
    p = _edited(fit_json, tmp_path, edit)
    with pytest.raises(films.FilmError, match=key) as exc:
        coating_from_fit(p, 633.0)
    assert str(exc.value).startswith(str(p))


@pytest.mark.parametrize("case", ["layer-string", "parameter-null", "thickness-array"])
def test_trace_coating_from_a_wrong_type_is_exit_2(fit_json, tmp_path, capsys, case):
    p = _edited(fit_json, tmp_path, WRONG[case][0])
    assert main([*BASE, "--coating-from", str(p)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and f"--coating-from {p}:" in err, err


@pytest.mark.parametrize(
    ("rng", "match"),
    [
        ([0, 1e308], r"wavelength_range_nm\[0\]: expected a number in \[1, 1e\+06\]"),
        ([450, 1e308], r"wavelength_range_nm\[1\]: expected a number in"),
        ([750, 450], r"not a range \[min, max\] with min < max"),
        ([450, 450], r"not a range"),
    ],
)
def test_an_implausible_fitted_range_is_refused(fit_json, tmp_path, rng, match):
    p = _edited(fit_json, tmp_path, lambda d: d.__setitem__("wavelength_range_nm", rng))
    with pytest.raises(films.FilmError, match=match):
        coating_from_fit(p, 633.0)


def test_a_fitted_range_beyond_the_stack_s_table_is_refused(tmp_path):
    st = films.Stack([films.Layer(Cauchy(**CAUCHY), D_NM, "coat")], "si")  # Si: 250-1450 nm
    doc = {"stack": st.to_dict(), "wavelength_range_nm": [300.0, 5000.0]}
    p = tmp_path / "wide.json"
    p.write_text(json.dumps(doc))
    with pytest.raises(films.FilmError, match=r"reaches beyond the substrate table \(250-1450"):
        coating_from_fit(p, 633.0)


def test_a_deeply_nested_fit_json_is_a_clear_error(tmp_path, capsys):
    p = tmp_path / "deep.json"
    p.write_text('{"stack": ' + "[" * 100_000 + "]" * 100_000 + "}")
    with pytest.raises(films.FilmError, match="deep.json: .*nested too deeply"):
        coating_from_fit(p, 633.0)
    assert main([*BASE, "--coating-from", str(p)]) == 2
    err = capsys.readouterr().err
    assert "nested too deeply" in err and "Traceback" not in err
