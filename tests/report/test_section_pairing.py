"""Sections nk and film pair files through the report's sample groups, never by count."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf import films
from labbrdf.dataset import Measurement, make_frame, write_csv
from labbrdf.report.builder import Builder
from labbrdf.report.context import Context
from labbrdf.report.inputs import ingest_files
from labbrdf.report.pairing import how_to_pair, same_sample, sample_groups, sample_groups_of
from labbrdf.report.sections.film import film_section
from labbrdf.report.sections.nk import nk_section

WL = np.arange(400.0, 901.0, 25.0)
ANGLES = (55.0, 65.0, 75.0)
N_BULK = 3.9 + 0.02j
# one Cauchy film (A + B / lambda^2 [um]) of D_NM on the bulk: a stack for section film
D_NM, A, B = 120.0, 1.46, 0.004
MODEL = """\
[substrate]
material = "constant"
n = 3.9
k = 0.02

[[layer]]
name = "oxide"
material = "cauchy"
thickness_nm = [60, 200]
A = [1.3, 1.7]
B = 0.004
"""


def _r(wl: np.ndarray, theta_deg: float, film: bool) -> tuple[np.ndarray, np.ndarray]:
    """r_s, r_p of the bare bulk or of the one film on it (Airy sum, written out here)."""
    s0 = np.sin(np.radians(theta_deg))
    c0 = np.cos(np.radians(theta_deg)) + 0j
    c2 = np.sqrt(1 - (s0 / N_BULK) ** 2 + 0j)
    if not film:
        return (c0 - N_BULK * c2) / (c0 + N_BULK * c2), (N_BULK * c0 - c2) / (N_BULK * c0 + c2)
    n1 = A + B / (wl / 1000.0) ** 2
    c1 = np.sqrt(1 - (s0 / n1) ** 2 + 0j)
    rs01 = (c0 - n1 * c1) / (c0 + n1 * c1)
    rs12 = (n1 * c1 - N_BULK * c2) / (n1 * c1 + N_BULK * c2)
    rp01 = (n1 * c0 - c1) / (n1 * c0 + c1)
    rp12 = (N_BULK * c1 - n1 * c2) / (N_BULK * c1 + n1 * c2)
    ph = np.exp(4j * np.pi * D_NM * n1 * c1 / wl)
    return (rs01 + rs12 * ph) / (1 + rs01 * rs12 * ph), (rp01 + rp12 * ph) / (1 + rp01 * rp12 * ph)


def _write(
    tmp: Path, film: bool, ell_sample: str, refl_sample: str, ell_name: str = "psi.csv"
) -> tuple[Path, Path]:
    """A psi/Delta file and a p/s reflectance file of one (bare or coated) sample."""
    ell, refl = [], []
    for th in ANGLES:
        rs, rp = _r(WL, th, film)
        rs, rp = np.broadcast_to(rs, WL.shape), np.broadcast_to(rp, WL.shape)
        rho = rp / rs
        psi = np.degrees(np.arctan(np.abs(rho)))
        delta = -np.degrees(np.angle(rho)) % 360.0
        for q, v, s in (("psi", psi, 0.02), ("delta", delta, 0.05)):
            ell.append(
                make_frame(sample=ell_sample, instrument="synthetic", source=ell_name,
                           quantity=q, value=v, sigma=s, unit="deg", wavelength_nm=WL,
                           theta_i_deg=th, theta_r_deg=th, phi_r_deg=180.0)
            )  # fmt: skip
        for ch, r in (("s", rs), ("p", rp)):
            f = make_frame(sample=refl_sample, instrument="synthetic", source="R.csv",
                           quantity="reflectance", value=np.abs(r) ** 2, sigma=0.002, unit="1",
                           wavelength_nm=WL, theta_i_deg=th, theta_r_deg=th,
                           phi_r_deg=180.0)  # fmt: skip
            refl.append(f.assign(channel=ch))
    pe, pr = tmp / ell_name, tmp / "R.csv"
    write_csv(Measurement(pd.concat(ell, ignore_index=True), {}), pe)
    write_csv(Measurement(pd.concat(refl, ignore_index=True), {}), pr)
    return pe, pr


def _run(paths: list[Path], same: list[list[Path]], film: bool) -> dict:
    """Ingest, pair, then section nk (and film with MODEL)."""
    b = Builder("t", progress=False)
    ctx = Context(b)
    with b.section("ingest", "Ingested files"):
        ingest_files(ctx, paths)
        sample_groups(ctx, paths, same)
    with b.section("nk", "n, k"):
        nk_section(ctx)
    if film:
        with b.section("film", "film"):
            film_section(ctx, _model(paths[0].parent))
    b.finish()
    b.results["_ctx"] = ctx
    return b.results


def _model(d: Path) -> films.FilmModel:
    p = d / "stack.toml"
    p.write_text(MODEL)
    return films.load_model(p)


def _notes(res: dict, sec: str) -> list[str]:
    s = {s["id"]: s for s in res["sections"]}[sec]
    return [it["text"] for it in s["items"] if it["kind"] == "note"]


def _checks(res: dict, prefix: str) -> list[dict]:
    return [c for c in res["checks"] if c["id"].startswith(prefix)]


# --------------------------------------------------------------------------- section nk


def test_nk_does_not_pair_the_only_ellipsometer_file_by_count(tmp_path: Path) -> None:
    pe, pr = _write(tmp_path, False, "bulk A", "bulk B")
    res = _run([pe, pr], [], film=False)
    assert _checks(res, "nk.reflectance") == []
    assert "nk_reflectance_comparison" not in res["tables"]
    (note,) = [n for n in _notes(res, "nk") if "R.csv" in n]
    assert "psi.csv is the only ellipsometer file" in note
    assert f"--same-sample {pe},{pr}" in note
    assert f"same_sample=[[{str(pe)!r}, {str(pr)!r}]]" in note


def test_nk_pairs_through_the_given_mapping(tmp_path: Path) -> None:
    pe, pr = _write(tmp_path, False, "bulk A", "bulk B")
    res = _run([pe, pr], [[pe, pr]], film=False)
    (chk,) = _checks(res, "nk.reflectance")
    # the same bulk index makes both files: Fresnel R of the inverted n, k is the measured R
    assert chk["status"] == "pass"
    row = res["tables"]["nk_reflectance_comparison"]["rows"][0]
    assert (row["nk_file"], row["refl_file"]) == ("psi.csv", "R.csv")
    assert abs(row["mean_diff"]) < 1e-6
    assert not [n for n in _notes(res, "nk") if "--same-sample" in n]


def test_nk_pairs_by_the_stated_sample_name(tmp_path: Path) -> None:
    pe, pr = _write(tmp_path, False, "bulk A", "bulk A")
    res = _run([pe, pr], [], film=False)
    assert [c["status"] for c in _checks(res, "nk.reflectance")] == ["pass"]


def test_nk_note_without_any_ellipsometer_file_of_the_sample(tmp_path: Path) -> None:
    # two ellipsometer files: the count rule never applied; the note still says how to pair
    pe, pr = _write(tmp_path, False, "bulk A", "bulk B")
    other = tmp_path / "other"
    other.mkdir()
    pe2, _ = _write(other, False, "bulk C", "bulk C", "psi2.csv")
    res = _run([pe, pe2, pr], [], film=False)
    (note,) = [n for n in _notes(res, "nk") if "R.csv" in n]
    assert "only ellipsometer file" not in note
    assert f"--same-sample ELLIPSOMETER_FILE,{pr}" in note


def test_real_trio_without_the_mapping_is_not_paired(real_exports: Path) -> None:
    # w1_12082006*.dat: one wafer whose three files state three different sample names
    d = real_exports / "woollam-wvase-ascii"
    paths = [d / f"w1_12082006{s}.dat" for s in ("", "_p-pol_refl", "_s-pol_refl")]
    res = _run(paths, [], film=False)
    assert _checks(res, "nk.reflectance") == []
    (note,) = [n for n in _notes(res, "nk") if "only ellipsometer file" in n]
    # one group for all three (a file may be in one --same-sample group only)
    assert f"--same-sample {paths[0]},{paths[1]},{paths[2]} " in note
    paired = _run(paths, [paths], film=False)
    assert len(_checks(paired, "nk.reflectance")) == 2


# --------------------------------------------------------------------------- section film


@pytest.fixture(scope="module")
def coated(tmp_path_factory: pytest.TempPathFactory) -> dict:
    tmp = tmp_path_factory.mktemp("coated")
    pe, pr = _write(tmp, True, "wafer A", "wafer B")
    return {"apart": _run([pe, pr], [], film=True), "paired": _run([pe, pr], [[pe, pr]], True)}


def test_film_does_not_pair_the_only_psi_delta_file_by_count(coated: dict) -> None:
    res = coated["apart"]
    assert _checks(res, "film.reflectance") == []
    (note,) = [n for n in _notes(res, "film") if "R.csv" in n]
    assert "only psi/Delta file does not make it the same sample" in note
    assert "--same-sample" in note and "same_sample=[[" in note
    # the stack is still fitted and kept for the later sections
    assert list(res["_ctx"].film_fits) == ["psi.csv"]


def test_film_compares_the_reflectance_paired_by_the_mapping(coated: dict) -> None:
    res = coated["paired"]
    (chk,) = _checks(res, "film.reflectance")
    assert chk["status"] == "pass"
    row = res["tables"]["film_reflectance_comparison"]["rows"][0]
    assert row["points"] == 2 * len(ANGLES) * len(WL)
    assert not [n for n in _notes(res, "film") if "--same-sample" in n]


# --------------------------------------------------------------------------- the helper


def test_same_sample_without_groups_uses_the_names_the_rows_state() -> None:
    ctx = Context(Builder("t", progress=False))
    rows = [
        make_frame(sample=s, instrument="x", source=src, quantity="reflectance", value=[0.1],
                   unit="1", wavelength_nm=[500.0], theta_i_deg=0.0)
        for s, src in (("S1", "a.csv"), ("S1", "b.csv"), ("S2", "c.csv"))
    ]  # fmt: skip
    ctx.frames = rows
    assert len(sample_groups_of(ctx)) == 2
    assert same_sample(ctx, "a.csv", "b.csv") and same_sample(ctx, "c.csv", "c.csv")
    assert not same_sample(ctx, "a.csv", "c.csv")
    assert not same_sample(ctx, "nowhere.csv", "a.csv")


def test_two_inputs_of_one_file_name_pair_with_nothing(tmp_path: Path) -> None:
    from labbrdf.samples import SampleGroup

    ctx = Context(Builder("t", progress=False))
    ctx.samples = [
        SampleGroup("x", (tmp_path / "1" / "d.csv", tmp_path / "e.csv"), "given"),
        SampleGroup("y", (tmp_path / "2" / "d.csv", tmp_path / "f.csv"), "given"),
    ]
    assert not same_sample(ctx, "d.csv", "e.csv") and not same_sample(ctx, "d.csv", "f.csv")
    assert same_sample(ctx, "e.csv", "e.csv")


def test_how_to_pair_spells_the_inputs_as_given(tmp_path: Path) -> None:
    from labbrdf.samples import SampleGroup

    ctx = Context(Builder("t", progress=False))
    ctx.samples = [SampleGroup("x", (Path("rel/a.dat"),), "alone")]
    text = how_to_pair(ctx, ["a.dat", "b.dat"])
    assert "--same-sample rel/a.dat,b.dat" in text
    assert "same_sample=[['rel/a.dat', 'b.dat']]" in text


def test_how_to_pair_merges_the_groups_the_files_are_in(tmp_path: Path) -> None:
    from labbrdf.samples import SampleGroup

    ctx = Context(Builder("t", progress=False))
    ctx.samples = [
        SampleGroup("x", (Path("rel/a.dat"), Path("rel/map.di")), "given"),
        SampleGroup("y", (Path("b.dat"),), "alone"),
    ]
    assert "--same-sample rel/a.dat,rel/map.di,b.dat " in how_to_pair(ctx, ["a.dat", "b.dat"])
