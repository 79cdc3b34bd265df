"""The exit operator's faster paths against their plain definitions."""

from __future__ import annotations

import numpy as np

from labbrdf.tracer.operator import ExitOperator


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
