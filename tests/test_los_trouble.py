"""State sharing gaps filled for the potential field (Sgorbissa & Arkin §5 rule 3): a teammate seen
only at the step it sent its Tr bit, and R1 in trouble with no teammate in sight."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamnav.papers.los_help.brains import LosExplorer
from teamnav.papers.los_help.brains import brain as brain_mod

from test_los_help import StraightNav, info, msg, obs

WALL = [(0.0, 0.1, 0.5)]  # a wall 0.5 m ahead (+x), where the goal is


def _trapped(monkeypatch, cr=3, **params):
    """R1 whose navigator never progresses, in trouble after ``cr`` steps with nobody in sight."""
    stuck = StraightNav(stuck=True)
    monkeypatch.setattr(brain_mod, "make_navigator", lambda *a, **k: stuck)
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[(6.0, 0.0)], trouble_cr=cr, goal_sharing=False,
                                        trouble_helper_towards_goal=False, **params),
                     np.random.default_rng(0), info(0, 2))
    return r1


@pytest.mark.parametrize("at_send", [False, True])
def test_teammate_seen_only_when_it_sent_its_state_is_headed_for(monkeypatch, at_send):
    """§5 rule 3 with a one-step sighting: the Tr bit sent at step k arrives at k + 1, when the
    teammate is out of sight again; ``trouble_sighting_at_send`` pairs it with the sighting at k."""
    r1 = _trapped(monkeypatch, trouble_sighting_at_send=at_send)
    for k in range(3):
        r1.step(obs(k, walls=WALL))
    assert r1.trouble.tr
    # step 3: R2 seen 3 m to the left (+y) for this step only; its message of step 3 arrives at 4
    r1.step(obs(3, walls=WALL, seen=[(1, 3.0, math.pi / 2)]))
    assert r1.mode == "own_goal"  # no Tr bit yet
    a, _ = r1.step(obs(4, walls=WALL, inbox=[msg(1, 3, trouble=False)]))
    if at_send:
        assert r1.mode == "trouble_follow" and a.direction_rad == pytest.approx(math.pi / 2)
        a, _ = r1.step(obs(5, pose=(0.0, 0.2, 0.0), walls=WALL))  # kept at its last seen position
        assert r1.mode == "trouble_follow" and a.direction_rad == pytest.approx(math.pi / 2)
    else:
        assert r1.mode == "own_goal"
    # a teammate that sent "in trouble" is no candidate either way
    r2 = _trapped(monkeypatch, trouble_sighting_at_send=at_send)
    for k in range(3):
        r2.step(obs(k, walls=WALL))
    r2.step(obs(3, walls=WALL, seen=[(1, 3.0, math.pi / 2)]))
    r2.step(obs(4, walls=WALL, inbox=[msg(1, 3, trouble=True)]))
    assert r2.mode == "own_goal"


def test_in_trouble_with_nobody_in_sight_returns_to_the_last_helper_and_waits(monkeypatch):
    """``trouble_return``: R1 saw R2 (not in trouble) 2 m behind it; trapped later with nobody in
    sight, it walks back there (Pr stays at its bound), waits ``trouble_wait_steps``, then drives
    with A again."""
    r1 = _trapped(monkeypatch, cr=50, trouble_return=True, trouble_wait_steps=5)
    # step 0-1: R2 seen at (-2, 0) (behind), its Tr bit (false) arrives at step 1
    r1.step(obs(0, walls=WALL, seen=[(1, 2.0, math.pi)]))
    r1.step(obs(1, walls=WALL, seen=[(1, 2.0, math.pi)], inbox=[msg(1, 0, trouble=False)]))
    assert r1.mode == "own_goal" and not r1.trouble.tr
    k = 2
    while not r1.trouble.tr:
        r1.step(obs(k, walls=WALL))
        k += 1
    pr = r1.trouble.pr
    a, _ = r1.step(obs(k, walls=WALL))
    assert r1.mode == "trouble_return" and a.direction_rad == pytest.approx(math.pi)
    assert r1.trouble.tr and r1.trouble.pr == pr
    # there (within 2 radii + a step): it stays, then after 5 steps A takes over
    waits = []
    for j in range(1, 8):
        a, _ = r1.step(obs(k + j, pose=(-1.5, 0.0, 0.0), walls=WALL))
        waits.append((r1.mode, a.direction_rad))
    assert waits[:5] == [("trouble_return", None)] * 5
    assert waits[-1][0] == "own_goal" and waits[-1][1] == pytest.approx(math.atan2(0.0, 7.5))


def test_alone_r1_never_returns_anywhere(monkeypatch):
    """The potential field alone stays trapped (§6): with no teammate ever seen there is no point
    to return to, so R1 in trouble keeps driving with A."""
    r1 = _trapped(monkeypatch, trouble_return=True, trouble_sighting_at_send=True)
    for k in range(20):
        a, _ = r1.step(obs(k, walls=WALL))
    assert r1.trouble.tr and r1.mode == "own_goal" and a.direction_rad == pytest.approx(0.0)


def test_return_without_waiting_hands_back_to_a_and_can_count_as_progress(monkeypatch):
    """``trouble_wait_steps=0``: at the point, nobody in sight, A drives again at once;
    ``trouble_return_progress``: closing in on the point lowers Pr (§5: progress towards G_icurr)."""
    r1 = _trapped(monkeypatch, cr=50, trouble_return=True, trouble_wait_steps=0, trouble_return_progress=True)
    r1.step(obs(0, walls=WALL, seen=[(1, 4.0, math.pi)]))
    r1.step(obs(1, walls=WALL, seen=[(1, 4.0, math.pi)], inbox=[msg(1, 0, trouble=False)]))
    k = 2
    while not r1.trouble.tr:
        r1.step(obs(k, walls=WALL))
        k += 1
    pr = r1.trouble.pr
    x = 0.0
    for j in range(5):
        a, _ = r1.step(obs(k + j, pose=(x, 0.0, 0.0), walls=WALL))
        assert r1.mode == "trouble_return" and a.direction_rad == pytest.approx(math.pi)
        x -= 0.2
    assert r1.trouble.tr and r1.trouble.pr < pr
    a, _ = r1.step(obs(k + 5, pose=(-3.6, 0.0, 0.0), walls=WALL))  # there: A again, the point forgotten
    assert r1.mode == "own_goal" and a.direction_rad == pytest.approx(0.0)
    a, _ = r1.step(obs(k + 6, pose=(-3.4, 0.0, 0.0), walls=WALL))
    assert r1.mode == "own_goal"


def _r1_in_trouble_behind_a_wall(monkeypatch, **params):
    """R1 (goal 6 m ahead, behind ``WALL``, its navigator stuck) after 3 steps: in trouble."""
    stuck = StraightNav(stuck=True)
    monkeypatch.setattr(brain_mod, "make_navigator", lambda *a, **k: stuck)
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[(6.0, 0.0)], trouble_cr=3, goal_sharing=False, **params),
                     np.random.default_rng(0), info(0, 2))
    for k in range(3):
        r1.step(obs(k, walls=WALL))
    assert r1.trouble.tr
    return r1


@pytest.mark.parametrize("release", [False, True])
def test_released_by_a_helper_walking_away_goes_on_to_where_it_was_seen(monkeypatch, release):
    """``trouble_release_to_helper``: R1 (goal 6 m ahead, behind a wall) follows R2, which then
    walks away from R1's goal (6.7 m -> 9.5 m, beyond ``trouble_recede_m``) and is let go
    (``trouble_helper_towards_goal``); with the flag R1 heads on to R2's last seen position
    (-3, 3) until it is there, then A drives; without it A drives at once."""
    r1 = _r1_in_trouble_behind_a_wall(monkeypatch, trouble_release_to_helper=release)
    r1.step(obs(3, walls=WALL, seen=[(1, 3.0, math.pi / 2)]))
    a, _ = r1.step(obs(4, walls=WALL, seen=[(1, 3.0, math.pi / 2)], inbox=[msg(1, 3, trouble=False)]))
    assert r1.mode == "trouble_follow" and a.direction_rad == pytest.approx(math.pi / 2)
    # R2 walks away from the goal to (-3, 3): let go
    a, _ = r1.step(obs(5, walls=WALL, seen=[(1, 3.0 * math.sqrt(2), 3 * math.pi / 4)],
                       inbox=[msg(1, 4, trouble=False)]))
    seq = [(r1.mode, a.direction_rad)]
    for k, x in ((6, -0.2), (7, -0.4)):  # R2 out of sight
        a, _ = r1.step(obs(k, pose=(x, 0.2 * (k - 5), 0.0), walls=WALL))
        seq.append((r1.mode, a.direction_rad))
    if release:
        assert [m for m, _ in seq] == ["trouble_follow"] * 3
        assert seq[0][1] == pytest.approx(3 * math.pi / 4)
        assert seq[2][1] == pytest.approx(math.atan2(3.0 - 0.4, -3.0 + 0.4))
        # there: the point is forgotten and A drives again
        a, _ = r1.step(obs(8, pose=(-2.8, 2.8, 0.0), walls=WALL))
        assert r1.mode == "own_goal" and r1._release_xy is None
    else:
        assert [m for m, _ in seq] == ["own_goal"] * 3
        assert seq[0][1] == pytest.approx(0.0)


@pytest.mark.parametrize("near_m", [None, 1.5])
def test_close_behind_a_helper_at_its_own_speed_counts_as_progress(monkeypatch, near_m):
    """``trouble_near_helper_m``: R1 in trouble follows R2, which walks 1 m ahead of it at R1's
    own speed; by the paper's rule (distance to G_icurr = R2 falling) Pr never falls, with the
    gap fill it does."""
    r1 = _r1_in_trouble_behind_a_wall(monkeypatch, trouble_near_helper_m=near_m)
    r1.step(obs(3, walls=WALL, seen=[(1, 1.0, math.pi / 2)]))
    r1.step(obs(4, walls=WALL, seen=[(1, 1.0, math.pi / 2)], inbox=[msg(1, 3, trouble=False)]))
    assert r1.mode == "trouble_follow"
    pr = r1.trouble.pr
    modes = []
    for k in range(5, 10):
        y = 0.2 * (k - 4)
        r1.step(obs(k, pose=(0.0, y, 0.0), walls=WALL, seen=[(1, 1.0, math.pi / 2)],
                    inbox=[msg(1, k - 1, trouble=False)]))
        modes.append(r1.mode)
    if near_m is None:
        assert modes == ["trouble_follow"] * 5 and r1.trouble.tr and r1.trouble.pr >= pr
    else:
        # Pr falls to 0: out of trouble, A drives again (§5 rule 1; trapped again later)
        assert modes[0] == "trouble_follow" and "own_goal" in modes


@pytest.mark.parametrize("drop", [False, True])
def test_a_kept_helper_position_r1_cannot_close_in_on_is_dropped_after_cr_steps(monkeypatch, drop):
    """``trouble_drop_stalled_helper``: R1 in trouble follows R2 seen 3 m to its left; R2 goes out of
    sight and R1, pinned (its pose never changes), makes no progress towards R2's last seen
    position: after ``trouble_drop_after_steps`` such steps the position is dropped and A drives again.
    Without the gap fill the point is kept for as long as R1 is in trouble (§5's two ends only)."""
    r1 = _trapped(monkeypatch, cr=5, trouble_drop_stalled_helper=drop, trouble_drop_after_steps=5)
    k = 0
    while not r1.trouble.tr:
        r1.step(obs(k, walls=WALL))
        k += 1
    r1.step(obs(k, walls=WALL, seen=[(1, 3.0, math.pi / 2)]))
    a, _ = r1.step(obs(k + 1, walls=WALL, seen=[(1, 3.0, math.pi / 2)], inbox=[msg(1, k, trouble=False)]))
    assert r1.mode == "trouble_follow" and a.direction_rad == pytest.approx(math.pi / 2)
    modes = []
    for j in range(2, 14):  # R2 out of sight from now on, R1 does not move
        a, _ = r1.step(obs(k + j, walls=WALL))
        modes.append(r1.mode)
    assert r1.trouble.tr  # still in trouble: §5's own end never came
    if drop:
        first = modes.index("own_goal")
        assert 4 <= first <= 6 and set(modes[first:]) == {"own_goal"}
        assert r1.trouble_helpers_dropped == 1 and a.direction_rad == pytest.approx(0.0)
    else:
        assert set(modes) == {"trouble_follow"} and r1.trouble_helpers_dropped == 0
