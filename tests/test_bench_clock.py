"""``benchmarks/_common.clock_brains``: the benchmarks' CPU clock on the brains counts a group
team's robots once (through ``step_group``), and every robot's ``step`` without group brains."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from teamnav import load_scenario
from teamnav.experiments.spec import build_grid
from teamnav.sim.engine import Simulation

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from _common import clock_brains, unclock_brains  # benchmarks/_common.py


@pytest.mark.parametrize("group_brains", [False, True], ids=["per-robot", "group"])
def test_clock_counts_a_group_teams_robots_once(group_brains):
    # global crumbs that expire (the first group): the group brain runs those robots' reference step
    scn = load_scenario("blazing-a-trail", duration_s=3.0, seed=1000,
                        overrides={"robots.0.params.global_crumb_ttl_s": 600.0})
    sim = Simulation(build_grid(scn), scn, group_brains=group_brains)
    robots = [b for g in sim.brains for b in g]
    calls = {"step": 0}
    if group_brains:  # below TEAM_MIN the team's per-robot faces are the reference brains it steps
        assert len(sim.group_teams) == 1
        team = sim.group_teams[0][0]
        assert not team._team and not all(team._fast)
        orig = type(robots[0]).step

        def counted(self, obs):
            calls["step"] += 1
            return orig(self, obs)

        type(robots[0]).step = counted  # the reference steps, however they are reached
    try:
        brain_s, wrapped = clock_brains(sim, ("step", "log"))
        want = {(id(b), m) for b in robots for m in (("log",) if group_brains else ("step", "log"))}
        if group_brains:
            want.add((id(team), "step_group"))
        assert {(id(o), m) for o, m in wrapped} == want
        sim.run(10)
        assert brain_s[0] > 0.0
        if group_brains:  # the reference steps ran, inside step_group, and no clock wraps them
            assert calls["step"] > 0 and all("step" not in vars(b) for b in robots)
        unclock_brains(wrapped)
        assert all("log" not in vars(b) and "step" not in vars(b) for b in robots)
    finally:
        if group_brains:
            type(robots[0]).step = orig
