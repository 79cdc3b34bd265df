"""Formats that are recognised but not read, with what to do instead.

Woollam CompleteEASE ``.SE`` (``woollam-completeease-se``)
    CompleteEASE saves its measurements in a proprietary binary ``.SE`` file whose layout is
    not published. CompleteEASE exports the same data as text (the ``.dat`` read by
    ``woollam-completeease``), so a binary ``.SE`` is refused with that advice. A file named
    ``.se`` that is text is not this format: it is dispatched on its content like any text
    export (a Woollam ASCII file saved as ``.se`` is read as such).
"""

from __future__ import annotations

import os
import re

from ..dataset import Measurement
from ._base import AdapterError, Format, read_head

__all__ = [
    "FORMATS",
    "refuse_completeease_se",
    "refuse_completeease_sesnap",
    "refuse_spectrapen",
]

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
    head = read_head(path)
    if _binary(head):
        raise AdapterError(path, _SE_HINT)
    raise AdapterError(
        path,
        "this .se file is text, not a CompleteEASE binary .SE; read it with the format of "
        "its content (--format on the command line, format= in Python; see labbrdf formats)",
    )


_ZIP = b"PK\x03\x04"


def refuse_completeease_sesnap(path: str | os.PathLike[str]) -> Measurement:
    """Refuse a CompleteEASE ``.SEsnap`` snapshot with what to do instead.

    Raises
    ------
    AdapterError
        Always: a ZIP archive gets the CompleteEASE text-export advice; anything else is
        told that it is not a snapshot.
    """
    head = read_head(path)
    if head.startswith(_ZIP):
        raise AdapterError(
            path,
            "a Woollam CompleteEASE snapshot (.SEsnap: a ZIP archive around a binary .SE file, "
            "whose layout is not published); export the data as text from CompleteEASE (the "
            "ASCII .dat export, read by format 'woollam-completeease')",
        )
    raise AdapterError(
        path,
        "this .sesnap file is not a ZIP archive, so not a CompleteEASE snapshot; read it with "
        "the format of its content (--format on the command line, format= in Python)",
    )


#: the SpectraPen title line: a quantity, blanks or a TAB, a unit in brackets, a comma
_PSI_TITLE = re.compile(r"^\s*([A-Za-z][A-Za-z ]{0,40}?)\s*\[([^\]\r\n]{1,40})\]\s*,?\s*$")


def _psi_lines(head: bytes) -> list[str]:
    text = head.decode("utf-8", "replace")
    return [ln.strip() for ln in text.splitlines()[:12] if ln.strip()]


def _sniff_spectrapen(head: bytes) -> bool:
    lines = _psi_lines(head)
    return (
        len(lines) >= 3
        and _PSI_TITLE.match(lines[0]) is not None
        and lines[1].startswith("Time,")
        and lines[2].startswith("Index,")
    )


def refuse_spectrapen(path: str | os.PathLike[str]) -> Measurement:
    """Refuse a PSI SpectraPen CSV export, naming the quantity its title states.

    Raises
    ------
    AdapterError
        Always: spectral irradiance (or another quantity of the light) has no dataset
        quantity; a file that does not have the SpectraPen layout is told so.
    """
    head = read_head(path)
    lines = _psi_lines(head)
    if not _sniff_spectrapen(head):
        raise AdapterError(
            path,
            "expected a PSI SpectraPen export: a title '<Quantity> [<unit>],' then the rows "
            "'Time,...' and 'Index,...'",
            1,
        )
    m = _PSI_TITLE.match(lines[0])
    assert m is not None  # checked by the sniffer
    quantity, unit = m.group(1).strip(), m.group(2).strip()
    raise AdapterError(
        path,
        f"a PSI SpectraPen export of {quantity} [{unit}]: a measurement of the light reaching "
        "the instrument, not an optical property of a sample (reflectance, transmittance, "
        "absorbance), so labbrdf has no quantity for it and does not read it",
        1,
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
    Format(
        "woollam-completeease-sesnap",
        "Woollam CompleteEASE snapshot .SEsnap (ZIP around a .SE): recognised and refused "
        "(export it as text)",
        (".sesnap",),
        _sniff_se,
        refuse_completeease_sesnap,
        (),
    ),
    Format(
        "psi-spectrapen",
        "PSI SpectraPen CSV (spectral irradiance): recognised and refused (not a property "
        "of a sample)",
        (".csv",),
        _sniff_spectrapen,
        refuse_spectrapen,
        (),
        keywords=(b"Irradiance",),
    ),
)
