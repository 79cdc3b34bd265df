"""Shared test fixtures and tolerances.

Tests that need ../shared (real instrument exports, oracles) use the ``shared_dir``,
``real_exports`` or ``oracles`` fixtures, which skip cleanly where the folder is absent
(a user's clone has no ../shared). Paths inside the project (``project_root``,
``fixtures_dir``, ``specular_scan``) are built here once, so a test file may move between
folders without counting its parents.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT / "labbrdf" / "data" / "fixtures"
SHARED = Path(os.environ.get("LABBRDF_SHARED", ROOT.parent / "shared"))

#: relative tolerance against double-precision oracles (1e-10)
RTOL_ORACLE = 1e-10

#: the sample the CLI tests trace: bare aluminium (n + ik = 1.55 + 7.71i), GGX alpha 0.2,
#: 45 deg incidence, 650 nm; a test adds how much to trace (rays, seed, scheduler, outputs)
TRACE_SAMPLE = (
    "trace",
    "--substrate",
    "1.55+7.71j",
    "--alpha",
    "0.2",
    "--theta-i",
    "45",
    "--wavelength",
    "650",
)


@pytest.fixture(autouse=True, scope="session")
def _user_cache(tmp_path_factory: pytest.TempPathFactory):
    """Every test caches (the tracer's exit operators) in a session folder, never ~/.cache."""
    old = os.environ.get("XDG_CACHE_HOME")
    os.environ["XDG_CACHE_HOME"] = str(tmp_path_factory.mktemp("cache"))
    yield
    if old is None:
        os.environ.pop("XDG_CACHE_HOME", None)
    else:
        os.environ["XDG_CACHE_HOME"] = old


@pytest.fixture(scope="session")
def project_root() -> Path:
    """The project folder (holds ``labbrdf/``): PYTHONPATH of a test's subprocess."""
    return ROOT


@pytest.fixture(scope="session")
def fixtures_dir() -> Path:
    return FIXTURES


@pytest.fixture(scope="session")
def specular_scan() -> Path:
    """The bundled specular BRDF scan (``fixtures/specular/osr_specular.csv``)."""
    return FIXTURES / "specular" / "osr_specular.csv"


@pytest.fixture
def trace_sample() -> list[str]:
    """:data:`TRACE_SAMPLE` as a fresh list (a test appends to it)."""
    return list(TRACE_SAMPLE)


@pytest.fixture
def trace_argv(trace_sample: list[str]) -> list[str]:
    """A small trace of :data:`TRACE_SAMPLE`: 2000 rays, serial (for the tests that need a
    trace to run, not its statistics)."""
    return [*trace_sample, "--rays", "2000", "--scheduler", "serial"]


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    if not SHARED.is_dir():
        pytest.skip(f"{SHARED} absent (real exports and oracles live outside the project)")
    return SHARED


@pytest.fixture(scope="session")
def real_exports(shared_dir: Path) -> Path:
    d = shared_dir / "real-exports"
    if not d.is_dir():
        pytest.skip(f"{d} absent")
    return d


@pytest.fixture(scope="session")
def oracles(shared_dir: Path) -> Path:
    d = shared_dir / "oracles"
    if not d.is_dir():
        pytest.skip(f"{d} absent")
    return d


@pytest.fixture(scope="session")
def prediction_sets():
    """The writers of consistent synthetic one-sample files (``tests/prediction_sets.py``)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "prediction_sets", Path(__file__).with_name("prediction_sets.py")
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def sample_set(prediction_sets, tmp_path_factory: pytest.TempPathFactory) -> dict:
    """One sample's height map, psi/Delta (true and wrong index) and measured ``.bsdf``."""
    pytest.importorskip("SurfaceTopography")
    from labbrdf.adapters.topography import read_height_map
    from labbrdf.prediction import roughness_alpha

    ps = prediction_sets
    d = tmp_path_factory.mktemp("sample_a")
    hm = ps.write_height_map(d / "sample_a_heights.nc")
    fit = roughness_alpha(read_height_map(hm))
    return {
        "dir": d,
        "height_map": hm,
        "fit": fit,
        "psi_delta": ps.write_wvase(d / "sample_a_psi.dat", ps.TRUE_NK),
        "psi_delta_wrong": ps.write_wvase(d / "sample_b_psi.dat", ps.WRONG_NK, "SYNTHETIC B"),
        "bsdf": ps.write_bsdf(d / "sample_a.bsdf", ps.brdf_config(fit.alpha)),
    }


@pytest.fixture(scope="session")
def microfacet_rows():
    """``rows(distribution, alpha, seed)``: a synthetic microfacet BRDF with 2 % noise.

    n = 1.5, k = 0 at 633 nm; incidences 20, 45, 65 deg, detectors 0-80 deg in three
    azimuth planes (180, 150, 120 deg); sigma = the 2 % of each value.
    """
    import numpy as np

    from labbrdf import models
    from labbrdf.dataset import make_frame

    def rows(distribution: str, alpha: float, seed: int):
        ti = np.repeat([20.0, 45.0, 65.0], 3 * 17)
        tr = np.tile(np.linspace(0.0, 80.0, 17), 9)
        pr = np.tile(np.repeat([180.0, 150.0, 120.0], 17), 3)
        truth = models.get("microfacet", n=1.5, k=0.0, distribution=distribution)
        y = truth.evaluate(*np.radians([ti, tr, pr]), params={"alpha": alpha})
        y = y * (1 + 0.02 * np.random.default_rng(seed).standard_normal(y.size))
        return make_frame(
            sample="s",
            instrument="synthetic",
            source="test",
            quantity="brdf",
            value=y,
            unit="sr-1",
            wavelength_nm=633.0,
            sigma=0.02 * np.abs(y),
            theta_i_deg=ti,
            theta_r_deg=tr,
            phi_r_deg=pr,
        )

    return rows
