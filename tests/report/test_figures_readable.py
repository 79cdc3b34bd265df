"""Every figure readable where it is shown: text size, width, legends and colour scales.

A browser shows a PNG at its natural size as 96 pixels per inch, so text of ``f`` points
in a figure saved at ``dpi`` appears at ``f * dpi / 96`` points. The report's text column
is 1100 CSS pixels wide; a figure no wider is shown whole, at its natural size.
"""

from __future__ import annotations

import base64
import importlib
import pkgutil
import re

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import LogNorm
from matplotlib.text import Text

import labbrdf
from labbrdf import Substrate, TraceConfig
from labbrdf.report import figures, html
from labbrdf.report.builder import Builder

MIN_SHOWN_PT = 9.0  # a printed footnote
COLUMN_PX = 1100  # the report's text column
N_SCAN_PANELS = 2
N_POLAR_CASES = 2


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _shown_pt(fig, dpi: float) -> float:
    """The smallest visible text of ``fig`` [pt] as shown at natural size."""
    fig.canvas.draw()
    sizes = [
        t.get_fontsize()
        for t in fig.findobj(Text)
        if t.get_visible() and t.get_text().strip() and (t.axes is None or t.axes.get_visible())
    ]
    return min(sizes) * dpi / 96.0


def _legends_over_data(fig) -> list[bool]:
    """For each legend of an axes: whether it reaches into the axes' data area."""
    fig.canvas.draw()
    out = []
    for ax in fig.axes:
        leg = ax.get_legend()
        if leg is not None:
            out.append(leg.get_window_extent().y1 > ax.get_window_extent().y0 + 1)
    return out


def _png_size(uri: str) -> tuple[int, int]:
    raw = base64.b64decode(uri.split(",", 1)[1])
    return int.from_bytes(raw[16:20], "big"), int.from_bytes(raw[20:24], "big")


def _spy(seen: list[dict], real):
    """A stand-in for ``figures.to_uri`` that records each figure before rendering it."""

    def spy(fig, dpi=None):
        kw = {} if dpi is None else {"dpi": dpi}
        used = dpi if dpi is not None else real.__defaults__[0]
        seen.append(
            {
                "fig": fig,
                "pt": _shown_pt(fig, used),
                "legends_over_data": _legends_over_data(fig),
                "fig_legends": list(fig.legends),
                "cbar_labels": [ax.get_ylabel() for ax in fig.axes],
                "norms": [c.norm for ax in fig.axes if ax.name == "polar" for c in ax.collections],
            }
        )
        return real(fig, **kw)

    return spy


#: the modules of the figure package that call ``to_uri`` (the spy replaces it in each)
_FIGURE_MODULES = [
    importlib.import_module(f"labbrdf.report.figures.{m.name}")
    for m in pkgutil.iter_modules(figures.__path__)
    if hasattr(importlib.import_module(f"labbrdf.report.figures.{m.name}"), "to_uri")
]


@pytest.fixture(scope="module")
def rendered():
    """Each maker's figure drawn once: name -> (record, PNG data URI)."""
    out = {}
    real = figures.to_uri
    with pytest.MonkeyPatch.context() as mp:
        for name, make in MAKERS.items():
            seen: list[dict] = []
            spy = _spy(seen, real)
            for module in _FIGURE_MODULES:  # every module that renders with to_uri
                mp.setattr(module, "to_uri", spy)
            uri = make()
            (entry,) = seen
            out[name] = (entry, uri)
            plt.close("all")
    return out


def _scan_series(n: int) -> list[dict]:
    tr = np.linspace(5.0, 85.0, 17)
    grid = np.linspace(0.0, 89.9, 121)
    out = []
    for k in range(n):
        ti = 15.0 + 5.0 * k
        v = 0.1 + np.exp(-(((tr - ti) / 8.0) ** 2))
        out.append(
            {
                "theta_i": ti,
                "theta_r": tr,
                "value": v,
                "sigma": 0.02 * v,
                "curve_theta_r": grid,
                "curves": {"smooth3": 0.1 + np.exp(-(((grid - ti) / 8.0) ** 2))},
                "residual": {"smooth3": np.zeros_like(tr)},
            }
        )
    return out


def _hemisphere_panel(ti: float) -> dict:
    th, ph = np.meshgrid(np.arange(2.0, 86.0, 6.0), np.arange(0.0, 181.0, 12.0))
    th, ph = th.ravel(), ph.ravel()
    meas = 0.05 + np.exp(-((th - ti) ** 2) / 50.0) * (ph > 150)
    return {
        "label": f"\u03b8i = {ti:g}\u00b0",
        "theta_r": th,
        "phi_r": ph,
        "measured": meas,
        "model": 1.1 * meas,
        "residual": np.full(th.size, 0.1),
    }


def _spike_map() -> np.ndarray:
    m = np.full((18, 72), 0.02)
    m[:, ::2] = 0.0
    m[9, 36] = 500.0  # the specular bin of a smooth surface
    return m


def _panel(title: str) -> dict:
    x = np.linspace(400.0, 800.0, 30)
    return {
        "title": title,
        "xlabel": "wavelength [nm]",
        "ylabel": "specular DOP, unpolarized incidence [1]",
        "series": [
            {"label": "ellipsometer |cos 2psi| (+-1 sigma)", "x": x, "y": x / 1e3},
            {"label": "tracer, specular bin (+-1 SE)", "x": x, "y": x / 1e3, "style": "points"},
        ],
    }


MAKERS = {
    "scan": lambda: figures.scan_figure(
        [{"label": f"S, {w} nm", "series": _scan_series(13)} for w in (400, 500)],
        title="S: measured scans and fitted models",
    ),
    "spectra": lambda: figures.spectra_figure(
        list("abcde"),
        {p: "sr-1" for p in "abcde"},
        [
            {
                "label": "S: fit (95% interval)",
                "wavelength": np.array([400.0, 550.0, 700.0]),
                "values": {p: np.array([1.0, 2.0, 3.0]) for p in "abcde"},
            }
        ],
    ),
    "compare": lambda: figures.compare_models_figure(
        [
            {
                "label": f"S, {w} nm",
                "theta_r": np.linspace(40, 50, 11),
                "value": np.linspace(1, 2, 11),
                "curve_theta_r": np.linspace(40, 50, 50),
                "curves": {"smooth3": np.linspace(1, 2, 50), "five_param": np.linspace(1, 2, 50)},
            }
            for w in (400, 500, 600, 700)
        ]
    ),
    "xy": lambda: figures.xy_figure(
        [{"x": [1, 2, 3], "y": [1, 4, 9], "label": "f00"}], "theta_r [deg]", "f [sr-1]"
    ),
    "hemispherical": lambda: figures.hemispherical_figure(
        {"label": "spectrophotometer", "wavelength": [400, 500, 600], "value": [0.5, 0.6, 0.7]},
        [{"label": "integral", "wavelength": [500], "value": [0.6]}],
    ),
    "spectrum": lambda: figures.spectrum_figure(
        [400, 500, 600], [0.5, 0.6, 0.7], [380, 500, 780], [0.5, 0.6, 0.7], title="S"
    ),
    "polar_maps": lambda: figures.polar_maps_figure(
        ["a", "b"],
        [_spike_map()] * N_POLAR_CASES,
        [np.full((18, 72), 0.5)] * N_POLAR_CASES,
        np.linspace(0, 90, 19),
        np.linspace(0, 360, 73),
        title="maps",
    ),
    "brdf_maps": lambda: figures.brdf_maps_figure([_hemisphere_panel(t) for t in (20, 50)]),
    "residual_grid": lambda: figures.brdf_residual_grid_figure(
        [_hemisphere_panel(t) for t in range(15, 76, 10)], title="residuals"
    ),
    "cuts": lambda: figures.brdf_cuts_figure(
        [
            {
                "label": f"\u03b8i = {t}\u00b0",
                "x": np.linspace(-80, 80, 17),
                "y": np.linspace(1, 2, 17),
                "grid": np.linspace(-85, 85, 60),
                "curves": {"model": np.linspace(1, 2, 60)},
                "specular": float(t),
            }
            for t in (15, 30, 45, 60, 75)
        ]
    ),
    "panels": lambda: figures.panels_figure(
        [_panel(f"{w} nm") for w in (400, 600, 1500, 2500)], ncols=4, panel_size=(2.9, 2.2)
    ),
    "stage_map": lambda: figures.map_figure(
        [
            {
                "title": f"{w} nm",
                "x": [0, 1, 2],
                "y": [0, 1, 0],
                "value": [1, 2, 3],
                "label": "d [nm]",
            }
            for w in (400, 500, 600)
        ]
    ),
}


@pytest.mark.parametrize("name", sorted(MAKERS))
def test_every_report_figure_is_readable_at_the_size_the_page_shows_it(name, rendered) -> None:
    entry, uri = rendered[name]
    assert entry["pt"] >= MIN_SHOWN_PT, (name, entry["pt"])
    width, _ = _png_size(uri)
    assert width <= COLUMN_PX, (name, width)  # shown whole, never scaled down


@pytest.mark.parametrize("name", ["scan", "compare", "cuts", "panels", "spectra"])
def test_legends_never_sit_on_the_data(name, rendered) -> None:
    entry, _ = rendered[name]
    # a legend of an axes hangs below it, outside the data area (or the figure has one)
    assert not any(entry["legends_over_data"]), name


def test_a_scan_of_many_incidences_colours_them_on_a_scale_and_keeps_a_short_legend(
    rendered,
) -> None:
    entry, _ = rendered["scan"]
    (legend,) = entry["fig_legends"]
    labels = [t.get_text() for t in legend.get_texts()]
    assert len(labels) <= 3, labels  # measured and the model, not 26 entries
    n_scales = sum("theta_i" in lab for lab in entry["cbar_labels"])
    assert n_scales == N_SCAN_PANELS  # one angle scale per panel


def test_a_specular_spike_puts_the_s0_map_on_a_log_scale_that_says_so(rendered) -> None:
    from labbrdf._plotting import map_scale

    assert map_scale(_spike_map())["log"]
    assert not map_scale(np.full((18, 72), 0.3))["log"]  # a diffuse map stays linear
    entry, _ = rendered["polar_maps"]
    assert sum(isinstance(n, LogNorm) for n in entry["norms"]) == N_POLAR_CASES
    assert sum("log scale" in lab for lab in entry["cbar_labels"]) == N_POLAR_CASES


def test_trace_png_is_a_readable_page_wide_figure(tmp_path) -> None:
    r = labbrdf.trace(
        TraceConfig(
            wavelength_nm=650,
            theta_i_deg=45,
            rays=2000,
            seed=1,
            substrate=Substrate(n=1.55, k=7.71, alpha=0.2),
            scattering="single",
            estimator="counting",
        )
    )
    fig = r.plot()
    assert _shown_pt(fig, fig.dpi) >= MIN_SHOWN_PT
    out = figures.save_trace_maps_png(r, tmp_path / "maps.png")
    raw = out.read_bytes()
    width = int.from_bytes(raw[16:20], "big")
    assert 900 <= width <= COLUMN_PX


def _page(uri: str, long_text: str) -> str:
    b = Builder("t")
    with b.section("s", "S"):
        b.figure("f", "F", "measured", uri)
        b.table(
            "t",
            "T",
            [("file", "file", ""), ("header", "header", "")],
            [{"file": "a.dat", "header": long_text}],
        )
    b.finish()
    return html.render(b.results, b.images, b.swatches)


def test_the_page_shows_figures_at_their_natural_size_and_long_cells_in_a_box(rendered) -> None:
    _, uri = rendered["xy"]
    page = _page(uri, "x" * 300)
    w, h = _png_size(uri)
    (img,) = re.findall(r"<img [^>]*>", page)
    assert f'width="{w}"' in img and f'height="{h}"' in img
    # nothing scales a figure down to the column: a wider one scrolls in its box
    css = re.search(r"figure img \{([^}]*)\}", page).group(1)
    assert "max-width: none" in css
    assert '<div class="figbox">' in page
    # a long text cell scrolls inside itself instead of widening the table
    assert '<div class="long">' + "x" * 300 + "</div>" in page
