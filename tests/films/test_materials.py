"""A material named by a file is read by the caller's reader, never by the films themselves."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from labbrdf.films import FilmError, Stack, as_material, load_model, read_fit_json
from labbrdf.nk.dispersion import Tabulated

MODEL = (
    '[substrate]\nfile = "sub.txt"\n\n[[layer]]\nname = "mix"\nmaterial = "ema"\n'
    'components = ["sio2", {file = "film.txt"}]\nthickness_nm = 10\n'
)


def _reader(calls: list[Path]):
    """A reader that records what it is asked for and answers a constant table."""

    def read(path):
        calls.append(Path(path))
        return Tabulated([300.0, 1200.0], [1.7, 1.7], [0.0, 0.0], str(path), f"file:{path}")

    return read


def _model(tmp_path: Path) -> Path:
    p = tmp_path / "m.toml"
    p.write_text(MODEL)
    return p


def test_a_model_file_reads_its_file_materials_with_the_reader_given(tmp_path: Path) -> None:
    calls: list[Path] = []
    fm = load_model(_model(tmp_path), _reader(calls))
    assert calls == [tmp_path / "sub.txt", tmp_path / "film.txt"]  # relative to the model
    assert fm.stack.substrate.nk(500.0) == pytest.approx(1.7 + 0j)


def test_a_model_file_naming_a_file_without_a_reader_names_the_file_and_line(
    tmp_path: Path,
) -> None:
    with pytest.raises(FilmError, match=r"m.toml, line 2: .*sub.txt.*no table reader.*read_table"):
        load_model(_model(tmp_path))
    p = tmp_path / "m.toml"
    p.write_text(MODEL.replace('file = "sub.txt"', 'material = "si"'))
    with pytest.raises(FilmError, match=r"m.toml, line 7: .*film.txt.*no table reader"):
        load_model(p)


@pytest.mark.parametrize(
    "material",
    [
        {"model": "tabulated", "file": "t.txt"},
        {"model": "ema", "components": ["void", {"model": "tabulated", "file": "t.txt"}]},
        {"model": "graded", "base": {"model": "tabulated", "file": "t.txt"}, "parameter": "x",
         "top": 1, "bottom": 1},
    ],
)  # fmt: skip
def test_as_material_reads_a_file_only_through_the_reader(material) -> None:
    with pytest.raises(FilmError, match="'t.txt': no table reader"):
        as_material(material)
    calls: list[Path] = []
    try:
        as_material(material, _reader(calls))
    except FilmError:
        pass  # a table has no parameter "x" to grade: the reader was asked all the same
    assert calls == [Path("t.txt")]


def test_a_fit_json_naming_a_file_is_read_with_the_reader_given(tmp_path: Path) -> None:
    st = load_model(_model(tmp_path), _reader([])).stack
    fit = tmp_path / "fit.json"
    fit.write_text(json.dumps({"stack": st.to_dict(), "wavelength_range_nm": [400.0, 800.0]}))
    with pytest.raises(FilmError, match=r"fit.json: stack: .*no table reader"):
        read_fit_json(fit)
    calls: list[Path] = []
    back = Stack.from_fit_json(fit, _reader(calls))
    assert back.to_dict() == st.to_dict() and len(calls) == 2
