"""What every report figure shares: the Agg backend, the layout, the PNG data URI, the PNG file.

Every figure function of :mod:`labbrdf.report.figures` ends in :func:`to_uri` (directly or
through :func:`finish`, :func:`finish_below` or :func:`finish_grid`), which renders the
figure at :data:`labbrdf.figstyle.DPI` and closes it.
"""

from __future__ import annotations

import base64
import io
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from ..._plotting import legend_outside  # noqa: E402
from ..._plotting import text as _text  # noqa: E402
from ...figstyle import DPI  # noqa: E402

__all__ = ["finish", "finish_below", "finish_grid", "layout", "save_png", "to_uri"]


def to_uri(fig: Figure, dpi: int = DPI) -> str:
    """Render ``fig`` to PNG and return it as a data URI; the figure is closed."""
    buf = io.BytesIO()
    try:
        fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def layout(fig: Any, title: str | None) -> None:
    """The figure's title (if any) in a band of its own above the tight layout."""
    if not title:
        fig.tight_layout()
        return
    fig.suptitle(_text(title))
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - 0.32 / fig.get_size_inches()[1]))


def finish(fig: Any, ax: Any, title: str | None) -> str:
    """Grid, title and the legend below the axes, then the figure as a PNG data URI."""
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(_text(title))
    fig.tight_layout()
    legend_outside(ax, ncol=2)
    return to_uri(fig)


def finish_below(fig: Any, ax: Any, title: str | None) -> str:
    """Title, tight layout and the legend of ``ax`` below the figure, as a PNG data URI."""
    layout(fig, title)
    legend_outside(ax)
    return to_uri(fig)


def finish_grid(fig: Any, title: str | None) -> str:
    """Figure title (if any), tight layout, then the figure as a PNG data URI."""
    layout(fig, title)
    return to_uri(fig)


def save_png(uri: str, path: Any) -> Any:
    """Write a figure's PNG data URI to ``path`` atomically (never a half-written file).

    Parameters
    ----------
    uri : str
        ``data:image/png;base64,...`` as the figure functions return it.
    path : path-like
        Output ``.png``.

    Returns
    -------
    pathlib.Path
    """
    from pathlib import Path

    from labbrdf.outputs import atomic_output

    data = base64.b64decode(uri.split(",", 1)[1])
    with atomic_output(path) as tmp:
        Path(tmp).write_bytes(data)
    return Path(path)
