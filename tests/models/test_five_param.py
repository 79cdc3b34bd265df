"""five_param (Wu et al. five-parameter BRDF, eq. 3 of Zou 2013) against the oracle table."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf import models
from labbrdf.integrate import reciprocity_defect
from labbrdf.models import ModelError
from labbrdf.models.five_param import five_param_geometry

G_CHOICES = ("ts", "none", "mb")
# Maxwell-Beard constants of the oracle rows (recovered from its G_mb column: Omega = 0.7 rad,
# tau = 0.25 rad reproduce all 72 values to 1e-12; they are the model's defaults)
MB = {"Omega": 0.7, "tau": 0.25}


@pytest.fixture(scope="module")
def five_param_reference(oracles: Path) -> pd.DataFrame:
    return pd.read_csv(oracles / "five_param_reference.csv")


def _tol_12_digits(ref: np.ndarray) -> np.ndarray:
    """Half a unit in the 12th significant digit (the oracle prints %.12g) + float64."""
    ref = np.asarray(ref, dtype=float)
    mag = np.floor(np.log10(np.abs(ref), where=ref != 0, out=np.zeros_like(ref)))
    return 0.5 * 10.0 ** (mag - 11) + 8 * np.finfo(float).eps * np.abs(ref)


def _rows(df: pd.DataFrame):
    for name, g in df.groupby("param_set"):
        r = g.iloc[0]
        p = {"kb": r.kb, "kr": r.kr, "a": r.a, "b": r.b, "kd": r.kd}
        ang = [np.radians(g[c].to_numpy()) for c in ("theta_i_deg", "theta_r_deg", "dphi_deg")]
        yield name, g, p, ang


@pytest.mark.parametrize("g_choice", G_CHOICES)
def test_values_and_swapped_values_match_oracle(five_param_reference, g_choice):
    m = models.get("five_param", shadowing=g_choice)
    n = 0
    for _, g, p, (ti, tr, ph) in _rows(five_param_reference):
        f = m.evaluate(ti, tr, ph, params=p)
        fs = m.evaluate(tr, ti, ph, params=p)
        ref, ref_s = g[f"fr_{g_choice}"].to_numpy(), g[f"fr_swapped_{g_choice}"].to_numpy()
        assert np.all(np.abs(f - ref) <= _tol_12_digits(ref))
        assert np.all(np.abs(fs - ref_s) <= _tol_12_digits(ref_s))
        n += ref.size
    assert n == len(five_param_reference) == 72


@pytest.mark.parametrize("g_choice", G_CHOICES)
def test_shadowing_and_angles_match_oracle(five_param_reference, g_choice):
    m = models.get("five_param", shadowing=g_choice)
    for _, g, p, (ti, tr, ph) in _rows(five_param_reference):
        ca, cg = five_param_geometry(ti, tr, ph)
        for got, col in (
            (ca, "cos_alpha"),
            (cg, "cos_gamma"),
            (m.shadowing(m.values(p), ti, tr, ph), f"G_{g_choice}"),
        ):
            ref = g[col].to_numpy()
            assert np.all(np.abs(got - ref) <= _tol_12_digits(ref)), col


def test_mb_defaults_are_the_oracle_constants_and_fixed():
    p = models.get("five_param", shadowing="mb").params
    assert {k: p[k].value for k in MB} == MB
    assert not p["Omega"].vary and not p["tau"].vary
    assert "Omega" not in models.get("five_param").params


def test_lobe_lands_in_the_specular_half_plane():
    m = models.get("five_param")
    p = {"kb": 0.8, "kr": 0.1, "a": 1.5, "b": 1.2, "kd": 0.0}
    phi = np.radians(np.arange(0.0, 360.0, 1.0))
    f = m.evaluate(math.radians(40.0), math.radians(40.0), phi, params=p)
    assert math.degrees(phi[np.argmax(f)]) == 180.0
    assert f.max() > 30 * f[0]  # back-scatter side: 36 times below (Cauchy tails)


def test_specular_geometry_gives_alpha_zero_and_gamma_theta_i():
    ti = np.radians([10.0, 35.0, 70.0])
    ca, cg = five_param_geometry(ti, ti, np.pi)
    np.testing.assert_allclose(ca, 1.0, rtol=1e-15)
    np.testing.assert_allclose(cg, np.cos(ti), rtol=1e-15)


def test_user_callable_shadowing_is_used_and_stored():
    def half(ti, tr, pr, ca, cg):
        return 0.5 * np.ones_like(ca)

    m = models.get("five_param", shadowing=half)
    ref = models.get("five_param", shadowing="none")
    p = {"kb": 0.3, "kr": 0.2, "a": 1.0, "b": 0.5, "kd": 0.0}
    np.testing.assert_allclose(
        m.evaluate(0.3, 0.5, 2.0, params=p),
        0.5 * ref.evaluate(0.3, 0.5, 2.0, params=p),
        rtol=1e-15,
    )
    assert m.options["shadowing"] is half
    json.dumps(m.describe())  # a callable option is stored as its repr


@pytest.mark.parametrize(
    ("diffuse", "expected"),
    [("kd_over_cos_i", 1 / math.cos(0.7)), ("lambert", 1.0), ("kd_cos_i", math.cos(0.7))],
)
def test_diffuse_forms(diffuse, expected):
    m = models.get("five_param", diffuse=diffuse)
    p = {"kb": 1e-6, "kd": 0.1}
    comp = m.linear_components(m.values(p), np.array(0.7), np.array(0.2), np.array(1.0), None)
    assert comp["kd"] == pytest.approx(expected, rel=1e-15)
    assert m.options == {"shadowing": "ts", "diffuse": diffuse}


def test_linear_components_reproduce_the_model():
    m = models.get("five_param", shadowing="mb")
    p = m.values({"kb": 0.4, "kr": 0.3, "a": 2.0, "b": 1.5, "kd": 0.03})
    ti, tr, pr = np.broadcast_arrays(
        np.radians([[20.0], [50.0]]), np.radians([10, 50, 80.0]), np.radians([[[0.0]], [[180.0]]])
    )
    comp = m.linear_components(p, ti, tr, pr, None)
    assert set(comp) == {"kb", "kd"}
    np.testing.assert_allclose(
        0.4 * comp["kb"] + 0.03 * comp["kd"], m.evaluate(ti, tr, pr, params=p), rtol=1e-15
    )


@pytest.mark.parametrize("g_choice", G_CHOICES)
def test_reciprocity_truth(g_choice):
    spec = {"kb": 0.8, "kr": 0.1, "a": 1.5, "b": 1.2}
    m = models.get("five_param", shadowing=g_choice)
    assert m.is_reciprocal({**spec, "kd": 0.0})
    assert reciprocity_defect(m, {**spec, "kd": 0.0}).max_abs == 0.0
    assert not m.is_reciprocal({**spec, "kd": 0.005})
    d = reciprocity_defect(m, {**spec, "kd": 0.005})
    # the diffuse defect kd |1/cos ti - 1/cos tr| peaks at (85, 0) deg on the default grid
    assert d.max_abs == pytest.approx(0.005 * (1 / math.cos(math.radians(85)) - 1), rel=1e-12)
    lam = models.get("five_param", shadowing=g_choice, diffuse="lambert")
    assert lam.is_reciprocal({**spec, "kd": 0.005})
    assert reciprocity_defect(lam, {**spec, "kd": 0.005}).max_abs == 0.0


def test_asymmetric_user_shadowing_is_not_reciprocal():
    m = models.get("five_param", shadowing=lambda ti, tr, pr, ca, cg: np.cos(ti) + 0 * tr)
    assert not m.is_reciprocal({"kd": 0.0})
    sym = models.get("five_param", shadowing=lambda ti, tr, pr, ca, cg: np.cos(ti) * np.cos(tr))
    assert sym.is_reciprocal({"kd": 0.0})


def test_bounds_follow_notes_2_4():
    p = models.get("five_param").params
    assert (p["kb"].min, p["kb"].max, p["kb"].log) == (1e-6, 1e3, True)
    assert (p["kr"].min, p["kr"].max, p["kr"].log) == (1e-3, 3.0, True)
    assert (p["a"].min, p["a"].max) == (0.05, 10.0)
    assert (p["b"].min, p["b"].max) == (-20.0, 20.0)
    assert (p["kd"].min, p["kd"].max) == (0.0, 1 / math.pi)
    assert models.get("five_param").linear == ("kb", "kd")


def test_docstring_flags_g_as_unverified():
    assert "unverified against the 2002 paper" in " ".join(
        models.get("five_param").__doc__.split()
    )


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"shadowing": "blinn"}, "option 'shadowing' must be one of"),
        ({"diffuse": "oren"}, "option 'diffuse' must be one of"),
        ({"G": "ts"}, "unknown options \\['G'\\]"),
    ],
)
def test_bad_options_are_rejected(options, match):
    with pytest.raises(ModelError, match=match):
        models.get("five_param", **options)


@pytest.mark.parametrize(
    ("params", "match"),
    [
        ({"kr": 0.0}, "'kr' must be > 0"),
        ({"a": -1.0}, "'a' must be > 0"),
        ({"Omega": 0.0}, "'Omega' must be > 0"),
    ],
)
def test_bad_parameter_values_are_rejected(params, match):
    m = models.get("five_param", shadowing="mb")
    with pytest.raises(ModelError, match=match):
        m.evaluate(0.3, 0.4, params=params)
