"""``labbrdf cache``: shows the tracer's operator cache and clears labbrdf's files only."""

from __future__ import annotations

import json

import pytest

from labbrdf.cli import main
from labbrdf.tracer import cache
from labbrdf.tracer.binning import Grid
from labbrdf.tracer.operator import exit_operator


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """A cache with two operators of a small grid and one file that is not labbrdf's."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setenv(cache.ENV_MAX_BYTES, "300M")
    for alpha in (0.3, 0.4):
        exit_operator(Grid(10.0, 20.0), 1.5, alpha)
    d = cache.cache_dir()
    (d / "mine.txt").write_text("a user's note")
    return d


def test_info_shows_folder_entries_size_and_cap(folder, capsys):
    assert main(["cache", "info"]) == 0
    out = capsys.readouterr().out
    size = sum(p.stat().st_size for p in folder.glob("exit-*.op"))
    assert str(folder) in out
    assert "entries  2" in out
    assert f"{size / 1e6:.1f} MB" in out
    assert "300.0 MB" in out and cache.ENV_MAX_BYTES in out
    assert main(["cache"]) == 0  # info is the default
    assert capsys.readouterr().out == out


def test_info_as_json(folder, capsys):
    assert main(["cache", "info", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["folder"] == str(folder)
    assert len(d["entries"]) == 2 and d["max_bytes"] == 300_000_000
    assert d["total_bytes"] == sum(e["size"] for e in d["entries"])


def test_clear_removes_only_labbrdf_files(folder, capsys):
    assert main(["cache", "clear"]) == 0
    assert "removed 2 file(s)" in capsys.readouterr().out
    assert [p.name for p in folder.iterdir()] == ["mine.txt"]
    assert main(["cache", "info"]) == 0
    assert "entries  0" in capsys.readouterr().out


def test_a_bad_cap_setting_exits_2_naming_the_variable(folder, monkeypatch, capsys):
    monkeypatch.setenv(cache.ENV_MAX_BYTES, "lots")
    assert main(["cache", "info"]) == 2
    err = capsys.readouterr().err
    assert cache.ENV_MAX_BYTES in err and "Traceback" not in err


def test_an_unknown_action_exits_2(capsys):
    with pytest.raises(SystemExit) as info:
        main(["cache", "purge"])
    assert info.value.code == 2
