"""Film fits of the shared real exports: a native oxide on Si and the Ta2O5 trio."""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf import adapters
from labbrdf.films import FilmModel, Layer, Stack
from labbrdf.fitting.film import fit_film
from labbrdf.nk import tabulated_from_file
from labbrdf.nk.dispersion import Cauchy

pytestmark = pytest.mark.shared


def test_native_oxide_on_silicon_is_about_2_nm(real_exports):
    m = adapters.read(real_exports / "woollam-completeease-ascii" / "complete_ease_example.dat")
    st = Stack([Layer("sio2", 2.0, "oxide")], "si")
    f = fit_film(
        FilmModel(st, {"oxide.thickness_nm": (0.0, 20.0)}), m, wavelength_range_nm=(250, 1450)
    )
    s = f.summary()
    d = s["layers"][0]["parameters"]["thickness_nm"]
    assert 1.5 < d["value"] < 3.0  # the file's sample: "2 nm SiO2 on Si"
    assert f.misfit_scale is not None  # Green's Si is not this wafer: the fit says so
    assert d["ci95_scaled"][1] - d["ci95_scaled"][0] > d["ci95"][1] - d["ci95"][0]
    assert s["mse"] == pytest.approx(np.sqrt(s["redchi"]))


@pytest.mark.slow
def test_ta2o5_trio_fits_on_tantalum_and_its_psi_delta_stack_predicts_r_p(real_exports):
    d = real_exports / "woollam-wvase-ascii"
    files = [
        d / "w1_12082006.dat",
        d / "w1_12082006_p-pol_refl.dat",
        d / "w1_12082006_s-pol_refl.dat",
    ]
    data = adapters.read_many(files).data
    # every third wavelength: the same fit at a third of the cost
    keep = np.unique(data.wavelength_nm.to_numpy())[::3]
    data = data[data.wavelength_nm.isin(keep)]
    ellipsometry = data[data.quantity.isin(["psi", "delta"])]
    ta = tabulated_from_file(d / "w2_10102006.dat")  # the same lab's bare Ta wafer
    layer = Layer(Cauchy(A=2.1, B=0.02), 200.0, "ta2o5")
    box = {
        "ta2o5.thickness_nm": (100.0, 300.0),
        "ta2o5.A": (1.9, 2.4),
        "ta2o5.B": (0.0, 0.08),
        "ta2o5.C": (-0.005, 0.01),
    }
    # one wafer whose three headers name it three ways ("... p-pol refl"): said to be one
    one = {"wavelength_range_nm": (350, 1450), "one_sample": True}
    on_ta = fit_film(FilmModel(Stack([layer], ta), box), data, **one)
    on_si = fit_film(FilmModel(Stack([layer], "si"), box), data, **one)
    alone = fit_film(  # psi/Delta alone: the reflectance below is then a prediction
        FilmModel(Stack([layer], ta), box), ellipsometry, wavelength_range_nm=(350, 1450)
    )
    assert on_ta.mse < 0.2 * on_si.mse  # the substrate is tantalum, not silicon
    s = on_ta.summary()
    assert 150 < s["layers"][0]["parameters"]["thickness_nm"]["value"] < 220
    assert 2.1 < s["layers"][0]["nk_at_633nm"]["n"] < 2.3  # Ta2O5 at 633 nm
    refl = adapters.read(files[1]).data
    refl = refl[(refl.wavelength_nm >= 350) & (refl.wavelength_nm <= 1450)]
    z = alone.compare_reflectance(refl)["z"].to_numpy()
    assert np.mean(z**2) < 1.0  # R_p within the file's sigmas (two-phase n, k gave R = 1)
