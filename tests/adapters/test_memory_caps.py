"""Declared point counts are checked before anything is allocated for them.

Each crafted file is read in a child process whose address space is limited to 512 MB
(``resource.setrlimit(RLIMIT_AS)``): a reader that trusts the count runs into MemoryError
there (or is killed), one that checks it first raises AdapterError.
"""

from __future__ import annotations

import os
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from labbrdf.adapters import READERS

LIMIT = 512 << 20

_CHILD = """
import resource, sys
resource.setrlimit(resource.RLIMIT_AS, ({limit}, {limit}))
from labbrdf.adapters import READERS, AdapterError
try:
    READERS[sys.argv[1]].read(sys.argv[2])
except AdapterError as exc:
    print("AdapterError:", exc)
else:
    print("read without error")
"""


def _read_limited(fmt: str, path: Path, root: Path) -> str:
    env = {**os.environ, "PYTHONPATH": str(root), "OPENBLAS_NUM_THREADS": "1"}
    out = subprocess.run(
        [sys.executable, "-c", _CHILD.format(limit=LIMIT), fmt, str(path)],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout.strip()


def _reference(fmt: str) -> str:
    """The reference export of ``fmt``: the first example of its registry entry. The
    crafted files below change a count at a known place of that file."""
    return READERS[fmt].examples[0].path


def _jcamp_dup(real: Path, tmp: Path) -> Path:
    raw = (real / _reference("jcamp-dx")).read_bytes()
    i = raw.index(b"Tk69")
    p = tmp / "dup.jdx"
    p.write_bytes(raw[: i + 1] + b"99999999" + raw[i + 1 :])  # 3e8 repeats, NPOINTS 440
    return p


def _jcamp_npoints(real: Path, tmp: Path) -> Path:
    raw = (real / _reference("jcamp-dx")).read_bytes()
    p = tmp / "npoints.jdx"
    p.write_bytes(raw.replace(b"##NPOINTS=  440", b"##NPOINTS=  999999999999"))
    return p


def _spc(real: Path, tmp: Path, npts: int, nsub: int | None = None) -> Path:
    raw = bytearray((real / _reference("galactic-spc")).read_bytes())
    struct.pack_into("<i", raw, 4, npts)
    if nsub is not None:
        raw[0] |= 0x04  # TMULTI
        struct.pack_into("<i", raw, 24, nsub)
    p = tmp / f"n{npts}_{nsub}.spc"
    p.write_bytes(bytes(raw))
    return p


def _pe(real: Path, tmp: Path) -> Path:
    src = real / _reference("perkinelmer-uvwinlab-asc")
    lines = src.read_bytes().split(b"\n")
    k = lines.index(b"#DATA") if b"#DATA" in lines else lines.index(b"#DATA\r")
    # the #GR block ends "... FIRSTX, DELTAX, NPOINTS, ..." : NPOINTS is line gr + 7
    gr = next(i for i, s in enumerate(lines) if s.rstrip(b"\r") == b"#GR")
    lines[gr + 7] = b"1999999" + (b"\r" if lines[gr + 7].endswith(b"\r") else b"")
    assert gr + 7 < k
    p = tmp / "npoints.Probe.Raw.asc"
    p.write_bytes(b"\n".join(lines))
    return p


def _jasco_text(real: Path, tmp: Path) -> Path:
    raw = (real / _reference("jasco-spectramanager-text")).read_bytes()
    p = tmp / "npoints.txt"
    p.write_bytes(raw.replace(b"NPOINTS\t61", b"NPOINTS\t1999999"))
    assert p.read_bytes() != raw
    return p


def _jws(real: Path, tmp: Path) -> Path:
    raw = bytearray((real / _reference("jasco-jws")).read_bytes())
    struct.pack_into("<i", raw, 0x84, 2**31 - 1)
    p = tmp / "npoints.jws"
    p.write_bytes(bytes(raw))
    return p


def _speos(real: Path, tmp: Path) -> Path:
    raw = (real / _reference("speos-bsdf")).read_bytes()
    p = tmp / "huge.anisotropicbsdf"
    p.write_bytes(raw.replace(b"\n19 37\n", b"\n1999999999 37\n", 1))
    assert p.read_bytes() != raw
    return p


CASES = {
    "jcamp-dup-past-npoints": ("jcamp-dx", _jcamp_dup, "DUP count"),
    "jcamp-npoints-above-cap": ("jcamp-dx", _jcamp_npoints, "exceeds the limit"),
    "spc-fnpts-above-cap": ("galactic-spc", lambda r, t: _spc(r, t, 2**31 - 1), "exceeds"),
    "spc-fnpts-beyond-file": ("galactic-spc", lambda r, t: _spc(r, t, 1_000_000), "bytes"),
    "spc-fnsub-total": ("galactic-spc", lambda r, t: _spc(r, t, 901, 2**31 - 1), "exceeds"),
    "perkinelmer-npoints": ("perkinelmer-uvwinlab-asc", _pe, "NPOINTS = 1999999 needs"),
    "jasco-text-npoints": ("jasco-spectramanager-text", _jasco_text, "NPOINTS = 1999999"),
    "jasco-jws-npoints": ("jasco-jws", _jws, "NPOINTS = 2147483647 exceeds"),
    "speos-table-size": ("speos-bsdf", _speos, "more than the file of"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_crafted_huge_count_raises_adaptererror_within_512_mb(
    real_exports: Path, tmp_path: Path, case: str, project_root: Path
) -> None:
    fmt, make, expected = CASES[case]
    path = make(real_exports, tmp_path)
    out = _read_limited(fmt, path, project_root)
    assert out.startswith(f"AdapterError: {path}"), out
    assert expected in out, out


# ------------------------------------------------------------ header strings


_CHILD_TIMED = """
import resource, sys, time
resource.setrlimit(resource.RLIMIT_AS, ({limit}, {limit}))
import labbrdf
from labbrdf.adapters import AdapterError
t = time.perf_counter()
try:
    m = labbrdf.read(sys.argv[1])
except AdapterError as exc:
    print("AdapterError:", str(exc)[:300])
else:
    print("rows", len(m), "sample", len(m.data["sample"].iloc[0]),
          "meta_title", len(m.meta["blocks"][0]["title"]))
print("seconds", time.perf_counter() - t)
# VmHWM is this process's own peak; Linux carries ru_maxrss over from the forking parent
try:
    hwm = next(l for l in open("/proc/self/status") if l.startswith("VmHWM:"))
    peak_kib = int(hwm.split()[1])
except (OSError, StopIteration):
    peak_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print("peak_mb", peak_kib / 1024)
"""

#: 1 GiB of address space: the 5 MB title once per row (440 rows) needed 2.3 GB
GIB = 1 << 30


def test_five_megabyte_jcamp_title_reads_within_one_gib(
    tmp_path: Path, project_root: Path
) -> None:
    """The title is the sample name: kept once (cut in the table), never once per row."""
    title = "T" * 5_000_000
    rows = "".join(f"{400 + 10 * i} {i % 7 + 1}\n" for i in range(440))
    p = tmp_path / "title.jdx"
    p.write_text(
        f"##TITLE= {title}\n##JCAMP-DX= 4.24\n##XUNITS= NANOMETERS\n##YUNITS= ABSORBANCE\n"
        f"##NPOINTS= 440\n##XYPOINTS= (XY..XY)\n{rows}##END=\n"
    )
    env = {**os.environ, "PYTHONPATH": str(project_root), "OPENBLAS_NUM_THREADS": "1"}
    out = subprocess.run(
        [sys.executable, "-c", _CHILD_TIMED.format(limit=GIB), str(p)],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    lines = dict(line.split(" ", 1) for line in out.stdout.strip().splitlines())
    assert lines["rows"].startswith("440 sample 512 meta_title 5000000"), out.stdout
    # the table, one copy of the title in meta and the interpreter: far below the limit
    assert float(lines["peak_mb"]) < 400, out.stdout


def test_memory_error_in_a_reader_names_the_file(tmp_path: Path, monkeypatch) -> None:
    from labbrdf import adapters

    def exhausted(path):
        raise MemoryError

    fmt = adapters.READERS["jcamp-dx"]
    monkeypatch.setitem(
        adapters.READERS,
        "jcamp-dx",
        adapters.Format(fmt.name, fmt.description, fmt.extensions, fmt.sniff, exhausted),
    )
    p = tmp_path / "x.jdx"
    p.write_text("##TITLE= t\n##JCAMP-DX= 4.24\n")
    with pytest.raises(adapters.AdapterError, match=r"x.jdx: ran out of memory reading it as"):
        adapters.read(p)


def test_long_sample_names_are_cut_with_a_mark() -> None:
    from labbrdf.dataset import MAX_NAME_CHARS, capped_name, make_frame

    assert capped_name("short") == "short"
    long = "x" * 10_000
    cut = capped_name(long)
    assert len(cut) == MAX_NAME_CHARS and cut.endswith("... [10000 characters, cut]")
    f = make_frame(
        sample=long,
        instrument="i",
        source="s",
        quantity="absorbance",
        value=[1.0, 2.0],
        unit="1",
        wavelength_nm=[400.0, 401.0],
    )
    assert set(f["sample"]) == {cut}
