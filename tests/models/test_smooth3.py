"""smooth3 (Zou, Bai, Wu 2013, eq. 7): formula, published parameters, reciprocity, errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf import models
from labbrdf.models import ModelError
from labbrdf.models.smooth3 import smooth3_brdf


def _published(path: Path) -> pd.DataFrame:
    return pd.read_csv(path, comment="#")


@pytest.fixture(scope="module")
def zou2013_table1(fixtures_dir: Path) -> pd.DataFrame:
    """OSR parameters, Table 1 of doi:10.3788/AOS201333.0612008."""
    return _published(fixtures_dir / "published" / "zou2013_table1.csv")


@pytest.fixture(scope="module")
def zou2013_table2(fixtures_dir: Path) -> pd.DataFrame:
    """Mirror parameters, Table 2 of doi:10.3788/AOS201333.0612008."""
    return _published(fixtures_dir / "published" / "zou2013_table2.csv")


def test_published_tables_hold_the_printed_parameters(zou2013_table1, zou2013_table2):
    assert list(zou2013_table1.wavelength_nm) == [360, 500, 550, 860]
    assert list(zou2013_table2.wavelength_nm) == [360, 500, 550, 860]
    row = zou2013_table1.set_index("wavelength_nm").loc[550]
    assert (row.k1, row.k2, row.k3) == (1.0150, -0.01660, 0.4176)
    row = zou2013_table2.set_index("wavelength_nm").loc[550]
    assert (row.k1, row.k2, row.k3) == (0.5494, 0.1682, 0.3693)


def test_formula_matches_eq7_written_out():
    m = models.get("smooth3")
    ti, tr = math.radians(45.0), math.radians(47.0)
    k1, k2, k3 = 0.9, 0.02, 0.35
    expected = k1 / (8 * math.cos(ti) * math.cos(tr)) * math.exp(-((ti - tr - k2) ** 2) / k3**2)
    got = m.evaluate(ti, tr, params={"k1": k1, "k2": k2, "k3": k3})
    assert got == pytest.approx(expected, rel=4e-16)


def test_peak_sits_at_theta_i_minus_k2():
    m = models.get("smooth3")
    ti = math.radians(45.0)
    p = {"k1": 1.0, "k2": 0.1, "k3": 0.05}
    tr = np.linspace(ti - 0.3, ti + 0.1, 40001)
    f = m.evaluate(ti, tr, params=p) * np.cos(tr)  # the Gaussian part alone
    assert tr[np.argmax(f)] == pytest.approx(ti - 0.1, abs=1e-5)


def test_phi_r_is_ignored():
    m = models.get("smooth3")
    a = m.evaluate(0.5, 0.6, phi_r=np.pi)
    b = m.evaluate(0.5, 0.6, phi_r=0.3)
    assert a == b


@pytest.mark.parametrize(
    ("sample", "ti", "tr", "expected"),
    [
        ("OSR", 30, 50, 0.1209),
        ("OSR", 50, 30, 0.1059),
        ("mirror", 30, 50, 0.0173),
        ("mirror", 50, 30, 0.0971),
    ],
)
def test_reciprocity_numbers_of_notes_1_3(
    zou2013_table1, zou2013_table2, sample, ti, tr, expected
):
    table = zou2013_table1 if sample == "OSR" else zou2013_table2
    row = table.set_index("wavelength_nm").loc[550]
    m = models.get("smooth3")
    got = m.evaluate(
        math.radians(ti), math.radians(tr), params={"k1": row.k1, "k2": row.k2, "k3": row.k3}
    )
    assert abs(got - expected) <= 5e-5  # 4 decimals printed


def test_reciprocal_iff_k2_is_zero(zou2013_table1):
    m = models.get("smooth3")
    assert m.is_reciprocal({"k2": 0.0})
    for k2 in zou2013_table1.k2:
        assert not m.is_reciprocal({"k2": k2})
    ti, tr = np.meshgrid(np.radians(np.arange(0, 86, 5.0)), np.radians(np.arange(0, 86, 5.0)))
    p = {"k1": 1.0, "k2": 0.0, "k3": 0.4}
    assert np.array_equal(m.evaluate(ti, tr, params=p), m.evaluate(tr, ti, params=p))


def test_only_k1_exp_product_is_identifiable_on_the_specular_line():
    m = models.get("smooth3")
    t = np.radians([30.0, 45.0, 60.0])
    k2, k3 = 0.05, 0.3
    a = m.evaluate(t, t, params={"k1": 1.0, "k2": k2, "k3": k3})
    b = m.evaluate(t, t, params={"k1": math.exp(-((k2 / k3) ** 2)), "k2": 0.0, "k3": 0.7})
    np.testing.assert_allclose(a, b, rtol=1e-15)


def test_linear_component_reproduces_the_model():
    m = models.get("smooth3")
    p = m.values({"k1": 0.77, "k2": -0.02, "k3": 0.41})
    ti, tr, pr = np.broadcast_arrays(
        np.radians([[30.0], [60.0]]), np.radians([28, 31, 40.0]), np.pi
    )
    comp = m.linear_components(p, ti, tr, pr, None)
    assert set(comp) == set(m.linear) == {"k1"}
    np.testing.assert_allclose(0.77 * comp["k1"], m.evaluate(ti, tr, params=p), rtol=1e-15)


def test_bounds_and_units_follow_notes_1_5():
    p = models.get("smooth3").params
    assert (p["k1"].min, p["k1"].max, p["k1"].units) == (0.0, 5.0, "1")
    assert (p["k2"].min, p["k2"].max, p["k2"].units) == (-0.5, 0.5, "rad")
    assert (p["k3"].min, p["k3"].max, p["k3"].log) == (1e-3, math.pi / 2, True)


def test_k3_not_positive_is_rejected():
    m = models.get("smooth3")
    with pytest.raises(ModelError, match="'k3' must be > 0"):
        m.evaluate(0.5, 0.5, params={"k3": 0.0})


def test_options_are_rejected():
    with pytest.raises(ModelError, match="smooth3' takes no options"):
        models.get("smooth3", g="ts")


def test_grazing_and_horizon_evaluate_without_runtime_warning():
    # RuntimeWarnings from labbrdf are errors (pyproject filterwarnings)
    f = smooth3_brdf(np.array([np.pi / 2, 0.3]), np.array([0.3, np.pi / 2]), 1.0, 0.0, 0.4)
    assert np.all(f > 1e10)
