"""``labbrdf hemispherical``: directional-hemispherical reflectance of a model."""

from __future__ import annotations

import argparse
from typing import Any

from ._options import _angle_value, _emit_json, _model_from_args, _wavelength_value
from ._paths import InputPath


def cmd_hemispherical(args: argparse.Namespace) -> int:
    """Print the directional-hemispherical reflectance of the model at each angle."""
    import numpy as np

    from ..integrate import hemispherical_reflectance

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


def add_parser(sub: Any) -> None:
    """The ``hemispherical`` subcommand's options."""
    s = sub.add_parser("hemispherical", help="directional-hemispherical reflectance of a model")
    s.add_argument("--model", required=True)
    s.add_argument("--param", action="append", metavar="NAME=VALUE")
    s.add_argument("--theta-i", type=_angle_value, nargs="+", required=True, metavar="DEG")
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
