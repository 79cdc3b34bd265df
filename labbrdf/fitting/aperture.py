"""A fit with and without the instrument's aperture, and how far the parameters move.

Workflow layer: fits a model twice (:func:`labbrdf.fitting.fit`), once as it is and once
seen through the detector's cone and the beam's divergence
(:class:`labbrdf.models.aperture.Apertured`), and tabulates the two estimates. Where they
differ by more than their standard errors, a fit that ignores the aperture has put the
instrument's width into the sample's parameters.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import pandas as pd

from ..models import Model
from ..models import get as get_model
from ..models.aperture import Apertured
from .core import fit
from .result import FitResult

__all__ = ["ApertureComparison", "fit_with_aperture"]


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
