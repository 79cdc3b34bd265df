"""Bruggeman interface and roughness layers of two or three constituents."""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf.films import FilmError, Layer, Roughness, Stack, as_material, load_model, named_inputs
from labbrdf.films import matrices as stk
from labbrdf.films.ema import Ema, bruggeman_mix
from labbrdf.nk import tabulated_from_file
from labbrdf.nk.dispersion import Cauchy, Constant

EPS = [
    np.array([2.1 + 0.0j, 4.0 + 0.3j, -12.0 + 1.5j, 15.0 + 4.0j]),  # dielectric .. metal
    np.array([1.0 + 0.0j, 2.25 + 0.0j, 1.0 + 0.0j, 3.8 + 0.1j]),
    np.array([12.0 + 0.5j, 1.0 + 0.0j, 2.0 + 0.2j, 1.0 + 0.0j]),
]


def _g(e, eps, f):
    return sum(fi * (ei - e) / (ei + 2 * e) for fi, ei in zip(f, eps, strict=True))


def test_two_constituents_are_the_closed_form_root():
    for f in (0.0, 0.2, 0.5, 1.0):
        e = bruggeman_mix(EPS[:2], [1 - f, f])
        np.testing.assert_array_equal(e, stk.bruggeman(EPS[0], EPS[1], 1 - f))


@pytest.mark.parametrize("f", [(0.6, 0.3, 0.1), (0.2, 0.2, 0.6), (0.34, 0.33, 0.33)])
def test_three_constituents_solve_the_equation_with_a_passive_root(f):
    e = bruggeman_mix(EPS, list(f))
    assert np.max(np.abs(_g(e, EPS, f))) < 1e-12
    assert np.all(e.imag >= 0)
    # the root does not depend on the order in which the constituents are given
    np.testing.assert_allclose(bruggeman_mix(EPS[::-1], list(f)[::-1]), e, rtol=0, atol=1e-12)


def test_three_constituents_reduce_to_two():
    """A zero third fraction, or a third constituent equal to the second, is a two-mix."""
    e2 = stk.bruggeman(EPS[0], EPS[1], 0.7)
    np.testing.assert_allclose(bruggeman_mix(EPS, [0.7, 0.3, 0.0]), e2, rtol=0, atol=1e-13)
    same = [EPS[0], EPS[1], EPS[1]]
    np.testing.assert_allclose(bruggeman_mix(same, [0.7, 0.1, 0.2]), e2, rtol=0, atol=1e-12)


def test_small_fractions_are_maxwell_garnett_to_first_order():
    """``e = e_h + 3 e_h sum_i f_i (e_i - e_h)/(e_i + 2 e_h) + O(f^2)`` for both mixing rules.

    The remainder is second order: a tenth of the fraction leaves a hundredth of it.
    """
    host, a, b = EPS

    def slope(e):
        return 3 * host * (e - host) / (e + 2 * host)

    def remainders(f):
        two = bruggeman_mix([host, a], [1 - f, f]) - host - f * slope(a)
        three = bruggeman_mix([host, a, b], [1 - 2 * f, f, f]) - host - f * (slope(a) + slope(b))
        return np.abs(two), np.abs(three)

    for big, small in zip(remainders(1e-3), remainders(1e-4), strict=True):
        np.testing.assert_allclose(big / small, 100.0, rtol=0.02)
        assert np.all(big < 1e-5 * np.abs(host))


def test_an_ema_layer_end_members_and_the_roughness_layer():
    film = Cauchy(A=2.1, B=0.02)

    def index(material):
        st = Stack([Layer(material, 2.0, "rough"), Layer(film, 100.0, "film")], "si")
        return st.indices(np.array([400.0, 633.0]))[1]

    n_film = film.nk(np.array([400.0, 633.0]))
    np.testing.assert_allclose(index(Ema(("@film", "void"), 0.0)), n_film, rtol=1e-14)
    np.testing.assert_allclose(index(Ema(("@film", "void"), 1.0)), 1.0, atol=1e-14)
    # the Aspnes roughness layer is the mixture of the layer below with the ambient
    np.testing.assert_allclose(
        index(Ema(("@ambient", "@film"), 0.3)), index(Roughness(0.3)), rtol=1e-14
    )


def test_a_reference_follows_the_fitted_layer_and_round_trips():
    st = Stack(
        [Layer("ema(@film, void)", 2.0, "rough"), Layer(Cauchy(A=2.0), 100.0, "film")], "si"
    )
    assert set(st.values()) >= {"rough.fraction", "rough.thickness_nm"}
    up = st.with_values({"film.A": 2.2, "rough.fraction": 0.25})
    assert up.layers[0].material.fraction == 0.25
    e = up.indices(633.0)[1] ** 2
    e_film = Cauchy(A=2.2).nk(633.0) ** 2
    assert e == pytest.approx(stk.bruggeman(e_film, 1.0, 0.75), rel=1e-14)
    back = Stack.from_dict(up.to_dict())
    np.testing.assert_array_equal(back.psi_delta(633.0, 70.0), up.psi_delta(633.0, 70.0))
    three = as_material({"model": "ema", "components": ["sio2", "void", "si"], "fraction3": 0.2})
    assert set(three.params) == {"fraction", "fraction3"}
    assert as_material(three.to_dict()).to_dict() == three.to_dict()


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: Stack([Layer("ema(@nope, void)", 1.0, "r")], "si"), "names no other layer"),
        (lambda: Stack([Layer("ema(@r, void)", 1.0, "r")], "si"), "names no other layer"),
        (
            lambda: Stack([Layer("ema(@x, void)", 1, "r"), Layer("roughness", 1, "x")], "si"),
            "itself a mixture",
        ),
        (lambda: Ema(("void",)), "2 or 3 constituents"),
        (lambda: Ema(("void", "si")), "constituent 'si'"),
        (lambda: Ema(("void", "@a"), 0.5, 0.2), "needs a third"),
        (lambda: Ema(("void", "@a", "@b"), 0.7, 0.5), "fraction \\+ fraction3"),
        (lambda: as_material("ema(void, roughness)"), "is roughness"),
        (lambda: as_material({"model": "ema", "components": "void"}), "components ="),
        (lambda: as_material({"model": "ema", "components": [1.5, 1], "x": 1}), "unknown key"),
        (lambda: Ema((Constant(1.5), "void")).with_params({"A": 1.0}), "unknown parameter"),
        (lambda: Stack([], "ema(si, void)"), "ema is a layer"),
    ],
)
def test_bad_mixtures_are_refused_naming_what_is_wrong(build, match):
    with pytest.raises(FilmError, match=match):
        build()


def test_bruggeman_mix_refuses_bad_fractions():
    with pytest.raises(ValueError, match="sum to 1"):
        bruggeman_mix(EPS, [0.5, 0.5, 0.5])
    with pytest.raises(ValueError, match="2 or 3"):
        bruggeman_mix(EPS[:1], [1.0])


MODEL = """\
[substrate]
material = "si"

[[layer]]
name = "rough"
material = "ema"
components = ["@film", "void", {file = "extra.csv"}]
fraction = [0, 1]
fraction3 = 0.1
thickness_nm = [0, 5]

[[layer]]
name = "film"
material = "cauchy"
A = [1.8, 2.4]
thickness_nm = [100, 300]

[[layer]]
name = "iface"
material = "ema(@film, @substrate)"
fraction = {value = 0.5, vary = false}
thickness_nm = 1
"""


def test_model_file_reads_mixtures_and_names_their_files(tmp_path):
    (tmp_path / "extra.csv").write_text("300,1.5,0.0\n1200,1.6,0.0\n")
    p = tmp_path / "m.toml"
    p.write_text(MODEL)
    m = load_model(p, tabulated_from_file)
    rough, _, iface = m.stack.layers
    assert isinstance(rough.material, Ema) and len(rough.material.components) == 3
    assert rough.material.fraction3 == 0.1 and iface.material.references == ["film", "substrate"]
    assert {"rough.fraction", "rough.thickness_nm", "film.A"} <= set(m.free)
    assert "iface.fraction" not in m.free
    assert tmp_path / "extra.csv" in named_inputs(p, "model")


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (
            lambda t: t.replace('["@film", "void", {file = "extra.csv"}]', "1"),
            r"line 7: .*components",
        ),
        (lambda t: t.replace('"void", {file', "{x = 1}, {file"), r"line 7: .*model"),
        (
            lambda t: t.replace('material = "cauchy"', 'material = "cauchy"\ncomponents = []'),
            "ema",
        ),
        (lambda t: t.replace("fraction3 = 0.1", "fraction3 = 0.95"), r"fraction \+ fraction3"),
    ],
)
def test_bad_mixtures_in_a_model_file_name_the_file(tmp_path, edit, match):
    (tmp_path / "extra.csv").write_text("300,1.5,0.0\n1200,1.6,0.0\n")
    p = tmp_path / "bad.toml"
    p.write_text(edit(MODEL))
    with pytest.raises(FilmError, match=match) as exc:
        load_model(p, tabulated_from_file)
    assert "bad.toml" in str(exc.value)
