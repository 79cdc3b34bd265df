"""One meaning per option name: --wavelength NM is one wavelength, --wavelength-range MIN:MAX
a range of rows; --theta-i DEG an angle of incidence, --theta-i-range MIN:MAX a range of
rows, in every subcommand; old spellings fail naming the new one; no abbreviations (a
prefix never stands for an option)."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

import labbrdf
from labbrdf.cli import _options, build_parser, main

SCAN = Path(labbrdf.__file__).parent / "data" / "fixtures" / "specular" / "osr_specular.csv"
TRACE = ["trace", "--substrate", "1.5+7j", "--alpha", "0.2", "--theta-i", "45", "--rays", "10"]


def subparsers() -> dict[str, argparse.ArgumentParser]:
    p = build_parser()
    (sub,) = (a for a in p._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def test_every_command_gives_each_wavelength_and_angle_option_one_meaning() -> None:
    seen = {
        "--wavelength": set(),
        "--wavelength-range": set(),
        "--theta-i": set(),
        "--theta-i-range": set(),
    }
    for name, sp in subparsers().items():
        assert sp.allow_abbrev is False, name
        for a in sp._actions:
            for opt in set(a.option_strings) & set(seen):
                kind = type(a).__name__ if isinstance(a, _options._Renamed) else a.type
                seen[opt].add(kind)
    assert seen["--wavelength"] == {_options._wavelength_value, "_Renamed"}
    assert seen["--wavelength-range"] == {_options._range}
    assert seen["--theta-i"] == {_options._angle_value, "_Renamed"}
    assert seen["--theta-i-range"] == {_options._row_range}


@pytest.mark.parametrize("command", ["ingest", "nk", "film", "fit"])
def test_the_old_angle_row_range_spelling_names_the_new_one(command, capsys) -> None:
    err = exit_2([command, str(SCAN), "--theta-i", "40:60"], capsys)
    assert "--theta-i-range MIN:MAX" in err


def test_report_old_angle_row_range_spelling_names_the_new_one(tmp_path: Path, capsys) -> None:
    argv = ["report", str(SCAN), "-o", str(tmp_path / "r"), "--theta-i", "40:60"]
    assert "--theta-i-range MIN:MAX" in exit_2(argv, capsys)
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize(
    "argv",
    [
        ["trace", "--substrate", "1.5+7j", "--wavelength", "650", "--theta-i", "40:60"],
        ["hemispherical", "--model", "smooth3", "--theta-i", "40:60"],
        ["export", "--model", "smooth3", "--theta-i", "40:60", "-o", "x.bsdf"],
    ],
)
def test_an_angle_given_as_a_range_names_the_row_range(argv, capsys) -> None:
    assert "a range of rows is --theta-i-range MIN:MAX" in exit_2(argv, capsys)


def test_the_angle_row_range_selects_rows_and_is_checked_first(capsys) -> None:
    assert main(["ingest", str(SCAN), "--theta-i-range", "40:50", "--json"]) == 0
    assert '"theta_i_deg": [\n      45.0' in capsys.readouterr().out
    err = exit_2(["ingest", str(SCAN), "--theta-i-range", "60:40"], capsys)
    assert "MIN must not exceed MAX" in err


def exit_2(argv: list[str], capsys) -> str:
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err


@pytest.mark.parametrize("command", ["ingest", "nk", "film"])
def test_the_old_row_range_spelling_names_the_new_one(command, capsys) -> None:
    err = exit_2([command, str(SCAN), "--wavelength", "400:700"], capsys)
    assert "--wavelength-range MIN:MAX" in err


def test_report_old_row_range_spelling_names_the_new_one(tmp_path: Path, capsys) -> None:
    argv = ["report", str(SCAN), "-o", str(tmp_path / "r"), "--wavelength", "400:700"]
    assert "--wavelength-range MIN:MAX" in exit_2(argv, capsys)
    assert not (tmp_path / "r").exists()


def test_film_old_two_word_range_is_refused(capsys) -> None:
    err = exit_2(["film", str(SCAN), "--wavelength-range", "400", "700"], capsys)
    assert "expected MIN:MAX in one word" in err


def test_fit_nk_wavelength_is_now_wavelength(capsys) -> None:
    argv = ["fit", str(SCAN), "--model", "microfacet", "--nk-from", "x.dat"]
    assert "say --wavelength NM" in exit_2([*argv, "--nk-wavelength", "550"], capsys)


def test_fit_wavelength_is_for_nk_from_only(capsys) -> None:
    argv = ["fit", str(SCAN), "--model", "smooth3", "--wavelength", "550", "--scheduler", "serial"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--nk-from" in err and "--wavelength-range MIN:MAX" in err


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ("400:700", "a range of rows is --wavelength-range MIN:MAX"),
        ("0", "expected one wavelength [nm] > 0"),
        ("nan", "expected one wavelength [nm] > 0"),
        ("green", "expected one wavelength [nm] > 0"),
    ],
)
def test_a_single_wavelength_is_one_positive_number(value, message, capsys) -> None:
    assert message in exit_2([*TRACE, "--wavelength", value], capsys)


@pytest.mark.parametrize(
    "argv",
    [
        ["ingest", str(SCAN), "--wavelength-r", "400:700"],
        ["ingest", str(SCAN), "--wave", "400:700"],
        [*TRACE, "--wavelength", "650", "--single"],
        [*TRACE[:-2], "--wavelength", "650", "--ray", "10"],
    ],
)
def test_no_option_is_taken_by_a_prefix(argv, capsys) -> None:
    assert "unrecognized arguments" in exit_2(argv, capsys)


def test_the_new_row_range_selects_rows(tmp_path: Path, capsys) -> None:
    out = tmp_path / "sel.csv"
    assert main(["ingest", str(SCAN), "--wavelength-range", "500:560", "-o", str(out)]) == 0
    import labbrdf

    assert set(labbrdf.read(out).data["wavelength_nm"]) == {500.0, 550.0}
    capsys.readouterr()
    assert main(["ingest", str(SCAN), "--wavelength-range", "1000:2000"]) == 2
    assert "--wavelength-range 1000:2000: no row left" in capsys.readouterr().err


def test_a_model_without_an_index_is_refused_with_nk_from(capsys) -> None:
    argv = ["hemispherical", "--model", "smooth3", "--theta-i", "30", "--nk-from", str(SCAN)]
    assert main([*argv, "--wavelength", "500"]) == 2
    assert "--nk-from: model 'smooth3' takes no index n, k" in capsys.readouterr().err


def test_nk_from_a_file_without_psi_delta_names_option_and_file(capsys) -> None:
    argv = ["hemispherical", "--model", "microfacet", "--theta-i", "30", "--nk-from", str(SCAN)]
    assert main([*argv, "--wavelength", "500", "--param", "alpha=0.2"]) == 2
    err = capsys.readouterr().err
    assert f"--nk-from {SCAN}: no psi/delta rows" in err


def test_report_passes_the_row_range_to_the_library(monkeypatch, tmp_path: Path) -> None:
    import labbrdf.report

    seen = {}

    def fake_report(files, model, out, **kw):
        seen.update(kw["selection"])
        return 0

    monkeypatch.setattr(labbrdf.report, "user_report", fake_report)
    argv = ["report", str(SCAN), "-o", str(tmp_path / "r"), "--scheduler", "serial"]
    assert main([*argv, "--wavelength-range", "400:700", "--theta-i-range", "45"]) == 0
    assert seen == {"wavelength": "400:700", "theta_i": "45"}
