"""HTML reports: the validation report (``labbrdf validate``) and the user report.

>>> from labbrdf import report
>>> report.validate(out="reports/validation", quick=True)      # doctest: +SKIP
>>> report.user_report(["scan.csv"], "smooth3", "reports/mine")  # doctest: +SKIP

Each writes one folder, atomically: ``index.html`` (one self-contained page, figures embedded
as PNG data URIs, no external resources), ``results.json`` (every number on the page) and
``tables/*.csv``. Both return the exit code: 0 when every check passed (or was skipped
because an input or module is missing), 1 when a check failed.
"""

from __future__ import annotations

from .user import user_report
from .validate import validate

__all__ = ["user_report", "validate"]
