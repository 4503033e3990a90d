"""office_complex's potential-field traps and the helpers' sight of them (Sgorbissa & Arkin §5-§6, Fig. 13, Table 2).

§5 frees a trapped R1 only through a teammate in sight; Table 2's potential field with helpers
finishes every complex-map task, so no trap of the paper's map was out of every helper's sight.
``office_complex`` has three (the 1.6 m alleys behind the U walls of rooms 1, 2 and 8);
``office_complex_closed`` closes them (the U's back flush with the room's wall), so a potential
field is trapped inside the U as in Fig. 13, in sight of the room's doorway.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from teamnav.papers.los_help import tasks as L
from teamnav.experiments.runner import run
from teamnav.experiments.spec import load_scenario
from teamnav.world import builtin_map
from teamnav.world.los import line_of_sight

#: Where R1 on the potential field gave up (2500 steps on one target) in the default runs on
#: office_complex (40-target prefixes of tasks 1-5, R1+R2 and R1..R4), with its target then.
ALLEY_GIVE_UPS: dict[str, tuple[tuple[float, float], tuple[float, float]]] = {
    "room 1 behind its U": ((7.6, 5.4), (12.5, 5.4)),
    "room 2 behind its U": ((16.2, 5.4), (22.0, 5.4)),
    "room 8 behind its U": ((28.0, 18.6), (23.4, 18.6)),
}
#: The alleys (xmin, ymin, xmax, ymax) [m] between a U's back and its room's wall, and the room.
ALLEYS: dict[int, tuple[float, float, float, float]] = {
    1: (6.6, 3.4, 8.2, 7.4), 2: (15.0, 3.4, 16.6, 7.4), 8: (27.6, 16.2, 29.2, 21.0)}


def _blocking(name):
    g = builtin_map(name).grid
    return np.ascontiguousarray(np.asarray(g.occupied()).astype(np.uint8)), g.resolution_m


@pytest.fixture(scope="module")
def grids():
    return {name: _blocking(name) for name in ("office_complex", "office_complex_closed")}


def _samples(route, step_m=0.1):
    pts = []
    for a, b in zip(route[:-1], route[1:]):
        n = max(1, math.ceil(math.dist(a, b) / step_m))
        pts += [(a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t) for t in np.arange(n) / n]
    return np.array([*pts, route[-1]], dtype=float)


def _seen_from(grid, p, pts) -> bool:
    """Is ``p`` in line of sight within the visibility radius of any of ``pts``?"""
    blk, res = grid
    pts = np.asarray(pts, dtype=float).reshape(-1, 2)
    near = np.hypot(pts[:, 0] - p[0], pts[:, 1] - p[1]) <= L.VISIBILITY_M
    vis = np.asarray(line_of_sight(blk, 0.0, 0.0, res, np.full(len(pts), float(p[0])),
                                   np.full(len(pts), float(p[1])), pts[:, 0].copy(), pts[:, 1].copy()))
    return bool((near & vis).any())


def test_the_alleys_behind_the_u_walls_are_out_of_every_route_s_sight_and_closed_in_the_variant(grids):
    routes = [_samples(r) for r in L.team_routes("complex", 3)]
    open_, closed = grids["office_complex"], grids["office_complex_closed"]
    for name, (p, target) in ALLEY_GIVE_UPS.items():
        assert open_[0][int(p[1] / 0.1), int(p[0] / 0.1)] == 0, name  # free on office_complex
        assert not any(_seen_from(open_, p, pts) for pts in routes), name  # no helper of R1..R4 sees it
        assert not _seen_from(open_, p, [target]), name  # nor R1 its target there (a wall between)
        assert closed[0][int(p[1] / 0.1), int(p[0] / 0.1)] == 1, name  # a wall on office_complex_closed
    # the variant differs from the map exactly by the three alleys, filled; places and notes alike
    a, b = builtin_map("office_complex"), builtin_map("office_complex_closed")
    filled = np.zeros_like(open_[0], dtype=bool)
    for x0, y0, x1, y1 in ALLEYS.values():
        filled[round(y0 / 0.1):round(y1 / 0.1), round(x0 / 0.1):round(x1 / 0.1)] = True
    diff = open_[0] != closed[0]
    assert diff.any() and not (diff & ~filled).any() and (closed[0][filled] == 1).all()
    assert a.places == b.places and b.grid.name == "builtin:office_complex_closed"


def test_on_the_closed_variant_the_doorway_sees_the_room_from_its_centre_to_the_wall_behind_the_u(grids):
    """Every free spot (robot clearance) within 0.75 m of the centre line, from the room's centre to
    the wall behind the U (the U's pocket included), is in sight of the room's doorway on the closed
    variant; on office_complex the alley behind the U is not."""
    env = builtin_map("office_complex")
    for k, (x0, _y0, x1, _y1) in ALLEYS.items():
        cx, cy = env.places[f"room_{k}"]
        y0, y1 = cy - 1.0, cy + 1.0
        door = env.places[f"door_{k}"]
        lo, hi = (cx, x1 + 0.1) if x0 > cx else (x0 - 0.1, cx)
        xs = np.arange(lo + 0.25, hi - 0.2, 0.2)
        ys = np.arange(y0 + 0.25, y1 - 0.2, 0.2)
        for name, expect_all in (("office_complex_closed", True), ("office_complex", False)):
            blk, res = grids[name]
            free = [(x, y) for x in xs for y in ys
                    if not blk[int((y - 0.25) / res):int((y + 0.25) / res) + 1,
                               int((x - 0.25) / res):int((x + 0.25) / res) + 1].any()]
            seen = [_seen_from(grids[name], p, [door]) for p in free]
            assert free and all(seen) == expect_all, (k, name, [p for p, s in zip(free, seen) if not s][:3])


def _pf_alone(map_name, a, b, budget_steps):
    env = builtin_map(map_name)
    start = (*env.places[a], 90.0)
    target = L.world_to_frame(start, [env.places[b]])[0]
    over = {
        "map.builtin": map_name,
        "robots.0.params.navigator": "potential_field",
        "robots.0.params.targets_xy": [[float(target[0]), float(target[1])]],
        "robots.0.params.max_steps_per_target": budget_steps,
        "robots.0.start.poses": [list(start)],
        **{f"robots.{k + 1}.count": 0 for k in range(3)},
    }
    res = run(load_scenario("los-help-complex", overrides=over, duration_s=budget_steps * L.DT_S), progress=False)
    return res.metrics, np.asarray(res.data.true_pose)[-1, 0, :2]


@pytest.mark.parametrize("a, b, k", [("room_1", "room_2", 1), ("room_8", "room_7", 8)])
def test_the_potential_field_alone_is_still_trapped_on_the_closed_variant_inside_the_u_in_sight_of_the_door(
        grids, a, b, k):
    # Fig. 13: the U traps a robot inside it; §6: "1) does not guarantee the robot to reach its
    # target without the help of other robots"
    m, end = _pf_alone("office_complex_closed", a, b, 300)
    assert m["los_finished"] == 0 and m["los_gave_up"] == 1
    x0, y0, x1, y1 = ALLEYS[k]
    u = (x0 - 1.4, y0, x0, y1) if k in (1, 2) else (x1, y0, x1 + 1.4, y1)  # the U's box
    assert u[0] <= end[0] <= u[2] and u[1] <= end[1] <= u[3], end
    door = builtin_map("office_complex").places[f"door_{k}"]
    assert _seen_from(grids["office_complex_closed"], end, [door])
