"""One weighting rule: labbrdf.fit, the CLI's fit and the report weight alike; bounds said.

The default everywhere is ``weighting="auto"`` with zeros masked: 1/sigma^2 where every
point has a sigma, relative weights where none has. A parameter that ends at a bound of its
box is reported as ``at bound: NAME`` wherever success is reported.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import labbrdf
from labbrdf.cli import main
from labbrdf.dataset import Measurement, write_csv


@pytest.fixture(scope="module")
def no_sigma(fixtures_dir, tmp_path_factory):
    """One wavelength of the OSR specular scan, its sigmas removed, two values set to 0."""
    m = labbrdf.read(fixtures_dir / "specular" / "osr_specular.csv")
    d = m.data
    d = d[d["wavelength_nm"] == d["wavelength_nm"].min()].reset_index(drop=True)
    d = d.assign(sigma=np.nan)
    d.loc[[3, 7], "value"] = 0.0  # instrument-masked directions
    p = tmp_path_factory.mktemp("weighting") / "osr_one.csv"
    write_csv(Measurement(d, {}), p)
    return p


def test_python_and_cli_give_the_same_fit(no_sigma, capsys):
    res = labbrdf.fit("smooth3", labbrdf.read(no_sigma))
    assert res.weighting.startswith("relative") and res.nmasked == 2
    assert main(["fit", str(no_sigma), "--model", "smooth3", "--json"]) == 0
    rec = json.loads(capsys.readouterr().out)[0]
    assert rec["weighting"] == res.weighting and rec["nmasked"] == 2
    for name, p in rec["params"].items():
        # same data (CSV round trip at full precision), same seed: the same optimum
        assert p["value"] == pytest.approx(res.values[name], rel=1e-6)


def test_the_weighting_is_printed_beside_the_values(no_sigma, capsys):
    res = labbrdf.fit("smooth3", labbrdf.read(no_sigma))
    assert "    weighting          = relative: sigma = max(|y|" in res.fit_report()
    assert "<th>weighting</th><td>relative" in res._repr_html_()
    assert main(["fit", str(no_sigma), "--model", "smooth3"]) == 0
    out = capsys.readouterr().out
    header, row = out.strip().splitlines()[-2:]
    assert "weighting" in header.split() and "relative" in row.split()


def test_a_parameter_at_its_bound_is_not_plain_success(no_sigma, capsys):
    m = labbrdf.read(no_sigma)
    free = labbrdf.fit("smooth3", m)
    assert free.status == "ok" and free.at_bound == []
    k3 = free.values["k3"]
    box = {"k3": {"value": 0.5 * k3, "min": 0.1 * k3, "max": 0.6 * k3}}
    res = labbrdf.fit("smooth3", m, params=box)
    assert res.success and res.at_bound == ["k3"] and res.status == "at bound: k3"
    assert "success            = True, but k3 at a bound of its box" in res.fit_report()
    assert res.summary()["status"] == "at bound: k3"
    table = labbrdf.fit_many(m, "smooth3", params=box)
    assert list(table["status"]) == ["at bound: k3"]  # the table `labbrdf fit` prints


@pytest.mark.shared
def test_the_bsdf_microfacet_fit_is_one_answer_and_says_at_bound(real_exports, capsys):
    # alpha 1.5 (at its bound, reported as success) from the CLI and 0.2594 from Python
    # with their former defaults: now one answer, and its status says where it ended
    f = real_exports / "zemax-bsdf" / "test_13_planesymmetric_brdf_zemax.bsdf"
    model = labbrdf.models.get("microfacet", ideal_mirror=True)
    res = labbrdf.fit(model, labbrdf.read(f))
    argv = ["fit", str(f), "--model", "microfacet", "--param", "ideal_mirror=true", "--json"]
    assert main(argv) == 0
    rec = json.loads(capsys.readouterr().out)[0]
    assert rec["params"]["alpha"]["value"] == pytest.approx(res.values["alpha"], rel=1e-6)
    assert rec["weighting"] == res.weighting and res.weighting.startswith("relative")
    assert res.status == "at bound: alpha" and rec["params"]["alpha"]["at_bound"]
    assert main(argv[:-1]) == 0
    assert "at bound: alpha" in capsys.readouterr().out
