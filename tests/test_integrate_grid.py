"""Grid quadrature of tabulated BSDF values about the specular direction.

``labbrdf.integrate.grid_integral`` and its ``.bsdf`` face in the adapter.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from labbrdf.adapters import zemax_bsdf as zb
from labbrdf.bsdf_geometry import SYMMETRIES, azimuth_weights
from labbrdf.integrate import grid_integral

LAMBERT = 1.0 / math.pi  # a BRDF whose hemispherical integral is 1 [sr^-1]


def _lambert(n_az: int, n_rad: int) -> np.ndarray:
    return np.full((1, 1, 1, n_az, n_rad), LAMBERT)


@pytest.mark.parametrize(
    ("az", "symmetry"),
    [
        (np.arange(0, 181, 15.0), "PlaneSymmetrical"),
        (np.arange(0, 360, 7.5), "Asymmetrical"),
        (np.arange(0, 361, 30.0), "Asymmetrical4D"),  # the first node repeated at 360
        (np.array([40.0]), "Asymmetrical"),
        (np.array([10.0, 20.0, 300.0]), "Asymmetrical"),  # uneven, wrapping across 0
    ],
)
def test_azimuth_weights_cover_the_circle_once(az, symmetry):
    w = azimuth_weights(az, symmetry)
    assert w.shape == az.shape and np.all(w >= 0)
    assert math.isclose(w.sum(), 2.0 * math.pi, rel_tol=1e-14)


def test_lambertian_at_normal_incidence_converges_to_one_at_second_order():
    # At normal incidence the cells about the specular direction are polar-coordinate cells,
    # so the rule is the midpoint-cell rule of int_0^90 cos r sin r dr: its error, that of
    # the half cell at 90 deg where the node's cosine is 0, is h^2 / 8 + O(h^4) [h in rad].
    errors = []
    for h in (2.0, 1.0, 0.5):
        rad = np.arange(0.0, 90.0 + h / 2, h)
        az = np.arange(0.0, 360.0, 10.0)
        g = grid_integral(_lambert(az.size, rad.size), [0.0], az, rad)
        err = 1.0 - g["integral"][0, 0, 0]
        hr = math.radians(h)
        assert err == pytest.approx(hr**2 / 8, rel=hr**2)
        # Lambertian: the integral is the covered part of the projected hemisphere, both
        # sums of az.size * rad.size terms adding up to about 1 (rounding <= n eps)
        n_eps = az.size * rad.size * np.finfo(float).eps
        assert g["uncovered_fraction"][0] == pytest.approx(err, rel=0, abs=n_eps)
        errors.append(err)
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.01)
    assert errors[1] / errors[2] == pytest.approx(4.0, rel=0.01)


def test_plane_symmetric_half_equals_the_mirrored_full_circle():
    rng = np.random.default_rng(1)
    ti, rad = np.array([0.0, 30.0, 70.0]), np.arange(0.0, 91.0, 5.0)
    half = np.arange(0.0, 181.0, 10.0)
    v_half = rng.uniform(0.0, 1.0, (2, 1, ti.size, half.size, rad.size))
    full = np.concatenate([half, 360.0 - half[-2:0:-1]])
    v_full = np.concatenate([v_half, v_half[..., -2:0:-1, :]], axis=3)
    a = grid_integral(v_half, ti, half, rad, symmetry="PlaneSymmetrical")
    b = grid_integral(v_full, ti, full, rad, symmetry="Asymmetrical")
    np.testing.assert_allclose(a["integral"], b["integral"], rtol=1e-13, atol=0)
    np.testing.assert_allclose(
        a["uncovered_fraction"], b["uncovered_fraction"], rtol=0, atol=1e-13
    )


def test_tis_and_ratio():
    az, rad = np.arange(0.0, 360.0, 30.0), np.arange(0.0, 91.0, 10.0)
    v = _lambert(az.size, rad.size)
    g = grid_integral(v, [0.0], az, rad)
    assert np.isnan(g["tis"]).all() and np.isnan(g["ratio"]).all()
    g = grid_integral(v, [0.0], az, rad, tis=[[[0.5]]])
    assert g["ratio"][0, 0, 0] == 0.5 / g["integral"][0, 0, 0]


def test_the_adapter_face_is_the_array_quadrature():
    rng = np.random.default_rng(2)
    ti, az, rad = np.array([10.0, 50.0]), np.arange(0.0, 360.0, 45.0), np.arange(0.0, 81.0, 8.0)
    v = rng.uniform(0.0, 1.0, (1, 3, ti.size, az.size, rad.size))
    t = zb.BsdfTable(
        "Asymmetrical", "XYZ", "BRDF", np.zeros(1), ti, az, rad, v, np.ones((1, 3, 2))
    )
    a, b = zb.grid_integral(t), grid_integral(v, ti, az, rad, tis=np.ones((1, 3, 2)))
    for k in ("integral", "uncovered_fraction", "tis", "ratio"):
        assert np.array_equal(a[k], b[k]), k


@pytest.mark.parametrize(
    ("kw", "msg"),
    [
        (dict(symmetry="Isotropic"), "symmetry 'Isotropic': expected one of"),
        (
            dict(values=np.ones((1, 3, 4))),
            r"values: expected shape \(rotation, channel, 1, 3, 4\)",
        ),
        (dict(values=np.ones((1, 1, 1, 4, 3))), r"from the grid, got \(1, 1, 1, 4, 3\)"),
        (dict(radial_deg=[]), "radial_deg: expected a non-empty 1-D list"),
        (dict(azimuth_deg=[[0.0, 90.0, 180.0]]), "azimuth_deg: expected a non-empty 1-D list"),
        (dict(tis=np.ones((1, 1, 2))), r"tis: expected shape \(1, 1, 1\), got \(1, 1, 2\)"),
    ],
)
def test_bad_arguments_are_refused(kw, msg):
    args = dict(
        values=np.ones((1, 1, 1, 3, 4)),
        theta_i_deg=[20.0],
        azimuth_deg=[0.0, 90.0, 180.0],
        radial_deg=[0.0, 5.0, 10.0, 20.0],
        symmetry=SYMMETRIES[0],
    )
    args.update(kw)
    with pytest.raises(ValueError, match=msg):
        grid_integral(**args)
