"""The package's public face: what ``import labbrdf`` offers, lists and documents."""

from __future__ import annotations

import ast
import importlib
import re
import subprocess
import sys
from pathlib import Path

import labbrdf

DOCS = Path(__file__).resolve().parents[1] / "docs"


def test_dir_lists_every_public_name_and_each_resolves() -> None:
    listed = dir(labbrdf)
    assert set(labbrdf.__all__) <= set(listed)
    for name in labbrdf.__all__:
        assert getattr(labbrdf, name) is not None, name


def test_the_user_facing_names_are_there() -> None:
    for name in (
        "Substrate",
        "Coating",
        "TraceConfig",
        "select",
        "nk_table",
        "user_report",
        "models",
        "nk",
        "ellipsometry",
        "selection",
        "topography",
        "read_height_map",
    ):
        assert name in dir(labbrdf), name
        getattr(labbrdf, name)


def test_an_unknown_name_raises_attributeerror() -> None:
    try:
        labbrdf.no_such_thing  # noqa: B018
    except AttributeError as exc:
        assert "no_such_thing" in str(exc)
    else:
        raise AssertionError("no AttributeError")


def test_import_stays_cheap() -> None:
    heavy = "('pandas', 'scipy', 'matplotlib', 'nlopt')"
    code = f"import sys, labbrdf; print(sorted(m for m in {heavy} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_api_page_documents_exactly_the_top_level_names() -> None:
    text = (DOCS / "api.md").read_text(encoding="utf-8")
    block = text.split(":toctree: generated", 1)[1].split("```", 1)[0]
    documented = re.findall(r"^   (\w+)$", block, flags=re.M)
    assert documented == list(labbrdf._LAZY)


def _api_block(text: str, heading: str) -> list[str]:
    block = text.split(heading, 1)[1].split("```{eval-rst}", 1)[1].split("```", 1)[0]
    return re.findall(r"^   (\w+)$", block, flags=re.M)


def test_every_module_is_public_or_plumbing_and_in_the_api_page() -> None:
    pkg = Path(labbrdf.__file__).parent
    modules = sorted(
        p.stem if p.is_file() else p.name
        for p in pkg.iterdir()
        if (p.suffix == ".py" and not p.stem.startswith("_")) or (p / "__init__.py").is_file()
    )
    assert modules == sorted([*labbrdf._MODULES, *labbrdf._PLUMBING])
    text = (DOCS / "api.md").read_text(encoding="utf-8")
    assert sorted(_api_block(text, "## Modules")) == sorted(labbrdf._MODULES)
    assert sorted(_api_block(text, "## Internals")) == sorted(labbrdf._PLUMBING)
    for name in labbrdf._MODULES:
        assert name in dir(labbrdf), name


def test_plumbing_is_off_the_public_face_but_importable_by_path() -> None:
    for name in ("cli", "jsonsafe", "outputs", "provenance", "richrepr"):
        assert name not in dir(labbrdf) and name not in labbrdf.__all__, name
        assert importlib.import_module(f"labbrdf.{name}").__name__ == f"labbrdf.{name}"
    code = "import labbrdf; labbrdf.richrepr"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 1 and "AttributeError" in out.stderr


def _type_checking_imports() -> tuple[set[str], set[tuple[str, str]]]:
    """What the ``if TYPE_CHECKING:`` block of labbrdf/__init__.py imports."""
    tree = ast.parse(Path(labbrdf.__file__).read_text(encoding="utf-8"))
    block = next(
        n for n in tree.body if isinstance(n, ast.If) and ast.unparse(n.test) == "TYPE_CHECKING"
    )
    modules, names = set(), set()
    for imp in block.body:
        assert isinstance(imp, ast.ImportFrom) and imp.level == 1, ast.unparse(imp)
        for alias in imp.names:
            if imp.module is None:
                modules.add(alias.name)
            elif f"{imp.module}.{alias.name}" in labbrdf._MOVED.values():
                modules.add(alias.asname or alias.name)
            else:
                names.add((alias.name, f"labbrdf.{imp.module}"))
    return modules, names


def test_the_type_checking_imports_mirror_the_tables() -> None:
    modules, names = _type_checking_imports()
    assert modules == {*labbrdf._MODULES, *labbrdf._MOVED}
    assert names == {(name, module) for name, (module, _) in labbrdf._LAZY.items()}
    assert all(name == attr for name, (_, attr) in labbrdf._LAZY.items())


def test_all_and_dir_follow_from_the_tables() -> None:
    assert labbrdf.__all__ == [
        "__version__",
        *labbrdf._LAZY,
        *labbrdf._MODULES,
        *labbrdf._MOVED,
    ]
    assert dir(labbrdf) == sorted(labbrdf.__all__)


def test_moved_modules_keep_their_old_name() -> None:
    from labbrdf.roughness import smoothness, synthetic, topography

    assert labbrdf.topography is topography
    assert labbrdf.smoothness is smoothness
    assert labbrdf.surface is synthetic
    assert set(labbrdf._MOVED) <= set(dir(labbrdf))
