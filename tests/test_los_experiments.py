"""Line-of-sight help experiments (Sgorbissa & Arkin §6): tasks, frames, scenario files,
metrics and the report section's verdicts on hand-made rows."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.control import registry as controllers
from teamnav.papers.los_help import tasks as L
from teamnav.papers.los_help.metrics import los_help, los_legs
from teamnav.experiments.metrics import RunData
from teamnav.experiments.report.model import Comparison, Missing, Plot, Table, Text
from teamnav.papers.los_help.report import section as S
from teamnav.world import builtin_map
from teamnav.world.distance import distance_field

BRAINS = {"los-explorer-v1", "los-helper-v1"} <= set(controllers.names())
needs_brains = pytest.mark.skipif(not BRAINS, reason="los-explorer-v1 / los-helper-v1 not registered yet")


# ---------------------------------------------------------------------------- tasks
@pytest.mark.parametrize("m", list(L.MAPS))
def test_tasks_are_deterministic_distinct_and_never_repeat_a_room_twice_in_a_row(m):
    tasks = [L.task_rooms(m, t) for t in range(1, L.N_TASKS + 1)]
    assert tasks[0] == L.task_rooms(m, 1)  # same list on every call
    assert len({tuple(t) for t in tasks}) == L.N_TASKS  # 5 different random target sets
    rooms = set(L.room_centres(m))
    for t in tasks:
        assert len(t) == L.N_TARGETS and set(t) == rooms  # 200 targets visit every room
        assert all(a != b for a, b in zip(t, t[1:]))
        # roughly uniform: every room between 1/3 and 3x its share
        counts = np.array([t.count(r) for r in rooms])
        assert counts.min() > L.N_TARGETS / len(rooms) / 3 and counts.max() < 3 * L.N_TARGETS / len(rooms)
    assert L.task_rooms(m, 2, 7) == tasks[1][:7]  # a quick task is a prefix of the full one


def test_the_first_targets_are_pinned_so_shipped_files_cannot_drift():
    assert L.task_rooms("simple", 1, 4) == ["room_N2", "room_N1", "room_S4", "room_S2"]
    assert L.task_rooms("complex", 1, 3) == L.task_rooms("complex", 1, 3)


@pytest.mark.parametrize("m", list(L.MAPS))
def test_targets_sit_in_free_space_in_the_middle_of_rooms(m):
    env = builtin_map(L.MAPS[m])
    clear = distance_field(env.grid)
    pts = L.task_targets_world(m, 3)
    for x, y in pts:
        r, c = env.grid.world_to_cell((x, y))
        assert clear[r, c] >= 1.0, (x, y)  # a metre from any wall or obstacle
    centres = {tuple(v) for v in L.room_centres(m).values()}
    assert {tuple(p) for p in pts.tolist()} <= centres


@pytest.mark.parametrize("m", list(L.MAPS))
def test_patrol_routes_and_starts_lie_in_the_corridors_with_clearance(m):
    env = builtin_map(L.MAPS[m])
    clear = distance_field(env.grid)
    corridors = [v for k, v in env.regions.items() if k.startswith("corridor")]
    lay = L.LAYOUTS[m]
    pts = [lay.r1_start[:2]] + [p for start, route in lay.helpers for p in (start[:2], *route)]
    for x, y in pts:
        r, c = env.grid.world_to_cell((x, y))
        assert clear[r, c] >= L.RADIUS_M + 0.3, (x, y)
        # in a corridor, or in a doorway just off it (the simple map's helpers step into the doors)
        assert any(x0 <= x <= x1 and y0 - 0.4 <= y <= y1 + 0.4 for x0, y0, x1, y1 in corridors), (x, y)


@pytest.mark.parametrize("m", list(L.MAPS))
def test_helpers_give_up_a_waypoint_only_well_after_the_longest_leg_of_any_route(m):
    # the waypoint timeout ends deadlocks in doorways (a helper blocked by R1 for thousands of
    # steps, los_tasks.HELPER_WAYPOINT_TIMEOUT_STEPS); it must never cut a free leg short, even
    # with a detour of the leg's own length around a teammate
    timeout = L.HELPER_WAYPOINT_TIMEOUT_STEPS[m]
    assert L.HELPER_NAVIGATOR[m] == "visbug21"  # walks back out of a room it was pushed into
    legs = []
    for team in L.TEAMS:
        for (start, _), route in zip(L.LAYOUTS[m].helpers, L.team_routes(m, team)):
            pts = [start[:2], *route]
            legs += [math.dist(a, b) / L.STEP_LENGTH_M for a, b in zip(pts, pts[1:])]
    assert 2.0 * max(legs) <= timeout, (max(legs), timeout)
    assert timeout <= 0.1 * L.BUDGET_STEPS_PER_TARGET[m]  # and a deadlock ends long before R1 gives up


@pytest.mark.parametrize("both", [False, True])
def test_simple_r2_route_steps_into_the_south_doors_or_every_door(both):
    # R2 alone steps into the north doorways too (where R1 trapped in N4/N5 sees it)
    route = L.simple_r2_route(both)
    env = builtin_map(L.MAPS["simple"])
    clear = distance_field(env.grid)
    for x, y in route:
        r, c = env.grid.world_to_cell((x, y))
        assert clear[r, c] >= L.RADIUS_M + 0.3, (x, y)
    south = {x for x, y in route if y < 5.8}
    north = {x for x, y in route if y > 8.2}
    assert south == set(L.SIMPLE_DOORS_S)
    assert north == (set(L.SIMPLE_DOORS_N) if both else set())
    xs = [x for x, _ in route]
    assert xs == sorted(xs) and route[0][0] == 1.0 and route[-1][0] == 29.0  # west to east, end to end


def test_r1_r2_team_r2_passes_every_door_on_both_sides_and_sees_every_room_from_a_doorway():
    env = builtin_map(L.MAPS["simple"])
    occ, res = np.asarray(env.grid.occupied()), env.grid.resolution_m
    route = L.team_routes("simple", 1)[0]
    doorways = {(x, 5.5) for x in L.SIMPLE_DOORS_S} | {(x, 8.5) for x in L.SIMPLE_DOORS_N}
    assert doorways <= set(route) and len(doorways) == 10
    # from its doorways R2 sees each room's centre: a robot trapped in any room sees R2 (§5)
    centres = L.room_centres("simple")
    seen = {r for r, c in centres.items() for p in doorways if _sees(occ, res, p, c)
            and math.hypot(c[0] - p[0], c[1] - p[1]) <= L.VISIBILITY_M}
    assert seen == set(centres)
    # the sweep's case carries that route in R2's own start frame
    ov = L.team_overrides("simple", 1)
    assert ov["robots.1.count"] == 1 and ov["robots.2.count"] == ov["robots.3.count"] == 0
    world = L.frame_to_world(L.LAYOUTS["simple"].helpers[0][0], ov["robots.1.params.patrol_xy"])
    np.testing.assert_allclose(world, np.array(route), atol=1e-4)


@pytest.mark.parametrize("m", list(L.MAPS))
def test_the_r1_to_r4_and_r1_to_r3_teams_keep_the_scenario_files_routes(m):
    from teamnav.experiments.spec import load_scenario

    scn = load_scenario(L.SCENARIOS[m])
    shipped = [g.params["patrol_xy"] for g in scn.robots[1:]]
    for h in (2, 3):
        assert [L.patrol_xy(m, k, h) for k in range(3)] == [[list(p) for p in r] for r in shipped]
        assert not [k for k in L.team_overrides(m, h) if "patrol_xy" in k]  # counts only
    # R1..R4 on office_simple: R2 south doors only, R3 north doors only (the split)
    if m == "simple":
        r2, r3 = L.team_routes(m, 3)[:2]
        assert {x for x, y in r2 if y < 5.8} == set(L.SIMPLE_DOORS_S) and all(y < 8.2 for _, y in r2)
        assert {x for x, y in r3 if y > 8.2} == set(L.SIMPLE_DOORS_N) and all(y > 5.8 for _, y in r3)
    else:
        assert L.team_routes(m, 1) == L.team_routes(m, 3)  # one route per helper on office_complex
    with pytest.raises(ValueError, match="team must be one of"):
        L.team_routes(m, 4)


def _sees(occ, res, a, b):
    """Line of sight between two world points on an occupancy grid (2 cm samples)."""
    n = int(math.hypot(b[0] - a[0], b[1] - a[1]) / 0.02) + 2
    xs, ys = np.linspace(a[0], b[0], n), np.linspace(a[1], b[1], n)
    return not occ[(ys / res).astype(int), (xs / res).astype(int)].any()


@pytest.mark.parametrize("m, rooms", [("simple", None), ("complex", {"room_3", "room_5", "room_7"})])
def test_every_helper_route_passes_where_it_sees_into_the_rooms(m, rooms):
    # §6: helpers patrol the corridors; a room centre is seen from there only through the room's
    # door, from a short stretch beside it: each route must pass those stretches (simple map: all
    # ten rooms, the doors of S1 and N5 lie at the corridor's ends)
    env = builtin_map(L.MAPS[m])
    occ, res = np.asarray(env.grid.occupied()), env.grid.resolution_m
    centres = L.room_centres(m)
    want = set(centres) if rooms is None else rooms
    for k, (start, route) in enumerate(L.LAYOUTS[m].helpers):
        pts = [start[:2], *route]
        seen = {r for a, b in zip(pts, pts[1:]) for t in np.linspace(0.0, 1.0, 150)
                for r, c in centres.items()
                if (p := (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t))
                and math.hypot(c[0] - p[0], c[1] - p[1]) <= L.VISIBILITY_M and _sees(occ, res, p, c)}
        if m == "simple" or k != 1:  # on the complex map R3 (north-south corridor) sees room 7 only
            assert seen >= want, (k, sorted(want - seen))


# ---------------------------------------------------------------------------- frames
poses = st.tuples(st.floats(-50, 50), st.floats(-50, 50), st.floats(-360, 360))
points = st.lists(st.tuples(st.floats(-100, 100), st.floats(-100, 100)), min_size=1, max_size=5)


@settings(max_examples=200, deadline=None)
@given(poses, points)
def test_start_frame_conversion_round_trips_and_keeps_distances(pose, pts):
    local = L.world_to_frame(pose, pts)
    np.testing.assert_allclose(L.frame_to_world(pose, local), np.asarray(pts), atol=1e-9)
    d_world = np.hypot(*(np.asarray(pts) - np.asarray(pose[:2])).T)
    np.testing.assert_allclose(np.hypot(*local.T), d_world, atol=1e-9)


@settings(max_examples=100, deadline=None)
@given(poses, st.floats(0.1, 20))
def test_a_point_straight_ahead_of_the_start_is_on_the_frames_x_axis(pose, d):
    x, y, th = pose
    ahead = (x + d * math.cos(math.radians(th)), y + d * math.sin(math.radians(th)))
    np.testing.assert_allclose(L.world_to_frame(pose, [ahead])[0], [d, 0.0], atol=1e-9)


def test_targets_xy_are_the_world_targets_in_r1s_start_frame():
    xy = np.array(L.task_targets_xy("complex", 2, 10))
    np.testing.assert_allclose(L.frame_to_world(L.LAYOUTS["complex"].r1_start, xy), L.task_targets_world("complex", 2, 10),
                               atol=1e-4)
    # R1 starts facing 90 deg: its frame is not the world's, so the numbers must differ
    assert not np.allclose(xy, L.task_targets_world("complex", 2, 10), atol=1.0)


# ---------------------------------------------------------------------------- files
def test_shipped_scenario_and_sweep_files_are_what_the_generator_writes(tmp_path):
    from teamnav.experiments import registry
    from teamnav.experiments.sweep import sweep_files

    (tmp_path / "sc").mkdir()
    (tmp_path / "sw").mkdir()
    for p in L.write_files(tmp_path / "sc", tmp_path / "sw"):
        shipped = registry.path(p.stem) if p.parent.name == "sc" else sweep_files()[p.stem]
        assert shipped.read_text(encoding="utf-8") == p.read_text(encoding="utf-8"), (
            f"{shipped.name} is stale: run python -m teamnav.papers.los_help.tasks")


@needs_brains
@pytest.mark.parametrize("name", ["los-help-simple", "los-help-complex", "los-help-noise"])
def test_every_los_help_scenario_validates_with_the_robots_in_their_roles(name):
    from teamnav.experiments.spec import load_scenario

    scn = load_scenario(name)
    assert [g.controller for g in scn.robots] == ["los-explorer-v1"] + ["los-helper-v1"] * 3
    assert [g.count for g in scn.robots] == [1, 1, 1, 1]
    assert all(g.kinematics == "holonomic_step" and g.odometry.frame == "start" for g in scn.robots)
    assert all(g.detector.noise_model == "occlusion" and g.detector.fov_deg == 360 for g in scn.robots)
    assert scn.radio.mode == "line_of_sight" and scn.stop_when_finished
    assert len(scn.robots[0].params["targets_xy"]) == L.N_TARGETS
    assert scn.robots[0].params["navigator"] == "visbug21" and scn.robots[0].params["state_sharing"] is False


@needs_brains
def test_one_override_sets_err_max_of_every_robot_and_helpers_can_be_dropped():
    from teamnav.experiments.spec import load_scenario

    scn = load_scenario("los-help-complex", overrides={"robots.0.detector.err_max": 0.3, "robots.2.count": 0})
    assert [g.detector.err_max for g in scn.robots] == [0.3] * 4
    assert [g.count for g in scn.robots] == [1, 1, 0, 1]
    assert load_scenario("los-help-noise").robots[3].detector.err_max == 0.2


def test_sweeps_grid_what_the_paper_varies():
    from teamnav.experiments.sweep import load_sweep

    t1 = load_sweep("los-table1")
    # the paper's nested teams (R1; R1,2; R1..3; R1..4) x 3 algorithms x 5 tasks
    assert t1.n_trials == 3 * 4 * len(L.JUDGED_TASKS) and not t1.set and list(t1.grid) == [S.TARGETS_KEY]
    # §6: the potential field with state + goal sharing, Avoid-Past and VisBug with goal sharing only
    ties = {c[S.NAV_KEY]: c[S.STATE_KEY] for c in t1.cases}
    assert ties == {"potential_field": True, "avoid_past": False, "visbug21": False}
    for t in (t1, load_sweep("los-table2")):
        teams = {c["case"]: [c[f"robots.{k}.count"] for k in (1, 2, 3)] for c in t.cases}
        assert teams["visbug21/R1"] == [0, 0, 0] and teams["pot-field/R1-2"] == [1, 0, 0]
        assert teams["avoid-past/R1-3"] == [1, 1, 0] and teams["avoid-past/R1-4"] == [1, 1, 1]
        assert sorted(map(tuple, teams.values())) == sorted([(0, 0, 0), (1, 0, 0), (1, 1, 0), (1, 1, 1)] * 3)
    # the R1+R2 team's R2 walks both sides of office_simple's corridor, on the complex map no change
    assert "robots.1.params.patrol_xy" in [c for c in t1.cases if c["case"] == "visbug21/R1-2"][0]
    assert not any("robots.1.params.patrol_xy" in c for c in load_sweep("los-table2").cases)
    assert t1.grid["robots.0.params.targets_xy"][4] == L.task_targets_xy("simple", L.JUDGED_TASKS[4])
    from teamnav.experiments.sweep import sweep_names

    assert not [n for n in sweep_names() if n.startswith("los-") and n.endswith("-pf")]  # folded into cases
    noise = load_sweep("los-noise-complex")
    assert noise.grid[S.ERR_KEY] == list(L.ERR_MAX) and noise.scenario == "los-help-complex"
    assert load_sweep("los-ablation").n_trials == 3 * 4 * len(L.JUDGED_TASKS)


# ---------------------------------------------------------------------------- metrics
def _data(logs, *, finished, n_steps):
    z = np.zeros((1, 2, 3))
    return RunData(t_s=np.zeros(1), true_pose=z, odom_pose=z, stalled=np.zeros((1, 2), bool),
                   radius_m=np.full(2, 0.2), grid=None, n_steps=n_steps, logs=logs, finished=finished)


def _log(step, robot, **values):
    return {"step": step, "t_s": step * 0.1, "robot": robot, "values": values}


def test_metrics_read_r1s_last_log_and_add_the_unrecorded_tail_of_a_finished_run():
    logs = [
        _log(0, 0, targets_reached=0, finished=False, moves=0, msgs_sent=0, bytes_sent=0, tr=False),
        _log(0, 1, targets_reached=0, moves=0, msgs_sent=0, bytes_sent=0),  # a helper: no "finished"
        _log(10, 0, targets_reached=1, finished=False, moves=9, msgs_sent=4, bytes_sent=400, tr=True),
        _log(10, 1, targets_reached=7, moves=10, msgs_sent=6, bytes_sent=800),
    ]
    m = los_help(_data(logs, finished=True, n_steps=13))
    assert m["los_finished"] == 1 and m["los_steps"] == 9 + 3 and m["los_targets_reached"] == 1
    assert m["los_msgs_r1"] == 4 and m["los_msgs_per_robot"] == 5.0 and m["los_bytes_per_robot"] == 600.0
    assert m["los_trouble_frac"] == 0.5
    ahead = [_log(10, 0, targets_reached=1, finished=False, moves=11)]  # moves counted at decision time
    assert los_help(_data(ahead, finished=True, n_steps=11))["los_steps"] == 11  # never more than the run's steps
    unfinished = los_help(_data(logs, finished=False, n_steps=500))
    assert unfinished["los_finished"] == 0 and unfinished["los_steps"] == 9  # what it did, not comparable
    gave_up = logs[:2] + [_log(10, 0, targets_reached=1, finished=True, gave_up=True, moves=9, steps_ghost=4,
                               goal_seen_steps=2, temp_switches=3)]
    m = los_help(_data(gave_up, finished=True, n_steps=11))  # the run stopped on R1's "finished"
    assert m["los_finished"] == 0 and m["los_gave_up"] == 1
    assert m["los_frac_ghost"] == 4 / 11 and m["los_frac_goal_seen"] == 2 / 11 and m["los_temp_switches"] == 3


def test_max_target_steps_is_the_longest_gap_between_the_samples_that_first_show_each_target():
    # R1 reaches target 1 by step 20, targets 2 and 3 by step 70 (one sample), target 4 by step 90;
    # a helper's samples (no "finished") and R1's repeated counts change nothing
    logs = [_log(0, 0, targets_reached=0, finished=False, moves=0),
            _log(10, 0, targets_reached=0, finished=False, moves=10),
            _log(20, 0, targets_reached=1, finished=False, moves=20),
            _log(20, 1, targets_reached=9, moves=20),
            _log(40, 0, targets_reached=1, finished=False, moves=40),
            _log(70, 0, targets_reached=3, finished=False, moves=70),
            _log(90, 0, targets_reached=4, finished=True, moves=90)]
    m = los_help(_data(logs, finished=True, n_steps=91))
    assert m["los_max_target_steps"] == 50 and m["los_finished"] == 1
    # finished after its last kept sample: the last target counts as reached at the run's last step
    tail = logs[:-1]
    assert los_help(_data(tail, finished=True, n_steps=200))["los_max_target_steps"] == 130
    # not finished: only reached targets count (the one it gave up on is in los_gave_up)
    assert los_help(_data(tail, finished=False, n_steps=6000))["los_max_target_steps"] == 50
    assert los_help(_data(logs[:2], finished=False, n_steps=6000))["los_max_target_steps"] == 0


def test_metrics_are_empty_without_an_explorer_log():
    assert los_help(_data([_log(0, 1, targets_reached=3, moves=2)], finished=False, n_steps=5)) == {}


def test_legs_split_r1s_steps_into_leaving_corridor_wrong_rooms_and_entering():
    """Two legs on office_simple sampled every 10 steps: base -> room S1, then S1 -> S2 by way of a
    wrong room (N2); each interval's steps go to the leg it started in, placed where R1 ends it."""
    xy = [(1, 7), (2, 7), (1.4, 5.0), (3, 3),                      # leg 0: corridor, door, S1
          (2, 4), (1.4, 6.5), (8.9, 10), (8, 7), (7.2, 5), (8.9, 3)]  # leg 1: S1, corridor, N2, corridor, S2
    ti = [0, 0, 0, 1, 1, 1, 1, 1, 1, 2]
    pose = np.zeros((len(xy), 1, 3))
    pose[:, 0, :2] = xy
    logs = [_log(10 * k, 0, target_index=t, moves=10 * k, targets_reached=t, finished=k == len(xy) - 1)
            for k, t in enumerate(ti)]
    data = RunData(t_s=np.arange(len(xy), dtype=float), true_pose=pose, odom_pose=pose,
                   stalled=np.zeros((len(xy), 1), bool), radius_m=np.full(1, 0.2),
                   grid=builtin_map("office_simple").grid, n_steps=90, logs=logs, finished=True)
    m = los_legs(data)
    assert m == {"los_leg_leave": 5.0, "los_leg_corridor": 15.0, "los_leg_other_rooms": 5.0, "los_leg_enter": 20.0}
    assert sum(m.values()) == 90 / 2  # every step of a reached target, once
    # a map without corridors (not a built-in office) has no legs
    from teamnav.world import OccupancyGrid

    plain = RunData(t_s=data.t_s, true_pose=pose, odom_pose=pose, stalled=data.stalled, radius_m=data.radius_m,
                    grid=OccupancyGrid(np.zeros((10, 10), np.uint8), 0.1), n_steps=90, logs=logs, finished=True)
    assert los_legs(plain) == {}


# ---------------------------------------------------------------------------- section verdicts
@pytest.fixture(autouse=True)
def _no_min_pairs(monkeypatch):
    """The verdicts' mechanics are tested on hand-made rows of 2-4 tasks: fewer than the claim
    file's ``min_pairs`` (5, for the judged tasks 11-20), which would make every paired verdict
    "not judged"; the pairs rule has its own tests, which set it back."""
    from teamnav.experiments.claims import load_claims
    from teamnav.papers.los_help.report import _los_verdicts as V

    cf = load_claims("los-help")
    free = {c.id: c.model_copy(update={"min_pairs": None}) for c in cf.claims}
    monkeypatch.setattr(V, "_claim", lambda cid: free[cid])
    return free


def _row(nav, steps, finished=1, **params):
    return {"status": "ok", "params": {S.NAV_KEY: nav, S.TARGETS_KEY: [[1.0, 2.0]] * 20, **params},
            "metrics": {"los_steps": 10 * steps, "los_steps_per_target": steps, "los_finished": finished,
                        "los_msgs_per_robot": 10.0,
                        "los_bytes_per_robot": 1000.0}}


def _by_team(falling=True):
    out = {}
    for h in range(4):
        rows = []
        for task in range(2):
            base = {"avoid_past": 500, "visbug21": 800, "potential_field": 600}
            for nav, s in base.items():
                f = (s / (h + 1) if falling else s * (1 + 0.1 * h)) + 5 * task
                rows.append(_row(nav, 9999 if (nav == "potential_field" and h == 0) else f,
                                 finished=0 if (nav == "potential_field" and h == 0) else 1,
                                 **{f"robots.{k + 1}.count": int(k < h) for k in range(3)},
                                 **{S.TARGETS_KEY: [[float(task), 0.0]] * 20}))
        out[h] = rows
    return out


def test_table_cells_mean_and_relative_std_and_failures():
    assert S.cell(np.array([100.0, 120.0]), np.array([1.0, 1.0])) == "110 (12.9 %) 2/2"
    assert S.cell(np.array([5000.0, 5000.0]), np.array([0.0, 0.0])) == "fails (0/2 finished)"
    assert S.cell(np.array([100.0, 5000.0]), np.array([1.0, 0.0])) == "100 (0.0 %) 1/2"
    assert S.cell(np.array([]), np.array([])) == "not run"


def test_comparisons_hold_when_steps_fall_and_pf_fails_alone_and_not_otherwise():
    by_team = _by_team(True)
    tab, means = S.table_block("simple", by_team)
    assert isinstance(tab, Table) and tab.rows[0][2] == "fails (0/2 finished)"
    comps = S.table_comparisons("simple", means, by_team)
    assert [c.holds for c in comps] == [True, True, True, True]
    bad = _by_team(False)
    comps = S.table_comparisons("complex", S.table_block("complex", bad)[1], bad)
    assert [c.holds for c in comps[:3]] == [False, False, False]
    assert comps[3].holds is True  # PF alone still fails, finishes with helpers
    assert comps[4].claim.startswith("Table 2: with 3 helpers")


def test_a_team_that_finishes_nothing_counts_as_worst_in_the_falling_verdict():
    def rows(h, fins, steps):
        return [_row("avoid_past", s, finished=f, **{f"robots.{k + 1}.count": int(k < h) for k in range(3)},
                     **{S.TARGETS_KEY: [[float(t), 0.0]] * 20})
                for t, (f, s) in enumerate(zip(fins, steps))]
    # R1 alone finishes no task, the teams with helpers all finish with falling steps: holds
    by_team = {0: rows(0, [0, 0], [700, 800]), 1: rows(1, [1, 1], [400, 420]), 2: rows(2, [1, 1], [300, 310]),
               3: rows(3, [1, 1], [200, 220])}
    comp = [c for c in S.table_comparisons("simple", S.table_block("simple", by_team)[1], by_team)
            if "Av. Past" in c.claim][0]
    assert comp.holds is True and comp.ours.startswith("fails (0/2) → 410 → 305 → 210")
    # a team with more helpers failing everything after one that finished: does not hold
    by_team[3] = rows(3, [0, 0], [900, 900])
    comp = [c for c in S.table_comparisons("simple", S.table_block("simple", by_team)[1], by_team)
            if "Av. Past" in c.claim][0]
    assert comp.holds is False and comp.ours.startswith("fails (0/2) → 410 → 305 → fails (0/2)")


def test_r1_alone_level_is_the_finished_mean_or_steps_per_reached_target_when_tasks_failed():
    def r(nav, spt, fin, reached):
        row = _row(nav, spt, finished=fin)
        row["metrics"]["los_targets_reached"] = reached
        return row
    lv = S.alone_levels([r("visbug21", 300, 1, 20), r("visbug21", 500, 1, 20),
                         r("avoid_past", 600, 0, 10), r("avoid_past", 800, 1, 20), r("avoid_past", 1500, 0, 0),
                         r("potential_field", 1500, 0, 0)])
    assert lv["visbug21"] == 400.0 and lv["avoid_past"] == 700.0  # a task that reached nothing has no rate
    assert math.isnan(lv["potential_field"])


def test_noise_verdicts_follow_the_paper_rows():
    alone = {"avoid_past": 500.0, "visbug21": 800.0, "potential_field": float("nan")}
    rows = [_row(nav, s, **{S.ERR_KEY: e}) for nav, base in (("avoid_past", 200), ("visbug21", 300))
            for e, s in ((0.0, base), (0.4, base * 1.5))]
    plot, means = S.noise_plot("simple", rows, alone)
    assert isinstance(plot, Plot) and len(plot.hlines) == 2
    grow, below = S.noise_comparisons("simple", means, alone)
    assert grow.holds is True and below.holds is True
    grow, fade = S.noise_comparisons("complex", means, alone)
    assert fade.holds is False  # gain 300 -> 200 keeps more than half: help did not fade


def test_noise_growth_is_judged_on_the_tasks_finished_at_both_noise_levels():
    alone = {"avoid_past": 900.0}
    def r(task, e, steps, fin=1):
        return _row("avoid_past", steps, finished=fin, **{S.ERR_KEY: e, S.TARGETS_KEY: [[float(task), 0.0]] * 20})
    # at 0 the hard task 2 failed: unpaired means 200 -> 300 "grow", paired (task 1) 200 -> 150 do not
    rows = [r(1, 0.0, 200), r(2, 0.0, 800, fin=0), r(1, 0.4, 150), r(2, 0.4, 450)]
    _plot, means = S.noise_plot("simple", rows, alone)
    assert means["avoid_past"] == {0.0: 200.0, 0.4: 300.0}
    assert S.noise_comparisons("simple", means, alone)[0].holds is True
    grow = S.noise_comparisons("simple", means, alone, rows)[0]
    assert grow.holds is False and "200 → 150 (paired, 1 tasks)" in grow.ours
    assert S.paired_noise(rows, "avoid_past", (0.0, 0.4)) == ([200.0, 150.0], 1)


def test_noise_growth_on_fewer_pairs_than_the_claim_file_fixes_is_not_judged(monkeypatch):
    from teamnav.experiments.claims import load_claims
    from teamnav.papers.los_help.report import _los_verdicts as V

    cf = load_claims("los-help")
    five = {c.id: c.model_copy(update={"min_pairs": 5}) for c in cf.claims}
    monkeypatch.setattr(V, "_claim", lambda cid: five[cid])
    alone = {"avoid_past": 900.0}
    rows = [_row("avoid_past", s, **{S.ERR_KEY: e, S.TARGETS_KEY: [[float(t), 0.0]] * 20})
            for t in range(4) for e, s in ((0.0, 200 + t), (0.4, 300 + t))]
    _plot, means = S.noise_plot("simple", rows, alone)
    grow = S.noise_comparisons("simple", means, alone, rows)[0]
    assert grow.holds is None and grow.differs.startswith("not judged (n = 4)")
    rows += [_row("avoid_past", s, **{S.ERR_KEY: e, S.TARGETS_KEY: [[9.0, 0.0]] * 20}) for e, s in ((0.0, 200), (0.4, 300))]
    _plot, means = S.noise_plot("simple", rows, alone)
    assert S.noise_comparisons("simple", means, alone, rows)[0].holds is True  # 5 pairs: judged


class _FakeCtx:
    """A ctx whose sweeps return hand-made rows (no simulation); ``paper_falling``: whether the
    paper-rules column's table rows fall with helpers (the teamnav column's always do)."""

    def __init__(self, quick, paper_falling=True):
        self.quick = quick
        self.paper_falling = paper_falling
        self.calls = []

    def sweep(self, sweep_name, **kw):
        name = sweep_name if isinstance(sweep_name, str) else sweep_name.sweep_name
        self.calls.append((name, kw, sweep_name))
        teams = ([S.team_of({"params": {k: v for k, v in c.items()}}) for c in sweep_name.cases]
                 if not isinstance(sweep_name, str) else [])
        falling = self.paper_falling or not name.endswith("-paper-rules")
        rows = [r for h in sorted(set(teams)) for r in _by_team(falling)[h]] if "table" in name else [
            _row(nav, 300 + 100 * e, **{S.ERR_KEY: e, S.DELAYED_KEY: True, S.STATE_KEY: True})
            for nav in L.NAVIGATORS for e in (0.0, 0.4)]

        class R:
            def rows(self):
                return rows

        return R()


@needs_brains
def test_full_build_asks_for_nested_teams_and_every_sweep_and_returns_every_block_kind():
    ctx = _FakeCtx(quick=False)
    blocks = S.build(ctx)
    names = [c[0] for c in ctx.calls]
    assert names.count("los-table1") == names.count("los-table2") == 1  # one call: algorithm x team cases
    assert {"los-noise-simple", "los-noise-complex", "los-ablation"} <= set(names)
    assert not any(n.endswith("-pf") for n in names)  # the algorithms are the sweeps' cases
    spec = [c[2] for c in ctx.calls if c[0] == "los-table1"][0]
    assert len(spec.cases) == 12 and [c for c in ctx.calls if c[0] == "los-table1"][0][1] == {"name": "los-table1"}
    tab = [b for b in blocks if isinstance(b, Table) and b.title.startswith("Table 1")][0]
    # per algorithm: paper as written, teamnav, the paper's row
    assert [r[1] for r in tab.rows] == ["paper as written", "teamnav", "paper"] * 3
    assert tab.rows[3][0] == "Av. Past" and tab.rows[4][0] == ""
    assert tab.rows[3][2:] == tab.rows[4][2:] == ["502 (0.7 %) 2/2", "252 (1.4 %) 2/2", "169 (2.1 %) 2/2", "128 (2.8 %) 2/2"]
    assert tab.rows[5][2:] == ["554.2 (11.7 %)", "426.2 (8.1 %)", "302.0 (14.2 %)", "257.2 (5.6 %)"]
    assert "20 targets per task" in tab.note
    noise = [b for b in blocks if isinstance(b, Table) and b.title.startswith("Fig. 16")][0]
    assert noise.columns[-1] == "R1 alone" and noise.rows[0][-1].startswith("fails") and noise.rows[2][-1] == "502 (0.7 %) 2/2"
    assert noise.columns[1:4] == ["column", "err_max 0", "err_max 0.4"]
    assert [r[1] for r in noise.rows] == ["paper as written", "teamnav"] * 3
    # every table and noise sweep is asked for in both columns; Table 2 also over route plans B and C
    assert {"los-table1-paper-rules", "los-table2-paper-rules", "los-noise-simple-paper-rules",
            "los-noise-complex-paper-rules", "los-table2-plan-b", "los-table2-plan-c-paper-rules"} <= set(names)
    plan_b = [c for c in ctx.calls if c[0] == "los-table2-plan-b"][0]
    assert plan_b[2].scenario == "los-help-complex-plan-b" and len(plan_b[2].cases) == 9  # no R1-alone cases
    plans = [b for b in blocks if isinstance(b, Table) and b.title.startswith("Table 2 over route plans")][0]
    assert {r[2] for r in plans.rows} == {"plan A", "plan B", "plan C", "mean over 3 plans"}
    texts = " ".join(b.text for b in blocks if hasattr(b, "text"))
    assert "Table 2's map is ours" in texts and "los-help-complex-plan-b" in texts
    claims = [b for b in blocks if isinstance(b, Table) and b.title.startswith("Claims:")][0]
    assert claims.columns[3:5] == ["paper as written", "teamnav"]
    assert all("(holds)" in r[3] and "(holds)" in r[4] for r in claims.rows if r[0].startswith("Table 1"))
    assert {Table, Plot, Comparison} <= {type(b) for b in blocks}
    assert not any(isinstance(b, Missing) for b in blocks)
    verdicts = {b.claim: b.holds for b in blocks if isinstance(b, Comparison)}
    assert verdicts["Table 1: Av. Past steps fall as helpers are added (R1, R1,2, R1,2,3, R1,2,3,4)"] is True
    # the Avoid-Past half-life readings run in the paper column only; the budget block reads every claim
    assert "los-avoid-past-half-life-teams-paper-rules" in names and "los-avoid-past-half-life-teams" not in names
    hl = [b for b in blocks if isinstance(b, Table) and b.title.startswith("Avoid-Past's memory half-life with")][0]
    assert any(r[0].startswith("1000 (the fill") for r in hl.rows) and "Readings, not the judged verdict" in hl.note
    cut = [b for b in blocks if isinstance(b, Table) and b.title.startswith("The verdicts with the step budget")][0]
    assert len(cut.rows) == len(claims.rows) and len(cut.columns) == 1 + 2 * 3
    for c_row, k_row in zip(claims.rows, cut.rows):  # budget x 1 is the verdict as judged, in both columns
        for got, cell in ((k_row[1], c_row[3]), (k_row[4], c_row[4])):
            assert cell.endswith(f"({'not judged' if got.startswith('not judged') else got})"), (c_row[0], got, cell)


@needs_brains
def test_quick_build_runs_short_tasks_and_says_what_it_left_out():
    ctx = _FakeCtx(quick=True)
    blocks = S.build(ctx)
    assert all(len(c[1]["grid"][S.TARGETS_KEY][0]) == S.QUICK_TARGETS for c in ctx.calls)
    spec = [c[2] for c in ctx.calls if c[0] == "los-table1"][0]
    assert sorted(c["case"] for c in spec.cases) == sorted(f"{a}/{t}" for a in ("pot-field", "avoid-past", "visbug21")
                                                           for t in ("R1", "R1-4"))
    assert all(c[1]["set"][S.BUDGET_KEY] == S.QUICK_BUDGET_STEPS_PER_TARGET for c in ctx.calls)
    # quick mode runs the complex map too (both columns, route plans B and C with R1..R4 only)
    assert not {b.what.split(" (")[0] for b in blocks if isinstance(b, Missing)} & {"Table 2 / Fig. 14", "Fig. 17"}
    plan_c = [c for c in ctx.calls if c[0] == "los-table2-plan-c-paper-rules"][0]
    assert plan_c[1]["name"] == "los-table2-plan-c-quick-paper-rules"
    assert sorted(c["case"] for c in plan_c[2].cases) == ["avoid-past/R1-4", "pot-field/R1-4", "visbug21/R1-4"]
    assert all("quick mode" in b.differs for b in blocks if isinstance(b, Comparison) and b.holds is not None)
    from teamnav.papers.los_help.report import _los_half_life as HL

    assert any(isinstance(b, Missing) and b.what.startswith("Avoid-Past's memory half-life")
               and f"{HL.trials()} trials" in b.why
               for b in blocks)
    assert not any("half-life-teams" in c[0] for c in ctx.calls)  # quick mode runs no half-life reading
    assert any(isinstance(b, Text) and b.text.startswith("Does the step budget move the verdicts?") for b in blocks)


# ---------------------------------------------------------------------------- a real run
@needs_brains
def test_a_one_target_run_finishes_with_steps_proportional_to_the_path():
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario

    goal = L.world_to_frame(L.LAYOUTS["simple"].r1_start, [(7.0, 7.0)]).tolist()  # 6 m down the corridor, in view
    scn = load_scenario("los-help-simple", overrides={"robots.0.params.targets_xy": goal, "robots.1.count": 0,
                                                      "robots.2.count": 0, "robots.3.count": 0}, duration_s=20.0)
    m = run(scn, progress=False).metrics
    assert m["los_finished"] == 1
    # 6 m in 0.2 m steps, stopping within eps = 0.5 m: 28..31 steps
    assert 6.0 - L.GOAL_TOLERANCE_M <= m["los_steps"] * L.STEP_LENGTH_M <= 6.0 + 2 * L.STEP_LENGTH_M


def test_steps_fall_verdict_pairs_tasks_so_a_failed_hard_task_cannot_fake_a_fall():
    # task A is hard (600 steps per target alone, 500 with a helper), task B easy (100, 110);
    # with two helpers R1 fails task A: its mean over finished tasks alone (110) would "fall"
    def row(h, task, steps, fin=1):
        return {"status": "ok", "params": {S.NAV_KEY: "avoid_past", S.TARGETS_KEY: [[float(task), 0.0]]},
                "metrics": {"los_steps_per_target": steps, "los_finished": fin}}
    by_team = {0: [row(0, 1, 600), row(0, 2, 100)], 1: [row(1, 1, 500), row(1, 2, 110)],
               2: [row(2, 1, 9999, fin=0), row(2, 2, 120)]}
    means, kept, run = S.paired_means(by_team, "avoid_past", [0, 1, 2])
    assert (kept, run) == (1, 2) and means == [100.0, 110.0, 120.0]  # the easy task only: rising
    tab, m = S.table_block("simple", by_team)
    comp = [c for c in S.table_comparisons("simple", m, by_team) if "Av. Past" in c.claim][0]
    assert comp.holds is False and "paired: the 1 of 2 tasks" in comp.ours


def test_a_failed_falling_verdict_says_how_large_each_rise_is_against_the_task_noise():
    from teamnav.papers.los_help.report._los_verdicts import paired_rises

    steps = {0: [100.0, 110.0, 120.0], 1: [110.0, 115.0, 118.0], 2: [90.0, 95.0, 99.0]}
    by_team = {h: [_row("avoid_past", s, **{S.TARGETS_KEY: [[float(task), 0.0]] * 20})
                   for task, s in enumerate(v)] for h, v in steps.items()}
    # R1 -> R1,2 rose by 10, 5, -2: +4.3 ± 3.5 (s.e.); R1,2 -> R1,2,3 fell: not listed
    assert paired_rises(by_team, "avoid_past", [0, 1, 2]) == ["R1 → R1,2: +4 ± 3 (s.e. over 3 tasks; 2 of 3 worse)"]
    comps = S.table_comparisons("simple", {"avoid_past": [110.0, 114.3, 94.7], "visbug21": [float("nan")] * 4,
                                           "potential_field": [float("nan")] * 4}, by_team)
    ap = next(c for c in comps if "Av. Past" in c.claim)
    assert ap.holds is False and "R1 → R1,2: +4 ± 3 (s.e. over 3 tasks; 2 of 3 worse)" in ap.differs


def test_legs_table_sets_the_finished_tasks_against_their_shortest_path():
    from teamnav.papers.los_help.report._los_tables import legs_block

    t = L.task_targets_xy("simple", 1, 3)
    legs = {"los_leg_leave": 100.0, "los_leg_corridor": 60.0, "los_leg_other_rooms": 10.0, "los_leg_enter": 20.0}

    def row(nav, finished, scale=1.0):
        return {"status": "ok", "params": {S.NAV_KEY: nav, S.TARGETS_KEY: t},
                "metrics": {"los_finished": finished, **{k: v * scale for k, v in legs.items()}}}

    by_team = {0: [row("avoid_past", 1), row("avoid_past", 0, scale=3.0), row("potential_field", 0)]}
    tab = legs_block({"simple": by_team})
    ap = next(r for r in tab.rows if r[1] == "Av. Past")
    floor = L.shortest_steps_per_target("simple", 1, 3)
    # the finished task only (the unfinished one, three times as long, is left out as in Tables 1-2)
    assert ap[3:8] == ["100", "60", "10", "20", "190"] and ap[8] == f"{floor:.0f}"
    assert ap[9] == f"{190 / floor:.2f}" and ap[10] == "1/2"
    pf = next(r for r in tab.rows if r[1] == "Pot. Fields")
    assert pf[9] == "n/a (no task finished)" and pf[10] == "0/1"


def test_verdict_rules_are_read_from_the_claim_file(monkeypatch):
    """The section's rules live in claims/los-help.yaml (judged on the paper-rules
    column, report seeds < 1000); a stricter threshold there changes the verdict here."""
    from teamnav.experiments.claims import load_claims
    from teamnav.papers.los_help.report import _los_verdicts as V

    cf = load_claims("los-help")
    assert all(c.judged == "paper_rules" and max(c.seed_list) < 1000 for c in cf.claims)
    by_team = _by_team(True)
    means = S.table_block("simple", by_team)[1]
    assert [c.holds for c in S.table_comparisons("simple", means, by_team)][:3] == [True, True, True]
    strict = cf["table1-visbug21-falls"].model_copy(update={"min_pairs": None, "rule": [
        cf["table1-visbug21-falls"].rule[0].model_copy(update={"threshold": -1e6})]})
    monkeypatch.setattr(V, "_claim", lambda cid: strict if cid == "table1-visbug21-falls"
                        else cf[cid].model_copy(update={"min_pairs": None}))
    comps = S.table_comparisons("simple", means, by_team)
    assert [c.holds for c in comps][:3] == [True, True, False]


# ---------------------------------------------------------------------------- two columns, route plans
@needs_brains
def test_verdicts_are_the_paper_as_written_columns_and_the_teamnav_column_says_what_gap_fills_add():
    # the paper-rules runs rise with helpers, the teamnav runs fall: the verdict follows the paper's column
    blocks = S.build(_FakeCtx(quick=False, paper_falling=False))
    comps = {(b.claim, b.column): b for b in blocks if isinstance(b, Comparison)}
    assert {b.column for b in blocks if isinstance(b, Comparison)} == {"paper", "teamnav"}
    key = "Table 1: Av. Past steps fall as helpers are added (R1, R1,2, R1,2,3, R1,2,3,4)"
    ap, ap_tn = comps[(key, "paper")], comps[(key, "teamnav")]
    assert ap.holds is False and ap_tn.holds is True
    assert ap.ours.startswith("502 → 552 → 602 → 652") and ap_tn.ours.startswith("502 → 252 → 169 → 128")
    assert "the verdict" in ap.differs and "not judged" in ap_tn.differs
    claims = [b for b in blocks if isinstance(b, Table) and b.title.startswith("Claims:")][0]
    row = next(r for r in claims.rows if r[0].startswith("Table 1: Av. Past"))
    assert "(does not hold)" in row[3] and "(holds)" in row[4]
    # and the other way round: a paper column that falls holds whatever teamnav does
    assert comps[("Table 1: the potential field alone fails, and finishes with helpers (state + goal sharing)",
                  "paper")].holds is True


@needs_brains
def test_the_paper_rules_column_runs_every_robot_at_paper_rules_with_the_cases_plan_and_quick_budget():
    from teamnav.control import registry
    from teamnav.papers.trails.report._trails import paper_rules_spec
    from teamnav.experiments.spec import load_scenario
    from teamnav.experiments.sweep import expand, resolve_spec

    base = S.table_spec("complex", [0, 3]).model_copy(update={"scenario": "los-help-complex-plan-b"})
    spec = resolve_spec(paper_rules_spec(base), set=S._quick_set(), grid={S.TARGETS_KEY: S._tasks("complex", True)},
                        duration_s=S._budget_s("complex", True))
    trials = expand(spec)
    assert len(trials) == 6
    t = next(x for x in trials if x.params["case"] == "avoid-past/R1-4")
    scn = load_scenario(spec.scenario, overrides={k: v for k, v in t.params.items() if k not in ("case", "duration_s")})
    assert [g.params.get("paper_rules") for g in scn.robots] == [True] * 4
    r1 = scn.robots[0].params
    assert r1["navigator"] == "avoid_past" and r1["max_steps_per_target"] == S.QUICK_BUDGET_STEPS_PER_TARGET
    assert len(r1["targets_xy"]) == S.QUICK_TARGETS
    plan_b = load_scenario("los-help-complex-plan-b")
    assert scn.robots[2].params["patrol_xy"] == plan_b.robots[2].params["patrol_xy"]
    p = registry.lookup("los-explorer-v1").Params(**r1)
    assert p.see_past_teammates is False and p.report_margin_steps == 0.0 and p.navigator_params["paper_rules"] is True
    # the teamnav column keeps our gap-fills
    ours = load_scenario(base.scenario).robots[0].params
    assert "paper_rules" not in ours and registry.lookup("los-explorer-v1").Params(**ours).see_past_teammates is True


def _plan(steps_by_team, alone=None):
    """One route plan's rows of Av. Past: {team: [steps of task 0, task 1]}."""
    out = {h: [_row("avoid_past", s, **{f"robots.{k + 1}.count": int(k < h) for k in range(3)},
                    **{S.TARGETS_KEY: [[float(task), 0.0]] * 20}) for task, s in enumerate(v)]
           for h, v in steps_by_team.items()}
    if alone is not None:
        out[0] = alone[0]
    return out


def test_table2_verdicts_read_the_mean_over_route_plans():
    a = _plan({0: [500, 500], 1: [400, 400], 2: [300, 300], 3: [200, 200]})
    b = _plan({1: [600, 600], 2: [300, 300], 3: [200, 200]}, alone=a)  # plan B alone rises at R2
    c = _plan({1: [450, 450], 2: [310, 310], 3: [210, 210]}, alone=a)
    means = S.table_block("complex", a)[1]
    record: dict = {}
    comps = S.table_comparisons("complex", means, a, plans=[a, b, c], record=record)
    ap = next(x for x in comps if "Av. Past" in x.claim)
    # the means over the plans: 500, 483, 303, 203: falling although plan B rises
    assert ap.holds is True and ap.ours.startswith("500 → 483 → 303 → 203")
    assert "mean over 3 route plans" in ap.ours and "plan B: 500 → 600 → 300 → 200" in ap.ours
    assert record["table2-avoid-past-falls"][0]["max_rise"] == pytest.approx(-16.67, abs=0.01)  # 500 -> 483.3
    # plan B's rise large enough to lift the mean above R1 alone: fails, though plan A alone falls
    b2 = _plan({1: [800, 800], 2: [300, 300], 3: [200, 200]}, alone=a)
    ap2 = next(x for x in S.table_comparisons("complex", means, a, plans=[a, b2, c]) if "Av. Past" in x.claim)
    assert ap2.holds is False and ap2.ours.startswith("500 → 550")
    assert next(x for x in S.table_comparisons("complex", means, a) if "Av. Past" in x.claim).holds is True
    tab = S.route_plans_block({"paper_rules": [a, b2, c], "teamnav": [a, b, c]}, ("plan A", "plan B", "plan C"))
    mean_rows = [r for r in tab.rows if r[0] == "Av. Past" and r[2] == "mean over 3 plans"]
    assert [r[1] for r in mean_rows] == ["paper as written", "teamnav"]
    assert mean_rows[0][3:] == ["500", "550", "303", "203"] and mean_rows[1][4] == "483"


def test_route_plan_files_are_what_the_generator_writes_and_differ_only_in_the_helpers_routes(tmp_path):
    from teamnav.experiments import registry
    from teamnav.papers.los_help.report import _los_common as C

    for p in C.write_route_plan_files(tmp_path):
        assert registry.path(p.stem).read_text(encoding="utf-8") == p.read_text(encoding="utf-8"), (
            f"{p.name} is stale: run python -m teamnav.papers.los_help.report._los_common")
    a = L.scenario_data("complex")
    routes = {}
    for plan in ("B", "C"):
        d = C.route_plan_scenario(plan)
        assert d["robots"][0] == a["robots"][0] and d["map"] == a["map"]
        for k in (1, 2, 3):
            assert {x: v for x, v in d["robots"][k]["params"].items() if x != "patrol_xy"} == \
                {x: v for x, v in a["robots"][k]["params"].items() if x != "patrol_xy"}
        routes[plan] = [g["params"]["patrol_xy"] for g in d["robots"][1:]]
    routes["A"] = [g["params"]["patrol_xy"] for g in a["robots"][1:]]
    assert len({json.dumps(v) for v in routes.values()}) == 3  # three different plans
    with pytest.raises(ValueError, match="plan must be one of"):
        C.route_plan_scenario("A")


def test_route_plans_lie_in_the_corridors_with_clearance_and_see_every_room_together():
    from teamnav.papers.los_help.report._los_common import ROUTE_PLANS

    env = builtin_map(L.MAPS["complex"])
    clear = distance_field(env.grid)
    occ, res = np.asarray(env.grid.occupied()), env.grid.resolution_m
    corridors = [v for k, v in env.regions.items() if k.startswith("corridor")]
    centres = L.room_centres("complex")
    assert ROUTE_PLANS["A"][1] == L.LAYOUTS["complex"].helpers
    for plan, (_text, helpers) in ROUTE_PLANS.items():
        seen = set()
        for start, route in helpers:
            pts = [start[:2], *route]
            for x, y in pts:
                r, c = env.grid.world_to_cell((x, y))
                assert clear[r, c] >= L.RADIUS_M + 0.3, (plan, x, y)
                assert any(x0 <= x <= x1 and y0 - 0.4 <= y <= y1 + 0.4 for x0, y0, x1, y1 in corridors), (plan, x, y)
            seen |= {name for a, b in zip(pts, pts[1:]) for t in np.linspace(0.0, 1.0, 150)
                     for name, c in centres.items()
                     if (p := (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t))
                     and math.hypot(c[0] - p[0], c[1] - p[1]) <= L.VISIBILITY_M and _sees(occ, res, p, c)}
        assert seen == set(centres), (plan, sorted(set(centres) - seen))  # R2..R4 together see every room


def test_table2_claims_are_judged_on_the_mean_over_route_plans_fixed_before_the_data():
    from teamnav.experiments.claims import load_claims

    cf = load_claims("los-help")
    t2 = [c for c in cf.claims if c.id.startswith("table2-")]
    assert len(t2) == 5
    for c in t2:
        plans = [h for h in c.history if "route plans" in h.change]
        assert plans and plans[-1].before_data and "route plans" in c.note
    # every claim is judged on tasks no run had touched, written before their first run
    for c in cf.claims:
        assert c.task_list == list(range(11, 21)) and c.history[-1].before_data and "11-20" in c.history[-1].change


def test_noise_table_pairs_each_algorithms_rows_across_columns_when_one_column_lacks_an_algorithm():
    from teamnav.papers.los_help.report._los_tables import noise_table_cols

    rows = [_row(nav, s, **{S.ERR_KEY: e}) for nav, s in (("avoid_past", 200), ("visbug21", 300)) for e in (0.0, 0.4)]
    tab = noise_table_cols("simple", {"paper_rules": rows[2:], "teamnav": rows}, {"paper_rules": [], "teamnav": []})
    assert [r[:2] for r in tab.rows] == [["Av. Past", "teamnav"], ["VisBug", "paper as written"], ["VisBug", "teamnav"]]
    assert tab.rows[1][2] == tab.rows[2][2] == "300 (0.0 %) 1/1"


def test_a_route_plan_without_a_paired_mean_at_a_team_fails_the_table2_trend():
    # claims/los-help.yaml: plan C finished nothing with R1..3 while A and B did: the trend fails,
    # it is not left unjudged (and a single plan with the same gap is judged as before)
    a = _plan({0: [500, 500], 1: [400, 400], 2: [300, 300], 3: [200, 200]})
    b = _plan({1: [420, 420], 2: [310, 310], 3: [210, 210]}, alone=a)
    c = _plan({1: [450, 450], 2: [9999, 9999], 3: [220, 220]}, alone=a)
    for r in c[2]:
        r["metrics"]["los_finished"] = 0
    record: dict = {}
    ap = next(x for x in S.table_comparisons("complex", S.table_block("complex", a)[1], a, plans=[a, b, c],
                                             record=record) if "Av. Past" in x.claim)
    assert record["table2-avoid-past-falls"][1][0] is False  # the claim table says so too
    assert ap.holds is False and "route plan has no paired mean" in ap.differs and "plan C: n/a → n/a → n/a → n/a, 0 of 2 tasks" in ap.ours
    assert next(x for x in S.table_comparisons("complex", S.table_block("complex", a)[1], a, plans=[a, b])
                if "Av. Past" in x.claim).holds is True


def test_table1_trend_fails_when_no_task_is_finished_by_every_team_that_finished_one():
    # claims/los-help.yaml (rule change of 2026-11-27): R1 alone finished task 0 only, R1..4 task 1
    # only; the helpers lost a task that R1 finished, so the trend does not hold (it was "not judged")
    a = _plan({0: [500, 500], 1: [400, 400], 2: [300, 300], 3: [200, 200]})
    a[0][1]["metrics"]["los_finished"] = 0
    for h in (1, 2, 3):
        a[h][0]["metrics"]["los_finished"] = 0
    a[3][1]["metrics"]["los_finished"] = 1
    record: dict = {}
    ap = next(x for x in S.table_comparisons("simple", S.table_block("simple", a)[1], a, record=record)
              if "Av. Past" in x.claim)
    assert ap.holds is False and record["table1-avoid-past-falls"][1][0] is False
    assert "no task was finished by every team that finished one" in ap.differs
    # with a common task the same rows are judged on the paired means again (and fall)
    a[0][1]["metrics"]["los_finished"] = 1
    assert next(x for x in S.table_comparisons("simple", S.table_block("simple", a)[1], a)
                if "Av. Past" in x.claim).holds is True


def test_a_paired_trend_on_fewer_pairs_than_the_claim_file_fixes_is_not_judged(monkeypatch):
    """FIDELITY §3: ``min_pairs`` of a claim; the two tasks of ``_by_team`` are 2 pairs, fewer than 5."""
    from teamnav.experiments.claims import load_claims
    from teamnav.papers.los_help.report import _los_verdicts as V

    cf = load_claims("los-help")
    by_team = _by_team(True)
    means = S.table_block("simple", by_team)[1]
    assert [c.holds for c in S.table_comparisons("simple", means, by_team)][:3] == [True, True, True]
    five = {c.id: c.model_copy(update={"min_pairs": 5}) for c in cf.claims}
    monkeypatch.setattr(V, "_claim", lambda cid: five[cid])
    record: dict = {}
    comps = S.table_comparisons("simple", means, by_team, record=record)
    assert [c.holds for c in comps][:3] == [None, None, None]
    assert comps[1].differs.startswith("not judged (n = 2)")
    assert record["table1-avoid-past-falls"][1] == (None, "not judged (n = 2)")
    with pytest.raises(Exception, match="min_pairs"):
        type(cf.claims[0])(**{**cf.claims[0].model_dump(), "min_pairs": 3})  # fewer than 5 is refused


def test_claim_tasks_are_report_tasks_below_the_tuning_range():
    from teamnav.experiments.claims import load_claims

    c = load_claims("los-help").claims[0]
    assert type(c)(**{**c.model_dump(), "tasks": "11-20"}).task_list == list(range(11, 21))
    with pytest.raises(Exception, match="tuning"):
        type(c)(**{**c.model_dump(), "tasks": "1001-1005"})
