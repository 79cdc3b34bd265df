"""A sample's bulk n, k from a file at one wavelength: read_nk, bulk_index_at, model_with_nk."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from labbrdf import models
from labbrdf.errors import SetupError
from labbrdf.nk import NkError, bulk_index_at, combined_table, model_with_nk, nk_at, read_nk

TA = "woollam-wvase-ascii/w2_10102006.dat"


def table(n: list[float], k: list[float]) -> pd.DataFrame:
    """A combined table of one sample at 500 and 600 nm (sigmas 0.01, no correlation)."""
    return pd.DataFrame(
        {"sample": "s", "source": "s.dat", "wavelength_nm": [500.0, 600.0], "n": n, "k": k,
         "n_sigma": 0.01, "k_sigma": 0.01, "nk_cov": 0.0}
    )  # fmt: skip


def test_between_nodes_the_index_is_interpolated_linearly() -> None:
    n, k = bulk_index_at(table([1.0, 2.0], [4.0, 6.0]), 525.0)
    assert (n, k) == pytest.approx((1.25, 4.5), abs=1e-12)


def test_outside_the_table_names_the_source() -> None:
    with pytest.raises(NkError, match=r"^sample.dat: wavelength_nm: \[700.0\] outside"):
        bulk_index_at(table([1.0, 2.0], [4.0, 6.0]), 700.0, source="sample.dat")


@pytest.mark.parametrize(("n", "k"), [([-0.5, 2.0], [4.0, 6.0]), ([1.0, 2.0], [-1.0, 6.0])])
def test_a_pseudo_index_outside_the_physical_half_plane_is_refused(n, k) -> None:
    with pytest.raises(NkError, match=r"^f.dat: the pseudo-index at 500 nm .* not a physical"):
        bulk_index_at(table(n, k), 500.0, source="f.dat")


@pytest.mark.shared
def test_a_file_gives_its_combined_table(real_exports: Path) -> None:
    import labbrdf

    got = read_nk(real_exports / TA)
    pd.testing.assert_frame_equal(got, combined_table(labbrdf.read(real_exports / TA)))
    n, k = bulk_index_at(got, 550.0)
    at = nk_at(got, 550.0)
    assert (n, k) == (float(at["n"]), float(at["k"]))


def test_a_file_without_psi_delta_names_the_file(fixtures_dir: Path) -> None:
    scan = fixtures_dir / "specular" / "osr_specular.csv"
    with pytest.raises(NkError, match=r"osr_specular.csv: no psi/delta rows"):
        read_nk(scan)


def test_a_model_gets_the_index_at_the_wavelength() -> None:
    m = model_with_nk("microfacet", table([1.0, 2.0], [4.0, 6.0]), 550.0, diffuse=True)
    ref = models.get("microfacet", n=1.5, k=5.0, diffuse=True)
    th = np.radians([10.0, 40.0, 70.0])
    p = {"alpha": 0.2, "kd": 0.1}
    got = m.evaluate(0.5, th, np.pi, params=p)
    np.testing.assert_allclose(got, ref.evaluate(0.5, th, np.pi, params=p), rtol=1e-14)


def test_a_model_without_an_index_is_refused_by_name() -> None:
    with pytest.raises(SetupError) as info:
        model_with_nk("smooth3", table([1.0, 2.0], [4.0, 6.0]), 550.0)
    assert info.value.spelled({"nk_from": "--nk-from"}) == (
        "--nk-from: model 'smooth3' takes no index n, k"
    )


def test_option_names_are_the_constructor_keywords() -> None:
    assert {"n", "k", "diffuse"} <= models.option_names("microfacet")
    assert "n" not in models.option_names("smooth3")
    with pytest.raises(models.ModelError, match="unknown model 'phong'"):
        models.option_names("phong")
