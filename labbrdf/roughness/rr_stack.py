"""Rayleigh-Rice scatter of a thin-film stack whose interfaces are rough.

First-order vector perturbation theory for a coherent multilayer (Elson 1984; Germer's
roughness-stack models in NIST SCATMECH): each rough interface is a sheet of polarization
``(eps_below - eps_above) h_j(x, y)`` driven by the field the incident plane wave sets up
in the smooth stack; by reciprocity its far field in the direction ``k_s`` is the overlap
of that field with the field a plane wave arriving from ``k_s`` sets up at the same
interface. Physics layer: NumPy only. Derivation, conventions and the checks:
``docs/rayleigh-rice.md`` (section *Film stacks with rough interfaces*).

For interface ``j`` (between media ``a`` above and ``b`` below, ``Delta eps_j = eps_b -
eps_a``) the polarization factors that replace
``labbrdf.roughness.rayleigh_rice.jones_factors`` are, with ``E_y`` (s), ``E_x`` and
``H_y`` (p) the tangential fields at the interface of unit-amplitude plane waves from the
incident (superscript i) and the scatter (superscript s) directions,
``phi_s = phi_r - pi``::

    q_ss = K E_y^i E_y^s cos phi_s
    q_ps = -K E_x^i E_y^s sin phi_s                         (p -> s)
    q_sp = -K E_y^i E_x^s sin phi_s                         (s -> p)
    q_pp = K [sin ti sin ts H_y^i H_y^s / (eps_a eps_b) - E_x^i E_x^s cos phi_s]
    K = Delta eps_j / (4 cos ti cos ts)

(the normal field enters through ``D_z = -sin theta H_y``, continuous like the tangential
ones, so no field is evaluated on one side of an interface). For one interface these are
Germer's (1997) eqs. (4)-(7) exactly; for a stack the fields carry the phase of each
interface's depth. The Jones matrix of interface ``j`` is ``sqrt(16 pi^2 cos ti cos ts
PSD_j / lambda^4) q_j``:

* ``correlated``: every interface has the same heights ``h(x, y)`` (a conformal coating):
  the amplitudes add, ``q = sum_j q_j``, with one PSD (SCATMECH's
  ``Correlated_Roughness_Stack_BRDF_Model``);
* ``uncorrelated``: independent heights: the Mueller matrices add, each interface with its
  own PSD (SCATMECH's ``Uncorrelated_Roughness_Stack_BRDF_Model`` when all PSDs are equal,
  ``Roughness_Stack_BRDF_Model`` when only one interface is rough).

Conventions are those of :mod:`labbrdf.roughness.rayleigh_rice` (LB, ``exp(-i omega t)``,
``N = n + ik``, ambient index 1, lengths in metres). The stack is given top first:
``indices = [1, N_1, ..., N_M, N_substrate]``, ``thicknesses = [d_1, ..., d_M]``;
interface 0 is the ambient's, interface ``M`` the substrate's.

References
----------
.. [1] J. M. Elson, "Theory of light scattering from a rough surface with an
   inhomogeneous dielectric permittivity", Phys. Rev. B 30, 5460-5480 (1984).
.. [2] T. A. Germer, Appl. Opt. 36, 8798-8805 (1997), eqs. (3)-(7) (the single interface).
.. [3] C. Amra, "Light scattering from multilayer optics. I. Tools of investigation",
   J. Opt. Soc. Am. A 11, 197-210 (1994) (correlated and uncorrelated interfaces).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..films.graded import Graded
from ..films.stack import Stack
from .rayleigh_rice import (
    POLARIZATIONS,
    Polarization,
    PsdFunction,
    _angles,
    _mueller_from_jones,
    _psd_at,
    _root,
    _wavelength,
    bragg_frequencies,
)

__all__ = [
    "CORRELATIONS",
    "INTERFACES",
    "interface_factors",
    "mueller_brdf_stack",
    "stack_brdf",
    "stack_fields",
    "stack_layers",
]

#: how the interfaces' heights relate: the same heights (amplitudes add) or independent
CORRELATIONS = ("uncorrelated", "correlated")

#: which interfaces of a stack are rough (:func:`stack_brdf`): all, the same heights; all,
#: independent heights of the same PSD; only the substrate's; only the top (ambient's)
INTERFACES = ("correlated", "uncorrelated", "substrate", "top")

Correlation = Literal["uncorrelated", "correlated"]


def _stack(
    indices: ArrayLike, thicknesses: ArrayLike
) -> tuple[NDArray[np.complex128], NDArray[np.float64]]:
    n = np.asarray(indices, dtype=complex).ravel()
    d = np.asarray(thicknesses, dtype=float).ravel()
    if n.size < 2 or d.size != n.size - 2:
        raise ValueError(
            "expected indices [ambient, layer 1..M, substrate] and M thicknesses; got "
            f"{n.size} indices and {d.size} thicknesses"
        )
    if n[0] != 1.0:
        raise ValueError(f"the ambient index must be 1 (vacuum/air); got {n[0]!r}")
    bad = ~np.isfinite(n) | (n.real < 0) | (n.imag < 0) | (n == 0)
    if np.any(bad):
        raise ValueError(f"indices must be finite n + ik with n >= 0, k >= 0, N != 0; got {n!r}")
    if np.any(~np.isfinite(d)) or np.any(d < 0):
        raise ValueError(f"thicknesses must be finite and >= 0 [m]; got {d!r}")
    return n, d


def stack_fields(
    theta: ArrayLike, wavelength: float, indices: ArrayLike, thicknesses: ArrayLike
) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]]:
    """Tangential fields at every interface of a unit plane wave incident from the ambient.

    The characteristic-matrix solution (Born & Wolf, *Principles of Optics*, sec. 1.6) of
    the smooth stack, started from the substrate's down-going wave and normalised to a
    unit incident amplitude (``E`` for s, ``H = E`` for p in the ambient of index 1).

    Parameters
    ----------
    theta : array_like
        Angle of incidence in the ambient [rad].
    wavelength : float
        Vacuum wavelength [m].
    indices, thicknesses : array_like
        ``[1, N_1, ..., N_substrate]`` [1] and ``[d_1, ..., d_M]`` [m], top first.

    Returns
    -------
    (E_y, E_x, H_y) : ndarray of complex, shape ``theta.shape + (M + 1,)``
        ``E_y`` of the s wave, ``E_x`` and ``H_y`` of the p wave at interfaces 0..M [1];
        ``E_x`` is ``+(g / eps) H_y`` for a down-going wave, ``g = sqrt(eps - sin^2)``.
    """
    n, d = _stack(indices, thicknesses)
    k0 = 2.0 * math.pi / _wavelength(wavelength)
    t = np.asarray(theta, dtype=float)
    s2 = np.sin(t)[..., None] ** 2
    eps = n * n
    g = _root(eps - s2 + 0j)  # (..., M + 2)
    out = []
    for gamma in (g, g / eps):  # s: (E_y, dE_y/dz / ik0); p: (H_y, dH_y/dz / (ik0 eps))
        u = np.ones(t.shape, complex)
        v = -gamma[..., -1] * u
        us, vs = [u], [v]
        for j in range(d.size - 1, -1, -1):  # upwards through layer j + 1
            phase = k0 * g[..., j + 1] * d[j]
            c, s, gj = np.cos(phase), np.sin(phase), gamma[..., j + 1]
            u, v = c * u + 1j * s / gj * v, 1j * gj * s * u + c * v
            us.append(u)
            vs.append(v)
        u_i, v_i = np.stack(us[::-1], -1), np.stack(vs[::-1], -1)
        a = 0.5 * (u_i[..., 0] - v_i[..., 0] / gamma[..., 0])  # incident amplitude
        out.append((u_i / a[..., None], v_i / a[..., None]))
    (ey, _), (hy, vp) = out
    return ey, -vp, hy


def interface_factors(
    theta_i: ArrayLike,
    theta_r: ArrayLike,
    phi_r: ArrayLike,
    wavelength: float,
    indices: ArrayLike,
    thicknesses: ArrayLike,
) -> NDArray[np.complex128]:
    """The polarization factors ``[[q_ss, q_ps], [q_sp, q_pp]]`` of every interface [1].

    Module docstring; for one interface (no layers) they equal
    ``labbrdf.roughness.rayleigh_rice.jones_factors``.

    Parameters
    ----------
    theta_i, theta_r, phi_r : array_like
        Incidence, scatter polar angle and outward scatter azimuth (specular at pi) [rad].
    wavelength : float
        Vacuum wavelength [m].
    indices, thicknesses : array_like
        ``[1, N_1, ..., N_substrate]`` [1] and ``[d_1, ..., d_M]`` [m], top first.

    Returns
    -------
    ndarray of complex, shape ``broadcast + (M + 1, 2, 2)``
        Interface 0 (ambient / top layer) first.
    """
    ti, tr, pr = _angles(theta_i, theta_r, phi_r)
    n, d = _stack(indices, thicknesses)
    eps = n * n
    ey_i, ex_i, hy_i = stack_fields(ti, wavelength, n, d)
    ey_s, ex_s, hy_s = stack_fields(tr, wavelength, n, d)
    ps = (pr - math.pi)[..., None]
    cp, sp = np.cos(ps), np.sin(ps)
    k = (eps[1:] - eps[:-1]) / (4.0 * np.cos(ti) * np.cos(tr))[..., None]
    normal = (np.sin(ti) * np.sin(tr))[..., None] / (eps[1:] * eps[:-1])
    q = np.empty((*k.shape, 2, 2), dtype=complex)
    q[..., 0, 0] = k * ey_i * ey_s * cp
    q[..., 0, 1] = -k * ex_i * ey_s * sp
    q[..., 1, 0] = -k * ey_i * ex_s * sp
    q[..., 1, 1] = k * (normal * hy_i * hy_s - ex_i * ex_s * cp)
    return q


def _psds(psd2d: PsdFunction | Sequence[PsdFunction | None], m: int) -> list[PsdFunction | None]:
    if callable(psd2d):
        return [psd2d] * m
    out = list(psd2d)
    if len(out) != m:
        raise ValueError(f"expected one PSD (or None: smooth) per interface, {m}; got {len(out)}")
    return out


def mueller_brdf_stack(
    theta_i: ArrayLike,
    theta_r: ArrayLike,
    phi_r: ArrayLike,
    wavelength: float,
    indices: ArrayLike,
    thicknesses: ArrayLike,
    psd2d: PsdFunction | Sequence[PsdFunction | None],
    correlation: Correlation = "uncorrelated",
) -> NDArray[np.float64]:
    """The Mueller BRDF (..., 4, 4) [sr^-1] of a film stack with rough interfaces.

    Parameters
    ----------
    theta_i, theta_r, phi_r : array_like
        Incidence, scatter polar angle and outward scatter azimuth (specular at pi) [rad].
    wavelength : float
        Vacuum wavelength [m].
    indices, thicknesses : array_like
        ``[1, N_1, ..., N_substrate]`` [1] and ``[d_1, ..., d_M]`` [m], top first.
    psd2d : callable or sequence
        The 2-D PSD [m^4] of every interface (``psd2d(fx, fy)``), or, uncorrelated only,
        one per interface (top first; ``None`` for a smooth one).
    correlation : {"uncorrelated", "correlated"}
        Independent heights (Mueller matrices add) or the same heights at every interface
        (Jones matrices add; one PSD).

    Returns
    -------
    ndarray
        ``f_M`` in the LB frames; ``[..., 0, 0]`` is the unpolarized BRDF.

    Notes
    -----
    Valid where the single-interface Rayleigh-Rice is (``4 pi sigma cos theta / lambda <<
    1`` for every interface, small slopes), for coherent layers; the specular beam is not
    included.
    """
    if correlation not in CORRELATIONS:
        raise ValueError(f"correlation must be one of {CORRELATIONS}, got {correlation!r}")
    ti, tr, pr = _angles(theta_i, theta_r, phi_r)
    lam = _wavelength(wavelength)
    q = interface_factors(ti, tr, pr, lam, indices, thicknesses)
    fx, fy = bragg_frequencies(ti, tr, pr, lam)
    scale = 16.0 * math.pi**2 / lam**4 * np.cos(ti) * np.cos(tr)
    psds = _psds(psd2d, q.shape[-3])
    if correlation == "correlated":
        if not callable(psd2d):
            raise ValueError("correlated interfaces share one PSD: give one psd2d")
        m = _mueller_from_jones(q.sum(axis=-3))
        return (scale * _psd_at(psd2d, fx, fy))[..., None, None] * m
    out = np.zeros((*ti.shape, 4, 4))
    for j, psd in enumerate(psds):
        if psd is not None:
            w = scale * _psd_at(psd, fx, fy)
            out += w[..., None, None] * _mueller_from_jones(q[..., j, :, :])
    return out


def stack_layers(
    stack: Stack, wavelength_nm: float
) -> tuple[NDArray[np.complex128], NDArray[np.float64]]:
    """A film stack's ``[1, N_1, ..., N_substrate]`` [1] and thicknesses [m] at one wavelength.

    Parameters
    ----------
    stack : labbrdf.films.Stack
        Coherent layers (no incoherent layer, finite substrate, thickness spread or graded
        layer: their interfaces are not single sharp surfaces), ambient of index 1.
    wavelength_nm : float
        Vacuum wavelength [nm].

    Raises
    ------
    ValueError
        A stack this theory does not describe, naming what is wrong.
    """
    if not stack.coherent:
        raise ValueError(
            "the stack has an incoherent layer, a finite substrate or a thickness spread; "
            "Rayleigh-Rice of rough interfaces needs coherent layers on a semi-infinite substrate"
        )
    graded = [lay.name for lay in stack.layers if isinstance(lay.material, Graded)]
    if graded:
        raise ValueError(f"graded layers {graded} have no sharp interface to be rough")
    idx = [complex(np.asarray(n).reshape(-1)[0]) for n in stack.indices(float(wavelength_nm))]
    if idx[0] != 1.0:
        raise ValueError(f"the stack's ambient index is {idx[0]:.6g}; expected 1 (vacuum/air)")
    d = np.array([lay.thickness_nm for lay in stack.layers], dtype=float) * 1e-9
    return np.array(idx, dtype=complex), d


def stack_brdf(
    theta_i: ArrayLike,
    theta_r: ArrayLike,
    phi_r: ArrayLike,
    wavelength: float,
    indices: ArrayLike,
    thicknesses: ArrayLike,
    psd2d: PsdFunction,
    interfaces: str = "correlated",
    polarization: Polarization = "unpolarized",
) -> NDArray[np.float64]:
    """The BRDF [sr^-1] of a stack for one incident polarization, all scattered light.

    Parameters
    ----------
    theta_i, theta_r, phi_r, wavelength, indices, thicknesses
        As :func:`mueller_brdf_stack`.
    psd2d : callable
        The 2-D PSD [m^4] of every rough interface.
    interfaces : {"correlated", "uncorrelated", "substrate", "top"}
        :data:`INTERFACES`: every interface rough with the same heights, every interface
        rough with independent heights, or only the substrate's or the top interface rough.
    polarization : {"unpolarized", "s", "p"}
        ``M00``, ``M00 + M01`` or ``M00 - M01`` of the Mueller BRDF (``S1 = +1`` for s).
    """
    if interfaces not in INTERFACES:
        raise ValueError(f"interfaces must be one of {INTERFACES}, got {interfaces!r}")
    if polarization not in POLARIZATIONS:
        raise ValueError(f"polarization must be one of {POLARIZATIONS}, got {polarization!r}")
    m_if = np.asarray(indices).size - 1
    psds: PsdFunction | list[PsdFunction | None] = psd2d
    corr: Correlation = "correlated" if interfaces == "correlated" else "uncorrelated"
    if interfaces in ("substrate", "top"):
        psds = [None] * m_if
        psds[-1 if interfaces == "substrate" else 0] = psd2d
    m = mueller_brdf_stack(theta_i, theta_r, phi_r, wavelength, indices, thicknesses, psds, corr)
    sign = {"unpolarized": 0.0, "s": 1.0, "p": -1.0}[polarization]
    return np.asarray(m[..., 0, 0] + sign * m[..., 0, 1])
