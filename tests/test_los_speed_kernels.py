"""The line-of-sight help speed-ups of 2026-11-27 (4234b5f) give the same answers, bit for bit, as the
Python / numpy code they replace (as ``tests/test_los_speed_equivalence.py`` does for H7a).

Each new kernel or rewritten path is compared with its reference on hypothesis inputs; whole
runs are checked by ``benchmarks/los_fingerprint.py``.
"""

from __future__ import annotations

import math
from dataclasses import FrozenInstanceError, replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.control.nav.local import base

FAST = settings(max_examples=60, deadline=None)
seeds = st.integers(0, 2**32 - 1)
TWO_PI = 2.0 * math.pi


def _bits(x: float) -> int:
    return int(np.float64(x).view(np.int64))


# ------------------------------------------------------------------ mod 2π without fmod
_EDGES = [0.0, -0.0, TWO_PI, -TWO_PI, 2 * TWO_PI, -2 * TWO_PI, math.pi, -math.pi, 3 * math.pi,
          math.nextafter(TWO_PI, 0.0), math.nextafter(TWO_PI, 10.0), math.nextafter(2 * TWO_PI, 0.0),
          math.nextafter(2 * TWO_PI, 20.0), math.nextafter(-TWO_PI, 0.0), math.nextafter(-TWO_PI, -10.0),
          5e-324, -5e-324, 1e-300, -1e-300, 1e-17, -1e-17, math.inf, -math.inf, math.nan, 1e300, -1e300]


@given(st.floats(allow_nan=True, allow_infinity=True) | st.floats(-20.0, 20.0) | st.sampled_from(_EDGES)
       | st.sampled_from(_EDGES).map(lambda e: e + math.pi))
@settings(max_examples=400, deadline=None)
def test_mod_two_pi_is_pymod(x):
    """``mod_two_pi`` (the beam tests' angular distance) is ``pymod(x, 2π)`` bit for bit, zeros,
    the range bounds, NaN and infinities included (``np.mod`` is pinned against ``pymod``)."""
    got, want = base.mod_two_pi(x), base.pymod(x, TWO_PI)
    if math.isnan(want):
        assert math.isnan(got)
    else:
        assert _bits(got) == _bits(want)


def test_mod_two_pi_is_pymod_on_a_million_angles():
    from numba import njit

    @njit
    def both(x):
        a = np.empty_like(x)
        b = np.empty_like(x)
        for i in range(x.size):
            a[i] = base.mod_two_pi(x[i])
            b[i] = base.pymod(x[i], 2.0 * math.pi)
        return a, b

    rng = np.random.default_rng(21)
    x = rng.uniform(-3 * TWO_PI, 5 * TWO_PI, 1_000_000)
    a, b = both(np.concatenate([x, x + math.pi, np.array(_EDGES)]))
    same = (a.view(np.int64) == b.view(np.int64)) | (np.isnan(a) & np.isnan(b))
    assert same.all()


# ------------------------------------------------------------------ VisBug-21 Step 1: Ti
@given(seeds, st.integers(0, 60), st.integers(1, 120), st.sampled_from([0.25, 0.28, 0.5]),
       st.sampled_from([7.75, 3.0, 0.5]))
@FAST
def test_last_visible_is_the_last_of_visible(seed, k, j, r_safe, reach):
    """``_last_visible`` is the index of the last candidate ``VisBug21._visible`` finds visible
    (the numpy + ``segment_clear`` test of every candidate it replaced in
    ``_intermediate_target``), or -1."""
    from teamnav.control.nav.local.visbug21 import VisBug21, VisBugParams
    from teamnav.control.nav.local.visbug21_geometry import _last_visible

    rng = np.random.default_rng(seed)
    xy = rng.uniform(-5, 5, 2)
    pts = xy + rng.uniform(-9, 9, (k, 2))
    if k and seed % 3 == 0:
        pts[: k // 2] = xy + rng.uniform(-0.6, 0.6, (k // 2, 2))  # some close to the robot
    goal = xy + rng.uniform(-12, 12, 2)
    t = np.linspace(0.0, 1.0, j + 1)
    cand = xy + rng.uniform(-0.5, 0.5, 2) + t[:, None] * (goal - xy)
    if seed % 5 == 0:
        cand[0] = xy  # a candidate on the robot (segment of length 0)
    nav = VisBug21(VisBugParams(), np.random.default_rng(0), 0.2, 0.2)
    nav._slack = math.pi / int(rng.choice([8, 36, 72]))
    ok = nav._visible(xy, pts, cand, r_safe, reach)
    want = int(np.flatnonzero(ok)[-1]) if ok.any() else -1
    got = _last_visible(float(xy[0]), float(xy[1]), pts[:, 0], pts[:, 1], cand[:, 0], cand[:, 1], r_safe, reach,
                        nav._slack)
    assert got == want


# ------------------------------------------------------------------ fast dataclass constructors
def test_sharing_records_keep_dataclass_behaviour():
    """The goal-sharing records and message parts built by the slot-descriptor ``__init__``
    (``_fast_frozen_init``) keep their fields, defaults, equality, ``replace`` and frozenness."""
    from teamnav.papers.los_help.brains.goal_sharing import GoalPath, KnownGoal
    from teamnav.papers.los_help.brains.messages import GoalShare, LosHelpMsg, Sighting, VisReport

    p = GoalPath(4, 1.0, 2.0, 0.5, "ghost", 1, 7)
    assert (p.reached, p.d_promised_m, p.via_x_m, p.via_y_m, p.via_d_m) == (False, math.inf, None, None, None)
    assert replace(p, reached=True) == GoalPath(4, 1.0, 2.0, 0.5, "ghost", 1, 7, True)
    assert KnownGoal(1, 8, 0.5, -0.5) == KnownGoal(owner=1, goal_id=8, gx_m=0.5, gy_m=-0.5)
    assert VisReport(1, 8, 2.0) == VisReport(1, 8, 2.0, None, None, None)
    msg = LosHelpMsg(3)
    assert (msg.sightings, msg.goals, msg.reports, msg.trouble) == ((), (), (), None)
    for obj in (p, KnownGoal(1, 8, 0.5, -0.5), Sighting(1, 0.1, 2.0), GoalShare(1, 8, 0.0, 1.0), msg):
        with pytest.raises(FrozenInstanceError):
            obj.__setattr__(type(obj).__dataclass_fields__.__iter__().__next__(), 0)


@given(seeds, st.floats(-5.0, 5.0), st.floats(-5.0, 5.0), st.floats(-4.0, 4.0), st.sampled_from([8, 36, 72]),
       st.floats(0.0, 1.2))
@FAST
def test_leave_point_equals_numpy(seed, x, y, th, n_beams, hit_frac):
    """Step 2's leave test with ``_leave_candidates`` gives the point (bits), the M-line anchor
    and None exactly when the numpy version (``_leave_point_numpy``) does."""
    from teamnav.control.nav.local.visbug21 import MODE_FOLLOW, VisBug21, VisBugParams
    from teamnav.control.types import RangeScan

    rng = np.random.default_rng(seed)
    angles = np.linspace(-math.pi, math.pi, n_beams, endpoint=False)
    r = rng.uniform(0.3, 8.0, n_beams)
    r[rng.random(n_beams) < 0.4] = 8.0
    if seed % 4 == 0:
        r[:] = 8.0  # nothing sensed
    scan = RangeScan(r, angles, 8.0)
    pose = np.array([x, y, th])
    goal = pose[:2] + rng.uniform(-9, 9, 2)
    start = pose[:2] + rng.uniform(-2, 2, 2)
    navs = []
    leave_run = float(rng.choice([0.0, 0.5, 2.0]))
    for _ in range(2):
        nav = VisBug21(VisBugParams(leave_run_m=leave_run),
                       np.random.default_rng(0), 0.2, 0.2)
        nav.goal_xy = goal.copy()
        nav.mline = (start.copy(), goal.copy())
        nav.mode = MODE_FOLLOW
        nav.hit_dist_m = hit_frac * math.hypot(*(goal - start)) + 0.05
        nav._slack = math.pi / n_beams
        navs.append(nav)
    points = base.scan_points(pose, scan)
    r_safe = 0.25 + 0.03
    got = navs[0]._leave_point(pose, scan, points, r_safe, 8.0 - 0.25)
    want = navs[1]._leave_point_numpy(pose, scan, points, r_safe, 8.0 - 0.25)
    assert (got is None) == (want is None)
    if got is not None:
        assert np.array_equal(got.view(np.int64), want.view(np.int64))
    assert _bits(navs[0]._t_anchor) == _bits(navs[1]._t_anchor)


# ------------------------------------------------------------------ the brains' corridor test
@given(seeds, st.floats(-4.0, 4.0), st.floats(-4.0, 4.0), st.floats(0.0, 8.0), st.sampled_from([0.2, 0.21, 0.5]),
       st.sampled_from([0.0, 1e-12, 1e-9, 1e-6, 1e-3]))
@settings(max_examples=150, deadline=None)
def test_corridor_clear_skip_of_far_returns_keeps_the_answer(seed, theta, heading, length, clear, eps):
    """``corridor_clear`` skips returns farther than ``L + min_clear`` (plus a margin): its answer
    is the numpy test's (``_corridor_clear_numpy``, every return) also for returns placed
    right at that distance, on either side of it and at every bearing."""
    rng = np.random.default_rng(seed)
    n = int(rng.choice([8, 72, 181]))
    angles = np.linspace(-math.pi, math.pi, n, endpoint=False)
    edge = length + clear
    r = edge + rng.choice([-1.0, 1.0], n) * eps * rng.uniform(0.0, 2.0, n)
    r[rng.random(n) < 0.3] = rng.uniform(0.05, 8.0)
    r = np.clip(r, 0.0, 8.0)
    got = base.corridor_clear(r, angles, 8.0, theta, heading, length, clear)
    assert got == _corridor_clear_numpy(r, angles, 8.0, theta, heading, length, clear)


def _corridor_clear_numpy(r, angles, max_range_m, theta, heading, length, min_clear):
    """The brains' corridor test as numpy code, every return tested (as in
    ``tests/test_los_speed_equivalence.py``; np.cos/np.sin/np.hypot are libm's here)."""
    hit = r < max_range_m * (1.0 - 1e-9)
    if not hit.any():
        return True
    rel = angles[hit] + (theta - heading)
    along = r[hit] * np.cos(rel)
    across = np.abs(r[hit] * np.sin(rel))
    t = np.clip(along, 0.0, length)
    return bool(np.hypot(along - t, across).min() >= min_clear)
