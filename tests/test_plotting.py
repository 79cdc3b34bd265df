"""The shared drawing layer: no plotting library until something is drawn."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

from labbrdf._plotting import curve_grid


def test_objects_with_plot_methods_load_no_plotting_library() -> None:
    code = (
        "import sys, labbrdf._plotting, labbrdf.fitting, labbrdf.nk, labbrdf.tracer, "
        "labbrdf.dataset; print('matplotlib' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_the_model_curve_spans_the_measured_angles_with_a_margin() -> None:
    g = curve_grid(np.array([40.0, 50.0, 45.0]))
    assert g.size == 121
    np.testing.assert_allclose([g[0], g[-1]], [39.5, 50.5])
    # never below normal incidence nor at grazing
    g = curve_grid(np.array([0.0, 89.9]))
    assert g[0] == 0.0 and g[-1] == 89.9
