"""The ``labbrdf`` command: a thin argparse layer over the library.

Subcommands: ``ingest``, ``formats``, ``fit``, ``hemispherical``, ``trace``, ``validate``,
``report``. Every subcommand returns an exit code: 0 success, 1 a validation check failed,
2 bad input (unreadable file, unknown name, ...), with the error on stderr.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .jsonsafe import jsonable

__all__ = ["main"]


class UsageError(Exception):
    """A command-line input error: printed, exit code 2."""


def _emit_json(obj: Any) -> None:
    print(json.dumps(jsonable(obj), indent=2, allow_nan=False))


def _parse_assignments(items: Sequence[str] | None, what: str) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in items or ():
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise UsageError(f"{what} {item!r}: expected NAME=VALUE")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise UsageError(f"{what} {item!r}: {value!r} is not a number") from None
    return out


def _add_scheduler(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--scheduler",
        default="processes",
        help="serial, processes (default), local (dask LocalCluster) or tcp://host:port",
    )
    p.add_argument("--workers", type=int, default=None, help="worker processes (default: cores)")


def _check_executor(args: argparse.Namespace) -> None:
    """Reject a bad ``--scheduler`` / ``--workers`` before any work is done."""
    from .parallel import check_scheduler

    try:
        check_scheduler(args.scheduler)
    except ValueError as exc:
        raise UsageError(f"--scheduler: {exc}") from None
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers must be >= 1, got {args.workers}")


def _executor_errors(cmd: Any) -> Any:
    """Make a run abandoned by the executor exit with code 2 and the reason.

    Dead workers or an unreachable scheduler give the reason on stderr, not a traceback;
    nothing partial has been written.
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


def _samefile(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def cmd_ingest(args: argparse.Namespace) -> int:
    from . import adapters
    from .dataset import concat, write

    out = Path(args.output) if args.output else None
    if out is not None:
        if out.suffix.lower() not in {".parquet", ".csv"}:
            raise UsageError(f"-o {out}: use a .parquet or .csv file name")
        for f in args.files:
            if _samefile(out, Path(f)) or out.resolve() == Path(f).resolve():
                raise UsageError(f"-o {out} is one of the input files; refusing to overwrite it")
    rows: list[dict[str, Any]] = []
    measurements = []
    failures: list[dict[str, str]] = []
    for f in args.files:
        try:
            m = adapters.read(f, args.format)
        except (ValueError, NotImplementedError) as exc:
            if not args.keep_going:
                print(f"labbrdf ingest: {exc}", file=sys.stderr)
                return 2
            failures.append({"file": str(f), "error": str(exc)})
            continue
        s = m.summary()
        measurements.append(m)
        rows.append(
            {
                "file": str(f),
                "format": m.meta.get("format", args.format),
                "sample": s["sample"][0] if len(s["sample"]) == 1 else s["sample"],
                "rows": s["rows"],
                "quantities": s["quantities"],
                "wavelength_nm": s["wavelength_nm"],
                "theta_i_deg": s["theta_i_deg"],
            }
        )
    if out is not None and measurements:
        write(concat(measurements), out)
    if args.json:
        payload: Any = rows
        if failures:
            payload = rows + [{"file": f["file"], "error": f["error"]} for f in failures]
        _emit_json(payload)
    else:
        _print_ingest_table(rows)
        if out is not None and measurements:
            print(f"wrote {out} ({sum(r['rows'] for r in rows)} rows)")
    for f in failures:
        print(f"labbrdf ingest: FAILED {f['error']}", file=sys.stderr)
    return 2 if failures else 0


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
    head = ["file", "format", "sample", "quantities", "wavelength_nm", "theta_i_deg", "rows"]
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
                f"{wl[0]:.6g}-{wl[1]:.6g}",
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


# ------------------------------------------------------------------------------- fit


@_executor_errors
def cmd_fit(args: argparse.Namespace) -> int:
    from . import adapters
    from .fitting import fit_many

    _check_executor(args)
    data = adapters.read_many(args.files)
    fix = _parse_assignments(args.fix, "--fix")
    by = [c.strip() for c in args.by.split(",") if c.strip()]
    table, results = fit_many(
        data,
        args.model,
        by=by,
        method=args.method,
        seed=args.seed,
        fix=fix or None,
        scheduler=args.scheduler,
        workers=args.workers,
        progress=not args.json,
        return_results=True,
    )
    if args.output:
        from .dataset import atomic_output

        with atomic_output(args.output) as tmp:
            table.to_csv(tmp, index=False)
    if args.json:
        out = []
        for key, res in results:
            s = res.summary()
            out.append(
                {
                    "group": key,
                    "params": {
                        name: {
                            "value": p["value"],
                            "stderr": p.get("stderr"),
                            "ci95": p.get("ci95"),
                            "at_bound": p.get("at_bound", False),
                        }
                        for name, p in s["params"].items()
                    },
                    "rmse": s["rmse"],
                    "nfev": s["nfev"],
                    "success": s["success"],
                }
            )
        _emit_json(out)
    else:
        import pandas as pd

        with pd.option_context("display.width", 200, "display.max_columns", 50):
            print(table.to_string(index=False))
    return 0


def cmd_hemispherical(args: argparse.Namespace) -> int:
    import numpy as np

    from . import models
    from .integrate import hemispherical_reflectance

    model = models.get(args.model)
    params = _parse_assignments(args.param, "--param")
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
    from .parallel import imap

    _check_executor(args)
    sub = _complex(args.substrate, "--substrate")
    kw: dict[str, Any] = {
        "wavelength_nm": args.wavelength,
        "theta_i_deg": args.theta_i,
        "substrate": tracer.Substrate(n=sub.real, k=sub.imag, alpha=args.alpha),
        "rays": args.rays,
        "seed": args.seed,
        "scattering": "single" if args.single_scattering else "multiple",
        "coherent": args.coherent,
    }
    if args.coating is not None:
        coat = _complex(args.coating, "--coating")
        if args.thickness is None:
            raise UsageError("--coating needs --thickness (nm)")
        kw["coating"] = tracer.Coating(
            n=coat.real,
            k=coat.imag,
            thickness_nm=args.thickness,
            alpha=args.coating_alpha if args.coating_alpha is not None else args.alpha,
        )
    elif args.thickness is not None or args.coating_alpha is not None:
        raise UsageError("--thickness and --coating-alpha need --coating")
    config = tracer.TraceConfig(**kw)
    mapper: Any = map
    if args.scheduler != "serial":
        mapper = functools.partial(
            imap,
            scheduler=args.scheduler,
            workers=args.workers,
            progress=not args.json,
            desc="trace",
        )
    t0 = time.perf_counter()
    result = tracer.trace(config, map=mapper)
    seconds = time.perf_counter() - t0
    if args.output:
        result.save(args.output)
    if args.png:
        from .report.figures import save_trace_maps_png

        save_trace_maps_png(result, args.png)
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
    from .report import validate

    _check_executor(args)
    return int(
        validate(
            out=args.out,
            quick=args.quick,
            progress=True,
            scheduler=args.scheduler,
            workers=args.workers,
        )
    )


def cmd_report(args: argparse.Namespace) -> int:
    from .report import user_report

    return int(user_report(args.files, args.model, args.output))


# ------------------------------------------------------------------------------- main


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    p = argparse.ArgumentParser(
        prog="labbrdf",
        description="Optical-metrology toolkit: read instrument exports, fit BRDF models, "
        "check physics, trace polarized rays, write validation reports.",
    )
    p.add_argument("--version", action="version", version=f"labbrdf {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("ingest", help="read instrument exports into one dataset")
    s.add_argument("files", nargs="+", metavar="FILE")
    s.add_argument("--format", default=None, help="force an adapter (see `labbrdf formats`)")
    s.add_argument("-o", "--output", default=None, help="write OUT.parquet or OUT.csv")
    s.add_argument("--json", action="store_true", help="print a JSON list, one object per file")
    s.add_argument("--keep-going", action="store_true", help="read the rest after a failure")
    s.set_defaults(func=cmd_ingest)

    s = sub.add_parser("formats", help="list the supported export formats")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_formats)

    s = sub.add_parser("fit", help="fit a model per group (sample, wavelength)")
    s.add_argument("files", nargs="+", metavar="FILE_OR_DATASET")
    s.add_argument("--model", required=True)
    s.add_argument("--by", default="sample,wavelength_nm", help="comma-separated group columns")
    s.add_argument("--method", default="GN_CRS2_LM+LN_BOBYQA", help="nlopt GLOBAL[+LOCAL]")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--fix", action="append", metavar="NAME=VALUE", help="fix a parameter")
    s.add_argument("-o", "--output", default=None, help="write the parameter table (CSV)")
    s.add_argument("--json", action="store_true")
    _add_scheduler(s)
    s.set_defaults(func=cmd_fit)

    s = sub.add_parser("hemispherical", help="directional-hemispherical reflectance of a model")
    s.add_argument("--model", required=True)
    s.add_argument("--param", action="append", metavar="NAME=VALUE")
    s.add_argument("--theta-i", type=float, nargs="+", required=True, metavar="DEG")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_hemispherical)

    s = sub.add_parser("trace", help="Monte Carlo polarization ray tracing (pBRDF)")
    s.add_argument("--substrate", required=True, help="complex index, e.g. 1.55+7.71j")
    s.add_argument("--alpha", type=float, required=True, help="GGX roughness of the substrate")
    s.add_argument("--coating", default=None, help="coating index, e.g. 1.5")
    s.add_argument("--thickness", type=float, default=None, help="coating thickness [nm]")
    s.add_argument("--coating-alpha", type=float, default=None)
    s.add_argument("--theta-i", type=float, required=True, help="[deg]")
    s.add_argument("--wavelength", type=float, required=True, help="[nm]")
    s.add_argument("--rays", type=int, default=200_000)
    s.add_argument("--seed", type=int, default=1)
    s.add_argument("--single-scattering", action="store_true")
    s.add_argument("--coherent", action="store_true")
    s.add_argument("-o", "--output", default=None, help="write the pBRDF (.npz)")
    s.add_argument("--png", default=None, help="write S0/DOP hemisphere maps (.png)")
    s.add_argument("--json", action="store_true")
    _add_scheduler(s)
    s.set_defaults(func=cmd_trace)

    s = sub.add_parser("validate", help="run the whole validation and write the HTML report")
    s.add_argument("--out", default="reports/validation")
    s.add_argument("--quick", action="store_true", help="small scale (tests, previews)")
    _add_scheduler(s)
    s.set_defaults(func=cmd_validate)

    s = sub.add_parser("report", help="HTML report for your own files")
    s.add_argument("files", nargs="+", metavar="DATA")
    s.add_argument("--model", default="smooth3")
    s.add_argument("-o", "--output", required=True, metavar="DIR")
    s.set_defaults(func=cmd_report)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except UsageError as exc:
        print(f"labbrdf {args.command}: {exc}", file=sys.stderr)
        return 2
    except (ValueError, NotImplementedError, ImportError) as exc:
        # AdapterError, DatasetError, ModelError, FitError are ValueErrors with a message
        print(f"labbrdf {args.command}: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # pragma: no cover
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
