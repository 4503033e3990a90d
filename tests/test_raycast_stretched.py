"""Stretched jumps (``RayCaster(..., stretched=True)``): the same ranges as the square traversal,
bit for bit, on random grids, on the hand-made vertex cases and on the MIT basement; the
stretched rectangles are free and the widest; a stretched map that reaches into a wall is
caught by the same comparison."""

from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from teamnav.world.grid import OccupancyGrid
from teamnav.world.raycast import RayCaster, _run, brute_force_reference, clearance_map, stretch_map

BASEMENT_PNG = Path("/work/shared/data/mit/basement_hallways_5cm.png")


def both(blk, res, origin, poses, beams, rmax, parallel=False):
    """(square traversal, stretched) ranges of the same poses."""
    g = OccupancyGrid(blk, res, origin)
    sq = RayCaster(g, max_range_m=rmax)
    stc = RayCaster(g, max_range_m=rmax, stretched=True)
    assert sq.stretch is None and stc.stretch is not None
    p = np.asarray(poses, float).reshape(-1, 3)
    b = np.asarray(beams, float)
    return sq.cast(p, b, parallel=parallel), stc.cast(p, b, parallel=parallel)


small_grids = st.builds(
    lambda h, w, seed, density: (np.random.default_rng(seed).random((h, w)) < density).astype(np.uint8),
    st.integers(1, 24),
    st.integers(1, 24),
    st.integers(0, 2**32 - 1),
    st.sampled_from([0.0, 0.05, 0.15, 0.3, 0.6]),
)
angles = st.floats(-2 * math.pi, 2 * math.pi, allow_nan=False)
# on grid lines, cell centres and vertices half of the time: where the vertex rule decides
coords = st.one_of(st.floats(-0.1, 1.1), st.integers(0, 48).map(lambda k: k / 48))
# beams at multiples of 45 degrees (through vertices from such poses) half of the time
beam_angles = st.one_of(angles, st.integers(-8, 8).map(lambda k: k * math.pi / 4))


@settings(max_examples=250, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    blk=small_grids,
    res=st.sampled_from([1.0, 0.05, 0.37]),
    origin=st.tuples(st.floats(-3, 3), st.floats(-3, 3)),
    poses=st.lists(st.tuples(coords, coords, beam_angles), min_size=1, max_size=6),
    beams=st.lists(beam_angles, min_size=1, max_size=10),
    rmax_cells=st.floats(0.01, 40.0),
)
def test_stretched_ranges_equal_the_square_traversal_bit_for_bit(blk, res, origin, poses, beams, rmax_cells):
    h, w = blk.shape
    ox, oy = origin
    p = [(ox + fx * w * res, oy + fy * h * res, t) for fx, fy, t in poses]
    sq, stc = both(blk, res, origin, p, beams, rmax_cells * res)
    np.testing.assert_array_equal(stc, sq)
    _, par = both(blk, res, origin, p, beams, rmax_cells * res, parallel=True)
    np.testing.assert_array_equal(par, sq)


def test_vertex_and_grid_line_cases_equal():
    """Checkerboard-ish walls, poses on cell centres, corners and lines, beams every 15 degrees."""
    rng = np.random.default_rng(11)
    blk = (rng.random((30, 40)) < 0.08).astype(np.uint8)
    blk[10, 10] = blk[11, 11] = 1  # diagonally touching wall cells
    xs, ys = np.meshgrid(np.arange(0, 40, 0.5), np.arange(0, 30, 0.5))
    th = np.zeros(xs.size)
    poses = np.c_[xs.ravel(), ys.ravel(), th]
    beams = np.arange(24) * math.pi / 12
    sq, stc = both(blk, 1.0, (0.0, 0.0), poses, beams, 60.0)
    np.testing.assert_array_equal(stc, sq)
    assert ((sq > 2.0) & (sq < 60.0)).mean() > 0.5  # most rays cross several cells before a wall


@lru_cache(maxsize=1)
def basement() -> OccupancyGrid:
    from PIL import Image

    img = np.asarray(Image.open(BASEMENT_PNG).convert("L"))[::-1]
    return OccupancyGrid(np.ascontiguousarray((img < 254).astype(np.uint8)), 0.05, (0.0, 0.0))


def test_basement_mcl_like_sample_sets_equal():
    """What the beam model casts: Gaussian sample sets (walls and unknown space included) and a
    60-beam fan, and uniform free poses with a 181-beam fan."""
    g = basement()
    sq = RayCaster(g, max_range_m=10.0)
    stc = RayCaster(g, max_range_m=10.0, stretched=True)
    rng = np.random.default_rng(3)
    free = np.argwhere(g.cells == 0)
    fan = np.linspace(-math.pi / 2, math.pi / 2, 60)
    for _ in range(4):
        r, c = free[rng.integers(len(free))]
        centre = np.array([(c + 0.5) * 0.05, (r + 0.5) * 0.05, rng.uniform(-math.pi, math.pi)])
        p = centre + rng.standard_normal((3000, 3)) * np.array([1.0, 1.0, 0.5])
        ref = sq.cast(p, fan, parallel=False)
        np.testing.assert_array_equal(stc.cast(p, fan, parallel=False), ref)
        np.testing.assert_array_equal(stc.cast(p, fan, parallel=True), ref)
        assert (ref < 10.0).mean() > 0.5  # the map stops most rays: the comparison is not vacuous
    pick = free[rng.integers(0, len(free), 400)]
    p = np.c_[(pick[:, 1] + rng.random(400)) * 0.05, (pick[:, 0] + rng.random(400)) * 0.05,
              rng.uniform(-math.pi, math.pi, 400)]
    fan = np.linspace(-math.pi / 2, math.pi / 2, 181)
    got = stc.cast(p, fan)
    np.testing.assert_array_equal(got, sq.cast(p, fan))
    ref = brute_force_reference(g.blocking(), 0.0, 0.0, 0.05, p[:40, 0], p[:40, 1], p[:40, 2], fan, 10.0)
    assert np.abs(got[:40] - ref).max() <= 0.05


@settings(max_examples=60, deadline=None)
@given(blk=small_grids)
def test_stretch_map_rectangles_are_free_and_widest(blk):
    clear = clearance_map(blk)
    e = stretch_map(clear)
    hp, wp = clear.shape[:2]
    assert e.shape == (8, hp, wp, 2) and e.dtype == np.uint8
    pad = np.ones((hp, wp), np.uint8)
    pad[1:-1, 1:-1] = blk
    for q in range(4):
        sx = -1 if q & 1 else 1
        sy = -1 if q & 2 else 1
        for m in range(2):
            np.testing.assert_array_equal(e[2 * q + m, :, :, 0], clear[:, :, q])
            for r in range(hp):
                for c in range(wp):
                    s, x = int(e[2 * q + m, r, c, 0]), int(e[2 * q + m, r, c, 1])

                    def rect(nx, ny):  # cells of the nx x ny rectangle from (r, c) towards q
                        rows = sorted((r, r + sy * (ny - 1)))
                        cols = sorted((c, c + sx * (nx - 1)))
                        if min(rows[0], cols[0]) < 0 or rows[1] >= hp or cols[1] >= wp:
                            return np.ones(1)
                        return pad[rows[0]: rows[1] + 1, cols[0]: cols[1] + 1]

                    if s == 0:
                        assert x == 0
                        continue
                    nx, ny = (x, s) if m == 0 else (s, x)
                    assert x >= s and rect(nx, ny).max() == 0  # free, at least the square...
                    grow = (nx + 1, ny) if m == 0 else (nx, ny + 1)
                    assert rect(*grow).max() == 1  # ...and the widest (tallest)


def test_a_stretched_map_reaching_into_a_wall_is_caught():
    """The comparison above is not vacuous: rectangles one cell too wide let rays through the
    wall cell behind them, and the ranges differ."""
    blk = np.zeros((12, 12), np.uint8)
    blk[:, 8] = 1  # a wall at x in [8, 9)
    clear = clearance_map(blk)
    e = stretch_map(clear)
    poses = np.array([[2.3, 5.6, 0.1], [1.7, 3.2, -0.2], [4.1, 7.7, 0.05]])
    beams = np.linspace(-0.3, 0.3, 7)
    args = (0.0, 0.0, 1.0, poses[:, 0].copy(), poses[:, 1].copy(), poses[:, 2].copy(), beams, 30.0)
    ref = _run(clear, *args, np.empty((3, 7)), False)
    np.testing.assert_array_equal(_run(clear, *args, np.empty((3, 7)), False, ext=e), ref)
    bad = e.copy()
    # one column wider, left of the wall (padded columns 0-8), in the octants of quadrant (+x, +y)
    bad[0:2, :, :9, 1] = np.where(bad[0:2, :, :9, 1] > 0, bad[0:2, :, :9, 1] + 1, 0)
    broken = _run(clear, *args, np.empty((3, 7)), False, ext=bad)
    assert not np.array_equal(broken, ref)
    assert (broken > ref + 0.5).any()  # rays passed the wall


def test_stretch_map_rejects_a_bad_shape():
    with pytest.raises(ValueError, match="clear must be clearance_map"):
        stretch_map(np.zeros((5, 5), np.uint8))


@pytest.mark.parametrize("kind", ["laser", "sonar"])
def test_mcl_fused_cast_and_sum_equal_casting_then_summing(kind):
    """The filter's serial path (casting and summing in one pass over the stretched rectangles),
    its threaded path (stretched casting, then the sum) and the square traversal followed by the
    sum give the same log-likelihoods bit for bit; a sonar cone's rays take their minimum."""
    from teamnav.control.protocol import SensorInfo
    from teamnav.localization import MCL, MCLParams
    from teamnav.localization.beam_model import beam_loglik_kernel_serial
    from teamnav.world import load_map

    grid = load_map(Path(__file__).resolve().parents[1] / "src/teamnav/world/maps/mit/basement_hallways_5cm.yaml")
    if kind == "sonar":
        angles = np.linspace(-np.pi, np.pi, 17)[:-1]
        sensor = SensorInfo("sonar", "sonar", angles, 5.0, 0.05)
        extra = dict(sonar_rays_per_cone=5)
    else:
        angles = np.linspace(-np.pi / 2, np.pi / 2, 60)
        sensor = SensorInfo("laser", "laser", angles, 10.0, 0.02)
        extra = {}
    serial = MCL(MCLParams(n_particles=1500, **extra), grid, sensor, np.random.default_rng(1))
    threaded = MCL(MCLParams(n_particles=1500, parallel_min_work=0, **extra), grid, sensor, np.random.default_rng(1))
    pose = np.array([12.5, 20.1, 0.4])
    serial.init_pose(pose, np.diag([1.0, 1.0, 0.5]) ** 2)
    threaded.init_pose(pose, np.diag([1.0, 1.0, 0.5]) ** 2)
    np.testing.assert_array_equal(serial.particles, threaded.particles)
    scan = RayCaster(grid, serial.sees, sensor.max_range_m).cast(pose[None], angles)[0]
    a = serial.log_likelihood(scan).copy()
    b = threaded.log_likelihood(scan).copy()
    np.testing.assert_array_equal(a, b)
    # the square traversal and the plain sum, by hand
    p = serial.particles
    rays = RayCaster(grid, serial.sees, sensor.max_range_m).cast(p, serial._ray_angles, parallel=False)
    table = serial._beam_table(np.minimum(scan[serial._beam_idx], sensor.max_range_m))
    ref = beam_loglik_kernel_serial(rays, serial._k, table, 1.0 / serial._beam_table.step_m, 1.0, np.empty(len(p)))
    np.testing.assert_array_equal(a, ref)
    assert np.isfinite(a).all() and np.ptp(a) > 1.0  # different samples, different likelihoods
