"""The CLI's writers never lose a user's file; every output error is a message and exit 2.

Exit codes: 0 success, 1 a report check failed, 2 usage/input/output error, 3 ``fit``:
some groups failed.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import stat
from pathlib import Path

import numpy as np
import pytest

from labbrdf.cli import main
from labbrdf.dataset import Measurement, make_frame, write

SCAN = (
    Path(__file__).resolve().parents[1]
    / "labbrdf"
    / "data"
    / "fixtures"
    / "specular"
    / "osr_specular.csv"
)
TRACE = [
    "trace",
    "--substrate",
    "1.55+7.71j",
    "--alpha",
    "0.2",
    "--theta-i",
    "45",
    "--wavelength",
    "650",
    "--rays",
    "2000",
    "--scheduler",
    "serial",
    "--single-scattering",
]


def snapshot(root: Path) -> dict[str, tuple[bytes, int]]:
    """Every file under ``root``: bytes and mtime."""
    return {
        str(p.relative_to(root)): (p.read_bytes(), p.stat().st_mtime_ns)
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def small_dataset(path: Path, sample: str = "S", n: int = 7) -> Path:
    th = np.linspace(40.0, 50.0, n)
    y = np.exp(-(((th - 45.0) / 2.0) ** 2)) + 0.01
    m = Measurement(
        make_frame(
            sample=sample,
            instrument="synthetic",
            source="t",
            quantity="brdf",
            value=y,
            sigma=0.01 * y,
            unit="sr-1",
            wavelength_nm=500.0,
            theta_i_deg=45.0,
            theta_r_deg=th,
            phi_r_deg=180.0,
        )
    )
    write(m, path)
    return path


def expect_refused(capsys, argv: list[str], *words: str) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    for w in words:
        assert w in err, err
    return err


# --------------------------------------------------------------------------- data loss


def test_report_refuses_a_folder_holding_the_input_and_user_files(tmp_path, capsys):
    p = tmp_path / "p"
    p.mkdir()
    shutil.copy(SCAN, p / "scan.csv")
    (p / "notes.txt").write_text("x")
    before = snapshot(tmp_path)
    expect_refused(capsys, ["report", str(p / "scan.csv"), "-o", str(p)], str(p), "input")
    assert snapshot(tmp_path) == before


def test_report_refuses_an_input_file_as_output(tmp_path, capsys):
    scan = tmp_path / "scan.csv"
    shutil.copy(SCAN, scan)
    before = snapshot(tmp_path)
    expect_refused(capsys, ["report", str(scan), "-o", str(scan)], "existing file")
    assert snapshot(tmp_path) == before and scan.is_file()


def test_report_refuses_the_current_folder(tmp_path, capsys, monkeypatch):
    shutil.copy(SCAN, tmp_path / "scan.csv")
    (tmp_path / "notes.txt").write_text("x")
    monkeypatch.chdir(tmp_path)
    before = snapshot(tmp_path)
    expect_refused(capsys, ["report", "scan.csv", "-o", "."], "-o .")
    assert snapshot(tmp_path) == before


def test_report_refuses_a_non_empty_folder_and_replaces_an_earlier_report_on_request(
    tmp_path, capsys
):
    bad = tmp_path / "bad.xyz"  # unreadable: a failed check, but a quick report
    bad.write_text("x\n")
    out = tmp_path / "rep"
    out.mkdir()
    (out / "mine.txt").write_text("mine")
    expect_refused(capsys, ["report", str(bad), "-o", str(out)], "not empty")
    assert (out / "mine.txt").read_text() == "mine"
    (out / "mine.txt").unlink()
    assert main(["report", str(bad), "-o", str(out)]) == 1
    first = snapshot(out)
    expect_refused(capsys, ["report", str(bad), "-o", str(out)], "earlier", "--overwrite")
    assert snapshot(out) == first
    assert main(["report", str(bad), "-o", str(out), "--overwrite"]) == 1  # replaced
    assert (out / ".labbrdf-report").is_file()
    (out / "tables" / "extra.xlsx").write_text("mine")
    argv = ["report", str(bad), "-o", str(out), "--overwrite"]
    expect_refused(capsys, argv, "tables/extra.xlsx")
    assert (out / "tables" / "extra.xlsx").read_text() == "mine"


def test_validate_refuses_a_non_empty_folder_before_running(tmp_path, capsys):
    out = tmp_path / "v"
    out.mkdir()
    (out / "thesis.tex").write_text("x")
    before = snapshot(tmp_path)
    expect_refused(capsys, ["validate", "--out", str(out), "--quick"], "--out", "not empty")
    assert snapshot(tmp_path) == before


def test_fit_refuses_to_overwrite_its_input(tmp_path, capsys):
    scan = tmp_path / "scan.csv"
    shutil.copy(SCAN, scan)
    before = snapshot(tmp_path)
    argv = ["fit", str(scan), "--model", "smooth3", "--scheduler", "serial", "-o", str(scan)]
    expect_refused(capsys, argv, "one of the input files")
    assert snapshot(tmp_path) == before


# --------------------------------------------------------------------------- error handling


def test_ingest_dev_zero_is_refused_not_read_forever(capsys):
    expect_refused(
        capsys, ["ingest", "/dev/zero", "--format", "woollam-wvase"], "/dev/zero", "regular file"
    )


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["-o", "{d}"], ["existing folder"]),
        (["-o", "{d}/out.txt"], ["out.txt", ".npz"]),
        (["-o", "{d}/name.npz/"], ["ends with '/'"]),
        (["--png", "{d}/maps.jpg"], ["--png", ".png"]),
        (["--png", "{d}"], ["--png", "existing folder"]),
    ],
)
def test_trace_output_names_are_checked_before_tracing(tmp_path, capsys, argv, words):
    argv = [a.format(d=tmp_path) for a in argv]
    expect_refused(capsys, [*TRACE, *argv], *words)
    assert list(tmp_path.iterdir()) == []


def test_ingest_and_fit_refuse_a_folder_or_a_trailing_slash(tmp_path, capsys):
    data = small_dataset(tmp_path / "d.csv")
    before = sorted(p.name for p in tmp_path.iterdir())  # the dataset and its sidecar
    expect_refused(capsys, ["ingest", str(data), "-o", str(tmp_path)], "existing folder")
    expect_refused(
        capsys, ["ingest", str(data), "-o", str(tmp_path / "x.parquet") + "/"], "ends with '/'"
    )
    fit = ["fit", str(data), "--model", "smooth3", "--scheduler", "serial"]
    expect_refused(capsys, [*fit, "-o", str(tmp_path)], "existing folder")
    expect_refused(capsys, [*fit, "-o", str(tmp_path / "p.txt")], ".csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == before == ["d.csv", "d.meta.json"]


def _deny_writes(monkeypatch):
    from labbrdf import outputs

    def mkstemp(*a, dir=None, **k):
        raise PermissionError(13, "Permission denied", str(dir))

    def mkdtemp(*a, dir=None, **k):
        raise PermissionError(13, "Permission denied", str(dir))

    monkeypatch.setattr(outputs.tempfile, "mkstemp", mkstemp)
    monkeypatch.setattr(outputs.tempfile, "mkdtemp", mkdtemp)


def test_unwritable_output_folder_is_a_message_and_exit_2(tmp_path, capsys, monkeypatch):
    data = small_dataset(tmp_path / "d.csv")
    ro = tmp_path / "ro"
    ro.mkdir()
    _deny_writes(monkeypatch)
    fit = ["fit", str(data), "--model", "smooth3", "--scheduler", "serial"]
    expect_refused(capsys, [*fit, "-o", str(ro / "p.csv")], str(ro / "p.csv"), "writ")
    expect_refused(capsys, ["ingest", str(data), "-o", str(ro / "x.csv")], "x.csv", "writ")
    expect_refused(capsys, [*TRACE, "-o", str(ro / "t.npz")], "t.npz", "writ")
    expect_refused(capsys, [*TRACE, "--png", str(ro / "t.png")], "t.png", "writ")
    bad = tmp_path / "bad.xyz"
    bad.write_text("x\n")
    expect_refused(capsys, ["report", str(bad), "-o", str(ro / "rep")], "rep", "writ")


@pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv"), reason="needs root")
def test_read_only_folder_for_another_user():
    """As user nobody (root runs the tests here, and root may write anywhere): a folder
    nobody may write into is refused before any work, with a message and exit 2."""
    import subprocess
    import sys
    import tempfile

    base = Path(tempfile.mkdtemp(prefix="labbrdf-ro-", dir="/tmp"))
    try:
        base.chmod(0o755)  # readable by nobody (pytest's tmp_path is not)
        ro = base / "ro"
        ro.mkdir()
        ro.chmod(0o755)  # owned by root: read-only for nobody
        data = small_dataset(base / "d.csv")
        data.chmod(0o644)
        code = "import sys; from labbrdf.cli import main; sys.exit(main(sys.argv[1:]))"
        nobody = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", sys.executable]
        env = {
            **os.environ,
            "PYTHONPATH": str(Path(__file__).resolve().parents[1]),
            "MPLCONFIGDIR": str(base / "mpl"),
            "HOME": str(base),
        }
        (base / "mpl").mkdir(mode=0o777)
        (base / "mpl").chmod(0o777)
        probe = [*nobody, "-c", f"import labbrdf.cli; open({str(data)!r}).read()"]
        if subprocess.run(probe, capture_output=True, env=env, cwd="/", timeout=120).returncode:
            pytest.skip("the interpreter or labbrdf is not usable by user nobody")

        def run(*argv: str) -> subprocess.CompletedProcess:
            return subprocess.run(
                [*nobody, "-c", code, *argv],
                capture_output=True,
                text=True,
                env=env,
                cwd="/",
                timeout=120,
            )

        r = run("ingest", str(data), "-o", str(ro / "x.csv"))
        assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
        assert "x.csv" in r.stderr and "not writable" in r.stderr, r.stderr
        # a report is refused before its fits run, not after
        r = run("report", str(data), "-o", str(ro / "rep"))
        assert r.returncode == 2, r.stderr
        assert "not writable" in r.stderr and "section" not in r.stderr, r.stderr
        assert list(ro.iterdir()) == []
    finally:
        shutil.rmtree(base, ignore_errors=True)


# --------------------------------------------------------------------------- writers' content


def test_trace_writes_the_named_npz_with_umask_permissions(tmp_path, capsys):
    old = os.umask(0o027)
    try:
        assert main([*TRACE, "-o", str(tmp_path / "t.npz"), "--png", str(tmp_path / "m.png")]) == 0
    finally:
        os.umask(old)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.png", "t.npz"]
    for name in ("m.png", "t.npz"):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o640, name
    assert np.load(tmp_path / "t.npz")["mueller"].ndim == 4


def test_fit_parameter_table_neutralises_formula_sample_names(tmp_path, capsys):
    data = small_dataset(tmp_path / "d.csv", sample='=HYPERLINK("http://evil","x")')
    out = tmp_path / "p.csv"
    code = main(["fit", str(data), "--model", "smooth3", "--scheduler", "serial", "-o", str(out)])
    assert code in (0, 3)
    rows = list(csv.DictReader(out.open()))
    assert rows[0]["sample"] == '\'=HYPERLINK("http://evil","x")'


def test_fit_lists_failed_groups_and_exits_3(tmp_path, capsys):
    one = small_dataset(tmp_path / "one.csv", n=1)
    assert main(["fit", str(one), "--model", "smooth3", "--scheduler", "serial", "--json"]) == 3
    cap = capsys.readouterr()
    groups = json.loads(cap.out)
    assert len(groups) == 1
    assert groups[0]["success"] is False
    assert groups[0]["group"] == {"sample": "S", "wavelength_nm": 500.0}
    assert "not fitted" in groups[0]["message"]
    assert "FAILED" in cap.err
