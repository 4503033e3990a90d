"""Beyond the papers, combination 4: ``los-trail-explorer-v1``, R1 with a Trail of its goals' viewpoints
(teamnav.papers.beyond.brains.trail_memory): where crumbs are laid, which one R1 heads for, that
``goal_memory: "off"`` is ``los-explorer-v1`` exactly, and that bad values are refused."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from teamnav.control import Observation, RangeScan, RobotInfo, SensorInfo
from teamnav.papers.beyond.brains.trail_memory import LosTrailExplorer, place_name
from teamnav.papers.los_help.brains import LosExplorer
from teamnav.papers.los_help.brains import brain as brain_mod
from teamnav.geometry import wrap_angle

N_BEAMS = 360
ANGLES = np.linspace(-np.pi, np.pi, N_BEAMS, endpoint=False)
MAX_RANGE = 8.0


class StraightNav:
    """Algorithm A stand-in: heads straight at its goal and records the goals it was given."""

    def __init__(self) -> None:
        self.goal = None
        self.progressing = True
        self.calls: list[tuple[tuple[float, float], bool]] = []

    def set_goal(self, goal_xy, temporary: bool = False) -> None:
        self.goal = np.asarray(goal_xy, dtype=float)
        self.calls.append((tuple(self.goal.tolist()), bool(temporary)))

    def direction(self, pose, scan):
        return None if self.goal is None else math.atan2(self.goal[1] - pose[1], self.goal[0] - pose[0])


@pytest.fixture
def navs(monkeypatch):
    made: list[StraightNav] = []

    def make(name, params, *, rng, step_length_m, radius_m):
        made.append(StraightNav())
        return made[-1]

    monkeypatch.setattr(brain_mod, "make_navigator", make)
    return made


def info() -> RobotInfo:
    return RobotInfo(0, 1, 0.2, "holonomic_step", 0.5, 1.5, 0.1, 0.1,
                     sensors={"laser": SensorInfo("laser", "laser", ANGLES, MAX_RANGE)})


def obs(step, pose=(0.0, 0.0), walls=()) -> Observation:
    """Free to 8 m except ``walls``: (bearing_rad, half_width_rad, range_m), bearings in the world
    (the robot's heading is 0)."""
    r = np.full(N_BEAMS, MAX_RANGE)
    for b, hw, rng in walls:
        r[np.abs(wrap_angle(ANGLES - b)) <= hw] = rng
    return Observation(0, step, 0.1 * step, np.array([pose[0], pose[1], 0.0]), np.zeros(3),
                       scans={"laser": RangeScan(r, ANGLES.copy(), MAX_RANGE)})


def brain(**kw) -> LosTrailExplorer:
    p = LosTrailExplorer.Params(**{"targets_xy": [(6.0, 0.0)], "goal_memory": "trail", **kw})
    return LosTrailExplorer(p, np.random.default_rng(0), info())


def towards(a, b) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])


def test_a_crumb_is_laid_only_where_the_goal_is_in_view_with_its_straight_distance(navs):
    r = brain()
    r.step(obs(0, (0.0, 0.0)))  # goal in view: a crumb here, s = 6 m
    hidden = [(towards((0.0, 1.0), (6.0, 0.0)), 0.05, 2.0)]
    r.step(obs(1, (0.0, 1.0), hidden))  # a wall 2 m away along the goal's bearing: none
    r.step(obs(2, (0.1, 0.0)))  # in view again but within the spacing of the first: none
    r.step(obs(3, (0.0, -1.0)))  # in view, 1 m away: a second crumb
    assert r.trail.crumb_xy_m.tolist() == [[0.0, 0.0], [0.0, -1.0]]
    assert r.trail.crumb_s.tolist() == pytest.approx([6.0, math.hypot(6.0, 1.0)])
    assert r.trail.crumb_place == [place_name((6.0, 0.0))] * 2
    assert r.trail.crumb_t.tolist() == [0.0, 3.0]


def test_off_lays_nothing_and_drives_with_a_like_los_explorer(navs):
    r = brain(goal_memory="off")
    r.step(obs(0))
    hidden = [(towards((0.0, 3.0), (6.0, 0.0)), 0.05, 2.0)]
    r.step(obs(1, (0.0, 3.0), hidden))
    assert len(r.trail) == 0 and r.mode == "own_goal" and navs[0].calls[-1] == ((6.0, 0.0), False)
    assert "memory_crumbs" not in r.log()


def test_out_of_sight_r1_heads_for_the_crumb_with_the_shortest_d(navs):
    r = brain()
    for k, xy in enumerate([(0.0, 0.0), (2.0, -4.0), (0.0, 2.0)]):
        r.step(obs(k, xy))
    # from (-2, 2) the goal is hidden; crumbs at (0,0) D = 2.83 + 6, (0,2) D = 2 + 6.32 (shortest),
    # (2,-4) D = 7.2 + 5.66
    me = (-2.0, 2.0)
    a, _ = r.step(obs(3, me, [(towards(me, (6.0, 0.0)), 0.05, 2.0)]))
    assert r.mode == "memory"
    assert a.direction_rad == pytest.approx(towards(me, (0.0, 2.0)))
    assert r.log()["memory_steps"] == 1


def test_a_crumb_out_of_sight_is_not_headed_for_unless_reach_any(navs):
    for reach, mode in (("visible", "own_goal"), ("any", "memory")):
        r = brain(goal_memory_reach=reach)
        r.step(obs(0, (0.0, 0.0)))
        me = (-2.0, 2.0)
        # the goal and the crumb at (0, 0) both behind walls
        r.step(obs(1, me, [(towards(me, (6.0, 0.0)), 0.05, 1.0), (towards(me, (0.0, 0.0)), 0.05, 1.0)]))
        assert r.mode == mode


def test_only_in_trouble_uses_the_memory_only_when_tr_is_set(navs):
    r = brain(goal_memory_when="trouble")
    r.step(obs(0))
    me = (-2.0, 2.0)
    r.step(obs(1, me, [(towards(me, (6.0, 0.0)), 0.05, 2.0)]))
    assert r.mode == "own_goal"
    r.trouble.tr = True
    r.step(obs(2, me, [(towards(me, (6.0, 0.0)), 0.05, 2.0)]))
    assert r.mode == "memory"


def test_a_crumb_reached_without_the_goal_in_view_is_dropped_for_that_target(navs):
    r = brain()
    r.step(obs(0, (0.0, 0.0)))
    # back on the crumb, but now something hides the goal from it: the crumb is dropped, A drives
    r.step(obs(1, (0.05, 0.0), [(0.0, 0.05, 2.0)]))
    assert r.mode == "own_goal" and r.log()["memory_dropped"] == 1
    assert navs[0].calls[-1] == ((6.0, 0.0), False)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)), min_size=1, max_size=8),
       st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)))
def test_choose_crumb_is_the_shortest_d_through_a_crumb_in_view(crumbs, me):
    """In open space every crumb within 8 m is in view: the choice is the argmin of
    dist(me, crumb) + dist(crumb, goal), §4.3's D through a ghost."""
    # a crumb R1 stands on (within ghost_tolerance_m) is dropped at that step: not one of those
    assume(all(math.hypot(x - me[0], y - me[1]) > 0.25 for x, y in crumbs))
    goal = (12.0, 0.0)  # beyond the 8-m view: R1 lays no crumb of its own here
    r = LosTrailExplorer(LosTrailExplorer.Params(targets_xy=[goal], goal_memory="trail"),
                         np.random.default_rng(0), info())
    name = place_name(goal)
    r.trail.add_crumbs([name] * len(crumbs), crumbs, [math.hypot(goal[0] - x, goal[1] - y) for x, y in crumbs],
                       [0.0] * len(crumbs))
    r.step(obs(0, me))
    assert len(r.trail) == len(crumbs)
    i, seen = r.choose_crumb(goal)
    d = [math.hypot(x - me[0], y - me[1]) + math.hypot(goal[0] - x, goal[1] - y) for x, y in crumbs]
    assert seen and d[i] == pytest.approx(min(d), abs=1e-9)


def test_bad_values_are_refused_naming_the_field():
    with pytest.raises(ValidationError, match=r"goal_memory\n.*'off' or 'trail'"):
        LosTrailExplorer.Params(goal_memory="on")
    with pytest.raises(ValidationError, match=r"goal_memory_reach\n.*'visible' or 'any'"):
        LosTrailExplorer.Params(goal_memory_reach="all")
    with pytest.raises(ValidationError, match=r"goal_memory_spacing_m\n.*greater than 0"):
        LosTrailExplorer.Params(goal_memory_spacing_m=0.0)


def test_memory_off_runs_exactly_as_los_explorer_v1():
    """The same scenario with either brain (goal_memory off): identical metrics and logs."""
    from teamnav.papers.los_help import tasks as L
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario

    targets = [list(map(float, p)) for p in L.task_targets_xy("complex", 1, 2)]
    out = []
    for ctrl in ("los-explorer-v1", "los-trail-explorer-v1"):
        ov = {"robots.0.params.targets_xy": targets, "robots.0.controller": ctrl, "robots.2.count": 0,
              "robots.3.count": 0, "robots.0.params.navigator": "avoid_past"}
        res = run(load_scenario("los-help-complex", overrides=ov), progress=False)
        out.append(({k: v for k, v in res.metrics.items() if "wall" not in k and "cpu" not in k}, res))
    assert out[0][0] == out[1][0]
    logs = [[(e.get("robot"), e.get("step"), e.get("values")) for e in res.data.logs] for _, res in out]
    assert repr(logs[0]) == repr(logs[1])
    assert out[0][0]["los_targets_reached"] >= 1


@pytest.mark.parametrize("places, want", [("task", 2), ("current", 1)])
def test_task_places_remember_a_later_target_seen_on_the_way(navs, places, want):
    r = brain(targets_xy=[(6.0, 0.0), (0.0, 5.0)], goal_memory_places=places)
    r.step(obs(0))  # both targets in view from the start
    assert len(r.trail) == want
    assert sorted(r.trail.crumb_place) == sorted(place_name(t) for t in [(6.0, 0.0), (0.0, 5.0)][:want])


# ---------------------------------------------------------------------------- the report block
def test_the_sweep_has_every_case_the_block_reads_and_ten_tasks():
    from teamnav.papers.los_help import tasks as L
    from teamnav.papers.beyond.report import _beyond_trail_memory as B
    from teamnav.experiments.sweep import expand, load_sweep

    spec = load_sweep(B.SWEEP)
    cases = {str(c["case"]) for c in spec.cases}
    assert cases == {f"{n}/{t}/{m}" for n, _ in B.NAVS for t, _ in B.TEAMS for m in ("off", "trail")}
    grid = spec.grid[B.TARGETS_KEY]
    assert [list(map(list, g)) for g in grid] == [
        [[round(float(x), 3), round(float(y), 3)] for x, y in L.task_targets_xy("complex", k, 30)] for k in range(1, 11)]
    trials = {(str(t.params["case"]), json.dumps(t.params[B.TARGETS_KEY])): t for t in expand(spec)}
    assert len(trials) == 120
    sc = next(t for (c, _), t in trials.items() if c == "avoid-past/R1-4/trail").load()
    assert sc.robots[0].controller == "los-trail-explorer-v1" and sc.robots[0].params["goal_memory"] == "trail"
    assert [g.count for g in sc.robots] == [1, 1, 1, 1]


def test_each_claim_reads_only_metrics_the_block_computes():
    from teamnav.experiments.claims import load_claims
    from teamnav.papers.beyond.report import _beyond_trail_memory as B

    row = {"los_targets_reached": 3.0, "los_steps_per_target": 100.0, "los_finished": 0}
    vals = B.claim_values({f"{n}/{t}/{m}": {1: row, 2: row} for n, _ in B.NAVS for t, _ in B.TEAMS
                           for m in ("off", "trail")})
    for cid in ("trail-memory-r1", "trail-memory-helpers"):
        claim = load_claims("beyond")[cid]
        for cond in claim.rule:
            assert cond.metric in vals and (cond.relative_to is None or cond.relative_to in vals)
    assert vals["reached_gain_lo_ap_r1"] == 0.0 and vals["spt_r14_ratio_max"] == 1.0


def test_claim_values_pair_by_task():
    from teamnav.papers.beyond.report import _beyond_trail_memory as B

    def r(reached, spt):
        return {"los_targets_reached": reached, "los_steps_per_target": spt, "los_finished": int(reached == 30)}

    cases = {"avoid-past/R1/off": {1: r(10, 900.0), 2: r(20, 700.0), 3: r(30, 500.0)},
             "avoid-past/R1/trail": {1: r(14, 800.0), 2: r(22, 600.0), 3: r(30, 400.0)}}
    for n, _ in B.NAVS:
        cases[f"{n}/R1-4/off"] = {1: r(30, 400.0)}
        cases[f"{n}/R1-4/trail"] = {1: r(30, 420.0 if n == "visbug21" else 300.0)}
    v = B.claim_values(cases)
    gains = np.array([4.0, 2.0, 0.0])  # paired by task
    assert v["reached_gain_lo_ap_r1"] == pytest.approx(gains.mean() - 2.0 * gains.std(ddof=1) / math.sqrt(3))
    assert v["spt_ap_r1_trail_mean"] == pytest.approx(600.0) and v["spt_ap_r1_off_mean"] == pytest.approx(700.0)
    assert v["spt_r14_ratio_max"] == pytest.approx(1.05)


def test_a_row_of_an_unknown_task_is_named():
    from teamnav.papers.beyond.report import _beyond_trail_memory as B

    with pytest.raises(ValueError, match="robots.0.params.targets_xy: a row's target list is not one of the 1 tasks"):
        B.per_task([{B.TARGETS_KEY: [[1.0, 2.0]]}], [[[0.0, 0.0]]])


def test_full_mode_reads_every_case_and_judges_both_claims():
    from _report_fakes import FakeFullContext

    from teamnav.experiments.report.model import Comparison, Table
    from teamnav.papers.beyond.report import _beyond_trail_memory as B

    def rows_for(spec, seeds):
        out = []
        for c in spec.cases:
            for k, targets in enumerate(spec.grid[B.TARGETS_KEY]):
                mem = c["case"].endswith("/trail")
                out.append({"status": "ok", "params": {"case": c["case"], B.TARGETS_KEY: targets}, "seed": 0,
                            B.TARGETS_KEY: json.dumps(targets), "los_targets_reached": 30 if mem else 20 + k % 3,
                            "los_finished": int(mem), "los_steps_per_target": 500.0 - 10.0 * k - (100.0 if mem else 0.0)})
        return out

    ctx = FakeFullContext(rows_for)
    blocks = B.trail_memory(ctx)
    assert [a[:2] for a in ctx.asked] == [(B.SWEEP, [0])]
    (table,) = [b for b in blocks if isinstance(b, Table)]
    assert len(table.rows) == 6
    assert table.rows[2][2] == "209/300 (0/10)" and table.rows[2][3] == "300/300 (10/10)"
    assert table.rows[2][7].startswith("-100 ± 0") and "beyond 2 s.e." in table.rows[2][6]
    verdicts = [b for b in blocks if isinstance(b, Comparison)]
    assert [v.holds for v in verdicts] == [True, True]


def test_quick_mode_runs_avoid_past_alone_with_and_without_memory(tmp_path):
    from teamnav.experiments.report.context import SweepContext
    from teamnav.experiments.report.model import Comparison, Table
    from teamnav.papers.beyond.report import _beyond_trail_memory as B

    blocks = B.trail_memory(SweepContext(tmp_path, quick=True, workers=1, section="beyond"))
    (table,) = [b for b in blocks if isinstance(b, Table)]
    assert [r[:2] for r in table.rows] == [["Avoid-Past", "R1 alone"]]
    assert table.rows[0][2].endswith("/8 (1/1)") or table.rows[0][2].endswith("/8 (0/1)")
    assert all(v.holds is None for v in blocks if isinstance(v, Comparison))


def test_a_sweep_cut_short_is_shown_but_not_judged():
    from _report_fakes import FakeFullContext

    from teamnav.experiments.report.model import Comparison
    from teamnav.papers.beyond.report import _beyond_trail_memory as B

    def rows_for(spec, seeds):
        targets = spec.grid[B.TARGETS_KEY][0]  # task 1 only
        return [{"status": "ok", "params": {"case": c["case"]}, B.TARGETS_KEY: json.dumps(targets),
                 "los_targets_reached": 30, "los_finished": 1, "los_steps_per_target": 400.0} for c in spec.cases]

    blocks = B.trail_memory(FakeFullContext(rows_for))
    verdicts = [b for b in blocks if isinstance(b, Comparison)]
    assert [v.holds for v in verdicts] == [None, None]
    assert all("not judged: only 12 of the 120 runs finished" in v.ours for v in verdicts)
