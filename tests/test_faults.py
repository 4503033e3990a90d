"""Faults injected on the truth side (teamnav.sim.faults): each fault does what it says and
only in its window, brains learn of it only through their observations, a run without faults
is unchanged, bad fault specs are refused naming the field, and a fault scenario runs end to end."""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict, ValidationError
from typer.testing import CliRunner

from teamnav.control import registry
from teamnav.control.types import Action, Message, Observation
from teamnav.sim.config import (
    DetectorConfig,
    FaultsConfig,
    LaserConfig,
    OdometryConfig,
    RadioConfig,
    RobotGroupConfig,
    SimConfig,
    StartConfig,
)
from teamnav.sim.engine import Simulation
from teamnav.world.grid import WALL, OccupancyGrid


# ------------------------------------------------------------------------ a spy brain
class SpyParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    v_mps: float = 0.0
    omega_radps: float = 0.0
    send: bool = False


class Spy:
    """Drives a constant command, keeps every observation, sends its step number each step."""

    Params = SpyParams

    def __init__(self, params, rng, info):
        self.p = params
        self.info = info
        self.seen: list[Observation] = []

    def step(self, obs):
        self.seen.append(obs)
        out = [Message(self.info.robot_id, obs.time_s, {"step": obs.step})] if self.p.send else []
        return Action(self.p.v_mps, self.p.omega_radps), out

    def log(self):
        return {"n_seen": len(self.seen)}


@pytest.fixture(autouse=True)
def _spy_registered(monkeypatch):
    monkeypatch.setitem(registry._REGISTRY, "spy-fault-v1", f"{__name__}:Spy")


def _room(w_m=10.0, h_m=6.0, res=0.05):
    cells = np.zeros((int(round(h_m / res)), int(round(w_m / res))), np.uint8)
    cells[:2, :] = cells[-2:, :] = cells[:, :2] = cells[:, -2:] = WALL
    return OccupancyGrid(cells, res, name="room")


def _group(name, poses, **kw):
    kw.setdefault("sensors", ())
    return RobotGroupConfig(name=name, count=len(poses), controller="spy-fault-v1",
                            start=StartConfig(poses=tuple(poses)), **kw)


def _config(groups, faults=None, **kw):
    return SimConfig(robots=tuple(groups), faults=None if faults is None else FaultsConfig.model_validate(faults),
                     **kw)


def _brains(sim):
    return [b for g in sim.brains if isinstance(g, list) for b in g]


# ------------------------------------------------------------------------ no faults: unchanged
def _mixed(faults=None):
    return _config([
        _group("a", [(2.0, 2.0, 0.0), (2.0, 4.0, 0.0)], params={"v_mps": 0.3, "omega_radps": 0.2, "send": True},
               sensors=(LaserConfig(n_beams=30, noise_std_m=0.02, p_max=0.05),),
               detector=DetectorConfig(max_range_m=6.0, range_noise_std_m=0.1, p_false_positive=0.2),
               odometry=OdometryConfig(alpha=(0.05, 0.01, 0.05, 0.01))),
        RobotGroupConfig(name="b", count=3, controller="wander-batched-v1", radius_m=0.1,
                         sensors=(LaserConfig(n_beams=20, noise_std_m=0.01),), start=StartConfig(region=(5, 9, 1, 5))),
    ], faults, radio=RadioConfig(p_loss=0.3), seed=7)


def _trace(cfg, n=60):
    sim = Simulation(_room(), cfg)
    poses = []
    for _ in range(n):
        sim.step()
        poses.append(sim.state.poses())
    obs = [(o.step, o.odom_pose.tobytes(), [s.ranges_m.tobytes() for s in o.scans.values()], o.detections,
            [m.body for m in o.inbox]) for b in _brains(sim) if hasattr(b, "seen") for o in b.seen]
    return np.array(poses), sim.odometry.pose.copy(), obs, sim


def test_no_faults_and_an_empty_faults_section_change_nothing_bit_for_bit():
    p0, o0, obs0, sim0 = _trace(_mixed())
    p1, o1, obs1, sim1 = _trace(_mixed({}))
    np.testing.assert_array_equal(p0, p1)
    np.testing.assert_array_equal(o0, o1)
    assert obs0 == obs1
    assert sim0.faults is None and sim1.faults is None
    assert "faults" not in _mixed({}).model_dump() and "faults" not in _mixed().model_dump(mode="json")
    assert "faults" not in sim1.radio.counts()


def test_a_fault_leaves_everything_before_it_unchanged_and_runs_repeat_bit_for_bit():
    faults = {"kidnappings": [{"robot": 0, "t_s": 3.0}], "false_positives": [{"t0_s": 2.0, "t1_s": 4.0, "rate_hz": 5}],
              "blackouts": [{"t0_s": 2.5, "t1_s": 3.5}]}
    p0, _, _, _ = _trace(_mixed())
    p1, o1, obs1, _ = _trace(_mixed(faults))
    p2, o2, obs2, _ = _trace(_mixed(faults))
    np.testing.assert_array_equal(p0[:19], p1[:19])  # steps 1..19: before the first fault (t = 2 s)
    assert not np.array_equal(p0, p1)
    np.testing.assert_array_equal(p1, p2)
    np.testing.assert_array_equal(o1, o2)
    assert obs1 == obs2


# ------------------------------------------------------------------------ death
def test_a_dead_robot_stops_stays_an_obstacle_and_falls_silent():
    cfg = _config([
        _group("victim", [(3.0, 3.0, 0.0)], params={"v_mps": 0.4, "send": True}),
        # looks at the victim along y = 3 with a narrow laser, hears it
        _group("watcher", [(8.0, 3.0, 180.0)], sensors=(LaserConfig(n_beams=1, fov_deg=1.0, max_range_m=8.0,
                                                                    noise_std_m=0.0),)),
        # drives into where the victim stops
        _group("rammer", [(3.4, 1.0, 90.0)], params={"v_mps": 0.4}),
    ], {"deaths": [{"robot": {"group": "victim", "index": 0}, "t_s": 1.0}]})
    sim = Simulation(_room(), cfg)
    sim.run(60)
    victim, watcher, rammer = _brains(sim)
    assert [o.step for o in victim.seen] == list(range(10))  # not stepped from step 10 on
    np.testing.assert_allclose(sim.state.x_m[0], 3.0 + 0.4 * 1.0, atol=1e-9)  # moved until t = 1 s, then stopped
    ranges = [float(o.scans["laser"].ranges_m[0]) for o in watcher.seen]
    assert all(abs(r - (8.0 - 3.4 - 0.2)) < 1e-6 for r in ranges[12:])  # the watcher's laser still meets its body
    assert rammer.seen[-1].stalled  # the rammer is blocked by it
    assert 2.6 - 0.04 - 1e-9 <= sim.state.y_m[2] <= 2.6 + 1e-9  # stopped within a step of its body
    heard = [m.body["step"] for o in watcher.seen for m in o.inbox]
    assert heard == list(range(10))  # sent at steps 0..9 (alive), delivered one step later; nothing after
    died = [e for e in sim.recorder.events if e.get("fault") == "died"]
    assert died == [{"step": 10, "t_s": 1.0, "robot": 0, "place": None, "event": None, "fault": "died"}]


def test_death_in_a_batched_group_zeroes_its_commands():
    cfg = _config([RobotGroupConfig(count=3, controller="wander-batched-v1", sensors=(LaserConfig(n_beams=20),),
                                    start=StartConfig(region=(1, 9, 1, 5)))],
                  {"deaths": [{"robot": 1, "t_s": 0.5}]}, seed=2)
    sim = Simulation(_room(), cfg)
    sim.run(5)
    frozen = sim.state.poses()[1].copy()
    sim.run(30)
    np.testing.assert_array_equal(sim.state.poses()[1], frozen)
    assert not np.array_equal(sim.state.poses()[[0, 2]], sim.state.poses()[[0, 2]] * 0)


# ------------------------------------------------------------------------ radio
def _talkers(faults):
    return _config([_group("t", [(2.0, 2.0, 0.0), (4.0, 2.0, 0.0), (6.0, 2.0, 0.0)], params={"send": True})], faults)


def _inbox_steps(brain, sender):
    return [o.step for o in brain.seen for m in o.inbox if m.sender == sender]


def test_a_blackout_delivers_nothing_in_its_window_and_resumes_after():
    sim = Simulation(_room(), _talkers({"blackouts": [{"t0_s": 1.0, "t1_s": 2.0}]}))
    sim.run(40)
    for b in _brains(sim):
        got = {o.step for o in b.seen if o.inbox}
        # due at steps 10..20 (in the window): dropped; sent at 10..20: not sent, so step 21 gets nothing
        assert got == set(range(1, 41)) - set(range(10, 22))
    counts = sim.radio.counts()
    assert counts["faults"] == {"messages_not_sent": 3 * 11, "deliveries_dropped": 3 * 2}
    kinds = [(e["step"], e["fault"]) for e in sim.recorder.events]
    assert kinds == [(10, "blackout_start"), (21, "blackout_end")]


def test_a_radio_dropout_mutes_one_robot_both_ways_until_it_is_back():
    sim = Simulation(_room(), _talkers({"radio_dropouts": [{"robot": 1, "t_s": 1.0, "until_s": 2.0}]}))
    sim.run(40)
    a, b, c = _brains(sim)
    # b hears nothing due in 10..20 nor sent to it while it was off (step 20, due at 21)
    assert set(_inbox_steps(b, 0)) == set(range(1, 41)) - set(range(10, 22))
    assert set(_inbox_steps(a, 1)) == set(range(1, 41)) - set(range(11, 22))  # b's messages of 10..20 are not sent
    assert set(_inbox_steps(c, 0)) == set(range(1, 41))  # the others talk on


# ------------------------------------------------------------------------ sensor dropouts
def _seer(faults, reading="no_return"):
    return _config([_group("s", [(2.0, 3.0, 0.0), (5.0, 3.0, 180.0)],
                           sensors=(LaserConfig(n_beams=9, max_range_m=6.0, noise_std_m=0.0),),
                           detector=DetectorConfig(max_range_m=5.0, fov_deg=90.0))], faults)


@pytest.mark.parametrize("sensor", [0, "laser"])
def test_a_laser_dropout_reads_no_return_in_its_window_only(sensor):
    sim = Simulation(_room(), _seer({"sensor_dropouts": [{"robot": 0, "sensor": sensor, "t0_s": 1.0, "t1_s": 2.0}]}))
    sim.run(30)
    a, b = _brains(sim)
    for o in a.seen:
        r = o.scans["laser"].ranges_m
        assert np.all(r == 6.0) == (10 <= o.step <= 20), o.step
    assert not any(np.all(o.scans["laser"].ranges_m == 6.0) for o in b.seen)  # the other robot's laser works
    assert len(a.seen[15].detections) == 1  # the detector is another sensor: still on
    assert sim.faults.stats["scans_withheld"] == 11


def test_a_no_scan_dropout_publishes_no_scan_in_its_window_only():
    sim = Simulation(_room(), _seer({"sensor_dropouts": [{"robot": 0, "sensor": "laser", "t0_s": 1.0, "t1_s": 2.0,
                                                          "reading": "no_scan"}]}))
    sim.run(30)
    a, b = _brains(sim)
    assert [o.step for o in a.seen if "laser" not in o.scans] == list(range(10, 21))
    assert all("laser" in o.scans for o in b.seen)


def test_a_detector_dropout_detects_nothing_in_its_window_only():
    sim = Simulation(_room(), _seer({"sensor_dropouts": [{"robot": 1, "sensor": "detector", "t0_s": 1.0, "t1_s": 2.0}]}))
    sim.run(30)
    a, b = _brains(sim)
    assert [o.step for o in b.seen if not o.detections] == list(range(10, 21))
    assert all(len(o.detections) == 1 for o in a.seen)
    ev = [(e["step"], e["fault"], e["sensor"]) for e in sim.recorder.events]
    assert ev == [(10, "sensor_off", "detector"), (21, "sensor_on", "detector")]


# ------------------------------------------------------------------------ kidnapping
def test_kidnapping_moves_the_truth_but_not_the_odometry():
    base = [_group("k", [(2.0, 2.0, 0.0), (8.0, 4.0, 90.0)], params={"v_mps": 0.3},
                   sensors=(LaserConfig(n_beams=9, max_range_m=6.0, noise_std_m=0.0),))]
    ref = Simulation(_room(), _config(base))
    sim = Simulation(_room(), _config(base, {"kidnappings": [{"robot": 0, "t_s": 1.0, "pose": [5.0, 3.0, 90.0]},
                                                             {"robot": 1, "t_s": 1.5, "region": [1, 9, 1, 5]}]}))
    for _ in range(10):
        ref.step()
        sim.step()
    np.testing.assert_allclose(sim.state.poses()[0], [5.0, 3.0, math.pi / 2], atol=1e-12)  # moved at step 10
    np.testing.assert_array_equal(sim.odometry.pose, ref.odometry.pose)  # odometry never felt it
    np.testing.assert_array_equal(sim.odometry.delta, ref.odometry.delta)
    sim.step()
    ref.step()
    np.testing.assert_allclose(sim.state.poses()[0], [5.0, 3.03, math.pi / 2], atol=1e-9)  # drives on from there
    np.testing.assert_allclose(sim.odometry.pose[0], ref.odometry.pose[0], atol=1e-12)
    # the laser senses from the new pose in the step of the jump
    assert not np.array_equal(_brains(sim)[0].seen[10].scans["laser"].ranges_m,
                              _brains(ref)[0].seen[10].scans["laser"].ranges_m)
    sim.run(10)
    kid = [e for e in sim.recorder.events if e["fault"] == "kidnapped"]
    assert [(e["step"], e["robot"]) for e in kid] == [(10, 0), (15, 1)]
    x, y, _ = kid[1]["to"]
    assert 1 <= x <= 9 and 1 <= y <= 5 and kid[1]["from"] != kid[1]["to"]
    assert abs(x - sim.state.x_m[1]) < 0.3 + 1e-9  # where it landed (then drove 5 steps)


def test_a_kidnapping_pose_in_a_wall_is_refused_naming_the_field():
    cfg = _config([_group("k", [(2.0, 2.0, 0.0)])], {"kidnappings": [{"robot": 0, "t_s": 1.0, "pose": [0.02, 3.0, 0]}]})
    with pytest.raises(ValueError, match=r"faults\.kidnappings\[0\]\.pose: .*overlaps a wall"):
        Simulation(_room(), cfg)


# ------------------------------------------------------------------------ false positives
def test_false_positives_appear_only_in_their_window_and_only_within_field_of_view_and_range():
    cfg = _config([_group("d", [(2.0, 3.0, 0.0), (9.0, 5.0, 0.0), (9.0, 1.0, 0.0)],
                          detector=DetectorConfig(max_range_m=3.0, fov_deg=90.0))],
                  {"false_positives": [{"robot": 0, "t0_s": 1.0, "t1_s": 2.0, "rate_hz": 40.0}]})
    sim = Simulation(_room(), cfg)
    sim.run(40)
    a, b, c = _brains(sim)
    assert not any(o.detections for o in b.seen + c.seen)  # only robot 0 has a burst; nobody in range
    steps = [o.step for o in a.seen if o.detections]
    assert steps and set(steps) <= set(range(10, 21))
    phantoms = [d for o in a.seen for d in o.detections]
    assert 20 <= len(phantoms) <= 90  # Poisson, mean 40 Hz x 1.1 s = 44
    assert all(0.0 < d.range_m <= 3.0 and abs(d.bearing_rad) <= math.radians(45) + 1e-12 for d in phantoms)
    assert {d.robot_id for d in phantoms} <= {1, 2}  # a misrecognised teammate, never itself
    assert sim.faults.stats["phantoms"] == len(phantoms)


def test_false_positives_for_every_robot_with_a_detector_when_no_robot_is_named():
    cfg = _config([_group("d", [(2.0, 3.0, 0.0), (9.0, 5.0, 0.0)],
                          detector=DetectorConfig(max_range_m=3.0, report_identity=False)),
                   _group("blind", [(9.0, 1.0, 0.0)])],
                  {"false_positives": [{"t0_s": 0.0, "t1_s": 1.0, "rate_hz": 30.0}]})
    sim = Simulation(_room(), cfg)
    sim.run(20)
    a, b, c = _brains(sim)
    assert any(o.detections for o in a.seen) and any(o.detections for o in b.seen)
    assert all(d.robot_id is None for o in a.seen for d in o.detections)
    assert not any(o.detections for o in c.seen)


# ------------------------------------------------------------------------ validation
def _err(faults, groups=None):
    groups = groups or [_group("a", [(2.0, 2.0, 0.0)], detector=DetectorConfig()),
                        _group("b", [(4.0, 2.0, 0.0), (6.0, 2.0, 0.0)], sensors=(LaserConfig(),))]
    with pytest.raises(ValidationError) as exc:
        _config(groups, faults)
    return str(exc.value)


@pytest.mark.parametrize("faults,fragment", [
    ({"deaths": [{"robot": 3, "t_s": 1}]}, "faults.deaths[0].robot: expected a robot index in [0, 3)"),
    ({"deaths": [{"robot": {"group": "c"}, "t_s": 1}]}, "faults.deaths[0].robot.group: expected the name"),
    ({"deaths": [{"robot": {"group": "b", "index": 2}, "t_s": 1}]}, "faults.deaths[0].robot.index: expected"),
    ({"deaths": [{"robot": 0, "t_s": -1}]}, "greater than or equal to 0"),
    ({"deaths": [{"robot": 0, "t_s": 1, "when": 2}]}, "Extra inputs are not permitted"),
    ({"blackouts": [{"t0_s": 3, "t1_s": 1}]}, "t1_s must be >= t0_s"),
    ({"sensor_dropouts": [{"robot": 1, "sensor": 2, "t0_s": 0, "t1_s": 1}]},
     "faults.sensor_dropouts[0].sensor: expected a sensor index in [0, 1)"),
    ({"sensor_dropouts": [{"robot": 1, "sensor": "detector", "t0_s": 0, "t1_s": 1}]}, "has no detector"),
    ({"sensor_dropouts": [{"robot": 0, "sensor": "sonar", "t0_s": 0, "t1_s": 1}]}, "expected a sensor index, name"),
    ({"false_positives": [{"robot": 1, "t0_s": 0, "t1_s": 1, "rate_hz": 1}]}, "has no detector"),
    ({"false_positives": [{"robot": 0, "t0_s": 0, "t1_s": 1, "rate_hz": 0}]}, "greater than 0"),
    ({"kidnappings": [{"robot": 0, "t_s": 1, "pose": [1, 1, 0], "region": [0, 1, 0, 1]}]}, "not both"),
    ({"radio_dropouts": [{"robot": 0, "t_s": 2, "until_s": 1}]}, "until_s must be > t_s"),
    ({"kidnappings": [{"robot": 0, "t_s": 1, "pose": [1e9, 1, 0]}]}, "less than or equal to 1000000"),
    ({"false_positives": [{"robot": 0, "t0_s": 0, "t1_s": 1, "rate_hz": 1e6}]}, "less than or equal to 1000"),
    ({"deaths": [{"robot": 0, "t_s": 1}] * 1001}, "at most 1000 items"),
])
def test_bad_fault_specs_are_refused(faults, fragment):
    assert fragment in _err(faults)


def test_a_group_name_shared_by_two_groups_is_refused():
    groups = [_group("same", [(2.0, 2.0, 0.0)]), _group("same", [(4.0, 2.0, 0.0)])]
    assert "shared by robots[0] and robots[1]" in _err({"deaths": [{"robot": {"group": "same"}, "t_s": 1}]}, groups)


SCENARIO = """\
name: tiny-faults
map: {builtin: office_simple}
duration_s: 1.0
robots:
  - name: w
    count: 2
    controller: wander-v1
    sensors:
      - {kind: laser, n_beams: 30, max_range_m: 5.0}
    start: {region: [1.0, 29.0, 6.0, 8.0]}
faults:
  deaths: [{robot: 1, t_s: 0.5}]
"""


@pytest.mark.parametrize("patch,field,fragment", [
    (("robot: 1", "robot: 5"), "faults.deaths[0].robot", "expected a robot index in [0, 2)"),
    (("robot: 1", "robot: {group: v, index: 0}"), "faults.deaths[0].robot.group", "'v'"),
    (("t_s: 0.5", "t_s: .nan"), "faults.deaths[0].t_s", "finite"),
    (("deaths:", "dearhs:"), "faults.dearhs", "did you mean 'deaths'"),
    (("deaths: [{robot: 1, t_s: 0.5}]", "blackouts: [{t0_s: 2, t1_s: 1}]"), "faults.blackouts[0]", "t1_s must be"),
    (("deaths: [{robot: 1, t_s: 0.5}]", "sensor_dropouts: [{robot: 0, sensor: sonar, t0_s: 0, t1_s: 1}]"),
     "faults.sensor_dropouts[0].sensor", "'sonar'"),
])
def test_teamnav_validate_exits_2_naming_the_fault_field(tmp_path, patch, field, fragment):
    from teamnav.cli import app

    path = tmp_path / "s.yaml"
    path.write_text(textwrap.dedent(SCENARIO).replace(*patch))
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert result.stderr.startswith("error: ") and f"{field}: " in result.stderr and fragment in result.stderr, result.stderr


def test_teamnav_validate_accepts_good_faults(tmp_path):
    from teamnav.cli import app

    path = tmp_path / "s.yaml"
    path.write_text(SCENARIO)
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 0, result.output


# ------------------------------------------------------------------------ end to end
def test_a_fault_scenario_runs_end_to_end_and_its_events_and_metrics_say_what_happened(tmp_path):
    from teamnav import load_scenario, run
    from teamnav.sim.recorder import load

    scn = load_scenario("trail-team", duration_s=40.0, overrides=[
        "faults={deaths: [{robot: {group: pioneer, index: 3}, t_s: 20}], blackouts: [{t0_s: 5, t1_s: 10}]}",
        "metrics=[collisions, events, trails, faults]"])
    res = run(scn, out_dir=tmp_path / "run", progress=False)
    rec = load(tmp_path / "run")
    faults = [(e["fault"], e["robot"], round(e["t_s"], 6)) for e in rec.events if e.get("fault")]
    assert faults == [("blackout_start", -1, 5.0), ("blackout_end", -1, 10.1), ("died", 3, 20.0)]
    pose = rec.true_pose[:, 3]
    t = np.asarray(rec.t_s)
    assert np.all(pose[t >= 20.0] == pose[t >= 20.0][0])  # it stays where it died
    assert not np.all(pose[t < 20.0] == pose[0])
    assert res.metrics["fault_deaths"] == 1 and res.metrics["fault_blackouts"] == 1
    assert res.metrics["fault_first_s"] == 5.0
    # faults and the robots' starts (trail-team starts them one at a time) are not task events
    assert res.metrics["events_total"] == sum(1 for e in rec.events if not e.get("fault") and not e.get("launched"))
    assert res.metrics["collisions_robot"] == 0 and res.metrics["collisions_wall"] == 0
    written = (tmp_path / "run" / "scenario.yaml").read_text()
    assert "faults:" in written
    assert load_scenario(tmp_path / "run" / "scenario.yaml").model_dump() == scn.model_dump()  # reproduces it


def test_a_run_without_faults_has_no_fault_metrics_and_the_same_config_hash():
    from teamnav import load_scenario, run
    from teamnav.experiments.sweep import config_hash

    plain = load_scenario("demo", duration_s=1.0)
    assert config_hash(plain) == config_hash(load_scenario("demo", duration_s=1.0, overrides=["faults={}"]))
    assert config_hash(plain) == config_hash(load_scenario("demo", duration_s=1.0, overrides=["faults=null"]))
    assert not any(k.startswith("fault_") for k in run(plain, progress=False).metrics)


def test_relocalization_metrics_from_a_kidnapping_and_the_belief_logs():
    from teamnav.papers.robustness.metrics import fault_metrics
    from teamnav.experiments.metrics import RunData

    t = np.arange(0.0, 10.0)
    true = np.zeros((10, 2, 3))
    true[:, 1, 0] = np.where(t >= 3, 8.0, 1.0)  # robot 1 jumps from x = 1 to x = 8 at t = 3
    belief_x = [1.0, 1.0, 1.0, 1.0, 1.0, 3.0, 7.5, 8.0, 8.0, 8.0]  # back within 1.5 m at t = 6
    logs = [{"step": int(k * 10), "t_s": float(k), "robot": r,
             "values": {"pts": [[belief_x[k] if r == 1 else 0.0, 0.0]] * 4}} for k in range(10) for r in (0, 1)]
    kid = {"step": 30, "t_s": 3.0, "robot": 1, "place": None, "event": None, "fault": "kidnapped"}
    data = RunData(t_s=t, true_pose=true, odom_pose=true, stalled=np.zeros((10, 2), bool), radius_m=np.full(2, 0.2),
                   grid=None, event_log=[kid], logs=logs, n_steps=100, dt_s=0.1)
    m = fault_metrics(data)
    assert m["fault_kidnappings"] == 1 and m["fault_first_s"] == 3.0
    assert m["fault_kidnap_error_m"] == 7.0 and m["fault_relocalize_s"] == 3.0
    assert m["fault_relocalize_censored"] == 0 and m["fault_relocalized_fraction"] == 1.0
    never = RunData(t_s=t, true_pose=true, odom_pose=true, stalled=np.zeros((10, 2), bool), radius_m=np.full(2, 0.2),
                    grid=None, event_log=[kid], logs=[dict(r, values={"pts": [[1.0, 0.0]]}) for r in logs],
                    n_steps=100, dt_s=0.1)
    m = fault_metrics(never)
    assert m["fault_relocalize_s"] == 10.0 - 3.0 and m["fault_relocalize_censored"] == 1  # censored at the end
    assert fault_metrics(RunData(t_s=t, true_pose=true, odom_pose=true, stalled=np.zeros((10, 2), bool),
                                 radius_m=np.full(2, 0.2), grid=None)) == {}


def test_robustness_sweeps_pair_each_fault_with_a_fault_free_case():
    from teamnav.experiments.sweep import expand, load_sweep, sweep_names

    names = [n for n in sweep_names() if n.startswith("robustness-")]
    assert names == ["robustness-blazing", "robustness-los", "robustness-mcl", "robustness-try"]
    for name in names:
        spec = load_sweep(name)
        assert spec.cases[0] == {"case": "fault-free", "faults": None}, name
        assert all(c.get("faults") for c in spec.cases[1:]), name
        trials = expand(spec)  # every case resolves to a valid scenario
        free = {t.config_hash for t in trials if t.params["case"] == "fault-free"}
        assert len(free) == 1 and free.isdisjoint(t.config_hash for t in trials if t.params["case"] != "fault-free")


@pytest.mark.slow
def test_the_quick_robustness_report_runs_and_judges_every_claim(tmp_path):
    from teamnav.experiments.report import run_report

    res = run_report("robustness", tmp_path / "r", quick=True, progress=False)
    (sec,) = res.sections
    assert sec.status == "ok", sec.error
    assert len(sec.comparisons) == 15 and all(c.holds is not None for c in sec.comparisons)
