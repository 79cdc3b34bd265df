"""A microfacet distribution given by a table of its slope density (measured or analytic).

Physics layer: numpy only. Directions are unit vectors of shape (3, n) in a local frame
whose +z is the macroscopic normal on the side the ray is on.

References
----------
Heitz E., "Understanding the masking-shadowing function in microfacet-based BRDFs", JCGT
3(2) (2014) (D from P22, Lambda in slope form).
Heitz E., d'Eon E., "Importance sampling microfacet-based BSDFs using the distribution of
visible normals", CGF 33(4) (2014).
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import beckmann as _beckmann
from . import ggx as _ggx

__all__ = ["TabulatedNDF"]


def _sinh_edges(scale: float, extent: float, n: int) -> NDArray[np.float64]:
    """``n + 1`` edges ``scale sinh(t)``, t uniform, from -extent to +extent.

    Fine cells (~ scale * 2 asinh(extent/scale) / n) near zero slope, wide ones in the tails.
    """
    t = np.arcsinh(extent / scale)
    e = scale * np.sinh(np.linspace(-t, t, n + 1))
    e[0], e[-1] = -extent, extent
    e[n // 2] = 0.0 if n % 2 == 0 else e[n // 2]
    return e


class TabulatedNDF:
    """A microfacet distribution given by a table of its slope density P22.

    The slope density is piecewise constant on the cells of a rectilinear grid of slopes
    (x, y) = (-m_x/m_z, -m_y/m_z): cell (i, j) holds probability ``mass[i, j]``. Everything
    the tracer needs follows from that one piecewise-constant density, so sampling, D and
    Lambda describe the same microsurface:

    * ``D(m) = P22(x, y) / cos^4 theta_m`` (Heitz 2014, eq. 10);
    * Smith ``Lambda(w) = (1/mu) E[(x_phi - mu)^+]`` with ``mu = cot theta`` and x_phi the
      slope component along the azimuth of w (Heitz 2014, eq. 67/72 in slope form), valid
      for upward and downward w alike (it equals ``-1 - Lambda(-w)``);
    * visible normals ``D_w(m) ~ <w, m>^+ D(m)``, i.e. slopes with density
      ``P22(x, y) (w_z - w_x x - w_y y)^+`` (Heitz & d'Eon 2014), sampled exactly by
      rejection (see :meth:`sample_visible`).

    Lambda is precomputed on a grid of azimuths (uniform) and of mu (sinh-spaced, like the
    slope cells) and interpolated bilinearly; each cell is represented by ``sub x sub``
    sub-cell midpoints in that precomputation (an O(h^2) approximation of the cell's
    uniform density).

    Parameters
    ----------
    x_edges, y_edges : array_like
        Increasing cell edges in slope [1], at least 2 cells per axis.
    mass : array_like, shape (len(x_edges) - 1, len(y_edges) - 1)
        Non-negative cell probabilities (normalised here).
    n_phi, n_mu : int
        Azimuth and mu nodes of the Lambda table.
    sub : int
        Sub-cell midpoints per axis in the Lambda precomputation.
    name : str
        Label (e.g. ``"ggx(0.2)"``).
    normalise : bool
        Divide ``mass`` by its sum (the default). ``False`` keeps the masses exactly as
        given; they must then already sum to 1 within rounding (``size * eps``).

    Notes
    -----
    :meth:`from_dict` keeps the stored masses as they are (``normalise=False``), so a
    table survives :meth:`to_dict` / :meth:`from_dict` bit for bit on any machine.
    Dividing the stored masses by their sum again would not: their sum is 1 only to
    rounding, and which rounding depends on the vector width numpy's pairwise summation
    uses on the CPU at hand, so a renormalised copy differs in the last bits.
    """

    def __init__(
        self,
        x_edges: ArrayLike,
        y_edges: ArrayLike,
        mass: ArrayLike,
        *,
        n_phi: int = 72,
        n_mu: int = 1024,
        sub: int = 2,
        name: str = "table",
        normalise: bool = True,
    ) -> None:
        xe = np.asarray(x_edges, dtype=float)
        ye = np.asarray(y_edges, dtype=float)
        w = np.asarray(mass, dtype=float)
        if xe.ndim != 1 or ye.ndim != 1 or xe.size < 3 or ye.size < 3:
            raise ValueError("x_edges and y_edges must be 1-D with at least 3 edges")
        if (
            np.any(np.diff(xe) <= 0)
            or np.any(np.diff(ye) <= 0)
            or not np.all(np.isfinite(np.r_[xe, ye]))
        ):
            raise ValueError("slope edges must be finite and strictly increasing")
        if w.shape != (xe.size - 1, ye.size - 1):
            raise ValueError(f"mass must have shape {(xe.size - 1, ye.size - 1)}, got {w.shape}")
        if not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
            raise ValueError("mass must be finite, >= 0 and not all zero")
        self.x_edges, self.y_edges = xe, ye
        if normalise:
            self.mass = w / w.sum()
        elif abs(w.sum() - 1.0) <= w.size * np.finfo(float).eps:
            self.mass = w
        else:
            raise ValueError(f"mass must sum to 1 when normalise=False, got {w.sum()!r}")
        self.name = str(name)
        self.n_phi, self.n_mu, self.sub = int(n_phi), int(n_mu), int(sub)
        area = np.diff(xe)[:, None] * np.diff(ye)[None, :]
        self.density = self.mass / area  # P22 per cell [1]
        flat = self.mass.ravel()
        # r_max per cell: largest |slope| over the cell's corners (bound of the weight)
        cx = np.maximum(np.abs(xe[:-1]), np.abs(xe[1:]))
        cy = np.maximum(np.abs(ye[:-1]), np.abs(ye[1:]))
        self._rmax = np.sqrt(cx[:, None] ** 2 + cy[None, :] ** 2).ravel()
        w1 = flat * self._rmax
        self._m1 = float(w1.sum())
        # cells sorted by r_max: the cells a direction from below can see form a suffix
        self._order = np.argsort(self._rmax, kind="stable")
        self._r_sorted = self._rmax[self._order]
        self._cdf0s = np.cumsum(flat[self._order])
        self._cdf1s = np.cumsum(w1[self._order])
        self.mean_slope = (
            float(np.sum(self.mass * (0.5 * (xe[:-1] + xe[1:]))[:, None])),
            float(np.sum(self.mass * (0.5 * (ye[:-1] + ye[1:]))[None, :])),
        )
        self._lambda_table()

    # -- construction ---------------------------------------------------------------
    @classmethod
    def from_p22(
        cls,
        p22: Any,
        x_edges: ArrayLike,
        y_edges: ArrayLike | None = None,
        *,
        quad: int = 4,
        **kw: Any,
    ) -> TabulatedNDF:
        """Table of an analytic slope density by Gauss-Legendre quadrature in each cell.

        Parameters
        ----------
        p22 : callable
            ``p22(x, y)`` slope density [1], vectorised.
        x_edges, y_edges : array_like
            Cell edges (``y_edges`` defaults to ``x_edges``).
        quad : int
            Gauss-Legendre points per axis and cell.
        """
        xe = np.asarray(x_edges, dtype=float)
        ye = xe if y_edges is None else np.asarray(y_edges, dtype=float)
        g, gw = np.polynomial.legendre.leggauss(quad)
        hx, hy = np.diff(xe) / 2, np.diff(ye) / 2
        mx, my = (xe[:-1] + xe[1:]) / 2, (ye[:-1] + ye[1:]) / 2
        mass = np.zeros((mx.size, my.size))
        for a, wa in zip(g, gw, strict=True):
            xs = mx + hx * a
            for b, wb in zip(g, gw, strict=True):
                ys = my + hy * b
                mass += wa * wb * p22(xs[:, None], ys[None, :])
        mass *= hx[:, None] * hy[None, :]
        return cls(xe, ye, mass, **kw)

    @classmethod
    def of(
        cls,
        distribution: ModuleType,
        alpha: float,
        n: int = 256,
        extent: float | None = None,
        **kw: Any,
    ) -> TabulatedNDF:
        """Table of an analytic distribution's slope density, slopes within ``extent * alpha``.

        Parameters
        ----------
        distribution : module
            A distribution of :data:`labbrdf.microfacet.registry.DISTRIBUTIONS` (its ``p22``).
        alpha : float
            Roughness [1], > 0.
        n : int
            Cells per axis.
        extent : float, optional
            Largest slope of the table in units of alpha (default: the distribution's
            ``TABLE_EXTENT``). The mass beyond is dropped and the rest renormalised.
        """

        def p22(x: NDArray, y: NDArray) -> NDArray:
            return distribution.p22(x, y, alpha)

        ext = distribution.TABLE_EXTENT if extent is None else extent
        kw.setdefault("name", f"{distribution.NAME}({alpha:g})")
        return cls.from_p22(p22, _sinh_edges(alpha, ext * alpha, n), **kw)

    @classmethod
    def ggx(cls, alpha: float, n: int = 256, extent: float = 1000.0, **kw: Any) -> TabulatedNDF:
        """Table of the isotropic GGX slope density (:func:`labbrdf.microfacet.ggx.p22`).

        The mass beyond the table, ``1 / (1 + extent^2)`` of the radial tail (less in the
        square), is dropped and the rest renormalised.
        """
        return cls.of(_ggx, alpha, n, extent, **kw)

    @classmethod
    def beckmann(cls, alpha: float, n: int = 256, extent: float = 6.0, **kw: Any) -> TabulatedNDF:
        """Table of the Beckmann slope density (:func:`labbrdf.microfacet.beckmann.p22`)."""
        return cls.of(_beckmann, alpha, n, extent, **kw)

    @classmethod
    def from_slopes(
        cls,
        sx: ArrayLike,
        sy: ArrayLike,
        *,
        bins: int = 64,
        symmetrize: bool = True,
        extent: float | None = None,
        **kw: Any,
    ) -> TabulatedNDF:
        """Histogram table of measured slope pairs (dz/dx, dz/dy) [1].

        Parameters
        ----------
        sx, sy : array_like
            Slopes at the same points.
        bins : int
            Cells per axis (sinh-spaced around zero, scale = the RMS slope per axis).
        symmetrize : bool
            Add the point reflections (-sx, -sy): the table then has zero mean slope (the
            macro-surface is the mean plane, which Smith's projected-area normalisation
            needs) and looks the same from below (as under a coating).
        extent : float, optional
            Largest |slope| of the table (default: the largest measured one).
        """
        x = np.asarray(sx, dtype=float).ravel()
        y = np.asarray(sy, dtype=float).ravel()
        ok = np.isfinite(x) & np.isfinite(y)
        x, y = x[ok], y[ok]
        if x.size < 10:
            raise ValueError(f"need at least 10 finite slope pairs, got {x.size}")
        if symmetrize:
            x, y = np.r_[x, -x], np.r_[y, -y]
        lim = float(max(np.abs(x).max(), np.abs(y).max())) if extent is None else extent
        scale = float(np.sqrt(np.mean(x * x + y * y) / 2))
        if not (lim > 0 and scale > 0):
            raise ValueError("slopes are all zero")
        edges = _sinh_edges(min(scale, lim), lim * (1 + 1e-12), bins)
        h, _, _ = np.histogram2d(x, y, bins=[edges, edges])
        kw.setdefault("name", f"measured({x.size // (2 if symmetrize else 1)} slopes)")
        return cls(edges, edges, h, **kw)

    # -- serialisation ----------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """JSON-safe dict (the edges and the normalised masses as lists)."""
        return {
            "kind": "tabulated",
            "name": self.name,
            "x_edges": self.x_edges.tolist(),
            "y_edges": self.y_edges.tolist(),
            "mass": self.mass.tolist(),
            "n_phi": self.n_phi,
            "n_mu": self.n_mu,
            "sub": self.sub,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TabulatedNDF:
        """The table written by :meth:`to_dict`, its masses kept bit for bit.

        Masses that do not sum to 1 within rounding (a table written by hand) are
        normalised as by the constructor.
        """
        d = dict(data)
        d.pop("kind", None)
        mass = np.asarray(d.pop("mass"), dtype=float)
        exact = mass.size > 0 and abs(mass.sum() - 1.0) <= mass.size * np.finfo(float).eps
        return cls(d.pop("x_edges"), d.pop("y_edges"), mass, normalise=not exact, **d)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TabulatedNDF):
            return NotImplemented
        return (
            np.array_equal(self.x_edges, other.x_edges)
            and np.array_equal(self.y_edges, other.y_edges)
            and np.array_equal(self.mass, other.mass)
            and (self.n_phi, self.n_mu, self.sub) == (other.n_phi, other.n_mu, other.sub)
        )

    def __hash__(self) -> int:
        return hash((self.x_edges.tobytes(), self.y_edges.tobytes(), self.mass.tobytes()))

    def __repr__(self) -> str:
        return f"TabulatedNDF({self.name!r}, {self.mass.shape[0]}x{self.mass.shape[1]} cells)"

    # -- densities --------------------------------------------------------------------
    def p22(self, x: ArrayLike, y: ArrayLike) -> NDArray[np.float64]:
        """Slope density P22(x, y) [1]; 0 outside the table."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        i = np.searchsorted(self.x_edges, x, side="right") - 1
        j = np.searchsorted(self.y_edges, y, side="right") - 1
        inside = (i >= 0) & (i < self.mass.shape[0]) & (j >= 0) & (j < self.mass.shape[1])
        out = np.zeros(np.broadcast(x, y).shape)
        ii = np.clip(i, 0, self.mass.shape[0] - 1)
        jj = np.clip(j, 0, self.mass.shape[1] - 1)
        out[...] = np.where(inside, self.density[ii, jj], 0.0)
        return out

    def d(self, m: ArrayLike) -> NDArray[np.float64]:
        """Distribution of normals ``D(m) = P22(-m_x/m_z, -m_y/m_z) / m_z^4`` [sr^-1].

        Parameters
        ----------
        m : array_like, shape (3, n)
            Unit normals; D = 0 for m_z <= 0.
        """
        m = np.asarray(m, dtype=float)
        mz = m[2]
        up = mz > 0
        safe = np.where(up, mz, 1.0)
        val = self.p22(-m[0] / safe, -m[1] / safe) / safe**4
        return np.where(up, val, 0.0)

    # -- Smith Lambda -----------------------------------------------------------------
    def _lambda_table(self) -> None:
        xe, ye, s = self.x_edges, self.y_edges, self.sub
        # sub-cell midpoints and their masses
        fx = (np.arange(s) + 0.5) / s
        px = (xe[:-1, None] + np.diff(xe)[:, None] * fx[None, :]).ravel()
        py = (ye[:-1, None] + np.diff(ye)[:, None] * fx[None, :]).ravel()
        pm = np.repeat(np.repeat(self.mass / (s * s), s, axis=0), s, axis=1)
        keep = pm.ravel() > 0
        gx, gy = np.meshgrid(px, py, indexing="ij")
        gx, gy, pm = gx.ravel()[keep], gy.ravel()[keep], pm.ravel()[keep]
        rmax = float(np.sqrt(np.max(np.abs(xe)) ** 2 + np.max(np.abs(ye)) ** 2))
        scale = float(np.sqrt(max(np.sum(pm * (gx * gx + gy * gy)) / 2, 1e-300)))
        scale = min(scale, rmax)
        self._mu_scale = scale
        self._mu_t = float(np.arcsinh(rmax / scale))
        nm = self.n_mu
        tau = np.linspace(-self._mu_t, self._mu_t, nm + 1)
        nodes = scale * np.sinh(tau)
        nodes[0], nodes[-1] = -rmax, rmax
        self._mu_nodes = nodes
        phis = 2 * np.pi * np.arange(self.n_phi + 1) / self.n_phi
        g = np.zeros((self.n_phi + 1, nm + 1))
        dt = 2 * self._mu_t / nm
        for k, ph in enumerate(phis[:-1]):
            t = np.cos(ph) * gx + np.sin(ph) * gy
            b = np.clip(
                np.floor((np.arcsinh(t / scale) + self._mu_t) / dt).astype(np.int64), 0, nm - 1
            )
            # points with t >= nodes[j] are those in bins >= j (up to the node rounding)
            w = np.bincount(b, pm, minlength=nm)
            wt = np.bincount(b, pm * t, minlength=nm)
            sw = np.r_[np.cumsum(w[::-1])[::-1], 0.0]
            swt = np.r_[np.cumsum(wt[::-1])[::-1], 0.0]
            g[k] = np.maximum(swt - nodes * sw, 0.0)
        g[-1] = g[0]
        self._g = g

    def _g_of(self, mu: NDArray, phi: NDArray) -> NDArray:
        """E[(x_phi - mu)^+], bilinear in (asinh(mu/scale), phi); exact linear tails."""
        nm, npf = self.n_mu, self.n_phi
        dt = 2 * self._mu_t / nm
        lo, hi = self._mu_nodes[0], self._mu_nodes[-1]
        muc = np.clip(mu, lo, hi)
        ft = (np.arcsinh(muc / self._mu_scale) + self._mu_t) / dt
        j = np.clip(np.floor(ft).astype(np.int64), 0, nm - 1)
        a = np.clip(ft - j, 0.0, 1.0)
        fp = np.mod(phi, 2 * np.pi) / (2 * np.pi) * npf
        k = np.clip(np.floor(fp).astype(np.int64), 0, npf - 1)
        b = fp - k
        g = self._g
        val = (1 - b) * ((1 - a) * g[k, j] + a * g[k, j + 1]) + b * (
            (1 - a) * g[k + 1, j] + a * g[k + 1, j + 1]
        )
        # below the support every slope counts: g = g(lo) + (lo - mu); above it g = 0
        val = np.where(mu < lo, val + (lo - mu), val)
        return np.where(mu > hi, 0.0, val)

    def smith_lambda(self, w: ArrayLike) -> NDArray[np.float64]:
        """Smith Lambda(w) for directions w, shape (3, n) (up or down) [1].

        ``Lambda = E[(x_phi - mu)^+] / mu``, ``mu = w_z / sqrt(w_x^2 + w_y^2)`` (Heitz 2014,
        sec. 5.2); 0 for w straight up, -1 straight down.
        """
        w = np.asarray(w, dtype=float)
        st = np.hypot(w[0], w[1])
        with np.errstate(divide="ignore", invalid="ignore"):
            mu = np.where(st > 0, w[2] / np.where(st > 0, st, 1.0), np.copysign(np.inf, w[2]))
            mu = np.where(mu == 0, 1e-300, mu)
            phi = np.arctan2(w[1], w[0])
            finite = np.isfinite(mu)
            muf = np.where(finite, mu, 0.0)
            lam = self._g_of(muf, phi) / np.where(finite, mu, 1.0)
        return np.where(finite, lam, np.where(w[2] > 0, 0.0, -1.0))

    def smith_g1(self, w: ArrayLike) -> NDArray[np.float64]:
        """Smith masking ``G1 = 1 / (1 + Lambda(w))`` for w_z > 0, else 0."""
        w = np.asarray(w, dtype=float)
        lam = self.smith_lambda(w)
        with np.errstate(divide="ignore"):
            return np.where(w[2] > 0, 1.0 / (1.0 + np.where(w[2] > 0, lam, 0.0)), 0.0)

    # -- sampling ---------------------------------------------------------------------
    def _cells(
        self, cdf: NDArray, u: NDArray, v: NDArray, start: NDArray | int = 0
    ) -> tuple[NDArray, NDArray, NDArray]:
        """Pick a cell by inverse CDF of ``u`` over the sorted cells ``start..``.

        The position in the cell is uniform, from (u's remainder, v). Returns x, y and the
        (unsorted) cell index.
        """
        total = cdf[-1]
        start = np.asarray(start)
        base = np.where(start > 0, cdf[np.maximum(start - 1, 0)], 0.0)
        target = base + u * (total - base)
        k = np.minimum(np.searchsorted(cdf, target, side="right"), cdf.size - 1)
        k = np.maximum(k, start)
        lo = np.where(k > 0, cdf[np.maximum(k - 1, 0)], 0.0)
        width = cdf[k] - lo
        fx = np.clip((target - lo) / np.where(width > 0, width, 1.0), 0.0, 1.0)
        c = self._order[k]
        ny = self.mass.shape[1]
        i, j = np.divmod(c, ny)
        x = self.x_edges[i] + fx * (self.x_edges[i + 1] - self.x_edges[i])
        y = self.y_edges[j] + v * (self.y_edges[j + 1] - self.y_edges[j])
        return x, y, c

    def sample_slopes(self, n: int, rng: np.random.Generator) -> tuple[NDArray, NDArray]:
        """n slope pairs with density P22 [1]."""
        u = rng.random((2, n))
        x, y, _ = self._cells(self._cdf0s, u[0], u[1])
        return x, y

    def sample_visible(
        self, wi: NDArray[np.float64], rng: np.random.Generator, max_rounds: int = 10_000
    ) -> NDArray[np.float64]:
        """Sample visible normals ``D_wi(m) ~ <wi, m>^+ D(m)`` exactly, by rejection.

        Parameters
        ----------
        wi : ndarray, shape (3, n)
            Unit directions towards the light (w_z may be negative in the walk).
        rng : numpy.random.Generator
            Source of the (data-dependent number of) uniform numbers.

        Returns
        -------
        ndarray, shape (3, n)
            Unit normals.

        Notes
        -----
        In slope space the target is ``P22(x, y) (w_z - w_x x - w_y y)^+``, i.e.
        ``P22 (w_z - sin(theta) x_phi)^+`` with x_phi the slope along the azimuth of w and
        |x_phi| <= r_c, the largest |slope| of cell c.

        * w_z >= 0: the weight is at most ``w_z + sin(theta) r_c``; the proposal is the
          mixture ``P22 (w_z + sin(theta) r_c)`` (two precomputed cell CDFs, a uniform
          position in the cell), accepted with probability
          ``weight / (w_z + sin(theta) r_c)``.
        * w_z < 0 (a ray travelling up inside the walk): only cells with
          ``r_c > |cot(theta)|`` can be seen. With the cells sorted by r_c they form a
          suffix; the proposal is ``P22 r_c`` on that suffix, accepted with probability
          ``weight / (sin(theta) r_c)``.

        Both are exact for the table and efficient for heavy-tailed tables at grazing
        angles, where rejection against one global bound would almost never accept.
        (Sampling the visible slopes through the marginal along the azimuth of w, Heitz &
        d'Eon 2014, would need the table rotated to every azimuth.) A direction that sees
        no cell at all (possible only through the interpolation of Lambda in the walk) gets
        a facet of the steepest cell.
        """
        n = wi.shape[1]
        xs = np.empty(n)
        ys = np.empty(n)
        st_all = np.hypot(wi[0], wi[1])
        down_all = wi[2] < 0
        with np.errstate(divide="ignore"):
            mu_abs = np.where(down_all, -wi[2] / np.where(st_all > 0, st_all, 0.0), 0.0)
        start_all = np.where(
            down_all, np.searchsorted(self._r_sorted, mu_abs, side="right"), 0
        ).astype(np.int64)
        blind_all = start_all >= self._r_sorted.size
        start_all = np.minimum(start_all, self._r_sorted.size - 1)
        todo = np.arange(n)
        for _ in range(max_rounds):
            if todo.size == 0:
                break
            w = wi[:, todo]
            st = st_all[todo]
            down = down_all[todo]
            u = rng.random((4, todo.size))
            p0 = np.where(down, 0.0, w[2] / (w[2] + st * self._m1))
            first = u[0] < p0
            x = np.empty(todo.size)
            y = np.empty(todo.size)
            c = np.empty(todo.size, dtype=np.int64)
            for sel, cdf in ((first, self._cdf0s), (~first, self._cdf1s)):
                if sel.any():
                    x[sel], y[sel], c[sel] = self._cells(
                        cdf, u[1, sel], u[2, sel], start_all[todo[sel]]
                    )
            weight = w[2] - w[0] * x - w[1] * y
            bound = np.where(down, 0.0, w[2]) + st * self._rmax[c]
            acc = (u[3] * bound < weight) | blind_all[todo]
            xs[todo[acc]] = x[acc]
            ys[todo[acc]] = y[acc]
            todo = todo[~acc]
        else:
            raise RuntimeError(
                f"{todo.size} directions see no facet of the table after {max_rounds} rounds"
            )
        inv = 1.0 / np.sqrt(1.0 + xs * xs + ys * ys)
        return np.stack([-xs * inv, -ys * inv, inv])
