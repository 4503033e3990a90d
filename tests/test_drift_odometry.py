"""Translational odometry error (teamnav.sim.odometry): wheel-diameter scale error and wheel slip.

The slip is a random walk per metre driven: after L metres the distance error has std
``slip_std_m_per_sqrt_m * sqrt(L)`` and the heading error ``heading_slip_deg_per_sqrt_m * sqrt(L)``,
whatever the step. A scale error alone is a similarity between the odometry frame and the world,
which the 2002 paper's transform from two Places (Try to see it my way §2.1.5) undoes exactly.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from teamnav.geometry.angles import wrap_angle
from teamnav.geometry.similarity import similarity_from_two_pairs
from teamnav.sim.config import OdometryConfig
from teamnav.sim.odometry import Odometry, odometry_reference


def _straight(cfg: OdometryConfig, n: int, length_m: float, dt_s: float, v_mps: float = 0.5, seed: int = 0,
              backwards: bool = False) -> np.ndarray:
    """n robots drive ``length_m`` straight along +x (or reverse along -x) from the origin; end odometry (n, 3)."""
    odo = Odometry([cfg] * n, np.zeros((n, 3)), dt_s, np.random.default_rng(seed))
    steps = int(round(length_m / (v_mps * dt_s)))
    ds = length_m / steps * (-1.0 if backwards else 1.0)
    zeros = np.zeros(n)
    for k in range(steps):
        odo.step(np.full(n, k * ds), zeros, zeros, np.full(n, (k + 1) * ds), zeros, zeros)
    return odo.pose.copy()


@pytest.mark.parametrize("dt_s", [0.1, 0.025])
def test_distance_slip_std_is_sigma_sqrt_metres_whatever_the_step(dt_s):
    sigma, length = 0.02, 16.0
    end = _straight(OdometryConfig(slip_std_m_per_sqrt_m=sigma), 3000, length, dt_s, seed=1)
    along = end[:, 0] - length
    assert along.std() == pytest.approx(sigma * math.sqrt(length), rel=0.06)
    assert abs(along.mean()) < 4 * sigma * math.sqrt(length) / math.sqrt(3000)
    # distance slip alone leaves the heading and the cross-track position exact
    np.testing.assert_allclose(end[:, 1:], 0.0, atol=1e-12)


@pytest.mark.parametrize("dt_s", [0.1, 0.025])
def test_heading_slip_std_is_sigma_sqrt_metres_whatever_the_step(dt_s):
    sigma_deg, length = 1.0, 16.0
    end = _straight(OdometryConfig(heading_slip_deg_per_sqrt_m=sigma_deg), 3000, length, dt_s, seed=2)
    head_deg = np.degrees(wrap_angle(end[:, 2]))
    assert head_deg.std() == pytest.approx(sigma_deg * math.sqrt(length), rel=0.06)
    # a heading random walk bends the believed path: cross-track spread ~ sigma L^1.5 / sqrt(3)
    expect_y = math.radians(sigma_deg) * length**1.5 / math.sqrt(3)
    assert end[:, 1].std() == pytest.approx(expect_y, rel=0.1)


def test_reversing_robot_slips_by_the_distance_it_drives():
    sigma, length = 0.02, 9.0
    end = _straight(OdometryConfig(slip_std_m_per_sqrt_m=sigma), 3000, length, 0.1, seed=3, backwards=True)
    assert np.all(np.isfinite(end))
    assert (end[:, 0] + length).std() == pytest.approx(sigma * math.sqrt(length), rel=0.06)


def test_a_robot_that_does_not_drive_does_not_slip():
    odo = Odometry([OdometryConfig(slip_std_m_per_sqrt_m=0.5, heading_slip_deg_per_sqrt_m=30.0)] * 5,
                   np.zeros((5, 3)), 0.1, np.random.default_rng(0))
    th = np.zeros(5)
    for k in range(200):  # standing still, then turning on the spot
        th1 = th + (0.05 if k >= 100 else 0.0)
        odo.step(np.zeros(5), np.zeros(5), th, np.zeros(5), np.zeros(5), th1)
        th = th1
    np.testing.assert_allclose(odo.pose[:, :2], 0.0, atol=1e-12)
    np.testing.assert_allclose(wrap_angle(odo.pose[:, 2] - th), 0.0, atol=1e-12)


def test_runs_without_slip_draw_the_same_numbers_as_before():
    # Table 5.6 noise only: the stream is consumed 3 draws per robot per step, as before the slip
    alpha = (0.05, 0.01, 0.02, 0.01)
    n, dt = 4, 0.1
    cfgs = [OdometryConfig(alpha=alpha, frame="world")] * n
    odo = Odometry(cfgs, np.zeros((n, 3)), dt, np.random.default_rng(7))
    rng = np.random.default_rng(7)
    ref = np.zeros((n, 3))
    p0 = np.zeros((n, 3))
    for _ in range(50):
        p1 = p0 + [0.04, 0.01, 0.02]
        odo.step(*(p0[:, j].copy() for j in range(3)), *(p1[:, j].copy() for j in range(3)))
        ref, _ = odometry_reference(p0, p1, rng.standard_normal((n, 3)), np.array([alpha] * n), np.zeros(n),
                                    np.ones(n), ref)
        p0 = p1
    np.testing.assert_allclose(odo.pose, ref, atol=1e-12)


def test_slip_draws_follow_the_table_5_6_draws():
    # with slip on, a step draws (N, 3) for Table 5.6, then (N, 2) for the slip
    alpha, n = (0.05, 0.01, 0.02, 0.01), 3
    cfg = OdometryConfig(alpha=alpha, slip_std_m_per_sqrt_m=0.03, heading_slip_deg_per_sqrt_m=2.0, frame="world")
    odo = Odometry([cfg] * n, np.zeros((n, 3)), 0.1, np.random.default_rng(11))
    rng = np.random.default_rng(11)
    p0, ref = np.zeros((n, 3)), np.zeros((n, 3))
    for _ in range(30):
        p1 = p0 + [0.05, -0.01, 0.03]
        odo.step(*(p0[:, j].copy() for j in range(3)), *(p1[:, j].copy() for j in range(3)))
        noise = rng.standard_normal((n, 3))
        slip = rng.standard_normal((n, 2))
        ref, _ = odometry_reference(p0, p1, noise, np.array([alpha] * n), np.zeros(n), np.ones(n), ref, slip,
                                    np.full(n, 0.03), np.full(n, math.radians(2.0)))
        p0 = p1
    np.testing.assert_allclose(odo.pose, ref, atol=1e-12)


@pytest.mark.parametrize(("field", "value"), [
    ("slip_std_m_per_sqrt_m", -0.01), ("slip_std_m_per_sqrt_m", 0.6),
    ("heading_slip_deg_per_sqrt_m", -1.0), ("heading_slip_deg_per_sqrt_m", 31.0),
    ("scale_error", 0.5), ("scale_error", -0.5),
])
def test_out_of_range_translational_errors_name_the_field(field, value):
    with pytest.raises(ValidationError, match=field):
        OdometryConfig(**{field: value})


def test_the_scenario_sets_the_translational_errors_per_robot():
    from teamnav.experiments.spec import load_scenario

    sc = load_scenario("try-to-see-it-my-way", overrides={
        "robots.0.odometry.scale_error": 0.03, "robots.2.odometry.slip_std_m_per_sqrt_m": 0.01,
        "robots.3.odometry.heading_slip_deg_per_sqrt_m": 0.5})
    odo = [g.odometry for g in sc.robots]
    assert (odo[0].scale_error, odo[1].scale_error) == (0.03, 0.0)
    assert (odo[2].slip_std_m_per_sqrt_m, odo[3].heading_slip_deg_per_sqrt_m) == (0.01, 0.5)
    with pytest.raises(Exception, match="slip_std_m_per_sqrt_m"):
        load_scenario("try-to-see-it-my-way", overrides={"robots.1.odometry.slip_std_m_per_sqrt_m": -1})


_coord = st.floats(-3.0, 3.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(scale_error=st.floats(-0.2, 0.2), start=st.tuples(_coord, _coord, st.floats(-math.pi, math.pi)),
       moves=st.lists(st.tuples(st.floats(0.0, 0.3), st.floats(-0.6, 0.6)), min_size=3, max_size=40))
def test_a_scale_error_is_a_similarity_that_two_places_undo(scale_error, start, moves):
    # Any path (unicycle moves of d metres after a turn of w rad) with only a scale error: the
    # odometry (start frame) is (1 + s) R(-theta0) (p - p0), a similarity of the truth, so the
    # transform from two Places (home = the start, the second place = where the path ends) maps
    # every believed position onto the true one (Try §2.1.5: "translation, scaling and rotation").
    odo = Odometry([OdometryConfig(scale_error=scale_error)], np.array([start]), 0.1, np.random.default_rng(0))
    p = np.array(start, dtype=float)
    true, believed = [p[:2].copy()], [odo.pose[0, :2].copy()]
    for d, w in moves:
        q = p.copy()
        q[2] = wrap_angle(p[2] + w)
        q[0] += d * math.cos(q[2])
        q[1] += d * math.sin(q[2])
        odo.step(*(np.array([c]) for c in p), *(np.array([c]) for c in q))
        p = q
        true.append(p[:2].copy())
        believed.append(odo.pose[0, :2].copy())
    true, believed = np.array(true), np.array(believed)
    c, s = math.cos(-start[2]), math.sin(-start[2])
    rel = true - true[0]
    expect = (1 + scale_error) * np.stack([c * rel[:, 0] - s * rel[:, 1], s * rel[:, 0] + c * rel[:, 1]], axis=1)
    np.testing.assert_allclose(believed, expect, atol=1e-9)
    if np.hypot(*(true[-1] - true[0])) > 0.05:
        t = similarity_from_two_pairs(believed[0], believed[-1], true[0], true[-1])
        assert t.scale == pytest.approx(1 / (1 + scale_error), rel=1e-9)
        np.testing.assert_allclose(np.asarray(t.apply(believed)).reshape(-1, 2), true, atol=1e-8)
