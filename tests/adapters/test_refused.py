"""Formats recognised and refused with advice: CompleteEASE .SEsnap, PSI SpectraPen."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff


def test_sesnap_gets_the_completeease_text_export_advice(tmp_path: Path) -> None:
    p = tmp_path / "Si wafer.SEsnap"
    with zipfile.ZipFile(p, "w") as z:
        z.writestr("Si wafer.SE", b"\x00\x01binary")
    with pytest.raises(AdapterError, match=r"CompleteEASE snapshot .*export the data as text"):
        labbrdf.read(p)
    text = tmp_path / "notes.sesnap"
    text.write_text("hello\n")
    with pytest.raises(AdapterError, match="not a ZIP archive"):
        labbrdf.read(text)


def test_real_spectrapen_irradiance_is_refused_by_name(real_exports: Path) -> None:
    p = real_exports / "psi-spectrapen" / "psi-spectrapen-SP.csv"
    assert sniff(p) == ["psi-spectrapen"]
    with pytest.raises(AdapterError, match=r"line 1: a PSI SpectraPen export of Irradiance "
                       r"\[µW/cm2/nm\]: .*not an optical property of a sample"):  # fmt: skip
        labbrdf.read(p)


def test_spectrapen_photon_irradiance_variant(tmp_path: Path) -> None:
    p = tmp_path / "sp.csv"
    p.write_text(
        "Irradiance \t [µE/m2/s/nm],\nTime,11/10/2022 7:08:01 PM,\nIndex,13,\nName,,\nGPS,,\n"
        "[nm],\n327.1,3.7E+000\n",
        encoding="utf-8",
    )
    with pytest.raises(AdapterError, match=r"Irradiance \[µE/m2/s/nm\]"):
        labbrdf.read(p)
