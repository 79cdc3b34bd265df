"""Exit operators kept in memory (``operator.memory_cache``) instead of the disk cache."""

from __future__ import annotations

from collections import OrderedDict

import numpy as np

from labbrdf.tracer.binning import Grid
from labbrdf.tracer.operator import (
    MEMORY_OPERATORS,
    build_exit_operator,
    cache_dir,
    exit_operator,
    memory_cache,
)


def test_memory_cache_writes_nothing_and_reuses_the_operator(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    grid = Grid(10.0, 20.0)
    with memory_cache():
        a = exit_operator(grid, 1.5, 0.3)
        b = exit_operator(grid, 1.5, 0.3)
    assert a is b
    assert not cache_dir().exists()
    ref = build_exit_operator(grid, 1.5, 0.3)
    assert np.array_equal(a.spectrum, ref.spectrum)
    # outside the block the disk cache is back
    exit_operator(grid, 1.5, 0.3)
    assert [f.suffix for f in cache_dir().iterdir()] == [".op"]


def test_a_store_carries_operators_between_blocks_and_keeps_the_latest(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    grid = Grid(10.0, 20.0)
    store: OrderedDict = OrderedDict()
    with memory_cache(store):
        a = exit_operator(grid, 1.5, 0.3)
    with memory_cache(store):
        assert exit_operator(grid, 1.5, 0.3) is a
        for j in range(MEMORY_OPERATORS):
            exit_operator(grid, 1.5, 0.31 + 0.01 * j)
    assert len(store) == MEMORY_OPERATORS
    with memory_cache(store):
        assert exit_operator(grid, 1.5, 0.3) is not a  # evicted, rebuilt
    assert not cache_dir().exists()
