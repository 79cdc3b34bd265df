"""Power spectral densities (PSDs) of measured height maps and profiles, and their composite.

Arrays in, arrays out (heights already read, in metres): the 1-D PSD of a profile or of the
rows / columns of a map, the 2-D PSD of a map with its azimuthal average, each over the band
of spatial frequencies its sampling holds, with an uncertainty per frequency bin; several
spectra of one sample (different magnifications or instruments) combined into one composite
PSD over the union of their bands, the overlaps checked for agreement.

Conventions (those of :mod:`labbrdf.roughness.psd_models`): spatial frequency ``f`` [1/m]
(cycles per metre); the 2-D PSD [m^4] integrates over the frequency plane to the height
variance, the 1-D PSD [m^3] is two-sided and integrates over ``-inf < fx < inf`` to it.

Pipeline
--------
1. *Detrending*: the least-squares polynomial of total degree ``degree`` is subtracted
   (default 1, the mean plane), by :func:`labbrdf.roughness.levelling.level`, the levelling of
   ``labbrdf surface``.
2. *Window*: SurfaceTopography's (default ``"hann"``, normalised so that the mean of its
   square is one: the expected variance is kept); for a map's 2-D PSD its rotationally
   symmetric Hann window, for profiles and map rows a Hann window along the profile.
   ``"none"`` leaves the heights as they are (the periodogram then obeys Parseval exactly).
3. *Periodogram*: SurfaceTopography's ``power_spectrum_from_profile`` and
   ``power_spectrum_from_area`` (Jacobs, Junge & Pastewka 2017):
   ``C1D(q) = |dx sum h_i exp(-i q x_i)|^2 / L`` and
   ``C2D(q) = |dx dy sum h_ij exp(-i q.r_ij)|^2 / (Lx Ly)`` at ``q = 2 pi k / L``, with
   ``sigma^2 = (1/pi) int_0^inf C1D dq = (2 pi)^-2 int C2D d^2q``. With ``q = 2 pi f``
   these are exactly our two-sided ``PSD1(f) = C1D(2 pi f)`` and ``PSD2(f) = C2D(2 pi f)``
   (checked by Parseval in ``tests/roughness/test_psd.py``).
4. *Band*: from ``f_min = 1 / L`` (one period over the map, ``L`` the longest side for a
   map) to the Nyquist frequency ``1 / (2 dx)`` (the coarser pixel of a map). Periods
   longer than the map are removed by the detrending and not measured.
5. *Bins*: logarithmic, ``per_decade`` bins per decade; each bin holds the mean of the
   periodogram values in it (over the rows averaged, or over the annulus) and its
   standard error ``s / sqrt(n)``, ``s`` their standard deviation and ``n`` the number
   of independent values (an annulus counts each ``+f, -f`` pair once). Below
   :data:`MIN_SPREAD` values ``s`` is the mean itself: a periodogram value of a Gaussian
   surface is exponentially distributed, its standard deviation equal to its mean
   (Priestley 1981, ch. 6). The values of an unwindowed periodogram are independent;
   a window correlates neighbouring frequencies (Hann: over about two bins), so with
   it the annulus error is too small by up to ``sqrt(2)``. The rows of a map are
   correlated over a correlation length: a row-averaged 1-D PSD takes its error from
   the spread of the means of :data:`ROW_BLOCKS` contiguous blocks of rows instead.

Composite (Duparre et al. 2002): the spectra are put on one logarithmic grid; in
a bin covered by several, the inverse-variance weighted mean is taken; where two spectra
overlap, ``chi^2 / dof`` of their difference against the combined uncertainties and the
median ratio say whether they agree (a ratio far from 1 means a calibration or a
transfer-function problem of one instrument, or roughness outside one map's band leaking
in through the window).

References
----------
T. D. B. Jacobs, T. Junge, L. Pastewka, "Quantitative characterization of surface
topography using spectral analysis", Surf. Topogr.: Metrol. Prop. 5 (2017) 013001.
A. Duparre, J. Ferre-Borrull, S. Gliech, G. Notni, J. Steinert, J. M. Bennett, "Surface
characterization techniques for determining the root-mean-square roughness and power
spectral densities of optical components", Appl. Opt. 41 (2002) 154-171.
M. B. Priestley, *Spectral Analysis and Time Series*, Academic Press (1981), ch. 6.
J. M. Elson, J. M. Bennett, "Calculation of the power spectral density from surface
profile data", Appl. Opt. 34 (1995) 201-208.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .levelling import level

__all__ = [
    "AGREEMENT_CHI2",
    "MIN_POINTS",
    "MIN_SPREAD",
    "ROW_BLOCKS",
    "Overlap",
    "Spectrum",
    "composite",
    "map_psd",
    "profile_psd",
]

FloatArray = NDArray[np.float64]

#: fewest points per axis a PSD is computed from
MIN_POINTS = 16
#: independent values a bin needs for its sample spread to give its uncertainty
MIN_SPREAD = 10
#: contiguous blocks of rows whose means give a row-averaged PSD's uncertainty
ROW_BLOCKS = 16
#: chi^2 / dof above which two overlapping spectra are said to disagree
AGREEMENT_CHI2 = 4.0


def _surface_topography() -> Any:
    try:
        import SurfaceTopography
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "power spectra need SurfaceTopography: pip install 'labbrdf[topography]'"
        ) from exc
    return SurfaceTopography


# ------------------------------------------------------------------------ the result
@dataclass(frozen=True)
class Spectrum:
    """A binned PSD with its uncertainty and band.

    Attributes
    ----------
    f : ndarray
        Bin frequency [1/m]: the mean of the frequencies of the values in the bin.
    psd : ndarray
        Mean PSD in the bin: [m^3] for ``kind == "1d"``, [m^4] for ``"2d"``.
    u : ndarray
        Standard uncertainty of ``psd`` (standard error of the bin mean), same unit.
    n : ndarray of int
        Independent periodogram values in the bin.
    kind : str
        ``"1d"`` (two-sided profile PSD) or ``"2d"`` (azimuthal average of the 2-D PSD).
    direction : str
        ``"x"`` / ``"y"`` (profiles along that axis), ``"radial"`` (2-D) or
        ``"composite"``.
    band : (float, float)
        ``(f_min, f_max)`` [1/m] the sampling holds.
    label : str
        Where it comes from (a file name).
    detrend, window : str
        What was done before the transform.
    pixel_size : tuple of float
        Grid spacing [m] (empty for a composite).
    shape : tuple of int
        Points per axis (empty for a composite).
    grid_f, grid_psd : ndarray
        The unbinned periodogram: ``|f|`` of each grid value [1/m] and its PSD (for a
        1-D PSD the two-sided grid folded to ``f >= 0``: each ``f > 0`` value stands for
        ``+f`` and ``-f``, ``grid_weight`` 2); empty for a composite.
    grid_weight : ndarray
        Frequency-plane measure of each grid value: ``df`` [1/m] times the number of
        grid points it stands for (1-D), ``dfx dfy`` [1/m^2] (2-D).
    notes : tuple of str
        Doubts and what was done (members, overlaps of a composite).
    """

    f: FloatArray
    psd: FloatArray
    u: FloatArray
    n: NDArray[np.int64]
    kind: str
    direction: str
    band: tuple[float, float]
    label: str = ""
    detrend: str = ""
    window: str = ""
    pixel_size: tuple[float, ...] = ()
    shape: tuple[int, ...] = ()
    grid_f: FloatArray = field(default_factory=lambda: np.zeros(0), repr=False)
    grid_psd: FloatArray = field(default_factory=lambda: np.zeros(0), repr=False)
    grid_weight: FloatArray = field(default_factory=lambda: np.zeros(0), repr=False)
    notes: tuple[str, ...] = ()
    edges: FloatArray = field(default_factory=lambda: np.zeros(0), repr=False)
    grid_d2: FloatArray = field(default_factory=lambda: np.zeros(0), repr=False)

    def bin_points(self) -> tuple[FloatArray, FloatArray, NDArray[np.int64]]:
        """Where each bin's mean was taken: distinct grid frequencies, weights, bin index.

        ``sum(w * g(f_grid))`` per bin (``np.bincount`` over the index) is the mean of a
        function ``g`` over the same periodogram values the bin averages: what a model
        must be compared with (a bin-centre value is biased where the PSD curves within
        a bin). Without a grid (a composite) each bin is its own point.
        """
        if not self.grid_f.size or not self.edges.size:
            return self.f, np.ones_like(self.f), np.arange(self.f.size, dtype=np.int64)
        idx = _bin_index(self.grid_f, self.edges)
        ok = idx >= 0
        fu, inv, cnt = np.unique(self.grid_f[ok], return_inverse=True, return_counts=True)
        ib = np.zeros(fu.size, dtype=np.int64)
        ib[inv] = idx[ok]
        occupied = np.unique(ib)  # bins with values, in order: the rows of f / psd
        ib = np.searchsorted(occupied, ib)
        w = cnt / np.bincount(ib, weights=cnt)[ib]
        return fu, w.astype(float), ib

    @property
    def unit(self) -> str:
        """Unit of :attr:`psd`: ``"m^3"`` (1-D) or ``"m^4"`` (2-D)."""
        return "m^3" if self.kind == "1d" else "m^4"

    def _band(self, f_min: float | None, f_max: float | None) -> tuple[float, float]:
        lo = self.band[0] if f_min is None else float(f_min)
        hi = self.band[1] if f_max is None else float(f_max)
        if not 0 <= lo < hi:
            raise ValueError(f"band must satisfy 0 <= f_min < f_max, got [{lo}, {hi}] 1/m")
        return lo, hi

    def _moment(
        self, power: int, f_min: float | None, f_max: float | None, difference: bool = False
    ) -> float:
        lo, hi = self._band(f_min, f_max)
        if self.grid_f.size:
            top = hi * (1.0 + 1e-12)  # the Nyquist frequency k / (n dx) up to rounding
            sel = (self.grid_f >= lo * (1.0 - 1e-12)) & (self.grid_f <= top) & (self.grid_f > 0)
            f, p, w = self.grid_f[sel], self.grid_psd[sel], self.grid_weight[sel]
            gain = self.grid_d2[sel] if difference else (2.0 * np.pi * f) ** power
            return float(np.sum(p * w * gain))
        if difference:
            raise ValueError("a composite PSD has no pixel: use the continuum slope")
        sel = (self.f >= lo) & (self.f <= hi)
        f, p = self.f[sel], self.psd[sel]
        if f.size < 2:
            return math.nan
        meas = 2.0 * np.pi * f if self.kind == "2d" else np.full_like(f, 2.0)
        g = p * meas * (2.0 * np.pi * f) ** power
        # bins further apart than 1.5 grid steps bound a gap no map covers: not integrated
        r = np.diff(np.log(f))
        inside = r <= 1.5 * float(np.median(r))
        return float(np.sum(((g[1:] + g[:-1]) / 2 * np.diff(f))[inside]))

    def band_sigma(self, f_min: float | None = None, f_max: float | None = None) -> float:
        """RMS height [m] the PSD carries over ``[f_min, f_max]`` (default: its band).

        The sum of the unbinned periodogram times the frequency-plane measure of each
        value (Parseval: with ``window="none"`` and the full band it is the RMS of the
        detrended heights exactly); a composite integrates its bins by the trapezoid
        rule (``2 pi f PSD2`` over ``f``, or ``2 PSD1``), leaving out a gap no map covers.
        """
        return math.sqrt(self._moment(0, f_min, f_max))

    def band_slope(
        self, f_min: float | None = None, f_max: float | None = None, *, difference: bool = False
    ) -> float:
        """RMS slope [rad] over ``[f_min, f_max]``: ``sqrt(sum (2 pi f)^2 PSD df)``.

        For a 2-D PSD the gradient magnitude (both axes), for a 1-D PSD the slope along
        the profile: the continuum derivative. ``difference=True``: the forward difference
        over one pixel that ``labbrdf surface`` takes, whose power gain is
        ``(2 sin(pi fx dx) / dx)^2 (+ the same along y)`` instead of ``(2 pi f)^2``
        (4 / pi^2, 60 % less, at the Nyquist frequency); with the full band and no window this is
        the RMS of the periodic forward differences exactly.
        """
        return math.sqrt(self._moment(2, f_min, f_max, difference))


# ------------------------------------------------------------------------ helpers
def _complete(z: ArrayLike) -> FloatArray:
    a = np.asarray(np.ma.filled(np.ma.asarray(z, dtype=float), np.nan), dtype=float)
    if a.ndim not in (1, 2):
        raise ValueError(f"heights must be a profile (1-D) or a map (2-D), got {a.ndim}-D")
    if min(a.shape) < MIN_POINTS:
        raise ValueError(
            f"too small for a PSD: {' x '.join(map(str, a.shape))} points, at least "
            f"{MIN_POINTS} per axis are needed"
        )
    bad = int(np.count_nonzero(~np.isfinite(a)))
    if bad:
        raise ValueError(
            f"{bad} undefined height points (gaps): a PSD needs a complete grid; crop the "
            "map to a complete region or fill the gaps first"
        )
    return a


def _pixels(pixel_size: float | ArrayLike, ndim: int) -> tuple[float, ...]:
    p = np.broadcast_to(np.asarray(pixel_size, dtype=float), (ndim,))
    if not np.all(np.isfinite(p)) or np.any(p <= 0):
        raise ValueError(f"pixel_size must be positive and finite [m], got {pixel_size!r}")
    return tuple(float(v) for v in p)


def _st_window(window: str) -> str:
    w = str(window).lower()
    return "None" if w in ("none", "") else w


def _detrend_text(degree: int) -> str:
    return {0: "mean removed", 1: "least-squares mean plane removed"}.get(
        degree, f"least-squares polynomial of total degree {degree} removed"
    )


def _window_text(window: str, direction: str) -> str:
    if _st_window(window) == "None":
        return "none"
    shape = "rotationally symmetric " if direction == "radial" else ""
    along = "" if direction == "radial" else f" along {direction}"
    return f"{shape}{window}{along} (SurfaceTopography; mean square 1)"


def _log_edges(lo: float, hi: float, per_decade: int) -> FloatArray:
    n = max(1, int(math.ceil(per_decade * math.log10(hi / lo))))
    return np.geomspace(lo, hi, n + 1)


def _bin_index(f: FloatArray, edges: FloatArray) -> NDArray[np.int64]:
    """Bin of each ``f`` (the top edge in the last bin), -1 outside the edges."""
    idx = np.digitize(f, edges) - 1
    idx[f == edges[-1]] = len(edges) - 2
    idx[(idx < 0) | (idx > len(edges) - 2)] = -1
    return idx.astype(np.int64)


def _bin(
    f: FloatArray, values: FloatArray, edges: FloatArray, dof: FloatArray | None = None
) -> tuple[FloatArray, FloatArray, FloatArray, NDArray[np.int64]]:
    """Mean, standard error and count of ``values`` per bin of ``f`` (empty bins dropped).

    ``dof`` weights each value's contribution to the independent count (0.5 for a value
    whose conjugate is in the same bin); ``values`` may be 2-D (rows x frequencies), each
    column sharing the frequency of ``f``.
    """
    idx = _bin_index(f, edges)
    v2 = np.atleast_2d(values)
    d = np.ones_like(f) if dof is None else dof
    out_f, out_p, out_u, out_n = [], [], [], []
    for b in range(len(edges) - 1):
        sel = idx == b
        if not sel.any():
            continue
        vals = v2[:, sel].ravel()
        n_ind = max(float(np.sum(d[sel])) * v2.shape[0], 1.0)
        mean = float(np.mean(vals))
        if v2.shape[0] >= 2 * ROW_BLOCKS:
            # rows of a map: the spread of the means of contiguous blocks of rows (blocks
            # many correlation lengths wide are independent where single rows are not)
            blocks = np.array_split(v2[:, sel], ROW_BLOCKS, axis=0)
            bm = np.array([float(np.mean(b)) for b in blocks])
            u = float(np.std(bm, ddof=1)) / math.sqrt(ROW_BLOCKS)
        else:
            # periodogram values of a Gaussian surface are exponential (sd = mean): used
            # where too few values are in the bin for their sample spread to be trusted
            sd = float(np.std(vals, ddof=1)) if n_ind >= MIN_SPREAD else mean
            u = sd / math.sqrt(n_ind)
        out_f.append(float(np.mean(f[sel])))
        out_p.append(mean)
        out_u.append(u)
        out_n.append(int(round(n_ind)))
    return np.array(out_f), np.array(out_p), np.array(out_u), np.array(out_n, dtype=np.int64)


# ------------------------------------------------------------------------ 1-D spectra
def _row_periodograms(h: FloatArray, dx: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Folded two-sided periodograms of each column of ``h`` (profiles along axis 0).

    Returns the frequencies ``k / L`` for ``k = 0 .. n//2``, the per-profile values
    ``(n_f, n_profiles)`` and the measure of each frequency (``df``, times 2 where ``+f``
    and ``-f`` are folded together).
    """
    n = h.shape[0]
    L = n * dx
    c = np.abs(dx * np.fft.rfft(h, axis=0)) ** 2 / L
    f = np.arange(c.shape[0]) / L
    w = np.full(c.shape[0], 2.0 / L)
    w[0] = 1.0 / L
    if n % 2 == 0:
        w[-1] = 1.0 / L  # the Nyquist value is its own conjugate
    return f, c, w


def _st_profile_mean(z: FloatArray, px: tuple[float, ...], window: str) -> FloatArray:
    """SurfaceTopography's profile PSD on its FFT grid (q = 0 .. below Nyquist)."""
    st = _surface_topography()
    if z.ndim == 1:
        topo = st.UniformLineScan(z, (z.shape[0] * px[0],), periodic=False)
    else:
        topo = st.Topography(z, (z.shape[0] * px[0], z.shape[1] * px[1]), periodic=False)
    _, c = topo.power_spectrum_from_profile(
        window=_st_window(window), reliable=False, resampling_method=None
    )
    return np.asarray(c, dtype=float)


def _st_windowed(z: FloatArray, px: tuple[float, ...], window: str, direction: str) -> FloatArray:
    st = _surface_topography()
    if z.ndim == 1:
        topo = st.UniformLineScan(z, (z.shape[0] * px[0],), periodic=False)
    else:
        topo = st.Topography(z, (z.shape[0] * px[0], z.shape[1] * px[1]), periodic=False)
    return np.asarray(topo.window(window=_st_window(window), direction=direction).heights())


def profile_psd(
    heights: ArrayLike,
    pixel_size: float | ArrayLike,
    *,
    axis: str = "x",
    degree: int = 1,
    window: str = "hann",
    per_decade: int = 10,
    label: str = "",
) -> Spectrum:
    """Two-sided 1-D PSD [m^3] of a profile, or the average over a map's rows or columns.

    Parameters
    ----------
    heights : array_like, shape (N,) or (M, N)
        Heights [m] on a uniform grid; ``heights[i, j]`` at ``(i dx, j dy)``. No gaps.
    pixel_size : float or (float, float)
        Grid spacing [m].
    axis : {"x", "y"}
        For a map: the direction of the profiles (``"x"``: along the first index).
    degree : int
        Detrending polynomial (total degree over the whole map or profile).
    window : str
        ``"hann"`` (default), another :func:`scipy.signal.get_window` name, or ``"none"``.
    per_decade : int
        Logarithmic bins per decade of frequency.
    label : str
        Name kept in the result (the file).

    Returns
    -------
    Spectrum
        ``kind="1d"``; ``band = (1/L, 1/(2 dx))`` along the profiles.

    Raises
    ------
    ValueError
        Gaps, fewer than :data:`MIN_POINTS` points per axis, bad pixel size or axis.
    """
    z = _complete(heights)
    px = _pixels(pixel_size, z.ndim)
    if axis not in ("x", "y") or (z.ndim == 1 and axis != "x"):
        raise ValueError(f"axis must be 'x' or (for a map) 'y', got {axis!r}")
    lz = level(z, degree)
    if z.ndim == 2 and axis == "y":
        lz, px = lz.T.copy(), (px[1], px[0])
    st_mean = _st_profile_mean(lz, px, window)
    h = _st_windowed(lz, px, window, "x")
    f, c, w = _row_periodograms(h.reshape(h.shape[0], -1), px[0])
    L = z.shape[0 if axis == "x" else 1] * px[0]
    band = (1.0 / L, 1.0 / (2.0 * px[0]))
    mean = c.mean(axis=1)
    mean[: st_mean.size] = st_mean  # the same numbers, SurfaceTopography's arithmetic
    d2 = (2.0 * np.sin(np.pi * f * px[0]) / px[0]) ** 2
    edges = _log_edges(band[0], band[1], per_decade)
    bf, bp, bu, bn = _bin(f, c.T, edges)
    return Spectrum(
        bf,
        bp,
        bu,
        bn,
        "1d",
        axis,
        band,
        label,
        _detrend_text(degree),
        _window_text(window, axis),
        px,
        tuple(int(v) for v in z.shape),
        f,
        mean,
        w,
        _notes_1d(z),
        edges,
        d2,
    )


def _notes_1d(z: FloatArray) -> tuple[str, ...]:
    if z.ndim == 2 and z.shape[1] < 2 * ROW_BLOCKS:
        return (
            f"only {z.shape[1]} rows: the per-bin uncertainty treats them as independent "
            "(a lower bound where rows are correlated)",
        )
    return ()


# ------------------------------------------------------------------------ 2-D spectra
def _st_area_map(z: FloatArray, px: tuple[float, ...], window: str) -> FloatArray:
    st = _surface_topography()
    topo = st.Topography(z, (z.shape[0] * px[0], z.shape[1] * px[1]), periodic=False)
    _, _, c_qk = topo.power_spectrum_from_area(
        window=_st_window(window), reliable=False, return_map=True
    )
    return np.asarray(c_qk, dtype=float)


def map_psd(
    heights: ArrayLike,
    pixel_size: float | ArrayLike,
    *,
    degree: int = 1,
    window: str = "hann",
    per_decade: int = 10,
    label: str = "",
) -> Spectrum:
    """Azimuthally averaged 2-D PSD [m^4] of an areal height map.

    Parameters
    ----------
    heights : array_like, shape (M, N)
        Heights [m] on a uniform grid, no gaps.
    pixel_size : float or (float, float)
        Grid spacing (dx, dy) [m].
    degree, window, per_decade, label
        As :func:`profile_psd` (``window`` ``"hann"`` or ``"none"``).

    Returns
    -------
    Spectrum
        ``kind="2d"``, ``direction="radial"``; ``band = (1 / max(Lx, Ly),
        1 / (2 max(dx, dy)))``: the annuli from there on hold full circles of values.

    Notes
    -----
    The 2-D periodogram is SurfaceTopography's ``power_spectrum_from_area`` map; the
    annulus average here uses our own logarithmic bins so that each bin has its spread.
    Where ``f`` exceeds the Nyquist frequency of the coarser axis, an annulus is only
    partly sampled: those values are left out of the bins (kept for Parseval sums).
    """
    z = _complete(heights)
    if z.ndim != 2:
        raise ValueError("an areal map (2-D heights) is needed for a 2-D PSD")
    px = _pixels(pixel_size, 2)
    lz = level(z, degree)
    c = _st_area_map(lz, px, window)
    nx, ny = z.shape
    fx = np.fft.fftfreq(nx, px[0])
    fy = np.fft.fftfreq(ny, px[1])
    fr = np.hypot(fx[:, None], fy[None, :])
    band = (1.0 / max(nx * px[0], ny * px[1]), 1.0 / (2.0 * max(px)))
    edges = _log_edges(band[0], band[1], per_decade)
    flat_f, flat_c = fr.ravel(), c.ravel()
    bf, bp, bu, bn = _bin(flat_f, flat_c, edges, dof=np.full(flat_f.size, 0.5))
    weight = np.full(flat_f.size, 1.0 / (nx * px[0] * ny * px[1]))
    d2 = (2.0 * np.sin(np.pi * fx * px[0]) / px[0])[:, None] ** 2 + (
        2.0 * np.sin(np.pi * fy * px[1]) / px[1]
    )[None, :] ** 2
    return Spectrum(
        bf,
        bp,
        bu,
        bn,
        "2d",
        "radial",
        band,
        label,
        _detrend_text(degree),
        _window_text(window, "radial"),
        px,
        (nx, ny),
        flat_f,
        flat_c,
        weight,
        (),
        edges,
        d2.ravel(),
    )


# ------------------------------------------------------------------------ composite
@dataclass(frozen=True)
class Overlap:
    """Agreement of two spectra where their bands overlap."""

    first: str
    second: str
    band: tuple[float, float]  # [1/m]
    n_bins: int
    chi2_dof: float  # of (psd_1 - psd_2) against sqrt(u_1^2 + u_2^2)
    median_ratio: float  # median of psd_1 / psd_2
    agree: bool

    def sentence(self) -> str:
        """One line for notes and tables."""
        lo, hi = (v * 1e-6 for v in self.band)
        verdict = "agree" if self.agree else "DISAGREE"
        return (
            f"{self.first} and {self.second} {verdict} over {lo:.3g}-{hi:.3g} 1/um "
            f"({self.n_bins} bins): chi^2/dof {self.chi2_dof:.2f}, median ratio "
            f"{self.median_ratio:.3g}"
        )


def _on_grid(s: Spectrum, centres: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``s`` interpolated (log-log) to ``centres``; NaN outside its binned range."""
    p = np.full(centres.size, np.nan)
    u = np.full(centres.size, np.nan)
    ok = (s.psd > 0) & np.isfinite(s.psd)
    if np.count_nonzero(ok) < 2:
        return p, u
    f, lp = np.log(s.f[ok]), np.log(s.psd[ok])
    lu = np.log(np.maximum(s.u[ok], 1e-300))
    lc = np.log(centres)
    inside = (lc >= f[0]) & (lc <= f[-1])
    p[inside] = np.exp(np.interp(lc[inside], f, lp))
    u[inside] = np.exp(np.interp(lc[inside], f, lu))
    return p, u


def _overlap(
    a: Spectrum,
    b: Spectrum,
    pa: FloatArray,
    pb: FloatArray,
    ua: FloatArray,
    ub: FloatArray,
    centres: FloatArray,
) -> Overlap | None:
    both = np.isfinite(pa) & np.isfinite(pb)
    if np.count_nonzero(both) < 1:
        return None
    d = (pa[both] - pb[both]) / np.hypot(ua[both], ub[both])
    chi2 = float(np.mean(d * d))
    ratio = float(np.median(pa[both] / pb[both]))
    fb = centres[both]
    return Overlap(
        a.label,
        b.label,
        (float(fb[0]), float(fb[-1])),
        int(both.sum()),
        chi2,
        ratio,
        chi2 <= AGREEMENT_CHI2,
    )


def _gaps(spectra: list[Spectrum]) -> list[str]:
    """Frequency ranges inside the union of the bands that no spectrum covers."""
    out, reach = [], 0.0
    for lo, hi in sorted(s.band for s in spectra):
        if reach and lo > reach:
            out.append(f"no map covers {reach:.3g}-{lo:.3g} 1/m (a gap in the composite)")
        reach = max(reach, hi)
    return out


def composite(
    spectra: list[Spectrum], *, per_decade: int = 10, label: str = "composite"
) -> tuple[Spectrum, list[Overlap]]:
    """One PSD over the union of the bands of several spectra of one sample.

    Parameters
    ----------
    spectra : list of Spectrum
        Of one kind (all ``"1d"`` or all ``"2d"``), in one convention.
    per_decade : int
        Bins per decade of the composite grid.
    label : str
        Name of the result.

    Returns
    -------
    (Spectrum, list of Overlap)
        The composite (``direction="composite"``, band the union) and the agreement of
        each overlapping pair.

    Notes
    -----
    Each spectrum is interpolated log-log to the composite bin centres inside its binned
    range; where several cover a bin, the inverse-variance weighted mean is taken with
    uncertainty ``1 / sqrt(sum 1/u_i^2)`` (Duparre et al. 2002 join AFM and profilometer
    spectra into one master PSD the same way, by averaging where they overlap).
    """
    if not spectra:
        raise ValueError("no spectra to combine")
    kinds = {s.kind for s in spectra}
    if len(kinds) != 1:
        raise ValueError(
            "cannot combine 1-D (profile) and 2-D (areal) PSDs: their units differ "
            "(m^3 and m^4); use one kind"
        )
    lo = min(s.band[0] for s in spectra)
    hi = max(s.band[1] for s in spectra)
    edges = _log_edges(lo, hi, per_decade)
    centres = np.sqrt(edges[:-1] * edges[1:])
    grids = [_on_grid(s, centres) for s in spectra]
    P = np.array([g[0] for g in grids])
    U = np.array([g[1] for g in grids])
    have = np.isfinite(P) & np.isfinite(U) & (U > 0)
    w = np.where(have, 1.0 / np.where(have, U, 1.0) ** 2, 0.0)
    wsum = w.sum(axis=0)
    keep = wsum > 0
    mean = np.sum(np.where(have, P, 0.0) * w, axis=0)[keep] / wsum[keep]
    unc = 1.0 / np.sqrt(wsum[keep])
    overlaps = []
    for i in range(len(spectra)):
        for j in range(i + 1, len(spectra)):
            o = _overlap(spectra[i], spectra[j], P[i], P[j], U[i], U[j], centres)
            if o is not None:
                overlaps.append(o)
    members = "; ".join(f"{s.label or '?'} {s.band[0]:.3g}-{s.band[1]:.3g} 1/m" for s in spectra)
    notes = (f"members: {members}", *(o.sentence() for o in overlaps), *_gaps(spectra))
    comp = Spectrum(
        centres[keep],
        mean,
        unc,
        have.sum(axis=0)[keep].astype(np.int64),
        spectra[0].kind,
        "composite",
        (float(lo), float(hi)),
        label,
        spectra[0].detrend,
        spectra[0].window,
        notes=notes,
        edges=edges,
    )
    return comp, overlaps
