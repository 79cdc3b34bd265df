"""A fit with and without the instrument's aperture, and how far the parameters move.

Workflow layer: fits a model twice (:func:`labbrdf.fitting.fit`), once as it is and once
seen through the detector's cone and the beam's divergence
(:class:`labbrdf.models.aperture.Apertured`), and tabulates the two estimates. Where they
differ by more than their standard errors, a fit that ignores the aperture has put the
instrument's width into the sample's parameters.

:func:`stated_aperture` takes the aperture a file states (``Measurement.meta["aperture"]``)
and :func:`compare_groups` pairs the per-group fits of :func:`labbrdf.fitting.fit_many`
made with and without it (the ``labbrdf fit --aperture`` report).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import pandas as pd

from ..dataset import Measurement
from ..errors import LabbrdfError
from ..models import Model
from ..models import get as get_model
from ..models.aperture import MAX_APERTURE_DEG, Apertured
from .core import fit
from .result import FitResult

__all__ = [
    "Aperture",
    "ApertureComparison",
    "ApertureError",
    "compare_groups",
    "fit_with_aperture",
    "stated_aperture",
]


class ApertureError(LabbrdfError, ValueError):
    """An aperture that cannot be used: out of range, or stated differently by two files."""


@dataclass(frozen=True)
class Aperture:
    """The instrument's aperture used in a fit, and where it came from.

    Attributes
    ----------
    detector_deg, beam_deg : float
        Half-angles of the detector's cone and of the beam's divergence [deg], each in
        [0, ``labbrdf.models.aperture.MAX_APERTURE_DEG``].
    source : str
        Where the values came from (``"--aperture"``, ``"stated by FILE"`` ...).
    """

    detector_deg: float
    beam_deg: float = 0.0
    source: str = "given"

    def __post_init__(self) -> None:
        for name in ("detector_deg", "beam_deg"):
            v = getattr(self, name)
            if not (isinstance(v, int | float) and math.isfinite(v)):
                raise ApertureError(f"aperture {name}={v!r} ({self.source}): expected a number")
            if not 0.0 <= v <= MAX_APERTURE_DEG:
                raise ApertureError(
                    f"aperture {name}={v:g} deg ({self.source}): expected a half-angle in "
                    f"[0, {MAX_APERTURE_DEG:g}] deg"
                )

    @property
    def active(self) -> bool:
        """True unless both cones are 0 (a fit without the aperture)."""
        return self.detector_deg > 0 or self.beam_deg > 0

    def options(self) -> dict[str, float]:
        """The model options that apply it (:data:`labbrdf.models.APERTURE_OPTIONS`)."""
        if not self.active:
            return {}
        return {"detector_deg": float(self.detector_deg), "beam_deg": float(self.beam_deg)}

    def __str__(self) -> str:
        if not self.active:
            return f"aperture: none ({self.source})"
        return (
            f"aperture: detector {self.detector_deg:g} deg, beam {self.beam_deg:g} deg "
            f"(half-angles; {self.source})"
        )


def _stated(meta: dict[str, Any]) -> tuple[float, float] | None:
    ap = meta.get("aperture")
    if not ap:
        return None
    return float(ap.get("detector_deg", 0.0)), float(ap.get("beam_deg", 0.0))


def stated_aperture(data: Measurement) -> Aperture | None:
    """The aperture the data's files state (``meta["aperture"]``), or None.

    Parameters
    ----------
    data : Measurement
        One file's measurement or a concatenation (``meta["parts"]``).

    Returns
    -------
    Aperture or None
        None when no file states one.

    Raises
    ------
    ApertureError
        The files state different apertures, or some state one and others none (a fit of
        them together would apply one file's aperture to another's points).
    """
    parts = data.meta.get("parts") or [{"source": _source(data), "meta": data.meta}]
    stated = {str(p.get("source")): _stated(p.get("meta") or {}) for p in parts}
    values = set(stated.values())
    if values == {None}:
        return None
    if len(values) > 1:
        shown = "; ".join(
            f"{src}: {'none' if v is None else f'{v[0]:g}, {v[1]:g} deg'}"
            for src, v in stated.items()
        )
        raise ApertureError(
            f"the files state different apertures ({shown}); fit them separately or give "
            "--aperture DETECTOR_DEG[,BEAM_DEG] for all"
        )
    (value,) = values
    assert value is not None
    names = ", ".join(sorted(stated))
    return Aperture(value[0], value[1], source=f"stated by {names}")


def _source(data: Measurement) -> str:
    if "source" in data.data.columns and len(data.data):
        return ", ".join(sorted(set(map(str, data.data["source"]))))
    return "the data"


@dataclass
class ApertureComparison:
    """The fits without and with the aperture, and the shift of each parameter.

    Attributes
    ----------
    plain, apertured : FitResult
        The model fitted as it is, and averaged over the aperture.
    detector_deg, beam_deg : float
        The aperture's half-angles [deg].
    """

    plain: FitResult
    apertured: FitResult
    detector_deg: float
    beam_deg: float

    def table(self) -> pd.DataFrame:
        """One row per varying parameter.

        Columns ``without``, ``stderr_without``, ``with``, ``stderr_with`` (the two
        estimates and their standard errors, in the parameter's units), ``shift`` =
        without - with, ``shift_rel`` = shift / with, and ``shift_sigma`` = shift over the
        standard error of the apertured fit.
        """
        rows = []
        for k, q in self.apertured.params.items():
            if not q.vary:
                continue
            p = self.plain.params[k]
            shift = p.value - q.value
            rows.append(
                {
                    "parameter": k,
                    "without": p.value,
                    "stderr_without": p.stderr,
                    "with": q.value,
                    "stderr_with": q.stderr,
                    "shift": shift,
                    "shift_rel": shift / q.value if q.value else float("nan"),
                    "shift_sigma": shift / q.stderr if q.stderr else float("nan"),
                }
            )
        return pd.DataFrame(rows).set_index("parameter")

    def shifts(self) -> dict[str, dict[str, float | None]]:
        """:meth:`table` as plain values, per parameter (JSON-ready, NaN as None)."""
        out: dict[str, dict[str, float | None]] = {}
        for name, row in self.table().iterrows():
            out[str(name)] = {
                k: (None if v is None or not math.isfinite(float(v)) else float(v))
                for k, v in row.items()
            }
        return out

    def __str__(self) -> str:
        head = (
            f"aperture: detector {self.detector_deg:g} deg, beam {self.beam_deg:g} deg "
            f"(half-angles); chi2/nu without {self.plain.redchi:.4g}, with "
            f"{self.apertured.redchi:.4g}"
        )
        return head + "\n" + self.table().to_string(float_format=lambda v: f"{v:.5g}")


def fit_with_aperture(
    model: Model | str,
    data: Any,
    *,
    detector_deg: float,
    beam_deg: float = 0.0,
    nodes: tuple[int, int] = (8, 24),
    **fit_kw: Any,
) -> ApertureComparison:
    """Fit ``model`` to ``data`` without and with the instrument's aperture.

    Parameters
    ----------
    model : Model or str
        The sample's model or a registry name.
    data : Measurement, DataFrame or FitData
        As for :func:`labbrdf.fitting.fit`.
    detector_deg, beam_deg : float
        Half-angles of the detector's cone and of the beam's divergence [deg]
        (:class:`labbrdf.models.aperture.Apertured`).
    nodes : tuple of int
        The cap quadrature's ``(n_t, n_psi)``.
    **fit_kw
        Passed to both fits (``weighting``, ``mask_zeros``, ``fix`` ...).

    Returns
    -------
    ApertureComparison
        ``apertured`` is the estimate of the sample; ``table()`` says how far the
        parameters move.
    """
    m = get_model(model) if isinstance(model, str) else model
    plain = fit(m, data, **fit_kw)
    wrapped = Apertured(m, detector_deg=detector_deg, beam_deg=beam_deg, nodes=nodes)
    return ApertureComparison(plain, fit(wrapped, data, **fit_kw), detector_deg, beam_deg)


def compare_groups(
    plain: Sequence[tuple[dict[str, Any], FitResult]],
    apertured: Sequence[tuple[dict[str, Any], FitResult]],
    aperture: Aperture,
) -> list[tuple[dict[str, Any], ApertureComparison]]:
    """Pair the per-group fits without and with the aperture (same group keys).

    Parameters
    ----------
    plain, apertured : sequence of (dict, FitResult)
        ``fit_many(..., return_results=True)[1]`` of the two fits; a group fitted in only
        one of them is left out.
    aperture : Aperture
        The aperture of the second.

    Returns
    -------
    list of (dict, ApertureComparison)
        In the order of ``apertured``.
    """
    without = {_key(k): r for k, r in plain}
    out = []
    for key, res in apertured:
        other = without.get(_key(key))
        if other is not None:
            cmp = ApertureComparison(other, res, aperture.detector_deg, aperture.beam_deg)
            out.append((key, cmp))
    return out


def _key(key: dict[str, Any]) -> tuple[tuple[str, str], ...]:
    return tuple(sorted((k, repr(v)) for k, v in key.items()))
