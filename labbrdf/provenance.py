"""The software environment a result was produced with: Python and the numerical stack.

A lab reproducing a published report needs the versions that produced its numbers; the
reports and every fit record them. Versions are read from the installed distributions'
metadata, so nothing here imports numpy, pandas or dask.
"""

from __future__ import annotations

import platform
from importlib import metadata

__all__ = ["PACKAGES", "versions"]

#: distributions whose versions a report names (the numerical stack labbrdf runs on)
PACKAGES = (
    "numpy",
    "scipy",
    "pandas",
    "pyarrow",
    "nlopt",
    "colour-science",
    "matplotlib",
    "jinja2",
    "dask",
    "distributed",
    "SurfaceTopography",
)


def version_of(name: str) -> str | None:
    """Installed version of distribution ``name``, or None when it is not installed."""
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


def versions() -> dict[str, str | None]:
    """Python, the platform, labbrdf and each of :data:`PACKAGES` (None: not installed).

    Returns
    -------
    dict
        ``{"python": "3.11.7", "platform": "Linux-...-x86_64", "labbrdf": ..., "numpy": ...}``
    """
    out: dict[str, str | None] = {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "labbrdf": version_of("labbrdf"),
    }
    out.update({name: version_of(name) for name in PACKAGES})
    return out
