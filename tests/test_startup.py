"""Start-up stays light: what `import teamnav` and the CLI module import.

Read from ``python -X importtime`` (the list of modules a fresh interpreter imported), never
from a clock: speed is measured by ``benchmarks/bench_startup.py``. The heavy layers
(matplotlib, pandas, scipy's optimizer, ray, the report machinery) are imported by the
commands that use them, when they use them.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import teamnav

SRC = str(Path(teamnav.__file__).resolve().parent.parent)
#: top-level names (a module and everything under it) that must not be imported at start-up
HEAVY = ("matplotlib", "pandas", "scipy.optimize", "ray", "foxglove", "mcap", "teamnav.experiments.report",
         "teamnav.viz.plots", "teamnav.viz.report_figures")


def imported_modules(statement: str) -> list[str]:
    """The modules a fresh interpreter imports to run ``statement``, in order."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([SRC, os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.run([sys.executable, "-X", "importtime", "-c", statement], capture_output=True, text=True,
                          env=env, timeout=120, check=True)
    names = []
    for line in proc.stderr.splitlines():
        if line.startswith("import time:") and "|" in line:
            name = line.rsplit("|", 1)[1].strip()
            if name != "imported package":  # the header line
                names.append(name)
    assert names, proc.stderr[-2000:]
    return names


def heavy_among(names: list[str]) -> list[str]:
    return [n for n in names if any(n == h or n.startswith(h + ".") for h in HEAVY)]


@pytest.mark.parametrize("statement", ["import teamnav", "import teamnav.cli", "from teamnav.cli import app, main"])
def test_start_up_imports_no_heavy_layer(statement):
    names = imported_modules(statement)
    assert statement.split()[1] in names or "teamnav.cli" in names
    assert heavy_among(names) == [], f"{statement} imports {heavy_among(names)}; import them where they are used"


def test_import_teamnav_stays_out_of_numba_and_scipy():
    names = imported_modules("import teamnav")
    assert [n for n in names if n.split(".")[0] in ("numba", "scipy", "typer", "rich")] == []


def test_the_checker_sees_a_heavy_import():
    # the listing is read correctly: a statement that does import matplotlib is caught
    assert "matplotlib" in heavy_among(imported_modules("import teamnav, matplotlib"))


def test_the_lazy_report_command_is_listed_with_its_own_help():
    # `teamnav --help` shows the report command's line without importing it: the line written
    # in teamnav.cli must be the command's own
    import typer.main

    from teamnav import cli

    group = typer.main.get_command(cli.app)
    assert "report" in list(group.commands)
    for name, (_module, _attr, line) in cli._LAZY_COMMANDS.items():
        assert group.commands[name].get_short_help_str(200) == line
