"""Property: whatever the layout of inputs and outputs, no CLI writer changes an input or
touches anything outside its output path.

For random choices of writer (ingest -o, fit -o, trace -o, trace --png, report -o,
validate --out), of output (an input, the folder of the inputs, a non-empty folder, an
earlier report, a new path, a new nested path, an existing file, the working folder, a
name ending in '/') and of --overwrite, run the real CLI in a fresh temporary tree and
check: every input file keeps its bytes and mtime; no file outside the output path
appears, disappears or changes; an existing output is replaced only with --overwrite; the
exit code is one of 0-3 and never a traceback. The report builders are replaced by a fast
stand-in that goes through the real writer (write_report), since the property is about
where the writers write, not about the report's content.

Then, enumerated from the parser itself (so that an option added later is covered without
editing this file): for every command, every argument that names an input and every
output option, the output naming that input (or a link to it, or for a report folder the
folder holding it) is refused with exit 2, with and without --overwrite, and the input
keeps its bytes. The same for every file named inside an input (the table a film model
file or a fit JSON names): an output naming it is refused before any work.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import re
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import labbrdf.report
from labbrdf.cli import build_parser, main
from labbrdf.cli._paths import InputPath, OutputPath, path_actions
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


def _argv(writer: str, out: str, inputs: list[str], overwrite: bool = False) -> list[str]:
    trace = ["trace", "--substrate", "1.5+7j", "--alpha", "0.3", "--theta-i", "30"]
    trace += ["--wavelength", "600", "--rays", "500", "--scheduler", "serial", "--json"]
    return (
        {
            "ingest": ["ingest", *inputs, "-o", out, "--json"],
            "fit": ["fit", *inputs, "--model", "smooth3", "--scheduler", "serial", "--json"],
            "trace-o": [*trace, "-o", out],
            "trace-png": [*trace, "--png", out],
            "report": ["report", *inputs, "-o", out],
            "validate": ["validate", "--out", out, "--scheduler", "serial"],
        }[writer]
        + (["-o", out] if writer == "fit" else [])
        + (["--overwrite"] if overwrite else [])
    )


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
    overwrite=st.booleans(),
)
def test_no_writer_touches_inputs_or_anything_outside_its_output(
    fast_reports, writer, kind, n_inputs, overwrite
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
                code = main(_argv(writer, out, inputs, overwrite))
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
        if writer not in ("trace-o", "trace-png") or not overwrite:
            refused.add("link_to_input")  # trace has no inputs: with --overwrite, replaced
        if writer in SUFFIX:
            refused.add("trailing_slash")  # a folder name for a file output
            if not overwrite:
                refused.add("existing_file")
        else:
            refused.add("existing_file")  # a file where a report folder should go
            if not overwrite:
                refused.add("prev_report")
        if kind in refused:
            assert code == 2, (writer, kind, err.getvalue())
            assert after == before


# --------------------------------------------------------------------------- every input option


#: values for the required options that are neither inputs nor outputs, by destination;
#: a command that gains a required option fails here until it is given a value
FILLER = {"model": "smooth3", "theta_i": "30", "wavelength": "600"}


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def _input_output_pairs() -> list[tuple[str, str, str]]:
    pairs = []
    for name, sp in _subparsers().items():
        acts = path_actions(sp)
        for i in (a for a in acts if isinstance(a, InputPath)):
            for o in (a for a in acts if isinstance(a, OutputPath)):
                pairs.append((name, i.dest, o.dest))
    return pairs


PAIRS = _input_output_pairs()


def test_the_parser_declares_every_input_option_of_every_writer():
    # the options through which the tester destroyed inputs, and their neighbours
    for pair in [
        ("trace", "surface", "output"),
        ("trace", "nk_from", "png"),
        ("trace", "coating_surface", "output"),
        ("trace", "tls_key", "png"),
        ("fit", "nk_from", "output"),
        ("export", "trace", "output"),
        ("export", "nk_from", "output"),
        ("ingest", "files", "output"),
        ("surface", "file", "png"),
        ("report", "files", "output"),
        ("validate", "tls_ca", "out"),
    ]:
        assert pair in PAIRS


PATHLIKE_METAVAR = re.compile(r"FILE|PEM|DATA|DIR|PATH|\.[A-Za-z0-9]+$")
PATHLIKE_HELP = re.compile(r"^write |\bfile\b|\(\.[a-z0-9]+\)|height map|folder")
PATHLIKE_DEST = re.compile(r"^(output|out|png|file|files|path)$|_(file|path|from|surface|dir)$")


#: options whose help speaks of files but whose value is not a path (a list of column
#: names, a length, a unit, a sigma per quantity)
NOT_PATHS = {
    ("ingest", "columns"),
    ("film", "sigma"),
    ("surface", "pixel_size"),
    ("surface", "unit"),
    ("psd", "pixel_size"),
    ("psd", "unit"),
    ("trace", "pixel_size"),
    ("trace", "unit"),
    ("report", "prediction_slopes"),
    # a number or a LO..HI box (the metavar ends in ".HI")
    ("film", "substrate_thickness"),
    ("film", "thickness_spread"),
    ("film", "bandwidth"),
    ("film", "angle_spread"),
}


def test_no_option_that_names_a_file_is_left_undeclared():
    """An argument that looks like a path must be an InputPath or an OutputPath."""
    loose = []
    for name, sp in _subparsers().items():
        for a in sp._actions:
            if isinstance(a, InputPath | OutputPath) or a.nargs == 0:
                continue
            if (name, a.dest) in NOT_PATHS:
                continue
            if (
                PATHLIKE_METAVAR.search(str(a.metavar or ""))
                or PATHLIKE_HELP.search(a.help or "")
                or PATHLIKE_DEST.search(a.dest)
            ):
                loose.append(f"{name} {a.option_strings or a.dest}")
    assert loose == []


def _argv_naming(
    command: str, input_dest: str, input_path: str, output_dest: str, output: str, filler: str
) -> list[str]:
    sp = _subparsers()[command]
    argv = [command]
    for a in sp._actions:
        if a.dest in ("help",):
            continue
        if a.dest == input_dest:
            value = [input_path]
        elif a.dest == output_dest:
            value = [output]
        elif not a.required:
            continue
        elif isinstance(a, InputPath) and a.inside:  # a file that names the filler
            fill_dir = Path(filler).parent / f"fill-{a.dest}"
            fill_dir.mkdir(exist_ok=True)
            value = [str(_naming_file(a.inside, fill_dir, Path(filler)))]
        elif isinstance(a, InputPath):
            value = [filler]
        else:
            assert a.dest in FILLER, f"{command}: give the required {a.dest} a value in FILLER"
            value = [FILLER[a.dest]]
        argv += [*a.option_strings[:1], *value]
    return argv


@pytest.mark.parametrize("overwrite", [False, True], ids=["plain", "overwrite"])
@pytest.mark.parametrize("link", [False, True], ids=["same", "link"])
@pytest.mark.parametrize(("command", "input_dest", "output_dest"), PAIRS, ids=str)
def test_no_output_may_name_an_input_whichever_option_names_it(
    tmp_path, capsys, command, input_dest, output_dest, link, overwrite
):
    sp = _subparsers()[command]
    out_action = next(a for a in path_actions(sp) if a.dest == output_dest)
    assert isinstance(out_action, OutputPath)
    filler = tmp_path / "other.dat"
    filler.write_bytes(b"another input")
    if out_action.kind == "dir":
        folder = tmp_path / "rep"
        folder.mkdir()
        src = folder / "input.dat"
        out = tmp_path / "link" if link else folder
        if link:
            out.symlink_to(folder, target_is_directory=True)
    else:
        suffix = out_action.suffixes[0] if out_action.suffixes else ".dat"
        src = tmp_path / f"input{suffix}"
        out = tmp_path / f"link{suffix}" if link else src
        if link:
            out.symlink_to(src)
    src.write_bytes(b"the user's only copy\x00" * 1000)
    before = (src.read_bytes(), src.stat().st_mtime_ns)
    argv = _argv_naming(command, input_dest, str(src), output_dest, str(out), str(filler))
    if overwrite:
        argv.append("--overwrite")
    assert main(argv) == 2, argv
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert "input" in err and str(out) in err, err
    assert (src.read_bytes(), src.stat().st_mtime_ns) == before
    assert sorted(p.name for p in src.parent.iterdir() if p.name.startswith(".")) == []


# ------------------------------------------------------------ files named inside an input

TABLE = "300,1.5,3.0\n1200,2.0,4.0\n"


def _naming_file(kind: str, folder: Path, table: Path) -> Path:
    """A film model file (``kind="model"``), fit JSON (``"fit"``) or map listing (``"map"``)
    naming ``table``."""
    if kind == "map":
        p = folder / "map.csv"
        p.write_text(f"file,x,y\n{table},0,0\n")
        return p
    if kind == "model":
        p = folder / "model.toml"
        p.write_text(
            f'[substrate]\nfile = "{table}"\n\n[[layer]]\nmaterial = "sio2"\nthickness_nm = 10\n'
        )
        return p
    p = folder / "fit.json"
    coat = {"model": "cauchy", "A": 1.5, "B": 0.004, "C": 0.0}
    stack = {
        "ambient": {"model": "constant", "n": 1.0, "k": 0.0},
        "layers": [{"name": "coat", "thickness_nm": 100.0, "material": coat}],
        "substrate": {"model": "tabulated", "file": str(table)},
    }
    p.write_text(json.dumps({"stack": stack, "wavelength_range_nm": [400.0, 800.0]}))
    return p


def _inside_pairs() -> list[tuple[str, str, str]]:
    pairs = []
    for name, sp in _subparsers().items():
        acts = path_actions(sp)
        for i in (a for a in acts if isinstance(a, InputPath) and a.inside):
            for o in (a for a in acts if isinstance(a, OutputPath)):
                pairs.append((name, i.dest, o.dest))
    return pairs


INSIDE_PAIRS = _inside_pairs()


def test_the_options_whose_files_name_files_are_declared():
    for pair in [
        ("film", "model", "output"),
        ("film", "model", "fit_json"),
        ("trace", "coating_from", "output"),
        ("trace", "coating_from", "png"),
        ("report", "film_model", "output"),
        ("film-map", "listing", "output"),
        ("film-map", "listing", "png"),
    ]:
        assert pair in INSIDE_PAIRS


@pytest.mark.parametrize("overwrite", [False, True], ids=["plain", "overwrite"])
@pytest.mark.parametrize("link", [False, True], ids=["same", "link"])
@pytest.mark.parametrize(("command", "input_dest", "output_dest"), INSIDE_PAIRS, ids=str)
def test_no_output_may_name_a_file_that_an_input_names(
    tmp_path, capsys, command, input_dest, output_dest, link, overwrite
):
    """A table named inside a model file or fit JSON is an input: never an output."""
    sp = _subparsers()[command]
    in_action = next(a for a in path_actions(sp) if a.dest == input_dest)
    out_action = next(a for a in path_actions(sp) if a.dest == output_dest)
    filler = tmp_path / "other.dat"
    filler.write_bytes(b"another input")
    if out_action.kind == "dir":
        folder = tmp_path / "rep"
        folder.mkdir()
        table = folder / "table.csv"
        out = tmp_path / "link" if link else folder
        if link:
            out.symlink_to(folder, target_is_directory=True)
    else:
        suffix = out_action.suffixes[0] if out_action.suffixes else ".dat"
        table = tmp_path / f"table{suffix}"
        out = tmp_path / f"link{suffix}" if link else table
        if link:
            out.symlink_to(table)
    table.write_text(TABLE)
    before = (table.read_bytes(), table.stat().st_mtime_ns)
    naming = _naming_file(in_action.inside, tmp_path, table)
    argv = _argv_naming(command, input_dest, str(naming), output_dest, str(out), str(filler))
    if overwrite:
        argv.append("--overwrite")
    assert main(argv) == 2, argv
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert "input" in err and str(out) in err, err
    assert (table.read_bytes(), table.stat().st_mtime_ns) == before
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
