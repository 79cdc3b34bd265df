"""CID SpectraVue Measurements.csv: the real reflectance file and synthetic variants."""

from __future__ import annotations

from pathlib import Path

import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff
from labbrdf.adapters.cid import read_spectravue

REAL = "cid-spectravue/cid-spectravue-Rpc-Measurements.csv"
HEAD = "Date,Mode,IntegrationTime(ms),Smoothing,ScansToAverage,Tag,Version,CalibrationID,Coordinates,Wavelengths(nm),"  # noqa: E501


def test_real_reflectance_file_is_read_as_fraction(real_exports: Path) -> None:
    p = real_exports / REAL
    assert sniff(p) == ["cid-spectravue"]
    m = labbrdf.read(p)
    d = m.data
    assert len(d) == 2048 and set(d["quantity"]) == {"reflectance"}
    near = d.iloc[(d["wavelength_nm"] - 550.0).abs().argsort()[:1]]
    assert near["value"].iloc[0] == pytest.approx(0.266435, abs=1e-6)  # 26.6 % written
    assert m.meta["unit_from"].startswith("values (median 29.1")


def _file(*rows: str, wl=(390.0, 500.0, 600.0)) -> str:
    head = HEAD + ",".join(f"{w:g}" for w in wl) + ",\n"
    return head + "".join(r + "\n" for r in rows)


def _row(mode: str, values: str, tag: str = "", date: str = "3/8/2022 3:02:47 PM") -> str:
    return f"{date},{mode},0.9,0,1,{tag},0.9.38.0,abc,,,{values},"


def test_two_modes_two_samples(tmp_path: Path) -> None:
    p = tmp_path / "xMeasurements.csv"
    p.write_text(_file(_row("Abs Reflectance", "10,20,30", "\"leaf, A\""),
                       _row("Abs Transmittance", "40,50,60", "\"leaf, A\"")))  # fmt: skip
    d = labbrdf.read(p).data
    assert d.groupby("quantity", observed=True)["value"].sum().to_dict() == pytest.approx(
        {"reflectance": 0.6, "transmittance": 1.5}
    )
    assert set(d["sample"]) == {"leaf, A"}


def test_small_values_need_a_declared_unit(tmp_path: Path) -> None:
    p = tmp_path / "dark.csv"
    p.write_text(_file(_row("Reflectance", "0.1,0.2,0.3")))
    with pytest.raises(AdapterError, match="could be percent or fractions: declare the unit"):
        labbrdf.read(p)
    frac = labbrdf.read(p, format="cid-spectravue-fraction").data["value"].tolist()
    pct = labbrdf.read(p, format="cid-spectravue-percent").data["value"].tolist()
    assert frac == [0.1, 0.2, 0.3] and pct == pytest.approx([0.001, 0.002, 0.003])


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (_file(_row("Absorbance", "1,2,3")), r"line 2: Mode 'Absorbance': .*decadic absorbance"),
        (_file(_row("Fluorescence", "1,2,3")), r"line 2: Mode 'Fluorescence'"),
        (_file(_row("Reflectance", "10,20")), r"line 2: expected 10 metadata fields and 3 values"),
        (_file(_row("Reflectance", "10,x,30")), r"line 2: value: expected a number, found 'x'"),
        (_file(_row("Reflectance", "10,20,30"), _row("Reflectance", "10,20,30")),
         r"line 3: the same measurement as line 2"),
        (_file(_row("Reflectance", "10,20,30"), wl=(500.0, 400.0, 600.0)), r"strictly increasing"),
    ],
)  # fmt: skip
def test_what_cannot_be_read_is_refused(tmp_path: Path, text: str, match: str) -> None:
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(AdapterError, match=match) as info:
        read_spectravue(p)
    assert str(p) in str(info.value)
