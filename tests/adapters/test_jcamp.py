"""JCAMP-DX: hardening against corrupt counts, and the XYPOINTS table."""

from __future__ import annotations

from pathlib import Path

import pytest

from labbrdf.adapters import AdapterError
from labbrdf.adapters.jcamp import read_jcamp

JDX = "jcamp-dx"


def _dupinc(real_exports: Path) -> bytes:
    return (real_exports / JDX / "dupinc1.jdx").read_bytes()


def test_dup_count_past_npoints_is_refused_before_expansion(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = _dupinc(real_exports)
    i = raw.index(b"Tk69")  # line 19: "2500A1663l68...j79Tk69j04..." (T = repeat twice)
    bad = tmp_path / "dup.jdx"
    bad.write_bytes(raw[: i + 1] + b"0000000" + raw[i + 1 :])  # T0000000: 2e7 repeats
    with pytest.raises(AdapterError, match=r"line 19: DUP count 'T0000000'.*NPOINTS"):
        read_jcamp(bad)


def test_npoints_above_the_hard_cap_is_refused(real_exports: Path, tmp_path: Path) -> None:
    raw = _dupinc(real_exports).replace(b"##NPOINTS=  440", b"##NPOINTS=  4000000000")
    bad = tmp_path / "npoints.jdx"
    bad.write_bytes(raw)
    with pytest.raises(AdapterError, match=r"NPOINTS = 4000000000 exceeds the limit"):
        read_jcamp(bad)
