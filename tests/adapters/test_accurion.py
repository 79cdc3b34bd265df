"""Accurion EP4: the real files added to the shared exports later, and hardening."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError

ACC = "accurion-ep4-dat"


def _rows(m: labbrdf.Measurement, quantity: str, aoi: float, x: float, y: float):
    d = m.data
    sel = (
        (d["quantity"] == quantity)
        & np.isclose(d["theta_i_deg"], aoi, rtol=0, atol=1e-9)
        & np.isclose(d["x_mm"], x, rtol=0, atol=1e-9)
        & np.isclose(d["y_mm"], y, rtol=0, atol=1e-9)
    )
    return d[sel]


def test_post_synthesis_map_reads_zones_1_to_4_with_positions(real_exports: Path) -> None:
    m = labbrdf.read(real_exports / ACC / "post synthesis.dat")
    assert m.meta["format"] == "accurion-ep4"
    # 960 data lines, 160 per zone 0..5: zones 1-4 kept, two rows (psi, delta) each
    assert len(m) == 2 * 4 * 160
    assert m.meta["data_zones"] == [1, 2, 3, 4]
    # line 3: "658.0 2.0 50.000 143.615 34.702 4 34.626 63.213 30.000 63.213 000 -18.183
    # -30.305 0.000" (Lambda Bandwidth AOI Delta Psi Zone ... X_pos Y_pos Theta_pos)
    psi = _rows(m, "psi", 50.0, -18.183, -30.305)["value"].to_numpy()
    delta = _rows(m, "delta", 50.0, -18.183, -30.305)["value"].to_numpy()
    assert 34.702 in psi.tolist() and 143.615 in delta.tolist()
    assert set(m.data["wavelength_nm"]) == {658.0}
    assert sorted(set(m.data["theta_i_deg"])) == pytest.approx([50.0, 53.6, 57.2, 60.8, 64.4])


@pytest.mark.parametrize("cut", ["after the TAB behind Y_pos", "empty Zone", "empty X_pos"])
def test_row_with_an_empty_field_is_refused(real_exports: Path, tmp_path: Path, cut: str) -> None:
    raw = (real_exports / ACC / "post synthesis.dat").read_bytes()
    # line 3: "658.0 2.0 50.000 143.615 34.702 4 34.626 63.213 30.000 63.213 000 -18.183
    # -30.305 0.000" (... X_pos Y_pos Theta_pos)
    head = b"658.0\t2.0\t50.000\t143.615\t34.702\t4\t34.626\t63.213\t30.000\t63.213\t000\t"
    line3 = head + b"-18.183\t-30.305\t0.000"
    new = {
        "after the TAB behind Y_pos": head + b"-18.183\t-30.305\t",
        "empty Zone": line3.replace(b"\t4\t", b"\t\t"),
        "empty X_pos": head + b"\t-30.305\t0.000",
    }[cut]
    start = raw.index(line3)
    bad = tmp_path / "cut.dat"
    bad.write_bytes(raw[:start] + new + raw[start + len(line3) :])
    with pytest.raises(AdapterError, match=r"line 3: field \d+ \(\w+\) is empty"):
        labbrdf.read(bad)


def test_zone_numbers_are_kept_so_rows_of_one_spot_and_angle_differ(real_exports: Path) -> None:
    d = labbrdf.read(real_exports / "accurion-ep4-dat" / "15-1-1.dat").data
    assert "zone" in d.columns
    at50 = d[(d["theta_i_deg"] == 50.0) & (d["quantity"] == "psi")]
    # lines 3-6: zone 4 Psi 31.474, zone 2 31.291, ... (zones 0 and 5 are not data rows)
    assert sorted(at50["zone"]) == [1.0, 2.0, 3.0, 4.0]
    assert at50.loc[at50["zone"] == 2, "value"].item() == pytest.approx(31.291, abs=5e-4)
    assert at50.loc[at50["zone"] == 4, "value"].item() == pytest.approx(31.474, abs=5e-4)
    key = ["quantity", "wavelength_nm", "theta_i_deg", "x_mm", "y_mm", "zone"]
    assert not d.duplicated(key).any()
