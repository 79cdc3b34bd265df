"""The bundled synthetic fixtures: reproducible, labelled, physically what they claim to be.

The generator is ``fixtures/make_fixtures.py`` (not a package module; loaded from its path).
Physics checks use numbers independent of the generator: the published tables of Zou, Bai,
Wu 2013 typed in here from the paper, eq. (7) written out here, and the ellipsometry oracle
(../shared/oracles/ellipsometry_roundtrip.csv, pyElli transfer-matrix values).
"""

from __future__ import annotations

import csv
import importlib
import io
import math
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

# Zou X., Bai L., Wu Z., Acta Optica Sinica 33(6) 0612008 (2013), doi:10.3788/AOS201333.0612008,
# typed in from the paper: wavelength [nm] -> (k1 [1], k2 [rad], k3 [rad]).
PAPER_TABLE1_OSR = {
    360: (0.7443, -0.01156, 0.4161),
    500: (0.9740, -0.01506, 0.4177),
    550: (1.0150, -0.01660, 0.4176),
    860: (1.0310, -0.01968, 0.4155),
}
PAPER_TABLE2_MIRROR = {
    360: (0.4972, 0.1379, 0.3704),
    500: (0.5580, 0.1659, 0.3693),
    550: (0.5494, 0.1682, 0.3693),
    860: (0.3909, 0.1594, 0.3710),
}
# Table 3: wavelength [nm] -> measured hemispherical reflectance [%] as printed.
PAPER_TABLE3_MEASURED = {360: "41.3988", 500: "56.3683", 550: "59.2698"}

SPECULAR = {
    "specular/osr_specular.csv": ("OSR", PAPER_TABLE1_OSR),
    "specular/mirror_specular.csv": ("mirror", PAPER_TABLE2_MIRROR),
}
WVASE = {
    "ellipsometry/al_bare_wvase.dat": ("Al", complex(1.55, 7.71)),
    "ellipsometry/cu_bare_wvase.dat": ("Cu", complex(0.23, 3.63)),
}
PE_ASC = "spectrophotometer/osr_150mm_sphere.Sample.Raw.asc"
CARY_CSV = "spectrophotometer/osr_sphere_cary.csv"
HEMI_CSV = "spectrophotometer/osr_hemispherical_table3.csv"
SPECTRO_WL = list(range(550, 359, -5))
WVASE_FIRST = next(iter(WVASE))

# statistical checks: k = 4 standard errors (two-sided p ~ 6e-5 for a correct generator)
K_SIGMA = 4.0


@pytest.fixture(scope="module")
def gen(fixtures_dir: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        "make_fixtures", fixtures_dir / "make_fixtures.py"
    )
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def built(gen: ModuleType) -> dict[str, bytes]:
    return gen.build()


def _eq7(theta_i_deg, theta_r_deg, k1, k2, k3):
    """Eq. (7) of Zou 2013 written out independently of the generator [sr-1]."""
    ti, tr = np.radians(theta_i_deg), np.radians(theta_r_deg)
    return k1 / (8 * np.cos(ti) * np.cos(tr)) * np.exp(-(((ti - tr - k2) / k3) ** 2))


def _read_comment_csv(path: Path) -> tuple[dict[str, str], dict[str, np.ndarray]]:
    """Parse a labbrdf CSV: '# key: value' lines, then a header row and numeric rows."""
    meta: dict[str, str] = {}
    lines = path.read_text(encoding="ascii").splitlines()
    body = [ln for ln in lines if not ln.startswith("#")]
    for ln in lines:
        if ln.startswith("# ") and ": " in ln:
            k, v = ln[2:].split(": ", 1)
            meta[k] = v
    rows = list(csv.reader(io.StringIO("\n".join(body))))
    cols = {name: np.array([float(r[i]) for r in rows[1:]]) for i, name in enumerate(rows[0])}
    return meta, cols


def _read_wvase(path: Path) -> np.ndarray:
    """Numeric rows of a WVASE32 psi/Delta file (4 header lines, TAB separated)."""
    lines = path.read_bytes().decode("ascii").split("\r\n")
    return np.array([[float(x) for x in ln.split("\t")] for ln in lines[4:]])


def _oracle_rows(oracles: Path) -> dict[tuple[str, int], tuple[float, float]]:
    out = {}
    with open(oracles / "ellipsometry_roundtrip.csv", newline="") as fh:
        for r in csv.DictReader(fh):
            out[r["material"], round(float(r["angle_deg"]))] = (
                float(r["psi_deg"]),
                float(r["delta_deg"]),
            )
    return out


# ---------------------------------------------------------------------------------------
# reproducibility, listing, size


def test_generator_reproduces_committed_fixtures_byte_for_byte(
    gen: ModuleType, fixtures_dir: Path, tmp_path: Path
) -> None:
    assert gen.main(["--out", str(tmp_path)]) == 0
    for rel in gen.build():
        assert (tmp_path / rel).read_bytes() == (fixtures_dir / rel).read_bytes(), rel
    assert gen.main(["--check", "--out", str(fixtures_dir)]) == 0


def test_output_does_not_depend_on_which_psi_delta_is_available(
    gen: ModuleType, built: dict[str, bytes], monkeypatch: pytest.MonkeyPatch
) -> None:
    # the generator uses labbrdf.optics.psi_delta when it exists, else its own formula;
    # both must give the same bytes (8 significant digits hide ~1e-13 deg differences)
    monkeypatch.setattr(gen, "_psi_delta_function", lambda: (gen.psi_delta_fresnel, "fallback"))
    assert gen.build() == built


def test_check_mode_names_a_changed_or_missing_fixture(
    gen: ModuleType, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gen.write(tmp_path)
    edited = tmp_path / "specular" / "osr_specular.csv"
    edited.write_bytes(edited.read_bytes().replace(b"360,30,28.0,", b"360,30,28.1,", 1))
    (tmp_path / WVASE_FIRST).unlink()
    assert gen.main(["--check", "--out", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert "differs from the generator or is missing: specular/osr_specular.csv" in err
    assert f"differs from the generator or is missing: {WVASE_FIRST}" in err
    assert "mirror_specular.csv" not in err


def test_every_generated_file_is_listed_and_labelled_in_readme(
    built: dict[str, bytes], fixtures_dir: Path
) -> None:
    readme = (fixtures_dir / "README.md").read_text(encoding="utf-8")
    lines = {
        ln.split("|")[1].strip().strip("`"): ln
        for ln in readme.splitlines()
        if ln.startswith("| `")
    }
    for rel in built:
        assert rel in lines, f"{rel} has no line in fixtures/README.md"
        row = lines[rel]
        assert "SYNTHETIC" in row or "published" in row, rel
        assert ("20130612" in row) == (rel in SPECULAR or rel in WVASE), rel
    assert "20130612" in readme and "0.005" in readme and "0.02 deg" in readme


def test_fixtures_folder_holds_only_generated_or_documented_files(
    built: dict[str, bytes], fixtures_dir: Path
) -> None:
    allowed = set(built) | {"README.md", "make_fixtures.py"}
    readme = (fixtures_dir / "README.md").read_text(encoding="utf-8")
    for p in fixtures_dir.rglob("*"):
        rel = p.relative_to(fixtures_dir).as_posix()
        if p.is_dir() or "__pycache__" in rel:
            continue
        if rel.startswith("published/"):
            assert f"| `{rel}` |" in readme, f"{rel} has no line in fixtures/README.md"
        else:
            assert rel in allowed, f"{rel} is not made by make_fixtures.py"


def test_fixtures_total_size_is_below_2_mb(fixtures_dir: Path) -> None:
    total = sum(p.stat().st_size for p in fixtures_dir.rglob("*") if p.is_file())
    assert total < 2_000_000


def test_every_file_is_labelled_synthetic_or_published_inside(built: dict[str, bytes]) -> None:
    for rel, data in built.items():
        assert b"SYNTHETIC" in data or b"published values" in data, rel


# ---------------------------------------------------------------------------------------
# published numbers


def test_generator_tables_equal_the_paper(gen: ModuleType) -> None:
    for table, paper in (
        (gen.TABLE1_OSR, PAPER_TABLE1_OSR),
        (gen.TABLE2_MIRROR, PAPER_TABLE2_MIRROR),
    ):
        assert {int(r[0]): tuple(float(x) for x in r[1:4]) for r in table} == paper
    assert {int(r[0]): r[1] for r in gen.TABLE3_OSR} == PAPER_TABLE3_MEASURED
    # Table 3 "error" column is |integration - measured| / measured in percent, as printed
    for _wl, measured, integ, err in gen.TABLE3_OSR:
        rel = abs(float(integ) - float(measured)) / float(measured) * 100
        assert abs(rel - float(err)) <= 0.0005 + 1e-12


def _published_rows(fixtures_dir: Path, name: str) -> list[list[str]]:
    path = fixtures_dir / "published" / name
    assert path.is_file(), f"{path} missing: the published tables are part of the project"
    body = [
        ln
        for ln in path.read_text(encoding="utf-8").splitlines()
        if ln.strip() and not ln.startswith("#")
    ]
    return list(csv.reader(io.StringIO("\n".join(body))))


@pytest.mark.parametrize(
    ("name", "table"),
    [
        ("zou2013_table1.csv", "TABLE1_OSR"),
        ("zou2013_table2.csv", "TABLE2_MIRROR"),
        ("zou2013_table3.csv", "TABLE3_OSR"),
    ],
)
def test_published_tables_equal_the_generator_numbers_digit_for_digit(
    gen: ModuleType, fixtures_dir: Path, name: str, table: str
) -> None:
    rows = _published_rows(fixtures_dir, name)
    expected_header = {
        "TABLE1_OSR": ["wavelength_nm", "k1", "k2", "k3", "rmse_percent"],
        "TABLE2_MIRROR": ["wavelength_nm", "k1", "k2", "k3", "rmse_percent"],
        "TABLE3_OSR": [
            "wavelength_nm",
            "hemispherical_percent",
            "integration_percent",
            "error_percent",
        ],
    }[table]
    assert rows[0] == expected_header
    assert [tuple(r) for r in rows[1:]] == list(getattr(gen, table))


# ---------------------------------------------------------------------------------------
# specular scans


@pytest.mark.parametrize("rel", sorted(SPECULAR))
def test_specular_scan_has_the_paper_geometry(fixtures_dir: Path, rel: str) -> None:
    meta, c = _read_comment_csv(fixtures_dir / rel)
    assert meta["sample"] == SPECULAR[rel][0]
    assert meta["quantity"] == "brdf" and meta["unit"] == "sr-1"
    assert len(c["value"]) == 4 * 3 * 21
    assert set(c["wavelength_nm"]) == {360, 500, 550, 860}
    assert set(c["theta_i_deg"]) == {30, 45, 60}
    offsets = np.round((c["theta_r_deg"] - c["theta_i_deg"]) * 10).astype(int)
    assert set(offsets) == set(range(-20, 21, 2))  # +-2 deg in 0.2 deg steps
    assert np.all(c["phi_r_deg"] == 180)


@pytest.mark.parametrize("rel", sorted(SPECULAR))
def test_specular_scan_is_eq7_plus_the_stated_noise(fixtures_dir: Path, rel: str) -> None:
    _meta, c = _read_comment_csv(fixtures_dir / rel)
    table = SPECULAR[rel][1]
    k = np.array([table[int(w)] for w in c["wavelength_nm"]])
    truth = _eq7(c["theta_i_deg"], c["theta_r_deg"], k[:, 0], k[:, 1], k[:, 2])
    sigma_model = np.hypot(0.005 * truth, 1e-4)
    # sigma is printed to 3 significant digits: relative rounding <= 5e-3
    np.testing.assert_allclose(c["sigma"], sigma_model, rtol=5e-3)
    z = (c["value"] - truth) / c["sigma"]
    n = z.size
    assert abs(z.mean()) < K_SIGMA / math.sqrt(n)
    assert abs(z.std(ddof=1) - 1) < K_SIGMA / math.sqrt(2 * (n - 1))


def test_specular_noise_streams_differ_between_samples(fixtures_dir: Path) -> None:
    zs = []
    for rel, (_s, table) in sorted(SPECULAR.items()):
        _m, c = _read_comment_csv(fixtures_dir / rel)
        k = np.array([table[int(w)] for w in c["wavelength_nm"]])
        truth = _eq7(c["theta_i_deg"], c["theta_r_deg"], k[:, 0], k[:, 1], k[:, 2])
        zs.append((c["value"] - truth) / c["sigma"])
    r = np.corrcoef(zs[0], zs[1])[0, 1]
    assert abs(r) < K_SIGMA / math.sqrt(zs[0].size)


# ---------------------------------------------------------------------------------------
# ellipsometry


def test_generator_fresnel_matches_the_ellipsometry_oracle(gen: ModuleType, oracles: Path) -> None:
    idx = {
        "Al": complex(1.55, 7.71),
        "Cu": complex(0.23, 3.63),
        "Si": complex(3.88, 0.02),
        "glass": complex(1.5, 0.0),
    }
    for (mat, angle), (psi, delta) in _oracle_rows(oracles).items():
        p, d = gen.psi_delta_fresnel(idx[mat], float(angle))
        assert p == pytest.approx(psi, abs=1e-10)
        # Delta of lossless glass is 0 or 180 exactly; compare on the circle
        assert math.remainder(d - delta, 360.0) == pytest.approx(0, abs=1e-10)


def test_generator_fresnel_agrees_with_labbrdf_optics(gen: ModuleType) -> None:
    from labbrdf import optics

    assert gen._psi_delta_function()[1] == "labbrdf.optics.psi_delta"
    for n in (complex(1.55, 7.71), complex(0.23, 3.63)):
        for a in (65.0, 70.0, 75.0):
            p, d = optics.psi_delta(n, a)
            q, e = gen.psi_delta_fresnel(n, a)
            assert float(p) == pytest.approx(q, abs=1e-10)
            assert float(d) == pytest.approx(e, abs=1e-10)


@pytest.mark.parametrize("rel", sorted(WVASE))
def test_wvase_fixture_layout(fixtures_dir: Path, rel: str) -> None:
    raw = (fixtures_dir / rel).read_bytes()
    assert not raw.endswith(b"\n") and b"\n" not in raw.replace(b"\r\n", b"")
    lines = raw.decode("ascii").split("\r\n")
    assert lines[1].startswith("VASEmethod[Simulation for ") and lines[3] == "nm"
    assert lines[2] == f"Original[{Path(rel).name}]"
    data = _read_wvase(fixtures_dir / rel)
    assert data.shape == (3 * 71, 6)
    np.testing.assert_array_equal(data[:, 1], np.repeat([65.0, 70.0, 75.0], 71))
    np.testing.assert_array_equal(data[:, 0], np.tile(np.arange(300.0, 1001.0, 10.0), 3))
    assert np.all((data[:, 3] >= 0) & (data[:, 3] < 360))
    assert np.all(data[:, 4] == 0.02) and np.all(data[:, 5] == 0.05)


@pytest.mark.parametrize("rel", sorted(WVASE))
def test_wvase_fixture_agrees_with_the_oracle_within_noise(
    fixtures_dir: Path, oracles: Path, rel: str
) -> None:
    material, _n = WVASE[rel]
    oracle = _oracle_rows(oracles)
    data = _read_wvase(fixtures_dir / rel)
    for angle in (70, 75):  # the oracle's angles that the fixture has
        rows = data[data[:, 1] == angle]
        psi0, delta0 = oracle[material, angle]
        for col, truth, sig in ((2, psi0, 0.02), (3, delta0, 0.05)):
            z = (rows[:, col] - truth) / sig
            assert abs(z.mean()) < K_SIGMA / math.sqrt(z.size), (material, angle, col)
            assert abs(z.std(ddof=1) - 1) < K_SIGMA / math.sqrt(2 * (z.size - 1))


# ---------------------------------------------------------------------------------------
# hemispherical reflectance


def _pe_data(path: Path) -> list[tuple[str, str]]:
    lines = path.read_bytes().decode("ascii").split("\r\n")
    assert lines[-1] == ""  # CRLF after the last row, as UV WinLab writes
    i = lines.index("#DATA")
    return [tuple(ln.split("\t")) for ln in lines[i + 1 : -1]]


def _cary_data(path: Path) -> list[tuple[str, str]]:
    lines = path.read_bytes().decode("ascii").split("\r\n")
    assert lines[:2] == ["OSR,,", "Wavelength (nm),%R,"]
    end = lines.index("")
    out = []
    for ln in lines[2:end]:
        x, y, trailing = ln.split(",")
        assert trailing == ""
        out.append((x, y))
    return out


def test_sphere_exports_hold_the_published_values_exactly(fixtures_dir: Path) -> None:
    pe = dict(_pe_data(fixtures_dir / PE_ASC))
    cary = dict(_cary_data(fixtures_dir / CARY_CSV))
    for wl, pct in PAPER_TABLE3_MEASURED.items():
        assert pe[f"{wl}.000000"] == f"{pct}00"
        assert cary[str(wl)] == pct
    _meta, c = _read_comment_csv(fixtures_dir / HEMI_CSV)
    assert list(c["wavelength_nm"]) == [360, 500, 550]
    assert list(c["value"]) == [float(v) for v in PAPER_TABLE3_MEASURED.values()]


def test_sphere_interpolation_is_the_quadratic_through_table3(fixtures_dir: Path) -> None:
    xs = np.array(list(PAPER_TABLE3_MEASURED), dtype=float)
    ys = np.array([float(v) for v in PAPER_TABLE3_MEASURED.values()])
    coef = np.polyfit(xs, ys, 2)  # exact through 3 points
    for rows in (_pe_data(fixtures_dir / PE_ASC), _cary_data(fixtures_dir / CARY_CSV)):
        x = np.array([float(r[0]) for r in rows])
        y = np.array([float(r[1]) for r in rows])
        np.testing.assert_array_equal(x, SPECTRO_WL)  # 550 -> 360 nm, no extrapolation
        # printed to 4 decimals: |error| <= 5e-5 plus polyfit round-off
        np.testing.assert_allclose(y, np.polyval(coef, x), rtol=0, atol=5e-5 + 1e-9)
        assert np.all(np.diff(y) < 0)  # rises monotonically with wavelength


def test_perkinelmer_header_is_consistent_with_its_data(fixtures_dir: Path) -> None:
    lines = (fixtures_dir / PE_ASC).read_bytes().decode("ascii").split("\r\n")
    assert lines[0].startswith("PE UV       SUBTECH     SPECTRUM    ASCII       PEDS")
    assert "150mm sphere" in lines[24]
    assert "SYNTHETIC" in lines[7] and "SYNTHETIC" in lines[8]
    g = lines.index("#GR")
    gr = lines[g + 1 : g + 11]
    unit_x, unit_y, _scale, _offset, firstx, deltax, npts, _code, ymax, ymin = gr
    rows = _pe_data(fixtures_dir / PE_ASC)
    y = [float(r[1]) for r in rows]
    assert (unit_x, unit_y) == ("nm", "%R")
    assert int(npts) == len(rows)
    assert [float(r[0]) for r in rows] == [
        float(firstx) + i * float(deltax) for i in range(len(rows))
    ]
    assert (float(ymax), float(ymin)) == (max(y), min(y))


def test_interpolation_refuses_to_extrapolate(gen: ModuleType) -> None:
    with pytest.raises(ValueError, match=r"wavelength_nm: expected values within \[360, 550\]"):
        gen.hemispherical_interpolation(np.array([355.0, 400.0]))
    with pytest.raises(ValueError, match="wavelength_nm"):
        gen.hemispherical_interpolation(np.array([860.0]))


# ---------------------------------------------------------------------------------------
# every fixture reads with labbrdf.read (once its adapter exists)

ADAPTER_OF = {
    "specular/osr_specular.csv": "labbrdf_csv",
    "specular/mirror_specular.csv": "labbrdf_csv",
    HEMI_CSV: "labbrdf_csv",
    PE_ASC: "perkinelmer",
    CARY_CSV: "cary",
    "ellipsometry/al_bare_wvase.dat": "woollam",
    "ellipsometry/cu_bare_wvase.dat": "woollam",
}


def _read(fixtures_dir: Path, rel: str):
    """Read a fixture with labbrdf.read and check the adapter that should claim it did."""
    import labbrdf

    m = labbrdf.read(fixtures_dir / rel)
    assert importlib.import_module(f"labbrdf.adapters.{ADAPTER_OF[rel]}")
    return m


@pytest.mark.parametrize("rel", sorted(SPECULAR))
def test_specular_fixture_reads_as_brdf(fixtures_dir: Path, rel: str) -> None:
    m = _read(fixtures_dir, rel)
    df = m.data
    _meta, c = _read_comment_csv(fixtures_dir / rel)
    assert len(df) == 252
    assert set(df["quantity"].astype(str)) == {"brdf"}
    assert set(df["unit"]) == {"sr-1"}
    assert set(df["sample"]) == {SPECULAR[rel][0]}
    np.testing.assert_array_equal(df["value"].to_numpy(), c["value"])
    np.testing.assert_array_equal(df["sigma"].to_numpy(), c["sigma"])
    np.testing.assert_array_equal(df["theta_r_deg"].to_numpy(), c["theta_r_deg"])
    assert np.all(df["phi_r_deg"] == 180.0)


@pytest.mark.parametrize("rel", sorted(WVASE))
def test_wvase_fixture_reads_as_psi_and_delta(fixtures_dir: Path, rel: str) -> None:
    m = _read(fixtures_dir, rel)
    df = m.data
    data = _read_wvase(fixtures_dir / rel)
    assert len(df) == 2 * len(data)
    assert set(df["quantity"].astype(str)) == {"psi", "delta"}
    assert set(df["unit"]) == {"deg"}
    psi = df[df["quantity"].astype(str) == "psi"]
    delta = df[df["quantity"].astype(str) == "delta"]
    assert sorted(psi["value"]) == sorted(data[:, 2])
    assert sorted(delta["value"]) == sorted(data[:, 3])
    assert set(psi["sigma"]) == {0.02} and set(delta["sigma"]) == {0.05}
    assert set(df["theta_i_deg"]) == {65.0, 70.0, 75.0}
    assert set(df["sample"]) == {
        f"SYNTHETIC bare {WVASE[rel][0]} N={WVASE[rel][1].real:g}+{WVASE[rel][1].imag:g}i"
    }


@pytest.mark.parametrize("rel", [PE_ASC, CARY_CSV, HEMI_CSV])
def test_sphere_fixture_reads_as_fraction_with_the_published_values(
    fixtures_dir: Path, rel: str
) -> None:
    m = _read(fixtures_dir, rel)
    df = m.data
    assert len(df) == (3 if rel == HEMI_CSV else 39)
    assert set(df["quantity"].astype(str)) == {"hemispherical_reflectance"}
    assert set(df["unit"]) == {"1"}
    assert set(df["sample"]) == {"OSR"}
    assert df["theta_i_deg"].isna().all()
    got = dict(zip(df["wavelength_nm"], df["value"], strict=True))
    for wl, pct in PAPER_TABLE3_MEASURED.items():
        assert got[float(wl)] == pytest.approx(float(pct) / 100, rel=1e-15)
