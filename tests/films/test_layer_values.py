"""One grammar and one rule for a layer's values: the model file and ``--layer`` agree."""

from __future__ import annotations

from pathlib import Path

import pytest

from labbrdf import films
from labbrdf.films.layers import default_boxes, parse_layer, parse_value
from labbrdf.nk.dispersion import Cauchy, Sellmeier

CAUCHY_DEFAULT = {k: Cauchy.BOUNDS[k] for k in ("A", "B", "C")}


def _toml(tmp_path: Path, layer: str) -> films.FilmModel:
    p = tmp_path / "m.toml"
    p.write_text(f'[substrate]\nmaterial = "si"\n\n[[layer]]\nname = "f"\n{layer}\n')
    return films.load_model(p)


def _cli(spec: str) -> dict[str, tuple[float, float]]:
    return parse_layer(spec, 1, films.as_material)[1]


def test_parameters_not_written_are_free_in_their_default_box(tmp_path: Path) -> None:
    want = {"f.thickness_nm": (50.0, 400.0), **{f"f.{k}": b for k, b in CAUCHY_DEFAULT.items()}}
    assert _cli("f:cauchy:50..400") == want
    toml = _toml(tmp_path, 'material = "cauchy"\nthickness_nm = [50, 400]')
    assert toml.free == want
    # Cauchy's absorption stays at k_amp = 0 (transparent) unless a box is written
    assert "f.k_amp" not in want and _cli("f:cauchy:5:k_amp=0..0.1")["f.k_amp"] == (0.0, 0.1)


def test_a_number_fixes_a_parameter_and_a_box_frees_it_in_both_grammars(tmp_path: Path) -> None:
    cli_layer, cli_free = parse_layer("f:cauchy:120:A=1.9:B=0..0.02", 1, films.as_material)
    toml = _toml(tmp_path, 'material = "cauchy"\nthickness_nm = 120\nA = 1.9\nB = [0, 0.02]')
    assert cli_free == toml.free == {"f.B": (0.0, 0.02), "f.C": Cauchy.BOUNDS["C"]}
    assert cli_layer.material.A == toml.stack.layers[0].material.A == 1.9
    assert cli_layer.material.B == toml.stack.layers[0].material.B == pytest.approx(0.01)
    held = _toml(tmp_path, 'material = "cauchy"\nthickness_nm = 9\nC = {value = 0, vary = false}')
    assert set(held.free) == {"f.A", "f.B"}


def test_the_rule_is_the_default_models(tmp_path: Path) -> None:
    stack = films.Stack([films.Layer(Sellmeier(), 100.0, "s")], "si")
    default = films.FilmModel.default(stack).free
    assert default == {
        "s.thickness_nm": (0.0, 300.0),
        **{f"s.{k}": b for k, b in default_boxes(Sellmeier()).items()},
    }
    assert _cli("s:sellmeier:0..300") == default
    assert default_boxes(films.as_material("si")) == {}  # a table has no parameter
    rough = _toml(tmp_path, 'material = "roughness"\nthickness_nm = [0, 5]')
    assert rough.free == {"f.thickness_nm": (0.0, 5.0), "f.fraction": (0.0, 1.0)}


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("f:cauchy", "expected NAME:MATERIAL:THICKNESS"),
        ("f:cauchy:10:Q=1", "PARAM one of"),
        ("f:cauchy:3..1", "impossible bounds"),
        ("f:cauchy:x", "not a number or LO..HI"),
        ("f:cauchy:10:k_amp=-1", "k_amp must be >= 0"),
        ("f:nothing:10", "unknown material"),
    ],
)
def test_a_bad_layer_names_the_layer(spec: str, match: str) -> None:
    with pytest.raises(films.FilmError, match=match):
        parse_layer(spec, 1, films.as_material)


def test_values_of_the_command_line() -> None:
    assert parse_value("1.5", "x") == (1.5, None)
    assert parse_value("1..2", "x") == (1.5, (1.0, 2.0))
    with pytest.raises(films.FilmError, match="x: impossible bounds"):
        parse_value("2..2", "x")
