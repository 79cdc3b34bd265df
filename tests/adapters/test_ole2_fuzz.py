"""Chain-corruption and truncation sweeps of the OLE2 readers (UVProbe .spc, legacy JASCO .jws).

Each container is located with ``olefile`` (its FAT, DIFAT, directory and mini FAT sectors),
then damaged one 32-bit field (or one byte) at a time where a reader that trusts the
container would read wrong data: FAT entries, DIFAT entries, directory entries (start
sector, size, type, sibling and child links), mini FAT entries, the header's chain fields;
and the file is cut at every sector boundary and at random offsets. The values written are
drawn (seeded, so the sweep is the same on every run) from other sector indices, the
neighbours of the original value and the special markers ENDOFCHAIN, FREESECT, FATSECT and
DIFSECT.

Contract for every mutant: the reader raises an :class:`AdapterError` naming the file, or
returns exactly the data of the undamaged file. Different data with success (a silent
change) or any other exception (a traceback) fails the sweep, whose counts are printed.

The containers are synthetic (they run without ../shared): a UVProbe .spc and a legacy
.jws whose data streams lie in the FAT and whose small streams lie in the mini stream,
and a legacy .jws over 7 MB, whose FAT needs a DIFAT sector. The real exports are swept
too where ../shared is present.
"""

from __future__ import annotations

import random
import struct
import zlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import olefile
import pytest

from labbrdf.adapters import READERS, AdapterError

_END, _FREE, _FATSECT, _DIFSECT = 0xFFFFFFFE, 0xFFFFFFFF, 0xFFFFFFFD, 0xFFFFFFFC
_SS, _DIR = 512, 128

#: (kind, offset, bytes written) or ("truncate", length, b"")
Mutant = tuple[str, int, bytes]


# ----------------------------------------------------------------------------- containers


def _page(title: str, pairs: list[tuple[str, str]]) -> bytes:
    out = struct.pack("<II", 1, 0) + bytes([len(title)]) + title.encode()
    out += struct.pack("<I", len(pairs))
    for k, v in pairs:
        out += bytes([len(k)]) + k.encode() + bytes([len(v)]) + v.encode()
    return out


Writer = Callable[[dict[str, bytes]], bytes]


def _uvprobe(write_ole2: Writer, n: int = 600) -> bytes:
    """A UVProbe .spc: X and Y (8 n bytes each) in the FAT, the rest in the mini stream."""
    x = np.linspace(900.0, 300.0, n)
    y = np.sin(x / 37.0) + 1.5
    base = "DataStorage1/DataSetGroup/DataSet1"
    data = f"{base}/DataSpectrumStorage"
    return write_ole2(
        {
            f"{data}/Data/Data Header.1": struct.pack("<ii", n, 2),
            f"{data}/Data/X Data.1": x.astype("<f8").tobytes(),
            f"{data}/Data/Y Data.1": y.astype("<f8").tobytes(),
            f"{data}/DataHeader/Header Info": struct.pack("<3d", x[0], x[-1], 1.0) + bytes(8),
            f"{base}/MethodStorage/PageTexts0": _page(
                "[Instrument Properties]",
                [("Instrument Type:", "UV-1800"), ("Measuring Mode:", "Absorbance")],
            ),
        }
    )


def _legacy_jws(write_ole2: Writer, n: int = 1200, padding: int = 0) -> bytes:
    """A legacy .jws: Y-Data (4 n bytes) in the FAT; ``padding`` bytes of an unread stream."""
    info = struct.pack("<6I3d", 3, 1, 0, 1, 1, n, 4000.0, 4000.0 - 2.0 * (n - 1), -2.0)
    info = (info + struct.pack("<2I", 0x10000100, 0)).ljust(96, b"\x00")
    y = (50.0 + 20.0 * np.cos(np.arange(n) / 50.0)).astype("<f4").tobytes()
    streams = {"DataInfo": info, "Y-Data": y, "Header": bytes(range(64))}
    if padding:
        streams["MicroImages/Picture"] = bytes(padding)
    return write_ole2(streams)


# ----------------------------------------------------------------------------- layout


@dataclass(frozen=True)
class _Layout:
    """Where the structures of a container lie (sector indices, from ``olefile``)."""

    sectors: int  # sectors after the header
    fat: list[int]  # FAT sectors, in order
    difat: list[int]  # DIFAT sectors, in order
    directory: list[int]  # directory chain
    minifat: list[int]  # mini FAT chain
    entries: list[tuple[int, int]]  # (sid, size) of the allocated directory entries
    mini_entries: int  # mini FAT entries in use (mini sectors of the mini stream)


def _walk(fat: object, start: int) -> list[int]:
    out: list[int] = []
    while start not in (_END, _FREE) and len(out) < 1 << 16:
        out.append(start)
        start = int(fat[start])  # type: ignore[index]
    return out


def _layout(raw: bytes) -> _Layout:
    ole = olefile.OleFileIO(raw, raise_defects=olefile.DEFECT_INCORRECT)
    listed = list(struct.unpack_from("<109I", raw, 76))
    difat, d = [], ole.first_difat_sector  # chained by the last entry of each, not the FAT
    for _ in range(ole.num_difat_sectors):
        difat.append(d)
        *more, d = struct.unpack_from("<128I", raw, (d + 1) * _SS)
        listed += more
    ole.loadminifat()
    entries = [(e.sid, e.size) for e in ole.direntries if e is not None]
    return _Layout(
        sectors=(len(raw) - 1) // _SS,
        fat=listed[: ole.num_fat_sectors],
        difat=difat,
        directory=_walk(ole.fat, ole.first_dir_sector),
        minifat=_walk(ole.fat, ole.first_mini_fat_sector),
        entries=entries,
        mini_entries=len(ole.minifat),
    )


def _in(chain: list[int], index: int, width: int, per: int = _SS // 4) -> int:
    """Byte offset of item ``index`` (``width`` bytes each) of a structure on ``chain``."""
    per = _SS // width
    return (chain[index // per] + 1) * _SS + width * (index % per)


# ----------------------------------------------------------------------------- mutants


def _sector_value(rng: random.Random, old: int, nsect: int) -> int:
    pool = [rng.randrange(nsect), rng.randrange(nsect), old + 1, old - 1, nsect, 1 << 31]
    pool += [_END, _FREE, _FATSECT, _DIFSECT]
    return rng.choice([v & 0xFFFFFFFF for v in pool if v & 0xFFFFFFFF != old])


def _u32(raw: bytes, at: int) -> int:
    return int(struct.unpack_from("<I", raw, at)[0])


def _fields(rng: random.Random, raw: bytes, kind: str, offsets: list[int], nsect: int):
    for at in offsets:
        yield kind, at, struct.pack("<I", _sector_value(rng, _u32(raw, at), nsect))


def _directory_mutants(rng: random.Random, raw: bytes, lay: _Layout) -> Iterator[Mutant]:
    n = lay.sectors
    for sid, size in lay.entries:
        at = _in(lay.directory, sid, _DIR)
        yield from _fields(rng, raw, "dir-start", [at + 116], n)
        for new in rng.sample([size + 1, size - 1, size + 64, size - 64, size + _SS,
                               size - _SS, 2 * size, 0, 4095, 4096, 1 << 31], 3):  # fmt: skip
            if new != size:
                yield "dir-size", at + 120, struct.pack("<I", new & 0xFFFFFFFF)
        yield "dir-type", at + 66, bytes([rng.choice([t for t in range(6) if t != raw[at + 66]])])
        link = at + rng.choice([68, 72, 76])
        yield "dir-link", link, struct.pack("<I", rng.choice([rng.randrange(len(lay.entries) + 2),
                                                              0xFFFFFFFF, sid]))  # fmt: skip


def mutants(raw: bytes, seed: int, *, fat: int = 40, truncations: int = 12) -> list[Mutant]:
    """The sweep of one container (deterministic for a seed)."""
    rng = random.Random(seed)
    lay = _layout(raw)
    n = lay.sectors
    out: list[Mutant] = []
    fat_at = [_in(lay.fat, i, 4) for i in rng.sample(range(n), min(fat, n))]
    out += _fields(rng, raw, "fat", fat_at, n)
    out += _directory_mutants(rng, raw, lay)
    used = range(lay.mini_entries)
    out += _fields(rng, raw, "minifat", [_in(lay.minifat, i, 4) for i in used], n)
    header = [44, 48, 60, 64, 68, 72, 76, 80]  # FAT count, chain starts and counts, DIFAT
    out += _fields(rng, raw, "header", header * 2, n)
    for d in lay.difat:
        picks = [0, 1, lay.fat.__len__() - 110, 126, 127] + rng.sample(range(128), 5)
        out += _fields(rng, raw, "difat", [(d + 1) * _SS + 4 * j for j in picks], n)
    cuts = sorted({(k + 1) * _SS for k in range(n)} | {rng.randrange(len(raw)) for _ in range(8)})
    if len(cuts) > truncations:
        cuts = sorted(rng.sample(cuts, truncations))
    out += [("truncate", k, b"") for k in cuts if k < len(raw)]
    return out


def _apply(raw: bytes, m: Mutant) -> bytes:
    kind, at, new = m
    if kind == "truncate":
        return raw[:at]
    return raw[:at] + new + raw[at + len(new) :]


# ----------------------------------------------------------------------------- the sweep


@dataclass
class Counts:
    mutants: int = 0
    refusals: int = 0
    unchanged: int = 0
    tracebacks: int = 0
    silent: int = 0


def sweep(
    fmt: str, name: str, raw: bytes, tmp: Path, seed: int, **kw: int
) -> tuple[Counts, list[str]]:
    """Read every mutant of ``raw`` with format ``fmt``; the counts and the failures."""
    read: Callable = READERS[fmt].read
    src = tmp / "original" / name
    src.parent.mkdir()
    src.write_bytes(raw)
    want = read(src).data
    target = tmp / "mutant" / name
    target.parent.mkdir()
    counts, failures = Counts(), []
    for m in mutants(raw, seed, **kw):
        counts.mutants += 1
        target.write_bytes(_apply(raw, m))
        try:
            got = read(target).data
        except AdapterError as exc:
            if str(target) in str(exc):
                counts.refusals += 1
                continue
            counts.tracebacks += 1
            failures.append(f"{m[:2]}: the error does not name the file: {exc}")
        except Exception as exc:  # noqa: BLE001 - the contract allows only AdapterError
            counts.tracebacks += 1
            failures.append(f"{m[:2]}: {type(exc).__name__}: {exc}")
        else:
            if got.equals(want):
                counts.unchanged += 1
            else:
                counts.silent += 1
                failures.append(f"{m[:2]}: read {len(got)} rows, not the original {len(want)}")
    return counts, failures


def _check(fmt: str, name: str, raw: bytes, tmp: Path, **kw: int) -> None:
    counts, failures = sweep(fmt, name, raw, tmp, zlib.crc32(name.encode()), **kw)
    print(f"\n{fmt} {name}: {counts}")
    assert counts.mutants > 50
    assert counts.refusals > 0
    assert not failures, f"{counts}\n" + "\n".join(failures[:15])


#: a container over 7 MB: 115 FAT sectors, the last 6 listed in a DIFAT sector
_BIG = 7_400_000


def _big_jws(write_ole2: Writer) -> bytes:
    return _legacy_jws(write_ole2, padding=_BIG)


_SYNTHETIC: dict[str, tuple[str, Callable[[Writer], bytes], dict[str, int]]] = {
    "uvprobe.spc": ("shimadzu-uvprobe-spc", _uvprobe, {}),
    "legacy.jws": ("jasco-jws", _legacy_jws, {}),
    "difat.jws": ("jasco-jws", _big_jws, {"fat": 16, "truncations": 4}),
}


@pytest.mark.parametrize("name", sorted(_SYNTHETIC))
def test_synthetic_containers_are_refused_or_read_unchanged(
    tmp_path: Path, make_ole2: Writer, name: str
) -> None:
    fmt, make, kw = _SYNTHETIC[name]
    _check(fmt, name, make(make_ole2), tmp_path, **kw)


def test_the_large_synthetic_container_has_a_difat(make_ole2: Writer) -> None:
    lay = _layout(_big_jws(make_ole2))
    assert len(lay.fat) > 109 and len(lay.difat) == 1


@pytest.mark.parametrize(
    ("fmt", "rel"),
    [
        ("shimadzu-uvprobe-spc", "shimadzu-uvprobe/sa281-02-280K.spc"),
        ("jasco-jws", "jasco-jws-binary/legacy_trans_512.jws"),
    ],
)
def test_real_containers_are_refused_or_read_unchanged(
    real_exports: Path, tmp_path: Path, fmt: str, rel: str
) -> None:
    path = real_exports / rel
    if not path.is_file():
        pytest.skip(f"{rel} is not in the collection")
    _check(fmt, path.name, path.read_bytes(), tmp_path)
