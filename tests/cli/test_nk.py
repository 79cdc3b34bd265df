"""``labbrdf nk`` on a coated sample: pseudo-constants of a stack are said to be such."""

from __future__ import annotations

import json
from pathlib import Path

from labbrdf.cli import main

W1 = "woollam-wvase-ascii/w1_12082006.dat"
TA = "woollam-wvase-ascii/w2_10102006.dat"


def test_nk_says_what_a_coated_wafer_gives(real_exports: Path, capsys) -> None:
    assert main(["nk", str(real_exports / W1), "--wavelength-range", "480:520"]) == 0
    out = capsys.readouterr().out
    assert "pseudo-constants of a stack, not a material's n, k" in out
    assert "at 100% of the 25 wavelengths" in out and "not combined" in out


def test_nk_on_a_partly_angle_dependent_metal_says_the_sigmas_are_scaled(
    real_exports: Path, capsys
) -> None:
    assert main(["nk", str(real_exports / TA), "--wavelength-range", "400:800"]) == 0
    out = capsys.readouterr().out
    assert "angle-dependent over part of the spectrum" in out
    assert "sigmas are multiplied by sqrt(chi2/dof)" in out and "not combined" not in out


def test_nk_json_of_a_coated_wafer_has_no_combined_value(real_exports: Path, capsys) -> None:
    assert main(["nk", str(real_exports / W1), "--wavelength-range", "480:520", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert all(v is None for v in out["combined"]["n"])
    assert all(out["combined"]["angle_dependent"])
    assert len(out["n"]) == 8 * len(out["combined"]["n"])  # the per-angle values stay


def test_nk_from_a_coated_wafer_is_refused(real_exports: Path, capsys) -> None:
    argv = ["hemispherical", "--model", "microfacet", "--param", "alpha=0.1"]
    argv += ["--theta-i", "30", "--nk-from", str(real_exports / W1), "--wavelength", "500"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--nk-from" in err and "pseudo-constants of a stack" in err
