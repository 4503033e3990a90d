"""Ray casting: exactness against the 0.001-cell stepping reference, hand cases, API checks."""

from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from teamnav.world.grid import OccupancyGrid
from teamnav.world.raycast import RayCaster, brute_force_reference, cast_rays, clearance_map

BASEMENT_PNG = Path("/work/shared/data/mit/basement_hallways_5cm.png")
BASEMENT_RES_M = 0.05


@lru_cache(maxsize=1)
def basement_blocking() -> np.ndarray:
    """MIT basement: pixel 0 occupied, 205 unknown (blocking), >= 254 free; row 0 = bottom."""
    from PIL import Image

    img = np.asarray(Image.open(BASEMENT_PNG).convert("L"))[::-1]
    blk = np.ascontiguousarray((img < 254).astype(np.uint8))
    blk.setflags(write=False)
    return blk


def assert_within_one_cell(got, ref, res_m):
    err = np.abs(got - ref)
    worst = np.unravel_index(np.argmax(err), err.shape) if err.size else None
    assert err.size == 0 or err.max() <= res_m, f"worst error {err.max()} m at {worst}: {got[worst]} vs {ref[worst]}"


def cast_both(blk, ox, oy, res, xs, ys, th, beams, rmax):
    xs, ys, th, beams = (np.asarray(v, float) for v in (xs, ys, th, beams))
    got = cast_rays(blk, ox, oy, res, xs, ys, th, beams, rmax)
    ref = brute_force_reference(blk, ox, oy, res, xs, ys, th, beams, rmax)
    return got, ref


# ---------------------------------------------------------------------------- hypothesis
small_grids = st.builds(
    lambda h, w, seed, density: (np.random.default_rng(seed).random((h, w)) < density).astype(np.uint8),
    st.integers(1, 14),
    st.integers(1, 14),
    st.integers(0, 2**32 - 1),
    st.sampled_from([0.0, 0.1, 0.3, 0.6]),
)
angles = st.floats(-2 * math.pi, 2 * math.pi, allow_nan=False)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    blk=small_grids,
    res=st.sampled_from([1.0, 0.05, 0.37, 2.5]),
    origin=st.tuples(st.floats(-3, 3), st.floats(-3, 3)),
    poses=st.lists(st.tuples(st.floats(-0.2, 1.2), st.floats(-0.2, 1.2), angles), min_size=1, max_size=6),
    beams=st.lists(angles, min_size=1, max_size=8),
    rmax_cells=st.floats(0.01, 25.0),
)
def test_small_grids_match_reference(blk, res, origin, poses, beams, rmax_cells):
    h, w = blk.shape
    ox, oy = origin
    # poses as fractions of the map extent (a little outside too)
    xs = [ox + fx * w * res for fx, _, _ in poses]
    ys = [oy + fy * h * res for _, fy, _ in poses]
    th = [t for _, _, t in poses]
    got, ref = cast_both(blk, ox, oy, res, xs, ys, th, beams, rmax_cells * res)
    assert_within_one_cell(got, ref, res)
    assert np.all((got >= 0) & (got <= rmax_cells * res))
    serial = cast_rays(blk, ox, oy, res, np.array(xs), np.array(ys), np.array(th), np.array(beams), rmax_cells * res, parallel=False)
    np.testing.assert_array_equal(got, serial)


@lru_cache(maxsize=1)
def basement_free_cells() -> np.ndarray:
    return np.argwhere(basement_blocking() == 0)


@settings(max_examples=60, deadline=None)
@given(
    cell=st.floats(0.0, 1.0, exclude_max=True),
    offset=st.tuples(st.floats(0.0, 1.0, exclude_max=True), st.floats(0.0, 1.0, exclude_max=True)),
    th=angles,
    beams=st.lists(angles, min_size=1, max_size=12),
)
def test_basement_matches_reference(cell, offset, th, beams):
    """Poses in free space (5/6 of the map is unknown grey, where every range is 0)."""
    blk = basement_blocking()
    free = basement_free_cells()
    r, c = free[int(cell * len(free))]
    x, y = (c + offset[0]) * BASEMENT_RES_M, (r + offset[1]) * BASEMENT_RES_M
    got, ref = cast_both(blk, 0.0, 0.0, BASEMENT_RES_M, [x], [y], [th], beams, 10.0)
    assert_within_one_cell(got, ref, BASEMENT_RES_M)


def test_basement_random_free_poses_match_reference():
    """Seeded bulk check where it matters: poses in free space, a full fan of beams."""
    blk = basement_blocking()
    rng = np.random.default_rng(7)
    free = np.argwhere(blk == 0)
    pick = free[rng.integers(0, len(free), 40)]
    xs = (pick[:, 1] + rng.random(40)) * BASEMENT_RES_M
    ys = (pick[:, 0] + rng.random(40)) * BASEMENT_RES_M
    th = rng.uniform(-math.pi, math.pi, 40)
    beams = np.linspace(-math.pi / 2, math.pi / 2, 181)
    got, ref = cast_both(blk, 0.0, 0.0, BASEMENT_RES_M, xs, ys, th, beams, 10.0)
    assert_within_one_cell(got, ref, BASEMENT_RES_M)
    assert (got < 10.0).mean() > 0.5  # the map really stops most rays: the test is not vacuous


# ---------------------------------------------------------------------------- hand cases
def one(blk, x, y, th, rmax=100.0, res=1.0, ox=0.0, oy=0.0):
    return float(cast_rays(blk, ox, oy, res, np.array([x]), np.array([y]), np.array([th]), np.array([0.0]), rmax)[0, 0])


@pytest.fixture
def room():
    """10 x 10 free cells, one wall cell at (row 5, col 7)."""
    b = np.zeros((10, 10), np.uint8)
    b[5, 7] = 1
    return b


@pytest.mark.parametrize(
    ("x", "y", "th", "expected"),
    [
        (2.5, 5.5, 0.0, 4.5),  # east to the wall cell's face x = 7
        (9.5, 5.5, math.pi, 1.5),  # west to its face x = 8
        (7.5, 0.5, math.pi / 2, 4.5),  # north to y = 5
        (7.5, 9.5, -math.pi / 2, 3.5),  # south to y = 6
        (2.5, 2.5, 0.0, 7.5),  # east, no wall on this row: map edge x = 10
        (2.5, 2.5, math.pi, 2.5),  # west: map edge x = 0
        (2.5, 2.5, math.pi / 2, 7.5),  # north edge
        (2.5, 2.5, -math.pi / 2, 2.5),  # south edge
    ],
)
def test_axis_aligned_rays(room, x, y, th, expected):
    assert one(room, x, y, th) == pytest.approx(expected, abs=1e-9)


def test_axis_aligned_ray_on_a_grid_line_belongs_to_the_upper_row(room):
    # y = 5.0 is the bottom face of row 5: the ray runs inside row 5 (half-open cells) and hits
    assert one(room, 2.5, 5.0, 0.0) == pytest.approx(4.5)
    # y = 6.0 is the top face of the wall cell: the ray is in row 6 and passes
    assert one(room, 2.5, 6.0, 0.0) == pytest.approx(7.5)


def test_ray_exactly_through_cell_corners():
    b = np.zeros((8, 8), np.uint8)
    b[4, 4] = 1
    # from (0.5, 0.5) at 45 deg the ray passes vertices (1,1), (2,2)... and enters cell (4,4) at (4,4)
    r = one(b, 0.5, 0.5, math.pi / 4)
    assert r == pytest.approx(3.5 * math.sqrt(2), abs=1e-9)
    # a wall cell that only touches the diagonal at a vertex stops the ray there
    b2 = np.zeros((8, 8), np.uint8)
    b2[3, 4] = 1  # shares vertex (x=4, y=4) with the diagonal
    assert one(b2, 0.5, 0.5, math.pi / 4) == pytest.approx(3.5 * math.sqrt(2), abs=1e-9)
    # a vertex ray beside no wall goes on to the map edge
    assert one(np.zeros((8, 8), np.uint8), 0.5, 0.5, math.pi / 4) == pytest.approx(7.5 * math.sqrt(2), abs=1e-9)


@pytest.mark.parametrize("th", [math.pi / 4, 3 * math.pi / 4, -math.pi / 4, -3 * math.pi / 4])
def test_diagonal_ray_does_not_slip_between_touching_wall_cells(th):
    b = np.zeros((9, 9), np.uint8)
    # two cells touching at vertex v beside the diagonal from the centre cell (4, 4)
    dx, dy = round(math.cos(th)), round(math.sin(th))
    vx, vy = 4.5 + 1.5 * dx, 4.5 + 1.5 * dy  # vertex 1.5 cells out along the diagonal
    # cells sharing vertex (vx, vy) that the diagonal passes between
    c_side_a = (int(vy - 0.5 + 0.5 * dy), int(vx - 0.5 - 0.5 * dx))
    c_side_b = (int(vy - 0.5 - 0.5 * dy), int(vx - 0.5 + 0.5 * dx))
    b[c_side_a] = 1
    b[c_side_b] = 1
    r = one(b, 4.5, 4.5, th)
    assert r == pytest.approx(1.5 * math.sqrt(2), abs=1e-9)
    # same cells, nudged ray angles pass through one of the two cells: hit nearby either way
    for eps in (1e-9, -1e-9, 1e-3, -1e-3):
        assert one(b, 4.5, 4.5, th + eps) <= 1.5 * math.sqrt(2) + 1e-2


def test_pose_inside_wall_is_zero(room):
    assert one(room, 7.5, 5.5, 0.0) == 0.0
    assert one(room, 7.0, 5.0, 1.0) == 0.0  # on the wall cell's lower-left corner: inside (half-open)


def test_pose_outside_map_is_zero(room):
    for x, y in [(-0.1, 5.0), (10.0, 5.0), (5.0, -1e-9), (5.0, 10.0), (50.0, 50.0)]:
        assert one(room, x, y, 0.3) == 0.0


def test_max_range_cap(room):
    assert one(room, 2.5, 5.5, 0.0, rmax=3.0) == 3.0
    assert one(room, 2.5, 5.5, 0.0, rmax=4.5) == pytest.approx(4.5)
    assert one(room, 2.5, 2.5, 0.0, rmax=1e-6) == pytest.approx(1e-6)


def test_map_edge_stops_rays_with_world_origin_and_resolution():
    b = np.zeros((4, 6), np.uint8)  # 3 m x 2 m at 0.5 m, origin (-1, 2)
    x, y = -1.0 + 1.25, 2.0 + 0.75
    r = cast_rays(b, -1.0, 2.0, 0.5, np.array([x]), np.array([y]), np.array([0.0]),
                  np.array([0.0, math.pi / 2, math.pi, -math.pi / 2]), 100.0)
    np.testing.assert_allclose(r[0], [3.0 - 1.25, 2.0 - 0.75, 1.25, 0.75], atol=1e-12)


def test_long_open_rays_jump_correctly():
    """Big empty map (clearance > 255 cells) with one far obstacle: jumps must not skip it."""
    b = np.zeros((700, 700), np.uint8)
    b[350, 650] = 1
    assert one(b, 0.5, 350.5, 0.0, rmax=1000.0) == pytest.approx(650.0 - 0.5)
    got, ref = cast_both(b, 0.0, 0.0, 1.0, [3.3], [340.2], [0.0], np.linspace(-0.05, 0.05, 21), 1000.0)
    assert_within_one_cell(got, ref, 1.0)


# ---------------------------------------------------------------------------- API
def test_raycaster_matches_cast_rays_and_fills_out():
    cells = np.zeros((20, 30), np.uint8)
    cells[5:15, 12] = 1  # wall
    cells[3, 3:9] = 3  # glass: invisible to the laser
    g = OccupancyGrid(cells, 0.1, (1.0, -2.0))
    laser = RayCaster(g, sees=("wall", "unknown", "foam"), max_range_m=5.0)
    sonar = RayCaster(g, sees=("wall", "unknown", "glass"), max_range_m=5.0)
    poses = np.array([[1.55, -1.85, math.pi / 2], [1.5, -1.0, 0.0]])
    beams = np.array([0.0, 0.1, -0.2])
    out = np.full((2, 3), -1.0)
    got = laser.cast(poses, beams, out=out)
    assert got is out
    exp = cast_rays(g.blocking(("wall", "unknown", "foam")), 1.0, -2.0, 0.1, poses[:, 0], poses[:, 1], poses[:, 2], beams, 5.0)
    np.testing.assert_array_equal(out, exp)
    # first pose (cell row 1) looks north across the glass row 3: the laser reaches the map
    # edge (y = 0 m), the sonar stops at the glass (y = -1.7 m)
    assert laser.cast(poses[:1], np.array([0.0]))[0, 0] == pytest.approx(1.85)
    assert sonar.cast(poses[:1], np.array([0.0]))[0, 0] == pytest.approx(0.15)
    # second pose (cell row 10, col 5) looks east at the wall column 12 (x = 2.2 m)
    assert got[1, 0] == pytest.approx(0.7)
    np.testing.assert_array_equal(
        laser.cast_xyt(poses[:, 0], poses[:, 1], poses[:, 2], beams, parallel=False), exp
    )


def test_clearance_map_codes_the_largest_free_square_per_quadrant():
    rng = np.random.default_rng(5)
    b = (rng.random((9, 11)) < 0.15).astype(np.uint8)
    m = clearance_map(b).transpose(2, 0, 1)  # (quadrant, row, col)
    assert m.shape == (4, 11, 13) and m.dtype == np.uint8
    pad = np.ones((11, 13), np.uint8)
    pad[1:-1, 1:-1] = b
    assert (m[:, 0, :] == 0).all() and (m[:, :, -1] == 0).all()  # the ring is the map edge
    for q in range(4):
        sx = -1 if q & 1 else 1
        sy = -1 if q & 2 else 1
        for r in range(11):
            for c in range(13):
                k = int(m[q, r, c]) - 1
                assert (k < 0) == bool(pad[r, c])

                def square(n):  # cells of the n x n square from (r, c) towards the quadrant
                    rows = sorted((r, r + sy * (n - 1)))
                    cols = sorted((c, c + sx * (n - 1)))
                    return pad[rows[0] : rows[1] + 1, cols[0] : cols[1] + 1]

                if k >= 0:
                    assert square(k + 1).max() == 0  # free...
                    assert square(k + 2).max() == 1  # ...and maximal


def test_cache_is_invalidated_when_a_read_only_mask_is_freed():
    b = np.zeros((5, 5), np.uint8)
    b.setflags(write=False)
    assert one(b, 0.5, 2.5, 0.0) == pytest.approx(4.5)
    b2 = np.zeros((5, 5), np.uint8)
    b2[2, 3] = 1
    b2.setflags(write=False)
    assert one(b2, 0.5, 2.5, 0.0) == pytest.approx(2.5)


def test_writeable_mask_changes_are_seen():
    b = np.zeros((5, 5), np.uint8)
    assert one(b, 0.5, 2.5, 0.0) == pytest.approx(4.5)
    b[2, 2] = 1
    assert one(b, 0.5, 2.5, 0.0) == pytest.approx(1.5)
    # a read-only view of a writeable array is not trusted to stay the same either
    view = b.view()
    view.setflags(write=False)
    assert one(view, 0.5, 2.5, 0.0) == pytest.approx(1.5)
    b[2, 2] = 0
    assert one(view, 0.5, 2.5, 0.0) == pytest.approx(4.5)


def test_empty_inputs():
    b = np.zeros((3, 3), np.uint8)
    assert cast_rays(b, 0, 0, 1, np.empty(0), np.empty(0), np.empty(0), np.array([0.0]), 5.0).shape == (0, 1)
    assert cast_rays(b, 0, 0, 1, np.ones(2), np.ones(2), np.zeros(2), np.empty(0), 5.0).shape == (2, 0)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"resolution_m": 0.0}, "resolution_m"),
        ({"resolution_m": float("nan")}, "resolution_m"),
        ({"max_range_m": -1.0}, "max_range_m"),
        ({"origin_x_m": float("inf")}, "origin_x_m"),
        ({"xs": np.array([np.nan])}, "xs"),
        ({"ys": np.array([1.0, 2.0])}, "ys"),
        ({"thetas": np.zeros((1, 1))}, "thetas"),
        ({"beam_angles_rad": np.array([np.inf])}, "beam_angles_rad"),
        ({"blocking": np.zeros(4, np.uint8)}, "blocking"),
        ({"blocking": np.zeros((2, 2), np.float32)}, "blocking"),
        ({"out": np.zeros((2, 1))}, "out"),
        ({"out": np.zeros((1, 1), np.float32)}, "out"),
    ],
)
def test_bad_input_raises_value_error_naming_parameter(kwargs, match):
    args = dict(
        blocking=np.zeros((3, 3), np.uint8), origin_x_m=0.0, origin_y_m=0.0, resolution_m=1.0,
        xs=np.array([1.0]), ys=np.array([1.0]), thetas=np.array([0.0]), beam_angles_rad=np.array([0.0]),
        max_range_m=5.0,
    )
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        cast_rays(**args)


def test_raycaster_bad_input():
    g = OccupancyGrid.empty(1.0, 1.0, 0.1)
    with pytest.raises(ValueError, match="max_range_m"):
        RayCaster(g, max_range_m=0.0)
    with pytest.raises(ValueError, match="grid"):
        RayCaster(np.zeros((3, 3), np.uint8))
    with pytest.raises(ValueError, match="poses"):
        RayCaster(g).cast(np.zeros((2, 2)), np.zeros(1))
    with pytest.raises(ValueError, match="free"):
        RayCaster(g, sees=("free",))
