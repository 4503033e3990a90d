"""Per-robot observations: the engine refills the objects it handed over last step only when
the brain kept none of them, and a brain cannot tell the difference.

A brain that keeps nothing gets the same Observation, scans dict and RangeScan back each
step, with this step's values (fresh arrays); a brain that keeps its observation, its dict,
its scan or an array gets new objects, and what it kept stays as it was.
"""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from teamnav.control import registry
from teamnav.sim.config import ProximityConfig, RadioConfig, RobotGroupConfig, SimConfig
from teamnav.sim.engine import Simulation
from teamnav.world.grid import WALL, OccupancyGrid

BRAINS = """\
from teamnav.control import Action, Message, NoParams

SEEN = []  # (class, robot, step, what it saw, copied; id of the observation)
KEPT = []  # (robot, step, what it kept, a copy of it)


def _copy(x):
    if isinstance(x, dict):
        return {k: (v.ranges_m.copy(), v.angles_rad, v.max_range_m) for k, v in x.items()}
    if hasattr(x, "ranges_m"):
        return (x.ranges_m.copy(), x.angles_rad, x.max_range_m)
    if hasattr(x, "odom_pose"):
        return (x.step, x.time_s, x.odom_pose.copy(), x.odom_delta.copy(), _copy(x.scans), x.stalled, x.inbox)
    return x.copy()


class Snap:
    '''Records what it sees, keeps nothing; says hello every third step.'''

    Params = NoParams

    def __init__(self, params, rng, info):
        self.id = info.robot_id

    def step(self, obs):
        sc = obs.scans["proximity"]
        SEEN.append((type(self).__name__, obs.robot_id, obs.step, obs.time_s, obs.odom_pose.copy(),
                     obs.odom_delta.copy(), sc.ranges_m.copy(), sc.angles_rad.copy(), sc.max_range_m, obs.stalled,
                     obs.inbox, obs.events, obs.detections, sorted(obs.scans), id(obs)))
        out = [Message(self.id, obs.time_s, self.id, kind="hi")] if obs.step % 3 == self.id % 3 else []
        return Action(0.15, 0.2 if self.id % 2 else -0.1), out


class KeepAll(Snap):
    '''Keeps every observation (so each step's is a new one).'''

    def __init__(self, params, rng, info):
        super().__init__(params, rng, info)
        self.all = []

    def step(self, obs):
        self.all.append(obs)
        return super().step(obs)


class Keeper(Snap):
    '''Robot i keeps, by i mod 6: nothing, its observation, the scans dict, the scan, the
    ranges array, or nothing but adds a key to the scans dict.'''

    def step(self, obs):
        out = super().step(obs)
        what = self.id % 6
        if what == 5:
            obs.scans["mine"] = 1
        elif what:
            held = [None, obs, obs.scans, obs.scans["proximity"], obs.scans["proximity"].ranges_m][what]
            KEPT.append((self.id, obs.step, held, _copy(held)))
        return out
"""


@pytest.fixture()
def brains(tmp_path):
    path = tmp_path / "refill_brains.py"
    path.write_text(textwrap.dedent(BRAINS))
    return str(path)


def _sim(spec: str, n: int, seed: int = 4) -> Simulation:
    side = 1.2
    cells = np.zeros((int(side / 0.02) + 2,) * 2, np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = WALL
    grid = OccupancyGrid(cells, 0.02, (-0.02, -0.02))
    group = RobotGroupConfig(count=n, radius_m=0.08, max_v_mps=0.2, controller=spec, sensors=(ProximityConfig(),))
    return Simulation(grid, SimConfig(robots=(group,), seed=seed, record_every=1_000_000,
                                      radio=RadioConfig(mode="range", range_m=1.0)))


def _module(spec: str):
    import sys

    return sys.modules[registry.lookup(spec).__module__]


def test_refilled_observations_say_what_new_ones_say(brains):
    """A team whose brains keep nothing (refilled objects) sees exactly what a team whose
    brains keep everything (new objects every step) sees, messages included."""
    refilled, fresh = _sim(brains + ":Snap", 6), _sim(brains + ":KeepAll", 6)
    mod = _module(brains + ":Snap")
    mod.SEEN.clear()
    refilled.run(40)
    a = list(mod.SEEN)
    mod.SEEN.clear()
    fresh.run(40)
    b = list(mod.SEEN)
    assert len(a) == len(b) == 6 * 41  # step 0 and 40 steps
    assert any(row[10] for row in a)  # some inboxes carry messages
    assert any(row[9] for row in a)  # some robots stalled (they drive into walls and each other)
    for x, y in zip(a, b):
        assert x[1:3] == y[1:3]
        assert x[3] == y[3] and x[8:14] == y[8:14]
        for u, v in zip(x[4:8], y[4:8]):
            np.testing.assert_array_equal(u, v)
    # The team that keeps nothing was handed the same Observation object every step, the other
    # a new one each step.
    for robot in range(6):
        assert len({row[14] for row in a if row[1] == robot}) == 1
    assert len({id(o) for o in fresh.brains[0][0].all}) == 41


def test_what_a_brain_keeps_stays_as_it_was(brains):
    mod = _module(brains + ":Keeper")
    mod.KEPT.clear()
    mod.SEEN.clear()
    sim = _sim(brains + ":Keeper", 12)
    sim.run(30)
    assert {r for r, *_ in mod.KEPT} == {1, 2, 3, 4, 7, 8, 9, 10}
    for robot, step, held, copy in mod.KEPT:
        now = mod._copy(held)
        if isinstance(copy, tuple) and len(copy) == 7:  # an Observation
            assert held.step == step and now[0:2] == copy[0:2] and now[5:] == copy[5:]
            for u, v in zip(now[2:4], copy[2:4]):
                np.testing.assert_array_equal(u, v)
            np.testing.assert_array_equal(now[4]["proximity"][0], copy[4]["proximity"][0])
        elif isinstance(copy, dict):
            assert set(now) == set(copy) == {"proximity"}
            np.testing.assert_array_equal(now["proximity"][0], copy["proximity"][0])
        elif isinstance(copy, tuple):
            np.testing.assert_array_equal(now[0], copy[0])
            assert now[1:] == copy[1:]
        else:
            np.testing.assert_array_equal(now, copy)
    # Each step's observation of a robot that keeps something is a new object; the one that
    # added a key to its dict still gets only its sensor's scan.
    for robot in range(12):
        ids = [row[14] for row in mod.SEEN if row[1] == robot]
        assert len(ids) == 31
        if robot % 6 in (0, 4):
            assert len(set(ids)) == 1
        else:
            assert all(a != b for a, b in zip(ids, ids[1:]))
    assert all(row[13] == ["proximity"] for row in mod.SEEN)
