"""One interface's distribution as the walk sees it: closed form and table alike."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from scipy import stats

from labbrdf.microfacet import TabulatedNDF, beckmann, ggx
from labbrdf.microfacet.interface import ClosedForm, Table, facets, table_for

ALPHA = 0.3


def _dirs(theta_deg: float, n: int, down: bool) -> np.ndarray:
    """Propagation directions at theta from the normal, spread in azimuth."""
    t = np.radians(theta_deg)
    p = np.linspace(0, 2 * np.pi, n, endpoint=False)
    z = -np.cos(t) if down else np.cos(t)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.full(n, z)])


@functools.cache
def _kinds() -> tuple[ClosedForm, Table]:
    return ClosedForm(ggx, ALPHA), Table(TabulatedNDF.ggx(ALPHA, n=128), ALPHA)


@pytest.mark.parametrize("kind", [0, 1])
@pytest.mark.parametrize("below", [False, True])
def test_visible_normals_face_the_ray_on_its_side(kind, below):
    face = _kinds()[kind]
    n = 4000
    # a ray hitting the interface travels into it: down from above, up from below
    k = _dirs(50.0, n, down=not below)
    rng = np.random.default_rng(1)
    u = rng.random((2, n))
    m = face.sample_visible(k, np.full(n, below), u[0], u[1], rng)
    assert np.allclose((m * m).sum(axis=0), 1.0)
    assert np.all((k * m).sum(axis=0) < 0)  # the facet is seen: k . m < 0
    assert np.all(m[2] < 0) if below else np.all(m[2] > 0)


def test_from_below_the_table_and_the_closed_form_sample_the_same_normals():
    closed, table = _kinds()
    n = 20000
    k = _dirs(60.0, n, down=False)
    below = np.ones(n, dtype=bool)
    rng = np.random.default_rng(7)
    u = rng.random((2, n))
    mc = closed.sample_visible(k, below, u[0], u[1], rng)
    mt = table.sample_visible(k, below, u[0], u[1], np.random.default_rng(8))
    # the cosine to the ray and the polar angle of the normal (the azimuths differ by the
    # conventions' 180-degree turn, which an isotropic distribution does not see)
    for f in (lambda m: (k * m).sum(axis=0), lambda m: m[2]):
        assert stats.ks_2samp(f(mc), f(mt)).pvalue > 1e-3


@pytest.mark.parametrize("theta", [20.0, 75.0])
def test_lambda_and_g1_agree_between_the_kinds_from_both_sides(theta):
    closed, table = _kinds()
    for down in (False, True):
        k = _dirs(theta, 16, down)
        for below in (np.zeros(16, bool), np.ones(16, bool)):
            a, b = closed.smith_lambda(k, below), table.smith_lambda(k, below)
            assert np.allclose(a, b, rtol=1e-2, atol=1e-4)  # the table: 1 % (test_tabulated)
            assert np.allclose(closed.smith_g1(k, below), table.smith_g1(k, below), atol=3e-3)


def test_d_of_both_kinds():
    closed, table = _kinds()
    m = _dirs(10.0, 8, down=False)
    assert np.allclose(table.d(m), closed.d(m), rtol=5e-2)  # D constant per cell
    assert np.array_equal(closed.d(m), ggx.d(m[2], ALPHA))


def test_facets_chooses_the_kind_and_refuses_a_closed_form_without_a_sampler():
    assert isinstance(facets(0.2), ClosedForm) and facets(0.2).ggx_closed_form
    t = TabulatedNDF.beckmann(0.2, n=32)
    face = facets(0.2, t)
    assert isinstance(face, Table) and not face.ggx_closed_form and face.table is t
    with pytest.raises(ValueError, match="beckmann has no closed-form visible-normal sampling"):
        ClosedForm(beckmann, 0.2)


def test_table_for_gives_what_an_interface_stores_as_its_ndf():
    assert table_for("ggx", 0.2) is None
    t = table_for("beckmann", 0.25)
    assert t is not None and t.name == "beckmann(0.25)" and t.mass.shape == (256, 256)
    assert table_for("beckmann", 0.25) is t  # kept, not rebuilt
    with pytest.raises(KeyError, match="expected one of ggx, beckmann"):
        table_for("cosine", 0.2)
    with pytest.raises(ValueError, match="Beckmann table needs a roughness alpha > 0"):
        table_for("beckmann", 0.0)
