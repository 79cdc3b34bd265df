"""Start-up: ``labbrdf --version`` and every command's parser import no heavy library."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from labbrdf.cli import build_parser, main
from labbrdf.cli._parser import COMMANDS, chosen_command

HEAVY = ("scipy", "pandas", "matplotlib", "nlopt")

#: what a fresh interpreter reports: the heavy libraries imported after ``--version``, then
#: after building each command's parser in turn (modules accumulate: a later entry holds
#: the earlier ones too, so each command is checked by the first entry that names it)
_PROBE = f"""
import json, sys
from labbrdf.cli import main
from labbrdf.cli._parser import COMMANDS, build_parser
HEAVY = {HEAVY!r}
def heavy():
    return sorted(m for m in sys.modules if m.partition(".")[0] in HEAVY)
try:
    main(["--version"])
except SystemExit:
    pass
out = {{"--version": heavy(), "numpy after --version": "numpy" in sys.modules}}
for name in COMMANDS:
    build_parser(commands=(name,))
    out[name] = heavy()
from labbrdf.cli._run import _labbrdf_warnings
from labbrdf import progress
with _labbrdf_warnings("x"), progress.shown("x"):  # what wraps every command
    out["around a command"] = heavy()
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def imported() -> dict:
    done = subprocess.run(
        [sys.executable, "-c", _PROBE], capture_output=True, text=True, check=True, timeout=120
    )
    return json.loads(done.stdout.splitlines()[-1])


def test_version_imports_no_heavy_library_nor_numpy(imported):
    assert imported["--version"] == []
    assert imported["numpy after --version"] is False


@pytest.mark.parametrize("command", list(COMMANDS))
def test_each_command_parser_imports_no_scipy_pandas_matplotlib(imported, command):
    assert imported[command] == []


def test_what_wraps_every_command_imports_no_heavy_library(imported):
    # the warnings shown as one line and the progress line: no reader, no pandas
    assert imported["around a command"] == []


def test_help_lists_each_command_with_its_module_own_help_line():
    # the light table of help lines against the parsers the command modules build
    assert build_parser(commands=()).format_help() == build_parser().format_help()
    full = build_parser()
    (sub,) = [a for a in full._actions if a.dest == "command"]
    own = {a.dest: a.help for a in sub._choices_actions}
    assert own == COMMANDS


def test_only_the_chosen_command_is_built():
    p = build_parser(commands=("formats",))
    (sub,) = [a for a in p._actions if a.dest == "command"]
    assert sub.choices["formats"].get_default("func") is not None
    assert sub.choices["fit"].get_default("func") is None  # a stub with its help line


@pytest.mark.parametrize(
    ("argv", "command"),
    [
        (["fit", "a.csv", "--model", "x"], "fit"),
        (["--version"], None),
        (["-h", "film"], "film"),
        (["nosuch", "fit"], None),
        (["--", "fit"], None),
        ([], None),
    ],
)
def test_chosen_command_is_the_first_word_that_is_not_an_option(argv, command):
    assert chosen_command(argv) == command


def test_an_unknown_command_is_refused_with_the_list_of_commands(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["nosuch"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "invalid choice: 'nosuch'" in err and "surface" in err


def test_a_chosen_command_still_parses_its_options(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["surface", "--degree", "x", "f.txt"])
    assert exc.value.code == 2
    assert "--degree: invalid int value: 'x'" in capsys.readouterr().err
