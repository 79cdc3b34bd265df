"""``surface`` statistics against SurfaceTopography on the largest shared height map.

Run: ``python benchmarks/bench_surface.py [--repeat 3] [FILE]``

Reads FILE (default: the largest map of ``../shared/real-exports/topography``, the MetroPro
640 x 480 map), then times, in this process, the median CPU time (``time.process_time``) of
``--repeat`` interleaved runs of

* SurfaceTopography on the same heights and pixel size, detrended by its mean plane
  (``detrend("height")``): Sq (``rms_height_from_area``), Sdq (``rms_gradient``), the
  PSD (``power_spectrum_from_area``) and the ACF (``autocorrelation_from_area``);
* :func:`labbrdf.roughness.topography.roughness_statistics` without uncertainties (``blocks=0``:
  sigma, slopes, ACF lengths and principal axes, shape statistics, the GGX and Beckmann
  slope fits with their KS distances);
* the same with the default 5 x 5 tile jackknife (every statistic's uncertainty);
* :func:`labbrdf.roughness.form.check_form` (the form check of ``labbrdf surface``);

and prints each with its ratio to SurfaceTopography. CPU time, not wall time: the machine
may be shared. Not a timed test.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path

from labbrdf.adapters import read_inputs
from labbrdf.roughness.form import check_form
from labbrdf.roughness.topography import roughness_statistics

SHARED = Path(__file__).resolve().parents[2] / "shared" / "real-exports" / "topography"


def largest_map() -> Path:
    """The shared height map with the most points."""
    maps = []
    for p in sorted(SHARED.iterdir()):
        try:
            (hm,) = read_inputs([p], kind="height_map", on_error="raise").height_maps
        except (ValueError, OSError):
            continue
        maps.append((hm.heights.size, p))
    if not maps:
        raise SystemExit(f"no height map under {SHARED}")
    return max(maps)[1]


def surface_topography(z, px) -> Callable[[], object]:
    """SurfaceTopography's Sq, Sdq, PSD and ACF of the mean-plane-detrended map."""
    from SurfaceTopography import Topography

    def run() -> object:
        sizes = tuple(n * p for n, p in zip(z.shape, px, strict=True))
        t = Topography(z, physical_sizes=sizes).detrend("height")
        return (
            t.rms_height_from_area(),
            t.rms_gradient(),
            t.power_spectrum_from_area(),
            t.autocorrelation_from_area(),
        )

    return run


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file", nargs="?", default=None)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    path = Path(a.file) if a.file else largest_map()
    (hm,) = read_inputs([path], kind="height_map", on_error="raise").height_maps
    z, px = hm.heights, hm.pixel_size
    runs: dict[str, Callable[[], object]] = {
        "SurfaceTopography Sq, Sdq, PSD, ACF": surface_topography(z, px),
        "labbrdf statistics, no intervals": lambda: roughness_statistics(z, px, blocks=0),
        "labbrdf statistics, 5x5 jackknife": lambda: roughness_statistics(z, px),
        "labbrdf form check": lambda: check_form(z, px, 1),
    }
    times: dict[str, list[float]] = {k: [] for k in runs}
    for _ in range(a.repeat):
        for label, run in runs.items():
            t0 = time.process_time()
            run()
            times[label].append(time.process_time() - t0)
    med = {k: statistics.median(v) for k, v in times.items()}
    ref = med["SurfaceTopography Sq, Sdq, PSD, ACF"]
    print(f"{path.name}: {' x '.join(map(str, z.shape))} points; median CPU s of {a.repeat}")
    for label, t in med.items():
        print(f"  {label:38} {t:7.3f} s  {t / ref:6.1f} x SurfaceTopography")


if __name__ == "__main__":
    main()
