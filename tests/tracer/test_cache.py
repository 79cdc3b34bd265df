"""The tracer's disk cache (``tracer.cache``): nothing planted there changes a result, the
folder is private and bounded, and only labbrdf's own files are ever removed."""

from __future__ import annotations

import json
import os
import time
import warnings

import numpy as np
import pytest

from labbrdf.tracer import cache
from labbrdf.tracer.binning import Grid
from labbrdf.tracer.cache import CacheWarning, cache_dir
from labbrdf.tracer.operator import build_exit_operator, exit_operator

GRID = Grid(10.0, 20.0)


@pytest.fixture
def fresh(tmp_path, monkeypatch):
    """An empty cache folder, and the operator built without any cache."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.delenv(cache.ENV_MAX_BYTES, raising=False)
    return build_exit_operator(GRID, 1.5, 0.3)


def _stored() -> os.PathLike:
    """Run once so that the operator is stored; its file."""
    exit_operator(GRID, 1.5, 0.3)
    (path,) = cache_dir().glob("exit-*.op")
    return path


def _split(path) -> tuple[bytes, bytes]:
    raw = path.read_bytes()
    head = raw.index(b"\n", len(b"LABBRDF-TRACER-CACHE 1\n")) + 1
    return raw[:head], raw[head:]


def _no_warning_on_reload(fresh) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", CacheWarning)
        again = exit_operator(GRID, 1.5, 0.3)
    assert np.array_equal(again.spectrum, fresh.spectrum)


def _zeros(path) -> None:
    head, data = _split(path)
    path.write_bytes(head + bytes(len(data)))


def _nans(path) -> None:
    head, data = _split(path)
    path.write_bytes(head + np.full(len(data) // 4, np.nan, np.float32).tobytes())


def _huge_shape(path) -> None:
    head, data = _split(path)
    meta = json.loads(head.split(b"\n")[1])
    meta["shape"] = [2**40, 2**40, 2**40]
    path.write_bytes(head.split(b"\n")[0] + b"\n" + json.dumps(meta).encode() + b"\n" + data)


def _truncated(path) -> None:
    path.write_bytes(path.read_bytes()[:-1000])


def _one_bit(path) -> None:
    raw = bytearray(path.read_bytes())
    raw[-5] ^= 1
    path.write_bytes(bytes(raw))


def _npy(path) -> None:
    """An earlier release's format (.npy), with a crafted header of a huge shape."""
    head = {"descr": "<c8", "fortran_order": False, "shape": (2**40, 2**40, 2**40)}
    with open(path, "wb") as fh:
        np.lib.format.write_array_header_1_0(fh, head)


def _endless_header(path) -> None:
    path.write_bytes(b"LABBRDF-TRACER-CACHE 1\n" + b"{" * 100_000)


@pytest.mark.parametrize(
    "plant", [_zeros, _nans, _huge_shape, _truncated, _one_bit, _npy, _endless_header]
)
def test_a_planted_or_corrupt_operator_never_changes_the_result(fresh, plant):
    path = _stored()
    plant(path)
    with pytest.warns(CacheWarning, match=path.name):
        op = exit_operator(GRID, 1.5, 0.3)
    assert np.array_equal(op.spectrum, fresh.spectrum)
    _no_warning_on_reload(fresh)  # the bad file was replaced by the rebuilt one


@pytest.mark.parametrize("mode", [0o620, 0o602])
def test_an_operator_file_others_can_write_is_not_used_nor_replaced(fresh, mode):
    path = _stored()
    _zeros(path)
    path.chmod(mode)
    with pytest.warns(CacheWarning, match="writable by others"):
        op = exit_operator(GRID, 1.5, 0.3)
    assert np.array_equal(op.spectrum, fresh.spectrum)
    assert path.stat().st_mode & 0o777 == mode  # not ours alone: left as it is


@pytest.mark.skipif(os.getuid() != 0, reason="giving a file to another user needs root")
def test_an_operator_file_of_another_user_is_not_used(fresh):
    path = _stored()
    _zeros(path)
    os.chown(path, 4242, 4242)
    with pytest.warns(CacheWarning, match="another user"):
        op = exit_operator(GRID, 1.5, 0.3)
    assert np.array_equal(op.spectrum, fresh.spectrum)
    assert path.stat().st_uid == 4242


@pytest.mark.skipif(os.getuid() != 0, reason="giving a folder to another user needs root")
def test_a_cache_folder_of_another_user_is_not_used(fresh):
    path = _stored()
    _zeros(path)
    os.chown(path.parent, 4242, 4242)
    with pytest.warns(CacheWarning, match="another user"):
        op = exit_operator(GRID, 1.5, 0.3)
    assert np.array_equal(op.spectrum, fresh.spectrum)


def test_a_cache_folder_others_can_write_is_neither_read_nor_written(fresh):
    path = _stored()
    _zeros(path)
    path.parent.chmod(0o777)
    with pytest.warns(CacheWarning, match=r"writable by others.*not stored"):
        op = exit_operator(GRID, 1.5, 0.3)
    assert np.array_equal(op.spectrum, fresh.spectrum)
    with pytest.warns(CacheWarning):
        exit_operator(GRID, 1.4, 0.3)
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # nothing written


def test_a_symlink_or_a_pipe_under_an_operator_name_is_not_followed(fresh, tmp_path):
    path = _stored()
    target = tmp_path / "elsewhere.op"
    target.write_bytes(path.read_bytes())
    path.unlink()
    path.symlink_to(target)
    with pytest.warns(CacheWarning, match=path.name):
        op = exit_operator(GRID, 1.5, 0.3)
    assert np.array_equal(op.spectrum, fresh.spectrum)
    path.unlink()
    os.mkfifo(path)
    with pytest.warns(CacheWarning, match="not a regular file"):
        op = exit_operator(GRID, 1.5, 0.3)  # would block forever if it were opened to read
    assert np.array_equal(op.spectrum, fresh.spectrum)


def test_the_cache_folder_is_private(fresh):
    path = _stored()
    assert path.parent.stat().st_mode & 0o777 == 0o700


def _total() -> int:
    return sum(p.stat().st_size for p in cache_dir().iterdir())


def test_the_cache_stays_under_its_cap_across_many_traces(fresh, monkeypatch):
    one = _stored().stat().st_size
    cap = int(2.5 * one)
    monkeypatch.setenv(cache.ENV_MAX_BYTES, str(cap))
    for i in range(8):
        exit_operator(GRID, 1.5, 0.31 + 0.01 * i)
        assert _total() <= cap
    assert len(list(cache_dir().iterdir())) == 2
    assert cache.info().total_bytes <= cap


def test_eviction_removes_the_least_recently_used(fresh, monkeypatch):
    a = _stored()
    exit_operator(GRID, 1.4, 0.3)
    (b,) = set(cache_dir().glob("*.op")) - {a}
    now = time.time()
    os.utime(a, (now - 100, now - 100))  # a older than b ...
    os.utime(b, (now - 10, now - 10))
    exit_operator(GRID, 1.5, 0.3)  # ... but used last
    monkeypatch.setenv(cache.ENV_MAX_BYTES, str(2 * a.stat().st_size + 10))
    exit_operator(GRID, 1.3, 0.3)
    assert a.exists() and not b.exists()


def test_eviction_and_clear_remove_only_labbrdf_files(fresh, monkeypatch):
    path = _stored()
    others = ["notes.txt", "exit-abc.op", "exit-" + "0" * 32 + ".op.bak", "big.dat"]
    for name in others:
        (path.parent / name).write_bytes(b"x" * 100_000)
    monkeypatch.setenv(cache.ENV_MAX_BYTES, str(path.stat().st_size + 10))
    exit_operator(GRID, 1.4, 0.3)  # the old operator makes room; the rest is not ours
    names = sorted(p.name for p in path.parent.iterdir())
    assert path.name not in names and all(n in names for n in others)
    assert len(names) == len(others) + 1
    n, size = cache.clear()
    assert n == 1 and size > 0
    assert sorted(p.name for p in path.parent.iterdir()) == sorted(others)


def test_an_operator_larger_than_the_cap_is_not_stored(fresh, monkeypatch):
    monkeypatch.setenv(cache.ENV_MAX_BYTES, "1k")
    op = exit_operator(GRID, 1.5, 0.3)
    assert np.array_equal(op.spectrum, fresh.spectrum)
    assert not cache_dir().exists()


@pytest.mark.parametrize(
    ("text", "value"), [("0", 0), ("123", 123), ("500M", 500 * 10**6), ("2G", 2 * 10**9)]
)
def test_the_cap_setting(monkeypatch, text, value):
    monkeypatch.setenv(cache.ENV_MAX_BYTES, text)
    assert cache.max_bytes() == value


@pytest.mark.parametrize("text", ["-1", "1.5G", "lots", "1e9"])
def test_a_bad_cap_setting_names_the_variable(monkeypatch, text):
    monkeypatch.setenv(cache.ENV_MAX_BYTES, text)
    with pytest.raises(ValueError, match=cache.ENV_MAX_BYTES):
        cache.max_bytes()


def test_the_default_cap_suits_a_laptop(monkeypatch):
    monkeypatch.delenv(cache.ENV_MAX_BYTES, raising=False)
    assert cache.max_bytes() == cache.DEFAULT_MAX_BYTES == 2**30


def test_a_planted_operator_never_changes_a_trace(tmp_path, monkeypatch):
    from labbrdf.tracer import Coating, Substrate, TraceConfig, trace

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    cfg = TraceConfig(
        rays=2000,
        theta_i_deg=45.0,
        substrate=Substrate(n=1.55, k=7.71, alpha=0.2),
        coating=Coating(n=1.5, thickness_nm=100.0, alpha=0.2),
        scattering="single",
        theta_step_deg=10.0,
        phi_step_deg=20.0,
    )
    ref = trace(cfg)
    (path,) = cache_dir().glob("exit-*.op")
    for plant in (_zeros, _nans):
        plant(path)
        with pytest.warns(CacheWarning, match=path.name):
            got = trace(cfg)
        assert got.albedo() == ref.albedo()
        assert np.array_equal(got.sums, ref.sums)
