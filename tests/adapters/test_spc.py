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
