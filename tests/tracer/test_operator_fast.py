"""The exit operator's faster paths against their plain definitions."""

from __future__ import annotations

from collections import OrderedDict
from pathlib import Path

import numpy as np

from labbrdf.tracer.binning import Grid
from labbrdf.tracer.operator import (
    ExitOperator,
    build_exit_operator,
    exit_operators,
    memory_cache,
)


def test_apply_with_row_weights_is_the_weighted_sum_of_the_groups() -> None:
    # the levels summed on the spectrum equal the per-level results summed afterwards
    rng = np.random.default_rng(3)
    nt, npf, groups, b = 5, 12, 3, 2
    shape = (npf // 2 + 1, 4 * nt, 4 * nt)
    spec = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(np.complex64)
    op = ExitOperator(spec, nt, npf, 0.0)
    cells = rng.standard_normal((groups * b, nt, npf, 4, 4))
    cells[:, 3:] = 0.0  # some rows unused: the column subset path
    rows = rng.standard_normal((groups, nt))
    each = op.apply(cells).reshape(groups, b, nt, npf, 4, 4)
    want = np.einsum("lr,lbr...->br...", rows, each)
    got = op.apply(cells, rows=rows)
    assert got.shape == (b, nt, npf, 4, 4)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())


REFERENCE = Path(__file__).with_name("data") / "exit_operators_v3.npz"


def test_build_equals_the_plain_builds_numbers() -> None:
    # the faster build against the spectra the plain loop built (data/README.md), to the
    # float32 round-off of the stored spectrum
    eps = np.finfo(np.float32).eps
    with np.load(REFERENCE) as ref:
        for name in ref.files:
            ts, ps, alpha, masking, kind = name.split("_", 4)
            grid = Grid(float(ts), float(ps))
            op = build_exit_operator(
                grid, 1.5, float(alpha), nodes=(2, 2), masking=masking, kind=kind
            )
            want = ref[name]
            assert op.spectrum.shape == want.shape and op.spectrum.dtype == want.dtype, name
            tol = 8 * eps * np.abs(want).max()
            np.testing.assert_allclose(op.spectrum, want, rtol=0, atol=tol, err_msg=name)


def test_operators_built_one_ahead_are_the_plain_builds_and_use_the_memory_cache() -> None:
    # the next operator is built in a worker thread: the same numbers as built alone, and
    # inside memory_cache the worker keeps them in the caller's store (not on disk)
    grid = Grid(30.0, 40.0)
    requests = [("correlated", "transmission")] + [
        ("incident", kind) for kind in ("transmission", "reflection", "reflection_away")
    ]
    store: OrderedDict = OrderedDict()
    with memory_cache(store):
        ops = list(exit_operators(grid, 1.5, 0.2, requests, nodes=(2, 2)))
    assert len(store) == len(requests)
    for op, (masking, kind) in zip(ops, requests, strict=True):
        alone = build_exit_operator(grid, 1.5, 0.2, nodes=(2, 2), masking=masking, kind=kind)
        np.testing.assert_array_equal(op.spectrum, alone.spectrum)
