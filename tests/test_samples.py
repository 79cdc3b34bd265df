"""Pairing files by sample: stated names, a given mapping, and every way a mapping fails."""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd
import pytest

from labbrdf.samples import (
    PairingError,
    SampleFile,
    SampleGroup,
    group_of,
    pair_samples,
    sample_file,
    split_same_sample,
    stated_names,
)


@pytest.fixture
def files(tmp_path: Path) -> dict[str, Path]:
    out = {}
    for name in ("a.dat", "b.csv", "c.di", "d.bsdf", "e.txt"):
        out[name] = tmp_path / name
        out[name].write_text("x")
    return out


def test_files_sharing_a_stated_name_form_one_group_with_the_reason(files):
    groups = pair_samples(
        [(files["a.dat"], "Ta2O5-1"), (files["b.csv"], ["Ta2O5-1"]), (files["e.txt"], "other")]
    )
    assert groups[0] == SampleGroup(
        "Ta2O5-1", (files["a.dat"], files["b.csv"]), "sample name 'Ta2O5-1' in a.dat and b.csv"
    )
    assert groups[0].paired
    assert groups[1].paths == (files["e.txt"],)
    assert not groups[1].paired
    assert groups[1].reason == "no other file states the sample name 'other'"


def test_file_stem_names_do_not_pair(files, tmp_path):
    # readers fall back to the stem: two 'data.dat' in two folders are not one sample
    (tmp_path / "x").mkdir()
    (tmp_path / "y").mkdir()
    one, two = tmp_path / "x" / "data.dat", tmp_path / "y" / "data.dat"
    groups = pair_samples([(one, "data"), (two, "data #2"), (files["a.dat"], "a")])
    assert [g.paths for g in groups] == [(one,), (two,), (files["a.dat"],)]
    assert "states no sample name" in groups[0].reason
    assert "give a mapping" in groups[0].reason


@pytest.mark.parametrize(
    ("file_name", "sample", "stated"),
    [
        ("w1.dat", "w1", False),
        ("F4 0,5.Probe.Raw.asc", "F4 0,5", False),
        ("holmium.spc", "holmium #3", False),
        ("run.jdx", "run block 2", False),
        ("w1.dat", "Wafer 1", True),
        ("w1.dat", "w1-bis", True),
        ("w1.dat", "  ", False),
    ],
)
def test_stated_names_drop_file_name_fallbacks(file_name, sample, stated):
    f = SampleFile(Path("/d") / file_name, (sample,))
    assert stated_names(f) == ((sample,) if stated else ())


def test_given_mapping_pairs_files_without_names(files):
    groups = pair_samples(
        [files["a.dat"], (files["c.di"], ()), (files["e.txt"], "e")],
        [[files["c.di"], files["a.dat"]]],
        given_as="given with --same-sample",
    )
    assert groups[0].paths == (files["a.dat"], files["c.di"])
    assert groups[0].reason == "given with --same-sample (c.di and a.dat)"
    assert groups[0].name == "a.dat + c.di"
    assert groups[1].paths == (files["e.txt"],)


def test_given_mapping_names_the_group_after_the_files_names(files):
    groups = pair_samples(
        [(files["a.dat"], "Al mirror"), (files["c.di"], ()), (files["d.bsdf"], "d")],
        [[files["a.dat"], files["c.di"], files["d.bsdf"]]],
    )
    assert groups[0].name == "Al mirror"  # stated, before the .bsdf's file-stem name
    groups = pair_samples(
        [(files["c.di"], ()), (files["d.bsdf"], "d")], [[files["c.di"], files["d.bsdf"]]]
    )
    assert groups[0].name == "d"


def test_given_mapping_and_stated_names_combine(files):
    groups = pair_samples(
        [(files["a.dat"], "S1"), (files["b.csv"], "S1"), (files["c.di"], ())],
        [[files["c.di"], files["a.dat"]]],
    )
    assert len(groups) == 1
    assert groups[0].paths == (files["a.dat"], files["b.csv"], files["c.di"])
    assert "given as one sample" in groups[0].reason
    assert "sample name 'S1' in a.dat and b.csv" in groups[0].reason


def test_any_spelling_of_a_path_matches(files, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    link = tmp_path / "link.di"
    os.symlink(files["c.di"], link)
    groups = pair_samples([files["a.dat"], files["c.di"]], [["a.dat", str(link)]])
    assert len(groups) == 1
    assert group_of(groups, "./c.di") is groups[0]


def test_a_file_given_twice_counts_once_with_its_names_merged(files):
    groups = pair_samples([(files["a.dat"], "S"), (files["a.dat"], "T"), (files["b.csv"], "T")])
    assert len(groups) == 1
    assert groups[0].paths == (files["a.dat"], files["b.csv"])


def test_sample_file_reads_the_sample_column_and_height_map_meta(files):
    df = pd.DataFrame({"sample": ["S", "S", "T"]})
    assert sample_file(files["a.dat"], df).names == ("S", "T")

    class M:
        data = df

    assert sample_file(files["a.dat"], M()).names == ("S", "T")

    class H:
        meta = {"sample": " probe 7 "}

    assert sample_file(files["c.di"], H()).names == ("probe 7",)
    assert sample_file(files["c.di"], None).names == ()


def test_group_of_an_unknown_path_raises(files):
    groups = pair_samples([files["a.dat"]])
    with pytest.raises(KeyError, match="b.csv is in no sample group"):
        group_of(groups, files["b.csv"])


# ------------------------------------------------------------------------- error paths


def test_path_not_among_inputs_is_an_error(files, tmp_path):
    with pytest.raises(PairingError, match=r"group 1: .*nope\.di is not among the input files"):
        pair_samples([files["a.dat"], files["c.di"]], [[files["a.dat"], tmp_path / "nope.di"]])


def test_file_in_two_groups_is_an_error_naming_it(files):
    with pytest.raises(PairingError, match=r"a\.dat is in same-sample groups 1 and 2"):
        pair_samples(
            list(files.values()),
            [[files["a.dat"], files["b.csv"]], [files["c.di"], files["a.dat"]]],
        )


def test_file_listed_twice_in_a_group_is_an_error(files):
    with pytest.raises(PairingError, match=r"group 1: .*a\.dat is listed twice"):
        pair_samples(list(files.values()), [[files["a.dat"], files["a.dat"]]])


@pytest.mark.parametrize("group", [[], ["a.dat"]])
def test_group_of_fewer_than_two_files_is_an_error(files, group, monkeypatch):
    monkeypatch.chdir(files["a.dat"].parent)
    with pytest.raises(PairingError, match="expected two or more files"):
        pair_samples(list(files.values()), [group])


def test_a_bare_path_as_a_group_is_an_error(files):
    with pytest.raises(PairingError, match="got one path"):
        pair_samples(list(files.values()), [str(files["a.dat"])])  # type: ignore[list-item]


def test_given_groups_joined_by_stated_names_are_an_error(files):
    with pytest.raises(PairingError) as exc:
        pair_samples(
            [(files["a.dat"], "S"), files["b.csv"], (files["c.di"], "S"), files["d.bsdf"]],
            [[files["a.dat"], files["b.csv"]], [files["c.di"], files["d.bsdf"]]],
        )
    msg = str(exc.value)
    assert "groups 1 (a.dat and b.csv) and 2 (c.di and d.bsdf)" in msg
    assert "'S' in a.dat and c.di" in msg


def test_unknown_item_kind_is_a_type_error():
    with pytest.raises(TypeError, match="expected SampleFile"):
        pair_samples([42])  # type: ignore[list-item]


def test_real_exports_state_their_names_or_not(real_exports):
    from labbrdf import read
    from labbrdf.adapters.topography import read_height_map

    wv = real_exports / "woollam-wvase-ascii" / "w1_12082006.dat"
    bsdf = real_exports / "zemax-bsdf" / "test_13_planesymmetric_brdf_zemax.bsdf"
    di = real_exports / "topography" / "di-1.di"
    f_wv = sample_file(wv, read(wv))
    f_bsdf = sample_file(bsdf, read(bsdf))
    f_di = sample_file(di, read_height_map(di))
    assert stated_names(f_wv)  # WVASE states "Wafer 1 for Parul 12082006"
    assert f_bsdf.names == (bsdf.stem,) and stated_names(f_bsdf) == ()  # no name in .bsdf
    assert f_di.names == ()
    groups = pair_samples([f_wv, f_bsdf, f_di])
    assert [len(g.paths) for g in groups] == [1, 1, 1]
    groups = pair_samples([f_wv, f_bsdf, f_di], [[di, wv]])
    assert groups[0].paths == (wv, di)
    assert groups[0].name == stated_names(f_wv)[0]


def test_split_same_sample_keeps_commas_inside_file_names(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    odd = "F4 1-10 0,5 mgml.asc"
    inputs = [odd, "b.di", "c,d.dat"]
    assert split_same_sample(f"{odd},b.di", inputs) == [odd, "b.di"]
    assert split_same_sample(f"b.di,{odd},c,d.dat", inputs) == ["b.di", odd, "c,d.dat"]
    assert split_same_sample("./b.di,c,d.dat", inputs) == ["b.di", "c,d.dat"]


def test_split_same_sample_falls_back_to_every_comma(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    parts = split_same_sample("b.di,nope.dat,", ["b.di"])
    assert parts == ["b.di", "nope.dat"]
    with pytest.raises(PairingError, match="nope.dat is not among the input files"):
        pair_samples(["b.di"], [parts])


def _counted_keys(monkeypatch) -> list[str]:
    """Every path :func:`split_same_sample` resolves, recorded (the costly step)."""
    import labbrdf.samples as samples

    seen: list[str] = []
    real = samples._key

    def key(p):
        seen.append(os.fspath(p))
        return real(p)

    monkeypatch.setattr(samples, "_key", key)
    return seen


def test_split_same_sample_resolves_a_bounded_number_of_pieces(tmp_path, monkeypatch):
    """2,000 commas: the split is right and resolves O(commas) pieces, not O(commas^2).

    The old split tried every piece (2 million resolutions and joins of up to 2,000 parts:
    over two minutes); each comma now tries only the piece lengths an input can have.
    """
    monkeypatch.chdir(tmp_path)
    inputs = ["a.dat", "b,c.di", "d,e,f.csv"]
    seen = _counted_keys(monkeypatch)
    n = 2_000
    text = ",".join(inputs[i % 3] for i in range(n))
    got = split_same_sample(text, inputs)
    assert got == [inputs[i % 3] for i in range(n)]
    commas = text.count(",")
    assert commas > 3_900
    # distinct comma counts among the inputs (0, 1, 2): at most 3 pieces per comma (each
    # distinct piece is resolved once: here a handful), besides the inputs' own spellings
    assert len(seen) <= 3 * len(inputs) + 3 * (commas + 1)


def test_split_same_sample_of_2000_unknown_pieces_falls_back_at_once(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    seen = _counted_keys(monkeypatch)
    text = ",".join(f"x{i}" for i in range(2_000))
    assert split_same_sample(text, ["b.di"]) == [f"x{i}" for i in range(2_000)]
    assert len(seen) <= 3 + 2_000


def test_split_same_sample_takes_a_comma_spelt_by_an_absolute_path(tmp_path, monkeypatch):
    """The input relative, the value absolute through a folder with commas in its name."""
    folder = tmp_path / "run 1,2"
    folder.mkdir()
    monkeypatch.chdir(folder)
    inputs = ["a.dat", "b,c.di"]
    text = f"{folder / 'b,c.di'},a.dat"
    assert split_same_sample(text, inputs) == ["b,c.di", "a.dat"]
