"""Render a report's ``results`` dict to one self-contained HTML page (Jinja2, autoescape on).

Everything that comes from files (sample names, header lines, comments) is plain text in
``results`` and is escaped by Jinja2's autoescaping; the only raw values on the page are the
base64 PNG data URIs of the figures and the ``#rrggbb`` colour swatches, both made by the
report itself. Table cells are rendered with :func:`labbrdf.report.builder.fmt` and carry
``data-key`` (a JSON pointer into ``results.json``) and ``data-fmt`` attributes.
"""

from __future__ import annotations

import base64
from collections.abc import Mapping
from typing import Any

import jinja2

from .builder import esc_pointer, fmt

__all__ = ["png_size", "render"]


def png_size(uri: str) -> tuple[int, int]:
    """Width and height [px] of a ``data:image/png;base64,...`` figure (its IHDR chunk).

    Raises
    ------
    ValueError
        Not a PNG.
    """
    head = base64.b64decode(uri.split(",", 1)[1][:32])  # the first 24 bytes
    if head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        raise ValueError("not a PNG")
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


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
        resources). Every figure is shown at its natural size (``width`` and ``height``
        attributes of its pixels, never scaled down: :mod:`labbrdf.figstyle` sizes it for
        that); one wider than the text column scrolls inside its own box.
    """
    for fid, uri in images.items():
        if not uri.startswith("data:image/png;base64,"):
            raise ValueError(f"figure {fid!r} is not an embedded PNG data URI")
    tpl = _env().get_template("report.html")
    sizes = {fid: png_size(uri) for fid, uri in images.items()}
    return tpl.render(r=results, images=images, sizes=sizes, swatches=swatches or {})
