"""Layer and Stack objects, roughness, serialisation, TOML model files and their errors."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from labbrdf.films import (
    MAX_LAYERS,
    FilmError,
    Layer,
    Roughness,
    Stack,
    load_model,
    named_inputs,
    read_fit_json,
)
from labbrdf.films import matrices as stk
from labbrdf.nk import tabulated_from_file
from labbrdf.nk.dispersion import Cauchy, Sellmeier, Tabulated


def _oxide_on_si(d=100.0):
    return Stack([Layer(Sellmeier(), d, "oxide")], substrate="si")


def test_stack_psi_delta_is_the_stack_optics_of_its_materials():
    s = _oxide_on_si()
    lam = np.array([400.0, 633.0, 900.0])
    psi, delta = s.psi_delta(lam, 70.0)
    n_ox, n_si = Sellmeier().nk(lam), Tabulated.reference("si").nk(lam)
    psi0, delta0 = stk.ellipsometry([1.0, n_ox, n_si], [100.0], lam, 70.0)
    np.testing.assert_array_equal(psi, psi0)
    np.testing.assert_array_equal(delta, delta0)
    rs, rp = s.reflectance(lam, 70.0)
    assert np.all((rs > 0) & (rs < 1) & (rp >= 0) & (rp < 1))


def test_nk_per_layer_and_substrate():
    nk = _oxide_on_si().nk(633.0)
    assert list(nk) == ["oxide", "substrate"]
    assert nk["oxide"] == pytest.approx(1.457, abs=1e-3)
    assert nk["substrate"].real == pytest.approx(3.879 + 0.3 * (3.861 - 3.879), abs=1e-12)


def test_roughness_layer_is_the_bruggeman_half_mixture_of_the_medium_below_and_ambient():
    s = Stack([Layer(Roughness(), 3.0, "rough")], substrate="si")
    idx = s.indices(633.0)
    eps_si = Tabulated.reference("si").nk(633.0) ** 2
    assert idx[1] ** 2 == pytest.approx(stk.bruggeman(eps_si, 1.0, 0.5), rel=1e-12)


def test_to_dict_round_trip_and_with_values():
    s = Stack(
        [Layer(Roughness(0.4), 2.0, "rough"), Layer(Cauchy(A=2.0, B=0.02), 50.0, "film")],
        substrate="si",
    )
    again = Stack.from_dict(json.loads(json.dumps(s.to_dict())))
    lam = np.linspace(300, 1000, 8)
    np.testing.assert_array_equal(again.psi_delta(lam, 65.0)[0], s.psi_delta(lam, 65.0)[0])
    t = s.with_values({"film.thickness_nm": 60.0, "film.A": 2.1, "rough.fraction": 0.5})
    assert t.layers[1].thickness_nm == 60.0 and t.layers[1].material.A == 2.1
    assert t.layers[0].material.fraction == 0.5
    assert s.layers[1].thickness_nm == 50.0  # the original is unchanged
    with pytest.raises(FilmError, match="unknown stack parameter 'film.Q'"):
        s.with_values({"film.Q": 1.0})


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: Stack([Layer(1.5, 1.0, "a"), Layer(1.6, 1.0, "a")], "si"), "repeated"),
        (lambda: Layer(1.5, -1.0), "thickness_nm must be >= 0"),
        (lambda: Stack([], "roughness"), "roughness is a layer"),
        (lambda: Stack([Layer("unobtainium", 1.0)], "si"), "unknown material"),
        (lambda: Roughness(1.5), "fraction"),
    ],
)
def test_invalid_stacks_raise_film_errors(build, match):
    with pytest.raises(FilmError, match=match):
        build()


# ---- TOML model files

GOOD = """\
# native oxide on silicon
wavelength_nm = [300, 1000]

[substrate]
material = "si"

[[layer]]
name = "oxide"
material = "cauchy"
thickness_nm = [0, 10]
A = [1.3, 1.7]
B = 0.0036
C = {value = 0.0, min = -0.01, max = 0.01}
"""


def test_load_model_reads_layers_fixed_and_free_parameters(tmp_path):
    p = tmp_path / "m.toml"
    p.write_text(GOOD)
    fm = load_model(p)
    assert fm.wavelength_range_nm == (300.0, 1000.0)
    assert [lay.name for lay in fm.stack.layers] == ["oxide"]
    assert fm.free == {
        "oxide.thickness_nm": (0.0, 10.0),
        "oxide.A": (1.3, 1.7),
        "oxide.C": (-0.01, 0.01),
    }
    assert fm.stack.layers[0].thickness_nm == 5.0  # mid-box start
    assert fm.stack.layers[0].material.B == 0.0036


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (lambda t: t.replace("B = 0.0036", "Q = 1.0"), r"line 12: unknown parameter 'Q'"),
        (lambda t: t.replace("A = [1.3, 1.7]", "A = [1.7, 1.3]"), r"line 11: .*impossible bounds"),
        (
            lambda t: t.replace('material = "cauchy"', 'material = "nope"'),
            r"line 9: unknown material",
        ),
        (lambda t: t.replace("[[layer]]", "[[layers]]"), r"line 7: unknown key or table 'layers'"),
        (lambda t: t.replace("thickness_nm = [0, 10]\n", ""), r"line 7: layer 'oxide' has no"),
        (lambda t: t.replace("B = 0.0036", "B = 0.0036 ="), r"not valid TOML.*line 12"),
        (
            lambda t: t.replace('[substrate]\nmaterial = "si"\n', ""),
            r"line 1: missing \[substrate\]",
        ),
        (
            lambda t: t.replace("C = {value = 0.0,", "C = {value = 0.0, step = 1,"),
            r"line 13: .*step",
        ),
        (
            lambda t: t.replace("wavelength_nm = [300, 1000]", "wavelength_nm = [1000, 300]"),
            r"line 2: wavelength_nm",
        ),
    ],
)
def test_bad_model_file_names_the_file_and_line(tmp_path, edit, match):
    p = tmp_path / "bad.toml"
    p.write_text(edit(GOOD))
    with pytest.raises(FilmError, match=match) as exc:
        load_model(p)
    assert "bad.toml" in str(exc.value)


def test_model_file_with_a_table_file_substrate_relative_to_the_model(tmp_path):
    (tmp_path / "metal.csv").write_text("300,1.5,3.0\n1200,2.0,4.0\n")
    p = tmp_path / "m.toml"
    p.write_text(
        '[substrate]\nfile = "metal.csv"\n\n[[layer]]\nmaterial = "sio2"\nthickness_nm = 10\n'
    )
    fm = load_model(p, tabulated_from_file)
    assert fm.stack.substrate.nk(750.0) == pytest.approx(1.75 + 3.5j)
    assert fm.free == {}


def test_missing_model_file_is_a_film_error(tmp_path):
    with pytest.raises(FilmError, match="cannot read the model file"):
        load_model(tmp_path / "absent.toml")


def test_the_film_objects_import_nothing_of_the_fitting_workflow():
    import ast
    from pathlib import Path

    import labbrdf.films

    root = Path(labbrdf.films.__file__)
    files = sorted(root.parent.glob("*.py")) if root.name == "__init__.py" else [root]
    imported = set()
    for f in files:
        for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                names = [f"{node.module}.{a.name}" if node.module else a.name for a in node.names]
                imported |= {"." * node.level + n for n in names}
            elif isinstance(node, ast.Import):
                imported |= {a.name for a in node.names}
    assert not [m for m in imported if "fitting" in m], imported
    assert not hasattr(labbrdf.films, "fit_film")


# ------------------------------------------------------- model files: numbers, caps, files


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (lambda t: t.replace("thickness_nm = [0, 10]", "thickness_nm = nan"), r"line 10: thick"),
        (lambda t: t.replace("thickness_nm = [0, 10]", "thickness_nm = [0, inf]"), r"line 10: "),
        (lambda t: t.replace("thickness_nm = [0, 10]", 'thickness_nm = {value = "x"}'), "line 10"),
        (lambda t: t.replace("B = 0.0036", "B = nan"), r"line 12: B: expected a finite"),
        (lambda t: t.replace("B = 0.0036", "B = {value = 1, vary = 2}"), r"line 12: .*vary"),
        (lambda t: "ambient = inf\n" + t, r"line 1: ambient must be a real index"),
        (lambda t: t.replace("[300, 1000]", "[300, inf]"), r"line 2: wavelength_nm"),
        (lambda t: t.replace("[300, 1000]", "[0.001, 1000]"), r"line 2: .*outside the wave"),
        (lambda t: t.replace("[300, 1000]", "[300, 1e308]"), r"line 2: .*outside the wave"),
        (lambda t: t.replace('name = "oxide"', "name = 5"), r"line 8: name must be a string"),
        (lambda t: "layer = [1, 2]\n" + t[: t.index("[[layer]]")], r"line 1: 'layer' must"),
        (
            lambda t: t + '\n[[layer]]\nname = "oxide"\nmaterial = "si"\nthickness_nm = 1\n',
            "line 16",
        ),
        (lambda t: t.replace("thickness_nm = [0, 10]", "thickness_nm = 1e9"), r"line 10: .*<= 1e"),
    ],
)
def test_every_bad_number_of_a_model_names_the_file_and_the_line(tmp_path, edit, match):
    p = tmp_path / "bad.toml"
    p.write_text(edit(GOOD))
    with pytest.raises(FilmError, match=match) as exc:
        load_model(p)
    assert str(exc.value).startswith(str(p))


def test_a_model_of_more_layers_than_the_cap_is_refused_naming_the_file(tmp_path):
    p = tmp_path / "many.toml"
    layer = '[[layer]]\nmaterial = "sio2"\nthickness_nm = 1\n'
    p.write_text('[substrate]\nmaterial = "si"\n' + layer * 2000)
    with pytest.raises(FilmError, match=r"many.toml, line 1503: 2,000 layers; .* at most 500"):
        load_model(p)
    with pytest.raises(FilmError, match="at most 500"):
        Stack([Layer("sio2", 1.0)] * (MAX_LAYERS + 1), "si")


@pytest.mark.parametrize(
    ("body", "match"),
    [
        ("x = [" + "0," * 2_000_000 + "]\n", "larger than 1,048,576 bytes"),  # 2 M elements
        ("x = " + "[" * 100_000 + "]" * 100_000 + "\n", "nested too deeply"),
        ("x = " + "[" * 1000 + "]" * 1000 + "\n", "nested too deeply"),
        ("x = 1" + "0" * 5000 + "\n", "not a film model"),  # more digits than Python converts
    ],
    ids=["huge-array", "deep", "deep-1000", "long-int"],
)
def test_a_huge_or_deep_model_file_is_refused_at_once(tmp_path, body, match):
    p = tmp_path / "big.toml"
    p.write_text('[substrate]\nmaterial = "si"\n' + body)
    with pytest.raises(FilmError, match=match) as exc:
        load_model(p)
    assert str(exc.value).startswith(str(p))
    assert len(str(exc.value)) < 500


def test_a_device_or_a_fifo_named_in_a_model_is_refused_at_once(tmp_path):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    for name, kind in (("/dev/zero", "character device"), ("pipe.csv", "FIFO")):
        p = tmp_path / "m.toml"
        p.write_text(f'[substrate]\nfile = "{name}"\n')
        with pytest.raises(FilmError, match=rf"m.toml, line 2: .*{kind}"):
            load_model(p, tabulated_from_file)
    with pytest.raises(FilmError, match="FIFO"):
        load_model(fifo)  # the model file itself


def test_named_inputs_are_the_files_the_loaders_open(tmp_path):
    (tmp_path / "metal.csv").write_text("300,1.5,3.0\n1200,2.0,4.0\n")
    (tmp_path / "film.csv").write_text("300,1.4,0.0\n1200,1.5,0.0\n")
    p = tmp_path / "m.toml"
    p.write_text(
        '[substrate]\nfile = "metal.csv"\n\n[[layer]]\nfile = "film.csv"\nthickness_nm = 10\n'
        '[[layer]]\nmaterial = "sio2"\nthickness_nm = 10\n'
    )
    assert named_inputs(p, "model") == [tmp_path / "metal.csv", tmp_path / "film.csv"]
    st = load_model(p, tabulated_from_file).stack
    doc = {"stack": st.to_dict(), "wavelength_range_nm": [400.0, 800.0]}
    fit = tmp_path / "fit.json"
    fit.write_text(json.dumps(doc))
    assert named_inputs(fit, "fit") == [tmp_path / "metal.csv", tmp_path / "film.csv"]
    assert read_fit_json(fit, tabulated_from_file)[0].to_dict() == st.to_dict()
