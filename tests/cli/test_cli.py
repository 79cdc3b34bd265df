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
        "channels",
        "wavelength_nm",
        "wavelength_stated",
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
        "channel",
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
    kinds = {f["name"]: f["kind"] for f in json.loads(capsys.readouterr().out)}
    assert kinds["labbrdf-parquet"] == "optical"
    assert kinds["bruker-opdx"] == "height map"


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
    """Every optical real export reads by labbrdf.read without naming the format."""
    import labbrdf

    # topography/ holds height maps (read by SurfaceTopography, not by an optical adapter)
    not_ours = {"topography"}
    files = sorted(
        p
        for p in real_exports.rglob("*")
        if p.is_file() and p.name != "PROVENANCE.md" and p.parent.name not in not_ours
    )
    # 29 of the first collection + 6 of the second (its 9 less 3 height maps, the .bsdf in)
    # + 8 of the third round (Ta2O5 wafer three ways, UVProbe .txt/.spc, Ocean Optics,
    # headerless columns, legacy .jws) + 8 of the fourth (Avantes, Wasatch, CID, PSI, Jaz,
    # Ocean Optics .pi, Speos BSDF, NeXus)
    assert len(files) == 51
    # recognised and refused by name: raw counts and irradiance are no property of a sample
    refused = {
        "oceanoptics-pi": "raw detector",
        "avantes-avasoft": "radiometric",
        "psi-spectrapen": "not an optical property",
    }
    for p in files:
        if p.parent.name in refused:
            with pytest.raises(labbrdf.AdapterError, match=refused[p.parent.name]):
                labbrdf.read(p)
            continue
        # a headerless column file says nothing of itself: its columns are declared
        columns = "wavelength_nm,absorbance" if p.parent.name == "generic-columns" else None
        m = labbrdf.read(p, columns=columns)
        assert len(m) > 0, p
        assert m.meta["format"] != "labbrdf-dataset-csv", p


def test_fit_json_has_one_object_per_group(capsys, tmp_path, specular_scan):
    out = tmp_path / "params.csv"
    code = main(
        [
            "fit",
            str(specular_scan),
            "--model",
            "smooth3",
            "--scheduler",
            "serial",
            "--json",
            "-o",
            str(out),
        ]
    )
    assert code == 0
    groups = json.loads(capsys.readouterr().out)
    assert [g["group"]["wavelength_nm"] for g in groups] == [360.0, 500.0, 550.0, 860.0]
    g = groups[2]
    assert set(g) >= {"group", "params", "rmse", "nfev", "success"}
    assert set(g["params"]) == {"k1", "k2", "k3"}
    k1 = g["params"]["k1"]
    assert set(k1) == {"value", "stderr", "ci95", "at_bound"}
    # the fixture was generated from Table 1 (OSR 550 nm: k1 = 1.0150)
    assert k1["ci95"][0] <= 1.0150 <= k1["ci95"][1]
    import pandas as pd

    assert len(pd.read_csv(out)) == 4


def test_fit_fix_and_bad_names(capsys, specular_scan):
    scan = str(specular_scan)
    assert (
        main(
            ["fit", scan, "--model", "smooth3", "--scheduler", "serial", "--fix", "k2=0", "--json"]
        )
        == 0
    )
    groups = json.loads(capsys.readouterr().out)
    assert all(g["params"]["k2"]["value"] == 0.0 for g in groups)
    assert main(["fit", scan, "--model", "nope", "--scheduler", "serial"]) == 2
    assert "unknown model 'nope'" in capsys.readouterr().err
    assert main(["fit", scan, "--model", "smooth3", "--method", "GN_NOPE"]) == 2
    assert "GN_CRS2_LM" in capsys.readouterr().err  # lists the valid names
    assert main(["fit", scan, "--model", "smooth3", "--fix", "k2"]) == 2
    assert "expected NAME=VALUE" in capsys.readouterr().err
    assert main(["fit", scan, "--model", "smooth3", "--scheduler", "gpu"]) == 2
    assert "unknown scheduler" in capsys.readouterr().err


def test_hemispherical_json_matches_notes_table(capsys):
    # docs/models.md 1.2: OSR 550 nm published fit, rho = 57.0607 % at 45 deg, 58.9843 % at 46
    code = main(
        [
            "hemispherical",
            "--model",
            "smooth3",
            "--param",
            "k1=1.0150",
            "--param",
            "k2=-0.01660",
            "--param",
            "k3=0.4176",
            "--theta-i",
            "45",
            "46",
            "--json",
        ]
    )
    assert code == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["theta_i_deg"] for r in rows] == [45.0, 46.0]
    assert abs(rows[0]["rho"] - 0.570607) < 5e-7
    assert abs(rows[1]["rho"] - 0.589843) < 5e-7


def test_hemispherical_unknown_parameter(capsys):
    assert main(["hemispherical", "--model", "smooth3", "--param", "k9=1", "--theta-i", "45"]) == 2
    assert "k9" in capsys.readouterr().err


def test_trace_json_and_npz(tmp_path, capsys, trace_sample):
    out = tmp_path / "al.npz"
    code = main(
        [
            *trace_sample,
            "--rays",
            "20000",
            "--seed",
            "1",
            "--scheduler",
            "serial",
            "--single-scattering",
            "-o",
            str(out),
            "--json",
        ]
    )
    assert code == 0
    s = json.loads(capsys.readouterr().out)
    assert {"albedo", "energy", "rays", "seconds"} <= set(s)
    e = s["energy"]
    assert abs(e["exited"] + e["absorbed"] + e["terminated"] - 1.0) < 1e-12
    assert s["rays"] == 20000
    # single-scattering Al albedo at 45 deg, alpha 0.2 (oracles: ~0.85); loose physical bound
    assert 0.7 < s["albedo"] < 0.95
    import numpy as np

    d = np.load(out)
    assert d["mueller"].shape == (91, 360, 4, 4)
    assert d["theta_r_edges_deg"].shape == (92,) and d["phi_r_edges_deg"].shape == (361,)


def test_trace_bad_index_and_missing_thickness(capsys):
    base = ["trace", "--alpha", "0.2", "--theta-i", "45", "--wavelength", "650", "--rays", "10"]
    assert main([*base, "--substrate", "abc"]) == 2
    assert "expected a complex index" in capsys.readouterr().err
    assert main([*base, "--substrate", "1.5+7j", "--coating", "1.5"]) == 2
    assert "--coating needs --thickness" in capsys.readouterr().err
    assert main([*base, "--substrate", "1.5+7j", "--thickness", "100"]) == 2
    assert "need --coating" in capsys.readouterr().err


def test_report_command_writes_a_page_for_user_files(tmp_path, capsys, specular_scan):
    out = tmp_path / "rep"
    code = main(["report", str(specular_scan), "--model", "smooth3", "-o", str(out)])
    assert code == 0
    html = (out / "index.html").read_text()
    assert "data:image/png;base64," in html
    assert json.loads((out / "results.json").read_text())["summary"]["fail"] == 0


def test_report_command_records_an_unreadable_file_as_a_failed_check(tmp_path, capsys):
    bad = tmp_path / "bad.xyz"
    bad.write_text("x\n")
    out = tmp_path / "rep"
    assert main(["report", str(bad), "-o", str(out)]) == 1
    results = json.loads((out / "results.json").read_text())
    assert results["summary"]["fail"] == 1 and results["summary"]["pass"] == 0
    assert "bad.xyz: " in (out / "index.html").read_text()


def test_labbrdf_warnings_print_as_one_line_and_others_keep_their_format(monkeypatch, capsys):
    import warnings

    import labbrdf.cli.formats as cli_formats
    from labbrdf.tracer.cache import CacheWarning

    def formats(args):
        warnings.warn("cache file x.op was rebuilt: digest mismatch", CacheWarning, stacklevel=1)
        warnings.warn("a library's own words", UserWarning, stacklevel=1)
        return 0

    monkeypatch.setattr(cli_formats, "cmd_formats", formats)
    with pytest.warns(UserWarning, match="a library's own words") as seen:
        assert main(["formats"]) == 0
    err = capsys.readouterr().err
    assert err == "labbrdf formats: warning: cache file x.op was rebuilt: digest mismatch\n"
    assert [w.category for w in seen] == [UserWarning]  # handed on in Python's own way


def test_ctrl_c_while_the_parser_is_built_exits_130_without_traceback(monkeypatch, capsys):
    import labbrdf.cli._run as cli_run

    def interrupted(*args, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli_run, "build_parser", interrupted)
    assert main(["formats"]) == 130
    err = capsys.readouterr().err
    assert err == "labbrdf: interrupted\n"
