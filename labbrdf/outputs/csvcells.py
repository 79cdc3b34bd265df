"""CSV cells for people: a text cell a spreadsheet would run as a formula is neutralised."""

from __future__ import annotations

from typing import Any

#: text cells starting with one of these are prefixed with ``'`` in CSVs meant for people
#: (OWASP "CSV injection"): a spreadsheet would otherwise run them as a formula
CSV_FORMULA_PREFIXES = ("=", "+", "-", "@", "\t", "\r")


def csv_safe_cell(value: Any) -> Any:
    """Neutralise a text cell that a spreadsheet would run as a formula.

    A cell starting with ``= + - @``, TAB or CR gets a leading ``'``; anything else is
    returned unchanged (numbers too).
    """
    if isinstance(value, str) and value.startswith(CSV_FORMULA_PREFIXES):
        return "'" + value
    return value


def csv_safe_frame(df: Any) -> Any:
    """Copy a DataFrame with every text cell passed through :func:`csv_safe_cell`.

    For CSV tables meant to be opened by people, not for the dataset CSV (read back
    exactly).
    """
    out = df.copy()
    for col in out.columns:
        if out[col].dtype == object or str(out[col].dtype) in ("string", "str"):
            out[col] = out[col].map(csv_safe_cell)
    out.columns = [csv_safe_cell(c) if isinstance(c, str) else c for c in out.columns]
    return out
