"""``labbrdf nk``: optical constants n, k from ellipsometer psi/Delta."""

from __future__ import annotations

import argparse
from typing import Any, Literal

from ._options import _add_selection, _emit_json, _selected
from ._paths import InputPath, OutputPath, _add_overwrite


def cmd_nk(args: argparse.Namespace) -> int:
    """Invert psi/Delta to n, k per angle and wavelength; print the combined table."""
    from .. import adapters
    from ..ellipsometry import P_ANGLE_DEPENDENT
    from ..nk import angle_verdict, combined_table, nk_json, nk_table
    from ..outputs import atomic_output, csv_safe_frame

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


def add_parser(sub: Any) -> None:
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
