"""Odometry: exact without noise, Table 5.6 noise statistics, configured drift rates, frames."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.geometry.angles import wrap_angle
from teamnav.sim.config import OdometryConfig
from teamnav.sim.odometry import Odometry, odometry_reference, odometry_step


def _drive(n_steps, n_robots, cfg, dt=0.1, v=0.5, w=0.2, seed=0, start=None):
    """Drive robots along exact unicycle arcs; return (true poses (T+1, N, 3), odom (T+1, N, 3))."""
    start = np.zeros((n_robots, 3)) if start is None else start
    odo = Odometry([cfg] * n_robots, start, dt, np.random.default_rng(seed))
    p = start.copy()
    true = [p.copy()]
    odom = [odo.pose.copy()]
    for _ in range(n_steps):
        q = p.copy()
        q[:, 0] += v / w * (np.sin(p[:, 2] + w * dt) - np.sin(p[:, 2]))
        q[:, 1] -= v / w * (np.cos(p[:, 2] + w * dt) - np.cos(p[:, 2]))
        q[:, 2] = wrap_angle(p[:, 2] + w * dt)
        odo.step(p[:, 0].copy(), p[:, 1].copy(), p[:, 2].copy(), q[:, 0].copy(), q[:, 1].copy(), q[:, 2].copy())
        p = q
        true.append(p.copy())
        odom.append(odo.pose.copy())
    return np.array(true), np.array(odom)


def test_zero_noise_world_frame_equals_truth():
    start = np.array([[1.0, 2.0, 0.3], [-4.0, 0.5, -2.9]])
    true, odom = _drive(500, 2, OdometryConfig(frame="world"), start=start)
    np.testing.assert_allclose(odom, true, atol=1e-9)


def test_zero_noise_start_frame_is_truth_relative_to_start():
    start = np.array([[1.0, 2.0, 0.7]])
    true, odom = _drive(300, 1, OdometryConfig(frame="start"), start=start)
    np.testing.assert_array_equal(odom[0], 0.0)
    c, s = math.cos(-0.7), math.sin(-0.7)
    d = true[:, 0, :2] - start[0, :2]
    rel = np.stack([c * d[:, 0] - s * d[:, 1], s * d[:, 0] + c * d[:, 1]], axis=1)
    np.testing.assert_allclose(odom[:, 0, :2], rel, atol=1e-9)
    np.testing.assert_allclose(wrap_angle(odom[:, 0, 2] - (true[:, 0, 2] - 0.7)), 0.0, atol=1e-9)


def test_reversing_robot_gets_small_rotations():
    odo = Odometry([OdometryConfig(frame="world")], np.zeros((1, 3)), 0.1, np.random.default_rng(0))
    odo.step(np.array([0.0]), np.array([0.0]), np.array([0.0]), np.array([-0.05]), np.array([0.0]), np.array([0.0]))
    np.testing.assert_allclose(odo.delta[0], [-0.05, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(odo.pose[0], [-0.05, 0.0, 0.0], atol=1e-15)


@pytest.mark.parametrize("rate_deg_per_min", [0.35, 2.0, -1.0])
def test_heading_drift_grows_at_the_configured_rate(rate_deg_per_min):
    # 10 simulated minutes at dt = 0.1 s: heading error == rate * minutes (no random noise)
    true, odom = _drive(6000, 1, OdometryConfig(frame="world", heading_drift_deg_per_min=rate_deg_per_min))
    err_deg = np.degrees(wrap_angle(odom[:, 0, 2] - true[:, 0, 2]))
    minutes = np.arange(6001) * 0.1 / 60
    np.testing.assert_allclose(err_deg, rate_deg_per_min * minutes, atol=1e-6)


def test_scale_error_shows_in_distance():
    true, odom = _drive(1000, 1, OdometryConfig(frame="world", scale_error=0.05), w=1e-9)
    d_true = np.hypot(*(true[-1, 0, :2] - true[0, 0, :2]))
    d_odom = np.hypot(*(odom[-1, 0, :2] - odom[0, 0, :2]))
    assert d_odom / d_true == pytest.approx(1.05, rel=1e-6)


def test_random_noise_matches_a_monte_carlo_of_table_5_6():
    # 2000 robots on one straight path for 200 steps: the spread of the odometry end pose
    # matches an independent Monte Carlo of Table 5.6 (variance form) written out here.
    alpha = (0.02, 0.01, 0.03, 0.01)
    n, steps, dt, v, w = 2000, 200, 0.1, 0.5, 0.3
    _, odom = _drive(steps, n, OdometryConfig(frame="world", alpha=alpha), dt=dt, v=v, w=w, seed=1)
    rng = np.random.default_rng(99)
    rho = v / w
    trans = 2 * rho * math.sin(w * dt / 2)  # chord of one arc step
    rot1 = rot2 = w * dt / 2
    a1, a2, a3, a4 = alpha
    mc = np.zeros((n, 3))
    for _ in range(steps):
        m1 = rot1 - rng.normal(0, math.sqrt(a1 * rot1**2 + a2 * trans**2), n)
        mt = trans - rng.normal(0, math.sqrt(a3 * trans**2 + a4 * rot1**2 + a4 * rot2**2), n)
        m2 = rot2 - rng.normal(0, math.sqrt(a1 * rot2**2 + a2 * trans**2), n)
        mc[:, 0] += mt * np.cos(mc[:, 2] + m1)
        mc[:, 1] += mt * np.sin(mc[:, 2] + m1)
        mc[:, 2] += m1 + m2
    end = odom[-1]
    for k in range(2):
        assert end[:, k].std() == pytest.approx(mc[:, k].std(), rel=0.1)
        assert end[:, k].mean() == pytest.approx(mc[:, k].mean(), abs=3 * mc[:, k].std() / math.sqrt(n) + 1e-3)
    assert np.std(wrap_angle(end[:, 2] - np.mean(end[:, 2]))) == pytest.approx(np.std(mc[:, 2]), rel=0.1)
    # and the heading spread grows like sqrt(steps): compare half way and the end
    half = odom[steps // 2, :, 2]
    ratio = np.std(wrap_angle(end[:, 2] - np.mean(end[:, 2]))) / np.std(wrap_angle(half - np.mean(half)))
    assert ratio == pytest.approx(math.sqrt(2), rel=0.1)


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**31), st.booleans())
def test_kernel_matches_numpy_reference(seed, noisy):
    rng = np.random.default_rng(seed)
    n = 7
    p0 = np.column_stack([rng.uniform(-5, 5, (n, 2)), rng.uniform(-math.pi, math.pi, n)])
    p1 = p0 + np.column_stack([rng.normal(0, 0.1, (n, 2)), rng.normal(0, 0.3, n)])
    p1[0, :2] = p0[0, :2]  # a pure rotation
    p1[:, 2] = wrap_angle(p1[:, 2])
    noise = rng.standard_normal((n, 3)) if noisy else np.empty((0, 3))
    alpha = rng.uniform(0, 0.2, (n, 4))
    drift = rng.normal(0, 1e-3, n)
    scale = rng.uniform(0.9, 1.1, n)
    pose = np.column_stack([rng.uniform(-5, 5, (n, 2)), rng.uniform(-math.pi, math.pi, n)])
    slip_noise = rng.standard_normal((n, 2)) if noisy else np.empty((0, 2))
    slip_m, slip_rad = rng.uniform(0, 0.05, n), rng.uniform(0, 0.02, n)
    ref_pose, ref_delta = odometry_reference(p0, p1, noise, alpha, drift, scale, pose, slip_noise, slip_m, slip_rad)
    delta = np.zeros((n, 3))
    odometry_step(*(np.ascontiguousarray(c) for c in (p0[:, 0], p0[:, 1], p0[:, 2], p1[:, 0], p1[:, 1], p1[:, 2])),
                  noise, alpha, drift, scale, pose, delta, slip_noise, slip_m, slip_rad)
    np.testing.assert_allclose(pose, ref_pose, atol=1e-12)
    np.testing.assert_allclose(delta, ref_delta, atol=1e-12)


def test_delta_composes_to_the_pose():
    true, _ = _drive(1, 1, OdometryConfig())
    odo = Odometry([OdometryConfig(alpha=(0.1, 0.1, 0.1, 0.1))], np.zeros((1, 3)), 0.1, np.random.default_rng(3))
    before = odo.pose.copy()
    odo.step(*(np.array([c]) for c in true[0, 0]), *(np.array([c]) for c in true[1, 0]))
    dx, dy, dth = odo.delta[0]
    th = before[0, 2]
    np.testing.assert_allclose(odo.pose[0, :2], before[0, :2] + [dx * math.cos(th) - dy * math.sin(th),
                                                                 dx * math.sin(th) + dy * math.cos(th)], atol=1e-12)
    assert odo.pose[0, 2] == pytest.approx(wrap_angle(th + dth))


def test_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="start_poses"):
        Odometry([OdometryConfig()], np.zeros((2, 3)), 0.1, np.random.default_rng(0))
    with pytest.raises(ValueError, match="dt_s"):
        Odometry([OdometryConfig()], np.zeros((1, 3)), float("nan"), np.random.default_rng(0))
