"""``labbrdf trace``: the library's setup errors are said with the command's option names."""

from __future__ import annotations

from pathlib import Path

import pytest

import labbrdf
from labbrdf.cli import main

SCAN = Path(labbrdf.__file__).parent / "data" / "fixtures" / "specular" / "osr_specular.csv"
BASE = ["trace", "--theta-i", "45", "--wavelength", "633", "--rays", "10", "--json"]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--nk-from", str(SCAN), "--alpha", "0.2"], f"--nk-from {SCAN}: no psi/delta rows"),
        (["--substrate", "2j", "--nk-from", str(SCAN), "--alpha", "0.2"],
         "give the substrate index with --substrate N+Kj or --nk-from FILE"),
        (["--substrate", "2j", "--alpha", "0", "--distribution", "beckmann"],
         "--distribution beckmann needs a roughness alpha > 0"),
        (["--substrate", "2j", "--alpha", "0.2", "--coating-alpha", "0.1"],
         "--thickness, --coating-alpha and --coating-surface need --coating (or --coating-from)"),
        (["--substrate", "2j", "--alpha", "0.2", "--coating", "1.5", "--thickness", "9",
          "--coating-alpha", "0.1", "--coating-surface", str(SCAN)],
         "give the coating roughness once: --coating-alpha or --coating-surface"),
        (["--substrate", "2j", "--alpha", "0.2", "--coating", "x"],
         "--coating 'x': expected a complex index"),
    ],
)  # fmt: skip
def test_setup_errors_name_the_options(argv, message, capsys) -> None:
    assert main([*BASE, *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert "substrate_index" not in err and "coating_index" not in err  # no Python keywords
