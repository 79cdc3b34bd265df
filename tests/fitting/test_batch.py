"""The batch fitter fit_many: a model per group, the executor it runs on, its arguments.

The model-per-group form is what ``labbrdf fit --nk-from`` uses (a microfacet model with
the index n, k of each wavelength): its table must equal the per-wavelength batches it
replaced, row for row. Its executor may be an :class:`~labbrdf.parallel.Executor` or a
scheduler name; the numbers may not depend on which.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd
import pytest

from labbrdf import models, parallel
from labbrdf.dataset import make_frame
from labbrdf.fitting import METHOD, FitError, fit, fit_many

#: the index (n, k) of each wavelength [nm]: two metals, so that the models differ
INDEX = {500.0: (1.2, 6.0), 650.0: (1.6, 7.5)}
ALPHA = {("A", 500.0): 0.12, ("A", 650.0): 0.18, ("B", 500.0): 0.25, ("B", 650.0): 0.3}


def microfacet_scans() -> pd.DataFrame:
    """In-plane microfacet BRDF scans of two samples at two wavelengths, 2 % noise."""
    rng = np.random.default_rng(7)
    tr = np.arange(0.0, 80.0, 2.0)
    frames = []
    for (sample, wl), alpha in ALPHA.items():
        n, k = INDEX[wl]
        m = models.get("microfacet", n=n, k=k)
        for ti in (20.0, 45.0):
            v = np.asarray(
                m.evaluate(np.radians(ti), np.radians(tr), np.pi, params={"alpha": alpha})
            )
            v = v * (1 + 0.02 * rng.standard_normal(v.shape))
            frames.append(
                make_frame(
                    sample=sample,
                    instrument="synthetic",
                    source=f"{sample}.csv",
                    quantity="brdf",
                    value=v,
                    unit="sr-1",
                    wavelength_nm=wl,
                    sigma=0.02 * np.abs(v),
                    theta_i_deg=ti,
                    theta_r_deg=tr,
                    phi_r_deg=180.0,
                )  # fmt: skip
            )
    return pd.concat(frames, ignore_index=True)


def model_at(key: dict[str, Any]) -> models.Model:
    n, k = INDEX[key["wavelength_nm"]]
    return models.get("microfacet", n=n, k=k)


def no_time(t: pd.DataFrame) -> pd.DataFrame:
    return t.drop(columns="elapsed_s")


def test_a_model_per_group_equals_one_batch_per_wavelength() -> None:
    df = microfacet_scans()
    table, results = fit_many(
        df, model_at, by=["wavelength_nm", "sample"], executor="serial", return_results=True
    )
    parts = []
    for wl, part in df.groupby("wavelength_nm", sort=True):
        n, k = INDEX[float(wl)]
        parts.append(
            fit_many(
                part,
                models.get("microfacet", n=n, k=k),
                by=["wavelength_nm", "sample"],
                executor="serial",
            )  # fmt: skip
        )
    pd.testing.assert_frame_equal(no_time(table), no_time(pd.concat(parts, ignore_index=True)))
    assert list(zip(table["wavelength_nm"], table["sample"], strict=True)) == [
        (500.0, "A"), (500.0, "B"), (650.0, "A"), (650.0, "B")
    ]  # fmt: skip
    # each group was fitted with its own wavelength's index, and recovers its alpha
    for key, res in results:
        assert res.options["n"] == INDEX[key["wavelength_nm"]][0]
        alpha = ALPHA[(key["sample"], key["wavelength_nm"])]
        assert res.values["alpha"] == pytest.approx(alpha, rel=0.05)


def test_a_model_per_group_checks_fixed_names_on_each_model() -> None:
    with pytest.raises(FitError, match="has no parameter 'q'"):
        fit_many(microfacet_scans(), model_at, fix={"q": 1.0}, executor="serial")


@pytest.mark.slow
def test_executor_object_and_scheduler_names_give_the_same_table() -> None:
    df = microfacet_scans()
    serial = fit_many(df, model_at, executor=parallel.Executor("serial"), progress=False)
    by_name = fit_many(df, model_at, scheduler="processes", workers=2, progress=False)
    pool = fit_many(df, model_at, executor=parallel.Executor("processes", workers=2))
    pd.testing.assert_frame_equal(no_time(serial), no_time(by_name))
    pd.testing.assert_frame_equal(no_time(serial), no_time(pool))
    single = fit(
        model_at({"wavelength_nm": 650.0}),
        df[(df["sample"] == "B") & (df["wavelength_nm"] == 650.0)],
    )
    assert serial["alpha"].iloc[-1] == single.values["alpha"]


def test_executor_and_scheduler_together_are_refused() -> None:
    df = microfacet_scans()
    with pytest.raises(ValueError, match="either an executor or a scheduler"):
        fit_many(df, model_at, executor="serial", scheduler="serial")
    with pytest.raises(ValueError, match="an Executor has its own worker count"):
        fit_many(df, model_at, executor=parallel.Executor("serial"), workers=2)
    with pytest.raises(ValueError, match="unknown scheduler 'gpu'"):
        fit_many(df, model_at, executor="gpu")


def test_the_default_method_is_the_fitting_core_constant() -> None:
    import inspect

    from labbrdf.fitting import core, film
    from labbrdf.report import user_report

    assert METHOD == "GN_CRS2_LM+LN_BOBYQA"
    for f in (core.fit, fit_many, film.fit_film, user_report):
        assert inspect.signature(f).parameters["method"].default is METHOD
