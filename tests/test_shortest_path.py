"""Shortest paths through a grid's free space (teamnav.world.shortest_path) and the floor of the
line-of-sight tasks built on them (los_tasks.shortest_steps_*)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.papers.los_help import tasks as L
from teamnav.world import OccupancyGrid
from teamnav.world.shortest_path import MOVE_ERROR_BOUND, GridPaths

RES = 0.1


def _box(h=60, w=80, wall=False):
    cells = np.zeros((h, w), np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = 1
    if wall:
        cells[: h - 15, w // 2] = 1  # a wall from the bottom up to 1.5 m below the top
    return OccupancyGrid(cells, RES, name="test-box")


_EMPTY = GridPaths(_box(), 0.0)
_WALL = GridPaths(_box(wall=True), 0.2)
_pt = st.tuples(st.floats(0.35, 7.6), st.floats(0.35, 5.6))


@settings(max_examples=60, deadline=None)
@given(_pt, _pt)
def test_in_open_space_the_path_is_the_straight_line_within_the_move_error(a, b):
    d = math.dist(a, b)
    got = float(_EMPTY.lengths([a], [b])[0, 0])
    # cell centres stand in for the points: up to half a cell diagonal at each end
    slack = 2 * math.hypot(RES, RES) / 2
    assert d - slack - 1e-9 <= got <= d * (1 + MOVE_ERROR_BOUND) + slack + 1e-9


@settings(max_examples=40, deadline=None)
@given(_pt, _pt)
def test_lengths_are_symmetric(a, b):
    ab = _EMPTY.lengths([a], [b])[0, 0]
    ba = _EMPTY.lengths([b], [a])[0, 0]
    assert ab == pytest.approx(ba, abs=1e-9)


def test_a_wall_is_walked_round_over_its_end_with_the_clearance():
    grid = _box(wall=True)
    c = 0.3
    paths = GridPaths(grid, c)
    a, b = (2.05, 1.05), (6.05, 1.05)
    # the wall's top end is the cell row 44 (y 4.4-4.5) at x 4.0-4.1: the shortest path bends round a
    # point c above it (the obstacle cell's centre, where the distance is measured from)
    corner = (4.05, 4.45 + c)
    analytic = math.dist(a, corner) + math.dist(corner, b)
    got = float(paths.lengths([a], [b])[0, 0])
    assert analytic - 0.1 <= got <= analytic * (1 + MOVE_ERROR_BOUND) + 0.2
    assert got > 1.5 * math.dist(a, b)  # far longer than the straight line it may not take


def test_no_path_is_infinite_and_several_sources_give_a_matrix():
    cells = np.zeros((20, 40), np.uint8)
    cells[:, 20] = 1  # a wall across the map
    paths = GridPaths(OccupancyGrid(cells, RES), 0.0)
    d = paths.lengths([[0.55, 0.55], [0.55, 1.05]], [[1.55, 0.55], [3.55, 0.55]])
    assert d.shape == (2, 2) and np.isfinite(d[:, 0]).all() and np.isinf(d[:, 1]).all()


def test_bad_points_and_clearances_are_named_in_the_error():
    grid = _box()
    with pytest.raises(ValueError, match=r"sources_xy\[0\] = \(0.05, 3\) m is not free space with 0.2 m clearance on map test-box"):
        GridPaths(grid, 0.2).lengths([[0.05, 3.0]], [[4.0, 3.0]])
    with pytest.raises(ValueError, match=r"targets_xy\[1\] = \(40, 3\) m is outside map test-box"):
        GridPaths(grid, 0.2).lengths([[4.0, 3.0]], [[4.0, 3.0], [40.0, 3.0]])
    for bad in (-0.1, float("nan"), "0.2"):
        with pytest.raises(ValueError, match="clearance_m must be a finite number >= 0"):
            GridPaths(grid, bad)


# ---------------------------------------------------------------------------- the los floor
@pytest.mark.parametrize("m", ["simple", "complex"])
def test_the_floor_is_the_shortest_path_through_the_targets_less_the_tolerance(m):
    rooms = L.room_centres(m)
    names = list(rooms)
    a, b = rooms[names[0]], rooms[names[-1]]
    paths = GridPaths(L._env(m).grid, L.RADIUS_M)
    start = L.LAYOUTS[m].r1_start[:2]
    eps = L.GOAL_TOLERANCE_M
    want = (paths.lengths([start], [a])[0, 0] - eps + paths.lengths([a], [b])[0, 0] - 2 * eps) / L.STEP_LENGTH_M / 2
    assert L.shortest_steps_for_targets(m, [a, b]) == pytest.approx(want, rel=1e-9)
    # through walls: the shortest path is longer than the straight line between the rooms
    assert paths.lengths([a], [b])[0, 0] > math.dist(a, b)


def test_the_floor_names_a_target_that_is_not_a_room_centre():
    with pytest.raises(ValueError, match=r"targets_world\[1\] = \(15, 7\) m is not a room centre of office_simple"):
        L.shortest_steps_for_targets("simple", [L.room_centres("simple")["room_S1"], (15.0, 7.0)])
    with pytest.raises(ValueError, match="at least one target"):
        L.shortest_steps_for_targets("simple", [])


def test_no_navigator_beats_the_floor_on_a_short_task():
    """R1 alone with VisBug-21 on the first 4 targets of task 1: its steps per target can only be
    above the shortest path (a floor computed too long would fail here)."""
    from teamnav import load_scenario, run
    from teamnav.papers.los_help.metrics import los_help

    n = 4
    over = {"robots.0.params.targets_xy": L.task_targets_xy("simple", 1, n), **L.team_overrides("simple", 0)}
    data = run(load_scenario("los-help-simple", overrides=over), progress=False).data
    m = los_help(data)
    assert m["los_finished"] == 1
    floor = L.shortest_steps_per_target("simple", 1, n)
    assert floor < m["los_steps_per_target"] < 6 * floor


@settings(max_examples=40, deadline=None)
@given(_pt, _pt, _pt)
def test_lengths_obey_the_triangle_inequality_round_a_wall(a, b, c):
    try:
        d = _WALL.lengths([a, b], [b, c])
        ac = _WALL.lengths([a], [c])[0, 0]
    except ValueError:
        return  # a point on the wall or within its clearance: not a free point
    assert ac <= d[0, 0] + d[1, 1] + 1e-9

