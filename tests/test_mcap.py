"""MCAP export read back with the `mcap` reader: Foxglove schemas, channels, counts and values match the run."""

from __future__ import annotations

import math

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from typer.testing import CliRunner

import _replay_run
from teamnav.cli import app
from teamnav.sim.recorder import load
from teamnav.viz.mcap_export import export_mcap


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lab")
    run_dir = _replay_run.make_run(folder)
    stats = export_mcap(run_dir, folder / "lab.mcap")
    return run_dir, stats


def _summary(path):
    with open(path, "rb") as f:
        s = make_reader(f).get_summary()
    return {c.topic: (s.schemas[c.schema_id].name, s.schemas[c.schema_id].encoding, c.message_encoding,
                      s.statistics.channel_message_counts.get(c.id, 0)) for c in s.channels.values()}


def test_schemas_channels_and_counts_match_the_run(exported):
    run_dir, stats = exported
    rec = load(run_dir)
    T, N = rec.true_pose.shape[:2]
    topics = _summary(stats.path)
    assert topics["/map"][:3] == ("foxglove.Grid", "protobuf", "protobuf") and topics["/map"][3] == 1
    assert topics["/tf"] == ("foxglove.FrameTransforms", "protobuf", "protobuf", T)
    scan = rec.scans["g0_laser"]
    for i in range(N):
        assert topics[f"/robot_{i}/pose"] == ("foxglove.PoseInFrame", "protobuf", "protobuf", T)  # one per recorded step
        assert topics[f"/robot_{i}/believed_pose"][3] == T
        assert topics[f"/robot_{i}/scan/laser"] == ("foxglove.LaserScan", "protobuf", "protobuf", scan.step.shape[0])
    for name, lay in rec.layers.items():
        assert topics[f"/layers/{name}"] == ("foxglove.SceneUpdate", "protobuf", "protobuf", lay.step.shape[0])
    assert stats.messages == sum(v[3] for v in topics.values()) and stats.channels == len(topics)


def test_messages_decode_to_the_recorded_values(exported):
    run_dir, stats = exported
    rec = load(run_dir)
    N = rec.true_pose.shape[1]
    scan = rec.scans["g0_laser"]
    k_pose, k_scan = 0, 0
    with open(stats.path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _schema, channel, msg, dec in reader.iter_decoded_messages(topics=["/robot_1/pose", "/robot_1/scan/laser", "/tf"]):
            if channel.topic == "/robot_1/pose":
                x, y, th = rec.true_pose[k_pose, 1]
                assert msg.log_time == round(rec.t_s[k_pose] * 1e9) and dec.frame_id == "world"
                assert dec.pose.position.x == pytest.approx(x, abs=1e-5) and dec.pose.position.y == pytest.approx(y, abs=1e-5)
                assert 2 * math.atan2(dec.pose.orientation.z, dec.pose.orientation.w) == pytest.approx(th, abs=1e-5)
                k_pose += 1
            elif channel.topic == "/robot_1/scan/laser":
                assert dec.frame_id == "robot_1/base"
                assert dec.start_angle == pytest.approx(scan.angles_rad[0]) and dec.end_angle == pytest.approx(scan.angles_rad[-1])
                np.testing.assert_allclose(dec.ranges, scan.ranges[k_scan, 1], rtol=1e-6)
                k_scan += 1
            elif channel.topic == "/tf" and k_pose == 5:
                # world → robot_i/odom → robot_i/base composes to the true pose
                tf = {(t.parent_frame_id, t.child_frame_id): t for t in dec.transforms}
                assert len(tf) == 2 * N
                a, b = tf[("world", "robot_1/odom")], tf[("robot_1/odom", "robot_1/base")]
                ya = 2 * math.atan2(a.rotation.z, a.rotation.w)
                px = a.translation.x + math.cos(ya) * b.translation.x - math.sin(ya) * b.translation.y
                py = a.translation.y + math.sin(ya) * b.translation.x + math.cos(ya) * b.translation.y
                assert (px, py) == pytest.approx(tuple(rec.true_pose[5, 1, :2]), abs=1e-4)
    assert k_pose == rec.true_pose.shape[0] and k_scan == scan.step.shape[0]


def test_cli_export_and_bad_input(exported, tmp_path):
    run_dir, _ = exported
    runner = CliRunner()
    out = tmp_path / "o.mcap"
    res = runner.invoke(app, ["export", str(run_dir), "--mcap", str(out)])
    assert res.exit_code == 0, res.output
    assert out.stat().st_size > 1000
    res = runner.invoke(app, ["export", str(run_dir), "--mcap", str(out)])
    assert res.exit_code == 2 and "exists" in res.output
    res = runner.invoke(app, ["export", str(tmp_path), "--mcap", str(tmp_path / "p.mcap")])
    assert res.exit_code == 2 and "not a run folder" in res.output
