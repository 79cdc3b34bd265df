"""Speos ``.anisotropicbsdf`` text files: the reader, its scale, its angles and its errors.

The answer key is the shared pair of one measurement: the Radiant ``.bsdf`` (read by
``zemax-bsdf``) and its Speos conversion. The conversion resampled the Zemax grid
bilinearly onto the Speos normal-reference grid; where a Speos node falls on a Zemax node
(the plane of incidence, at radial angles on the Zemax list), bilinear interpolation returns
the Zemax value exactly, times the one factor the converter applied to the whole table.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import labbrdf
from labbrdf.adapters import AdapterError, sniff
from labbrdf.adapters.speos_bsdf import hemispherical_integral, read_speos_table
from labbrdf.adapters.zemax_bsdf import grid_integral, read_table

ZEMAX = "zemax-bsdf/test_13_planesymmetric_brdf_zemax.bsdf"
SPEOS = "speos-anisotropicbsdf/test_13_planesymmetric_brdf_speos_reference.anisotropicbsdf"


def _key(d) -> list[tuple[float, float, float]]:
    return list(
        zip(
            d["theta_i_deg"].round(6),
            d["theta_r_deg"].round(6),
            d["phi_r_deg"].round(6) % 360.0,
            strict=True,
        )
    )


def _ratios(real_exports: Path) -> dict[float, np.ndarray]:
    """Speos / Zemax at every direction both grids hold, per incidence."""
    z = labbrdf.read(real_exports / ZEMAX).data
    s = labbrdf.read(real_exports / SPEOS).data
    s = s[s["wavelength_nm"] == 350.0]
    zk = dict(zip(_key(z), z["value"], strict=True))
    sk = dict(zip(_key(s), s["value"], strict=True))
    common = sorted(set(zk) & set(sk))
    assert len(common) == 217
    # left out: the 8 nodes at theta_r 85 on the specular side (radial 85-90, past the last
    # .bsdf radial of 80: the .bsdf holds 0 there, the conversion 0 or rounding residue of
    # 1e-14), and the 2 nodes at radial 80 on the source side ((25, 55) and (55, 25)), where
    # the converter's trigonometry lands a hair past its grid and its lookup returns 0
    out: dict[float, list[float]] = {}
    for c in common:
        if zk[c] > 0 and sk[c] > 1e-9:
            out.setdefault(c[0], []).append(sk[c] / zk[c])
    assert sum(map(len, out.values())) == 207
    return {k: np.array(v) for k, v in out.items()}


def test_speos_and_zemax_files_of_one_measurement_agree_where_the_grids_meet(
    real_exports: Path,
) -> None:
    ratios = _ratios(real_exports)
    assert sorted(ratios) == list(np.arange(15.0, 76.0, 5.0))
    # angles: at every common direction of one incidence the two files differ by one
    # factor (a wrong azimuth origin or sense pairs unrelated values: spreads of 10-30 %)
    for ti, r in ratios.items():
        assert np.ptp(r) / r.mean() < 1e-12, ti
    # units: the converter scaled each table so that it integrates to its TIS; we scale
    # the reference table (15 deg) to the spectrum's 13.4506 % = the TIS of the .bsdf.
    # So Speos / Zemax = TIS / (integral of the .bsdf table) at 15 deg; the two integrals
    # use different rules on 5-deg grids (second order: ~h^2/12 ~ 6e-4 of the curvature)
    zemax = grid_integral(read_table(real_exports / ZEMAX))
    assert ratios[15.0][0] == pytest.approx(zemax["ratio"].ravel()[0], rel=1e-3)


def test_real_speos_file_reads_with_its_header_and_scale(real_exports: Path) -> None:
    p = real_exports / SPEOS
    assert sniff(p) == ["speos-bsdf"]
    m = labbrdf.read(p)
    assert m.meta["format"] == "speos-bsdf"
    assert m.meta["version"] == "v8.0"
    assert m.meta["spectrum"]["wavelength_nm"] == [350.0, 850.0]
    # 13 incidences x (18 theta > 0 x 36 azimuths + 1 pole) x 2 wavelengths
    assert len(m) == 13 * (18 * 36 + 1) * 2
    t = read_speos_table(p)
    # the reference table integrates to the spectrum coefficient once scaled
    d = m.data
    first = d[(d["theta_i_deg"] == 15.0) & (d["wavelength_nm"] == 350.0)]
    pole = first[first["theta_r_deg"] == 0.0]["value"].item()
    integral = hemispherical_integral(t)[0, 0]
    assert pole == pytest.approx(0.17944232155258916 * 0.134506 / integral, rel=1e-12)
    assert set(d["quantity"]) == {"brdf"} and set(d["unit"]) == {"sr-1"}


def _speos_text(
    *,
    mode: str = "0",
    flags: str = "1\t0",
    vtype: str = "1",
    incidences: str = "10.0\t30.0",
    reference: str = "10.0\t0",
    nth: int = 91,
    value: float = 2.0,
    end: str = "End of file\n",
) -> str:
    """A Lambertian reflector on a 1 x 10 deg grid: every table value ``value``."""
    theta = np.linspace(0.0, 90.0, nth)
    phi = np.arange(0.0, 361.0, 10.0)
    table = f"{nth} {phi.size}\n" + "".join(f"\t{p:g}" for p in phi) + "\n"
    table += "".join(f"{t:g}" + f"\t{value:g}" * phi.size + "\n" for t in theta)
    return (
        "OPTIS - Anisotropic BSDF surface file v8.0\n"
        f"{mode}\nA comment\n17\nTwo lines\nof text\n0\t1\t0\n{flags}\n{vtype}\n1\n0\t\n"
        f"2\n{incidences}\t\n{reference}\n\n2\n400\t50\n700\t25\n" + table * 2 + end
    )


def test_lambertian_table_reads_as_coefficient_over_pi(tmp_path: Path) -> None:
    p = tmp_path / "lambert.anisotropicbsdf"
    p.write_text(_speos_text())
    m = labbrdf.read(p)
    assert m.meta["description"] == "Two lines\nof text"
    d = m.data
    for wl, r in ((400.0, 0.5), (700.0, 0.25)):
        v = d[d["wavelength_nm"] == wl]["value"].to_numpy()
        # trapezoid of cos sin over 1-deg steps: relative error h^2/3 = 1e-4
        np.testing.assert_allclose(v, r / np.pi, rtol=2e-4)
    # the source at phi_r 0, the specular direction (table phi 0) at phi_r 180
    assert sorted(set(d["phi_r_deg"].round(6)))[:3] == [0.0, 10.0, 20.0]
    t = read_speos_table(p)
    assert t.values.shape == (1, 2, 91, 37)


def test_table_azimuth_zero_is_the_specular_direction(tmp_path: Path) -> None:
    p = tmp_path / "spec.anisotropicbsdf"
    lines = _speos_text().splitlines()
    i = next(k for k, s in enumerate(lines) if s.startswith("10\t"))  # theta 10 of table 1
    cells = lines[i].split("\t")
    cells[1] = "7"  # table phi 0
    lines[i] = "\t".join(cells)
    p.write_text("\n".join(lines) + "\n")
    d = labbrdf.read(p).data
    hot = d[d["value"] == d["value"].max()]
    assert set(hot["phi_r_deg"]) == {180.0} and set(hot["theta_r_deg"]) == {10.0}


@pytest.mark.parametrize(
    ("change", "match", "line"),
    [
        ({"mode": "1"}, "binary Speos BSDF file", 2),
        ({"flags": "0\t1"}, "transmission tables", 8),
        ({"vtype": "0"}, "values type 0", 9),
        ({"incidences": "10.0"}, "incidences: expected 2 value", 13),
        ({"reference": "20.0\t0"}, "not one of the incidences", None),
        ({"end": ""}, "expected 'End of file'", None),
        ({"end": "End of file\n1 2\n"}, "nothing after 'End of file'", None),
        ({"incidences": "30.0\t10.0"}, "increasing angles", 13),
    ],
)
def test_bad_speos_files_name_the_file_and_line(
    tmp_path: Path, change: dict, match: str, line: int | None
) -> None:
    p = tmp_path / "bad.anisotropicbsdf"
    p.write_text(_speos_text(**change))
    with pytest.raises(AdapterError, match=match) as exc:
        labbrdf.read(p)
    assert exc.value.path == str(p)
    if line is not None:
        assert exc.value.line == line


def test_a_table_row_with_a_missing_value_names_its_line(tmp_path: Path) -> None:
    lines = _speos_text().splitlines()
    i = next(k for k, s in enumerate(lines) if s.startswith("45\t"))
    lines[i] = lines[i].rsplit("\t", 1)[0]
    p = tmp_path / "short.anisotropicbsdf"
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(AdapterError, match="expected 38 values in the row") as exc:
        labbrdf.read(p)
    assert exc.value.line == i + 1


def test_a_huge_table_count_is_refused_before_allocating(tmp_path: Path) -> None:
    text = _speos_text().replace("91 37\n", "900000000 37\n", 1)
    p = tmp_path / "huge.anisotropicbsdf"
    p.write_text(text)
    with pytest.raises(AdapterError, match="more than the file of"):
        labbrdf.read(p)


def test_a_non_speos_file_forced_to_the_format_is_refused(tmp_path: Path) -> None:
    p = tmp_path / "other.anisotropicbsdf"
    p.write_text("1 2\n3 4\n")
    with pytest.raises(AdapterError, match="expected a Speos BSDF file"):
        labbrdf.read(p, format="speos-bsdf")
