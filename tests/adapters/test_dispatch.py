"""labbrdf.read dispatch: what reaches a reader, and how the format is chosen."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

import labbrdf
from labbrdf.adapters import READERS, AdapterError, sniff


@pytest.mark.parametrize("fmt", sorted(READERS))
def test_character_device_is_refused_with_and_without_format(fmt: str, project_root: Path) -> None:
    # run in a child with a memory limit and a timeout: before the fix /dev/zero was read
    # until memory ran out
    code = (
        "import resource, labbrdf\n"
        "resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))\n"
        "from labbrdf.adapters import AdapterError\n"
        "try:\n"
        f"    labbrdf.read('/dev/zero', format={fmt!r})\n"
        "except AdapterError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "PYTHONPATH": str(project_root)},
    )
    assert out.stdout.strip() == "/dev/zero: is a character device, expected a regular file"
    with pytest.raises(AdapterError, match="character device"):
        labbrdf.read("/dev/zero")


def test_fifo_is_refused_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe.dat"
    os.mkfifo(fifo)

    # should a reader open the FIFO, a writer unblocks it after 5 s (so the test fails
    # instead of hanging)
    def unblock() -> None:
        while not done.wait(5):
            with open(fifo, "wb"):
                pass

    done = threading.Event()
    threading.Thread(target=unblock, daemon=True).start()
    for fmt in (None, "woollam-wvase", "jcamp-dx", "labbrdf-parquet", "labbrdf-dataset-csv"):
        with pytest.raises(AdapterError, match=r"pipe\.dat: is a FIFO"):
            labbrdf.read(fifo, format=fmt)
    with pytest.raises(AdapterError, match="is a FIFO"):
        sniff(fifo)
    with pytest.raises(AdapterError, match="is a FIFO"):
        READERS["woollam-wvase"].read(fifo)
    done.set()


def test_directory_with_format_names_it_a_directory(tmp_path: Path) -> None:
    with pytest.raises(AdapterError, match="is a directory"):
        labbrdf.read(tmp_path, format="jcamp-dx")


# ----------------------------------------------------------------- content over extension


def test_jasco_text_saved_as_csv_is_read_as_jasco(real_exports: Path, tmp_path: Path) -> None:
    src = real_exports / "jasco-spectramanager-text" / "uvvis_abs.txt"
    renamed = tmp_path / "uvvis_abs.csv"
    renamed.write_bytes(src.read_bytes())
    m = labbrdf.read(renamed)
    assert m.meta["format"] == "jasco-spectramanager-text"
    ref = labbrdf.read(renamed, format="jasco-spectramanager-text")
    assert m.data["value"].tolist() == ref.data["value"].tolist()
    assert len(m.data) == 61


def test_wvase_saved_as_txt_is_read_as_wvase(real_exports: Path, tmp_path: Path) -> None:
    src = real_exports / "woollam-wvase-ascii" / "w2_10102006.dat"
    renamed = tmp_path / "w2_10102006.txt"
    renamed.write_bytes(src.read_bytes())
    m = labbrdf.read(renamed)
    assert m.meta["format"] == "woollam-wvase"
    assert len(m.data) == len(labbrdf.read(src).data)


def test_jasco_text_saved_as_asc_is_read_as_jasco(real_exports: Path, tmp_path: Path) -> None:
    # .asc belongs to one format only, whose sniffer does not claim the file
    src = real_exports / "jasco-spectramanager-text" / "uvvis_abs.txt"
    renamed = tmp_path / "uvvis_abs.asc"
    renamed.write_bytes(src.read_bytes())
    assert labbrdf.read(renamed).meta["format"] == "jasco-spectramanager-text"


def test_damaged_file_of_a_one_format_extension_gets_that_readers_error(
    real_exports: Path, tmp_path: Path
) -> None:
    src = real_exports / "perkinelmer-uvwinlab-asc" / "KTF-D.Probe.Raw.asc"
    bad = tmp_path / "KTF-D.asc"
    bad.write_bytes(b"PE UV  garbage\r\n" + src.read_bytes().split(b"\r\n", 1)[1])
    with pytest.raises(AdapterError) as exc:
        labbrdf.read(bad)
    assert "no adapter" not in str(exc.value)


def test_unrecognised_csv_names_the_csv_formats_not_all(tmp_path: Path) -> None:
    p = tmp_path / "notes.csv"
    p.write_text("hello,world\n1,2\n")
    with pytest.raises(AdapterError) as exc:
        labbrdf.read(p)
    msg = str(exc.value)
    for name in ("agilent-cary-winuv-csv", "labbrdf-dataset-csv", "labbrdf-specular-scan"):
        assert name in msg
    for name in ("zemax-bsdf", "galactic-spc", "woollam-wvase", "jcamp-dx"):
        assert name not in msg


def test_unrecognised_file_names_a_format_whose_keyword_it_carries(
    real_exports: Path, tmp_path: Path
) -> None:
    # a JCAMP file without its ##JCAMP-DX line: the sniffer does not claim it, but ##TITLE
    # in the first line makes jcamp-dx a candidate worth naming
    src = real_exports / "jcamp-dx" / "dupinc1.jdx"
    lines = src.read_bytes().split(b"\r\n")
    p = tmp_path / "dupinc1.txt"
    p.write_bytes(b"\r\n".join(ln for ln in lines if not ln.startswith(b"##JCAMP")))
    with pytest.raises(AdapterError) as exc:
        labbrdf.read(p)
    msg = str(exc.value)
    assert "jcamp-dx" in msg
    assert "filmsense" in msg  # a .txt format
    assert "zemax-bsdf" not in msg and "galactic-spc" not in msg


def test_unknown_extension_without_keywords_does_not_list_every_format(tmp_path: Path) -> None:
    p = tmp_path / "data.xyz"
    p.write_text("1 2 3\n4 5 6\n")
    with pytest.raises(AdapterError, match=r"formats\(\)") as exc:
        labbrdf.read(p)
    assert "woollam-wvase" not in str(exc.value)


def test_adapter_error_survives_pickling():
    # errors raised on a dask or process-pool worker travel back pickled
    import pickle

    from labbrdf.adapters import AdapterError

    e = AdapterError("x.dat", "expected a number", 7, unit="byte")
    back = pickle.loads(pickle.dumps(e))
    assert type(back) is AdapterError
    assert (back.path, back.reason, back.line, back.unit, str(back)) == (
        "x.dat", "expected a number", 7, "byte", "x.dat, byte 7: expected a number",
    )  # fmt: skip


# ------------------------------------------------------------ messages and refusals


def test_messages_name_the_option_of_both_interfaces(tmp_path: Path) -> None:
    """The CLI has --format, Python has format=: a message that tells to force a format
    names both."""
    p = tmp_path / "notes.csv"
    p.write_text("hello,world\n1,2\n")
    with pytest.raises(AdapterError) as exc:
        labbrdf.read(p)
    msg = str(exc.value)
    assert "--format NAME on the command line" in msg and "format=NAME in Python" in msg
    assert "pass format= to" not in msg


def test_no_adapter_message_names_the_cli_listing(tmp_path: Path) -> None:
    p = tmp_path / "data.xyz"
    p.write_text("hello\n")
    with pytest.raises(AdapterError, match=r"`labbrdf formats` \(labbrdf.adapters.formats\(\)"):
        labbrdf.read(p)


def test_unclaimed_ole2_container_is_named_as_such(tmp_path: Path, make_ole2) -> None:
    p = tmp_path / "book.xls"
    p.write_bytes(make_ole2({"Workbook": b"x" * 100}))
    with pytest.raises(AdapterError, match=r"OLE2 compound document .* Shimadzu UVProbe .spc"):
        labbrdf.read(p)


def test_headerless_numbers_get_the_columns_hint(tmp_path: Path) -> None:
    p = tmp_path / "spectrum.dat"
    p.write_text("400\t0.1\n401\t0.2\n402\t0.3\n")
    with pytest.raises(AdapterError, match=r"bare numbers: declare the columns with --columns"):
        labbrdf.read(p)


def test_binary_completeease_se_is_refused_with_what_to_do(tmp_path: Path) -> None:
    p = tmp_path / "wafer.SE"
    p.write_bytes(b"\x01\x00\x00\x00CompleteEASE\x00" + bytes(range(256)) * 4)
    with pytest.raises(AdapterError, match=r"CompleteEASE binary .SE.*export it as text") as exc:
        labbrdf.read(p)
    assert str(p) in str(exc.value)


def test_text_saved_as_se_is_read_by_its_content(real_exports: Path, tmp_path: Path) -> None:
    src = real_exports / "woollam-completeease-ascii" / "complete_ease_example.dat"
    p = tmp_path / "complete_ease_example.se"
    p.write_bytes(src.read_bytes())
    assert labbrdf.read(p).meta["format"] == labbrdf.read(src).meta["format"]


def test_text_forced_as_completeease_se_says_to_read_it_by_content(tmp_path: Path) -> None:
    p = tmp_path / "x.se"
    p.write_text("just text\n")
    with pytest.raises(AdapterError, match=r"is text, not a CompleteEASE binary .SE.*--format"):
        labbrdf.read(p, format="woollam-completeease-se")


def test_empty_se_is_refused_as_empty(tmp_path: Path) -> None:
    p = tmp_path / "x.se"
    p.write_bytes(b"")
    with pytest.raises(AdapterError, match=r"the file is empty"):
        labbrdf.read(p)


def test_every_registered_format_is_listed_with_its_extensions() -> None:
    names = {f["name"]: f for f in labbrdf.adapters.formats()}
    for name, ext in [
        ("shimadzu-uvprobe-text", ".txt"),
        ("shimadzu-uvprobe-spc", ".spc"),
        ("oceanoptics-text", ".txt"),
        ("jasco-jws", ".jws"),
        ("woollam-completeease-se", ".se"),
    ]:
        assert ext in names[name]["extensions"], name
    assert names["columns"]["extensions"] == []


def test_formats_list_the_height_maps_too_with_their_kind() -> None:
    from labbrdf.adapters.topography import HEIGHT_MAP_FORMATS

    rows = labbrdf.adapters.formats()
    kinds = {f["name"]: f["kind"] for f in rows}
    assert {n: kinds.get(n) for n in labbrdf.adapters.READERS} == dict.fromkeys(
        labbrdf.adapters.READERS, "optical"
    )
    by_name = {f["name"]: f for f in rows}
    for hm in HEIGHT_MAP_FORMATS:
        assert by_name[hm.name]["kind"] == "height map"
        assert by_name[hm.name]["extensions"] == [*hm.extensions, *hm.shared_extensions]
        assert by_name[hm.name]["quantities"] == ["height"]
    assert len(rows) == len(labbrdf.adapters.READERS) + len(HEIGHT_MAP_FORMATS)


def test_a_format_row_prints_as_its_line() -> None:
    row = {f["name"]: f for f in labbrdf.adapters.formats()}["nanoscope"]
    line = str(row)
    assert line.split()[:3] == ["nanoscope", "height", "map"]
    assert ".spm" in line and row["description"] in line


def test_cli_formats_lists_the_height_map_formats(capsys) -> None:
    from labbrdf.cli import main

    assert main(["formats"]) == 0
    lines = {ln.split()[0]: ln for ln in capsys.readouterr().out.splitlines()}
    assert "height map" in lines["surfacetopography"] and ".sdf" in lines["surfacetopography"]
    assert "height map" in lines["zygo-metropro"] and "optical" in lines["woollam-wvase"]


def test_cli_formats_lists_the_new_formats(capsys) -> None:
    from labbrdf.cli import main

    assert main(["formats"]) == 0
    out = capsys.readouterr().out
    for name in ("shimadzu-uvprobe-text", "shimadzu-uvprobe-spc", "oceanoptics-text", "columns"):
        assert name in out
