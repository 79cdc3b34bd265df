"""What the spectrophotometer adapters (JASCO text and .jws, PerkinElmer .asc, Cary CSV,
JCAMP-DX, SPC) share: dispatch of every real export to its own reader, sniffers that claim
exactly their own files, forced formats and empty, missing or garbage files refused; and
the one holmium spectrum that both the SPC and the JCAMP-DX decoders read.

Each format's own checks are in its file (``test_jasco.py``, ``test_perkinelmer.py``,
``test_cary.py``, ``test_jcamp.py``, ``test_spc.py``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import READERS, AdapterError, sniff
from labbrdf.adapters.jcamp import read_jcamp
from labbrdf.adapters.spc import read_spc

MINE = {
    "jasco-spectramanager-text": "jasco-spectramanager-text",
    "jasco-jws": "jasco-jws-binary",
    "perkinelmer-uvwinlab-asc": "perkinelmer-uvwinlab-asc",
    "agilent-cary-winuv-csv": "agilent-cary-winuv-csv",
    "jcamp-dx": "jcamp-dx",
    "galactic-spc": "galactic-spc",
}


def test_spc_and_jcamp_hold_the_same_holmium_spectrum(real_exports: Path) -> None:
    """dupinc1.jdx (250-469.5 nm, 4 decimals) is the same holmium glass scan as HOLMIUM.SPC.

    Two independent decoders (SQZ/DIF/DUP text, scaled int32 binary) must agree to the
    SPC quantum 2**-22 (the JCAMP values are exact 4-decimal numbers; the SPC integer is
    within one quantum of them, and the two files were rounded independently: 2 quanta).
    Two points differ by far more in the files themselves (dupinc1 was hand re-encoded
    with DXEDIT): 386 nm and 455 nm, where 0.984 vs 0.948 is a digit swap.
    """
    spc = read_spc(real_exports / "galactic-spc" / "HOLMIUM.SPC").data
    jdx = read_jcamp(real_exports / "jcamp-dx" / "dupinc1.jdx").data
    on = spc.set_index("wavelength_nm")["value"].loc[jdx["wavelength_nm"]].to_numpy()
    diff = np.abs(on - jdx["value"].to_numpy())
    off = jdx["wavelength_nm"].to_numpy()[diff > 2 * 2.0**-22]
    assert off.tolist() == [386.0, 455.0]
    assert diff.max() == pytest.approx(0.036, abs=1e-4)


# ------------------------------------------------------------------ dispatch


def _real_files(real_exports: Path) -> list[Path]:
    return sorted(p for p in real_exports.glob("*/*") if p.name != "PROVENANCE.md")


def test_dispatch_without_format_picks_our_adapter(real_exports: Path) -> None:
    n = 0
    for fmt, folder in MINE.items():
        for path in sorted((real_exports / folder).iterdir()):
            via_read = labbrdf.read(path)
            direct = READERS[fmt].read(path)
            assert via_read.data.equals(direct.data), path.name
            assert via_read.meta["format"] == fmt, path.name
            n += 1
    # 13 of the first collection + "F4-P3HT 1-10 0,5 mgml.Probe.Raw.asc" (added later)
    # + the legacy (OLE2) "legacy_trans_512.jws"
    assert n == 15


def test_our_sniffers_claim_exactly_our_own_real_files(real_exports: Path) -> None:
    """Sniffing is what separates .txt (JASCO, Film Sense, SENTECH) and .csv files."""
    for path in _real_files(real_exports):
        head = path.read_bytes()[:8192]
        claimed = {fmt for fmt in MINE if READERS[fmt].sniff(head)}
        owner = {fmt for fmt, folder in MINE.items() if folder == path.parent.name}
        assert claimed == owner, path.name
        if owner:
            assert set(sniff(path)) & set(READERS) >= owner


@pytest.mark.parametrize("fmt", sorted(MINE))
def test_forcing_our_format_on_other_real_files_raises(real_exports: Path, fmt: str) -> None:
    for path in _real_files(real_exports):
        if path.parent.name == MINE[fmt]:
            continue
        with pytest.raises(AdapterError, match=r"(line|byte) \d+|expected|no |not "):
            labbrdf.read(path, format=fmt)


@pytest.mark.parametrize("fmt", sorted(MINE))
def test_empty_missing_and_garbage_files_raise(tmp_path: Path, fmt: str) -> None:
    empty = tmp_path / "empty.x"
    empty.write_bytes(b"")
    with pytest.raises(AdapterError, match="the file is empty"):
        READERS[fmt].read(empty)
    with pytest.raises(AdapterError, match="cannot be read"):
        READERS[fmt].read(tmp_path / "missing.x")
    with pytest.raises(AdapterError, match="is a directory"):
        READERS[fmt].read(tmp_path)
    garbage = tmp_path / "garbage.x"
    garbage.write_bytes(np.random.default_rng(7).integers(0, 256, 4096, dtype=np.uint8).tobytes())
    with pytest.raises(AdapterError, match=str(garbage.name)):
        READERS[fmt].read(garbage)
