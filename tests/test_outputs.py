"""labbrdf.outputs: nothing a user owns is lost by our outputs (library level)."""

from __future__ import annotations

import csv
import errno
import io
import json
import os
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf import outputs
from labbrdf.dataset import Measurement, make_frame, read, write
from labbrdf.outputs import (
    REPORT_MARKER,
    OutputError,
    atomic_output,
    check_file_output,
    check_report_dir,
    clean_leftovers,
    csv_safe_cell,
    replace_dir,
    write_policy,
)
from labbrdf.report import builder


def _report(d: Path) -> None:
    (d / "index.html").write_text("<html></html>")
    (d / "tables").mkdir()
    (d / "tables" / "fits.csv").write_text("a\n1\n")


# --------------------------------------------------------------------------- report folders


def test_report_folder_refuses_a_folder_with_user_files(tmp_path):
    out = tmp_path / "p"
    out.mkdir()
    (out / "scan.csv").write_text("data")
    (out / "notes.txt").write_text("x")
    with pytest.raises(OutputError, match="not empty and not a labbrdf report"):
        replace_dir(out, _report)
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt", "scan.csv"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p"]


def test_report_folder_is_marked_and_an_earlier_report_is_replaced(tmp_path):
    out = tmp_path / "rep"
    replace_dir(out, _report)
    info = json.loads((out / REPORT_MARKER).read_text())
    assert info["labbrdf"] == "report" and info["files"] == ["index.html", "tables/fits.csv"]
    replace_dir(out, lambda d: (d / "index.html").write_text("new"))
    assert (out / "index.html").read_text() == "new"
    assert not (out / "tables").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]


def test_earlier_report_with_a_foreign_file_is_refused_naming_it(tmp_path):
    out = tmp_path / "rep"
    replace_dir(out, _report)
    (out / "tables" / "my_notes.txt").write_text("mine")
    with pytest.raises(OutputError, match=r"tables/my_notes\.txt"):
        replace_dir(out, _report)
    assert (out / "tables" / "my_notes.txt").read_text() == "mine"


def test_report_written_before_the_marker_is_recognised_by_its_layout(tmp_path):
    out = tmp_path / "rep"
    out.mkdir()
    _report(out)
    keys = ["title", "meta", "sections", "tables", "checks", "summary"]
    (out / "results.json").write_text(json.dumps({k: {} for k in keys}))
    replace_dir(out, lambda d: (d / "index.html").write_text("new"))
    assert (out / "index.html").read_text() == "new"
    # the same layout plus a user file is not ours
    (tmp_path / "other").mkdir()
    _report(tmp_path / "other")
    (tmp_path / "other" / "results.json").write_text(json.dumps({k: {} for k in keys}))
    (tmp_path / "other" / "mine.docx").write_text("x")
    with pytest.raises(OutputError, match="mine.docx"):
        replace_dir(tmp_path / "other", _report)


def test_report_folder_refuses_input_inside_equal_file_and_cwd(tmp_path, monkeypatch):
    scan = tmp_path / "p" / "scan.csv"
    scan.parent.mkdir()
    scan.write_text("data")
    with pytest.raises(OutputError, match="contains the input"):
        check_report_dir(tmp_path / "p", inputs=[scan])
    with pytest.raises(OutputError, match="existing file"):
        check_report_dir(scan, inputs=[scan])
    with pytest.raises(OutputError, match="inside the input"):
        check_report_dir(tmp_path / "p", inputs=[tmp_path])
    empty = tmp_path / "empty"
    empty.mkdir()
    monkeypatch.chdir(empty)
    with pytest.raises(OutputError, match="current folder"):
        check_report_dir(".")
    assert check_report_dir(tmp_path / "new") == (tmp_path / "new").resolve()
    assert check_report_dir(tmp_path / "empty2") == (tmp_path / "empty2").resolve()


def test_write_report_refuses_an_output_folder_holding_an_input(tmp_path):
    scan = tmp_path / "scan.csv"
    scan.write_text("data")
    res = {"tables": {}, "checks": []}
    with pytest.raises(OutputError, match="contains the input"):
        builder.write_report(tmp_path, res, "<html/>", inputs=[scan])
    assert scan.read_text() == "data"


# --------------------------------------------------------------------------- files


def test_file_output_refusals(tmp_path):
    scan = tmp_path / "scan.csv"
    scan.write_text("data")
    with pytest.raises(OutputError, match="one of the input files"):
        check_file_output(scan, inputs=[scan], suffixes=(".csv",))
    with pytest.raises(OutputError, match="one of the input files"):
        check_file_output(tmp_path / "x" / ".." / "scan.csv", inputs=[scan])
    with pytest.raises(OutputError, match="existing folder"):
        check_file_output(tmp_path, suffixes=())
    with pytest.raises(OutputError, match=r"ends with '/'.*\.parquet"):
        check_file_output(str(tmp_path / "name.parquet") + "/", suffixes=(".parquet",))
    with pytest.raises(OutputError, match=r"expected a file name ending in \.npz"):
        check_file_output(tmp_path / "out.txt", suffixes=(".npz",))
    with pytest.raises(OutputError, match="not a regular file"):
        check_file_output("/dev/null")
    assert check_file_output(tmp_path / "new.csv", suffixes=(".csv",)) == tmp_path / "new.csv"


def test_atomic_output_follows_the_umask(tmp_path):
    old = os.umask(0o027)
    try:
        with atomic_output(tmp_path / "a.csv") as tmp:
            Path(tmp).write_text("x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "a.csv").stat().st_mode) == 0o640
    old = os.umask(0o002)
    try:
        with atomic_output(tmp_path / "b.csv") as tmp:
            Path(tmp).write_text("x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "b.csv").stat().st_mode) == 0o664


def test_dataset_write_follows_the_umask(tmp_path):
    m = Measurement(
        make_frame(
            sample="S",
            instrument="x",
            source="s",
            quantity="brdf",
            value=np.ones(2),
            unit="sr-1",
            wavelength_nm=500.0,
            theta_i_deg=45.0,
            theta_r_deg=np.array([40.0, 50.0]),
            phi_r_deg=180.0,
        )
    )
    old = os.umask(0o022)
    try:
        write(m, tmp_path / "d.csv")
        write(m, tmp_path / "d.parquet")
    finally:
        os.umask(old)
    for name in ("d.csv", "d.parquet"):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o644, name


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_folder_gives_an_output_error(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        with pytest.raises(OutputError, match=r"ro/a\.csv.*writ"):
            with atomic_output(ro / "a.csv") as tmp:
                Path(tmp).write_text("x")
    finally:
        ro.chmod(0o755)


def test_os_error_at_rename_is_an_output_error_naming_the_path(tmp_path, monkeypatch):
    def boom(*a, **k):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(outputs.files.os, "replace", boom)
    with pytest.raises(OutputError, match=r"a\.csv: No space left on device; the disk is full"):
        with atomic_output(tmp_path / "a.csv") as tmp:
            Path(tmp).write_text("x")
    assert list(tmp_path.iterdir()) == []


def test_an_os_error_while_writing_names_the_output_and_the_cause(tmp_path):
    with pytest.raises(OutputError, match=r"cannot write .*a\.csv: No space left on device"):
        with atomic_output(tmp_path / "a.csv"):
            raise OSError(errno.ENOSPC, None)  # no strerror, as some libraries raise it
    assert list(tmp_path.iterdir()) == []


def test_a_write_error_in_a_report_names_the_report_file(tmp_path):
    def write(d: Path) -> None:
        (d / "tables").mkdir()
        name = str(d / "tables" / "fits.csv")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), name)

    out = tmp_path / "rep"
    with pytest.raises(OutputError, match=r"rep/tables/fits\.csv: No space left on device"):
        replace_dir(out, write)
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- the write policy


def test_the_library_replaces_an_existing_file_outside_a_write_policy(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("old")
    assert check_file_output(p) == p
    with atomic_output(p) as tmp:
        Path(tmp).write_text("new")
    assert p.read_text() == "new"


def test_write_policy_refuses_an_existing_file_before_any_work(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("old")
    with write_policy(overwrite=False):
        with pytest.raises(OutputError, match=r"-o .*a\.csv: exists; pass --overwrite"):
            check_file_output(p)
        assert check_file_output(tmp_path / "b.csv") == tmp_path / "b.csv"
        assert check_file_output(p, overwrite=True) == p  # an explicit argument wins
    with write_policy(overwrite=True):
        assert check_file_output(p) == p
    assert p.read_text() == "old"


def test_write_policy_refuses_a_file_that_appears_while_writing(tmp_path):
    p = tmp_path / "a.csv"
    with write_policy(overwrite=False):
        with pytest.raises(OutputError, match=r"a\.csv: a file of that name appeared"):
            with atomic_output(p) as tmp:
                Path(tmp).write_text("ours")
                p.write_text("theirs")  # e.g. another program, during a long run
    assert p.read_text() == "theirs"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["a.csv"]


def test_write_policy_refuses_its_inputs_even_when_overwriting(tmp_path):
    src = tmp_path / "scan.csv"
    src.write_text("the only copy")
    link = tmp_path / "link.csv"
    link.symlink_to(src)
    with write_policy(overwrite=True, inputs=[src]):
        for out in (src, link):
            with pytest.raises(OutputError, match="one of the input files"):
                check_file_output(out)
            with pytest.raises(OutputError, match="one of the input files"):
                with atomic_output(out) as tmp:  # a writer that skipped the check
                    Path(tmp).write_text("x")
        with pytest.raises(OutputError, match="contains the input"):
            check_report_dir(tmp_path)
    assert src.read_text() == "the only copy" and link.is_symlink()
    assert sorted(x.name for x in tmp_path.iterdir()) == ["link.csv", "scan.csv"]


@pytest.mark.parametrize("code", [errno.EPERM, errno.EXDEV])
def test_without_hard_links_an_existing_file_is_still_refused(tmp_path, monkeypatch, code):
    def no_link(*a, **k):
        raise OSError(code, os.strerror(code))

    monkeypatch.setattr(outputs.files.os, "link", no_link)
    with write_policy(overwrite=False):
        with atomic_output(tmp_path / "new.csv") as tmp:
            Path(tmp).write_text("new")
        with pytest.raises(OutputError, match="appeared"):
            with atomic_output(tmp_path / "new.csv") as tmp:
                Path(tmp).write_text("again")
    assert (tmp_path / "new.csv").read_text() == "new"
    assert [x.name for x in tmp_path.iterdir()] == ["new.csv"]


def test_an_os_error_of_the_hard_link_names_the_output(tmp_path, monkeypatch):
    def broken(*a, **k):
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(outputs.files.os, "link", broken)
    with write_policy(overwrite=False):
        with pytest.raises(OutputError, match=r"cannot write .*new\.csv: Input/output error"):
            with atomic_output(tmp_path / "new.csv") as tmp:
                Path(tmp).write_text("new")
    assert list(tmp_path.iterdir()) == []


def test_a_writer_given_a_temporary_name_writes_under_a_no_overwrite_policy(tmp_path):
    p = tmp_path / "m.png"
    with write_policy(overwrite=False):
        with atomic_output(p) as outer:
            with atomic_output(outer) as inner:  # a writer that is itself atomic
                Path(inner).write_bytes(b"png")
        assert p.read_bytes() == b"png"
        with pytest.raises(OutputError, match=r"cannot write .*/m2\.png: No space left"):
            with atomic_output(tmp_path / "m2.png") as outer:
                with atomic_output(outer):
                    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert [x.name for x in tmp_path.iterdir()] == ["m.png"]


def test_write_policy_replaces_an_earlier_report_only_when_overwriting(tmp_path):
    out = tmp_path / "rep"
    replace_dir(out, _report)
    first = (out / "index.html").read_text()
    with write_policy(overwrite=False):
        with pytest.raises(OutputError, match="earlier labbrdf report; pass --overwrite"):
            replace_dir(out, lambda d: (d / "index.html").write_text("new"))
        assert (out / "index.html").read_text() == first
        empty = tmp_path / "empty"
        empty.mkdir()
        replace_dir(empty, _report)  # an empty folder holds nothing to lose
    with write_policy(overwrite=True):
        replace_dir(out, lambda d: (d / "index.html").write_text("new"))
    assert (out / "index.html").read_text() == "new"


# --------------------------------------------------------------------------- leftovers


def _killed_writer(script: str, tmp_path: Path) -> None:
    """Run ``script`` in a child that SIGKILLs itself mid-write."""
    code = textwrap.dedent(
        f"""
        import os, signal, sys
        sys.path.insert(0, {str(Path(__file__).resolve().parents[1])!r})
        from pathlib import Path
        from labbrdf import outputs
        tmp_path = Path({str(tmp_path)!r})
        def die(*a):
            os.kill(os.getpid(), signal.SIGKILL)
        """
    ) + textwrap.dedent(script)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=60)
    assert r.returncode == -9, r.stderr.decode()


def test_leftovers_of_a_killed_run_are_cleaned_by_the_next_run(tmp_path):
    (tmp_path / "a.csv").write_text("old")
    _killed_writer(
        """
        with outputs.atomic_output(tmp_path / "a.csv") as tmp:
            Path(tmp).write_text("half")
            die()
        """,
        tmp_path,
    )
    _killed_writer(
        """
        outputs.replace_dir(tmp_path / "rep", lambda d: die())
        """,
        tmp_path,
    )
    left = sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("."))
    assert len(left) == 2 and all("labbrdf-" in n for n in left), left
    # look-alikes that are not ours: no marker, foreign host, a live process, other names
    (tmp_path / ".rep.labbrdf-new-ffffff-1-abc").mkdir()
    host = outputs.files._host_tag()
    (tmp_path / f".rep.labbrdf-new-{host}-999999999-abc").mkdir()
    (tmp_path / f".a.csv.labbrdf-tmp-{host}-{os.getpid()}-xyz.tmp").write_text("")
    (tmp_path / ".a.csv.mine.tmp").write_text("")
    foreign = sorted(p.name for p in tmp_path.iterdir() if p.name not in left)
    with atomic_output(tmp_path / "a.csv") as tmp:
        Path(tmp).write_text("new")
    replace_dir(tmp_path / "rep", _report)
    assert (tmp_path / "a.csv").read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*foreign, "rep"])


def test_report_moved_aside_by_a_killed_run_is_put_back(tmp_path):
    replace_dir(tmp_path / "rep", _report)
    _killed_writer(
        """
        real = outputs.files.os.replace
        calls = []
        def replace(a, b):
            real(a, b)
            calls.append(1)
            if len(calls) == 1:  # the old report is aside, the new one not yet in place
                die()
        outputs.files.os.replace = replace
        outputs.replace_dir(tmp_path / "rep", lambda d: (d / "index.html").write_text("2"))
        """,
        tmp_path,
    )
    assert not (tmp_path / "rep").exists()
    assert clean_leftovers(tmp_path / "rep") != []  # the unfinished new folder
    assert (tmp_path / "rep" / "tables" / "fits.csv").read_text() == "a\n1\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]


# --------------------------------------------------------------------------- CSV cells


@pytest.mark.parametrize(
    "text", ['=HYPERLINK("http://x")', "+1", "-2+3", "@SUM(A1)", "\tx", "\rx"]
)
def test_csv_formula_cells_are_neutralised(text):
    assert csv_safe_cell(text) == "'" + text
    assert csv_safe_cell(-2.5) == -2.5
    assert csv_safe_cell("OSR 550") == "OSR 550"


def test_report_tables_csv_neutralises_formulas():
    res = {
        "tables": {
            "fits": {
                "columns": [{"key": "sample"}, {"key": "k1"}],
                "rows": [{"sample": '=HYPERLINK("http://evil","x")', "k1": -1.5}],
            }
        },
        "checks": [],
    }
    rows = list(csv.reader(io.StringIO(builder.tables_csv(res)["fits"])))
    assert rows[1] == ['\'=HYPERLINK("http://evil","x")', "-1.5"]


def test_dataset_csv_keeps_sample_names_exactly(tmp_path):
    """The dataset CSV is read back by labbrdf: no quote prefix, exact round trip."""
    name = '=HYPERLINK("http://x")'
    m = Measurement(
        make_frame(
            sample=name,
            instrument="-x",
            source="@s",
            quantity="brdf",
            value=np.ones(2),
            unit="sr-1",
            wavelength_nm=500.0,
            theta_i_deg=45.0,
            theta_r_deg=np.array([40.0, 50.0]),
            phi_r_deg=180.0,
        )
    )
    write(m, tmp_path / "d.csv")
    back = read(tmp_path / "d.csv")
    pd.testing.assert_frame_equal(back.data, m.data)


def test_leftover_report_folders_of_earlier_labbrdf_versions_are_removed(tmp_path):
    """Before the host/pid names, a killed report run left .rep.old-XXXXXXXX folders."""
    keys = ["title", "meta", "sections", "tables", "checks", "summary"]

    def legacy(name: str, age_s: float, extra: str | None = None) -> Path:
        d = tmp_path / name
        d.mkdir()
        _report(d)
        (d / "results.json").write_text(json.dumps({k: {} for k in keys}))
        if extra:
            (d / extra).write_text("mine")
        t = os.path.getmtime(d) - age_s
        os.utime(d, (t, t))
        return d

    legacy(".rep.old-abcd1234", 7200)
    kept = [
        legacy(".rep.new-efgh5678", 60).name,  # recent: a run of an older version may be busy
        legacy(".rep.old-ijkl9012", 7200, "thesis.tex").name,  # holds a user's file
        legacy(".rep.old-mine", 7200).name,  # not the old name pattern
    ]
    replace_dir(tmp_path / "rep", _report)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*kept, "rep"])


def test_library_reports_refuse_a_foreign_folder_before_any_work(tmp_path, capsys, specular_scan):
    from labbrdf import report

    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("x")
    with pytest.raises(OutputError, match="not empty"):
        report.user_report([specular_scan], "smooth3", out, progress=True)
    with pytest.raises(OutputError, match="not empty"):
        report.validate(out=out, progress=True, quick=True)
    assert "section" not in capsys.readouterr().err  # nothing ran
    assert [p.name for p in out.iterdir()] == ["thesis.tex"]


# --------------------------------------------------------------------------- inputs


def test_read_input_file_refuses_devices_fifos_folders_and_oversized_files(tmp_path):
    from labbrdf.outputs import InputFileError, read_input_file

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)  # opening it for reading would block until a writer came
    for path, kind in (("/dev/zero", "character device"), (fifo, "FIFO"), (tmp_path, "folder")):
        with pytest.raises(InputFileError, match=rf"{path}: is a {kind}"):
            read_input_file(path, max_bytes=100, what="table")
    big = tmp_path / "big.txt"
    big.write_bytes(b"x" * 101)
    with pytest.raises(InputFileError, match=r"big.txt: larger than 100 bytes"):
        read_input_file(big, max_bytes=100, what="table")
    assert read_input_file(big, max_bytes=101) == b"x" * 101
    with pytest.raises(InputFileError, match="absent.txt: cannot read the table"):
        read_input_file(tmp_path / "absent.txt", max_bytes=100, what="table")


def test_a_file_read_under_a_write_policy_becomes_an_input(tmp_path):
    from labbrdf.outputs import read_input_file

    table = tmp_path / "table.csv"
    table.write_text("300,1.5\n")
    with write_policy(overwrite=True, inputs=[]):
        read_input_file(table, max_bytes=100)
        with pytest.raises(OutputError, match="one of the input files"):
            check_file_output(table)
        with pytest.raises(OutputError, match="one of the input files"):
            with atomic_output(table) as tmp:
                Path(tmp).write_text("replaced\n")
    assert table.read_text() == "300,1.5\n"
    with atomic_output(table) as tmp:  # outside the policy: the library replaces it
        Path(tmp).write_text("replaced\n")
