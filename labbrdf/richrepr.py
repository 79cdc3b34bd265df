"""HTML for notebooks: the ``_repr_html_`` of datasets, fits and traces.

Plain strings built with :func:`html.escape` (no Jinja2, no pandas): the result objects of
every layer may use it, as Jupyter calls ``_repr_html_`` to show an object, the way lmfit's
and pandas' results show themselves.
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Sequence
from typing import Any

__all__ = ["card"]

_STYLE = "border-collapse:collapse;font-size:0.9em;margin:0.3em 0;font-family:system-ui,sans-serif"
_CELL = "border:1px solid #ccc;padding:2px 6px;text-align:left"


def _cell(value: Any, tag: str = "td") -> str:
    return f'<{tag} style="{_CELL}">{html.escape(str(value))}</{tag}>'


def card(
    title: str,
    facts: Iterable[tuple[str, Any]],
    table: tuple[Sequence[str], Iterable[Sequence[Any]]] | None = None,
    extra_html: str = "",
) -> str:
    """A titled block: key-value facts, an optional table, and already-safe extra HTML.

    Parameters
    ----------
    title : str
        Heading (escaped).
    facts : iterable of (str, value)
        One row each, key and value (both escaped).
    table : (header, rows), optional
        Column names and rows of values (escaped).
    extra_html : str
        HTML appended as is: only from a trusted renderer (``DataFrame.to_html``).

    Returns
    -------
    str
        An HTML fragment.
    """
    out = [f"<div><strong>{html.escape(title)}</strong>", f'<table style="{_STYLE}">']
    out += [f"<tr>{_cell(k, 'th')}{_cell(v)}</tr>" for k, v in facts]
    out.append("</table>")
    if table is not None:
        header, rows = table
        out.append(f'<table style="{_STYLE}"><tr>')
        out += [_cell(h, "th") for h in header]
        out.append("</tr>")
        out += ["<tr>" + "".join(_cell(v) for v in row) + "</tr>" for row in rows]
        out.append("</table>")
    out.append(extra_html)
    out.append("</div>")
    return "".join(out)
