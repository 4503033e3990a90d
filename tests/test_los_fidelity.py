"""Line-of-sight help, the paper column as Sgorbissa & Arkin ran it: the artifact fixes both
columns share (a ghost the navigator calls unreachable is dropped, a teammate seen when it sent
its Tr bit is a candidate) and the paper column's visible-only chase of a trouble helper (§5)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from teamnav.control import Detection, Message, Observation, RangeScan, RobotInfo, SensorInfo
from teamnav.papers.los_help.brains import LosExplorer
from teamnav.papers.los_help.brains.explorer_params import LosExplorerParams
from teamnav.papers.los_help.brains.goal_sharing import goal_id
from teamnav.papers.los_help.brains.messages import MESSAGE_KIND, LosHelpMsg, Sighting, VisReport
from teamnav.world import MapBuilder
from teamnav.world.raycast import RayCaster
from teamnav.control.nav.local.visbug21 import MODE_UNREACHABLE
from test_nav_local import disc_free

N_BEAMS = 360
ANGLES = np.linspace(-np.pi, np.pi, N_BEAMS, endpoint=False)
MAX_RANGE = 8.0
STEP_M = 0.1
RADIUS_M = 0.2


def _info(team_size: int = 2) -> RobotInfo:
    laser = SensorInfo("laser", "laser", ANGLES, MAX_RANGE)
    return RobotInfo(0, team_size, RADIUS_M, "holonomic_step", 0.5, 1.5, STEP_M, 0.1, sensors={"laser": laser})


def _polar(a, b):
    return math.hypot(b[0] - a[0], b[1] - a[1]), math.atan2(b[1] - a[1], b[0] - a[0])


class _World:
    """R1 alone on a small grid (its odometry frame is the map's, heading 0, holonomic steps);
    teammates exist only as the detections and messages a test hands it."""

    def __init__(self, grid, start_xy, brain):
        self.grid, self.brain = grid, brain
        self.caster = RayCaster(grid, max_range_m=MAX_RANGE)
        self.xy = np.array(start_xy, float)
        self.k = 0
        self.stood = 0  # steps in a row without a move command

    def step(self, *, seen=(), inbox=()):
        pose = np.array([self.xy[0], self.xy[1], 0.0])
        ranges = self.caster.cast(pose[None], ANGLES, parallel=False)[0]
        dets = tuple(Detection(float(r), float(b), int(i)) for i, r, b in seen)
        ob = Observation(0, self.k, 0.1 * self.k, pose, np.zeros(3), scans={"laser": RangeScan(ranges, ANGLES.copy(), MAX_RANGE)},
                         detections=dets, stalled=False, inbox=tuple(inbox))
        action, _ = self.brain.step(ob)
        self.k += 1
        if action.direction_rad is None:
            self.stood += 1
            return action
        self.stood = 0
        new = self.xy + STEP_M * np.array([math.cos(action.direction_rad), math.sin(action.direction_rad)])
        if disc_free(self.grid, new, RADIUS_M):
            self.xy = new
        return action


def _ghost_behind_a_wall_line(drop: bool, paper_rules: bool = True):
    """A 14 x 10 m room, closed at x = 10.5 (R1's goal lies beyond, out of sight), with a closed
    4 x 4 m box in R1's way. R2, seen from R1's start, promises a D from (7.5, 5.0), a point
    that no path reaches (the trace's ghost stood 0.11 m from a wall line, where our robot's
    body cannot stand; here the wall line closes round it, so that VisBug-21's Bug2 test
    decides within a few hundred steps). R2 then leaves R1's sight: a ghost."""
    grid = (MapBuilder(14.0, 10.0, 0.1).border(0.2).rect(6.0, 3.0, 9.0, 7.0, filled=False, thickness_m=0.2)
            .rect(10.5, 0.0, 10.8, 10.0).build("ghost_behind_a_wall_line"))
    start, r2, goal = (2.0, 5.0), (7.5, 5.0), (12.5, 5.0)
    params = LosExplorerParams(targets_xy=[goal], navigator="visbug21", paper_rules=paper_rules,
                               visibility_radius_m=MAX_RANGE, drop_unreachable_ghost=drop, state_sharing=False)
    world = _World(grid, start, LosExplorer(params, np.random.default_rng(0), _info()))
    d, b = _polar(start, r2)
    world.step(seen=[(1, d, b)])
    back = LosHelpMsg(0, (Sighting(0, math.atan2(start[1] - r2[1], start[0] - r2[0]), d),), (),
                      (VisReport(0, goal_id(1, 2), 5.1),), None)
    world.step(seen=[(1, d, b)], inbox=[Message(1, 0.0, back, kind=MESSAGE_KIND)])
    path = world.brain.sharing.path(0)
    assert path is not None and not path.reached
    assert math.dist((path.px_m, path.py_m), r2) < 1e-6, "the ghost is R2's position as R1 saw it"
    return world


def test_a_ghost_visbug_calls_unreachable_freezes_r1_in_the_paper_column_unless_dropped():
    """The frozen ghost, reproduced with VisBug-21 as the paper column runs it (one fixed turn,
    no gap-fill dropping a stalled ghost): VisBug walks round the wall line to the ghost and
    declares it unreachable (Bug2's test); without the fix R1 then stands still for good, the
    ghost kept (§4.2: headed for until reached or replaced). With it the ghost is dropped as a
    reached one, at the step A gave up, and A drives R1 on towards its own goal."""
    world = _ghost_behind_a_wall_line(drop=False)
    for _ in range(1500):
        world.step()
        if world.stood >= 300:
            break
    assert world.stood >= 300 and not world.brain.sharing.path(0).reached
    assert world.brain._nav.mode == MODE_UNREACHABLE and world.brain.mode == "ghost"
    gave_up_at = world.k - world.stood

    fixed = _ghost_behind_a_wall_line(drop=True)
    for _ in range(1500):
        fixed.step()
        if fixed.brain.ghosts_unreachable:
            break
    assert fixed.brain.ghosts_unreachable == 1 and fixed.brain.sharing.path(0).reached
    assert fixed.brain.log()["ghosts_unreachable"] == 1
    assert fixed.k - 1 <= gave_up_at + 1  # dropped at the step A gave up, not later
    moves = fixed.brain.moves
    for _ in range(20):
        fixed.step()
    assert fixed.brain.moves == moves + 20 and fixed.brain.mode == "own_goal" and fixed.stood == 0


def test_the_ghost_fix_is_in_both_columns_and_not_a_paper_rule():
    assert LosExplorerParams().drop_unreachable_ghost and LosExplorerParams(paper_rules=True).drop_unreachable_ghost
    assert "drop_unreachable_ghost" not in LosExplorerParams.PAPER_RULES
    assert "drop_unreachable_ghost" in LosExplorerParams.ARTIFACT_FIXES


# ---------------------------------------------------------------------------- §5 rule 3, both columns
def _trapped_r1(monkeypatch, paper_rules: bool):
    """R1 whose navigator never progresses (``test_los_trouble``'s set-up), in either column."""
    from test_los_help import StraightNav, info

    from teamnav.papers.los_help.brains import brain as brain_mod

    stuck = StraightNav(stuck=True)
    monkeypatch.setattr(brain_mod, "make_navigator", lambda *a, **k: stuck)
    extra = {} if paper_rules else {"trouble_helper_towards_goal": False}
    return LosExplorer(LosExplorer.Params(targets_xy=[(6.0, 0.0)], trouble_cr=3, goal_sharing=False,
                                          paper_rules=paper_rules, **extra),
                       np.random.default_rng(0), info(0, 2))


@pytest.mark.parametrize("paper_rules", [True, False])
def test_a_teammate_seen_when_it_sent_its_tr_bit_is_a_candidate_in_both_columns(monkeypatch, paper_rules):
    """The radio's one-step delay is ours: R2 seen for one step (step 3) sends Tr = false at 3,
    the bit arrives at 4 when R2 is out of sight again; in both columns R1 heads for where it saw
    R2 (it was in V(R_1) when it shared its state, §5)."""
    from test_los_help import msg, obs

    wall = [(0.0, 0.1, 0.5)]
    r1 = _trapped_r1(monkeypatch, paper_rules)
    assert r1.params.trouble_sighting_at_send
    for k in range(3):
        r1.step(obs(k, walls=wall))
    assert r1.trouble.tr
    r1.step(obs(3, walls=wall, seen=[(1, 3.0, math.pi / 2)]))
    a, _ = r1.step(obs(4, walls=wall, inbox=[msg(1, 3, trouble=False)]))
    assert r1.mode == "trouble_follow" and a.direction_rad == pytest.approx(math.pi / 2)


@pytest.mark.parametrize("paper_rules", [True, False])
def test_the_paper_column_follows_a_trouble_helper_only_while_it_is_in_sight(monkeypatch, paper_rules):
    """§5 rule 3: the teammate R1 heads to is one in V(R_1). R2 is followed while seen; once it
    is out of sight (and no Tr bit pairs it with a sighting) the paper column lets it go and A
    drives again, still in trouble; teamnav's gap-fill ``keep_trouble_helper`` keeps heading
    for R2's last seen position."""
    from test_los_help import msg, obs

    wall = [(0.0, 0.1, 0.5)]
    r1 = _trapped_r1(monkeypatch, paper_rules)
    assert r1.params.keep_trouble_helper is (not paper_rules)
    k = 0
    while not r1.trouble.tr:
        r1.step(obs(k, walls=wall))
        k += 1
    r1.step(obs(k, walls=wall, seen=[(1, 3.0, math.pi / 2)]))
    a, _ = r1.step(obs(k + 1, walls=wall, seen=[(1, 3.0, math.pi / 2)], inbox=[msg(1, k, trouble=False)]))
    assert r1.mode == "trouble_follow" and a.direction_rad == pytest.approx(math.pi / 2)
    # the bit of step k + 1 arrives with R2 out of sight: it was seen when it sent it, still a candidate
    r1.step(obs(k + 2, walls=wall, inbox=[msg(1, k + 1, trouble=False)]))
    assert r1.mode == "trouble_follow"
    modes = []
    for j in range(3, 8):  # out of sight, and no bit pairs it with a sighting any more
        a, _ = r1.step(obs(k + j, walls=wall, inbox=[msg(1, k + j - 1, trouble=False)]))
        modes.append(r1.mode)
    assert r1.trouble.tr
    if paper_rules:
        assert set(modes) == {"own_goal"} and a.direction_rad == pytest.approx(0.0)
    else:
        assert set(modes) == {"trouble_follow"} and a.direction_rad == pytest.approx(math.pi / 2)


# ---------------------------------------------------------------------------- the fills' rules
def test_half_life_rule_takes_the_longest_value_that_finishes_every_tuning_task_and_must_bracket_it():
    from teamnav.papers.los_help.tasks import HALF_LIFE_GRID, choose_half_life

    grid = HALF_LIFE_GRID
    # a value fails at its first unfinished task; the longest value finishing all 5 wins
    got = {4000.0: (0, 1), 2000.0: (2, 3), 1000.0: (0, 1), 500.0: (4, 5), 250.0: (5, 5), 125.0: (5, 5), None: (0, 1)}
    assert choose_half_life(got, grid) == 250.0
    with pytest.raises(ValueError, match="extend the grid up"):
        choose_half_life({h: (5, 5) for h in grid}, grid)
    with pytest.raises(ValueError, match="extend the grid down"):
        choose_half_life({**{h: (0, 1) for h in grid}, grid[0]: (5, 5)}, grid)
    with pytest.raises(ValueError, match="not run"):
        choose_half_life({250.0: (5, 5), 4000.0: (0, 1)}, grid)
    with pytest.raises(ValueError, match="no half-life"):
        choose_half_life({h: (4, 5) for h in grid}, grid)
    # four of five finished is not "every tuning task"
    assert choose_half_life({**{h: (0, 1) for h in grid}, 64.0: (5, 5), 125.0: (4, 5), 32.0: (5, 5)}, grid) == 64.0


def test_turn_rule_counts_finished_tasks_first_then_steps_then_keeps_left():
    from teamnav.papers.los_help.tasks import choose_turn

    assert choose_turn({"left": {1: None, 2: 500.0}, "right": {1: 900.0, 2: 800.0}}) == "right"
    assert choose_turn({"left": {1: 400.0, 2: 500.0}, "right": {1: 300.0, 2: None}}) == "left"
    assert choose_turn({"left": {1: 400.0, 2: 500.0}, "right": {1: 300.0, 2: 590.0}}) == "right"
    assert choose_turn({"left": {1: 400.0}, "right": {1: 400.0}}) == "left"
    with pytest.raises(ValueError, match="both turns"):
        choose_turn({"left": {1: 1.0}})


@pytest.mark.parametrize("navigator", ["visbug21", "avoid_past"])
def test_the_tuning_sweeps_run_r1_with_the_paper_columns_settings(navigator):
    """The tuning runs set the paper column's values explicitly (a fill under test cannot ride on
    ``paper_rules: true``, which refuses a second value): with the rules' own values they are the
    paper column exactly."""
    from teamnav.control.nav.local import NAVIGATORS
    from teamnav.papers.los_help.tasks import paper_column_r1

    sets = paper_column_r1(navigator)
    params = {k.removeprefix("robots.0.params."): v for k, v in sets.items()}
    explicit = LosExplorerParams(**params)
    ruled = LosExplorerParams(paper_rules=True, navigator=navigator)
    for field in LosExplorerParams.model_fields:
        if field in ("paper_rules", "navigator_params"):
            continue
        assert getattr(explicit, field) == getattr(ruled, field), field
    nav_cls = NAVIGATORS[navigator].Params
    a, b = nav_cls(**explicit.navigator_params), nav_cls(**ruled.navigator_params)
    assert {f: getattr(a, f) for f in nav_cls.model_fields if f != "paper_rules"} == \
        {f: getattr(b, f) for f in nav_cls.model_fields if f != "paper_rules"}


def test_the_tuning_sweeps_use_tuning_tasks_only():
    from teamnav.experiments.sweep import load_sweep
    from teamnav.papers.los_help import tasks as L

    for name in ("los-avoid-past-half-life", "los-visbug-turn"):
        spec = load_sweep(name)
        assert spec.grid["robots.0.params.targets_xy"] == [L.task_targets_xy("simple", t) for t in L.TUNING_TASKS]
        assert all(t >= 1001 for t in L.TUNING_TASKS)
        for case in spec.cases:
            assert case["robots.1.count"] == case["robots.2.count"] == case["robots.3.count"] == 0


# ---------------------------------------------------------------------------- the ledger
def test_every_quote_of_the_ledger_is_the_papers_own_words():
    from teamnav.papers.los_help.report import _los_ledger as G

    try:
        text = G._paper_text()
    except FileNotFoundError:
        pytest.skip("the paper's text (shared/papers) is not beside this checkout")
    quotes = [q for _s, q in G.QUOTES.values()] + [q for *_x, q in G.STATED_SETUP]
    missing = [q for q in quotes if not G.quote_found(q, text)]
    assert not missing
    assert not G.quote_found("R_j in V(R_i) when R_i reads its Tr bit", text)  # a paraphrase is caught


def test_the_ledger_covers_every_paper_rule_and_artifact_fix_in_the_model_shape():
    from teamnav.control.nav.local import NAVIGATORS
    from teamnav.experiments.report.model import LEDGER_SOURCES, Ledger
    from teamnav.papers.los_help.brains.helper import LosHelperParams
    from teamnav.papers.los_help.report._los_ledger import ledger_blocks, ledger_rows

    rows = ledger_rows()
    paper = {r.name.split(" (")[0]: r for r in rows if r.column == "paper"}
    for key, value in {**LosHelperParams.PAPER_RULES, **LosExplorerParams.PAPER_RULES}.items():
        assert paper[key].value == value and paper[key].source == "stated" and '"' in paper[key].ref, key
    for nav, cls in NAVIGATORS.items():
        for key in cls.Params.PAPER_RULES:
            assert f"navigator_params.{key}" in paper, (nav, key)
    assert paper["navigator_params.turn"].source == "fill" and "tuning tasks 1001-1005" in paper["navigator_params.turn"].ref
    for col in ("paper", "teamnav"):
        mine = {r.name: r for r in rows if r.column == col}
        for key in ("drop_unreachable_ghost", "trouble_sighting_at_send", "restart_navigator_on_give_up"):
            assert mine[key].source == "artifact-fix" and mine[key].value is True, (col, key)
        assert mine["navigator_params.memory_half_life_steps (avoid_past)"].source == "fill"
        assert mine["Avoid-Past memory, lifelong (ablation row)"].source == "literal-ablation"
    assert all(r.source in LEDGER_SOURCES for r in rows)
    blocks = ledger_blocks()
    assert [type(b) for b in blocks] == [Ledger, Ledger]
    assert {r.column for r in blocks[0].rows} == {"paper"} and {r.column for r in blocks[1].rows} == {"teamnav"}
    rec = blocks[0].rows[0].record()
    assert set(rec) == {"column", "name", "value", "source", "ref"}


def test_a_precondition_not_met_reads_so_in_the_paper_column_never_fails(monkeypatch):
    from teamnav.experiments.claims import load_claims
    from teamnav.experiments.report.model import Comparison
    from teamnav.papers.los_help.report import _los_ledger as G
    from teamnav.papers.los_help.report.section import _preconditions_on

    claims = load_claims("los-help")
    comps = [Comparison("Table 1: Av. Past steps fall as helpers are added (R1, R1,2)", "554 -> 257", "x", False,
                        column="paper"),
             Comparison("Table 1: Av. Past steps fall as helpers are added (R1, R1,2)", "554 -> 257", "x", False,
                        column="teamnav"),
             Comparison("Table 1: VisBug steps fall as helpers are added (R1, R1,2)", "840 -> 201", "y", False,
                        column="paper")]
    monkeypatch.setitem(G.PRECONDITIONS, "avoid_past", (False, "3 of 5 tasks finished"))
    monkeypatch.setitem(G.PRECONDITIONS, "visbug21", (True, "5 of 5 tasks finished"))
    out = _preconditions_on(comps, claims)
    assert out[0].holds is None and out[0].differs.startswith("precondition not met") and "3 of 5" in out[0].differs
    assert out[1].holds is False and out[2].holds is False  # teamnav is no verdict; VisBug's precondition holds
    blocks = G.precondition_blocks()
    assert [b.holds for b in blocks] == [False, True] and "table1-avoid-past-falls" in blocks[0].claims


def test_the_units_note_states_the_budget_relative_to_each_maps_longest_path():
    from teamnav.papers.los_help import tasks as L
    from teamnav.papers.los_help.report.section import units_note

    note = units_note()
    for m in L.MAPS:
        k = L.budget_over_longest_leg(m)
        assert 10 < k < 100 and f"({k:.0f} times its longest room-to-room shortest path)" in note
    assert "never judged" in note and "cut to 1/2 and 1/4" in note  # the budget block answers it


def test_every_claim_quotes_the_paper_word_for_word():
    from teamnav.experiments.claims import load_claims
    from teamnav.papers.los_help.report import _los_ledger as G

    try:
        text = G._paper_text()
    except FileNotFoundError:
        pytest.skip("the paper's text (shared/papers) is not beside this checkout")
    assert [c.id for c in load_claims("los-help").claims if not G.quote_found(c.statement.quote, text)] == []


def test_full_mode_runs_the_claim_files_judged_tasks_and_quick_mode_none_of_them():
    from teamnav.experiments.claims import load_claims
    from teamnav.experiments.sweep import load_sweep
    from teamnav.papers.los_help import tasks as L
    from teamnav.papers.los_help.report import section as S

    judged = {t for c in load_claims("los-help").claims for t in c.task_list}
    assert judged == set(L.JUDGED_TASKS) and not judged & set(L.OLD_TASKS) and not judged & set(L.TUNING_TASKS)
    for m in L.MAPS:
        want = [L.task_targets_xy(m, t) for t in L.JUDGED_TASKS]
        assert S._tasks(m, quick=False) == want
        assert S._tasks(m, quick=True) == [L.task_targets_xy(m, 1, S.QUICK_TARGETS)]
    for name in ("los-table1", "los-table2", "los-noise-simple", "los-noise-complex", "los-ablation"):
        grid = load_sweep(name).grid[S.TARGETS_KEY]
        m = "complex" if "table2" in name or "complex" in name else "simple"
        assert grid == [L.task_targets_xy(m, t) for t in L.JUDGED_TASKS], name


def test_the_memory_readings_stand_side_by_side_and_the_fill_is_the_longest_that_finished_all():
    from teamnav.papers.los_help.report._los_ledger import MEMORY_READINGS, memory_readings_block
    from teamnav.papers.los_help.tasks import choose_half_life

    got = {}
    for name, fin, _steps, _where in MEMORY_READINGS:
        if name.startswith("half-life"):
            k, n = map(int, fin.split("/"))
            got[float(name.split()[1])] = (k, n)
    assert choose_half_life(got) == 1000.0  # the printed readings give the printed fill
    assert {r[0].split(" (")[0] for r in MEMORY_READINGS} >= {"lifelong", "reset per goal"}
    assert memory_readings_block().columns[0] == "reading"
