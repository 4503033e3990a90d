"""Local navigators of Sgorbissa & Arkin's set A (§2, §6): potential field, Avoid-Past, VisBug-21.

The navigators are driven in a small closed loop of our own (no ``teamnav.sim``): ranges from
:class:`~teamnav.world.raycast.RayCaster` at the true pose, a fixed-length step in the returned
heading when the disc stays clear of every wall cell, and the robot's own frame shifted and
rotated from the world's (as odometry frames are).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.control.nav.local import (
    NAVIGATORS,
    AvoidPast,
    AvoidPastParams,
    LocalNavigator,
    PotentialFieldParams,
    ProgressMonitor,
    VisBug21,
    VisBugParams,
    goal_in_sight,
    make_navigator,
    safe_heading,
)
from teamnav.control.nav.local.base import segment_clearance
from teamnav.control.nav.local.visbug21 import MODE_FOLLOW, MODE_TO_GOAL, MODE_UNREACHABLE
from teamnav.control.types import RangeScan
from teamnav.world import MapBuilder, OccupancyGrid, builtin_map
from teamnav.world.raycast import RayCaster

STEP_M = 0.1
RADIUS_M = 0.25
N_BEAMS = 120
RANGE_M = 4.0
ANGLES = np.linspace(-np.pi, np.pi, N_BEAMS, endpoint=False)
FREE_SCAN = RangeScan(np.full(N_BEAMS, RANGE_M), ANGLES, RANGE_M)


# ---------------------------------------------------------------------------- closed loop
def disc_free(grid: OccupancyGrid, xy, r: float) -> bool:
    """No wall cell within ``r`` of ``xy`` (and inside the map)."""
    res = grid.resolution_m
    ox, oy = grid.origin_xy_m
    h, w = grid.shape
    c0, c1 = int(math.floor((xy[0] - r - ox) / res)), int(math.floor((xy[0] + r - ox) / res))
    r0, r1 = int(math.floor((xy[1] - r - oy) / res)), int(math.floor((xy[1] + r - oy) / res))
    if c0 < 0 or r0 < 0 or c1 >= w or r1 >= h:
        return False
    rows, cols = np.nonzero(grid.cells[r0:r1 + 1, c0:c1 + 1] != 0)
    x0, y0 = ox + (cols + c0) * res, oy + (rows + r0) * res
    dx = np.maximum(np.maximum(x0 - xy[0], 0.0), xy[0] - (x0 + res))
    dy = np.maximum(np.maximum(y0 - xy[1], 0.0), xy[1] - (y0 + res))
    return bool(np.all(dx * dx + dy * dy >= r * r))


class Loop:
    """Drive ``nav`` on ``grid`` from ``start`` to ``goal`` (world frame); own frame = world moved by ``frame``."""

    def __init__(self, grid, nav, start, goal, frame=(3.0, -2.0, 0.7)):
        self.grid, self.nav = grid, nav
        self.caster = RayCaster(grid, max_range_m=RANGE_M)
        self.pose = np.array([start[0], start[1], 0.0])
        self.goal = np.asarray(goal, float)
        self.fx, self.fy, self.ft = frame
        self.steps = self.stalls = 0
        self.progress: list[bool] = []
        self.path = [self.pose[:2].copy()]
        nav.set_goal(self.to_own(self.goal))

    def to_own(self, xy):
        c, s = math.cos(self.ft), math.sin(self.ft)
        dx, dy = xy[0] - self.fx, xy[1] - self.fy
        return np.array([c * dx + s * dy, -s * dx + c * dy])

    def own_pose(self):
        return np.array([*self.to_own(self.pose[:2]), self.pose[2] - self.ft])

    def step(self):
        ranges = self.caster.cast(self.pose[None], ANGLES, parallel=False)[0]
        h = self.nav.direction(self.own_pose(), RangeScan(ranges, ANGLES, RANGE_M))
        self.progress.append(self.nav.progressing)
        self.steps += 1
        if h is None:
            return
        hw = h + self.ft
        new = self.pose[:2] + STEP_M * np.array([math.cos(hw), math.sin(hw)])
        mid = 0.5 * (self.pose[:2] + new)
        if disc_free(self.grid, new, RADIUS_M) and disc_free(self.grid, mid, RADIUS_M):
            self.pose = np.array([new[0], new[1], hw])
        else:
            self.stalls += 1
        self.path.append(self.pose[:2].copy())

    def dist(self) -> float:
        return float(np.hypot(*(self.pose[:2] - self.goal)))

    def run(self, budget: int, eps_m: float = 0.2) -> int | None:
        """Steps to come within ``eps_m`` of the goal, or None within ``budget``."""
        while self.steps < budget:
            if self.dist() < eps_m:
                return self.steps
            self.step()
        return self.steps if self.dist() < eps_m else None


def nav_of(name, params=None, seed=0):
    return make_navigator(name, params, rng=np.random.default_rng(seed), step_length_m=STEP_M, radius_m=RADIUS_M)


def open_room() -> OccupancyGrid:
    return MapBuilder(12.0, 10.0, 0.1).border(0.2).build("open")


def u_trap() -> OccupancyGrid:
    """A 12 m square room with a cup open to the south; the goal (6, 10) lies behind its bottom."""
    b = MapBuilder(12.0, 12.0, 0.1).border(0.2)
    b.rect(3.5, 7.0, 8.5, 7.3).rect(3.5, 4.0, 3.8, 7.3).rect(8.2, 4.0, 8.5, 7.3)
    return b.build("u_trap")


U_START, U_GOAL = (6.0, 2.0), (6.0, 10.0)


# ---------------------------------------------------------------------------- interface
def test_navigators_registry_and_protocol():
    assert set(NAVIGATORS) == {"potential_field", "avoid_past", "visbug21"}
    for name in NAVIGATORS:
        nav = nav_of(name)
        assert isinstance(nav, LocalNavigator) and nav.name == name
        assert nav.direction(np.zeros(3), FREE_SCAN) is None  # no goal yet


def test_unknown_name_and_bad_params_are_refused():
    with pytest.raises(ValueError, match="did you mean 'visbug21'"):
        nav_of("visbug2")
    with pytest.raises(ValueError, match="influence_m"):
        nav_of("potential_field", {"influence_m": -1.0})
    with pytest.raises(ValueError, match="avoid_gain_per_mm"):
        nav_of("avoid_past", {"avoid_gain_per_mm": 1.0})
    with pytest.raises(ValueError, match="turn"):
        nav_of("visbug21", {"turn": "up"})
    with pytest.raises(ValueError, match="must be a VisBugParams"):
        nav_of("visbug21", PotentialFieldParams())
    with pytest.raises(ValueError, match="step_length_m"):
        make_navigator("avoid_past", None, rng=np.random.default_rng(0), step_length_m=0.0, radius_m=0.2)
    with pytest.raises(ValueError, match="goal_xy"):
        nav_of("potential_field").set_goal(np.array([np.nan, 0.0]))
    nav = nav_of("visbug21")
    nav.set_goal(np.array([1.0, 0.0]))
    with pytest.raises(ValueError, match="pose"):
        nav.direction(np.zeros(2), FREE_SCAN)
    with pytest.raises(ValueError, match="RangeScan"):
        nav.direction(np.zeros(3), np.ones(4))
    # a Params model and a dict give the same navigator settings
    assert nav_of("visbug21", VisBugParams(turn="right")).params == nav_of("visbug21", {"turn": "right"}).params
    with pytest.raises(Exception):
        VisBugParams().turn = "right"  # frozen


# ---------------------------------------------------------------------------- geometry
@settings(max_examples=60, deadline=None)
@given(
    x=st.floats(-20, 20), y=st.floats(-20, 20), th=st.floats(-math.pi, math.pi),
    gx=st.floats(-20, 20), gy=st.floats(-20, 20), name=st.sampled_from(["potential_field", "visbug21"]),
)
def test_free_space_heading_is_the_goal_bearing(x, y, th, gx, gy, name):
    """No obstacle sensed: the potential field and VisBug head straight at the goal, whatever the pose."""
    if math.hypot(gx - x, gy - y) < 0.05 or (name == "visbug21" and math.hypot(gx - x, gy - y) > RANGE_M - 0.4):
        gx, gy = x + 1.0, y - 0.5
    nav = nav_of(name)
    nav.set_goal(np.array([gx, gy]))
    h = nav.direction(np.array([x, y, th]), FREE_SCAN)
    bearing = math.atan2(gy - y, gx - x)
    assert abs(math.remainder(h - bearing, 2 * math.pi)) < 1e-4


@settings(max_examples=60, deadline=None)
@given(wall_y=st.floats(0.3, 1.5), want=st.floats(-math.pi, math.pi))
def test_guard_keeps_every_step_clear_of_a_wall(wall_y, want):
    """safe_heading never returns a step that passes closer than the clearance to sensed points
    when a clear one exists, and returns the wanted heading itself when that one is clear."""
    pts = np.column_stack((np.linspace(-3, 3, 121), np.full(121, wall_y)))
    xy = np.zeros(2)
    clearance = 0.28
    h = safe_heading(want, xy, pts, STEP_M, clearance)
    end = xy + STEP_M * np.array([math.cos(h), math.sin(h)])
    assert segment_clearance(pts, xy, end[None])[0] >= clearance - 1e-9 or wall_y < clearance
    want_end = xy + STEP_M * np.array([math.cos(want), math.sin(want)])
    if segment_clearance(pts, xy, want_end[None])[0] >= clearance:
        assert abs(math.remainder(h - want, 2 * math.pi)) < 1e-12


def test_guard_backs_away_when_already_too_close():
    pts = np.column_stack((np.linspace(-1, 1, 41), np.full(41, 0.15)))  # wall 15 cm north
    h = safe_heading(math.pi / 2, np.zeros(2), pts, STEP_M, 0.28)
    assert abs(math.remainder(h + math.pi / 2, 2 * math.pi)) < 1e-9  # straight south


def test_goal_in_sight():
    grid = MapBuilder(10.0, 6.0, 0.1).border(0.2).rect(4.9, 0.2, 5.1, 4.0).build("wall")
    caster = RayCaster(grid, max_range_m=RANGE_M)
    pose = np.array([3.0, 2.0, 0.4])
    scan = RangeScan(caster.cast(pose[None], ANGLES)[0], ANGLES, RANGE_M)
    assert not goal_in_sight(pose, scan, np.array([6.5, 2.0]))      # behind the wall
    assert goal_in_sight(pose, scan, np.array([3.0, 4.5]))          # in the open
    assert not goal_in_sight(pose, scan, np.array([3.0, 5.7]), clearance_m=0.3)  # too near the map edge to drive to
    assert not goal_in_sight(pose, scan, np.array([-2.0, 2.0]))     # beyond the range


def test_progress_monitor_counts_window_steps():
    m = ProgressMonitor(window_steps=3, fraction=0.5, step_length_m=0.1)
    assert all(m.update(d) for d in (5.0, 4.9, 4.8, 4.7))
    # stuck: 4 steps within 0.05 m of the reference -> not progressing after the window
    flags = [m.update(d) for d in (4.69, 4.71, 4.68, 4.7, 4.69)]
    assert flags == [True, True, True, False, False]
    assert m.update(4.6)  # beats the reference by a full step's half: progressing again
    m.reset()
    assert m.update(100.0)


# ---------------------------------------------------------------------------- potential field
def test_potential_field_goes_straight_in_open_space():
    start, goal = (1.5, 1.5), (10.0, 8.0)
    loop = Loop(open_room(), nav_of("potential_field"), start, goal)
    steps = loop.run(300, eps_m=STEP_M)
    straight = math.dist(start, goal) / STEP_M
    assert steps is not None and steps <= 1.1 * straight
    assert loop.stalls == 0 and all(loop.progress)


def test_potential_field_is_trapped_in_the_u():
    """§6: the potential field alone does not reach a goal behind a U (local minimum)."""
    loop = Loop(u_trap(), nav_of("potential_field"), U_START, U_GOAL)
    assert loop.run(1200) is None
    assert loop.stalls == 0
    # it sits under the cup's bottom and knows it is not progressing (§5)
    assert abs(loop.pose[0] - 6.0) < 0.5 and 5.5 < loop.pose[1] < 7.0
    assert not any(loop.progress[-500:])
    assert loop.progress[0]


# ---------------------------------------------------------------------------- Avoid-Past
@pytest.mark.parametrize("seed,x0", [(0, 6.0), (1, 5.7), (2, 5.4)])
def test_avoid_past_escapes_the_u(seed, x0):
    """Balch & Arkin 1993: the visits fill the box canyon until the robot is pushed out of it."""
    loop = Loop(u_trap(), nav_of("avoid_past", seed=seed), (x0, 2.0), U_GOAL)
    steps = loop.run(1500)
    assert steps is not None and loop.stalls == 0
    assert max(p[1] for p in loop.path) > 7.3  # it went round the cup, not through it


def test_avoid_past_robot_memory_survives_a_new_goal():
    nav = nav_of("avoid_past", {"memory_scope": "robot", "memory_half_life_steps": None})
    assert isinstance(nav, AvoidPast)
    loop = Loop(u_trap(), nav, U_START, U_GOAL)
    for _ in range(200):
        loop.step()
    visits = dict(nav.visits)
    assert sum(visits.values()) == pytest.approx(200 * STEP_M)
    nav.set_goal(loop.to_own(np.array([1.0, 1.0])))
    assert nav.visits == visits
    assert nav.progressing  # the progress estimate restarted for the new goal
    # a visited neighbourhood pushes away from itself
    from teamnav.control.nav.local.avoid_past import avoid_past_vector
    v = avoid_past_vector(np.array([1.0, 0.0]), {(0, 0): 5.0, (0, -1): 5.0}, 0.5, 2.0, 1.0)
    assert v[0] > 0 and abs(v[1]) < 1e-12


# ---------------------------------------------------------------------------- VisBug-21
@pytest.mark.parametrize("turn", ["left", "right"])
def test_visbug_reaches_the_goal_behind_the_u(turn):
    nav = nav_of("visbug21", {"turn": turn})
    loop = Loop(u_trap(), nav, U_START, U_GOAL)
    steps = loop.run(600)
    assert steps is not None and loop.stalls == 0
    # Bug2: the M-line is x = 6; it followed the cup's boundary on the chosen side
    xs = [p[0] for p in loop.path]
    assert (min(xs) < 3.3) if turn == "left" else (max(xs) > 8.7)


def test_visbug_reaches_a_room_around_its_wall_in_office_simple():
    """Start in the corridor below room N2's centre; the wall is in the way and the door 1.7 m east."""
    em = builtin_map("office_simple")
    goal = em.places["room_N2"]
    loop = Loop(em.grid, nav_of("visbug21", {"turn": "right"}), (9.0, 7.0), goal)
    steps = loop.run(300)
    assert steps is not None and loop.stalls == 0
    assert max(p[0] for p in loop.path) > 10.0  # went through the door (x in [10.0, 11.2])
    # the potential field is trapped under the same room
    pf = Loop(em.grid, nav_of("potential_field"), (9.0, 7.0), goal)
    assert pf.run(600) is None


def test_visbug_wrong_way_round_still_arrives():
    """Bug2 is complete: turning left walks the whole building's boundary but gets there."""
    em = builtin_map("office_simple")
    loop = Loop(em.grid, nav_of("visbug21", {"turn": "left"}), (21.0, 7.0), em.places["room_S4"])
    steps = loop.run(3000)
    assert steps is not None and steps > 1500 and loop.stalls == 0


def test_visbug_reverse_walk_turns_back_from_the_wrong_way_round_and_still_gives_up_when_enclosed():
    """``reverse_walk_factor``: the wrong way round (above) turns back after 3 d_H and arrives
    in a fraction of the lap; an enclosed goal is still declared unreachable (a full lap)."""
    em = builtin_map("office_simple")
    loop = Loop(em.grid, nav_of("visbug21", {"turn": "left", "reverse_walk_factor": 3.0}), (21.0, 7.0),
                em.places["room_S4"])
    steps = loop.run(3000)
    assert steps is not None and steps < 600 and loop.stalls == 0
    # the same, switched on for one goal by start_again (at a ghost, Sgorbissa & Arkin §4.2)
    nav = nav_of("visbug21", {"turn": "left"})
    again = Loop(em.grid, nav, (21.0, 7.0), em.places["room_S4"])
    nav.start_again(reverse_walk_factor=3.0)
    assert again.run(3000) == steps
    nav.set_goal(again.to_own(np.array([1.0, 1.0])))
    assert nav._reverse_for is None
    b = MapBuilder(10.0, 10.0, 0.1).border(0.2).rect(6.0, 3.0, 9.0, 7.0, filled=False, thickness_m=0.2)
    box = Loop(b.build("box"), nav_of("visbug21", {"reverse_walk_factor": 1.0}), (2.0, 5.0), (7.5, 5.0))
    assert box.run(1500) is None and box.nav.mode == MODE_UNREACHABLE


def test_visbug_new_goal_restarts_and_same_goal_does_not():
    nav = nav_of("visbug21")
    assert isinstance(nav, VisBug21)
    loop = Loop(u_trap(), nav, U_START, U_GOAL)
    while nav.mode != MODE_FOLLOW and loop.steps < 200:
        loop.step()
    for _ in range(5):
        loop.step()
    assert nav.mode == MODE_FOLLOW and nav.hit_xy is not None
    hit, mline = nav.hit_xy.copy(), nav.mline
    nav.set_goal(loop.to_own(np.array(U_GOAL) + 1e-8))  # the same goal
    assert nav.mode == MODE_FOLLOW and np.array_equal(nav.hit_xy, hit) and nav.mline is mline
    nav.set_goal(loop.to_own(np.array([1.0, 1.0])))
    assert nav.mode == MODE_TO_GOAL and nav.hit_xy is None and nav.mline is None
    loop.step()
    assert np.allclose(nav.mline[0], loop.to_own(loop.path[-2]))  # new M-line from where it stood


def test_visbug_gives_up_on_an_enclosed_goal():
    """Bug2's termination test: back at the hit point after a full lap -> unreachable, stay."""
    # the box leaves a 0.8 m passage to the room's east wall: the robot must keep following the box
    b = MapBuilder(10.0, 10.0, 0.1).border(0.2).rect(6.0, 3.0, 9.0, 7.0, filled=False, thickness_m=0.2)
    loop = Loop(b.build("box"), nav_of("visbug21"), (2.0, 5.0), (7.5, 5.0))
    assert loop.run(800) is None
    ys = [p[1] for p in loop.path]
    assert 2.4 < min(ys) and max(ys) < 7.6
    assert loop.nav.mode == MODE_UNREACHABLE and not loop.nav.progressing
    assert loop.nav.direction(loop.own_pose(), FREE_SCAN) is None


def test_visbug_random_turn_is_seeded():
    sides = []
    for seed in range(6):
        nav = nav_of("visbug21", {"turn": "random"}, seed=seed)
        nav.set_goal(np.array([1.0, 2.0]))
        sides.append(nav.side)
    assert set(sides) == {1, -1}
    again = nav_of("visbug21", {"turn": "random"}, seed=3)
    again.set_goal(np.array([1.0, 2.0]))
    assert again.side == sides[3]


def test_avoid_past_params_extend_the_potential_fields():
    p = AvoidPastParams(influence_m=0.5, avoid_gain_per_m=0.3)
    assert isinstance(p, PotentialFieldParams) and p.influence_m == 0.5


def test_avoid_past_push_saturates_and_points_away():
    from teamnav.control.nav.local.avoid_past import avoid_past_vector
    v = avoid_past_vector(np.array([1.0, 0.25]), {(0, 0): 1e6}, 0.5, 2.0, 0.1, avoid_max=2.0)
    assert math.hypot(*v) == pytest.approx(2.0) and v[0] > 0 and abs(v[1]) < 1e-9
    assert not avoid_past_vector(np.array([9.0, 9.0]), {(0, 0): 1e6}, 0.5, 2.0, 0.1).any()  # out of reach


@pytest.mark.parametrize("side,d,want_rad", [(1, 0.5, 0.0), (-1, 0.5, math.pi), (1, 0.3, 0.6), (-1, 0.3, math.pi - 0.6),
                                              (1, 0.8, -0.9), (1, 2.0, -math.pi / 3)])
def test_boundary_heading_keeps_the_wall_on_the_chosen_side(side, d, want_rad):
    """A wall d metres to the south, followed at 0.5 m with gain 1.5: +1 (obstacle on the right)
    drives east, -1 west; too close turns away (north) by 1.5 x relative error, too far towards
    it, clipped at 60 degrees."""
    from teamnav.control.nav.local.visbug21 import boundary_heading
    pts = np.column_stack((np.linspace(-3, 3, 121), np.full(121, -d)))
    h = boundary_heading(np.zeros(2), pts, 0.5, side, 1.5)
    assert abs(math.remainder(h - want_rad, 2 * math.pi)) < 1e-9


# ---------------------------------------------------------------------------- seen free, leave rule
@settings(max_examples=60, deadline=None)
@given(x=st.floats(-5, 5), y=st.floats(-5, 5), th=st.floats(-math.pi, math.pi), r=st.floats(0.5, 3.5),
       bearing=st.floats(-math.pi, math.pi), frac=st.floats(0.05, 2.0))
def test_seen_free_is_in_front_of_the_returns(x, y, th, r, bearing, frac):
    """Inside a circular wall of radius r every point nearer than r is seen free, none beyond it."""
    from teamnav.control.nav.local.base import seen_free
    scan = RangeScan(np.full(N_BEAMS, r), ANGLES, RANGE_M)
    d = frac * r
    p = np.array([[x + d * math.cos(bearing), y + d * math.sin(bearing)]])
    got = bool(seen_free(np.array([x, y, th]), scan, p)[0])
    if frac < 0.999:
        assert got
    elif frac > 1.001:
        assert not got


def test_visbug_does_not_leave_for_a_run_hidden_behind_a_door_jamb():
    """office_simple, R1 alone (los-help-simple task 4, first target; its robot: 0.2 m radius and
    step, 72 beams of 8 m): following the corridor's south side, the robot sees the M-line slip
    into room N2's door; the sensed points leave the run past the door free, but the jamb's far
    face is hidden from it. It must not leave for that point (it did, hit the jamb at once and
    walked the whole building again, lap after lap)."""
    from teamnav.control.nav.local.base import scan_points
    em = builtin_map("office_simple")
    nav = make_navigator("visbug21", None, rng=np.random.default_rng(0), step_length_m=0.2, radius_m=0.2)
    angles = np.linspace(-np.pi, np.pi, 72, endpoint=False)
    caster = RayCaster(em.grid, max_range_m=8.0)
    s, g = np.array([1.2, 7.03]), np.array([26.9, 11.1])
    nav.set_goal(g)
    nav.mline = (s, g)
    nav.mode, nav.hit_xy = MODE_FOLLOW, np.array([10.8, 8.45])
    nav.hit_dist_m = float(np.hypot(*(g - nav.hit_xy)))
    nav._slack = math.pi / 72
    r_safe = 0.2 + nav.params.safety_margin_m

    def leave_from(xy):
        pose = np.array([*xy, 0.0])
        scan = RangeScan(caster.cast(pose[None], angles, parallel=False)[0], angles, 8.0)
        return nav._leave_point(pose, scan, scan_points(pose, scan), r_safe + nav.params.leave_hysteresis_m,
                                8.0 - r_safe)

    assert leave_from((8.37, 6.13)) is None
    # inside room N3 it sees the M-line cross the room: the same test is not simply always False
    q = leave_from((13.0, 10.5))
    assert q is not None and 14.0 < q[0] < 17.8 and 8.4 < q[1] < 10.0


# ---------------------------------------------------------------------------- temporary goals
def test_visbug_temporary_goal_keeps_and_resumes_the_task():
    nav = nav_of("visbug21")
    loop = Loop(u_trap(), nav, U_START, U_GOAL)
    task = loop.to_own(np.array(U_GOAL))
    while nav.mode != MODE_FOLLOW and loop.steps < 200:
        loop.step()
    for _ in range(5):
        loop.step()
    assert nav.mode == MODE_FOLLOW
    hit, mline, d_hit, side = nav.hit_xy, nav.mline, nav.hit_dist_m, nav.side
    nav.set_goal(loop.to_own(np.array([1.0, 1.0])), temporary=True)  # e.g. a teammate in sight
    assert nav.temporary and nav.hit_xy is None and nav.mode == MODE_TO_GOAL
    assert np.allclose(nav.suspended_goal_xy, task)
    nav.set_goal(loop.to_own(np.array([1.5, 1.0])), temporary=True)  # the teammate moved: still suspended
    assert np.allclose(nav.suspended_goal_xy, task)
    for _ in range(25):
        loop.step()
    nav.set_goal(task)  # back on the task: M-line, H, d_H, mode and side as before
    assert not nav.temporary and nav.suspended_goal_xy is None
    assert nav.hit_xy is hit and nav.mline is mline and nav.hit_dist_m == d_hit
    assert nav.mode == MODE_FOLLOW and nav.side == side
    assert loop.run(1500) is not None and loop.stalls == 0


def test_visbug_plain_goal_drops_the_suspended_task_and_default_restarts():
    nav = nav_of("visbug21")
    loop = Loop(u_trap(), nav, U_START, U_GOAL)
    task = loop.to_own(np.array(U_GOAL))
    while nav.mode != MODE_FOLLOW and loop.steps < 200:
        loop.step()
    nav.set_goal(loop.to_own(np.array([1.0, 1.0])), temporary=True)
    nav.set_goal(loop.to_own(np.array([2.0, 1.0])))  # a plain new goal: the task is forgotten
    assert nav.suspended_goal_xy is None and not nav.temporary
    nav.set_goal(task)
    assert nav.hit_xy is None and nav.mline is None and nav.mode == MODE_TO_GOAL


def test_visbug_resumes_afresh_when_the_excursion_ended_closer_than_its_hit_point():
    nav = nav_of("visbug21")
    loop = Loop(u_trap(), nav, U_START, U_GOAL)
    task = loop.to_own(np.array(U_GOAL))
    while nav.mode != MODE_FOLLOW and loop.steps < 200:
        loop.step()
    d_hit = nav.hit_dist_m
    nav.set_goal(loop.to_own(np.array([2.0, 9.0])), temporary=True)
    nav.set_goal(task)
    # the robot now stands (say) 1 m from T, closer than d_H - margin: Bug2 starts over here
    here = task + np.array([0.0, -1.0])
    assert 1.0 < d_hit - nav.params.leave_margin_m
    h = nav.direction(np.array([*here, 0.0]), FREE_SCAN)
    assert np.allclose(nav.mline[0], here) and nav.hit_xy is None and nav.mode == MODE_TO_GOAL
    assert abs(math.remainder(h - math.pi / 2, 2 * math.pi)) < 1e-9


def test_visbug_start_again_forgets_the_task_boundary_walk():
    """§4.2 "start again ... with A": after start_again the task goal starts afresh (new M-line
    from where the robot is, no hit point), both on the task goal itself and after a temporary
    one (which would otherwise resume the suspended walk)."""
    for temporary in (False, True):
        nav = nav_of("visbug21")
        loop = Loop(u_trap(), nav, U_START, U_GOAL)
        task = loop.to_own(np.array(U_GOAL))
        while nav.mode != MODE_FOLLOW and loop.steps < 200:
            loop.step()
        assert nav.mode == MODE_FOLLOW and nav.hit_xy is not None
        if temporary:
            nav.set_goal(loop.to_own(np.array([1.0, 1.0])), temporary=True)
        nav.start_again()
        nav.set_goal(task)
        here = task + np.array([0.0, -3.0])
        nav.direction(np.array([*here, 0.0]), FREE_SCAN)
        assert np.allclose(nav.mline[0], here) and nav.hit_xy is None and nav.mode == MODE_TO_GOAL


def test_potential_field_trapped_in_the_u_escapes_with_a_temporary_goal():
    """§5 rule 3 / §3 rule 5 on the potential field: trapped alone under the cup; a temporary
    goal at a teammate seen out of the cup's mouth takes it out, and from there the field
    (descended again, Fig. 9) brings it round the cup to its goal."""
    nav = nav_of("potential_field")
    loop = Loop(u_trap(), nav, U_START, U_GOAL)
    assert loop.run(400) is None and not loop.progress[-1]  # trapped (as in the test above)
    mate = np.array([1.5, 2.0])
    nav.set_goal(loop.to_own(mate), temporary=True)
    assert nav.temporary
    for _ in range(300):
        if np.hypot(*(loop.pose[:2] - mate)) < 0.5:
            break
        loop.step()
    assert np.hypot(*(loop.pose[:2] - mate)) < 0.5
    nav.set_goal(loop.to_own(np.array(U_GOAL)))
    assert not nav.temporary
    steps = loop.run(loop.steps + 400)
    assert steps is not None and loop.stalls == 0
    assert min(p[0] for p in loop.path[-100:]) < 3.5  # it went round the cup's west side


# ---------------------------------------------------------------------------- local direction, hit distance
@settings(max_examples=25, deadline=None)
@given(th=st.floats(-math.pi, math.pi), dx=st.floats(-0.1, 0.1), dy=st.floats(-0.3, 0.3))
def test_visbug_nearer_end_turns_towards_the_door_on_the_goals_side(th, dx, dy):
    """In room N3 of office_simple, against its east wall: the sensed ends of the room's wall
    are its door's jambs (x 16.0 and 17.2, y 8.4) whatever the beams' sampling; the robot turns
    towards the jamb nearer the goal's way: clockwise (side -1) for room N5 to the east,
    counter-clockwise (+1) for room N1 to the west (|xO| + |OT|, TangentBug's heuristic)."""
    from teamnav.control.nav.local.base import scan_points
    em = builtin_map("office_simple")
    angles = np.linspace(-np.pi, np.pi, 72, endpoint=False)
    pose = np.array([17.34 + dx, 9.58 + dy, th])
    scan = RangeScan(RayCaster(em.grid, max_range_m=8.0).cast(pose[None], angles, parallel=False)[0], angles, 8.0)
    for room, side in (("room_N5", -1), ("room_N1", 1)):
        nav = make_navigator("visbug21", None, rng=np.random.default_rng(0), step_length_m=0.2, radius_m=0.2)
        assert nav.params.turn == "nearer_end"
        nav.set_goal(np.array(em.places[room]))
        nav._followed(pose, scan)
        ends = np.array(nav._ends)
        assert np.allclose(np.sort(ends[:, 0]), [16.0, 17.2], atol=0.15) and np.allclose(ends[:, 1], 8.4, atol=0.2)
        nav._choose_side(pose[:2])
        assert nav.side == side
    assert scan_points(pose, scan).shape[0] > 0


def test_visbug_nearer_end_leaves_a_room_by_its_door_towards_the_goal():
    """From room N3 to room N5: "nearer_end" goes out of the door and east; a fixed "left"
    (the obstacle on the right) goes out west and round the whole building."""
    em = builtin_map("office_simple")
    near = Loop(em.grid, nav_of("visbug21"), (14.0, 11.0), em.places["room_N5"])
    assert near.run(600) is not None and near.stalls == 0
    left = Loop(em.grid, nav_of("visbug21", {"turn": "left"}), (14.0, 11.0), em.places["room_N5"])
    steps = left.run(3000)
    assert steps is not None and steps > 3 * near.steps


def test_visbug_hit_distance_is_where_the_obstacle_cuts_the_m_line():
    """Bug2's H lies on the M-line at the obstacle; the robot stops up to a step short of it.
    d_H is measured there, so an M-line point between the robot and the wall is no leave point."""
    b = MapBuilder(12.0, 10.0, 0.1).border(0.2).rect(5.0, 2.0, 5.3, 8.0)
    nav = nav_of("visbug21")
    loop = Loop(b.build("wall"), nav, (2.0, 5.0), (9.0, 5.0), frame=(0.0, 0.0, 0.0))
    while nav.mode != MODE_FOLLOW and loop.steps < 200:
        loop.step()
    d_robot = float(np.hypot(*(nav.goal_xy - nav.hit_xy)))
    # the wall's face is at x = 5.0; the blocked M-line point lies within R (+ a sample) of it
    r_safe = RADIUS_M + nav.params.safety_margin_m
    assert 9.0 - 5.0 + r_safe - 0.1 - 1e-9 <= nav.hit_dist_m <= 9.0 - 5.0 + r_safe + 1e-9
    assert nav.hit_dist_m < d_robot
    assert loop.run(600) is not None


def test_visbug_resumes_with_step1_when_the_excursion_left_the_boundary_far_behind():
    nav = nav_of("visbug21")
    loop = Loop(u_trap(), nav, U_START, U_GOAL)
    task = loop.to_own(np.array(U_GOAL))
    while nav.mode != MODE_FOLLOW and loop.steps < 200:
        loop.step()
    loop.step()
    hit, mline, d_hit = nav.hit_xy, nav.mline, nav.hit_dist_m
    nav.set_goal(loop.to_own(np.array([1.0, 1.0])), temporary=True)
    nav.set_goal(task)
    # back 3 m from the cup, in the open: not the walk of the cup's boundary, but Step 1 on the kept M-line
    far = loop.to_own(np.array([9.5, 2.0]))
    nav.direction(np.array([*far, 0.0]), FREE_SCAN)
    assert nav.mode == MODE_TO_GOAL and nav.mline is mline and nav.hit_xy is hit and nav.hit_dist_m == d_hit


# ---------------------------------------------------------------------------- paper rules
def test_visbug_as_written_reaches_the_goal_behind_the_u_cutting_across_the_boundary():
    """``paper_rules``: one fixed turn (right, the paper column's fill chosen on tuning tasks), and
    Step 2's Ti may be the farthest visible boundary point (``boundary_shortcut``): Bug2 still
    arrives, on the right side, no slower than the follower."""
    follower = Loop(u_trap(), nav_of("visbug21", {"turn": "right"}), U_START, U_GOAL)
    base = follower.run(600)
    nav = nav_of("visbug21", {"paper_rules": True})
    assert nav.params.turn == "right" and nav.params.boundary_shortcut
    loop = Loop(u_trap(), nav, U_START, U_GOAL)
    steps = loop.run(600)
    assert steps is not None and base is not None and loop.stalls == 0
    assert max(p[0] for p in loop.path) > 8.7  # round the cup's east side
    assert steps <= base


def test_visbug_boundary_target_is_the_farthest_visible_point_ahead():
    """A wall 0.6 m to the right (y = -0.6), the robot walking it with the wall on its right
    (side +1): the target lies ahead (+x), stood back from the wall, and is seen free."""
    nav = nav_of("visbug21", {"boundary_shortcut": True, "turn": "left"})
    nav.side, nav._slack = 1, math.pi / 72
    wall = np.column_stack((np.linspace(-2.0, 3.0, 51), np.full(51, -0.6)))
    t = nav._boundary_target(np.zeros(2), wall, wall, 0.25, 0.33, 7.7)
    assert t is not None and t[0] > 1.0 and abs(t[1] - (-0.6 + 0.33)) < 1e-9
    nav.side = -1  # walking the other way: the target lies behind (-x)
    t = nav._boundary_target(np.zeros(2), wall, wall, 0.25, 0.33, 7.7)
    assert t is not None and t[0] < -1.0


def test_avoid_past_as_written_keeps_one_memory():
    """The memory's lifetime is a fill the same in both columns (the paper gives none): paper_rules
    keeps the default and lets an ablation choose another lifetime."""
    nav = nav_of("avoid_past", {"paper_rules": True})
    assert nav.params.memory_scope == "robot"
    assert nav.params.memory_half_life_steps == nav_of("avoid_past").params.memory_half_life_steps
    assert nav_of("avoid_past", {"paper_rules": True, "memory_scope": "goal"}).params.memory_scope == "goal"
    assert nav_of("potential_field", {"paper_rules": True}).params.paper_rules
