"""One distribution interface for both interfaces: GGX, Beckmann and slope tables.

The coating's top takes a slope table like the substrate (seen from below as its point
reflection); the evaluated estimator covers tables on a bare substrate (no isotropy
assumed there) and on the coating's top (exits through the sampled facets).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from labbrdf.cli import main
from labbrdf.microfacet import TabulatedNDF
from labbrdf.tracer import Coating, Substrate, TraceConfig, trace

MIN_COUNT = 400


def _z_counting_pair(r0, r1):
    za = (r1.albedo() - r0.albedo()) / np.hypot(r1.albedo_stderr(), r0.albedo_stderr())
    se = np.hypot(r0.mueller_stderr, r1.mueller_stderr)
    ok = ((r0.counts >= MIN_COUNT) & (r1.counts >= MIN_COUNT))[..., None, None] & (se > 0)
    return za, ((r1.mueller - r0.mueller) / np.where(ok, se, 1.0))[ok]


@pytest.mark.slow
@pytest.mark.parametrize(("scattering", "theta"), [("multiple", 45.0), ("single", 60.0)])
def test_ggx_table_on_the_coating_reproduces_the_ggx_coating(scattering, theta):
    """Independent seeds, counting: albedo |z| < 4; RMS z over all populated bins and
    elements in [0.8, 1.2]; none beyond 5."""
    base = TraceConfig(
        rays=100_000,
        seed=3,
        theta_i_deg=theta,
        scattering=scattering,
        substrate=Substrate(alpha=0.3),
        coating=Coating(alpha=0.3),
        theta_step_deg=5.0,
        phi_step_deg=10.0,
        estimator="counting",
    )
    r0 = trace(base)
    r1 = trace(base.replace(seed=4, coating=Coating(alpha=0.3, ndf=TabulatedNDF.ggx(0.3))))
    assert r1.estimator == "counting"
    za, z = _z_counting_pair(r0, r1)
    assert abs(za) < 4
    assert z.size > 300
    assert 0.8 < np.sqrt(np.mean(z**2)) < 1.2
    assert np.abs(z).max() < 5


def _anisotropic_table() -> TabulatedNDF:
    rng = np.random.default_rng(0)
    sx = rng.normal(0.15, 0.25, 200_000)  # tilted and anisotropic: a "measured" table
    sy = rng.normal(0.0, 0.1, 200_000)
    return TabulatedNDF.from_slopes(sx, sy, bins=48)


@pytest.mark.slow
@pytest.mark.parametrize("table", ["beckmann", "measured"])
def test_evaluated_bare_table_agrees_with_counting(table):
    ndf = TabulatedNDF.beckmann(0.3) if table == "beckmann" else _anisotropic_table()
    cfg = TraceConfig(
        theta_i_deg=40.0,
        substrate=Substrate(alpha=0.3, ndf=ndf),
        scattering="single",
        theta_step_deg=3.0,
        phi_step_deg=6.0,
    )
    ev = trace(cfg.replace(rays=2000))
    assert ev.estimator == "evaluated"
    ct = trace(cfg.replace(rays=400_000, seed=1, estimator="counting"))
    se = np.hypot(ev.mueller_stderr, ct.mueller_stderr)
    ok = (ct.counts >= MIN_COUNT)[..., None, None] & (se > 0)
    z = ((ev.mueller - ct.mueller) / np.where(ok, se, 1.0))[ok]
    assert z.size > 300
    assert 0.8 < np.sqrt(np.mean(z**2)) < 1.2
    assert np.abs(z).max() < 5


def test_coating_table_round_trips_through_json():
    cfg = TraceConfig(coating=Coating(alpha=0.3, ndf=TabulatedNDF.beckmann(0.3, n=32)))
    back = TraceConfig.from_json(cfg.to_json())
    assert back == cfg
    assert back.coating is not None and back.coating.ndf == cfg.coating.ndf


def test_tabulated_coating_top_is_evaluated_through_its_sampled_facets():
    coat = Coating(alpha=0.3, ndf=TabulatedNDF.ggx(0.3, n=32))
    cfg = TraceConfig(scattering="single", coating=coat, rays=200, theta_step_deg=10.0)
    assert cfg.resolved_estimator == "evaluated"
    # the GGX exit operator does not describe a table: the exit is always sampled
    assert trace(cfg).info["exit_sampled"] == 1.0
    with pytest.raises(ValueError, match="'evaluated' needs scattering='single'"):
        TraceConfig(coating=coat, estimator="evaluated")
    with pytest.raises(ValueError, match="tabulated coating NDF"):
        TraceConfig(coating=coat, coherent=True)
    with pytest.raises(ValueError, match="coating.ndf must be a TabulatedNDF"):
        Coating(ndf="beckmann")


def test_coating_table_walk_closes_its_energy_ledger():
    coat = Coating(alpha=0.3, ndf=TabulatedNDF.beckmann(0.3, n=64))
    for scattering in ("single", "multiple"):
        led = trace(
            TraceConfig(rays=3000, coating=coat, scattering=scattering, theta_step_deg=10.0)
        ).ledger
        total = led["exited"] + led["absorbed"] + led["terminated"]
        assert total == pytest.approx(1.0, abs=1e-12)


def test_cli_beckmann_reaches_both_interfaces(capsys):
    argv = ["trace", "--substrate", "1.55+7.71j", "--alpha", "0.2", "--coating", "1.5",
            "--thickness", "500", "--theta-i", "45", "--wavelength", "650", "--rays", "500",
            "--scheduler", "serial", "--distribution", "beckmann", "--json"]  # fmt: skip
    assert main(argv) == 0
    cfg = json.loads(capsys.readouterr().out)["config"]
    assert cfg["substrate"]["ndf"] is not None
    assert cfg["coating"]["ndf"] is not None
    assert main([*argv[:4], "0", *argv[5:]]) == 2
    assert "alpha > 0" in capsys.readouterr().err


def test_cli_coating_surface_keeps_the_measured_table(real_exports, capsys):
    di = real_exports / "topography" / "di-1.di"
    if not di.is_file():
        pytest.skip("di-1.di absent")
    argv = ["trace", "--substrate", "1.55+7.71j", "--alpha", "0.1", "--coating", "1.5",
            "--thickness", "500", "--coating-surface", str(di), "--theta-i", "45",
            "--wavelength", "650", "--rays", "500", "--scheduler", "serial",
            "--json"]  # fmt: skip
    assert main(argv) == 0
    cfg = json.loads(capsys.readouterr().out)["config"]
    assert cfg["coating"]["ndf"] is not None
