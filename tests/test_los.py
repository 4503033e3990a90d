"""Line of sight, pairs within range (spatial hash) and visible pairs."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.world.los import line_of_sight, pairs_within, visible_pairs

grids = st.builds(
    lambda h, w, seed, density: (np.random.default_rng(seed).random((h, w)) < density).astype(np.uint8),
    st.integers(1, 12),
    st.integers(1, 12),
    st.integers(0, 2**32 - 1),
    st.sampled_from([0.0, 0.15, 0.4]),
)
# endpoints in cell units, biased to nice values (cell centres, faces, vertices) by hypothesis
coords = st.one_of(st.floats(-0.5, 12.5), st.integers(0, 12).map(float), st.integers(0, 24).map(lambda v: v / 2))


def sampled_los(blocking, ax, ay, bx, by, step=1e-3):
    """Reference: sample the segment every ``step`` cells (half-open cells, outside = blocked);
    between two samples that change row and column, test the side cell crossed (both at a
    vertex, within 1e-9 cell, unless the vertex is the end point b itself)."""
    h, w = blocking.shape
    if (bx, by) < (ax, ay):  # the documented traversal order: from the smaller endpoint
        ax, ay, bx, by = bx, by, ax, ay

    def blocked(r, c):
        return r < 0 or r >= h or c < 0 or c >= w or blocking[r, c] != 0

    length = math.hypot(bx - ax, by - ay)
    n = max(1, int(math.ceil(length / step)))
    s = np.linspace(0.0, 1.0, n + 1)
    cs = np.floor(ax + s * (bx - ax)).astype(int)
    rs = np.floor(ay + s * (by - ay)).astype(int)
    cs[-1], rs[-1] = math.floor(bx), math.floor(by)
    if blocked(rs[0], cs[0]):
        return False
    for k in range(1, n + 1):
        r0, c0, r1, c1 = rs[k - 1], cs[k - 1], rs[k], cs[k]
        if r0 == r1 and c0 == c1:
            continue
        if r0 != r1 and c0 != c1:
            tx = (max(c0, c1) - ax) / (bx - ax)
            ty = (max(r0, r1) - ay) / (by - ay)
            tol = 1e-9 / length
            if min(tx, ty) >= 1.0 - tol:
                side = []  # a vertex at the end point itself: only b's own cell counts
            elif tx < ty - tol:
                side = [(r0, c1)]
            elif ty < tx - tol:
                side = [(r1, c0)]
            else:
                side = [(r0, c1), (r1, c0)]
            if any(blocked(r, c) for r, c in side):
                return False
        if blocked(r1, c1):
            return False
    return True


@settings(max_examples=300, deadline=None)
@given(blk=grids, segs=st.lists(st.tuples(coords, coords, coords, coords), min_size=1, max_size=5))
def test_los_is_symmetric_and_matches_sampled_reference(blk, segs):
    a = np.array(segs, dtype=float)
    res, ox, oy = 0.5, -1.0, 2.0
    x0, y0, x1, y1 = (ox + a[:, 0] * res, oy + a[:, 1] * res, ox + a[:, 2] * res, oy + a[:, 3] * res)
    fwd = line_of_sight(blk, ox, oy, res, x0, y0, x1, y1)
    bwd = line_of_sight(blk, ox, oy, res, x1, y1, x0, y0)
    np.testing.assert_array_equal(fwd, bwd)
    # the reference works in the cell units the world coordinates really map to
    cell = np.stack([(x0 - ox) / res, (y0 - oy) / res, (x1 - ox) / res, (y1 - oy) / res], axis=1)
    for k, (ax, ay, bx, by) in enumerate(cell.tolist()):
        if math.hypot(bx - ax, by - ay) > 1e-6:  # the reference needs a direction
            assert fwd[k] == sampled_los(blk, ax, ay, bx, by), (ax, ay, bx, by)


def test_hand_cases():
    b = np.zeros((6, 6), np.uint8)
    b[2, 2] = 1
    b[4, 0] = b[5, 1] = 1  # two wall cells touching at the vertex x=1, y=5
    cases = [
        ((0.5, 2.5), (5.5, 2.5), False),  # through the wall cell
        ((0.5, 1.5), (5.5, 1.5), True),  # the row below it
        ((2.5, 2.5), (4.5, 4.5), False),  # starts inside a wall
        ((4.5, 4.5), (2.5, 2.5), False),  # ends inside a wall
        ((0.5, 3.5), (2.0, 2.0), False),  # ends on the wall cell's lower-left corner: that point is in it
        ((0.5, 5.5), (1.5, 4.5), False),  # squeezes between the two touching wall cells
        ((2.5, 5.5), (-0.5, 2.5), False),  # leaves the map
        ((3.5, 3.5), (3.5, 3.5), True),  # zero length in free space
        ((3.0, 0.5), (3.0, 5.5), True),  # along the grid line x=3: runs in column 3, free
        ((2.0, 0.5), (2.0, 5.5), False),  # along x=2: column 2, which holds the wall
    ]
    for (ax, ay), (bx, by), exp in cases:
        got = line_of_sight(b, 0.0, 0.0, 1.0, np.array([ax]), np.array([ay]), np.array([bx]), np.array([by]))[0]
        assert got == exp, ((ax, ay), (bx, by))


@pytest.mark.parametrize("flip", [False, True])
def test_diagonal_between_touching_wall_cells_is_blocked(flip):
    b = np.zeros((6, 6), np.uint8)
    b[2, 3] = b[3, 2] = 1  # touch at vertex (x=3, y=3); the segment below passes exactly through it
    a, c = (1.5, 1.5), (4.5, 4.5)
    if flip:
        b = b[:, ::-1].copy()
        a, c = (6 - 1.5, 1.5), (6 - 4.5, 4.5)
    ok = line_of_sight(b, 0.0, 0.0, 1.0, np.array([a[0], c[0]]), np.array([a[1], c[1]]), np.array([c[0], a[0]]), np.array([c[1], a[1]]))
    assert not ok.any()
    # one cell off the diagonal: free
    b2 = np.zeros((6, 6), np.uint8)
    b2[2, 4] = b2[4, 2] = 1
    assert line_of_sight(b2, 0.0, 0.0, 1.0, np.array([1.5]), np.array([1.5]), np.array([4.5]), np.array([4.5]))[0]


def brute_pairs(xs, ys, r):
    out = []
    for i in range(len(xs)):
        for j in range(i + 1, len(xs)):
            if (xs[i] - xs[j]) ** 2 + (ys[i] - ys[j]) ** 2 <= r * r:
                out.append((i, j))
    return out


@settings(max_examples=150, deadline=None)
@given(
    pts=st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=0, max_size=40),
    r=st.floats(0.01, 30.0),
)
def test_pairs_within_matches_brute_force(pts, r):
    xs = np.array([p[0] for p in pts], float)
    ys = np.array([p[1] for p in pts], float)
    i, j = pairs_within(xs, ys, r)
    assert list(zip(i.tolist(), j.tolist())) == brute_pairs(xs, ys, r)


def test_pairs_within_many_points_and_duplicates():
    rng = np.random.default_rng(3)
    xs = np.concatenate([rng.uniform(0, 100, 1500), [5.0, 5.0, 5.0]])
    ys = np.concatenate([rng.uniform(0, 100, 1500), [5.0, 5.0, 5.0]])
    i, j = pairs_within(xs, ys, 2.5)
    assert list(zip(i.tolist(), j.tolist())) == brute_pairs(xs, ys, 2.5)
    assert {(1500, 1501), (1500, 1502), (1501, 1502)} <= set(zip(i.tolist(), j.tolist()))


def brute_visible(blk, ox, oy, res, xs, ys, r):
    n = len(xs)
    out = np.zeros((n, n), bool)
    for a in range(n):
        for b in range(n):
            if a != b and math.hypot(xs[a] - xs[b], ys[a] - ys[b]) <= r:
                out[a, b] = line_of_sight(blk, ox, oy, res, xs[[a]], ys[[a]], xs[[b]], ys[[b]])[0]
    return out


@settings(max_examples=60, deadline=None)
@given(blk=grids, seed=st.integers(0, 2**32 - 1), n=st.integers(0, 25), r=st.floats(0.1, 8.0))
def test_visible_pairs_matches_brute_force(blk, seed, n, r):
    rng = np.random.default_rng(seed)
    h, w = blk.shape
    res, ox, oy = 0.5, 1.0, -1.0
    xs = ox + rng.uniform(-0.5, w + 0.5, n) * res
    ys = oy + rng.uniform(-0.5, h + 0.5, n) * res
    vis = visible_pairs(blk, ox, oy, res, xs, ys, r)
    assert vis.shape == (n, n) and vis.dtype == np.bool_
    np.testing.assert_array_equal(vis, vis.T)
    assert not vis.diagonal().any()
    np.testing.assert_array_equal(vis, brute_visible(blk, ox, oy, res, xs, ys, r))


def test_visible_pairs_respects_walls_and_range():
    b = np.zeros((10, 20), np.uint8)
    b[:, 10] = 1
    xs = np.array([1.0, 5.0, 15.0, 9.5])
    ys = np.array([5.0, 5.0, 5.0, 5.0])
    vis = visible_pairs(b, 0.0, 0.0, 1.0, xs, ys, 6.0)
    # 0-1 (4 m, same side) and 1-3 (4.5 m) see each other; 0-3 8.5 m is out of range; 2 is behind the wall
    assert vis.astype(int).tolist() == [[0, 1, 0, 0], [1, 0, 0, 1], [0, 0, 0, 0], [0, 1, 0, 0]]


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: pairs_within(np.zeros(2), np.zeros(2), 0.0), "max_range_m"),
        (lambda: pairs_within(np.zeros(2), np.zeros(3), 1.0), "ys"),
        (lambda: pairs_within(np.array([np.nan, 0.0]), np.zeros(2), 1.0), "xs"),
        (lambda: line_of_sight(np.zeros((2, 2), np.uint8), 0, 0, -1.0, [0.0], [0.0], [1.0], [1.0]), "resolution_m"),
        (lambda: line_of_sight(np.zeros((2, 2), np.uint8), 0, 0, 1.0, [0.0], [0.0], [1.0], [1.0, 2.0]), "y1"),
        (lambda: visible_pairs(np.zeros((2, 2, 2), np.uint8), 0, 0, 1.0, [0.0], [0.0], 1.0), "blocking"),
    ],
)
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_serial_and_parallel_kernels_agree():
    """Small inputs take the one-thread kernel; both give the same answers."""
    from teamnav.world import los

    rng = np.random.default_rng(3)
    blocking = (rng.random((40, 50)) < 0.2).astype(np.uint8)
    n = los._PARALLEL_MIN_SEGMENTS + 7
    x0, x1 = rng.uniform(0, 50, n), rng.uniform(0, 50, n)
    y0, y1 = rng.uniform(0, 40, n), rng.uniform(0, 40, n)
    a = np.empty(n, np.bool_)
    b = np.empty(n, np.bool_)
    los._los_kernel(blocking, 0.0, 0.0, 1.0, x0, y0, x1, y1, a)
    los._los_kernel_serial(blocking, 0.0, 0.0, 1.0, x0, y0, x1, y1, b)
    np.testing.assert_array_equal(a, b)
    assert 0 < a.sum() < n  # both outcomes occur
    np.testing.assert_array_equal(line_of_sight(blocking, 0.0, 0.0, 1.0, x0[:9], y0[:9], x1[:9], y1[:9]), a[:9])
