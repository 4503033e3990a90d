"""The runner (complete run folders or none, reproducibility) and the metrics on known data."""

from __future__ import annotations

import json
import math
import textwrap
from pathlib import Path

import numpy as np
import pytest

from teamnav.experiments import metrics as M
from teamnav.experiments.runner import OutputDirError, run
from teamnav.experiments.spec import load_scenario
from teamnav.world import MapBuilder

SCENARIO = """\
name: small
map: {builtin: office_simple}
duration_s: 2.0
seed: 5
robots:
  - count: 3
    controller: wander-v1
    sensors:
      - {kind: laser, n_beams: 30, max_range_m: 5.0}
    odometry: {alpha: [0.05, 0.02, 0.05, 0.02], heading_drift_deg_per_min: 2.0}
    start: {region: [1.0, 29.0, 6.0, 8.0]}
"""

RUN_FILES = {"scenario.yaml", "metrics.json", "trajectories.npz", "events.json", "logs.json", "comm.json",
             "map.yaml", "robots.json", "trajectories.png"}


@pytest.fixture
def scenario_file(tmp_path) -> Path:
    p = tmp_path / "small.yaml"
    p.write_text(textwrap.dedent(SCENARIO))
    return p


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


# ---------------------------------------------------------------------------- runner
def test_run_folder_complete_and_reproducible(tmp_path, scenario_file):
    out = tmp_path / "runs" / "a"
    result = run(load_scenario(scenario_file), out_dir=out, progress=False)
    assert result.run_dir == out
    assert RUN_FILES <= {p.name for p in out.iterdir()}
    assert leftovers(out.parent) == []
    stored = json.loads((out / "metrics.json").read_text())
    assert stored == {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in result.metrics.items()}
    assert result.metrics["steps"] == 20
    assert result.metrics["path_length_m_mean"] > 0.1
    assert result.metrics["odom_error_m_max"] > 0.0  # the odometry drifts
    with np.load(out / "trajectories.npz") as z:
        assert z["true_pose"].shape[1:] == (3, 3)

    again = run(load_scenario(out / "scenario.yaml"), out_dir=tmp_path / "runs" / "b", progress=False)
    assert M.deterministic(again.metrics) == M.deterministic(result.metrics)
    assert np.array_equal(again.data.true_pose, result.data.true_pose)
    assert (tmp_path / "runs" / "b" / "scenario.yaml").read_text() == (out / "scenario.yaml").read_text()


def test_failing_metric_leaves_no_run_folder(tmp_path, scenario_file, monkeypatch):
    def boom(data):
        raise RuntimeError("metric exploded")

    monkeypatch.setitem(M._REGISTRY, "path_length", M._Metric(boom, "boom", True))
    out = tmp_path / "runs" / "x"
    with pytest.raises(RuntimeError, match="metric exploded"):
        run(load_scenario(scenario_file), out_dir=out, progress=False)
    assert not out.exists()
    assert list((tmp_path / "runs").iterdir()) == []


def test_failing_plot_leaves_previous_folder_untouched(tmp_path, scenario_file, monkeypatch):
    import teamnav.viz.plots as plots

    out = tmp_path / "x"
    out.mkdir()
    (out / "old.txt").write_text("old")

    def boom(*a, **k):
        raise RuntimeError("plot exploded")

    monkeypatch.setattr(plots, "plot_run", boom)
    with pytest.raises(RuntimeError, match="plot exploded"):
        run(load_scenario(scenario_file), out_dir=out, progress=False, force=True)
    assert [p.name for p in out.iterdir()] == ["old.txt"]
    assert leftovers(tmp_path) == []


def test_non_empty_out_dir_refused_before_running(tmp_path, scenario_file):
    out = tmp_path / "x"
    out.mkdir()
    (out / "f").write_text("")
    calls = []
    with pytest.raises(OutputDirError, match="not empty"):
        run(load_scenario(scenario_file), out_dir=out, progress=calls.append)
    assert calls == []


def test_empty_out_dir_is_used(tmp_path, scenario_file):
    out = tmp_path / "empty"
    out.mkdir()
    run(load_scenario(scenario_file, duration_s=0.5), out_dir=out, progress=False)
    assert (out / "metrics.json").is_file()


def test_no_out_dir_writes_nothing_and_progress_callable(tmp_path, scenario_file, monkeypatch):
    monkeypatch.chdir(tmp_path)
    before = sorted(tmp_path.iterdir())
    seen: list[int] = []
    result = run(load_scenario(scenario_file), progress=seen.append)
    assert result.run_dir is None and sorted(tmp_path.iterdir()) == before
    assert seen and seen == sorted(seen) and max(seen) <= 20 and max(seen) >= 19


def test_gif(tmp_path, scenario_file):
    from PIL import Image

    out = tmp_path / "g"
    run(load_scenario(scenario_file, duration_s=1.0), out_dir=out, progress=False, gif=True)
    with Image.open(out / "run.gif") as im:
        assert im.format == "GIF" and im.n_frames > 5


def test_metrics_subset_only(tmp_path, scenario_file):
    result = run(load_scenario(scenario_file, overrides={"metrics": ["steps", "collisions"]}), progress=False)
    assert set(result.metrics) == {"steps", "sim_time_s", "collisions_wall", "collisions_robot"}


# ---------------------------------------------------------------------------- metrics on known data
def _data(true_pose, odom_pose=None, *, radius=0.2, grid=None, **kw) -> M.RunData:
    true_pose = np.asarray(true_pose, float)
    T, N, _ = true_pose.shape
    return M.RunData(
        t_s=np.arange(T) * 1.0,
        true_pose=true_pose,
        odom_pose=true_pose.copy() if odom_pose is None else np.asarray(odom_pose, float),
        stalled=np.zeros((T, N), bool),
        radius_m=np.full(N, radius),
        grid=grid if grid is not None else MapBuilder(10.0, 10.0, 0.05).border(0.2).build("box"),
        n_steps=T - 1,
        dt_s=1.0,
        wall_s=0.5,
        **kw,
    )


def test_path_length_speed_and_steps():
    square = [[2, 2, 0], [4, 2, 0], [4, 4, 0], [2, 4, 0], [2, 2, 0]]
    still = [[6, 6, 0]] * 5
    d = _data(np.stack([square, still], axis=1))
    v = M.compute(["path_length", "mean_speed", "steps", "throughput"], d)
    assert v["path_length_m_max"] == pytest.approx(8.0) and v["path_length_m_min"] == 0.0
    assert v["path_length_m_mean"] == pytest.approx(4.0) and v["path_length_m_total"] == pytest.approx(8.0)
    assert v["mean_speed_mps"] == pytest.approx(4.0 / 4.0)
    assert v["steps"] == 4 and v["robot_steps_per_s"] == pytest.approx(4 * 2 / 0.5)


def test_odometry_error_is_pure_drift_in_any_odometry_frame():
    rng = np.random.default_rng(0)
    truth = np.cumsum(rng.normal(0, 0.3, (50, 2, 3)), axis=0) + [5, 5, 0]
    # odometry in each robot's own start frame: exact, then 1 m off in its own x at the end
    c, s = np.cos(-truth[0, :, 2]), np.sin(-truth[0, :, 2])
    dx, dy = truth[..., 0] - truth[0, :, 0], truth[..., 1] - truth[0, :, 1]
    odom = np.stack([c * dx - s * dy, s * dx + c * dy, truth[..., 2] - truth[0, :, 2]], axis=-1)
    assert M.odometry_error(_data(truth, odom))["odom_error_m_max"] == pytest.approx(0.0, abs=1e-9)
    drifted = odom.copy()
    drifted[-1, 0, 0] += 1.0
    v = M.odometry_error(_data(truth, drifted))
    assert v["odom_error_m_max"] == pytest.approx(1.0) and v["odom_error_m_mean"] == pytest.approx(0.5)


def test_collisions_detect_overlaps_and_nothing_else():
    apart = [[[3, 3, 0], [6, 6, 0]]] * 3
    assert M.collisions(_data(apart)) == {"collisions_wall": 0, "collisions_robot": 0}
    touching = [[[3, 3, 0], [3.3, 3, 0]]] * 2  # centres 0.3 m apart, radii 0.2 m
    assert M.collisions(_data(touching))["collisions_robot"] == 2
    in_wall = [[[0.1, 5, 0], [6, 6, 0]]]
    assert M.collisions(_data(in_wall))["collisions_wall"] == 1


def test_events_messages_and_stalls():
    d = _data([[[3, 3, 0]]] * 4, events=["took", "given", "took"], messages_sent=5, bytes_sent=120, messages_delivered=9)
    stalled = d.stalled.copy()
    stalled[1:3] = True
    d = M.RunData(**{**d.__dict__, "stalled": stalled})
    v = M.compute(["events", "messages", "stall_fraction"], d)
    assert v["events.took"] == 2 and v["events.given"] == 1 and v["events_total"] == 3
    assert (v["messages_sent"], v["bytes_sent"], v["messages_delivered"]) == (5, 120, 9)
    assert v["stall_fraction"] == pytest.approx(0.5)


def test_deterministic_drops_timing_only():
    v = {"steps": 3, "wall_time_s": 1.2, "robot_steps_per_s": 10.0, "path_length_m_mean": 1.0}
    assert M.deterministic(v) == {"steps": 3, "path_length_m_mean": 1.0}


def test_metric_registry_refuses_duplicates_and_unknown():
    with pytest.raises(ValueError, match="already registered"):
        M.register("steps", M.steps, "again")
    with pytest.raises(ValueError, match="did you mean 'steps'"):
        M.compute(["stpes"], _data([[[3, 3, 0]]] * 2))


def test_run_folder_map_keeps_the_source_maps_thresholds_and_cells(tmp_path):
    """The run folder's map.yaml is written with the thresholds its map file was read with
    (depot: free_thresh 0.25) and loads back to the same cells (commit cd4f30d, 2026-11-27)."""
    from teamnav.experiments.runner import run as run_scenario
    from teamnav.experiments.spec import PACKAGE_MAP_DIR, build_grid, load_scenario
    from teamnav.world.mapio import load_map, read_map_yaml

    scn = load_scenario("demo", overrides=["map={package: nav2/depot.yaml}", "robots.0.start.region=null",
                                           "robots.0.count=2"], duration_s=0.5)
    result = run_scenario(scn, out_dir=tmp_path / "run", progress=False)
    written = read_map_yaml(result.run_dir / "map.yaml")
    source = read_map_yaml(PACKAGE_MAP_DIR / "nav2" / "depot.yaml")
    assert (written.occupied_thresh, written.free_thresh) == (source.occupied_thresh, source.free_thresh) == (0.65, 0.25)
    np.testing.assert_array_equal(load_map(result.run_dir / "map.yaml").cells, build_grid(scn).cells)
