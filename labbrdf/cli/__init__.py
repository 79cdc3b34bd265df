"""The ``labbrdf`` command: a thin argparse layer over the library.

Subcommands: ``ingest``, ``formats``, ``fit``, ``nk``, ``film``, ``film-map``, ``surface``,
``psd``, ``export``, ``hemispherical``, ``trace``, ``validate``, ``report``, ``cache``; each is
one module of this package, its parser (``add_parser``) beside its command (``cmd_<name>``). Every
subcommand returns an exit code: 0 success, 1 a check of a report (``validate``,
``report``) failed, 2 a usage, input or output error (unreadable file, unknown name, an
output path that is refused or cannot be written, ...), 3 ``fit``: some groups could not be
fitted or did not converge (listed with ``success`` false and the reason), 130 interrupted,
141 the reader of our output went away; the error is on stderr (:mod:`._run`). Every output
path goes through :mod:`labbrdf.outputs`.

One name, one meaning, in every subcommand: ``--wavelength NM`` is one wavelength [nm],
``--wavelength-range MIN:MAX`` a range of rows; ``--theta-i DEG`` is an angle of incidence
[deg] (one in ``trace``, a list in ``export`` and ``hemispherical``), ``--theta-i-range
MIN:MAX`` a range of rows; options are taken by their full names only
(``allow_abbrev=False``), and older spellings are refused naming the new one. The library
does the work: the commands parse text into values and call it once (e.g.
:func:`labbrdf.sample.trace_config_from_inputs`); a
:class:`labbrdf.errors.SetupError` is said with the options' names
(:data:`._options.OPTION_NAMES`).

Arguments that name files are declared as :class:`._paths.InputPath` or
:class:`._paths.OutputPath`; before a command runs, :func:`._paths._checked_outputs` checks
all its outputs against all its inputs and runs it under one rule
(:func:`labbrdf.outputs.write_policy`): an existing output is replaced only with
``--overwrite``, an input never, and every write is atomic.

Shared plumbing: :mod:`._options` (option values, row selection, the executor options),
:mod:`._paths` (input and output paths), :mod:`._parser` (:func:`build_parser`),
:mod:`._run` (:func:`main`: warnings and exit codes).
"""

from __future__ import annotations

from ._parser import build_parser
from ._run import main

__all__ = ["build_parser", "main"]
