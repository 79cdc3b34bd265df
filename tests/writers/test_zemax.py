"""The .bsdf writer and the model / trace export (labbrdf.writers.zemax)."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf import bsdf_geometry, models
from labbrdf.adapters import zemax_bsdf as zb
from labbrdf.outputs import OutputError, write_policy
from labbrdf.writers import zemax as bx


def test_writer_refuses_overwrite_and_leaves_no_temp(tmp_path):
    kw = dict(
        theta_i_deg=[10], radial_deg=[0, 10], azimuth_deg=[0, 180], values=np.ones((1, 1, 1, 2, 2))
    )
    p = bx.write_bsdf(tmp_path / "a.bsdf", symmetry="PlaneSymmetrical", **kw)
    before = p.read_bytes()
    with pytest.raises(OutputError, match="exists"):
        bx.write_bsdf(p, symmetry="PlaneSymmetrical", **kw)
    with pytest.raises(ValueError, match="finite"):
        bad = dict(kw, values=np.full((1, 1, 1, 2, 2), np.nan))
        bx.write_bsdf(p, overwrite=True, symmetry="PlaneSymmetrical", **bad)
    assert p.read_bytes() == before
    assert sorted(x.name for x in tmp_path.iterdir()) == ["a.bsdf"]
    with pytest.raises(ValueError, match="azimuth"):
        bx.write_bsdf(
            tmp_path / "b.bsdf", **dict(kw, azimuth_deg=[0, 270]), symmetry="PlaneSymmetrical"
        )


def test_writer_follows_the_one_output_rule(tmp_path):
    kw = dict(
        theta_i_deg=[10], radial_deg=[0, 10], azimuth_deg=[0, 180], values=np.ones((1, 1, 1, 2, 2))
    )
    p = bx.write_bsdf(tmp_path / "in.bsdf", symmetry="PlaneSymmetrical", **kw)
    before = p.read_bytes()
    with write_policy(overwrite=True, inputs=[p]), pytest.raises(OutputError, match="input"):
        bx.write_bsdf(p, overwrite=True, symmetry="PlaneSymmetrical", **kw)
    with pytest.raises(OutputError, match="folder"):
        bx.write_bsdf(tmp_path, overwrite=True, symmetry="PlaneSymmetrical", **kw)
    assert p.read_bytes() == before


def test_model_to_bsdf(tmp_path):
    model = models.get("five_param")
    ti = np.array([20.0, 50.0])
    rad = np.arange(0, 181, 1.0)
    az = np.arange(0, 181, 2.0)
    p = bx.model_to_bsdf(
        model, None, tmp_path / "m.bsdf", theta_i_deg=ti, radial_deg=rad, azimuth_deg=az, digits=12
    )
    m = labbrdf.read(p)
    d = m.data.sample(50, random_state=0)
    want = model.evaluate(
        np.radians(d.theta_i_deg), np.radians(d.theta_r_deg), np.radians(d.phi_r_deg)
    )
    np.testing.assert_allclose(d.value, want, rtol=1e-10)
    t = zb.read_table(p)
    rho = labbrdf.integrate.hemispherical_reflectance(model, None, ti)
    np.testing.assert_allclose(t.tis[0, 0], rho, rtol=0.02)
    g = zb.grid_integral(t)
    assert np.all(g["uncovered_fraction"] < 0.01)


def _imported_modules(path: str) -> set[str]:
    """Absolute names of the modules a source file imports (relative ones resolved)."""
    tree = ast.parse(Path(path).read_text())
    package = Path(path).parent.relative_to(Path(labbrdf.__file__).parent.parent).parts
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = list(package[: len(package) - node.level + 1]) if node.level else []
            mod = ".".join([*base, *([node.module] if node.module else [])])
            out.update([mod, *(f"{mod}.{a.name}" for a in node.names)])
    return out


def test_the_reader_does_not_import_the_export_workflow():
    imported = _imported_modules(zb.__file__)
    assert "labbrdf.adapters._base" in imported  # the resolution of relative imports works
    assert not any(m.startswith("labbrdf.writers.zemax") for m in imported)


def test_the_geometry_is_numpy_only():
    imported = _imported_modules(bsdf_geometry.__file__)
    assert imported - {"__future__", "__future__.annotations"} == {
        "numpy",
        "numpy.typing",
        "numpy.typing.ArrayLike",
        "numpy.typing.NDArray",
    }


@pytest.mark.parametrize(
    ("text", "angles"),
    [("0:80:20", [0, 20, 40, 60, 80]), ("0:1:0.1", np.round(np.arange(11) * 0.1, 9)),
     ("0,45,90", [0, 45, 90]), ("5", [5])],
)  # fmt: skip
def test_angle_grid_reads_start_stop_step_with_the_stop_or_a_list(text, angles):
    np.testing.assert_array_equal(bx.angle_grid(text), angles)


@pytest.mark.parametrize("text", ["0:x:1", "0:80", "0:80:0", "80:0:5", "0:80:-1", "a,b", ""])
def test_angle_grid_refuses_other_text(text):
    with pytest.raises(ValueError, match="expected START:STOP:STEP or a comma-separated list"):
        bx.angle_grid(text)
