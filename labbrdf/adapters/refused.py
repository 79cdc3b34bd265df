"""Binary formats that are recognised but not read, with what to do instead.

Woollam CompleteEASE ``.SE`` (``woollam-completeease-se``)
    CompleteEASE saves its measurements in a proprietary binary ``.SE`` file whose layout is
    not published. CompleteEASE exports the same data as text (the ``.dat`` read by
    ``woollam-completeease``), so a binary ``.SE`` is refused with that advice. A file named
    ``.se`` that is text is not this format: it is dispatched on its content like any text
    export (a Woollam ASCII file saved as ``.se`` is read as such).
"""

from __future__ import annotations

import os

from ..dataset import Measurement
from ._base import AdapterError, Format, check_regular_file

__all__ = ["FORMATS", "refuse_completeease_se"]

_SE_HINT = (
    "a Woollam CompleteEASE binary .SE file, whose layout is not published; export it as "
    "text from CompleteEASE (the ASCII .dat export, read by format 'woollam-completeease')"
)


def _binary(head: bytes) -> bool:
    """NUL bytes or control characters other than TAB/CR/LF/FF/EOF: not a text export."""
    sample = head[:4096]
    return b"\x00" in sample or any(b < 9 or 13 < b < 26 or 27 <= b < 32 for b in sample)


def _sniff_se(head: bytes) -> bool:
    """Never claimed by content alone: only the extension tells ``.SE`` from other binaries."""
    return False


def refuse_completeease_se(path: str | os.PathLike[str]) -> Measurement:
    """Refuse a CompleteEASE ``.SE`` file with what to do instead.

    Raises
    ------
    AdapterError
        Always: a binary ``.SE`` is named and the text export is suggested; a text file is
        told to be read by its own format.
    """
    check_regular_file(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
    except OSError as exc:
        raise AdapterError(path, f"cannot be read ({exc.strerror or exc})") from None
    if not head or head.isspace():
        raise AdapterError(path, "the file is empty")
    if _binary(head):
        raise AdapterError(path, _SE_HINT)
    raise AdapterError(
        path,
        "this .se file is text, not a CompleteEASE binary .SE; read it with the format of "
        "its content (--format on the command line, format= in Python; see labbrdf formats)",
    )


FORMATS = (
    Format(
        "woollam-completeease-se",
        "Woollam CompleteEASE binary .SE: recognised and refused (export it as text)",
        (".se",),
        _sniff_se,
        refuse_completeease_se,
        (),
    ),
)
