"""Moving disc robots without ever letting them penetrate a wall or each other.

Every robot is a disc of radius ``radius_m``. A wall is any non-free cell
(``grid.blocking(None)``) and everything outside the map. A disc *overlaps* a cell when the
distance from its centre to the cell's square is strictly less than its radius (touching is
allowed), and two discs overlap when their centres are closer than the sum of their radii.

Resolution rule (one :func:`move_discs` call moves everyone)
-----------------------------------------------------------
- Robots move one after another in index order (robot 0 first). Robot ``i`` is checked
  against the walls and against every other robot where it *currently* is (robots
  ``< i`` already moved this step, robots ``> i`` not yet). Starting from a state without
  overlaps, no overlap can ever appear, and the same inputs give the same result bit for
  bit.
- The motion primitive (turn on the spot, then an arc; :mod:`teamnav.sim.kinematics`) is
  sampled at ``n = ceil(|arc| / (SUBSTEP_FRACTION * radius))`` equally spaced points along
  the arc. Consecutive samples are at most a quarter radius apart, so a disc cannot tunnel
  through a wall however thin (one cell) or through another robot.
- If a sample overlaps a wall or a robot, the robot **advances to the last safe sample**
  (possibly staying where it was) and its ``stalled`` flag is set. Otherwise it reaches the
  exact end of the arc and ``stalled`` is cleared.
- Rotation is always allowed for a disc: the heading becomes the commanded one
  (``theta + pre_turn + turn``) even when the translation was blocked. (A blocked
  differential-drive robot pushing against a wall would pivot; a disc turning in place
  sweeps no new area.)

Wall checks first look up the distance field of the blocking mask (one read decides for a
robot more than ``radius + sqrt(2) * res`` from any wall) and only next to walls test the
cells under the disc's bounding box exactly. Robot–robot candidates come from a grid of the
start-of-step positions with cell side ``4 * (max radius + max arc)`` (dense over the robots'
bounding box, or hashed buckets when that box is too sparse); robot ``i`` looks up the cells
within ``r_i + max radius + |arc_i| + max arc`` of its start point (1 to 4 of them), so a
step costs O(N) for a swarm, not O(N²). Which candidates are
looked up decides nothing but the cost: each is tested exactly, and every robot that can
touch robot ``i`` is among them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# Compiled into move_discs' cached machine code: numba's on-disk cache keys on this file
# alone, so a change to these functions must change this file too (or clear __pycache__),
# else an old move_discs keeps running the old arc (the chord form of arc_point, for one).
from teamnav.sim.kinematics import arc_point, wrap
from teamnav.world.distance import block_shift

__all__ = ["SUBSTEP_FRACTION", "discs_hit_walls", "move_discs"]

#: Largest distance between two collision samples along a path, as a fraction of the radius.
SUBSTEP_FRACTION: float = 0.25
#: Side of the robot hash's cells in units of the farthest two robots' start points can be
#: apart and still meet, ``2 (max radius + max arc)``: with 2, a robot looks up 1 to 4 cells
#: (the square its own reach spans), not the 3 x 3 around its cell.
_CELL_REACHES: float = 2.0
#: Most cells a robot of the dense grid of start points (beyond, buckets hashed by cell).
_CELLS_PER_ROBOT: int = 4
#: Most the dense grid's cell side may grow past the hash's (a swarm of one robot a square
#: metre, Thymio-sized: 0.38 m to about 0.5 m) before the buckets are hashed instead.
_DENSE_GROWTH: float = 4.0
#: Added to that reach [m]: covers the rounding of arc samples and of the cell arithmetic,
#: so that no robot that could meet another is ever left out of its look-up.
_HASH_MARGIN_M: float = 1e-6
_SQRT2 = math.sqrt(2.0)


@njit(cache=True)
def _disc_hits_wall(blocking, clear_m, sh, ox, oy, res, cs, sn, px, py, r):
    """True when the disc (px, py, r) overlaps a blocking cell or leaves the map.

    ``clear_m`` holds one lower bound of the distance field per ``2**sh x 2**sh`` block of
    cells (``sh == 0``: the field itself); it only decides when the exact test can be skipped.

    ``cs, sn`` are the cosine and sine of the map's yaw: a rotated map's disc centre is taken
    into the grid's local frame first (a disc is round, so only its centre moves); with
    ``cs == 1, sn == 0`` nothing is computed and the test is the axis-aligned one, bit for bit.
    """
    if sn != 0.0 or cs != 1.0:
        dx = px - ox
        dy = py - oy
        px = cs * dx + sn * dy
        py = -sn * dx + cs * dy
        ox = 0.0
        oy = 0.0
    h = blocking.shape[0]
    w = blocking.shape[1]
    if px - r < ox or py - r < oy or px + r > ox + w * res or py + r > oy + h * res:
        return True
    c = min(int(math.floor((px - ox) / res)), w - 1)
    row = min(int(math.floor((py - oy) / res)), h - 1)
    if clear_m[row >> sh, c >> sh] - _SQRT2 * res >= r:  # |p - centre| <= res/sqrt2, centre to square <= res/sqrt2
        return False
    c0 = max(int(math.floor((px - r - ox) / res)), 0)
    c1 = min(int(math.floor((px + r - ox) / res)), w - 1)
    r0 = max(int(math.floor((py - r - oy) / res)), 0)
    r1 = min(int(math.floor((py + r - oy) / res)), h - 1)
    r2 = r * r
    for rr in range(r0, r1 + 1):
        y0 = oy + rr * res
        dy = max(y0 - py, 0.0, py - (y0 + res))
        if dy * dy >= r2:
            continue
        for cc in range(c0, c1 + 1):
            if blocking[rr, cc] != 0:
                x0 = ox + cc * res
                dx = max(x0 - px, 0.0, px - (x0 + res))
                if dx * dx + dy * dy < r2:
                    return True
    return False


@njit(cache=True)
def _field_shift(blocking, clear_m):
    """``k`` such that ``clear_m`` holds one value per ``2**k x 2**k`` block of ``blocking``
    (0: a dense field). :func:`teamnav.world.distance.block_shift` checks the shape first."""
    h = blocking.shape[0]
    w = blocking.shape[1]
    k = 0
    while k < 30 and ((h + (1 << k) - 1) >> k != clear_m.shape[0] or (w + (1 << k) - 1) >> k != clear_m.shape[1]):
        k += 1
    return k


@njit(cache=True)
def _discs_hit_walls(blocking, clear_m, ox, oy, res, cs, sn, xs, ys, rs, out):
    sh = _field_shift(blocking, clear_m)
    for i in range(xs.shape[0]):
        out[i] = _disc_hits_wall(blocking, clear_m, sh, ox, oy, res, cs, sn, xs[i], ys[i], rs[i])


@njit(cache=True, inline="always")
def _bucket(kx, ky, mask):
    return ((kx * 73856093) ^ (ky * 19349663)) & mask


@njit(cache=True)
def move_discs(x, y, th, radius, pre_turn, arc, turn, blocking, clear_m, geo, collide, stalled):
    """Move every robot along its motion primitive, in index order, never overlapping.

    Parameters
    ----------
    x, y, th : (N,) float64
        True poses [m, m, rad], updated in place.
    radius : (N,) float64
        Disc radii [m].
    pre_turn, arc, turn : (N,) float64
        Motion primitives (:func:`teamnav.sim.kinematics.motion_primitives`).
    blocking : (H, W) uint8
        1 where a cell blocks motion.
    clear_m : (H, W) float64
        Distance field of ``blocking`` [m] (:func:`teamnav.world.distance.distance_field`), or
        its lower bound per block of ``2**k x 2**k`` cells, shape ``(ceil(H / 2**k), ceil(W / 2**k))``
        (:func:`teamnav.world.distance.clearance_bound`): the same moves, from 1/64 000 of the memory
        at 2 cm (the field only lets a disc far from every wall skip the exact test).
    geo : (5,) float64
        ``origin_x_m, origin_y_m, resolution_m, cos(yaw), sin(yaw)``
        (:attr:`teamnav.world.grid.OccupancyGrid.geo`).
    collide : bool
        Whether robots collide with each other.
    stalled : (N,) bool
        Written: True where the translation was cut short.
    """
    n = x.shape[0]
    ox = geo[0]
    oy = geo[1]
    res = geo[2]
    cs = geo[3] if geo.shape[0] > 4 else 1.0  # a 3-element geo: an unrotated map
    sn = geo[4] if geo.shape[0] > 4 else 0.0
    use_hash = collide and n > 1
    sh = _field_shift(blocking, clear_m)
    # ---- start-of-step positions in cells (counting sort): a dense grid over the robots'
    # bounding box (rows of cells contiguous: one range per column of a look-up), or, when
    # that box would need more than _CELLS_PER_ROBOT cells a robot (robots parked far away,
    # a sparse team on a huge map), hashed buckets
    dense = False
    x0 = 0.0
    y0 = 0.0
    nky = 1
    nkx = 1
    size = 1
    cell = 1.0
    rmax = 0.0
    smax = 0.0
    if use_hash:
        for i in range(n):
            rmax = max(rmax, radius[i])
            smax = max(smax, abs(arc[i]))
        cell = _CELL_REACHES * 2.0 * (rmax + smax)
        if not cell > 0.0:  # nobody has a size or moves: no robot looks anything up
            cell = 1.0
        x0 = x[0]
        x1 = x[0]
        y0 = y[0]
        y1 = y[0]
        for i in range(n):
            x0 = min(x0, x[i])
            x1 = max(x1, x[i])
            y0 = min(y0, y[i])
            y1 = max(y1, y[i])
        # the dense grid's cells may grow up to _DENSE_GROWTH times (fewer cells, more robots in each)
        dcell = cell
        fx = math.floor((x1 - x0) / dcell) + 1.0
        fy = math.floor((y1 - y0) / dcell) + 1.0
        while fx * fy > _CELLS_PER_ROBOT * n + 16 and dcell < _DENSE_GROWTH * cell:
            dcell *= 1.25
            fx = math.floor((x1 - x0) / dcell) + 1.0
            fy = math.floor((y1 - y0) / dcell) + 1.0
        dense = fx * fy <= _CELLS_PER_ROBOT * n + 16
        if dense:
            cell = dcell
            nkx = int(fx)
            nky = int(fy)
            size = nkx * nky
        else:
            while size < 2 * n:
                size *= 2
    mask = size - 1
    key = np.empty(n if use_hash else 0, np.int64)
    start = np.zeros(size + 1 if use_hash else 0, np.int64)
    items = np.empty(n if use_hash else 0, np.int64)
    if use_hash:
        for i in range(n):
            if dense:
                key[i] = int(math.floor((x[i] - x0) / cell)) * nky + int(math.floor((y[i] - y0) / cell))
            else:
                key[i] = _bucket(int(math.floor(x[i] / cell)), int(math.floor(y[i] / cell)), mask)
            start[key[i] + 1] += 1
        for b in range(size):
            start[b + 1] += start[b]
        fill = start[:size].copy()
        for i in range(n):
            items[fill[key[i]]] = i
            fill[key[i]] += 1
    # ---- move robots one by one
    for i in range(n):
        th0 = th[i] + pre_turn[i]
        a = arc[i]
        stalled[i] = False
        if a != 0.0:
            ri = radius[i]
            nsub = max(1, int(math.ceil(abs(a) / (SUBSTEP_FRACTION * ri))))
            bx = x[i]
            by = y[i]
            kx0 = kx1 = ky0 = ky1 = 0
            if use_hash:
                # the cells a robot overlapping i this step can start in: the two start points
                # are less than ri + rj + |a_i| + |a_j| apart (every sample of an arc lies within
                # its length of its start), plus a margin for rounding
                reach = ri + rmax + abs(a) + smax + _HASH_MARGIN_M
                if dense:
                    kx0 = max(0, int(math.floor((x[i] - reach - x0) / cell)))
                    kx1 = min(nkx - 1, int(math.floor((x[i] + reach - x0) / cell)))
                    ky0 = max(0, int(math.floor((y[i] - reach - y0) / cell)))
                    ky1 = min(nky - 1, int(math.floor((y[i] + reach - y0) / cell)))
                else:
                    kx0 = int(math.floor((x[i] - reach) / cell))
                    kx1 = int(math.floor((x[i] + reach) / cell))
                    ky0 = int(math.floor((y[i] - reach) / cell))
                    ky1 = int(math.floor((y[i] + reach) / cell))
            for k in range(1, nsub + 1):
                px, py, _ = arc_point(x[i], y[i], th0, a, turn[i], k / nsub)
                hit = _disc_hits_wall(blocking, clear_m, sh, ox, oy, res, cs, sn, px, py, ri)
                if not hit and use_hash:
                    for cx in range(kx0, kx1 + 1):
                        # dense: the column's cells ky0..ky1 in one range; hashed: one bucket a cell
                        for cy in range(ky0, ky0 + 1 if dense else ky1 + 1):
                            if dense:
                                q0 = start[cx * nky + ky0]
                                q1 = start[cx * nky + ky1 + 1]
                            else:
                                bk = _bucket(cx, cy, mask)
                                q0 = start[bk]
                                q1 = start[bk + 1]
                            for q in range(q0, q1):
                                j = items[q]
                                if j != i:
                                    ddx = px - x[j]
                                    ddy = py - y[j]
                                    rr = ri + radius[j]
                                    if ddx * ddx + ddy * ddy < rr * rr:
                                        hit = True
                                        break
                            if hit:
                                break
                        if hit:
                            break
                if hit:
                    stalled[i] = True
                    break
                bx = px
                by = py
            x[i] = bx
            y[i] = by
        th[i] = wrap(th0 + turn[i])


def discs_hit_walls(blocking, clear_m, geo, xs, ys, rs) -> np.ndarray:
    """Which discs overlap a blocking cell or leave the map.

    Parameters
    ----------
    blocking : ndarray of shape (H, W), uint8
    clear_m : ndarray of shape (H, W), float64
        Distance field of ``blocking`` [m], or its block lower bound
        (:func:`teamnav.world.distance.clearance_bound`; see :func:`move_discs`).
    geo : sequence of 3 or 5 floats
        ``origin_x_m, origin_y_m, resolution_m`` and, for a rotated map, ``cos(yaw), sin(yaw)``
        (:attr:`teamnav.world.grid.OccupancyGrid.geo`).
    xs, ys, rs : ndarray of shape (n,)
        Disc centres and radii [m].

    Returns
    -------
    ndarray of shape (n,), bool

    Examples
    --------
    >>> from teamnav.world.distance import distance_field
    >>> b = np.zeros((10, 10), np.uint8); b[:, 5] = 1
    >>> discs_hit_walls(b, distance_field(b, 0.1), (0.0, 0.0, 0.1), np.array([0.3, 0.45]),
    ...                 np.array([0.5, 0.5]), np.array([0.2, 0.2])).tolist()
    [False, True]
    """
    xs = np.ascontiguousarray(xs, dtype=np.float64)
    ys = np.ascontiguousarray(ys, dtype=np.float64)
    rs = np.ascontiguousarray(rs, dtype=np.float64)
    out = np.empty(xs.shape[0], dtype=np.bool_)
    block_shift(np.shape(clear_m), np.shape(blocking))  # ValueError for a field of another map
    _discs_hit_walls(
        np.ascontiguousarray(blocking, dtype=np.uint8), np.ascontiguousarray(clear_m, dtype=np.float64),
        float(geo[0]), float(geo[1]), float(geo[2]), float(geo[3]) if len(geo) > 3 else 1.0,
        float(geo[4]) if len(geo) > 4 else 0.0, xs, ys, rs, out,
    )
    return out
