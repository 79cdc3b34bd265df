"""FRED scripts of fitted Harvey models: round trip through FRED's documented formulas."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from labbrdf import fit, models
from labbrdf.fitting import FitData
from labbrdf.outputs import OutputError
from labbrdf.writers.fred import write_fred_script


def _members(path: Path) -> dict[str, float]:
    """``scat.<member> = <number>`` lines of the script (an independent parse)."""
    text = path.read_bytes().decode("ascii")
    assert "\r\n" in text and text.splitlines()[0].startswith("'")
    pairs = re.findall(r"^\s*scat\.(\w+) = ([-+0-9.eE]+)", text, flags=re.M)
    return {k: float(v) for k, v in pairs}


def _fred_abg(m: dict, ti: np.ndarray, tr: np.ndarray, pr: np.ndarray) -> np.ndarray:
    """FRED's ABg: Acoef / (Bcoef + |b - b0|^G), b the projected direction vectors."""
    b = np.stack([np.sin(tr) * np.cos(pr), np.sin(tr) * np.sin(pr)])
    b0 = np.stack([-np.sin(ti), 0 * ti])  # specular direction, source at azimuth 0
    return m["Acoef"] / (m["Bcoef"] + np.linalg.norm(b - b0, axis=0) ** m["G"])


def _fred_hs(m: dict, ti: np.ndarray, tr: np.ndarray, pr: np.ndarray) -> np.ndarray:
    """FRED's Harvey-Shack: b0 (1 + (|b - b0| / L)^2)^(S / 2)."""
    b = np.stack([np.sin(tr) * np.cos(pr), np.sin(tr) * np.sin(pr)])
    b0 = np.stack([-np.sin(ti), 0 * ti])
    return m["b0"] * (1 + (np.linalg.norm(b - b0, axis=0) / m["L"]) ** 2) ** (m["S"] / 2)


def _data(model: models.Model, quantity: str = "brdf") -> FitData:
    rng = np.random.default_rng(4)
    ti = np.repeat([10.0, 40.0], 20)
    tr = np.tile(np.linspace(0, 80, 20), 2)
    pr = np.tile(np.where(np.arange(20) % 2, 180.0, 150.0), 2)
    y = model.evaluate(np.radians(ti), np.radians(tr), np.radians(pr))
    y = y * (1 + 0.02 * rng.standard_normal(y.size))
    return FitData(ti, tr, y, phi_r_deg=pr, wavelength_nm=633.0, quantity=quantity)


@pytest.mark.parametrize(
    ("name", "params", "fred"),
    [
        ("abg", {"A": 0.003, "B": 1e-3, "g": 1.7}, _fred_abg),
        ("harvey_shack", {"b0": 3.0, "L": 0.03, "S": -2.2}, _fred_hs),
    ],
)
def test_round_trip_through_freds_formula(tmp_path: Path, name: str, params: dict, fred) -> None:
    model = models.get(name)
    for k, v in params.items():
        model.params[k].value = v
    res = fit(model, _data(model), weighting="relative")
    path = write_fred_script(res, tmp_path / "m.frs")
    m = _members(path)
    rng = np.random.default_rng(0)
    ti, tr, pr = rng.uniform(0, 1.3, 40), rng.uniform(0, 1.5, 40), rng.uniform(0, 6.28, 40)
    np.testing.assert_allclose(
        fred(m, ti, tr, pr), model.evaluate(ti, tr, pr, params=res.params), rtol=1e-14
    )
    text = path.read_text()
    assert "wavelength of the fit: 633 nm" in text and "theta_i 10..40 deg" in text
    assert "scat.ApplyRefl = True" in text and "scat.ApplyTrans = False" in text


def test_transmission_fit_applies_on_transmission(tmp_path: Path) -> None:
    model = models.get("abg", transmission=True)
    res = fit(model, _data(model, "btdf"), weighting="relative")
    text = write_fred_script(res, tmp_path / "t.frs", wavelength_stated=False).read_text()
    assert "scat.ApplyTrans = True" in text and "(BTDF)" in text
    assert "a label: the measurement states no wavelength" in text


def test_refusals(tmp_path: Path) -> None:
    model = models.get("abg")
    res = fit(model, _data(model), weighting="relative")
    path = write_fred_script(res, tmp_path / "a.frs")
    before = path.read_bytes()
    with pytest.raises(OutputError, match="exists; pass --overwrite"):
        write_fred_script(res, path)
    assert path.read_bytes() == before
    with pytest.raises(OutputError, match=r"expected a file name ending in \.frs"):
        write_fred_script(res, tmp_path / "a.txt")
    with pytest.raises(OutputError, match="without double quotes"):
        write_fred_script(res, tmp_path / "b.frs", name='say "hi"')
    floor = models.get("abg", diffuse=True)
    with pytest.raises(OutputError, match="has no Lambertian floor"):
        write_fred_script(fit(floor, _data(floor), weighting="relative"), tmp_path / "c.frs")
    mf = models.get("microfacet", ideal_mirror=True)
    with pytest.raises(OutputError, match="FRED scripts are written for"):
        write_fred_script(fit(mf, _data(mf)), tmp_path / "d.frs")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.frs"]
