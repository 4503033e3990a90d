"""trail-share-v1 in lanes: the crumbs a robot follows lie in the other lane.

Robots keep to the left lane of the trail office's 1.8 m corridors (the trail brains'
``box_reach_m``), so the goal crumbs an outbound robot follows were dropped by robots coming back,
about 1 m across the corridor. Where the robot's wall follower swings it into a passing place, its
look-ahead point moves more than 2 m from those crumbs; the 3 m neighbourhood (``radius_m``,
trail_share's module docstring) still finds them ahead, the old 2 m found none and the robot turned
back towards the nearest crumb beside it."""

from __future__ import annotations

import math

import pytest

from _trail_brain_fakes import make_brains, make_obs


def _swerved(monkeypatch, **params):
    """Source crumbs along the other lane (y = 0, x = 0..10, time to the source falling with x);
    the robot in its own lane swerves into a passing place: at (3, 1.4) heading 70 deg."""
    from teamnav.papers.trails.brains import trail_share as TS

    (b,) = make_brains(monkeypatch, TS, TS.TrailShare, 1, round=["home", "source"], lookahead_m=1.0,
                       broadcast_interval_s=600.0, **params)
    b.step(make_obs(0, 0, [-50.0, 0.0, 0.0]))
    xs = [float(x) for x in range(11)]
    b.trail.add_crumbs(["source"] * len(xs), [[x, 0.0] for x in xs], [30.0 - x for x in xs], [0.0] * len(xs))
    b.step(make_obs(0, 1, [3.0, 1.4, math.radians(70.0)]))
    return b


def test_the_default_neighbourhood_reaches_the_other_lane_and_points_on_along_it(monkeypatch):
    b = _swerved(monkeypatch)
    assert b.params.radius_m == 4.0
    hint = b.nav.headings[-1]
    assert b.log()["following"] is True
    # towards (6, 0), the lowest time-to-place within 4 m of the look-ahead point (3.34, 2.34)
    assert hint == pytest.approx(math.atan2(-1.4, 3.0))


def test_a_three_metre_neighbourhood_reaches_the_other_lane_too(monkeypatch):
    b = _swerved(monkeypatch, radius_m=3.0)
    assert b.log()["following"] is True
    # towards (5, 0), the lowest time-to-place within 3 m of the look-ahead point (3.34, 2.34)
    assert b.nav.headings[-1] == pytest.approx(math.atan2(-1.4, 2.0))


def test_a_two_metre_neighbourhood_loses_the_trail_there(monkeypatch):
    b = _swerved(monkeypatch, radius_m=2.0)
    hint = b.nav.headings[-1]
    assert b.log()["following"] is False
    assert hint is None or math.cos(hint) <= 1e-9  # nothing ahead: recovery to the crumb beside it
