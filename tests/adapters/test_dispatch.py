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

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("fmt", sorted(READERS))
def test_character_device_is_refused_with_and_without_format(fmt: str) -> None:
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
        env={**os.environ, "PYTHONPATH": str(ROOT)},
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
