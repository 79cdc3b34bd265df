"""Sphinx configuration of the labbrdf documentation site.

Built by ``make docs`` with warnings as errors. The pages in this folder are MyST Markdown
(they read as plain Markdown on a code host too); the API reference is generated from the
numpydoc docstrings, the command-line reference from the argument parser itself and the
formats table from the adapters' registry, so none of them can drift from the code.
"""

from __future__ import annotations

import re
import sys
import types
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

project = "labbrdf"
author = "the labbrdf developers"
copyright = "the labbrdf developers"  # noqa: A001 - Sphinx's name for it

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "sphinxarg.ext",
    "labbrdf_registry",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "api/generated/*.inc"]
myst_enable_extensions = ["colon_fence", "dollarmath"]
myst_heading_anchors = 3

autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "show-inheritance": True}
# numpydoc renumbers a docstring's citations per docstring; a module's reference list is
# cited from its functions' docstrings ("[2]_" in ``pseudo_nk`` names the module's [2]),
# which docutils sees as uncited
suppress_warnings = ["ref.citation"]
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# Every cross-reference to labbrdf's own objects must resolve; names outside the package
# (numpy, pandas, the standard library) are not linked, since the build has no network to
# fetch their inventories.
nitpicky = True
nitpick_ignore_regex = [(r"py:.*", r"(?!labbrdf\b).*")]

html_theme = "alabaster"
html_title = "labbrdf"
html_static_path = ["_static"]  # custom.css: code blocks wrap, the body takes the page
templates_path = ["_templates"]
html_theme_options = {
    "description": "Optical metrology of surfaces: files to fits to reports",
    "page_width": "1240px",  # command lines and tables need the width
}
smartquotes = False  # option names stay as typed (--format, not an en dash)


def _package_reexports(module: str, obj: object) -> bool:
    """Whether the package above ``module`` offers ``obj`` under the module's own name.

    ``labbrdf.report.validate`` (function) shadows its module; ``labbrdf.specular_dop``
    stays the module, so the function of that name is documented on the module's page.
    """
    import importlib

    parent, _, name = module.rpartition(".")
    return getattr(importlib.import_module(parent), name, None) is obj


def _top_level() -> dict[str, object]:
    import labbrdf

    return {name: getattr(labbrdf, name) for name in labbrdf._LAZY}


def _skip_shadowed(app, what, name, obj, skip, options):  # noqa: ANN001, ANN202, ARG001
    """Skip a package attribute named like one of its submodules.

    ``labbrdf.report.validate`` is both a function (re-exported by the package) and a
    module; the function is documented on its module's page, where it is defined. A class
    that ``labbrdf`` offers at the top (``Substrate``) is documented once, as
    ``labbrdf.Substrate``, not again on the pages of the modules that define or re-export it.
    """
    if isinstance(obj, types.GenericAlias):
        return True  # a type alias (``Section``): autodoc cannot sign it; its #: comment stays
    module = getattr(obj, "__module__", None) or ""
    if what == "module" and module.endswith("." + name) and _package_reexports(module, obj):
        return True
    if what == "module" and isinstance(obj, type) and _top_level().get(name) is obj:
        return True  # a class labbrdf offers at the top is documented once, there

    return None


_LITERAL = re.compile(r"``.*?``")
_BARS = re.compile(r"(?<![|\\])\|(?=[^\s|=+-])([^|`\n]*?[^\s|\\])\|(?![|_])")
_CITE = re.compile(r"\[(\d+)\]_")


def _plain_math(app, what, name, obj, options, lines):  # noqa: ANN001, ANN202, ARG001
    """Read the docstrings' plain notation as the text it is, before numpydoc parses them.

    The docstrings write absolute values and norms as ``|x|`` (never rST substitutions,
    which this project does not use), and a function cites its module's numbered reference
    list as ``[2]_`` (numpydoc would only link a citation defined in the same docstring).
    """
    own = {m.group(1) for line in lines for m in re.finditer(r"^\.\. \[(\d+)\]", line.strip())}
    for i, line in enumerate(lines):
        parts = re.split(r"(``.*?``)", line)
        for j in range(0, len(parts), 2):  # outside inline literals only
            text = _BARS.sub(r"\\|\1\\|", parts[j])
            parts[j] = _CITE.sub(
                lambda m: m.group(0) if m.group(1) in own else m.group(0)[:-1], text
            )
        lines[i] = "".join(parts)


def setup(app):  # noqa: ANN001, ANN201
    """Connect the skip rule and the docstring reading (before numpydoc's, priority 100)."""
    app.connect("autodoc-skip-member", _skip_shadowed)
    app.connect("autodoc-process-docstring", _plain_math, priority=100)
