"""File outputs and inputs: the write policy, checks, atomic writes, leftover clean-up.

The rules every output follows are stated in :mod:`labbrdf.outputs`.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import re
import shutil
import socket
import stat
import tempfile
import time
from collections.abc import Iterable, Iterator, Sequence
from contextvars import ContextVar
from dataclasses import dataclass
from pathlib import Path

#: the marker file written into every report folder
REPORT_MARKER = ".labbrdf-report"


_LEGACY_REPORT_KEYS = {"title", "meta", "sections", "tables", "checks", "summary"}


class InputFileError(ValueError):
    """An input that labbrdf refuses to open: not a regular file, or larger than its cap.

    The message names the path and what was expected (CLI exit code 2).
    """


class OutputError(ValueError, OSError):
    """An output path that labbrdf refuses to write (or cannot write); CLI exit code 2.

    Also an OSError, so that code which caught the OS error of a failed write still does.
    """


@dataclass(frozen=True)
class WritePolicy:
    """What a writer may replace: see :func:`write_policy`.

    Attributes
    ----------
    overwrite : bool
        Whether an existing output may be replaced.
    inputs : tuple of Path
        Files the running command reads; never replaced.
    """

    overwrite: bool = True
    inputs: tuple[Path, ...] = ()


_LIBRARY_POLICY = WritePolicy()
_POLICY: ContextVar[WritePolicy | None] = ContextVar("labbrdf_write_policy", default=None)


#: temporary files of this process's open :func:`atomic_output` blocks and their targets:
#: a nested block writing onto one of them (a writer given the temporary name) replaces
#: it, and names the real target in its messages
_OWN_TMPS: dict[str, Path] = {}


def _current() -> WritePolicy:
    return _POLICY.get() or _LIBRARY_POLICY


@contextlib.contextmanager
def write_policy(
    *, overwrite: bool, inputs: Iterable[str | os.PathLike[str]] = ()
) -> Iterator[WritePolicy]:
    """Apply the output rule to every check and write inside the ``with`` block.

    Parameters
    ----------
    overwrite : bool
        False: an existing output file, or a non-empty earlier report folder, is refused
        (checked before any work and again at the final rename, atomically).
    inputs : iterable of path-like
        Every input of the command, refused as an output even when ``overwrite``.

    Yields
    ------
    WritePolicy
        The policy in force.
    """
    policy = WritePolicy(bool(overwrite), tuple(Path(p) for p in inputs))
    token = _POLICY.set(policy)
    try:
        yield policy
    finally:
        _POLICY.reset(token)


def _policy_inputs(inputs: Iterable[str | os.PathLike[str]]) -> list[Path]:
    return [Path(p) for p in inputs] + list(_current().inputs)


def _overwrite(overwrite: bool | None) -> bool:
    return _current().overwrite if overwrite is None else overwrite


# --------------------------------------------------------------------------- helpers


def _umask() -> int:
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)  # not thread-safe, hence /proc first
    os.umask(mask)
    return mask


def _host_tag() -> str:
    return hashlib.sha1(socket.gethostname().encode()).hexdigest()[:6]


def _tag() -> str:
    """``HOST-PID`` of this process, part of every temporary name."""
    return f"{_host_tag()}-{os.getpid()}"


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # EPERM: alive, another user's
        return True
    return True


def _display(path: Path | str) -> str:
    return str(_OWN_TMPS.get(os.path.abspath(path), path))


def _wraps_oserror(path: Path | str, what: str, exc: OSError) -> OutputError:
    reason = exc.strerror or (os.strerror(exc.errno) if exc.errno else "") or str(exc)
    if exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        hint = "; expected a folder you can write to"
    elif exc.errno == errno.ENOSPC:
        hint = "; the disk is full"
    else:
        hint = ""
    return OutputError(f"{what} {_display(path)}: {reason}{hint}")


def _is_within(child: Path, parent: Path) -> bool:
    """``child`` equals ``parent`` or lies inside it (both resolved)."""
    return child == parent or parent in child.parents


def _resolved(p: str | os.PathLike[str]) -> Path:
    return Path(os.path.abspath(os.fspath(p))).resolve()


def _same(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return a.resolve() == b.resolve()


def _check_writable(path: Path, option: str, shown: str | None = None) -> None:
    """Refuse an output whose nearest existing parent folder is not writable.

    Checked before any work, so that a long run does not end in a permission error.
    """
    d = Path(os.path.abspath(path)).parent
    while not d.exists() and d != d.parent:
        d = d.parent
    if d.is_dir() and not os.access(d, os.W_OK | os.X_OK):
        raise OutputError(
            f"{option} {shown or path}: the folder {d} is not writable; expected a folder you can "
            "write to"
        )


def _ends_with_sep(p: str | os.PathLike[str]) -> bool:
    s = os.fspath(p)
    return s.endswith(os.sep) or (os.altsep is not None and s.endswith(os.altsep))


# --------------------------------------------------------------------------- inputs


def _not_regular(mode: int) -> str | None:
    """What a non-regular file is (``"a folder"``, ``"a FIFO (named pipe)"``, ...), or None."""
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def check_input_files(paths: Iterable[str | os.PathLike[str]]) -> list[Path]:
    """Refuse inputs that are not regular files.

    A device such as ``/dev/zero`` would be read forever, and a folder is not a data file;
    a missing file is left to the reader.
    """
    out = []
    for p in paths:
        path = Path(p)
        try:
            st = os.stat(path)
        except OSError:
            out.append(path)
            continue
        kind = _not_regular(st.st_mode)
        if kind == "a folder":
            raise OutputError(f"{path}: is a folder; expected a data file")
        if kind is not None:
            raise OutputError(f"{path}: is {kind}, not a regular file; expected a data file")
        out.append(path)
    return out


def note_inputs(paths: Iterable[str | os.PathLike[str]]) -> None:
    """Add files the running command reads to the inputs of the :func:`write_policy` in force.

    A file named inside another input (a table named by a model file, ...) is an input too:
    from here on no output of the command may replace it, even with ``--overwrite``.
    Outside a :func:`write_policy` block this does nothing.
    """
    policy = _POLICY.get()
    if policy is None:
        return
    known = set(policy.inputs)
    new = tuple(p for p in (Path(x) for x in paths) if p not in known)
    if new:
        _POLICY.set(WritePolicy(policy.overwrite, policy.inputs + new))


def read_input_file(path: str | os.PathLike[str], *, max_bytes: int, what: str = "file") -> bytes:
    """Read a whole user-named input file: a regular file of at most ``max_bytes``.

    The one way labbrdf opens a file that a user or another input names outside the
    instrument readers (model files, fit JSON, n,k tables). The file is checked from its
    ``stat`` before it is opened, so ``/dev/zero`` is never read and a folder never
    opened; it is opened with ``O_NONBLOCK``, so a FIFO put in its place meanwhile cannot
    block the open, and checked again on the open descriptor. Its size is checked before
    reading and while reading (a file that grows). Under a :func:`write_policy` the file
    joins the command's inputs (:func:`note_inputs`).

    Parameters
    ----------
    path : path-like
        The file.
    max_bytes : int
        Largest size accepted [bytes].
    what : str
        What the file is, for the messages (``"model file"``, ...).

    Returns
    -------
    bytes
        The file's contents.

    Raises
    ------
    InputFileError
        Missing or unreadable (with the OS's reason), not a regular file (a folder, a
        device, a FIFO, a socket), or larger than ``max_bytes``; the message names the path.
    """
    p = Path(path)
    note_inputs([p])
    try:
        kind = _not_regular(os.stat(p).st_mode)
        if kind is not None:
            raise InputFileError(f"{p}: is {kind}; expected a regular {what}")
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise InputFileError(f"{p}: cannot read the {what} ({exc.strerror or exc})") from None
    try:
        st = os.fstat(fd)
        kind = _not_regular(st.st_mode)
        if kind is not None:
            raise InputFileError(f"{p}: is {kind}; expected a regular {what}")
        too_big = InputFileError(
            f"{p}: larger than {max_bytes:,} bytes, the most a {what} may have; expected a "
            f"{what} written by hand or by labbrdf"
        )
        if st.st_size > max_bytes:
            raise too_big
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(max_bytes + 1)
        if len(data) > max_bytes:
            raise too_big
        return data
    except OSError as exc:
        raise InputFileError(f"{p}: cannot read the {what} ({exc.strerror or exc})") from None
    finally:
        os.close(fd)


# --------------------------------------------------------------------------- files


def check_file_output(
    path: str | os.PathLike[str],
    *,
    inputs: Iterable[str | os.PathLike[str]] = (),
    suffixes: Sequence[str] = (),
    option: str = "-o",
    overwrite: bool | None = None,
) -> Path:
    """Validate a file output before any work is done; return it as a Path.

    Parameters
    ----------
    path : path-like
        The output file name.
    inputs : iterable of path-like
        The command's input files: the output may not be one of them.
    suffixes : sequence of str
        Accepted suffixes (lower case, with the dot); empty accepts any.
    option : str
        The option name, for the messages.
    overwrite : bool, optional
        Whether an existing file may be replaced; default: the :func:`write_policy` in
        force (whose inputs are refused too).

    Raises
    ------
    OutputError
        The name ends with a separator (a folder), has the wrong suffix, is an existing
        folder or a non-regular file, is one of the inputs, or is an existing file and
        not ``overwrite``.
    """
    if not os.fspath(path):
        raise OutputError(f"{option}: empty file name")
    want = " or ".join(suffixes) if suffixes else "a file"
    if _ends_with_sep(path):
        raise OutputError(
            f"{option} {os.fspath(path)}: ends with '/', which names a folder; expected a "
            f"file name ending in {want}"
        )
    p = Path(path)
    if p.is_symlink() and not p.exists():
        raise OutputError(f"{option} {p}: a dangling symbolic link; expected a file name")
    if p.exists():
        if p.is_dir():
            raise OutputError(
                f"{option} {p}: is an existing folder; expected a file name ending in {want}"
            )
        if not p.is_file():
            raise OutputError(f"{option} {p}: not a regular file; expected a file name")
    if suffixes and p.suffix.lower() not in suffixes:
        raise OutputError(f"{option} {p}: expected a file name ending in {want}")
    _refuse_inputs(p, _policy_inputs(inputs), option)
    if os.path.lexists(p) and not _overwrite(overwrite):
        raise OutputError(
            f"{option} {p}: exists; pass --overwrite to replace it (nothing was changed)"
        )
    parent = p.parent if str(p.parent) else Path(".")
    if parent.exists() and not parent.is_dir():
        raise OutputError(f"{option} {p}: {parent} is not a folder")
    _check_writable(p, option)
    return p


def _refuse_inputs(p: Path, inputs: Iterable[Path], option: str) -> None:
    for fp in inputs:
        if (p.exists() and fp.exists() and _same(p, fp)) or _resolved(p) == _resolved(fp):
            raise OutputError(
                f"{option} {p} is one of the input files ({fp}); refusing to overwrite it, "
                "even with --overwrite"
            )


def refuse_input_as_output(
    path: str | os.PathLike[str],
    *,
    inputs: Iterable[str | os.PathLike[str]] = (),
    kind: str = "file",
    option: str = "-o",
) -> None:
    """Refuse an output that is one of the inputs (a file) or holds or lies in one (a folder).

    Only this check of :func:`check_file_output` and :func:`check_report_dir`, which both
    make it first: the CLI makes it alone before reading the inputs that name other files,
    so that an input given as an output is refused as such.

    Parameters
    ----------
    path : path-like
        The output.
    inputs : iterable of path-like
        The inputs (with those of the :func:`write_policy` in force).
    kind : {"file", "dir"}
        A file output or a report folder.
    option : str
        The option name, for the messages.

    Raises
    ------
    OutputError
        Naming the output and the input.
    """
    if kind != "dir":
        _refuse_inputs(Path(path), _policy_inputs(inputs), option)
        return
    if os.path.lexists(path) and not os.path.isdir(path):
        return  # an existing file where a folder should go: check_report_dir says so
    out, shown = _resolved(path), os.fspath(path)
    for f in _policy_inputs(inputs):
        fp = _resolved(f)
        if _is_within(fp, out):
            raise OutputError(
                f"{option} {shown}: contains the input {f}; expected a folder that holds "
                "none of the input files"
            )
        if _is_within(out, fp):
            raise OutputError(f"{option} {shown}: lies inside the input {f}")


def _put_in_place(tmp: str, target: Path, overwrite: bool) -> None:
    """Rename ``tmp`` onto ``target``; without ``overwrite``, never replace a file.

    A hard link creates ``target`` only if no file of that name exists (atomically); on
    a file system without hard links, the existence check and the rename are separate.
    """
    if overwrite:
        os.replace(tmp, target)
        return
    exists = OutputError(
        f"cannot write {target}: a file of that name appeared while labbrdf worked; pass "
        "--overwrite to replace it (it was left as it was)"
    )
    try:
        os.link(tmp, target)
    except FileExistsError:
        raise exists from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV,
                             errno.EMLINK, errno.ENOSYS, errno.EACCES):  # fmt: skip
            raise
        if os.path.lexists(target):
            raise exists from None
        os.replace(tmp, target)
        return
    os.unlink(tmp)


def clean_leftovers(target: str | os.PathLike[str]) -> list[Path]:
    """Remove what killed earlier runs of labbrdf left beside ``target``.

    That is temporary files and folders with our name pattern whose process (on this host)
    is gone; folders only when they hold our :data:`REPORT_MARKER`.

    A previous report moved aside (``...labbrdf-old-...``) when ``target`` itself is
    missing is moved back to ``target`` rather than removed. Returns what was removed.
    """
    target = Path(target)
    parent = target.parent if str(target.parent) else Path(".")
    pat = re.compile(
        r"^\." + re.escape(target.name) + r"\.labbrdf-(tmp|new|old)-([0-9a-f]{6})-(\d+)-"
        r"[A-Za-z0-9_]+(\.tmp)?$"
    )
    # report folders of labbrdf versions before these names (no host or pid): removed only
    # when they hold exactly a report of ours and are older than an hour
    legacy = re.compile(r"^\." + re.escape(target.name) + r"\.(new|old)-[a-z0-9_]{8}$")
    host = _host_tag()
    removed: list[Path] = []
    try:
        entries = sorted(os.scandir(parent), key=lambda e: e.name)
    except OSError:
        return removed
    for e in entries:
        lm = legacy.match(e.name)
        if lm and _is_legacy_leftover(Path(e.path)):
            p = Path(e.path)
            try:
                if lm.group(1) == "old" and not os.path.lexists(target):
                    os.replace(p, target)
                else:
                    shutil.rmtree(p)
                    removed.append(p)
            except OSError:
                pass
            continue
        m = pat.match(e.name)
        if not m or m.group(2) != host or _pid_alive(int(m.group(3))):
            continue
        kind = m.group(1)
        p = Path(e.path)
        try:
            if kind == "tmp":
                if e.is_file(follow_symlinks=False) and m.group(4):
                    p.unlink()
                    removed.append(p)
                continue
            if e.is_symlink() or not e.is_dir() or not (p / REPORT_MARKER).is_file():
                continue
            if kind == "old" and not os.path.lexists(target):
                os.replace(p, target)  # killed between the two renames: put it back
                continue
            shutil.rmtree(p)
            removed.append(p)
        except OSError:
            continue
    return removed


def _is_legacy_leftover(p: Path) -> bool:
    try:
        if p.is_symlink() or not p.is_dir() or time.time() - p.stat().st_mtime < 3600:
            return False
    except OSError:
        return False
    ours = _marker_files(p)
    return ours is not None and not _foreign(p, ours)


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike[str]) -> Iterator[str]:
    """Yield a temporary file name beside ``path``; rename it onto ``path`` on success.

    On any exception the temporary file is removed and ``path`` is left as it was. The
    file gets ``0o666 & ~umask`` (a file it replaces: that file's mode). An OS error
    while writing or renaming (read-only folder, full disk, ...) becomes
    :class:`OutputError` naming ``path`` and the cause. Under a :func:`write_policy`,
    ``path`` may not be an input, nor an existing file unless it allows overwriting.
    """
    target = Path(path)
    parent = target.parent if str(target.parent) else Path(".")
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _wraps_oserror(parent, "cannot create the folder", exc) from None
    clean_leftovers(target)
    try:
        fd, tmp = tempfile.mkstemp(
            prefix=f".{target.name}.labbrdf-tmp-{_tag()}-", suffix=".tmp", dir=parent
        )
    except OSError as exc:
        raise _wraps_oserror(target, "cannot write", exc) from None
    os.close(fd)
    _OWN_TMPS[os.path.abspath(tmp)] = _OWN_TMPS.get(os.path.abspath(target), target)
    try:
        try:
            yield tmp
        except OutputError:
            raise
        except OSError as exc:  # the writer's own error: say which output and why
            raise _wraps_oserror(target, "cannot write", exc) from exc
        policy = _current()
        _refuse_inputs(target, policy.inputs, "cannot write")
        try:
            mode = stat.S_IMODE(os.stat(target).st_mode) if target.is_file() else None
        except OSError:
            mode = None
        try:
            os.chmod(tmp, mode if mode is not None else 0o666 & ~_umask())
            if target.is_dir():
                raise OutputError(f"cannot write {target}: is an existing folder")
            _put_in_place(tmp, target, policy.overwrite or os.path.abspath(target) in _OWN_TMPS)
        except OutputError:
            raise
        except OSError as exc:
            raise _wraps_oserror(target, "cannot write", exc) from None
    finally:
        _OWN_TMPS.pop(os.path.abspath(tmp), None)
        if os.path.lexists(tmp):
            with contextlib.suppress(OSError):
                os.unlink(tmp)


# --------------------------------------------------------------------------- folders


def _marker_files(d: Path) -> set[str] | None:
    """List the files a report folder's marker names, or None for a non-report folder.

    Paths are relative and '/'-separated.
    """
    marker = d / REPORT_MARKER
    if marker.is_file() and not marker.is_symlink():
        try:
            info = json.loads(marker.read_text(encoding="utf-8"))
            files = info["files"]
            if info.get("labbrdf") == "report" and all(isinstance(f, str) for f in files):
                return set(files)
        except (OSError, ValueError, KeyError, TypeError):
            return None
        return None
    # a report written before the marker existed: exactly our layout
    try:
        res = json.loads((d / "results.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not (isinstance(res, dict) and _LEGACY_REPORT_KEYS <= set(res)):
        return None
    files = {"index.html", "results.json"}
    tables = d / "tables"
    if tables.is_dir() and not tables.is_symlink():
        files |= {f"tables/{c.name}" for c in tables.iterdir() if c.name.endswith(".csv")}
    return files


def _foreign(d: Path, ours: set[str]) -> list[str]:
    """Entries of ``d`` (recursively) that are not among ``ours`` or their folders."""
    dirs = {str(Path(f).parent).replace(os.sep, "/") for f in ours} - {"."}
    for f in list(dirs):
        dirs |= {str(p).replace(os.sep, "/") for p in Path(f).parents if str(p) != "."}
    allowed = set(ours) | {REPORT_MARKER}
    out: list[str] = []
    for root, dnames, fnames in os.walk(d):
        rel_root = Path(root).relative_to(d)
        for name in sorted(dnames):
            rel = (rel_root / name).as_posix()
            if rel not in dirs or (Path(root) / name).is_symlink():
                out.append(rel + "/")
        dnames[:] = [n for n in dnames if (rel_root / n).as_posix() in dirs]
        for name in sorted(fnames):
            rel = (rel_root / name).as_posix()
            full = Path(root) / name
            if rel not in allowed or full.is_symlink() or not full.is_file():
                out.append(rel)
    return out


def _listing(d: Path) -> list[str]:
    return sorted(
        (Path(root) / n).relative_to(d).as_posix()
        for root, _, names in os.walk(d)
        for n in names
        if not (root == str(d) and n == REPORT_MARKER)
    )


# --------------------------------------------------------------------------- CSV cells
