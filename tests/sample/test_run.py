"""A tracer run from values and files: labbrdf.sample.trace_config_from_inputs.

The assembled config must equal the one written out by hand from the same values (the
command line and Python build the same run); every argument that does not fit raises a
SetupError naming the keywords, which the command line spells as its options.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from labbrdf.adapters.topography import HeightMap
from labbrdf.errors import SetupError
from labbrdf.microfacet import TabulatedNDF
from labbrdf.nk import bulk_index_at, read_nk
from labbrdf.sample import slopes, trace_config_from_inputs
from labbrdf.sample.run import SampleWarning
from labbrdf.tracer import Coating, Substrate, TraceConfig

TA = "woollam-wvase-ascii/w2_10102006.dat"


def rough_map(shape: tuple[int, ...] = (64, 64)) -> HeightMap:
    """A seeded random areal (or line) height map with a 10 nm pitch [m]."""
    z = np.random.default_rng(3).normal(0.0, 2e-9, shape)
    return HeightMap(z, (1e-8,) * len(shape), "synthetic.map", "Height", ("Height",), {}, ())


def test_values_give_the_config_written_by_hand() -> None:
    cfg = trace_config_from_inputs(
        633.0, 45.0, substrate_index=1.5 + 7j, alpha=0.2, coating_index=1.45 + 0j,
        thickness_nm=120.0, rays=1000, seed=4, scattering="single",
    )  # fmt: skip
    sub = Substrate(n=1.5, k=7.0, alpha=0.2)
    coat = Coating(n=1.45, k=0.0, thickness_nm=120.0, alpha=0.2)  # the substrate's alpha
    hand = TraceConfig(wavelength_nm=633.0, theta_i_deg=45.0, substrate=sub, coating=coat,
                       rays=1000, seed=4, scattering="single")  # fmt: skip
    assert cfg == hand


def test_beckmann_gives_both_interfaces_the_beckmann_table() -> None:
    cfg = trace_config_from_inputs(
        633.0, 30.0, substrate_index=1.5 + 7j, alpha=0.2, distribution="beckmann",
        coating_index=1.45 + 0j, thickness_nm=100.0, coating_alpha=0.3,
    )  # fmt: skip
    assert cfg.substrate.ndf == TabulatedNDF.beckmann(0.2)
    assert cfg.coating is not None and cfg.coating.ndf == TabulatedNDF.beckmann(0.3)


def test_a_height_map_gives_its_slope_table() -> None:
    hm = rough_map()
    cfg = trace_config_from_inputs(
        633.0, 45.0, substrate_index=1.5 + 7j, surface=hm, coating_index=1.5 + 0j,
        thickness_nm=500.0, coating_surface=hm,
    )  # fmt: skip
    ref = Substrate.from_surface(hm.heights, hm.pixel_size, n=1.5, k=7.0)
    assert cfg.substrate == ref
    assert cfg.coating is not None
    assert cfg.coating.ndf == ref.ndf and cfg.coating.alpha == ref.alpha


@pytest.mark.shared
def test_the_index_from_an_ellipsometer_file_is_its_bulk_index(real_exports: Path) -> None:
    cfg = trace_config_from_inputs(600.0, 45.0, nk_from=real_exports / TA, alpha=0.1)
    n, k = bulk_index_at(read_nk(real_exports / TA), 600.0)
    assert (cfg.substrate.n, cfg.substrate.k) == (n, k)


@pytest.mark.shared
def test_an_index_outside_the_file_names_it(real_exports: Path) -> None:
    with pytest.raises(SetupError, match=r"nk_from .*w2_10102006.dat: .*outside the measured"):
        trace_config_from_inputs(3000.0, 45.0, nk_from=real_exports / TA, alpha=0.1)


@pytest.mark.parametrize(
    ("kw", "keywords", "options"),
    [
        ({"alpha": 0.2}, "substrate_index N+Kj or nk_from", "--substrate N+Kj or --nk-from"),
        ({"substrate_index": 2j, "nk_from": "x.dat", "alpha": 0.2}, "or nk_from", "or --nk-from"),
        ({"substrate_index": 2j}, "with alpha A or surface", "with --alpha A or --surface"),
        ({"substrate_index": 2j, "alpha": 0.0, "distribution": "beckmann"},
         "distribution beckmann needs", "--distribution beckmann needs"),
        ({"substrate_index": 2j, "alpha": 0.2, "distribution": "phong"},
         "distribution 'phong': expected", "--distribution 'phong': expected"),
        ({"substrate_index": 2j, "alpha": 0.2, "coating_index": 1.5},
         "coating_index needs thickness_nm", "--coating needs --thickness"),
        ({"substrate_index": 2j, "alpha": 0.2, "thickness_nm": 10.0},
         "need coating_index (or coating_from)", "need --coating (or --coating-from)"),
        ({"substrate_index": 2j, "alpha": 0.2, "coating_alpha": 0.1},
         "need coating_index", "need --coating"),
        ({"substrate_index": 2j, "alpha": 0.2, "coating_from": "f.json", "coating_index": 1.5},
         "give the coating once: coating_from", "give the coating once: --coating-from"),
        ({"substrate_index": 2j, "alpha": 0.2, "coating_from": "f.json", "thickness_nm": 5.0},
         "or coating_index and thickness_nm", "or --coating and --thickness"),
        ({"substrate_index": 2j, "alpha": 0.2, "coating_index": 1.5, "thickness_nm": 5.0,
          "coating_alpha": 0.1, "coating_surface": "top.di"},
         "roughness once: coating_alpha or coating_surface",
         "roughness once: --coating-alpha or --coating-surface"),
    ],
)  # fmt: skip
def test_arguments_that_do_not_fit_are_named(kw, keywords, options) -> None:
    from labbrdf.cli._options import OPTION_NAMES

    with pytest.raises(SetupError) as info:
        trace_config_from_inputs(633.0, 45.0, **kw)
    assert keywords in str(info.value)
    assert options in info.value.spelled(OPTION_NAMES)


def test_a_profile_is_no_slope_table() -> None:
    line = rough_map((256,))
    with pytest.raises(SetupError, match=r"^surface synthetic.map: .*areal height map"):
        trace_config_from_inputs(633.0, 45.0, substrate_index=2j, surface=line)
    with pytest.raises(SetupError, match=r"^coating_surface synthetic.map: a line profile"):
        trace_config_from_inputs(
            633.0, 45.0, substrate_index=2j, alpha=0.2, coating_index=1.5,
            thickness_nm=5.0, coating_surface=line,
        )  # fmt: skip


def test_a_coating_fit_that_cannot_be_read_names_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "fit.json"
    bad.write_text("{}")
    with pytest.raises(SetupError, match=r"^coating_from .*fit.json: not a film fit"):
        trace_config_from_inputs(633.0, 45.0, substrate_index=2j, alpha=0.2, coating_from=bad)


def test_file_names_with_braces_are_said_as_they_are(tmp_path: Path) -> None:
    bad = tmp_path / "{odd}.json"
    bad.write_text("{}")
    with pytest.raises(SetupError) as info:
        trace_config_from_inputs(633.0, 45.0, substrate_index=2j, alpha=0.2, coating_from=bad)
    assert "{odd}.json" in info.value.spelled({"coating_from": "--coating-from"})


def test_height_map_files_are_read_with_their_warnings(monkeypatch) -> None:
    hm = rough_map()
    hm_warned = HeightMap(hm.heights, hm.pixel_size, "m.di", "Height", ("Height",), {},
                          ("pixel size not stated",))  # fmt: skip
    calls = []

    def fake_read(path, channel, *, unit=None, pixel_size=None):
        calls.append((str(path), channel, unit, pixel_size))
        return hm_warned

    monkeypatch.setattr(slopes, "read_height_map", fake_read)
    said: list[str] = []
    cfg = trace_config_from_inputs(
        633.0, 45.0, substrate_index=2j, surface="m.di", channel="Height", unit="nm",
        pixel_size=(1e-8, 1e-8), warn=said.append,
    )  # fmt: skip
    assert calls == [("m.di", "Height", "nm", (1e-8, 1e-8))]
    assert said == ["m.di: pixel size not stated"]
    assert cfg.substrate.ndf is not None
    # a labbrdf warning class, so the command line prints it as one line
    with pytest.warns(SampleWarning, match="pixel size not stated"):
        trace_config_from_inputs(633.0, 45.0, substrate_index=2j, surface="m.di")


def test_a_map_too_big_for_memory_is_a_setup_error(monkeypatch) -> None:
    def no_memory(*args, **kw):
        raise MemoryError

    monkeypatch.setattr(slopes, "read_height_map", no_memory)
    with pytest.raises(SetupError, match=r"^surface huge.di: out of memory"):
        trace_config_from_inputs(633.0, 45.0, substrate_index=2j, surface="huge.di")


def test_values_the_tracer_refuses_are_its_own_errors() -> None:
    with pytest.raises(ValueError, match="substrate.alpha"):
        trace_config_from_inputs(633.0, 45.0, substrate_index=2j, alpha=20.0)


def test_a_lambertian_base_is_built_from_its_albedo_under_a_coating():
    cfg = trace_config_from_inputs(
        650.0,
        30.0,
        base_albedo=0.4,
        coating_index=1.5 + 0j,
        thickness_nm=100.0,
        coating_alpha=0.1,
    )
    assert cfg.substrate == Substrate.lambertian(0.4)
    assert cfg.coating is not None and cfg.coating.alpha == 0.1


@pytest.mark.parametrize(
    ("kwargs", "expected"),
    [
        ({"alpha": 0.2}, "base_albedo replaces the metal substrate: drop alpha"),
        ({"substrate_index": 1 + 1j}, "drop substrate_index"),
        (
            {"coating_index": 1.5 + 0j, "thickness_nm": 100.0},
            "base_albedo with a coating needs its roughness: coating_alpha",
        ),
        ({"base_albedo": 1.5}, "base_albedo: substrate.albedo must be"),
    ],
)
def test_a_base_refuses_the_metal_and_a_coating_without_roughness(kwargs, expected):
    kwargs = {"base_albedo": 0.5, **kwargs}
    with pytest.raises(SetupError) as err:
        trace_config_from_inputs(650.0, 30.0, **kwargs)
    assert expected in str(err.value)
