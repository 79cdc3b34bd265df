"""Galactic SPC: degenerate X axes are refused; reflectance and transmittance Y types."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from labbrdf.adapters import AdapterError
from labbrdf.adapters.spc import read_spc


def _holmium(real_exports: Path) -> bytearray:
    return bytearray((real_exports / "galactic-spc/HOLMIUM.SPC").read_bytes())


@pytest.mark.parametrize(
    ("first", "last", "match"),
    [
        (500.0, 500.0, r"byte 8: the X axis is not strictly monotonic \(ffirst = flast = 500\)"),
        (1e-300, 1e-300, r"byte 8: the X axis spans 1e-300 to 1e-300 nm, outside"),
        (1e300, 1e300, r"byte 8: the X axis spans 1e\+300 to 1e\+300 nm, outside"),
        (250.0, 2e6, r"byte 8: the X axis spans 250 to 2e\+06 nm, outside"),
    ],
)
def test_degenerate_or_non_physical_x_range_is_refused(
    real_exports: Path, tmp_path: Path, first: float, last: float, match: str
) -> None:
    raw = _holmium(real_exports)
    struct.pack_into("<dd", raw, 8, first, last)  # ffirst, flast at byte 8 and 16
    bad = tmp_path / "x.spc"
    bad.write_bytes(bytes(raw))
    with pytest.raises(AdapterError, match=match):
        read_spc(bad)


def test_descending_x_range_is_read(real_exports: Path, tmp_path: Path) -> None:
    raw = _holmium(real_exports)
    struct.pack_into("<dd", raw, 8, 700.0, 250.0)
    path = tmp_path / "down.spc"
    path.write_bytes(bytes(raw))
    d = read_spc(path).data
    assert d["wavelength_nm"].iloc[0] == 700.0 and d["wavelength_nm"].iloc[-1] == 250.0


# ------------------------------------------------------------ reflectance and transmittance


def _float_spc(y: list[float], *, ytype: int, labels: bytes = b"") -> bytes:
    """A one-subfile SPC with float32 Y over 400-500 nm; ``labels`` go to fcatxt (TALABS)."""
    h = bytearray(512)
    h[0], h[1] = (0x20 if labels else 0), 0x4B
    struct.pack_into("<b", h, 3, -128)
    struct.pack_into("<iddi", h, 4, len(y), 400.0, 500.0, 1)
    h[28], h[29] = 3, ytype
    h[218 : 218 + len(labels)] = labels
    sub = bytearray(32)
    struct.pack_into("<b", sub, 1, -128)
    return bytes(h) + bytes(sub) + struct.pack(f"<{len(y)}f", *y)


def test_reflectance_y_type_of_a_real_file_is_read_as_percent_when_above_1(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = _holmium(real_exports)
    raw[29] = 129  # fytype: reflectance
    p = tmp_path / "r.spc"
    p.write_bytes(bytes(raw))
    m = read_spc(p)
    d = m.data
    assert set(d["quantity"]) == {"reflectance"} and len(d) == 901
    # first Y 1.1663 (the same as the JCAMP file of this spectrum), up to 3.3747: percent
    assert d["value"].iloc[0] == pytest.approx(0.011663, rel=1e-4)
    assert d["value"].max() == pytest.approx(0.033747, rel=1e-4)
    assert m.meta["y_type_name"] == "reflectance"
    assert m.meta["y_scale_in_file"] == "percent"
    assert "3.3747" in m.meta["y_scale_basis"]


def test_transmittance_y_type_with_values_up_to_1_is_read_as_fraction(tmp_path: Path) -> None:
    p = tmp_path / "t.spc"
    p.write_bytes(_float_spc([0.25, 0.5, 0.75], ytype=128))
    m = read_spc(p)
    assert set(m.data["quantity"]) == {"transmittance"}
    assert list(m.data["value"]) == [0.25, 0.5, 0.75]
    assert m.meta["y_scale_in_file"] == "fraction"
    assert "does not say" in m.meta["y_scale_basis"]


def test_percent_axis_label_wins_over_the_value_range(tmp_path: Path) -> None:
    p = tmp_path / "rl.spc"
    p.write_bytes(_float_spc([0.5, 0.75, 1.0], ytype=129, labels=b"Wavelength\x00%R\x00\x00"))
    m = read_spc(p)
    assert list(m.data["value"]) == [0.005, 0.0075, 0.01]
    assert m.meta["y_scale_in_file"] == "percent"
    assert "'%R'" in m.meta["y_scale_basis"]


def test_other_y_types_are_still_refused_at_their_byte(tmp_path: Path) -> None:
    p = tmp_path / "c.spc"
    p.write_bytes(_float_spc([1.0, 2.0], ytype=4))  # counts
    with pytest.raises(AdapterError, match=r"byte 29: y type 4 \(counts\): only absorbance"):
        read_spc(p)
