"""A 0 nm coating is the bare substrate, or it is refused."""

from __future__ import annotations

import pytest

import labbrdf
from labbrdf.tracer import Coating, Substrate, TraceConfig, trace_summary

AL = Substrate(n=1.55, k=7.71, alpha=0.2)


def test_incoherent_zero_thickness_coating_is_refused():
    with pytest.raises(ValueError, match=r"coating.thickness_nm must be > 0 in the incoherent"):
        TraceConfig(wavelength_nm=650, theta_i_deg=45, rays=1000, substrate=AL,
                    coating=Coating(thickness_nm=0.0))  # fmt: skip


def test_coherent_zero_thickness_film_is_the_bare_substrate():
    # same seed, same facets: an Airy film of 0 nm has the substrate's amplitudes, so the
    # two runs agree to round-off, far inside the Monte Carlo error
    kw = {"wavelength_nm": 650, "theta_i_deg": 45, "rays": 50_000, "seed": 3, "substrate": AL}
    film = labbrdf.trace(
        TraceConfig(**kw, coating=Coating(thickness_nm=0.0, alpha=0.2), coherent=True)
    )
    bare = labbrdf.trace(TraceConfig(**kw))
    assert trace_summary(film)["albedo"] == pytest.approx(trace_summary(bare)["albedo"], rel=1e-12)
