"""Formats recognised and refused with advice: CompleteEASE .SEsnap, PSI SpectraPen, RGL
tensor .bsdf, MERL .binary."""

from __future__ import annotations

import struct
import zipfile
from pathlib import Path

import numpy as np
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


def test_rgl_tensor_bsdf_is_refused_by_its_header(tmp_path: Path) -> None:
    # an RGL database file shares .bsdf with the Zemax text format: the header decides
    p = tmp_path / "acrylic_felt_green_rgb.bsdf"
    p.write_bytes(b"tensor_file\x00\x01\x00" + struct.pack("<I", 9) + b"\x00" * 64)
    assert sniff(p) == ["rgl-tensor-bsdf"]
    with pytest.raises(AdapterError, match=r"byte 1: a binary RGL tensor file \(version 1\.0"):
        labbrdf.read(p)
    (tmp_path / "rows.txt").write_text("1 2\n")
    with pytest.raises(AdapterError, match="expected an RGL tensor file"):
        labbrdf.read(tmp_path / "rows.txt", format="rgl-tensor-bsdf")


def test_merl_binary_is_refused_by_its_header(tmp_path: Path) -> None:
    p = tmp_path / "gold-metallic-paint.binary"
    p.write_bytes(struct.pack("<3i", 90, 90, 180) + np.zeros(64).tobytes())
    assert sniff(p) == ["merl-binary"]
    with pytest.raises(AdapterError, match="a MERL BRDF database file"):
        labbrdf.read(p)
    other = tmp_path / "other.binary"
    other.write_bytes(struct.pack("<3i", 90, 90, 360))
    with pytest.raises(AdapterError, match="expected a MERL BRDF"):
        labbrdf.read(other, format="merl-binary")
    # with no format forced, the one reader of the extension says what is wrong
    with pytest.raises(AdapterError, match="expected a MERL BRDF"):
        labbrdf.read(other)
