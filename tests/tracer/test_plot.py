"""TraceResult.plot and its in-plane cut: the S0 and DOP maps and the plane of incidence."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

import labbrdf
from labbrdf import Substrate, TraceConfig
from labbrdf.tracer.result import DOP_SE_MAX, MIN_COUNT, SHOW_COUNT


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _trace(estimator: str) -> labbrdf.TraceResult:
    return labbrdf.trace(
        TraceConfig(
            wavelength_nm=650,
            theta_i_deg=45,
            rays=20_000,
            seed=3,
            substrate=Substrate(n=1.55, k=7.71, alpha=0.3),
            scattering="single",
            estimator=estimator,
            theta_step_deg=6,
            phi_step_deg=6,
        )
    )


@pytest.fixture(scope="module")
def counting():
    return _trace("counting")


@pytest.fixture(scope="module")
def evaluated():
    return _trace("evaluated")


def test_the_in_plane_cut_takes_both_half_planes_of_incidence(counting) -> None:
    c = counting.in_plane()
    th = counting.theta_r_deg
    n = th.size
    np.testing.assert_array_equal(c["theta_deg"], np.concatenate([-th[::-1], th]))
    np.testing.assert_array_equal(c["phi_r_deg"], [0.0, 180.0])  # bins centred on the plane
    j0 = int(np.flatnonzero(counting.phi_r_deg == 0.0)[0])
    j180 = int(np.flatnonzero(counting.phi_r_deg == 180.0)[0])
    s0 = counting.mueller[..., 0, 0]
    np.testing.assert_array_equal(c["s0"][:n], s0[::-1, j0])
    np.testing.assert_array_equal(c["s0"][n:], s0[:, j180])
    np.testing.assert_array_equal(c["s0_stderr"][n:], counting.mueller_stderr[:, j180, 0, 0])
    # the specular lobe is on the positive side, at theta_r near theta_i
    assert abs(c["theta_deg"][np.argmax(c["s0"])] - 45.0) <= 6.0


def test_polarized_input_has_no_s0_error_from_the_diagonal(counting) -> None:
    c = counting.in_plane((1.0, 1.0, 0.0, 0.0))
    assert np.isnan(c["s0_stderr"]).all()
    j180 = int(np.flatnonzero(counting.phi_r_deg == 180.0)[0])
    n = counting.theta_r_deg.size
    np.testing.assert_array_equal(c["s0"][n:], counting.s0((1, 1, 0, 0))[:, j180])


def test_the_dop_is_shown_only_where_it_can_be_read(counting, evaluated) -> None:
    d = counting.readable_dop()
    few = counting.counts < SHOW_COUNT
    assert few.any() and (~few).any()
    assert np.isnan(d[few]).all()
    np.testing.assert_array_equal(d[~few], counting.dop()[~few])
    e = evaluated.readable_dop()
    noisy = ~(evaluated.dop_stderr() <= DOP_SE_MAX)
    assert np.isnan(e[noisy]).all()
    np.testing.assert_array_equal(e[~noisy], evaluated.dop()[~noisy])


def test_the_s0_scale_ends_at_the_largest_well_populated_bin(counting, evaluated) -> None:
    ok = counting.counts >= MIN_COUNT
    assert counting.s0_scale_max() == counting.mueller[..., 0, 0][ok].max()
    assert evaluated.s0_scale_max() is None


def test_the_figure_carries_the_maps_and_the_cut(counting) -> None:
    fig = counting.plot()
    ax_s0, cb_s0, ax_dop, cb_dop, ax_cut, ax_twin = _axes(fig)
    (mesh_s0,) = ax_s0.collections
    (mesh_dop,) = ax_dop.collections
    np.testing.assert_array_equal(mesh_s0.get_array().ravel(), counting.s0().ravel())
    dop = np.ma.masked_invalid(counting.readable_dop())
    got = mesh_dop.get_array()
    np.testing.assert_array_equal(np.ma.getmaskarray(got).ravel(), dop.mask.ravel())
    np.testing.assert_array_equal(got.compressed(), dop.compressed())
    assert mesh_s0.get_clim() == (0.0, counting.s0_scale_max())
    assert mesh_dop.get_clim() == (0.0, 1.0)
    c = counting.in_plane()
    (s0_line,) = ax_cut.lines
    np.testing.assert_array_equal(s0_line.get_ydata(), c["s0"])
    (dop_line,) = ax_twin.lines
    np.testing.assert_array_equal(dop_line.get_xdata(), c["theta_deg"])
    np.testing.assert_array_equal(dop_line.get_ydata(), c["dop"])


def _axes(fig):
    polar = [a for a in fig.axes if a.name == "polar"]
    plain = [a for a in fig.axes if a.name != "polar"]
    cbars = [a for a in plain if a.get_label() == "<colorbar>"]
    cut = [a for a in plain if a.get_label() != "<colorbar>"]
    assert len(polar) == 2 and len(cbars) == 2 and len(cut) == 2
    return polar[0], cbars[0], polar[1], cbars[1], cut[0], cut[1]


def test_it_draws_on_given_axes_the_first_two_polar(counting) -> None:
    fig = plt.figure()
    axes = [fig.add_subplot(1, 3, 1, projection="polar"), fig.add_subplot(1, 3, 2)]
    axes.append(fig.add_subplot(1, 3, 3))
    with pytest.raises(ValueError, match="projection='polar'"):
        counting.plot(ax=axes)
    fig = plt.figure()
    axes = [fig.add_subplot(1, 3, i + 1, projection="polar" if i < 2 else None) for i in range(3)]
    assert counting.plot(ax=axes) is fig
    with pytest.raises(ValueError, match="stokes_in"):
        counting.plot(stokes_in=(1.0, 2.0, 0.0, 0.0))
