"""microfacet with each registered distribution: Beckmann against closed forms written here.

The Beckmann D and the exact Smith G1 below are eqs. (25)-(27) of Walter et al. 2007, written
independently of :mod:`labbrdf.microfacet.beckmann` (G1 directly, not through Lambda).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import special

from labbrdf import models
from labbrdf.cli import main
from labbrdf.fitting import fit
from labbrdf.integrate import hemispherical_reflectance
from labbrdf.microfacet import DISTRIBUTIONS
from labbrdf.models import ModelError


def _beckmann_d(cos_m: np.ndarray, alpha: float) -> np.ndarray:
    """Eq. (25): exp(-tan^2 / a^2) / (pi a^2 cos^4)."""
    tan2 = 1.0 / cos_m**2 - 1.0
    return np.exp(-tan2 / alpha**2) / (math.pi * alpha**2 * cos_m**4)


def _beckmann_g1(cos_v: np.ndarray, alpha: float) -> np.ndarray:
    """Eq. (27), exact form: 2 / (1 + erf(a) + exp(-a^2) / (a sqrt(pi))), a = 1/(alpha tan)."""
    a = cos_v / (alpha * np.sqrt(1.0 - cos_v**2))
    return 2.0 / (1.0 + special.erf(a) + np.exp(-(a**2)) / (a * math.sqrt(math.pi)))


def _brdf_here(alpha, ti, tr, pr):
    """f = D(h) G1(i) G1(o) / (4 cos i cos o), F = 1, from the closed forms above."""
    wi = np.stack(np.broadcast_arrays(np.sin(ti), 0.0 * ti, np.cos(ti)))
    wo = np.stack([np.sin(tr) * np.cos(pr), np.sin(tr) * np.sin(pr), np.cos(tr)])
    h = (wi + wo) / np.linalg.norm(wi + wo, axis=0)
    g = _beckmann_g1(np.cos(ti), alpha) * _beckmann_g1(np.cos(tr), alpha)
    return _beckmann_d(h[2], alpha) * g / (4 * np.cos(ti) * np.cos(tr))


@pytest.mark.parametrize("alpha", [0.08, 0.3, 0.9])
def test_beckmann_model_equals_the_closed_forms_of_walter_2007(alpha):
    m = models.get("microfacet", ideal_mirror=True, distribution="beckmann")
    ti = np.radians([5.0, 30.0, 60.0, 80.0])[:, None]
    tr = np.radians(np.linspace(2.0, 85.0, 12))[None, :]
    for pr in (math.pi, 2.0, 0.3):
        got = m.evaluate(ti, tr, pr, params={"alpha": alpha})
        want = _brdf_here(alpha, ti, tr, pr)
        # two algebraic forms of the same double-precision expressions: a few ulps apart
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-300)
    # and it is not GGX: the two differ by far more than rounding
    ggx = models.get("microfacet", ideal_mirror=True).evaluate(ti, tr, params={"alpha": alpha})
    assert np.max(np.abs(ggx / m.evaluate(ti, tr, params={"alpha": alpha}) - 1)) > 0.05


@pytest.mark.parametrize("name", list(DISTRIBUTIONS))
def test_reciprocal_and_mueller_00_is_the_brdf(name):
    m = models.get("microfacet", n=1.4, k=2.1, distribution=name)
    rng = np.random.default_rng(5)
    ti, tr, pr = rng.uniform(0, 1.4, 50), rng.uniform(0, 1.4, 50), rng.uniform(0, 2 * np.pi, 50)
    p = {"alpha": 0.35}
    f = m.evaluate(ti, tr, pr, params=p)
    np.testing.assert_allclose(m.evaluate(tr, ti, pr, params=p), f, rtol=1e-12)
    np.testing.assert_allclose(m.mueller(ti, tr, pr, params=p)[..., 0, 0], f, rtol=1e-12)


#: fraction of facet slopes with tan(theta_m) < 1, from each distribution's slope CDF
#: (Walter et al. 2007: Beckmann P(tan^2 < t) = 1 - exp(-t / a^2), GGX t / (a^2 + t))
_SLOPE_CDF_AT_1 = {
    "beckmann": lambda a: -math.expm1(-1.0 / a**2),
    "ggx": lambda a: 1.0 / (1.0 + a**2),
}


@pytest.mark.parametrize("name", list(_SLOPE_CDF_AT_1))
@pytest.mark.parametrize("alpha", [0.5, 1.0])
def test_unshadowed_albedo_at_normal_incidence_is_the_slope_fraction_below_45_deg(name, alpha):
    """F = 1, G = 1, theta_i = 0: rho = int_{theta_m < 45 deg} D cos theta_m d omega_m.

    The mirror direction of a facet tilted by theta_m lies at 2 theta_m: the facets beyond
    45 deg send the light below the horizon, the others return all of it.
    """
    m = models.get("microfacet", ideal_mirror=True, shadowing="none", distribution=name)
    rho = hemispherical_reflectance(m, {"alpha": alpha}, [0.0], rtol=1e-7)
    assert rho[0] == pytest.approx(_SLOPE_CDF_AT_1[name](alpha), rel=1e-5)


@pytest.mark.parametrize("name", list(DISTRIBUTIONS))
def test_smith_albedo_is_at_most_one(name):
    m = models.get("microfacet", ideal_mirror=True, distribution=name)
    rho = hemispherical_reflectance(m, {"alpha": 0.4}, [0.0, 45.0, 75.0], rtol=1e-5)
    assert np.all((rho > 0.5) & (rho <= 1.0))


def test_a_noisy_beckmann_brdf_is_fitted_back_within_3_standard_errors(microfacet_rows):
    data = microfacet_rows("beckmann", 0.25, seed=3)
    res = fit(models.get("microfacet", n=1.5, k=0.0, distribution="beckmann"), data)
    p = res.params["alpha"]
    assert p.stderr is not None and abs(p.value - 0.25) < 3 * p.stderr, (p.value, p.stderr)
    assert res.options["distribution"] == "beckmann"
    # GGX cannot describe it: its best chi2 is far above the Beckmann one
    other = fit(models.get("microfacet", n=1.5, k=0.0), data)
    assert other.chisqr > 5 * res.chisqr


def test_options_label_and_texts_state_the_distribution():
    b = models.get("microfacet", n=1.5, distribution="beckmann")
    g = models.get("microfacet", n=1.5)
    assert b.options["distribution"] == "beckmann" and "distribution" not in g.options
    assert (b.label, g.label) == ("microfacet (Beckmann)", "microfacet (GGX)")
    assert "Beckmann D" in b.reference and "GGX D" in g.reference
    assert "Beckmann" in b.reciprocity_note
    assert b.params["alpha"].description == "Beckmann roughness"
    assert models.get("microfacet", **b.options).distribution == "beckmann"


@pytest.mark.parametrize("bad", ["cauchy", 3.0, ["ggx"]])
def test_an_unknown_distribution_is_refused_with_the_registered_ones(bad):
    with pytest.raises(ModelError, match=r"'distribution' must be one of \['ggx', 'beckmann'"):
        models.get("microfacet", n=1.5, distribution=bad)


def test_fit_command_takes_the_distribution_and_refuses_an_unknown_one(
    tmp_path, capsys, microfacet_rows
):
    path = tmp_path / "b.csv"
    microfacet_rows("beckmann", 0.25, seed=4).to_csv(path, index=False)
    base = ["fit", str(path), "--model", "microfacet", "--param", "n=1.5", "--param", "k=0"]
    assert main([*base, "--param", "distribution=beckmann", "--json"]) == 0
    out = capsys.readouterr().out
    assert '"distribution": "beckmann"' in out
    assert main([*base, "--param", "distribution=cauchy"]) == 2
    err = capsys.readouterr().err
    assert "'distribution' must be one of ['ggx', 'beckmann']" in err
    assert "Traceback" not in err
