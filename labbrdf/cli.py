"""The ``labbrdf`` command: a thin argparse layer over the library.

Subcommands: ``ingest``, ``formats``, ``fit``, ``nk``, ``surface``, ``export``,
``hemispherical``, ``trace``, ``validate``, ``report``. Every subcommand returns an exit
code: 0 success, 1 a check of a report (``validate``, ``report``) failed, 2 a usage, input
or output error (unreadable file, unknown name, an output path that is refused or cannot be
written, ...), 3 ``fit``: some groups could not be fitted or did not converge (listed with
``success`` false and the reason), 141 the reader of our output went away; the error is on
stderr. Every output path goes through :mod:`labbrdf.outputs`.

One name, one meaning, in every subcommand: ``--wavelength NM`` is one wavelength [nm],
``--wavelength-range MIN:MAX`` a range of rows; options are taken by their full names only
(``allow_abbrev=False``), and older spellings are refused naming the new one. The library
does the work: the commands parse text into values and call it once (e.g.
:func:`labbrdf.tracer_setup.trace_config_from_inputs`); a
:class:`labbrdf.errors.SetupError` is said with the options' names (:data:`OPTION_NAMES`).

Arguments that name files are declared as :class:`InputPath` or :class:`OutputPath`; before
a command runs, :func:`_checked_outputs` checks all its outputs against all its inputs and
runs it under one rule (:func:`labbrdf.outputs.write_policy`): an existing output is
replaced only with ``--overwrite``, an input never, and every write is atomic.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import json
import math
import os
import sys
import time
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, Literal

from .jsonsafe import jsonable

__all__ = ["main"]


class UsageError(Exception):
    """A command-line input error: printed, exit code 2."""


# ------------------------------------------------------------------------- input/output paths


class InputPath(argparse.Action):
    """An option or positional argument that names files the command reads.

    Every output of the command refuses all of them (see :func:`_checked_outputs`), so
    an option declared with ``action=InputPath`` cannot be forgotten by a writer. A file
    that names other files (``inside="model"``: a film model file, ``inside="fit"``: a film
    fit JSON) brings those in as inputs too (:func:`labbrdf.films.named_inputs`).
    """

    def __init__(
        self,
        option_strings: Sequence[str],
        dest: str,
        *,
        inside: Literal["model", "fit"] | None = None,
        **kw: Any,
    ) -> None:
        super().__init__(option_strings, dest, **kw)
        self.inside = inside

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        setattr(namespace, self.dest, values)


class OutputPath(argparse.Action):
    """An option that names an output the command writes; checked before it runs.

    ``kind`` is ``"file"`` (with the accepted ``suffixes``) or ``"dir"`` (a report folder).
    """

    def __init__(
        self,
        option_strings: Sequence[str],
        dest: str,
        *,
        suffixes: Sequence[str] = (),
        kind: Literal["file", "dir"] = "file",
        **kw: Any,
    ) -> None:
        super().__init__(option_strings, dest, **kw)
        self.suffixes = tuple(suffixes)
        self.kind = kind

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        setattr(namespace, self.dest, values)


def path_actions(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """The :class:`InputPath` and :class:`OutputPath` arguments of a (sub)parser."""
    return [a for a in parser._actions if isinstance(a, InputPath | OutputPath)]


def _option_name(a: argparse.Action) -> str:
    return a.option_strings[0] if a.option_strings else str(a.metavar or a.dest)


def _named_paths(args: argparse.Namespace, kind: type) -> list[tuple[argparse.Action, str]]:
    out: list[tuple[argparse.Action, str]] = []
    actions: Sequence[argparse.Action] = getattr(args, "path_actions", ())
    for a in actions:
        v = getattr(args, a.dest, None)
        if isinstance(a, kind) and v is not None:
            out.extend((a, str(p)) for p in (v if isinstance(v, list) else [v]))
    return out


def _inputs(args: argparse.Namespace) -> list[str]:
    """Every file the command's options name as an input."""
    return [p for _, p in _named_paths(args, InputPath)]


def _named_inside(args: argparse.Namespace) -> list[str]:
    """The files named inside the inputs: a model's or a fit's tables, ``--layer`` files."""
    inner = [f for spec in getattr(args, "layer", None) or () for f in _layer_files(spec)]
    for a, p in _named_paths(args, InputPath):
        kind = getattr(a, "inside", None)
        if kind is not None:
            from .films import named_inputs

            try:
                inner += [str(f) for f in named_inputs(p, kind)]
            except ValueError as exc:  # the loader's message, naming the file
                raise UsageError(f"{_option_name(a)} {exc}") from None
    return inner


def _check_outputs(args: argparse.Namespace) -> None:
    """Check every output option against the :func:`labbrdf.outputs.write_policy` in force."""
    from .outputs import check_file_output, check_report_dir

    seen: dict[Path, str] = {}
    for a, path in _named_paths(args, OutputPath):
        if not isinstance(a, OutputPath):  # pragma: no cover - _named_paths filtered
            continue
        name = _option_name(a)
        if a.kind == "dir":
            out = check_report_dir(path, option=name)
        else:
            out = check_file_output(path, suffixes=a.suffixes, option=name)
        key = Path(os.path.abspath(out))
        if key in seen:
            raise UsageError(f"{name} {path}: also given to {seen[key]}; expected two names")
        seen[key] = name


@contextlib.contextmanager
def _checked_outputs(args: argparse.Namespace) -> Iterator[None]:
    """Check every input and output of the command, then run it under the output rule.

    The rule (:func:`labbrdf.outputs.write_policy`): an existing output is replaced only
    with ``--overwrite``, an input never; every file written inside, sidecars included,
    follows it. The files named inside the inputs (:func:`_named_inside`) are inputs too,
    checked against every output before the command runs; their readers check that they
    are regular files, naming the file that names them.
    """
    from .outputs import check_input_files, refuse_input_as_output, write_policy

    inputs = _inputs(args)
    check_input_files(inputs)
    for a, path in _named_paths(args, OutputPath):  # an input given as an output: said first
        kind = a.kind if isinstance(a, OutputPath) else "file"
        refuse_input_as_output(path, inputs=inputs, kind=kind, option=_option_name(a))
    inputs += _named_inside(args)
    with write_policy(overwrite=bool(getattr(args, "overwrite", False)), inputs=inputs):
        _check_outputs(args)
        yield


def _add_overwrite(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="replace existing outputs (never an input); without it an existing file is "
        "refused before any work",
    )


def _emit_json(obj: Any) -> None:
    print(json.dumps(jsonable(obj), indent=2, allow_nan=False))


def _parse_assignments(items: Sequence[str] | None, what: str) -> dict[str, float]:
    """``NAME=VALUE`` options (``--fix``, ``--sigma``): names and finite numbers."""
    out: dict[str, float] = {}
    for item in items or ():
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise UsageError(f"{what} {item!r}: expected NAME=VALUE")
        try:
            x = float(value)
        except ValueError:
            raise UsageError(f"{what} {item!r}: {value!r} is not a number") from None
        if not (value.strip().isascii() and math.isfinite(x)):
            raise UsageError(f"{what} {item!r}: expected a finite ASCII number")
        out[name.strip()] = x
    return out


def _value(text: str) -> float | bool | str:
    """A model option's value: a number, true/false, or a word."""
    t = text.strip()
    if t.lower() in ("true", "yes", "on"):
        return True
    if t.lower() in ("false", "no", "off"):
        return False
    try:
        x = float(t)
    except ValueError:
        return t
    if not (t.isascii() and math.isfinite(x)):
        raise UsageError(f"{t!r}: expected a finite ASCII number")
    return x


def _split_params(
    model: str, items: Sequence[str] | None
) -> tuple[dict[str, Any], dict[str, float]]:
    """``--param NAME=VALUE``: model options (e.g. microfacet's n, k) and parameter values."""
    from .models import option_names

    opts_names = option_names(model)
    options: dict[str, Any] = {}
    values: dict[str, float] = {}
    for item in items or ():
        name, sep, raw = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise UsageError(f"--param {item!r}: expected NAME=VALUE")
        try:
            v = _value(raw)
        except UsageError as exc:
            raise UsageError(f"--param {name}: {exc}") from None
        if name in opts_names:
            options[name] = v
        elif isinstance(v, float):
            values[name] = v
        else:
            raise UsageError(f"--param {item!r}: {raw!r} is not a number")
    return options, values


def _range(text: str) -> str:
    """The argparse type of a ``MIN:MAX`` option: one word with a colon (checked later)."""
    if ":" not in text:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected MIN:MAX in one word, e.g. 400:700 (either end may be "
            "left open: 400: or :700)"
        )
    return text


def _fit_seed(text: str) -> int:
    """The argparse type of a fit's ``--seed``: an integer in [0, MAX_SEED]."""
    from .fitting.core import MAX_SEED

    try:
        x = int(text)
    except ValueError:
        x = -1
    if not 0 <= x <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"{text!r}: expected an integer in [0, {MAX_SEED}]")
    return x


def _open_fraction(text: str) -> float:
    """The argparse type of a fraction in (0, 1) (``--relative-floor``)."""
    try:
        x = float(text)
    except ValueError:
        x = math.nan
    if not (text.strip().isascii() and 0 < x < 1):
        raise argparse.ArgumentTypeError(f"{text!r}: expected a number in (0, 1)")
    return x


def _wavelength_value(text: str) -> float:
    """The argparse type of ``--wavelength NM``: one wavelength [nm]."""
    try:
        x = float(text)
    except ValueError:
        x = math.nan
    if not (text.strip().isascii() and math.isfinite(x) and x > 0):
        hint = "; a range of rows is --wavelength-range MIN:MAX" if ":" in text else ""
        raise argparse.ArgumentTypeError(f"{text!r}: expected one wavelength [nm] > 0{hint}")
    return x


class _Renamed(argparse.Action):
    """An old option spelling: refused, naming the new one."""

    def __init__(self, option_strings: Sequence[str], dest: str, *, new: str, **kw: Any) -> None:
        super().__init__(
            option_strings,
            dest,
            nargs="?",
            default=argparse.SUPPRESS,
            help=argparse.SUPPRESS,
            **kw,
        )
        self.new = new

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        parser.error(f"{option_string} is not an option of this command: {self.new}")


#: what ``--wavelength`` says in a command that selects rows (it has no single wavelength)
_WAVELENGTH_IS_ONE = (
    "--wavelength NM is one wavelength (export, hemispherical, trace, fit --nk-from); "
    "select a range of rows with --wavelength-range MIN:MAX"
)


def _add_selection(p: argparse.ArgumentParser, *, wavelength_taken: bool = False) -> None:
    """The row-selection options; ``--wavelength`` is refused unless the command has one."""
    g = p.add_argument_group("selection")
    g.add_argument(
        "--wavelength-range",
        type=_range,
        default=None,
        metavar="MIN:MAX",
        help="[nm], e.g. 400:700",
    )
    if not wavelength_taken:
        g.add_argument("--wavelength", action=_Renamed, new=_WAVELENGTH_IS_ONE)
    g.add_argument("--theta-i", default=None, metavar="MIN:MAX", help="[deg], e.g. 40:60")
    g.add_argument("--theta-r", default=None, metavar="MIN:MAX", help="[deg], e.g. :70")
    g.add_argument("--quantity", default=None, help="comma-separated quantities")
    g.add_argument("--sample", default=None, help="comma-separated sample names")


def _selected(args: argparse.Namespace, m: Any) -> Any:
    """The Measurement ``m`` restricted to the selection options (meta kept)."""
    from .dataset import Measurement
    from .selection import select

    chosen = _selection(args)
    if not chosen:
        return m
    return Measurement(select(m, **chosen), m.meta)


#: the selection options: argparse destination -> :func:`labbrdf.selection.select` keyword
SELECTION_KEYS = {
    "wavelength_range": "wavelength",
    "theta_i": "theta_i",
    "theta_r": "theta_r",
    "quantity": "quantity",
    "sample": "sample",
}


def _selection(args: argparse.Namespace) -> dict[str, Any]:
    """The given selection options as :func:`labbrdf.selection.select` keywords."""
    return {
        kw: getattr(args, dest)
        for dest, kw in SELECTION_KEYS.items()
        if getattr(args, dest, None) is not None
    }


def _add_scheduler(p: argparse.ArgumentParser) -> None:
    """The executor options of a command that runs tasks (:func:`_executor` reads them)."""
    from .parallel import DEFAULT_SCHEDULER

    p.add_argument(
        "--scheduler",
        default=DEFAULT_SCHEDULER,
        help=f"serial, processes, local (dask LocalCluster on 127.0.0.1; default "
        f"{DEFAULT_SCHEDULER}), "
        "tls://host:port (a dask scheduler with TLS) or tcp://host:port (unauthenticated: "
        "a trusted network only)",
    )
    p.add_argument("--workers", type=int, default=None, help="worker processes (default: cores)")
    p.add_argument(
        "--tls-ca", action=InputPath, default=None, metavar="PEM", help="CA certificate (tls://)"
    )
    p.add_argument(
        "--tls-cert",
        action=InputPath,
        default=None,
        metavar="PEM",
        help="this client's certificate",
    )
    p.add_argument(
        "--tls-key",
        action=InputPath,
        default=None,
        metavar="PEM",
        help="this client's private key",
    )
    p.add_argument(
        "--dashboard", action="store_true", help="start the local cluster's dashboard (127.0.0.1)"
    )
    p.add_argument(
        "--worker-timeout",
        type=float,
        default=None,
        metavar="SECONDS",
        help="how long to wait for a worker on a tcp:// or tls:// scheduler that has none "
        "(default 60)",
    )


def _executor(args: argparse.Namespace, progress: bool = True) -> Any:
    """The :class:`labbrdf.parallel.Executor` of the command's options, built once.

    A bad ``--scheduler``, ``--workers`` or security option is refused here, before any
    work is done (exit 2).
    """
    from .parallel import Executor, check_scheduler, configure

    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers must be >= 1, got {args.workers}")
    try:  # first: certificates given here decide what --scheduler local needs
        configure(
            dashboard=True if args.dashboard else None,
            tls_ca=args.tls_ca,
            tls_cert=args.tls_cert,
            tls_key=args.tls_key,
            worker_timeout=args.worker_timeout,
        )
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    try:
        check_scheduler(args.scheduler)
    except ValueError as exc:
        raise UsageError(f"--scheduler: {exc}") from None
    return Executor(
        args.scheduler,
        workers=args.workers,
        progress=progress,
        dashboard=True if args.dashboard else None,
        tls_ca=args.tls_ca,
        tls_cert=args.tls_cert,
        tls_key=args.tls_key,
        worker_timeout=args.worker_timeout,
    )


def _executor_errors(cmd: Any) -> Any:
    """Make a run abandoned by the executor exit with code 2 and the reason.

    Dead workers, an unreachable scheduler or a local cluster that did not start give the
    reason on stderr, not a traceback; nothing partial has been written. Ctrl-C says that
    the run was interrupted (exit 130, from :func:`main`).
    """

    @functools.wraps(cmd)
    def wrapper(args: argparse.Namespace) -> int:
        from .parallel import ParallelError

        try:
            return cmd(args)
        except ParallelError as exc:
            raise UsageError(str(exc)) from None

    return wrapper


# ------------------------------------------------------------------------------- ingest


def cmd_ingest(args: argparse.Namespace) -> int:
    from . import adapters
    from .dataset import concat, write
    from .outputs import check_file_output

    out = None
    if args.output:  # checked with the inputs by _checked_outputs
        out = Path(args.output)
        if out.suffix.lower() == ".csv":  # its metadata goes to a sidecar beside it
            from .dataset import sidecar_path

            check_file_output(
                sidecar_path(out), suffixes=(".json",), option=f"-o {out}: its metadata file"
            )
    from .selection import SelectionError

    rows: list[dict[str, Any]] = []
    measurements = []
    failures: list[dict[str, str]] = []
    unselected: list[str] = []
    try:
        inputs = adapters.read_inputs(
            args.files,
            args.format,
            columns=_columns_spec(args),
            on_error="collect" if args.keep_going else "raise",
        )
    except (ValueError, NotImplementedError, OSError, ImportError) as exc:
        print(f"labbrdf ingest: {exc}", file=sys.stderr)
        return 2
    maps = [(i.path, i.height_map) for i in inputs.files if i.height_map is not None]
    for i in inputs.files:
        path, m = i.path, i.measurement
        if i.error:
            failures.append({"file": path, "error": i.error})
            continue
        if m is None:  # a height map: reported below, not part of the dataset
            continue
        try:
            m = _selected(args, m)
        except SelectionError as exc:
            unselected.append(f"{path}: {exc}")
            continue
        s = m.summary()
        _print_notes("ingest", path, i.measurement.meta if i.measurement is not None else m.meta)
        measurements.append(m)
        rows.append(
            {
                "file": path,
                "format": m.meta.get("format", args.format),
                "sample": s["sample"][0] if len(s["sample"]) == 1 else s["sample"],
                "rows": s["rows"],
                "quantities": s["quantities"],
                "channels": _channels(m.data),
                "wavelength_nm": s["wavelength_nm"],
                # False: the file states none and wavelength_nm is a label (.bsdf)
                "wavelength_stated": m.meta.get("wavelength_stated") is not False,
                "theta_i_deg": s["theta_i_deg"],
            }
        )
    if unselected and not measurements and not failures:
        raise UsageError("; ".join(unselected))
    if out is not None and measurements:
        write(concat(measurements), out)
    if args.json:
        payload: Any = rows + [{"file": p, "height_map": hm.summary()} for p, hm in maps]
        if failures:
            payload = payload + [{"file": f["file"], "error": f["error"]} for f in failures]
        _emit_json(payload)
    else:
        if rows or not maps:
            _print_ingest_table(rows)
        for p, hm in maps:
            print(f"{p}: height map, not optical data: {hm.summary_line()}")
        if out is not None and measurements:
            print(f"wrote {out} ({sum(r['rows'] for r in rows)} rows)")
    if out is not None and maps and not measurements:
        print(f"labbrdf ingest: no optical data, {out} not written", file=sys.stderr)
    for f in failures:
        print(f"labbrdf ingest: FAILED {f['error']}", file=sys.stderr)
    for u in unselected:
        print(f"labbrdf ingest: nothing selected in {u}", file=sys.stderr)
    return 2 if failures else 0


def _print_notes(command: str, path: str, meta: dict[str, Any]) -> None:
    """Print what a reader noted in ``meta["notes"]`` (rows dropped, lines skipped...).

    One line per note on stderr, prefixed with the file.
    """
    notes = list(meta.get("notes") or ())
    for part in meta.get("parts") or ():
        notes += (part.get("meta") or {}).get("notes") or ()
    for note in notes:
        print(f"labbrdf {command}: note: {path}: {note}", file=sys.stderr)


def _columns_spec(args: argparse.Namespace) -> str | None:
    """``--columns`` with ``--skip-lines`` joined as its ``skip_lines=`` setting."""
    if args.skip_lines is None:
        return args.columns
    if args.columns is None:
        raise UsageError("--skip-lines skips the leading lines of a file read with --columns")
    return f"{args.columns},skip_lines={args.skip_lines}"


def _channels(d: Any) -> dict[str, list[str]]:
    """The channels of each quantity that has any, in file order.

    ``p``/``s`` reflectance, generalised ellipsometry ``pp``/``ps``/``sp``, tristimulus
    ``X``/``Y``/``Z``; quantities without a channel are left out.
    """
    if "channel" not in d.columns:
        return {}
    out: dict[str, list[str]] = {}
    for q, c in d[["quantity", "channel"]].drop_duplicates().itertuples(index=False):
        if c:
            out.setdefault(str(q), []).append(str(c))
    return out


def _channels_cell(channels: dict[str, list[str]]) -> str:
    """``"p"``; ``"pp,ps,sp"`` when every quantity has the same; else per quantity."""
    if not channels:
        return "-"
    lists = {tuple(v) for v in channels.values()}
    if len(lists) == 1:
        return ",".join(next(iter(lists)))
    return " ".join(f"{q}:{','.join(v)}" for q, v in channels.items())


def _short(text: str, width: int = 36) -> str:
    return text if len(text) <= width else text[: width - 3] + "..."


def _quantities_cell(qs: list[str]) -> str:
    mm = [q for q in qs if q.startswith("mueller_")]
    rest = [q for q in qs if not q.startswith("mueller_")]
    if len(mm) > 2:
        rest.append(f"mueller({len(mm)})")
    else:
        rest.extend(mm)
    return ",".join(rest)


def _print_ingest_table(rows: list[dict[str, Any]]) -> None:
    head = [
        "file",
        "format",
        "sample",
        "quantities",
        "channel",
        "wavelength_nm",
        "theta_i_deg",
        "rows",
    ]
    table = []
    for r in rows:
        wl = r["wavelength_nm"]
        th = r["theta_i_deg"]
        table.append(
            [
                Path(r["file"]).name,
                str(r["format"]),
                _short(
                    str(r["sample"])
                    if isinstance(r["sample"], str)
                    else f"{len(r['sample'])} samples: {r['sample'][0]}, ..."
                ),
                _quantities_cell(r["quantities"]),
                _channels_cell(r["channels"]),
                f"{wl[0]:.6g}-{wl[1]:.6g}" if r["wavelength_stated"] else "not stated",
                ",".join(f"{t:g}" for t in th[:8]) + (",..." if len(th) > 8 else "") or "-",
                str(r["rows"]),
            ]
        )
    widths = [
        max(len(h), *(len(t[i]) for t in table)) if table else len(h) for i, h in enumerate(head)
    ]
    print("  ".join(h.ljust(w) for h, w in zip(head, widths, strict=True)))
    for t in table:
        print("  ".join(c.ljust(w) for c, w in zip(t, widths, strict=True)))


def cmd_formats(args: argparse.Namespace) -> int:
    from .adapters import formats

    fmts = formats()
    if args.json:
        _emit_json(fmts)
    else:
        for f in fmts:
            print(f"{f['name']:<28} {' '.join(f['extensions']):<18} {f['description']}")
    return 0


# ------------------------------------------------------------------------------- cache


def cmd_cache(args: argparse.Namespace) -> int:
    """Show (``info``) or empty (``clear``) the tracer's operator cache."""
    from .tracer import cache

    if args.action == "clear":
        n, size = cache.clear()
        print(f"removed {n} file(s), {size / 1e6:.1f} MB, from {cache.cache_dir()}")
        return 0
    info = cache.info()
    if args.json:
        _emit_json(
            {
                "folder": str(info.folder),
                "entries": [vars(e) for e in info.entries],
                "total_bytes": info.total_bytes,
                "max_bytes": info.max_bytes,
                "problem": info.problem,
            }
        )
        return 0
    print(f"folder   {info.folder}" + (f" (not used: {info.problem})" if info.problem else ""))
    print(f"entries  {len(info.entries)}")
    print(f"total    {info.total_bytes / 1e6:.1f} MB")
    print(f"cap      {info.max_bytes / 1e6:.1f} MB (set with {cache.ENV_MAX_BYTES})")
    return 0


# ------------------------------------------------------------------------------- fit


#: the keywords of the library's builders, as the command line spells them
OPTION_NAMES = {
    "nk_from": "--nk-from",
    "wavelength_nm": "--wavelength",
    "substrate_index": "--substrate",
    "alpha": "--alpha",
    "surface": "--surface",
    "coating_index": "--coating",
    "coating_from": "--coating-from",
    "thickness_nm": "--thickness",
    "coating_alpha": "--coating-alpha",
    "coating_surface": "--coating-surface",
    "distribution": "--distribution",
    "base_albedo": "--base-albedo",
}


@contextlib.contextmanager
def _option_errors() -> Iterator[None]:
    """Library errors about arguments, said with the options' names (exit 2)."""
    from .errors import SetupError
    from .nk import NkError

    try:
        yield
    except SetupError as exc:
        raise UsageError(exc.spelled(OPTION_NAMES)) from None
    except NkError as exc:
        raise UsageError(f"--nk-from {exc}") from None


def _fit_settings(args: argparse.Namespace) -> tuple[Any, dict[str, Any], dict[str, Any]]:
    """The model (None with ``--nk-from``), its options and the fit keywords of the options.

    Everything that can be refused without the data is refused here, before any work:
    counts, names, and every ``--fix`` and ``--param`` value outside the bounds the model
    declares (:meth:`labbrdf.models.Model.check_value`).
    """
    from . import models
    from .fitting.replicates import MAX_REPLICATES

    if args.replicates is not None and not 1 <= args.replicates <= MAX_REPLICATES:
        raise UsageError(
            f"--replicates must be an integer in [1, {MAX_REPLICATES}]; got {args.replicates}"
        )
    if args.wavelength is not None and not args.nk_from:
        raise UsageError(
            "--wavelength NM is the wavelength of --nk-from's n, k; select a range of "
            "rows with --wavelength-range MIN:MAX"
        )
    fix = _parse_assignments(args.fix, "--fix")
    options, start = _split_params(args.model, args.param)
    model = None
    if args.nk_from:
        bounds = _bounds_model(args.model, options, start)
    else:
        try:
            model = bounds = _starts_taken(args.model, options, start)
        except models.ModelError as exc:
            raise UsageError(f"--model {args.model}: {exc} (give options with --param)") from None
        if (args.replicates or 1) > 1 and not model.stochastic:
            raise UsageError(
                f"--replicates {args.replicates}: model {args.model!r} is deterministic (no "
                "Monte Carlo seed), every replicate would be the same fit; leave --replicates out"
            )
    _check_values(bounds, fix, start, args.free)
    params: dict[str, Any] = {k: {"value": v} for k, v in start.items()}
    for name in args.free or ():
        params.setdefault(name, {})["vary"] = True
    kw: dict[str, Any] = {"fix": fix or None, "params": params or None}
    if args.replicates is not None:
        kw["replicates"] = args.replicates
    return model, options, kw


def _starts_taken(name: str, options: dict[str, Any], start: dict[str, float]) -> Any:
    """The model ``name`` built with ``options``, less the names it has as parameters.

    A name can be both an option and, with other options, a parameter (layered's
    ``thickness_nm``: the incoherent coating's thickness, and a fitted parameter with
    ``coherent=true``, when the option is unused): there it is the parameter's start value,
    moved from ``options`` into ``start`` (checked against its bounds like any other),
    never an option that is silently ignored. Raises :class:`labbrdf.models.ModelError`
    as the model does.
    """
    from . import models

    taken = [k for k in options if k in _parameter_names(name, options)]
    for k in taken:
        v = options.pop(k)
        if not isinstance(v, float):
            raise UsageError(f"--param {k}={v}: a parameter of this model: expected a number")
        start[k] = v
    return models.get(name, **options)


def _parameter_names(name: str, options: dict[str, Any]) -> set[str]:
    """The parameters of the model ``name`` with ``options`` (empty if none can be built).

    The words and flags among the options (``coherent``, ``base``, ``diffuse``) choose the
    parameters, not the numbers; so where the numbers are refused (a start value given as
    an option), the model is built without them, with a stand-in index if it needs one.
    """
    from . import models

    words = {k: v for k, v in options.items() if not isinstance(v, float)}
    for opts in (options, words, {**words, "n": 1.5, "k": 0.0}):
        try:
            return set(models.get(name, **opts).params)
        except (models.ModelError, TypeError):
            continue
    return set()


def _bounds_model(name: str, options: dict[str, Any], start: dict[str, float]) -> Any:
    """The model of ``--nk-from`` with a stand-in index, for its parameters' bounds.

    A model's parameters and bounds do not depend on the index n, k (only on options such
    as ``diffuse`` or ``base``); None where even that model cannot be built (the fit says
    why, per wavelength, before any group is fitted).
    """
    from . import models

    stand_in = {**options, "n": 1.5, "k": 0.0}
    try:
        model = _starts_taken(name, stand_in, start)
    except (models.ModelError, TypeError):
        return None
    for k in [k for k in options if k not in stand_in]:
        del options[k]
    return model


def _check_values(
    model: Any, fix: dict[str, float], start: dict[str, float], free: Sequence[str] | None
) -> None:
    """Every ``--fix``, ``--param`` value and ``--free`` name checked against ``model``."""
    from .models import ModelError

    if model is None:
        return
    for option, values in (("--fix", fix), ("--param", start)):
        for name, v in values.items():
            try:
                model.check_value(name, v)
            except ModelError as exc:
                raise UsageError(f"{option} {name}={v:g}: {exc}") from None
    for name in free or ():
        if name not in model.params:
            raise UsageError(
                f"--free {name}: model {model.name!r} has no parameter {name!r}; parameters "
                f"are {list(model.params)}"
            )


def _residual_groups(args: argparse.Namespace, data: Any, by: list[str]) -> None:
    """``--residual-maps`` draws one group: refuse several before any fit runs."""
    from .fitting.batch import group_keys

    if not args.residual_maps:
        return
    keys = group_keys(data, [*by, "wavelength_nm"] if args.nk_from else by)
    if len(keys) == 1:
        return
    shown = "; ".join(", ".join(f"{k}={v}" for k, v in key.items()) for key in keys[:4])
    more = f" and {len(keys) - 4} more" if len(keys) > 4 else ""
    raise UsageError(
        f"--residual-maps {args.residual_maps}: draws one fitted group; the data hold "
        f"{len(keys)} ({shown}{more}); select one, e.g. with --sample and --wavelength-range, "
        "or leave --residual-maps out"
    )


@_executor_errors
def cmd_fit(args: argparse.Namespace) -> int:
    from . import adapters
    from .fitting import auto_weighting, fit_many, fit_many_nk, fit_records

    model, options, settings = _fit_settings(args)
    by = [c.strip() for c in args.by.split(",") if c.strip()]
    data = _selected(args, adapters.read_many(args.files))
    _residual_groups(args, data, by)
    executor = _executor(args, progress=not args.json)
    kw: dict[str, Any] = {
        **settings,
        "by": by,
        "method": args.method,
        "seed": args.seed,
        "executor": executor,
        "return_results": True,
        "mask_zeros": not args.keep_zeros,
        "relative_floor": args.relative_floor,
    }
    weighting = args.weighting if args.weighting != "auto" else auto_weighting(data)
    if weighting is not None:
        kw["weighting"] = weighting
    if args.nk_from:
        with _option_errors():
            table, results = fit_many_nk(
                data,
                args.model,
                args.nk_from,
                options=options,
                wavelength_nm=args.wavelength,
                **kw,
            )
    else:
        table, results = fit_many(data, model, **kw)
    if args.output:
        from .outputs import atomic_output, csv_safe_frame

        with atomic_output(args.output) as tmp:
            csv_safe_frame(table).to_csv(tmp, index=False)
    if args.residual_maps:
        _residual_maps(args, data, results)
    failed = [r for r in table.to_dict("records") if not r["success"]]
    if args.json:
        _emit_json(fit_records(table, results, by))
    else:
        import pandas as pd

        with pd.option_context("display.width", 200, "display.max_columns", 50):
            print(table.to_string(index=False))
    for r in failed:
        group = ", ".join(f"{b}={r[b]}" for b in by)
        print(f"labbrdf fit: group {group} FAILED: {r['message']}", file=sys.stderr)
    return 3 if failed else 0


def _residual_maps(args: argparse.Namespace, data: Any, results: list) -> None:
    """``--residual-maps PNG``: the maps of the one group (checked before the fit).

    A group that could not be fitted has no maps: said on stderr (the exit code is 3).
    """
    from . import models
    from .report.figures import fit_maps_figure, save_png

    if not results:
        print(
            f"labbrdf fit: --residual-maps {args.residual_maps}: not drawn, the group was "
            "not fitted",
            file=sys.stderr,
        )
        return
    key, res = results[0]
    rows = data.data
    for col, v in key.items():
        rows = rows[rows[col] == v]
    rows = rows[rows["quantity"] == res.quantity]
    if res.nmasked:
        rows = rows[rows["value"] != 0]
    model = models.get(res.model, **res.options)
    title = f"{res.model}: " + ", ".join(f"{k}={v}" for k, v in key.items())
    save_png(fit_maps_figure(model, res.values, rows, title=title), args.residual_maps)


def _model_from_args(args: argparse.Namespace) -> tuple[Any, dict[str, float]]:
    """Build the model of ``--model`` and return it with the ``--param`` parameter values.

    Model options come from ``--param`` (and ``--nk-from``'s n, k at ``--wavelength``).
    """
    from . import models
    from .nk import model_with_nk

    options, values = _split_params(args.model, args.param)
    try:
        if args.nk_from:
            if args.wavelength is None:
                raise UsageError("--nk-from needs --wavelength NM")
            with _option_errors():
                return model_with_nk(args.model, args.nk_from, args.wavelength, **options), values
        return models.get(args.model, **options), values
    except models.ModelError as exc:
        raise UsageError(f"--model {args.model}: {exc} (give options with --param)") from None


def cmd_nk(args: argparse.Namespace) -> int:
    from . import adapters
    from .ellipsometry import P_ANGLE_DEPENDENT
    from .nk import angle_verdict, combined_table, nk_json, nk_table
    from .outputs import atomic_output, csv_safe_frame

    data = _selected(args, adapters.read_many(args.files))
    on_ill: Literal["warn", "raise"] = "warn" if args.allow_ill_conditioned else "raise"
    table = nk_table(data, on_ill_conditioned=on_ill, theta_sigma_deg=args.theta_sigma)
    if args.output:
        out = combined_table(table) if args.combined else table
        with atomic_output(args.output) as tmp:
            csv_safe_frame(out).to_csv(tmp, index=False)
    if args.json:
        _emit_json(nk_json(table))
        return 0
    import pandas as pd

    comb = combined_table(table)
    cols = [c for c in ("sample", "wavelength_nm", "n", "n_sigma", "k", "k_sigma", "chi2",
                        "dof", "p_value", "angle_dependent") if c in comb.columns]  # fmt: skip
    with pd.option_context("display.width", 200, "display.max_rows", 40):
        print(comb[cols].to_string(index=False))
    for (sample, source), g in comb.groupby(["sample", "source"], sort=False):
        v = angle_verdict(g)
        if v.kind == "stack":
            print(
                f"{sample} ({source}): {v.text}, not a material's n, k. They are not combined "
                "(n, k empty above; per angle with -o FILE or --json) and predict no "
                "reflectance; `labbrdf film` fits a stack model for the layers' constants."
            )
        elif g["angle_dependent"].astype(bool).any():
            print(
                f"{sample} ({source}): {v.text}. Where the angles disagree "
                f"(p < {P_ANGLE_DEPENDENT:g}) the sigmas are multiplied by sqrt(chi2/dof) to "
                "cover their scatter."
            )
    return 0


def _film_value(text: str, what: str) -> tuple[float, tuple[float, float] | None]:
    """``V`` (fixed) or ``LO..HI`` (fitted, started mid-box) of a --layer field."""
    lo_s, sep, hi_s = text.partition("..")
    try:
        if not sep:
            return float(text), None
        lo, hi = float(lo_s), float(hi_s)
    except ValueError:
        raise UsageError(f"{what}: {text!r} is not a number or LO..HI") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise UsageError(f"{what}: impossible bounds {text!r} (need LO < HI)")
    return (lo + hi) / 2, (lo, hi)


def _layer_files(spec: str) -> list[str]:
    """The file a ``--layer NAME:MATERIAL:...`` names as its material, if any."""
    fields = spec.split(":")
    return [fields[1]] if len(fields) >= 2 and os.path.exists(fields[1]) else []


def _film_model(args: argparse.Namespace) -> Any:
    """The FilmModel of --model FILE, or of --substrate and --layer, or the default."""
    from . import films
    from .nk import tabulated_from_file

    if args.model is not None:
        if args.layer or args.substrate:
            raise UsageError("give --model FILE or --substrate/--layer, not both")
        return films.load_model(args.model)
    if not args.layer:
        if args.substrate not in (None, "si"):
            raise UsageError("--substrate without --layer: give the layers with --layer")
        return films.FilmModel.cauchy_on_silicon()
    sub_text = args.substrate or "si"
    try:
        sub = (
            films.as_material(sub_text)
            if not os.path.exists(sub_text)
            else tabulated_from_file(sub_text)
        )
    except ValueError as exc:
        raise UsageError(f"--substrate {sub_text}: {exc}") from None
    layers, free = [], {}
    for j, spec in enumerate(args.layer, 1):
        fields = spec.split(":")
        if len(fields) < 3:
            raise UsageError(
                f"--layer {spec!r}: expected NAME:MATERIAL:THICKNESS[:PARAM=V|LO..HI ...], "
                "e.g. oxide:cauchy:0..20:A=1.3..1.7"
            )
        name, mat, thick = fields[0] or f"layer{j}", fields[1], fields[2]
        d, dbox = _film_value(thick, f"--layer {name}: thickness")
        try:
            m = tabulated_from_file(mat) if _layer_files(spec) else films.as_material(mat)
        except ValueError as exc:
            raise UsageError(f"--layer {name}: {exc}") from None
        values = {}
        for item in fields[3:]:
            key, sep, val = item.partition("=")
            if not sep or key not in m.params:
                raise UsageError(
                    f"--layer {name}: {item!r}: expected PARAM=V or PARAM=LO..HI with PARAM "
                    f"one of {sorted(m.params) or 'none (a table)'}"
                )
            values[key], box = _film_value(val, f"--layer {name}: {key}")
            if box is not None:
                free[f"{name}.{key}"] = box
        try:
            m = films.materials._with_params(m, values)
            layers.append(films.Layer(m, d, name))
        except ValueError as exc:
            raise UsageError(f"--layer {name}: {exc}") from None
        if dbox is not None:
            free[f"{name}.thickness_nm"] = dbox
    try:
        stack = films.Stack(layers, sub)
    except ValueError as exc:
        raise UsageError(f"--layer: {exc}") from None
    return films.FilmModel(stack, free, None, "--layer")


def _film_table(summary: dict[str, Any]) -> str:
    """The text table of a film fit summary."""

    def fmt(p: dict[str, Any]) -> str:
        v = p["value"]
        if not p.get("vary"):
            return f"{v:.6g} (fixed)"
        se, ci = p.get("stderr"), p.get("ci95")
        out = f"{v:.6g}"
        if se is not None:
            out += f" +- {se:.2g}"
        if ci:
            out += f"  [{ci[0]:.6g}, {ci[1]:.6g}]"
        sc = p.get("ci95_scaled")
        if sc:
            out += f"  scaled [{sc[0]:.6g}, {sc[1]:.6g}]"
        if p.get("flags"):
            out += "  " + ",".join(p["flags"])
        return out

    lines = []
    for lay in summary["layers"]:
        mat = lay["material"].get("model", "?")
        lines.append(f"layer {lay['name']} ({mat})")
        for k, p in lay["parameters"].items():
            lines.append(f"  {k:<14s} {fmt(p)}")
        nk = lay.get("nk_at_633nm")
        if nk:
            n_se = nk.get("n_stderr")
            k_se = nk.get("k_stderr")
            n_txt = f"{nk['n']:.5f}" + (f" +- {n_se:.2g}" if n_se is not None else "")
            k_txt = f"{nk['k']:.5f}" + (f" +- {k_se:.2g}" if k_se is not None else "")
            lines.append(f"  n, k at 633 nm: {n_txt}, {k_txt}")
    lines.append(f"substrate ({summary['substrate']['material'].get('model', '?')})")
    wl = summary["wavelength_range_nm"]
    lines.append(
        f"fit: {summary['ndata']} values, {wl[0]:g}-{wl[1]:g} nm, {summary['nvarys']} free; "
        f"chi2/nu = {summary['redchi']:.4g}, MSE = {summary['mse']:.4g} (Woollam); "
        f"{summary['nfev']} evaluations, {summary['method']}, seed {summary['seed']}, "
        f"intervals: {summary['ci_method']}"
    )
    if not summary["success"]:
        lines.append(f"fit did not converge: {summary['message']}")
    lines.extend(f"note: {n}" for n in summary["notes"])
    lines.extend(f"warning: {w}" for w in summary["warnings"])
    return "\n".join(lines)


def _one_sample(args: argparse.Namespace, parts: list[Any], data: Any) -> bool:
    """Whether the files of a film fit are one sample: refused (exit 2) when they are not.

    Files that state different sample names in the selected rows are one sample only by
    ``--same-sample``; every ``--same-sample`` value is checked against the inputs first
    (:func:`labbrdf.samples.pair_samples`), whether or not it is needed.
    """
    from pathlib import Path

    from .films import FILM_QUANTITIES
    from .fitting.film import stated_samples
    from .samples import SampleFile, pair_samples, split_same_sample

    def said(rows: Any) -> dict[str, None]:  # the names of the rows a film fit uses
        rows = rows[rows["quantity"].astype(str).isin(FILM_QUANTITIES)]
        return dict.fromkeys(n for names in stated_samples(rows).values() for n in names)

    selected = said(data.data)
    files = []
    for path, m in zip(args.files, parts, strict=True):  # each file's own, still selected
        own = said(m.data)
        files.append(SampleFile(Path(path), tuple(n for n in own if n in selected)))
    groups = pair_samples(
        files,
        [split_same_sample(v, args.files) for v in args.same_sample or ()],
        given_as="given with --same-sample",
    )
    stating = [g for g in groups if any(f.names and f.path in g.paths for f in files)]
    if len(stating) < 2:
        return True
    listing = "; ".join(
        f"{f.path} states {', '.join(map(repr, f.names))}" for f in files if f.names
    )
    spelt = ",".join(str(f.path) for f in files if f.names)
    raise UsageError(
        f"the files state different samples ({listing}); a film fit is of one sample: fit "
        f"each on its own (or select one with --sample), or, if they are one sample, say "
        f"so with --same-sample {spelt}"
    )


def cmd_film(args: argparse.Namespace) -> int:
    from . import adapters
    from .dataset import concat
    from .fitting.film import fit_film
    from .outputs import atomic_output, csv_safe_frame

    fm = _film_model(args)
    sigma = _parse_assignments(args.sigma, "--sigma")
    wl_range = None
    if args.wavelength_range is not None:  # the rows, and the range that replaces the file's
        from .selection import parse_range

        r = parse_range(args.wavelength_range, "--wavelength-range")
        if not 0 <= r.lo < r.hi:
            raise UsageError(
                f"--wavelength-range {args.wavelength_range}: expected MIN:MAX with "
                "0 <= MIN < MAX [nm]"
            )
        wl_range = (r.lo, r.hi)
    parts = [adapters.read(p) for p in args.files]
    data = _selected(args, concat(parts))
    res = fit_film(
        fm,
        data,
        wavelength_range_nm=wl_range,
        default_sigma=sigma or None,
        method=args.method,
        seed=args.seed,
        ci=args.ci,
        one_sample=_one_sample(args, parts, data),
    )
    summary = res.summary()
    if args.output:
        with atomic_output(args.output) as tmp:
            csv_safe_frame(res.nk_table()).to_csv(tmp, index=False)
    if args.fit_json:
        res.save_json(args.fit_json)
    if args.json:
        _emit_json(summary)
    else:
        print(_film_table(summary))
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    import numpy as np

    from .bsdf_export import model_to_bsdf

    if args.format != "zemax-bsdf":
        raise UsageError(f"--format {args.format!r}: export writes zemax-bsdf")
    if (args.model is None) == (args.trace is None):
        raise UsageError("export a model (--model NAME --param ...) or a trace (--trace RUN.npz)")
    if args.trace is not None:
        return _export_trace(args)
    if args.theta_i is None:
        raise UsageError("--model needs --theta-i DEG [DEG ...]")
    model, values = _model_from_args(args)
    unknown = [k for k in values if k not in model.params]
    if unknown:
        raise UsageError(f"--param {unknown}: {args.model} parameters are {list(model.params)}")
    out = Path(args.output)  # checked with the inputs by _checked_outputs
    model_to_bsdf(
        model,
        values,
        out,
        theta_i_deg=np.asarray(args.theta_i, float),
        radial_deg=_grid(args.radial, "--radial"),
        azimuth_deg=_grid(args.azimuth, "--azimuth"),
        overwrite=args.overwrite,
    )
    print(f"wrote {out}")
    return 0


def _export_trace(args: argparse.Namespace) -> int:
    """``export --trace RUN.npz``: the tracer's unpolarized S0 on the scatter grid."""
    from .bsdf_export import binned_to_bsdf
    from .tracer import TraceResult

    out = Path(args.output)  # checked with the inputs by _checked_outputs
    if args.theta_i is not None or args.param or args.nk_from:
        raise UsageError(
            "--trace takes its angle and material from the run; drop --theta-i/--param"
        )
    try:
        res = TraceResult.load(args.trace)
    except (OSError, KeyError, ValueError) as exc:
        raise UsageError(f"--trace {args.trace}: not a labbrdf trace file ({exc})") from None
    cfg = res.config
    binned_to_bsdf(
        out,
        theta_i_deg=cfg.theta_i_deg,
        values=res.s0(),
        theta_edges_deg=res.theta_r_edges_deg,
        phi_edges_deg=res.phi_r_edges_deg,
        radial_deg=_grid(args.radial, "--radial"),
        azimuth_deg=_grid(args.azimuth, "--azimuth"),
        wavelength_nm=cfg.wavelength_nm,
        symmetry="Asymmetrical",
        comments=(f"labbrdf trace S0 (unpolarized), {res.rays} rays, seed {cfg.seed}",),
        overwrite=args.overwrite,
    )
    print(f"wrote {out}")
    return 0


def _grid(text: str, option: str) -> Any:
    """``START:STOP:STEP`` (inclusive) or a comma-separated list, as an array [deg]."""
    import numpy as np

    try:
        if ":" in text:
            a, b, c = (float(x) for x in text.split(":"))
            if not c > 0 or b < a:
                raise ValueError
            return np.round(np.arange(a, b + c / 2, c), 9)
        return np.array([float(x) for x in text.split(",")], float)
    except ValueError:
        raise UsageError(
            f"{option} {text!r}: expected START:STOP:STEP or a comma-separated list"
        ) from None


def _channel(text: str | None) -> int | str | None:
    """``--channel``: an index (digits) or a name."""
    return int(text) if text and text.isdigit() else text


def _pixel_size(args: argparse.Namespace) -> tuple[float, ...] | None:
    """``--pixel-size LENGTH[,LENGTH]`` in metres (``--unit`` for bare numbers)."""
    from .adapters.topography import length_m

    px_text = getattr(args, "pixel_size", None)
    if px_text is None:
        return None
    try:
        pixel = tuple(length_m(v, getattr(args, "unit", None)) for v in px_text.split(","))
    except ValueError as exc:
        raise UsageError(f"--pixel-size: {exc}") from None
    if len(pixel) not in (1, 2):
        raise UsageError(f"--pixel-size {px_text!r}: one pitch or two (dx,dy)")
    return pixel


def _warn(message: str) -> None:
    print(f"labbrdf: warning: {message}", file=sys.stderr)


def _height_map(path: str, channel: str | None, args: argparse.Namespace) -> Any:
    """Read a height map; ``--pixel-size`` / ``--unit`` of ``args`` state its geometry."""
    from .adapters import read_inputs

    pixel = _pixel_size(args)
    try:
        (hm,) = read_inputs(
            [path],
            kind="height_map",
            channel=_channel(channel),
            unit=args.unit,
            pixel_size=pixel,
            on_error="raise",
        ).height_maps
    except MemoryError:
        raise UsageError(f"{path}: out of memory while reading the height map") from None
    for w in hm.warnings:
        _warn(f"{path}: {w}")
    return hm


def _progress_printer(label: str, after_s: float = 2.0) -> Any:
    """``progress(done, total)`` reporting on stderr after ``after_s`` s (a TTY: at once)."""
    t0 = time.monotonic()

    def progress(done: int, total: int) -> None:
        if total > 1 and (sys.stderr.isatty() or time.monotonic() - t0 > after_s):
            el = time.monotonic() - t0
            print(f"{label}: pass {done}/{total} ({el:.0f} s)", file=sys.stderr, flush=True)

    return progress


def cmd_surface(args: argparse.Namespace) -> int:
    from .adapters.topography import length_m
    from .outputs import check_file_output, check_input_files
    from .topography import level, on_measured_points, roughness_statistics

    check_input_files([args.file])
    if args.png:
        check_file_output(args.png, inputs=[args.file], suffixes=(".png",), option="--png")
    cutoff = None
    if args.short_cutoff is not None:
        try:
            cutoff = length_m(args.short_cutoff, args.unit)
        except ValueError as exc:
            raise UsageError(f"--short-cutoff: {exc}") from None
    if args.erode_mask < 0:
        raise UsageError(f"--erode-mask {args.erode_mask}: expected pixels >= 0")
    hm = _height_map(args.file, args.channel, args)
    try:
        st = roughness_statistics(
            hm.heights,
            hm.pixel_size,
            degree=args.degree,
            blocks=args.blocks,
            short_cutoff=cutoff,
            erode=args.erode_mask,
            progress=_progress_printer(f"labbrdf surface: {args.file}"),
        )
        st = on_measured_points(st, hm.points, args.degree)
        if args.png:
            from .report.figures import save_png, surface_figure

            z = level(hm.heights, args.degree)
            title = f"{Path(args.file).name} ({hm.channel})"
            save_png(surface_figure(z, hm.pixel_size, st, title=title), args.png)
    except MemoryError:
        shape = " x ".join(map(str, hm.heights.shape))
        raise UsageError(
            f"{args.file}: out of memory for the statistics of a {shape} map"
            f" ({hm.heights.nbytes / 2**20:.0f} MiB of heights; the statistics need about"
            " 14 times that)"
        ) from None
    except ValueError as exc:
        raise UsageError(f"{args.file}: {exc}") from None
    d = st.to_dict()
    d["file"] = str(args.file)
    d["channel"] = hm.channel
    d["geometry_warnings"] = list(hm.warnings)
    if args.json:
        _emit_json(d)
        return 0
    u = d.get("uncertainty") or {}

    def row(label: str, key: str, scale: float, unit: str) -> None:
        v = d.get(key)
        if v is None:
            print(f"{label:<38} undefined")
            return
        e = u.get(key)
        err = f" +- {e * scale:.3g}" if e is not None else ""
        print(f"{label:<38} {v * scale:.4g}{err} {unit}")

    print(f"{args.file} ({d['kind']}, channel {hm.channel}, {d['levelling']})")
    print(f"bandwidth: {d['bandwidth']}")
    row("sigma (RMS height)", "sigma", 1e9, "nm")
    row("RMS slope", "slope_rms", 1.0, "")
    row("correlation length c", "c", 1e6, "um")
    row("alpha_gaussian_acf = sqrt(2) sigma/c", "alpha_gaussian_acf", 1.0, "")
    row("alpha_ggx_ml (used by trace)", "alpha_ggx_ml", 1.0, "")
    if d["kind"] == "areal":
        row("anisotropy c_major/c_minor", "anisotropy_ratio", 1.0, "")
    fits = d["slope_fits"]
    for name in ("ggx", "beckmann"):
        f = fits[name]
        print(f"{name + ' alpha (ML)':<38} {f['alpha']:.4g}  KS {f['ks']:.3g}  AIC {f['aic']:.6g}")
    print(f"best description of the slopes: {fits['best']}")
    if fits.get("warning"):
        print(f"warning: {fits['warning']}")
    for note in d.get("notes") or ():
        if note != fits.get("warning"):
            print(f"note: {note}")
    return 0


def cmd_hemispherical(args: argparse.Namespace) -> int:
    import numpy as np

    from .integrate import hemispherical_reflectance

    model, params = _model_from_args(args)
    theta = np.asarray(args.theta_i, dtype=float)
    rho = np.atleast_1d(hemispherical_reflectance(model, params, theta))
    if args.json:
        _emit_json(
            [{"theta_i_deg": float(t), "rho": float(r)} for t, r in zip(theta, rho, strict=True)]
        )
    else:
        print("theta_i_deg  rho")
        for t, r in zip(theta, rho, strict=True):
            print(f"{t:11.4g}  {r:.6f}")
    return 0


# ------------------------------------------------------------------------------- trace


def _complex(text: str, what: str) -> complex:
    try:
        return complex(text.replace(" ", "").replace("i", "j"))
    except ValueError:
        raise UsageError(f"{what} {text!r}: expected a complex index like 1.55+7.71j") from None


@_executor_errors
def cmd_trace(args: argparse.Namespace) -> int:
    from . import tracer
    from .tracer_setup import trace_config_from_inputs

    executor = _executor(args, progress=not args.json)  # outputs checked by _checked_outputs
    with _option_errors():
        config = trace_config_from_inputs(
            args.wavelength,
            args.theta_i,
            base_albedo=args.base_albedo,
            substrate_index=None
            if args.substrate is None
            else _complex(args.substrate, "--substrate"),
            nk_from=args.nk_from,
            alpha=args.alpha,
            surface=args.surface,
            coating_index=None if args.coating is None else _complex(args.coating, "--coating"),
            coating_from=args.coating_from,
            thickness_nm=args.thickness,
            coating_alpha=args.coating_alpha,
            coating_surface=args.coating_surface,
            distribution=args.distribution,
            channel=_channel(args.channel),
            unit=args.unit,
            pixel_size=_pixel_size(args),
            warn=_warn,
            rays=args.rays,
            seed=args.seed,
            scattering="single" if args.single_scattering else "multiple",
            coherent=args.coherent,
            estimator=args.estimator,
            scalar=args.scalar,
        )
    t0 = time.perf_counter()
    result = tracer.trace(config, map=functools.partial(executor.imap, desc="trace"))
    seconds = time.perf_counter() - t0
    if args.output:
        result.save(args.output)
    if args.png:
        from .report.figures import save_trace_maps_png

        save_trace_maps_png(result, args.png)  # atomically
    summary = tracer.trace_summary(result)
    summary["seconds"] = seconds
    if args.json:
        _emit_json(summary)
    else:
        e = summary["energy"]
        print(
            f"albedo {summary['albedo']:.6f}  exited {e['exited']:.6f}  absorbed "
            f"{e['absorbed']:.6f}  terminated {e['terminated']:.6f}  rays {summary['rays']}  "
            f"{seconds:.2f} s"
        )
    return 0


# ------------------------------------------------------------------------------- report


@_executor_errors
def cmd_validate(args: argparse.Namespace) -> int:
    from .outputs import check_report_dir
    from .report import validate
    from .report.validate import default_fixtures_dir

    executor = _executor(args)
    check_report_dir(args.out, inputs=[default_fixtures_dir()], option="--out")  # the fixtures
    return int(validate(out=args.out, quick=args.quick, progress=True, executor=executor))


@_executor_errors
def cmd_report(args: argparse.Namespace) -> int:
    from .report import user_report
    from .report.sections.film import default_film_model
    from .samples import split_same_sample

    executor = _executor(args, progress=not args.quiet)
    options, start = _split_params(args.model, args.param)
    selection = _selection(args)
    return int(
        user_report(
            args.files,
            args.model,
            args.output,
            options=options,
            start=start,
            selection=selection,
            progress=not args.quiet,
            film_model=default_film_model() if args.film_default else args.film_model,
            executor=executor,
            same_sample=[split_same_sample(v, args.files) for v in args.same_sample or ()],
            prediction_slopes=args.prediction_slopes,
        )
    )


# ------------------------------------------------------------------------------- main


def _add_geometry(s: argparse.ArgumentParser) -> None:
    """``--pixel-size`` and ``--unit``: the geometry of a height map, stated by the user."""
    s.add_argument(
        "--pixel-size",
        default=None,
        metavar="LENGTH[,LENGTH]",
        help="lateral pitch of the height map, e.g. 312.5nm or 1um,2um (replaces the file's)",
    )
    s.add_argument(
        "--unit",
        default=None,
        metavar="UNIT",
        help="length unit of the numbers in the height-map file (m, mm, um, nm, pm, A)",
    )


def _ingest_parser(sub: Any) -> None:
    """The ``ingest`` subcommand's options."""
    s = sub.add_parser("ingest", help="read instrument exports into one dataset")
    s.add_argument("files", nargs="+", action=InputPath, metavar="FILE")
    s.add_argument("--format", default=None, help="force an adapter (see `labbrdf formats`)")
    s.add_argument(
        "--columns",
        default=None,
        metavar="NAMES",
        help="declare the columns of a headerless numeric file (implies --format columns), "
        "e.g. wavelength_nm,absorbance; see docs/formats.md",
    )
    s.add_argument(
        "--skip-lines",
        default=None,
        metavar="N|auto",
        help="with --columns: skip the first N lines (a title or header), or with 'auto' "
        "every line before the first row of numbers; the skipped lines go in the metadata",
    )
    s.add_argument(
        "-o",
        "--output",
        action=OutputPath,
        suffixes=(".parquet", ".csv"),
        default=None,
        help="write OUT.parquet, or OUT.csv and its metadata OUT.meta.json",
    )
    _add_overwrite(s)
    s.add_argument("--json", action="store_true", help="print a JSON list, one object per file")
    s.add_argument("--keep-going", action="store_true", help="read the rest after a failure")
    _add_selection(s)
    s.set_defaults(func=cmd_ingest)


def _formats_parser(sub: Any) -> None:
    """The ``formats`` subcommand's options."""
    s = sub.add_parser("formats", help="list the supported export formats")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_formats)


def _cache_parser(sub: Any) -> None:
    """The ``cache`` subcommand's options."""
    s = sub.add_parser("cache", help="show or clear the tracer's operator cache")
    s.add_argument(
        "action",
        nargs="?",
        choices=("info", "clear"),
        default="info",
        help="info: where the cache is, its entries, their total size and the cap (default); "
        "clear: remove labbrdf's entries",
    )
    s.add_argument("--json", action="store_true", help="info as JSON")
    s.set_defaults(func=cmd_cache)


def _fit_parser(sub: Any) -> None:
    """The ``fit`` subcommand's options."""
    from .fitting.core import METHOD

    s = sub.add_parser("fit", help="fit a model per group (sample, wavelength)")
    s.add_argument("files", nargs="+", action=InputPath, metavar="FILE_OR_DATASET")
    s.add_argument("--model", required=True)
    s.add_argument("--by", default="sample,wavelength_nm", help="comma-separated group columns")
    s.add_argument("--method", default=METHOD, help="nlopt GLOBAL[+LOCAL]")
    s.add_argument("--seed", type=_fit_seed, default=0, help="the optimiser's seed")
    s.add_argument(
        "--replicates",
        type=int,
        default=None,
        metavar="R",
        help="fit a Monte Carlo model (layered) with R model seeds and report their mean, "
        "with the seed spread in the standard error (default: the model's, 3 for layered)",
    )
    s.add_argument("--fix", action="append", metavar="NAME=VALUE", help="fix a parameter")
    s.add_argument(
        "--param",
        action="append",
        metavar="NAME=VALUE",
        help="a model option (microfacet n=, k=, diffuse=true; five_param shadowing=mb; "
        "layered base=diffuse, rays=, floor=true) or a parameter's starting value",
    )
    s.add_argument(
        "--free", action="append", metavar="NAME", help="vary a parameter fixed by default"
    )
    s.add_argument(
        "--nk-from",
        action=InputPath,
        default=None,
        metavar="FILE",
        help="n, k from psi/Delta (microfacet)",
    )
    s.add_argument(
        "--wavelength",
        type=_wavelength_value,
        default=None,
        metavar="NM",
        help="[nm] take --nk-from's n, k at this wavelength for every group (needed for "
        "files that state none); default: each group's own",
    )
    s.add_argument("--nk-wavelength", action=_Renamed, new="say --wavelength NM")
    s.add_argument(
        "--weighting",
        choices=["auto", "sigma", "relative", "uniform"],
        default="auto",
        help="auto: 1/sigma^2 where every point has sigma, else relative",
    )
    s.add_argument(
        "--relative-floor",
        type=_open_fraction,
        default=1e-3,
        help="floor of --weighting relative, a fraction of the largest absolute value",
    )
    s.add_argument("--keep-zeros", action="store_true", help="fit points with value 0 too")
    s.add_argument(
        "-o",
        "--output",
        action=OutputPath,
        suffixes=(".csv",),
        default=None,
        help="write the parameter table (CSV)",
    )
    s.add_argument(
        "--residual-maps",
        action=OutputPath,
        suffixes=(".png",),
        default=None,
        metavar="PNG",
        help="draw measured, model and relative residual per incidence (one fitted group)",
    )
    _add_overwrite(s)
    s.add_argument("--json", action="store_true")
    _add_selection(s, wavelength_taken=True)
    _add_scheduler(s)
    s.set_defaults(func=cmd_fit)


def _nk_parser(sub: Any) -> None:
    """The ``nk`` subcommand's options."""
    s = sub.add_parser("nk", help="optical constants n, k from ellipsometer psi/Delta")
    s.add_argument("files", nargs="+", action=InputPath, metavar="FILE")
    s.add_argument(
        "-o",
        "--output",
        action=OutputPath,
        suffixes=(".csv",),
        default=None,
        help="write the table (CSV)",
    )
    _add_overwrite(s)
    s.add_argument("--combined", action="store_true", help="-o writes the per-wavelength table")
    s.add_argument("--theta-sigma", type=float, default=0.0, help="angle uncertainty [deg]")
    s.add_argument(
        "--allow-ill-conditioned",
        action="store_true",
        help="warn, not fail, near normal incidence",
    )
    s.add_argument("--json", action="store_true")
    _add_selection(s)
    s.set_defaults(func=cmd_nk)


def _film_parser(sub: Any) -> None:
    """The ``film`` subcommand's options."""
    from .fitting.core import METHOD

    s = sub.add_parser(
        "film",
        help="fit a thin-film stack (thicknesses, n, k) to psi/Delta, R and T of one sample",
    )
    s.add_argument(
        "files",
        nargs="+",
        action=InputPath,
        metavar="FILE",
        help="files of one sample (joint fit)",
    )
    s.add_argument(
        "--model",
        action=InputPath,
        inside="model",
        default=None,
        metavar="MODEL.toml",
        help="a film model file",
    )
    s.add_argument(
        "--substrate",
        action=InputPath,
        default=None,
        metavar="NAME|FILE",
        help="si, sio2, a dispersion model, or an n,k or ellipsometer file (default si)",
    )
    s.add_argument(
        "--layer",
        action="append",
        default=[],
        metavar="NAME:MATERIAL:THICKNESS[:P=V|LO..HI]",
        help="a layer, top first (repeat); LO..HI values are fitted, e.g. "
        "oxide:cauchy:0..20:A=1.3..1.7:B=0.004 (no --model/--layer: one Cauchy layer on Si)",
    )
    s.add_argument(
        "--sigma",
        action="append",
        metavar="QUANTITY=VALUE",
        help="sigma for rows whose file gives none (e.g. reflectance=0.005)",
    )
    s.add_argument(
        "--same-sample",
        action="append",
        # not an InputPath: every name must be one of the FILE inputs (refused otherwise)
        metavar="A,B[,...]",
        help="these FILE inputs are one sample although they state different sample names "
        "(files that do are refused without it)",
    )
    s.add_argument(
        "--ci",
        choices=("wald", "profile"),
        default="profile",
        help="95%% intervals from the profile of chi2 (default) or the covariance",
    )
    s.add_argument("--method", default=METHOD, help="nlopt stages")
    s.add_argument("--seed", type=_fit_seed, default=0, help="the optimiser's seed")
    s.add_argument(
        "-o",
        "--output",
        action=OutputPath,
        suffixes=(".csv",),
        default=None,
        metavar="NK.csv",
        help="write each layer's n, k on the fitted wavelengths",
    )
    s.add_argument(
        "--fit-json",
        action=OutputPath,
        suffixes=(".json",),
        default=None,
        metavar="FIT.json",
        help="write the fit (best-fit stack, intervals) as JSON",
    )
    _add_overwrite(s)
    s.add_argument("--json", action="store_true")
    _add_selection(s)
    s.set_defaults(func=cmd_film)


def _surface_parser(sub: Any) -> None:
    """The ``surface`` subcommand's options."""
    s = sub.add_parser("surface", help="roughness statistics of a height map or profile")
    s.add_argument("file", action=InputPath, metavar="FILE")
    s.add_argument("--channel", default=None, help="channel name or index (default: height)")
    s.add_argument("--degree", type=int, default=1, help="levelling polynomial (1 = plane)")
    s.add_argument("--blocks", type=int, default=None, help="tiles per axis for uncertainties")
    s.add_argument(
        "--png",
        action=OutputPath,
        suffixes=(".png",),
        default=None,
        help="write map, ACF and slope histogram (.png)",
    )
    _add_overwrite(s)
    s.add_argument(
        "--short-cutoff",
        default=None,
        metavar="LENGTH",
        help="Gaussian S-filter cut-off (ISO 16610-61), e.g. 2um: slopes and alphas then refer"
        " to longer wavelengths (default: none, down to the pixel)",
    )
    s.add_argument(
        "--erode-mask",
        type=int,
        default=0,
        metavar="N",
        help="drop the points within N pixels of a dropout (their rims often carry spikes)",
    )
    _add_geometry(s)
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_surface)


def _export_parser(sub: Any) -> None:
    """The ``export`` subcommand's options."""
    s = sub.add_parser("export", help="write a model BRDF in an exchange format")
    s.add_argument("--format", default="zemax-bsdf", help="zemax-bsdf")
    s.add_argument("--model", default=None, help="a model (with --param) ...")
    s.add_argument(
        "--trace", action=InputPath, default=None, metavar="RUN.npz", help="... or a trace's S0"
    )
    s.add_argument("--param", action="append", metavar="NAME=VALUE")
    s.add_argument("--nk-from", action=InputPath, default=None, metavar="FILE")
    s.add_argument(
        "--wavelength",
        type=_wavelength_value,
        default=None,
        metavar="NM",
        help="[nm] for --nk-from",
    )
    s.add_argument("--theta-i", type=float, nargs="+", default=None, metavar="DEG")
    s.add_argument("--radial", default="0:80:2", help="START:STOP:STEP [deg] about specular")
    s.add_argument("--azimuth", default="0:180:5", help="START:STOP:STEP [deg]")
    s.add_argument("-o", "--output", action=OutputPath, suffixes=(".bsdf",), required=True)
    _add_overwrite(s)
    s.set_defaults(func=cmd_export)


def _hemispherical_parser(sub: Any) -> None:
    """The ``hemispherical`` subcommand's options."""
    s = sub.add_parser("hemispherical", help="directional-hemispherical reflectance of a model")
    s.add_argument("--model", required=True)
    s.add_argument("--param", action="append", metavar="NAME=VALUE")
    s.add_argument("--theta-i", type=float, nargs="+", required=True, metavar="DEG")
    s.add_argument(
        "--nk-from", action=InputPath, default=None, metavar="FILE", help="n, k from psi/Delta"
    )
    s.add_argument(
        "--wavelength",
        type=_wavelength_value,
        default=None,
        metavar="NM",
        help="[nm] for --nk-from",
    )
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_hemispherical)


def _trace_parser(sub: Any) -> None:
    """The ``trace`` subcommand's options."""
    s = sub.add_parser("trace", help="Monte Carlo polarization ray tracing (pBRDF)")
    s.add_argument("--substrate", default=None, help="complex index, e.g. 1.55+7.71j")
    s.add_argument(
        "--nk-from",
        action=InputPath,
        default=None,
        metavar="FILE",
        help="substrate n, k from psi/Delta",
    )
    s.add_argument("--alpha", type=float, default=None, help="GGX roughness of the substrate")
    s.add_argument(
        "--surface",
        action=InputPath,
        default=None,
        metavar="FILE",
        help="measured height map: its slope table",
    )
    s.add_argument("--channel", default=None, help="height channel of --surface")
    s.add_argument(
        "--base-albedo",
        type=float,
        default=None,
        metavar="A",
        help="a Lambertian base of albedo A in [0, 1] instead of the metal substrate "
        "(paints, plastics: with --coating and --coating-alpha)",
    )
    _add_geometry(s)
    s.add_argument("--coating", default=None, help="coating index, e.g. 1.5")
    s.add_argument(
        "--coating-from",
        default=None,
        action=InputPath,
        inside="fit",
        metavar="FIT.json",
        help="coating index at --wavelength and thickness from a one-layer film fit",
    )
    s.add_argument("--thickness", type=float, default=None, help="coating thickness [nm]")
    s.add_argument("--coating-alpha", type=float, default=None)
    s.add_argument(
        "--coating-surface",
        action=InputPath,
        default=None,
        metavar="FILE",
        help="measured height map of the coating's top: its slope table (and, for "
        "reference, its ML GGX alpha)",
    )
    s.add_argument(
        "--distribution",
        choices=("ggx", "beckmann"),
        default="ggx",
        help="microfacet distribution of the interfaces given by an alpha (measured maps "
        "always use their own slope table)",
    )
    s.add_argument("--theta-i", type=float, required=True, help="[deg]")
    s.add_argument(
        "--wavelength", type=_wavelength_value, required=True, metavar="NM", help="[nm]"
    )
    s.add_argument("--rays", type=int, default=200_000)
    s.add_argument("--seed", type=int, default=1)
    s.add_argument("--single-scattering", action="store_true")
    s.add_argument("--coherent", action="store_true")
    s.add_argument(
        "--estimator",
        choices=("auto", "evaluated", "counting"),
        default="auto",
        help="evaluated: closed-form first surface + exit operator (single scattering with "
        "a rough first interface); counting: exits counted into bins; auto (default): "
        "evaluated where it applies",
    )
    s.add_argument(
        "--scalar",
        action="store_true",
        help="unpolarized Fresnel reflectance at every vertex (only M00; how scalar codes "
        "compute)",
    )
    s.add_argument(
        "-o",
        "--output",
        action=OutputPath,
        suffixes=(".npz",),
        default=None,
        help="write the pBRDF (.npz)",
    )
    s.add_argument(
        "--png",
        action=OutputPath,
        suffixes=(".png",),
        default=None,
        help="write S0/DOP hemisphere maps (.png)",
    )
    _add_overwrite(s)
    s.add_argument("--json", action="store_true")
    _add_scheduler(s)
    s.set_defaults(func=cmd_trace)


def _validate_parser(sub: Any) -> None:
    """The ``validate`` subcommand's options."""
    s = sub.add_parser("validate", help="run the whole validation and write the HTML report")
    s.add_argument("--out", action=OutputPath, kind="dir", default="reports/validation")
    _add_overwrite(s)
    s.add_argument("--quick", action="store_true", help="small scale (tests, previews)")
    _add_scheduler(s)
    s.set_defaults(func=cmd_validate)


def _report_parser(sub: Any) -> None:
    """The ``report`` subcommand's options."""
    s = sub.add_parser("report", help="HTML report for your own files")
    s.add_argument(
        "files",
        nargs="+",
        action=InputPath,
        metavar="DATA",
        help="instrument exports, .bsdf files, datasets and height maps (.di, .opdx, ...)",
    )
    s.add_argument("--model", default="smooth3")
    s.add_argument(
        "--param",
        action="append",
        metavar="NAME=VALUE",
        help="a model option (microfacet n=, k=, diffuse=true) or a parameter's start value",
    )
    s.add_argument("-o", "--output", action=OutputPath, kind="dir", required=True, metavar="DIR")
    _add_overwrite(s)
    film = s.add_mutually_exclusive_group()
    film.add_argument(
        "--film-model",
        default=None,
        action=InputPath,
        inside="model",
        metavar="FILE.toml",
        help="fit this film stack to psi/Delta files whose angles disagree",
    )
    film.add_argument(
        "--film-default",
        action="store_true",
        help="... or the stated default: one transparent Cauchy layer on c-Si, thickness free",
    )
    s.add_argument(
        "--same-sample",
        action="append",
        # not an InputPath: every name must be one of the DATA inputs (refused otherwise)
        metavar="A,B[,...]",
        help="these DATA inputs are one sample (repeatable; inputs stating one sample name "
        "are paired anyway)",
    )
    s.add_argument(
        "--prediction-slopes",
        choices=("ggx", "measured"),
        default="ggx",
        help="roughness of the section prediction: the GGX alpha of the height map's slopes "
        "(default) or their measured table (as trace --surface)",
    )
    s.add_argument("--quiet", action="store_true", help="no progress lines")
    _add_selection(s)
    _add_scheduler(s)
    s.set_defaults(func=cmd_report)


class _Parser(argparse.ArgumentParser):
    """A parser that takes options by their full names only.

    No abbreviations (``allow_abbrev=False``): ``--wavelength`` must never be taken for
    ``--wavelength-range``, nor a later option's prefix for an earlier one.
    """

    def __init__(self, *args: Any, **kw: Any) -> None:
        kw.setdefault("allow_abbrev", False)
        super().__init__(*args, **kw)


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    p = _Parser(
        prog="labbrdf",
        description="Optical-metrology toolkit: read instrument exports, fit BRDF models, "
        "check physics, trace polarized rays, write validation reports.",
    )
    p.add_argument("--version", action="version", version=f"labbrdf {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    _ingest_parser(sub)
    _formats_parser(sub)
    _fit_parser(sub)
    _nk_parser(sub)
    _film_parser(sub)
    _surface_parser(sub)
    _export_parser(sub)
    _hemispherical_parser(sub)
    _trace_parser(sub)
    _validate_parser(sub)
    _report_parser(sub)
    _cache_parser(sub)
    for sp in sub.choices.values():  # what _checked_outputs checks, per command
        sp.set_defaults(path_actions=tuple(path_actions(sp)))
    return p


@contextlib.contextmanager
def _labbrdf_warnings(command: str) -> Iterator[None]:
    """Print labbrdf's own warnings as one line each, without Python's source-line dump.

    A reader's doubts (:class:`~labbrdf.adapters.AdapterWarning`, always shown), a tracer
    cache file that was rebuilt, an ill-conditioned inversion: every warning class defined
    in labbrdf. Other libraries' warnings keep Python's format.
    """
    from .adapters import AdapterWarning

    with warnings.catch_warnings():
        original = warnings.showwarning

        def show(message: Any, category: Any, *rest: Any, **kw: Any) -> None:
            if category.__module__.partition(".")[0] == "labbrdf":
                print(f"labbrdf {command}: warning: {message}", file=sys.stderr)
            else:
                original(message, category, *rest, **kw)

        warnings.simplefilter("always", AdapterWarning)
        warnings.showwarning = show
        yield


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    try:
        parser = build_parser()
    except KeyboardInterrupt:
        print("labbrdf: interrupted", file=sys.stderr)
        return 130
    args = parser.parse_args(argv)
    try:
        with _checked_outputs(args), _labbrdf_warnings(args.command):
            return int(args.func(args))
    except UsageError as exc:
        print(f"labbrdf {args.command}: {exc}", file=sys.stderr)
        return 2
    except (ValueError, NotImplementedError, ImportError) as exc:
        # AdapterError, DatasetError, ModelError, FitError are ValueErrors with a message
        print(f"labbrdf {args.command}: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # the reader of our output stopped early (`labbrdf ingest --json | head`): not an
        # error of ours; point stdout at devnull so that Python's exit flush stays quiet
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141
    except OSError as exc:  # an output or input the OS refused: no traceback
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"labbrdf {args.command}: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"labbrdf {args.command}: out of memory (is an input a huge file?)", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"labbrdf {args.command}: interrupted; the run is abandoned", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
