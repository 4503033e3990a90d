"""The line-of-sight help speed-ups (H7a) give the same bits as the numpy code they replace.

Each fast path (numba kernels, scalar paths, Avoid-Past's dense visit grid) is compared with
the numpy version it replaced — kept as ``_*_numpy`` in its module, or written out here where
it was inline in a brain — on random inputs, bit for bit (``==`` on floats, not approx): the
los-help runs must not move (``benchmarks/los_fingerprint.py`` checks whole runs).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.papers.los_help.brains.goal_sharing import beam_near_reaches, max_beam_gap, point_visible
from teamnav.control.nav.local import base
from teamnav.control.nav.local.avoid_past import AvoidPast, AvoidPastParams, avoid_past_vector
from teamnav.control.nav.local.potential_field import (
    PotentialFieldParams,
    _field_vector_numpy,
    field_vector,
)
from teamnav.control.types import RangeScan
from teamnav.geometry.angles import wrap_angle

FAST = settings(max_examples=40, deadline=None)
coord = st.floats(-30.0, 30.0, allow_nan=False)
angle = st.floats(-20.0, 20.0, allow_nan=False)
seeds = st.integers(0, 2**32 - 1)


def _bits(a) -> np.ndarray:
    return np.asarray(a, dtype=np.float64).view(np.int64)


def _scan(rng: np.random.Generator, n: int = 72, max_range_m: float = 8.0, fov_deg: float = 360.0) -> RangeScan:
    """A scan with walls (random returns), some beams without a return, some ties."""
    fov = math.radians(fov_deg)
    angles = (np.linspace(-math.pi, math.pi, n, endpoint=False) if fov_deg >= 360.0
              else np.linspace(-fov / 2, fov / 2, n))
    r = rng.uniform(0.05, max_range_m, n)
    r[rng.random(n) < 0.3] = max_range_m
    r[1::7] = r[0]  # equal readings
    return RangeScan(r, angles, max_range_m)


# ------------------------------------------------------------------ scalar helpers
@given(st.floats(-1e6, 1e6, allow_nan=False) | st.floats(-10.0, 10.0) | st.sampled_from(
    [0.0, -0.0, math.pi, -math.pi, 2 * math.pi, -2 * math.pi, 3 * math.pi, -3 * math.pi, -1e-300, 1e-17, -1e-17,
     math.pi + 1e-16, -math.pi - 1e-16, math.nextafter(-math.pi, 0.0), math.nextafter(math.pi, 4.0), math.inf,
     -math.inf, math.nan]))
@FAST
def test_pymod_and_wrap_scalar_equal_numpy(a):
    with np.errstate(invalid="ignore"):
        want_mod, want_wrap = np.mod(a, 2 * math.pi), float(wrap_angle(a))
    got_mod, got_wrap = base.pymod(a, 2 * math.pi), base.wrap_scalar(a)
    if math.isnan(want_wrap):
        assert math.isnan(got_wrap) and math.isnan(got_mod) == math.isnan(want_mod)
    else:
        assert _bits(got_mod) == _bits(want_mod)
        assert _bits(got_wrap) == _bits(want_wrap)


# ------------------------------------------------------------------ visibility (goal_sharing, brain)
def _point_visible_numpy(point_body_xy, ranges_m, angles_rad, radius_m, margin_m=0.0, max_gap_rad=None):
    """goal_sharing.point_visible as it was at f9d6cb5."""
    x, y = float(point_body_xy[0]), float(point_body_xy[1])
    d = math.hypot(x, y)
    if d > radius_m:
        return False
    if d < 1e-9:
        return True
    b = math.atan2(y, x)
    diff = np.abs(np.mod(np.asarray(angles_rad, dtype=np.float64) - b + math.pi, 2 * math.pi) - math.pi)
    i = int(np.argmin(diff))
    if max_gap_rad is None:
        max_gap_rad = max_beam_gap(np.asarray(angles_rad, dtype=np.float64))
    if diff[i] > max_gap_rad:
        return False
    return bool(ranges_m[i] >= d - margin_m)


def _keeps_numpy(scan: RangeScan, bx: float, by: float, gap_rad: float, vis_radius_m: float) -> bool:
    """_LosBrain._keeps as it was at f9d6cb5 (body-frame point)."""
    d = math.hypot(bx, by)
    if d > vis_radius_m:
        return False
    if d < 1e-9:
        return True
    angles = np.asarray(scan.angles_rad, dtype=np.float64)
    diff = np.abs(np.mod(angles - math.atan2(by, bx) + math.pi, 2 * math.pi) - math.pi)
    near = diff <= 1.5 * max(gap_rad, 1e-6)
    return bool(near.any() and np.any(np.asarray(scan.ranges_m)[near] >= d))


@given(seeds, st.floats(-9.0, 9.0), st.floats(-9.0, 9.0), st.sampled_from([0.0, 0.4, 0.8]),
       st.sampled_from([(72, 360.0), (181, 180.0), (8, 360.0), (1, 360.0)]))
@FAST
def test_point_visible_and_keep_view_equal_numpy(seed, x, y, margin, layout):
    rng = np.random.default_rng(seed)
    scan = _scan(rng, *layout[:1], fov_deg=layout[1])
    # points exactly on a beam's bearing and at a beam's range too (ties)
    a = np.asarray(scan.angles_rad)
    mid = 0.5 * (a[0] + a[1]) if a.size > 1 else a[0]  # half way between two beams: a tie
    r0 = float(scan.ranges_m[0])
    for px, py in ((x, y), (r0 * math.cos(a[0]), r0 * math.sin(a[0])), (r0 * math.cos(mid), r0 * math.sin(mid))):
        assert point_visible((px, py), scan.ranges_m, scan.angles_rad, 8.0, margin) == \
            _point_visible_numpy((px, py), scan.ranges_m, scan.angles_rad, 8.0, margin)
        gap = max_beam_gap(np.asarray(scan.angles_rad))
        d, b = math.hypot(px, py), math.atan2(py, px)
        if 1e-9 <= d <= 8.0:
            assert beam_near_reaches(scan.ranges_m, scan.angles_rad, d, b, 1.5 * max(gap, 1e-6)) == \
                _keeps_numpy(scan, px, py, gap, 8.0)


def _corridor_clear_numpy(scan: RangeScan, theta: float, heading: float, length: float, radius: float) -> bool:
    """_LosBrain._corridor_clear as it was at f9d6cb5 (after the visibility-radius check)."""
    r = np.asarray(scan.ranges_m, dtype=np.float64)
    hit = r < float(scan.max_range_m) * (1.0 - 1e-9)
    if not hit.any():
        return True
    rel = np.asarray(scan.angles_rad, dtype=np.float64)[hit] + (theta - heading)
    along = r[hit] * np.cos(rel)
    across = np.abs(r[hit] * np.sin(rel))
    t = np.clip(along, 0.0, length)
    return bool(np.hypot(along - t, across).min() >= radius * 1.05)


@given(seeds, angle, angle, st.floats(0.2, 8.0), st.sampled_from([0.2, 0.25, 0.5]))
@FAST
def test_corridor_clear_equals_numpy(seed, theta, heading, length, radius):
    rng = np.random.default_rng(seed)
    scan = _scan(rng)
    if seed % 5 == 0:
        scan = RangeScan(np.full(72, 8.0), scan.angles_rad, 8.0)  # nothing sensed
    assert base.corridor_clear(scan.ranges_m, scan.angles_rad, 8.0, theta, heading, length, radius * 1.05) == \
        _corridor_clear_numpy(scan, theta, heading, length, radius)


# ------------------------------------------------------------------ navigators' geometry (base.py)
@given(seeds, coord, coord, angle)
@FAST
def test_scan_points_equal_numpy(seed, x, y, th):
    scan = _scan(np.random.default_rng(seed))
    pose = np.array([x, y, th])
    assert np.array_equal(_bits(base.scan_points(pose, scan)), _bits(base._scan_points_numpy(pose, scan)))


@given(seeds, st.integers(0, 40), st.integers(1, 30), st.booleans(), st.booleans())
@FAST
def test_segment_clearance_equals_numpy(seed, k, j, per_segment_start, slack):
    rng = np.random.default_rng(seed)
    pts = rng.uniform(-5, 5, (k, 2))
    ends = rng.uniform(-5, 5, (j, 2))
    ends[0] = ends[-1]
    start = rng.uniform(-5, 5, (j, 2)) if per_segment_start else rng.uniform(-5, 5, 2)
    if per_segment_start:
        start[0] = ends[0]  # a zero-length segment
    s = rng.uniform(0, 0.3, k) if slack else None
    got = base.segment_clearance(pts, start, ends, s)
    want = base._segment_clearance_numpy(pts, start, ends, s)
    assert np.array_equal(_bits(got), _bits(want))


@given(seeds, angle, st.sampled_from([0.1, 0.2]), st.sampled_from([0.23, 0.28, 0.6]), st.floats(0.0, 1.0))
@FAST
def test_safe_heading_equals_numpy(seed, heading, step, clearance, spread):
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-3, 3, 2)
    # points around the robot, some close enough to block steps (and sometimes every step)
    pts = xy + rng.uniform(-spread - 0.2, spread + 0.2, (int(rng.integers(0, 60)), 2))
    got = base.safe_heading(heading, xy, pts, step, clearance)
    assert _bits(got) == _bits(base._safe_heading_numpy(heading, xy, pts, step, clearance))


@given(seeds, coord, coord, angle, st.integers(0, 72))
@FAST
def test_field_vector_equals_numpy(seed, gx, gy, th, k):
    rng = np.random.default_rng(seed)
    pose = np.array([rng.uniform(-3, 3), rng.uniform(-3, 3), th])
    pts = pose[:2] + rng.uniform(-2, 2, (k, 2))
    if k:
        pts[0] = pose[:2]  # a point at the robot's centre (d = 0)
    params = PotentialFieldParams()
    got = field_vector(pose, np.array([gx, gy]), pts, 72, params, 0.2)
    want = _field_vector_numpy(pose, np.array([gx, gy]), pts, 72, params, 0.2)
    assert np.array_equal(_bits(got), _bits(want))


@given(seeds, st.sampled_from([0.1, 0.2]))
@settings(max_examples=15, deadline=None)
def test_avoid_past_visit_grid_gives_the_dictionary_walks_vector(seed, step):
    """A random walk (with jumps, so the grid grows in every direction, and goal changes that
    reset the memory): each step's vector equals the potential field's plus avoid_past_vector
    over the visits dictionary."""
    rng = np.random.default_rng(seed)
    p = AvoidPastParams(memory_scope="goal", memory_half_life_steps=None)  # the resets exercise the mirror's rebuild
    nav = AvoidPast(p, np.random.default_rng(0), step, 0.2)
    nav.set_goal(np.array([5.0, 5.0]))
    pose = np.array([0.0, 0.0, 0.0])
    for i in range(120):
        pose = pose + np.array([*rng.normal(0, step, 2), 0.0])
        if i % 40 == 39:
            pose[:2] += rng.uniform(-30, 30, 2)
        if i % 50 == 49:  # a new own goal (memory_scope="goal"): a fresh memory, the mirror rebuilt
            nav.set_goal(np.array([5.0, 5.0 + i]))
            assert nav.visits == {}
        elif i % 50 == 25:  # an excursion and back keep the memory
            n_visited = len(nav.visits)
            nav.set_goal(np.array([-3.0, 1.0]), temporary=True)
            nav.set_goal(np.array([5.0, 5.0 + 49 * (i // 50)]) if i > 50 else np.array([5.0, 5.0]))
            assert len(nav.visits) == n_visited > 0
        pts = pose[:2] + rng.uniform(-2, 2, (5, 2))
        got = nav._vector(pose, pts, 72)
        want = field_vector(pose, nav.goal_xy, pts, 72, p, 0.2) + avoid_past_vector(
            pose[:2], nav.visits, p.cell_m, p.memory_radius_m, p.avoid_gain_per_m, p.avoid_max)
        assert np.array_equal(_bits(got), _bits(want))
    nav.visits = dict(nav.visits)  # replaced behind its back: the mirror is rebuilt
    got = nav._vector(pose, pts, 72)
    want = field_vector(pose, nav.goal_xy, pts, 72, p, 0.2) + avoid_past_vector(
        pose[:2], nav.visits, p.cell_m, p.memory_radius_m, p.avoid_gain_per_m, p.avoid_max)
    assert np.array_equal(_bits(got), _bits(want))


def test_point_visible_of_an_empty_scan_still_raises():
    with pytest.raises(ValueError, match="empty sequence"):
        point_visible((1.0, 0.0), np.zeros(0), np.zeros(0), 8.0)


@given(seeds, coord, coord, angle, st.booleans(), st.sampled_from(["nearer_end", "left"]))
@FAST
def test_visbug_followed_equals_numpy(seed, x, y, th, with_ref, turn):
    """VisBug-21's obstacle cut (the followed points, the reference point it keeps and the
    sensed ends of ``turn="nearer_end"``) from the kernel and from the numpy version."""
    from teamnav.control.nav.local.visbug21 import VisBug21, VisBugParams

    rng = np.random.default_rng(seed)
    scan = _scan(rng, n=int(rng.choice([8, 36, 72])))
    if seed % 7 == 0:  # a closed room seen all round: no ends
        scan = RangeScan(np.full(len(scan.ranges_m), 2.0), scan.angles_rad, 8.0)
    if seed % 11 == 0:  # nothing sensed
        scan = RangeScan(np.full(len(scan.ranges_m), 8.0), scan.angles_rad, 8.0)
    pose = np.array([x, y, th])
    navs = [VisBug21(VisBugParams(turn=turn), np.random.default_rng(0), 0.2, 0.2) for _ in range(2)]
    for nav in navs:
        nav._follow_ref = pose[:2] + rng.uniform(-3, 3, 2) if with_ref else None
        nav._ends = "unset"
    navs[1]._follow_ref = None if navs[0]._follow_ref is None else navs[0]._follow_ref.copy()
    got, want = navs[0]._followed(pose, scan), navs[1]._followed_numpy(pose, scan)
    assert np.array_equal(_bits(got), _bits(want))
    a, b = navs[0]._follow_ref, navs[1]._follow_ref
    assert (a is None and b is None) or np.array_equal(_bits(a), _bits(b))
    a, b = navs[0]._ends, navs[1]._ends
    if isinstance(b, tuple):
        assert all(np.array_equal(_bits(u), _bits(v)) for u, v in zip(a, b))
    else:
        assert a == b


def _libm():
    """The C maths library's hypot, atan2 and atan (what numba's math.* calls compile to)."""
    import ctypes
    import ctypes.util
    import types

    lib = ctypes.CDLL(ctypes.util.find_library("m"))
    fns = {}
    for name, nargs in (("hypot", 2), ("atan2", 2), ("atan", 1)):
        f = getattr(lib, name)
        f.restype, f.argtypes = ctypes.c_double, [ctypes.c_double] * nargs
        fns[name] = f
    return types.SimpleNamespace(**fns)


_LIBM = _libm()


@given(seeds, st.integers(0, 12), st.sampled_from([0.0, 0.1, 0.4]))
@FAST
def test_detector_range_bearing_and_occlusion_noise_equal_libm(seed, m, err_max):
    """The detector's kernels (Sgorbissa & Arkin eqs. 1-2) against the numpy lines they replaced,
    with libm's scalar functions where NumPy now has its own."""
    from teamnav.sim.sensors.detector import _occlusion_noise, _range_bearing, _wrap

    rng = np.random.default_rng(seed)
    n = 5
    xs, ys = rng.uniform(-10, 10, n), rng.uniform(-10, 10, n)
    thetas = rng.uniform(-math.pi, math.pi, n)
    thetas[0] = math.pi
    a = rng.integers(0, n, m)
    b = (a + rng.integers(1, n, m)) % n
    b[: m // 3] = a[: m // 3]  # a zero range (d_r = 0: the half angle is pi/2)
    dx, dy = xs[b] - xs[a], ys[b] - ys[a]
    # libm's hypot/atan2/atan element by element, as the kernels call them: NumPy >= 2.4 has
    # its own SIMD versions and Python's math.hypot its own algorithm, either may differ from
    # libm in the last bit
    want_r = np.array([_LIBM.hypot(p, q) for p, q in zip(dx, dy)])
    want_b = _wrap(np.array([_LIBM.atan2(q, p) for p, q in zip(dx, dy)]) - thetas[a]) if m else np.empty(0)
    got_r, got_b = _range_bearing(xs, ys, thetas, a, b)
    assert np.array_equal(_bits(got_r), _bits(want_r)) and np.array_equal(_bits(got_b), _bits(want_b))
    u = rng.random((2, m))
    size = np.full(m, 0.4)
    with np.errstate(divide="ignore"):
        half = np.array([_LIBM.atan(t) for t in size / (2.0 * want_r)])
    want_d = want_r + want_r * (err_max * (2.0 * u[0] - 1.0))
    want_a = want_b + half * (2.0 * u[1] - 1.0)
    want_a = _wrap(want_a) if m else want_a
    got_d, got_a = _occlusion_noise(want_r, want_b, size, u[0], u[1], err_max)
    assert np.array_equal(_bits(got_d), _bits(want_d)) and np.array_equal(_bits(got_a), _bits(want_a))


@given(seeds, st.integers(0, 40), st.integers(1, 30), st.floats(0.0, 1.0), st.booleans())
@FAST
def test_segment_clear_is_segment_clearance_at_least(seed, k, j, lim, slack):
    rng = np.random.default_rng(seed)
    pts = rng.uniform(-3, 3, (k, 2))
    ends = rng.uniform(-3, 3, (j, 2))
    start = rng.uniform(-3, 3, (j, 2)) if seed % 2 else rng.uniform(-3, 3, 2)
    s = rng.uniform(0, 0.3, k) if slack else None
    assert np.array_equal(base.segment_clear(pts, start, ends, lim, s),
                          base._segment_clearance_numpy(pts, start, ends, s) >= lim)


def _boundary_heading_numpy(xy, points, follow_distance_m, side, gain):
    """visbug21.boundary_heading as it was at f9d6cb5."""
    if points.shape[0] == 0:
        return None
    rel = points - xy
    d2 = np.einsum("ij,ij->i", rel, rel)
    i = int(np.argmin(d2))
    d = math.sqrt(d2[i])
    err = max(-1.0, min(1.0, (follow_distance_m - d) / follow_distance_m))
    corr = max(-math.pi / 3, min(math.pi / 3, gain * err))
    return math.atan2(rel[i, 1], rel[i, 0]) + side * (0.5 * math.pi + corr)


@given(seeds, st.integers(1, 50), st.sampled_from([1, -1]))
@FAST
def test_boundary_heading_equals_numpy(seed, k, side):
    from teamnav.control.nav.local.visbug21 import boundary_heading

    rng = np.random.default_rng(seed)
    xy = rng.uniform(-3, 3, 2)
    pts = xy + rng.uniform(-2, 2, (k, 2))
    pts[k // 2] = pts[0]  # equal distances: the first one
    assert _bits(boundary_heading(xy, pts, 0.4, side, 1.5)) == _bits(_boundary_heading_numpy(xy, pts, 0.4, side, 1.5))


@given(seeds, coord, coord, angle, st.sampled_from([1, -1]), st.sampled_from([0.2, 0.25]),
       st.sampled_from([0.33, 0.45]), st.sampled_from([2.0, 7.75]), st.sampled_from(["followed", "wall", "ties"]))
@settings(max_examples=80, deadline=None)
def test_visbug_boundary_target_equals_numpy(seed, x, y, th, side, r_safe, follow_m, reach_m, kind):
    """Step 2's boundary target (``boundary_shortcut``, the paper-rules VisBug-21)
    from ``_boundary_pick`` and from the numpy version it replaced (kept as
    ``_boundary_target_numpy``), bit for bit: on the followed points of random scans, on a
    straight wall, and on points with repeated positions and equal bearings (ties in the
    stable ordering, zero-length chords)."""
    from teamnav.control.nav.local.visbug21 import VisBug21, VisBugParams

    rng = np.random.default_rng(seed)
    scan = _scan(rng, n=int(rng.choice([8, 36, 72])))
    pose = np.array([x, y, th])
    nav = VisBug21(VisBugParams(turn="left", boundary_shortcut=True), np.random.default_rng(0), 0.2, 0.2)
    nav.side, nav._slack = side, math.pi / len(scan.ranges_m)
    points = base.scan_points(pose, scan)
    if kind == "followed":
        nav._follow_ref, nav._ends = None, "unset"
        followed = nav._followed(pose, scan)
    elif kind == "wall":
        n = int(rng.integers(3, 60))
        followed = np.column_stack((np.linspace(-3.0, 3.0, n) + x, np.full(n, y + rng.uniform(-1.0, 1.0))))
    else:
        base_pts = pose[:2] + rng.uniform(-3.0, 3.0, (int(rng.integers(2, 6)), 2))
        followed = base_pts[rng.integers(0, len(base_pts), int(rng.integers(3, 20)))]
        followed = np.concatenate((followed, pose[:2] + 2.0 * (followed - pose[:2])))  # equal bearings
    got = nav._boundary_target(pose[:2].copy(), followed, points, r_safe, follow_m, reach_m)
    want = nav._boundary_target_numpy(pose[:2].copy(), followed, points, r_safe, follow_m, reach_m)
    assert (got is None) == (want is None)
    if want is not None:
        assert np.array_equal(_bits(got), _bits(want))
