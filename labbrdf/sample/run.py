"""A tracer run from what a user has: index values or files, roughness values or height maps.

:func:`trace_config_from_inputs` assembles the :class:`~labbrdf.Substrate` and the
:class:`~labbrdf.Coating` of a :class:`~labbrdf.TraceConfig` from

- the substrate index: a value, or the bulk n, k of an ellipsometer file at the traced
  wavelength (:func:`labbrdf.sample.bulk_index`);
- the substrate roughness: a GGX or Beckmann alpha, or the slope table of a measured
  areal height map (:func:`labbrdf.sample.measured_substrate`);
- an optional coating: index and thickness values, or the one layer of a film fit at the
  traced wavelength (:func:`labbrdf.sample.coating_from_fit`), with its top's roughness as an
  alpha (default: the substrate's) or a measured map.

``labbrdf trace`` is this function behind its options. Arguments that do not fit together
raise :class:`labbrdf.errors.SetupError`, whose message names the keywords (the command line
spells them as its options).
"""

from __future__ import annotations

import dataclasses
import os
import warnings
from collections.abc import Callable
from typing import Any, Literal

from ..adapters.topography import HeightMap
from ..errors import SetupError, escaped
from ..nk import NkError
from ..tracer.config import Coating, Substrate, TraceConfig
from ..tracer.medium import Medium
from .coating import coating_from_fit
from .index import bulk_index
from .slopes import analytic_table, height_map, measured_substrate, pitch

__all__ = ["SampleWarning", "trace_config_from_inputs"]

PathLike = str | os.PathLike[str]


class SampleWarning(UserWarning):
    """Something a sample was built with that its files did not state (e.g. a pixel size)."""


def _warn(message: str) -> None:
    warnings.warn(message, SampleWarning, stacklevel=3)


def _substrate(
    wavelength_nm: float,
    index: complex | None,
    nk_from: PathLike | None,
    alpha: float | None,
    surface: PathLike | HeightMap | None,
    distribution: str,
    read: Callable[[PathLike | HeightMap, str], HeightMap],
) -> Substrate:
    if (index is None) == (nk_from is None):
        raise SetupError("give the substrate index with {substrate_index} N+Kj or {nk_from} FILE")
    if nk_from is not None:
        try:
            index = bulk_index(nk_from, wavelength_nm)
        except NkError as exc:
            raise SetupError(f"{{nk_from}} {escaped(exc)}") from None
    assert index is not None
    if surface is not None:
        return measured_substrate(read(surface, "surface"), index)
    if alpha is None:
        raise SetupError("give the substrate roughness with {alpha} A or {surface} FILE")
    return Substrate(
        n=index.real, k=index.imag, alpha=alpha, ndf=analytic_table(distribution, alpha)
    )


def _base(albedo: float, metal: dict[str, object], coated: bool, roughness: bool) -> Substrate:
    """A Lambertian base of ``albedo``, refusing the conductor's arguments."""
    given = [f"{{{name}}}" for name, value in metal.items() if value is not None]
    if given:
        raise SetupError(f"{{base_albedo}} replaces the metal substrate: drop {', '.join(given)}")
    if coated and not roughness:
        raise SetupError(
            "{base_albedo} with a coating needs its roughness: {coating_alpha} A or "
            "{coating_surface} FILE (there is no substrate alpha to default to)"
        )
    try:
        return Substrate.lambertian(albedo)
    except ValueError as exc:
        raise SetupError(f"{{base_albedo}}: {escaped(exc)}") from None


def _coating(
    wavelength_nm: float,
    substrate: Substrate,
    index: complex | None,
    coating_from: PathLike | None,
    thickness_nm: float | None,
    alpha: float | None,
    surface: PathLike | HeightMap | None,
    distribution: str,
    read: Callable[[PathLike | HeightMap, str], HeightMap],
) -> Coating | None:
    if coating_from is not None:
        if index is not None or thickness_nm is not None:
            raise SetupError(
                "give the coating once: {coating_from} FIT.json, or {coating_index} and "
                "{thickness_nm}"
            )
        try:
            index, thickness_nm = coating_from_fit(coating_from, wavelength_nm)
        except ValueError as exc:
            raise SetupError(f"{{coating_from}} {escaped(exc)}") from None
    if index is None:
        if thickness_nm is not None or alpha is not None or surface is not None:
            raise SetupError(
                "{thickness_nm}, {coating_alpha} and {coating_surface} need {coating_index} "
                "(or {coating_from})"
            )
        return None
    if thickness_nm is None:
        raise SetupError("{coating_index} needs {thickness_nm} (nm)")
    if alpha is not None and surface is not None:
        raise SetupError("give the coating roughness once: {coating_alpha} or {coating_surface}")
    if surface is not None:
        hm = read(surface, "coating_surface")
        if hm.heights.ndim != 2:
            raise SetupError(
                f"{{coating_surface}} {escaped(hm.path)}: a line profile; the coating needs "
                "an areal height map"
            )
        try:
            top = Substrate.from_surface(hm.heights, pitch(hm))
        except ValueError as exc:
            raise SetupError(f"{{coating_surface}} {escaped(hm.path)}: {escaped(exc)}") from None
        coat_alpha, coat_ndf = float(top.alpha), top.ndf
    else:
        coat_alpha = alpha if alpha is not None else substrate.alpha
        coat_ndf = analytic_table(distribution, coat_alpha)
    return Coating(
        n=index.real, k=index.imag, thickness_nm=thickness_nm, alpha=coat_alpha, ndf=coat_ndf
    )


def _with_medium(coating: Coating | None, medium: tuple[float, float, float]) -> Coating:
    """The coating filled with the Henyey-Greenstein medium ``(tau, ssa, g)``."""
    if coating is None:
        raise SetupError(
            "{medium} needs a coating: {coating_index} and {thickness_nm}, or {coating_from}"
        )
    try:
        return dataclasses.replace(coating, medium=Medium(*medium))
    except ValueError as exc:
        raise SetupError(f"{{medium}} {escaped(exc)}") from None


def trace_config_from_inputs(
    wavelength_nm: float,
    theta_i_deg: float,
    *,
    base_albedo: float | None = None,
    substrate_index: complex | None = None,
    nk_from: PathLike | None = None,
    alpha: float | None = None,
    surface: PathLike | HeightMap | None = None,
    coating_index: complex | None = None,
    coating_from: PathLike | None = None,
    thickness_nm: float | None = None,
    coating_alpha: float | None = None,
    coating_surface: PathLike | HeightMap | None = None,
    medium: tuple[float, float, float] | None = None,
    distribution: Literal["ggx", "beckmann"] = "ggx",
    channel: int | str | None = None,
    unit: str | None = None,
    pixel_size: float | tuple[float, ...] | None = None,
    warn: Callable[[str], None] = _warn,
    **run: Any,
) -> TraceConfig:
    """The :class:`~labbrdf.TraceConfig` of a substrate, a coating and a run.

    Parameters
    ----------
    wavelength_nm : float
        Vacuum wavelength [nm]; an index taken from a file is taken here.
    theta_i_deg : float
        Angle of incidence [deg].
    base_albedo : float, optional
        A Lambertian base of this albedo [1] instead of a metal
        (:meth:`labbrdf.Substrate.lambertian`); the metal's arguments are then refused and a
        coating needs its own roughness.
    substrate_index : complex, optional
        Substrate index ``n + ik`` [1] ...
    nk_from : path-like, optional
        ... or an ellipsometer file: its bulk n, k at ``wavelength_nm``
        (:func:`labbrdf.sample.bulk_index`). Exactly one of the two.
    alpha : float, optional
        Substrate roughness [1] (GGX or Beckmann alpha, see ``distribution``) ...
    surface : path-like or HeightMap, optional
        ... or a measured areal height map: the substrate's facets follow its slope table
        (:meth:`labbrdf.Substrate.from_surface`). ``surface`` wins over ``alpha``.
    coating_index : complex, optional
        Coating index [1], with ``thickness_nm`` ...
    coating_from : path-like, optional
        ... or a one-layer film fit's JSON: the layer's index at ``wavelength_nm`` and
        its thickness (:func:`labbrdf.sample.coating_from_fit`). At most one of the two; none:
        no coating.
    thickness_nm : float, optional
        Coating thickness [nm] (with ``coating_index``).
    coating_alpha : float, optional
        Roughness of the coating's top [1] (default: the substrate's alpha) ...
    coating_surface : path-like or HeightMap, optional
        ... or a measured areal height map of the top: its slope table.
    medium : (float, float, float), optional
        A scattering coating: optical thickness [1], single-scattering albedo [1] and
        Henyey-Greenstein asymmetry [1] of the medium filling it
        (:class:`labbrdf.tracer.Medium`); needs a coating.
    distribution : {"ggx", "beckmann"}
        Microfacet distribution of the interfaces given by an alpha (measured maps always
        use their own slope table).
    channel, unit, pixel_size :
        How height-map files are read (:func:`labbrdf.read_height_map`): channel name or
        index, length unit of the file's numbers, pitch [m] per axis.
    warn : callable, optional
        Called with each doubt about a height map's geometry (default
        :func:`warnings.warn`).
    **run
        Any other :class:`~labbrdf.TraceConfig` field (``rays``, ``seed``,
        ``scattering``, ``coherent``, ``estimator``, ``scalar`` ...).

    Returns
    -------
    TraceConfig

    Raises
    ------
    labbrdf.errors.SetupError
        Arguments missing or given twice, or a file that cannot give what is asked of it
        (the message names the keyword and the file).
    ValueError
        A value the tracer refuses (:class:`~labbrdf.TraceConfig`'s checks).
    """

    def read(source: PathLike | HeightMap, keyword: str) -> HeightMap:
        return height_map(source, keyword, channel, unit, pixel_size, warn)

    if base_albedo is not None:
        metal: dict[str, object] = {
            "substrate_index": substrate_index,
            "nk_from": nk_from,
            "alpha": alpha,
            "surface": surface,
        }
        coated = coating_index is not None or coating_from is not None
        roughness = coating_alpha is not None or coating_surface is not None
        substrate = _base(base_albedo, metal, coated, roughness)
    else:
        substrate = _substrate(
            wavelength_nm, substrate_index, nk_from, alpha, surface, distribution, read
        )
    coating = _coating(
        wavelength_nm,
        substrate,
        coating_index,
        coating_from,
        thickness_nm,
        coating_alpha,
        coating_surface,
        distribution,
        read,
    )
    if medium is not None:
        coating = _with_medium(coating, medium)
    return TraceConfig(
        wavelength_nm=wavelength_nm,
        theta_i_deg=theta_i_deg,
        substrate=substrate,
        coating=coating,
        **run,
    )
