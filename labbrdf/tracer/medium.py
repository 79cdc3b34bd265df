"""A scattering coating: a homogeneous Henyey-Greenstein medium between the interfaces.

Paints, plastics and vinyls scatter inside their clear layer. :class:`Medium` describes a
homogeneous medium filling the coating: its optical thickness ``tau`` (extinction
coefficient times the coating's thickness, along the normal), its single-scattering albedo
``ssa`` and the asymmetry ``g`` of its Henyey-Greenstein phase function [1]_. The walk
(:mod:`labbrdf.tracer.walk`, its crossing of the coating) hands every ray that crosses the
coating to :func:`traverse`, which follows it through the medium until it reaches the top
interface from below or the base from above.

Position-free, as the rest of the walk (Guo et al. 2018 [2]_, the model pbrt-v4's
``LayeredBxDF`` evaluates): the coating is laterally infinite, so a ray's state inside it
is its depth and its direction only. With the depth ``z`` in units of the thickness
(0 at the top, 1 at the base), a free flight of optical length ``s ~ Exp(1)`` changes the
depth by ``s |k_z| / tau``. A flight that would leave the slab ends at the boundary it
reaches; any other ends in a scattering event: the ray's weight is multiplied by ``ssa``
and its new direction is drawn from the HG phase function about the old one. The
coating's own absorption (its ``k``) stays Beer-Lambert along the path length: a flight
of depth change ``dz`` multiplies the weight by ``exp(-a dz / |k_z|)``, ``a = 4 pi k d /
lambda`` (:meth:`labbrdf.tracer.setup.WalkSetup.beer_lambert` for a straight crossing).

Bounded work: once a ray's medium weight falls below :data:`ROULETTE_BELOW` it plays
Russian roulette (survives with probability ``w / ROULETTE_BELOW`` and continues with the
weight ``ROULETTE_BELOW``, unbiased), and a ray still inside after :data:`MAX_EVENTS`
scattering events in one crossing is dropped. ``ssa = 0`` or ``tau = 0`` has no
scattering: the crossing is then the deterministic attenuation
``exp(-(tau + a) / |k_z|)`` and draws no random numbers.

Notes
-----
Polarization: the HG phase function is scalar. A scattered ray keeps only the intensity
row of its Mueller matrix (``M <- diag(1, 0, 0, 0) M``), i.e. the medium fully depolarizes
what it scatters, as the Lambertian base does; an unscattered ray keeps its full Mueller
matrix (extinction is the same for every polarization). A polarizing medium (a Mie or
Rayleigh phase matrix) would need the scattering plane's rotations and is not modelled.
The weight that the event cap drops and a roulette survivor's boost are booked with the
absorbed weight (the crossing reports one loss), so the walk's energy ledger still closes.

References
----------
.. [1] Henyey L. G., Greenstein J. L., "Diffuse radiation in the galaxy", Astrophys. J.
   93, 70-83 (1941) (the phase function). doi:10.1086/144246
.. [2] Guo Y., Hasan M., Zhao S., "Position-free Monte Carlo simulation for arbitrary
   layered BSDFs", ACM Trans. Graph. 37(6), 279 (2018) (free flights in depth between
   the interfaces). doi:10.1145/3272127.3275053
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "MAX_EVENTS",
    "ROULETTE_BELOW",
    "Medium",
    "cross_slab",
    "hg_phase",
    "hg_sample_cos",
    "scatter_directions",
    "traverse",
]

F64 = NDArray[np.float64]

#: scattering events of one ray in one crossing after which it is dropped; a diffusing
#: ray needs about tau^2 events to cross, so tau <= MAX_TAU stays far below it
MAX_EVENTS = 2000
#: medium weight below which a ray plays Russian roulette
ROULETTE_BELOW = 0.1
#: the largest optical thickness accepted
MAX_TAU = 20.0
#: crossings of one ray through the coating in one step (up and down between a Lambertian
#: base and the medium) after which it is dropped
MAX_ROUNDS = 1000


def _num(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


@dataclass(frozen=True)
class Medium:
    """A homogeneous Henyey-Greenstein medium filling the coating.

    Parameters
    ----------
    tau : float
        Optical thickness [1] in [0, 20]: the extinction coefficient times the coating's
        thickness, along the normal (a ray at angle theta to the normal crosses
        ``tau / cos theta`` mean free paths).
    ssa : float
        Single-scattering albedo [1] in [0, 1]: the scattered fraction of the extinction.
    g : float
        Henyey-Greenstein asymmetry [1] in (-1, 1): the mean cosine of the scattering
        angle (0 isotropic, > 0 forward).
    """

    tau: float = 1.0
    ssa: float = 1.0
    g: float = 0.0

    def __post_init__(self) -> None:
        for name, ok, expected in (
            ("tau", _num(self.tau) and 0 <= self.tau <= MAX_TAU, f"in [0, {MAX_TAU:g}]"),
            ("ssa", _num(self.ssa) and 0 <= self.ssa <= 1, "in [0, 1]"),
            ("g", _num(self.g) and -1 < self.g < 1, "in (-1, 1)"),
        ):
            if not ok:
                value = getattr(self, name)
                raise ValueError(
                    f"coating.medium.{name} must be a number {expected}, got {value!r}"
                )

    @property
    def scatters(self) -> bool:
        """Whether any light scatters (``tau > 0`` and ``ssa > 0``)."""
        return self.tau > 0 and self.ssa > 0

    def to_dict(self) -> dict[str, float]:
        """JSON-safe dict."""
        return {"tau": self.tau, "ssa": self.ssa, "g": self.g}

    def describe(self) -> str:
        """One line for people."""
        return f"HG medium tau {self.tau:g}, albedo {self.ssa:g}, g {self.g:g}"


def hg_phase(cos_theta: ArrayLike, g: float) -> F64:
    """Henyey-Greenstein phase function [sr^-1] ([1]_, normalised over 4 pi sr).

    ``p = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^(3/2))``, ``theta`` the angle
    between the travel directions before and after the event.
    """
    c = np.asarray(cos_theta, float)
    return np.asarray(
        (1.0 - g * g) / (4.0 * np.pi * (1.0 + g * g - 2.0 * g * c) ** 1.5), dtype=float
    )


def hg_sample_cos(g: float, u: F64) -> F64:
    """Cosines of HG scattering angles from uniforms ``u`` in [0, 1) (exact inverse CDF).

    The CDF of ``mu = cos theta`` is ``F(mu) = (1 - g^2) / (2 g) ((1 + g^2 - 2 g mu)^(-1/2)
    - (1 + g)^(-1))``, whose inverse is ``mu = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g u))^2)
    / (2 g)`` (``u = 0`` gives ``mu = -1``). Below ``|g| = 1e-6`` that form cancels; there
    ``mu = mu0 + 3 g (1 - mu0^2) / 2`` with ``mu0 = 2 u - 1`` (the inverse of F to first
    order in g, exact for g = 0; the neglected term is O(g^2) < 1e-12).
    """
    if abs(g) < 1e-6:
        mu0 = 2.0 * u - 1.0
        return np.clip(mu0 + 1.5 * g * (1.0 - mu0 * mu0), -1.0, 1.0)
    t = (1.0 - g * g) / (1.0 - g + 2.0 * g * u)
    return np.clip((1.0 + g * g - t * t) / (2.0 * g), -1.0, 1.0)


def _basis(k: F64) -> tuple[F64, F64]:
    """Two unit vectors completing ``k`` (3, n) to a right-handed orthonormal frame.

    The branch-free frame of Duff et al., "Building an orthonormal basis, revisited",
    JCGT 6(1) 2017 (continuous except where ``k_z`` changes sign).
    """
    sign = np.where(k[2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + k[2])
    b = k[0] * k[1] * a
    t1 = np.stack([1.0 + sign * k[0] * k[0] * a, sign * b, -sign * k[0]])
    t2 = np.stack([b, sign + k[1] * k[1] * a, -k[1]])
    return t1, t2


def scatter_directions(k: F64, mu: F64, phi: F64) -> tuple[F64, F64]:
    """New directions at angle ``arccos mu`` to ``k`` (3, n), azimuth ``phi`` [rad].

    Returns the unit directions (3, n) and a unit Stokes-frame axis perpendicular to each.
    """
    t1, t2 = _basis(k)
    st = np.sqrt(np.clip(1.0 - mu * mu, 0.0, None))
    kn = mu * k + st * (np.cos(phi) * t1 + np.sin(phi) * t2)
    kn = kn / np.sqrt((kn * kn).sum(axis=0))
    return kn, _basis(kn)[0]


@dataclass
class Crossing:
    """The outcome of :func:`cross_slab` for each ray (one column each)."""

    k: F64  # (3, n) direction at the boundary reached
    s: F64  # (3, n) Stokes frame axis (the input's where not scattered)
    weight: F64  # (n,) medium weight: Beer-Lambert, ssa per event, roulette (0: dropped)
    scattered: NDArray[np.bool_]  # at least one event: depolarized
    up: NDArray[np.bool_]  # reached the top (from below); else the base (or dropped)
    events: NDArray[np.int64]  # scattering events


def cross_slab(medium: Medium, a_abs: float, k: F64, s: F64, rng: np.random.Generator) -> Crossing:
    """Carry rays across the slab from the interface they leave to the one they reach.

    Parameters
    ----------
    medium : Medium
    a_abs : float
        Absorption optical thickness [1] of the coating's own ``k`` along the normal,
        ``4 pi k d / lambda``.
    k, s : ndarray (3, n)
        Directions (``k_z < 0``: starting down from the top, ``> 0``: up from the base)
        and Stokes frame axes; not modified.
    rng : numpy.random.Generator
        Draws four uniforms per ray and event (none without scattering).

    Returns
    -------
    Crossing
    """
    n = k.shape[1]
    out = Crossing(
        k=k.copy(),
        s=s.copy(),
        weight=np.ones(n),
        scattered=np.zeros(n, dtype=bool),
        up=k[2] > 0,
        events=np.zeros(n, dtype=np.int64),
    )
    if not medium.scatters:
        out.weight = np.exp(-(medium.tau + a_abs) / np.abs(k[2]))
        return out
    z = np.where(k[2] > 0, 1.0, 0.0)
    act = np.arange(n)
    for _ in range(MAX_EVENTS + 1):
        if act.size == 0:
            return out
        act, z = _flight(medium, a_abs, rng, out, act, z)
    # rays still inside after MAX_EVENTS events: dropped
    out.weight[act] = 0.0
    _park(out.k, out.s, act)
    out.up[act] = True
    return out


def _park(k: F64, s: F64, idx: NDArray[np.int64]) -> None:
    """Dropped rays (weight 0): straight up with a valid frame, to the top from below."""
    k[:, idx] = np.array([[0.0], [0.0], [1.0]])
    s[:, idx] = np.array([[1.0], [0.0], [0.0]])


def _flight(
    medium: Medium,
    a_abs: float,
    rng: np.random.Generator,
    out: Crossing,
    act: NDArray[np.int64],
    z: F64,
) -> tuple[NDArray[np.int64], F64]:
    """One free flight of the rays ``act`` at depths ``z``; returns those still inside."""
    u = rng.random((4, act.size))
    kk = out.k[:, act]
    akz = np.maximum(np.abs(kk[2]), 1e-12)
    dz = -np.log1p(-u[0]) * akz / medium.tau
    down = kk[2] < 0
    room = np.where(down, 1.0 - z, z)
    leave = dz >= room
    step = np.where(leave, room, dz)
    w = out.weight[act] * np.exp(-a_abs * step / akz)
    z = np.where(down, z + step, z - step)
    # leaving: at the boundary it travels towards
    out.up[act[leave]] = ~down[leave]
    # scattering: weight ssa, a new HG direction, roulette
    sc = ~leave
    w = np.where(sc, w * medium.ssa, w)
    i = act[sc]
    mu = hg_sample_cos(medium.g, u[1, sc])
    kn, sn = scatter_directions(kk[:, sc], mu, 2.0 * np.pi * u[2, sc])
    out.k[:, i], out.s[:, i] = kn, sn
    out.scattered[i] = True
    out.events[i] += 1
    low = sc & (w < ROULETTE_BELOW)
    live = np.where(low, u[3] * ROULETTE_BELOW < w, True)
    w = np.where(low, np.where(live, ROULETTE_BELOW, 0.0), w)
    out.weight[act] = w
    dead = act[sc & ~live]
    out.up[dead] = True
    _park(out.k, out.s, dead)
    keep = sc & live
    return act[keep], z[keep]


def traverse(
    medium: Medium,
    a_abs: float,
    rng: np.random.Generator,
    idx: NDArray[np.int64],
    k: F64,
    s: F64,
    M: F64,
    base: Callable[[NDArray[np.int64]], float] | None,
) -> tuple[float, NDArray[np.bool_], NDArray[np.int64]]:
    """The walk's crossing of a scattering coating for the rays ``idx`` (in place).

    Each ray crosses the medium (:func:`cross_slab`); its Mueller matrix is multiplied by
    its medium weight and, if it scattered, reduced to its intensity row (module Notes).
    With a Lambertian base (``base``: re-emits the rays it is given in place and returns
    the M00 it absorbs) a ray reaching the base is re-emitted and crosses again, until
    it reaches the top; over a conductor (``base=None``) it stops at the base.

    Returns
    -------
    absorbed : float
        The M00 lost (Beer-Lambert, ``1 - ssa`` per event, the base's ``1 - albedo``; the
        roulette and the event cap, module Notes).
    up : ndarray of bool (len(idx),)
        Reached the top interface from below (else the base, from above).
    based : ndarray of int
        The rays (of ``idx``) that had at least one base event.
    """
    absorbed = 0.0
    up = np.zeros(idx.size, dtype=bool)
    based = np.zeros(idx.size, dtype=bool)
    todo = np.arange(idx.size)
    for _ in range(MAX_ROUNDS):
        j = idx[todo]
        c = cross_slab(medium, a_abs, k[:, j], s[:, j], rng)
        absorbed += float((M[0, 0, j] * (1.0 - c.weight)).sum())
        M[:, :, j] *= c.weight
        dep = j[c.scattered]
        M[1:, :, dep] = 0.0
        k[:, j], s[:, j] = c.k, c.s
        up[todo] = c.up
        if base is None or c.up.all():
            return absorbed, up, idx[based]
        todo = todo[~c.up]
        based[todo] = True
        absorbed += base(idx[todo])
    j = idx[todo]  # still bouncing between the base and the medium: dropped
    absorbed += float(M[0, 0, j].sum())
    M[:, :, j] = 0.0
    _park(k, s, j)
    up[todo] = True
    return absorbed, up, idx[based]
