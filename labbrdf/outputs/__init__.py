"""Output-path safety: every file or folder labbrdf writes goes through this package.

Nothing a user owns is lost by our outputs. The command line follows one rule for every
output it writes, sidecar files included: **an existing file (or earlier report folder) is
never replaced unless ``--overwrite`` is given; an input is never replaced, even with
``--overwrite``; every write is atomic.** The CLI states the rule once per command with
:func:`write_policy` (whether to overwrite, and all the command's inputs); every check and
every write of this package consults it, so a writer added later follows it without being
told.
Outside a :func:`write_policy` block (the library used from Python) an existing output is
replaced, as :func:`open` with ``"w"`` would, and only the inputs passed explicitly are
refused.

* :func:`check_file_output` refuses a file output that is one of the inputs, an existing
  file (unless overwriting), an existing folder or anything but a regular file, a name
  ending in a path separator (a folder), or a name without the expected suffix.
* :func:`check_report_dir` refuses a report folder that is (or contains, or lies inside)
  an input, an existing file, the current working folder, or an existing folder that is
  neither empty nor a previous labbrdf report; a previous report in which the user put
  a file of their own is refused too, naming that file, and a previous report is
  replaced only when overwriting. A report folder is recognised by
  its marker file :data:`REPORT_MARKER` (a small JSON that lists the files we wrote), or,
  for reports written before the marker existed, by its exact layout (``index.html``,
  ``results.json`` with the report keys, ``tables/*.csv`` and nothing else).
* :func:`atomic_output` (files) and :func:`replace_dir` (report folders) build the output
  under a temporary hidden name beside it and rename it into place; outputs get the
  permissions of the umask (``0o666 & ~umask``; a replaced file keeps its mode). When
  not overwriting, the file is put in place with a hard link, which fails rather than
  replace a file that appeared while we worked. Any OS error while writing (a full
  disk, a read-only folder, ...) becomes an :class:`OutputError` that names the output
  path and the cause.
* Temporary names carry our pattern, a host tag and the process id
  (``.NAME.labbrdf-tmp-HOST-PID-XXXX.tmp``, ``.NAME.labbrdf-new-HOST-PID-XXXX``,
  ``.NAME.labbrdf-old-HOST-PID-XXXX``). A run killed with SIGKILL leaves them behind; the
  next write of the same output removes those whose process is gone (on this host), and
  for folders only when they hold our marker. Nothing else is ever removed.

Every refusal raises :class:`OutputError` (a ValueError: the CLI prints it and exits 2)
naming the path and what was expected.

The package's modules: :mod:`~labbrdf.outputs.files` (the write policy, file inputs and
outputs, temporary names), :mod:`~labbrdf.outputs.folders` (report folders) and
:mod:`~labbrdf.outputs.csvcells`. It imports nothing from labbrdf at import time, so
every layer may use it.
"""

from __future__ import annotations

from .csvcells import CSV_FORMULA_PREFIXES, csv_safe_cell, csv_safe_frame
from .files import (
    REPORT_MARKER,
    InputFileError,
    OutputError,
    WritePolicy,
    atomic_output,
    check_file_output,
    check_input_files,
    clean_leftovers,
    note_inputs,
    read_input_file,
    refuse_input_as_output,
    write_policy,
)
from .folders import check_report_dir, replace_dir

__all__ = [
    "CSV_FORMULA_PREFIXES",
    "REPORT_MARKER",
    "InputFileError",
    "OutputError",
    "WritePolicy",
    "atomic_output",
    "check_file_output",
    "check_input_files",
    "check_report_dir",
    "clean_leftovers",
    "csv_safe_cell",
    "csv_safe_frame",
    "note_inputs",
    "read_input_file",
    "refuse_input_as_output",
    "replace_dir",
    "write_policy",
]
