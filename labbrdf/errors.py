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
:class:`labbrdf.NkError`                         ``ValueError``
:class:`labbrdf.SetupError`                      ``ValueError``
:class:`labbrdf.parallel.ParallelError`          ``RuntimeError``
===============================================  =================
"""

from __future__ import annotations

__all__ = ["AdapterWarning", "LabbrdfError", "SampleError", "SetupError"]


class AdapterWarning(UserWarning):
    """A file was read, but something in it may be wrong (the message names file and line).

    Readers issue it with :func:`warnings.warn` and keep the text in ``meta["warnings"]``
    where they can; the command line prints it as ``labbrdf <command>: warning: ...``.
    Defined here, with nothing to import, so that the command line can show it without
    importing the readers; :mod:`labbrdf.adapters` offers it.
    """


class LabbrdfError(Exception):
    """Base class of the errors labbrdf raises on purpose."""


class _Spelled(dict[str, str]):
    """``{argument}`` fields spelled by a mapping, else as the keyword itself."""

    def __missing__(self, key: str) -> str:
        return key


class SetupError(LabbrdfError, ValueError):
    """Arguments of a builder that do not fit together (or a value one of them refuses).

    The message names the arguments; it is kept as a template whose ``{name}`` fields are
    the builder's keyword arguments, so that a caller with other names for them (the
    command line's options) can say it in its own words with :meth:`spelled`.
    ``str(error)`` names the keywords.

    Parameters
    ----------
    template : str
        The message, with ``{keyword}`` fields (other braces doubled).
    """

    def __init__(self, template: str) -> None:
        self.template = template
        super().__init__(self.spelled({}))

    def spelled(self, names: dict[str, str]) -> str:
        """The message with each ``{keyword}`` replaced by ``names[keyword]`` (or itself)."""
        return self.template.format_map(_Spelled(names))


class SampleError(LabbrdfError, ValueError):
    """Files or values that cannot make a sample's substrate, coating or tracer run.

    The message names the file and what is missing.
    """


def escaped(text: object) -> str:
    """``text`` made safe inside a :class:`SetupError` template (braces doubled)."""
    return str(text).replace("{", "{{").replace("}", "}}")
