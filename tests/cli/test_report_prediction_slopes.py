"""``labbrdf report --prediction-slopes``: the roughness the section prediction traces."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from labbrdf.cli import main
from labbrdf.dataset import Measurement, make_frame, write
from labbrdf.report.user import user_report


def _dataset(path: Path) -> Path:
    m = Measurement(
        make_frame(sample="Al-7", instrument="synthetic", source=path.name,
                   quantity="reflectance", value=np.linspace(0.90, 0.95, 6), unit="1",
                   wavelength_nm=np.linspace(400.0, 900.0, 6), theta_i_deg=8.0),
        {},
    )  # fmt: skip
    write(m, path)
    return path


def test_report_records_the_slopes_asked_for(tmp_path: Path) -> None:
    out = tmp_path / "rep"
    f = _dataset(tmp_path / "a.parquet")
    code = main(["report", str(f), "-o", str(out), "--quiet", "--prediction-slopes", "measured"])
    assert code == 0
    res = json.loads((out / "results.json").read_text())
    assert res["meta"]["prediction_slopes"] == "measured"


def test_report_default_slopes_are_ggx(tmp_path: Path) -> None:
    out = tmp_path / "rep"
    assert main(["report", str(_dataset(tmp_path / "a.parquet")), "-o", str(out), "--quiet"]) == 0
    assert json.loads((out / "results.json").read_text())["meta"]["prediction_slopes"] == "ggx"


def test_report_unknown_slopes_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    f = _dataset(tmp_path / "a.parquet")
    out = tmp_path / "rep"
    with pytest.raises(SystemExit) as e:
        main(["report", str(f), "-o", str(out), "--prediction-slopes", "gauss"])
    assert e.value.code == 2
    assert "--prediction-slopes: invalid choice: 'gauss'" in capsys.readouterr().err
    assert not out.exists()


def test_user_report_refuses_unknown_slopes_before_any_work(tmp_path: Path) -> None:
    out = tmp_path / "rep"
    with pytest.raises(ValueError, match="prediction_slopes: expected one of ggx, measured"):
        user_report([_dataset(tmp_path / "a.parquet")], "smooth3", out, prediction_slopes="x")
    assert not out.exists()
