"""Moving places (a moving resource; Vaughan et al. 2000 §6 future work): the motion's
interpolation and jumps, its validation, and events fired where the place is now, not where it was."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import BaseModel, ConfigDict, ValidationError

from _report_fakes import FakeFullContext
from teamnav.control import registry
from teamnav.experiments.errors import ScenarioError
from teamnav.experiments.spec import load_scenario
from teamnav.sim.config import PlaceConfig, RobotGroupConfig, SimConfig, StartConfig
from teamnav.sim.engine import Simulation
from teamnav.sim.events import Places, motion_table, place_positions
from teamnav.world.grid import WALL, OccupancyGrid

coord = st.floats(-50.0, 50.0, allow_nan=False)


@st.composite
def motions(draw, mode=None, periodic=None):
    n = draw(st.integers(1, 5))
    gaps = draw(st.lists(st.floats(0.5, 100.0), min_size=n, max_size=n))
    ts = np.cumsum(gaps).tolist()
    path = [{"t_s": t, "x_m": draw(coord), "y_m": draw(coord)} for t in ts]
    periodic = draw(st.booleans()) if periodic is None else periodic
    motion = {"mode": mode or draw(st.sampled_from(["linear", "jump"])), "path": path}
    if periodic:
        motion["period_s"] = ts[-1] + draw(st.floats(0.5, 100.0))
    return PlaceConfig.model_validate({"name": "source", "x_m": draw(coord), "y_m": draw(coord), "event": "e",
                                       "motion": motion})


@settings(max_examples=150, deadline=None)
@given(motions(), st.data())
def test_at_every_knot_the_place_is_at_that_knot(place, data):
    t, x, y, _ = motion_table(place)
    end = len(t) - (place.motion.period_s is not None)  # the period's knot is the start again
    px, py = place_positions(place, t[:end])
    np.testing.assert_allclose(px, x[:end], atol=1e-9)
    np.testing.assert_allclose(py, y[:end], atol=1e-9)


@settings(max_examples=150, deadline=None)
@given(motions(mode="linear"), st.floats(0.0, 1.0))
def test_linear_motion_lies_on_its_segment_at_the_right_fraction(place, frac):
    t, x, y, _ = motion_table(place)
    k = int(frac * (len(t) - 1) * 0.999)
    u = frac * (len(t) - 1) * 0.999 - k
    ts = t[k] + u * (t[k + 1] - t[k])
    px, py = place_positions(place, ts)
    want = (x[k] + u * (x[k + 1] - x[k]), y[k] + u * (y[k + 1] - y[k]))
    assert math.hypot(px[0] - want[0], py[0] - want[1]) <= 1e-6 * (1 + abs(x[k + 1] - x[k]) + abs(y[k + 1] - y[k]))


@settings(max_examples=150, deadline=None)
@given(motions(mode="linear"), st.floats(0.0, 500.0), st.floats(1e-3, 5.0))
def test_linear_motion_is_no_faster_than_its_fastest_segment(place, t0, dt):
    t, x, y, period = motion_table(place)
    vmax = max(np.hypot(np.diff(x), np.diff(y)) / np.diff(t))
    px, py = place_positions(place, [t0, t0 + dt])
    if period is not None and (t0 % period) > ((t0 + dt) % period):
        return  # wrapped: linear motion is continuous across the period, but the bound needs the split
    assert math.hypot(px[1] - px[0], py[1] - py[0]) <= vmax * dt * (1 + 1e-9) + 1e-9


@settings(max_examples=150, deadline=None)
@given(motions(mode="jump"), st.floats(0.0, 1000.0))
def test_jump_mode_is_at_the_last_knot_reached(place, ts):
    t, x, y, period = motion_table(place)
    tm = ts % period if period is not None else ts
    k = max(j for j in range(len(t)) if t[j] <= tm)
    px, py = place_positions(place, ts)
    if period is not None and k == len(t) - 1:
        k = 0
    assert (px[0], py[0]) == (x[k], y[k])


@settings(max_examples=100, deadline=None)
@given(motions(periodic=True), st.floats(0.0, 1000.0), st.integers(1, 5))
def test_periodic_motion_repeats(place, ts, n):
    p = place.motion.period_s
    a, b = place_positions(place, ts), place_positions(place, ts + n * p)
    scale = 1 + max(abs(w.x_m) + abs(w.y_m) for w in place.motion.path) + abs(place.x_m) + abs(place.y_m)
    # float mod of t and t + nP can land either side of a knot by 1 ulp; jumps are compared away from knots
    if place.motion.mode == "jump":
        t, *_ = motion_table(place)
        if np.min(np.abs((ts % p) - t)) < 1e-6 * (1 + ts):
            return
    assert abs(a[0][0] - b[0][0]) + abs(a[1][0] - b[1][0]) <= 1e-6 * scale * (1 + n * p)


def test_after_the_last_waypoint_a_non_periodic_place_stays():
    p = PlaceConfig.model_validate({"name": "s", "x_m": 0, "y_m": 0, "motion": {"path": [{"t_s": 5, "x_m": 3, "y_m": 4}]}})
    for mode in ("linear", "jump"):
        q = p.model_copy(update={"motion": p.motion.model_copy(update={"mode": mode})})
        x, y = place_positions(q, [5.0, 60.0, 1e6])
        assert x.tolist() == [3.0] * 3 and y.tolist() == [4.0] * 3


# ------------------------------------------------------------------------ validation
def _place(motion):
    return PlaceConfig.model_validate({"name": "s", "x_m": 0.0, "y_m": 0.0, "motion": motion})


@pytest.mark.parametrize("motion, field, words", [
    ({"path": [{"t_s": 5, "x_m": 1, "y_m": 1}, {"t_s": 3, "x_m": 2, "y_m": 2}]}, "motion", ["path[1].t_s", "increase", "3"]),
    ({"path": [{"t_s": 5, "x_m": 1, "y_m": 1}, {"t_s": 5, "x_m": 2, "y_m": 2}]}, "motion", ["path[1].t_s", "increase"]),
    ({"path": [{"t_s": 5, "x_m": float("nan"), "y_m": 1}]}, "motion.path.0.x_m", ["finite"]),
    ({"path": [{"t_s": float("inf"), "x_m": 1, "y_m": 1}]}, "motion.path.0.t_s", []),
    ({"path": [{"t_s": 0, "x_m": 1, "y_m": 1}]}, "motion.path.0.t_s", ["greater than 0"]),
    ({"path": []}, "motion.path", ["at least 1"]),
    ({"path": [{"t_s": 5, "x_m": 1}]}, "motion.path.0.y_m", ["required"]),
    ({"mode": "teleport", "path": [{"t_s": 5, "x_m": 1, "y_m": 1}]}, "motion.mode", ["linear", "jump"]),
    ({"path": [{"t_s": 5, "x_m": 1, "y_m": 1}], "period_s": 5}, "motion", ["period_s", "last waypoint time 5"]),
    ({"path": [{"t_s": 5, "x_m": 1, "y_m": 1}], "speed": 2}, "motion.speed", ["Extra inputs"]),
])
def test_bad_motion_is_refused_naming_the_field(motion, field, words):
    with pytest.raises(ValidationError) as info:
        _place(motion)
    err = info.value.errors()[0]
    assert ".".join(str(x) for x in err["loc"]) == field, err
    for w in words:
        assert w in err["msg"], err["msg"]


def test_static_place_serialises_as_before_and_motion_round_trips():
    static = PlaceConfig(name="s", x_m=1.0, y_m=2.0, event="e")
    assert "motion" not in static.model_dump(mode="json")
    moving = _place({"mode": "jump", "path": [{"t_s": 5, "x_m": 1, "y_m": 1}], "period_s": 9})
    assert PlaceConfig.model_validate(moving.model_dump(mode="json")) == moving


SCENARIO = """\
name: moving
map: {builtin: trail_office_corridors}
duration_s: 1
places:
  - {place: source, radius_m: 1.0, event: took_resource,
     motion: {mode: jump, path: [{t_s: 600, place: c3_east_end}, {t_s: 900, x_m: 24.4, y_m: 15.9}], period_s: 1200}}
robots:
  - {count: 1, controller: idle-v1, sensors: [], start: {near: home, spread_m: 0.3}}
"""


def test_scenario_waypoints_may_name_places_of_the_builtin_map(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text(SCENARIO)
    s = load_scenario(f)
    (p,) = s.places
    assert (p.name, p.x_m, p.y_m) == ("source", 5.4, 15.9)
    assert [(w.t_s, w.x_m, w.y_m) for w in p.motion.path] == [(600, 34.5, 15.9), (900, 24.4, 15.9)]


@pytest.mark.parametrize("old, new, words", [
    ("place: c3_east_end}", "place: c3_east_ned}", ["places[0].motion.path[0].place", "did you mean 'c3_east_end'"]),
    ("place: c3_east_end}", "place: c3_east_end, x_m: 3}", ["places[0].motion.path[0]", "not both"]),
    ("{t_s: 900, x_m: 24.4", "{t_s: 500, x_m: 24.4", ["places[0].motion", "path[1].t_s", "increase"]),
])
def test_bad_scenario_waypoints_name_file_and_field(tmp_path, old, new, words):
    f = tmp_path / "s.yaml"
    f.write_text(SCENARIO.replace(old, new))
    with pytest.raises(ScenarioError) as info:
        load_scenario(f)
    msg = str(info.value)
    assert "s.yaml" in msg
    for w in words:
        assert w in msg, msg


# ------------------------------------------------------------------------ events where the place is now
def test_a_place_that_moves_onto_a_robot_fires_enter_and_one_that_leaves_marks_it_outside():
    p = _place({"path": [{"t_s": 1.0, "x_m": 5.0, "y_m": 0.0}, {"t_s": 2.0, "x_m": 0.0, "y_m": 0.0}], "period_s": 3.0})
    p = p.model_copy(update={"event": "e"})
    places = Places([p], np.array([5.0]), np.array([0.0]))
    fired = [places.update(k, 0.1 * k, np.array([5.0]), np.array([0.0]))[0] for k in range(1, 41)]
    steps = [k for k, f in enumerate(fired, start=1) if f]
    # the robot at x = 5 (radius 1) is inside once the place reaches x = 4 (t = 0.8 s), outside once it has
    # gone back below 4 (t > 1.2 s), and entered again in the next period (t = 3.8 s)
    assert steps == [8, 38]
    inside = [bool(places.update(41 + k, 3.8 + 0.1 * k, np.array([5.0]), np.array([0.0]))[0]) for k in range(1)]
    assert inside == [False]  # "enter": no second firing while it stays inside
    assert places.track[0] == {"step": 0, "t_s": 0.0, "place": "s", "x_m": 0.0, "y_m": 0.0}
    xs = [r["x_m"] for r in places.track]
    assert max(xs) == 5.0 and all(abs(b - a) >= 0.25 - 1e-12 for a, b in zip(xs, xs[1:]))


class _DriveParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _Drive:
    """Drives east at 0.5 m/s and keeps its observations."""

    Params = _DriveParams

    def __init__(self, params, rng, info):
        self.seen = []

    def step(self, obs):
        from teamnav.control.types import Action

        self.seen.append(obs)
        return Action(0.5, 0.0, None), []

    def log(self):
        return {}


@pytest.fixture()
def _drive_registered(monkeypatch):
    monkeypatch.setitem(registry._REGISTRY, "drive-test-v1", f"{__name__}:_Drive")


def _room(side_m=6.0, res=0.05):
    n = int(round(side_m / res))
    cells = np.zeros((n, n), np.uint8)
    cells[:2, :] = cells[-2:, :] = cells[:, :2] = cells[:, -2:] = WALL
    return OccupancyGrid(cells, res, name="room")


@pytest.mark.parametrize("motion", [None, {"mode": "jump", "path": [{"t_s": 0.5, "x_m": 4.0, "y_m": 1.0}]}])
def test_robot_driving_through_gets_the_event_at_the_moved_place_not_the_old_spot(_drive_registered, motion):
    place = {"name": "src", "x_m": 2.0, "y_m": 1.0, "radius_m": 0.5, "event": "took_resource"}
    if motion is not None:
        place["motion"] = motion
    cfg = SimConfig(
        robots=(RobotGroupConfig(count=1, controller="drive-test-v1", sensors=(),
                                 start=StartConfig(poses=((1.0, 1.0, 0.0),))),),
        places=(PlaceConfig.model_validate(place),),
    )
    sim = Simulation(_room(), cfg)
    sim.run(80)
    fired = [(e["step"], round(float(sim.recorder.events[i]["t_s"]), 6)) for i, e in enumerate(sim.recorder.events)]
    if motion is None:
        assert fired == [(10, 1.0)]  # x = 1.5 at step 10: the static place's edge
    else:
        # x = 3.5 (step 50, or 51 where the float sum of 0.05 m steps falls just short): the moved place's
        # edge; nothing at x = 1.5 (step 10), where the place was until t = 0.5 s
        assert len(fired) == 1 and fired[0][0] in (50, 51)
        assert abs(sim.recorder.events[0]["robot"]) == 0
        assert sim.places.track == [
            {"step": 0, "t_s": 0.0, "place": "src", "x_m": 2.0, "y_m": 1.0},
            {"step": 5, "t_s": pytest.approx(0.5), "place": "src", "x_m": 4.0, "y_m": 1.0},
        ]
    seen = sim.brains[0][0].seen
    assert [o.step for o in seen if o.events] == [e[0] for e in fired]


# ------------------------------------------------------------------------ the report block (section beyond)
def test_motion_speed_counts_the_cycle_distance_over_its_duration():
    from teamnav.papers.beyond.report.section import motion_speed_mps

    far = {"t_s": 600.0, "x_m": 24.4, "y_m": 15.9}
    assert motion_speed_mps((5.4, 15.9), None) == 0.0
    jump = motion_speed_mps((5.4, 15.9), {"mode": "jump", "path": [far], "period_s": 1200.0})
    glide = motion_speed_mps((5.4, 15.9), {"mode": "linear", "path": [far], "period_s": 1200.0})
    assert jump == pytest.approx(38.0 / 1200.0) and glide == jump
    assert motion_speed_mps((0.0, 0.0), {"path": [{"t_s": 10.0, "x_m": 3.0, "y_m": 4.0}]}) == pytest.approx(0.5)


def test_moving_resource_block_quick_runs_its_two_cases(tmp_path):
    from teamnav.experiments.report.context import SweepContext
    from teamnav.experiments.report.model import Plot, Table
    from teamnav.papers.beyond.report.section import MOVING_QUICK_CASES, _moving_resource

    ctx = SweepContext(tmp_path, quick=True, workers=1, section="beyond")
    blocks = _moving_resource(ctx)
    (table,) = [b for b in blocks if isinstance(b, Table)]
    assert [r[0] for r in table.rows] == list(MOVING_QUICK_CASES)
    assert table.rows[0][1] == "0.0000" and float(table.rows[1][1]) == pytest.approx(0.05, rel=1e-9)
    assert all("(n = 1)" in r[2] for r in table.rows), table.rows  # one seed each, and it finished
    (plot,) = [b for b in blocks if isinstance(b, Plot)]
    assert [s.x for s in plot.series] == [[0.0, pytest.approx(0.05)]]
    assert "no verdict" in plot.caption


# ------------------------------------------------------------------------ blazing-trail-v1's optional crumb expiry
def _blaze(**params):
    from teamnav.control.check import synthetic_infos
    from teamnav.papers.trails.brains.blazing_trail import BlazingTrail

    return BlazingTrail(BlazingTrail.Params(**params), np.random.default_rng(0), synthetic_infos(1)[0])


def _batch(n, x0):
    from teamnav.papers.trails.brains.crumbs import CrumbBatch

    return CrumbBatch(np.column_stack([x0 + np.arange(n, dtype=float), np.zeros(n)]), np.zeros(n))


def test_global_crumbs_never_expire_by_default_the_papers_rule():
    b = _blaze()
    assert b.params.global_crumb_ttl_s is None
    b._add_global(_batch(3, 0.0), 0.0)
    b._add_global(_batch(2, 10.0), 100.0)
    assert len(b.global_crumbs) == 5 and not b._added  # no bookkeeping without a ttl


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(1, 6), st.floats(0.0, 50.0)), min_size=1, max_size=8),
       st.floats(1.0, 100.0), st.sampled_from([None, 4, 9]))
def test_global_crumbs_expire_ttl_after_they_were_added(batches, ttl, cap):
    b = _blaze(global_crumb_ttl_s=ttl, max_global_crumbs=cap)
    t, kept = 0.0, []  # (time added, x) of every crumb the list should hold
    for i, (n, gap) in enumerate(batches):
        t += gap
        b._add_global(_batch(n, 100.0 * i), t)
        kept += [(t, 100.0 * i + j) for j in range(n)]
        if cap is not None:
            kept = kept[-cap:]
        b._expire(t - ttl)
        kept = [(ta, x) for ta, x in kept if not ta < t - ttl]
        assert b.global_crumbs.xy_m[:, 0].tolist() == [x for _, x in kept]


def _fake_full():
    """Full mode without running: every case of the asked sweep gets one row per seed, its units
    falling with the case's position in the sweep (so the table's order and numbers can be read back)."""
    return FakeFullContext(lambda spec, seeds: [
        {"status": "ok", "params": {"case": c["case"]}, "units_total": 60 - 5 * i + s,
         "breakdown_censored": int(i < 4), "trip_time_s_after_mean": 100.0, "crumbs_max": 500 + i}
        for i, c in enumerate(spec.cases) for s in seeds])


def test_moving_resource_block_full_mode_reads_every_case_and_the_blazing_sweep():
    from teamnav.experiments.report.model import Plot, Table
    from teamnav.papers.beyond.report.section import _moving_resource

    ctx = _fake_full()
    blocks = _moving_resource(ctx)
    assert [(seeds, d) for _, seeds, d in ctx.asked] == [(list(range(10)), 3600.0)] * 2
    main, blaze = [b for b in blocks if isinstance(b, Table)]
    assert [r[0] for r in main.rows] == ["static", "jump-30min", "jump-15min", "jump-10min", "jump-5min",
                                         "glide-0.01", "glide-0.02", "glide-0.05"]
    assert main.rows[0][2].startswith("64.5 ± 3.0 (n = 10)") and main.rows[0][3] == "0 of 10"
    assert main.rows[4][3] == "10 of 10"
    speeds = [float(r[1]) for r in main.rows]
    assert speeds[1:5] == pytest.approx([38 / 3600, 38 / 1800, 38 / 1200, 38 / 600], abs=5e-5)  # printed to 4 places
    (plot,) = [b for b in blocks if isinstance(b, Plot)]
    jumps, glides = plot.series
    assert jumps.x == sorted(jumps.x) and len(jumps.x) == 5 and len(glides.x) == 4
    assert [r[2] for r in blaze.rows[:2]] == ["never (the paper)", "300 s after added"]
    assert {r[0] for r in blaze.rows} == {"static", "jump-10min", "glide-0.02"}


def test_moving_places_are_recorded_as_a_layer_where_they_are(_drive_registered, tmp_path):
    """A run with a moving place writes its positions (Places.track) as the ``moving_places`` layer,
    so replays and exports draw it where it is; a run without one writes no such layer."""
    from teamnav.sim.recorder import load as load_run

    def run(motion):
        place = {"name": "src", "x_m": 2.0, "y_m": 1.0, "radius_m": 0.5, "event": "took_resource"}
        if motion is not None:
            place["motion"] = motion
        cfg = SimConfig(robots=(RobotGroupConfig(count=1, controller="drive-test-v1", sensors=(),
                                                 start=StartConfig(poses=((1.0, 1.0, 0.0),))),),
                        places=(PlaceConfig.model_validate(place),))
        sim = Simulation(_room(), cfg)
        sim.run(30)
        return sim

    sim = run({"mode": "jump", "path": [{"t_s": 0.5, "x_m": 4.0, "y_m": 1.0}, {"t_s": 2.0, "x_m": 3.0, "y_m": 2.0}]})
    sim.recorder.save(tmp_path / "moving")
    layer = load_run(tmp_path / "moving").layers["moving_places"]
    assert layer.kind == "markers" and layer.frame == "world" and layer.hold
    assert layer.step.tolist() == [0, 5, 20] and set(layer.robot.tolist()) == {-1}
    rows = [layer.data[layer.offset[k]:layer.offset[k + 1]].tolist() for k in range(len(layer.step))]
    assert rows == [[[2.0, 1.0]], [[4.0, 1.0]], [[3.0, 2.0]]]
    assert "moving_places" not in run(None).recorder.layer_names
