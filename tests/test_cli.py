"""The teamnav command: bad input gives one clear message and exit 2; runs write their folder."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from typer.testing import CliRunner

from teamnav.cli import app

GOOD = """\
name: tiny
map: {builtin: office_simple}
duration_s: 1.0
robots:
  - count: 2
    controller: wander-v1
    sensors:
      - {kind: laser, n_beams: 30, max_range_m: 5.0}
    start: {region: [1.0, 29.0, 6.0, 8.0]}
"""

runner = CliRunner()


def write(tmp_path: Path, text: str, name: str = "s.yaml") -> Path:
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return p


def invoke(*args: str):
    return runner.invoke(app, [str(a) for a in args])


def assert_bad_input(result, *fragments: str) -> None:
    """Exit 2, a message on stderr naming every fragment, no traceback."""
    assert result.exit_code == 2, result.output
    assert isinstance(result.exception, SystemExit)
    assert "Traceback" not in result.output
    assert result.stderr.startswith("error: ")
    for frag in fragments:
        assert frag in result.stderr, (frag, result.stderr)


# (file patch, extra CLI args, expected field, more fragments)
BAD_FILES = {
    "unknown key": (("    sensors:", "    sensrs:"), (), "robots[0].sensrs", ["unknown key", "did you mean 'sensors'"]),
    "wrong type": (("duration_s: 1.0", "duration_s: soon"), (), "duration_s", ["'soon'"]),
    "nan": (("duration_s: 1.0", "duration_s: .nan"), (), "duration_s", ["finite", "nan"]),
    "out of range": (("  - count: 2", "  - count: -3"), (), "robots[0].count", ["greater than or equal to 0", "-3"]),
    "missing map": (("{builtin: office_simple}", "{file: maps/none.yaml}"), (), "map.file", ["none.yaml", "no such file"]),
    "malformed map": (("{builtin: office_simple}", "{file: bad_map.yaml}"), (), "map.file", ["bad_map.yaml", "'origin'"]),
    "unknown controller": (("wander-v1", "wandr-v1"), (), "robots[0].controller", ["did you mean 'wander-v1'"]),
    "bad params": (("    controller: wander-v1", "    controller: wander-v1\n    params: {cruise_speed_mps: -0.5}"), (),
                   "robots[0].params.cruise_speed_mps", ["greater than 0", "-0.5"]),
    "bad set key": ((None, None), ("--set", "robots.0.cuont=3"), "robots[0].cuont", ["unknown key", "--set robots.0.cuont=3"]),
    "bad set value": ((None, None), ("--set", "robots.0.count=many"), "robots[0].count", ["'many'", "--set robots.0.count=many"]),
    "yaml syntax": (("map: {builtin: office_simple}", "map: {builtin: [office_simple}"), (), "YAML syntax error", ["line 2"]),
    "nested sensor": (("max_range_m: 5.0", "max_range_m: -5.0"), (), "robots[0].sensors[0].max_range_m", ["-5.0"]),
}


@pytest.mark.parametrize("command", ["validate", "run"])
@pytest.mark.parametrize("case", sorted(BAD_FILES))
def test_bad_input_one_message_exit_2(tmp_path, command, case):
    (old, new), extra, field, fragments = BAD_FILES[case]
    text = GOOD if old is None else GOOD.replace(old, new)
    assert text != GOOD or old is None
    (tmp_path / "bad_map.yaml").write_text("image: x.pgm\nresolution: 0.05\norigin: [0, 0]\n")
    path = write(tmp_path, text)
    args = [command, path, *extra]
    if command == "run":
        args += ["--out", tmp_path / "out"]
    result = invoke(*args)
    assert_bad_input(result, str(path), field, *fragments)
    assert not (tmp_path / "out").exists()


def test_unknown_scenario_name():
    result = invoke("run", "dmeo")
    assert_bad_input(result, "unknown scenario 'dmeo'", "did you mean 'demo'")


def test_malformed_set_item(tmp_path):
    result = invoke("validate", write(tmp_path, GOOD), "--set", "robots.0.count")
    assert_bad_input(result, "--set", "KEY=VALUE")


def test_validate_reports_ok(tmp_path):
    result = invoke("validate", write(tmp_path, GOOD), "--set", "robots.0.count=3")
    assert result.exit_code == 0, result.output
    assert "ok:" in result.stdout and "3 robots" in result.stdout and "10 steps" in result.stdout


def test_list_shows_scenarios_controllers_maps():
    result = invoke("list")
    assert result.exit_code == 0, result.output
    for word in ("demo", "swarm", "depot", "wander-v1", "wander-batched-v1", "office_simple", "nav2/depot.yaml"):
        assert word in result.stdout


def test_out_dir_not_empty_needs_force(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    path = write(tmp_path, GOOD)
    result = invoke("run", path, "--out", out)
    assert_bad_input(result, str(out), "not empty", "--force")
    assert (out / "keep.txt").read_text() == "mine"
    result = invoke("run", path, "--out", out, "--force", "--quiet")
    assert result.exit_code == 0, result.output
    assert not (out / "keep.txt").exists() and (out / "metrics.json").is_file()
    assert result.stdout.strip() == str(out)


RUN_FILES = {"scenario.yaml", "metrics.json", "trajectories.npz", "events.json", "logs.json", "comm.json",
             "map.yaml", "robots.json", "trajectories.png"}


def test_run_demo_through_cli_runner(tmp_path):
    out = tmp_path / "demo"
    result = invoke("run", "demo", "--duration", "5", "--out", out, "--seed", "2")
    assert result.exit_code == 0, result.output
    assert RUN_FILES <= {p.name for p in out.iterdir()}
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["steps"] == 50
    assert metrics["collisions_wall"] == 0 and metrics["collisions_robot"] == 0
    assert "path_length_m_mean" in result.stdout and str(out) in result.stdout
    assert [p.name for p in tmp_path.iterdir()] == ["demo"]  # no staging folder left behind


def test_run_demo_as_subprocess(tmp_path):
    out = tmp_path / "demo"
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    proc = subprocess.run(
        [sys.executable, "-m", "teamnav", "run", "demo", "--duration", "5", "--out", str(out), "--quiet"],
        capture_output=True, text=True, env=env, timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == str(out)
    assert RUN_FILES <= {p.name for p in out.iterdir()}


def test_bad_input_as_subprocess_exit_2(tmp_path):
    path = write(tmp_path, GOOD.replace("duration_s: 1.0", "duration_s: .nan"))
    proc = subprocess.run([sys.executable, "-m", "teamnav", "validate", str(path)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and str(path) in proc.stderr and "duration_s" in proc.stderr
