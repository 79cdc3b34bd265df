"""The one figure style of the package: sizes, resolution and fonts of every figure.

Every figure (the report's PNGs, ``trace --png``, the ``plot()`` methods) is drawn inside
:func:`rc_context` and sized with the constants here, so that its text is readable where it
is shown.

The rule: a browser shows an image at its natural size as 96 image pixels per inch (the CSS
pixel), so a figure saved at ``DPI = 96`` shows each of its points as one point on the
screen; its smallest text (:data:`MIN_PT`) is then 9 pt, the size of a printed footnote. The
widest figure (:data:`PAGE_WIDTH_IN`) fits the report's text column (1100 CSS px) without
being scaled down; wider content (many panels) wraps into rows rather than shrinking.
Nothing here imports matplotlib until a figure is drawn.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

__all__ = [
    "BASE_PT",
    "DPI",
    "MIN_PT",
    "PAGE_WIDTH_IN",
    "PANEL_MIN_IN",
    "RC",
    "TITLE_PT",
    "grid_shape",
    "rc_context",
    "shown_pt",
    "smallest_text_pt",
    "styled",
]

#: resolution of every saved figure [dots per inch]: one figure point = one CSS point
DPI = 96
#: text of axis labels and titles [pt]
BASE_PT = 10.0
#: the smallest text: ticks, legends, colour bars, notes [pt]
MIN_PT = 9.0
#: figure titles [pt]
TITLE_PT = 11.0
#: widest figure [inch]: 1056 px at DPI, inside the report's 1100 px column
PAGE_WIDTH_IN = 11.0
#: smallest panel of a grid of panels (width, height) [inch]
PANEL_MIN_IN = (2.7, 2.4)

#: matplotlib rcParams of every figure
RC: dict[str, Any] = {
    "figure.dpi": DPI,
    "savefig.dpi": DPI,
    "font.size": BASE_PT,
    "axes.titlesize": BASE_PT,
    "axes.labelsize": BASE_PT,
    "xtick.labelsize": MIN_PT,
    "ytick.labelsize": MIN_PT,
    "legend.fontsize": MIN_PT,
    "legend.title_fontsize": MIN_PT,
    "figure.titlesize": TITLE_PT,
    "lines.linewidth": 1.3,
    "lines.markersize": 4.5,
    "axes.grid": False,
}

F = TypeVar("F", bound=Callable[..., Any])


@contextmanager
def rc_context() -> Iterator[None]:
    """Draw inside the package's style (matplotlib ``rc_context`` with :data:`RC`)."""
    import matplotlib

    with matplotlib.rc_context(RC):  # type: ignore[arg-type]  # str keys, checked by mpl
        yield


def styled(func: F) -> F:
    """Decorator: run a figure-making function inside :func:`rc_context`."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with rc_context():
            return func(*args, **kwargs)

    return wrapper  # type: ignore[return-value]


def grid_shape(n: int, ncols: int, panel_w_in: float) -> tuple[int, int, float]:
    """Rows, columns and panel width [inch] of ``n`` panels that fit :data:`PAGE_WIDTH_IN`.

    Parameters
    ----------
    n : int
        Number of panels.
    ncols : int
        Columns asked for.
    panel_w_in : float
        Panel width asked for [inch]; at least ``PANEL_MIN_IN[0]``.

    Returns
    -------
    nrows, ncols : int
    panel_w_in : float
        The columns are reduced until they fit the page at the asked width (never below
        the smallest panel); the width is reduced to the page's share if needed.
    """
    n = max(1, int(n))
    w = max(float(panel_w_in), PANEL_MIN_IN[0])
    ncols = max(1, min(int(ncols), n, int(PAGE_WIDTH_IN // PANEL_MIN_IN[0])))
    while ncols > 1 and ncols * w > PAGE_WIDTH_IN:
        if PAGE_WIDTH_IN / ncols >= PANEL_MIN_IN[0]:
            w = PAGE_WIDTH_IN / ncols
            break
        ncols -= 1
    w = min(w, PAGE_WIDTH_IN / ncols)
    return -(-n // ncols), ncols, w


def shown_pt(fontsize_pt: float, dpi: float = DPI) -> float:
    """Size [pt] of ``fontsize_pt`` text of a figure saved at ``dpi``, shown at natural size.

    A browser shows an image pixel as one CSS pixel (1/96 inch).
    """
    return float(fontsize_pt) * float(dpi) / 96.0


def smallest_text_pt(fig: Any, dpi: float = DPI) -> float:
    """The smallest visible, non-empty text of ``fig`` [pt] as shown at natural size."""
    from matplotlib.text import Text

    fig.canvas.draw()  # tick labels exist once drawn
    sizes = [
        t.get_fontsize()
        for t in fig.findobj(Text)
        if t.get_visible() and t.get_text().strip() and _on_canvas(t)
    ]
    return shown_pt(min(sizes), dpi) if sizes else float("inf")


def _on_canvas(t: Any) -> bool:
    """Whether a text artist's axes (if any) is visible: hidden panels keep their ticks."""
    ax = t.axes
    return ax is None or ax.get_visible()
