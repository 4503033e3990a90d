"""Avoid-Past (Sgorbissa & Arkin §6 algorithm 2; Balch & Arkin 1993): the memory's lifetime
(``memory_scope``) and the escapes it buys on the paper's office maps.

Driven in :mod:`test_nav_local`'s closed loop (no ``teamnav.sim``): ranges at the true pose, the
robot's own frame shifted and rotated from the world's.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_nav_local import STEP_M, U_GOAL, U_START, Loop, nav_of, u_trap

from teamnav.control.nav.local import AvoidPast, AvoidPastParams
from teamnav.world import builtin_map


def _visited(nav: AvoidPast, steps: int) -> Loop:
    loop = Loop(u_trap(), nav, U_START, U_GOAL)
    for _ in range(steps):
        loop.step()
    return loop


def test_default_memory_is_the_robots_own_decayed_by_the_fill_in_both_columns():
    """The robot's memory, never reset at a goal, decays with the half-life that the fill's rule
    chose on tuning tasks; the paper gives no lifetime, so paper_rules leaves the same value."""
    assert AvoidPastParams().memory_scope == "robot" and AvoidPastParams().memory_radius_m == 3.0
    assert AvoidPastParams().memory_half_life_steps == 1000.0  # HALF_LIFE_RULE on tuning tasks 1001-1005
    assert AvoidPastParams(paper_rules=True).memory_half_life_steps == AvoidPastParams().memory_half_life_steps
    assert AvoidPastParams(paper_rules=True).memory_scope == "robot"
    with pytest.raises(ValueError):
        AvoidPastParams(memory_scope="task")


def test_a_new_own_goal_forgets_the_visits_a_temporary_one_does_not():
    nav = nav_of("avoid_past", {"memory_scope": "goal", "memory_half_life_steps": None})
    loop = _visited(nav, 100)
    visits = dict(nav.visits)
    assert sum(visits.values()) == pytest.approx(100 * STEP_M)
    own = loop.to_own(np.asarray(U_GOAL))
    # an excursion (a teammate, a ghost: temporary) and the way back to the same goal keep them
    nav.set_goal(loop.to_own(np.array([1.0, 1.0])), temporary=True)
    assert nav.visits == visits
    loop.step()
    nav.set_goal(own + 1e-8)  # the same goal (within GOAL_SAME_TOL_M)
    assert sum(nav.visits.values()) == pytest.approx(101 * STEP_M)
    # a new goal of the robot's own starts an empty memory, and the push with it
    nav.set_goal(loop.to_own(np.array([1.0, 1.0])))
    assert nav.visits == {} and nav.progressing
    loop.step()
    assert sum(nav.visits.values()) == pytest.approx(STEP_M)


def test_robot_scope_keeps_one_memory():
    nav = nav_of("avoid_past", {"memory_half_life_steps": None})
    loop = _visited(nav, 50)
    nav.set_goal(loop.to_own(np.array([1.0, 1.0])))
    assert sum(nav.visits.values()) == pytest.approx(50 * STEP_M)


def test_reset_memory_pushes_like_a_fresh_navigator():
    """After the reset the vector is the one of a navigator that never saw the old goal (the
    dense mirror of the visits is rebuilt, not left stale)."""
    a = nav_of("avoid_past", {"memory_scope": "goal"})
    loop = _visited(a, 150)
    a.set_goal(loop.to_own(np.array([1.0, 1.0])))
    b = nav_of("avoid_past", {"memory_scope": "goal"})
    b.set_goal(loop.to_own(np.array([1.0, 1.0])))
    pts = np.array([[0.0, 0.0]])
    for k in range(30):
        pose = np.array([0.05 * k, 0.02 * k, 0.0])
        assert np.array_equal(a._vector(pose, pts, 72), b._vector(pose, pts, 72))


@pytest.mark.parametrize("room,start,door_x", [("room_N2", (9.0, 7.0), (10.0, 11.2)),
                                               ("room_S4", (21.2, 6.5), (18.6, 19.8))])
def test_avoid_past_finds_the_door_the_potential_field_misses(room, start, door_x):
    """office_simple: the goal is a room's centre behind the corridor wall, its door 1.1-2.3 m
    to the side. The potential field sits on the wall (§6: trapped); Avoid-Past fills the spot
    with visits and is pushed along the wall to the door and in."""
    em = builtin_map("office_simple")
    goal = em.places[room]
    ap = Loop(em.grid, nav_of("avoid_past"), start, goal)
    steps = ap.run(1500)
    assert steps is not None and ap.stalls == 0
    inside = [p for p in ap.path if abs(p[1] - 7.0) > 1.4]  # out of the corridor, in the room
    assert door_x[0] < inside[0][0] < door_x[1]  # it entered through the door
    pf = Loop(em.grid, nav_of("potential_field"), start, goal)
    assert pf.run(1500) is None


@pytest.mark.slow  # two runs of up to 18,000 steps: a reproduction of 2b5e0ce's trace
def test_trip_memory_reaches_a_sequence_the_robot_memory_does_not():
    """2b5e0ce's trace, R1 alone on office_simple (``los-help-simple``, task 1's first 12 targets, budget
    1500 steps each, pinned here: the scenario's own budget is 6000 since 513792e, and with
    that much time even the saturated memory crawls through). With one memory for the robot's
    life (the old default, and again the default since bdfa8a8: the paper's rule) the trodden
    corridor's visits saturate the push and R1 gives up on the 11th target (S4 from S5), at this
    radius of 2 m and budget; with the trip's memory (``memory_scope="goal"``, the default from
    2026-11-23 to 2026-11-27) it reaches all 12."""
    from teamnav import load_scenario, run
    from teamnav.papers.los_help.tasks import task_targets_xy

    def reached(navigator_params) -> tuple[int, bool]:
        ov = {"robots.0.params.navigator": "avoid_past", "robots.0.params.state_sharing": False,
              "robots.0.params.navigator_params": navigator_params,
              "robots.0.params.targets_xy": task_targets_xy("simple", 1, 12),
              "robots.0.params.max_steps_per_target": 1500,
              "robots.1.count": 0, "robots.2.count": 0, "robots.3.count": 0}
        m = run(load_scenario("los-help-simple", overrides=ov, duration_s=0.1 * 1500 * 12), progress=False).metrics
        return int(m["los_targets_reached"]), bool(m["los_finished"])

    assert reached({"memory_scope": "goal"}) == (12, True)
    n, finished = reached({"memory_scope": "robot", "memory_radius_m": 2.0})
    assert n < 12 and not finished


def test_memory_half_life_weighs_each_visit_by_its_age():
    """The decay gap-fill: after the same walk, the push equals the one of an
    undecayed memory whose visits were each scaled by 2^(-age / h), and it is smaller."""
    from teamnav.control.nav.local.avoid_past import avoid_past_vector

    h = 40.0
    nav = nav_of("avoid_past", {"memory_half_life_steps": h, "avoid_max": 1000.0})
    ref = nav_of("avoid_past", {"avoid_max": 1000.0, "memory_half_life_steps": None})
    poses = [np.array([0.1 * k, 0.0, 0.0]) for k in range(60)] + [np.array([6.0, 0.0, 0.0])]
    pts = np.array([[5.0, 5.0]])
    for n in (nav, ref):
        n.set_goal(np.array([30.0, 0.0]))
        for pose in poses[:-1]:
            n._vector(pose, pts, 72)
    got = nav._vector(poses[-1], pts, 72) - ref._vector(poses[-1], pts, 72)  # the same field part
    expected: dict = {}
    for k, pose in enumerate(poses):  # the k-th deposit is (60 - k) steps old at the last call
        key = (int(np.floor(pose[0] / 0.3)), int(np.floor(pose[1] / 0.3)))
        expected[key] = expected.get(key, 0.0) + STEP_M * 2.0 ** (-(len(poses) - 1 - k) / h)
    p = nav.params
    here = poses[-1][:2]
    decayed = p.avoid_gain_per_m * avoid_past_vector(here, expected, p.cell_m, p.memory_radius_m, 1.0)
    undecayed = p.avoid_gain_per_m * avoid_past_vector(here, ref.visits, p.cell_m, p.memory_radius_m, 1.0)
    assert np.linalg.norm(decayed) < 0.9 * np.linalg.norm(undecayed)
    np.testing.assert_allclose(got, decayed - undecayed, rtol=1e-9, atol=1e-12)


def test_memory_half_life_survives_the_rescale_and_is_not_a_paper_rule():
    nav = nav_of("avoid_past", {"memory_half_life_steps": 0.01})  # rescales every few steps
    nav.set_goal(np.array([30.0, 0.0]))
    pts = np.array([[5.0, 5.0]])
    for k in range(200):
        v = nav._vector(np.array([0.01 * k, 0.0, 0.0]), pts, 72)
        assert np.isfinite(v).all() and all(np.isfinite(n) for n in nav.visits.values())
    assert "memory_half_life_steps" not in AvoidPastParams.PAPER_RULES  # a fill, the same in both columns
    with pytest.raises(ValueError, match="memory_half_life_steps"):
        AvoidPastParams(memory_half_life_steps=0.0)
