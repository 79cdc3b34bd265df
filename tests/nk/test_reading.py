"""Tables of n, k from files are built in the dataset layer; the dispersion module reads none."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import labbrdf
from labbrdf.films import as_material
from labbrdf.nk import dispersion as disp
from labbrdf.nk import tabulated_from_file

DISPERSION = Path(disp.__file__).parent


def test_the_dispersion_models_import_nothing_that_reads_files() -> None:
    imported = set()
    for f in sorted(DISPERSION.glob("*.py")):
        for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                imported |= {a.name for a in node.names}
            elif isinstance(node, ast.ImportFrom):
                mod = ("." * node.level) + (node.module or "")
                imported |= {f"{mod}.{a.name}" if node.level else mod for a in node.names}
    upper = ("pandas", "..", "labbrdf")  # nothing from outside the package of models
    assert not [m for m in imported if m.startswith(upper)], imported
    assert not hasattr(disp.Tabulated, "from_file")


def test_the_dispersion_models_load_without_pandas_or_the_readers() -> None:
    code = (
        "import sys\nfrom labbrdf.nk.dispersion import MODELS\n"
        "print(sorted(m for m in sys.modules if m == 'pandas' or m.startswith("
        "('labbrdf.adapters', 'labbrdf.nk.reading', 'labbrdf.films'))))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.strip() == "[]", done.stderr


def test_a_table_file_gives_the_table_of_its_text(tmp_path: Path) -> None:
    text = "# film\nwavelength_nm;n;k\n800;1.8;0\n400;2.0;0.1\n"
    p = tmp_path / "film.csv"
    p.write_text(text)
    t = tabulated_from_file(p)
    w, n, k = disp.parse_nk_table(text, "text")
    assert t.wavelength_nm.tolist() == w.tolist() == [400.0, 800.0]
    assert t.n.tolist() == n.tolist() and t.k.tolist() == k.tolist()
    assert t.source == str(p) and t.to_dict() == {"model": "tabulated", "file": str(p)}


def test_a_file_keyed_table_is_read_back_by_as_material_not_by_from_dict(tmp_path: Path) -> None:
    p = tmp_path / "glass.txt"
    p.write_text("500 1.5\n600 1.49\n")
    d = tabulated_from_file(p).to_dict()
    with pytest.raises(disp.DispersionError, match="glass.txt.*tabulated_from_file"):
        disp.from_dict(d)
    assert as_material(d, tabulated_from_file).nk(550.0) == pytest.approx(1.495 + 0j)


def test_a_file_neither_table_nor_export_names_both_reasons(tmp_path: Path) -> None:
    p = tmp_path / "notes.txt"
    p.write_text("400 2.0\nwords, not numbers\n")
    with pytest.raises(disp.DispersionError, match="notes.txt: neither an n,k table") as exc:
        tabulated_from_file(p)
    assert "line 2" in str(exc.value) and "ellipsometer file" in str(exc.value)


def test_a_film_model_file_entry_reads_the_table(tmp_path: Path) -> None:
    (tmp_path / "sub.txt").write_text("400 3.0 0.5\n900 2.5 0.1\n")
    model = tmp_path / "m.toml"
    model.write_text(
        '[substrate]\nfile = "sub.txt"\n\n[[layer]]\nname = "oxide"\nmaterial = "sio2"\n'
        "thickness_nm = 10\n"
    )
    fm = labbrdf.films.load_model(model, tabulated_from_file)
    assert fm.stack.substrate.nk(650.0) == pytest.approx(2.75 + 0.3j)
