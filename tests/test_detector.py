"""Robot detector: range, field of view and line-of-sight gating, noise models, false detections."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.control.types import Detection
from teamnav.geometry.angles import wrap_angle
from teamnav.sim.config import DetectorConfig
from teamnav.sim.sensors import RobotDetector
from teamnav.world.grid import GLASS, WALL, OccupancyGrid
from teamnav.world.los import visible_pairs

RES = 0.1


def empty(width_m=20.0, height_m=20.0):
    return OccupancyGrid.empty(width_m, height_m, RES)


def run(det, xs, ys, ths, observers=None, seed=0, ids=None, radii=None):
    xs, ys, ths = (np.asarray(v, dtype=float) for v in (xs, ys, ths))
    n = xs.shape[0]
    observers = np.arange(n) if observers is None else np.asarray(observers)
    ids = np.arange(n) if ids is None else ids
    radii = np.full(n, 0.2) if radii is None else radii
    return det.detect_arrays(xs, ys, ths, radii, observers, np.random.default_rng(seed), ids)


def pairs(arr):
    return set(zip(arr.observer.tolist(), arr.target.tolist()))


# ---------------------------------------------------------------------------- gating
def test_range_gate_centre_to_centre():
    det = RobotDetector(DetectorConfig(max_range_m=5.0), empty())
    a = run(det, [1.0, 5.9, 6.1], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0], observers=[0])
    assert pairs(a) == {(0, 1)}  # 4.9 m seen, 5.1 m not
    assert a.range_m.tolist() == pytest.approx([4.9])


def test_fov_gate_uses_body_frame_bearing():
    det = RobotDetector(DetectorConfig(fov_deg=90.0, max_range_m=10.0), empty())
    th = 0.3
    # targets at body-frame bearings 40, -44, 50, 180 degrees, 3 m away
    b = np.radians([40.0, -44.0, 50.0, 180.0])
    xs = np.concatenate([[10.0], 10.0 + 3 * np.cos(th + b)])
    ys = np.concatenate([[10.0], 10.0 + 3 * np.sin(th + b)])
    a = run(det, xs, ys, np.full(5, th), observers=[0])
    assert a.target.tolist() == [1, 2]
    np.testing.assert_allclose(a.bearing_rad, b[:2], atol=1e-12)


def test_wall_hides_glass_does_not():
    for material, seen in ((WALL, False), (GLASS, True)):
        g = empty(10.0, 4.0)
        cells = g.cells.copy()
        cells[:, 50] = material  # x in [5.0, 5.1)
        g = g.with_cells(cells)
        det = RobotDetector(DetectorConfig(max_range_m=8.0), g)
        a = run(det, [3.0, 7.0, 4.0], [2.0, 2.0, 2.0], [0.0, np.pi, 0.0])
        expect = {(0, 2), (2, 0)} | ({(0, 1), (1, 0), (1, 2), (2, 1)} if seen else set())
        assert pairs(a) == expect
    # with line_of_sight off, the wall hides nothing
    det = RobotDetector(DetectorConfig(max_range_m=8.0, line_of_sight=False), g.with_cells(np.where(g.cells > 0, WALL, 0)))
    assert len(pairs(run(det, [3.0, 7.0], [2.0, 2.0], [0.0, 0.0]))) == 2


def test_full_circle_visibility_is_symmetric_and_matches_visible_pairs():
    rng = np.random.default_rng(5)
    cells = (rng.random((150, 150)) < 0.03).astype(np.uint8)
    g = OccupancyGrid(cells, RES)
    free = g.free_cells()[rng.choice(len(g.free_cells()), 300, replace=False)]
    xy = g.cell_centers(free[:, 0], free[:, 1])
    det = RobotDetector(DetectorConfig(max_range_m=4.0, sees=("wall",)), g)
    a = run(det, xy[:, 0], xy[:, 1], rng.uniform(-np.pi, np.pi, 300))
    p = pairs(a)
    assert p == {(j, i) for i, j in p}
    vis = visible_pairs(g.blocking(("wall",)), 0.0, 0.0, RES, xy[:, 0], xy[:, 1], 4.0)
    assert p == set(zip(*np.nonzero(vis)))
    assert 0 < len(p) < 300 * 299  # some pairs are hidden by the clutter, some are seen


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 25))
def test_bearing_and_range_from_random_poses(seed, n):
    rng = np.random.default_rng(seed)
    xs, ys, ths = rng.uniform(0.5, 19.5, n), rng.uniform(0.5, 19.5, n), rng.uniform(-10, 10, n)
    det = RobotDetector(DetectorConfig(max_range_m=30.0), empty())
    a = run(det, xs, ys, ths)
    assert len(a) == n * (n - 1)
    o, t = a.observer, a.target
    np.testing.assert_allclose(a.range_m, np.hypot(xs[t] - xs[o], ys[t] - ys[o]), rtol=1e-12)
    expect = wrap_angle(np.arctan2(ys[t] - ys[o], xs[t] - xs[o]) - ths[o])
    np.testing.assert_allclose(a.bearing_rad, expect, atol=1e-12)
    assert np.all(a.bearing_rad > -np.pi) and np.all(a.bearing_rad <= np.pi)


def test_only_observers_look():
    det = RobotDetector(DetectorConfig(max_range_m=10.0), empty())
    a = run(det, [1.0, 2.0, 3.0, 4.0], [1.0] * 4, [0.0] * 4, observers=[2, 0])
    assert set(a.observer.tolist()) == {0, 2}
    assert a.row.tolist() == [0, 0, 0, 1, 1, 1]  # row k belongs to observers[k]; ordered by row
    assert a.observer[:3].tolist() == [2, 2, 2] and a.target[:3].tolist() == [0, 1, 3]


# ---------------------------------------------------------------------------- noise
def _ring(n_targets=400, radius=3.0):
    """Observer at the centre of a ring of targets (all in view)."""
    ang = np.linspace(-np.pi, np.pi, n_targets, endpoint=False) + 1e-3
    xs = np.concatenate([[10.0], 10.0 + radius * np.cos(ang)])
    ys = np.concatenate([[10.0], 10.0 + radius * np.sin(ang)])
    return xs, ys, np.zeros(n_targets + 1)


def test_occlusion_noise_bounded_by_eqs_1_2():
    err_max = 0.2
    det = RobotDetector(DetectorConfig(max_range_m=50.0, noise_model="occlusion", err_max=err_max), empty(40, 40))
    xs, ys, th = _ring(2000, 3.0)
    radii = np.full(xs.shape[0], 0.25)
    clean = RobotDetector(DetectorConfig(max_range_m=50.0), empty(40, 40))
    truth = run(clean, xs, ys, th, observers=[0], radii=radii)
    a = run(det, xs, ys, th, observers=[0], radii=radii, seed=9)
    assert np.array_equal(a.target, truth.target)
    d_r, a_r = truth.range_m, truth.bearing_rad
    d_noise = (a.range_m - d_r) / d_r  # eq. 1
    bound = np.arctan(2 * 0.25 / (2 * d_r))  # eq. 2, robotsize = diameter
    a_noise = wrap_angle(a.bearing_rad - a_r) / bound
    assert np.all(np.abs(a.range_m - d_r) <= d_r * err_max + 1e-12)
    assert np.all(np.abs(a_noise) <= 1 + 1e-9)
    # uniform on [-err_max, err_max] and [-1, 1] (Sgorbissa & Arkin §6.1): mean 0, variance e^2/3
    m = d_noise.size
    assert abs(d_noise.mean()) < 5 * err_max / math.sqrt(3 * m)
    assert d_noise.var() == pytest.approx(err_max**2 / 3, rel=0.1)
    assert np.abs(d_noise).max() > 0.98 * err_max
    assert a_noise.var() == pytest.approx(1 / 3, rel=0.1)


def test_gaussian_noise_statistics():
    det = RobotDetector(DetectorConfig(max_range_m=50.0, range_noise_std_m=0.1, bearing_noise_std_deg=2.0),
                        empty(40, 40))
    xs, ys, th = _ring(3000, 5.0)
    truth = run(RobotDetector(DetectorConfig(max_range_m=50.0), empty(40, 40)), xs, ys, th, observers=[0])
    a = run(det, xs, ys, th, observers=[0], seed=3)
    dr = a.range_m - truth.range_m
    db = wrap_angle(a.bearing_rad - truth.bearing_rad)
    m = dr.size
    assert abs(dr.mean()) < 5 * 0.1 / math.sqrt(m) and dr.std() == pytest.approx(0.1, rel=0.06)
    assert abs(db.mean()) < 5 * math.radians(2) / math.sqrt(m)
    assert db.std() == pytest.approx(math.radians(2.0), rel=0.06)


# ---------------------------------------------------------------------------- false detections
def test_false_negative_rate():
    p = 0.3
    det = RobotDetector(DetectorConfig(max_range_m=50.0, p_false_negative=p), empty(40, 40))
    xs, ys, th = _ring(2000)
    a = run(det, xs, ys, th, observers=[0], seed=1)
    assert np.all(a.target >= 0)  # no phantoms configured
    missed = 1 - len(a) / 2000
    assert abs(missed - p) < 5 * math.sqrt(p * (1 - p) / 2000)


@pytest.mark.parametrize("fov_deg, identity", [(360.0, True), (60.0, False)])
def test_false_positive_rate_and_placement(fov_deg, identity):
    p = 0.2
    n = 3000
    det = RobotDetector(
        DetectorConfig(fov_deg=fov_deg, max_range_m=2.0, p_false_positive=p, report_identity=identity), empty(40, 40)
    )
    rng = np.random.default_rng(2)
    # robots far apart (no true detections): only phantoms
    gx, gy = np.meshgrid(np.arange(55) * 2.5, np.arange(55) * 2.5)
    xs, ys = gx.ravel()[:n], gy.ravel()[:n]
    ids = np.arange(n) + 100
    a = det.detect_arrays(xs, ys, rng.uniform(-np.pi, np.pi, n), np.full(n, 0.2), np.arange(n),
                          np.random.default_rng(4), ids)
    assert np.all(a.target == -1)
    assert np.unique(a.row).shape == a.row.shape  # at most one phantom per observer per step
    assert abs(len(a) / n - p) < 5 * math.sqrt(p * (1 - p) / n)
    assert np.all(a.range_m > 0) and np.all(a.range_m <= 2.0)
    assert a.range_m.mean() == pytest.approx(1.0, abs=0.1)  # uniform in (0, max]
    half = math.radians(fov_deg) / 2
    assert np.all(np.abs(a.bearing_rad) <= half) and np.all(a.bearing_rad > -np.pi)
    assert np.abs(a.bearing_rad).max() > 0.9 * half  # spread over the whole field of view
    if identity:
        assert np.all(np.isin(a.robot_id, ids)) and np.all(a.robot_id != ids[a.observer])
    else:
        assert np.all(a.robot_id == -1)


def test_phantom_identity_is_another_robot():
    det = RobotDetector(DetectorConfig(max_range_m=1.0, p_false_positive=1.0), empty())
    xs, ys = np.array([1.0, 5.0, 9.0]), np.array([1.0, 5.0, 9.0])
    ids = np.array([7, 8, 9])
    rng = np.random.default_rng(0)
    seen = {0: set(), 1: set(), 2: set()}
    for _ in range(200):
        a = det.detect_arrays(xs, ys, np.zeros(3), np.full(3, 0.2), np.arange(3), rng, ids)
        assert a.row.tolist() == [0, 1, 2]  # p = 1: one phantom each
        for o, rid in zip(a.observer.tolist(), a.robot_id.tolist()):
            seen[o].add(rid)
    assert seen == {0: {8, 9}, 1: {7, 9}, 2: {7, 8}}  # never itself, every other robot


# ---------------------------------------------------------------------------- identity, API
def test_identity_on_and_off():
    xs, ys, th = [1.0, 2.0, 3.0], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]
    ids = np.array([70, 71, 72])
    with_id = RobotDetector(DetectorConfig(max_range_m=5.0), empty())
    out = with_id.detect(np.array(xs), np.array(ys), np.array(th), np.full(3, 0.2), np.array([1]),
                         np.random.default_rng(0), ids)
    assert out == [(Detection(1.0, math.pi, 70), Detection(1.0, 0.0, 72))]
    anon = RobotDetector(DetectorConfig(max_range_m=5.0, report_identity=False), empty())
    out = anon.detect(np.array(xs), np.array(ys), np.array(th), np.full(3, 0.2), np.array([1]),
                      np.random.default_rng(0), ids)
    assert [d.robot_id for d in out[0]] == [None, None]


def test_detect_wraps_detect_arrays_and_is_deterministic():
    cfg = DetectorConfig(max_range_m=6.0, range_noise_std_m=0.05, bearing_noise_std_deg=1.0,
                         p_false_negative=0.2, p_false_positive=0.3)
    det = RobotDetector(cfg, empty())
    rng = np.random.default_rng(0)
    n = 40
    xs, ys, th = rng.uniform(1, 19, n), rng.uniform(1, 19, n), rng.uniform(-3, 3, n)
    obs = np.arange(0, n, 2)
    args = (xs, ys, th, np.full(n, 0.2), obs)
    arr = det.detect_arrays(*args, np.random.default_rng(5), np.arange(n))
    lists = det.detect(*args, np.random.default_rng(5), np.arange(n))
    again = det.detect(*args, np.random.default_rng(5), np.arange(n))
    other = det.detect(*args, np.random.default_rng(6), np.arange(n))
    assert lists == again and lists != other
    assert len(lists) == obs.shape[0]
    flat = [d for row in lists for d in row]
    assert [d.range_m for d in flat] == arr.range_m.tolist()
    assert [d.robot_id for d in flat] == [None if v < 0 else v for v in arr.robot_id.tolist()]
    for k, row in enumerate(lists):
        assert len(row) == int((arr.row == k).sum())


def test_bad_input_names_parameter():
    det = RobotDetector(DetectorConfig(), empty())
    x = np.array([1.0, 2.0])
    r = np.full(2, 0.2)
    g = np.random.default_rng(0)
    with pytest.raises(ValueError, match=r"observers must be indices in \[0, 2\), got \[5\]"):
        det.detect(x, x, x, r, np.array([5]), g, np.arange(2))
    with pytest.raises(ValueError, match="observers must not repeat"):
        det.detect(x, x, x, r, np.array([0, 0]), g, np.arange(2))
    with pytest.raises(ValueError, match=r"ids must be an integer array of shape \(2,\)"):
        det.detect(x, x, x, r, np.array([0]), g, np.arange(3))
    with pytest.raises(ValueError, match=r"thetas must have shape \(2,\)"):
        det.detect(x, x, np.zeros(3), r, np.array([0]), g, np.arange(2))
    with pytest.raises(ValueError, match="xs must be finite"):
        det.detect(np.array([np.nan, 1.0]), x, x, r, np.array([0]), g, np.arange(2))
    with pytest.raises(ValueError, match="rng must be a numpy.random.Generator"):
        det.detect(x, x, x, r, np.array([0]), 3, np.arange(2))
    with pytest.raises(ValueError, match="cfg must be a DetectorConfig"):
        RobotDetector({"fov_deg": 90}, empty())


# ---------------------------------------------------------------------------- the engine's shared pass
def _walled(res=0.1):
    cells = np.zeros((120, 160), np.uint8)
    cells[60:62, 10:150] = WALL  # a long wall with gaps at both ends
    cells[20:40, 70:72] = GLASS
    return OccupancyGrid(cells, res)


_CFGS = [
    DetectorConfig(max_range_m=6.0, noise_model="occlusion", err_max=0.2),
    DetectorConfig(max_range_m=6.0, fov_deg=200.0, noise_model="gaussian", range_noise_std_m=0.1,
                   bearing_noise_std_deg=4.0),
    DetectorConfig(max_range_m=9.0, noise_model="gaussian"),  # noise-free: no draws
    DetectorConfig(max_range_m=6.0, fov_deg=120.0, noise_model="gaussian", range_noise_std_m=0.1,
                   p_false_negative=0.2, p_false_positive=0.3),
    DetectorConfig(max_range_m=6.0, noise_model="occlusion", err_max=0.1, report_identity=False, line_of_sight=False,
                   p_false_positive=0.5),
]


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 12), st.sampled_from(range(len(_CFGS))), st.integers(1, 4))
def test_detect_groups_equals_one_detect_per_group(seed, n, which, n_groups):
    """The engine's one pass for several groups gives each group exactly what its own
    :meth:`detect` call gives, and leaves every group's stream in the same state."""
    g = np.random.default_rng(seed)
    grid = _walled()
    det = RobotDetector(_CFGS[which], grid)
    xs, ys = g.uniform(0.3, 15.7, n), g.uniform(0.3, 11.7, n)
    if n > 2:
        xs[2], ys[2] = xs[1], ys[1]  # two robots on one spot: d_r = 0
    ths = g.uniform(-np.pi, np.pi, n)
    radii = g.uniform(0.1, 0.3, n)
    ids = np.arange(n, dtype=np.int64) + 10
    cuts = np.unique(np.concatenate([[0, n], g.integers(1, n, n_groups - 1)]))  # contiguous groups
    groups = [np.arange(cuts[k], cuts[k + 1], dtype=np.int64) for k in range(cuts.shape[0] - 1)]
    one = [np.random.default_rng([seed, k]) for k in range(len(groups))]
    many = [np.random.default_rng([seed, k]) for k in range(len(groups))]
    expected = [det.detect(xs, ys, ths, radii, obs, rng, ids) for obs, rng in zip(groups, one)]
    got = det._detect_groups(xs, ys, ths, radii, groups, many, ids)
    assert got == expected  # Detection dataclasses compare field by field, floats exactly
    assert [r.bit_generator.state for r in one] == [r.bit_generator.state for r in many]


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 12), st.sampled_from(range(len(_CFGS))), st.integers(1, 4),
       st.booleans())
def test_detect_groups_padded_equals_padded_tuples(seed, n, which, n_groups, far):
    """The padded arrays a team's group brain gets straight from the detector are, byte for
    byte, ``pad_detections`` of the concatenated groups' Detection tuples, with the same draws
    from every group's stream; a detector with false negatives or positives declines (None)
    and draws nothing."""
    from teamnav.control.group import pad_detections

    g = np.random.default_rng(seed)
    det = RobotDetector(_CFGS[which], _walled())
    xs, ys = g.uniform(0.3, 15.7, n), g.uniform(0.3, 11.7, n)
    if far:  # spread out: often nobody sees anybody (the empty arrays)
        xs = np.arange(n) * 7.0 + 0.5
        ys = np.where(np.arange(n) % 2 == 0, 1.0, 10.0)
    elif n > 2:
        xs[2], ys[2] = xs[1], ys[1]
    ths = g.uniform(-np.pi, np.pi, n)
    radii = g.uniform(0.1, 0.3, n)
    ids = np.arange(n, dtype=np.int64) + 10
    cuts = np.unique(np.concatenate([[0, n], g.integers(1, n, n_groups - 1)]))
    groups = [np.arange(cuts[k], cuts[k + 1], dtype=np.int64) for k in range(cuts.shape[0] - 1)]
    one = [np.random.default_rng([seed, k]) for k in range(len(groups))]
    many = [np.random.default_rng([seed, k]) for k in range(len(groups))]
    before = [r.bit_generator.state for r in many]
    got = det._detect_groups_padded(xs, ys, ths, radii, groups, many, ids)
    if det.cfg.p_false_negative or det.cfg.p_false_positive:
        assert got is None
        assert [r.bit_generator.state for r in many] == before
        return
    tuples = [row for d in det._detect_groups(xs, ys, ths, radii, groups, one, ids) for row in d]
    expected = pad_detections(tuples, n)
    assert [r.bit_generator.state for r in one] == [r.bit_generator.state for r in many]
    for a, b in zip(got, expected):
        assert a.dtype == b.dtype and a.shape == b.shape and a.flags.c_contiguous
        assert a.tobytes() == b.tobytes()


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 40), st.sampled_from([0, 1, 3, 4]))
def test_small_team_kernel_equals_spatial_hash(seed, n, which):
    """Up to 64 robots the visible pairs come from one all-pairs kernel; it returns the
    spatial-hash path's detections bit for bit (ordering included)."""
    from teamnav.sim.sensors import detector as det_mod

    g = np.random.default_rng(seed)
    det = RobotDetector(_CFGS[which], _walled())
    xs, ys, ths = g.uniform(0.3, 15.7, n), g.uniform(0.3, 11.7, n), g.uniform(-np.pi, np.pi, n)
    obs = np.sort(g.choice(n, size=max(1, n // 2), replace=False)).astype(np.int64)
    brute = det._visible(xs, ys, ths, obs)
    saved = det_mod._BRUTE_MAX_ROBOTS
    try:
        det_mod._BRUTE_MAX_ROBOTS = 0
        hashed = det._visible(xs, ys, ths, obs)
    finally:
        det_mod._BRUTE_MAX_ROBOTS = saved
    for a, b in zip(brute, hashed):
        assert a.dtype == b.dtype and np.array_equal(a, b)


def test_occlusion_at_err_max_zero_is_perfect_sensing_and_keeps_the_stream():
    """Commit 7915eb8 (2026-11-27): Sgorbissa & Arkin's Tables 1-2 are "perfect sensing": the occlusion model at
    err_max = 0 returns the exact range and bearing (eq. 2's bearing error only in the noise
    figures, err_max > 0), and draws its uniforms all the same (the same random stream)."""
    xs, ys, th = _ring(200, 3.0)
    radii = np.full(xs.shape[0], 0.25)
    clean = RobotDetector(DetectorConfig(max_range_m=50.0), empty(40, 40))
    truth = run(clean, xs, ys, th, observers=[0], radii=radii)
    zero = RobotDetector(DetectorConfig(max_range_m=50.0, noise_model="occlusion", err_max=0.0), empty(40, 40))
    a = run(zero, xs, ys, th, observers=[0], radii=radii, seed=9)
    assert np.array_equal(a.target, truth.target)
    assert np.array_equal(a.range_m, truth.range_m) and np.array_equal(a.bearing_rad, truth.bearing_rad)
    rng0, rng1 = np.random.default_rng(3), np.random.default_rng(3)
    zero.detect_arrays(xs, ys, th, radii, [0], rng0, np.arange(xs.size))
    RobotDetector(DetectorConfig(max_range_m=50.0, noise_model="occlusion", err_max=0.3), empty(40, 40)).detect_arrays(
        xs, ys, th, radii, [0], rng1, np.arange(xs.size))
    assert rng0.random() == rng1.random()
    # err_max > 0: eq. 2 moves the bearing
    noisy = RobotDetector(DetectorConfig(max_range_m=50.0, noise_model="occlusion", err_max=0.1), empty(40, 40))
    assert not np.array_equal(run(noisy, xs, ys, th, observers=[0], radii=radii, seed=9).bearing_rad, truth.bearing_rad)
