"""``labbrdf validate``: the whole validation, written as an HTML report."""

from __future__ import annotations

import argparse
from typing import Any

from ._executor import _add_scheduler, _executor, _executor_errors
from ._paths import OutputPath, _add_overwrite


@_executor_errors
def cmd_validate(args: argparse.Namespace) -> int:
    """Run the validation and write its report; exit 1 if a check failed."""
    from ..outputs import check_report_dir
    from ..report import validate
    from ..report.validate import default_fixtures_dir

    executor = _executor(args)
    check_report_dir(args.out, inputs=[default_fixtures_dir()], option="--out")  # the fixtures
    return int(validate(out=args.out, quick=args.quick, progress=True, executor=executor))


def add_parser(sub: Any) -> None:
    """The ``validate`` subcommand's options."""
    s = sub.add_parser("validate", help="run the whole validation and write the HTML report")
    s.add_argument("--out", action=OutputPath, kind="dir", default="reports/validation")
    _add_overwrite(s)
    s.add_argument("--quick", action="store_true", help="small scale (tests, previews)")
    _add_scheduler(s)
    s.set_defaults(func=cmd_validate)
