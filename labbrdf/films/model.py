"""A stack with the search box of its free parameters: what a film fit fits."""

from __future__ import annotations

from dataclasses import dataclass, field

from ..nk import dispersion as disp
from .layers import Layer
from .stack import Stack


@dataclass
class FilmModel:
    """A stack and the parameters a fit varies.

    Parameters
    ----------
    stack : Stack
        Starting values of every parameter.
    free : dict
        ``"<layer>.<name>"`` -> (min, max) of each varying parameter.
    wavelength_range_nm : tuple, optional
        Only data in [min, max] are fitted.
    source : str
        The model file, for messages.
    """

    stack: Stack
    free: dict[str, tuple[float, float]] = field(default_factory=dict)
    wavelength_range_nm: tuple[float, float] | None = None
    source: str = "<model>"

    @classmethod
    def cauchy_on_silicon(cls) -> FilmModel:
        """The stated default for one transparent layer on silicon.

        A Cauchy layer (``A`` in [1.3, 2.6], ``B`` in [0, 0.1] um^2, ``C = 0``, ``k = 0``,
        thickness in [0, 1000] nm) on crystalline Si (Green 2008 table), fitted over the
        table's 250-1450 nm: a native or thermal oxide, nitride or polymer film on a wafer.
        """
        layer = Layer(disp.Cauchy(A=1.5, B=0.005), 100.0, "film")
        free = {"film.thickness_nm": (0.0, 1000.0), "film.A": (1.3, 2.6), "film.B": (0.0, 0.1)}
        return cls(Stack([layer], "si"), free, (250.0, 1450.0), "default: Cauchy layer on Si")

    @classmethod
    def default(cls, stack: Stack, thickness_max_nm: float | None = None) -> FilmModel:
        """The default fit of a stack.

        Vary every layer's thickness and every parametric layer material's parameters
        (default boxes of :mod:`labbrdf.nk.dispersion`); the substrate and tables stay fixed.
        Thickness box: [0, max(3 d, 20 nm)] unless ``thickness_max_nm`` is given.
        """
        free: dict[str, tuple[float, float]] = {}
        for lay in stack.layers:
            hi = thickness_max_nm or max(3 * lay.thickness_nm, 20.0)
            free[f"{lay.name}.thickness_nm"] = (0.0, float(hi))
            if isinstance(lay.material, disp.Tabulated):
                continue
            for k, b in lay.material.bounds().items():
                if isinstance(lay.material, disp.Cauchy) and k in ("exponent", "band_edge"):
                    continue  # fixed unless asked: k_amp = 0 keeps the layer transparent
                if isinstance(lay.material, disp.Cauchy) and k == "k_amp":
                    continue
                if (
                    isinstance(lay.material, disp.Dispersion)
                    and k in lay.material.fixed_by_default()
                ):
                    continue
                free[f"{lay.name}.{k}"] = b
        return cls(stack, free)
