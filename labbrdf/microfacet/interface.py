"""One rough interface's microfacet distribution, as a ray walking on it sees it.

Physics layer: numpy only. The tracer's walk carries one :class:`Facets` object per
interface (the coating's top, the substrate) and asks it, for the rays on that interface,
for the Smith ``Lambda`` and ``G1`` of their travel directions, for visible facet normals
and for ``D``. Two kinds serve every distribution of :mod:`labbrdf.microfacet.registry`:

* :class:`ClosedForm`: a distribution module that samples its visible normals in closed
  form (``TRACED_IN_CLOSED_FORM``, e.g. GGX), at one roughness ``alpha``;
* :class:`Table`: a :class:`~labbrdf.microfacet.TabulatedNDF` (a measured height map's
  slopes, or an analytic distribution's slope table, e.g. Beckmann), whose D, Lambda and
  visible-normal sampling all follow from one piecewise-constant slope density.

:func:`facets` builds the right one. Directions are global unit vectors of shape (3, n),
+z the macroscopic normal pointing into the air; ``k`` is a ray's propagation direction.
A ray ``below`` an interface (inside the coating, under its top) sees the lower side of the
height field; Smith masking then uses the mirror image of the interface (module docstring
of :mod:`labbrdf.tracer.walk`).

References
----------
Heitz E., "Understanding the masking-shadowing function in microfacet-based BRDFs", JCGT
3(2) (2014). Heitz E., Hanika J., d'Eon E., Dachsbacher C., "Multiple-scattering microfacet
BSDFs with the Smith model", ACM TOG 35(4) (2016) (Lambda of downward directions).
"""

from __future__ import annotations

import functools
from types import ModuleType
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from . import ggx
from .registry import get
from .tabulated import TabulatedNDF

__all__ = ["ClosedForm", "Facets", "Table", "facets", "table_for"]

F64 = NDArray[np.float64]
Side = NDArray[np.bool_] | None


class Facets(Protocol):
    """What the walk asks of an interface's distribution (the rays on it only)."""

    name: str
    alpha: float
    #: the exit operator of the evaluated estimator is built for this interface's kind
    ggx_closed_form: bool

    def smith_lambda(self, k: F64, below: Side = None) -> F64:
        """Smith Lambda [1] of travel directions ``k`` (3, n) (up or down)."""
        ...

    def smith_g1(self, k: F64, below: Side = None) -> F64:
        """Smith ``G1 = 1 / (1 + Lambda)`` [1] of travel directions ``k``; 0 into the surface."""
        ...

    def sample_visible(
        self, k: F64, below: Side, u1: F64, u2: F64, rng: np.random.Generator
    ) -> F64:
        """Visible facet normals (3, n) for rays travelling along ``k``, global frame."""
        ...

    def d(self, m: F64) -> F64:
        """Distribution of normals D(m) [sr^-1] of unit normals ``m`` (3, n), seen from above."""
        ...


class ClosedForm:
    """A distribution with closed-form Lambda and visible-normal sampling, one ``alpha``.

    Seen from below, an isotropic distribution's lower side is its mirror image in the
    mean plane: the walk flips the z components of the direction and of the sampled
    normal.

    Parameters
    ----------
    distribution : module
        A registered distribution with ``TRACED_IN_CLOSED_FORM`` (its ``smith_lambda``,
        ``smith_g1``, ``sample_visible`` and ``d``).
    alpha : float
        Roughness [1], >= 0.
    """

    def __init__(self, distribution: ModuleType, alpha: float) -> None:
        if not getattr(distribution, "TRACED_IN_CLOSED_FORM", False):
            raise ValueError(
                f"{distribution.NAME} has no closed-form visible-normal sampling: "
                "trace it through its slope table (Table)"
            )
        self.distribution = distribution
        self.alpha = float(alpha)
        self.name = f"{distribution.NAME}({self.alpha:g})"
        self.ggx_closed_form = distribution is ggx

    def __repr__(self) -> str:
        return f"ClosedForm({self.name})"

    @staticmethod
    def _kz(k: F64, below: Side) -> F64:
        return k[2] if below is None else np.where(below, -k[2], k[2])

    def smith_lambda(self, k: F64, below: Side = None) -> F64:
        """Smith Lambda of the travel directions (the distribution's closed form)."""
        return self.distribution.smith_lambda(self._kz(k, below), self.alpha)

    def smith_g1(self, k: F64, below: Side = None) -> F64:
        """Smith G1 of the travel directions (0 for a direction into the surface)."""
        return self.distribution.smith_g1(self._kz(k, below), self.alpha)

    def sample_visible(
        self, k: F64, below: Side, u1: F64, u2: F64, rng: np.random.Generator
    ) -> F64:
        """Visible normals from the uniforms ``u1``, ``u2`` (``rng`` unused)."""
        wi = -k
        if below is not None:
            wi[2] = np.where(below, k[2], wi[2])
        m = self.distribution.sample_visible(wi, self.alpha, u1, u2)
        if below is not None:
            m[2] = np.where(below, -m[2], m[2])
        return m

    def d(self, m: F64) -> F64:
        """D(m) [sr^-1] from the normals' z components."""
        return self.distribution.d(m[2], self.alpha)


class Table:
    """A slope table (:class:`~labbrdf.microfacet.TabulatedNDF`) as an interface.

    Seen from below, the lower side of a height field has the slope distribution of its
    point reflection ``r -> -r``: a direction ``k`` below is ``-k`` above, and a normal
    sampled for ``-k`` above is ``-m`` below (a table need not be isotropic, so the mirror
    in the mean plane would not do).

    Parameters
    ----------
    table : TabulatedNDF
    alpha : float
        The roughness the table stands for [1] (kept for the description and the node
        counts of the evaluated estimator; not used by the walk).
    """

    ggx_closed_form = False

    def __init__(self, table: TabulatedNDF, alpha: float) -> None:
        self.table = table
        self.alpha = float(alpha)
        self.name = table.name

    def __repr__(self) -> str:
        return f"Table({self.name})"

    @staticmethod
    def _dirs(k: F64, below: Side) -> F64:
        return k if below is None else np.where(below, -k, k)

    def smith_lambda(self, k: F64, below: Side = None) -> F64:
        """Smith Lambda of the travel directions (the table's, Heitz 2014 in slope form)."""
        return self.table.smith_lambda(self._dirs(k, below))

    def smith_g1(self, k: F64, below: Side = None) -> F64:
        """Smith G1 of the travel directions (0 for a direction into the surface)."""
        return self.table.smith_g1(self._dirs(k, below))

    def sample_visible(
        self, k: F64, below: Side, u1: F64, u2: F64, rng: np.random.Generator
    ) -> F64:
        """Visible normals by the table's exact rejection sampler (draws from ``rng``)."""
        if below is None:
            return self.table.sample_visible(-k, rng)
        sign = np.where(below, -1.0, 1.0)
        return sign * self.table.sample_visible(-k * sign, rng)

    def d(self, m: F64) -> F64:
        """D(m) [sr^-1] of the table."""
        return self.table.d(m)


def facets(alpha: float, table: TabulatedNDF | None = None) -> ClosedForm | Table:
    """The interface of roughness ``alpha``: its slope table if given, else GGX.

    Parameters
    ----------
    alpha : float
        Roughness [1] (GGX's when there is no table).
    table : TabulatedNDF or None
        A slope table (measured, or an analytic distribution's, e.g.
        ``TabulatedNDF.of(beckmann, alpha)``).
    """
    if table is None:
        return ClosedForm(ggx, alpha)
    return Table(table, alpha)


@functools.lru_cache(maxsize=8)
def table_for(distribution: str, alpha: float) -> TabulatedNDF | None:
    """What an interface of a registered distribution at ``alpha`` stores as its ``ndf``.

    None for GGX (the walk's closed form, ``ndf=None``); otherwise the distribution's slope
    table, :meth:`TabulatedNDF.of` with its default 256 cells per axis (the table
    ``labbrdf trace --distribution`` builds), kept for the last 8 (name, alpha) pairs: a
    table takes about 0.5 s to build.

    Raises
    ------
    KeyError
        An unknown distribution (the message lists the registered ones).
    ValueError
        A tabulated distribution without a roughness ``alpha > 0``.
    """
    dist = get(distribution)
    if dist is ggx:
        return None
    if not alpha > 0:
        raise ValueError(f"the {dist.LABEL} table needs a roughness alpha > 0, got {alpha!r}")
    return TabulatedNDF.of(dist, alpha)
