"""The one-pass sensing kernel against the former cast -> robot bodies -> noise path.

``RangeSensor._pass`` casts each robot's rays only up to the nearest other robot's disc met
first, in one numba loop per robot; everything here checks that it gives the former ranges
bit for bit: the map cast of :func:`cast_rays`, cut by :func:`robot_hits_reference` (every
ray against every disc), the nearest ray of each beam, then :func:`beam_noise_keyed`.
"""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from teamnav.sim.config import LaserConfig, ProximityConfig, SonarConfig
from teamnav.sim.sensors import range_sensors as rs_mod
from teamnav.sim.sensors import robot_hits as rh_mod
from teamnav.sim.sensors.range_sensors import beam_noise_keyed, build_range_sensor
from teamnav.sim.sensors.robot_hits import beam_plan, robot_hits_reference
from teamnav.world import raycast as rc_mod
from teamnav.world.grid import WALL, OccupancyGrid
from teamnav.world.raycast import cast_rays


def random_grid(rng, res, yaw=0.0):
    h, w = int(rng.integers(20, 90)), int(rng.integers(20, 90))
    cells = np.zeros((h, w), np.uint8)
    for _ in range(int(rng.integers(0, 12))):  # walls and blocks
        r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
        cells[r0:r0 + int(rng.integers(1, 15)), c0:c0 + int(rng.integers(1, 4))] = WALL
        cells[r0:r0 + int(rng.integers(1, 3)), c0:c0 + int(rng.integers(1, 15))] = WALL
    return OccupancyGrid(cells, res, (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3))), yaw_rad=yaw)


def sensor_for(kind, rng, max_range, grid):
    if kind == "laser":
        cfg = LaserConfig(n_beams=int(rng.integers(1, 200)), fov_deg=float(rng.choice([90.0, 180.0, 270.0, 360.0])),
                          max_range_m=max_range, noise_std_m=0.01, p_max=0.05, p_short=0.05, sees_robots=True)
    elif kind == "sonar":
        cfg = SonarConfig(n_transducers=int(rng.integers(1, 16)), rays_per_cone=int(rng.integers(1, 6)),
                          max_range_m=max_range, sees_robots=True)
    else:
        cfg = ProximityConfig(angles_deg=tuple(float(a) for a in rng.uniform(-400, 400, int(rng.integers(1, 9)))),
                              max_range_m=min(max_range, 10.0), sees_robots=True)
    return build_range_sensor(cfg, grid)


def former(sensor, xs, ys, th, bodies, key):
    """The ranges the engine computed before the one-pass kernel: cast, bodies, nearest ray, noise."""
    g = sensor.caster.grid
    kx, ky, ox, oy = g.kernel_frame(xs, ys)
    rays = cast_rays(sensor.caster.blocking, ox, oy, g.resolution_m, kx, ky, g.kernel_theta(th),
                     sensor.ray_angles_rad, sensor.max_range_m, parallel=False)
    if bodies is not None:
        robot_hits_reference(xs, ys, th, sensor.ray_angles_rad, bodies, rays)
    n, nb = xs.shape[0], sensor.angles_rad.shape[0]
    true = rays if sensor.rays_per_beam == 1 else rays.reshape(n, nb, sensor.rays_per_beam).min(axis=2)
    if key is None:
        return true
    return beam_noise_keyed(true, key, sensor.noise_std_m, sensor.p_max, sensor.p_short, sensor.max_range_m)


def grazing_bodies(rng, sensor, xs, ys, th, n_extra):
    """Random discs plus discs tangent to a ray (within a few ulps) and discs whose front is
    at (about) the map range of a ray: the cases where the cap or the window could slip."""
    g = sensor.caster.grid
    kx, ky, ox, oy = g.kernel_frame(xs, ys)
    maps = cast_rays(sensor.caster.blocking, ox, oy, g.resolution_m, kx, ky, g.kernel_theta(th),
                     sensor.ray_angles_rad, sensor.max_range_m, parallel=False)
    bx, by, br = [], [], []
    for _ in range(n_extra):
        i = int(rng.integers(0, xs.shape[0]))
        b = int(rng.integers(0, sensor.ray_angles_rad.shape[0]))
        a = th[i] + sensor.ray_angles_rad[b]
        dx, dy = math.cos(a), math.sin(a)
        r = float(rng.uniform(0.05, 0.4))
        kind = int(rng.integers(0, 3))
        if kind == 0:  # tangent to ray b at a random distance
            t = float(rng.uniform(0.0, sensor.max_range_m))
            side = 1.0 if rng.random() < 0.5 else -1.0
            eps = float(rng.choice([0.0, 1e-15, -1e-15, 1e-12, -1e-12]))
            cx = xs[i] + t * dx - side * (r + eps) * dy
            cy = ys[i] + t * dy + side * (r + eps) * dx
        elif kind == 1:  # front surface at the map range of ray b (a hit equal to the cap)
            t = float(maps[i, b]) + float(rng.choice([0.0, 1e-13, -1e-13, 1e-9, -1e-9]))
            t += int(rng.integers(-3, 4)) * float(np.spacing(t))
            cx, cy = xs[i] + (t + r) * dx, ys[i] + (t + r) * dy
        else:  # the sensor on the disc's rim, or just inside / outside it
            e = float(rng.choice([0.0, 1e-12, -1e-12]))
            cx, cy = xs[i] + (r + e) * dx, ys[i] + (r + e) * dy
        bx.append(cx)
        by.append(cy)
        br.append(r)
    return np.array(bx), np.array(by), np.array(br)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1), st.sampled_from(["laser", "sonar", "proximity"]), st.booleans(),
       st.sampled_from([0.05, 0.1, 0.25]), st.sampled_from([0.0, 0.0, 0.7]), st.booleans())
def test_one_pass_matches_former_path_bit_for_bit(seed, kind, parallel, res, yaw, always_one_pass):
    rng = np.random.default_rng(seed)
    grid = random_grid(rng, res, yaw)
    max_range = float(rng.choice([0.5, 3.0, 10.0, 40.0]))
    sensor = sensor_for(kind, rng, max_range, grid)
    n_all = int(rng.integers(1, 80))
    lo = grid.local_to_world(np.array([[-1.0, -1.0]]))[0]
    span = max(grid.cells.shape) * res + 2.0
    all_x = lo[0] + rng.uniform(0.0, span, n_all)
    all_y = lo[1] + rng.uniform(0.0, span, n_all)
    all_r = rng.uniform(0.0, 0.5, n_all)
    sensing = np.sort(rng.choice(n_all, size=int(rng.integers(1, n_all + 1)), replace=False))
    xs, ys = all_x[sensing].copy(), all_y[sensing].copy()
    th = rng.uniform(-10.0, 10.0, sensing.shape[0])
    if rng.random() < 0.3:  # axis-parallel and diagonal headings
        th = rng.choice([0.0, math.pi / 2, -math.pi, math.pi / 4, 3 * math.pi / 4], sensing.shape[0])
    gx, gy, gr = grazing_bodies(rng, sensor, xs, ys, th, int(rng.integers(0, 40)))
    all_x, all_y, all_r = np.concatenate([all_x, gx]), np.concatenate([all_y, gy]), np.concatenate([all_r, gr])
    bodies = (all_x, all_y, all_r, sensing.astype(np.int64))
    key = int(rng.integers(0, 2**63))
    old = rs_mod.PARALLEL_MIN_RAYS, rs_mod.ONE_PASS_MIN_RAYS
    try:
        rs_mod.PARALLEL_MIN_RAYS = 0 if parallel else 10**12
        if always_one_pass:  # also the few-ray sensors through the one-pass kernel
            rs_mod.ONE_PASS_MIN_RAYS = 0
        got = sensor._pass(xs, ys, th, bodies, key)
        got_true = sensor._pass(xs, ys, th, bodies, None)
        got_map = sensor._pass(xs, ys, th, None, None)
    finally:
        rs_mod.PARALLEL_MIN_RAYS, rs_mod.ONE_PASS_MIN_RAYS = old
    np.testing.assert_array_equal(got_true, former(sensor, xs, ys, th, bodies, None))
    np.testing.assert_array_equal(got, former(sensor, xs, ys, th, bodies, key))
    np.testing.assert_array_equal(got_map, former(sensor, xs, ys, th, None, None))


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_capped_cast_is_min_of_cast_and_cap(seed):
    """_cast_pose_capped == min(_cast_serial, cap), caps at, just below and above the map range."""
    rng = np.random.default_rng(seed)
    res = float(rng.choice([0.05, 0.1, 1.0]))
    grid = random_grid(rng, res)
    clear = rc_mod.clearance_map(grid.blocking(None))
    n, nb = 20, int(rng.integers(1, 64))
    xs = grid.origin_xy_m[0] + rng.uniform(-1.0, grid.cells.shape[1] * res + 1.0, n)
    ys = grid.origin_xy_m[1] + rng.uniform(-1.0, grid.cells.shape[0] * res + 1.0, n)
    th = rng.uniform(-4.0, 4.0, n)
    ang = rng.uniform(-math.pi, math.pi, nb)
    ct, st_, cb, sb = np.cos(th), np.sin(th), np.cos(ang), np.sin(ang)
    tmax = float(rng.choice([0.3, 5.0, 50.0])) / res
    full = np.empty((n, nb))
    ox, oy = grid.origin_xy_m
    rc_mod._cast_serial(clear, ox, oy, res, xs, ys, ct, st_, cb, sb, tmax, full, 0, n)
    scratch = [np.empty(nb), np.empty(nb), np.empty(nb), np.empty(nb), np.empty(nb, np.int64), np.empty(nb, np.int64),
               np.empty(nb, np.uint8), np.empty(nb, np.int64), np.empty(nb, np.int64)]
    for p in range(n):
        m = full[p]
        cap = np.where(rng.random(nb) < 0.5, m, rng.uniform(0.0, tmax * res * 1.2, nb))
        cap = cap * rng.choice([1.0, 1.0 + 1e-10, 1.0 - 1e-10, 1.5, 0.5], nb)
        ulps = rng.choice([0, 0, 1, -1, 2, -2, 5, -5], nb)  # caps a few ulps from the map range
        cap = np.maximum(0.0, cap + ulps * np.spacing(cap))
        cap[rng.random(nb) < 0.1] = np.inf
        cap[rng.random(nb) < 0.1] = 0.0
        out = np.empty(nb)
        inv = 1.0 / res
        rc_mod._cast_pose_capped(clear, (xs[p] - ox) * inv, (ys[p] - oy) * inv, res, ct[p], st_[p], cb, sb, tmax, cap,
                                 True, out, *scratch)
        np.testing.assert_array_equal(out, np.minimum(m, cap))
        rc_mod._cast_pose_capped(clear, (xs[p] - ox) * inv, (ys[p] - oy) * inv, res, ct[p], st_[p], cb, sb, tmax, cap,
                                 False, out, *scratch)
        np.testing.assert_array_equal(out, m)


def _random_discs_and_fan(rng, seed, max_discs, fan_rays, random_rays):
    """1..max_discs discs in a 12 m square (radii up to 0.5 m), an even half-turn fan of
    ``fan_rays`` rays (odd seeds) or ``random_rays`` random directions, the fan's plan and
    the discs' hash (cell side default, 0.7 or 1.5 m)."""
    n_all = int(rng.integers(1, max_discs))
    all_x = rng.uniform(0.0, 12.0, n_all)
    all_y = rng.uniform(0.0, 12.0, n_all)
    all_r = rng.uniform(0.0, 0.5, n_all)
    angles = np.linspace(-math.pi / 2, math.pi / 2, fan_rays) if seed % 2 else rng.uniform(-4.0, 4.0, random_rays)
    hsh = rh_mod._prepare(all_x, all_y, all_r, 10.0, float(rng.choice([0.0, 0.7, 1.5])))
    return n_all, all_x, all_y, all_r, angles, beam_plan(angles), hsh


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 6.0), st.floats(0.0, 12.0))
def test_two_reaches_test_every_disc_once(seed, inner, reach):
    """Discs within `inner`, then those beyond it up to `reach`: the same rows as one call
    (and as every ray against every disc, for the discs that matter)."""
    rng = np.random.default_rng(seed)
    n_all, all_x, all_y, all_r, angles, plan, hsh = _random_discs_and_fan(rng, seed, 150, 181, 40)
    nb = angles.shape[0]
    for i in range(min(n_all, 10)):
        th = float(rng.uniform(-7.0, 7.0))
        ct, st_ = math.cos(th), math.sin(th)
        base = rng.uniform(0.0, reach, nb) if rng.random() < 0.5 else np.full(nb, reach)
        one = base.copy()
        rh_mod._robot_hits_row(all_x[i], all_y[i], ct, st_, i, 0.0, reach, plan.beams, plan.even, hsh, one,
                               np.empty(nb), np.empty(nb), True, rh_mod._ALL)
        two = base.copy()
        rdx, rdy = np.empty(nb), np.empty(nb)
        rh_mod._robot_hits_row(all_x[i], all_y[i], ct, st_, i, 0.0, min(inner, reach), plan.beams, plan.even, hsh, two,
                               rdx, rdy, True, rh_mod._ALL)
        rh_mod._robot_hits_row(all_x[i], all_y[i], ct, st_, i, min(inner, reach), reach, plan.beams, plan.even, hsh,
                               two, rdx, rdy, False, rh_mod._ALL)
        np.testing.assert_array_equal(two, one)
        if reach >= base.max():
            ref = base[None, :].copy()
            robot_hits_reference(all_x[i:i + 1], all_y[i:i + 1], np.array([th]), angles,
                                 (all_x, all_y, all_r, np.array([i])), ref)
            np.testing.assert_array_equal(one, ref[0])


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(2.0, 9.0), st.sampled_from([0.5, 0.7, 1.5]), st.booleans())
def test_clipped_columns_keep_discs_at_the_reach_and_behind_the_fan(seed, reach, cell, half_turn):
    """A wide window reads in each hash column only the rows that can hold a disc the culls
    keep: discs whose front is just inside the reach (any direction, the largest radius) and
    discs centred behind a half-turn fan's half-plane that still cross its edge rays are
    met, as when every ray is tested against every disc."""
    rng = np.random.default_rng(seed)
    px, py = rng.uniform(-3.0, 3.0, 2)
    th = float(rng.uniform(-7.0, 7.0))
    width = math.pi if half_turn else float(rng.uniform(0.5, 3.0))
    angles = np.linspace(-width / 2, width / 2, int(rng.choice([31, 181])))
    plan = beam_plan(angles)
    rmax = 0.45
    xs, ys, rs = [px], [py], [0.2]
    for _ in range(60):
        kind = int(rng.integers(0, 3))
        r = float(rng.choice([rmax, rmax, 0.2, 0.01]))
        delta = float(rng.choice([0.0, 1e-12, 1e-9, 1e-6, 1e-3, 0.1]))
        if kind == 0:  # front just inside the reach, often straight along an axis (the circle's extremes)
            a = th + float(rng.uniform(-width / 2, width / 2))
            axis = float(rng.choice([0.0, 0.5, 1.0, -0.5])) * math.pi
            if rng.random() < 0.5 and abs(math.remainder(axis - th, 2 * math.pi)) < width / 2:
                a = axis
            d = reach + r - delta
            xs.append(px + d * math.cos(a))
            ys.append(py + d * math.sin(a))
        elif kind == 1:  # centred behind the half-plane, crossing an edge ray
            a = th + (width / 2 if rng.random() < 0.5 else -width / 2)
            t = float(rng.uniform(0.0, reach))
            back = th + math.pi  # the fan's middle turned round
            off = r - delta
            xs.append(px + t * math.cos(a) + off * math.cos(back))
            ys.append(py + t * math.sin(a) + off * math.sin(back))
        else:
            xs.append(px + float(rng.uniform(-reach - 1, reach + 1)))
            ys.append(py + float(rng.uniform(-reach - 1, reach + 1)))
        rs.append(r)
    all_x, all_y, all_r = np.array(xs), np.array(ys), np.array(rs)
    hsh = rh_mod._prepare(all_x, all_y, all_r, 10.0, cell)
    nb = angles.shape[0]
    got = np.full(nb, reach)
    rh_mod._robot_hits_row(px, py, math.cos(th), math.sin(th), 0, 0.0, reach, plan.beams, plan.even, hsh, got,
                           np.empty(nb), np.empty(nb), True, rh_mod._ALL)
    want = np.full((1, nb), reach)
    robot_hits_reference(np.array([px]), np.array([py]), np.array([th]), angles, (all_x, all_y, all_r, np.array([0])),
                         want)
    np.testing.assert_array_equal(got, want[0])


@pytest.mark.parametrize("axis", [0, 1, 2, 3])
@pytest.mark.parametrize("cell", [0.7, 1.5])
def test_clipped_rows_keep_a_disc_just_past_a_row_boundary_at_the_reach(axis, cell):
    """The row clipping's circle, on its tight side: a disc of the largest radius straight
    ahead along an axis, its front 0.1 mm inside the reach and its centre 1 mm past a hash row
    (column) boundary, the boundary the clipped range must not stop short of."""
    c, s_ = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][axis]
    rmax, delta, eps = 0.45, 1e-4, 1e-3
    lo_corner = -8.0  # an anchor disc there sets the hash's origin: boundaries at lo_corner + k cell
    if c + s_ > 0:  # ahead along +x or +y: the centre just past the first boundary beyond 5.5 m
        target = lo_corner + math.ceil((5.5 - lo_corner) / cell) * cell + eps
    else:  # along -x or -y: just before (below) the last boundary under -5.5 m
        target = lo_corner + math.floor((-5.5 - lo_corner) / cell) * cell - eps
    dist = abs(target)
    reach = dist - rmax + delta
    # 250 small discs out of reach at the far corner: enough discs for the hash to keep `cell`
    xs = [0.0, lo_corner, abs(c) * target] + [12.0] * 250
    ys = [0.0, lo_corner, abs(s_) * target] + [12.0] * 250
    rs = [0.2, 0.01, rmax] + [0.01] * 250
    all_x, all_y, all_r = np.array(xs), np.array(ys), np.array(rs)
    th = math.atan2(s_, c)
    angles = np.linspace(-math.pi / 2, math.pi / 2, 181)
    plan = beam_plan(angles)
    hsh = rh_mod._prepare(all_x, all_y, all_r, 10.0, cell)
    assert (hsh[5], hsh[6], hsh[7]) == (lo_corner, lo_corner, cell)
    got = np.full(181, reach)
    rh_mod._robot_hits_row(0.0, 0.0, math.cos(th), math.sin(th), 0, 0.0, reach, plan.beams, plan.even, hsh, got,
                           np.empty(181), np.empty(181), True, rh_mod._ALL)
    want = np.full((1, 181), reach)
    robot_hits_reference(np.zeros(1), np.zeros(1), np.array([th]), angles, (all_x, all_y, all_r, np.array([0])), want)
    assert want[0, 90] < reach - 0.5 * delta  # the middle ray meets the disc
    np.testing.assert_array_equal(got, want[0])


def test_basement_team_matches_former_path():
    """1000 robots on the MIT basement map, as bench_engine's laser case: bit for bit, serial and parallel."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from bench_engine import build_sim

    sim = build_sim("laser", "batched", 1000, seed=4)
    for _ in range(3):
        sim.step()
    grp = sim._groups[0]
    sensor, bodies = grp.sensors[0], grp.bodies[0]
    s = sim.state
    xs, ys, th = s.x_m.copy(), s.y_m.copy(), s.theta_rad.copy()
    want = former(sensor, xs, ys, th, bodies, 12345)
    threads = numba.get_num_threads()
    try:
        for t in sorted({1, threads}):
            numba.set_num_threads(t)
            np.testing.assert_array_equal(sensor._pass(xs, ys, th, bodies, 12345), want)
    finally:
        numba.set_num_threads(threads)


@pytest.mark.parametrize("mod", [rs_mod, rh_mod, rc_mod])
def test_every_kernel_is_cached(mod):
    from numba.core.caching import NullCache
    from numba.core.registry import CPUDispatcher

    kernels = [v for v in vars(mod).values() if isinstance(v, CPUDispatcher) and v.__module__ == mod.__name__]
    assert kernels
    for k in kernels:
        assert not isinstance(k._cache, NullCache), f"{mod.__name__}.{k.__name__} lacks cache=True"


@pytest.mark.parametrize("heading", [0.0, 0.3, math.pi / 2, -2.5, math.pi])
@pytest.mark.parametrize("gap", [2e-9, 1e-7, 1e-3, 0.2])
@pytest.mark.parametrize("open_space", [True, False])
def test_disc_just_beyond_the_near_ring_on_a_lone_long_ray(heading, gap, open_space):
    """A disc met after the cast (just beyond the near reach: ``_OPEN_NEAR_M`` in open space,
    ``_NEAR_M`` with a wall within 4 m) on the only ray that runs far: the box of that ray's
    segment must hold it, however thin (one beam, small radii)."""
    cells = np.zeros((800, 800), np.uint8)
    if not open_space:  # a wall 3 m behind the pose: less than _NEAR_M of free map around it
        cells[:, 340] = WALL
    grid = OccupancyGrid(cells, 0.05, (-20.0, -20.0))
    sensor = build_range_sensor(LaserConfig(n_beams=1, fov_deg=1.0, max_range_m=10.0, noise_std_m=0.0,
                                            sees_robots=True), grid)
    if not open_space:
        heading = math.copysign(min(abs(heading), 1.0), heading) if heading else 0.0  # away from the wall
    r = 0.02
    near = rs_mod._OPEN_NEAR_M if open_space else rs_mod._NEAR_M
    t = near + gap
    cx, cy = (t + r) * math.cos(heading), (t + r) * math.sin(heading)
    bodies = (np.array([0.0, cx, 9.0]), np.array([0.0, cy, 9.0]), np.array([0.01, r, 0.01]), np.array([0]))
    xs, ys, th = np.zeros(1), np.zeros(1), np.array([heading])
    got = sensor._pass(xs, ys, th, bodies, None)
    np.testing.assert_array_equal(got, former(sensor, xs, ys, th, bodies, None))
    assert got[0, 0] < t + 1e-6


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1), st.booleans(), st.sampled_from([1, 3, 45, 181]))
def test_far_discs_grazing_the_segments_of_long_rays(seed, open_space, n_beams):
    """Runs of rays still longer than the near reach after the cast test the discs of the box
    around their segments (up to ``_FAR_RUN`` rays a box): discs beyond the near reach that
    graze a long ray (centred up to a radius off it, within a few ulps of tangent), that sit just past the
    segment's start or with their front just before its end, and larger discs than the rest
    (the box's margin is the largest radius): the former path's ranges bit for bit."""
    rng = np.random.default_rng(seed)
    cells = np.zeros((800, 800), np.uint8)
    if not open_space:
        cells[:, 340] = WALL  # 3 m behind the pose
    grid = OccupancyGrid(cells, 0.05, (-20.0, -20.0))
    fov = float(rng.choice([20.0, 90.0, 180.0]))
    sensor = build_range_sensor(LaserConfig(n_beams=n_beams, fov_deg=fov, max_range_m=10.0, noise_std_m=0.0,
                                            sees_robots=True), grid)
    heading = float(rng.uniform(-1.0, 1.0)) if not open_space else float(rng.uniform(-4.0, 4.0))
    near = rs_mod._OPEN_NEAR_M if open_space else rs_mod._NEAR_M
    angles = heading + sensor.ray_angles_rad
    bx, by, br = [0.0], [0.0], [0.2]
    for _ in range(int(rng.integers(1, 12))):
        a = float(angles[int(rng.integers(0, angles.shape[0]))])
        dx, dy = math.cos(a), math.sin(a)
        r = float(rng.choice([0.01, 0.2, 0.45]))
        kind = int(rng.integers(0, 3))
        if kind == 0:  # grazing: centred up to a radius off the ray, beyond the near reach
            t = near + float(rng.uniform(0.0, 10.0 - near))
            tangent = r + float(rng.choice([0.0, 1e-15, -1e-15, 1e-12, -1e-12]))
            off = tangent * float(rng.choice([1.0, rng.uniform(0, 1)]))
            side = 1.0 if rng.random() < 0.5 else -1.0
            cx, cy = t * dx - side * off * dy, t * dy + side * off * dx
        elif kind == 1:  # front just past the near reach
            t = near + float(rng.choice([2e-9, 1e-7, 1e-3, 0.3]))
            cx, cy = (t + r) * dx, (t + r) * dy
        else:  # front just before the range's end
            t = 10.0 - float(rng.choice([1e-9, 1e-6, 0.05]))
            cx, cy = (t + r) * dx, (t + r) * dy
        bx.append(cx)
        by.append(cy)
        br.append(r)
    bodies = (np.array(bx), np.array(by), np.array(br), np.array([0]))
    xs, ys, th = np.zeros(1), np.zeros(1), np.array([heading])
    old = rs_mod.PARALLEL_MIN_RAYS
    try:
        rs_mod.PARALLEL_MIN_RAYS = 10**12
        got = sensor._pass(xs, ys, th, bodies, None)
    finally:
        rs_mod.PARALLEL_MIN_RAYS = old
    np.testing.assert_array_equal(got, former(sensor, xs, ys, th, bodies, None))


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(-30.0, 30.0), st.floats(-30.0, 30.0), st.floats(0.1, 20.0))
def test_a_far_box_anywhere_reads_only_the_hash_grid(seed, bx, by, side):
    """A box that misses the hash grid (beyond every disc: the far box of a long free ray)
    tests nothing and reads nothing past the grid's cell table; any box gives rows between
    "every disc" and "only the discs centred in the box" (cells are coarser than the box).

    Runs the kernel as plain Python (``py_func``), where an index past an array raises:
    compiled, the read past ``start`` was silent or, now and then, a segfault that killed
    sweep workers (the sporadic worker deaths that da79e90, 2026-11-27, fixed)."""
    rng = np.random.default_rng(seed)
    n_all, all_x, all_y, all_r, angles, plan, hsh = _random_discs_and_fan(rng, seed, 40, 61, 20)
    nb = angles.shape[0]
    box = (bx, bx + side, by, by + side)
    i = int(rng.integers(0, n_all))
    th = float(rng.uniform(-4.0, 4.0))
    base = np.full(nb, 30.0)
    got = base.copy()
    rh_mod._robot_hits_row.py_func(all_x[i], all_y[i], math.cos(th), math.sin(th), i, 0.0, 30.0, plan.beams,
                                   plan.even, hsh, got, np.empty(nb), np.empty(nb), True, box)
    every = base[None, :].copy()
    robot_hits_reference(all_x[i:i + 1], all_y[i:i + 1], np.array([th]), angles, (all_x, all_y, all_r, np.array([i])),
                         every)
    inside = (all_x >= box[0]) & (all_x <= box[1]) & (all_y >= box[2]) & (all_y <= box[3])
    boxed = base[None, :].copy()
    me = int(np.cumsum(inside)[i] - 1) if inside[i] else -1
    robot_hits_reference(all_x[i:i + 1], all_y[i:i + 1], np.array([th]), angles,
                         (all_x[inside], all_y[inside], all_r[inside], np.array([me])), boxed)
    assert np.all(every[0] <= got) and np.all(got <= boxed[0])


def test_a_box_above_the_last_cell_column_regression():
    """The case that crashed: the sensing robot in the grid's last column, its far box wholly
    above the grid (ky0 > nky - 1 made ``start[kx * nky + ky0]`` read past the table)."""
    all_x = np.array([0.0, 5.0])
    all_y = np.array([0.0, 5.0])
    all_r = np.array([0.25, 0.25])
    hsh = rh_mod._prepare(all_x, all_y, all_r, 10.0, 1.0)
    assert (hsh[7], hsh[8], hsh[9]) == (1.5, 4, 4)  # cell, nkx, nky: a 4 x 4 table of 17 entries
    plan = beam_plan(np.linspace(-math.pi / 2, math.pi / 2, 31))
    row = np.full(31, 9.0)
    rh_mod._robot_hits_row.py_func(5.0, 5.0, 1.0, 0.0, 1, 0.0, 9.0, plan.beams, plan.even, hsh, row, np.empty(31),
                                   np.empty(31), True, (4.0, 6.0, 10.0, 12.0))
    assert np.all(row == 9.0)  # the box holds no disc: nothing shortened


@pytest.mark.parametrize("sigma,p_max,p_short", [(0.01, 0.0, 0.0), (0.5, 0.05, 0.1), (0.0, 0.2, 0.0), (0.0, 0.0, 0.3),
                                                 (2.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.1, 0.5, 0.5)])
def test_noise_row_matches_keyed_rows(sigma, p_max, p_short):
    """The two-loop noise of a row (fast ziggurat path vectorized, slow beams redone) against
    _counter_noise_rows, over enough beams to meet the slow path and the tail many times."""
    rng = np.random.default_rng(7)
    n, nb = 40, 3000
    true = rng.uniform(0.0, 12.0, (n, nb))
    true[:, ::7] = 0.0
    key = np.uint64(rng.integers(0, 2**63))
    want = np.empty_like(true)
    rs_mod._counter_noise_rows(true, key, 0, n, sigma, p_max, p_short, 10.0, want)
    got = true.copy()
    slow = np.empty(nb, np.bool_)
    for i in range(n):
        s0 = np.uint64((int(key) + i * nb * 64 * int(rs_mod._GAMMA)) % 2**64)  # row i's first stream state
        rs_mod._noise_row(got[i], s0, p_max + p_short > 0.0, sigma > 0.0, sigma, p_max, p_short, 10.0, slow)
    np.testing.assert_array_equal(got, want)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_open_space_poses_skip_the_traversal_bit_for_bit(seed, tiled):
    """A pose whose four free squares reach past tmax + 1 cells gets tmax * res on every ray
    without a traversal: the same bits as traversing each ray (``_cast_pose_capped`` without
    caps), on an open map (codes up to the 255 cap, dense or tiled), for limits just below,
    at and above the free squares, poses on grid lines and axis-parallel rays included."""
    rng = np.random.default_rng(seed)
    res = float(rng.choice([0.02, 0.05, 1.0]))
    h, w = int(rng.integers(40, 400)), int(rng.integers(40, 400))
    cells = np.zeros((h, w), np.uint8)
    for _ in range(int(rng.integers(0, 4))):
        r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
        cells[r0:r0 + int(rng.integers(1, 20)), c0:c0 + int(rng.integers(1, 3))] = WALL
    grid = OccupancyGrid(cells, res, (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3))))
    blocking = grid.blocking(None)
    dense = rc_mod.clearance_map(blocking)
    clear = rc_mod.clearance_tiles(blocking) if tiled else dense
    n, nb = 40, int(rng.integers(1, 12))
    ox, oy = grid.origin_xy_m
    fx = rng.uniform(0.0, w, n)
    fy = rng.uniform(0.0, h, n)
    on_line = rng.random(n) < 0.3
    fx[on_line] = np.floor(fx[on_line])  # poses on grid lines
    both = on_line & (rng.random(n) < 0.5)
    fy[both] = np.floor(fy[both])
    xs, ys = ox + fx * res, oy + fy * res
    th = np.where(rng.random(n) < 0.3, rng.choice([0.0, math.pi / 2, math.pi, -math.pi / 2], n), rng.uniform(-4, 4, n))
    ang = np.where(rng.random(nb) < 0.3, rng.choice([0.0, math.pi / 2, math.pi], nb), rng.uniform(-math.pi, math.pi, nb))
    ct, st_, cb, sb = np.cos(th), np.sin(th), np.cos(ang), np.sin(ang)
    inv = 1.0 / res
    scratch = [np.empty(nb), np.empty(nb), np.empty(nb), np.empty(nb), np.empty(nb, np.int64), np.empty(nb, np.int64),
               np.empty(nb, np.uint8), np.empty(nb, np.int64), np.empty(nb, np.int64)]
    for tmax in (float(rng.uniform(1.0, 20.0)), float(rng.integers(5, 300)), float(rng.integers(5, 300)) - 1e-9,
                 251.0, 253.0, 253.00000000000003, 300.0):
        full = np.empty((n, nb))
        rc_mod._cast_serial(clear, ox, oy, res, xs, ys, ct, st_, cb, sb, tmax, full, 0, n)
        for p in range(n):
            out = np.empty(nb)
            rc_mod._cast_pose_capped(dense, (xs[p] - ox) * inv, (ys[p] - oy) * inv, res, ct[p], st_[p], cb, sb, tmax,
                                     np.zeros(nb), False, out, *scratch)
            np.testing.assert_array_equal(full[p], out)
            r, c = int((ys[p] - oy) * inv) + 1, int((xs[p] - ox) * inv) + 1
            if 0 < r < h + 1 and 0 < c < w + 1 and int(dense[r, c].min()) - 2 >= tmax:  # a skipped pose
                np.testing.assert_array_equal(out, tmax * res)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_one_pass_in_open_space_matches_former_path(seed, parallel):
    """Poses with more than 4 m of free map all around take the discs up to 8 m before the cast
    (``_OPEN_NEAR_M``), the others up to 4 m: the ranges are the former path's bit for bit,
    in an open walled arena crowded with robots (as bench_scale's laser case)."""
    rng = np.random.default_rng(seed)
    res = float(rng.choice([0.05, 0.1]))
    side = int(rng.integers(250, 450))
    cells = np.zeros((side, side), np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = WALL
    grid = OccupancyGrid(cells, res, (float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3))))
    sensor = build_range_sensor(LaserConfig(n_beams=int(rng.choice([90, 181])), fov_deg=float(rng.choice([180.0, 360.0])),
                                            max_range_m=float(rng.choice([6.0, 10.0, 30.0])), noise_std_m=0.01,
                                            sees_robots=True), grid)
    n_all = int(rng.integers(20, 250))
    ox, oy = grid.origin_xy_m
    all_x = ox + rng.uniform(0.3, side * res - 0.3, n_all)
    all_y = oy + rng.uniform(0.3, side * res - 0.3, n_all)
    all_r = rng.uniform(0.05, 0.3, n_all)
    sensing = np.sort(rng.choice(n_all, size=min(n_all, 60), replace=False))
    xs, ys = all_x[sensing].copy(), all_y[sensing].copy()
    th = rng.uniform(-10.0, 10.0, sensing.shape[0])
    gx, gy, gr = grazing_bodies(rng, sensor, xs, ys, th, 40)
    bodies = (np.concatenate([all_x, gx]), np.concatenate([all_y, gy]), np.concatenate([all_r, gr]),
              sensing.astype(np.int64))
    old = rs_mod.PARALLEL_MIN_RAYS
    try:
        rs_mod.PARALLEL_MIN_RAYS = 0 if parallel else 10**12
        got = sensor._pass(xs, ys, th, bodies, None)
    finally:
        rs_mod.PARALLEL_MIN_RAYS = old
    np.testing.assert_array_equal(got, former(sensor, xs, ys, th, bodies, None))
