"""Files written through dataset.atomic_output follow the umask like any other output."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from labbrdf.dataset import Measurement, make_frame, write_csv, write_parquet


def _m() -> Measurement:
    return Measurement(
        make_frame(
            sample="s",
            instrument="i",
            source="f",
            quantity="psi",
            value=[1.0],
            unit="deg",
            wavelength_nm=500.0,
        )
    )


@pytest.mark.parametrize("umask", [0o022, 0o027, 0o002])
def test_written_datasets_get_0666_minus_the_umask(tmp_path: Path, umask: int) -> None:
    old = os.umask(umask)
    try:
        paths = [
            write_csv(_m(), tmp_path / "a.csv"),
            tmp_path / "a.meta.json",
            write_parquet(_m(), tmp_path / "a.parquet"),
        ]
        plain = tmp_path / "plain.txt"
        plain.write_text("x")
    finally:
        os.umask(old)
    want = 0o666 & ~umask
    assert stat.S_IMODE(plain.stat().st_mode) == want  # what open() gives
    for p in paths:
        assert stat.S_IMODE(p.stat().st_mode) == want, p.name
