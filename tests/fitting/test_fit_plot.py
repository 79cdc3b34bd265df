"""FitResult.plot: the data with their sigmas, the fitted model and the residuals."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

import labbrdf
from labbrdf import models
from labbrdf.fitting import FitData, fit


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def osr_550(fixtures_dir):
    scan = labbrdf.read(fixtures_dir / "specular" / "osr_specular.csv")
    return scan.data[scan.data.wavelength_nm == 550]


@pytest.fixture(scope="module")
def result(osr_550):
    return fit("smooth3", osr_550)


def _groups(data):
    return sorted(data.groupby("theta_i_deg"), key=lambda kv: kv[0])


def test_the_data_are_drawn_with_their_file_sigmas(result, osr_550) -> None:
    fig = result.plot()
    ax, axr = fig.axes
    bars = ax.containers
    groups = _groups(osr_550)
    assert len(bars) == len(groups) == 3
    for container, (_, g) in zip(bars, groups, strict=True):
        g = g.sort_values("theta_r_deg", kind="stable")
        line, _, (segments,) = container
        np.testing.assert_array_equal(line.get_xdata(), g["theta_r_deg"].to_numpy())
        np.testing.assert_array_equal(line.get_ydata(), g["value"].to_numpy())
        # each error bar spans value -+ sigma
        spans = np.array([s[:, 1] for s in segments.get_segments()])
        np.testing.assert_allclose(spans[:, 1] - spans[:, 0], 2 * g["sigma"].to_numpy())


def test_the_model_line_is_the_fitted_model(result, osr_550) -> None:
    ax = result.plot().axes[0]
    model = models.get("smooth3")
    curves = [ln for ln in ax.lines if ln.get_gid() == "model"]
    assert len(curves) == 3
    for ln, (ti, _) in zip(curves, _groups(osr_550), strict=True):
        x = np.asarray(ln.get_xdata(), float)
        expect = model.evaluate(
            np.radians(ti), np.radians(x), np.pi, wavelength=550.0, params=result.values
        )
        np.testing.assert_allclose(ln.get_ydata(), expect, rtol=1e-12)
        assert x.size == 121


def test_the_residuals_below_are_the_data_minus_the_fit(result, osr_550) -> None:
    axr = result.plot().axes[1]
    points = [ln for ln in axr.lines if ln.get_label() == "y - f"]
    assert len(points) == 3
    got = np.concatenate([ln.get_ydata() for ln in points])
    # independent of the plot: value - model at the data points
    d = osr_550.sort_values(["theta_i_deg", "theta_r_deg"], kind="stable")
    f = models.get("smooth3").evaluate(
        np.radians(d["theta_i_deg"].to_numpy()),
        np.radians(d["theta_r_deg"].to_numpy()),
        np.pi,
        wavelength=550.0,
        params=result.values,
    )
    np.testing.assert_allclose(got, d["value"].to_numpy() - f, rtol=1e-9, atol=1e-15)
    assert "residual" in axr.get_ylabel()


def test_it_draws_on_given_axes(result) -> None:
    fig, (a, b) = plt.subplots(2)
    assert result.plot(ax=(a, b)) is fig
    assert a.containers and b.lines
    with pytest.raises(ValueError, match="expected two Axes"):
        result.plot(ax=a)


def test_a_model_outside_the_registry_is_drawn_through_the_data_points(result, osr_550) -> None:
    class Custom(models.get("smooth3").__class__):
        name = "my_smooth3"

    res = fit(Custom(), osr_550)
    ax = res.plot().axes[0]
    curves = [ln for ln in ax.lines if ln.get_gid() == "model"]
    got = np.concatenate([ln.get_ydata() for ln in curves])
    d = osr_550.reset_index(drop=True)
    order = np.lexsort((d["theta_r_deg"].to_numpy(), d["theta_i_deg"].to_numpy()))
    np.testing.assert_allclose(got, res.best_fit[order])


def test_a_result_without_data_or_of_a_film_fit_says_why_it_cannot_plot(result) -> None:
    import dataclasses

    with pytest.raises(ValueError, match="carries no data"):
        dataclasses.replace(result, data=None).plot()
    film = FitData([60.0, 70.0], [60.0, 70.0], [1.0, 2.0], quantity="film", unit="mixed")
    with pytest.raises(ValueError, match="film fit"):
        dataclasses.replace(result, data=film).plot()


@pytest.fixture(scope="module")
def hemispherical():
    """A five_param fit to points over the whole hemisphere at two incidences."""
    ti, tr, pr = np.meshgrid([30.0, 60.0], np.arange(5.0, 86.0, 10.0), np.arange(0.0, 181.0, 20.0))
    ti, tr, pr = ti.ravel(), tr.ravel(), pr.ravel()
    model = models.get("five_param")
    y = model.evaluate(np.radians(ti), np.radians(tr), np.radians(pr), params=model.values())
    data = FitData(ti, tr, y * (1.0 + 0.05 * np.cos(3.0 * np.radians(pr))), phi_r_deg=pr)
    return fit("five_param", data, maxeval=[60, 60])


def test_hemispherical_data_are_drawn_as_maps_not_one_line_per_scan(hemispherical) -> None:
    fig = hemispherical.plot()
    maps = [ax for ax in fig.axes if ax.collections and ax.get_aspect() == 1.0]
    assert len(maps) == 2 * 3  # measured, model and residual per incidence
    # guide circles only: the 20 scans of each incidence are not drawn as lines
    assert sum(len(ax.lines) for ax in fig.axes) <= 3 * len(maps)
    (measured,) = maps[0].collections
    # the measured map spans the data of its incidence (log colour scale)
    d = hemispherical.data
    y30 = np.asarray(d.value)[np.asarray(d.theta_i_deg) == 30.0]
    assert measured.norm.vmax == pytest.approx(
        max(y30.max(), hemispherical.best_fit[np.asarray(d.theta_i_deg) == 30.0].max())
    )
    with pytest.raises(ValueError, match="maps"):
        hemispherical.plot(ax=plt.subplots(2)[1])
