"""Degree of polarization of the specular reflection for unpolarized light, from psi.

Physics layer (NumPy only). For unpolarized incident light the specular reflection of an
isotropic, non-depolarizing sample is partially polarized with

    DOP = |cos 2 psi|,

and an ellipsometer's depolarization channel lowers that, under a stated model of how the
depolarizing part acts. This is the measured side of the comparison in Dong et al. (2022)
Fig. 6 (an imaging ellipsometer's DOP beside the traced pBRDF's); the derivation is in
``docs/ellipsometry.md`` section "Specular DOP for unpolarized light".

Derivation
----------
The normalized Mueller matrix of an isotropic non-depolarizing reflector is (Fujiwara
2007, eq. (3.107), Woollam's sign of the first row)

    M / M11 = [[1, -N, 0, 0], [-N, 1, 0, 0], [0, 0, C, S], [0, 0, -S, C]],
    N = cos 2psi,  C = sin 2psi cos Delta,  S = sin 2psi sin Delta.

Unpolarized light ``[1, 0, 0, 0]`` leaves as ``M11 [1, -N, 0, 0]``: its DOP,
``sqrt(S1^2 + S2^2 + S3^2) / S0``, is ``|N| = |cos 2psi|``, whatever Delta. labbrdf's own
Mueller convention (:func:`labbrdf.optics.mueller_reflection`) has ``m12 = +cos 2psi``;
the sign of S1 does not change the DOP.

With depolarization
-------------------
Woollam's WVASE / CompleteEASE ``Depolarization`` [%] and Film Sense's ``1 - P`` are the
same quantity ``d = 1 - P``: P is the degree of polarization of the reflected beam for the
instrument's incident linear polarization (near 45 deg), ``P = sqrt(N'^2 + C'^2 + S'^2)``
with N', C', S' the measured normalized Stokes components. A non-depolarizing sample has
``N^2 + C^2 + S^2 = 1`` and ``d = 0``. Two models of the depolarizing part bracket what it
does to m12, and so to the DOP for unpolarized light:

``"mixed"`` (default): a partial ideal depolarizer mixed in with weight d,
    ``M = M11 [(1 - d) M_nd + d diag(1, 0, 0, 0)]``. The 45-deg input then leaves as
    ``[1, -(1 - d) N, (1 - d) C, (1 - d) S]``, so ``P = 1 - d`` (the file's d is the
    weight), ``m12 = -(1 - d) cos 2psi`` and ``DOP = (1 - d) |cos 2psi|``. The file's psi
    is taken as that of the polarized part (the vendors report psi, Delta and d as separate
    channels and fit psi, Delta with d beside them).

``"retardance"``: the depolarization comes from a spread of Delta only (film thickness
    non-uniformity, spectral bandwidth or angular spread over which psi barely changes):
    averaging over the spread shrinks C and S but leaves N, so ``m12 = -cos 2psi`` and
    ``DOP = |cos 2psi|``, the upper bound.

Uncertainty (first order, psi and d independent):

    sigma_DOP^2 = ((1 - d) 2 |sin 2psi| sigma_psi)^2 + (|cos 2psi| sigma_d)^2,

sigma_psi in radians (only the first term for ``"retardance"``). At psi = 45 deg the DOP
has a kink (|cos 2psi| folds at 0); the first-order sigma there is the half-width of the
folded distribution's linear part, not its standard deviation.

References
----------
.. [1] H. Fujiwara, *Spectroscopic Ellipsometry: Principles and Applications*, Wiley
   (2007), sections 3.4 (Stokes and Mueller matrices of a sample) and 4.4.4
   (depolarization measured by rotating-compensator ellipsometry).
.. [2] Dong Z. et al., Acta Optica Sinica 42(22), 2224001 (2022), eq. (13) (DOP) and Fig. 6.
"""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["DEPOLARIZERS", "SpecularDOP", "specular_dop"]

#: the models of the depolarizing part (module docstring)
DEPOLARIZERS = ("mixed", "retardance")


class SpecularDOP(NamedTuple):
    """DOP of the specular reflection for unpolarized light and its 1-sigma error [1]."""

    dop: NDArray[np.float64]
    sigma: NDArray[np.float64]


def _array(name: str, value: ArrayLike, lo: float, hi: float, unit: str) -> NDArray[np.float64]:
    a = np.asarray(value, dtype=float)
    bad = ~np.isfinite(a) | (a < lo) | (a > hi)
    if np.any(bad):
        v = a[bad].ravel()[:3].tolist()
        raise ValueError(f"{name}: expected finite values in [{lo:g}, {hi:g}] {unit}, got {v}")
    return a


def specular_dop(
    psi_deg: ArrayLike,
    *,
    psi_sigma_deg: ArrayLike = 0.0,
    depolarization: ArrayLike = 0.0,
    depolarization_sigma: ArrayLike = 0.0,
    depolarizer: Literal["mixed", "retardance"] = "mixed",
) -> SpecularDOP:
    """DOP of the specular reflection of unpolarized light from psi (and depolarization).

    Parameters
    ----------
    psi_deg : array_like
        Ellipsometric psi in [0, 90] [deg].
    psi_sigma_deg : array_like, optional
        1-sigma error of psi [deg], >= 0 (0: no error propagated).
    depolarization : array_like, optional
        ``d = 1 - P`` in [0, 1] [fraction] (Woollam ``Depolarization`` / 100, Film Sense
        ``1 - P``; labbrdf's ``depolarization`` quantity). 0: non-depolarizing.
    depolarization_sigma : array_like, optional
        1-sigma error of d [fraction], >= 0.
    depolarizer : {"mixed", "retardance"}
        How the depolarizing part acts (module docstring): a partial ideal depolarizer
        mixed in (``DOP = (1 - d) |cos 2psi|``) or a spread of Delta only
        (``DOP = |cos 2psi|``, d unused).

    Returns
    -------
    SpecularDOP
        ``dop`` and ``sigma`` [1], broadcast over the inputs.

    Raises
    ------
    ValueError
        A value outside its range or not finite, a negative sigma, or an unknown
        ``depolarizer``.

    Examples
    --------
    >>> r = specular_dop([0.0, 45.0, 30.0])
    >>> [round(float(v), 12) for v in r.dop]
    [1.0, 0.0, 0.5]
    """
    if depolarizer not in DEPOLARIZERS:
        raise ValueError(f"depolarizer {depolarizer!r}: expected one of {list(DEPOLARIZERS)}")
    psi = np.radians(_array("psi_deg", psi_deg, 0.0, 90.0, "deg"))
    s_psi = np.radians(_array("psi_sigma_deg", psi_sigma_deg, 0.0, np.inf, "deg"))
    d = _array("depolarization", depolarization, 0.0, 1.0, "(fraction)")
    s_d = _array("depolarization_sigma", depolarization_sigma, 0.0, np.inf, "(fraction)")
    psi, s_psi, d, s_d = np.broadcast_arrays(psi, s_psi, d, s_d)
    n = np.abs(np.cos(2.0 * psi))
    slope = 2.0 * np.abs(np.sin(2.0 * psi))
    if depolarizer == "retardance":
        return SpecularDOP(n.astype(float), slope * s_psi)
    keep = 1.0 - d
    sigma = np.hypot(keep * slope * s_psi, n * s_d)
    return SpecularDOP(keep * n, sigma)
