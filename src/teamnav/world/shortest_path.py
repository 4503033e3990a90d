"""Shortest paths through a grid's free space, kept a clearance away from obstacles.

What a navigator's path is measured against: the length of the shortest collision-free path
between two points for a disc of radius ``clearance_m``. Used by the experiments as a floor
(Sgorbissa & Arkin §6 count R1's motion steps, "directly proportional to the length of the
path followed"; the paper gives no optimum, so a reader cannot tell from its tables how far a
local algorithm is from the best path: the floor says it for ours).

Method: Dijkstra (``scipy.sparse.csgraph``) on the cells whose centre lies farther than
``clearance_m`` from every blocking cell centre (:func:`teamnav.world.distance.distance_field`),
with 16 moves per cell (the 8 neighbours and the 8 knight moves). A move is allowed only when
the cells it passes over are free too (no corner cutting). The longest error of a 16-move
path against the straight line is 1 / cos(13.28°) − 1 = 2.7 % (the largest angle between a
direction and the nearest move is half the 26.57° between (1, 0) and (2, 1)), so a length is
within +2.7 % plus about a cell of the true shortest path through the inflated free space.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import dijkstra

from teamnav.world.distance import distance_field
from teamnav.world.grid import OccupancyGrid

__all__ = ["GridPaths", "MOVE_ERROR_BOUND"]

#: Largest relative excess of a 16-move grid path over the straight segment it follows.
MOVE_ERROR_BOUND: float = 1.0 / math.cos(math.atan2(1.0, 2.0) / 2.0) - 1.0

# (d_row, d_col) and the cells (relative) a move passes over besides its two ends
_MOVES: tuple[tuple[int, int, tuple[tuple[int, int], ...]], ...] = (
    (0, 1, ()), (1, 0, ()),
    (1, 1, ((0, 1), (1, 0))), (1, -1, ((0, -1), (1, 0))),
    (1, 2, ((0, 1), (1, 1))), (2, 1, ((1, 0), (1, 1))),
    (1, -2, ((0, -1), (1, -1))), (2, -1, ((1, 0), (1, -1))),
)


class GridPaths:
    """Shortest path lengths on ``grid`` for a disc of radius ``clearance_m``.

    Parameters
    ----------
    grid : OccupancyGrid
        The map; every non-free cell blocks.
    clearance_m : float
        Smallest distance [m] from a path's cell centres to a blocking cell centre (a robot's
        radius, plus a margin if wanted). Must be >= 0.

    Examples
    --------
    >>> g = OccupancyGrid(np.zeros((40, 60), np.uint8), 0.1)
    >>> paths = GridPaths(g, 0.0)
    >>> round(float(paths.lengths([[0.55, 0.55]], [[4.55, 2.55]])[0, 0]), 3)   # along knight moves: exact
    4.472
    >>> round(float(paths.lengths([[0.55, 0.55]], [[4.55, 3.55]])[0, 0]), 2)   # 5 m straight, +1.3 %
    5.06
    """

    def __init__(self, grid: OccupancyGrid, clearance_m: float) -> None:
        if not (isinstance(clearance_m, (int, float)) and math.isfinite(clearance_m) and clearance_m >= 0.0):
            raise ValueError(f"clearance_m must be a finite number >= 0, got {clearance_m!r}")
        self.grid = grid
        self.clearance_m = float(clearance_m)
        blocking = grid.blocking()
        if blocking.all():
            self.free = np.zeros(blocking.shape, dtype=bool)
        elif not blocking.any():
            self.free = np.ones(blocking.shape, dtype=bool)
        else:
            self.free = distance_field(grid) > self.clearance_m
        h, w = self.free.shape
        self._index = -np.ones((h, w), dtype=np.int64)
        n = int(self.free.sum())
        self._index[self.free] = np.arange(n)
        rows, cols, vals = [], [], []
        res = grid.resolution_m
        for di, dj, over in _MOVES:
            # every cell (i, j) with (i + di, j + dj) inside the grid
            i0, i1 = max(0, -di), h - max(0, di)
            j0, j1 = max(0, -dj), w - max(0, dj)
            if i1 <= i0 or j1 <= j0:
                continue
            ok = self.free[i0:i1, j0:j1] & self.free[i0 + di:i1 + di, j0 + dj:j1 + dj]
            for oi, oj in over:
                ok &= self.free[i0 + oi:i1 + oi, j0 + oj:j1 + oj]
            a = self._index[i0:i1, j0:j1][ok]
            b = self._index[i0 + di:i1 + di, j0 + dj:j1 + dj][ok]
            rows.append(a)
            cols.append(b)
            vals.append(np.full(a.size, math.hypot(di, dj) * res))
        r = np.concatenate(rows) if rows else np.zeros(0, np.int64)
        c = np.concatenate(cols) if cols else np.zeros(0, np.int64)
        v = np.concatenate(vals) if vals else np.zeros(0)
        self._graph = sparse.csr_matrix((v, (r, c)), shape=(n, n))

    def _node(self, xy: np.ndarray, what: str, k: int) -> int:
        i, j = (int(v) for v in self.grid.world_to_cell(xy))
        h, w = self.free.shape
        if not (0 <= i < h and 0 <= j < w):
            raise ValueError(f"{what}[{k}] = ({xy[0]:g}, {xy[1]:g}) m is outside map {self.grid.name} "
                             f"(bounds {self.grid.bounds_m})")
        node = int(self._index[i, j])
        if node < 0:
            raise ValueError(f"{what}[{k}] = ({xy[0]:g}, {xy[1]:g}) m is not free space with "
                             f"{self.clearance_m:g} m clearance on map {self.grid.name}")
        return node

    def lengths(self, sources_xy, targets_xy) -> np.ndarray:
        """Shortest path lengths [m], shape (n_sources, n_targets); ``inf`` where no path exists.

        Parameters
        ----------
        sources_xy, targets_xy : array_like of shape (n, 2)
            World points [m]; each must lie in a cell of the inflated free space.

        Raises
        ------
        ValueError
            A point outside the map or too close to an obstacle (the message names it).
        """
        src = np.asarray(sources_xy, dtype=float).reshape(-1, 2)
        dst = np.asarray(targets_xy, dtype=float).reshape(-1, 2)
        s = [self._node(p, "sources_xy", k) for k, p in enumerate(src)]
        t = [self._node(p, "targets_xy", k) for k, p in enumerate(dst)]
        if not s or not t:
            return np.zeros((len(s), len(t)))
        uniq, inv = np.unique(np.asarray(s), return_inverse=True)
        d = dijkstra(self._graph, directed=False, indices=uniq)
        return d[inv][:, t]
