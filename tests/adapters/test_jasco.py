"""JASCO Spectra Manager text: a UTF-8 BOM or CR-only line ends are recognised."""

from __future__ import annotations

from pathlib import Path

import pytest

import labbrdf
from labbrdf.adapters import sniff

TXT = "jasco-spectramanager-text"


@pytest.mark.parametrize("variant", ["bom", "cr", "bom+cr"])
def test_bom_and_cr_only_line_ends_are_recognised(
    real_exports: Path, tmp_path: Path, variant: str
) -> None:
    src = real_exports / TXT / "PbSe batch 1.txt"
    raw = src.read_bytes().replace(b"\r\n", b"\n")
    if "cr" in variant:
        raw = raw.replace(b"\n", b"\r")
    if "bom" in variant:
        raw = b"\xef\xbb\xbf" + raw
    path = tmp_path / "PbSe.txt"
    path.write_bytes(raw)
    assert sniff(path) == ["jasco-spectramanager-text"]
    m = labbrdf.read(path)
    assert m.data["value"].equals(labbrdf.read(src).data["value"])
