"""Start poses of all robots from their groups' :class:`~teamnav.sim.config.StartConfig`.

- Explicit ``poses`` ([x_m, y_m, theta_deg] per robot; the first ``count`` of the list) are checked: each disc must lie in free
  space inside the map and overlap no other robot's; otherwise a ``ValueError`` names the
  group and the pose index.
- Otherwise robots are drawn uniformly at random over the free space of ``region`` (or of
  the whole map): a point is drawn uniformly inside a uniformly chosen *candidate cell* (a
  free cell whose distance to the nearest wall cell centre, from
  :func:`~teamnav.world.distance.distance_field`, is at least ``radius + sqrt(2) * res``, so
  every point of it has clearance >= radius), rejected when outside ``region`` or when
  overlapping a robot already placed, and drawn again. Heading ``theta_deg`` or uniform on
  (-pi, pi].

Groups with explicit poses are placed first (in group order), then the random ones (in group
order, robots in index order), all from the run's "start" random stream, so a seed fixes the
start. Clearance to walls uses the same exact disc test as the collision model
(:func:`teamnav.sim.collisions.discs_hit_walls`), so a robot never starts stuck.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from teamnav.geometry.angles import wrap_angle
from teamnav.sim.collisions import discs_hit_walls
from teamnav.world.distance import distance_field
from teamnav.world.grid import OccupancyGrid

__all__ = ["MAX_TRIES_PER_ROBOT", "start_poses"]

#: Random draws allowed per robot before the region is declared too crowded.
MAX_TRIES_PER_ROBOT: int = 20_000
_BATCH = 64


class _Placed:
    """Discs placed so far, in a uniform spatial hash (dict of cells) for overlap checks."""

    def __init__(self, cell_m: float) -> None:
        self.cell = cell_m
        self.buckets: dict[tuple[int, int], list[tuple[float, float, float, int]]] = {}

    def key(self, x: float, y: float) -> tuple[int, int]:
        return (math.floor(x / self.cell), math.floor(y / self.cell))

    def overlapping(self, x: float, y: float, r: float) -> int | None:
        kx, ky = self.key(x, y)
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for (px, py, pr, idx) in self.buckets.get((kx + dx, ky + dy), ()):
                    if (x - px) ** 2 + (y - py) ** 2 < (r + pr) ** 2:
                        return idx
        return None

    def add(self, x: float, y: float, r: float, idx: int) -> None:
        self.buckets.setdefault(self.key(x, y), []).append((x, y, r, idx))


#: Cells of the candidate mask built at once (a strip of rows; the strip's temporaries are
#: a few bytes a cell, so about 10 MB).
_STRIP_CELLS = 1 << 20


class _AmbiguousField(Exception):
    """A block field's window met a cell whose distance is within rounding of the threshold."""


class _Candidates:
    """The candidate cells (flat indices, ascending) of a mask given strip by strip, kept as runs.

    ``take(i)`` is ``np.flatnonzero(mask)[i]``, bit for bit, without the index array (8 bytes
    per candidate: 200 MB for a 10 000-robot arena at 2 cm): a run of consecutive candidates
    costs 16 bytes, and an open arena has about one per row.
    """

    def __init__(self, strips) -> None:
        starts, counts = [], []
        for first, ok in strips:
            h, w = ok.shape
            pad = np.zeros((h, w + 2), np.int8)
            pad[:, 1:-1] = ok
            edge = np.diff(pad, axis=1)
            r_on, c_on = np.nonzero(edge == 1)  # row-major: the runs in flat order
            _, c_off = np.nonzero(edge == -1)
            starts.append((first + r_on) * w + c_on)
            counts.append(c_off - c_on)
        start = np.concatenate(starts) if starts else np.zeros(0, np.int64)
        count = np.concatenate(counts) if counts else np.zeros(0, np.int64)
        self._start = start.astype(np.int64)
        self._before = np.concatenate([[0], np.cumsum(count, dtype=np.int64)])  # candidates before run k
        self.size = int(self._before[-1])

    def take(self, i: np.ndarray) -> np.ndarray:
        k = np.searchsorted(self._before, i, side="right") - 1
        return self._start[k] + (i - self._before[k])


def _candidate_strips(grid: OccupancyGrid, blocking: np.ndarray, clear_m: np.ndarray, r: float, region):
    """Yield ``(first row, bool mask of a strip of rows)``: the free cells whose every point has
    clearance >= ``r`` (distance field >= ``r + sqrt(2) * res``), inside the map by ``r`` and
    meeting ``region`` (as ``xmin, xmax, ymin, ymax``).

    ``clear_m`` is the distance field or its block lower bound
    (:func:`teamnav.world.distance.clearance_bound`). With the bound, a block whose bound
    reaches the threshold is far from every wall; in the others the field is computed exactly
    in a window around the block reaching ``ceil(thr / res) + 1`` cells further (a wall outside
    it is further than the threshold), so the mask is the dense field's. A window cell within
    1e-9 (relative) of the threshold, where two nearest walls could round differently, raises
    :class:`_AmbiguousField` (the caller then uses the dense field).
    """
    from teamnav.world.distance import block_shift

    h, w = blocking.shape
    res = grid.resolution_m
    ox, oy = grid.origin_xy_m
    xmin, xmax, ymin, ymax = region
    thr = r + math.sqrt(2.0) * res
    cols = np.arange(w)[None, :]
    sh = block_shift(clear_m.shape, blocking.shape)
    step = (1 << sh) if sh else max(1, _STRIP_CELLS // w)
    for r0 in range(0, h, step):
        r1 = min(h, r0 + step)
        rows = np.arange(r0, r1)[:, None]
        far = _far_strip(blocking, clear_m, sh, thr, res, r0, r1) if sh else clear_m[r0:r1] >= thr
        ok = far & (blocking[r0:r1] == 0)
        if not grid.rotated:
            cx0 = ox + cols * res
            cy0 = oy + rows * res
            ok &= (cx0 - r >= ox) & (cx0 + res + r <= ox + w * res) & (cy0 - r >= oy) & (cy0 + res + r <= oy + h * res)
            ok &= (cx0 + res > xmin) & (cx0 < xmax) & (cy0 + res > ymin) & (cy0 < ymax)
        else:
            # the map edge in the grid's own axes; the (world-frame) region against the cell's
            # centre, widened by half the cell's diagonal (each drawn point is checked exactly below)
            lx0 = cols * res
            ly0 = rows * res
            ok &= (lx0 - r >= 0) & (lx0 + res + r <= w * res) & (ly0 - r >= 0) & (ly0 + res + r <= h * res)
            centre = grid.cell_centers(*np.broadcast_arrays(rows, cols))
            half = res / math.sqrt(2.0)
            ok &= (centre[..., 0] + half > xmin) & (centre[..., 0] - half < xmax)
            ok &= (centre[..., 1] + half > ymin) & (centre[..., 1] - half < ymax)
        yield r0, ok


def _far_strip(blocking, bound, sh, thr, res, r0, r1) -> np.ndarray:
    """``distance_field(blocking)[r0:r1] >= thr`` (one block row) from the block bound ``bound``."""
    from teamnav.world.distance import _edt

    h, w = blocking.shape
    b = 1 << sh
    lb = bound[r0 >> sh]
    far = np.repeat(lb >= thr, b)[:w][None, :].repeat(r1 - r0, axis=0)
    near = np.flatnonzero(lb < thr)
    if near.size == 0:
        return far
    halo = int(math.ceil(thr / res)) + 1
    # runs of consecutive near blocks, each with its window
    cuts = np.flatnonzero(np.diff(near) != 1)
    for j0, j1 in zip(np.concatenate([[near[0]], near[cuts + 1]]), np.concatenate([near[cuts], [near[-1]]])):
        c0, c1 = int(j0) * b, min(w, (int(j1) + 1) * b)
        wr0, wr1 = max(0, r0 - halo), min(h, r1 + halo)
        wc0, wc1 = max(0, c0 - halo), min(w, c1 + halo)
        free = blocking[wr0:wr1, wc0:wc1] == 0
        if free.all():
            far[:, c0:c1] = True
            continue
        d = _edt(free, res)[r0 - wr0:r1 - wr0, c0 - wc0:c1 - wc0]
        if (np.abs(d - thr) <= 1e-9 * thr).any():
            raise _AmbiguousField
        far[:, c0:c1] = d >= thr
    return far


def start_poses(grid: OccupancyGrid, groups: Sequence, rng: np.random.Generator, clear_m: np.ndarray | None = None) -> np.ndarray:
    """Start poses for every robot of ``groups`` (robot ids in group order).

    Parameters
    ----------
    grid : OccupancyGrid
        The true map.
    groups : sequence of RobotGroupConfig
    rng : numpy.random.Generator
        The run's start stream.
    clear_m : ndarray, optional
        ``distance_field(grid)`` when the caller already has it, or its block lower bound
        (:func:`~teamnav.world.distance.clearance_bound`, for a huge map): the same poses.

    Returns
    -------
    ndarray of shape (N, 3)
        (x [m], y [m], theta [rad]) per robot.

    Raises
    ------
    ValueError
        An explicit pose overlaps a wall, leaves the map or overlaps another robot; or no
        place can be found for a random robot.

    Examples
    --------
    >>> from teamnav.sim.config import RobotGroupConfig, StartConfig
    >>> g = OccupancyGrid.empty(4.0, 4.0, 0.1)
    >>> start_poses(g, [RobotGroupConfig(count=1, start=StartConfig(poses=((1.0, 1.0, 90.0),)))],
    ...             np.random.default_rng(0)).round(4).tolist()
    [[1.0, 1.0, 1.5708]]
    """
    if not isinstance(grid, OccupancyGrid):
        raise ValueError(f"grid must be an OccupancyGrid, got {type(grid).__name__}")
    blocking = grid.blocking(None)
    if clear_m is None:
        clear_m = distance_field(blocking, grid.resolution_m)
    res = grid.resolution_m
    ox, oy = grid.origin_xy_m
    geo = grid.geo
    counts = [g.count for g in groups]
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(int)
    n = int(offsets[-1])
    poses = np.zeros((n, 3))
    rmax = max((g.radius_m for g in groups), default=1.0)
    placed = _Placed(2.0 * rmax)

    def label(gi: int) -> str:
        return f"robots[{gi}] ({groups[gi].name!r})"

    # ---- explicit poses first
    for gi, g in enumerate(groups):
        if g.start.poses is None:
            continue
        p = np.array(g.start.poses, dtype=np.float64).reshape(-1, 3)
        if p.shape[0] < g.count:
            raise ValueError(f"{label(gi)}.start.poses must list at least count={g.count} poses, got {p.shape[0]}")
        p = p[: g.count]
        hit = discs_hit_walls(blocking, clear_m, geo, p[:, 0], p[:, 1], np.full(g.count, g.radius_m))
        for k in range(g.count):
            x, y, th_deg = (float(v) for v in p[k])
            if hit[k]:
                raise ValueError(
                    f"{label(gi)}.start.poses[{k}] must place a robot of radius {g.radius_m} m in free space "
                    f"inside the map, got ({x}, {y}) which overlaps a wall or the map edge"
                )
            other = placed.overlapping(x, y, g.radius_m)
            if other is not None:
                raise ValueError(
                    f"{label(gi)}.start.poses[{k}] must not overlap another robot, got ({x}, {y}) "
                    f"which overlaps robot {other} at ({poses[other, 0]}, {poses[other, 1]})"
                )
            idx = int(offsets[gi]) + k
            placed.add(x, y, g.radius_m, idx)
            poses[idx] = (x, y, float(wrap_angle(math.radians(th_deg))))

    # ---- random poses
    h, w = blocking.shape
    for gi, g in enumerate(groups):
        if g.start.poses is not None:
            continue
        r = g.radius_m
        xmin, xmax, ymin, ymax = g.start.region if g.start.region is not None else grid.bounds_m
        try:
            cand = _Candidates(_candidate_strips(grid, blocking, clear_m, r, (xmin, xmax, ymin, ymax)))
        except _AmbiguousField:  # never met so far; the dense field decides, as it always did
            cand = _Candidates(_candidate_strips(grid, blocking, distance_field(blocking, res), r,
                                                 (xmin, xmax, ymin, ymax)))
        if cand.size == 0:
            where = f"region {list(g.start.region)}" if g.start.region is not None else "the map"
            raise ValueError(
                f"{label(gi)}.start needs free space with clearance >= radius_m={r} m in {where}, found none"
            )
        for k in range(g.count):
            idx = int(offsets[gi]) + k
            tries = 0
            done = False
            while not done:
                if tries >= MAX_TRIES_PER_ROBOT:
                    raise ValueError(
                        f"{label(gi)}.start could not place robot {k} of {g.count} (radius {r} m) without overlap "
                        f"after {tries} tries; give a larger region or fewer robots"
                    )
                cells = cand.take(rng.integers(0, cand.size, size=_BATCH))
                u = rng.random((_BATCH, 2))
                if not grid.rotated:
                    xs = ox + (cells % w + u[:, 0]) * res
                    ys = oy + (cells // w + u[:, 1]) * res
                else:
                    world = grid.cell_to_world(cells // w + u[:, 1], cells % w + u[:, 0])
                    xs, ys = world[:, 0], world[:, 1]
                for x, y in zip(xs.tolist(), ys.tolist()):
                    tries += 1
                    if not (xmin <= x <= xmax and ymin <= y <= ymax):
                        continue
                    if placed.overlapping(x, y, r) is not None:
                        continue
                    placed.add(x, y, r, idx)
                    poses[idx, 0] = x
                    poses[idx, 1] = y
                    done = True
                    break
            if g.start.theta_deg is not None:
                poses[idx, 2] = float(wrap_angle(math.radians(g.start.theta_deg)))
            elif not grid.rotated:
                poses[idx, 2] = float(wrap_angle(rng.uniform(-math.pi, math.pi)))
            else:
                # uniform either way; turned with the map so a rotated map's run is its twin's, turned
                poses[idx, 2] = float(wrap_angle(rng.uniform(-math.pi, math.pi) + grid.yaw_rad))
    return poses
