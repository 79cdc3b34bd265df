"""The aperture a fit uses: its range, what files state, the registry's apertured models."""

from __future__ import annotations

import numpy as np
import pytest

from labbrdf import models
from labbrdf.dataset import Measurement, concat, make_frame
from labbrdf.fitting import FitData, FitError, fit
from labbrdf.fitting.aperture import Aperture, ApertureError, stated_aperture
from labbrdf.models.aperture import Apertured


@pytest.mark.parametrize("bad", [-0.1, 20.5, float("nan"), "1"])
def test_aperture_out_of_range_refused(bad) -> None:
    with pytest.raises(ApertureError, match=r"aperture detector_deg=.* \(given\): expected"):
        Aperture(bad)


def test_aperture_options_and_text() -> None:
    a = Aperture(1.0, 0.5, source="stated by x.csv")
    assert a.options() == {"detector_deg": 1.0, "beam_deg": 0.5}
    assert str(a) == "aperture: detector 1 deg, beam 0.5 deg (half-angles; stated by x.csv)"
    assert Aperture(0.0).options() == {} and not Aperture(0.0).active


def _m(source: str, aperture: dict | None) -> Measurement:
    frame = make_frame(
        sample="s",
        instrument="i",
        source=source,
        quantity="brdf",
        value=[1.0],
        unit="sr-1",
        wavelength_nm=[633.0],
        theta_i_deg=[10.0],
        theta_r_deg=[10.0],
        phi_r_deg=[180.0],
    )
    return Measurement(frame, {} if aperture is None else {"aperture": aperture})


def test_stated_aperture_of_one_file_and_of_agreeing_files() -> None:
    assert stated_aperture(_m("a.csv", None)) is None
    one = stated_aperture(_m("a.csv", {"detector_deg": 1.0, "beam_deg": 0.0}))
    assert one == Aperture(1.0, 0.0, source="stated by a.csv")
    both = concat([_m("a.csv", {"detector_deg": 1.0}), _m("b.csv", {"detector_deg": 1.0})])
    assert stated_aperture(both) == Aperture(1.0, 0.0, source="stated by a.csv, b.csv")


def test_files_where_one_states_none_are_refused() -> None:
    mixed = concat([_m("a.csv", {"detector_deg": 1.0}), _m("b.csv", None)])
    with pytest.raises(ApertureError, match=r"\(a.csv: 1, 0 deg; b.csv: none\)"):
        stated_aperture(mixed)


def test_registry_builds_the_apertured_model_from_recorded_options() -> None:
    m = models.get("abg", diffuse=True, detector_deg=1.0)
    assert isinstance(m, Apertured) and m.inner.options == {"diffuse": True}
    again = models.get(m.name, **m.options)
    assert isinstance(again, Apertured) and again.options == m.options
    p = {"A": 2e-5, "B": 1e-4, "g": 2.0, "kd": 0.1}
    args = (np.radians(20.0), np.radians(20.4), np.pi)
    assert float(again.evaluate(*args, params=p)) == float(m.evaluate(*args, params=p))


def test_specular_intensity_is_not_fitted_through_an_aperture() -> None:
    m = Apertured(models.get("microfacet", n=1.5, k=0.0), detector_deg=1.0)
    assert m.quantities == ("brdf",)
    data = FitData(
        [10.0, 20.0, 30.0], [10.0, 20.0, 30.0], [0.04, 0.04, 0.05], quantity="specular_intensity"
    )
    with pytest.raises(FitError, match="describes \\['brdf'\\], not 'specular_intensity'"):
        fit(m, data)
