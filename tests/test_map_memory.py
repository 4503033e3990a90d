"""Memory savings on a map's per-cell arrays that change no value.

- The ray caster's clearance maps are filled in place (``raycast._clearance_into``): the codes
  are those of the former construction (four flipped copies of the padded free mask, one
  anchored-squares pass each, then a transposed copy), kept here as the reference.
- A map whose cells are only free and wall (every generated arena) hands out its own cell
  array as the blocking mask of every sensor that sees walls: the same bytes, not a copy.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings, strategies as st
from hypothesis.extra.numpy import arrays

from teamnav.world import raycast
from teamnav.world.grid import DEFAULT_SEES, FREE, GLASS, WALL, OccupancyGrid


def _reference_clearance(blocking: np.ndarray) -> np.ndarray:
    free = np.zeros((blocking.shape[0] + 2, blocking.shape[1] + 2), dtype=np.bool_)
    free[1:-1, 1:-1] = blocking == 0
    out = np.empty((4,) + free.shape, dtype=np.uint8)
    for q in range(4):
        flip = (slice(None, None, -1 if q & 2 else 1), slice(None, None, -1 if q & 1 else 1))
        sq = np.empty(free.shape, np.uint8)
        raycast._anchored_squares(np.ascontiguousarray(free[flip]), sq)
        out[q] = sq[flip]
    return np.ascontiguousarray(out.transpose(1, 2, 0))


@settings(max_examples=60, deadline=None)
@given(blocking=arrays(np.uint8, st.tuples(st.integers(1, 40), st.integers(1, 40)),
                       elements=st.sampled_from([0, 0, 0, 1])))
def test_clearance_maps_in_place_are_the_former_ones(blocking):
    got = raycast.clearance_map(blocking)
    want = _reference_clearance(blocking)
    assert got.shape == want.shape and got.dtype == want.dtype and got.flags.c_contiguous
    assert np.array_equal(got, want)


def test_clearance_codes_reach_the_cap_in_open_space():
    b = np.zeros((600, 560), np.uint8)
    b[300, 140] = 1
    got = raycast.clearance_map(b)
    assert got.max() == 255 and np.array_equal(got, _reference_clearance(b))


@settings(max_examples=40, deadline=None)
@given(cells=arrays(np.uint8, st.tuples(st.integers(1, 30), st.integers(1, 30)),
                    elements=st.sampled_from([FREE, FREE, WALL, GLASS])))
def test_blocking_masks_are_shared_only_when_equal(cells):
    g = OccupancyGrid(cells, 0.1)
    for sees in [None, *DEFAULT_SEES.values(), ("glass",), ("foam",)]:
        mask = g.blocking(sees)
        want = (cells != FREE) if sees is None else g.visible_ids(sees)[cells]
        assert mask.dtype == np.uint8 and not mask.flags.writeable
        assert np.array_equal(mask, want.astype(np.uint8))
        assert (mask is g.cells) == (np.array_equal(mask, g.cells))  # shared exactly when the bytes agree


# ---------------------------------------------------------------------------- tiled clearance
def _tiles_to_dense(tiles) -> np.ndarray:
    pool, index, dims = tiles
    s = raycast.TILE_CELLS
    r, c = np.meshgrid(np.arange(dims[0]), np.arange(dims[1]), indexing="ij")
    return np.stack([pool[index[q][r // s, c // s], r % s, c % s] for q in range(4)], axis=-1)


@settings(max_examples=40, deadline=None)
@given(blocking=arrays(np.uint8, st.tuples(st.integers(1, 120), st.integers(1, 120)),
                       elements=st.sampled_from([0] * 30 + [1])))
def test_clearance_tiles_hold_the_same_codes(blocking):
    assert np.array_equal(_tiles_to_dense(raycast.clearance_tiles(blocking)), raycast.clearance_map(blocking))


def test_an_open_arena_shares_its_tiles():
    b = np.zeros((1000, 1000), np.uint8)
    b[0, :] = b[-1, :] = b[:, 0] = b[:, -1] = 1
    pool, index, _ = raycast.clearance_tiles(b)
    assert pool.nbytes * 20 < raycast.clearance_map(b).nbytes
    assert np.array_equal(_tiles_to_dense((pool, index, _)), raycast.clearance_map(b))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 1000), h=st.integers(5, 150), w=st.integers(5, 150), n=st.integers(0, 15))
def test_rays_through_tiles_are_the_dense_rays_bit_for_bit(seed, h, w, n):
    rng = np.random.default_rng(seed)
    cells = np.zeros((h, w), np.uint8)
    for _ in range(n):
        r, c = int(rng.integers(0, h)), int(rng.integers(0, w))
        cells[r:r + int(rng.integers(1, 20)), c:c + int(rng.integers(1, 20))] = WALL
    g = OccupancyGrid(cells, 0.05, (0.3, -0.2))
    dense = raycast.RayCaster(g, max_range_m=4.0)
    tiled = raycast.RayCaster(g, max_range_m=4.0)
    tiled.clearance = raycast.clearance_tiles(tiled.blocking)
    p = np.column_stack([rng.uniform(0.2, 0.4 + w * 0.05, 64), rng.uniform(-0.3, w * 0.05, 64),
                         rng.uniform(-np.pi, np.pi, 64)])
    p[:8, :2] = np.round(p[:8, :2] / 0.05) * 0.05  # on grid lines and vertices
    beams = np.linspace(-np.pi, np.pi, 37)
    for parallel in (False, True):
        want = dense.cast(p, beams, parallel=parallel)
        got = tiled.cast(p, beams, parallel=parallel)
        assert np.array_equal(got.view(np.uint64), want.view(np.uint64))


def test_sensor_kernels_read_tiles_as_the_dense_maps_serial_and_parallel():
    """The engine's fused sensing kernels (robot bodies, capped map cast, keyed noise), on
    enough rays to take the parallel path (``PARALLEL_MIN_RAYS``, with numba's threads > 1) and
    on few."""
    from teamnav.sim.config import LaserConfig
    from teamnav.sim.sensors.range_sensors import build_range_sensor

    rng = np.random.default_rng(4)
    cells = np.zeros((260, 240), np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = WALL
    for _ in range(30):
        r, c = int(rng.integers(0, 250)), int(rng.integers(0, 230))
        cells[r:r + int(rng.integers(1, 9)), c:c + int(rng.integers(1, 9))] = WALL
    g = OccupancyGrid(cells, 0.05, (0.0, 0.0))
    cfg = LaserConfig(n_beams=90, fov_deg=270.0, max_range_m=5.0)
    dense, tiled = build_range_sensor(cfg, g), build_range_sensor(cfg, g)
    tiled.caster.clearance = raycast.clearance_tiles(tiled.caster.blocking)
    for n in (400, 7):  # 36 000 rays (parallel with 2 threads) and 630
        xs, ys = rng.uniform(0.3, 11.7, n), rng.uniform(0.3, 12.7, n)
        th = rng.uniform(-np.pi, np.pi, n)
        bodies = (xs, ys, np.full(n, 0.15), np.arange(n))
        for b in (None, bodies):
            want = dense.sense(xs, ys, th, np.random.default_rng(1), b)
            got = tiled.sense(xs, ys, th, np.random.default_rng(1), b)
            assert np.array_equal(got.view(np.uint64), want.view(np.uint64))
