"""The ``layered`` model's scattering coating (``medium=True``).

Checks: the option's refusals name the reason; the medium's parameters exist, reach the
tracer and key the model's cache; a diffuse base with a medium is traced (seeded, with
Monte Carlo error) and agrees with the trace of the same configuration made by hand; a
non-scattering medium agrees with the closed form of a clear coating with the same
extinction within the Monte Carlo error.
"""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf import models
from labbrdf.models.base import ModelError
from labbrdf.tracer import Coating, Medium, Substrate, TraceConfig, trace

K = 4.0
PARAMS = {"alpha_top": 0.3, "albedo": 0.4, "medium_tau": 0.8, "medium_ssa": 0.9, "medium_g": 0.5}


def _points(theta_i_deg: float = 45.0):
    tr = np.radians(np.arange(0.0, 80.0, 7.0))
    return np.full(tr.shape, np.radians(theta_i_deg)), tr, np.full(tr.shape, np.pi)


def test_medium_option_is_checked():
    with pytest.raises(ModelError, match="medium=True needs the incoherent coating"):
        models.get("layered", n=1.55, k=7.71, coherent=True, medium=True)
    # multiple scattering on the top goes through the evaluated multiple-scattering walk
    m = models.get("layered", base="diffuse", medium=True, scattering="multiple", grid="6x12")
    cfg = m._config({**PARAMS, "n_coat": 1.5}, 45.0, 550.0)
    assert cfg.scattering == "multiple" and cfg.coating.medium is not None and m.stochastic
    with pytest.raises(ModelError, match="'medium' must be true or false"):
        models.get("layered", base="diffuse", medium="yes")


def test_a_diffuse_base_under_a_medium_is_traced_with_its_parameters():
    m = models.get("layered", base="diffuse", medium=True, rays=2000, grid="6x12")
    assert {"medium_tau", "medium_ssa", "medium_g"} <= set(m.params)
    assert m.stochastic and m.default_replicates == 3 and m.fd_rel_step == 3e-3
    assert models.get("layered", **m.options).options == m.options  # round trip
    ti, tr, pr = _points()
    f = m.evaluate(ti, tr, pr, params=PARAMS)
    var = m.point_variance(PARAMS, ti, tr, pr, None)
    assert (var > 0).all()  # traced: Monte Carlo error, not the closed form
    # the model's trace is the tracer's with the medium of its parameters
    cfg = TraceConfig(
        theta_i_deg=45.0,
        wavelength_nm=550.0,
        substrate=Substrate.lambertian(0.4),
        coating=Coating(n=1.5, thickness_nm=1000.0, alpha=0.3, medium=Medium(0.8, 0.9, 0.5)),
        rays=2000,
        scattering="single",
        estimator="evaluated",
        theta_step_deg=6.0,
        phi_step_deg=12.0,
    )
    np.testing.assert_array_equal(
        m.trace_maps(m.values(PARAMS), 45.0, 550.0)[0], trace(cfg).mueller[..., 0, 0]
    )
    # each medium parameter reaches the trace (and the cache key)
    for name, v in (("medium_tau", 2.0), ("medium_ssa", 0.3), ("medium_g", -0.3)):
        g = m.evaluate(ti, tr, pr, params={**PARAMS, name: v})
        assert np.abs(g - f).max() > 0.05 * np.abs(f).max(), name


def test_a_dark_medium_is_an_absorbing_clear_coating():
    # ssa = 0: the medium only extinguishes, as a clear coating whose k is tau lambda /
    # (4 pi d) does, whose map is the renewal closed form (no Monte Carlo error): the
    # traced model agrees with it within its error at every point; ignoring the medium
    # would leave the coating lossless (the body's light 2.7-3.9x brighter)
    tau, lam, d = 0.5, 550.0, 1000.0
    clear = models.get(
        "layered", base="diffuse", grid="6x12", coating_k=tau * lam / (4 * np.pi * d)
    )
    murky = models.get("layered", base="diffuse", medium=True, rays=5000, grid="6x12")
    ti, tr, pr = _points(30.0)
    p = {**PARAMS, "medium_tau": tau, "medium_ssa": 0.0}
    a = clear.evaluate(ti, tr, pr, params={k: p[k] for k in ("alpha_top", "albedo")})
    b = murky.evaluate(ti, tr, pr, params=p)
    se = np.sqrt(murky.point_variance(p, ti, tr, pr, None))
    assert (np.abs(b - a) < K * se).all(), (b / a - 1, se / a)
