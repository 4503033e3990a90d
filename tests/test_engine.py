"""The engine: determinism, belief-only observations, mixed brains, stalls, events, radio, recorder, start."""

from __future__ import annotations

import gc
import json
import math
import types

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict

from teamnav.control import registry
from teamnav.control.types import Action, Message, Observation
from teamnav.sim import recorder as rec_mod
from teamnav.sim.config import (
    LaserConfig,
    OdometryConfig,
    PlaceConfig,
    ProximityConfig,
    RadioConfig,
    RobotGroupConfig,
    SimConfig,
    StartConfig,
)
from teamnav.sim.engine import Simulation
from teamnav.sim.state import RobotState
from teamnav.world.grid import WALL, OccupancyGrid


# ------------------------------------------------------------------------ a spy brain
class SpyParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    v_mps: float = 0.0
    omega_radps: float = 0.0
    direction_deg: float | None = None
    send: bool = False


class Spy:
    """Drives a constant command, keeps every observation, sends its step number when asked."""

    Params = SpyParams

    def __init__(self, params, rng, info):
        self.p = params
        self.info = info
        self.seen: list[Observation] = []

    def step(self, obs):
        self.seen.append(obs)
        out = [Message(self.info.robot_id, obs.time_s, {"step": obs.step})] if self.p.send else []
        d = None if self.p.direction_deg is None else math.radians(self.p.direction_deg)
        return Action(self.p.v_mps, self.p.omega_radps, d), out

    def log(self):
        return {"n_seen": len(self.seen)}


@pytest.fixture(autouse=True)
def _spy_registered(monkeypatch):
    monkeypatch.setitem(registry._REGISTRY, "spy-test-v1", f"{__name__}:Spy")


def _room(side_m=6.0, res=0.05):
    n = int(round(side_m / res))
    cells = np.zeros((n, n), np.uint8)
    cells[:2, :] = cells[-2:, :] = cells[:, :2] = cells[:, -2:] = WALL
    cells[n // 2 - 2: n // 2 + 2, n // 4: 3 * n // 4] = WALL
    return OccupancyGrid(cells, res, name="room")


def _pose(sim):
    return sim.state.poses()


def _wander_config(seed, n=4):
    return SimConfig(
        robots=(
            RobotGroupConfig(name="a", count=n, controller="wander-v1",
                             sensors=(LaserConfig(n_beams=60, noise_std_m=0.02),),
                             odometry=OdometryConfig(alpha=(0.05, 0.01, 0.05, 0.01), heading_drift_deg_per_min=1.0)),
            RobotGroupConfig(name="b", count=n, controller="wander-batched-v1", radius_m=0.1,
                             sensors=(ProximityConfig(noise_std_m=0.005),)),
        ),
        radio=RadioConfig(p_loss=0.2),
        seed=seed,
    )


# ------------------------------------------------------------------------ determinism
def test_same_seed_same_trajectories_bit_for_bit_and_different_seed_differs():
    runs = []
    for seed in (11, 11, 12):
        sim = Simulation(_room(), _wander_config(seed))
        traj = [_pose(sim)]
        odom = []
        for _ in range(80):
            sim.step()
            traj.append(_pose(sim))
            odom.append(sim.odometry.pose.copy())
        runs.append((np.array(traj), np.array(odom)))
    np.testing.assert_array_equal(runs[0][0], runs[1][0])
    np.testing.assert_array_equal(runs[0][1], runs[1][1])
    assert not np.array_equal(runs[0][0][0], runs[2][0][0])  # different start
    path_m = np.hypot(*np.diff(runs[0][0][:, :, :2], axis=0).transpose(2, 0, 1)).sum(axis=0)
    assert np.all(path_m > 0.5), path_m


# ------------------------------------------------------------------------ truth vs belief
def _reachable(roots, limit=20000):
    """Objects reachable from ``roots`` through gc referents (skipping modules, classes, functions)."""
    seen, stack, out = set(), list(roots), []
    while stack and len(out) < limit:
        o = stack.pop()
        if id(o) in seen or isinstance(o, (type, types.ModuleType, types.FunctionType, types.BuiltinFunctionType)):
            continue
        seen.add(id(o))
        out.append(o)
        stack.extend(gc.get_referents(o))
    return out


def test_observations_carry_belief_only_and_never_views_of_truth():
    cfg = SimConfig(robots=(RobotGroupConfig(
        count=2, controller="spy-test-v1", params={"v_mps": 0.3, "omega_radps": 0.2},
        sensors=(LaserConfig(n_beams=30),),
        odometry=OdometryConfig(heading_drift_deg_per_min=30.0, scale_error=0.1, frame="world"),
        start=StartConfig(poses=((1.0, 1.0, 0.0), (1.0, 4.5, 0.0))),
    ),), seed=3)
    sim = Simulation(_room(), cfg)
    sim.run(30)
    s = sim.state
    truth_arrays = [s.x_m, s.y_m, s.theta_rad, s.v_mps, s.omega_radps, s.radius_m, s.stalled, s.group]
    for k, brain in enumerate(sim.brains[0]):
        obs = brain.seen[-1]
        assert obs.robot_id == k and obs.step == 30
        # odometry drifted away from the truth (frame world: same frame, different numbers)
        assert abs(obs.odom_pose[2] - s.theta_rad[k]) > 0.01
        assert np.hypot(obs.odom_pose[0] - s.x_m[k], obs.odom_pose[1] - s.y_m[k]) > 0.01
        for arr in [obs.odom_pose, obs.odom_delta, *(sc.ranges_m for sc in obs.scans.values())]:
            assert not any(np.shares_memory(arr, t) for t in truth_arrays)
        # nothing reachable from what the brain holds is the simulator or its truth
        for o in _reachable([obs, brain.info, brain]):
            assert not isinstance(o, (Simulation, RobotState))
            assert not any(o is t for t in truth_arrays)
    # scribbling on an observation changes nothing in the simulator
    before = _pose(sim)
    obs = sim.brains[0][0].seen[-1]
    obs.odom_pose[:] = 99.0
    next(iter(obs.scans.values())).ranges_m[:] = 0.0
    np.testing.assert_array_equal(_pose(sim), before)
    assert not np.any(sim.odometry.pose == 99.0)


def test_odom_start_frame_begins_at_zero_and_delta_is_reported():
    cfg = SimConfig(robots=(RobotGroupConfig(
        count=1, controller="spy-test-v1", params={"v_mps": 0.5}, sensors=(),
        start=StartConfig(poses=((2.0, 1.0, 90.0),)),
    ),))
    sim = Simulation(_room(), cfg)
    sim.run(3)
    seen = sim.brains[0][0].seen
    np.testing.assert_array_equal(seen[0].odom_pose, 0.0)
    np.testing.assert_allclose(seen[2].odom_delta, [0.05, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(seen[3].odom_pose, [0.15, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(_pose(sim)[0], [2.0, 1.15, math.pi / 2], atol=1e-12)


# ------------------------------------------------------------------------ mixed brains
def test_per_robot_and_batched_controllers_run_together():
    sim = Simulation(_room(), _wander_config(5, n=3))
    assert isinstance(sim.brains[0], list) and len(sim.brains[0]) == 3
    assert getattr(sim.brains[1], "batched", False)
    path_m = np.zeros(6)
    for _ in range(100):
        before = _pose(sim)
        sim.step()
        path_m += np.hypot(*(_pose(sim)[:, :2] - before[:, :2]).T)
    assert np.all(path_m > 0.5), path_m
    assert sim.group_of.tolist() == [0, 0, 0, 1, 1, 1]
    assert sim.robot_info(4).radius_m == 0.1 and sim.robot_info(4).robot_id == 4


# ------------------------------------------------------------------------ stall, holonomic
def test_stall_flag_reaches_the_brain():
    cfg = SimConfig(robots=(RobotGroupConfig(
        count=1, controller="spy-test-v1", params={"v_mps": 0.5}, sensors=(), max_v_mps=0.5,
        start=StartConfig(poses=((5.3, 1.0, 0.0),)),  # 0.5 m from the east wall at x = 5.9
    ),))
    sim = Simulation(_room(), cfg)
    flags = []
    sim.add_hook(post_step=lambda s: flags.append(bool(s.state.stalled[0])))
    sim.run(20)
    seen = sim.brains[0][0].seen
    assert [o.stalled for o in seen[1:]] == flags
    assert not flags[0] and flags[-1]
    assert 5.9 - sim.state.x_m[0] >= 0.2 - 1e-9


def test_holonomic_step_turns_then_moves_a_fixed_step():
    cfg = SimConfig(robots=(RobotGroupConfig(
        count=1, controller="spy-test-v1", params={"direction_deg": 90.0}, sensors=(), kinematics="holonomic_step",
        step_length_m=0.25, start=StartConfig(poses=((1.0, 1.0, 0.0),)),
    ),))
    sim = Simulation(_room(), cfg)
    sim.run(2)
    np.testing.assert_allclose(_pose(sim)[0], [1.0 - 0.25, 1.0 + 0.25, math.pi], atol=1e-12)


# ------------------------------------------------------------------------ events, radio
def test_events_fire_at_places_in_the_same_step():
    cfg = SimConfig(
        robots=(RobotGroupConfig(count=1, controller="spy-test-v1", params={"v_mps": 0.5}, sensors=(),
                                 start=StartConfig(poses=((1.0, 1.0, 0.0),))),),
        places=(PlaceConfig(name="src", x_m=2.0, y_m=1.0, radius_m=0.5, event="given_resource"),),
    )
    sim = Simulation(_room(), cfg)
    sim.run(30)
    seen = sim.brains[0][0].seen
    fired = [o.step for o in seen if o.events]
    assert fired == [10]  # x = 1.5 at step 10: on the place's edge
    assert seen[10].events == ("given_resource",)
    assert [(e["step"], e["event"]) for e in sim.recorder.events] == [(10, "given_resource")]


def test_radio_messages_arrive_next_step():
    cfg = SimConfig(
        robots=(RobotGroupConfig(count=3, controller="spy-test-v1", params={"send": True}, sensors=(),
                                 start=StartConfig(poses=((1.0, 1.0, 0.0), (2.0, 1.0, 0.0), (1.0, 5.0, 0.0)))),),
        radio=RadioConfig(mode="line_of_sight", range_m=3.0),
    )
    sim = Simulation(_room(), cfg)
    sim.run(5)
    seen = sim.brains[0][1].seen
    assert seen[0].inbox == ()
    for k in range(1, 6):
        # only robot 0 is in range and sight of robot 1; its message of step k-1 arrives at step k
        assert [(m.sender, m.body["step"]) for m in seen[k].inbox] == [(0, k - 1)]
    assert all(o.inbox == () for o in sim.brains[0][2].seen)  # robot 2 is behind the wall stub
    comm = sim.recorder.comm
    assert comm["messages_sent"] == 3 * 6 and comm["messages_delivered"] == 2 * 5


# ------------------------------------------------------------------------ recorder
def test_recorder_saves_atomically_and_loads_back(tmp_path):
    cfg = _wander_config(2, n=2).model_copy(update={"record_every": 5})
    sim = Simulation(_room(), cfg)
    sim.run(23)
    out = sim.recorder.save(tmp_path / "run")
    assert sorted(p.name for p in out.iterdir()) == ["comm.json", "events.json", "logs.json", "trajectories.npz"]
    r = rec_mod.load(out)
    assert r.step.tolist() == [0, 5, 10, 15, 20]
    np.testing.assert_allclose(r.t_s, [0.0, 0.5, 1.0, 1.5, 2.0])
    assert r.true_pose.shape == (5, 4, 3) and r.odom_pose.shape == (5, 4, 3) and r.stalled.shape == (5, 4)
    np.testing.assert_allclose(r.true_pose[0], sim.recorder.true_pose[0])
    assert r.comm["messages_sent"] == 0 and isinstance(r.events, list)
    json.loads((out / "comm.json").read_text())
    with pytest.raises(ValueError, match="run_dir"):
        rec_mod.load(tmp_path / "nothing")


def test_recorder_keeps_controller_logs():
    cfg = SimConfig(robots=(RobotGroupConfig(count=2, controller="spy-test-v1", sensors=()),), record_every=2)
    sim = Simulation(_room(), cfg)
    sim.run(4)
    logs = sim.recorder.logs
    assert [(e["step"], e["robot"], e["values"]["n_seen"]) for e in logs] == [
        (0, 0, 0), (0, 1, 0), (2, 0, 3), (2, 1, 3), (4, 0, 5), (4, 1, 5)
    ]


# ------------------------------------------------------------------------ run loop, hooks
def test_run_stops_when_finished_and_reports_progress():
    cfg = SimConfig(robots=(RobotGroupConfig(count=1, controller="idle-v1", sensors=()),))
    sim = Simulation(_room(), cfg)
    done, pre = [], []
    sim.add_hook(pre_step=lambda s: pre.append(s.step_index))
    sim.run(100, progress=done.append, is_finished=lambda s: s.time_s >= 0.5 - 1e-9)
    assert sim.step_index == 5 and done == [1, 2, 3, 4, 5] and pre == [0, 1, 2, 3, 4]
    with pytest.raises(ValueError, match="n_steps"):
        sim.run(-1)


# ------------------------------------------------------------------------ bad input, start
def test_bad_controller_name_and_params_name_the_group():
    with pytest.raises(ValueError, match=r"robots\[0\] \('bots'\).*did you mean 'wander-v1'"):
        Simulation(_room(), SimConfig(robots=(RobotGroupConfig(name="bots", controller="wandr-v1"),)))
    with pytest.raises(ValueError, match=r"robots\[0\] \('bots'\).*spy-test-v1.*params.v_mps.*'fast'"):
        Simulation(_room(), SimConfig(robots=(RobotGroupConfig(name="bots", controller="spy-test-v1",
                                                               params={"v_mps": "fast"}),)))
    with pytest.raises(ValueError, match="grid"):
        Simulation(np.zeros((3, 3)), SimConfig())


def test_explicit_start_poses_are_checked():
    def make(poses):
        return SimConfig(robots=(RobotGroupConfig(name="g", count=len(poses), controller="idle-v1", sensors=(),
                                                  start=StartConfig(poses=poses)),))

    with pytest.raises(ValueError, match=r"robots\[0\] \('g'\)\.start\.poses\[1\].*wall"):
        Simulation(_room(), make(((1.0, 1.0, 0.0), (0.1, 1.0, 0.0))))
    with pytest.raises(ValueError, match=r"robots\[0\] \('g'\)\.start\.poses\[1\].*overlaps robot 0"):
        Simulation(_room(), make(((1.0, 1.0, 0.0), (1.3, 1.0, 0.0))))


def test_random_start_respects_region_clearance_and_no_overlap():
    region = (0.5, 2.5, 0.5, 2.0)
    cfg = SimConfig(robots=(
        RobotGroupConfig(name="g", count=12, radius_m=0.15, controller="idle-v1", sensors=(),
                         start=StartConfig(region=region, theta_deg=45.0)),
        RobotGroupConfig(name="h", count=20, radius_m=0.2, controller="idle-v1", sensors=()),
    ))
    sim = Simulation(_room(), cfg)
    p = _pose(sim)
    r = sim.state.radius_m
    assert np.all((p[:12, 0] >= 0.5) & (p[:12, 0] <= 2.5) & (p[:12, 1] >= 0.5) & (p[:12, 1] <= 2.0))
    np.testing.assert_allclose(p[:12, 2], math.pi / 4)
    from teamnav.sim.collisions import discs_hit_walls

    assert not discs_hit_walls(sim._blocking, sim._clear_m, sim._geo, p[:, 0], p[:, 1], r).any()
    d = np.hypot(p[:, None, 0] - p[None, :, 0], p[:, None, 1] - p[None, :, 1]) - (r[:, None] + r[None, :])
    np.fill_diagonal(d, np.inf)
    assert d.min() >= 0
    crowded = SimConfig(robots=(RobotGroupConfig(name="g", count=40, radius_m=0.3, controller="idle-v1", sensors=(),
                                                 start=StartConfig(region=(0.5, 1.5, 0.5, 1.5))),))
    with pytest.raises(ValueError, match=r"robots\[0\] \('g'\)\.start"):
        Simulation(_room(), crowded)


def test_detector_reports_teammates_in_the_observers_body_frame():
    from teamnav.sim.config import DetectorConfig

    cfg = SimConfig(robots=(RobotGroupConfig(
        count=3, controller="spy-test-v1", sensors=(), detector=DetectorConfig(max_range_m=3.0),
        start=StartConfig(poses=((1.0, 1.0, 90.0), (2.0, 1.0, 0.0), (1.0, 5.0, 0.0))),
    ),))
    sim = Simulation(_room(), cfg)
    sim.run(1)
    dets = sim.brains[0][0].seen[-1].detections
    # robot 1 is 1 m away on robot 0's right (-90 deg); robot 2 is out of range and behind the stub
    assert [(d.robot_id, round(d.range_m, 9), round(d.bearing_rad, 9)) for d in dets] == [(1, 1.0, round(-math.pi / 2, 9))]
    assert sim.brains[0][2].seen[-1].detections == ()


# ------------------------------------------------------------------------ sensing path
@pytest.mark.parametrize("count", [6, 130])  # 130 x 181 rays: the parallel kernels
def test_engine_readings_equal_the_public_sensor_api(count):
    # the engine senses through an unchecked per-step path; it must read exactly what the
    # checked public RangeSensor.sense returns from the same poses, bodies and Generator state
    import copy

    cfg = SimConfig(robots=(RobotGroupConfig(count=count, controller="spy-test-v1", radius_m=0.2,
                                             params={"v_mps": 0.3, "omega_radps": 0.4},
                                             sensors=(LaserConfig(n_beams=181, noise_std_m=0.02, p_max=0.01,
                                                                  p_short=0.01),)),),
                    seed=5)
    sim = Simulation(_room(side_m=12.0), cfg)
    grp = sim._groups[0]
    sensor = grp.sensors[0]
    ids = np.arange(count)
    hit_robot = False
    sim.step()  # the first step also takes the brains' step-0 decision (a second sensing)
    for _ in range(3):
        rng_before = copy.deepcopy(grp.rngs[0])
        sim.step()
        s = sim.state
        expect = sensor.sense(s.x_m.copy(), s.y_m.copy(), s.theta_rad.copy(), rng_before,
                              bodies=(s.x_m.copy(), s.y_m.copy(), s.radius_m.copy(), ids))
        got = np.stack([b.seen[-1].scans[sensor.name].ranges_m for b in sim.brains[0]])
        np.testing.assert_array_equal(got, expect)
        walls_only = sensor.true_ranges(s.x_m, s.y_m, s.theta_rad)
        with_bodies = sensor.true_ranges(s.x_m, s.y_m, s.theta_rad, bodies=(s.x_m, s.y_m, s.radius_m, ids))
        hit_robot |= bool((with_bodies < walls_only).any())
    assert hit_robot  # the robots do block each other's beams here


def test_same_run_on_one_or_all_threads():
    # every sensing kernel is exact or counter-based: the thread count never changes a run
    import numba

    cfg = SimConfig(robots=(RobotGroupConfig(count=130, controller="wander-batched-v1", radius_m=0.2,
                                             sensors=(LaserConfig(n_beams=181, noise_std_m=0.02, p_max=0.01,
                                                                  p_short=0.01),)),),
                    seed=9)
    runs = []
    before = numba.get_num_threads()
    try:
        for threads in (1, numba.config.NUMBA_NUM_THREADS):
            numba.set_num_threads(threads)
            sim = Simulation(_room(side_m=12.0), cfg)
            sim.run(15)
            runs.append(sim.state.poses())
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(runs[0], runs[1])


def test_the_final_step_is_recorded_even_between_samples():
    """record_every=7 over 10 steps samples 0 and 7; the runner also keeps step 10."""
    from teamnav import load_scenario, run

    res = run(load_scenario("demo", duration_s=1.0, overrides={"record_every": 7}), progress=False)
    assert res.data.t_s[-1] == pytest.approx(1.0)
    assert res.data.true_pose.shape[0] == 3


def test_start_poses_longer_than_count_use_the_first_count_and_too_few_is_an_error():
    poses = ((1.0, 1.0, 0.0), (2.0, 1.0, 90.0), (0.1, 1.0, 0.0))  # the third would overlap a wall
    cfg = SimConfig(robots=(RobotGroupConfig(name="g", count=2, controller="idle-v1", sensors=(),
                                             start=StartConfig(poses=poses)),))
    got = Simulation(_room(), cfg).state.poses()
    np.testing.assert_allclose(got[:, :2], [[1.0, 1.0], [2.0, 1.0]])
    np.testing.assert_allclose(got[1, 2], np.pi / 2)
    with pytest.raises(ValueError, match=r"start.poses must list at least count=3 poses.*got 2"):
        RobotGroupConfig(name="g", count=3, controller="idle-v1", start=StartConfig(poses=poses[:2]))


def test_long_sensor_names_are_recorded_under_distinct_short_keys(tmp_path):
    """A sensor name past the recorder's 64-character key limit used to crash a run with
    record_scans on; the key is cut and keeps the sensor's index (the full name stays in the
    scan's metadata)."""
    from teamnav.experiments.runner import run as run_scenario
    from teamnav.experiments.spec import load_scenario
    from teamnav.sim.recorder import load

    long = "a_very_long_sensor_name_that_goes_on_and_on_and_on_past_sixty_four_characters_"
    scn = load_scenario("demo", overrides=["record_scans=true", "robots.0.count=2", "robots.0.start.region=null",
                                           f"robots.0.sensors=[{{kind: laser, name: {long}x}}, {{kind: laser, name: {long}y}}]"],
                        duration_s=0.3)
    result = run_scenario(scn, out_dir=tmp_path / "run", progress=False)
    scans = load(result.run_dir).scans
    assert len(scans) == 2 and all(len(k) <= 64 for k in scans)
    assert sorted(s.sensor for s in scans.values()) == [long + "x", long + "y"]


def test_decide_first_and_set_commands_let_an_outside_agent_act_on_step_0():
    """Simulation.decide_first takes the step-0 decision without motion (idempotent), and
    set_commands replaces the stored commands of chosen robots before the next step moves
    them; bad ids or shapes are refused."""
    from teamnav.experiments.spec import build_grid, load_scenario

    scn = load_scenario("demo", overrides=["robots.0.count=3"], duration_s=1.0)
    sim = Simulation(build_grid(scn), scn)
    x0 = sim.state.x_m.copy()
    sim.decide_first()
    sim.decide_first()
    assert sim.step_index == 0 and np.array_equal(sim.state.x_m, x0)
    sim.set_commands([1], [0.0], [0.0])
    sim.step()
    assert sim.state.x_m[1] == x0[1] and sim.state.y_m[1] == sim.state.y_m[1]  # robot 1 held still
    assert not np.array_equal(sim.state.x_m[[0, 2]], x0[[0, 2]])  # the others moved on their brains
    with pytest.raises(ValueError, match="robot indices"):
        sim.set_commands([3], [0.0], [0.0])
    with pytest.raises(ValueError, match="shape"):
        sim.set_commands([0, 1], [0.0], [0.0, 0.0])
    with pytest.raises(ValueError, match="finite"):
        sim.set_commands([0], [float("nan")], [0.0])
