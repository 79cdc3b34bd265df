"""The base of every labbrdf error: catch :class:`LabbrdfError` to catch them all.

Low-level: imports nothing. Each subclass is also the built-in error it always was
(``ValueError`` for bad input, ``RuntimeError`` for a failed parallel run), so code that
catches those keeps working:

===============================================  =================
error                                            also a
===============================================  =================
:class:`labbrdf.AdapterError`                    ``ValueError``
:class:`labbrdf.DatasetError`                    ``ValueError``
:class:`labbrdf.ModelError`                      ``ValueError``
:class:`labbrdf.FitError`                        ``ValueError``
:class:`labbrdf.parallel.ParallelError`          ``RuntimeError``
===============================================  =================
"""

from __future__ import annotations

__all__ = ["LabbrdfError"]


class LabbrdfError(Exception):
    """Base class of the errors labbrdf raises on purpose."""
