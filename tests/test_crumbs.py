"""Crumb lists of "Blazing a trail" (Vaughan et al. 2000 §4.1): average heading within a radius,
broadcast-and-clear (the waggle dance), carrying robots follow the opposite heading."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.papers.trails.brains.crumbs import CrumbBatch, CrumbList, average_heading, preferred_heading
from teamnav.geometry.angles import angle_diff

from _trail_brain_fakes import make_brains, make_obs


def test_average_heading_is_circular_and_ignores_crumbs_outside_the_radius():
    c = CrumbList()
    c.drop(0.0, 0.0, math.pi - 0.2)
    c.drop(1.0, 0.0, -math.pi + 0.1)   # across the +-pi cut: arithmetic mean would be ~0
    c.drop(2.0, 0.0, math.pi)
    c.drop(6.0, 0.0, 0.0)              # outside the 3 m radius
    m = c.average_heading(1.0, 0.0, 3.0)
    assert abs(angle_diff(m, math.pi - (0.2 - 0.1) / 3)) < 1e-3
    assert c.average_heading(1.0, 0.0, 5.0) != pytest.approx(m)  # the far crumb now counts
    assert c.average_heading(20.0, 20.0, 3.0) is None
    # boundary is inclusive
    assert c.average_heading(9.0, 0.0, 3.0) == pytest.approx(0.0)


def test_opposite_headings_cancel_to_no_preference():
    xy = np.zeros((2, 2))
    assert average_heading(xy, np.array([0.3, 0.3 + math.pi]), 0.0, 0.0, 1.0) is None
    with pytest.raises(ValueError, match="radius_m must be a positive"):
        average_heading(xy, np.zeros(2), 0.0, 0.0, 0.0)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(-math.pi, math.pi), min_size=1, max_size=30), st.floats(-math.pi, math.pi))
def test_average_heading_rotates_with_the_crumbs(headings, rot):
    """Rotating every crumb heading by rot rotates the mean by rot (equivariance)."""
    h = np.array(headings)
    xy = np.zeros((h.size, 2))
    m0 = average_heading(xy, h, 0.0, 0.0, 1.0)
    m1 = average_heading(xy, h + rot, 0.0, 0.0, 1.0)
    if m0 is None or np.hypot(np.sin(h).sum(), np.cos(h).sum()) < 1e-3:
        return  # directions cancel out: undefined mean
    assert abs(angle_diff(m1, m0 + rot)) < 1e-6


def test_broadcast_and_clear_sender_keeps_its_own_crumbs_globally():
    """§4.1: on arrival the private list goes out; everyone, the sender too, appends it to the
    global list; the sender's private list is cleared."""
    private, glob_sender, glob_other = CrumbList(), CrumbList(), CrumbList()
    glob_other.drop(-5.0, -5.0, 1.0)
    for k in range(5):
        private.drop(float(k), 0.0, 0.0)
    body = private.to_batch()
    private.clear()
    for g in (glob_sender, glob_other):
        g.extend(body)
    assert len(private) == 0 and len(body) == 5
    np.testing.assert_array_equal(glob_sender.xy_m[:, 0], np.arange(5.0))
    assert len(glob_other) == 6
    private.drop(9.0, 9.0, 0.0)  # clearing the private list did not touch what was broadcast
    assert len(body) == 5 and len(glob_sender) == 5


def test_carrying_robot_follows_the_opposite_heading_home():
    """Crumbs dropped while carrying point back to the source, so the average still points
    to the source and a carrying robot turns the other way."""
    c = CrumbList()
    c.drop(0.0, 0.0, 0.0)                       # outbound, heading east to the source
    c.drop(0.5, 0.0, math.pi, outbound=False)   # carrying, heading west to home
    m = c.average_heading(0.0, 0.0, 1.0)
    assert m == pytest.approx(0.0, abs=1e-12)
    assert preferred_heading(m, carrying=False) == pytest.approx(0.0, abs=1e-12)
    assert abs(preferred_heading(m, carrying=True)) == pytest.approx(math.pi)
    assert preferred_heading(None, carrying=True) is None


def test_loops_are_cut_from_the_private_list():
    """Out to a dead end and back, then on north: the out-and-back detour is cut, and a robot
    turning on the spot (no path) cuts nothing."""
    c = CrumbList()
    path = 0.0
    pts = [(0.5 * k, 0.0, 0.0) for k in range(21)]  # east to x = 10 (the junction is at x = 5)
    pts += [(10.0 - 0.5 * k, 0.3, math.pi) for k in range(1, 11)]  # back west to x = 5
    pts += [(5.0, 0.5 * k, math.pi / 2) for k in range(1, 11)]  # north from the junction
    cut = 0
    last = pts[0]
    for x, y, h in pts:
        path += math.hypot(x - last[0], y - last[1])
        last = (x, y)
        cut += c.drop_pruning_loops(x, y, h, outbound=True, path_m=path, radius_m=1.0, min_loop_m=4.0)
    assert cut > 0
    xy = c.xy_m
    assert xy[:, 0].max() <= 6.0  # the dead-end leg (x > 6) is gone
    assert (c.heading_rad[xy[:, 1] < 0.5] == 0.0).all()  # no westbound crumb left on the way in
    assert (np.abs(c.heading_rad[xy[:, 1] > 1.0] - math.pi / 2) < 1e-12).all()
    still = CrumbList()
    for k in range(20):
        assert not still.drop_pruning_loops(0.0, 0.0, 0.3 * k, outbound=True, path_m=0.0, radius_m=1.0,
                                            min_loop_m=4.0)
    assert len(still) == 20


def test_crumb_list_grows_and_can_be_capped():
    c = CrumbList()
    c.extend(CrumbBatch(np.arange(2000.0).repeat(2).reshape(-1, 2), np.zeros(2000)))
    assert len(c) == 2000 and c.xy_m[-1, 0] == 1999.0
    capped = CrumbList(max_crumbs=3)
    for k in range(5):
        capped.drop(float(k), 0.0, 0.0)
    np.testing.assert_array_equal(capped.xy_m[:, 0], [2.0, 3.0, 4.0])
    with pytest.raises(ValueError, match="xy_m has 2 rows"):
        CrumbBatch(np.zeros((2, 2)), np.zeros(3))


# ---------------------------------------------------------------------------- the brain
_obs = make_obs


def _brains(monkeypatch, n=2, **params):
    from teamnav.papers.trails.brains import blazing_trail as B

    return make_brains(monkeypatch, B, B.BlazingTrail, n, **params)


def test_brain_waggle_dance_reaches_the_team_and_steers_both_ways(monkeypatch):
    a, b = _brains(monkeypatch, crumb_interval_s=1.0, radius_m=1.5)
    # robot a drives east along y = 0 for 10 s, dropping a crumb per second, then reaches the source
    for k in range(100):
        _, out = a.step(_obs(0, k, [0.04 * k, 0.0, 0.0]))
        assert out == []
    assert len(a.private) == 10 and len(a.global_crumbs) == 0
    _, out = a.step(_obs(0, 100, [4.0, 0.0, 0.0], events=["took_resource"]))
    assert a.carrying and len(a.private) == 0 and len(a.global_crumbs) == 11  # + the crumb at the source
    assert len(out) == 1 and out[0].kind == "crumbs" and len(out[0].body) == 11
    # the teammate seeking the source near the trail prefers east; a (carrying) prefers west
    b.step(_obs(1, 101, [1.0, 0.5, 2.0], inbox=out))
    assert len(b.global_crumbs) == 11 and b.nav.headings[-1] == pytest.approx(0.0)
    a.step(_obs(0, 101, [3.0, 0.0, 0.0]))
    assert abs(a.nav.headings[-1]) == pytest.approx(math.pi)
    # home again with the unit: one delivery, another broadcast (the homebound crumbs)
    _, out = a.step(_obs(0, 102, [0.0, 0.0, np.pi], events=["given_resource"]))
    assert not a.carrying and a.log()["trips"] == 1 and len(out) == 1
    log = b.log()
    assert {"carrying", "trips", "place_index", "n_crumbs", "following", "mode"} <= set(log)
    assert log["following"] and log["n_crumbs"] == 11 and "crumbs" in log["layers"]
    assert "layers" not in b.log()  # drawn at most once per layer_every_steps


def test_brain_without_communication_follows_only_its_own_crumbs(monkeypatch):
    a, b = _brains(monkeypatch, communicate=False)
    for k in range(30):
        a.step(_obs(0, k, [0.1 * k, 0.0, 0.0]))
    _, out = a.step(_obs(0, 30, [3.0, 0.0, 0.0], events=["took_resource"]))
    assert out == [] and len(a.global_crumbs) == 4
    from teamnav.control.types import Message

    b.step(_obs(1, 31, [1.0, 0.0, 0.0], inbox=[Message(0, 3.0, a.global_crumbs.to_batch(), kind="crumbs")]))
    assert len(b.global_crumbs) == 0 and b.nav.headings[-1] is None


def test_brain_turns_around_at_each_place_reached_unless_told_not_to(monkeypatch):
    (a,) = _brains(monkeypatch, n=1, leave_place_m=2.5)
    a.step(_obs(0, 0, [0.0, 0.0, 0.0]))
    a.step(_obs(0, 1, [0.1, 0.0, 0.0], events=["given_resource"]))  # home, not sought: no turn
    a.step(_obs(0, 2, [0.2, 0.0, 0.0], events=["took_resource"]))
    a.step(_obs(0, 3, [0.3, 0.0, 0.0], events=["given_resource"]))
    assert a.nav.turn_arounds == [(2, 2.5), (3, 2.5)]  # called before Navigate's step of that tick
    (b,) = _brains(monkeypatch, n=1, turn_at_place=False)
    b.step(_obs(0, 0, [0.0, 0.0, 0.0], events=["took_resource"]))
    assert b.nav.turn_arounds == []


def test_brain_drops_no_crumbs_while_turning_on_the_spot(monkeypatch):
    """A robot turning on the spot (at a place, in Panic) would drop crumbs pointing every way."""
    for min_move, expected in ((0.1, 1), (0.0, 5)):
        (a,) = _brains(monkeypatch, n=1, crumb_interval_s=1.0, crumb_min_move_m=min_move)
        for k in range(41):  # 4 s on the spot, turning at 0.5 rad/s
            a.step(_obs(0, k, [3.0, 1.0, 0.05 * k]))
        assert len(a.private) == expected


def _corner_crumbs(b):
    """A trail east along y = 0 to (5, 0), then north along x = 5 (crumbs 0.5 m apart)."""
    xs = np.arange(0.0, 5.0, 0.5)
    ys = np.arange(0.5, 5.0, 0.5)
    xy = np.concatenate([np.stack([xs, 0 * xs], 1), np.stack([5.0 + 0 * ys, ys], 1)])
    h = np.concatenate([np.zeros(xs.size), np.full(ys.size, math.pi / 2)])
    b.global_crumbs.extend(CrumbBatch(xy, h))


def test_brain_reads_the_trail_a_little_ahead_so_it_turns_at_the_corner(monkeypatch):
    prefs = {}
    for look in (0.0, 1.5):
        (b,) = _brains(monkeypatch, n=1, radius_m=2.0, lookahead_m=look)
        _corner_crumbs(b)
        b.step(_obs(0, 0, [3.0, 0.0, 0.0]))
        prefs[look] = b.nav.headings[-1]
    # at (3, 0) the crumbs around the robot are mostly east-heading; 1.5 m ahead the corner's
    # northbound crumbs count: the hint turns to the corridor the trail takes
    assert prefs[0.0] < math.radians(15.0) < math.radians(30.0) < prefs[1.5] < math.pi / 2


def test_brain_vetoes_a_reversal_on_a_hint_from_too_few_crumbs(monkeypatch):
    for n_crumbs, allowed in ((2, False), (3, True)):
        (b,) = _brains(monkeypatch, n=1, radius_m=2.0, lookahead_m=0.0, reverse_min_crumbs=3)
        b.global_crumbs.extend(CrumbBatch(np.tile([[1.0, 0.0]], (n_crumbs, 1)), np.zeros(n_crumbs)))
        b.step(_obs(0, 0, [1.5, 0.0, math.pi]))  # heading west against an eastbound trail
        assert b.nav.headings[-1] == pytest.approx(0.0) and b.nav.allow_reverse[-1] is allowed


def test_brain_off_the_trail_heads_back_to_the_nearest_crumb_within_the_recovery_radius(monkeypatch):
    """recover_radius_m: no crumb around the point ahead, the nearest within 6 m lies behind the
    robot (it ran into a dead end): the hint points at it and may reverse the robot."""
    for recover, hint in ((6.0, math.pi), (0.0, None), (3.0, None)):
        (b,) = _brains(monkeypatch, n=1, radius_m=2.0, lookahead_m=1.0, recover_radius_m=recover)
        b.global_crumbs.extend(CrumbBatch(np.array([[0.0, 0.0], [-1.0, 0.0], [-2.0, 0.0], [0.0, 9.0]]),
                                          np.zeros(4)))
        b.step(_obs(0, 0, [4.0, 0.0, 0.0]))  # heading east, 4 m past the trail's east end
        got = b.nav.headings[-1]
        assert (got is None) if hint is None else got == pytest.approx(hint)
        assert b.nav.allow_reverse[-1] is (hint is not None)
    # on the trail the paper's average rules, whatever the recovery radius
    (b,) = _brains(monkeypatch, n=1, radius_m=2.0, lookahead_m=0.0, recover_radius_m=6.0)
    b.global_crumbs.extend(CrumbBatch(np.array([[4.0, 0.5]]), np.array([0.3])))
    b.step(_obs(0, 0, [4.0, 0.0, 0.0]))
    assert b.nav.headings[-1] == pytest.approx(0.3)


def test_nearest_crumb_within_a_radius():
    c = CrumbList()
    assert c.nearest(0.0, 0.0, 5.0) is None
    for x in (0.0, 2.0, 7.0):
        c.drop(x, 1.0, 0.0)
    assert c.nearest(2.4, 1.0, 5.0) == (2.0, 1.0)
    assert c.nearest(12.0, 1.0, 5.0) == (7.0, 1.0)
    assert c.nearest(12.01, 1.0, 5.0) is None  # just beyond the radius


# ---------------------------------------------------------------------------- closed loop
def trail_scenario(controller: str, params: dict, duration_s: float = 40.0):
    """trail_office_corridors (the U shape), robot 0 starting 2.4 m east of the source facing it, robot 1 at home."""
    from teamnav.experiments.spec import Scenario, load_scenario

    robot = {"radius_m": 0.25, "max_v_mps": 0.5, "max_omega_degps": 100, "controller": controller, "params": params,
             "sensors": [{"kind": "laser", "n_beams": 181, "fov_deg": 180, "max_range_m": 8.0, "noise_std_m": 0.01}],
             "odometry": {"frame": "world", "heading_drift_deg_per_min": 1.0, "alpha": [0.01, 0.005, 0.01, 0.005]}}
    return load_scenario(Scenario.model_validate({
        "name": "trail-closed-loop", "map": {"builtin": "trail_office_corridors"}, "duration_s": duration_s, "seed": 2,
        "record_every": 5, "metrics": [],
        "places": [{"place": "home", "radius_m": 1.0, "event": "given_resource"},
                   {"place": "source", "radius_m": 1.0, "event": "took_resource"}],
        "robots": [{**robot, "name": "near_source", "count": 1, "start": {"poses": [[7.8, 15.9, 180.0]]}},
                   {**robot, "name": "at_home", "count": 1, "start": {"near": "home", "spread_m": 0.3}}],
        "radio": {"mode": "broadcast"},
    }))


def test_closed_loop_waggle_dance_on_trail_office():
    from teamnav.experiments.runner import run

    res = run(trail_scenario("blazing-trail-v1", {}), progress=False)
    got = [(e["robot"], e["event"]) for e in res.data.event_log]
    assert got and got[0] == (0, "took_resource")
    t_found = res.data.event_log[0]["t_s"]
    assert t_found < 20.0
    logs = {r: [x for x in res.data.logs if x["robot"] == r] for r in (0, 1)}
    for rows in logs.values():
        assert {"carrying", "trips", "place_index", "n_crumbs", "following", "mode"} <= set(rows[-1]["values"])
    after = [x["values"] for x in logs[1] if x["t_s"] > t_found + 0.5]
    # the teammate at home heard the dance: its global list holds robot 0's private list
    assert after and after[0]["n_crumbs"] == [x["values"] for x in logs[0] if x["t_s"] > t_found + 0.5][0]["n_crumbs"]
    assert after[0]["n_crumbs"] > 0 and not after[0]["carrying"]
    assert [x["values"] for x in logs[0]][-1]["carrying"]  # robot 0 carries its unit
    assert "crumbs" in res.sim.recorder.layer_names
