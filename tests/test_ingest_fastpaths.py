"""The fast paths of the ingest pipeline give the same result as the exact ones.

``validate``, the block parser and the Woollam reader take shortcuts on large, clean files
(range checks by min/max, categorical string columns, ASCII files parsed in place, a
numbers-only first parse of a tagged block, fewer columns when the first line is short).
Each test here builds a case where the shortcut must decline or must agree bit for bit
with the row-by-row computation it replaces.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import labbrdf
from labbrdf.adapters._frame import within
from labbrdf.adapters._numblock import _count_lf, _slow, parse_block
from labbrdf.adapters.woollam_header import ascii_head
from labbrdf.adapters.woollam_rows import wrap_finite
from labbrdf.dataset import DatasetError, Measurement, make_frame, validate, wrap_delta

HEAD = (
    b"fast path\r\n"
    b"VASEmethod[EllipsometerType=4, Isotropic, WVASE=3.616, Tue Oct 10 10:24:56 2006]\r\n"
    b"Original[fast.dat]\r\nnm\r\n"
)


def _table(n: int = 6) -> pd.DataFrame:
    return make_frame(
        sample="s",
        instrument="i",
        source="f.dat",
        quantity=["psi", "delta"] * (n // 2),
        value=np.tile([30.0, 200.0], n // 2),
        unit="deg",
        wavelength_nm=np.repeat(np.linspace(400, 800, n // 2), 2),
        sigma=0.01,
        theta_i_deg=70.0,
        theta_r_deg=70.0,
        phi_r_deg=180.0,
    )


def _categorical(df: pd.DataFrame) -> pd.DataFrame:
    out = df.copy()
    for c in ("sample", "instrument", "source", "unit", "quantity"):
        out[c] = out[c].astype("category")
    return out


# ----------------------------------------------------------------------------- validate


def test_validate_result_is_independent_of_its_input():
    df = _table()
    out = validate(df)
    out.loc[0, "value"] = 1.0
    out.loc[0, "sample"] = "other"
    assert df.loc[0, "value"] == 30.0 and df.loc[0, "sample"] == "s"
    df.loc[1, "wavelength_nm"] = 1.0
    assert out.loc[1, "wavelength_nm"] == 400.0


def test_validate_gives_a_fresh_range_index_and_object_strings_from_categoricals():
    df = _categorical(_table()).set_axis(np.arange(6)[::-1] + 10)
    out = validate(df)
    assert isinstance(out.index, pd.RangeIndex) and out.index[0] == 0
    for c in ("sample", "instrument", "source", "unit"):
        assert out[c].dtype == object and isinstance(out[c].iloc[0], str)
    assert list(out["quantity"].cat.categories) == list(labbrdf.dataset.QUANTITIES)
    pd.testing.assert_frame_equal(out, validate(_table()))


def test_validate_duplicate_columns_are_named():
    df = _table()
    dup = pd.concat([df, df[["sigma"]]], axis=1)
    with pytest.raises(DatasetError, match=r"duplicate column\(s\) \['sigma'\]"):
        validate(dup)


@pytest.mark.parametrize(
    ("column", "bad", "match"),
    [
        ("sample", "", "column 'sample': expected a non-empty string in rows 2"),
        ("unit", "1", r"column 'unit': '1' does not fit quantity 'psi' .* rows 2"),
        ("quantity", "colour", r"unknown quantity \['colour'\] in rows 2"),
    ],
)
def test_validate_categorical_columns_name_the_bad_row(column, bad, match):
    df = _table()
    df.loc[2, column] = bad
    with pytest.raises(DatasetError, match=match):
        validate(_categorical(df))


def test_validate_unused_bad_category_is_not_an_error():
    df = _categorical(_table())
    df["quantity"] = df["quantity"].cat.add_categories(["colour"])
    df["sample"] = df["sample"].cat.add_categories([""])
    assert len(validate(df)) == 6


def test_validate_missing_value_in_a_categorical_is_named():
    df = _categorical(_table())
    df.loc[4, "source"] = np.nan
    with pytest.raises(
        DatasetError, match="column 'source': expected a non-empty string in rows 4"
    ):
        validate(df)


@pytest.mark.parametrize(
    ("column", "values", "match"),
    [
        ("theta_i_deg", [0.0, 90.0], None),
        ("theta_r_deg", [np.nan, 90.0], None),
        ("theta_i_deg", [np.nan, 90.0000001], "column 'theta_i_deg'.* rows 1"),
        ("phi_r_deg", [np.nan, 359.9999], None),
        ("phi_r_deg", [0.0, -np.inf], "column 'phi_r_deg'.* rows 1"),
        ("sigma", [np.nan, 0.0], None),
        ("sigma", [np.nan, np.inf], "column 'sigma'.* rows 1"),
        ("wavelength_nm", [400.0, 5e-324], None),
        ("wavelength_nm", [400.0, -0.0], "column 'wavelength_nm'.* rows 1"),
    ],
)
def test_validate_range_checks_at_their_edges(column, values, match):
    df = _table(2)
    df[column] = values
    if match is None:
        assert len(validate(df)) == 2
    else:
        with pytest.raises(DatasetError, match=match):
            validate(df)


def test_validate_psi_and_delta_edges_with_other_quantities_out_of_their_range():
    df = _table(4)
    df.loc[0, "value"] = 90.0  # psi edge: fine
    df.loc[1, "value"] = 0.0  # delta edge: fine
    df.loc[2, ["quantity", "unit", "value"]] = ["brdf", "sr-1", 1e6]  # no range for brdf
    assert len(validate(df)) == 4
    df.loc[3, "value"] = 359.99999999999994
    assert len(validate(df)) == 4
    df.loc[3, "value"] = 360.0
    with pytest.raises(DatasetError, match=r"delta outside \[0, 360\).* rows 3"):
        validate(df)


# ----------------------------------------------------------------------------- helpers


def test_within_declines_nan_inf_and_checks_both_edges():
    a = np.array([0.0, 90.0])
    assert within(a, 0.0, 90.0) and not within(a, 0.0, 90.0, hi_open=True)
    assert not within(np.array([1.0, np.nan]))
    assert not within(np.array([1.0, np.inf]))
    assert within(np.array([])) and within(np.array([-1e308, 1e308]))


def test_fast_delta_wrap_is_bitwise_np_mod():
    rng = np.random.default_rng(11)
    edges = [-0.0, 0.0, -360.0, -1e-20, -5e-14, -1e-300, 359.99999999999994, -359.99999999999994]
    d = np.concatenate([rng.uniform(-360.0, 360.0, 100_000), edges])
    np.testing.assert_array_equal(wrap_finite(d).view(np.int64), wrap_delta(d).view(np.int64))
    wide = np.array([-720.5, 725.0, 30.0])  # outside [-360, 360): the general path
    np.testing.assert_array_equal(wrap_finite(wide), wrap_delta(wide))


def test_line_feed_count_across_chunks_is_bytes_count():
    data = b"ab\n" * 1000 + b"\n\r\n" + b"x" * 77
    for start in (0, 1, 5, len(data) - 1):
        assert _count_lf(data, start, chunk=64) == data.count(b"\n", start)


def test_ascii_head_stops_after_whole_lines():
    raw = b"a\r\nb\r\nc\r\nd"
    assert ascii_head(raw, 2) == "a\r\nb\r\n"
    assert ascii_head(raw, 9) == raw.decode()


# ----------------------------------------------------------------------------- parser


@pytest.mark.parametrize(
    "body",
    [
        # a tag-like first field that pandas would read as a number: still a tag
        "500\t70\t30\t200\t0.1\t0.1\ninf\t500\t70\t30\t200\t0.1\t0.1\n",
        "500\t70\t30\t200\t0.1\t0.1\nnan\t500\t70\t30\t200\t0.1\t0.1\n",
        # a blank line and a short first line; a longer line further on
        "500\t70\n\n600\t70\t30\t200\t0.1\t0.1\t\t5\n",
        # untagged rows only, last line without LF
        "500\t70\t30\t200\t0.1\t0.1\r\n600\t70\t31\t201\t0.1\t0.1",
    ],
)
def test_block_parser_agrees_with_the_strict_parser(body):
    fast = parse_block("f", body, 5, 8, tagged=True)
    slow = _slow("f", body, 5, 8, "\t", True)
    np.testing.assert_array_equal(fast.values, slow.values)
    np.testing.assert_array_equal(fast.lines, slow.lines)
    assert list(fast.tags) == list(slow.tags) and fast.blank_lines == slow.blank_lines
    ascii_ = parse_block("f", None, 5, 8, tagged=True, data=b"xx\n" + body.encode(), data_start=3)
    np.testing.assert_array_equal(ascii_.values, slow.values)
    np.testing.assert_array_equal(ascii_.lines, slow.lines)


def test_block_parser_needs_text_or_bytes():
    with pytest.raises(TypeError, match="needs body or data"):
        parse_block("f", None, 1, 2)


def test_block_parser_from_bytes_reports_a_bad_field_with_its_line():
    data = HEAD + b"500\t70\t30\t200\t0.1\t0.1\r\n600\t70\t3x\t200\t0.1\t0.1\r\n"
    with pytest.raises(labbrdf.AdapterError, match="line 6.*field 3: expected a number"):
        parse_block("f", None, 5, 8, tagged=True, data=data, data_start=len(HEAD))


# ----------------------------------------------------------------------------- reader


def _rows(n: int, seed: int = 5) -> bytes:
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        psi, delta = rng.uniform(1, 89), rng.uniform(-180, 180)
        out.append(f"{400 + i}\t{65 + i % 3}\t{psi:.6f}\t{delta:.6f}\t0.01\t0.02\r\n")
    return "".join(out).encode()


def test_ascii_and_decoded_files_give_the_same_table(tmp_path):
    body = _rows(50)
    a = tmp_path / "a.dat"
    a.write_bytes(HEAD + body)
    b = tmp_path / "b.dat"
    b.write_bytes(HEAD.replace(b"fast path", b"fast path \xc2\xb5m") + body)  # UTF-8 title
    ma, mb = labbrdf.read(a), labbrdf.read(b)
    assert ma.meta["encoding"] == mb.meta["encoding"] == "utf-8"
    assert mb.meta["title"] == "fast path \u00b5m"
    cols = [c for c in ma.data.columns if c not in ("sample", "source")]
    pd.testing.assert_frame_equal(ma.data[cols], mb.data[cols], check_exact=True)
    assert len(ma) == 100 and ma.data["value"].between(0, 360).all()


def test_theta_columns_do_not_share_memory(tmp_path):
    p = tmp_path / "a.dat"
    p.write_bytes(HEAD + _rows(4))
    d = labbrdf.read(p).data
    th_i, th_r = d["theta_i_deg"].to_numpy(), d["theta_r_deg"].to_numpy()
    assert not np.shares_memory(th_i, th_r)


def test_inf_and_minus_inf_in_one_row_are_dropped_not_missing(tmp_path):
    # psi + delta sums to NaN here: the fast "missing field" test must look closer
    p = tmp_path / "a.dat"
    p.write_bytes(HEAD + _rows(3) + b"700\t65\tinf\t-inf\t0.01\t0.02\r\n")
    m = labbrdf.read(p)
    assert len(m) == 6
    assert [(d["quantity"], d["count"]) for d in m.meta["dropped_rows"]] == [
        ("psi", 1),
        ("delta", 1),
    ]


@pytest.mark.parametrize(
    ("row", "match"),
    [
        (b"700\t65\t30\t200\t-0.01\t0.02", "line 8: sigma must be a finite number >= 0"),
        (b"700\t95\t30\t200\t0.01\t0.02", "line 8: angle of incidence must be within"),
        (b"700\t65\t91\t200\t0.01\t0.02", r"line 8: psi must be within \[0, 90\]"),
        (b"-700\t65\t30\t200\t0.01\t0.02", "line 8: spectral value must be a finite"),
        (b"700\t65\t30\t200\t0.01", "line 8: missing field"),
        (b"700\t65\t30\t200\t0.01\t0.02\t7", "line 8: too many fields"),
    ],
)
def test_a_bad_row_after_good_ones_is_named_by_line(tmp_path, row, match):
    p = tmp_path / "a.dat"
    p.write_bytes(HEAD + _rows(3) + row + b"\r\n" + _rows(2, seed=6))
    with pytest.raises(labbrdf.AdapterError, match=match):
        labbrdf.read(p)


def test_measurement_of_a_large_untagged_file_keeps_every_check(tmp_path):
    # 20 000 lines: big enough for the in-place paths, small enough for a unit test
    p = tmp_path / "big.dat"
    p.write_bytes(HEAD + _rows(20_000))
    m = labbrdf.read(p)
    assert isinstance(m, Measurement) and len(m) == 40_000
    assert m.meta["data_lines"] == 20_000 and m.meta["blank_lines_skipped"] == 0
    d = m.data
    psi = d[d["quantity"] == "psi"]
    assert psi["value"].between(0, 90).all() and (d["phi_r_deg"] == 180.0).all()


def test_csv_is_exact_even_under_numpy_legacy_printing(tmp_path):
    # colour-science, imported by the report, sets numpy's 12-digit legacy="1.13" printing
    df = _table()
    df["value"] = df["value"] + np.arange(6) / 3.0  # non-terminating binary fractions
    m = Measurement(df)
    with np.printoptions(legacy="1.13"):
        back = labbrdf.dataset.read_csv(labbrdf.dataset.write_csv(m, tmp_path / "t.csv"))
    pd.testing.assert_frame_equal(back.data, m.data, check_exact=True)
