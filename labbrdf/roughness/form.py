"""Form of a height map: how much of its height variance a quadric carries, and its shape.

A map of a curved part (a cylinder, a lens) levelled by a plane keeps the curvature in its
"roughness": sigma, slopes and correlation length then describe the form, not the finish.
:func:`check_form` measures the share of the height variance left by the levelling that a
least-squares quadric (the levelling of degree 2, :func:`labbrdf.roughness.levelling.level`) also
removes, and names the quadric's shape from its principal curvatures: a cylinder (one
curvature much the larger), a sphere or bowl (two alike, same sign), a saddle.

Physics layer: numpy only; heights and lengths in metres.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .levelling import level

__all__ = ["FORMS", "FORM_DOMINATES", "CYLINDER_RATIO", "FormCheck", "check_form"]

#: the form removals the levelling offers, by name: the polynomial's total degree
FORMS: dict[str, int] = {"mean": 0, "plane": 1, "quadric": 2}

#: a map is dominated by form when the quadric removes at least this share of the height
#: variance the levelling left (sigma then falls below sqrt(1 - 0.5) = 71 % of its value)
FORM_DOMINATES = 0.5

#: principal curvatures whose ratio is at most this are a cylinder: the straighter axis
#: then carries at most 0.25^2 = 6 % of the quadric's height variance (variance goes with
#: the square of the curvature)
CYLINDER_RATIO = 0.25

#: most points the quadric's curvature is fitted on (an even subsample of a larger map)
_MAX_POINTS = 1 << 18


@dataclass(frozen=True)
class FormCheck:
    """The form a levelled height map keeps.

    Attributes
    ----------
    degree : int
        The levelling the share is relative to (0 mean, 1 plane).
    share : float
        Share of the height variance after that levelling which a quadric removes [1].
    dominated : bool
        ``share >= FORM_DOMINATES``.
    shape : str
        ``"cylinder"``, ``"sphere"``, ``"saddle"`` (a map) or ``"arc"`` (a profile).
    radii_m : tuple of float
        Principal radii of curvature, smallest first [m] (inf: straight).
    axis_deg : float
        Direction of the straighter principal axis (a cylinder's axis), from +x towards +y
        [deg], in (-90, 90]; NaN for a profile.
    """

    degree: int
    share: float
    dominated: bool
    shape: str
    radii_m: tuple[float, ...]
    axis_deg: float

    def message(self) -> str:
        """One sentence: the share, the shape and what to do."""
        left = {0: "the mean", 1: "the mean plane"}.get(self.degree, f"degree {self.degree}")
        r = " and ".join(_fmt_radius(v) for v in self.radii_m)
        shape = self.shape
        if self.shape == "cylinder":
            shape = f"cylinder of radius {_fmt_radius(self.radii_m[0])}, axis at "
            shape += f"{self.axis_deg:.0f} deg from x"
        elif self.shape != "arc":
            shape = f"{self.shape}, radii {r}"
        else:
            shape = f"arc of radius {r}"
        return (
            f"form dominates: a quadric carries {100 * self.share:.3g} % of the height variance "
            f"left after removing {left} ({shape}); sigma, slopes and c describe the form, "
            "not the finish: remove it (--form quadric, degree=2)"
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields (infinite radii as None)."""
        d = asdict(self)
        d["radii_m"] = [v if math.isfinite(v) else None for v in self.radii_m]
        d["axis_deg"] = self.axis_deg if math.isfinite(self.axis_deg) else None
        return d


def _fmt_radius(r: float) -> str:
    if not math.isfinite(r):
        return "inf"
    for unit, f in (("m", 1.0), ("mm", 1e-3), ("um", 1e-6)):
        if r >= f:
            return f"{r / f:.3g} {unit}"
    return f"{r / 1e-9:.3g} nm"


def _curvatures(z: np.ndarray, px: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Principal curvatures [1/m] of the least-squares quadric, and their directions."""
    step = max(1, int(math.ceil(math.sqrt(z.size / _MAX_POINTS))))
    sub = z[(slice(None, None, step),) * z.ndim]
    axes = [np.arange(0, n * step, step)[: sub.shape[k]] * px[k] for k, n in enumerate(sub.shape)]
    grids = np.meshgrid(*axes, indexing="ij")
    ok = np.isfinite(sub)
    scale = max(n * p for n, p in zip(z.shape, px, strict=True)) / 2  # coordinates in [-1, 1]
    c = [(g[ok] - g[ok].mean()) / scale for g in grids]
    if z.ndim == 1:
        cols = [np.ones_like(c[0]), c[0], c[0] ** 2]
    else:
        x, y = c
        cols = [np.ones_like(x), x, y, x * x, x * y, y * y]
    h = sub[ok] - sub[ok].mean()
    coef = np.linalg.lstsq(np.column_stack(cols), h, rcond=None)[0] / scale**2
    if z.ndim == 1:
        return np.array([2.0 * coef[2]]), np.eye(1)
    a, b, cc = coef[3], coef[4], coef[5]
    k, v = np.linalg.eigh(np.array([[2 * a, b], [b, 2 * cc]]))
    return k, v


def check_form(
    heights: ArrayLike, pixel_size: float | tuple[float, ...], degree: int = 1
) -> FormCheck | None:
    """How much form a height map levelled to ``degree`` keeps.

    Parameters
    ----------
    heights : array_like, 1-D or 2-D
        Heights [m]; NaN points are invalid.
    pixel_size : float or tuple of float
        Grid spacing per axis [m].
    degree : int
        The levelling applied (0 mean, 1 plane); at 2 or above there is no quadric left
        to find.

    Returns
    -------
    FormCheck or None
        None for ``degree >= 2`` or a map whose levelled heights are all zero.
    """
    z = np.asarray(heights, dtype=float)
    if degree >= 2:
        return None
    px = tuple(float(p) for p in np.broadcast_to(np.asarray(pixel_size, float), (z.ndim,)))
    before = float(np.nanmean(level(z, degree) ** 2))
    after = float(np.nanmean(level(z, 2) ** 2))
    if not before > 0:
        return None
    share = 1.0 - after / before
    k, v = _curvatures(z, px)
    order = np.argsort(-np.abs(k))  # the most curved first: the smallest radius
    k, v = k[order], v[:, order]
    radii = tuple(1.0 / abs(x) if x != 0 else math.inf for x in k)
    if z.ndim == 1:
        return FormCheck(degree, share, share >= FORM_DOMINATES, "arc", radii, math.nan)
    if abs(k[1]) <= CYLINDER_RATIO * abs(k[0]):
        shape = "cylinder"
    elif k[0] * k[1] > 0:
        shape = "sphere"
    else:
        shape = "saddle"
    ex, ey = v[:, 1]  # the straighter axis
    ang = (math.degrees(math.atan2(ey, ex)) + 90.0) % 180.0 - 90.0
    ang = 90.0 if ang == -90.0 else ang
    return FormCheck(degree, share, share >= FORM_DOMINATES, shape, radii, ang)
