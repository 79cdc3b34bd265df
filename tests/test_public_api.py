"""The package's public face: what ``import labbrdf`` offers, lists and documents."""

from __future__ import annotations

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


def test_every_module_of_the_package_is_an_attribute_and_in_the_api_page() -> None:
    pkg = Path(labbrdf.__file__).parent
    modules = sorted(
        p.stem if p.is_file() else p.name
        for p in pkg.iterdir()
        if (p.suffix == ".py" and not p.stem.startswith("_")) or (p / "__init__.py").is_file()
    )
    text = (DOCS / "api.md").read_text(encoding="utf-8")
    for name in modules:
        assert name in dir(labbrdf), name
        assert re.search(rf"^   {name}$", text, flags=re.M), f"{name} missing from docs/api.md"
