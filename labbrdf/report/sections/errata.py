"""Section ``errata``: the errors of the source papers this report depends on [Zou2013]_.

With the checks that confirm them; derivations in ``docs/errata.md``.

References
----------
.. [Zou2013] Zou X., Bai L., Wu Z., "Mirror reflectance spectrum modeling of smooth samples",
   Acta Optica Sinica 33(6), 0612008 (2013). doi:10.3788/AOS201333.0612008
"""

from __future__ import annotations

import math

from ... import integrate, models
from ..builder import Unavailable
from ..context import Context
from ..published import paper_values

__all__ = ["errata_section"]

#: Energy-limit angles of the paper's own fits [deg], docs/models.md 1.4 (printed to 0.1)
ENERGY_LIMIT_DEG = {
    ("OSR", 360.0): 70.4,
    ("OSR", 500.0): 63.1,
    ("OSR", 550.0): 61.9,
    ("OSR", 860.0): 61.5,
    ("mirror", 360.0): 77.9,
    ("mirror", 500.0): 76.3,
    ("mirror", 550.0): 76.5,
    ("mirror", 860.0): 80.6,
}
#: entries printed one digit off in docs/models.md 1.4: the root is 76.2498 deg (76.2)
NOTES_MISROUNDED = {("mirror", 500.0)}
#: R(30, 50) and R(50, 30) [sr^-1] at 550 nm with the paper's fits, docs/models.md 1.3
RECIPROCITY_550 = {"OSR": (0.1209, 0.1059), "mirror": (0.0173, 0.0971)}

#: The errata, one row each: where in which paper, what is printed, what is correct, and
#: where the correction matters in this report
_ERRATA: tuple[dict[str, str], ...] = (
    {
        "where": "2013 Table 3",
        "printed": "'integration result' at theta_i = 45 deg",
        "correct": "reproduced at 46 deg with the proper 2 pi int f cos sin convention",
        "used": "hemispherical section: both angles shown",
    },
    {
        "where": "2013 eq. (8)",
        "printed": "energy conserved iff k1 <= 4/pi",
        "correct": "no k1 > 0 conserves energy at all angles; k1 <= 4/(pi max I/cos) on "
        "[0, theta_max] (docs/models.md 1.4)",
        "used": "energy checks: rho(theta_i) and the limit angle of every fit",
    },
    {
        "where": "2013 section 2",
        "printed": "the model is reciprocal",
        "correct": "reciprocal iff k2 = 0 (docs/models.md 1.3)",
        "used": "reciprocity defect of every fit",
    },
    {
        "where": "2013 eq. (5)",
        "printed": "(k' - sin g)",
        "correct": "(k' - sin g tan g)",
        "used": "not used by the report",
    },
    {
        "where": "2013 eq. (6)",
        "printed": "square missing inside the root",
        "correct": "see docs/models.md 3.4",
        "used": "ellipsometric inversion (optics)",
    },
    {
        "where": "2022 eq. (14)",
        "printed": "GGX D without alpha^2 in the numerator",
        "correct": "D = alpha^2 / (pi cos^4 g (alpha^2 + tan^2 g)^2)",
        "used": "tracer maps and validations",
    },
    {
        "where": "2022 eq. (17)",
        "printed": "rotation Mueller M[0,0] = 0",
        "correct": "M[0,0] = 1",
        "used": "tracer maps and validations",
    },
    {
        "where": "2022 eq. (12)",
        "printed": "-2 sqrt(Ts Tp) on the diagonal block",
        "correct": "+2 Re(t_s t_p*) scaled by the beam-area factor",
        "used": "tracer (coated surfaces)",
    },
    {
        "where": "2022 eq. (2)",
        "printed": "PSD exponent k_x^2 c_x + k_y^2 c_y",
        "correct": "k_x^2 c_x^2 + k_y^2 c_y^2",
        "used": "surface generation (not in maps)",
    },
    {
        "where": "2022 section 4",
        "printed": "maximum polarization at d = lambda/4",
        "correct": "cannot appear in incoherent ray optics (a lossless varnish's thickness "
        "only enters through absorption); needs coherent film amplitudes",
        "used": "coating-thickness factor study",
    },
)


def errata_section(ctx: Context) -> None:
    """The paper errata the report depends on, with the checks that confirm them."""
    b = ctx.b
    rows = list(_ERRATA)
    b.table(
        "errata",
        "Errata of the source papers that this report depends on",
        [
            ("where", "where", ""),
            ("printed", "printed", ""),
            ("correct", "correct", ""),
            ("used", "where it matters here", ""),
        ],
        rows,
        caption="Derivations and references: docs/errata.md and docs/models.md.",
    )
    t = ctx.published.get("params")
    if t is None:
        raise Unavailable("published Tables 1-2 not found (fixtures/published)")
    m = models.get("smooth3")
    _energy_limits(ctx, m)
    _reciprocity(ctx, m)


def _energy_limits(ctx: Context, m: models.Model) -> None:
    """Erratum of eq. (8): where the paper's own fits reach rho = 1, with the checks."""
    b = ctx.b
    erows, worst, worst_root = [], 0.0, 0.0
    for (sample, wl), ref in ENERGY_LIMIT_DEG.items():
        pv = paper_values(ctx.published, sample, wl)
        if pv is None:
            continue
        ang = integrate.energy_limit_angle(m, pv)
        # independent of the closed form: rho at our angle by quadrature must be 1
        rho_q = float(integrate.hemispherical_reflectance(m, pv, ang, method="quadrature"))
        worst_root = max(worst_root, abs(rho_q - 1.0))
        if (sample, wl) not in NOTES_MISROUNDED:
            worst = max(worst, abs(ang - ref))
        erows.append(
            {
                "sample": sample,
                "wavelength_nm": wl,
                "k1": pv["k1"],
                "limit_deg": ang,
                "notes_deg": ref,
                "k1max_60": integrate.k1_max_energy(pv["k2"], pv["k3"], 60.0),
                "k1max_89": integrate.k1_max_energy(pv["k2"], pv["k3"], 89.0),
            }
        )
    b.table(
        "errata_energy",
        "Energy conservation of the paper's own fits (erratum of eq. 8)",
        [
            ("sample", "sample", ""),
            ("wavelength_nm", "\u03bb [nm]", "g"),
            ("k1", "k1 published", ".4f"),
            ("limit_deg", "\u03c1 = 1 reached at \u03b8i [deg]", ".3f"),
            ("notes_deg", "docs/models.md 1.4 [deg]", ".1f"),
            ("k1max_60", "k1 max for \u03c1 \u2264 1 up to 60\u00b0", ".4g"),
            ("k1max_89", "k1 max up to 89\u00b0", ".4g"),
        ],
        erows,
        caption="Modelled: smooth3 with the published Table 1-2 parameters. Eq. (8) of the "
        "paper claims energy conservation for k1 <= 4/pi; every published fit satisfies "
        "that and still reaches rho = 1 before grazing incidence.",
    )
    if erows:
        b.check(
            "errata.energy_limit_roots",
            "each angle where the paper's fits reach \u03c1 = 1 is a root by quadrature",
            worst_root <= 1e-6,
            against="adaptive Gauss-Legendre quadrature of the BRDF (not the closed form)",
            value=worst_root,
            tolerance=1e-6,
            justification="max |rho_quad(theta) - 1|; the quadrature is converged to 1e-6 "
            "relative",
        )
        b.check(
            "errata.energy_limit_angles",
            "the angles where the paper's fits reach \u03c1 = 1 match docs/models.md 1.4",
            worst <= 0.05,
            against="docs/models.md 1.4 (independent scipy-quad oracle script)",
            value=worst,
            tolerance=0.05,
            justification="largest difference [deg]; docs/models.md prints 0.1 deg (rounding "
            "bound 0.05). Excluded: mirror 500 nm, printed there as 76.3 but whose root is "
            "76.2498 deg (checked by quadrature above), so the printed value is misrounded.",
        )


def _reciprocity(ctx: Context, m: models.Model) -> None:
    """Erratum of the reciprocity claim: f(30, 50) and f(50, 30) of the 550 nm fits."""
    b = ctx.b
    rrows, worst = [], 0.0
    for sample, (a_ref, b_ref) in RECIPROCITY_550.items():
        pv = paper_values(ctx.published, sample, 550.0)
        if pv is None:
            continue
        fa = float(m.evaluate(math.radians(30), math.radians(50), params=pv))
        fb = float(m.evaluate(math.radians(50), math.radians(30), params=pv))
        worst = max(worst, abs(fa - a_ref), abs(fb - b_ref))
        rrows.append(
            {
                "sample": sample,
                "k2": pv["k2"],
                "f_30_50": fa,
                "f_50_30": fb,
                "notes_30_50": a_ref,
                "notes_50_30": b_ref,
            }
        )
    b.table(
        "errata_reciprocity",
        "Reciprocity of the paper's own fits at 550 nm (the paper claims reciprocity)",
        [
            ("sample", "sample", ""),
            ("k2", "k2 [rad]", ".5g"),
            ("f_30_50", "f(30\u00b0, 50\u00b0) [sr\u207b\u00b9]", ".4f"),
            ("f_50_30", "f(50\u00b0, 30\u00b0) [sr\u207b\u00b9]", ".4f"),
            ("notes_30_50", "docs/models.md 1.3 f(30, 50)", ".4f"),
            ("notes_50_30", "docs/models.md 1.3 f(50, 30)", ".4f"),
        ],
        rrows,
        caption="Modelled: smooth3 with the published parameters, in-plane (phi_r = 180 deg). "
        "Swapping incidence and detector changes the value unless k2 = 0.",
    )
    if rrows:
        b.check(
            "errata.reciprocity_values",
            "f(30, 50) and f(50, 30) of the paper's 550 nm fits match docs/models.md 1.3",
            worst <= 5e-5,
            against="docs/models.md 1.3",
            value=worst,
            tolerance=5e-5,
            justification="4 decimals printed: rounding bound 5e-5 sr^-1",
        )
