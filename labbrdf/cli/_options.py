"""Option values, row selection and the options' names shared by the commands.

Text to values (``NAME=VALUE`` lists, model options, ranges, seeds, one wavelength), the
row-selection options and :func:`_selected`, a height map's stated geometry, the model of
``--model``/``--param``/``--nk-from``, and :class:`UsageError`: a command-line input
error, printed by :func:`labbrdf.cli.main` with exit code 2.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
from collections.abc import Iterator, Sequence
from typing import Any


class UsageError(Exception):
    """A command-line input error: printed, exit code 2."""


def _emit_json(obj: Any) -> None:
    from ..jsonsafe import jsonable

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
    from ..models import option_names

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
    from ..fitting.defaults import MAX_SEED

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


def _angle_value(text: str) -> float:
    """The argparse type of ``--theta-i DEG``: an angle of incidence [deg]."""
    try:
        x = float(text)
    except ValueError:
        x = math.nan
    if not (text.strip().isascii() and math.isfinite(x)):
        hint = "; a range of rows is --theta-i-range MIN:MAX" if ":" in text else ""
        raise argparse.ArgumentTypeError(f"{text!r}: expected an angle of incidence [deg]{hint}")
    return x


def _medium_value(text: str) -> tuple[float, float, float]:
    """The argparse type of ``--medium TAU,SSA,G``: three finite numbers."""
    parts = text.split(",")
    try:
        values = tuple(float(x) for x in parts)
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected TAU,SSA,G (optical thickness, single-scattering albedo, "
            "HG asymmetry), e.g. 0.8,0.9,0.5"
        )
    return values[0], values[1], values[2]


def _row_range(text: str) -> str:
    """The argparse type of ``--theta-i-range``: ``MIN:MAX``, ``MIN:``, ``:MAX`` or one value.

    Checked here with :func:`labbrdf.selection.parse_range` (a bad range is refused before
    any file is read) and handed on as text, which the selection parses the same way.
    """
    from ..selection import SelectionError, parse_range

    try:
        parse_range(text, "--theta-i-range")
    except SelectionError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--theta-i-range ")) from None
    return text


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

#: what ``--theta-i`` says in a command that selects rows (it has no single angle)
_THETA_I_IS_AN_ANGLE = (
    "--theta-i DEG is an angle of incidence (export, hemispherical, trace); "
    "select a range of rows with --theta-i-range MIN:MAX"
)


def _add_selection(p: argparse.ArgumentParser, *, wavelength_taken: bool = False) -> None:
    """The row-selection options; ``--wavelength`` is refused unless the command has one.

    ``--theta-i`` is always refused here, naming ``--theta-i-range``: in the commands that
    have one it is an angle of incidence, never a range of rows.
    """
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
    g.add_argument(
        "--theta-i-range",
        type=_row_range,
        default=None,
        metavar="MIN:MAX",
        help="[deg], e.g. 40:60 (or one angle, e.g. 45)",
    )
    g.add_argument("--theta-i", action=_Renamed, new=_THETA_I_IS_AN_ANGLE)
    g.add_argument("--theta-r", default=None, metavar="MIN:MAX", help="[deg], e.g. :70")
    g.add_argument("--quantity", default=None, help="comma-separated quantities")
    g.add_argument("--sample", default=None, help="comma-separated sample names")


def _selected(args: argparse.Namespace, m: Any) -> Any:
    """The Measurement ``m`` restricted to the selection options (meta kept)."""
    from ..dataset import Measurement
    from ..selection import select

    chosen = _selection(args)
    if not chosen:
        return m
    return Measurement(select(m, **chosen), m.meta)


#: the selection options: argparse destination -> :func:`labbrdf.selection.select` keyword
SELECTION_KEYS = {
    "wavelength_range": "wavelength",
    "theta_i_range": "theta_i",
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


def _channel(text: str | None) -> int | str | None:
    """``--channel``: an index (digits) or a name."""
    return int(text) if text and text.isdigit() else text


def _pixel_size(args: argparse.Namespace) -> tuple[float, ...] | None:
    """``--pixel-size LENGTH[,LENGTH]`` in metres (``--unit`` for bare numbers)."""
    from ..adapters.topography import length_m

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
    "medium": "--medium",
}


@contextlib.contextmanager
def _option_errors() -> Iterator[None]:
    """Library errors about arguments, said with the options' names (exit 2)."""
    from ..errors import SetupError
    from ..nk import NkError

    try:
        yield
    except SetupError as exc:
        raise UsageError(exc.spelled(OPTION_NAMES)) from None
    except NkError as exc:
        raise UsageError(f"--nk-from {exc}") from None


def _model_from_args(args: argparse.Namespace) -> tuple[Any, dict[str, float]]:
    """Build the model of ``--model`` and return it with the ``--param`` parameter values.

    Model options come from ``--param`` (and ``--nk-from``'s n, k at ``--wavelength``).
    """
    from .. import models
    from ..nk import model_with_nk

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
