"""The house rules of the package that a linter does not check.

Functions stay short enough to read: none of 120 lines or more, except those listed in
``long_functions.json`` beside this file (the baseline of the day the rule was made), and a
listed one may only shrink. Break a long function into named steps; when one falls under
the limit, remove it from the baseline. Modules follow the same rule at 800 lines
(``long_modules.json``): split a module by its jobs before it grows past the limit.

Imports: no module imports, directly or through others, a module that imports it back,
whether at the top or inside a function (imports under ``if TYPE_CHECKING:`` are type
annotations, not imports at run time); a report section imports no other section (shared
helpers live in report-level modules).
"""

from __future__ import annotations

import ast
import json
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "labbrdf"
BASELINE = Path(__file__).with_name("long_functions.json")
LIMIT = 120
MODULE_BASELINE = Path(__file__).with_name("long_modules.json")
MODULE_LIMIT = 800


def long_functions() -> dict[str, int]:
    """``module.py:qualname`` -> length in lines, for every function of LIMIT lines or more."""
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
                        length = (child.end_lineno or child.lineno) - child.lineno + 1
                        if length >= LIMIT:
                            out[f"{path.relative_to(PACKAGE).as_posix()}:{name}"] = length
                    stack.append((child, name + "."))
    return out


def test_no_function_grows_past_the_limit() -> None:
    baseline = json.loads(BASELINE.read_text(encoding="utf-8"))
    now = long_functions()
    new = {k: v for k, v in now.items() if k not in baseline}
    grown = {k: (baseline[k], v) for k, v in now.items() if k in baseline and v > baseline[k]}
    assert not new, f"functions of {LIMIT} lines or more: {new}; break them into named steps"
    assert not grown, f"listed long functions grew (baseline, now): {grown}"


def test_the_baseline_lists_only_functions_that_are_still_long() -> None:
    baseline = json.loads(BASELINE.read_text(encoding="utf-8"))
    gone = sorted(set(baseline) - set(long_functions()))
    assert not gone, f"now under {LIMIT} lines, remove from long_functions.json: {gone}"


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
