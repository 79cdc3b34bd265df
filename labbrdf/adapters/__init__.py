"""Instrument adapters: one module per vendor format, a plain-dict registry, one ``read``.

>>> import labbrdf
>>> m = labbrdf.read("w2_10102006.dat")           # doctest: +SKIP
>>> labbrdf.adapters.formats()                    # doctest: +SKIP

Dispatch (:func:`read`): an explicit ``format`` wins; else the header sniffers decide,
the formats of the file's extension first: when exactly one of them claims the file it is
read with that one; when none does, the content decides across all formats (a JASCO text
export saved as ``.csv`` is still read as JASCO). When no sniffer claims the file, an
extension that belongs to one format only sends it to that reader, whose error says what is
wrong where; otherwise :class:`AdapterError` names the closest candidates: the formats of the
extension and those whose typical keywords occur in the first bytes. Readers never try each
other under ``except``: a parse error is reported as is.

Height maps (profilometer, AFM and interferometer files, :mod:`labbrdf.adapters.topography`)
are an input kind of their own (:data:`~labbrdf.adapters.heightmap_formats.HEIGHT_MAP_FORMATS`):
:func:`input_kind` tells them from optical exports before anything is parsed -- an extension
only height maps have, or, for an extension optical exports share (MetroPro ``.dat``), magic
bytes a height-map sniffer claims and no optical sniffer does. :func:`read` refuses a height
map with an :class:`AdapterError` that says so (a height map is not a :class:`Measurement`);
:func:`read_inputs` reads a list of paths of either kind, each file once.
"""

from ..errors import AdapterWarning
from ._base import AdapterError, Example, Format
from .inputs import InputFile, Inputs, read_inputs
from .registry import (
    KINDS,
    READERS,
    FormatRow,
    formats,
    input_kind,
    read,
    read_many,
    sniff,
)

__all__ = [
    "AdapterError",
    "AdapterWarning",
    "Example",
    "Format",
    "FormatRow",
    "InputFile",
    "Inputs",
    "KINDS",
    "READERS",
    "formats",
    "input_kind",
    "read",
    "read_inputs",
    "read_many",
    "sniff",
]
