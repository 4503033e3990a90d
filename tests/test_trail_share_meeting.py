"""Meeting flags of Navigate / trail-share-v1 (all off by default since dfcab8a, 2026-11-26): gap-fills for robots that
meet at corners (trail_share module docstring). Hand-made situations: synthetic scans and
odometry poses fed step by step, the fake Navigate for the brain-level flag."""

from __future__ import annotations

import math

import numpy as np
import pytest

from _trail_brain_fakes import make_brains, make_obs
from teamnav.control.check import synthetic_infos
from teamnav.papers.trails.brains.blazing_trail import BlazingTrail
from teamnav.papers.trails.brains.trail_share import TrailShare
from teamnav.control.nav.navigate import Navigate
from test_nav_navigate import INFO, MAX_R, cast, nav, observe, t_junction

CLEAR = np.full(181, MAX_R)


def _panic_then_navigate(n):
    """A stall starts Panic; open space ends it (stop, no turn needed, drive on 2 s): the robot
    stands at the origin facing +x with the post-Panic opening cool-down set."""
    k = 0
    n.step(observe(CLEAR, (0.0, 0.0, 0.0), k, stalled=True))
    assert n.mode == "panic"
    while n.mode == "panic":
        k += 1
        n.step(observe(CLEAR, (0.0, 0.0, 0.0), k))
        assert k < 100
    return k + 1


@pytest.mark.parametrize(("flag", "mode"), [(False, "navigate"), (True, "advance")])
def test_hint_skips_the_post_panic_opening_cooldown(flag, mode):
    # After a Panic the 1.5 m cool-down hides the right branch of a T-junction; with the flag a
    # trail hint down that branch takes it at once.
    n = nav(hint_skips_cooldown=flag)
    k = _panic_then_navigate(n)
    pose = (0.6, 0.0, 0.0)
    n.step(observe(cast(t_junction(), pose), pose, k), -math.pi / 2)
    assert n.mode == mode


def test_hint_skips_no_cooldown_of_an_opening_already_decided():
    # Exploring, a decided opening stays cooled down (a hint later does not re-open it early:
    # only the cool-down that follows a Panic or a turn is skipped).
    n = nav(hint_skips_cooldown=True, p_take_opening=0.0)
    pose = (0.6, 0.0, 0.0)
    n.step(observe(cast(t_junction(), pose), pose, 0))  # exploring, p = 0: seen, not taken
    assert n.mode == "navigate"
    n.step(observe(cast(t_junction(), pose), pose, 1), -math.pi / 2)
    assert n.mode == "navigate"


@pytest.mark.parametrize(("flag", "hint_deg", "turns"), [(False, 90.0, False), (True, 90.0, True),
                                                         (True, -70.0, True), (True, 30.0, False)])
def test_face_hint_after_panic_turns_towards_the_hint_first(flag, hint_deg, turns):
    n = nav(face_hint_after_panic=flag)
    k = _panic_then_navigate(n)
    cmd = n.step(observe(CLEAR, (0.0, 0.0, 0.0), k), math.radians(hint_deg))
    assert (n.mode == "turn") == turns
    if turns:
        assert cmd[0] == 0.0 and math.copysign(1.0, cmd[1]) == math.copysign(1.0, hint_deg)
        assert n._turn_goal_rad == pytest.approx(math.radians(abs(hint_deg)))
        # Once only: the next Panic-free hint far off does not turn the robot again.
        n.mode = "navigate"
        n.step(observe(CLEAR, (0.0, 0.0, 0.0), k + 1), math.radians(hint_deg))
        assert n.mode == "navigate"


def _approach(n, obstacle, n_clear=15, n_after=50, v_mps=0.4):
    """Drive along +x in open space; after n_clear steps ``obstacle(x)`` (segments) is in the
    scan. Returns the commands from then on."""
    x, cmds = 0.0, []
    for k in range(n_clear + n_after):
        walls = obstacle(x) if k >= n_clear else []
        r = cast(walls, (x, 0.0, 0.0)) if walls else CLEAR
        v, w = n.step(observe(r, (x, 0.0, 0.0), k))
        if k >= n_clear:
            cmds.append((v, w))
        x += 0.1 * v_mps if k < n_clear else 0.0  # after it appears the pose is held
    return cmds


def _robot_ahead(x):
    return [(x + 0.6, -0.25, x + 0.6, 0.25)]  # a robot-sized obstacle 0.6 m ahead


def test_give_way_stops_for_an_obstacle_that_appears_ahead_then_times_out():
    cmds = _approach(nav(give_way_s=3.0), _robot_ahead)
    stopped = [c == (0.0, 0.0) for c in cmds]
    assert all(stopped[:29]) and not all(stopped[30:])  # 3 s at 0.1 s a step, then Navigate again


def test_give_way_ends_when_the_obstacle_is_gone():
    n = nav(give_way_s=3.0)
    cmds = _approach(n, _robot_ahead, n_after=1)
    assert cmds == [(0.0, 0.0)]
    v, w = n.step(observe(CLEAR, (0.56, 0.0, 0.0), 100))
    assert v > 0.0  # gone: drives on


def test_give_way_off_by_default_and_not_for_a_wall_approached_steadily():
    cmds = _approach(nav(), _robot_ahead)
    assert cmds[0] != (0.0, 0.0)
    n = nav(give_way_s=3.0)
    wall = [(3.0, -5.0, 3.0, 5.0)]
    x = 0.0
    for k in range(60):  # 0.04 m a step up to 0.6 m from the wall: ranges fall as driven
        r = cast(wall, (x, 0.0, 0.0))
        n.step(observe(r, (x, 0.0, 0.0), k))
        assert not n._gw_active
        x = min(x + 0.04, 2.4)


@pytest.mark.parametrize(("ignore", "reverses"), [(False, False), (True, True)])
def test_reversal_inside_the_reversal_memory_only_when_told(ignore, reverses):
    n = nav(reverse_cooldown_s=0.0, reverse_cooldown_m=3.0, reverse_memory_m=3.0)
    n.step(observe(CLEAR, (0.0, 0.0, math.pi), 0), 0.0)
    assert n.mode == "turn"
    n.mode = "navigate"  # as if the turn had ended; the robot is back 1 m from that spot
    n.step(observe(CLEAR, (1.0, 0.0, math.pi), 1), 0.0, reverse_ignore_memory=ignore)
    assert (n.mode == "turn") == reverses


@pytest.mark.parametrize(("flag", "told"), [(False, False), (True, True)])
def test_recover_reverse_tells_navigate_only_while_recovering(monkeypatch, flag, told):
    from teamnav.papers.trails.brains import trail_share as TS

    (b,) = make_brains(monkeypatch, TS, TS.TrailShare, 1, round=["home", "source"], radius_m=2.0,
                       lookahead_m=1.0, broadcast_interval_s=600.0, recover_reverse=flag)
    b.step(make_obs(0, 0, [-50.0, 0.0, 0.0]))
    xs = [0.0, 1.0, 2.0, 3.0, 4.0]
    b.trail.add_crumbs(["source"] * 5, [[x, 0.0] for x in xs], [30.0 - x for x in xs], [0.0] * 5)
    b.step(make_obs(0, 1, [4.0, 0.0, 0.0]))  # on the trail: following, not recovering
    b.step(make_obs(0, 2, [4.0, 3.0, math.pi / 2]))  # off it up a branch: recovering
    assert b.nav.ignore_memory == [False, False, told]
    assert b.log()["recovering"] is True


def test_give_way_never_fires_for_walls_alone_round_a_corner():
    # An L-shaped corridor (east, then north): wall following round the corner brings walls into
    # the front sector while the heading swings; no other robot, so no giving way.
    walls = [(-5.0, -0.9, 2.7, -0.9), (2.7, -0.9, 2.7, 10.0), (-5.0, 0.9, 0.9, 0.9), (0.9, 0.9, 0.9, 10.0)]
    n = nav(give_way_s=3.0)
    fired = []
    pose = np.array([-3.0, 0.0, 0.0])
    for k in range(300):
        v, w = n.step(observe(cast(walls, pose), pose, k), math.pi / 2 if pose[0] > 0.5 else 0.0)
        fired.append(n._gw_active)
        pose = pose + 0.1 * np.array([v * math.cos(pose[2]), v * math.sin(pose[2]), w])
    assert pose[1] > 3.0  # round the corner and up the north leg
    assert not any(fired)


# ------------------------------------------------------------------ meeting guard
def _blocked_corridor(n, start_step, n_steps=200):
    """A 1.4 m corridor along +x with a robot-sized obstacle 0.9 m ahead that leaves no room to
    pass (the box is blocked); the trail's hint points on along +x. Closed loop with perfect
    odometry; returns the headings [deg] and modes."""
    walls = [(0.65, -0.35, 1.15, -0.35), (1.15, -0.35, 1.15, 0.15), (1.15, 0.15, 0.65, 0.15),
             (0.65, 0.15, 0.65, -0.35), (-5.0, 0.7, 10.0, 0.7), (-5.0, -0.7, 10.0, -0.7)]
    pose = np.array([0.0, 0.3, 0.0])
    heads, modes = [], []
    for j in range(n_steps):
        v, w = n.step(observe(cast(walls, pose), pose, start_step + j), 0.0)
        heads.append(math.degrees(pose[2]))
        modes.append(n.mode)
        pose = pose + 0.1 * np.array([v * math.cos(pose[2]), v * math.sin(pose[2]), w])
    return np.abs(heads), modes


@pytest.mark.parametrize("guard_deg", [0.0, 90.0])
def test_meet_guard_keeps_a_blocked_robot_facing_along_the_trail_for_meet_guard_s(guard_deg):
    # After a Panic the other robot still blocks the corridor: the left-wall follower turns on
    # the spot and, unguarded, comes round and drives back the way it came. Guarded, the robot
    # turns no further than ~guard_deg from the hint, until meet_guard_s (8 s) has passed.
    n = nav(meet_guard_deg=guard_deg, meet_guard_s=8.0)
    k = _panic_then_navigate(n)
    heads, modes = _blocked_corridor(n, k)
    if guard_deg == 0.0:
        assert heads[:70].max() > 150.0
    else:
        assert heads[:78].max() < guard_deg + 5.0 and "turn" not in modes[:78]
        assert heads.max() > 150.0  # released after 8 s: the rules above again


def test_meet_guard_needs_a_meeting():
    # The same corridor with no Panic and the obstacle in sight from the start (nothing appeared
    # ahead): the guarded robot does exactly what the unguarded one does.
    a, ma = _blocked_corridor(nav(meet_guard_deg=90.0), 0, 120)
    b, mb = _blocked_corridor(nav(), 0, 120)
    assert np.array_equal(a, b) and ma == mb and a.max() > 150.0


def test_meet_guard_starts_when_an_obstacle_appears_ahead():
    # A robot comes into view 0.6 m ahead at t = 1.5 s (no Panic): the guard window opens.
    n = nav(meet_guard_deg=90.0)
    _approach(n, _robot_ahead, n_after=2)
    assert n._meet_until_s == pytest.approx(1.5 + 8.0) and n._meet_until_m == pytest.approx(n._odo_m + 3.0)


@pytest.mark.parametrize(("navigate", "expected_s"), [({}, 0.0), ({"give_way_s": 3.0}, 3.0)])
def test_both_trail_brains_drive_without_give_way_by_default(navigate, expected_s):
    # ff866a4 (2026-11-23) turned give_way_s = 3 on for trail-share-v1 only; the lane fix of
    # 8a4187d (box_reach_m = 2.0, 2026-11-26) made it cost, so both brains drive with the same
    # Navigate again (dfcab8a).
    info = synthetic_infos(1)[0]
    share = TrailShare(TrailShare.Params(navigate=navigate), np.random.default_rng(0), info)
    assert share.nav.params.give_way_s == expected_s
    blaze = BlazingTrail(BlazingTrail.Params(), np.random.default_rng(0), info)
    assert blaze.nav.params.give_way_s == 0.0


# ------------------------------------------------------------------ asymmetric give-way
def _approach_bold(n, bold, n_clear=15, n_after=50):
    """``_approach`` with ``_robot_ahead``, telling Navigate ``bold`` at every step."""
    x, cmds = 0.0, []
    for k in range(n_clear + n_after):
        walls = _robot_ahead(x) if k >= n_clear else []
        r = cast(walls, (x, 0.0, 0.0)) if walls else CLEAR
        v, w = n.step(observe(r, (x, 0.0, 0.0), k), bold=bold)
        if k >= n_clear:
            cmds.append((v, w))
        x += 0.04 if k < n_clear else 0.0
    return cmds


@pytest.mark.parametrize(("bold_s", "bold", "n_stopped"), [(None, True, 30), (0.5, True, 5), (0.5, False, 30),
                                                           (0.0, True, 1)])
def test_give_way_bold_waits_briefly_only_for_the_bold_robot(bold_s, bold, n_stopped):
    # Vaughan et al. SAB 2000 / ICAR 2005 (gap-fill): the robot with the higher investment (told
    # bold) waits only give_way_bold_s, the other the full give_way_s; off (None): both 3 s.
    cmds = _approach_bold(nav(give_way_s=3.0, give_way_bold_s=bold_s), bold)
    stopped = [c == (0.0, 0.0) for c in cmds]
    assert all(stopped[: n_stopped - 1]) and not stopped[n_stopped]


def test_give_way_bold_is_off_without_give_way():
    cmds = _approach_bold(nav(give_way_s=0.0, give_way_bold_s=0.5), True)
    assert cmds[0] != (0.0, 0.0)


@pytest.mark.parametrize(("bold_s", "told"), [(None, []), (0.5, [False, True])])
def test_trail_share_tells_navigate_bold_when_loaded(bold_s, told):
    # trail-share-v1 passes bold = loaded (seeking round[0], home) only when the param is set.
    calls = []

    class Spy(Navigate):
        def step(self, obs, preferred_heading_rad=None, **kw):
            calls.append(kw.get("bold"))
            return super().step(obs, preferred_heading_rad, **kw)

    nav_kw = {} if bold_s is None else {"give_way_bold_s": bold_s}
    b = TrailShare(TrailShare.Params(round=["home", "source"], navigate=nav_kw), np.random.default_rng(0), INFO)
    b.nav.__class__ = Spy
    b.step(make_obs(0, 0, [0.0, 0.0, 0.0]))
    assert b.round.index == 1  # seeking the source: unloaded
    b.step(make_obs(0, 1, [0.1, 0.0, 0.0], ["source"]))
    assert b.round.index == 0  # at the source: loaded, heading home
    if bold_s is None:
        assert calls == [None, None]
    else:
        assert calls == told
