"""Property: whatever the layout of inputs and outputs, no CLI writer changes an input or
touches anything outside its output path.

For random choices of writer (ingest -o, fit -o, trace -o, trace --png, report -o,
validate --out) and of output (an input, the folder of the inputs, a non-empty folder, an
earlier report, a new path, a new nested path, an existing file, the working folder, a
name ending in '/'), run the real CLI in a fresh temporary tree and check: every input
file keeps its bytes and mtime; no file outside the output path appears, disappears or
changes; the exit code is one of 0-3 and never a traceback. The report builders are
replaced by a fast stand-in that goes through the real writer (write_report), since the
property is about where the writers write, not about the report's content.
"""

from __future__ import annotations

import contextlib
import io
import os
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import labbrdf.report
from labbrdf.cli import main
from labbrdf.dataset import Measurement, make_frame, write
from labbrdf.outputs import replace_dir
from labbrdf.report.builder import write_report

WRITERS = ["ingest", "fit", "trace-o", "trace-png", "report", "validate"]
OUTPUTS = [
    "input",
    "inputs_folder",
    "nonempty_dir",
    "prev_report",
    "new",
    "new_nested",
    "existing_file",
    "cwd",
    "trailing_slash",
    "link_to_input",
    "link_to_folder",
]
SUFFIX = {"ingest": ".parquet", "fit": ".csv", "trace-o": ".npz", "trace-png": ".png"}


def _fake_report(paths, model, out, **kw):
    results = {"title": "t", "tables": {}, "checks": [], "summary": {}}
    write_report(out, results, "<html/>", inputs=[Path(p) for p in paths])
    return 0


def _fake_validate(out="reports/validation", **kw):
    write_report(out, {"title": "v", "tables": {}, "checks": []}, "<html/>")
    return 0


def _dataset(path: Path, sample: str) -> None:
    th = np.linspace(40.0, 50.0, 7)
    y = np.exp(-(((th - 45.0) / 2.0) ** 2)) + 0.01
    write(
        Measurement(
            make_frame(
                sample=sample,
                instrument="synthetic",
                source=path.name,
                quantity="brdf",
                value=y,
                sigma=0.01 * y,
                unit="sr-1",
                wavelength_nm=500.0,
                theta_i_deg=45.0,
                theta_r_deg=th,
                phi_r_deg=180.0,
            )
        ),
        path,
    )


def _tree(root: Path) -> dict[str, Path]:
    data = root / "data"
    data.mkdir()
    _dataset(data / "a.csv", "A")
    _dataset(data / "b.csv", "B")
    (data / "notes.txt").write_text("my notes\n")
    other = root / "other"
    other.mkdir()
    (other / "thesis.tex").write_text("\\section{x}\n")
    replace_dir(root / "prev", lambda d: (d / "index.html").write_text("<html/>"))
    for suffix in (".parquet", ".csv", ".npz", ".png", ""):
        (root / f"existing{suffix or '_file'}").write_text("user file\n")
        (root / f"link{suffix or '_file'}").symlink_to(data / "a.csv")
    (root / "link_dir").symlink_to(data, target_is_directory=True)
    return {"data": data, "other": other}


def _snapshot(root: Path) -> dict[str, tuple[bytes, int]]:
    out = {}
    for dirpath, _, names in os.walk(root):
        for n in names:
            p = Path(dirpath) / n
            if p.is_symlink():
                out[p.relative_to(root).as_posix()] = (os.readlink(p).encode(), 0)
            else:
                out[p.relative_to(root).as_posix()] = (p.read_bytes(), p.stat().st_mtime_ns)
    return out


def _output(kind: str, writer: str, root: Path, d: dict[str, Path]) -> str:
    suffix = SUFFIX.get(writer, "")
    return {
        "input": str(d["data"] / "a.csv"),
        "inputs_folder": str(d["data"]),
        "nonempty_dir": str(d["other"]),
        "prev_report": str(root / "prev"),
        "new": str(root / f"out{suffix}"),
        "new_nested": str(root / "new" / "deeper" / f"out{suffix}"),
        "existing_file": str(root / f"existing{suffix or '_file'}"),
        "cwd": ".",
        "trailing_slash": str(root / f"slash{suffix}") + "/",
        "link_to_input": str(root / f"link{suffix or '_file'}"),
        "link_to_folder": str(root / "link_dir"),
    }[kind]


def _argv(writer: str, out: str, inputs: list[str]) -> list[str]:
    trace = ["trace", "--substrate", "1.5+7j", "--alpha", "0.3", "--theta-i", "30"]
    trace += ["--wavelength", "600", "--rays", "500", "--scheduler", "serial", "--json"]
    return {
        "ingest": ["ingest", *inputs, "-o", out, "--json"],
        "fit": ["fit", *inputs, "--model", "smooth3", "--scheduler", "serial", "--json"],
        "trace-o": [*trace, "-o", out],
        "trace-png": [*trace, "--png", out],
        "report": ["report", *inputs, "-o", out],
        "validate": ["validate", "--out", out, "--scheduler", "serial"],
    }[writer] + (["-o", out] if writer == "fit" else [])


def _under(rel: str, out: Path, root: Path) -> bool:
    p = (root / rel).resolve()
    return p == out or out in p.parents


@pytest.fixture
def fast_reports(monkeypatch):
    monkeypatch.setattr(labbrdf.report, "user_report", _fake_report)
    monkeypatch.setattr(labbrdf.report, "validate", _fake_validate)


@pytest.mark.slow
@settings(
    max_examples=int(os.environ.get("LABBRDF_PROPERTY_EXAMPLES", "30")),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
    derandomize=True,
)
@given(
    writer=st.sampled_from(WRITERS),
    kind=st.sampled_from(OUTPUTS),
    n_inputs=st.integers(1, 2),
)
def test_no_writer_touches_inputs_or_anything_outside_its_output(
    fast_reports, writer, kind, n_inputs
):
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp).resolve()
        d = _tree(root)
        inputs = [str(d["data"] / "a.csv"), str(d["data"] / "b.csv")][:n_inputs]
        out = _output(kind, writer, root, d)
        cwd = d["data"] if kind == "cwd" else root
        before = _snapshot(root)
        err = io.StringIO()
        old = os.getcwd()
        os.chdir(cwd)
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                code = main(_argv(writer, out, inputs))
        finally:
            os.chdir(old)
        after = _snapshot(root)
        assert code in (0, 1, 2, 3), err.getvalue()
        assert "Traceback" not in err.getvalue()
        target = (cwd / out.rstrip("/")).resolve()
        for f in inputs:
            rel = Path(f).relative_to(root).as_posix()
            assert after.get(rel) == before[rel], f"{writer} -> {kind}: input {rel} changed"
        outside_before = {k: v for k, v in before.items() if not _under(k, target, root)}
        outside_after = {k: v for k, v in after.items() if not _under(k, target, root)}
        assert outside_after == outside_before, (writer, kind, code, err.getvalue())
        refused = {"input", "inputs_folder", "nonempty_dir", "cwd", "link_to_folder"}
        if writer not in ("trace-o", "trace-png"):
            refused.add("link_to_input")  # trace has no inputs: the link is just replaced
        if writer in SUFFIX:
            refused.add("trailing_slash")  # a folder name for a file output
        else:
            refused.add("existing_file")  # a file where a report folder should go
        if kind in refused:
            assert code == 2, (writer, kind, err.getvalue())
            assert after == before
