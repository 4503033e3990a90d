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


def test_list_names_one_per_line_and_json_for_scripts():
    from teamnav.experiments import registry

    result = invoke("list", "--names")
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines() == list(registry.names())
    result = invoke("list", "--json")
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert set(doc) == {"scenarios", "controllers", "builtin_maps", "packaged_maps"}
    assert [s["name"] for s in doc["scenarios"]] == list(registry.names())
    assert all(set(s) == {"name", "description"} and s["description"] for s in doc["scenarios"])
    assert "wander-v1" in doc["controllers"] and "office_simple" in doc["builtin_maps"]
    assert "nav2/depot.yaml" in doc["packaged_maps"]
    result = invoke("list", "--names", "--json")
    assert result.exit_code == 2 and "--names or --json" in result.stderr


def test_list_names_and_json_parse_in_a_real_pipe():
    names = subprocess.run(f'"{sys.executable}" -m teamnav list --names | sort', shell=True,
                           capture_output=True, text=True, timeout=120)
    assert names.returncode == 0, names.stderr
    lines = names.stdout.splitlines()
    assert "demo" in lines and all(ln and ln == ln.strip() and " " not in ln for ln in lines)
    doc = subprocess.run([sys.executable, "-m", "teamnav", "list", "--json"], capture_output=True, text=True, timeout=120)
    assert doc.returncode == 0, doc.stderr
    assert sorted(s["name"] for s in json.loads(doc.stdout)["scenarios"]) == lines


def _table_rows(stdout: str) -> list[list[str]]:
    """The body rows of the rich metrics table: [metric, value, unit]."""
    return [[c.strip() for c in ln.strip("│").split("│")] for ln in stdout.splitlines()
            if ln.startswith("│")]


@pytest.mark.parametrize("scenario, headline, hidden", [
    ("demo", "path_length_m_mean", "odom_heading_error_deg_mean"),
    ("collab-mcl-hallway", "loc_final_error_m", "loc_error_series"),
])
def test_run_prints_headline_metrics_with_units_and_where_the_rest_is(tmp_path, scenario, headline, hidden):
    out = tmp_path / "run"
    result = invoke("run", scenario, "--duration", "2", "--set", "robots.0.count=2", "--out", out)
    assert result.exit_code == 0, result.output
    rows = _table_rows(result.stdout)
    assert 0 < len(rows) <= 15
    assert all(len(r) == 3 for r in rows), rows
    assert not any(c in r[1] for r in rows for c in "[{"), "no series in the table"
    metrics = json.loads((out / "metrics.json").read_text())
    assert len(metrics) > len(rows)
    by_key = {r[0]: r for r in rows}
    assert headline in by_key and hidden not in result.stdout and hidden in metrics
    assert by_key[headline][2] == "m"
    assert f"{out / 'metrics.json'}" in result.stdout


def test_headline_rows_fall_back_to_scalars_with_units_from_the_key():
    from teamnav.cli import headline_rows, unit_from_key

    values = {f"x{i}_s": i for i in range(20)}
    values.update({"a_series": "[1, 2]", "b": [1, 2], "c": {"k": 1}, "speed_mps": 0.5, "length_m_max": 2.0})
    rows = headline_rows(["not-a-declared-metric"], values)
    assert len(rows) == 15 and rows[0] == ("x0_s", 0, "s")
    assert not {"a_series", "b", "c"} & {k for k, _, _ in rows}
    assert [unit_from_key(k) for k in ("speed_mps", "length_m_max", "lifetime_min_total", "count", "trips_total")] == \
        ["m/s", "m", "min", "", ""]
    # declared metrics give their declared keys, paper sets first, and no series
    rows = headline_rows(["steps", "localization"], {"sim_time_s": 2.0, "steps": 20, "loc_final_error_m": 1.5,
                                                     "loc_error_series": "{}", "loc_censored": 0})
    assert rows == [("loc_censored", 0, "robots"), ("loc_final_error_m", 1.5, "m"), ("sim_time_s", 2.0, "s")]


def test_quick_report_says_its_claims_are_indicative_on_the_same_line(tmp_path):
    import teamnav.experiments.report as report
    from teamnav.experiments.report.cli import section_line
    from teamnav.experiments.report.model import Comparison, SectionSpec

    claims = [Comparison("a", "1", "1", True), Comparison("b", "2", "3", False)]
    report.register_section(SectionSpec(key="fake-claims", title="Fake", paper="fake.txt", build=lambda ctx: claims))
    try:
        quick = invoke("report", "fake-claims", "--quick", "--out", tmp_path / "r")
        full = invoke("report", "fake-claims", "--out", tmp_path / "r")
    finally:
        report.unregister_section("fake-claims")
    assert quick.exit_code == 0 and full.exit_code == 0, quick.output + full.output
    line = next(ln for ln in quick.stdout.splitlines() if "fake-claims" in ln)
    assert "1/2 claims hold (quick mode: indicative only, small sample; run without --quick for the verdicts)" in line
    assert "1/2 claims hold" in full.stdout and "quick mode" not in full.stdout
    from types import SimpleNamespace

    s = SimpleNamespace(key="k", status="error", wall_s=1.0, comparisons=claims, error="RuntimeError: x")
    assert section_line(s, quick=True).endswith("(quick mode: indicative only, small sample; run without --quick "
                                                 "for the verdicts)  (RuntimeError: x)")
    unjudged = SimpleNamespace(key="k", status="ok", wall_s=1.0, comparisons=[*claims, Comparison("c", "4", "-", None)],
                               error="")
    assert "1/3 claims hold, 1 not judged (quick mode" in section_line(unjudged, quick=True)


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
