"""NeXus NXellipsometry (HDF5): the real pyElli file and synthetic files of both layouts."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import READERS, AdapterError, sniff
from labbrdf.adapters.nexus import HDF5_MAGIC, read_nexus

h5py = pytest.importorskip("h5py")

REAL = "nexus-nxellipsometry/SiO2onSi.ellips.nxs"
TWIN = "woollam-completeease-ascii/complete_ease_example.dat"
KEY = ["quantity", "theta_i_deg", "wavelength_nm"]


def _sorted(df):
    out = df[df["quantity"].isin(["psi", "delta"])].copy()
    out["quantity"] = out["quantity"].astype(str)
    return out.sort_values(KEY).reset_index(drop=True)


def test_real_file_reads_exactly_as_its_completeease_text_export(real_exports: Path) -> None:
    nxs = labbrdf.read(real_exports / REAL)
    dat = labbrdf.read(real_exports / TWIN)
    assert nxs.meta["format"] == "nexus-nxellipsometry"
    a, b = _sorted(nxs.data), _sorted(dat.data)
    assert len(a) == len(b) == 2 * 3 * 1088
    for col in ("quantity", "value", "wavelength_nm", "theta_i_deg", "theta_r_deg", "phi_r_deg"):
        assert a[col].tolist() == b[col].tolist(), col
    assert a["sigma"].isna().all()  # the NeXus file has no errors (NOT_PROVIDED)
    assert set(a["sample"]) == {"2nm SiO2 on Si"}
    (entry,) = nxs.meta["entries"]
    assert entry["spectral_unit_in_file"] == "angstrom"
    assert entry["acquisition_program"] == "CompleteEASE 6.37"
    assert entry["psi_delta_unit_in_file"].startswith("deg (no unit stated")
    # psi 40.014217 / 38.278538 / 37.364731 at 1930 angstrom for AOI 50/60/70
    first = a[(a["quantity"] == "psi") & (a["wavelength_nm"] == 193.0)]
    assert first["value"].tolist() == [40.014217, 38.278538, 37.364731]


def test_real_file_is_sniffed_and_dispatched(real_exports: Path) -> None:
    assert sniff(real_exports / REAL) == ["nexus-nxellipsometry"]


# ------------------------------------------------------------------ synthetic files


def _strings(g, **fields) -> None:
    for k, v in fields.items():
        g[k] = v


def _current(
    path: Path,
    *,
    data: np.ndarray | None = None,
    aoi=(55.0, 65.0),
    aoi_units: str | None = "degree",
    spectrum_units: str | None = "nm",
    data_units: str | None = "degree",
    data_type: str | None = "Psi/Delta",
    definition: str = "NXellipsometry",
    errors: bool = True,
) -> np.ndarray:
    """A file of the current definition: 2 angles x 2 observables x 4 wavelengths."""
    wl = np.array([400.0, 500.0, 600.0, 700.0])
    if data is None:
        data = np.stack([np.stack([20.0 + a / 10 + wl / 100, 100.0 + a + wl / 10]) for a in aoi])
    with h5py.File(path, "w") as f:
        e = f.create_group("entry")
        e.attrs["NX_class"] = "NXentry"
        e["definition"] = definition
        e["sample/name"] = "film A"
        e["sample"].attrs["NX_class"] = "NXsample"
        e["instrument/angle_of_incidence"] = np.asarray(aoi)
        if aoi_units is not None:
            e["instrument/angle_of_incidence"].attrs["units"] = aoi_units
        dc = e.create_group("data_collection")
        dc.attrs["NX_class"] = "NXdata"
        if data_type is not None:
            dc["data_type"] = data_type
        dc["wavelength_spectrum"] = wl
        if spectrum_units is not None:
            dc["wavelength_spectrum"].attrs["units"] = spectrum_units
        dc["measured_data"] = data
        if data_units is not None:
            dc["measured_data"].attrs["units"] = data_units
        if errors:
            dc["measured_data_errors"] = np.full(data.shape, 0.01)
    return data


def test_current_layout_is_read_with_errors_and_angles(tmp_path: Path) -> None:
    p = tmp_path / "a.nxs"
    data = _current(p)
    m = labbrdf.read(p)
    d = m.data
    assert len(d) == 16 and set(d["sample"]) == {"film A"}
    psi = d[(d["quantity"] == "psi") & (d["theta_i_deg"] == 65.0)]
    assert psi["value"].tolist() == data[1, 0].tolist()
    assert psi["wavelength_nm"].tolist() == [400.0, 500.0, 600.0, 700.0]
    assert (d["sigma"] == 0.01).all()
    assert m.meta["entries"][0]["layout"].startswith("NXellipsometry (data_collection)")


def test_radians_and_angstrom_are_converted_and_delta_wrapped(tmp_path: Path) -> None:
    p = tmp_path / "rad.nxs"
    data = np.zeros((1, 2, 4))
    data[0, 0] = np.radians(30.0)
    data[0, 1] = np.radians(-90.0)  # Delta = -90 deg -> 270 deg
    _current(p, data=data, aoi=(np.radians(70.0),), aoi_units="rad", data_units="rad",
             spectrum_units="angstrom", errors=False)  # fmt: skip
    d = read_nexus(p).data
    assert d["theta_i_deg"].to_numpy() == pytest.approx(70.0, abs=1e-12)
    assert d.loc[d["quantity"] == "psi", "value"].to_numpy() == pytest.approx(30.0)
    assert d.loc[d["quantity"] == "delta", "value"].to_numpy() == pytest.approx(270.0)
    assert d["wavelength_nm"].iloc[0] == 40.0  # 400 angstrom
    assert d["sigma"].isna().all()


def test_draft_time_series_gets_times(tmp_path: Path) -> None:
    p = tmp_path / "t.nxs"
    data = np.arange(2 * 1 * 3 * 2 * 5, dtype=float).reshape(2, 1, 3, 2, 5) + 10.0
    with h5py.File(p, "w") as f:
        e = f.create_group("entry")
        e.attrs["NX_class"] = "NXentry"
        e["definition"] = "NXellipsometry"
        e["instrument/angle_of_incidence"] = [50, 60, 70]
        e["instrument/angle_of_incidence"].attrs["units"] = "degrees"
        e["instrument/spectrometer/wavelength"] = np.linspace(300.0, 700.0, 5)
        e["instrument/spectrometer/wavelength"].attrs["units"] = "nm"
        e["sample/data_type"] = "psi/delta"
        e["sample/column_names"] = [b"delta", b"psi"]  # order given by the names
        e["sample/measured_data"] = data
        e["sample/data_error"] = "NOT_PROVIDED"
        e["sample/time_points"] = [0.0, 2.0]
        e["sample/time_points"].attrs["units"] = "min"
    d = read_nexus(p).data
    assert sorted(d["time_s"].unique()) == [0.0, 120.0]
    late = d[(d["time_s"] == 120.0) & (d["theta_i_deg"] == 60.0) & (d["quantity"] == "psi")]
    assert late["value"].tolist() == data[1, 0, 1, 1].tolist()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"definition": "NXmx"}, r"application definition NXmx, not NXellipsometry"),
        ({"data_type": "Mueller matrix"}, r"data_type is 'Mueller matrix'.*Psi/Delta data only"),
        ({"data_type": "tan(Psi)/cos(Delta)"}, r"data_type is 'tan\(Psi\)/cos\(Delta\)'"),
        ({"data_type": None}, r"no /entry/data_collection/data_type"),
        (
            {"aoi": (50.0, 60.0, 70.0), "data": np.full((2, 2, 4), 30.0)},
            r"2 measurements but .*angle_of_incidence has 3",
        ),
        ({"spectrum_units": None}, r"wavelength_spectrum states no unit"),
        ({"spectrum_units": "furlong"}, r"wavelength_spectrum has units 'furlong'"),
        ({"aoi_units": "grad"}, r"angle_of_incidence has units 'grad'"),
        ({"data_units": "percent"}, r"measured_data has units 'percent'"),
    ],
)
def test_what_cannot_be_read_is_refused_by_name(tmp_path: Path, kwargs, match) -> None:
    p = tmp_path / "bad.nxs"
    _current(p, **kwargs)
    with pytest.raises(AdapterError, match=match) as info:
        labbrdf.read(p)
    assert str(p) in str(info.value)


def test_unitless_small_values_are_ambiguous_and_refused(tmp_path: Path) -> None:
    p = tmp_path / "amb.nxs"
    _current(p, data=np.full((2, 2, 4), 0.5), data_units=None)
    with pytest.raises(AdapterError, match="could be radians or degrees"):
        read_nexus(p)


def test_hdf5_that_is_not_nexus_is_refused(tmp_path: Path) -> None:
    p = tmp_path / "plain.h5"
    with h5py.File(p, "w") as f:
        f["x"] = [1.0, 2.0]
    with pytest.raises(AdapterError, match="without a NeXus NXentry group: not a NeXus file"):
        labbrdf.read(p)


def test_huge_declared_dataset_is_refused_before_reading(tmp_path: Path) -> None:
    p = tmp_path / "huge.nxs"
    _current(p)
    with h5py.File(p, "a") as f:
        dc = f["entry/data_collection"]
        del dc["measured_data"], dc["measured_data_errors"]
        # 2 x 2 x 10^9 doubles (32 GB) declared, chunked, nothing written: a small file
        dc.create_dataset("measured_data", shape=(2, 2, 10**9), dtype="f8", chunks=(1, 1, 1024))
    assert p.stat().st_size < 100_000
    with pytest.raises(AdapterError, match=r"declares 4000000000 values, over the limit"):
        read_nexus(p)


def test_damaged_files_are_refused_naming_the_file(tmp_path: Path) -> None:
    src = tmp_path / "ok.nxs"
    _current(src)
    raw = src.read_bytes()
    for k, cut in enumerate((8, 200, len(raw) // 2, len(raw) - 10)):
        p = tmp_path / f"cut{k}.nxs"
        p.write_bytes(raw[:cut])
        with pytest.raises(AdapterError) as info:
            read_nexus(p)
        assert str(p) in str(info.value)
    empty = tmp_path / "empty.nxs"
    empty.write_bytes(b"")
    with pytest.raises(AdapterError, match="the file is empty"):
        read_nexus(empty)


def test_without_h5py_the_message_names_the_extra(tmp_path: Path, monkeypatch) -> None:
    p = tmp_path / "a.nxs"
    _current(p)
    monkeypatch.setitem(sys.modules, "h5py", None)
    with pytest.raises(
        AdapterError, match=r"needs the h5py package: pip install 'labbrdf\[nexus\]'"
    ):
        read_nexus(p)


def test_sniffer_claims_hdf5_signature_only() -> None:
    f = READERS["nexus-nxellipsometry"]
    assert f.sniff(HDF5_MAGIC + b"\0" * 100)
    assert f.sniff(b"\0" * 512 + HDF5_MAGIC)  # after a user block
    assert not f.sniff(b"VASEmethod[" + HDF5_MAGIC)


def test_a_file_that_makes_hdf5_loop_is_refused_after_the_timeout(
    real_exports: Path, tmp_path: Path, monkeypatch
) -> None:
    """Three bytes of the real file changed (found by mutation): the HDF5 library then loops
    forever reading the 'definition' text; the read is stopped and the file refused."""
    raw = bytearray((real_exports / REAL).read_bytes())
    for offset, byte in ((101422, 0o2), (107705, 0o12), (107768, 0o234)):  # cmp -l, 1-based
        raw[offset] = byte
    p = tmp_path / "loops.nxs"
    p.write_bytes(bytes(raw))
    monkeypatch.setattr("labbrdf.adapters.nexus.READ_TIMEOUT_S", 3.0)
    with pytest.raises(AdapterError, match=r"did not finish reading the file in 3 s") as info:
        read_nexus(p)
    assert str(p) in str(info.value)
