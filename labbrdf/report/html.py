"""Render a report's ``results`` dict to one self-contained HTML page (Jinja2, autoescape on).

Everything that comes from files (sample names, header lines, comments) is plain text in
``results`` and is escaped by Jinja2's autoescaping; the only raw values on the page are the
base64 PNG data URIs of the figures and the ``#rrggbb`` colour swatches, both made by the
report itself. Table cells are rendered with :func:`labbrdf.report.builder.fmt` and carry
``data-key`` (a JSON pointer into ``results.json``) and ``data-fmt`` attributes.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import jinja2

from .builder import esc_pointer, fmt

__all__ = ["render"]


def _env() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("labbrdf.report", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.filters["fmt"] = fmt
    env.filters["ptr"] = esc_pointer
    return env


def render(
    results: Mapping[str, Any],
    images: Mapping[str, str],
    swatches: Mapping[str, str] | None = None,
) -> str:
    """The HTML page for ``results``.

    Parameters
    ----------
    results : mapping
        The JSON-safe results (as written to ``results.json``).
    images : mapping
        Figure id -> ``data:image/png;base64,...`` URI.
    swatches : mapping, optional
        Swatch id -> ``#rrggbb``.

    Returns
    -------
    str
        One self-contained HTML document (inline CSS, embedded figures, no external
        resources).
    """
    for fid, uri in images.items():
        if not uri.startswith("data:image/png;base64,"):
            raise ValueError(f"figure {fid!r} is not an embedded PNG data URI")
    tpl = _env().get_template("report.html")
    return tpl.render(r=results, images=images, swatches=swatches or {})
