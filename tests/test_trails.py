"""Trails of "Try to see it my way" (Vaughan et al. 2002 §2): Places, Crumbs, combining through
two common Places, the policies, expiry, the lowest time-to-place rule, an N-place round."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.papers.trails.brains.forager import PlaceRound
from teamnav.papers.trails.brains.trails import Trail, TrailMessage, place_transform, temporary_trail
from teamnav.geometry.similarity import Similarity

from _trail_brain_fakes import make_brains, make_obs


def _msg(places: dict[str, tuple[float, float]], crumbs: list[tuple[str, float, float, float, float]]) -> TrailMessage:
    names = tuple(places)
    return TrailMessage(names, np.array([places[n] for n in names], float).reshape(-1, 2),
                        tuple(c[0] for c in crumbs), np.array([c[1:3] for c in crumbs], float).reshape(-1, 2),
                        np.array([c[3] for c in crumbs], float), np.array([c[4] for c in crumbs], float))


coord = st.floats(-50.0, 50.0)


@settings(max_examples=60, deadline=None)
@given(scale=st.floats(0.5, 2.0), rot=st.floats(-math.pi, math.pi), tx=coord, ty=coord,
       ax=coord, ay=coord, bx=coord, by=coord,
       crumbs=st.lists(st.tuples(coord, coord), min_size=1, max_size=20))
def test_two_common_places_recover_any_similarity(scale, rot, tx, ty, ax, ay, bx, by, crumbs):
    """§2.1.5: the sender's frame is the local one through an unknown similarity T; combining
    maps its crumbs and its extra Place back exactly where they are locally."""
    a, b = np.array([ax, ay]), np.array([bx, by])
    if np.linalg.norm(a - b) < 1.0:
        b = a + np.array([1.0, 0.5])
    T = Similarity(scale, rot, tx, ty)  # local -> sender
    local = Trail()
    local.set_place("A", *a)
    local.set_place("B", *b)
    c_local = np.array(crumbs)
    c_sender = T.apply(c_local)
    far_place = np.array([3.0, -7.0])
    sent = _msg({"A": tuple(T.apply(a)), "B": tuple(T.apply(b)), "C": tuple(T.apply(far_place))},
                [("B", x, y, 5.0, 1.0) for x, y in c_sender])
    used = local.combine(sent, "pessimistic")
    assert used is not None
    assert used.scale == pytest.approx(1.0 / scale, rel=1e-9)
    tol = 1e-7 * (1.0 + np.abs(c_local).max() + np.abs([tx, ty]).max()) * max(scale, 1 / scale) ** 2
    np.testing.assert_allclose(local.crumb_xy_m, c_local, atol=tol)
    np.testing.assert_allclose(local.places["C"], far_place, atol=tol + 1e-7 * 10)
    # common Places are not copied: they keep their local estimates
    np.testing.assert_array_equal(local.places["A"], a)
    np.testing.assert_array_equal(local.places["B"], b)


def test_policies_with_zero_one_two_common_places():
    crumb = [("B", 1.0, 2.0, 7.0, 0.0)]
    # 2 common: both policies transform (here: pure translation by (+10, 0))
    for policy in ("pessimistic", "optimistic"):
        tr = Trail(); tr.set_place("A", 10.0, 0.0); tr.set_place("B", 20.0, 0.0)
        T = tr.combine(_msg({"A": (0.0, 0.0), "B": (10.0, 0.0)}, crumb), policy)
        assert T is not None and T.tx == pytest.approx(10.0)
        np.testing.assert_allclose(tr.crumb_xy_m, [[11.0, 2.0]])
    # 1 common: pessimistic refuses (nothing copied, not even Places), optimistic translates
    tr = Trail(); tr.set_place("A", 10.0, 0.0)
    assert tr.combine(_msg({"A": (0.0, 0.0), "B": (5.0, 5.0)}, crumb), "pessimistic") is None
    assert len(tr) == 0 and set(tr.places) == {"A"}
    tr.combine(_msg({"A": (0.0, 0.0), "B": (5.0, 5.0)}, crumb), "optimistic")
    np.testing.assert_allclose(tr.crumb_xy_m, [[11.0, 2.0]])
    np.testing.assert_allclose(tr.places["B"], [15.0, 5.0])
    np.testing.assert_allclose(tr.places["A"], [10.0, 0.0])
    # 0 common: pessimistic refuses, optimistic copies as-is
    tr = Trail(); tr.set_place("A", 10.0, 0.0)
    assert tr.combine(_msg({"B": (5.0, 5.0)}, crumb), "pessimistic") is None
    assert len(tr) == 0
    tr.combine(_msg({"B": (5.0, 5.0)}, crumb), "optimistic")
    np.testing.assert_allclose(tr.crumb_xy_m, [[1.0, 2.0]])
    np.testing.assert_allclose(tr.places["B"], [5.0, 5.0])


def test_without_place_transforms_trails_are_copied_as_is():
    tr = Trail(); tr.set_place("A", 10.0, 0.0); tr.set_place("B", 20.0, 0.0)
    T = tr.combine(_msg({"A": (0.0, 0.0), "B": (0.0, 10.0)}, [("B", 1.0, 2.0, 7.0, 0.0)]), "pessimistic",
                   use_transforms=False)
    assert T == Similarity.identity()
    np.testing.assert_allclose(tr.crumb_xy_m, [[1.0, 2.0]])


def test_coincident_common_places_count_as_one():
    loc = {"A": [0.0, 0.0], "B": [0.0, 0.0]}
    rec = {"A": [1.0, 1.0], "B": [1.0, 1.0]}
    assert place_transform(loc, rec, "pessimistic") is None
    assert place_transform(loc, rec, "optimistic") == Similarity(1.0, 0.0, -1.0, -1.0)
    with pytest.raises(ValueError, match="policy must be one of"):
        place_transform(loc, rec, "hopeful")


def test_more_than_two_common_places_use_the_farthest_pair():
    """N places: the best-conditioned pair fixes T; a slightly inconsistent third is ignored."""
    loc = {"A": [0.0, 0.0], "B": [0.5, 0.0], "C": [20.0, 0.0]}
    rec = {"A": [0.0, 0.0], "B": [0.5, 0.3], "C": [0.0, 20.0]}  # rotated 90 deg; B off by 0.3 m
    T = place_transform(loc, rec, "pessimistic")
    assert T.rotation_rad == pytest.approx(-math.pi / 2)
    assert T.scale == pytest.approx(1.0)


def test_expiry_removes_old_crumbs_and_bounds_memory():
    tr = Trail()
    tr.set_place("A", 0.0, 0.0)
    tr.add_crumbs(["A", "A", "A"], [[0, 0], [1, 1], [2, 2]], [1.0, 2.0, 3.0], [0.0, 100.0, 250.0])
    assert tr.expire(now_s=300.0, max_age_s=240.0) == 1  # t=0 is 300 s old
    np.testing.assert_array_equal(tr.crumb_t, [100.0, 250.0])
    np.testing.assert_allclose(tr.crumb_xy_m, [[1, 1], [2, 2]])
    assert tr.crumb_place == ["A", "A"]
    # a robot receiving 1-crumb trails from 4 robots every 2 s for an hour keeps ~4 min of them
    tr = Trail(); tr.set_place("A", 0.0, 0.0)
    for k in range(1800):
        now = 2.0 * k
        tr.add_crumbs(["A"] * 4, np.zeros((4, 2)), np.ones(4), np.full(4, now))
        tr.expire(now, 240.0)
    assert len(tr) == 4 * 121


def test_lowest_time_to_place_within_radius_for_the_goal_only():
    """§2.3: head for the lowest-s crumb of the current goal within the radius."""
    tr = Trail()
    tr.set_place("A", 0.0, 0.0); tr.set_place("B", 30.0, 0.0)
    tr.add_crumbs(["B", "B", "B", "A", "B"],
                  [[1.0, 0.0], [0.0, 1.5], [5.0, 0.0], [0.0, -1.0], [-1.0, 0.0]],
                  [20.0, 12.0, 1.0, 0.5, 30.0], [0.0] * 5)
    idx, s = tr.best_crumb("B", 0.0, 0.0, radius_m=2.0)
    # (5, 0) has s=1 but is out of the radius; the A crumb has s=0.5 but is for another place
    assert (idx, s) == (1, 12.0)
    assert tr.heading_to_best("B", 0.0, 0.0, 2.0) == pytest.approx(math.pi / 2)
    assert tr.best_crumb("A", 0.0, 0.0, 2.0) == (3, 0.5)
    assert tr.best_crumb("B", 20.0, 20.0, 2.0) is None
    assert tr.best_crumb("C", 0.0, 0.0, 2.0) is None


def test_temporary_trail_carries_all_places_and_one_crumb():
    tr = Trail()
    tr.set_place("home", 0.0, 0.0); tr.set_place("source", 9.0, 3.0)
    tr.add_crumbs(["home"], [[1.0, 1.0]], [3.0], [4.0])
    m = temporary_trail(tr, "source", 5.0, 2.0, 11.0, 40.0)
    assert m.place_names == ("home", "source") and m.crumb_place == ("source",)
    np.testing.assert_allclose(m.crumb_xy_m, [[5.0, 2.0]])
    assert (m.crumb_s[0], m.crumb_t[0]) == (11.0, 40.0)
    # two places + one crumb, as plain numbers: bytes are countable
    from teamnav.control.types import Message
    assert Message(0, 40.0, m, kind="trail").size_bytes() > 24 + 8 * 4


def test_place_round_with_three_places():
    """N = 3 (a mail round): only the sought place advances, in cyclic order."""
    r = PlaceRound(["depot", "mail_a", "mail_b"])
    assert r.goal == "mail_a"
    assert r.observe(("mail_b",), 1.0) == [] and r.last_place == "mail_b"
    assert r.observe(("mail_a",), 2.0) == ["mail_a"] and r.goal == "mail_b"
    assert r.observe(("mail_b", "depot"), 3.0) == ["mail_b", "depot"]
    assert (r.goal, r.trips, r.last_place, r.last_place_time_s) == ("mail_a", 3, "depot", 3.0)
    with pytest.raises(ValueError, match="at least 2 distinct"):
        PlaceRound(["home", "home"])


def test_trail_message_rejects_mismatched_columns():
    with pytest.raises(ValueError, match="must have one length"):
        TrailMessage(("A",), np.zeros((1, 2)), ("A", "A"), np.zeros((1, 2)), np.zeros(1), np.zeros(1))


# ---------------------------------------------------------------------------- the brain
_obs = make_obs


def _brains(monkeypatch, n=2, **params):
    from teamnav.papers.trails.brains import trail_share as TS

    return make_brains(monkeypatch, TS, TS.TrailShare, n, **params)


def test_brain_shares_time_to_place_crumbs_across_rotated_frames(monkeypatch):
    """Robot a's frame is robot b's rotated by 90 deg: a trail a lays from the source towards home
    steers b, seeking the source, along the right direction in b's own frame (§2.1.5, §2.3)."""
    a, b = _brains(monkeypatch, round=["home", "source"], broadcast_interval_s=2.0, radius_m=3.0)
    rot = Similarity(1.0, math.pi / 2, 0.0, 0.0)  # b's frame -> a's frame
    # b's world: home at (0, 0), source at (20, 0); both start at home and reach the source
    b.step(_obs(1, 0, [0.0, 0.0, 0.0]))
    b.step(_obs(1, 1, [20.0, 0.0, 0.0], events=["source"]))
    a.step(_obs(0, 0, [0.0, 0.0, 0.0]))
    xa, ya = rot.apply([20.0, 0.0])
    _, out = a.step(_obs(0, 1, [xa, ya, 0.0], events=["source"]))
    # a drives from the source back home (b's frame: x from 20 down to 0), broadcasting every 2 s
    sent = []
    for k in range(2, 200):
        xa, ya = rot.apply([20.0 - 0.1 * k, 0.0])
        _, out = a.step(_obs(0, k, [xa, ya, 0.0]))
        sent += out
    # one every 2 s while moving: t = 2, 4, ..., 18 s
    assert len(sent) == 9 and all(m.kind == "trail" and len(m.body.crumb_place) == 1 for m in sent)
    assert {m.body.crumb_place[0] for m in sent} == {"source"}
    # b, now at home again and seeking the source, hears them
    b.step(_obs(1, 300, [0.0, 0.0, math.pi], events=["home"]))
    assert b.round.goal == "source"
    b.step(_obs(1, 301, [8.0, 0.0, 0.0], inbox=sent))
    assert b.combined == 9 and b.refused == 0
    # the crumbs landed on b's x axis, and b heads to the lowest time-to-source one: east
    np.testing.assert_allclose(b.trail.crumb_xy_m[b.trail.place_mask("source")][:, 1], 0.0, atol=1e-9)
    assert b.nav.headings[-1] == pytest.approx(0.0, abs=1e-9)
    log = b.log()
    assert log["following"] and log["place_index"] == 1 and log["trips"] == 2


def test_brain_pessimistic_refuses_before_two_places_optimistic_uses(monkeypatch):
    for policy, n_used in (("pessimistic", 0), ("optimistic", 1)):
        a, b = _brains(monkeypatch, round=["home", "source"], policy=policy)
        a.step(_obs(0, 0, [0.0, 0.0, 0.0]))
        a.step(_obs(0, 1, [20.0, 0.0, 0.0], events=["source"]))
        _, out = a.step(_obs(0, 30, [19.0, 0.0, 0.0]))
        assert len(out) == 1
        b.step(_obs(1, 0, [0.0, 0.0, 0.0]))  # knows only home
        b.step(_obs(1, 31, [1.0, 0.0, 0.0], inbox=out))
        assert b.combined == n_used and ("source" in b.trail.places) == bool(n_used)


def test_brain_broadcasts_only_while_moving_and_expires_old_crumbs(monkeypatch):
    (a,) = _brains(monkeypatch, n=1, crumb_max_age_s=10.0)
    sent = []
    for k in range(100):  # standing still at home for 10 s: one trail at t = 0, then none
        sent += a.step(_obs(0, k, [0.0, 0.0, 0.0]))[1]
    assert len(sent) == 1
    for k in range(100, 400):
        sent += a.step(_obs(0, k, [0.05 * (k - 100), 0.0, 0.0]))[1]
    assert len(sent) == 1 + 14  # t = 12, 14, ..., 38 s (at t = 10 s it had not moved yet)
    assert len(a.trail) == 5 and a.trail.crumb_t.min() >= 40.0 - 10.0  # only the last 10 s kept


def test_brain_without_communication_sends_and_reads_nothing(monkeypatch):
    a, b = _brains(monkeypatch, communicate=False)
    _, out = a.step(_obs(0, 0, [0.0, 0.0, 0.0]))
    assert out == [] and len(a.trail) == 1
    msg = temporary_trail(a.trail, "given_resource", 1.0, 0.0, 3.0, 0.0)
    from teamnav.control.types import Message

    b.step(_obs(1, 0, [0.0, 0.0, 0.0], inbox=[Message(0, 0.0, msg, kind="trail")]))
    assert len(b.trail) == 1  # only its own crumb


# ---------------------------------------------------------------------------- closed loop
def test_closed_loop_trail_sharing_on_trail_office():
    from test_crumbs import trail_scenario

    from teamnav.experiments.runner import run

    for policy in ("optimistic", "pessimistic"):
        res = run(trail_scenario("trail-share-v1", {"policy": policy}), progress=False)
        assert res.data.event_log[0]["robot"] == 0 and res.data.event_log[0]["event"] == "took_resource"
        finder, home = res.sim.brains[0][0], res.sim.brains[1][0]
        assert finder.round.goal == "given_resource" and finder.round.trips == 1
        last = [x["values"] for x in res.data.logs if x["robot"] == 1][-1]
        assert {"carrying", "trips", "place_index", "n_crumbs", "following", "mode"} <= set(last)
        assert last["n_crumbs"] == len(home.trail) > 0
        if policy == "optimistic":  # one common Place (home): translated in, the source learnt
            assert home.refused == 0 and "took_resource" in home.trail.places
            assert home.trail.place_mask("took_resource").sum() > 0
        else:  # the finder knows two Places, the robot at home one: refused
            assert home.refused > 0 and "took_resource" not in home.trail.places


def test_brain_three_place_round_seeks_each_place_in_turn(monkeypatch):
    """N = 3 (a mail round, §2.1): the goal cycles depot -> a -> b -> depot; the trail rule reads
    only the crumbs of the current goal; ``every_place`` lays one crumb per visited Place."""
    (r,) = _brains(monkeypatch, n=1, round=["depot", "a", "b"], crumbs_for="every_place", radius_m=5.0)
    _, out = r.step(_obs(0, 0, [0.0, 0.0, 0.0]))
    r.step(_obs(0, 50, [10.0, 0.0, 0.0], events=["a"]))
    assert r.round.goal == "b" and set(r.trail.places) == {"depot", "a"}
    r.trail.add_crumbs(["b", "depot"], [[12.0, 2.0], [8.0, -2.0]], [1.0, 0.5], [5.0, 5.0])
    r.step(_obs(0, 51, [10.0, 0.0, 0.0]))
    assert r.nav.headings[-1] == pytest.approx(math.pi / 4)  # to the "b" crumb, not the lower-s "depot" one
    _, out = r.step(_obs(0, 80, [11.0, 1.0, 0.0]))
    assert out[0].body.crumb_place == ("depot", "a")  # one crumb per visited Place
    np.testing.assert_allclose(out[0].body.crumb_s, [8.0, 3.0])  # time since each visit
    r.step(_obs(0, 100, [12.0, 2.0, 0.0], events=["b"]))
    r.step(_obs(0, 150, [0.0, 0.0, 0.0], events=["depot"]))
    assert r.round.goal == "a" and r.round.trips == 3 and r.log()["place_index"] == 1


def test_brain_descends_the_trail_and_explores_at_its_end(monkeypatch):
    """descend_only: once at the lowest crumb near it, the robot does not turn back to a higher
    one (the paper's rule as written does: it dithers at the end of a trail)."""
    for descend, at_end in ((True, None), (False, math.pi)):
        (r,) = _brains(monkeypatch, n=1, descend_only=descend, radius_m=2.1, broadcast_interval_s=600.0)
        r.step(_obs(0, 0, [-50.0, 0.0, 0.0]))
        xs = np.arange(5.0)
        r.trail.add_crumbs(["took_resource"] * 5, np.c_[xs, np.zeros(5)], 10.0 - 2.0 * xs, np.full(5, 0.0))
        r.step(_obs(0, 1, [2.0, 0.0, 0.0]))
        assert r.nav.headings[-1] == pytest.approx(0.0)  # on towards x = 4 (s = 2)
        r.step(_obs(0, 2, [4.3, 0.0, 0.0]))  # just past the trail's end (s = 2 at x = 4)
        assert r.nav.headings[-1] == at_end  # the paper's rule turns back to it


def test_brain_turns_around_at_the_place_it_seeks(monkeypatch):
    (a,) = _brains(monkeypatch, n=1, round=["home", "source"], leave_place_m=2.0)
    a.step(_obs(0, 0, [0.0, 0.0, 0.0]))
    a.step(_obs(0, 1, [5.0, 0.0, 0.0], events=["home"]))  # passing home while seeking the source
    a.step(_obs(0, 2, [20.0, 0.0, 0.0], events=["source"]))
    assert a.nav.turn_arounds == [(2, 2.0)]
    (b,) = _brains(monkeypatch, n=1, round=["home", "source"], turn_at_place=False)
    b.step(_obs(0, 0, [0.0, 0.0, 0.0]))
    b.step(_obs(0, 1, [20.0, 0.0, 0.0], events=["source"]))
    assert b.nav.turn_arounds == []


def test_brain_picks_the_best_crumb_around_a_point_ahead_and_heads_to_it_from_where_it_is(monkeypatch):
    heads = {}
    for look in (0.0, 1.0):
        (a,) = _brains(monkeypatch, n=1, round=["home", "source"], radius_m=1.5, lookahead_m=look)
        a.step(_obs(0, 0, [0.0, 0.0, 0.0]))
        # one crumb beside the robot (10 s from the source), one ahead (5 s from it)
        a.trail.add_crumbs(["source", "source"], [[0.0, 1.2], [2.5, 0.0]], [10.0, 5.0], [0.0, 0.0])
        a.step(_obs(0, 1, [0.0, 0.0, 0.0]))
        heads[look] = a.nav.headings[-1]
    assert heads[0.0] == pytest.approx(math.pi / 2)  # only the crumb beside it is within 1.5 m
    assert heads[1.0] == pytest.approx(0.0)  # around (1, 0) the better crumb at (2.5, 0) counts


def test_brain_off_the_trail_heads_back_to_the_nearest_goal_crumb_below_its_bound(monkeypatch):
    """recover_radius_m: no goal crumb around the point ahead; the nearest goal crumb within the
    recovery radius (and below the descend-only bound) gives the hint."""
    for recover, hint in ((6.0, math.pi), (0.0, None)):
        (a,) = _brains(monkeypatch, n=1, round=["home", "source"], radius_m=1.5, lookahead_m=1.0,
                       recover_radius_m=recover, broadcast_interval_s=600.0)
        a.step(_obs(0, 0, [-50.0, 0.0, 0.0]))
        # the trail to the source ends at x = 0 (behind the robot); a home crumb lies nearer
        a.trail.add_crumbs(["source", "source", "home"], [[-1.0, 0.0], [0.0, 0.0], [3.5, 0.0]],
                           [6.0, 5.0, 1.0], [0.0, 0.0, 0.0])
        a.step(_obs(0, 1, [4.0, 0.0, 0.0]))
        got = a.nav.headings[-1]
        assert (got is None) if hint is None else got == pytest.approx(hint)


def test_nearest_crumb_for_a_goal_below_a_time_to_place():
    tr = Trail()
    assert tr.nearest_crumb("A", 0.0, 0.0, 5.0) is None
    tr.add_crumbs(["A", "A", "B"], [[1.0, 0.0], [3.0, 0.0], [0.5, 0.0]], [9.0, 4.0, 1.0], [0.0, 0.0, 0.0])
    assert tr.nearest_crumb("A", 0.0, 0.0, 5.0) == (1.0, 0.0)
    assert tr.nearest_crumb("A", 0.0, 0.0, 5.0, below_s=5.0) == (3.0, 0.0)
    assert tr.nearest_crumb("A", 0.0, 0.0, 2.9, below_s=5.0) is None
    assert tr.nearest_crumb("C", 0.0, 0.0, 5.0) is None
