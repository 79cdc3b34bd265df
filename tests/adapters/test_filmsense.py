"""Film Sense: header field counts are enforced (a lost field must not shift the AOI)."""

from __future__ import annotations

from pathlib import Path

import pytest

from labbrdf.adapters import AdapterError
from labbrdf.adapters.filmsense import read_filmsense

FS = "filmsense-txt"


def test_line2_with_a_field_deleted_is_refused_not_read_as_a_2_deg_aoi(
    real_exports: Path, tmp_path: Path
) -> None:
    raw = (real_exports / FS / "Filmsense_staticTest.txt").read_bytes()
    # line 2: "8	1	-70.012	-0.002	-0.003	19.0913"; sed '2s/-70.012\t//'
    bad = tmp_path / "static.txt"
    bad.write_bytes(raw.replace(b"8\t1\t-70.012\t", b"8\t1\t", 1))
    with pytest.raises(AdapterError, match=r"line 2: count line .*expected 6 .* found 5"):
        read_filmsense(bad)


def test_led_line_with_a_field_deleted_is_refused(real_exports: Path, tmp_path: Path) -> None:
    raw = (real_exports / FS / "Filmsense_kineticTest.txt").read_bytes()
    # line 3: "367.20	14.32	3.39	2.48	1.218	1.363	0.059"
    bad = tmp_path / "kinetic.txt"
    bad.write_bytes(raw.replace(b"367.20\t14.32\t", b"367.20\t", 1))
    with pytest.raises(AdapterError, match=r"line 3: LED line: expected 7 numbers .* found 6"):
        read_filmsense(bad)


def test_dynamic_line2_with_a_field_deleted_is_refused(real_exports: Path, tmp_path: Path) -> None:
    raw = (real_exports / FS / "Filmsense_kineticTest.txt").read_bytes()
    bad = tmp_path / "kinetic.txt"
    bad.write_bytes(raw.replace(b"8\t7\t-70.012\t", b"8\t7\t", 1))  # line 2
    with pytest.raises(AdapterError, match=r"line 2: count line .*expected 4 .* found 3"):
        read_filmsense(bad)
