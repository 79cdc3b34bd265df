"""The two number parsers of the text readers, side by side: where they differ, on purpose.

``parse_block`` reads a block whose rows may be short (NaN-padded), tagged, or hold
``inf``/``nan``; ``parse_rows`` reads the ``.bsdf`` tables, whose header states every row's
length, and refuses all three.
"""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf.adapters import AdapterError
from labbrdf.adapters._numblock import finite_number, parse_block, parse_rows


def test_a_short_row_is_padded_by_the_block_parser_and_refused_by_the_row_parser() -> None:
    block = parse_block("f.txt", "1 2 3\n4 5\n", 7, 3, sep=None)
    np.testing.assert_array_equal(block.values, [[1, 2, 3], [4, 5, np.nan]])
    np.testing.assert_array_equal(block.lines, [7, 8])
    with pytest.raises(AdapterError, match="expected 3 values in the row, found 2") as exc:
        parse_rows("f.bsdf", ["1 2 3", "4 5"], [7, 8], 3)
    assert exc.value.line == 8


@pytest.mark.parametrize("word", ["inf", "nan", "-Infinity"])
def test_non_finite_spellings_are_read_by_the_block_parser_and_refused_by_the_row_parser(
    word: str,
) -> None:
    block = parse_block("f.txt", f"1 {word}\n", 1, 2, sep=None)
    assert block.values[0, 0] == 1.0 and not np.isfinite(block.values[0, 1])
    with pytest.raises(AdapterError, match="expected numbers, found the character"):
        parse_rows("f.bsdf", [f"1 {word}"], [1], 2)


def test_the_row_parser_reads_exactly_what_is_written() -> None:
    rows = ["1 -2.5 3e-3", "+4 .5 6E2"]
    np.testing.assert_array_equal(
        parse_rows("f.bsdf", rows, [3, 4], 3), [[1, -2.5, 3e-3], [4, 0.5, 600.0]]
    )


def test_finite_number_names_what_and_where() -> None:
    assert finite_number("f.bsdf", "-1.5e2", 3, "TIS") == -150.0
    with pytest.raises(AdapterError, match="TIS: expected an ASCII decimal number") as exc:
        finite_number("f.bsdf", "1,5", 3, "TIS")
    assert exc.value.line == 3
    with pytest.raises(AdapterError, match="TIS: '1e999' is not a finite number"):
        finite_number("f.bsdf", "1e999", 4, "TIS")
