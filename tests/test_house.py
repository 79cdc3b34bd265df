"""The house rules of the package that a linter does not check.

Functions stay short enough to read: none of 120 lines or more, except those listed in
``long_functions.json`` beside this file (the baseline of the day the rule was made), and a
listed one may only shrink. Break a long function into named steps; when one falls under
the limit, remove it from the baseline.
"""

from __future__ import annotations

import ast
import json
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "labbrdf"
BASELINE = Path(__file__).with_name("long_functions.json")
LIMIT = 120


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
