"""office_complex as the line-of-sight help experiments use it (Sgorbissa & Arkin §6, Fig. 13, Table 2).

The map must trap a potential field (§6: "1) does not guarantee the robot to reach its target
without the help of other robots because of the presence of local minima") while the helpers
"patrolling the corridors" see every target (Table 2: helpers cut R1's steps on this map).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from teamnav.papers.los_help import tasks as L
from teamnav.experiments.runner import run
from teamnav.experiments.spec import load_scenario
from teamnav.world import builtin_map


def _sees(occ, res, a, b, max_range_m=L.VISIBILITY_M) -> bool:
    n = int(math.dist(a, b) / 0.02) + 2
    xs, ys = np.linspace(a[0], b[0], n), np.linspace(a[1], b[1], n)
    return math.dist(a, b) <= max_range_m and not occ[(ys / res).astype(int), (xs / res).astype(int)].any()


def _route_samples(start, route, step_m=0.25):
    pts = [start[:2], *route]
    out = []
    for a, b in zip(pts, pts[1:]):
        n = max(2, int(math.dist(a, b) / step_m) + 1)
        out += [(a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t) for t in np.linspace(0.0, 1.0, n)]
    return out


def test_h_corridor_helpers_step_into_every_door_and_see_every_target():
    env = builtin_map(L.MAPS["complex"])
    occ, res = np.asarray(env.grid.occupied()), env.grid.resolution_m
    doors_h = {k: env.places[f"door_{k}"] for k in range(1, 9)}
    targets = {k: env.places[f"room_{k}"] for k in range(1, 9)}
    for helper in (0, 2):  # R2 and R4 walk H
        start, route = L.LAYOUTS["complex"].helpers[helper]
        for k, door in doors_h.items():
            assert any(math.dist(p, door) < 0.05 for p in route), (helper, k)
        samples = _route_samples(start, route)
        unseen = [k for k, t in targets.items() if not any(_sees(occ, res, p, t) for p in samples)]
        assert unseen == [], (helper, unseen)
    # R2 starts at the west end going east, R4 at the east end going west (opposite phases)
    (s2, r2), (s4, r4) = L.LAYOUTS["complex"].helpers[0], L.LAYOUTS["complex"].helpers[2]
    assert s2[0] < 10 < 26 < s4[0] and r2[-1][0] > 30 and r4[-1][0] < 5
    # R3 walks V from end to end and stops in front of each of its four doors
    s3, r3 = L.LAYOUTS["complex"].helpers[1]
    for k in (2, 3, 6, 7):
        dx, dy = env.places[f"door_{k}v"]
        assert any(abs(p[1] - dy) < 0.05 and abs(p[0] - dx) < 0.75 for p in r3), k


def _leg(navigator: str, a: str, b: str, helpers: int, budget_steps: int):
    """R1 from room ``a``'s centre (heading 90 deg) to room ``b``'s, alone or with helpers."""
    env = builtin_map(L.MAPS["complex"])
    start = (*env.places[a], 90.0)
    target = L.world_to_frame(start, [env.places[b]])[0]
    over = {
        "robots.0.params.navigator": navigator,
        "robots.0.params.state_sharing": navigator == "potential_field",
        "robots.0.params.targets_xy": [[float(target[0]), float(target[1])]],
        "robots.0.params.max_steps_per_target": budget_steps,
        "robots.0.start.poses": [list(start)],
        **{f"robots.{k + 1}.count": int(k < helpers) for k in range(3)},
    }
    scn = load_scenario("los-help-complex", overrides=over, duration_s=budget_steps * L.DT_S)
    return run(scn, progress=False).metrics


def test_potential_field_alone_sticks_in_room_1s_trap_where_visbug_gets_out():
    # room 1's U wall opens towards the centre, east of it: heading east to room 2, a potential
    # field drives into it and stays; VisBug-21 follows the walls out (the long way round: about
    # 1050 steps, turning right at the U and following the building's walls into room 2's V door)
    pf = _leg("potential_field", "room_1", "room_2", 0, 400)
    assert pf["los_finished"] == 0 and pf["los_gave_up"] == 1
    vb = _leg("visbug21", "room_1", "room_2", 0, 2000)
    assert vb["los_finished"] == 1 and vb["los_steps"] < 2000


def _helper_log(timeout_steps: int) -> dict:
    """R2 of los-help-complex sent first to a point inside the corridor's south wall (unreachable),
    then back to its start; its last log after 12 s (120 steps)."""
    start, _ = L.LAYOUTS["complex"].helpers[0]
    patrol = L.world_to_frame(start, [(5.0, 10.7), start[:2]]).round(4).tolist()
    over = {"robots.1.params.patrol_xy": patrol, "robots.1.params.waypoint_timeout_steps": timeout_steps,
            "robots.1.params.navigator": "potential_field",  # straight back to its start once it gives up
            "robots.2.count": 0, "robots.3.count": 0, "record_every": 1, "stop_when_finished": False}
    data = run(load_scenario("los-help-complex", overrides=over, duration_s=12.0), progress=False).data
    return [e["values"] for e in data.logs if e["robot"] == 1][-1]


def test_a_helper_passes_over_a_waypoint_it_cannot_reach_after_its_timeout():
    stuck = _helper_log(0)
    assert stuck["target_index"] == 0 and stuck["waypoints_skipped"] == 0  # without a timeout it tries forever
    moved = _helper_log(50)
    # passed over at step 51, back at its start (2 m) ~10 steps later, passed over again at ~112
    assert moved["waypoints_skipped"] == 2 and moved["targets_reached"] >= 1
