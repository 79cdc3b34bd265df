"""Every text reader takes ASCII digits only: Python's float() also reads '１２'.

One real file per text format, one data field turned into full-width digits (U+FF10..),
'1_000'-style or a non-finite spelling the format does not have: each must raise
AdapterError naming the line, never read a number.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

from labbrdf.adapters import READERS, AdapterError, AdapterWarning
from labbrdf.adapters._base import parse_number

FULL = str.maketrans("0123456789", "０１２３４５６７８９")

#: format -> (file, a field as written on a data line, its line number): the example of
#: each text format's registry entry that names such a field (``Example.number``)
CASES = {
    name: (ex.path, *ex.number)
    for name, f in READERS.items()
    for ex in f.examples
    if ex.number is not None
}


def _case(real_exports: Path, fmt: str) -> tuple[bytes, str, int]:
    rel, field, line = CASES[fmt]
    text = (real_exports / rel).read_bytes().decode("latin-1")
    assert field in text.splitlines()[line - 1], (fmt, field, line)
    return text.encode("latin-1"), field, line


def _replace_on_line(raw: bytes, line: int, old: str, new: str) -> bytes:
    lines = raw.split(b"\n")
    lines[line - 1] = lines[line - 1].replace(old.encode(), new.encode("utf-8"), 1)
    return b"\n".join(lines)


@pytest.mark.parametrize("fmt", sorted(CASES))
def test_full_width_digits_are_not_numbers(real_exports: Path, tmp_path: Path, fmt: str) -> None:
    raw, field, line = _case(real_exports, fmt)
    bad = tmp_path / Path(CASES[fmt][0]).name
    bad.write_bytes(_replace_on_line(raw, line, field, field.translate(FULL)))
    with pytest.raises(AdapterError, match=rf"line {line}\b"):
        READERS[fmt].read(bad)


@pytest.mark.parametrize(
    "fmt", ["sentech-spectraray", "jasco-spectramanager-text", "agilent-cary-winuv-csv"]
)
@pytest.mark.parametrize("spelling", ["nan", "inf", "-Infinity", "1_0"])
def test_non_finite_spellings_are_refused_where_the_format_has_none(
    real_exports: Path, tmp_path: Path, fmt: str, spelling: str
) -> None:
    raw, field, line = _case(real_exports, fmt)
    bad = tmp_path / Path(CASES[fmt][0]).name
    bad.write_bytes(_replace_on_line(raw, line, field, spelling))
    with pytest.raises(AdapterError, match=rf"line {line}\b"):
        READERS[fmt].read(bad)


@pytest.mark.parametrize("text", ["１２", "1_000", "٣", "nan", "inf", "1e999", "0x10", ""])
def test_parse_number_refuses_what_float_would_take(text: str) -> None:
    with pytest.raises(AdapterError):
        parse_number(text, "f.txt", 1, "X")


def test_parse_number_takes_nonfinite_only_when_asked() -> None:
    assert parse_number(" -1.5e-3 ", "f", 1, "X") == -1.5e-3
    assert parse_number("inf", "f", 1, "X", nonfinite=True) == float("inf")


#: the text formats read with the shared block parser (labbrdf.adapters._numblock.parse_block)
#: and those that call its last-line check themselves (check_last_row); JCAMP-DX, Cary and
#: Zemax files end with a marker or footer, which a cut removes (refused as truncated)
CUT_CHECKED = [
    "woollam-wvase",
    "woollam-completeease",
    "accurion-ep4",
    "sentech-spectraray",
    "shimadzu-uvprobe-text",
    "jasco-spectramanager-text",
    "perkinelmer-uvwinlab-asc",
    "filmsense",
    "oceanoptics-text",
]
#: files that end with a data row (where CASES names another)
_CUT_FILES = {
    "shimadzu-uvprobe-text": "shimadzu-uvprobe/sa281-02-280K.txt",
    "jasco-spectramanager-text": "jasco-spectramanager-text/PbSe batch 1.txt",
    "filmsense": "filmsense-txt/Filmsense_kineticTest.txt",
    "oceanoptics-text": "oceanoptics-oceanview/ambient_0_40_Absorbance_10-54-38-373.txt",
}


def _last_number_cut(raw: bytes, keep: int) -> bytes:
    """``raw`` without its trailing line ends, its last number cut after ``keep`` of its
    characters past the decimal separator (0: right after the separator)."""
    body = raw.rstrip(b"\r\n \t")
    mark = max(body.rfind(b"."), body.rfind(b","))
    return body[: mark + 1 + keep]


@pytest.mark.parametrize("fmt", CUT_CHECKED)
def test_every_block_reader_refuses_a_last_number_cut_at_its_separator(
    real_exports: Path, tmp_path: Path, fmt: str
) -> None:
    """``0,`` or ``12.`` at the very end of a file is a number cut short, never 0 or 12."""
    rel = _CUT_FILES.get(fmt) or CASES[fmt][0]
    raw = (real_exports / rel).read_bytes()
    cut = _last_number_cut(raw, 0)
    line = len(cut.decode("latin-1").splitlines())
    bad = tmp_path / Path(rel).name
    bad.write_bytes(cut)
    with pytest.raises(AdapterError, match=rf"line {line}: .*ends without its digits") as exc:
        READERS[fmt].read(bad)
    assert str(bad) in str(exc.value)


@pytest.mark.parametrize("fmt", CUT_CHECKED)
def test_every_block_reader_refuses_or_warns_on_a_last_number_missing_a_digit(
    real_exports: Path, tmp_path: Path, fmt: str
) -> None:
    rel = _CUT_FILES.get(fmt) or CASES[fmt][0]
    raw = (real_exports / rel).read_bytes()
    body = raw.rstrip(b"\r\n \t")
    cut = body[:-1]
    line = len(cut.decode("latin-1").splitlines())
    bad = tmp_path / Path(rel).name
    bad.write_bytes(cut)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            READERS[fmt].read(bad)
        except AdapterError as exc:
            assert re.search(rf"line {line}: .*looks truncated", str(exc)), str(exc)
            return
    texts = [str(w.message) for w in caught if issubclass(w.category, AdapterWarning)]
    assert texts and re.search(rf"line {line}: .*may be truncated", texts[0]), texts
    body_line = body.decode("latin-1").splitlines()[-1]
    assert body_line[-1].isdigit(), body_line


def test_a_complete_last_value_of_a_significant_digits_writer_is_not_doubted(
    tmp_path: Path,
) -> None:
    """WVASE writes sigmas with 6 significant digits (``0.0775003`` beside ``0.278168``): a
    last value with all six is complete even with fewer decimals than another row; one with
    five is doubted (a cut always removes significant digits)."""
    from labbrdf.adapters._truncation import check_last_field

    rows = ["1.0\t0.0775003", "2.0\t0.0935513", "3.0\t0.106933", "4.0\t0.145151", "5.0\t0.171798"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert check_last_field(tmp_path / "f.dat", "6.0\t0.278168", rows, 7, "\t") is None
    with pytest.warns(AdapterWarning, match="line 7: .*'0.27816'.* may be truncated"):
        check_last_field(tmp_path / "f.dat", "6.0\t0.27816", rows, 7, "\t")


def test_the_real_wvase_file_without_a_final_line_end_reads_without_a_doubt(
    real_exports: Path,
) -> None:
    p = real_exports / "woollam-wvase-ascii" / "w2_10102006.dat"
    assert not p.read_bytes().endswith(b"\n")  # the case: its last line has no line end
    with warnings.catch_warnings():
        warnings.simplefilter("error", AdapterWarning)
        assert len(READERS["woollam-wvase"].read(p)) > 0
