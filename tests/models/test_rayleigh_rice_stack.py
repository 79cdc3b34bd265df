"""The rayleigh_rice model of a coated sample: a film fit's stack with rough interfaces."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from labbrdf import films, models
from labbrdf.adapters.zemax_bsdf import WAVELENGTH_COMMENT
from labbrdf.bsdf_geometry import scatter_to_angles
from labbrdf.cli import main
from labbrdf.fitting.film import fit_film
from labbrdf.nk.dispersion import Cauchy, Constant
from labbrdf.roughness import rr_stack as rs
from labbrdf.writers.zemax import write_bsdf

TRUE = {"A": 3e-4, "B": 12.0, "C": 1.6}
WL_NM = 633.0
COAT = Cauchy(A=1.46, B=0.003, C=0.0)
AL = Constant(1.55, 7.71)


def _stack(d_nm: float = 120.0) -> films.Stack:
    return films.Stack([films.Layer(COAT, d_nm, "coat")], AL)


@pytest.fixture(scope="module")
def film_json(tmp_path_factory: pytest.TempPathFactory):
    """A film fit (thickness free) to exact psi/Delta of 120 nm of a silica-like Cauchy on Al."""
    truth = _stack()
    wl = np.arange(450.0, 751.0, 50.0)
    rows = []
    for th in (60.0, 70.0):
        psi, delta = truth.psi_delta(wl, th)
        for q, v, s in (("psi", psi, 0.02), ("delta", delta, 0.05)):
            rows.append(
                pd.DataFrame({"sample": "m", "instrument": "x", "source": "m.dat",
                              "quantity": q, "value": v, "sigma": s, "unit": "deg",
                              "wavelength_nm": wl, "theta_i_deg": th, "theta_r_deg": th,
                              "phi_r_deg": 180.0})
            )  # fmt: skip
    model = films.FilmModel(
        truth.with_values({"coat.thickness_nm": 100.0}), {"coat.thickness_nm": (50.0, 200.0)}
    )
    fit = fit_film(model, pd.concat(rows, ignore_index=True))
    return fit.save_json(tmp_path_factory.mktemp("film") / "coat_fit.json")


@pytest.fixture(scope="module")
def coated_bsdf(tmp_path_factory, film_json):
    """A .bsdf of the coated mirror (correlated interfaces, known K-correlation), 2 % noise."""
    m = models.get("rayleigh_rice", film=_stack())
    ti = np.array([20.0, 50.0])
    rad = np.array([0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 60.0])
    az = np.array([0.0, 45.0, 90.0, 135.0, 180.0])
    tr, pr, above = scatter_to_angles(ti[:, None, None], rad[None, None, :], az[None, :, None])
    f = m.evaluate(
        np.radians(np.broadcast_to(ti[:, None, None], tr.shape)),
        np.radians(np.where(above, tr, 0.0)),
        np.radians(pr),
        wavelength=WL_NM,
        params=TRUE,
    )
    rng = np.random.default_rng(31)
    vals = np.where(above, f * (1.0 + 0.02 * rng.standard_normal(f.shape)), 0.0)
    return write_bsdf(
        tmp_path_factory.mktemp("rrs") / "coated.bsdf",
        theta_i_deg=ti,
        radial_deg=rad,
        azimuth_deg=az,
        values=vals[None, None],
        symmetry="PlaneSymmetrical",
        comments=[f"{WAVELENGTH_COMMENT}{WL_NM:g}"],
        digits=8,
    )


def test_model_evaluates_the_stack_physics(film_json) -> None:
    ti, tr, pr = 0.3, np.array([0.1, 0.5, 1.2]), np.array([0.0, 2.0, math.pi])
    for interfaces in rs.INTERFACES:
        m = models.get("rayleigh_rice", film=str(film_json), interfaces=interfaces)
        assert m.stack is not None and m.options["interfaces"] == interfaces
        n, d = rs.stack_layers(m.stack, WL_NM)
        assert d[0] == pytest.approx(120e-9, rel=1e-4)  # the fit found the thickness
        got = m.evaluate(ti, tr, pr, wavelength=WL_NM, params=TRUE)
        want = rs.stack_brdf(ti, tr, pr, WL_NM * 1e-9, n, d, m.psd2d(TRUE), interfaces)
        np.testing.assert_allclose(got, want, rtol=1e-14)
        mm = m.mueller(ti, tr, pr, wavelength_nm=WL_NM, params=TRUE)
        np.testing.assert_allclose(mm[..., 0, 0], want, rtol=1e-12)
    # the options rebuild the model (a Stack given in Python is kept as its dict)
    m = models.get("rayleigh_rice", film=_stack())
    again = models.get("rayleigh_rice", **m.options)
    assert again.evaluate(0.3, 0.4, 3.0, wavelength=WL_NM, params=TRUE) == pytest.approx(
        m.evaluate(0.3, 0.4, 3.0, wavelength=WL_NM, params=TRUE), rel=1e-15
    )


def test_a_film_of_no_thickness_is_the_bare_substrate() -> None:
    bare = models.get("rayleigh_rice", n=1.55, k=7.71, wavelength_nm=WL_NM)
    thin = models.get("rayleigh_rice", film=_stack(0.0), wavelength_nm=WL_NM)
    ti, tr, pr = 0.4, np.linspace(0.0, 1.4, 9), np.linspace(0.0, 6.0, 9)
    a = bare.evaluate(ti, tr, pr, params=TRUE)
    b = thin.evaluate(ti, tr, pr, params=TRUE)
    np.testing.assert_allclose(b, a, rtol=1e-12)


def test_cli_recovers_the_psd_of_a_coated_mirror(coated_bsdf, film_json, capsys) -> None:
    argv = ["fit", str(coated_bsdf), "--model", "rayleigh_rice", "--param"]
    argv += [f"film={film_json}", "--weighting", "relative", "--json"]
    assert main(argv) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["success"]
    for name, true in TRUE.items():
        p = row["params"][name]
        assert abs(p["value"] - true) <= 3 * p["stderr"], (name, p, true)


def test_bad_film_options(film_json, tmp_path) -> None:
    cases = [
        ({"film": str(film_json), "n": 1.5}, "leave out n, k"),
        ({"n": 1.5, "interfaces": "uncorrelated"}, "needs the option 'film'"),
        ({"film": str(film_json), "interfaces": "conformal"}, "'interfaces' must be one of"),
        ({"film": 3.0}, "film fit JSON path or a Stack"),
        ({"film": str(tmp_path / "none.json")}, "none.json"),
    ]
    for opts, match in cases:
        with pytest.raises(models.ModelError, match=match):
            models.get("rayleigh_rice", **opts)
    slab = films.Stack([films.Layer(COAT, 100.0, "c")], AL, substrate_thickness_nm=1e6)
    with pytest.raises(models.ModelError, match="coherent layers"):
        models.get("rayleigh_rice", film=slab)
    m = models.get("rayleigh_rice", film=str(film_json), wavelength_nm=1064.0)
    with pytest.raises(models.ModelError, match="outside the film fit's range 450-750 nm"):
        m.evaluate(0.1, 0.2, 3.0, params=TRUE)


def test_cli_film_that_is_not_a_film_fit_exits_2(coated_bsdf, tmp_path, capsys) -> None:
    bad = tmp_path / "notafit.json"
    bad.write_text('{"kind": "brdf"}')
    argv = ["fit", str(coated_bsdf), "--model", "rayleigh_rice", "--param", f"film={bad}"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "notafit.json" in err and "Traceback" not in err


def test_a_substrate_named_by_a_file_is_read_as_the_film_commands_read_it(tmp_path) -> None:
    """A fit of ``labbrdf film ... --substrate FILE`` names its substrate by the file.

    The model reads it through the n,k file reader, from a fit JSON path and from the
    options it records (their dict names the file again), and the stack equals one built
    from the same table in memory.
    """
    from labbrdf.nk import tabulated_from_file

    table = tmp_path / "al.csv"
    table.write_text("wavelength_nm,n,k\n400,1.55,7.71\n900,1.55,7.71\n", encoding="utf-8")
    stack = films.Stack([films.Layer(COAT, 120.0, "coat")], tabulated_from_file(table))
    doc = {"stack": stack.to_dict()}
    assert doc["stack"]["substrate"]["file"] == str(table)
    m = models.get("rayleigh_rice", film=doc["stack"])
    again = models.get("rayleigh_rice", **m.options)
    want = models.get("rayleigh_rice", film=_stack()).evaluate(
        0.3, 0.4, 3.0, wavelength=WL_NM, params=TRUE
    )
    for model in (m, again):
        got = model.evaluate(0.3, 0.4, 3.0, wavelength=WL_NM, params=TRUE)
        assert got == pytest.approx(want, rel=1e-12)
