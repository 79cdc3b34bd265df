"""A single-spectrum text export joined with itself (``cat a a > b``) is refused at the line
where the copy starts (:func:`labbrdf.adapters._truncation.check_joined`), in every reader of
such exports, real files and bundled fixtures alike; never read as one spectrum with every
wavelength twice, a footer, or a confusing error further on."""

from __future__ import annotations

from pathlib import Path

import pytest

import labbrdf
from labbrdf.adapters import READERS, AdapterError
from labbrdf.adapters._base import split_lines
from labbrdf.adapters._truncation import check_joined

FIXTURES = Path(labbrdf.__file__).parent / "data" / "fixtures"

#: format -> a real export (under ../shared/real-exports) or a bundled fixture
CASES = [
    ("jasco-spectramanager-text", "jasco-spectramanager-text/PbSe batch 1.txt"),
    ("jasco-spectramanager-text", "jasco-spectramanager-text/uvvis_abs.txt"),
    ("perkinelmer-uvwinlab-asc", "perkinelmer-uvwinlab-asc/KTF-D.Probe.Raw.asc"),
    ("perkinelmer-uvwinlab-asc", "fixture:spectrophotometer/osr_150mm_sphere.Sample.Raw.asc"),
    ("agilent-cary-winuv-csv", "agilent-cary-winuv-csv/CuPCtS_H2O_vis.csv"),
    ("agilent-cary-winuv-csv", "fixture:spectrophotometer/osr_sphere_cary.csv"),
    ("oceanoptics-text", "oceanoptics-oceanview/ambient_0_40_Absorbance_10-54-38-373.txt"),
    ("oceanoptics-jaz", "oceanoptics-jaz/oo-reflectance.jaz"),
    ("filmsense", "filmsense-txt/Filmsense_staticTest.txt"),  # no final line end
    ("filmsense", "filmsense-txt/Filmsense_kineticTest.txt"),
    ("jcamp-dx", "jcamp-dx/blckpac1.jdx"),
]

AVANTES = (
    "\r\nIntegration time [ms]:  84.900\r\nAveraging Nr. [scans]: 10\r\n"
    "Data measured with spectrometer [name]: 1501154U1\r\n"
    "Wave   ;Sample   ;Dark     ;Reference;Reflectance\r\n"
    "[nm]   ;[counts] ;[counts] ;[counts] ;[%]\r\n\r\n"
    " 400.00;  200.000;  100.000;  300.000;50.00000\r\n"
    " 400.60;  200.000;  100.000;  500.000;25.00000\r\n"
)


def _source(real_exports: Path, rel: str) -> Path:
    if rel.startswith("fixture:"):
        return FIXTURES / rel.removeprefix("fixture:")
    return real_exports / rel


def _copy_start(raw: bytes) -> int:
    """1-based line of ``raw + raw`` where the copy starts (the glued line without a line
    end)."""
    n = len(split_lines(raw.decode("latin-1")))
    return n + 1 if raw.endswith((b"\n", b"\r")) else n


@pytest.mark.parametrize(("fmt", "rel"), CASES, ids=[Path(r).name for _, r in CASES])
def test_an_export_joined_with_itself_is_refused_where_the_copy_starts(
    real_exports: Path, tmp_path: Path, fmt: str, rel: str
) -> None:
    raw = _source(real_exports, rel).read_bytes()
    READERS[fmt].read(_source(real_exports, rel))  # the export alone is read
    joined = tmp_path / Path(rel).name
    joined.write_bytes(raw + raw)
    line = _copy_start(raw)
    expected = "a second top-level block" if fmt == "jcamp-dx" else "two exports joined"
    with pytest.raises(AdapterError, match=rf"line {line}: .*{expected}") as exc:
        READERS[fmt].read(joined)
    assert str(joined) in str(exc.value)


def test_an_avasoft_export_joined_with_itself_is_refused(tmp_path: Path) -> None:
    p = tmp_path / "feather.txt"
    p.write_bytes(AVANTES.encode())
    assert len(READERS["avantes-avasoft"].read(p)) == 2
    p.write_bytes((AVANTES + AVANTES).encode())
    with pytest.raises(AdapterError, match=r"feather.txt, line 11: .*two exports joined"):
        READERS["avantes-avasoft"].read(p)


def test_check_joined_finds_a_copy_glued_to_a_last_line_without_line_end() -> None:
    lines = ["Film_Sense_Data", "2\t1\t-70", "1\t2", "Temp: 29.8Film_Sense_Data", "2\t1\t-70"]
    with pytest.raises(AdapterError, match=r"f.txt, line 4: the first line .*line 1"):
        check_joined("f.txt", lines)
    check_joined("f.txt", ["", "TITLE\ta", "XYDATA", "1\t2", "", "[Comments]"])  # no copy
    check_joined("f.txt", [])
