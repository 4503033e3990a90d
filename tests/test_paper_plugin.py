"""A fifth paper from outside teamnav plugs in through the one registration path.

``tests/toy_paper`` is an outside package (with the ``.dist-info`` that ``pip install`` writes)
that registers a toy paper under the ``teamnav.papers`` entry-point group, as teamnav's own
five papers do. Put on the path, its scenario, brain, maps, metric set, sweep and report
section show up in the CLI; off the path, none of them does.
"""

from __future__ import annotations

import json
import os
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

TOY = Path(__file__).with_name("toy_paper")


def _teamnav(*args: str, toy: bool = True, cwd: Path | None = None) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    if toy:
        env["PYTHONPATH"] = os.pathsep.join([str(TOY), *filter(None, [env.get("PYTHONPATH")])])
    return subprocess.run([sys.executable, "-m", "teamnav", *args], capture_output=True, text=True, env=env,
                          timeout=600, cwd=cwd)


def test_toy_paper_shows_in_list():
    out = _teamnav("list", "--json")
    assert out.returncode == 0, out.stderr
    cat = json.loads(out.stdout)
    assert {"name": "toy-box", "description": "two toy circlers in the toy paper's box"} in cat["scenarios"]
    assert "toy-circler-v1" in cat["controllers"]
    assert {"toy_box", "toy_box_wide"} <= set(cat["builtin_maps"])
    # teamnav's own papers are still there beside it
    assert "los-help-simple" in [s["name"] for s in cat["scenarios"]]
    assert "los-explorer-v1" in cat["controllers"]


def test_without_the_package_nothing_of_it_shows():
    out = _teamnav("list", "--json", toy=False)
    assert out.returncode == 0, out.stderr
    cat = json.loads(out.stdout)
    assert "toy-box" not in [s["name"] for s in cat["scenarios"]]
    assert "toy-circler-v1" not in cat["controllers"]


def test_toy_scenario_runs_with_its_brain_map_and_metric(tmp_path):
    out = _teamnav("run", "toy-box", "--out", str(tmp_path / "run"), "-q")
    assert out.returncode == 0, out.stderr
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    # two circlers at 0.3 m/s for 2 s: 0.6 m each; their x positions spread over the box
    assert metrics["path_length_m_mean"] == pytest.approx(0.6, abs=0.02)
    assert 0.0 < metrics["toy_spread_m"] < 6.0


def test_toy_sweep_runs_by_name(tmp_path):
    out = _teamnav("sweep", "toy-seeds", "--out", str(tmp_path / "sw"), "-q")
    assert out.returncode == 0, out.stderr + out.stdout
    with sqlite3.connect(tmp_path / "sw" / "results.sqlite") as db:
        n = db.execute("SELECT COUNT(*) FROM trials").fetchone()[0]
    assert n == 2


def test_toy_section_builds_in_the_report(tmp_path):
    out = _teamnav("report", "toy-paper", "--out", str(tmp_path / "rep"), "--quick", "-q")
    assert out.returncode == 0, out.stderr + out.stdout
    html = (tmp_path / "rep" / "index.html").read_text()
    assert "Toy paper: circles in a box" in html and "Toy circles" in html


def test_a_broken_registration_is_skipped_with_a_warning(tmp_path):
    """One broken plug-in must not take teamnav down: it is named in a warning, the rest runs."""
    bad = tmp_path / "bad"
    (bad / "bad_paper-0.1.dist-info").mkdir(parents=True)
    (bad / "bad_paper-0.1.dist-info" / "METADATA").write_text("Metadata-Version: 2.1\nName: bad_paper\nVersion: 0.1\n")
    (bad / "bad_paper-0.1.dist-info" / "entry_points.txt").write_text("[teamnav.papers]\nbad = bad_paper:PAPER\n")
    (bad / "bad_paper.py").write_text("PAPER = {'key': 'bad'}\n")
    env = dict(os.environ, PYTHONPATH=str(bad))
    out = subprocess.run([sys.executable, "-m", "teamnav", "list", "--names"], capture_output=True, text=True,
                         env=env, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "skipped paper entry point bad = bad_paper:PAPER" in out.stderr
    assert "expected a teamnav.plugins.Paper, found dict" in out.stderr
    assert "los-help-simple" in out.stdout.split()
