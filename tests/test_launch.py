"""Robots started one at a time from one spot (``SimConfig.launch``, Vaughan et al. 2000 §5 and
2002 §3.5): they leave the spot one at a time, a robot that has not started does not move, is
not stepped, and no other robot's laser meets it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import BaseModel, ConfigDict

from teamnav.control import registry
from teamnav.control.types import Action, Message
from teamnav.sim.config import LaserConfig, LaunchConfig, OdometryConfig, RobotGroupConfig, SimConfig
from teamnav.sim.engine import Simulation
from teamnav.world.grid import WALL, OccupancyGrid


class DriveParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    v_mps: float = 0.3


class Drive:
    """Drives a constant speed (backwards when negative), keeps its observations, talks every step."""

    Params = DriveParams

    def __init__(self, params, rng, info):
        self.p = params
        self.info = info
        self.seen = []

    def step(self, obs):
        self.seen.append(obs)
        return Action(self.p.v_mps, 0.0), [Message(self.info.robot_id, obs.time_s, {"step": obs.step})]


@pytest.fixture(autouse=True)
def _drive_registered(monkeypatch):
    monkeypatch.setitem(registry._REGISTRY, "drive-test-v1", f"{__name__}:Drive")


def _corridor(length_m=20.0, width_m=2.0, res=0.05):
    """A straight corridor along x, walls two cells thick."""
    w, h = int(round(length_m / res)), int(round(width_m / res))
    cells = np.zeros((h, w), np.uint8)
    cells[:2, :] = cells[-2:, :] = cells[:, :2] = cells[:, -2:] = WALL
    return OccupancyGrid(cells, res, name="corridor")


def _config(n=4, v=0.3, clear_m=0.9, spot=(2.0, 1.0, 0.0), drift=0.0):
    return SimConfig(
        robots=(RobotGroupConfig(name="r", count=n, radius_m=0.25, controller="drive-test-v1", params={"v_mps": v},
                                 sensors=(LaserConfig(n_beams=181, max_range_m=8.0, noise_std_m=0.0),),
                                 odometry=OdometryConfig(frame="world", heading_drift_deg_per_min=drift)),),
        launch=LaunchConfig(spot=spot, clear_m=clear_m),
    )


def _run(sim, n_steps):
    """Per step after the step: true (x, y) of every robot and the waiting mask."""
    xy, waiting = [], []
    for _ in range(n_steps):
        sim.step()
        xy.append(np.stack([sim.state.x_m, sim.state.y_m], axis=1).copy())
        waiting.append(sim.waiting.copy())
    return np.array(xy), np.array(waiting)


@settings(max_examples=8, deadline=None)
@given(v=st.floats(0.15, 0.5), clear_m=st.floats(0.5, 1.5))
def test_robots_leave_the_spot_one_at_a_time(v, clear_m):
    sim = Simulation(_corridor(), _config(v=v, clear_m=clear_m))
    spot = np.array([2.0, 1.0])
    n_steps = int(math.ceil(4 * clear_m / (v * sim.dt_s))) + 40
    xy, waiting = _run(sim, n_steps)
    d = np.hypot(*(xy - spot).transpose(2, 0, 1))  # (steps, robots) from the spot
    started = ~waiting
    # never two started robots on the spot (within clear_m of it) at once
    assert ((d < clear_m) & started).sum(axis=1).max() <= 1
    # every robot started, in id order, one step at a time at most
    at = sim.launched_at
    assert (at >= 0).all() and (np.diff(at) > 0).all()
    for i in range(1, 4):
        k = at[i] - 1  # the step index before robot i starts is row k - 1 of the per-step arrays
        # it starts at the first step the earlier robots are all clear of the spot ...
        assert d[k - 1, :i].min() >= clear_m - 1e-9
        assert d[k - 2, :i].min() < clear_m
        # ... and sat on the spot, unmoved, until then
        assert np.allclose(xy[: k - 1, i], spot)
    # the interval is the time to drive clear_m (the commanded speed, reached at once here)
    steps_apart = np.diff(at) * sim.dt_s
    assert steps_apart == pytest.approx(np.full(3, clear_m / v), abs=2 * sim.dt_s + 1e-9)


def test_a_waiting_robot_is_not_stepped_not_seen_and_starts_its_odometry_at_the_spot():
    # robots back away from the spot along -x while their lasers look +x at it (spot at x = 10)
    sim = Simulation(_corridor(), _config(v=-0.3, clear_m=0.9, spot=(10.0, 1.0, 0.0), drift=30.0))
    brains = sim.brains[0]
    xy, waiting = _run(sim, 200)
    at = sim.launched_at.tolist()
    assert at[0] == 0 and 0 < at[1] < at[2] < at[3] <= 200
    for i, b in enumerate(brains):  # its brain sees no step before its start, every step after
        steps = [o.step for o in b.seen]
        assert steps[0] == at[i] and steps == list(range(at[i], steps[-1] + 1))
        # odometry starts at the spot when the robot starts (30 deg/min of drift from then on only)
        first = b.seen[0].odom_pose
        assert first[0] == pytest.approx(10.0, abs=0.04) and first[1] == pytest.approx(1.0, abs=1e-9)
        assert abs(first[2]) < math.radians(30.0) / 60.0 * 0.2
    beam0 = len(brains[0].seen[0].scans["laser"].ranges_m) // 2  # straight ahead, toward the spot
    ahead = np.array([o.scans["laser"].ranges_m[beam0] for o in brains[0].seen])
    # robot 0 backs away: while robot 1 waits on the spot, nothing is ahead within range ...
    assert np.allclose(ahead[1: at[1]], 8.0)
    # ... once robot 1 is there, robot 0's laser meets its body: distance minus its radius
    k = at[1] + 1
    dist = xy[k - 1, 1, 0] - xy[k - 1, 0, 0]
    assert ahead[k] == pytest.approx(dist - 0.25, abs=0.02)
    # the waiting robots never moved and heard nothing before they started
    for i in (1, 2, 3):
        assert np.allclose(xy[: at[i] - 1, i], [10.0, 1.0])


def test_without_launch_the_config_serialises_as_before_and_bad_launches_are_refused():
    assert "launch" not in SimConfig().model_dump()
    with pytest.raises(ValueError, match=r"launch.spot \[0.1, 1.0, 0.0\]"):
        Simulation(_corridor(), _config(spot=(0.1, 1.0, 0.0)))


def test_a_batched_groups_waiting_robots_ignore_its_commands_until_they_start():
    batched = SimConfig(robots=(RobotGroupConfig(name="b", count=3, radius_m=0.2, controller="wander-batched-v1"),),
                        launch=LaunchConfig(spot=(2.0, 1.0, 0.0), clear_m=0.6))
    sim = Simulation(_corridor(), batched)
    xy, waiting = _run(sim, 600)
    assert (sim.launched_at[1:] > 0).all() or waiting[-1].any()
    for i in (1, 2):
        stop = sim.launched_at[i] - 1 if sim.launched_at[i] > 0 else len(xy)
        assert np.allclose(xy[:stop, i], [2.0, 1.0])
    assert np.hypot(*(xy[-1, 0] - [2.0, 1.0])) > 0.0  # robot 0 did move


def test_a_trail_run_logs_every_start_and_counts_no_collision_for_robots_waiting_at_the_spot():
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario

    res = run(load_scenario("blazing-a-trail", duration_s=20.0, seed=1000), progress=False)
    starts = [(e["robot"], e["t_s"]) for e in res.data.event_log if e.get("launched")]
    assert [r for r, _ in starts] == [0, 1, 2, 3] and starts[0][1] == 0.0
    assert all(a < b for (_, a), (_, b) in zip(starts, starts[1:]))
    # the waiting robots are recorded at the spot, on top of each other, yet nothing collided
    first = res.data.true_pose[0, :, :2]
    assert np.allclose(first[1:], first[1])
    assert res.metrics["collisions_robot"] == 0 and res.metrics["collisions_wall"] == 0
