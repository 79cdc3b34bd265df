"""What a film model, stack or fit may state: the caps, the quantities a film fit uses, the error.

Every builder of a stack (a model file, a fit JSON, ``--layer``, the library) checks against
these bounds, so a crafted file cannot build an unbounded stack.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ..errors import LabbrdfError

#: dataset quantities a film fit uses (psi/Delta at any angle; specular R and T, by
#: polarisation channel ``s``/``p`` or unpolarised)
FILM_QUANTITIES = ("psi", "delta", "reflectance", "transmittance")


#: wavelength at which a fit summary quotes each layer's n, k [nm] (He-Ne line)
NK_REPORT_NM = 633.0


#: the most layers a stack may have, whoever builds it (a model file, a fit JSON,
#: ``--layer``, the library): real coatings have a few to a few hundred; the cap keeps a
#: crafted file from building thousands of layers
MAX_LAYERS = 500


#: the thickest layer a model file or fit JSON may state [nm] (10 mm): thicker is a
#: substrate, not a coherent film
MAX_THICKNESS_NM = 1.0e7


#: the wavelengths a model or fit may state [nm]: 1 nm (soft X-rays) to 1 mm (far IR)
WAVELENGTH_LIMITS_NM = (1.0, 1.0e6)


#: the largest index modulus |n + ik| a fit JSON's stack may have over its fitted range [1]
#: (metals in the far infrared reach a few hundred)
MAX_INDEX = 1.0e4


#: largest film model file (TOML) read [bytes]: a model of MAX_LAYERS layers is ~50 kB
MAX_MODEL_BYTES = 1 << 20


#: largest film fit JSON read [bytes]: its tables may hold many rows
MAX_FIT_JSON_BYTES = 64 << 20


#: most rows of a table inside a fit JSON
MAX_TABLE_POINTS = 1_000_000


class FilmError(LabbrdfError, ValueError):
    """A bad film model (file, layer or parameter) or film data."""


def check_wavelength_range(rng: Sequence[float], what: str) -> tuple[float, float]:
    """A wavelength range [nm]: finite, ordered, within :data:`WAVELENGTH_LIMITS_NM`.

    Raises
    ------
    FilmError
        Naming ``what``.
    """
    lo, hi = (float(x) for x in rng)
    a, b = WAVELENGTH_LIMITS_NM
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise FilmError(f"{what}: [{lo:g}, {hi:g}] is not a range [min, max] with min < max")
    if lo < a or hi > b:
        raise FilmError(
            f"{what}: [{lo:g}, {hi:g}] nm lies outside the wavelengths of optics "
            f"[{a:g}, {b:g}] nm (labbrdf.films.WAVELENGTH_LIMITS_NM)"
        )
    return lo, hi
