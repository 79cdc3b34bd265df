"""Measured against predicted values: the chi-square test of their z scores.

One test and one significance level for every section that sets a measurement against a
prediction from another file (``nk``: Fresnel reflectance from n, k; ``film``: the fitted
stack's reflectance).
"""

from __future__ import annotations

import numpy as np
from scipy import stats

__all__ = ["P_AGREE", "chi_square"]

#: significance level of the reflectance-agreement check (chi-square test of the z scores)
P_AGREE = 1e-3


def chi_square(z: np.ndarray) -> tuple[int, float, float]:
    """Points, chi-square and p-value of the finite z scores (z = difference / sigma).

    Parameters
    ----------
    z : ndarray
        z scores [1]; NaN and infinite ones are left out.

    Returns
    -------
    (int, float, float)
        Number of finite z, their sum of squares, and the chi-square survival function at
        it with that many degrees of freedom (NaN when there is none).
    """
    ok = np.isfinite(z)
    nz = int(ok.sum())
    chi2 = float(np.sum(z[ok] ** 2))
    p = float(stats.chi2.sf(chi2, nz)) if nz else float("nan")
    return nz, chi2, p
