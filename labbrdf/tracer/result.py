"""The pBRDF of a tracer run: Mueller matrix per bin, maps, albedo, energy ledger, .npz I/O."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .binning import Grid
from .config import TraceConfig

__all__ = ["DOP_SE_MAX", "MIN_COUNT", "SHOW_COUNT", "TraceResult", "trace_summary"]

UNPOLARIZED = (1.0, 0.0, 0.0, 0.0)

#: counting estimator: peaks and colour scales use bins with at least this many exiting
#: rays (fewer: the bin value is dominated by one or two rays, e.g. the thin
#: theta_r = 90 deg edge row)
MIN_COUNT = 20
#: counting estimator: the DOP is shown only in bins with at least this many rays
SHOW_COUNT = 10
#: evaluated estimator: the DOP is shown where its standard error is at most this [1]
DOP_SE_MAX = 0.02


def _stokes(stokes_in: ArrayLike) -> NDArray[np.float64]:
    s = np.asarray(stokes_in, dtype=float)
    if s.shape != (4,) or not np.all(np.isfinite(s)):
        raise ValueError(f"stokes_in must be 4 finite numbers [S0, S1, S2, S3], got {stokes_in!r}")
    if s[0] <= 0 or np.sqrt((s[1:] ** 2).sum()) > s[0] * (1 + 1e-12):
        raise ValueError(f"stokes_in must have S0 > 0 and DOP <= 1, got {stokes_in!r}")
    return s


@dataclass
class TraceResult:
    """Result of :func:`labbrdf.tracer.trace`.

    Attributes
    ----------
    config : TraceConfig
    sums, sumsq : ndarray, shape (n_theta, n_phi, 4, 4)
        Summed exit Mueller weights per bin and their squares (per-ray spread).
    counts : ndarray of int, shape (n_theta, n_phi)
        Exiting rays per bin.
    hemi : ndarray, shape (4, 4)
        Exit Mueller weights summed over the hemisphere, per incident ray.
    ledger : dict
        ``exited``, ``absorbed``, ``terminated`` (fractions of the incident power,
        unpolarized input) and ``incident`` (rays).
    block_hemi : ndarray, shape (n_blocks, 4, 4)
        ``hemi`` of each block, per ray of that block (block-spread error estimates).
    block_rays : ndarray of int, shape (n_blocks,)
    seconds : float
        Wall time of the run [s].
    events : int
        Facet events traced.
    stderr : ndarray, shape (n_theta, n_phi, 4, 4), or None
        Evaluated estimator: standard error of :attr:`mueller` from the spread of the
        ``config.batches`` independent batches [sr^-1]; None for counting (whose error
        comes from the per-ray spread in ``sumsq``).
    batch_mueller : ndarray, shape (batches, n_theta, n_phi, 4, 4), float32, or None
        Evaluated estimator: each batch's Mueller BRDF (for errors of derived maps such as
        the DOP, :meth:`dop_stderr`). With the evaluated estimator ``block_hemi`` and
        ``block_rays`` hold the batches', not the blocks', hemispherical sums and rays.
    info : dict
        Timings of the evaluated estimator's parts [s] and the operator's size [MB].
    """

    config: TraceConfig
    sums: NDArray[np.float64]
    sumsq: NDArray[np.float64]
    counts: NDArray[np.int64]
    hemi: NDArray[np.float64]
    ledger: dict[str, float]
    block_hemi: NDArray[np.float64]
    block_rays: NDArray[np.int64]
    seconds: float = 0.0
    events: int = 0
    stderr: NDArray[np.float64] | None = None
    batch_mueller: NDArray[np.float32] | None = None
    info: dict[str, float] = field(default_factory=dict)
    _grid: Grid = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._grid = Grid(self.config.theta_step_deg, self.config.phi_step_deg)

    # -- grid ----------------------------------------------------------------------
    @property
    def grid(self) -> Grid:
        """The binning grid."""
        return self._grid

    @property
    def rays(self) -> int:
        """Number of traced rays."""
        return self.config.rays

    @property
    def theta_r_deg(self) -> NDArray[np.float64]:
        """Polar bin centres [deg]."""
        return self._grid.theta_centres_deg

    @property
    def phi_r_deg(self) -> NDArray[np.float64]:
        """Azimuth bin centres [deg] (source at 0, specular half-plane at 180)."""
        return self._grid.phi_centres_deg

    @property
    def theta_r_edges_deg(self) -> NDArray[np.float64]:
        """Polar bin edges [deg]."""
        return self._grid.theta_edges_deg

    @property
    def phi_r_edges_deg(self) -> NDArray[np.float64]:
        """Azimuth bin edges [deg] (the first bin wraps around 0)."""
        return self._grid.phi_edges_deg

    # -- pBRDF -----------------------------------------------------------------------
    @property
    def mueller(self) -> NDArray[np.float64]:
        """Bin-averaged Mueller BRDF, shape (n_theta, n_phi, 4, 4) [sr^-1].

        ``f = W / (N Omega_cos)``: summed weights over rays times cos-weighted solid angle
        (derivation in :mod:`labbrdf.tracer.binning`).
        """
        w = self._grid.cos_solid_angle_sr[:, :, None, None]
        return self.sums / (self.rays * w)

    def _repr_html_(self) -> str:
        """What was traced and the albedo, for notebooks."""
        from ..richrepr import card

        c = self.config
        facts = [
            ("wavelength [nm], theta_i [deg]", f"{c.wavelength_nm:g}, {c.theta_i_deg:g}"),
            ("substrate", c.substrate.describe()),
            (
                "coating",
                "none"
                if c.coating is None
                else f"N = {c.coating.n:g}+{c.coating.k:g}i, {c.coating.thickness_nm:g} nm, "
                f"alpha {c.coating.alpha:g}",
            ),
            ("estimator, scattering", f"{self.estimator}, {c.scattering}"),
            ("rays, seconds", f"{self.rays}, {self.seconds:.3g}"),
            ("grid", f"{self.mueller.shape[0]} x {self.mueller.shape[1]} bins of 4 x 4"),
            ("albedo", f"{self.albedo():.6g} +- {self.albedo_stderr():.2g}"),
        ]
        return card("labbrdf TraceResult", facts)

    @property
    def estimator(self) -> str:
        """``"evaluated"`` or ``"counting"``: what produced this result.

        Read from the result itself (its batch errors), not from the config: a file
        written before the evaluated estimator existed holds a counting run whatever its
        config would resolve to today.
        """
        return "evaluated" if self.stderr is not None else "counting"

    @property
    def mueller_stderr(self) -> NDArray[np.float64]:
        """Monte Carlo standard error of :attr:`mueller` [sr^-1].

        Evaluated estimator: from the spread of the independent batches (:attr:`stderr`).
        Counting: from the per-ray spread (every ray is an independent sample); zero where
        no ray exited, so compare only bins with enough rays (:attr:`counts`).
        """
        if self.stderr is not None:
            return self.stderr
        n = self.rays
        mean = self.sums / n
        var = np.maximum(self.sumsq / n - mean * mean, 0.0) / n
        return np.sqrt(var) / self._grid.cos_solid_angle_sr[:, :, None, None]

    def stokes(self, stokes_in: ArrayLike = UNPOLARIZED) -> NDArray[np.float64]:
        """Exit Stokes BRDF ``f @ S_in`` per bin, shape (n_theta, n_phi, 4) [sr^-1]."""
        return self.mueller @ _stokes(stokes_in)

    def s0(self, stokes_in: ArrayLike = UNPOLARIZED) -> NDArray[np.float64]:
        """S0 map [sr^-1] for the input Stokes vector (default unpolarized)."""
        return self.stokes(stokes_in)[..., 0]

    def dop(self, stokes_in: ArrayLike = UNPOLARIZED) -> NDArray[np.float64]:
        """Degree of polarization map (Dong 2022 eq. (13)); NaN where no ray exited [1]."""
        st = self.stokes(stokes_in)
        pol = np.sqrt((st[..., 1:] ** 2).sum(axis=-1))
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(st[..., 0] > 0, pol / st[..., 0], np.nan)

    def dop_stderr(self, stokes_in: ArrayLike = UNPOLARIZED) -> NDArray[np.float64]:
        """Standard error of :meth:`dop` from the spread of the batch DOPs [1].

        Evaluated estimator only (NaN maps for counting, whose per-ray errors do not carry
        the covariances the DOP needs). ``sqrt(sum_b N_b (d_b - d)^2 / (N (B - 1)))``, the
        batch DOPs d_b weighted by their rays.
        """
        if self.batch_mueller is None:
            return np.full(self.sums.shape[:2], np.nan)
        s = _stokes(stokes_in)
        st = self.batch_mueller.astype(np.float64) @ s
        with np.errstate(divide="ignore", invalid="ignore"):
            d_b = np.sqrt((st[..., 1:] ** 2).sum(axis=-1)) / st[..., 0]
        d = self.dop(stokes_in)
        w = self.block_rays.astype(float)[:, None, None]
        nb = w.shape[0]
        var = (w * (d_b - d) ** 2).sum(axis=0) / w.sum() / (nb - 1)
        return np.sqrt(var)

    def readable_dop(self, stokes_in: ArrayLike = UNPOLARIZED) -> NDArray[np.float64]:
        """:meth:`dop` where it can be read, NaN elsewhere [1].

        Counting estimator: bins with at least :data:`SHOW_COUNT` exiting rays; evaluated:
        bins whose DOP standard error (:meth:`dop_stderr`) is at most :data:`DOP_SE_MAX`.
        The report's maps show the DOP the same way.
        """
        dop = self.dop(stokes_in)
        if self.estimator == "evaluated":
            with np.errstate(invalid="ignore"):
                return np.where(self.dop_stderr(stokes_in) <= DOP_SE_MAX, dop, np.nan)
        return np.where(self.counts >= SHOW_COUNT, dop, np.nan)

    def s0_scale_max(self, stokes_in: ArrayLike = UNPOLARIZED) -> float | None:
        """Top of an S0 colour scale [sr^-1]: the largest S0 among well-populated bins.

        Counting estimator: bins with at least :data:`MIN_COUNT` exiting rays (None if
        there are none); evaluated: None (every bin is an estimate of its own, the whole
        range is shown).
        """
        if self.estimator == "evaluated":
            return None
        ok = self.counts >= MIN_COUNT
        return float(self.s0(stokes_in)[ok].max()) if ok.any() else None

    def in_plane(self, stokes_in: ArrayLike = UNPOLARIZED) -> dict[str, NDArray[np.float64]]:
        """S0 and DOP in the plane of incidence, back-scatter half first.

        The bins whose azimuth is nearest phi_r = 0 (back-scatter) and phi_r = 180 deg
        (specular half-plane), joined into one cut over a signed angle.

        Parameters
        ----------
        stokes_in : sequence of 4 floats
            Input Stokes vector (default unpolarized).

        Returns
        -------
        dict of arrays
            ``theta_deg`` (-theta_r on the back-scatter side, +theta_r on the specular
            side) [deg], ``s0`` [sr^-1], ``s0_stderr`` (the Monte Carlo error of M00 times
            S0_in for unpolarized input; NaN otherwise, the per-element errors not carrying
            the covariances a polarized input needs), ``dop`` [1] (:meth:`readable_dop`:
            NaN where too noisy to read), ``dop_stderr`` [1]
            (:meth:`dop_stderr`) and ``phi_r_deg`` (the two azimuths used).
        """
        s = _stokes(stokes_in)
        phi = self.phi_r_deg
        j0 = int(np.argmin(np.minimum(np.abs(phi), np.abs(360.0 - phi))))
        j180 = int(np.argmin(np.abs(phi - 180.0)))
        th = self.theta_r_deg
        back, fwd = slice(None, None, -1), slice(None)
        s0, dop, dop_e = self.s0(s), self.readable_dop(s), self.dop_stderr(s)
        if np.any(s[1:] != 0):
            s0_e = np.full(s0.shape, np.nan)
        else:
            s0_e = self.mueller_stderr[..., 0, 0] * s[0]

        def cut(a: NDArray[np.float64]) -> NDArray[np.float64]:
            return np.concatenate([a[back, j0], a[fwd, j180]])

        return {
            "theta_deg": np.concatenate([-th[back], th]),
            "s0": cut(s0),
            "s0_stderr": cut(s0_e),
            "dop": cut(dop),
            "dop_stderr": cut(dop_e),
            "phi_r_deg": np.array([phi[j0], phi[j180]]),
        }

    def plot(self, stokes_in: ArrayLike = UNPOLARIZED, ax: Any = None) -> Any:
        """Hemisphere maps of S0 and DOP and their cut in the plane of incidence.

        The maps are drawn as the report's tracer maps (polar: azimuth phi_r with the
        specular half-plane at 180 deg, radius theta_r; the DOP blank where it cannot be
        read, :meth:`readable_dop`; the S0 scale up to :meth:`s0_scale_max`, logarithmic
        when a peak dominates the map, ``labbrdf._plotting.map_scale``); the cut is
        :meth:`in_plane` with 1-sigma error bars (S0) and a band (DOP). The new figure is
        in the package's style (:mod:`labbrdf.figstyle`: readable at 96 dpi).

        Parameters
        ----------
        stokes_in : sequence of 4 floats
            Input Stokes vector (default unpolarized).
        ax : sequence of 3 matplotlib Axes, optional
            Where to draw: S0 map and DOP map (both with ``projection="polar"``) and the
            cut. Default a new figure with the two maps side by side above the cut.

        Returns
        -------
        matplotlib Figure
        """
        from ..figstyle import PAGE_WIDTH_IN, rc_context

        s = _stokes(stokes_in)
        with rc_context():
            if ax is None:
                import matplotlib.pyplot as plt

                fig = plt.figure(figsize=(PAGE_WIDTH_IN, 8.6), layout="constrained")
                grid = fig.add_gridspec(2, 2, height_ratios=[1.35, 1.0])
                ax = [
                    fig.add_subplot(grid[0, 0], projection="polar"),
                    fig.add_subplot(grid[0, 1], projection="polar"),
                    fig.add_subplot(grid[1, :]),
                ]
            axes = list(np.asarray(ax, dtype=object).ravel())
            if len(axes) != 3 or any(a.name != "polar" for a in axes[:2]):
                raise ValueError("ax: expected three Axes, the first two with projection='polar'")
            self._draw(s, axes)
        return axes[0].figure

    def _draw(self, s: NDArray[np.float64], axes: list[Any]) -> None:
        """The two maps and the cut of :meth:`plot` on ``axes``."""
        from .._plotting import draw_cut, draw_polar_pair, map_scale

        s0 = self.s0(s)
        edges = (self.theta_r_edges_deg, self.phi_r_edges_deg)
        titles = ("S\u2080", "DOP")
        sc = map_scale(s0, self.s0_scale_max(s))
        draw_polar_pair((axes[0], axes[1]), titles, (s0, self.readable_dop(s)), sc, edges)
        c = self.in_plane(s)
        draw_cut(axes[2], c["theta_deg"], c["s0"], c["s0_stderr"], c["dop"], c["dop_stderr"])
        axes[2].set_title(
            f"plane of incidence (\u03b8i = {self.config.theta_i_deg:g}\u00b0), "
            f"input Stokes {[float(v) for v in s]}; maps: azimuth \u03c6r (specular at "
            "180\u00b0), radius \u03b8r [deg]"
        )

    def albedo(self, stokes_in: ArrayLike = UNPOLARIZED) -> float:
        """Directional-hemispherical reflectance: exited S0 / incident S0 [1]."""
        s = _stokes(stokes_in)
        return float((self.hemi @ s)[0] / s[0])

    def hemi_stderr(self) -> NDArray[np.float64]:
        """Standard error of :attr:`hemi` from the spread of the blocks, shape (4, 4).

        NaN with fewer than 2 blocks. Blocks of unequal size are weighted by their rays.
        """
        a = self.block_hemi
        w = self.block_rays.astype(float)[:, None, None]
        nb = a.shape[0]
        if nb < 2:
            return np.full((4, 4), np.nan)
        mean = (a * w).sum(axis=0) / w.sum()
        var = ((w * (a - mean) ** 2).sum(axis=0) / w.sum()) * nb / (nb - 1)
        return np.sqrt(var / nb)

    def albedo_stderr(self, stokes_in: ArrayLike = UNPOLARIZED) -> float:
        """Standard error of :meth:`albedo` from the spread of the blocks [1]."""
        s = _stokes(stokes_in)
        a = self.block_hemi @ s
        w = self.block_rays.astype(float)
        nb = a.shape[0]
        if nb < 2:
            return float("nan")
        a0 = a[:, 0] / s[0]
        mean = np.sum(a0 * w) / w.sum()
        var = np.sum(w * (a0 - mean) ** 2) / w.sum() * nb / (nb - 1)
        return float(np.sqrt(var / nb))

    # -- I/O -------------------------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Write an .npz with ``mueller``, bin centres/edges, config JSON and ledger.

        A name without ``.npz`` gets it appended (as numpy does); the file is written
        atomically (:func:`labbrdf.outputs.atomic_output`). Returns the path written.
        """
        from ..outputs import atomic_output

        path = Path(path)
        final = path if path.suffix == ".npz" else path.with_name(path.name + ".npz")
        with atomic_output(final) as tmp, open(tmp, "wb") as fh:
            self._savez(fh)
        return final

    def _savez(self, fh: Any) -> None:
        extra: dict[str, Any] = {}
        if self.stderr is not None:
            extra["stderr"] = self.stderr
        if self.batch_mueller is not None:
            extra["batch_mueller"] = self.batch_mueller
        np.savez_compressed(
            fh,
            mueller=self.mueller,
            mueller_stderr=self.mueller_stderr,
            theta_r_deg=self.theta_r_deg,
            phi_r_deg=self.phi_r_deg,
            theta_r_edges_deg=self.theta_r_edges_deg,
            phi_r_edges_deg=self.phi_r_edges_deg,
            sums=self.sums,
            sumsq=self.sumsq,
            counts=self.counts,
            hemi=self.hemi,
            block_hemi=self.block_hemi,
            block_rays=self.block_rays,
            config=np.array(self.config.to_json()),
            ledger=np.array(json.dumps(self.ledger, sort_keys=True)),
            seconds=np.array(self.seconds),
            events=np.array(self.events),
            info=np.array(json.dumps(self.info, sort_keys=True)),
            **extra,
        )

    @classmethod
    def load(cls, path: str | Path) -> TraceResult:
        """Read a file written by :meth:`save`."""
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as z:
                cfg = TraceConfig.from_json(str(z["config"]))
                return cls(
                    config=cfg,
                    sums=z["sums"],
                    sumsq=z["sumsq"],
                    counts=z["counts"],
                    hemi=z["hemi"],
                    ledger=json.loads(str(z["ledger"])),
                    block_hemi=z["block_hemi"],
                    block_rays=z["block_rays"],
                    seconds=float(z["seconds"]),
                    events=int(z["events"]),
                    stderr=z["stderr"] if "stderr" in z else None,
                    batch_mueller=z["batch_mueller"] if "batch_mueller" in z else None,
                    info=json.loads(str(z["info"])) if "info" in z else {},
                )
        except (KeyError, ValueError, OSError) as exc:
            raise ValueError(f"{path}: not a labbrdf TraceResult .npz ({exc})") from exc


def trace_summary(result: TraceResult) -> dict[str, Any]:
    """JSON-safe summary for the CLI: albedo, energy fractions, rays, seconds."""
    led = result.ledger
    return {
        "albedo": result.albedo(),
        "albedo_stderr": result.albedo_stderr(),
        "energy": {
            "exited": led["exited"],
            "absorbed": led["absorbed"],
            "terminated": led["terminated"],
        },
        "rays": result.rays,
        "estimator": result.estimator,
        "seconds": result.seconds,
        "events": result.events,
        "config": result.config.to_dict(),
    }
