"""Angles, SE(2), similarity transforms and frames from mutual bearings."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from teamnav.geometry import (
    Similarity,
    angle_diff,
    compose,
    from_matrix,
    inverse,
    mean_angle,
    relative,
    relative_frame_from_bearings,
    similarity_from_two_pairs,
    to_matrix,
    transform_goal,
    transform_points,
    wrap_angle,
)

finite = st.floats(-1e6, 1e6, allow_nan=False)
angle = st.floats(-50.0, 50.0, allow_nan=False)
coord = st.floats(-100.0, 100.0, allow_nan=False)
pose = st.tuples(coord, coord, st.floats(-math.pi, math.pi)).map(np.array)
point = st.tuples(coord, coord).map(np.array)


def _same_angle(a, b, atol=1e-9):
    return np.allclose(np.abs(angle_diff(a, b)), 0.0, atol=atol)


# ---------------------------------------------------------------------------- angles
@given(finite)
def test_wrap_angle_range_idempotence_and_equivalence(a):
    w = wrap_angle(a)
    assert isinstance(w, float)
    assert -math.pi < w <= math.pi
    assert wrap_angle(w) == w
    # same direction: the difference is a multiple of 2*pi (up to rounding at this magnitude)
    k = (a - w) / (2 * math.pi)
    assert abs(k - round(k)) < 1e-9 * max(1.0, abs(a))


@given(arrays(np.float64, st.integers(0, 20), elements=finite))
def test_wrap_angle_arrays(a):
    w = wrap_angle(a)
    assert w.shape == a.shape
    assert np.all((w > -math.pi) & (w <= math.pi))
    np.testing.assert_array_equal(wrap_angle(w), w)
    np.testing.assert_allclose(np.cos(w), np.cos(a), atol=1e-6)
    np.testing.assert_allclose(np.sin(w), np.sin(a), atol=1e-6)


def test_wrap_angle_boundaries():
    assert wrap_angle(math.pi) == math.pi
    assert wrap_angle(-math.pi) == math.pi
    assert wrap_angle(3 * math.pi) == pytest.approx(math.pi)
    assert wrap_angle(-3 * math.pi) == pytest.approx(math.pi)
    assert wrap_angle(-1e-300) == -1e-300  # in range: untouched
    assert wrap_angle(2 * math.pi) == 0.0
    assert math.isnan(wrap_angle(float("nan")))
    np.testing.assert_array_equal(wrap_angle(np.array([-math.pi, math.pi])), [math.pi, math.pi])


@given(angle, angle)
def test_angle_diff_is_smallest_signed_rotation(a, b):
    d = angle_diff(a, b)
    assert -math.pi < d <= math.pi
    assert _same_angle(b + d, a, atol=1e-7)


def test_mean_angle_wraps_across_pi_and_weights():
    assert mean_angle([math.pi - 0.2, -math.pi + 0.2]) == pytest.approx(math.pi)
    assert mean_angle([0.1, -0.1, 0.3]) == pytest.approx(math.atan2(np.sin([0.1, -0.1, 0.3]).sum(), np.cos([0.1, -0.1, 0.3]).sum()))
    assert mean_angle([0.0, math.pi / 2], weights=[1.0, 0.0]) == 0.0
    assert math.isnan(mean_angle([0.0, math.pi]))
    np.testing.assert_allclose(mean_angle([[0.0, 0.2], [1.0, 1.2]], axis=1), [0.1, 1.1])
    with pytest.raises(ValueError, match="weights"):
        mean_angle([0.0, 1.0], weights=[1.0, -1.0])
    with pytest.raises(ValueError, match="empty"):
        mean_angle([])


@given(st.floats(-math.pi, math.pi), st.lists(st.floats(-0.5, 0.5), min_size=1, max_size=10))
def test_mean_angle_of_spread_around_a_direction(centre, offsets):
    offsets = np.array(offsets)
    sym = np.concatenate([offsets, -offsets])  # symmetric spread: mean is exactly the centre
    assert _same_angle(mean_angle(centre + sym), centre, atol=1e-9)


# ---------------------------------------------------------------------------- SE(2)
@given(pose)
def test_compose_with_inverse_is_identity(a):
    np.testing.assert_allclose(compose(a, inverse(a)), 0.0, atol=1e-9)
    np.testing.assert_allclose(compose(inverse(a), a), 0.0, atol=1e-9)
    back = inverse(inverse(a))
    np.testing.assert_allclose(back[:2], a[:2], atol=1e-9)
    assert _same_angle(back[2], a[2])


@given(pose, pose, pose)
def test_compose_is_associative(a, b, c):
    left = compose(compose(a, b), c)
    right = compose(a, compose(b, c))
    np.testing.assert_allclose(left[:2], right[:2], atol=1e-8)
    assert _same_angle(left[2], right[2])


@given(pose, pose, st.lists(point, min_size=1, max_size=5))
def test_transform_points_and_compose_match_matrices(a, b, pts):
    pts = np.array(pts)
    homog = np.c_[pts, np.ones(len(pts))]
    np.testing.assert_allclose(transform_points(a, pts), (to_matrix(a) @ homog.T).T[:, :2], atol=1e-9)
    m = to_matrix(compose(a, b))
    np.testing.assert_allclose(m, to_matrix(a) @ to_matrix(b), atol=1e-9)
    back = from_matrix(to_matrix(a))
    np.testing.assert_allclose(back[:2], a[:2])
    assert _same_angle(back[2], a[2])


@given(pose, pose)
def test_relative_expresses_b_in_a(a, b):
    r = relative(a, b)
    again = compose(a, r)
    np.testing.assert_allclose(again[:2], b[:2], atol=1e-8)
    assert _same_angle(again[2], b[2])


def test_se2_broadcasting_and_known_values():
    poses = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, math.pi / 2]])
    out = compose(poses, [1.0, 0.0, 0.0])
    np.testing.assert_allclose(out, [[1.0, 0.0, 0.0], [1.0, 1.0, math.pi / 2]], atol=1e-12)
    pts = np.zeros((2, 4, 2))
    assert transform_points(poses[:, None, :], pts).shape == (2, 4, 2)
    assert to_matrix(poses).shape == (2, 3, 3)
    with pytest.raises(ValueError, match=r"a must be a pose array of shape \(\.\.\., 3\).*\(2,\)"):
        compose([1.0, 2.0], [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="pts must be a point array"):
        transform_points([0.0, 0.0, 0.0], [1.0, 2.0, 3.0])


# ---------------------------------------------------------------------------- similarity
sim = st.builds(Similarity, st.floats(0.1, 10.0), st.floats(-math.pi, math.pi), coord, coord)


@given(point, point, point, point)
def test_similarity_maps_both_pairs_exactly(p1, p2, q1, q2):
    if np.linalg.norm(p2 - p1) < 1e-3 or np.linalg.norm(q2 - q1) < 1e-3:
        return
    T = similarity_from_two_pairs(p1, p2, q1, q2)
    scale_ref = np.linalg.norm(q2 - q1) / np.linalg.norm(p2 - p1)
    assert T.scale == pytest.approx(scale_ref, rel=1e-9)
    tol = 1e-7 * (1 + T.scale) * 100
    np.testing.assert_allclose(T.apply(p1), q1, atol=tol)
    np.testing.assert_allclose(T.apply(p2), q2, atol=tol)
    Ti = T.inverse()
    np.testing.assert_allclose(Ti.apply(q1), p1, atol=tol / T.scale + 1e-7)
    np.testing.assert_allclose(Ti.apply(q2), p2, atol=tol / T.scale + 1e-7)


@given(sim, st.lists(point, min_size=1, max_size=6))
def test_similarity_recovered_from_two_of_its_images(T, pts):
    p1, p2 = np.array([0.0, 0.0]), np.array([3.0, 4.0])
    R = similarity_from_two_pairs(p1, p2, T.apply(p1), T.apply(p2))
    assert R.scale == pytest.approx(T.scale)
    assert _same_angle(R.rotation_rad, T.rotation_rad)
    pts = np.array(pts)
    np.testing.assert_allclose(R.apply(pts), T.apply(pts), atol=1e-6 * (1 + T.scale) * 100)


@given(sim, sim, point, st.floats(-math.pi, math.pi))
def test_similarity_compose_inverse_and_heading(A, B, p, heading):
    AB = A.compose(B)
    np.testing.assert_allclose(AB.apply(p), A.apply(B.apply(p)), atol=1e-6 * (1 + A.scale * B.scale) * 100)
    np.testing.assert_allclose(A.inverse().apply(A.apply(p)), p, atol=1e-6 * 100)
    ident = A.compose(A.inverse())
    assert ident.scale == pytest.approx(1.0)
    np.testing.assert_allclose(A.matrix() @ np.r_[p, 1.0], np.r_[A.apply(p), 1.0], atol=1e-6 * 100 * A.scale)
    # a heading maps like the direction of a small step
    step = A.apply(np.array([p, p + 1e-3 * np.array([math.cos(heading), math.sin(heading)])]))
    d = step[1] - step[0]
    assert _same_angle(A.apply_heading(heading), math.atan2(d[1], d[0]), atol=1e-6)


def test_similarity_degenerate_and_invalid():
    with pytest.raises(ValueError, match=r"p1 and p2 must be distinct"):
        similarity_from_two_pairs([1.0, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0, 0.0])
    with pytest.raises(ValueError, match=r"q1 and q2 must be distinct"):
        similarity_from_two_pairs([0.0, 0.0], [1.0, 0.0], [2.0, 2.0], [2.0, 2.0])
    with pytest.raises(ValueError, match=r"q2 must be a finite point"):
        similarity_from_two_pairs([0.0, 0.0], [1.0, 0.0], [2.0, 2.0], [float("nan"), 2.0])
    with pytest.raises(ValueError, match=r"scale must be a positive finite number, got -1"):
        Similarity(-1.0, 0.0, 0.0, 0.0)


# ---------------------------------------------------------------------------- bearings
def _measure(pose_a, pose_b):
    """Bearing [rad] of robot b as robot a measures it, in a's frame, and the distance."""
    d = pose_b[:2] - pose_a[:2]
    return wrap_angle(math.atan2(d[1], d[0]) - pose_a[2]), float(np.hypot(*d))


@settings(max_examples=200)
@given(pose, pose)
def test_relative_frame_from_bearings_matches_true_relative_pose(p1, p2):
    if np.hypot(*(p2[:2] - p1[:2])) < 1e-3:
        return
    b21, d = _measure(p1, p2)  # R1 sees R2 (paper's alpha21)
    b12, _ = _measure(p2, p1)  # R2 sees R1 (paper's alpha12)
    got = relative_frame_from_bearings(b21, b12, d)
    want = relative(p1, p2)
    np.testing.assert_allclose(got[:2], want[:2], atol=1e-6)
    assert _same_angle(got[2], want[2], atol=1e-6)
    # the paper's formula, theta21 = 180 deg + alpha21 - alpha12
    assert _same_angle(got[2], math.pi + b21 - b12)
    # and R2's view of R1 (theta12 = 180 + alpha12 - alpha21) is the inverse pose
    back = relative_frame_from_bearings(b12, b21, d)
    np.testing.assert_allclose(compose(got, back), 0.0, atol=1e-6)


@given(pose, pose, point)
def test_transform_goal_matches_truth(p1, p2, goal_in_2):
    if np.hypot(*(p2[:2] - p1[:2])) < 1e-3:
        return
    b21, d = _measure(p1, p2)
    b12, _ = _measure(p2, p1)
    goal_world = transform_points(p2, goal_in_2)
    want = transform_points(inverse(p1), goal_world)
    np.testing.assert_allclose(transform_goal(goal_in_2, b21, b12, d), want, atol=1e-6)


def test_bearings_known_case_and_errors():
    # R1 at origin facing +x; R2 at (0, 2) facing -x: R1 sees R2 at +90 deg, R2 sees R1 at +90 deg (to its left)
    got = relative_frame_from_bearings(math.pi / 2, math.pi / 2, 2.0)
    np.testing.assert_allclose(got, [0.0, 2.0, math.pi], atol=1e-12)
    # vectorised over pairs
    assert relative_frame_from_bearings(np.zeros(5), np.zeros(5), np.ones(5)).shape == (5, 3)
    with pytest.raises(ValueError, match="distance_m must be >= 0"):
        relative_frame_from_bearings(0.0, 0.0, -1.0)
    with pytest.raises(ValueError, match="bearing_1_in_2_rad must be finite"):
        relative_frame_from_bearings(0.0, float("nan"), 1.0)
