"""The engine's array path for a compiled team (``Simulation._step_team_fast``,
``Detector._detect_groups_padded``, ``SharedSensing.blocks``): the group brain's observation
is, field by field and byte for byte, the one the general path builds from each group's
readings and Detection tuples; the path is taken only where nothing else reads those (no
faults, no recorded scans).

Scenarios: R1..R4 of the line-of-sight help system (Sgorbissa & Arkin, Tables 1-2's team on
office_simple, tuning task 1001, with and without the §6.1 detector noise) and the four robots
of Vaughan et al. 2000 (``blazing-a-trail``, tuning seed 1000).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from teamnav import load_scenario
from teamnav.experiments.spec import build_grid
from teamnav.papers.los_help.tasks import task_targets_xy, team_overrides
from teamnav.sim.engine import Simulation

STEPS = 400


def _los(err_max: float = 0.0, **extra):
    ov = dict(team_overrides("simple", 3))
    ov["robots.0.params.targets_xy"] = task_targets_xy("simple", 1001)
    ov["robots.0.params.navigator"] = "visbug21"
    if err_max:
        for k in range(4):
            ov[f"robots.{k}.detector.err_max"] = err_max
    ov.update(extra)
    return load_scenario("los-help-simple", overrides=ov, duration_s=STEPS * 0.1, seed=0)


def _trail(**extra):
    return load_scenario("blazing-a-trail", overrides=dict(extra), duration_s=STEPS * 0.1, seed=1000)


def _general(sim: Simulation) -> None:
    """Send every team down the general path (per-group readings, Detection tuples)."""
    sim._padded_sets = None
    for g in sim._groups:
        g.team_fast = None
        g.padded_det = -1
        g.team_blocks = {}


def _ser(o):
    """A comparable form of an observation field: arrays as (dtype, shape, bytes), NaN-safe."""
    if isinstance(o, np.ndarray):
        return (o.dtype.str, o.shape, o.tobytes())
    if dataclasses.is_dataclass(o) and not isinstance(o, type):
        return (type(o).__name__, tuple((f.name, _ser(getattr(o, f.name))) for f in dataclasses.fields(o)))
    if isinstance(o, dict):
        return ("dict", tuple((k, _ser(v)) for k, v in o.items()))
    if isinstance(o, (tuple, list)):
        return (type(o).__name__, tuple(_ser(v) for v in o))
    if isinstance(o, float) and o != o:
        return ("nan",)
    return o


def _observations(sim: Simulation, steps: int) -> list:
    seen = []
    for team, *_ in sim.group_teams:
        inner = team.step_group

        def spy(obs, inner=inner):
            seen.append(_ser(obs))
            return inner(obs)

        team.step_group = spy
    for _ in range(steps):
        sim.step()
    return seen


@pytest.mark.parametrize("scn", [_los(), _los(0.4), _trail()], ids=["los-team", "los-team-err0.4", "blazing-a-trail"])
def test_team_array_path_equals_general_path(scn):
    fast = Simulation(build_grid(scn), scn, group_brains=True)
    assert fast.group_teams and all(g.team_fast is not None for g in fast._groups), "the array path is not taken"
    slow = Simulation(build_grid(scn), scn, group_brains=True)
    _general(slow)
    a, b = _observations(fast, STEPS), _observations(slow, STEPS)
    assert len(a) == len(b) == STEPS + 1  # step 0's decision, then one per step
    for k, (ra, rb) in enumerate(zip(a, b)):
        assert ra == rb, f"step {k}: the group brain's observations differ"
    for x, y in ((fast.state.x_m, slow.state.x_m), (fast.odometry.pose, slow.odometry.pose)):
        assert x.tobytes() == y.tobytes()


def test_team_array_path_off_where_tuples_are_read():
    """Recorded scans (the recorder draws each detection) keep the general path."""
    scn = _los(**{"record_scans": True})
    sim = Simulation(build_grid(scn), scn, group_brains=True)
    assert sim.group_teams and all(g.team_fast is None and g.padded_det == -1 for g in sim._groups)
