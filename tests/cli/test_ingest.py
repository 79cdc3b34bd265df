"""``labbrdf ingest``: the channel of each quantity and an unstated wavelength, in the JSON
and in the table."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from labbrdf.cli import main

WVASE = "woollam-wvase-ascii"
FILES = {
    "rp": f"{WVASE}/ta2o5_02262007_rp.dat",  # reflectance, channel p
    "rs": f"{WVASE}/ta2o5_02262007_rs.dat",  # reflectance, channel s
    "ge": f"{WVASE}/w1_al2o3_20081120_anisotropy.dat",  # psi, delta in pp, ps, sp
    "plain": f"{WVASE}/w2_10102006.dat",  # psi, delta without a channel
    "bsdf": "zemax-bsdf/test_13_planesymmetric_brdf_zemax.bsdf",  # no wavelength stated
}


@pytest.fixture(scope="module")
def files(real_exports: Path) -> dict[str, Path]:
    out = {k: real_exports / v for k, v in FILES.items()}
    missing = [str(p) for p in out.values() if not p.is_file()]
    if missing:
        pytest.skip(f"absent: {missing}")
    return out


def test_ingest_json_shows_the_channel_of_each_quantity(files, capsys):
    assert main(["ingest", *map(str, files.values()), "--json"]) == 0
    out = {Path(o["file"]).name: o for o in json.loads(capsys.readouterr().out)}
    by = {k: out[Path(v).name] for k, v in FILES.items()}
    assert by["rp"]["quantities"] == by["rs"]["quantities"] == ["reflectance"]
    assert by["rp"]["channels"] == {"reflectance": ["p"]}
    assert by["rs"]["channels"] == {"reflectance": ["s"]}
    assert by["ge"]["channels"] == {"psi": ["pp", "ps", "sp"], "delta": ["pp", "ps", "sp"]}
    assert by["plain"]["channels"] == {} and by["plain"]["quantities"] == ["psi", "delta"]
    assert by["bsdf"]["wavelength_stated"] is False and by["rp"]["wavelength_stated"] is True


def test_ingest_table_has_a_channel_column_and_says_wavelength_not_stated(files, capsys):
    assert main(["ingest", *map(str, files.values())]) == 0
    lines = capsys.readouterr().out.splitlines()
    head = lines[0].split()
    assert head[:6] == ["file", "format", "sample", "quantities", "channel", "wavelength_nm"]
    col = lines[0].index("channel")
    wl = lines[0].index("wavelength_nm")
    cells = {ln.split()[0]: (ln[col:wl].strip(), ln[wl:].split()[0]) for ln in lines[1:]}
    assert cells[Path(FILES["rp"]).name][0] == "p"
    assert cells[Path(FILES["rs"]).name][0] == "s"
    assert cells[Path(FILES["ge"]).name][0] == "pp,ps,sp"
    assert cells[Path(FILES["plain"]).name][0] == "-"
    assert cells[Path(FILES["bsdf"]).name] == ("-", "not")  # "not stated", not "555-555"
    assert "not stated" in lines[[ln.split()[0] for ln in lines].index(Path(FILES["bsdf"]).name)]


def test_channels_cell_names_the_quantity_when_channels_differ():
    from labbrdf.cli.ingest import _channels_cell

    assert _channels_cell({}) == "-"
    assert _channels_cell({"reflectance": ["p"], "transmittance": ["s"]}) == (
        "reflectance:p transmittance:s"
    )


def test_ingest_prints_every_readers_notes_with_the_file_name(real_exports: Path, capsys):
    """The Jaz reader notes the rows it dropped (no reference above dark); ``ingest`` shows
    it on stderr, one line per note, as it does for the columns reader's skipped lines."""
    jaz = real_exports / "oceanoptics-jaz" / "oo-reflectance.jaz"
    if not jaz.is_file():
        pytest.skip(f"absent: {jaz}")
    assert main(["ingest", str(jaz)]) == 0
    err = capsys.readouterr().err.splitlines()
    notes = [ln for ln in err if ln.startswith(f"labbrdf ingest: note: {jaz}: ")]
    assert len(notes) == 1 and "11 rows dropped" in notes[0], err


def test_ingest_prints_no_note_line_for_a_reader_without_notes(files, capsys):
    assert main(["ingest", str(files["rp"])]) == 0
    assert "note:" not in capsys.readouterr().err
