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


@pytest.fixture
def trace_cmd(trace_argv: list[str]) -> list[str]:
    """The small shared trace, single scattering (its outputs are what is checked)."""
    return [*trace_argv, "--single-scattering"]


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


def test_report_refuses_a_folder_holding_the_input_and_user_files(tmp_path, capsys, specular_scan):
    p = tmp_path / "p"
    p.mkdir()
    shutil.copy(specular_scan, p / "scan.csv")
    (p / "notes.txt").write_text("x")
    before = snapshot(tmp_path)
    expect_refused(capsys, ["report", str(p / "scan.csv"), "-o", str(p)], str(p), "input")
    assert snapshot(tmp_path) == before


def test_report_refuses_an_input_file_as_output(tmp_path, capsys, specular_scan):
    scan = tmp_path / "scan.csv"
    shutil.copy(specular_scan, scan)
    before = snapshot(tmp_path)
    expect_refused(capsys, ["report", str(scan), "-o", str(scan)], "existing file")
    assert snapshot(tmp_path) == before and scan.is_file()


def test_report_refuses_the_current_folder(tmp_path, capsys, monkeypatch, specular_scan):
    shutil.copy(specular_scan, tmp_path / "scan.csv")
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


def test_fit_refuses_to_overwrite_its_input(tmp_path, capsys, specular_scan):
    scan = tmp_path / "scan.csv"
    shutil.copy(specular_scan, scan)
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
def test_trace_output_names_are_checked_before_tracing(tmp_path, capsys, argv, words, trace_cmd):
    argv = [a.format(d=tmp_path) for a in argv]
    expect_refused(capsys, [*trace_cmd, *argv], *words)
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

    monkeypatch.setattr(outputs.files.tempfile, "mkstemp", mkstemp)
    monkeypatch.setattr(outputs.files.tempfile, "mkdtemp", mkdtemp)


def test_unwritable_output_folder_is_a_message_and_exit_2(
    tmp_path, capsys, monkeypatch, trace_cmd
):
    data = small_dataset(tmp_path / "d.csv")
    ro = tmp_path / "ro"
    ro.mkdir()
    _deny_writes(monkeypatch)
    fit = ["fit", str(data), "--model", "smooth3", "--scheduler", "serial"]
    expect_refused(capsys, [*fit, "-o", str(ro / "p.csv")], str(ro / "p.csv"), "writ")
    expect_refused(capsys, ["ingest", str(data), "-o", str(ro / "x.csv")], "x.csv", "writ")
    expect_refused(capsys, [*trace_cmd, "-o", str(ro / "t.npz")], "t.npz", "writ")
    expect_refused(capsys, [*trace_cmd, "--png", str(ro / "t.png")], "t.png", "writ")
    bad = tmp_path / "bad.xyz"
    bad.write_text("x\n")
    expect_refused(capsys, ["report", str(bad), "-o", str(ro / "rep")], "rep", "writ")


@pytest.mark.skipif(os.geteuid() != 0 or not shutil.which("setpriv"), reason="needs root")
def test_read_only_folder_for_another_user(project_root):
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
            "PYTHONPATH": str(project_root),
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


def test_trace_writes_the_named_npz_with_umask_permissions(tmp_path, capsys, trace_cmd):
    old = os.umask(0o027)
    try:
        assert (
            main([*trace_cmd, "-o", str(tmp_path / "t.npz"), "--png", str(tmp_path / "m.png")])
            == 0
        )
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


# ------------------------------------------------------------------ one rule, every writer


def _fake_height_map(path, channel, args=None):
    from labbrdf.adapters.topography import HeightMap

    rng = np.random.default_rng(3)
    z = rng.normal(size=(64, 64))
    z = (z + np.roll(z, 1, 0) + np.roll(z, 1, 1) + np.roll(z, 1, (0, 1))) * 1e-9
    return HeightMap(heights=z, pixel_size=(1e-7, 1e-7), path=str(path), channel="height")


def _fake_validate(out="reports/validation", **kw):
    from labbrdf.report.builder import write_report

    write_report(out, {"title": "v", "tables": {}, "checks": []}, "<html/>")
    return 0


@pytest.fixture
def writers(tmp_path, monkeypatch, fixtures_dir, trace_cmd):
    """Each writer command: its argv without the output, its output option and suffix.

    ``surface`` reads a synthetic height map (the readers are tested elsewhere) and
    ``validate`` is a stand-in that goes through the real report writer.
    """
    import labbrdf.cli.surface
    import labbrdf.report

    monkeypatch.setattr(labbrdf.cli.surface, "_height_map", _fake_height_map)
    monkeypatch.setattr(labbrdf.report, "validate", _fake_validate)
    data = small_dataset(tmp_path / "in" / "scan.csv")
    hm = tmp_path / "in" / "afm.di"
    hm.write_bytes(b"height map")
    bad = tmp_path / "in" / "bad.xyz"
    bad.write_text("x\n")
    return {
        "ingest-parquet": (["ingest", str(data)], "-o", ".parquet"),
        "ingest-csv": (["ingest", str(data)], "-o", ".csv"),
        "fit": (["fit", str(data), "--model", "smooth3", "--scheduler", "serial"], "-o", ".csv"),
        "nk": (["nk", str(fixtures_dir / "ellipsometry" / "al_bare_wvase.dat")], "-o", ".csv"),
        "trace-o": (trace_cmd, "-o", ".npz"),
        "trace-png": (trace_cmd, "--png", ".png"),
        "surface": (["surface", str(hm), "--blocks", "0"], "--png", ".png"),
        "export": (["export", "--model", "smooth3", "--theta-i", "30"], "-o", ".bsdf"),
        "report": (["report", str(bad)], "-o", ""),
        "validate": (["validate", "--scheduler", "serial"], "--out", ""),
    }


WRITERS = [
    "ingest-parquet",
    "ingest-csv",
    "fit",
    "nk",
    "trace-o",
    "trace-png",
    "surface",
    "export",
    "report",
    "validate",
]


def _existing_output(path: Path, suffix: str) -> None:
    if suffix:
        path.write_text("the user's file\n")
    else:
        from labbrdf.outputs import replace_dir

        replace_dir(path, lambda d: (d / "index.html").write_text("an earlier report"))


@pytest.mark.parametrize("writer", WRITERS)
def test_every_writer_replaces_an_existing_output_only_with_overwrite(
    writer, writers, tmp_path, capsys
):
    argv, option, suffix = writers[writer]
    out = tmp_path / "out" / f"result{suffix}"
    out.parent.mkdir()
    _existing_output(out, suffix)
    before = snapshot(tmp_path)
    err = expect_refused(capsys, [*argv, option, str(out)], option, str(out), "--overwrite")
    assert "exists" in err or "earlier labbrdf report" in err
    assert snapshot(tmp_path) == before  # nothing written, not even a temporary file
    assert main([*argv, option, str(out), "--overwrite"]) in (0, 1)
    after = snapshot(tmp_path)
    changed = {k for k in after if before.get(k) != after[k]} | (before.keys() - after.keys())
    assert changed, "--overwrite wrote nothing"
    assert all(k.startswith("out") for k in changed), changed  # only the output changed


def test_ingest_csv_never_replaces_a_metadata_file_it_was_not_named(tmp_path, capsys):
    data = small_dataset(tmp_path / "scan.parquet")
    (tmp_path / "data.meta.json").write_text('{"mine": true}\n')
    before = snapshot(tmp_path)
    out = tmp_path / "data.csv"
    expect_refused(capsys, ["ingest", str(data), "-o", str(out)], "data.meta.json", "--overwrite")
    assert snapshot(tmp_path) == before
    assert main(["ingest", str(data), "-o", str(out), "--overwrite"]) == 0
    assert json.loads((tmp_path / "data.meta.json").read_text()) != {"mine": True}


def test_ingest_csv_refuses_an_input_as_its_metadata_file(tmp_path, capsys):
    data = small_dataset(tmp_path / "scan.csv")  # writes scan.meta.json, read back with it
    meta = tmp_path / "scan.meta.json"
    other = small_dataset(tmp_path / "other.parquet")
    shutil.copy(meta, tmp_path / "x.meta.json")
    before = snapshot(tmp_path)
    argv = ["ingest", str(other), str(tmp_path / "x.meta.json"), "-o", str(tmp_path / "x.csv")]
    expect_refused(capsys, [*argv, "--overwrite"], "x.meta.json", "input")
    assert snapshot(tmp_path) == before
    assert data.exists()


def _full_disk_files(monkeypatch):
    """Every temporary file labbrdf writes goes to /dev/full (ENOSPC on write)."""
    import tempfile

    real = tempfile.mkstemp

    def mkstemp(*a, **kw):
        fd, name = real(*a, **kw)
        if ".labbrdf-tmp-" in os.path.basename(name):
            os.unlink(name)
            os.symlink("/dev/full", name)
        return fd, name

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)


def _full_disk_reports(monkeypatch):
    """Every report folder labbrdf builds has its index.html on /dev/full."""
    import tempfile

    real = tempfile.mkdtemp

    def mkdtemp(*a, **kw):
        name = real(*a, **kw)
        if ".labbrdf-new-" in os.path.basename(name):
            os.symlink("/dev/full", os.path.join(name, "index.html"))
        return name

    monkeypatch.setattr(tempfile, "mkdtemp", mkdtemp)


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (ENOSPC)")
@pytest.mark.parametrize("writer", WRITERS)
def test_a_full_disk_names_the_output_and_the_cause(
    writer, writers, tmp_path, capsys, monkeypatch
):
    argv, option, suffix = writers[writer]
    out = tmp_path / "out" / f"result{suffix}"
    if suffix:
        _full_disk_files(monkeypatch)
    else:
        _full_disk_reports(monkeypatch)
    before = snapshot(tmp_path)
    err = expect_refused(capsys, [*argv, option, str(out)], "No space left on device")
    shown = out.with_name("result.meta.json") if writer == "ingest-csv" else out
    assert f"{shown}:" in err or f"{shown}/index.html:" in err, err  # the path, then the cause
    assert snapshot(tmp_path) == before
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == []  # no leftovers


def test_two_outputs_of_one_command_may_not_be_the_same_file(tmp_path):
    # today every command's outputs differ in suffix; the check is for a later command
    import argparse

    from labbrdf.cli._options import UsageError
    from labbrdf.cli._paths import OutputPath, _checked_outputs

    p = str(tmp_path / "x.png")
    png = OutputPath(["--png"], "png", suffixes=(".png",))
    maps = OutputPath(["--maps"], "maps", suffixes=(".png",))
    args = argparse.Namespace(path_actions=(png, maps), png=p, maps=p)
    with pytest.raises(UsageError, match=r"--maps .*x.png: also given to --png"):
        with _checked_outputs(args):
            pass  # pragma: no cover
    assert not os.path.exists(p)
