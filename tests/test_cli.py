"""The labbrdf command: ingest table/JSON, failures, atomic output that never clobbers inputs."""

from __future__ import annotations

import json

import numpy as np
import pytest

from labbrdf.cli import main
from labbrdf.dataset import Measurement, make_frame, read, write


@pytest.fixture
def dataset_files(tmp_path):
    paths = []
    for name, th in (("a", 45.0), ("b", 60.0)):
        m = Measurement(
            make_frame(
                sample=f"S-{name}",
                instrument="synthetic",
                source=f"{name}.csv",
                quantity="brdf",
                value=np.linspace(1.0, 2.0, 5),
                unit="sr-1",
                wavelength_nm=np.linspace(400.0, 800.0, 5),
                theta_i_deg=th,
                theta_r_deg=th,
                phi_r_deg=180.0,
            ),
            {"note": name},
        )
        p = tmp_path / f"{name}.parquet"
        write(m, p)
        paths.append(p)
    return paths


def test_ingest_json_lists_one_object_per_file(dataset_files, capsys):
    assert main(["ingest", *map(str, dataset_files), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [o["file"] for o in out] == [str(p) for p in dataset_files]
    first = out[0]
    assert set(first) == {
        "file",
        "format",
        "sample",
        "rows",
        "quantities",
        "wavelength_nm",
        "theta_i_deg",
    }
    assert first["format"] == "labbrdf-parquet"
    assert first["rows"] == 5
    assert first["quantities"] == ["brdf"]
    assert first["wavelength_nm"] == [400.0, 800.0]
    assert out[1]["theta_i_deg"] == [60.0]


def test_ingest_table_names_columns(dataset_files, capsys):
    assert main(["ingest", str(dataset_files[0])]) == 0
    head = capsys.readouterr().out.splitlines()[0].split()
    assert head == [
        "file",
        "format",
        "sample",
        "quantities",
        "wavelength_nm",
        "theta_i_deg",
        "rows",
    ]


def test_ingest_writes_concatenation(dataset_files, tmp_path, capsys):
    out = tmp_path / "all.csv"
    assert main(["ingest", *map(str, dataset_files), "-o", str(out)]) == 0
    m = read(out)
    assert len(m) == 10
    assert sorted(set(m.data["sample"])) == ["S-a", "S-b"]
    assert [p["meta"]["note"] for p in m.meta["parts"]] == ["a", "b"]


def test_ingest_exits_2_on_first_unreadable_file(dataset_files, tmp_path, capsys):
    bad = tmp_path / "bad.xyz"
    bad.write_text("nothing to see\n")
    code = main(["ingest", str(bad), str(dataset_files[0]), "--json"])
    err = capsys.readouterr()
    assert code == 2
    assert str(bad) in err.err
    assert err.out == ""  # stopped at the first failure


def test_ingest_keep_going_reads_the_rest_and_lists_failures(dataset_files, tmp_path, capsys):
    bad = tmp_path / "bad.xyz"
    bad.write_text("nothing to see\n")
    out = tmp_path / "all.parquet"
    code = main(["ingest", str(bad), str(dataset_files[0]), "--keep-going", "-o", str(out)])
    cap = capsys.readouterr()
    assert code == 2
    assert "FAILED" in cap.err and str(bad) in cap.err
    assert len(read(out)) == 5


def test_ingest_refuses_to_overwrite_an_input(dataset_files, capsys):
    before = dataset_files[0].read_bytes()
    code = main(["ingest", *map(str, dataset_files), "-o", str(dataset_files[0])])
    assert code == 2
    assert "one of the input files" in capsys.readouterr().err
    assert dataset_files[0].read_bytes() == before


def test_ingest_rejects_unknown_output_type(dataset_files, tmp_path, capsys):
    assert main(["ingest", str(dataset_files[0]), "-o", str(tmp_path / "x.xlsx")]) == 2
    assert ".parquet or .csv" in capsys.readouterr().err


def test_ingest_unknown_format_lists_formats(dataset_files, capsys):
    assert main(["ingest", str(dataset_files[0]), "--format", "nope"]) == 2
    assert "supported formats are" in capsys.readouterr().err


def test_formats_json(capsys):
    assert main(["formats", "--json"]) == 0
    names = [f["name"] for f in json.loads(capsys.readouterr().out)]
    assert "labbrdf-parquet" in names


def test_dataset_csv_is_read_without_format(dataset_files, tmp_path, capsys):
    # .csv is shared by Cary, the labbrdf scan layouts and labbrdf datasets: the sniffer decides
    out = tmp_path / "all.csv"
    assert main(["ingest", *map(str, dataset_files), "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["ingest", str(out), "--json"]) == 0
    (obj,) = json.loads(capsys.readouterr().out)
    assert obj["format"] == "labbrdf-dataset-csv"
    assert obj["rows"] == 10


def test_every_real_export_reads_through_one_entry_point(real_exports):
    """Issue 3: all 29 real files read by labbrdf.read without naming the format."""
    import labbrdf

    files = sorted(p for p in real_exports.rglob("*") if p.is_file() and p.name != "PROVENANCE.md")
    assert len(files) == 29
    for p in files:
        m = labbrdf.read(p)
        assert len(m) > 0, p
        assert m.meta["format"] != "labbrdf-dataset-csv", p
