"""Mutated real exports: the ellipsometer readers raise AdapterError or lose nothing silently.

Each example takes a real file of one format, applies one mutation (truncate at a random
byte, delete or duplicate a random line, flip up to three random bytes, insert a garbage
token at a random byte) and reads the result with the format's reader. Two properties:

1. nothing but :class:`AdapterError` is ever raised;
2. a returned measurement never has silently fewer rows than the intact data lines imply.
   A mutation touches at most a known number of lines (truncation: the cut line and all
   after it; deletion: one line; a flipped byte or an inserted token: the line it lands in
   and, when it is or makes a line break, its neighbour, so 2 per change), and a line holds
   at most ``ROWS_PER_LINE`` rows of the result (Psi and Delta = 2 for Woollam and
   Accurion, 2 x 3 angles or 16 Mueller elements for SENTECH, 3 quantities x 8 LEDs for a
   Film Sense time point), so ``rows >= rows_original - touched * ROWS_PER_LINE``.
   Truncation and deletion cannot add data: ``rows <= rows_original``; duplication
   cannot remove any: ``rows >= rows_original``.

The files and their rows per line come from each format's registry entry
(``Format.examples``, ``Example.rows_per_line``). Bounded: 60 examples per format, no
deadline (the slow line-by-line parser runs on most mutated files).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import labbrdf
from labbrdf.adapters import READERS, AdapterError

#: format -> the real exports it is fuzzed on: the examples of its registry entry that
#: state how many rows one text line gives (``Example.rows_per_line``)
FILES = {
    name: [ex.path for ex in f.examples if ex.rows_per_line is not None]
    for name, f in READERS.items()
    if any(ex.rows_per_line is not None for ex in f.examples)
}

#: file name -> at most this many rows come from one line of it
ROWS_PER_LINE = {
    Path(ex.path).name: ex.rows_per_line
    for f in READERS.values()
    for ex in f.examples
    if ex.rows_per_line is not None
}

GARBAGE = [
    b"abc",
    b"1.2.3",
    b"\t",
    b" ",
    b"nan",
    b"-",
    b"1e999",
    b"\xb5",
    b"\x00",
    b";",
    b"#",
    b"E",
    b"0",
    b"\r\n",
    b"\n",
    b",",
    b"inf",
    b"\xff\xfe",
    b"9" * 40,
]

_ORIGINAL: dict[str, int] = {}


def original_rows(path: Path, fmt: str) -> int:
    key = str(path)
    if key not in _ORIGINAL:
        _ORIGINAL[key] = len(labbrdf.read(path, format=fmt))
    return _ORIGINAL[key]


def line_spans(raw: bytes) -> list[tuple[int, int]]:
    """(start, end) byte offsets of each line, end after its LF."""
    spans, start = [], 0
    while start < len(raw):
        nl = raw.find(b"\n", start)
        end = len(raw) if nl < 0 else nl + 1
        spans.append((start, end))
        start = end
    return spans


def mutate(data: st.DataObject, raw: bytes) -> tuple[bytes, str, int]:
    """Return mutated bytes, the kind of mutation and the number of lines it touches."""
    kind = data.draw(st.sampled_from(["truncate", "delete", "duplicate", "flip", "insert"]))
    spans = line_spans(raw)
    if kind == "truncate":
        b = data.draw(st.integers(0, len(raw) - 1))
        touched = sum(1 for _, end in spans if end > b)
        return raw[:b], kind, touched
    if kind in ("delete", "duplicate"):
        k = data.draw(st.integers(0, len(spans) - 1))
        s, e = spans[k]
        if kind == "delete":
            return raw[:s] + raw[e:], kind, 1
        if raw[s:e].endswith(b"\n"):
            return raw[:e] + raw[s:e] + raw[e:], kind, 0
        eol = b"\r\n" if b"\r\n" in raw else b"\n"  # last line, no final newline
        return raw + eol + raw[s:e], kind, 0
    if kind == "flip":
        n = data.draw(st.integers(1, 3))
        out = bytearray(raw)
        for _ in range(n):
            i = data.draw(st.integers(0, len(raw) - 1))
            out[i] = data.draw(st.integers(0, 255))
        return bytes(out), kind, 2 * n
    i = data.draw(st.integers(0, len(raw)))
    token = data.draw(st.sampled_from(GARBAGE))
    return raw[:i] + token + raw[i:], kind, 2


@pytest.mark.parametrize("fmt", sorted(FILES))
@settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    derandomize=True,
)
@given(data=st.data())
def test_mutated_real_files_raise_adapter_error_or_keep_every_intact_row(real_exports, fmt, data):
    rel = data.draw(st.sampled_from(FILES[fmt]))
    src = real_exports / rel
    raw = src.read_bytes()
    n0 = original_rows(src, fmt)
    per_line = ROWS_PER_LINE[src.name]
    mutated, kind, touched = mutate(data, raw)
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / src.name
        p.write_bytes(mutated)
        try:
            m = labbrdf.read(p, format=fmt)
        except AdapterError as exc:
            assert p.name in str(exc)
            return
    rows = len(m)
    assert rows >= n0 - touched * per_line, (kind, touched, rows, n0)
    if kind in ("truncate", "delete"):
        assert rows <= n0, (kind, rows, n0)
    if kind == "duplicate":
        assert rows >= n0, (kind, rows, n0)
