"""The HTML validation report: structure, numbers, exit codes, atomicity, escaping.

One quick validation report is built per test session (module fixture); the other tests
build small reports (a subset of the sections, or a user report of a generated file).
"""

from __future__ import annotations

import base64
import json
import math
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from labbrdf import report
from labbrdf.report import builder as _common  # the module was report/_common.py
from labbrdf.report import html
from labbrdf.report.builder import Builder, Unavailable, fmt, resolve
from labbrdf.report.validate import SECTION_IDS as SECTIONS

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


class _Page(HTMLParser):
    """Collects tags, attributes, text and the data-key cells of a page."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict[str, str | None]]] = []
        self.cells: list[tuple[str, str, str]] = []  # (data-key, data-fmt, text)
        self.td_keyed = 0
        self.td_plain = 0
        self._open: list[tuple[str, str, str, list[str]] | None] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append((tag, a))
        if tag == "td":
            if "data-key" in a:
                self.td_keyed += 1
            else:
                self.td_plain += 1
        if tag in ("td", "span"):
            keyed = "data-key" in a
            self._open.append((tag, a["data-key"], a.get("data-fmt", ""), []) if keyed else None)

    def handle_endtag(self, tag):
        if tag in ("td", "span") and self._open:
            entry = self._open.pop()
            if entry is not None:
                assert entry[0] == tag
                self.cells.append((entry[1], entry[2], "".join(entry[3])))

    def handle_data(self, data):
        self.text.append(data)
        for entry in self._open:
            if entry is not None:
                entry[3].append(data)


def _parse(path: Path) -> _Page:
    p = _Page()
    p.feed(path.read_text(encoding="utf-8"))
    p.close()
    return p


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory: pytest.TempPathFactory) -> tuple[int, Path, dict]:
    out = tmp_path_factory.mktemp("report") / "validation"
    code = report.validate(out=out, quick=True, progress=False)
    return code, out, json.loads((out / "results.json").read_text(encoding="utf-8"))


# --------------------------------------------------------------------------- quick report


def test_quick_report_passes_and_writes_html_json_csv(quick_report):
    code, out, results = quick_report
    failed = [(c["id"], c["reason"]) for c in results["checks"] if c["status"] == "fail"]
    assert failed == []
    assert code == 0
    assert results["summary"]["exit_code"] == 0
    assert (out / "index.html").is_file()
    csvs = {p.stem for p in (out / "tables").glob("*.csv")}
    assert csvs == set(results["tables"]) | {"checks"}


def test_quick_report_has_every_section_of_the_issue(quick_report):
    _, _, results = quick_report
    ids = [s["id"] for s in results["sections"]]
    assert ids == list(SECTIONS)
    # sections that depend only on the bundled fixtures and the models must have run
    status = {s["id"]: s["status"] for s in results["sections"]}
    for sid in (
        "ingest",
        "fits",
        "scans",
        "spectra",
        "hemispherical",
        "physics",
        "compare",
        "colour",
        "model_measurement",
        "errata",
    ):
        assert status[sid] == "ok", (sid, results["sections"][ids.index(sid)]["reason"])


def test_html_parses_and_has_no_external_resources(quick_report):
    _, out, _ = quick_report
    page = _parse(out / "index.html")
    names = [t for t, _ in page.tags]
    assert names.count("html") == 1 and "body" in names
    assert "script" not in names and "link" not in names and "iframe" not in names
    for tag, a in page.tags:
        for attr in ("src", "href"):
            v = a.get(attr)
            if v is None:
                continue
            if attr == "href":
                assert v.startswith("#"), (tag, v)
            else:
                assert v.startswith("data:image/png;base64,"), (tag, v[:40])
    assert "url(" not in (out / "index.html").read_text(encoding="utf-8")


def test_every_figure_is_an_embedded_nonempty_png(quick_report):
    _, out, results = quick_report
    page = _parse(out / "index.html")
    imgs = [a for t, a in page.tags if t == "img"]
    assert len(imgs) == len(results["figures"]) > 5
    for a in imgs:
        raw = base64.b64decode(a["src"].split(",", 1)[1], validate=True)
        assert raw.startswith(PNG_MAGIC)
        # width and height from the IHDR chunk: a real picture, not a 1x1 placeholder
        w, h = int.from_bytes(raw[16:20], "big"), int.from_bytes(raw[20:24], "big")
        assert w > 200 and h > 150


def test_every_figure_has_a_caption_naming_measured_and_modelled(quick_report):
    _, _, results = quick_report
    for fid, f in results["figures"].items():
        cap = f["caption"].lower()
        assert "modelled" in cap or "measured" in cap, fid


def test_every_table_number_equals_results_json(quick_report):
    _, out, results = quick_report
    page = _parse(out / "index.html")
    n_cells = sum(len(t["rows"]) * len(t["columns"]) for t in results["tables"].values())
    n_checks = len(results["checks"])
    # every cell of a data table and the value/tolerance cells of every check carry a
    # data-key; the only plain cells are the 4 text columns of the check tables
    assert page.td_keyed == n_cells + 2 * n_checks
    assert page.td_plain == 4 * n_checks
    numbers = 0
    for key, spec, text in page.cells:
        value = resolve(results, key)
        assert text == fmt(value, spec), (key, text, value)
        numbers += isinstance(value, (int, float)) and not isinstance(value, bool)
    assert numbers > 100


def test_csv_tables_equal_results_json(quick_report):
    import csv

    _, out, results = quick_report
    for tid, t in results["tables"].items():
        with open(out / "tables" / f"{tid}.csv", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
        assert len(rows) == len(t["rows"]), tid
        for got, want in zip(rows, t["rows"], strict=True):
            for k, v in want.items():
                if isinstance(v, float):
                    assert float(got[k]) == v, (tid, k)
                elif v is None:
                    assert got[k] == ""


def test_every_check_says_status_and_against_what(quick_report):
    _, _, results = quick_report
    assert results["checks"]
    for c in results["checks"]:
        assert c["status"] in _common.STATUSES
        assert c["against"], c["id"]
        if c["status"] == "skipped":
            assert c["reason"], c["id"]
        elif c["tolerance"] is not None:
            assert c["justification"], c["id"]


def test_results_json_is_strict_json(quick_report):
    _, out, _ = quick_report
    json.loads(
        (out / "results.json").read_text(encoding="utf-8"),
        parse_constant=lambda s: pytest.fail(f"non-JSON constant {s}"),
    )


def test_fits_recover_published_parameters_within_four_sigma(quick_report):
    _, _, results = quick_report
    c = {x["id"]: x for x in results["checks"]}["fits.smooth3.published"]
    assert c["status"] == "pass"
    assert c["value"] <= 4.0


def test_table3_is_reproduced_at_46_not_45_degrees(quick_report):
    _, _, results = quick_report
    rows = results["tables"]["hemispherical"]["rows"]
    by_wl = {r["wavelength_nm"]: r for r in rows}
    # docs/models.md 1.2: 42.93 / 56.54 / 58.98 % at 46 deg, printed to 2 decimals
    for wl, want in ((360.0, 0.4293), (500.0, 0.5654), (550.0, 0.5898)):
        assert by_wl[wl]["paper_46"] == pytest.approx(want, abs=5e-5)
        assert by_wl[wl]["t3_integration"] - by_wl[wl]["paper_45"] > 0.013


def test_colour_of_osr_is_computed_from_the_sphere_spectra(quick_report):
    _, _, results = quick_report
    rows = results["tables"]["colour"]["rows"]
    assert rows
    for r in rows:
        assert re.fullmatch(r"#[0-9a-f]{6}", r["hex"])
        assert r["wl_min"] == 360.0 and r["wl_max"] == 550.0
        assert "constant extrapolation" in r["method"]
        # the three-point file is too few points for a colour
        if r["points"] == 3:
            assert r["reliable"] is False


# --------------------------------------------------------------------------- exit codes


def test_deliberately_failing_check_makes_exit_code_1(tmp_path):
    def failing(b: Builder) -> None:
        b.check("test.fail", "a check that fails on purpose", False, against="nothing")

    code = report.validate(
        out=tmp_path / "r", quick=True, progress=False, sections_to_run=[], extra_checks=[failing]
    )
    assert code == 1
    res = json.loads((tmp_path / "r" / "results.json").read_text())
    assert res["summary"]["fail"] == 1 and res["summary"]["exit_code"] == 1
    assert "test.fail" in (tmp_path / "r" / "index.html").read_text()


def test_corrupted_fixture_folder_fails_the_ingest_check(tmp_path, fixtures_dir):
    fx = tmp_path / "fixtures"
    (fx / "specular").mkdir(parents=True)
    good = fixtures_dir / "specular" / "osr_specular.csv"
    (fx / "specular" / good.name).write_bytes(good.read_bytes())
    lines = good.read_text().splitlines()
    lines[9] = "360,30,not-a-number,180,0.12,0.0006"
    (fx / "specular" / "broken.csv").write_text("\n".join(lines) + "\n")
    code = report.validate(
        out=tmp_path / "r", quick=True, progress=False, fixtures_dir=fx, sections_to_run=[]
    )
    assert code == 1
    res = json.loads((tmp_path / "r" / "results.json").read_text())
    c = {x["id"]: x for x in res["checks"]}["ingest.read"]
    assert c["status"] == "fail"
    assert "broken.csv" in c["reason"] and "line 10" in c["reason"]
    assert c["value"] == 1 and c["tolerance"] == 2


def test_section_with_missing_module_is_skipped_never_passed():
    b = Builder("t")
    with b.section("a", "needs a module"):
        raise Unavailable("module xyz missing")
    with b.section("b", "import error"):
        import labbrdf_no_such_module  # noqa: F401
    assert b.finish() == 0
    assert [c["status"] for c in b.results["checks"]] == ["skipped", "skipped"]
    assert b.results["sections"][0]["reason"] == "module xyz missing"
    assert b.results["sections"][0]["status"] == "not available"


def test_section_that_raises_is_a_failed_check():
    b = Builder("t")
    with b.section("a", "buggy"):
        raise ZeroDivisionError("boom")
    assert b.finish() == 1
    c = b.results["checks"][0]
    assert c["status"] == "fail" and "ZeroDivisionError: boom" in c["reason"]


def test_report_builds_without_shared_and_skips_oracle_checks(tmp_path):
    code = report.validate(
        out=tmp_path / "r",
        quick=True,
        progress=False,
        shared_dir=False,
        sections_to_run=["tracer_validation"],
    )
    res = json.loads((tmp_path / "r" / "results.json").read_text())
    sec = {s["id"]: s for s in res["sections"]}["tracer_validation"]
    assert sec["status"] != "not available", sec["reason"]  # the tracer is part of labbrdf
    checks = {c["id"]: c for c in res["checks"]}
    for cid in ("tracer.albedo_oracle", "tracer.inplane_oracle"):
        assert checks[cid]["status"] == "skipped"
        assert "../shared" in checks[cid]["reason"]
    assert code == 0


def test_unknown_section_name_is_refused(tmp_path):
    with pytest.raises(ValueError, match="unknown section.*'nope'"):
        report.validate(out=tmp_path / "r", sections_to_run=["nope"], progress=False)


# --------------------------------------------------------------------------- atomicity


def _leftovers(parent: Path, name: str) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if p.name.startswith(f".{name}."))


def test_failed_run_leaves_previous_report_intact(tmp_path, monkeypatch):
    out = tmp_path / "validation"
    assert report.validate(out=out, progress=False, sections_to_run=[]) == 0
    # a user's file in the report would now be refused up front; the old report's own
    # files are the fingerprint
    before = (out / "index.html").read_bytes()
    results_before = (out / "results.json").read_bytes()

    def broken_render(*a, **k):
        raise RuntimeError("disk full while rendering")

    monkeypatch.setattr(html, "render", broken_render)
    with pytest.raises(RuntimeError, match="disk full"):
        report.validate(out=out, progress=False, sections_to_run=[])
    assert (out / "results.json").read_bytes() == results_before
    assert (out / "index.html").read_bytes() == before
    assert _leftovers(tmp_path, "validation") == []


def test_failure_while_writing_leaves_previous_report_intact(tmp_path):
    out = tmp_path / "rep"
    _common.atomic_dir(out, lambda d: (d / "a.txt").write_text("1"))

    def half_written(d: Path) -> None:
        (d / "a.txt").write_text("2")
        raise OSError("interrupted")

    with pytest.raises(OSError, match="interrupted"):
        _common.atomic_dir(out, half_written)
    assert (out / "a.txt").read_text() == "1"
    assert _leftovers(tmp_path, "rep") == []


def test_successful_run_replaces_the_old_report(tmp_path):
    out = tmp_path / "validation"
    assert report.validate(out=out, progress=False, sections_to_run=[]) == 0
    (out / "tables" / "checks.csv").unlink()  # the user removed one of our files: still ours
    old = json.loads((out / "results.json").read_text())["meta"]["created_utc"]
    assert report.validate(out=out, progress=False, sections_to_run=[]) == 0
    assert (out / "index.html").is_file() and (out / ".labbrdf-report").is_file()
    assert json.loads((out / "results.json").read_text())["meta"]["created_utc"] >= old
    assert _leftovers(tmp_path, "validation") == []


def test_a_folder_that_is_not_a_report_is_never_replaced(tmp_path):
    out = tmp_path / "validation"
    out.mkdir()
    (out / "stale.txt").write_text("mine")
    with pytest.raises(ValueError, match="not empty and not a labbrdf report"):
        report.validate(out=out, progress=False, sections_to_run=[])
    assert (out / "stale.txt").read_text() == "mine"
    assert [p.name for p in out.iterdir()] == ["stale.txt"]
    assert _leftovers(tmp_path, "validation") == []


# --------------------------------------------------------------------------- user report


def _scan_file(path: Path, sample: str, notes: str) -> Path:
    """A labbrdf specular-scan CSV made from smooth3 (OSR 550 nm parameters) + 0.5 % noise."""
    rng = np.random.default_rng(7)
    k1, k2, k3 = 1.015, -0.0166, 0.4176
    lines = [
        "# labbrdf specular-scan v1",
        f"# sample: {sample}",
        "# instrument: test rig",
        "# quantity: brdf",
        "# unit: sr-1",
        f"# notes: {notes}",
        "wavelength_nm,theta_i_deg,theta_r_deg,value,sigma",
    ]
    for wl in (500.0, 550.0):
        for ti in (30.0, 45.0, 60.0):
            for tr in np.arange(ti - 2, ti + 2.01, 0.2):
                a, r = math.radians(ti), math.radians(tr)
                f = k1 / (8 * math.cos(a) * math.cos(r)) * math.exp(-(((a - r - k2) / k3) ** 2))
                s = 0.005 * f
                lines.append(f"{wl:g},{ti:g},{tr:.1f},{f + s * rng.standard_normal():.6f},{s:.6f}")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_sample_name_from_file_is_escaped_not_executed(tmp_path):
    evil = "<script>alert(1)</script>"
    f = _scan_file(tmp_path / "evil.csv", evil, '<img src=x onerror="alert(2)">')
    out = tmp_path / "r"
    code = report.user_report([f], "smooth3", out, progress=False)
    assert code == 0
    text = (out / "index.html").read_text(encoding="utf-8")
    page = _parse(out / "index.html")
    names = [t for t, _ in page.tags]
    assert "script" not in names
    assert all(a.get("src", "data:").startswith("data:") for t, a in page.tags if t == "img")
    assert not any(k.startswith("on") for _, a in page.tags for k in a)
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in text
    assert evil not in text
    # the text itself is shown: the parser gives it back as data
    assert evil in "".join(page.text)
    assert 'onerror="alert(2)"' not in text


def test_user_report_shows_ingest_fits_and_checks(tmp_path):
    f = _scan_file(tmp_path / "scan.csv", "tile 7", "plain")
    out = tmp_path / "r"
    assert report.user_report([f], "smooth3", out, progress=False) == 0
    res = json.loads((out / "results.json").read_text())
    fits = res["tables"]["fit_smooth3"]["rows"]
    assert [r["wavelength_nm"] for r in fits] == [500.0, 550.0]
    # the generating k1 lies inside the reported 95 % interval
    for r in fits:
        assert r["k1_lo"] <= 1.015 <= r["k1_hi"]
    ids = {c["id"]: c["status"] for c in res["checks"]}
    assert ids["ingest.read"] == "pass" and ids["fits.smooth3.success"] == "pass"
    assert ids["colour.available"] == "skipped"


def test_user_report_unreadable_file_fails_with_the_file_named(tmp_path):
    bad = tmp_path / "nothing.csv"
    bad.write_text("# labbrdf specular-scan v1\n# quantity: brdf\nwavelength_nm,value\n")
    good = _scan_file(tmp_path / "scan.csv", "tile", "plain")
    assert report.user_report([good, bad], "smooth3", tmp_path / "r", progress=False) == 1
    res = json.loads((tmp_path / "r" / "results.json").read_text())
    c = {x["id"]: x for x in res["checks"]}["ingest.unreadable"]
    assert c["status"] == "fail" and "nothing.csv" in c["reason"]
    assert [r["file"] for r in res["tables"]["ingested_files"]["rows"]] == ["scan.csv"]


def test_user_report_refuses_unknown_model(tmp_path):
    f = _scan_file(tmp_path / "scan.csv", "tile", "plain")
    with pytest.raises(ValueError, match="model: unknown model 'nope'"):
        report.user_report([f], "nope", tmp_path / "r", progress=False)
    assert not (tmp_path / "r").exists()


def test_user_report_refuses_empty_paths(tmp_path):
    with pytest.raises(ValueError, match="paths: expected at least one"):
        report.user_report([], "smooth3", tmp_path / "r", progress=False)


def test_user_report_refuses_unknown_keyword(tmp_path):
    with pytest.raises(TypeError, match="unexpected keyword.*'colour'"):
        report.user_report(["x"], "smooth3", tmp_path / "r", colour=True)


# --------------------------------------------------------------------------- formatting


@pytest.mark.parametrize(
    ("value", "spec", "text"),
    [
        (None, ".3g", "\u2014"),
        (float("nan"), ".3g", "\u2014"),
        (0.41521, "%", "41.52"),
        (3.0, "d", "3"),
        (7, "", "7"),
        (1.23456789, "", "1.23457"),
        (True, "", "yes"),
        ("<b>", "", "<b>"),
        ([0.1, 0.25], "%", "[10.00, 25.00]"),
    ],
)
def test_fmt_is_the_one_formatting_function(value, spec, text):
    assert fmt(value, spec) == text


def test_render_refuses_a_figure_that_is_not_an_embedded_png():
    b = Builder("t")
    b.finish()
    with pytest.raises(ValueError, match="figure 'x' is not an embedded PNG"):
        html.render(b.results, {"x": "http://example.com/a.png"})


def test_builder_refuses_bad_status_and_swatch():
    b = Builder("t")
    with pytest.raises(ValueError, match="check status must be one of"):
        b.check("x", "x", "ok")
    with b.section("s", "s"):
        with pytest.raises(ValueError, match="bad colour"):
            b.swatch("s", "red; background:url(x)")


def test_builder_refuses_duplicate_ids_and_empty_figures():
    b = Builder("t")
    with b.section("s", "s"):
        b.table("t1", "t", [("a", "a", "")], [{"a": 1}])
        with pytest.raises(ValueError, match="duplicate table id 't1'"):
            b.table("t1", "t", [("a", "a", "")], [{"a": 1}])
        with pytest.raises(ValueError, match="figure 'f' has no image"):
            b.figure("f", "f", "caption", "")
        b.figure("g", "g", "caption", "data:image/png;base64,AAAA")
        with pytest.raises(ValueError, match="duplicate figure id 'g'"):
            b.figure("g", "g", "caption", "data:image/png;base64,AAAA")


def test_progress_lines_go_to_stderr(tmp_path, capsys):
    report.validate(out=tmp_path / "r", progress=True, sections_to_run=[])
    err = capsys.readouterr().err
    assert "section ingest" in err and "wrote" in err


def test_save_trace_maps_png_writes_a_png(tmp_path):
    import labbrdf
    from labbrdf.report.figures import save_trace_maps_png

    # the PNG is the result's own figure (TraceResult.plot): a real, small result
    res = labbrdf.trace(
        labbrdf.TraceConfig(
            wavelength_nm=650,
            theta_i_deg=45,
            rays=500,
            seed=1,
            substrate=labbrdf.Substrate(n=1.55, k=7.71, alpha=0.2),
            scattering="single",
            estimator="counting",
        )
    )
    p = save_trace_maps_png(res, tmp_path / "maps.png")
    assert p.read_bytes().startswith(PNG_MAGIC)


# --------------------------------------------------------------------------- one count


def _page_tally(page: Path) -> dict[str, int]:
    """Statuses of the checks as the page shows them (one element per check)."""
    p = _parse(page)
    shown = [a for _, a in p.tags if str(a.get("id") or "").startswith("check-")]
    ids = [a["id"] for a in shown]
    assert len(ids) == len(set(ids)), "a check is shown twice"
    return {s: sum(a.get("data-status") == s for a in shown) for s in _common.STATUSES}


def _headline_numbers(text: str) -> dict[str, int]:
    m = re.fullmatch(
        r"(\d+) checks? passed(?: \((\d+) of them bookkeeping\))?, (\d+) failed, "
        r"(\d+) not applicable",
        text,
    ) or re.fullmatch(
        r"nothing checked beyond bookkeeping \((\d+) bookkeeping checks?, (\d+) not applicable\)",
        text,
    )
    assert m is not None, text
    g = [int(x) if x is not None else 0 for x in m.groups()]
    if len(g) == 2:
        return {"pass": g[0], "bookkeeping": g[0], "fail": 0, "skipped": g[1]}
    return {"pass": g[0], "bookkeeping": g[1], "fail": g[2], "skipped": g[3]}


def _assert_one_count(out: Path, res: dict) -> None:
    summary = res["summary"]
    t = _common.tally(res["checks"])
    assert {k: summary[k] for k in t} == t
    assert summary["total"] == len(res["checks"]) == t["pass"] + t["fail"] + t["skipped"]
    assert _headline_numbers(summary["headline"]) == {
        k: t[k] for k in ("pass", "bookkeeping", "fail", "skipped")
    }
    assert _page_tally(out / "index.html") == {s: t[s] for s in _common.STATUSES}
    rows = (out / "tables" / "checks.csv").read_text().splitlines()[1:]
    assert len(rows) == t["total"]


def test_validation_report_headline_page_and_results_json_count_alike(quick_report):
    _, out, res = quick_report
    assert res["summary"]["bookkeeping"] >= 1  # the case that made the counts differ
    _assert_one_count(out, res)


def test_user_report_that_fits_nothing_counts_alike_and_lists_what_did_not_apply(
    tmp_path, fixtures_dir
):
    f = fixtures_dir / "spectrophotometer" / "osr_sphere_cary.csv"  # no BRDF rows
    out = tmp_path / "r"
    report.user_report([f], "smooth3", out, progress=False)
    res = json.loads((out / "results.json").read_text())
    _assert_one_count(out, res)
    assert res["summary"]["bookkeeping"] >= 1
    # nothing was fitted: the title does not promise smooth3 fits
    assert res["title"] == "labbrdf report: 1 file(s), nothing fitted"
    page = (out / "index.html").read_text()
    assert "<title>labbrdf report: 1 file(s), nothing fitted</title>" in page
    # the sections that did not apply are listed once, with their reasons, not one
    # section and one check table each
    na = {n["section"]: n for n in res["not_applicable"]}
    assert {"fits", "scans", "spectra", "physics", "brdf", "surface"} <= set(na)
    assert page.count('id="not-applicable"') == 1
    for sid, n in na.items():
        assert f'id="sec-{sid}"' not in page
        assert n["reason"] and n["reason"] in page.replace("&#39;", "'")
    assert page.count("<h3>Checks</h3>") == sum(
        1
        for s in res["sections"]
        if s["id"] not in na and any(it["kind"] == "check" for it in s["items"])
    )


def test_user_report_with_fits_keeps_its_model_title(tmp_path):
    f = _scan_file(tmp_path / "scan.csv", "tile 7", "plain")
    out = tmp_path / "r"
    assert report.user_report([f], "smooth3", out, progress=False) == 0
    res = json.loads((out / "results.json").read_text())
    assert res["title"] == "labbrdf report: smooth3 fits"
    _assert_one_count(out, res)


def test_headline_counts_bookkeeping_passes_and_says_nothing_checked_without_others():
    checks = [
        {"status": "pass", "substantive": False},
        {"status": "pass"},
        {"status": "fail"},
        {"status": "skipped"},
    ]
    t = _common.tally(checks)
    assert t == {"pass": 2, "fail": 1, "skipped": 1, "total": 4, "bookkeeping": 1}
    assert _common.headline(t) == _common.headline(checks)
    assert _common.headline(t) == "2 checks passed (1 of them bookkeeping), 1 failed, " + (
        "1 not applicable"
    )
    only = [checks[0], checks[3]]
    assert _common.headline(only) == (
        "nothing checked beyond bookkeeping (1 bookkeeping check, 1 not applicable)"
    )
