"""Line of sight between points on an occupancy grid, and neighbour pairs by spatial hash.

Who can see whom is the heart of Sgorbissa & Arkin's cooperation (goal sharing only happens
between robots in line of sight, §3) and of the detection events of Fox et al. (§4); the
simulator's radio model may also require it. :func:`visible_pairs` answers it for a whole
team in one call, and :func:`pairs_within` gives the engine the candidate pairs for
robot-robot collisions.

Semantics
---------
A segment is visible when neither endpoint lies in a blocking cell (or outside the grid)
and it crosses no blocking cell. Cells are half-open, as in
:class:`~teamnav.world.grid.OccupancyGrid`; a segment through a grid vertex (other than its
own end point) also touches the two cells beside the vertex, so it never slips between two
diagonally touching wall cells — the same rule as :mod:`teamnav.world.raycast`.
Each segment is traversed from its lexicographically smaller endpoint, so
``line_of_sight(a, b) == line_of_sight(b, a)`` exactly, bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from teamnav.world.raycast import VERTEX_TOL_CELLS, _check_blocking, _check_finite, _check_positive, _check_vec

__all__ = ["line_of_sight", "pairs_within", "visible_pairs"]


# ---------------------------------------------------------------------------- kernels
@njit(cache=True, inline="always")
def _blocked(blocking, r, c):
    return r < 0 or r >= blocking.shape[0] or c < 0 or c >= blocking.shape[1] or blocking[r, c] != 0


@njit(cache=True)
def _segment_visible(blocking, ax, ay, bx, by):
    """True when the segment between cell-unit points a and b crosses no blocking cell."""
    if bx < ax or (bx == ax and by < ay):  # canonical order: symmetric by construction
        ax, bx = bx, ax
        ay, by = by, ay
    c = int(math.floor(ax))
    r = int(math.floor(ay))
    if _blocked(blocking, r, c):
        return False
    if _blocked(blocking, int(math.floor(by)), int(math.floor(bx))):
        return False
    ddx = bx - ax
    ddy = by - ay
    length = math.sqrt(ddx * ddx + ddy * ddy)
    if length == 0.0:
        return True
    dx = ddx / length
    dy = ddy / length
    if dx > 0.0:
        sx = 1
        offx = 1
        idx = 1.0 / dx
    elif dx < 0.0:
        sx = -1
        offx = 0
        idx = 1.0 / dx
    else:
        sx = 1
        offx = 1
        idx = np.inf
    if dy > 0.0:
        sy = 1
        offy = 1
        idy = 1.0 / dy
    elif dy < 0.0:
        sy = -1
        offy = 0
        idy = 1.0 / dy
    else:
        sy = 1
        offy = 1
        idy = np.inf
    end = length - VERTEX_TOL_CELLS  # crossings at the end point itself do not count
    while True:
        tx = ((c + offx) - ax) * idx
        ty = ((r + offy) - ay) * idy
        if tx < ty - VERTEX_TOL_CELLS:
            if tx >= end:
                return True
            c += sx
        elif ty < tx - VERTEX_TOL_CELLS:
            if ty >= end:
                return True
            r += sy
        else:
            if min(tx, ty) >= end:
                return True
            if _blocked(blocking, r, c + sx) or _blocked(blocking, r + sy, c):
                return False
            c += sx
            r += sy
        if _blocked(blocking, r, c):
            return False


@njit(cache=True, inline="always")
def _visible_i(blocking, ox, oy, inv, x0, y0, x1, y1, i):
    return _segment_visible(blocking, (x0[i] - ox) * inv, (y0[i] - oy) * inv, (x1[i] - ox) * inv, (y1[i] - oy) * inv)


@njit(cache=True, parallel=True)
def _los_kernel(blocking, ox, oy, inv, x0, y0, x1, y1, out):
    for i in prange(x0.shape[0]):
        out[i] = _visible_i(blocking, ox, oy, inv, x0, y0, x1, y1, i)


@njit(cache=True)
def _los_kernel_serial(blocking, ox, oy, inv, x0, y0, x1, y1, out):
    for i in range(x0.shape[0]):
        out[i] = _visible_i(blocking, ox, oy, inv, x0, y0, x1, y1, i)


#: Below this many segments one thread is faster: waking the thread pool costs more than the
#: work, and on a loaded machine far more (a 4-robot team paid ~20 ms per call).
_PARALLEL_MIN_SEGMENTS = 512


@njit(cache=True)
def _lower_bound(kx, ky, qx, qy):
    """First index of the lexicographically sorted (kx, ky) that is >= (qx, qy)."""
    lo = 0
    hi = kx.shape[0]
    while lo < hi:
        mid = (lo + hi) >> 1
        if kx[mid] < qx or (kx[mid] == qx and ky[mid] < qy):
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True)
def _hash_pairs(order, kx, ky, xs, ys, r2, out_i, out_j, fill):
    """Pairs within sqrt(r2) among points sorted by cell (kx, ky); counts them, and
    writes them to out_i/out_j (i < j in original indices) when ``fill``."""
    n = order.shape[0]
    m = 0
    for a in range(n):
        i = order[a]
        cx = kx[a]
        cy = ky[a]
        # own cell (later entries only) then the 4 "forward" neighbour cells: each
        # unordered pair of cells is visited once
        for nb in range(5):
            if nb == 0:
                qx = cx
                qy = cy
                start = a + 1
            else:
                qx = cx + (0 if nb == 1 else 1)
                qy = cy + (1 if nb == 1 else nb - 3)
                start = _lower_bound(kx, ky, qx, qy)
            s = start
            while s < n and kx[s] == qx and ky[s] == qy:
                j = order[s]
                ddx = xs[i] - xs[j]
                ddy = ys[i] - ys[j]
                if ddx * ddx + ddy * ddy <= r2:
                    if fill:
                        out_i[m] = min(i, j)
                        out_j[m] = max(i, j)
                    m += 1
                s += 1
    return m


# ---------------------------------------------------------------------------- public API
def line_of_sight(blocking, origin_x_m, origin_y_m, resolution_m, x0, y0, x1, y1) -> np.ndarray:
    """Whether each segment ``(x0, y0) -> (x1, y1)`` is free of blocking cells.

    Parameters
    ----------
    blocking : ndarray of shape (H, W), uint8
        1 where a cell stops sight (``grid.blocking(sees)``).
    origin_x_m, origin_y_m : float
        World coordinates [m] of the lower-left corner of cell (0, 0).
    resolution_m : float
        Cell side [m].
    x0, y0, x1, y1 : ndarray of shape (n,), float64
        Segment endpoints [m].

    Returns
    -------
    ndarray of shape (n,), bool
        True when the segment crosses no blocking cell and both endpoints are in free cells
        inside the grid. Symmetric: swapping the endpoints gives the same answer.

    Examples
    --------
    >>> b = np.zeros((5, 5), np.uint8); b[2, 2] = 1
    >>> line_of_sight(b, 0.0, 0.0, 1.0, np.array([0.5, 0.5]), np.array([2.5, 0.5]),
    ...               np.array([4.5, 4.5]), np.array([2.5, 0.5])).tolist()
    [False, True]
    """
    blocking = _check_blocking(blocking)
    ox = _check_finite("origin_x_m", origin_x_m)
    oy = _check_finite("origin_y_m", origin_y_m)
    res = _check_positive("resolution_m", resolution_m)
    x0 = _check_vec("x0", x0)
    n = x0.shape[0]
    y0 = _check_vec("y0", y0, n)
    x1 = _check_vec("x1", x1, n)
    y1 = _check_vec("y1", y1, n)
    out = np.empty(n, dtype=np.bool_)
    if n:
        kernel = _los_kernel if n >= _PARALLEL_MIN_SEGMENTS else _los_kernel_serial
        kernel(blocking, ox, oy, 1.0 / res, x0, y0, x1, y1, out)
    return out


def pairs_within(xs, ys, max_range_m) -> tuple[np.ndarray, np.ndarray]:
    """All pairs of points at most ``max_range_m`` apart, found with a uniform spatial hash.

    Points are bucketed in square cells of side ``max_range_m``; only a cell and its 8
    neighbours are compared, so the cost is O(N log N + pairs), not O(N²).

    Parameters
    ----------
    xs, ys : ndarray of shape (N,), float64
        Point coordinates [m].
    max_range_m : float
        Distance cut-off [m] (inclusive).

    Returns
    -------
    i, j : ndarray of shape (M,), int64
        ``i < j``, sorted lexicographically by ``(i, j)``.

    Examples
    --------
    >>> i, j = pairs_within(np.array([0.0, 1.0, 5.0]), np.array([0.0, 0.0, 0.0]), 1.5)
    >>> i.tolist(), j.tolist()
    ([0], [1])
    """
    xs = _check_vec("xs", xs)
    ys = _check_vec("ys", ys, xs.shape[0])
    rng_m = _check_positive("max_range_m", max_range_m)
    n = xs.shape[0]
    if n < 2:
        return np.empty(0, np.int64), np.empty(0, np.int64)
    kx = np.floor((xs - xs.min()) / rng_m).astype(np.int64)
    ky = np.floor((ys - ys.min()) / rng_m).astype(np.int64)
    order = np.lexsort((ky, kx)).astype(np.int64)
    skx = np.ascontiguousarray(kx[order])
    sky = np.ascontiguousarray(ky[order])
    r2 = rng_m * rng_m
    dummy = np.empty(0, np.int64)
    m = _hash_pairs(order, skx, sky, xs, ys, r2, dummy, dummy, False)
    out_i = np.empty(m, np.int64)
    out_j = np.empty(m, np.int64)
    _hash_pairs(order, skx, sky, xs, ys, r2, out_i, out_j, True)
    srt = np.lexsort((out_j, out_i))
    return out_i[srt], out_j[srt]


def visible_pairs(blocking, origin_x_m, origin_y_m, resolution_m, xs, ys, max_range_m) -> np.ndarray:
    """Which points see each other: within range and in line of sight.

    Parameters
    ----------
    blocking : ndarray of shape (H, W), uint8
        1 where a cell stops sight.
    origin_x_m, origin_y_m : float
        World coordinates [m] of the lower-left corner of cell (0, 0).
    resolution_m : float
        Cell side [m].
    xs, ys : ndarray of shape (N,), float64
        Positions [m].
    max_range_m : float
        Sight range [m] (inclusive).

    Returns
    -------
    ndarray of shape (N, N), bool
        Symmetric, False on the diagonal. Candidate pairs come from :func:`pairs_within`,
        so the line-of-sight work grows with the number of neighbours, not with N².

    Examples
    --------
    >>> b = np.zeros((4, 8), np.uint8); b[:, 4] = 1
    >>> visible_pairs(b, 0.0, 0.0, 1.0, np.array([0.5, 2.5, 6.5]), np.array([1.5] * 3), 10.0).astype(int).tolist()
    [[0, 1, 0], [1, 0, 0], [0, 0, 0]]
    """
    blocking = _check_blocking(blocking)
    ox = _check_finite("origin_x_m", origin_x_m)
    oy = _check_finite("origin_y_m", origin_y_m)
    res = _check_positive("resolution_m", resolution_m)
    xs = _check_vec("xs", xs)
    ys = _check_vec("ys", ys, xs.shape[0])
    i, j = pairs_within(xs, ys, max_range_m)
    n = xs.shape[0]
    vis = np.zeros((n, n), dtype=np.bool_)
    if i.shape[0]:
        ok = np.empty(i.shape[0], dtype=np.bool_)
        kernel = _los_kernel if i.shape[0] >= _PARALLEL_MIN_SEGMENTS else _los_kernel_serial
        kernel(blocking, ox, oy, 1.0 / res, xs[i], ys[i], xs[j], ys[j], ok)
        vis[i[ok], j[ok]] = True
        vis[j[ok], i[ok]] = True
    return vis
