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


def test_speos_bsdf_is_refused_with_the_zemax_advice(tmp_path: Path) -> None:
    # the first lines of a Speos table: without its own sniffer it looked like numbers after
    # a five-line preamble and was offered --skip-lines, which would read the grid as data
    p = tmp_path / "vinyl.anisotropicbsdf"
    p.write_text(
        "OPTIS - Anisotropic BSDF surface file v8.0\n0\nComment\n23\nMeasurement description\n"
        "0\t1\t0\n1\t0\n1\n1\n0.0\t\n13\n15.0\t20.0\t25.0\t\n"
    )
    assert sniff(p) == ["speos-bsdf"]
    with pytest.raises(AdapterError, match=r"line 1: an Ansys Speos .*'zemax-bsdf'"):
        labbrdf.read(p)
    other = tmp_path / "other.anisotropicbsdf"
    other.write_text("1 2\n3 4\n")
    with pytest.raises(AdapterError, match="expected a Speos BSDF file"):
        labbrdf.read(other, format="speos-bsdf")


def test_real_speos_bsdf_is_refused_by_name(real_exports: Path) -> None:
    p = next((real_exports / "speos-anisotropicbsdf").glob("*.anisotropicbsdf"))
    with pytest.raises(AdapterError, match="Ansys Speos anisotropic BSDF file"):
        labbrdf.read(p)
