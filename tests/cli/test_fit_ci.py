"""`labbrdf fit --ci`: which interval each parameter carries, in the JSON and the table."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from labbrdf.cli import main


def _fit(scan, ci: str, capsys, tmp_path) -> tuple[dict, pd.DataFrame]:
    out = tmp_path / f"{ci}.csv"
    argv = ["fit", str(scan), "--model", "smooth3", "--scheduler", "serial", "--json"]
    assert main([*argv, "--ci", ci, "-o", str(out)]) == 0
    group = json.loads(capsys.readouterr().out)[0]
    return group, pd.read_csv(out).iloc[[0]]


def test_fit_ci_auto_profiles_where_profile_would_and_says_so(specular_scan, capsys, tmp_path):
    auto, table = _fit(specular_scan, "auto", capsys, tmp_path)
    prof, _ = _fit(specular_scan, "profile", capsys, tmp_path)
    how = auto["ci_methods"]
    assert set(how) == {"k1", "k2", "k3"} and set(how.values()) <= {"wald", "profile"}
    for k, h in how.items():
        assert table[f"{k}_ci"].iloc[0] == h
        if h == "profile":  # the same profile as --ci profile's
            assert auto["params"][k]["ci95"] == prof["params"][k]["ci95"]
            assert auto["ci_reasons"][k]
    assert prof["ci_methods"] == dict.fromkeys(how, "profile")


@pytest.mark.parametrize(("ci", "more"), [("auto", []), ("profile", ["--replicates", "2"])])
def test_fit_ci_other_than_wald_refuses_seed_replicates(specular_scan, capsys, ci, more):
    # layered fits 3 model seeds by default: their Wald errors are combined, not profiled
    argv = ["fit", str(specular_scan), "--model", "layered", "--param", "n=1.55"]
    assert main([*argv, "--param", "k=7.71", "--ci", ci, *more]) == 2
    err = capsys.readouterr().err
    assert f"--ci {ci}: seed replicates combine Wald errors" in err and "Traceback" not in err
