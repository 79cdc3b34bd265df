"""Section ``ingest``: every input file read into the common dataset, with what it holds."""

from __future__ import annotations

from pathlib import Path

from ..builder import Unavailable
from ..context import Context
from ..inputs import ingest_files
from ..published import read_published

__all__ = ["fixture_files", "fixtures_section"]


def fixture_files(folder: Path) -> list[Path]:
    """Every data file under ``folder`` except ``published/``, docs and the generator.

    ``predict_measure/`` is left out too: that set is one sample for the section
    ``model_measurement``, which reads it itself (its .bsdf is not a specular scan to fit).
    """
    skip_dirs = {"published", "predict_measure", "__pycache__"}
    out = []
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder)
        if not p.is_file() or any(part in skip_dirs or part.startswith(".") for part in rel.parts):
            continue
        if p.suffix.lower() in (".md", ".py", ".txt", ".pyc") or p.name.startswith("."):
            continue
        out.append(p)
    return out


def fixtures_section(ctx: Context) -> None:
    """The validation report's ingest: the published tables, then every fixture file."""
    fx = ctx.fixtures
    if fx is None:
        raise Unavailable("no fixture folder given")
    b = ctx.b
    b.text(
        f"Fixture folder: {fx}. Every file below was read with labbrdf.read (format "
        "from the extension and the header) into the common dataset. The fixtures are "
        "SYNTHETIC files in real export formats, see fixtures/README.md."
    )
    tables, pub = read_published(fx / "published")
    ctx.published.update(tables)
    b.text("Published tables read: " + (", ".join(pub) if pub else "none found") + ".")
    if not fx.is_dir():
        raise Unavailable(f"fixture folder {fx} not found")
    ingest_files(ctx, fixture_files(fx), root=fx)
