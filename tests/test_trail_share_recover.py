"""trail-share-v1's recovery gap-fill (``recover_radius_m``, on by default at 4 m): a robot
pushed off the trail (a meeting at a corner sends it down a dead-end branch) heads back to the
nearest goal crumb below its descend-only bound; 0 m gives the paper's exploring."""

from __future__ import annotations

import math

import pytest

from _trail_brain_fakes import make_brains, make_obs


def _brain(monkeypatch, **params):
    from teamnav.papers.trails.brains import trail_share as TS

    (b,) = make_brains(monkeypatch, TS, TS.TrailShare, 1, round=["home", "source"], radius_m=2.0,
                       lookahead_m=1.0, broadcast_interval_s=600.0, **params)
    return b


def _deflected(monkeypatch, x_m, **params):
    """A robot seeking the source went down the trail (source crumbs along y = 0, x = 0..4, time
    to the source falling with x) and on into a branch: at (x_m, 3) heading north, away from it."""
    b = _brain(monkeypatch, **params)
    b.step(make_obs(0, 0, [-50.0, 0.0, 0.0]))
    xs = [0.0, 1.0, 2.0, 3.0, 4.0]
    b.trail.add_crumbs(["source"] * 5, [[x, 0.0] for x in xs], [30.0 - x for x in xs], [0.0] * 5)
    b.step(make_obs(0, 1, [4.0, 0.0, 0.0]))  # on the crumb at x = 4: the bound is set to 26 s
    b.step(make_obs(0, 2, [x_m, 3.0, math.pi / 2]))
    return b


def test_the_default_heads_back_to_the_trail_it_left(monkeypatch):
    b = _deflected(monkeypatch, 4.0)
    assert b.params.recover_radius_m == 4.0
    assert b.nav.headings[-1] == pytest.approx(-math.pi / 2)  # back south to (4, 0), 3 m away
    assert b.log()["recovering"] is True
    assert b.log()["following"] is False


def test_zero_radius_gives_the_papers_exploring(monkeypatch):
    b = _deflected(monkeypatch, 4.0, recover_radius_m=0.0)
    assert b.nav.headings[-1] is None
    assert b.log()["recovering"] is False


def test_no_recovery_beyond_the_radius(monkeypatch):
    b = _deflected(monkeypatch, 8.0)  # nearest crumb (4, 0) is 5 m away
    assert b.nav.headings[-1] is None


def test_recovery_keeps_the_descend_only_bound(monkeypatch):
    """Only crumbs below the bound count: a crumb nearer the robot but higher up the trail than
    one it has reached is not a way back."""
    b = _brain(monkeypatch)
    b.step(make_obs(0, 0, [-50.0, 0.0, 0.0]))
    b.trail.add_crumbs(["source", "source"], [[4.0, 0.0], [0.0, 2.5]], [10.0, 40.0], [0.0, 0.0])
    b.step(make_obs(0, 1, [4.0, 0.0, 0.0]))  # reaches the crumb 10 s from the source
    b.step(make_obs(0, 2, [0.0, 4.5, math.pi / 2]))  # (0, 2.5) 2 m away, (4, 0) 6 m away
    assert b.nav.headings[-1] is None
    b2 = _brain(monkeypatch, descend_only=False)
    b2.step(make_obs(0, 0, [-50.0, 0.0, 0.0]))
    b2.trail.add_crumbs(["source", "source"], [[4.0, 0.0], [0.0, 2.5]], [10.0, 40.0], [0.0, 0.0])
    b2.step(make_obs(0, 1, [4.0, 0.0, 0.0]))
    b2.step(make_obs(0, 2, [0.0, 4.5, math.pi / 2]))
    assert b2.nav.headings[-1] == pytest.approx(-math.pi / 2)

