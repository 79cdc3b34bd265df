"""Formats that are recognised but not read, with what to do instead.

Woollam CompleteEASE ``.SE`` (``woollam-completeease-se``)
    CompleteEASE saves its measurements in a proprietary binary ``.SE`` file whose layout is
    not published. CompleteEASE exports the same data as text (the ``.dat`` read by
    ``woollam-completeease``), so a binary ``.SE`` is refused with that advice. A file named
    ``.se`` that is text is not this format: it is dispatched on its content like any text
    export (a Woollam ASCII file saved as ``.se`` is read as such).

RGL tensor ``.bsdf`` (``rgl-tensor-bsdf``)
    The measured materials of the EPFL Realistic Graphics Lab database: a binary "tensor
    file" (magic ``tensor_file`` and a NUL byte, then a version and named fields: the adaptive
    parametrisation of Dupuy and Jakob, 2018, not a table of BRDF values on angles). It
    shares the ``.bsdf`` extension with the Zemax/Radiant text format and is refused by its
    header.

MERL BRDF database ``.binary`` (``merl-binary``)
    Three int32 dimensions (90, 90, 180) and then 3 x 90 x 90 x 180 float64 values in the
    Rusinkiewicz half/difference-angle parametrisation (Matusik et al., 2003), RGB and
    without the wavelength or geometry of a measurement; refused by its header.
"""

from __future__ import annotations

import os
import re
import struct

from ..dataset import Measurement
from ._base import AdapterError, Format, read_head

__all__ = [
    "FORMATS",
    "refuse_completeease_se",
    "refuse_completeease_sesnap",
    "refuse_merl_binary",
    "refuse_rgl_tensor",
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


#: the first bytes of an RGL tensor file (the database's ``.bsdf``)
_RGL_MAGIC = b"tensor_file\x00"
#: the first bytes of a MERL BRDF: int32 dimensions 90 x 90 x 180 (theta_h, theta_d, phi_d/2)
_MERL_DIMS = struct.pack("<3i", 90, 90, 180)


def _sniff_rgl(head: bytes) -> bool:
    return head.startswith(_RGL_MAGIC)


def _sniff_merl(head: bytes) -> bool:
    return head.startswith(_MERL_DIMS)


def refuse_rgl_tensor(path: str | os.PathLike[str]) -> Measurement:
    """Refuse a binary RGL tensor ``.bsdf`` (EPFL material database) by name.

    Raises
    ------
    AdapterError
        Always: the tensor file is named and not read; a file without its header is told
        so.
    """
    head = read_head(path)
    if not _sniff_rgl(head):
        raise AdapterError(path, "expected an RGL tensor file starting 'tensor_file\\0'", 1)
    version = ".".join(str(b) for b in head[12:14])
    raise AdapterError(
        path,
        f"a binary RGL tensor file (version {version}, the EPFL measured-material database's "
        ".bsdf): an adaptive parametrisation for rendering, not a table of BRDF values on "
        "angles; it is recognised and not read (the Zemax/Radiant text .bsdf is 'zemax-bsdf')",
        1,
        unit="byte",
    )


def refuse_merl_binary(path: str | os.PathLike[str]) -> Measurement:
    """Refuse a MERL BRDF database ``.binary`` file by name.

    Raises
    ------
    AdapterError
        Always: the MERL layout is named and not read; a file without its header is told
        so.
    """
    if not _sniff_merl(read_head(path)):
        raise AdapterError(
            path, "expected a MERL BRDF: int32 dimensions 90 90 180 at the start", 1, unit="byte"
        )
    raise AdapterError(
        path,
        "a MERL BRDF database file (int32 dimensions 90 x 90 x 180, then float64 RGB values "
        "in half/difference angles): recognised and not read; it has no wavelength and no "
        "measurement geometry of its own",
        1,
        unit="byte",
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
    Format(
        "rgl-tensor-bsdf",
        "RGL material database binary tensor .bsdf: recognised and refused (not a table "
        "of BRDF values)",
        (".bsdf",),
        _sniff_rgl,
        refuse_rgl_tensor,
        (),
        keywords=(_RGL_MAGIC,),
    ),
    Format(
        "merl-binary",
        "MERL BRDF database .binary: recognised and refused (RGB in half/difference angles)",
        (".binary",),
        _sniff_merl,
        refuse_merl_binary,
        (),
    ),
)
