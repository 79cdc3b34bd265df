"""Height maps as an input kind of the adapters, and ``read_inputs`` over a list of paths."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf import adapters
from labbrdf.adapters import inputs as inputs_mod
from labbrdf.adapters import topography
from labbrdf.adapters._base import AdapterError
from labbrdf.adapters.topography import HEIGHT_MAP_FORMATS
from labbrdf.cli import main
from labbrdf.roughness.synthetic import gaussian_surface

METROPRO_MAGIC = b"\x88\x1b\x03\x6f"


def write_bcrf(path: Path, n: int = 32, seed: int = 3) -> Path:
    """A BCR-STM float file (SurfaceTopography's ``bcrf``): heights [nm], 32 x 32 um."""
    z = np.asarray(gaussian_surface(n, float(n), 100.0, 4.0, rng=seed).z, dtype="<f4")
    hdr = (
        f"fileformat = bcrf\nheadersize = 2048\nxpixels = {n}\nypixels = {n}\n"
        f"xlength = {float(n)!r}\nylength = {float(n)!r}\nxunit = um\nyunit = um\n"
        "zunit = nm\nintelmode = 1\n"
    )
    path.write_bytes(hdr.encode().ljust(2048, b" ") + z.tobytes())
    return path


@pytest.fixture
def wvase(fixtures_dir: Path) -> Path:
    return fixtures_dir / "ellipsometry" / "al_bare_wvase.dat"


@pytest.fixture
def counted(monkeypatch: pytest.MonkeyPatch) -> dict[str, int]:
    """Calls of every optical parser and of the height-map reader, by file name."""
    calls: dict[str, int] = {}

    def counting(fn):
        def wrapped(path, *a, **kw):
            name = Path(path).name
            calls[name] = calls.get(name, 0) + 1
            return fn(path, *a, **kw)

        return wrapped

    for name, f in list(adapters.READERS.items()):
        monkeypatch.setitem(adapters.READERS, name, dataclasses.replace(f, read=counting(f.read)))
    monkeypatch.setattr(inputs_mod, "read_height_map", counting(topography.read_height_map))
    return calls


# ------------------------------------------------------------------------ the registry


def test_height_map_extensions_are_no_optical_formats_and_shared_ones_are() -> None:
    optical = {e for f in adapters.READERS.values() for e in f.extensions}
    own = [e for f in HEIGHT_MAP_FORMATS for e in f.extensions]
    shared = {e for f in HEIGHT_MAP_FORMATS for e in f.shared_extensions}
    assert len(own) == len(set(own)), "an extension listed by two height-map formats"
    assert not set(own) & optical
    assert shared and shared <= optical  # "shared" means shared with an optical format
    assert all(e.startswith(".") and e == e.lower() for e in [*own, *shared])
    names = [f.name for f in HEIGHT_MAP_FORMATS]
    assert len(names) == len(set(names)) and not set(names) & set(adapters.READERS)


def test_height_map_extensions_are_ones_surfacetopography_reads() -> None:
    st = pytest.importorskip("SurfaceTopography")
    listed = set()
    for r in st.IO.readers:
        try:
            listed |= {f".{e.lower()}" for e in (r.file_extensions() or ())}
        except Exception:  # noqa: BLE001, S112 - a reader without extensions
            continue
    own = {e for f in HEIGHT_MAP_FORMATS for e in (*f.extensions, *f.shared_extensions)}
    # .di and .000 are Nanoscope names SurfaceTopography detects from the content
    assert own - listed <= {".di", ".000"}


def test_sniffers_never_raise_and_claim_only_their_magic() -> None:
    heads = [b"", b"\x00" * 8, METROPRO_MAGIC, b"\\*File list\r\n", b"VCA DATA\x01",
             b"fileformat = bcrf\n", b"VASEmethod[...]\n"]  # fmt: skip
    claims = {h: [f.name for f in HEIGHT_MAP_FORMATS if f.sniff(h)] for h in heads}
    assert claims[b""] == [] and claims[b"\x00" * 8] == [] and claims[heads[-1]] == []
    assert claims[METROPRO_MAGIC] == ["zygo-metropro"]
    assert claims[b"\\*File list\r\n"] == ["nanoscope"]
    assert claims[b"VCA DATA\x01"] == ["bruker-opdx"]
    assert claims[b"fileformat = bcrf\n"] == ["bcr-stm"]


# ------------------------------------------------------------------------ input_kind


@pytest.mark.parametrize(
    ("name", "content", "kind"),
    [
        ("afm.di", b"anything at all", "height_map"),  # an extension of its own
        ("scan.BCRF", b"junk", "height_map"),
        ("map.dat", METROPRO_MAGIC + b"\x00" * 64, "height_map"),  # shared .dat, magic
        ("map.dat", b"a plain text line\n1 2 3\n", "optical"),  # shared .dat, no magic
        ("map.bin", b"fileformat = bcrf\nheadersize = 2048\n", "height_map"),  # no format's
        ("map.csv", b"fileformat = bcrf\nheadersize = 2048\n", "optical"),  # optical's own
        ("notes.bin", b"just text\n", "optical"),
    ],
)
def test_input_kind_from_the_name_and_the_first_bytes(
    tmp_path: Path, name: str, content: bytes, kind: str
) -> None:
    p = tmp_path / name
    p.write_bytes(content)
    assert adapters.input_kind(p) == kind


def test_input_kind_of_a_wvase_dat_is_optical(wvase: Path) -> None:
    assert adapters.input_kind(wvase) == "optical"


def test_an_optical_sniffer_wins_over_a_height_map_sniffer_on_a_shared_extension(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    p = tmp_path / "both.dat"
    p.write_bytes(METROPRO_MAGIC + b"\x00" * 64)
    f = adapters.READERS["woollam-wvase"]
    monkeypatch.setitem(adapters.READERS, f.name, dataclasses.replace(f, sniff=lambda h: True))
    assert adapters.input_kind(p) == "optical"


def test_input_kind_of_a_missing_file_names_it(tmp_path: Path) -> None:
    with pytest.raises(AdapterError, match="absent.di"):
        adapters.input_kind(tmp_path / "absent.di")


# ------------------------------------------------------------------------ labbrdf.read


def test_read_refuses_a_height_map_and_says_what_reads_it(tmp_path: Path) -> None:
    p = tmp_path / "afm.di"
    p.write_bytes(b"\\*File list\r\n")
    with pytest.raises(AdapterError, match=r"afm\.di: is a height map") as exc:
        labbrdf.read(p)
    assert "read_height_map" in str(exc.value) and "read_inputs" in str(exc.value)


def test_read_with_a_forced_format_reads_as_that_format(tmp_path: Path) -> None:
    p = tmp_path / "afm.di"
    p.write_bytes(b"\\*File list\r\n")
    with pytest.raises(AdapterError) as exc:
        labbrdf.read(p, format="woollam-wvase")
    assert "height map" not in str(exc.value) and "afm.di" in str(exc.value)


# ------------------------------------------------------------------------ read_inputs


def test_read_inputs_reads_a_mixed_list_once_per_file(
    tmp_path: Path, wvase: Path, counted: dict[str, int]
) -> None:
    pytest.importorskip("SurfaceTopography")
    hm = write_bcrf(tmp_path / "afm.bcrf")
    junk = tmp_path / "junk.txt"
    junk.write_text("nothing here\n")
    got = labbrdf.read_inputs([wvase, hm, junk])
    assert isinstance(got, labbrdf.Inputs)
    assert counted == {wvase.name: 1, hm.name: 1}  # junk.txt: no parser claims it
    assert [f.kind for f in got.files] == ["optical", "height_map", "optical"]
    assert [f.ok for f in got.files] == [True, True, False]
    (failure,) = got.failures
    assert failure.path == str(junk) and failure.error.startswith(str(junk))
    assert "no adapter recognises" in failure.error


def test_read_inputs_gives_what_the_single_readers_give(tmp_path: Path, wvase: Path) -> None:
    pytest.importorskip("SurfaceTopography")
    hm_path = write_bcrf(tmp_path / "afm.bcrf")
    got = adapters.read_inputs([hm_path, wvase, wvase])
    ref = adapters.read(wvase)
    assert len(got.measurements) == 2
    assert got.measurement is not None
    assert got.measurement.data.equals(adapters.read_many([wvase, wvase]).data)
    assert got.measurements[0].data.equals(ref.data)
    (hm,) = got.height_maps
    ref_hm = topography.read_height_map(hm_path)
    np.testing.assert_array_equal(hm.heights, ref_hm.heights)
    assert hm.pixel_size == ref_hm.pixel_size
    assert not got.failures


def test_read_inputs_of_nothing_readable_has_no_measurement(tmp_path: Path) -> None:
    got = adapters.read_inputs([tmp_path / "absent.dat", tmp_path / "absent.di"])
    assert got.measurement is None and got.height_maps == ()
    assert [f.kind for f in got.failures] == ["optical", "height_map"]  # by the extension
    assert all(f.error.startswith(f.path) for f in got.failures)


def test_a_corrupt_height_map_is_a_failure_naming_the_file(tmp_path: Path) -> None:
    pytest.importorskip("SurfaceTopography")
    bad = tmp_path / "broken.di"
    bad.write_bytes(b"\\*File list\r\n\\Version: 0x0\r\ngarbage" + bytes(range(256)) * 4)
    (f,) = adapters.read_inputs([bad]).files
    assert f.kind == "height_map" and f.height_map is None
    assert f.error.startswith(str(bad)) and "SurfaceTopography" in f.error


def test_without_surfacetopography_a_height_map_is_a_failure_saying_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def missing() -> None:
        raise ImportError("reading topography files needs SurfaceTopography")

    monkeypatch.setattr(topography, "_surface_topography", missing)
    p = tmp_path / "afm.bcrf"
    p.write_bytes(b"fileformat = bcrf\n")
    (f,) = adapters.read_inputs([p]).failures
    assert f.error == f"{p}: reading topography files needs SurfaceTopography"
    with pytest.raises(ImportError):
        adapters.read_inputs([p], on_error="raise")


def test_on_error_raise_stops_at_the_first_failure(
    tmp_path: Path, wvase: Path, counted: dict[str, int]
) -> None:
    junk = tmp_path / "junk.txt"
    junk.write_text("nothing here\n")
    with pytest.raises(AdapterError, match="junk.txt"):
        adapters.read_inputs([junk, wvase], on_error="raise")
    assert counted == {}  # the file after the failure is not read


def test_a_forced_kind_reads_any_name_as_that_kind(tmp_path: Path) -> None:
    pytest.importorskip("SurfaceTopography")
    p = write_bcrf(tmp_path / "heights.txt")  # an optical extension
    assert adapters.read_inputs([p]).failures  # read as optical: no adapter claims it
    (hm,) = adapters.read_inputs([p], kind="height_map").height_maps
    assert hm.heights.shape == (32, 32)


def test_height_map_options_reach_the_reader(tmp_path: Path) -> None:
    pytest.importorskip("SurfaceTopography")
    p = write_bcrf(tmp_path / "afm.bcrf")
    (a,) = adapters.read_inputs([p]).height_maps
    (b,) = adapters.read_inputs([p], unit="nm", pixel_size=2e-6).height_maps
    ref = topography.read_height_map(p, unit="nm", pixel_size=2e-6)
    np.testing.assert_array_equal(b.heights, ref.heights)
    assert b.pixel_size == ref.pixel_size == (2e-6, 2e-6) != a.pixel_size
    assert b.meta["unit_stated"] == "nm" and "unit_stated" not in a.meta
    (f,) = adapters.read_inputs([p], channel="Nope").failures
    assert "no channel 'Nope'" in f.error


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"kind": "topography"}, "kind 'topography'"),
        ({"on_error": "ignore"}, "on_error 'ignore'"),
        ({"kind": "height_map", "format": "woollam-wvase"}, "not kind='height_map'"),
        ({"kind": "height_map", "columns": "wavelength_nm,absorbance"}, "not kind="),
    ],
)
def test_bad_arguments_are_refused(kw: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        adapters.read_inputs([], **kw)


# ------------------------------------------------------------------------ real files


@pytest.mark.shared
def test_real_metropro_dat_is_a_height_map_and_wvase_dat_optical(real_exports: Path) -> None:
    pytest.importorskip("SurfaceTopography")
    metropro = real_exports / "topography" / "metropro-1.dat"
    ta = real_exports / "woollam-wvase-ascii" / "w2_10102006.dat"
    assert adapters.input_kind(metropro) == "height_map"
    assert adapters.input_kind(ta) == "optical"
    with pytest.raises(AdapterError, match="is a height map"):
        labbrdf.read(metropro)
    got = adapters.read_inputs([metropro, ta])
    assert not got.failures and len(got.height_maps) == 1 and len(got.measurements) == 1


# ------------------------------------------------------------------------ labbrdf ingest


def test_ingest_reports_a_height_map_by_its_summary_and_writes_only_optical_rows(
    tmp_path: Path, wvase: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("SurfaceTopography")
    hm = write_bcrf(tmp_path / "afm.bcrf")
    out = tmp_path / "data.csv"
    assert main(["ingest", str(wvase), str(hm), "-o", str(out)]) == 0
    text = capsys.readouterr()
    assert f"{hm}: height map, not optical data: areal map, 32 x 32 points" in text.out
    assert "FAILED" not in text.err
    written = labbrdf.read(out)
    assert set(written.data["source"]) == set(adapters.read(wvase).data["source"])
    assert main(["ingest", "--json", str(wvase), str(hm)]) == 0
    rows = json.loads(capsys.readouterr().out)
    (entry,) = [r for r in rows if "height_map" in r]
    assert entry["file"] == str(hm)
    assert entry["height_map"]["points"] == [32, 32] and entry["height_map"]["missing"] == 0


def test_ingest_stops_at_an_unreadable_file_unless_keep_going(
    tmp_path: Path, wvase: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    junk = tmp_path / "junk.txt"
    junk.write_text("nothing here\n")
    assert main(["ingest", str(junk), str(wvase)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"labbrdf ingest: {junk}: no adapter recognises")
    assert main(["ingest", "--keep-going", str(junk), str(wvase)]) == 2
    text = capsys.readouterr()
    assert f"FAILED {junk}" in text.err and wvase.name in text.out


def test_ingest_of_height_maps_only_writes_nothing_and_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("SurfaceTopography")
    hm = write_bcrf(tmp_path / "afm.bcrf")
    out = tmp_path / "data.csv"
    assert main(["ingest", str(hm), "-o", str(out)]) == 0
    text = capsys.readouterr()
    assert not out.exists()
    assert f"no optical data, {out} not written" in text.err
    assert text.out.startswith(f"{hm}: height map")  # no empty optical table


@pytest.mark.parametrize("exc", [IndexError("list index out of range"), KeyError("xres")])
def test_any_error_of_one_file_is_its_failure_and_the_others_are_read(
    tmp_path: Path, fixtures_dir: Path, monkeypatch: pytest.MonkeyPatch, exc: Exception
) -> None:
    """A reader's unexpected error fails that file, named; before, it ended the whole list."""
    wvase = fixtures_dir / "ellipsometry" / "al_bare_wvase.dat"
    hm = tmp_path / "map.bcrf"
    hm.write_bytes(b"fileformat = bcrf\n")

    def broken(path, *a, **kw):
        raise exc

    monkeypatch.setattr(inputs_mod, "read_height_map", broken)
    got = labbrdf.read_inputs([hm, wvase])
    (fail,) = got.failures
    assert fail.path == str(hm) and fail.kind == "height_map"
    assert fail.error.startswith(f"{hm}: unexpected {type(exc).__name__}")
    assert len(got.measurements) == 1 and got.measurement is not None
    with pytest.raises(type(exc)):
        labbrdf.read_inputs([hm, wvase], on_error="raise")


# ------------------------------------------------------------- ASCII height profiles
def _profile_asc(path: Path) -> Path:
    """A two-column x z height profile as SurfaceTopography's ``nonuniform.asc`` is laid out:
    no header, fixed-width scientific numbers, irregular x."""
    rng = np.random.default_rng(0)
    x = np.cumsum(rng.uniform(10.0, 18.0, 140))
    z = 190.0 + np.cumsum(rng.normal(0.0, 3.0, 140))
    path.write_text("".join(f"   {a:.7e}   {b:.7e}\n" for a, b in zip(x, z, strict=True)))
    return path


def _gwyddion_asc(path: Path) -> Path:
    """A height matrix exported as text by Gwyddion: a '#' header with sizes and unit."""
    z = np.random.default_rng(1).normal(0.0, 1e-8, (16, 16))
    head = "# Channel: Height\n# Width: 10.000 µm\n# Height: 10.000 µm\n# Value units: m\n"
    path.write_text(head + "\n".join("\t".join(f"{v:.4e}" for v in r) for r in z) + "\n")
    return path


def test_an_ascii_height_profile_asc_is_a_height_map_not_a_perkinelmer_spectrum(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: routed to the PerkinElmer reader ("expected the magic 'PE UV ...'")."""
    pytest.importorskip("SurfaceTopography")
    prof = _profile_asc(tmp_path / "profile.asc")
    gwy = _gwyddion_asc(tmp_path / "matrix.asc")
    pe = tmp_path / "spectrum.asc"
    pe.write_text("PE UV       SUBTECH     SPECTRUM    ASCII       PEDS        4.00\n1\n")
    assert adapters.input_kind(prof) == "height_map"
    assert adapters.input_kind(gwy) == "height_map"
    assert adapters.input_kind(pe) == "optical"
    cut = tmp_path / "cut.bin"  # plain numbers under another name stay optical
    cut.write_bytes(prof.read_bytes())
    assert adapters.input_kind(cut) == "optical"
    assert main(["ingest", str(prof)]) == 2  # a profile in unknown units: refused as one
    err = capsys.readouterr().err
    assert "profile.asc" in err and "--unit" in err and "PE UV" not in err
    assert main(["ingest", str(gwy)]) == 0
    assert "matrix.asc: height map" in capsys.readouterr().out
    hm = topography.read_height_map(prof, unit="um")
    assert hm.is_profile and "non-uniform line scan (140 points" in hm.warnings[0]
