"""nk.plot_table: n and k against wavelength with their uncertainties."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

import labbrdf
from labbrdf import nk


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def al(fixtures_dir):
    return labbrdf.read(fixtures_dir / "ellipsometry" / "al_bare_wvase.dat")


def test_a_combined_table_draws_n_and_k_with_their_sigma_bands(al) -> None:
    table = nk.combined_table(al)
    ax_n, ax_k = nk.plot_table(table)
    for ax, q in ((ax_n, "n"), (ax_k, "k")):
        (line,) = ax.lines
        order = np.argsort(table["wavelength_nm"].to_numpy(), kind="stable")
        np.testing.assert_array_equal(line.get_xdata(), table["wavelength_nm"].to_numpy()[order])
        np.testing.assert_array_equal(line.get_ydata(), table[q].to_numpy()[order])
        (band,) = ax.collections
        # the band's outline reaches value + sigma and value - sigma
        y = band.get_paths()[0].vertices[:, 1]
        top = (table[q] + table[f"{q}_sigma"]).to_numpy()
        bottom = (table[q] - table[f"{q}_sigma"]).to_numpy()
        np.testing.assert_allclose(y.max(), top.max())
        np.testing.assert_allclose(y.min(), bottom.min())
        assert ax.get_xlabel() == "wavelength [nm]" and ax.get_ylabel() == f"{q} [1]"


def test_a_point_table_draws_one_series_per_angle_with_error_bars(al) -> None:
    table = nk.nk_table(al)
    ax_n, ax_k = nk.plot_table(table)
    angles = sorted(table["theta_i_deg"].round(2).unique())
    assert len(ax_n.containers) == len(angles) == 3
    for container, th in zip(ax_k.containers, angles, strict=True):
        g = table[table["theta_i_deg"].round(2) == th].sort_values("wavelength_nm")
        line = container.lines[0]
        np.testing.assert_array_equal(line.get_ydata(), g["k"].to_numpy())
        assert container.has_yerr
    assert ax_n.get_ylabel() == "<n> [1]"


def test_it_draws_on_given_axes_and_refuses_other_tables(al) -> None:
    fig, axes = plt.subplots(1, 2)
    out = nk.plot_table(nk.combined_table(al), ax=axes)
    assert list(out) == list(axes) and axes[0].lines
    with pytest.raises(ValueError, match="expected two Axes"):
        nk.plot_table(nk.combined_table(al), ax=axes[0])
    with pytest.raises(ValueError, match="not an n, k table"):
        nk.plot_table(al.data)


def test_a_series_is_labelled_by_member() -> None:
    import pandas as pd

    t = pd.DataFrame(
        {
            "wavelength_nm": [500.0, 600.0, 500.0, 600.0],
            "n": [1.0, 1.1, 2.0, 2.1],
            "k": [0.1, 0.2, 0.3, 0.4],
            "n_sigma": 0.01,
            "k_sigma": 0.02,
            "time_s": [0.0, 0.0, 5.0, 5.0],
        }
    )
    assert [lab for lab, _ in nk.series_members(t)] == ["time 0", "time 5"]
    ax_n, _ = nk.plot_table(t)
    assert [ln.get_label() for ln in ax_n.lines] == ["time 0", "time 5"]
    np.testing.assert_array_equal(ax_n.lines[1].get_ydata(), [2.0, 2.1])
