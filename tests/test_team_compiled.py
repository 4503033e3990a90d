"""R1..R4 of the line-of-sight help system in one compiled group brain
(``papers/los_help/brains/team_compiled.py``) run as the reference brains do, bit for bit
(Sgorbissa & Arkin §2-§6; ``docs/concepts/group-brains.md``).

The engine steps the reference team and the same scenario with ``group_brains=True`` side by
side and requires, at every step, equal true poses, odometry, commands and every robot's log,
with R1 compiled with its teammates (its goal-sharing choices: the own goal in sight, a
teammate, a ghost, the via point, a direct promise, a stalled point dropped) and the messages
on the radio as packed rows; with VisBug-21 (since 2026-11-29) also its temporary goals,
``start_again`` at a reached ghost and the resumed task goal. Where R1's compiled step declines
(``trouble_return``, VisBug-21's ``turn="random"``), R1 runs its reference brain inside the group
brain:
``tests/test_goal_sharing_compiled.py`` covers that with the scenario's defaults.
"""

from __future__ import annotations

import numpy as np
import pytest

from teamnav import load_scenario
from teamnav.experiments.spec import build_grid
from teamnav.papers.los_help.brains import team_compiled as T
from teamnav.papers.los_help.brains.packed import PackedLosMsg
from teamnav.papers.los_help.tasks import task_targets_xy, team_overrides
from teamnav.sim.engine import Simulation

STEPS = 1500


def _scenario(task: int, paper: bool, navigator: str, steps: int = STEPS, r1: dict | None = None,
              state_sharing: bool = False, **params):
    """R1..R4 on office_simple with one tuning task's targets, every robot on ``navigator``, with
    or without state sharing (§5), ``params`` for every robot and ``r1`` for R1 alone; ``paper``:
    the paper column (``paper_rules: true``)."""
    ov = dict(team_overrides("simple", 3))
    ov["robots.0.params.targets_xy"] = task_targets_xy("simple", task)
    for k in range(4):
        ov[f"robots.{k}.params.navigator"] = navigator
        ov[f"robots.{k}.params.state_sharing"] = state_sharing
        ov[f"robots.{k}.params.paper_rules"] = paper
        for name, value in params.items():
            ov[f"robots.{k}.params.{name}"] = value
    for name, value in (r1 or {}).items():  # R1's own
        ov[f"robots.0.params.{name}"] = value
    return load_scenario("los-help-simple", overrides=ov, duration_s=steps * 0.1, seed=0)


def _same_log(la: dict, lb: dict, where: str) -> None:
    layers_a, layers_b = la.pop("layers", None), lb.pop("layers", None)
    assert la == lb, f"logs differ: {where}: {la} vs {lb}"
    assert list(la) == list(lb), where
    assert (layers_a is None) == (layers_b is None), where
    if layers_a is not None:
        for name in layers_a:
            a, b = layers_a[name]["data"], layers_b[name]["data"]
            assert a.shape == b.shape and a.tobytes() == b.tobytes(), (name, where)


def side_by_side(scn, steps: int, r1_view: str = "_R1TeamView"):
    """The reference team and the compiled one, step by step (see the module docstring);
    ``r1_view``: R1's class in the group brain (``LosExplorer``: a reference row)."""
    ref = Simulation(build_grid(scn), scn)
    grp = Simulation(build_grid(scn), scn, group_brains=True)
    assert [(type(t).__name__, a, b) for t, a, b, _ in grp.group_teams] == [("LosTeamGroup", 0, 4)]
    brains_ref = [b for g in ref.brains for b in g]
    brains_grp = [b for g in grp.brains for b in g]
    assert [type(b).__name__ for b in brains_grp] == [r1_view] + ["_HelperView"] * 3, "the team as expected"
    packed = 0
    orig = grp.radio.send

    def send(outgoing, *args, **kwargs):
        nonlocal packed
        packed += sum(type(msg.body) is PackedLosMsg for _, msg in outgoing)
        return orig(outgoing, *args, **kwargs)

    grp.radio.send = send
    for _ in range(steps):
        ref.step()
        grp.step()
        where = f"step {ref.step_index}"
        assert np.array_equal(ref.state.poses(), grp.state.poses()), f"true poses differ at {where}"
        assert np.array_equal(ref.odometry.pose, grp.odometry.pose), f"odometry differs at {where}"
        assert np.array_equal(ref._dir_cmd, grp._dir_cmd, equal_nan=True), f"commands differ at {where}"
        for i, (a, b) in enumerate(zip(brains_ref, brains_grp)):
            _same_log(a.log(), b.log(), f"{where}, R{i + 1}")
    if r1_view == "_R1TeamView":
        assert packed > 100, "the compiled team's messages travel as packed rows"
    else:  # a reference row reads only LosHelpMsg: the compiled rows send those
        assert packed == 0
    assert brains_ref[0].target_steps == brains_grp[0].target_steps
    return brains_ref, brains_grp


@pytest.mark.parametrize("paper", [False, True], ids=["teamnav", "paper"])
@pytest.mark.parametrize("task,navigator,state_sharing", [(1001, "potential_field", True), (1002, "avoid_past", False)],
                         ids=["potential_field-state_sharing", "avoid_past"])
def test_whole_team_compiled_is_the_reference(task, navigator, state_sharing, paper):
    """Both columns, two tuning tasks, Tables 1-2's team cases (the potential field with state
    sharing, Avoid-Past without): R1 follows teammates and ghosts, and teammates when in trouble
    (§5 rule 3); in the teamnav column it also takes via points and direct promises."""
    refs, _ = side_by_side(_scenario(task, paper, navigator, state_sharing=state_sharing), STEPS)
    r1 = refs[0]
    assert r1.targets_reached >= 2
    assert r1.mode_steps.get("follow_teammate", 0) > 0 and r1.mode_steps.get("ghost", 0) > 0
    assert r1.temp_switches > 0 and r1.msgs_received > 100
    assert (r1.mode_steps.get("trouble_follow", 0) > 0) == state_sharing
    if not paper:
        assert r1.vias_taken > 0 and r1.promised_steps > 0


class _VisBugCalls:
    """Counts the reference VisBug-21's temporary goals, ``start_again`` calls (and those made
    while a task goal is suspended) and resumed task goals (the compiled rows never call them)."""

    def __init__(self, monkeypatch):
        from teamnav.control.nav.local.visbug21 import VisBug21

        self.temporary = self.start_again = self.start_again_suspended = self.resumed = 0
        set_goal, start_again, resume = VisBug21.set_goal, VisBug21.start_again, VisBug21._resume

        def counted_set_goal(nav, goal_xy, temporary=False):
            self.temporary += bool(temporary)
            return set_goal(nav, goal_xy, temporary)

        def counted_start_again(nav, reverse_walk_factor=None):
            self.start_again += 1
            self.start_again_suspended += nav.suspended_goal_xy is not None
            return start_again(nav, reverse_walk_factor)

        def counted_resume(nav, xy):
            self.resumed += 1
            return resume(nav, xy)

        monkeypatch.setattr(VisBug21, "set_goal", counted_set_goal)
        monkeypatch.setattr(VisBug21, "start_again", counted_start_again)
        monkeypatch.setattr(VisBug21, "_resume", counted_resume)


@pytest.mark.parametrize("paper", [False, True], ids=["teamnav", "paper"])
@pytest.mark.parametrize("task", [1001, 1002])
def test_visbug_team_compiled_is_the_reference(task, paper, monkeypatch):
    """Tables 1-2's VisBug-21 team (every robot on VisBug-21, no state sharing), both columns, two
    tuning tasks: R1 compiled with its teammates goes to teammates and ghosts as temporary goals
    (the task goal's M-line and hit point suspended, then resumed) and starts VisBug again at a
    reached ghost (``restart_navigator_at_ghost``, with ``visbug_reverse_walk_factor``)."""
    calls = _VisBugCalls(monkeypatch)
    refs, _ = side_by_side(_scenario(task, paper, "visbug21"), STEPS)
    r1 = refs[0]
    assert r1.targets_reached >= 1 and r1.msgs_received > 100
    assert r1.mode_steps.get("follow_teammate", 0) > 0 and r1.mode_steps.get("ghost", 0) > 0
    assert calls.temporary > 0 and calls.start_again > 0, vars(calls)
    if (task, paper) == (1001, True):  # the case with start_again during a temporary goal
        assert calls.start_again_suspended > 0 and calls.resumed > 0, vars(calls)


def test_visbug_team_gives_up_and_restarts_as_the_reference():
    """VisBug-21's Bug2 test fires among teammates (``return_tol_m`` 3.0, the paper column, tuning
    task 1002, 2500 steps): R1 gives up on its task goal and starts a fresh navigator
    (``restart_navigator_on_give_up``), as the reference."""
    nav = {"return_tol_m": 3.0, "turn": "right", "boundary_shortcut": True}
    refs, _ = side_by_side(_scenario(1002, True, "visbug21", 2500, navigator_params=nav), 2500)
    assert refs[0].nav_restarts > 0, refs[0].log()


@pytest.mark.parametrize("progress,steps", [("goal", STEPS), ("moved", 800)])
def test_trouble_following_gap_fills(progress, steps):
    """§5 rule 3's gap-fills with other values: progress measured towards the own goal or as a
    step not blocked, close behind the helper counting as progress, and a kept helper position
    given up after a few steps without closing in (``trouble_drop_stalled_helper``)."""
    refs, _ = side_by_side(_scenario(1002, False, "avoid_past", steps, state_sharing=True,
                                     r1={"trouble_progress": progress, "trouble_near_helper_m": 1.0,
                                         "trouble_drop_after_steps": 15}), steps)
    r1 = refs[0]
    assert r1.mode_steps.get("trouble_follow", 0) > 0
    if progress == "goal":
        assert r1.trouble_helpers_dropped > 0


def test_stalled_points_dropped_and_budget():
    """A short Cr drops points R1 does not close in on (``drop_stalled_ghost``), and a step
    budget per target ends the task (``max_steps_per_target``, gave up)."""
    refs, grps = side_by_side(_scenario(1001, False, "avoid_past", 1200, r1={"max_steps_per_target": 250},
                                        trouble_cr=8), 1200)
    assert refs[0].temp_dropped > 0, refs[0].log()
    assert refs[0].gave_up and refs[0].mode == "gave_up"


def test_a_reference_row_inside_the_team_is_the_reference():
    """R1 on VisBug-21 with ``turn="random"`` (declined: a draw of its Generator per task goal) runs
    its per-robot brain as a reference row inside the group brain, fed the observation the engine
    would give it, beside the compiled helpers: the same run, step by step."""
    scn = _scenario(1001, False, "visbug21", 800, r1={"navigator_params": {"turn": "random"}})
    refs, _ = side_by_side(scn, 800, r1_view="LosExplorer")
    assert refs[0].msgs_received > 100 and refs[0].mode_steps.get("ghost", 0) > 0


def test_what_is_declined_runs_the_reference_inside():
    """R1 with ``trouble_return`` or VisBug-21's ``turn="random"`` among teammates runs its
    reference brain inside the group brain (the helpers stay compiled); ``unsupported`` says why
    R1's row is not compiled."""
    from teamnav.papers.los_help.brains.explorer import LosExplorer

    for extra, why in (({"state_sharing": True, "trouble_return": True}, "trouble_return"),
                       ({"navigator": "visbug21", "navigator_params": {"turn": "random"}}, "turn 'random'")):
        scn = _scenario(1001, False, "potential_field", 5, r1=extra)
        sim = Simulation(build_grid(scn), scn, group_brains=True)
        assert [type(t).__name__ for t, *_ in sim.group_teams] == ["LosTeamGroup"]
        assert type(sim.brains[0][0]) is LosExplorer
        assert [type(b).__name__ for g in sim.brains[1:] for b in g] == ["_HelperView"] * 3
        infos = [sim.robot_info(i) for i in range(4)]
        params = [b.params for g in sim.brains for b in g]
        assert why in T.r1_team_unsupported(params[0], infos[0])
        assert T.LosTeamGroup.unsupported(params, infos) is None
