"""fit_many_nk (a model per wavelength with a measured index) and fit_records (JSON records).

fit_many_nk must equal fit_many with the model-per-group callable written by hand, plus the
n, k columns it used; fit_records gives one record per table row, failed groups included.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pandas as pd
import pytest

from labbrdf import models
from labbrdf.dataset import Measurement, make_frame
from labbrdf.errors import SetupError
from labbrdf.fitting import fit_many, fit_many_nk, fit_records
from labbrdf.jsonsafe import jsonable
from labbrdf.nk import NkError

INDEX = {500.0: (1.2, 6.0), 650.0: (1.6, 7.5)}


def nk_table() -> pd.DataFrame:
    """The combined table whose nodes are exactly INDEX."""
    wl = sorted(INDEX)
    return pd.DataFrame(
        {"sample": "ref", "source": "ref.dat", "wavelength_nm": wl,
         "n": [INDEX[w][0] for w in wl], "k": [INDEX[w][1] for w in wl],
         "n_sigma": 0.01, "k_sigma": 0.01, "nk_cov": 0.0}
    )  # fmt: skip


def scans(meta: dict[str, Any] | None = None) -> Measurement:
    """Noise-free microfacet scans of one sample at the two wavelengths (alpha 0.15, 0.25)."""
    tr = np.arange(0.0, 80.0, 2.0)
    frames = []
    for wl, alpha in ((500.0, 0.15), (650.0, 0.25)):
        m = models.get("microfacet", n=INDEX[wl][0], k=INDEX[wl][1])
        for ti in (20.0, 45.0):
            v = np.asarray(
                m.evaluate(np.radians(ti), np.radians(tr), np.pi, params={"alpha": alpha})
            )
            frames.append(make_frame(sample="A", instrument="synthetic", source="A.csv",
                                     quantity="brdf", value=v, unit="sr-1", wavelength_nm=wl,
                                     sigma=0.02 * np.abs(v), theta_i_deg=ti, theta_r_deg=tr,
                                     phi_r_deg=180.0))  # fmt: skip
    return Measurement(pd.concat(frames, ignore_index=True), meta or {})


def test_equals_fit_many_with_the_index_written_by_hand() -> None:
    data = scans()
    table, results = fit_many_nk(data, "microfacet", nk_table(), executor="serial")
    ref, ref_results = fit_many(
        data,
        lambda key: models.get("microfacet", n=INDEX[key["wavelength_nm"]][0],
                               k=INDEX[key["wavelength_nm"]][1]),
        by=["wavelength_nm", "sample"], executor="serial", return_results=True,
    )  # fmt: skip
    ref = ref[
        [
            "sample",
            "wavelength_nm",
            *(c for c in ref.columns if c not in ("sample", "wavelength_nm")),
        ]
    ]
    got = table.drop(columns=["n", "k", "elapsed_s"])
    pd.testing.assert_frame_equal(got, ref.drop(columns="elapsed_s"))
    assert table[["n", "k"]].to_numpy().tolist() == [list(INDEX[500.0]), list(INDEX[650.0])]
    assert table["alpha"].to_numpy() == pytest.approx([0.15, 0.25], rel=1e-6)
    assert [g for g, _ in results] == [g for g, _ in ref_results]


def test_one_wavelength_for_every_group_and_no_wavelength_column() -> None:
    table, results = fit_many_nk(
        scans(), "microfacet", nk_table(), wavelength_nm=500.0, by=["sample"], executor="serial"
    )
    assert list(table["sample"]) == ["A", "A"] and "wavelength_nm" not in table.columns
    assert set(map(tuple, table[["n", "k"]].to_numpy())) == {INDEX[500.0]}
    assert [g for g, _ in results] == [{"sample": "A"}, {"sample": "A"}]


def test_files_that_state_no_wavelength_need_one() -> None:
    meta = {"parts": [{"source": "x.bsdf", "meta": {"wavelength_stated": False}}]}
    with pytest.raises(SetupError) as info:
        fit_many_nk(scans(meta), "microfacet", nk_table(), executor="serial")
    said = info.value.spelled({"nk_from": "--nk-from", "wavelength_nm": "--wavelength"})
    assert said.startswith("--nk-from: x.bsdf state(s) no wavelength")
    assert said.endswith("with --wavelength NM")


def test_a_model_without_an_index_is_refused() -> None:
    with pytest.raises(SetupError, match="model 'smooth3' takes no index n, k"):
        fit_many_nk(scans(), "smooth3", nk_table(), executor="serial")


def test_a_wavelength_outside_the_index_table_names_the_source() -> None:
    with pytest.raises(NkError, match=r"^ref.dat: wavelength_nm: \[700.0\] outside"):
        fit_many_nk(scans(), "microfacet", nk_table(), wavelength_nm=700.0, source="ref.dat")


def test_records_have_a_row_each_failed_groups_included() -> None:
    data = scans().data
    b = data.assign(sample="B")  # B holds two wavelengths: one group by sample cannot fit
    df = pd.concat([data[data["wavelength_nm"] == 500.0], b], ignore_index=True)
    m = models.get("microfacet", n=1.2, k=6.0)
    table, results = fit_many(df, m, by=["sample"], executor="serial", return_results=True)
    recs = fit_records(table, results, ["sample"])
    assert [r["group"] for r in recs] == [{"sample": "A"}, {"sample": "B"}]
    ok, failed = recs
    assert ok["success"] and ok["params"]["alpha"]["value"] == pytest.approx(0.15, rel=1e-6)
    assert ok["nfev"] == results[0][1].nfev and math.isfinite(ok["rmse"])
    message = table["message"][1]
    assert "wavelength" in message
    assert failed == {"group": {"sample": "B"}, "params": {}, "rmse": None, "nfev": None,
                      "success": False, "message": message}  # fmt: skip
    json.dumps(jsonable(recs), allow_nan=False)  # JSON as it is printed
