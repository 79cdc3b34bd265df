"""A distribution added in two files (its module, one registry line) is fitted, traced, reported.

The test writes a new module into a temporary package, a Student-t slope distribution of
shape gamma = 3 (Ribardiere M., Bringier B., Meneveaux D., Simonot L., "STD: Student's
t-Distribution of slopes for microfacet based BSDFs", Computer Graphics Forum 36(2), 2017;
GGX is gamma = 2, Beckmann the limit gamma -> infinity), registers it with one line
(``DISTRIBUTIONS["student3"] = module``) and then uses it as a user would: the
``microfacet`` BRDF model and ``labbrdf fit``, the slope fits of a height map and
``labbrdf surface``, the report's slope table and figure, and ``labbrdf trace``.
"""

from __future__ import annotations

import importlib
import json
import math
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate

from labbrdf import models
from labbrdf.cli import main
from labbrdf.fitting import fit
from labbrdf.integrate import hemispherical_reflectance
from labbrdf.microfacet import DISTRIBUTIONS, TabulatedNDF, registry

#: the whole new module: closed forms with s = alpha^2, c = (gamma - 1) s = 2 s
STUDENT3 = '''
"""Student-t slopes, gamma = 3: P22 = (1 + q / (2 a^2))^-3 / (pi a^2), q = x^2 + y^2."""

import math

import numpy as np

from labbrdf.microfacet import parts

NAME = "student3"
LABEL = "Student-t (gamma 3)"
TABLE_EXTENT = 100.0
TRACED_IN_CLOSED_FORM = False


def p22(x, y, alpha):
    return (1.0 + (x * x + y * y) / (2 * alpha**2)) ** -3 / (math.pi * alpha**2)


def p2(x, alpha):
    return 3.0 / (4.0 * math.sqrt(2.0) * alpha) * (1.0 + x * x / (2 * alpha**2)) ** -2.5


def radial_density(r, alpha):
    return 2 * r / alpha**2 * (1.0 + r * r / (2 * alpha**2)) ** -3


def d(cos_m, alpha):
    c = np.asarray(cos_m, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        t2 = (1.0 - c * c) / (c * c)
        dd = (1.0 + t2 / (2 * alpha**2)) ** -3 / (math.pi * alpha**2 * c**4)
    return np.where(c > 0, dd, 0.0)


def smith_lambda(wz, alpha):
    # Lambda = (1/mu) int_mu^inf (x - mu) P2(x) dx, mu = cot theta, m = mu / sqrt(2 a^2):
    # ((1 + 2 m^2) / sqrt(1 + m^2) - 2 m) / (4 m), written without the cancellation
    z, t2 = parts.tan2(wz)
    with np.errstate(divide="ignore", over="ignore"):
        m = 1.0 / (alpha * np.sqrt(2.0 * t2))
        r = np.sqrt(1.0 + m * m)
        lam = 1.0 / (4.0 * m * r * (1.0 + 2.0 * m * m + 2.0 * m * r))
    return parts.both_ways(z, lam)


def smith_g1(wz, alpha):
    return parts.smith_g1(smith_lambda, wz, alpha)


def ml_s(q, areal):
    # score: mean(2 s / (2 s + q)) = 2/3 (areal) or 4/5 (the 1-D marginal)
    frac = 2.0 / 3.0 if areal else 0.8
    qpos = q[q > 0]
    if qpos.size == 0:
        return 0.0
    lo, hi = float(qpos.min()) * 1e-6, float(q.max()) * 1e6
    return parts.score_root(
        lambda s: float(np.mean(2 * s / (2 * s + q))) - frac, float(np.mean(q)), lo, hi
    )


def log_likelihood(q, s, n, areal):
    if areal:
        c = 2 * math.log(s) + 3 * math.log(2.0) - math.log(math.pi)
        return float(n * c - 3 * parts.sum_log(q, 2 * s))
    return float(n * (math.log(0.75) + 2 * math.log(2 * s)) - 2.5 * parts.sum_log(q, 2 * s))


def ks_cdf(s, areal):
    if areal:
        return lambda v: 1.0 - (1.0 + v / (2 * s)) ** -2
    def cdf(v):
        u = v / math.sqrt(2 * s)
        return 0.5 + u * (2 * u * u + 3) / (4 * (1 + u * u) ** 1.5)
    return cdf


def fisher_information(q, s, n, areal):
    k = 12.0 if areal else 10.0
    return float(2 * n / s**2 - k * np.sum(1.0 / (2 * s + q) ** 2))
'''


@pytest.fixture
def student3(tmp_path, monkeypatch):
    """The module written into a temporary package and registered with one line."""
    pkg = tmp_path / "userdists"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "student3.py").write_text(textwrap.dedent(STUDENT3))
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("userdists.student3")
    monkeypatch.setitem(DISTRIBUTIONS, "student3", module)  # the one registry line
    yield module
    for name in ("userdists.student3", "userdists"):
        sys.modules.pop(name, None)


def test_the_module_is_complete_and_its_closed_forms_are_right(student3):
    assert [n for n in registry.REQUIRED if not hasattr(student3, n)] == []
    for a in (0.1, 0.5):
        norm, _ = integrate.quad(
            lambda t, a=a: student3.d(np.cos(t), a) * np.cos(t) * np.sin(t) * 2 * np.pi,
            0,
            np.pi / 2,
            points=[a],
            limit=200,
        )
        assert norm == pytest.approx(1.0, rel=1e-7)
        for theta in (0.3, 1.0, 1.4):  # Lambda from its definition over the marginal P2
            mu = 1.0 / math.tan(theta)
            tail, _ = integrate.quad(
                lambda x, a=a, mu=mu: (x - mu) * student3.p2(x, a), mu, np.inf
            )
            lam = float(student3.smith_lambda(math.cos(theta), a))
            assert lam == pytest.approx(tail / mu, rel=1e-7, abs=1e-12)


def test_the_microfacet_model_fits_it_from_python_and_the_command_line(
    student3, tmp_path, capsys, microfacet_rows
):
    data = microfacet_rows("student3", 0.3, seed=7)
    res = fit(models.get("microfacet", n=1.5, k=0.0, distribution="student3"), data)
    p = res.params["alpha"]
    assert p.stderr is not None and abs(p.value - 0.3) < 3 * p.stderr, (p.value, p.stderr)
    assert models.get("microfacet", n=1.5, distribution="student3").label == (
        "microfacet (Student-t (gamma 3))"
    )
    path = tmp_path / "brdf.csv"
    data.to_csv(path, index=False)
    argv = ["fit", str(path), "--model", "microfacet", "--param", "n=1.5", "--param", "k=0",
            "--param", "distribution=student3", "--scheduler", "serial", "--json"]  # fmt: skip
    assert main(argv) == 0
    (out,) = json.loads(capsys.readouterr().out)
    assert out["options"]["distribution"] == "student3"
    assert out["params"]["alpha"]["value"] == pytest.approx(p.value, rel=1e-6)


def test_slope_fits_take_it_and_pick_it_for_its_own_slopes(student3):
    from labbrdf.roughness.slope_fits import fit_slope_distribution

    x, y = TabulatedNDF.of(student3, 0.2).sample_slopes(20_000, np.random.default_rng(11))
    fits = fit_slope_distribution(x, y)
    assert list(fits.fits) == ["ggx", "beckmann", "student3"]
    f = fits.student3
    # the table's cells blur the slopes by a fraction of a cell: far below 3 u
    assert abs(f.alpha - 0.2) < 3 * f.alpha_u, (f.alpha, f.alpha_u)
    assert fits.best == "student3" and f.ks < 0.02
    prof = fit_slope_distribution(x)  # the 1-D marginal of a profile
    assert abs(prof.student3.alpha - 0.2) < 3 * prof.student3.alpha_u


def test_surface_command_and_report_show_it(student3, real_exports: Path, capsys, monkeypatch):
    from labbrdf.report import figures
    from labbrdf.report.sections.surface import _fit_rows
    from labbrdf.roughness.synthetic import gaussian_surface
    from labbrdf.roughness.topography import roughness_statistics

    path = real_exports / "topography" / "di-1.di"
    if not path.exists():
        pytest.skip(f"{path} not present")
    assert main(["surface", str(path), "--blocks", "0", "--json", "--quiet"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["slope_fits"]["student3"]["alpha"] > 0
    z = gaussian_surface(64, 64e-6, 1e-7, 4e-6, rng=5).z
    st = roughness_statistics(z, 1e-6, blocks=0)
    assert [r["model"] for r in _fit_rows(st)] == ["ggx", "beckmann", "student3"]
    drawn = []
    density = student3.radial_density
    monkeypatch.setattr(student3, "radial_density", lambda r, a: drawn.append(a) or density(r, a))
    assert figures.surface_figure(z, (1e-6, 1e-6), st).startswith("data:image/png")
    assert drawn == [st.slope_fits.student3.alpha]


def test_trace_takes_it_through_its_slope_table(student3, capsys):
    argv = ["trace", "--theta-i", "30", "--wavelength", "633", "--rays", "400", "--alpha",
            "0.3", "--distribution", "student3", "--substrate", "1.5", "--single-scattering",
            "--scheduler", "serial", "--json"]  # fmt: skip
    assert main(argv) == 0
    run = json.loads(capsys.readouterr().out)
    assert run["config"]["substrate"]["ndf"]["name"] == "student3(0.3)"
    # the evaluated single-scattering albedo is the model's integral up to the table's
    # discretisation (Beckmann's table: 1e-5 relative)
    m = models.get("microfacet", n=1.5, k=0.0, distribution="student3")
    rho = hemispherical_reflectance(m, {"alpha": 0.3}, [30.0], rtol=1e-7)[0]
    assert run["albedo"] == pytest.approx(rho, rel=1e-3)
