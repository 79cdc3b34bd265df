"""JSON-safe copies of plain results: the one sanitiser of the CLI, the fits and the report.

Low-level: imports numpy only, so that every layer may use it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["jsonable"]


def jsonable(x: Any) -> Any:
    """A JSON-safe copy of ``x`` (``json.dumps(..., allow_nan=False)`` accepts it).

    Mappings become dicts with string keys, lists/tuples/arrays become lists, numpy
    scalars become Python numbers, NaN and infinities become None, paths and any other
    object become their ``str``.

    Parameters
    ----------
    x : Any
        A value built from mappings, sequences, numbers, strings and arrays.

    Returns
    -------
    Any
        The copy.
    """
    if isinstance(x, Mapping):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        v = float(x)
        return v if math.isfinite(v) else None
    if x is None or isinstance(x, str):
        return x
    if isinstance(x, Path):
        return str(x)
    return str(x)
