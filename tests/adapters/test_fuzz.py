"""Mutation fuzzing of every adapter over every real export, and "reading never writes".

For each format in ``labbrdf.adapters.READERS`` with real files in ../shared/real-exports
(the format of a file is the one ``labbrdf.read`` dispatches it to), Hypothesis mutates the
file's bytes and reads the result with that format forced. Mutations:

``truncate``  keep the first k bytes, 0 <= k < size;
``delete``    remove one line (lines split at CR, LF, CRLF, endings kept);
``duplicate`` repeat one line;
``flip``      overwrite 1-4 random bytes with random values;
``insert``    insert a garbage token (``NaN``, ``1e999``, ``,``, TAB, CRLF, NUL, ``##``, ...).

Contract checked on every example (n = rows + ``meta["dropped_points"]``, i.e. the points
the reader found, kept or dropped as missing; n0 the same for the unmutated file):

1. Nothing but :class:`~labbrdf.adapters.AdapterError` is ever raised (no IndexError,
   struct.error, UnicodeDecodeError, DatasetError, RuntimeWarning ...).
   A real file its format refuses whole (raw counts, irradiance) stays refused: every
   mutation raises AdapterError.
2. No wrong row count comes back silently:

   * ``COUNTED`` formats (``Format.states_count`` in the registry), whose files state their
     point count (JASCO text and binary, PerkinElmer, JCAMP-DX, SPC) or whose reader checks
     the wavelength steps against the instrument's data interval (Cary): every mutation
     either raises or gives n == n0.
     One documented exception: deleting the first or last data row of a Cary sample leaves
     a shorter but consistent scan (as real scans stopped early are, ``filters.csv``
     sample 600LP1), so for Cary ``delete`` the bound is n0 - k <= n <= n0 with k the
     numbers on the deleted line.
   * other formats (no declared count): a truncated file never yields more points than
     the whole file, n <= n0.

Examples are bounded (``EXAMPLES`` per file, derandomized, no example database), so the
run is reproducible and takes well under a minute.
"""

from __future__ import annotations

import hashlib
import os
import random
import re
import shutil
import tempfile
from collections import Counter
from pathlib import Path
from typing import Any

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import labbrdf  # noqa: E402
from labbrdf.adapters import READERS, AdapterError, sniff  # noqa: E402

FIXTURES = Path(labbrdf.__file__).parent / "data" / "fixtures"

#: the formats whose registry entry says their files state the point count
COUNTED = {name for name, f in READERS.items() if f.states_count}
EXAMPLES = 30
GARBAGE = [
    b"NaN", b"nan", b"inf", b"-inf", b"1e999", b"-", b"+", b".", b",", b";", b"\t", b" ",
    b"\r\n", b"\n", b"\r", b"#", b"##", b"?", b"\x00", b"\xff\xfe", b"\xe9", b"\x85",
    b"0", b"9999", b"abc", b"##END=", b"#DATA", b"XYDATA", b"\x0c",
]  # fmt: skip
_NUMBER = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _real_files(real_exports: Path) -> list[Path]:
    return sorted(p for p in real_exports.glob("*/*") if p.is_file() and p.suffix != ".md")


def _format_of(path: Path) -> str | None:
    """The format ``labbrdf.read`` dispatches the file to (None when ambiguous or unknown)."""
    name = path.name.lower()
    by_ext = [n for n, f in READERS.items() if any(name.endswith(e) for e in f.extensions)]
    if len(by_ext) == 1:
        return by_ext[0]
    claimed = sniff(path)
    pool = [n for n in claimed if n in by_ext] or claimed  # as labbrdf.read dispatches
    return pool[0] if len(pool) == 1 else None


def _points(m: labbrdf.Measurement) -> int:
    return len(m) + int(m.meta.get("dropped_points", 0) or 0)


def _mutate(raw: bytes, data: st.DataObject) -> tuple[str, bytes, int]:
    """A mutated copy of ``raw``, the operation, and k (numbers on a deleted line)."""
    op = data.draw(st.sampled_from(["truncate", "delete", "duplicate", "flip", "insert"]))
    if op == "truncate":
        return op, raw[: data.draw(st.integers(0, len(raw) - 1))], 0
    if op in ("delete", "duplicate"):
        lines = raw.splitlines(keepends=True)
        i = data.draw(st.integers(0, len(lines) - 1))
        k = len(_NUMBER.findall(lines[i]))
        new = lines[:i] + lines[i + 1 :] if op == "delete" else lines[: i + 1] + lines[i:]
        return op, b"".join(new), k
    buf = bytearray(raw)
    if op == "flip":
        for _ in range(data.draw(st.integers(1, 4))):
            buf[data.draw(st.integers(0, len(buf) - 1))] = data.draw(st.integers(0, 255))
        return op, bytes(buf), 0
    at = data.draw(st.integers(0, len(buf)))
    return op, bytes(buf[:at] + data.draw(st.sampled_from(GARBAGE)) + buf[at:]), 0


def _check(fmt: str, op: str, k: int, n0: int, m: labbrdf.Measurement) -> None:
    n = _points(m)
    if fmt in COUNTED:
        if fmt == "agilent-cary-winuv-csv" and op == "delete":
            assert n0 - k <= n <= n0, f"{op}: {n} points, expected {n0 - k}..{n0}"
        else:
            assert n == n0, f"{op}: {n} points read silently, the file has {n0}"
    elif op == "truncate":
        assert n <= n0, f"truncation gave {n} points, more than the whole file's {n0}"


def _fuzz_file(fmt: str, raw: bytes, n0: int | None, target: Path) -> None:
    reader = READERS[fmt].read

    @settings(
        max_examples=EXAMPLES,
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    )
    @given(data=st.data())
    def run(data: st.DataObject) -> None:
        op, mutated, k = _mutate(raw, data)
        target.write_bytes(mutated)
        try:
            m = reader(target)
        except AdapterError as exc:
            assert str(target) in str(exc), f"the error does not name the file: {exc}"
            return
        assert n0 is not None, f"{op}: a file refused whole was read after a mutation"
        assert set(m.data["source"]) == {target.name}
        _check(fmt, op, k, n0, m)

    run()


@pytest.mark.parametrize("fmt", sorted(READERS))
def test_mutated_real_files_raise_adaptererror_or_keep_their_count(
    real_exports: Path, fmt: str
) -> None:
    files = [p for p in _real_files(real_exports) if _format_of(p) == fmt]
    if not files:
        pytest.skip(f"no real export of {fmt}")
    with tempfile.TemporaryDirectory() as tmp:
        for path in files:
            n0 = _points_or_refused(fmt, path)  # None: refused by name, stays refused
            _fuzz_file(fmt, path.read_bytes(), n0, Path(tmp) / path.name)


def _points_or_refused(fmt: str, path: Path) -> int | None:
    """Points of a real file, None for a file its format recognises only to refuse it."""
    try:
        return _points(READERS[fmt].read(path))
    except AdapterError:
        return None


#: synthetic files of labbrdf's own CSV layouts (no real export exists), one row per line
_OWN = {
    "labbrdf-specular-scan": "# labbrdf specular-scan v1\r\n# sample: M1\r\n# quantity: brdf\r\n"
    "wavelength_nm,theta_i_deg,theta_r_deg,value,sigma\r\n"
    + "".join(f"632.8,45,{t},{0.5 + t},0.01\r\n" for t in range(-20, 70, 5)),
    "labbrdf-hemispherical-reflectance": "# labbrdf hemispherical-reflectance v1\n# unit: %\n"
    "# theta_i_deg: 8\nwavelength_nm,value,sigma\n"
    + "".join(f"{wl},{wl / 50:.3f},\n" for wl in range(300, 1300, 50)),
}


@pytest.mark.parametrize("fmt", sorted(_OWN))
def test_mutated_own_csv_files_raise_adaptererror_or_lose_only_the_touched_rows(
    tmp_path: Path, fmt: str
) -> None:
    """One data row per line: a truncated file is refused, warned about (a last number
    that may be cut short), or gives exactly its complete remaining data lines, each a row
    of the whole file (never a cut value); a deleted line costs at most one row, a
    duplicated line adds at most one; ``#`` inserted or flipped in at a line start
    comments a row out, so a flip or an insertion may lose rows (one per changed byte) but
    never add one."""
    raw = _OWN[fmt].encode()
    src = tmp_path / "orig.csv"
    src.write_bytes(raw)
    n0 = _points(READERS[fmt].read(src))
    assert n0 == 18 if fmt == "labbrdf-specular-scan" else n0 == 20
    whole = _rows(READERS[fmt].read(src))
    target = tmp_path / "mutated.csv"
    last = raw.rstrip().rfind(b"\n") + 1  # every cut inside the last row, as well
    for cut in range(last + 1, len(raw)):
        outcome = _truncation_outcome(READERS[fmt].read, raw, cut, target, whole)
        assert outcome in ("refused", "warned", "prefix"), f"cut at {cut}: {raw[last:cut]!r}"

    @settings(max_examples=60, deadline=None, derandomize=True, database=None)
    @given(data=st.data())
    def run(data: st.DataObject) -> None:
        op, mutated, _ = _mutate(raw, data)
        if op == "truncate":
            outcome = _truncation_outcome(READERS[fmt].read, raw, len(mutated), target, whole)
            assert outcome in ("refused", "warned", "prefix"), f"cut at {len(mutated)}"
            return
        target.write_bytes(mutated)
        try:
            m = READERS[fmt].read(target)
        except AdapterError as exc:
            assert str(target) in str(exc)
            return
        n = _points(m)
        low, high = {"delete": (n0 - 1, n0), "duplicate": (n0, n0 + 1)}.get(op, (n0 - 4, n0))
        assert low <= n <= high, f"{op}: {n} points from a file of {n0}"

    run()


def _snapshot(root: Path) -> dict[str, tuple[int, int, str]]:
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            st_ = p.stat()
            digest = hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "dir"
            out[str(p.relative_to(root))] = (st_.st_size, st_.st_mtime_ns, digest)
    return out


def test_reading_never_writes(real_exports: Path, tmp_path: Path, monkeypatch) -> None:
    """Read every export from a writable copy: no file appears, changes or is touched."""
    copy = tmp_path / "exports"
    for p in _real_files(real_exports):
        (copy / p.parent.name).mkdir(parents=True, exist_ok=True)
        shutil.copy2(p, copy / p.parent.name / p.name)
    work = tmp_path / "cwd"
    work.mkdir()
    monkeypatch.chdir(work)  # nothing may land in the working directory either
    before = _snapshot(tmp_path)
    read = 0
    for p in _real_files(copy):
        if _format_of(p) is None:
            continue
        try:
            labbrdf.read(p)
        except AdapterError:  # refused by name: refusing must not write either
            pass
        read += 1
    assert read > 0
    assert _snapshot(tmp_path) == before


# ----------------------------------------------------------------------- truncation sweep

#: text formats cut at byte offsets: those whose readers check the last line of a file cut
#: short (:func:`labbrdf.adapters._truncation.check_last_field`: UVProbe text, Woollam,
#: Accurion, SENTECH, declared columns, labbrdf's own CSV layouts...) and those whose files
#: state their point count or end with a footer or end marker
TRUNCATION_FORMATS = (
    "shimadzu-uvprobe-text",
    "woollam-wvase",
    "woollam-completeease",
    "accurion-ep4",
    "sentech-spectraray",
    "columns",
    "jasco-spectramanager-text",
    "perkinelmer-uvwinlab-asc",
    "agilent-cary-winuv-csv",
    "filmsense",
    "jcamp-dx",
    "zemax-bsdf",
    "speos-bsdf",
    "pab-pgii",
    "astm-brdf",
    "labbrdf-specular-scan",
    "labbrdf-hemispherical-reflectance",
    "oceanoptics-text",
    "oceanoptics-jaz",
    "avantes-avasoft",
)
#: the declared columns of the real headerless file
_COLUMNS_FILES = {"MoS2_fromCzech2015.txt": "wavelength_nm,absorbance"}
#: cut offsets tried per file (seeded by the file name: the same offsets on every run)
CUTS = 40
#: and the cuts in the last bytes of the last line (the last number or two)
LAST_LINE_CUTS = 24


def _rows(m: labbrdf.Measurement) -> set[tuple]:
    """Every row of a result as a hashable tuple (NaN as the string 'nan').

    ``source`` and ``sample`` are left out: a cut file has its own name, and a reader may
    name the sample from a footer the cut removed (then from the file name).
    """
    d = m.data.drop(columns=["source", "sample"])
    return {
        tuple("nan" if isinstance(v, float) and v != v else v for v in row)
        for row in d.itertuples(index=False)
    }


def _truncation_outcome(read, raw: bytes, cut: int, target: Path, whole: set[tuple]) -> str:
    """``refused``, ``warned``, ``prefix`` (every row as in the whole file) or ``changed``."""
    import warnings

    target.write_bytes(raw[:cut])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            m = read(target)
        except AdapterError as exc:
            assert str(target) in str(exc), f"cut {cut}: the error does not name the file: {exc}"
            return "refused"
    ours = [w for w in caught if issubclass(w.category, labbrdf.adapters.AdapterWarning)]
    if ours:
        text = str(ours[0].message)
        assert str(target) in text and ", line " in text, f"cut {cut}: {text}"
        return "warned"
    return "prefix" if _rows(m) <= whole else "changed"


def _avantes_rows(n: int) -> str:
    """AvaSoft 8 ASCII rows whose processed column is 100 (S - D) / (R - D), 5 decimals."""
    rows = []
    for i in range(n):
        d, r, s = 1000.0 + i, 31000.0 + 7 * i, 9000.0 + 13 * i
        rows.append(
            f"{400 + 0.6 * i:.2f};{s:9.3f};{d:9.3f};{r:9.3f};{100 * (s - d) / (r - d):.5f}\r\n"
        )
    return "".join(rows)


def _pgii_rows(n: int) -> str:
    """pgII rows of a diffuse reflector: theta phi DSF, 3 decimals as Mountain writes them."""
    return "".join(
        f"{5.0 + 0.25 * i:.3f}\t{(37.0 * i) % 360:.3f}\t{0.3 * (1 - 0.002 * i):.6f}\n"
        for i in range(n)
    )


def _astm_rows(n: int) -> str:
    """ASTM-style rows (radians, two wavelengths), 6 decimals throughout."""
    return "".join(
        f"0.523599,0.000000,{0.02 * i:.6f},3.141593,{0.3 - 0.001 * i:.6f},{0.4 - 0.001 * i:.6f}\n"
        for i in range(n)
    )


#: synthetic files of the formats with no real file here, or whose only real file is
#: refused whole (irradiance)
_SYNTHETIC = {
    "astm-brdf": [
        (
            "paint.astm",
            'NAME "paint"\nVARS theta_i,phi_i,theta_s,phi_s,450nm,550nm\n' + _astm_rows(40),
        )
    ],
    "pab-pgii": [
        (
            "f30_Rvis.txt",
            '#sample_name "white"\n#format: theta phi DSF\n#incident_angle 30 0\n'
            + _pgii_rows(40),
        )
    ],
    "avantes-avasoft": [
        (
            "feather_reflection.txt",
            "\r\nIntegration time [ms]:  84.900\r\nAveraging Nr. [scans]: 10\r\n"
            "Smoothing Nr. [pixels]: 1\r\nData measured with spectrometer [name]: 1501154U1\r\n"
            "Wave   ;Sample   ;Dark     ;Reference;Reflectance\r\n"
            "[nm]   ;[counts] ;[counts] ;[counts] ;[%]\r\n\r\n" + _avantes_rows(40),
        )
    ],
}


@pytest.mark.parametrize("fmt", ["pab-pgii", "astm-brdf"])
def test_mutated_synthetic_files_raise_adaptererror_or_keep_their_count(
    tmp_path: Path, fmt: str
) -> None:
    """The formats with no real export here: their synthetic file, mutated the same way."""
    ((name, text),) = _SYNTHETIC[fmt]
    src = tmp_path / name
    src.write_text(text)
    n0 = _points(READERS[fmt].read(src))
    assert n0 > 0
    _fuzz_file(fmt, text.encode(), n0, tmp_path / f"mutated-{name}")


def _truncation_cases(real_exports: Path, fmt: str) -> list[tuple[str, bytes, Any]]:
    """(file name, its bytes, the reader) of every real file, fixture or synthetic file."""
    if fmt == "columns":
        return [
            (name, p.read_bytes(), lambda p, c=cols: labbrdf.read(p, columns=c))
            for name, cols in _COLUMNS_FILES.items()
            if (p := real_exports / "generic-columns" / name).is_file()
        ]  # fmt: skip
    files = [p for p in _real_files(real_exports) if _format_of(p) == fmt]
    files += [p for p in sorted(FIXTURES.glob("*/*")) if p.is_file() and sniff(p) == [fmt]]
    read = READERS[fmt].read
    cases = [(p.name, p.read_bytes(), read) for p in files]
    return cases + [(name, text.encode("cp1252"), read) for name, text in _SYNTHETIC.get(fmt, [])]


def truncation_sweep(real_exports: Path, fmt: str, tmp: Path, cuts: int = CUTS) -> Counter:
    """Cut every file of ``fmt`` at ``cuts`` seeded offsets and inside its last line; count
    the outcomes (and the files read whole, ``files``)."""
    counts: Counter = Counter()
    for name, raw, read in _truncation_cases(real_exports, fmt):
        src = tmp / "whole" / name
        src.parent.mkdir(exist_ok=True)
        src.write_bytes(raw)
        try:
            whole = _rows(read(src))
        except AdapterError:  # refused whole (a layout the reader does not take yet)
            continue
        counts["files"] += 1
        rng = random.Random(name)
        offsets = set(rng.sample(range(1, len(raw)), min(cuts, len(raw) - 1)))
        body = raw.rstrip()  # and every cut in the end of the last line, where a number ends
        start = max(body.rfind(b"\n"), body.rfind(b"\r"), len(body) - LAST_LINE_CUTS - 1)
        offsets |= set(range(start + 2, len(body)))
        target = tmp / name
        for cut in sorted(offsets):
            outcome = _truncation_outcome(read, raw, cut, target, whole)
            counts[outcome] += 1
            if outcome == "changed":
                counts.setdefault("first_changed", f"{name} cut at byte {cut}")  # type: ignore[arg-type]
    return counts


@pytest.mark.parametrize("fmt", TRUNCATION_FORMATS)
def test_a_file_cut_anywhere_is_refused_warned_or_a_prefix_of_the_whole(
    real_exports: Path, tmp_path: Path, fmt: str
) -> None:
    """A real file cut at a byte offset never gives a changed value: the reader refuses it
    or warns naming the line, or every row it returns is a row of the whole file."""
    if not _truncation_cases(real_exports, fmt):
        pytest.skip(f"no real export of {fmt}")
    counts = truncation_sweep(real_exports, fmt, tmp_path)
    assert counts["files"] > 0, f"no file of {fmt} is read whole"
    assert counts["changed"] == 0, dict(counts)
