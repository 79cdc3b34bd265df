"""The house rules of the package that a linter does not check.

Functions stay short enough to read: none of 60 statements or more (counted as Python
sees them: a docstring, comments and a call spread over lines for its keywords do not
count, every statement inside the function's blocks does), except those listed in
``long_functions.json`` beside this file (the baseline of the day the rule was made), and a
listed one may only shrink. Break a long function into named steps; when one falls under
the limit, remove it from the baseline. Modules follow a rule of 800 lines
(``long_modules.json``): split a module by its jobs before it grows past the limit.

Imports: no module imports, directly or through others, a module that imports it back,
whether at the top or inside a function (imports under ``if TYPE_CHECKING:`` are type
annotations, not imports at run time); a report section imports no other section (shared
helpers live in report-level modules); and every import runs down the layers of
:data:`LAYERS` (or within one), from the command line down to the physics.
"""

from __future__ import annotations

import ast
import json
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "labbrdf"
BASELINE = Path(__file__).with_name("long_functions.json")
LIMIT = 60
MODULE_BASELINE = Path(__file__).with_name("long_modules.json")
MODULE_LIMIT = 800


def statements(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """The statements of a function: every one in its blocks, its docstring left out.

    A nested function or class counts as one statement here (its own body is counted as a
    function of its own).
    """
    body = list(fn.body)
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]  # the docstring
    count, todo = 0, body
    while todo:
        st = todo.pop()
        count += 1
        if isinstance(st, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            continue
        for name in ("body", "orelse", "finalbody"):
            todo.extend(getattr(st, name, ()))
        for part in (*getattr(st, "handlers", ()), *getattr(st, "cases", ())):
            todo.extend(part.body)
    return count


def long_functions() -> dict[str, int]:
    """``module.py:qualname`` -> statements, for every function of LIMIT statements or more."""
    out: dict[str, int] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        stack: list[tuple[ast.AST, str]] = [(tree, "")]
        while stack:
            node, prefix = stack.pop()
            for child in ast.iter_child_nodes(node):
                if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                    name = f"{prefix}{child.name}"
                    if not isinstance(child, ast.ClassDef):
                        length = statements(child)
                        if length >= LIMIT:
                            out[f"{path.relative_to(PACKAGE).as_posix()}:{name}"] = length
                    stack.append((child, name + "."))
    return out


def test_no_function_grows_past_the_limit() -> None:
    baseline = json.loads(BASELINE.read_text(encoding="utf-8"))
    now = long_functions()
    new = {k: v for k, v in now.items() if k not in baseline}
    grown = {k: (baseline[k], v) for k, v in now.items() if k in baseline and v > baseline[k]}
    assert not new, f"functions of {LIMIT} statements or more: {new}; break them into steps"
    assert not grown, f"listed long functions grew (baseline, now): {grown}"


def test_the_baseline_lists_only_functions_that_are_still_long() -> None:
    baseline = json.loads(BASELINE.read_text(encoding="utf-8"))
    gone = sorted(set(baseline) - set(long_functions()))
    assert not gone, f"now under {LIMIT} statements, remove from long_functions.json: {gone}"


def test_statements_are_counted_not_lines() -> None:
    code = '''
def f(x):
    """A docstring

    of several lines.
    """
    # a comment
    y = g(
        x,
        1,
    )
    if y:
        for i in y:
            x += i
    else:
        x = 0
    try:
        pass
    except ValueError:
        return 1
    def inner():
        return 2
    return x
'''
    fn = ast.parse(code).body[0]
    assert isinstance(fn, ast.FunctionDef)
    # y=, if, for, x+=, x=0, try, pass, return 1, def inner, return x
    assert statements(fn) == 10


# ----------------------------------------------------------------------------- modules


def long_modules() -> dict[str, int]:
    """``path`` -> lines, for every module of MODULE_LIMIT lines or more."""
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        n = len(path.read_text(encoding="utf-8").splitlines())
        if n >= MODULE_LIMIT:
            out[path.relative_to(PACKAGE).as_posix()] = n
    return out


def test_no_module_grows_past_the_limit() -> None:
    baseline = json.loads(MODULE_BASELINE.read_text(encoding="utf-8"))
    now = long_modules()
    new = {k: v for k, v in now.items() if k not in baseline}
    grown = {k: (baseline[k], v) for k, v in now.items() if k in baseline and v > baseline[k]}
    assert not new, f"modules of {MODULE_LIMIT} lines or more: {new}; split them by their jobs"
    assert not grown, f"listed long modules grew (baseline, now): {grown}"


def test_the_module_baseline_lists_only_modules_that_are_still_long() -> None:
    baseline = json.loads(MODULE_BASELINE.read_text(encoding="utf-8"))
    gone = sorted(set(baseline) - set(long_modules()))
    assert not gone, f"now under {MODULE_LIMIT} lines, remove from long_modules.json: {gone}"


# ----------------------------------------------------------------------------- imports


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _owner(name: str) -> str | None:
    """The module ``name`` is or lies in (``labbrdf.films.Stack`` -> ``labbrdf.films``)."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _type_checking(node: ast.AST) -> bool:
    test = getattr(node, "test", None)
    return isinstance(node, ast.If) and (
        (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING")
        or (isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")
    )


def imports_of(name: str) -> set[str]:
    """The labbrdf modules ``name`` imports at run time, at the top or inside functions."""
    path = MODULES[name]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    todo: list[ast.AST] = [ast.parse(path.read_text(encoding="utf-8"))]
    while todo:
        node = todo.pop()
        for child in ast.iter_child_nodes(node):
            if _type_checking(child):
                todo.append(ast.Module(body=child.orelse, type_ignores=[]))  # type: ignore[attr-defined]
                continue
            if isinstance(child, ast.Import):
                found.update(a.name for a in child.names)
            elif isinstance(child, ast.ImportFrom):
                base = package
                for _ in range(child.level - 1):
                    base = base.rpartition(".")[0]
                mod = (
                    child.module or ""
                    if not child.level
                    else ".".join(p for p in (base, child.module) if p)
                )
                found.update(f"{mod}.{a.name}" for a in child.names)
            todo.append(child)
    owners = {_owner(n) for n in found if n.startswith("labbrdf")}
    return {o for o in owners if o is not None and o != name}


def import_cycles(graph: dict[str, set[str]] | None = None) -> list[list[str]]:
    """The groups of modules that reach each other through their imports (Tarjan)."""
    graph = {m: imports_of(m) for m in MODULES} if graph is None else graph
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    cycles: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                cycles.append(sorted(group))

    for v in graph:
        if v not in index:
            visit(v)
    return cycles


def test_no_import_cycle() -> None:
    assert import_cycles() == []


def test_the_import_check_sees_lazy_imports_and_skips_type_annotations() -> None:
    # the dispatch is imported inside functions of the inputs module
    assert "labbrdf.adapters.registry" in imports_of("labbrdf.adapters.inputs")
    # the film fit's presentation names FilmFit for its annotations only
    assert "labbrdf.fitting.film" not in imports_of("labbrdf.fitting.film_display")
    loop = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert import_cycles(loop) == [["a", "b", "c"]]


def test_report_sections_import_no_other_section() -> None:
    sections = [m for m in MODULES if m.startswith("labbrdf.report.sections.")]
    crossing = {
        m: sorted(o for o in imports_of(m) if o.startswith("labbrdf.report.sections."))
        for m in sections
    }
    assert not {m: o for m, o in crossing.items() if o}, crossing


# ----------------------------------------------------------------------------- layers

#: the layers of the package, bottom first; a module is in the layer of its longest listed
#: prefix, and imports only from its own layer or those below it
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    (
        "plumbing",
        (
            "errors",
            "jsonsafe",
            "richrepr",
            "provenance",
            "outputs",
            "parallel",
            "progress",
            "_plotting",
            "figstyle",
        ),
    ),
    (
        "physics",
        (
            "optics",
            "bsdf_geometry",
            "specular_dop",
            "ellipsometry",
            "microfacet",
            "nk.dispersion",
            "films",
            "tracer",
            "roughness",
        ),
    ),
    ("data", ("dataset", "selection", "samples")),
    # n,k read from files (tables, an ellipsometer file's pseudo-constants): what the film
    # objects and the models are handed to read a material named by a file
    ("files", ("adapters", "nk.reading", "nk.tables")),
    ("models", ("models", "integrate")),
    ("measured constants and samples", ("nk", "sample")),
    (
        "workflows",
        (
            "fitting",
            "prediction",
            "rr_prediction",
            "_brdf_maps",
            "writers",
            # a PSD fitted with the fitting core's intervals; spectra of files as read
            "roughness.psd_fit",
            "roughness.psd_result",
        ),
    ),
    ("report", ("report",)),
    ("command line", ("cli", "__main__")),
)
#: the package's face (lazy names of every layer) and the fixtures' generator script
ABOVE_ALL = ("labbrdf", "labbrdf.data.fixtures.make_fixtures")
#: imports that still run up a layer, each with why; this list may only shrink
UPWARD_BASELINE: set[tuple[str, str]] = set()


def layer_of(module: str) -> int | None:
    """The index in :data:`LAYERS` of a module (None for one in no layer)."""
    rel = module.removeprefix("labbrdf.")
    best: tuple[int, int] | None = None
    for i, (_, prefixes) in enumerate(LAYERS):
        for p in prefixes:
            if (rel == p or rel.startswith(p + ".")) and (best is None or len(p) > best[1]):
                best = (i, len(p))
    return None if best is None else best[0]


def upward_imports(graph: dict[str, set[str]] | None = None) -> set[tuple[str, str]]:
    """``(importer, imported)`` for every import from a lower layer to a higher one."""
    graph = {m: imports_of(m) for m in MODULES} if graph is None else graph
    out = set()
    for m, imported in graph.items():
        low = layer_of(m)
        for o in imported:
            high = layer_of(o)
            if low is not None and high is not None and high > low:
                out.add((m, o))
    return out


def test_every_module_has_a_layer() -> None:
    assert [m for m in MODULES if layer_of(m) is None and m not in ABOVE_ALL] == []


def test_imports_run_down_the_layers() -> None:
    up = upward_imports()
    assert not up - UPWARD_BASELINE, f"imports that run up a layer: {sorted(up - UPWARD_BASELINE)}"
    gone = UPWARD_BASELINE - up
    assert not gone, f"no longer upward, remove from UPWARD_BASELINE: {sorted(gone)}"


def test_the_layer_check_sees_an_import_that_runs_up() -> None:
    graph = {
        "labbrdf.optics": {"labbrdf.models.base"},  # physics -> models: up
        "labbrdf.models.base": {"labbrdf.optics"},  # down
        "labbrdf.nk.dispersion.cauchy": {"labbrdf.nk.tables"},  # the subpackage is lower
        "labbrdf.cli.fit": {"labbrdf.report.user"},
    }
    assert upward_imports(graph) == {
        ("labbrdf.optics", "labbrdf.models.base"),
        ("labbrdf.nk.dispersion.cauchy", "labbrdf.nk.tables"),
    }
