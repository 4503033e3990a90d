"""Every `teamnav ... --help` page reads like a well-kept click CLI: units survive, flags are
flags, options that take a value name it, and `--version` is a plain flag.

The commands are read from the app, so a command registered later is checked too.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
import typer.main
from typer.testing import CliRunner

from teamnav import __version__
from teamnav.cli import app

runner = CliRunner()
#: a wide terminal with no colour, as a CI log or a pipe sees it
ENV = {"COLUMNS": "200", "NO_COLOR": "1", "TERM": "dumb"}
GROUP = typer.main.get_command(app)
COMMANDS = sorted(GROUP.commands)
#: a Python type leaking into help as a metavar: <bool>, <int>, <float>, <str>, <path>, <list[str]>, ...
TYPE_LEAK = re.compile(r"<\s*(?:bool|int|float|str|path|file|list|tuple|dict|set|datetime|uuid|choice|text|integer|boolean)\b[^>]*>",
                       re.IGNORECASE)


def help_of(*words: str) -> str:
    result = runner.invoke(app, [*words, "--help"], env=ENV)
    assert result.exit_code == 0, result.output
    return result.stdout


def test_the_known_commands_are_registered():
    assert {"list", "run", "validate", "replay", "export", "sweep", "report"} <= set(COMMANDS)


@pytest.mark.parametrize("words", [(), *[(c,) for c in COMMANDS]], ids=lambda w: " ".join(w) or "teamnav")
def test_help_shows_no_type_labels_and_no_markup(words):
    text = help_of(*words)
    assert text.startswith("Usage: "), text
    assert not TYPE_LEAK.search(text), TYPE_LEAK.search(text).group(0)
    assert "BOOLEAN" not in text and "\\[" not in text  # click's flag metavar; a rich escape left behind
    assert not set(text) & set("╭╮╰╯│─"), "help in a pipe or a dumb terminal has no box drawing"


@pytest.mark.parametrize("name", COMMANDS)
def test_every_option_that_takes_a_value_names_it_and_flags_show_none(name):
    cmd = GROUP.commands[name]
    text = help_of(name)
    for param in cmd.params:
        if param.param_type_name == "argument":
            assert param.metavar, f"teamnav {name}: give argument {param.name!r} a metavar (SCENARIO, RUN_DIR, ...)"
            assert param.metavar in text
            continue
        if param.hidden:
            continue
        long_opt = max(param.opts, key=len)
        if param.is_flag or getattr(param, "count", False):
            assert re.search(rf"{re.escape(long_opt)}(?:\s*/\s*--[\w-]+)?\s{{2,}}\S", text), (name, long_opt)
            continue
        assert param.metavar, f"teamnav {name} {long_opt}: give it a metavar (N, SECONDS, DIR, KEY=VALUE, ...)"
        assert f"{long_opt} {param.metavar}" in text, (name, long_opt, param.metavar)


def test_top_level_lists_every_command_with_its_whole_first_line():
    text = help_of()
    commands = text[text.index("Commands:"):]
    for name in COMMANDS:
        line = next(ln for ln in commands.splitlines() if ln.strip().startswith(name + " "))
        assert not line.rstrip().endswith("..."), line


@pytest.mark.parametrize("name", ["run", "sweep"])
def test_duration_shows_its_unit(name):
    text = help_of(name)
    assert re.search(r"--duration SECONDS\s+Simulated time[^\n]*\[s\]", text), text


def test_set_and_grid_metavars():
    assert "--set KEY=VALUE" in help_of("run")
    assert "--set KEY=VALUE" in help_of("validate")
    sweep = help_of("sweep")
    assert "--grid KEY=V1,V2,..." in sweep and "--out DIR" in sweep and "--workers N" in sweep


def test_version_is_a_plain_flag():
    result = runner.invoke(app, ["--version"], env=ENV)
    assert result.exit_code == 0, result.output
    assert result.stdout.strip() == f"teamnav {__version__}"
    for args in (["--version", "true"], ["--version", "false"], ["--version=true"]):
        result = runner.invoke(app, args, env=ENV)
        assert result.exit_code == 2, (args, result.output)
        assert __version__ not in result.stdout
    assert "--version takes no value" in runner.invoke(app, ["--version", "true"], env=ENV).stderr


def test_help_in_a_real_pipe_is_plain_text():
    proc = subprocess.run([sys.executable, "-m", "teamnav", "run", "--help"], capture_output=True, text=True,
                          env={**os.environ, **ENV}, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "--duration SECONDS" in proc.stdout and "[s]" in proc.stdout
    assert not TYPE_LEAK.search(proc.stdout) and "╭" not in proc.stdout
