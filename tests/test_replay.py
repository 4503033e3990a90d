"""The HTML replay's data (decoded in Python), the recorder's layers and scans, and `teamnav replay` errors."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

import _replay_run
from teamnav.cli import app
from teamnav.sim.recorder import Recorder, load
from teamnav.viz.plots import odom_in_world
from teamnav.viz.replay import _decode, build_replay, odom_anchor


@pytest.fixture(scope="module")
def lab_run(tmp_path_factory):
    return _replay_run.make_run(tmp_path_factory.mktemp("lab"))


def _poses(meta, arrays, key):
    q = meta["quant"]
    out = []
    for c in ("x", "y"):
        d = np.cumsum(arrays[f"{key}.{c}"].astype(np.int64).reshape(meta["n_frames"], meta["n_robots"]), axis=0)
        d = (d + 32768) % 65536 - 32768  # the page's Int16Array wraps the same way
        out.append((q["x0"] if c == "x" else q["y0"]) + (d + q["bias"]) * q["scale"])
    return np.stack(out, axis=-1)


def test_recorder_keeps_scans_detections_messages_and_controller_layers(lab_run):
    rec = load(lab_run)
    T, N = rec.true_pose.shape[:2]
    scan = rec.scans["g0_laser"]
    assert scan.ranges.shape == (T, N, 24) and np.array_equal(scan.step, rec.step)
    assert 0 < scan.ranges.min() and scan.ranges.max() <= 5.0
    assert set(rec.layers) == {"crumbs", "goal", "state", "detections", "messages"}
    # every robot broadcasts every step: from step 1 each robot receives N - 1 messages per recorded step
    msgs = rec.layers["messages"]
    assert np.all(np.diff(msgs.offset) == N - 1) and msgs.step.min() == 1
    d = rec.layers["detections"]
    seg = d.rows(int(np.flatnonzero(np.diff(d.offset) > 0)[0]))
    i = d.robot[np.flatnonzero(np.diff(d.offset) > 0)[0]]
    s = int(np.searchsorted(rec.step, d.step[np.flatnonzero(np.diff(d.offset) > 0)[0]]))
    np.testing.assert_allclose(seg[:, :2], np.repeat(rec.true_pose[s, i, None, :2], len(seg), 0), atol=1e-5)
    st = rec.layers["state"]
    assert st.kind == "state" and st.hold and set(st.labels) == {"searching", "carrying"}
    assert rec.layers["crumbs"].frame == "odom" and rec.layers["goal"].kind == "markers"
    assert all("layers" not in e["values"] for e in rec.logs) and rec.logs[-1]["values"]["n"] > 0


def test_recorder_refuses_bad_layers():
    rec = Recorder(2)
    with pytest.raises(ValueError, match="not declared"):
        rec.add_layer_sample("crumbs", 0, 0, [[0.0, 0.0]])
    rec.declare_layer("crumbs", "points", frame="odom")
    with pytest.raises(ValueError, match="shape"):
        rec.add_layer_sample("crumbs", 0, 0, [[0.0, 0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="robot"):
        rec.add_layer_sample("crumbs", 0, 5, [[0.0, 0.0]])
    with pytest.raises(ValueError, match="kind"):
        rec.declare_layer("x", "blobs")
    with pytest.raises(ValueError, match="points layer"):
        rec.declare_layer("crumbs", "markers", frame="odom")
    with pytest.raises(ValueError, match="non-finite"):
        rec.add_layer_sample("crumbs", 0, 0, [[np.nan, 0.0]])


def test_held_layer_round_trip_with_empty_sample(tmp_path):
    rec = Recorder(2)
    rec.record(0, 0.0, np.zeros((2, 3)), np.zeros((2, 3)), np.zeros(2, bool),
               logs={0: {"layers": {"crumbs": np.array([[1.0, 2.0], [3.0, 4.0]])}}, 1: {"v": 1}})
    rec.record(1, 0.1, np.zeros((2, 3)), np.zeros((2, 3)), np.zeros(2, bool), logs={0: {"layers": {"crumbs": np.zeros((0, 2))}}})
    rec.save(tmp_path)
    lay = load(tmp_path).layers["crumbs"]
    assert lay.offset.tolist() == [0, 2, 2] and lay.rows(0).tolist() == [[1.0, 2.0], [3.0, 4.0]] and lay.rows(1).shape == (0, 2)
    assert json.loads((tmp_path / "logs.json").read_text())["logs"] == [{"step": 0, "t_s": 0.0, "robot": 1, "values": {"v": 1}}]


def test_replay_data_matches_the_run_within_quantisation(lab_run, tmp_path):
    stats = build_replay(lab_run, tmp_path / "r.html")
    rec = load(lab_run)
    page = stats.path.read_text(encoding="utf-8")
    assert "http://" not in page and "https://" not in page and "<script src" not in page  # opens from disk, offline
    meta, arrays = _decode(page)
    assert stats.n_frames == rec.true_pose.shape[0] == meta["n_frames"]
    tol = 2 * meta["quant"]["scale"]
    np.testing.assert_allclose(_poses(meta, arrays, "true"), rec.true_pose[..., :2], atol=tol)
    believed = odom_in_world(rec.true_pose.astype(float), rec.odom_pose.astype(float))
    np.testing.assert_allclose(_poses(meta, arrays, "belief"), believed[..., :2], atol=tol)
    assert {m["name"] for m in meta["layers"]} == set(rec.layers)
    assert set(stats.layers) >= {"map", "true", "belief", "scans", "events", "crumbs", "messages"}


def test_decimation_keeps_last_sample_and_caps_frames(lab_run, tmp_path):
    n = load(lab_run).true_pose.shape[0]
    s = build_replay(lab_run, tmp_path / "a.html", every=7)
    assert s.n_frames == len(range(0, n, 7)) + (0 if (n - 1) % 7 == 0 else 1)
    s = build_replay(lab_run, tmp_path / "b.html", max_frames=10)
    meta, arrays = _decode(s.path.read_text(encoding="utf-8"))
    assert s.n_frames <= 11 and arrays["fstep"][-1] == load(lab_run).step[-1]
    with pytest.raises(ValueError, match="every"):
        build_replay(lab_run, tmp_path / "c.html", every=0)


def test_odom_anchor_agrees_with_the_figures():
    rng = np.random.default_rng(0)
    true, odom = rng.normal(size=(5, 4, 3)), rng.normal(size=(5, 4, 3))
    a = odom_anchor(true[0], odom[0])
    c, s = np.cos(a[:, 2]), np.sin(a[:, 2])
    x = c * odom[..., 0] - s * odom[..., 1] + a[:, 0]
    y = s * odom[..., 0] + c * odom[..., 1] + a[:, 1]
    np.testing.assert_allclose(np.stack([x, y], -1), odom_in_world(true, odom)[..., :2], atol=1e-12)


def test_cli_replay_writes_the_file_and_refuses_bad_folders(lab_run, tmp_path):
    runner = CliRunner()
    out = tmp_path / "x.html"
    res = runner.invoke(app, ["replay", str(lab_run), "--out", str(out), "--every", "2"])
    assert res.exit_code == 0, res.output
    assert out.is_file() and out.stat().st_size > 1000
    res = runner.invoke(app, ["replay", str(tmp_path / "missing")])
    assert res.exit_code == 2 and "does not exist" in res.output
    (tmp_path / "empty").mkdir()
    res = runner.invoke(app, ["replay", str(tmp_path / "empty")])
    assert res.exit_code == 2 and "not a run folder" in res.output


def test_cli_run_html_writes_the_replay_next_to_the_run(tmp_path):
    _replay_run.register()
    yml = tmp_path / "lab.yaml"
    yml.write_text(_replay_run.SCENARIO, encoding="utf-8")
    res = CliRunner().invoke(app, ["run", str(yml), "--duration", "1", "--out", str(tmp_path / "r"), "--html", "--quiet"])
    assert res.exit_code == 0, res.output
    meta, arrays = _decode((tmp_path / "r" / "replay.html").read_text(encoding="utf-8"))
    assert meta["n_frames"] == 11 and meta["n_robots"] == 3 and meta["scans"][0]["beams"] == 24


def test_replay_labels_fault_records_by_their_kind(tmp_path):
    """Faults are recorded with event None and their kind under "fault": the replay's event
    list shows "fault: died", not "None"."""
    res = CliRunner().invoke(app, ["run", "trail-team", "--duration", "8", "--quiet", "--out", str(tmp_path / "run"),
                                   "--set", "faults={deaths: [{robot: 1, t_s: 2}], blackouts: [{t0_s: 1, t1_s: 4}]}"])
    assert res.exit_code == 0, res.output
    meta, _ = _decode(build_replay(tmp_path / "run", tmp_path / "r.html").path.read_text(encoding="utf-8"))
    labels = {e["event"] for e in meta["events"]}
    assert {"fault: died", "fault: blackout_start", "fault: blackout_end"} <= labels and "None" not in labels
