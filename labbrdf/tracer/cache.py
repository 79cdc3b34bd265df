"""The tracer's disk cache of exit operators: verified on load, private, bounded.

Operators (:mod:`labbrdf.tracer.operator`) are kept in the user's cache folder,
``$XDG_CACHE_HOME/labbrdf/tracer`` (``~/.cache/labbrdf/tracer`` when ``XDG_CACHE_HOME`` is
unset), one file per operator named ``exit-<32 hex digits>.op``. Nothing there is trusted:

* The folder is made with mode 0o700. A folder or file that another user owns, or that
  the group or others may write, is not used (a :class:`CacheWarning` names it; the
  operator is built afresh and nothing is written there).
* A file holds a magic line, a one-line JSON header (the operator's key, dtype, shape and
  the BLAKE2b digest of the data) and the raw array. On load the header must name the
  key asked for and the shape and dtype that key implies, the file size must match,
  all before any memory is allocated for the data; the data must then have the digest.
  Anything else is rebuilt with a :class:`CacheWarning` naming the file.
* A file is written to a temporary name in the same folder and renamed into place, so an
  interrupted write never leaves a half-written file under a final name.
* The folder is bounded: before an operator is stored, the least recently used files are
  removed until the new one fits under :func:`max_bytes` (``LABBRDF_CACHE_MAX_BYTES``,
  default :data:`DEFAULT_MAX_BYTES`); a file's modification time records its last use.
  An operator larger than the cap is not stored. Only files of this module's own naming
  (:data:`NAME_PATTERN`), in this folder, owned by the user, are ever removed.

``labbrdf cache info`` and ``labbrdf cache clear`` show and clear the folder
(:func:`info`, :func:`clear`).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import stat
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "DEFAULT_MAX_BYTES",
    "ENV_MAX_BYTES",
    "NAME_PATTERN",
    "CacheInfo",
    "CacheWarning",
    "cache_dir",
    "clear",
    "info",
    "load",
    "max_bytes",
    "store",
]

#: the environment variable that sets the cache's size cap [bytes]
ENV_MAX_BYTES = "LABBRDF_CACHE_MAX_BYTES"
#: the default cap: 1 GiB, five operators of the 1-degree grid (192 MB each)
DEFAULT_MAX_BYTES = 1 << 30

#: names of the files this module creates (final names, temporary names, and the
#: ``.npy`` files of earlier labbrdf releases); nothing else is ever removed
NAME_PATTERN = re.compile(r"^(exit-[0-9a-f]{32}\.(op|npy)|\.exit-[A-Za-z0-9_]+\.tmp)$")
_KEY = re.compile(r"^[0-9a-f]{32}$")
_MAGIC = b"LABBRDF-TRACER-CACHE 1\n"
_HEADER_MAX = 4096
#: a temporary file older than this is a crashed write's leftover [s]
_STALE_TMP = 3600.0
_SUFFIXES = {"k": 10**3, "m": 10**6, "g": 10**9, "t": 10**12}


class CacheWarning(UserWarning):
    """A cache folder or file was not used (and the operator was rebuilt)."""


def _note(message: str) -> None:
    warnings.warn(f"tracer cache: {message}", CacheWarning, stacklevel=3)


def cache_dir() -> Path:
    """The user's cache folder for operators: ``$XDG_CACHE_HOME/labbrdf/tracer``.

    ``~/.cache`` when ``XDG_CACHE_HOME`` is unset; never the working folder.
    """
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "labbrdf" / "tracer"


def max_bytes() -> int:
    """The cache's size cap [bytes]: ``LABBRDF_CACHE_MAX_BYTES``, else 1 GiB.

    The variable takes a whole number of bytes, optionally with a decimal suffix ``k``,
    ``M``, ``G`` or ``T`` (``500M`` = 5e8 bytes); 0 turns the disk cache off.

    Raises
    ------
    ValueError
        A value that is not such a number (the message names the variable).
    """
    text = os.environ.get(ENV_MAX_BYTES, "").strip()
    if not text:
        return DEFAULT_MAX_BYTES
    m = re.fullmatch(r"(\d+)\s*([kKmMgGtT]?)[bB]?", text)
    if m is None:
        raise ValueError(
            f"{ENV_MAX_BYTES}={text!r}: expected a whole number of bytes >= 0, optionally "
            "with a suffix k, M, G or T (e.g. 500M)"
        )
    return int(m.group(1)) * _SUFFIXES.get(m.group(2).lower(), 1)


def _private(st: os.stat_result) -> str | None:
    """Why a folder or file of this stat is not ours alone (None when it is)."""
    if st.st_uid != os.getuid():
        return f"owned by another user (uid {st.st_uid})"
    if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return f"writable by others (mode {stat.S_IMODE(st.st_mode):o})"
    return None


def _folder(create: bool) -> Path | None:
    """The cache folder when it may be used (made 0o700 when ``create``), else None.

    A folder that is not a folder, belongs to another user or is writable by others is
    refused with a note; one that cannot be made is silently skipped (the operator is
    rebuilt next time).
    """
    folder = cache_dir()
    if create:
        try:
            folder.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
            folder.mkdir(mode=0o700, exist_ok=True)
        except OSError:
            return None
    try:
        st = os.stat(folder)
    except OSError:
        return None
    why = "not a folder" if not stat.S_ISDIR(st.st_mode) else _private(st)
    if why is not None:
        _note(f"{folder} is not used: {why}; operators are built afresh and not stored")
        return None
    return folder


def _header(key: str, array: NDArray) -> bytes:
    head = {
        "key": key,
        "dtype": array.dtype.str,
        "shape": list(array.shape),
        "blake2b": hashlib.blake2b(array.data.cast("B")).hexdigest(),
    }
    return _MAGIC + json.dumps(head, sort_keys=True).encode() + b"\n"


def _read_verified(fh, key: str, shape: tuple[int, ...], dtype: np.dtype) -> NDArray:
    """The array of an open cache file, or ValueError saying what does not match."""
    st = os.fstat(fh.fileno())
    if not stat.S_ISREG(st.st_mode):
        raise ValueError("not a regular file")
    why = _private(st)
    if why is not None:
        raise ValueError(why)
    if fh.read(len(_MAGIC)) != _MAGIC:
        raise ValueError("not a labbrdf cache file (no magic line)")
    line = fh.readline(_HEADER_MAX)
    if not line.endswith(b"\n"):
        raise ValueError("header line missing or too long")
    try:
        head = json.loads(line)
    except ValueError:
        raise ValueError("header is not JSON") from None
    want = {"key": key, "dtype": dtype.str, "shape": list(shape)}
    got = {k: head.get(k) for k in want} if isinstance(head, dict) else {}
    if got != want:
        raise ValueError(f"header {got} does not match {want}")
    nbytes = int(np.prod(shape)) * dtype.itemsize
    if st.st_size != fh.tell() + nbytes:
        raise ValueError(f"{st.st_size} bytes, expected {fh.tell() + nbytes}")
    out = np.empty(shape, dtype=dtype)
    buf = out.data.cast("B")
    if fh.readinto(buf) != nbytes:
        raise ValueError("truncated while reading")
    if hashlib.blake2b(buf).hexdigest() != head.get("blake2b"):
        raise ValueError("contents do not match their digest (corrupt or altered)")
    return out


def _path(key: str) -> Path:
    if not _KEY.match(key):
        raise ValueError(f"cache key must be 32 lower-case hex digits, got {key!r}")
    return cache_dir() / f"exit-{key}.op"


def load(
    key: str, shape: tuple[int, ...], dtype: np.dtype | type = np.complex64
) -> NDArray | None:
    """The stored array of ``key``, verified, or None (a note says why, if not just absent).

    Parameters
    ----------
    key : str
        32 lower-case hex digits: a hash of everything the array depends on.
    shape, dtype
        What ``key`` implies; a file stating anything else is not read.

    Returns
    -------
    ndarray or None
        None when there is no file, the cache is off or the file fails a check; the
        caller then builds the array (and may :func:`store` it).
    """
    path = _path(key)
    if max_bytes() == 0 or not path.exists() or _folder(create=False) is None:
        return None
    dtype = np.dtype(dtype)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | os.O_NONBLOCK)
        with os.fdopen(fd, "rb") as fh:
            out = _read_verified(fh, key, shape, dtype)
    except (OSError, ValueError, MemoryError) as exc:
        _note(f"{path} is not used ({exc}); the operator is rebuilt")
        return None
    try:
        os.utime(path)  # its last use, for the least-recently-used eviction
    except OSError:
        pass
    return out


def store(key: str, array: NDArray) -> Path | None:
    """Write ``array`` under ``key`` (atomically), first evicting to stay under the cap.

    Returns the file written, or None when nothing was (cache off, array larger than the
    cap, folder refused or not writable: the array is simply rebuilt next time).
    """
    path = _path(key)
    array = np.ascontiguousarray(array)
    cap = max_bytes()
    head = _header(key, array)
    size = len(head) + array.nbytes
    if size > cap:
        return None
    folder = _folder(create=True)
    if folder is None:
        return None
    try:
        if path.exists():
            st = os.lstat(path)
            if _private(st) is not None or not stat.S_ISREG(st.st_mode):
                return None  # not ours to replace; the note was given on load
        _evict(folder, cap - size, keep=path.name)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".exit-", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(head)
                fh.write(array.data.cast("B"))
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError:
        return None
    return path


@dataclass(frozen=True)
class CacheEntry:
    """One file of the cache: its name, size [bytes] and last use [s since the epoch]."""

    name: str
    size: int
    last_used: float


@dataclass(frozen=True)
class CacheInfo:
    """What :func:`info` reports.

    Attributes
    ----------
    folder : Path
        The cache folder.
    entries : list of CacheEntry
        Files of labbrdf's own naming there, owned by the user, most recently used first.
    total_bytes, max_bytes : int
        Their total size and the cap [bytes].
    problem : str or None
        Why the folder is not used (another user's, writable by others), if so.
    """

    folder: Path
    entries: list[CacheEntry]
    total_bytes: int
    max_bytes: int
    problem: str | None


def _ours(folder: Path) -> list[tuple[Path, os.stat_result]]:
    """Regular files of our naming in ``folder`` that the user owns (not followed)."""
    out: list[tuple[Path, os.stat_result]] = []
    try:
        names = os.listdir(folder)
    except OSError:
        return out
    for name in names:
        if not NAME_PATTERN.match(name):
            continue
        p = folder / name
        try:
            st = os.lstat(p)
        except OSError:
            continue
        if stat.S_ISREG(st.st_mode) and st.st_uid == os.getuid():
            out.append((p, st))
    return out


def _evict(folder: Path, budget: int, keep: str = "") -> list[Path]:
    """Remove our least recently used files until they total at most ``budget`` bytes.

    Temporary files of writes still under way (younger than an hour) are counted but
    not removed; ``keep`` names a file that is about to be replaced (not counted).
    """
    now = time.time()
    files = [(p, st) for p, st in _ours(folder) if p.name != keep]
    total = sum(st.st_size for _, st in files)
    removed = []
    for p, st in sorted(files, key=lambda f: f[1].st_mtime):
        if total <= budget:
            break
        if p.name.endswith(".tmp") and now - st.st_mtime < _STALE_TMP:
            continue
        try:
            p.unlink()
        except OSError:
            continue
        total -= st.st_size
        removed.append(p)
    return removed


def info() -> CacheInfo:
    """The cache folder, its files, their total size and the cap (nothing is changed)."""
    folder = cache_dir()
    problem = None
    try:
        st = os.stat(folder)
        problem = "not a folder" if not stat.S_ISDIR(st.st_mode) else _private(st)
    except OSError:
        pass
    files = sorted(_ours(folder), key=lambda f: -f[1].st_mtime) if folder.is_dir() else []
    entries = [CacheEntry(p.name, int(st.st_size), float(st.st_mtime)) for p, st in files]
    return CacheInfo(folder, entries, sum(e.size for e in entries), max_bytes(), problem)


def clear() -> tuple[int, int]:
    """Remove every file of labbrdf's naming (and the user's) from the cache folder.

    Other files there are left alone, and so is the folder itself.

    Returns
    -------
    (int, int)
        Files removed and the bytes they took.
    """
    folder = cache_dir()
    if not folder.is_dir():
        return 0, 0
    n = size = 0
    for p, st in _ours(folder):
        try:
            p.unlink()
        except OSError:
            continue
        n += 1
        size += st.st_size
    return n, size
