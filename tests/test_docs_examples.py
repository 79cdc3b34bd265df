"""Every ```python example of README.md and docs/*.md runs as written.

The blocks of one page run in order in one namespace (later blocks use the names of earlier
ones), in a scratch folder where the file names the examples use are the shipped fixtures
or the shared real exports (``EXAMPLE_FILES``). A line ``<!-- example: shared -->`` just
above a block marks a block that reads the shared exports (skipped where they are absent,
with the rest of its page); ``<!-- example: skip REASON -->`` marks a block that is not a
program (a new module's skeleton, a cluster address) and says why. To keep the suite fast
the examples' ray counts (``rays=200_000``) run with 2,000 rays: the calls are checked, not
the Monte Carlo noise.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FIXTURES = ROOT / "labbrdf" / "data" / "fixtures"

#: file name in the examples -> (shared export under real-exports/ or None, fixture or None)
EXAMPLE_FILES = {
    "w2_10102006.dat": ("woollam-wvase-ascii/w2_10102006.dat", None),
    "afm.di": ("topography/di-1.di", None),
    "metropro-1.dat": ("topography/metropro-1.dat", None),
    "sphere.bsdf": ("zemax-bsdf/test_13_planesymmetric_brdf_zemax.bsdf", None),
    "BrownVinyl.bsdf": ("zemax-bsdf/test_13_planesymmetric_brdf_zemax.bsdf", None),
    "scan.csv": (None, "specular/osr_specular.csv"),
}

_FENCE = re.compile(r"(?:<!-- example: (?P<mark>[^>]*?) -->\n)?```python\n(?P<code>.*?)```", re.S)


def _blocks(page: Path) -> list[tuple[str, str]]:
    """(mark, code) of every python block of a page; mark "" when unmarked."""
    return [(m["mark"] or "", m["code"]) for m in _FENCE.finditer(page.read_text("utf-8"))]


def _workdir(tmp: Path, shared: Path | None) -> None:
    """The scratch folder: the fixtures under labbrdf/data, the example file names, fit.json."""
    (tmp / "labbrdf").mkdir()
    (tmp / "labbrdf" / "data").symlink_to(ROOT / "labbrdf" / "data")
    for name, (real, fixture) in EXAMPLE_FILES.items():
        src = FIXTURES / fixture if fixture else (shared / real if shared else None)
        if src is not None and src.exists():
            (tmp / name).symlink_to(src)
    from labbrdf.films import Layer, Stack
    from labbrdf.nk.dispersion import Cauchy

    stack = Stack([Layer(Cauchy(A=1.5, B=0.004), 300.0, "varnish")], "si")
    doc = {"kind": "labbrdf film fit", "stack": stack.to_dict(),
           "wavelength_range_nm": [400.0, 800.0]}  # fmt: skip
    (tmp / "fit.json").write_text(json.dumps(doc))


def _shared() -> Path | None:
    d = Path(os.environ.get("LABBRDF_SHARED", ROOT.parent / "shared")) / "real-exports"
    return d if d.is_dir() else None


def test_every_block_is_found_and_marks_are_known() -> None:
    marks = [m for p in PAGES for m, _ in _blocks(p)]
    assert len(marks) >= 10
    assert all(m in ("", "shared") or m.startswith("skip ") for m in marks), marks


#: pages whose examples take seconds: topography.md's roughness_statistics with its
#: block intervals (about 20 s on a 640 x 480 map on a loaded core)
SLOW_PAGES = {"topography.md"}


@pytest.mark.parametrize(
    "page",
    [
        pytest.param(p, marks=[pytest.mark.slow] if p.name in SLOW_PAGES else [])
        for p in PAGES
        if _blocks(p)
    ],
    ids=lambda p: p.name,
)
def test_examples_run(page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shared = _shared()
    _workdir(tmp_path, shared)
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": f"example_{page.stem}"}
    try:
        for i, (mark, code) in enumerate(_blocks(page)):
            if mark.startswith("skip "):
                continue
            if mark == "shared" and shared is None:
                pytest.skip(f"{page.name} block {i + 1}: needs ../shared (real exports)")
            code = code.replace("rays=200_000", "rays=2_000")
            try:
                exec(compile(code, f"{page.name} block {i + 1}", "exec"), namespace)
            except Exception as exc:  # the page and block in the failure
                pytest.fail(f"{page.name} block {i + 1} ({mark or 'fixtures'}): {exc!r}")
    finally:
        plt.close("all")


def test_the_tutorials_ingest_table_is_what_ingest_prints(capsys, monkeypatch) -> None:
    """The tutorial's shown output of `labbrdf ingest` is the command's, column for column."""
    from labbrdf.cli import main

    text = (ROOT / "docs" / "tutorial.md").read_text("utf-8")
    shown = re.search(r"```text\n(file .*?)```", text, re.S)
    assert shown is not None
    monkeypatch.chdir(FIXTURES)
    files = ["specular/osr_specular.csv", "ellipsometry/al_bare_wvase.dat",
             "spectrophotometer/osr_sphere_cary.csv"]  # fmt: skip
    assert main(["ingest", *files]) == 0
    printed = [ln.rstrip() for ln in capsys.readouterr().out.splitlines() if ln.strip()]
    assert printed == [ln.rstrip() for ln in shown.group(1).splitlines() if ln.strip()]
    assert "one JSON array with an object per file" in text
