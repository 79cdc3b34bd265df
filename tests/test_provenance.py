"""The environment that produced a result is recorded with it."""

from __future__ import annotations

import json
import platform
from importlib import metadata

import labbrdf
from labbrdf.fitting import FitData, fit
from labbrdf.provenance import PACKAGES, version_of, versions
from labbrdf.report.validate import validate

STACK = ("numpy", "scipy", "pandas", "nlopt", "colour-science", "matplotlib", "dask")


def test_versions_names_python_and_the_numerical_stack():
    v = versions()
    assert v["python"] == platform.python_version()
    for name in STACK:
        assert name in PACKAGES
        assert v[name] == metadata.version(name)
    assert version_of("no-such-distribution-labbrdf") is None


def test_every_fit_records_the_nlopt_version():
    import numpy as np

    x = np.linspace(-2, 2, 21)
    ti = np.full_like(x, 45.0)
    y = labbrdf.models.get("smooth3").evaluate(
        np.radians(ti), np.radians(ti + x), params={"k1": 0.9, "k2": 0.01, "k3": 0.4}
    )
    r = fit("smooth3", FitData(ti, ti + x, y))
    assert r.nlopt_version == metadata.version("nlopt")
    assert r.summary()["nlopt_version"] == metadata.version("nlopt")


def test_report_header_and_results_json_name_the_environment(tmp_path):
    out = tmp_path / "r"
    validate(out, quick=True, progress=False, shared_dir=False, sections_to_run=["ingest"])
    env = json.loads((out / "results.json").read_text())["meta"]["environment"]
    page = (out / "index.html").read_text()
    for name in ("python", *STACK):
        assert env[name], name
        assert f"{name} {env[name]}" in page
