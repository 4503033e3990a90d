"""Range sensors: geometry, noise statistics, materials, robot bodies (teamnav.sim.sensors)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.sim.config import LaserConfig, ProximityConfig, SonarConfig
from teamnav.sim.sensors import (
    apply_beam_noise,
    apply_robot_hits,
    beam_angles,
    beam_noise_keyed,
    build_range_sensor,
    robot_hits_reference,
)
from teamnav.sim.sensors import range_sensors as rs_mod
from teamnav.sim.sensors import robot_hits as rh_mod
from teamnav.world.grid import FOAM, GLASS, WALL, OccupancyGrid
from teamnav.world.raycast import RayCaster

RES = 0.05


def walled_grid(width_m=10.0, height_m=4.0, wall_x_m=6.0, material=WALL):
    """Empty map with a one-cell wall of ``material`` at x in [wall_x_m, wall_x_m + RES)."""
    g = OccupancyGrid.empty(width_m, height_m, RES)
    cells = g.cells.copy()
    cells[:, int(round(wall_x_m / RES))] = material
    return g.with_cells(cells)


def laser(**kw):
    base = dict(n_beams=181, fov_deg=180.0, max_range_m=20.0, noise_std_m=0.0, sees_robots=True)
    base.update(kw)
    return LaserConfig(**base)


# ---------------------------------------------------------------------------- geometry
def test_laser_facing_wall_matches_geometry():
    g = walled_grid()
    s = build_range_sensor(laser(), g)
    r = s.true_ranges(np.array([2.0]), np.array([2.0]), np.array([0.0]))[0]
    assert r.shape == (181,)
    ang = s.angles_rad
    # beams that reach the wall before leaving the map's y range [0, 4]: range = 4 / cos(a)
    hits_wall = np.abs(4.0 * np.tan(ang)) < 2.0 - RES
    expect = 4.0 / np.cos(ang[hits_wall])
    np.testing.assert_allclose(r[hits_wall], expect, atol=RES)
    assert r[90] == pytest.approx(4.0, abs=1e-9)  # straight ahead, exact
    # beams at +-90 deg stop on the map edge 2 m away
    assert r[0] == pytest.approx(2.0, abs=1e-9) and r[-1] == pytest.approx(2.0, abs=1e-9)


def test_laser_rotated_pose_reads_same_wall():
    g = walled_grid()
    s = build_range_sensor(laser(n_beams=3, fov_deg=180.0), g)
    # facing -y from (2, 3): left beam (+90 deg in body frame) points +x towards the wall
    r = s.true_ranges(np.array([2.0]), np.array([3.0]), np.array([-np.pi / 2]))[0]
    np.testing.assert_allclose(r, [2.0, 3.0, 4.0], atol=1e-9)  # right: -x to edge, front: to y=0, left: wall


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 400), st.floats(1.0, 360.0))
def test_beam_angles_cover_fov(n, fov_deg):
    fov = math.radians(fov_deg)
    a = beam_angles(n, fov)
    assert a.shape == (n,)
    assert np.all(a > -np.pi) and np.all(a <= np.pi)
    assert np.all(np.diff(a) > 0)
    if n == 1:
        assert a[0] == 0.0
    elif fov >= 2 * np.pi - 1e-12:  # a full circle (within rounding of 360 deg)
        np.testing.assert_allclose(np.diff(a), 2 * np.pi / n, rtol=1e-9)
        assert np.min(np.abs(a)) < 1e-12  # a beam straight ahead
        assert a[-1] - a[0] == pytest.approx(2 * np.pi * (n - 1) / n)  # no duplicate at +-pi
    else:
        assert a[0] == pytest.approx(-fov / 2) and a[-1] == pytest.approx(fov / 2)
        np.testing.assert_allclose(np.diff(a), fov / (n - 1), rtol=1e-9)


def test_full_circle_laser_has_no_duplicate_beam():
    s = build_range_sensor(laser(n_beams=360, fov_deg=360.0), walled_grid())
    deg = np.round(np.degrees(s.angles_rad), 9) % 360
    assert np.unique(deg).shape == (360,)
    assert s.info().angles_rad.shape == (360,) and s.info().kind == "laser"


def test_proximity_angles_wrapped_and_short_range():
    g = walled_grid()
    s = build_range_sensor(ProximityConfig(), g)
    np.testing.assert_allclose(np.degrees(s.angles_rad), [-40, -20, 0, 20, 40, 160, -160], atol=1e-9)
    r = s.true_ranges(np.array([5.9]), np.array([2.0]), np.array([0.0]))[0]
    assert r[2] == pytest.approx(0.1, abs=1e-9)  # wall 0.1 m ahead, within 0.14 m
    assert r[5] == pytest.approx(0.14) and r[6] == pytest.approx(0.14)  # nothing behind


# ---------------------------------------------------------------------------- materials
@pytest.mark.parametrize(
    "material, laser_stops, sonar_stops, prox_stops",
    [(GLASS, False, True, True), (FOAM, True, False, True), (WALL, True, True, True)],
)
def test_materials_per_sensor_kind(material, laser_stops, sonar_stops, prox_stops):
    g = walled_grid(wall_x_m=2.1, material=material)  # the panel 0.1 m ahead of the robot
    g2 = g.with_cells(np.where(np.arange(g.shape[1])[None, :] == int(round(4.0 / RES)), WALL, g.cells))
    x, y, th = np.array([2.0]), np.array([2.0]), np.array([0.0])
    las = build_range_sensor(laser(n_beams=1, fov_deg=10.0), g2).true_ranges(x, y, th)[0, 0]
    son = build_range_sensor(SonarConfig(n_transducers=1, fov_deg=10.0, rays_per_cone=1, p_specular=0.0), g2)
    prox = build_range_sensor(ProximityConfig(angles_deg=(0.0,), max_range_m=5.0), g2)
    son_r = son.true_ranges(x, y, th)[0, 0]
    prox_r = prox.true_ranges(x, y, th)[0, 0]
    for reading, stops in ((las, laser_stops), (son_r, sonar_stops), (prox_r, prox_stops)):
        assert reading == pytest.approx(0.1 if stops else 2.0, abs=1e-9)  # panel, or the wall at x = 4


# ---------------------------------------------------------------------------- sonar cone
def test_sonar_cone_sees_thin_post_off_axis():
    g = OccupancyGrid.empty(8.0, 8.0, RES)
    cells = g.cells.copy()
    # a one-cell post 2 m away, 6 degrees left of the transducer axis (+x from (2, 4))
    px, py = 2.0 + 2.0 * math.cos(math.radians(6)), 4.0 + 2.0 * math.sin(math.radians(6))
    cells[int(py / RES), int(px / RES)] = WALL
    g = g.with_cells(cells)
    x, y, th = np.array([2.0]), np.array([4.0]), np.array([0.0])
    son = build_range_sensor(
        SonarConfig(n_transducers=1, fov_deg=10.0, cone_deg=15.0, rays_per_cone=11, max_range_m=5.0), g
    )
    r = son.true_ranges(x, y, th)[0, 0]
    assert r == pytest.approx(2.0, abs=2 * RES)
    # a laser beam on the same axis misses the post and sees the map edge 6 m away (capped)
    las = build_range_sensor(laser(n_beams=1, fov_deg=10.0, max_range_m=5.0), g)
    assert las.true_ranges(x, y, th)[0, 0] == pytest.approx(5.0)
    # the reading is exactly the nearest ray of the cone
    caster = RayCaster(g, son.sees, son.max_range_m)
    rays = caster.cast_xyt(x, y, th, son.ray_angles_rad)
    assert r == rays.min()


def test_sonar_ring_is_min_over_each_cone():
    rng = np.random.default_rng(3)
    g = OccupancyGrid((rng.random((60, 60)) < 0.05).astype(np.uint8), RES)
    cfg = SonarConfig(n_transducers=16, cone_deg=20.0, rays_per_cone=5, max_range_m=2.0)
    son = build_range_sensor(cfg, g)
    free = g.free_cells()[rng.choice(len(g.free_cells()), 50)]
    xy = g.cell_centers(free[:, 0], free[:, 1])
    th = rng.uniform(-np.pi, np.pi, 50)
    r = son.true_ranges(xy[:, 0], xy[:, 1], th)
    rays = RayCaster(g, son.sees, 2.0).cast_xyt(xy[:, 0], xy[:, 1], th, son.ray_angles_rad)
    np.testing.assert_array_equal(r, rays.reshape(50, 16, 5).min(axis=2))
    offsets = son.ray_angles_rad.reshape(16, 5) - son.angles_rad[:, None]
    np.testing.assert_allclose(offsets, np.tile(np.radians(np.linspace(-10, 10, 5)), (16, 1)), atol=1e-12)


# ---------------------------------------------------------------------------- noise
def test_gaussian_noise_statistics():
    g = walled_grid(wall_x_m=5.0)
    s = build_range_sensor(laser(n_beams=1, fov_deg=1.0, noise_std_m=0.05), g)
    n = 40_000
    x, y, th = np.full(n, 2.0), np.full(n, 2.0), np.zeros(n)
    obs = s.sense(x, y, th, np.random.default_rng(1))[:, 0]
    res = obs - 3.0
    assert abs(res.mean()) < 5 * 0.05 / math.sqrt(n)
    assert res.std() == pytest.approx(0.05, rel=0.03)


def test_max_and_short_fractions_binomial():
    g = walled_grid(wall_x_m=5.0)
    p_max, p_short = 0.1, 0.2
    s = build_range_sensor(laser(n_beams=10, fov_deg=5.0, noise_std_m=0.0, p_max=p_max, p_short=p_short), g)
    n = 3000
    x, y, th = np.full(n, 2.0), np.full(n, 2.0), np.zeros(n)
    true = s.true_ranges(x, y, th)
    obs = s.sense(x, y, th, np.random.default_rng(2))
    m = obs.size
    is_max = obs == s.max_range_m
    is_short = obs < true - 1e-12
    for frac, p in ((is_max.mean(), p_max), (is_short.mean(), p_short)):
        assert abs(frac - p) < 5 * math.sqrt(p * (1 - p) / m)
    # the rest is the exact true range (no Gaussian part here)
    np.testing.assert_array_equal(obs[~is_max & ~is_short], true[~is_max & ~is_short])
    # short readings are uniform on [0, true): mean true/2, and their quarters equally full
    ratio = obs[is_short] / true[is_short]
    assert ratio.mean() == pytest.approx(0.5, abs=5 * math.sqrt(1 / 12 / ratio.size))
    counts = np.histogram(ratio, bins=4, range=(0, 1))[0]
    assert counts.min() > 0.85 * ratio.size / 4


def test_sonar_specular_fraction():
    g = walled_grid(wall_x_m=3.0)
    s = build_range_sensor(SonarConfig(p_specular=0.25, noise_std_m=0.0, max_range_m=5.0), g)
    n = 1000
    obs = s.sense(np.full(n, 2.0), np.full(n, 2.0), np.zeros(n), np.random.default_rng(4))
    frac = (obs == 5.0).mean()
    true_max = (s.true_ranges(np.array([2.0]), np.array([2.0]), np.array([0.0])) == 5.0).mean()
    assert true_max == 0.0  # every transducer echoes (4 m box) ...
    assert abs(frac - 0.25) < 5 * math.sqrt(0.25 * 0.75 / obs.size)  # ... so max readings are speculars


def test_keyed_normals_are_standard_normal():
    # 1e6 ziggurat normals from the counter-based streams: moments, KS, tail beyond the base strip
    from scipy import stats

    z = (beam_noise_keyed(np.full((1000, 1000), 5.0), 12345, 1.0, 0.0, 0.0, 100.0) - 5.0).ravel()
    n = z.size
    assert abs(z.mean()) < 5 / math.sqrt(n)
    assert z.std() == pytest.approx(1.0, abs=5 * math.sqrt(0.5 / n))
    assert abs(stats.skew(z)) < 5 * math.sqrt(6 / n)
    assert abs(stats.kurtosis(z)) < 5 * math.sqrt(24 / n)
    assert stats.kstest(z, "norm").pvalue > 1e-4
    p_tail = 2 * stats.norm.sf(rs_mod._ZIG_R)  # draws from the ziggurat's tail branch
    assert abs((np.abs(z) > rs_mod._ZIG_R).mean() - p_tail) < 5 * math.sqrt(p_tail / n)
    # neighbouring beams and other keys are uncorrelated
    assert abs(np.corrcoef(z[:-1], z[1:])[0, 1]) < 5 / math.sqrt(n)
    z2 = (beam_noise_keyed(np.full((1000, 1000), 5.0), 12346, 1.0, 0.0, 0.0, 100.0) - 5.0).ravel()
    assert abs(np.corrcoef(z, z2)[0, 1]) < 5 / math.sqrt(n)


def test_keyed_mixture_fractions_and_short_uniform():
    from scipy import stats

    true = np.full((500, 400), 5.0)
    obs = beam_noise_keyed(true, 99, 0.0, 0.3, 0.4, 10.0)
    m = obs.size
    assert abs((obs == 10.0).mean() - 0.3) < 5 * math.sqrt(0.3 * 0.7 / m)
    short = obs < 5.0
    assert abs(short.mean() - 0.4) < 5 * math.sqrt(0.4 * 0.6 / m)
    assert stats.kstest(obs[short] / 5.0, "uniform").pvalue > 1e-4
    np.testing.assert_array_equal(obs[~short & (obs != 10.0)], 5.0)


def test_keyed_noise_deterministic_on_any_thread_count():
    true = np.random.default_rng(0).uniform(0.0, 8.0, (400, 180))
    ser = beam_noise_keyed(true, 2**64 - 1, 0.05, 0.02, 0.03, 8.0)  # serial below NOISE_PARALLEL_MIN_BEAMS
    par = np.empty_like(true)
    rs_mod._counter_noise_parallel(true, np.uint64(2**64 - 1), 0.05, 0.02, 0.03, 8.0, par)
    np.testing.assert_array_equal(par, ser)
    # rows do not depend on the rows around them: a slice of the batch reads the same numbers
    np.testing.assert_array_equal(beam_noise_keyed(true[:7], 2**64 - 1, 0.05, 0.02, 0.03, 8.0), par[:7])
    assert not np.array_equal(beam_noise_keyed(true, 5, 0.05, 0.02, 0.03, 8.0), par)
    inplace = true.copy()
    assert beam_noise_keyed(inplace, 2**64 - 1, 0.05, 0.02, 0.03, 8.0, out=inplace) is inplace
    np.testing.assert_array_equal(inplace, par)
    with pytest.raises(ValueError, match="key must be an integer"):
        beam_noise_keyed(true, -1, 0.05, 0.0, 0.0, 8.0)


def test_sense_draws_one_key_from_the_generator():
    g = walled_grid(wall_x_m=5.0)
    s = build_range_sensor(laser(n_beams=30, noise_std_m=0.05, p_max=0.1, p_short=0.1), g)
    x, y, th = np.full(20, 2.0), np.full(20, 2.0), np.linspace(-1, 1, 20)
    rng = np.random.default_rng(3)
    got = s.sense(x, y, th, rng)
    key_rng = np.random.default_rng(3)
    expect = beam_noise_keyed(s.true_ranges(x, y, th), rs_mod.draw_noise_key(key_rng), 0.05, 0.1, 0.1, 20.0)
    np.testing.assert_array_equal(got, expect)
    assert rng.bit_generator.state == key_rng.bit_generator.state  # one draw, nothing more
    # the engine's unchecked path reads the same
    np.testing.assert_array_equal(s._sense(x, y, th, np.random.default_rng(3)), got)


def test_noise_clipped_to_range_and_deterministic():
    g = walled_grid(wall_x_m=9.0)
    s = build_range_sensor(laser(noise_std_m=0.5, max_range_m=3.0, p_max=0.05, p_short=0.05), g)
    x, y, th = np.full(50, 2.0), np.full(50, 2.0), np.zeros(50)
    a = s.sense(x, y, th, np.random.default_rng(7))
    b = s.sense(x, y, th, np.random.default_rng(7))
    c = s.sense(x, y, th, np.random.default_rng(8))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert a.min() >= 0.0 and a.max() <= 3.0
    out = np.empty_like(a)
    assert s.sense(x, y, th, np.random.default_rng(7), out=out) is out
    np.testing.assert_array_equal(out, a)


# ---------------------------------------------------------------------------- robot bodies
def test_robot_body_blocks_and_own_body_does_not():
    g = walled_grid()
    s = build_range_sensor(laser(n_beams=3, fov_deg=180.0), g)
    all_x, all_y, all_r = np.array([2.0, 4.0]), np.array([2.0, 2.0]), np.array([0.2, 0.3])
    r = s.true_ranges(all_x[:1], all_y[:1], np.zeros(1), bodies=(all_x, all_y, all_r, np.array([0])))[0]
    np.testing.assert_allclose(r, [2.0, 1.7, 2.0], atol=1e-12)  # front beam stops at robot 1's disc
    # no bodies, or a sensor that does not see robots: the wall at 4 m
    assert s.true_ranges(all_x[:1], all_y[:1], np.zeros(1))[0, 1] == pytest.approx(4.0)
    blind = build_range_sensor(laser(n_beams=3, fov_deg=180.0, sees_robots=False), g)
    assert blind.true_ranges(all_x[:1], all_y[:1], np.zeros(1), bodies=(all_x, all_y, all_r, np.array([0])))[0, 1] == (
        pytest.approx(4.0)
    )
    # both robots sense at once; robot 1 faces robot 0 (origin 2 m away, radius 0.2)
    r2 = s.true_ranges(all_x, all_y, np.array([0.0, np.pi]), bodies=(all_x, all_y, all_r, np.array([0, 1])))
    assert r2[1, 1] == pytest.approx(1.8)
    # a robot whose sensor sits inside another's disc reads 0 on every beam
    r3 = s.true_ranges(np.array([3.8]), np.array([2.0]), np.zeros(1), bodies=(all_x, all_y, all_r, np.array([-1])))
    np.testing.assert_array_equal(r3, 0.0)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 120), st.sampled_from([None, 0.3, 1.0]), st.booleans())
def test_robot_hits_hash_matches_brute_force(seed, n_all, cell_m, parallel):
    rng = np.random.default_rng(seed)
    all_x = rng.uniform(0.0, 8.0, n_all)
    all_y = rng.uniform(0.0, 8.0, n_all)
    all_r = rng.uniform(0.05, 0.4, n_all)
    sensing = rng.choice(n_all, size=min(n_all, 30), replace=False)
    th = rng.uniform(-10.0, 10.0, sensing.shape[0])  # unwrapped headings
    # an even ring, or unsorted directions beyond +-pi (e.g. a sonar cone's edge rays)
    angles = beam_angles(37, 2 * np.pi) if seed % 2 else rng.uniform(-3 * np.pi, 3 * np.pi, 37)
    base = rng.uniform(0.0, 2.5, (sensing.shape[0], 37))  # stand-in map ranges (walls at random distances)
    bodies = (all_x, all_y, all_r, sensing.astype(np.int64))
    fast = apply_robot_hits(all_x[sensing], all_y[sensing], th, angles, bodies, base.copy(), 2.5, cell_m=cell_m,
                            parallel=parallel)
    ref = robot_hits_reference(all_x[sensing], all_y[sensing], th, angles, bodies, base.copy())
    np.testing.assert_array_equal(fast, ref)
    assert np.all(fast <= base)


def numpy_robot_hits(xs, ys, thetas, angles, bodies, ranges):
    """Pure-NumPy reference: every ray against every disc by broadcasting (n, N, R)."""
    all_x, all_y, all_r, me = bodies
    dirs = thetas[:, None] + angles[None, :]  # (n, R)
    dx, dy = np.cos(dirs)[:, None, :], np.sin(dirs)[:, None, :]
    fx = (xs[:, None] - all_x[None, :])[:, :, None]
    fy = (ys[:, None] - all_y[None, :])[:, :, None]
    cc = fx**2 + fy**2 - (all_r**2)[None, :, None]
    b = fx * dx + fy * dy
    disc = b**2 - cc
    with np.errstate(invalid="ignore"):
        t = np.where((b < 0) & (disc >= 0), -b - np.sqrt(disc), np.inf)
    t = np.where(cc <= 0, 0.0, t)
    own = me >= 0
    t[np.flatnonzero(own), me[own]] = np.inf  # the sensing robot's own disc
    return np.minimum(ranges, t.min(axis=1))


def test_robot_hits_kernels_match_numpy_reference():
    rng = np.random.default_rng(21)
    n_all = 60
    all_x, all_y, all_r = rng.uniform(0, 6, n_all), rng.uniform(0, 6, n_all), rng.uniform(0.05, 0.3, n_all)
    sensing = np.arange(0, n_all, 3)
    th = rng.uniform(-np.pi, np.pi, sensing.shape[0])
    angles = beam_angles(90, 2 * np.pi)
    base = rng.uniform(0.5, 3.0, (sensing.shape[0], 90))
    bodies = (all_x, all_y, all_r, sensing)
    ref = numpy_robot_hits(all_x[sensing], all_y[sensing], th, angles, bodies, base)
    fast = apply_robot_hits(all_x[sensing], all_y[sensing], th, angles, bodies, base.copy(), 3.0)
    np.testing.assert_allclose(fast, ref, rtol=1e-12, atol=1e-12)
    assert (ref < base).any()


def test_mixture_kernel_matches_numpy_reference():
    rng_true = np.random.default_rng(0)
    true = rng_true.uniform(0.0, 6.0, (200, 50))
    sigma, p_max, p_short, rmax = 0.3, 0.1, 0.15, 5.0
    got = apply_beam_noise(true, np.random.default_rng(3), sigma, p_max, p_short, rmax)
    g = np.random.default_rng(3)  # the documented draws, in order
    z = g.standard_normal(true.shape)
    u = g.random(true.shape)
    expect = np.clip(true + sigma * z, 0.0, rmax)
    expect = np.where(u < p_max + p_short, true * (u - p_max) / p_short, expect)
    expect = np.where(u < p_max, rmax, expect)
    np.testing.assert_allclose(got, expect, rtol=1e-15, atol=0)


def test_fast_atan2_error_bound():
    from numba import njit

    f = njit(lambda y, x: rh_mod._fast_atan2(y, x))
    rng = np.random.default_rng(5)
    pts = np.concatenate([rng.normal(size=(20000, 2)) * 10.0 ** rng.uniform(-6, 3, (20000, 1)),
                          [[0.0, 1.0], [1.0, 0.0], [0.0, -1.0], [-1.0, 0.0], [1.0, 1.0], [-1.0, -1.0], [0.0, 0.0]]])
    err = max(abs(f(py, px) - math.atan2(py, px)) for py, px in pts)
    assert err < 4e-8 < rh_mod._ANGLE_MARGIN_RAD / 10


def test_beam_plan_even_fans():
    for n, fov in ((180, np.pi), (181, np.pi), (360, 2 * np.pi), (7, 2 * np.pi), (1, 1.0), (5, 0.3)):
        plan = rh_mod.beam_plan(beam_angles(n, fov))
        assert plan.even[0], (n, fov)
        np.testing.assert_array_equal(plan.beams[3], np.arange(n))
    assert rh_mod.beam_plan(beam_angles(180, np.pi)).even[3]  # a half-turn fan: half-plane cull on
    assert not rh_mod.beam_plan(beam_angles(36, 2 * np.pi)).even[3]
    assert not rh_mod.beam_plan(np.array([0.0, 0.1, 0.3])).even[0]  # uneven: binary search
    assert not rh_mod.beam_plan(np.array([0.0, 0.1, 0.1])).even[0]  # repeated direction


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([(180, 180.0), (181, 180.0), (90, 120.0), (64, 360.0), (1, 1.0),
                                                   (12, 350.0)]), st.booleans())
def test_robot_hits_even_fans_match_brute_force(seed, fan, parallel):
    # crowded discs (touching, overlapping, some radius 0) around sensors on even fans, where the
    # windows are computed by arithmetic and discs behind a <= 180 deg fan are culled early
    rng = np.random.default_rng(seed)
    n_all = int(rng.integers(2, 150))
    side = float(rng.choice([0.5, 3.0, 15.0]))
    all_x, all_y = rng.uniform(0.0, side, n_all), rng.uniform(0.0, side, n_all)
    all_r = rng.choice([0.0, 0.05, 0.2, 0.5], n_all)
    sensing = rng.choice(n_all, size=min(n_all, 25), replace=False)
    th = rng.uniform(-7.0, 7.0, sensing.shape[0])
    angles = beam_angles(fan[0], math.radians(fan[1])) + rng.choice([0.0, rng.uniform(-4, 4)])
    base = rng.uniform(0.0, float(rng.choice([1.0, 20.0])), (sensing.shape[0], fan[0]))
    bodies = (all_x, all_y, all_r, sensing.astype(np.int64))
    fast = apply_robot_hits(all_x[sensing], all_y[sensing], th, angles, bodies, base.copy(), 20.0, parallel=parallel)
    ref = robot_hits_reference(all_x[sensing], all_y[sensing], th, angles, bodies, base.copy())
    np.testing.assert_array_equal(fast, ref)


def test_robot_hits_disc_abeam_of_a_half_turn_fan():
    # discs exactly beside the sensor (bearing +-90 deg: the fan's edge rays) and just behind it
    angles = beam_angles(181, np.pi)
    all_x = np.array([0.0, 0.0, 0.0, -0.25, -0.35])
    all_y = np.array([0.0, 2.0, -3.0, 1.0, -1.0])
    all_r = np.array([0.1, 0.2, 0.2, 0.3, 0.3])
    bodies = (all_x, all_y, all_r, np.array([0]))
    fast = apply_robot_hits(np.zeros(1), np.zeros(1), np.zeros(1), angles, bodies, np.full((1, 181), 9.0), 9.0)
    ref = robot_hits_reference(np.zeros(1), np.zeros(1), np.zeros(1), angles, bodies, np.full((1, 181), 9.0))
    np.testing.assert_array_equal(fast, ref)
    assert fast[0, -1] == pytest.approx(1.0 - math.sqrt(0.3**2 - 0.25**2)) and fast[0, 0] == pytest.approx(2.8)


def test_robot_hits_reference_geometry():
    # ray from the origin along +x; disc of radius 0.5 at (2, 0.3): hit at 2 - sqrt(0.25 - 0.09) = 1.6
    r = robot_hits_reference(np.zeros(1), np.zeros(1), np.zeros(1), np.array([0.0, 0.5, np.pi]),
                             (np.array([2.0]), np.array([0.3]), np.array([0.5]), np.array([-1])), np.full((1, 3), 9.0))
    assert r[0, 0] == pytest.approx(1.6)
    assert r[0, 2] == 9.0  # behind
    # ray at 0.5 rad: distance from centre to the ray line = |2 sin 0.5 - 0.3 cos 0.5| = 0.695 > 0.5: miss
    assert r[0, 1] == 9.0


def test_many_robots_scale_with_bodies():
    # 1000 robots x 180 beams in a 60 m square: fast path equals reference on a sample of robots
    rng = np.random.default_rng(11)
    g = OccupancyGrid.empty(60.0, 60.0, 0.1)
    n = 1000
    xs, ys, th = rng.uniform(1, 59, n), rng.uniform(1, 59, n), rng.uniform(-np.pi, np.pi, n)
    rad = np.full(n, 0.2)
    s = build_range_sensor(laser(n_beams=180, fov_deg=360.0, max_range_m=5.0), g)
    bodies = (xs, ys, rad, np.arange(n))
    r = s.true_ranges(xs, ys, th, bodies=bodies)
    sub = np.arange(0, n, 50)
    ref = s.caster.cast_xyt(xs[sub], ys[sub], th[sub], s.ray_angles_rad)
    robot_hits_reference(xs[sub], ys[sub], th[sub], s.ray_angles_rad, (xs, ys, rad, sub), ref)
    np.testing.assert_array_equal(r[sub], ref)
    assert (r < 5.0).mean() > 0.05  # robots are actually hit


# ---------------------------------------------------------------------------- bad input
def test_bad_input_names_parameter():
    g = walled_grid()
    with pytest.raises(ValueError, match="cfg must be"):
        build_range_sensor({"kind": "laser"}, g)
    with pytest.raises(ValueError, match="grid must be"):
        build_range_sensor(laser(), np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"sum to <= 1.*0.7 \+ 0.6"):
        build_range_sensor(laser(p_max=0.7, p_short=0.6), g)
    with pytest.raises(ValueError, match="p_max \\+ p_short"):
        apply_beam_noise(np.ones((1, 1)), np.random.default_rng(0), 0.0, 0.8, 0.3, 5.0)
    with pytest.raises(ValueError, match="rng must be a numpy.random.Generator"):
        apply_beam_noise(np.ones((1, 1)), 0, 0.0, 0.0, 0.0, 5.0)
    s = build_range_sensor(laser(), g)
    with pytest.raises(ValueError, match=r"bodies\[2\] \(all_radius\).*\(2,\)"):
        s.true_ranges(np.array([2.0]), np.array([2.0]), np.zeros(1),
                      bodies=(np.zeros(2), np.zeros(2), np.zeros(3), np.array([0])))
    with pytest.raises(ValueError, match="bodies must be a tuple"):
        s.true_ranges(np.array([2.0]), np.array([2.0]), np.zeros(1), bodies=[1, 2])
    with pytest.raises(ValueError, match="ys"):
        s.true_ranges(np.array([2.0]), np.array([2.0, 3.0]), np.zeros(1))
    with pytest.raises(ValueError, match="fov_rad"):
        beam_angles(3, 7.0)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 400), st.booleans())
def test_robot_hits_sparse_swarm_matches_brute_force(seed, n_all, parallel):
    """A sparse swarm (most robots see nobody, as 10 000 Thymios in a 100 m arena): rows
    whose rays reach no other disc are skipped after a first look at the hash, chunks of
    sensing robots share scratch; the rows equal every ray against every disc."""
    rng = np.random.default_rng(seed)
    side = math.sqrt(n_all) * float(rng.choice([0.3, 1.0]))
    all_x = rng.uniform(0.0, side, n_all)
    all_y = rng.uniform(0.0, side, n_all)
    all_r = np.full(n_all, 0.08) if seed % 2 else rng.uniform(0.0, 0.2, n_all)
    angles = np.radians([-40.0, -20.0, 0.0, 20.0, 40.0, 150.0, -150.0]) if seed % 3 else beam_angles(9, np.pi)
    sensing = np.arange(n_all) if rng.random() < 0.5 else rng.choice(n_all, size=(n_all + 1) // 2, replace=False)
    th = rng.uniform(-10.0, 10.0, sensing.shape[0])
    base = np.full((sensing.shape[0], angles.shape[0]), 0.14)
    base[rng.random(base.shape) < 0.2] = rng.uniform(0.0, 0.14)  # walls in some rays
    base[rng.random(sensing.shape[0]) < 0.05] = 0.0  # a robot against a wall: nothing to test
    bodies = (all_x, all_y, all_r, sensing.astype(np.int64))
    fast = apply_robot_hits(all_x[sensing], all_y[sensing], th, angles, bodies, base.copy(), 0.14, parallel=parallel)
    ref = robot_hits_reference(all_x[sensing], all_y[sensing], th, angles, bodies, base.copy())
    np.testing.assert_array_equal(fast, ref)
