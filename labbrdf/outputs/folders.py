"""Report folders: checked before any work, built beside the target and renamed into place.

:func:`check_report_dir` refuses a folder that is or holds an input, a file, the working
folder, or a folder that is not an earlier labbrdf report (or holds a file of the user's);
:func:`replace_dir` puts a finished report in place, writing its marker
(:data:`~labbrdf.outputs.files.REPORT_MARKER`). The rules: :mod:`labbrdf.outputs`.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from .files import (
    REPORT_MARKER,
    OutputError,
    _check_writable,
    _foreign,
    _is_within,
    _listing,
    _marker_files,
    _overwrite,
    _resolved,
    _tag,
    _umask,
    _wraps_oserror,
    clean_leftovers,
    refuse_input_as_output,
)


def check_report_dir(
    path: str | os.PathLike[str],
    *,
    inputs: Iterable[str | os.PathLike[str]] = (),
    option: str = "-o",
    overwrite: bool | None = None,
) -> Path:
    """Validate a report folder before any work is done; return it resolved.

    ``overwrite`` (default: the :func:`write_policy` in force, whose inputs are refused
    too) allows an earlier report to be replaced.

    Raises
    ------
    OutputError
        ``path`` is an existing file, equals or contains an input (or lies inside an
        input folder), is the current working folder, or is an existing folder that is
        neither empty nor a previous labbrdf report, or a previous report that holds a
        file we did not write (named in the message), or a previous report and not
        ``overwrite``.
    """
    if not os.fspath(path):
        raise OutputError(f"{option}: empty folder name")
    shown = os.fspath(path)
    if os.path.lexists(path) and not os.path.isdir(path):
        raise OutputError(
            f"{option} {shown}: is an existing file; expected a folder for the report "
            "(a new name, an empty folder or an earlier report)"
        )
    out = _resolved(path)
    refuse_input_as_output(path, inputs=inputs, kind="dir", option=option)
    try:
        cwd = Path.cwd().resolve()
    except OSError:
        cwd = None
    if cwd is not None and _is_within(cwd, out):
        raise OutputError(
            f"{option} {shown}: is the current folder (or contains it); expected a new "
            "folder name for the report, e.g. -o report"
        )
    if out.is_dir():
        try:
            empty = not any(out.iterdir())
        except OSError as exc:
            raise _wraps_oserror(out, "cannot read the folder", exc) from None
        if not empty:
            ours = _marker_files(out)
            if ours is None:
                raise OutputError(
                    f"{option} {shown}: is a folder that is not empty and not a labbrdf "
                    "report; expected a new folder name, an empty folder or an earlier "
                    "report (nothing in it was changed)"
                )
            foreign = _foreign(out, ours)
            if foreign:
                names = ", ".join(foreign[:5]) + (", ..." if len(foreign) > 5 else "")
                raise OutputError(
                    f"{option} {shown}: is an earlier labbrdf report that now also holds "
                    f"files labbrdf did not write ({names}); move them out or choose "
                    "another folder (nothing was changed)"
                )
            if not _overwrite(overwrite):
                raise OutputError(
                    f"{option} {shown}: is an earlier labbrdf report; pass --overwrite to "
                    "replace it (nothing was changed)"
                )
    if out.parent.exists() and not out.parent.is_dir():
        raise OutputError(f"{option} {shown}: {out.parent} is not a folder")
    _check_writable(out, option, shown)
    return out


def _write_marker(d: Path, files: list[str], status: str) -> None:
    try:
        from labbrdf import __version__ as version
    except ImportError:  # pragma: no cover
        version = "?"
    info = {"labbrdf": "report", "version": version, "status": status, "files": files}
    (d / REPORT_MARKER).write_text(json.dumps(info, indent=1) + "\n", encoding="utf-8")


def replace_dir(
    out: str | os.PathLike[str],
    write: Callable[[Path], Any],
    *,
    inputs: Iterable[str | os.PathLike[str]] = (),
    option: str = "-o",
) -> Path:
    """Build a report folder with ``write(tmp)`` and move it into place at ``out``.

    ``out`` is checked with :func:`check_report_dir` before and again after building
    (so an earlier report is replaced only when the :func:`write_policy` allows it). An
    OS error of ``write`` becomes :class:`OutputError` naming the report and the cause.
    The folder is built in a hidden temporary sibling (marked as ours from the start),
    then an existing ``out`` (an earlier report) is renamed aside, the new folder renamed
    in, and the old one deleted. If ``write`` raises, the temporary folder is removed and
    ``out`` is left untouched.
    """
    inputs = list(inputs)
    target = check_report_dir(out, inputs=inputs, option=option)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _wraps_oserror(target.parent, "cannot create the folder", exc) from None
    clean_leftovers(target)
    try:
        tmp = Path(
            tempfile.mkdtemp(prefix=f".{target.name}.labbrdf-new-{_tag()}-", dir=target.parent)
        )
    except OSError as exc:
        raise _wraps_oserror(target, "cannot write the report folder", exc) from None
    try:
        try:
            _write_marker(tmp, [], "building")
            os.chmod(tmp, 0o777 & ~_umask())  # mkdtemp makes 0700; a report is shared
        except OSError as exc:
            raise _wraps_oserror(target, "cannot write the report folder", exc) from None
        try:
            write(tmp)
        except OutputError:
            raise
        except OSError as exc:  # a full disk, ...: name the report and the file
            inner = Path(exc.filename) if isinstance(exc.filename, str) else None
            shown = target
            if inner is not None and _is_within(_resolved(inner), _resolved(tmp)):
                shown = target / _resolved(inner).relative_to(_resolved(tmp))
            raise _wraps_oserror(shown, "cannot write the report", exc) from exc
        _write_marker(tmp, _listing(tmp), "complete")
        check_report_dir(out, inputs=inputs, option=option)  # changed while we worked?
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    old: Path | None = None
    try:
        if target.exists():
            old = Path(
                tempfile.mkdtemp(prefix=f".{target.name}.labbrdf-old-{_tag()}-", dir=target.parent)
            )
            old.rmdir()
            os.replace(target, old)
        try:
            os.replace(tmp, target)
        except BaseException:
            if old is not None:
                os.replace(old, target)
                old = None
            raise
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        raise _wraps_oserror(target, "cannot replace the report folder", exc) from None
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
    return target
