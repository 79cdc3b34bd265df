"""Consistent synthetic files of one sample: height map, psi/Delta and measured BRDF.

The three files a lab would bring for "predict, then measure", written in formats labbrdf
reads: a Gaussian surface saved as a NetCDF height map (SurfaceTopography), a WVASE psi/Delta
file computed with :mod:`labbrdf.optics` for a known index, and a ``.bsdf`` written from a
trace (:func:`labbrdf.writers.zemax.binned_to_bsdf`) of a substrate with that index and the
height map's GGX alpha.

The validation report's bundled set (``labbrdf/data/fixtures/predict_measure/``) is made the
same way by ``make_fixtures.py``, on a finer map and with a reflectance spectrum; these
writers stay for the tests that vary the files (a coating, another seed, a wrong index).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from labbrdf import optics
from labbrdf.roughness.synthetic import gaussian_surface
from labbrdf.tracer import Coating, Substrate, TraceConfig, trace
from labbrdf.writers.zemax import binned_to_bsdf

#: the sample's index (aluminium near 600 nm) and a wrong one (a poorer metal)
TRUE_NK = 1.2 + 7.26j
WRONG_NK = 1.5 + 3.0j
WAVELENGTHS_NM = (500.0, 600.0, 700.0)
ANGLES_DEG = (55.0, 65.0, 75.0)
BRDF_WAVELENGTH_NM = 600.0
BRDF_AOI_DEG = 45.0
#: the scatter grid written (PlaneSymmetrical half)
RADIAL_DEG = np.arange(0.0, 81.0, 2.0)
AZIMUTH_DEG = np.arange(0.0, 181.0, 10.0)


def write_height_map(path: Path, n: int = 128, seed: int = 3) -> Path:
    """A Gaussian surface, sigma 0.3 um, c 4 um (alpha ~ sqrt(2) 0.3/4 ~ 0.1), as NetCDF."""
    from SurfaceTopography import Topography

    s = gaussian_surface(n, n * 1e-6, 0.3e-6, 4e-6, rng=seed)
    Topography(np.asarray(s.z), physical_sizes=(n * 1e-6, n * 1e-6), unit="m").to_netcdf(str(path))
    return path


def write_wvase(path: Path, nk: complex, title: str = "SYNTHETIC sample A") -> Path:
    """WVASE32 psi/Delta of a bare substrate of index ``nk`` (no noise, sigmas stated)."""
    lines = [
        title,
        "VASEmethod[Simulation, EllipsometerType=4, Isotropic, FixedPol=45.00, ZoneAve=1, "
        "Revs=100, OffsetMode=2, Offset1=0, Offset2=0, Offset3=0, WVASE=3.616, "
        "HardVer=17.034, Sun Nov 22 00:00:00 2026]",
        f"Original[{path.name}]",
        "nm",
    ]
    for aoi in ANGLES_DEG:
        for wl in WAVELENGTHS_NM:
            psi, delta = optics.psi_delta(nk, aoi)
            lines.append(
                f"{wl:.6f}\t{aoi:.6f}\t{float(psi):.10g}\t{float(delta):.10g}\t0.02\t0.05"
            )
    path.write_bytes("\r\n".join(lines).encode("ascii"))
    return path


def brdf_config(
    alpha: float, *, coating: Coating | None = None, seed: int = 0, rays: int = 32_768
) -> TraceConfig:
    """The run the prediction makes for this sample (single scattering, evaluated)."""
    step = 1.0 if coating is None else 2.0
    return TraceConfig(
        wavelength_nm=BRDF_WAVELENGTH_NM,
        theta_i_deg=BRDF_AOI_DEG,
        substrate=Substrate(n=TRUE_NK.real, k=TRUE_NK.imag, alpha=alpha),
        coating=coating,
        rays=rays,
        seed=seed,
        scattering="single",
        estimator="evaluated",
        theta_step_deg=step,
        phi_step_deg=step,
    )


def write_bsdf(path: Path, config: TraceConfig) -> Path:
    """The trace's unpolarized S0 as a measured ``.bsdf`` at :data:`BRDF_AOI_DEG`."""
    res = trace(config)
    return binned_to_bsdf(
        path,
        theta_i_deg=config.theta_i_deg,
        values=res.s0(),
        theta_edges_deg=res.theta_r_edges_deg,
        phi_edges_deg=res.phi_r_edges_deg,
        radial_deg=RADIAL_DEG,
        azimuth_deg=AZIMUTH_DEG,
        wavelength_nm=config.wavelength_nm,
    )
