"""Graded layers: a parameter varying through the thickness, computed in slices."""

from __future__ import annotations

import json

import numpy as np
import pytest

from labbrdf.films import FilmError, Layer, Stack, as_material, load_model, read_fit_json
from labbrdf.films.ema import Ema
from labbrdf.films.graded import Graded
from labbrdf.nk.dispersion import Cauchy, Constant

BASE = Cauchy(A=2.1, B=0.02)
WL = np.array([350.0, 500.0, 800.0, 1200.0])
ANG = np.array([[0.0], [55.0], [70.0]])


def _stack(material, d=180.0):
    return Stack([Layer(material, d, "film")], "si")


def test_a_flat_profile_is_the_homogeneous_layer_to_round_off():
    flat = _stack(Graded(BASE, "A", 2.1, 2.1, shape=2.0, sublayers=17))
    hom = _stack(BASE)
    for f in ("psi_delta", "reflectance"):
        np.testing.assert_allclose(
            getattr(flat, f)(WL, ANG), getattr(hom, f)(WL, ANG), rtol=0, atol=1e-11
        )


def test_slicing_converges_at_second_order():
    """The midpoint staircase: doubling the slices quarters the change."""

    def psi_delta(n):
        g = _stack(Graded(BASE, "A", 1.95, 2.25, sublayers=n))
        return np.concatenate(g.psi_delta(WL, ANG), axis=None)

    p = {n: psi_delta(n) for n in (10, 20, 40, 80)}
    steps = [np.max(np.abs(p[2 * n] - p[n])) for n in (10, 20, 40)]
    for coarse, fine in zip(steps, steps[1:], strict=False):
        assert 3.5 < coarse / fine < 4.5
    assert steps[-1] < 0.05  # deg: 40 -> 80 slices of 180 nm (0.3 of index across it)
    # and the gradient matters: far from the homogeneous layer of the mean index
    assert np.max(np.abs(p[80] - np.concatenate(_stack(BASE).psi_delta(WL, ANG), axis=None))) > 1


def test_a_graded_interface_from_void_to_the_substrate():
    iface = Graded(Ema(("void", "@substrate")), "fraction", 0.0, 1.0, sublayers=8)
    st = Stack([Layer(BASE, 100.0, "film"), Layer(iface, 4.0, "iface")], "si")
    slices = iface.slices()
    assert [s.fraction for s in slices] == pytest.approx((np.arange(8) + 0.5) / 8)
    n = st.nk(633.0)
    si = Stack([], "si").nk(633.0)["substrate"]
    assert 1.0 < n["iface"].real < si.real  # mid-depth: half void, half silicon


def test_graded_parameters_vary_and_round_trip(tmp_path):
    g = Graded(BASE, "A", 2.0, 2.2, shape=1.5, sublayers=12)
    st = _stack(g)
    v = st.values()
    assert {"film.A_top", "film.A_bottom", "film.shape", "film.B"} <= set(v)
    assert "film.A" not in v
    up = st.with_values({"film.A_bottom": 2.3, "film.B": 0.01})
    m = up.layers[0].material
    assert (m.bottom, m.base.B, m.top, m.sublayers) == (2.3, 0.01, 2.0, 12)
    assert set(st.units()) == set(v) and st.units()["film.A_top"] == "1"
    back = Stack.from_dict(st.to_dict())
    np.testing.assert_array_equal(back.psi_delta(WL, 70.0), st.psi_delta(WL, 70.0))
    doc = {"stack": st.to_dict(), "wavelength_range_nm": [300, 1000]}
    (tmp_path / "fit.json").write_text(json.dumps(doc))
    read, _ = read_fit_json(tmp_path / "fit.json")
    assert read.layers[0].material.to_dict() == g.to_dict()
    doc["stack"]["layers"][0]["material"]["sublayers"] = 10_000
    (tmp_path / "fit.json").write_text(json.dumps(doc))
    with pytest.raises(FilmError, match="sublayers"):
        read_fit_json(tmp_path / "fit.json")


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: Graded(BASE, "Q", 1, 2), "not a parameter of cauchy"),
        (lambda: Graded(BASE, "A", 1, 2, sublayers=0), "sublayers"),
        (lambda: Graded(BASE, "A", 1, 2, shape=0.0), "shape"),
        (lambda: Graded(BASE, "A", 1, float("nan")), "finite"),
        (lambda: Graded(Constant(1.5), "n", 1.5, -1.0), "n = -1"),
        (lambda: Graded(as_material("si"), "n", 1, 2), "dispersion model or an ema"),
        (lambda: Graded(BASE, "A", 1, 2).with_params({"A": 2.0}), "unknown parameter"),
        (lambda: as_material({"model": "graded", "base": {"model": "cauchy"}}), "expected base"),
        (lambda: Stack([], Graded(BASE, "A", 2, 2)), "graded is a layer"),
        (
            lambda: Stack(
                [Layer("ema(@g, void)", 1, "r"), Layer(Graded(BASE, "A", 2, 2), 1, "g")], "si"
            ),
            "mixture or graded",
        ),
    ],
)
def test_bad_graded_layers_are_refused(build, match):
    with pytest.raises(FilmError, match=match):
        build()


MODEL = """\
[substrate]
material = "si"

[[layer]]
name = "film"
material = "cauchy"
graded = "A"
A_top = [1.9, 2.3]
A_bottom = [1.9, 2.3]
B = 0.02
sublayers = 10
thickness_nm = [100, 300]
"""


def test_model_file_reads_a_graded_layer(tmp_path):
    p = tmp_path / "m.toml"
    p.write_text(MODEL)
    m = load_model(p)
    g = m.stack.layers[0].material
    assert isinstance(g, Graded) and (g.parameter, g.sublayers) == ("A", 10)
    assert g.top == g.bottom == pytest.approx(2.1)  # the middle of the boxes
    # the one rule: the unwritten C is free; Cauchy's absorption and the profile shape fixed
    assert set(m.free) == {"film.A_top", "film.A_bottom", "film.C", "film.thickness_nm"}


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (lambda t: t.replace('graded = "A"', 'graded = "Q"'), r"line 7: 'Q' is not a parameter"),
        (lambda t: t.replace('graded = "A"', "graded = 1"), r"line 7: graded ="),
        (lambda t: t.replace("sublayers = 10", "sublayers = 1.5"), r"line 11: sublayers must"),
        (lambda t: t.replace("sublayers = 10", "sublayers = 999"), r"line 7: .*sublayers"),
        (lambda t: t.replace("A_top", "A"), r"line 8: unknown parameter 'A'"),
    ],
)
def test_bad_graded_keys_name_the_file_and_line(tmp_path, edit, match):
    p = tmp_path / "bad.toml"
    p.write_text(edit(MODEL))
    with pytest.raises(FilmError, match=match) as exc:
        load_model(p)
    assert "bad.toml" in str(exc.value)
