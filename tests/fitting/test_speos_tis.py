"""The TIS comparison on a Speos table: a table written from a model integrates, on its own
grid, to what the model integrates there, at every incidence (the reader's scaling)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from labbrdf import models
from labbrdf.adapters.speos_bsdf import read_speos_table
from labbrdf.fitting.scatter_tis import speos_tis_comparison
from labbrdf.writers.speos import model_to_speos

P = {"A": 0.01, "B": 0.01, "g": 1.8, "kd": 0.05}


def test_a_models_table_integrates_like_the_model(tmp_path: Path) -> None:
    m = models.get("abg", diffuse=True)
    path = model_to_speos(m, P, tmp_path / "m.anisotropicbsdf", theta_i_deg=[10.0, 40.0, 70.0],
                          wavelength_nm=633.0)  # fmt: skip
    table = read_speos_table(path)
    cmp = speos_tis_comparison(m, P, table, 633.0)
    assert list(cmp["theta_i_deg"]) == [10.0, 40.0, 70.0]
    # the same values on the same nodes: the scaled measurement is the model's own integral
    np.testing.assert_allclose(cmp["ratio"], 1.0, rtol=1e-6)
    # the file states its TIS at the spectrum's incidence only (the first, as written)
    assert cmp["tis_file"][0] == pytest.approx(cmp["grid_measured"][0], rel=1e-6)
    assert cmp["tis_file"][1:].isna().all()
    # a 1 deg x 5 deg trapezoid grid over the whole hemisphere against the closed form
    np.testing.assert_allclose(cmp["grid_model"], cmp["tis_model"], rtol=2e-2)
