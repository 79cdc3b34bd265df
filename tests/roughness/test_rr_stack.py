"""Rayleigh-Rice of a film stack with rough interfaces (labbrdf.roughness.rr_stack).

Checked against NIST SCATMECH's roughness-stack models (stored values,
``data/scatmech_rr_stack.csv``, made as ``data/README.md`` says), against the
single-interface Rayleigh-Rice in the limits where a stack is one surface, and by
reciprocity. Each can fail: a wrong sign of the normal-field term or of a layer's phase
breaks the SCATMECH table, a field evaluated on one side of an interface breaks the
zero-thickness limit, a wrong frame breaks reciprocity.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf.roughness import rayleigh_rice as rr
from labbrdf.roughness import rr_stack as rs

TABLE = Path(__file__).with_name("data") / "scatmech_rr_stack.csv"
ELEMENTS = [f"M{i}{j}" for i in range(4) for j in range(4)]
LAM = 633e-9
AL, SI, SIO2, TIO2 = 1.55 + 7.71j, 3.88 + 0.02j, 1.46 + 0j, 2.3 + 0.01j


def kcorr(a: float, b: float, c: float):
    def psd(fx, fy):
        return a / (1.0 + b * b * (np.asarray(fx) ** 2 + np.asarray(fy) ** 2)) ** (c / 2.0)

    return psd


PSD = kcorr(1e-26, 2e-5, 2.5)


def _geometry(n=120, seed=3):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, 1.5, n), rng.uniform(0, 1.5, n), rng.uniform(-math.pi, math.pi, n)


@pytest.fixture(scope="module")
def table() -> pd.DataFrame:
    return pd.read_csv(TABLE)


def _stack_of(row) -> tuple[list[complex], list[float]]:
    """labbrdf's top-first indices and thicknesses [m] from the table's bottom-first films."""
    films = []
    for item in row["films_bottom_first_n+ki:um"].split():
        nk, d = item.split(":")
        n, k = nk.rstrip("i").split("+")
        films.append((complex(float(n), float(k)), float(d) * 1e-6))
    films = films[::-1]
    return [1.0] + [n for n, _ in films] + [complex(row["n_sub"], row["k_sub"])], [
        d for _, d in films
    ]


CASES = [
    (s, m)
    for s, m in (
        ("si-sio2-tio2", "correlated"),
        ("si-sio2-tio2", "uncorrelated"),
        ("si-sio2-tio2", "interface-substrate"),
        ("si-sio2-tio2", "interface-1"),
        ("si-sio2-tio2", "interface-2"),
        ("al-sio2", "correlated"),
        ("al-sio2", "uncorrelated"),
        ("al-sio2", "interface-substrate"),
        ("al-sio2", "interface-1"),
    )
]


@pytest.mark.parametrize(("stack", "model"), CASES)
def test_mueller_matches_scatmech_roughness_stacks(table, stack, model) -> None:
    """All 16 elements, in and out of plane, to 1e-9 of each matrix's largest element."""
    t = table[(table["stack"] == stack) & (table["model"] == model)]
    assert len(t) == 36
    r = t.iloc[0]
    n, d = _stack_of(r)
    psd = kcorr(r["A_um4"] * 1e-24, r["B_um"] * 1e-6, r["C"])
    m_interfaces = len(n) - 1
    if model.startswith("interface-"):
        # SCATMECH's this_layer counts from the substrate's interface (0) upwards
        k = 0 if model.endswith("substrate") else int(model.split("-")[1])
        psds: object = [psd if j == m_interfaces - 1 - k else None for j in range(m_interfaces)]
        corr = "uncorrelated"
    else:
        psds, corr = psd, model
    got = rs.mueller_brdf_stack(
        np.radians(t["theta_i_deg"].to_numpy()),
        np.radians(t["theta_s_deg"].to_numpy()),
        np.radians(t["phi_s_deg"].to_numpy() + 180.0),
        r["wavelength_um"] * 1e-6,
        n,
        d,
        psds,  # type: ignore[arg-type]
        corr,  # type: ignore[arg-type]
    ).reshape(-1, 16)
    want = t[ELEMENTS].to_numpy()
    scale = np.abs(want).max(axis=1, keepdims=True)
    assert np.max(np.abs(got - want) / scale) < 1e-9


@pytest.mark.parametrize("sub", [AL, SI, 1.5 + 0j])
def test_zero_thickness_and_ambient_index_films_are_the_bare_substrate(sub) -> None:
    ti, tr, pr = _geometry()
    bare = rr.mueller_brdf(ti, tr, pr, LAM, sub, PSD)
    scale = np.abs(bare).max()
    # a film of no thickness: correlated interfaces are one surface
    thin = rs.mueller_brdf_stack(ti, tr, pr, LAM, [1, TIO2, sub], [0.0], PSD, "correlated")
    np.testing.assert_allclose(thin, bare, rtol=0, atol=1e-12 * scale)
    # a film of the ambient's index: its top interface does not scatter, the substrate's does
    for corr in rs.CORRELATIONS:
        air = rs.mueller_brdf_stack(ti, tr, pr, LAM, [1, 1.0, sub], [321e-9], PSD, corr)
        np.testing.assert_allclose(air, bare, rtol=0, atol=1e-12 * scale)


def test_film_of_the_substrate_index_is_the_top_surface_and_correlation_moot() -> None:
    ti, tr, pr = _geometry()
    bare = rr.mueller_brdf(ti, tr, pr, LAM, SI, PSD)
    scale = np.abs(bare).max()
    for corr in rs.CORRELATIONS:
        same = rs.mueller_brdf_stack(ti, tr, pr, LAM, [1, SI, SI], [150e-9], PSD, corr)
        np.testing.assert_allclose(same, bare, rtol=0, atol=1e-12 * scale)
    # one rough interface of a real stack: correlated (one term) equals uncorrelated
    n, d = [1, TIO2, SIO2, AL], [60e-9, 110e-9]
    q = rs.interface_factors(ti, tr, pr, LAM, n, d)
    only = [None, PSD, None]
    unc = rs.mueller_brdf_stack(ti, tr, pr, LAM, n, d, only)
    one = rs._mueller_from_jones(q[..., 1, :, :])
    scale = (
        16
        * math.pi**2
        / LAM**4
        * np.cos(ti)
        * np.cos(tr)
        * PSD(*rr.bragg_frequencies(ti, tr, pr, LAM))
    )
    np.testing.assert_allclose(unc, scale[:, None, None] * one, rtol=1e-12, atol=0)


@pytest.mark.parametrize("corr", rs.CORRELATIONS)
def test_reciprocity(corr) -> None:
    """f_M(r -> i) = D f_M(i -> r)^T D, D = diag(1, 1, -1, 1), for an absorbing stack."""
    ti, tr, pr = _geometry(seed=5)
    n, d = [1, TIO2, SIO2, AL], [60e-9, 110e-9]
    m = rs.mueller_brdf_stack(ti, tr, pr, LAM, n, d, PSD, corr)
    back = rs.mueller_brdf_stack(tr, ti, -pr, LAM, n, d, PSD, corr)
    dd = np.diag([1.0, 1.0, -1.0, 1.0])
    np.testing.assert_allclose(
        back, dd @ np.swapaxes(m, -1, -2) @ dd, rtol=1e-12, atol=1e-12 * np.abs(m).max()
    )


def test_fields_at_the_top_are_one_plus_r() -> None:
    """At the ambient's interface E_y = 1 + r_s and H_y = 1 + r_p, with r of the films'
    own transfer matrices (a second derivation of the stack's fields)."""
    from labbrdf.films import matrices

    theta = np.radians([0.0, 35.0, 70.0])
    ey, ex, hy = rs.stack_fields(theta, LAM, [1, TIO2, SIO2, AL], [60e-9, 110e-9])
    rs_, rp, _, _ = matrices.amplitudes(
        [np.ones(1), np.full(1, TIO2), np.full(1, SIO2), np.full(1, AL)],
        [60.0, 110.0],
        np.array(633.0),
        np.degrees(theta),
    )
    np.testing.assert_allclose(ey[:, 0], 1 + rs_, rtol=1e-12)
    np.testing.assert_allclose(hy[:, 0], 1 + rp, rtol=1e-12)
    # E_x = (cos theta) (1 - r_p) in the ambient (incident minus reflected p wave)
    np.testing.assert_allclose(ex[:, 0], np.cos(theta) * (1 - rp), rtol=1e-12)


@pytest.mark.parametrize(
    ("indices", "thick", "psd", "corr", "match"),
    [
        ([1, 1.5], [1e-7], PSD, "uncorrelated", "M thicknesses"),
        ([1.33, 1.5], [], PSD, "uncorrelated", "ambient index must be 1"),
        ([1, 1.5, 2.0], [-1e-9], PSD, "uncorrelated", "thicknesses must be finite"),
        ([1, 1.5 - 0.1j, 2.0], [1e-7], PSD, "uncorrelated", "indices must be finite"),
        ([1, 1.5, 2.0], [1e-7], PSD, "conformal", "correlation must be one of"),
        ([1, 1.5, 2.0], [1e-7], [PSD], "uncorrelated", "one PSD"),
        ([1, 1.5, 2.0], [1e-7], [PSD, PSD], "correlated", "share one PSD"),
    ],
)
def test_bad_input_is_named(indices, thick, psd, corr, match) -> None:
    with pytest.raises(ValueError, match=match):
        rs.mueller_brdf_stack(0.3, 0.4, 3.0, LAM, indices, thick, psd, corr)
