"""Sphinx directive ``labbrdf-formats``: the table of export formats, from the registry.

The table is built from :func:`labbrdf.adapters.formats` at build time, so the documented
list of formats is the list the code reads.
"""

from __future__ import annotations

from typing import Any

from docutils import nodes
from sphinx.util.docutils import SphinxDirective


class FormatsTable(SphinxDirective):
    """Insert one row per registered format: name, kind, extensions, what it reads."""

    has_content = False

    def run(self) -> list[nodes.Node]:
        """The table node, one row per format of the registry."""
        from labbrdf import adapters

        rows = adapters.formats()
        table = nodes.table()
        group = nodes.tgroup(cols=5)
        table += group
        for width in (18, 8, 14, 44, 16):
            group += nodes.colspec(colwidth=width)
        head = nodes.thead()
        group += head
        head += self._row(
            ["format (--format)", "kind", "file endings", "what it reads", "quantities"]
        )
        body = nodes.tbody()
        group += body
        for row in rows:
            body += self._row(
                [
                    row["name"],
                    row["kind"],
                    ", ".join(row["extensions"]) or "-",
                    row["description"],
                    ", ".join(row["quantities"]),
                ]
            )
        return [table]

    @staticmethod
    def _row(cells: list[str]) -> nodes.row:
        row = nodes.row()
        for text in cells:
            entry = nodes.entry()
            entry += nodes.paragraph(text=text)
            row += entry
        return row


def setup(app: Any) -> dict[str, Any]:
    """Register the directive with Sphinx."""
    app.add_directive("labbrdf-formats", FormatsTable)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
