"""A film fit shows itself as a fit does: fit_report, str, _repr_html_ and plot()."""

from __future__ import annotations

import matplotlib
import numpy as np
import pandas as pd
import pytest

from labbrdf.films import FilmModel, Layer, Stack
from labbrdf.fitting.film import fit_film
from labbrdf.nk.dispersion import Cauchy

matplotlib.use("Agg")

TRUE = Stack([Layer(Cauchy(A=1.46, B=0.004), 105.0, "film")], "si")
BOX = {"film.thickness_nm": (0.0, 300.0), "film.A": (1.3, 1.8), "film.B": (0.0, 0.03)}


def _rows(quantity, w, t, value, sigma, channel=""):
    unit = "deg" if quantity in ("psi", "delta") else "1"
    return pd.DataFrame({"sample": "s", "instrument": "sim", "source": f"{quantity}.dat",
                         "quantity": quantity, "channel": channel, "value": value,
                         "sigma": sigma, "unit": unit, "wavelength_nm": w, "theta_i_deg": t,
                         "theta_r_deg": t, "phi_r_deg": 180.0})  # fmt: skip


@pytest.fixture(scope="module")
def fit():
    """psi/Delta at 60 and 70 deg and s-polarised R at 60 deg of an oxide on silicon."""
    rng = np.random.default_rng(1)
    W, T = np.meshgrid(np.linspace(300, 1000, 30), [60.0, 70.0], indexing="ij")
    w, t = W.ravel(), T.ravel()
    psi, delta = TRUE.psi_delta(w, t)
    rs, _ = TRUE.reflectance(w[t == 60], t[t == 60])
    data = pd.concat(
        [
            _rows("psi", w, t, psi + rng.normal(0, 0.02, w.size), 0.02),
            _rows("delta", w, t, np.mod(delta + rng.normal(0, 0.05, w.size), 360), 0.05),
            _rows("reflectance", w[t == 60], 60.0, rs + rng.normal(0, 0.005, rs.size), 0.005, "s"),
        ],
        ignore_index=True,
    )
    return fit_film(FilmModel(TRUE, BOX), data, seed=0, ci="wald")


def test_fit_report_is_the_text_of_the_summary_and_str(fit):
    text = fit.fit_report()
    assert str(fit) == text
    lines = text.splitlines()
    assert lines[0] == "layer film (cauchy)"
    thickness = next(x for x in lines if x.strip().startswith("thickness_nm")).split()
    assert float(thickness[1]) == pytest.approx(fit.summary()["layers"][0]["parameters"][
        "thickness_nm"]["value"], rel=1e-5)  # fmt: skip
    assert any(x.startswith("  n, k at 633 nm: ") for x in lines)
    assert "substrate: " in text
    s = fit.summary()
    assert f"fit: {s['ndata']} values, 300-1000 nm, 3 free; chi2/nu = {s['redchi']:.4g}" in text


def test_repr_html_shows_every_parameter_escaped(fit):
    h = fit._repr_html_()
    assert h.startswith("<div><strong>Film fit: film on si (reference table, Green 2008)</strong>")
    for name in ("thickness_nm", "A", "B", "C"):
        assert f">{name}</td>" in h
    assert "MSE (Woollam)" in h and "+-" in h
    assert "<script" not in h


def test_plot_draws_data_fit_and_residuals_per_channel(fit):
    fig = fit.plot()
    axes = fig.axes
    assert len(axes) == 6  # psi, Delta, R_s: data above, residuals below
    assert [a.get_title() for a in axes[3:]][-1] == "R_s residual (band: 1 sigma)"
    titles = [a.get_title() for a in axes]
    assert titles[:3] == [  # the top row: the data
        "psi: measured and fit",
        "delta: measured and fit",
        "R_s: measured and fit",
    ]
    d = fit.data
    rs = fit.channels == 2
    fit_line = axes[2].get_lines()[1]  # the first angle's fit line on the R_s panel
    x = d["wavelength_nm"].to_numpy()[rs]
    model = d["value"].to_numpy()[rs] - np.asarray(fit.result.residual)[rs]
    np.testing.assert_allclose(fit_line.get_xdata(), x)
    np.testing.assert_allclose(fit_line.get_ydata(), model)
    np.testing.assert_allclose(model, TRUE.reflectance(x, 60.0)[0], atol=0.01)
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_plot_into_given_axes_needs_two_per_channel(fit):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 2)
    with pytest.raises(ValueError, match="expected 6 Axes"):
        fit.plot(ax)
    plt.close(fig)
