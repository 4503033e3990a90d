"""Occupancy grid with a material layer.

Every cell holds a material id (``uint8``): ``0`` is free space, any other id is an
obstacle made of the material named ``grid.materials[id]``. Robots collide with every
non-free cell. Range sensors, however, declare which materials they *see* (a laser passes
through glass, a sonar echoes off it), so the Fox et al. hexagon (§5.2.2), whose obstacles
only one sensor type perceives, is just a map with two materials.

Conventions (ROS REP 103 and map_server):

- ``cells[row, col]``: row 0 is the *lowest* y (the bottom of the map image), so the array
  is the image flipped vertically.
- cell ``(row, col)`` covers ``[col*res, (col+1)*res) x [row*res, (row+1)*res)`` in the grid's
  *local* frame, whose origin is the lower-left corner of cell (0, 0) and whose x axis runs
  along the rows. The local frame sits at ``origin_xy_m`` in the world, turned by ``yaw_rad``
  (map_server's ``origin: [x, y, yaw]``, the pose of the lower-left pixel in the map frame):
  ``world = origin + R(yaw) @ local``. With ``yaw_rad == 0`` (every generated map and most
  map files) the cell covers ``[ox + col*res, ox + (col+1)*res) x [oy + row*res, oy + (row+1)*res)``.

Kernels (ray casting, line of sight, collisions, likelihood fields) work on the axis-aligned
cell array. For a rotated grid their callers pass positions in the local frame and headings
less ``yaw_rad`` (:meth:`OccupancyGrid.kernel_frame`, :meth:`OccupancyGrid.kernel_theta`);
for an unrotated grid nothing is transformed, so results are the same bit for bit as before
rotation was supported. Ranges, distances and clearances do not depend on the frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable

import numpy as np

#: Materials every grid knows, in this id order. Maps may append their own names.
#: ``unknown`` is what map_server calls "unknown" (grey) space: robots cannot enter it and,
#: by default, every sensor sees it (a ray that leaves the mapped area stops there).
DEFAULT_MATERIALS: tuple[str, ...] = ("free", "wall", "unknown", "glass", "foam")
FREE: int = 0
WALL: int = 1
UNKNOWN: int = 2
GLASS: int = 3  # invisible to a laser, echoes sonar
FOAM: int = 4  # absorbs sonar, seen by a laser

#: Most memory [bytes] a run's map may need (2 GiB); bigger maps, map images and arenas are
#: refused before anything is allocated, naming the estimate and this limit.
MAX_MAP_BYTES: int = 2 * 1024**3
#: Bytes a run needs per map cell: the cells and blocking masks (uint8), the float64 distance
#: field and scipy's Euclidean distance transform's working arrays (measured peak ~36 B/cell).
MAP_BYTES_PER_CELL: int = 40
#: The most cells a map may have (:data:`MAX_MAP_BYTES` / :data:`MAP_BYTES_PER_CELL`).
MAX_MAP_CELLS: int = MAX_MAP_BYTES // MAP_BYTES_PER_CELL


def map_memory_problem(n_cells: float, what: str) -> str | None:
    """Why a map of ``n_cells`` cells is refused (None when it fits :data:`MAX_MAP_BYTES`).

    Examples
    --------
    >>> map_memory_problem(1200 * 1200, "map") is None
    True
    >>> print(map_memory_problem(20_000 * 20_000, "arena 10000 x 10000 m at 0.5 m"))
    arena 10000 x 10000 m at 0.5 m has 400,000,000 cells, which needs about 14.9 GiB of memory (40 bytes per cell for the grid and its distance transform); expected at most 2.0 GiB (teamnav.world.grid.MAX_MAP_BYTES): use a coarser resolution_m or a smaller map
    """
    need = float(n_cells) * MAP_BYTES_PER_CELL
    if need <= MAX_MAP_BYTES:
        return None
    return (
        f"{what} has {int(n_cells):,} cells, which needs about {need / 1024**3:.1f} GiB of memory ({MAP_BYTES_PER_CELL} bytes "
        f"per cell for the grid and its distance transform); expected at most {MAX_MAP_BYTES / 1024**3:.1f} GiB "
        "(teamnav.world.grid.MAX_MAP_BYTES): use a coarser resolution_m or a smaller map"
    )


def check_map_size(width_cells: int, height_cells: int, what: str) -> None:
    """Raise ValueError (the :func:`map_memory_problem` text) when a ``width x height`` grid is too big.

    Examples
    --------
    >>> check_map_size(100, 100, "m.png")
    >>> check_map_size(100_000, 100_000, "m.png (100000 x 100000 px)")
    Traceback (most recent call last):
    ...
    ValueError: m.png (100000 x 100000 px) has 10,000,000,000 cells, which needs about 372.5 GiB of memory (40 bytes per cell for the grid and its distance transform); expected at most 2.0 GiB (teamnav.world.grid.MAX_MAP_BYTES): use a coarser resolution_m or a smaller map
    """
    problem = map_memory_problem(int(width_cells) * int(height_cells), what)
    if problem is not None:
        raise ValueError(problem)


#: What each built-in sensor kind sees by default.
DEFAULT_SEES: dict[str, tuple[str, ...]] = {
    "laser": ("wall", "unknown", "foam"),
    "sonar": ("wall", "unknown", "glass"),
    "proximity": ("wall", "unknown", "glass", "foam"),
    "vision": ("wall", "unknown", "foam"),
}


@dataclass(frozen=True)
class OccupancyGrid:
    """A 2-D map: material ids on a regular grid.

    Parameters
    ----------
    cells : ndarray of shape (H, W), uint8
        Material id per cell, 0 = free. Row 0 is the lowest y.
    resolution_m : float
        Cell side [m].
    origin_xy_m : tuple of float
        World coordinates [m] of the lower-left corner of cell (0, 0).
    materials : tuple of str
        ``materials[k]`` names material id ``k``; ``materials[0] == "free"``.
    name : str
        Where the map came from (file path or generator), for messages.
    yaw_rad : float, default 0
        Rotation of the grid's axes in the world [rad], about ``origin_xy_m`` (map_server's
        origin yaw), kept as given (a map file's yaw is written back as it was read).

    Examples
    --------
    >>> g = OccupancyGrid.empty(2.0, 1.0, 0.5)
    >>> g.shape, g.size_m
    ((2, 4), (2.0, 1.0))
    """

    cells: np.ndarray
    resolution_m: float
    origin_xy_m: tuple[float, float] = (0.0, 0.0)
    materials: tuple[str, ...] = DEFAULT_MATERIALS
    name: str = "<code>"
    yaw_rad: float = 0.0
    _masks: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        cells = np.ascontiguousarray(self.cells, dtype=np.uint8)
        if cells.ndim != 2 or cells.shape[0] < 1 or cells.shape[1] < 1:
            raise ValueError(f"map {self.name}: cells must be a non-empty 2-D array, got shape {cells.shape}")
        if not (np.isfinite(self.resolution_m) and self.resolution_m > 0):
            raise ValueError(f"map {self.name}: resolution must be a positive number of metres, got {self.resolution_m!r}")
        if not all(np.isfinite(v) for v in self.origin_xy_m):
            raise ValueError(f"map {self.name}: origin must be finite, got {self.origin_xy_m!r}")
        if not self.materials or self.materials[0] != "free":
            raise ValueError(f"map {self.name}: materials[0] must be 'free', got {self.materials!r}")
        if int(cells.max()) >= len(self.materials):
            raise ValueError(
                f"map {self.name}: cell material id {int(cells.max())} has no name (known: {self.materials})"
            )
        if not np.isfinite(self.yaw_rad):
            raise ValueError(f"map {self.name}: yaw must be a finite angle in radians, got {self.yaw_rad!r}")
        object.__setattr__(self, "yaw_rad", float(self.yaw_rad) + 0.0)  # -0.0 -> 0.0
        cells.setflags(write=False)
        object.__setattr__(self, "cells", cells)
        object.__setattr__(self, "origin_xy_m", (float(self.origin_xy_m[0]), float(self.origin_xy_m[1])))
        object.__setattr__(self, "resolution_m", float(self.resolution_m))

    # ------------------------------------------------------------------ construction
    @classmethod
    def empty(cls, width_m: float, height_m: float, resolution_m: float, origin_xy_m=(0.0, 0.0), name="<empty>"):
        """An all-free grid covering ``width_m x height_m``."""
        w = int(round(width_m / resolution_m))
        h = int(round(height_m / resolution_m))
        return cls(np.zeros((h, w), np.uint8), resolution_m, origin_xy_m, DEFAULT_MATERIALS, name)

    def with_cells(self, cells: np.ndarray) -> "OccupancyGrid":
        """A copy with new cells and the same geometry and materials."""
        return OccupancyGrid(cells, self.resolution_m, self.origin_xy_m, self.materials, self.name, self.yaw_rad)

    def with_pose(self, origin_xy_m: tuple[float, float], yaw_rad: float = 0.0) -> "OccupancyGrid":
        """A copy with the same cells and materials placed at another origin and yaw."""
        return OccupancyGrid(self.cells, self.resolution_m, origin_xy_m, self.materials, self.name, yaw_rad)

    # ------------------------------------------------------------------ geometry
    @property
    def shape(self) -> tuple[int, int]:
        return self.cells.shape  # type: ignore[return-value]

    @property
    def size_m(self) -> tuple[float, float]:
        """(width, height) [m]."""
        return (self.cells.shape[1] * self.resolution_m, self.cells.shape[0] * self.resolution_m)

    @property
    def rotated(self) -> bool:
        """True when the grid's axes are turned in the world (``yaw_rad != 0``)."""
        return self.yaw_rad != 0.0

    @property
    def corners_m(self) -> np.ndarray:
        """World (x, y) of the map's four corners, shape (4, 2): lower-left, lower-right,
        upper-right, upper-left (in the grid's own axes)."""
        w, h = self.size_m
        return self.local_to_world(np.array([[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]))

    @property
    def bounds_m(self) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax) [m] of the map in the world: for a rotated grid, the
        axis-aligned box around its four corners."""
        ox, oy = self.origin_xy_m
        w, h = self.size_m
        if not self.rotated:
            return (ox, ox + w, oy, oy + h)
        c = self.corners_m
        return (float(c[:, 0].min()), float(c[:, 0].max()), float(c[:, 1].min()), float(c[:, 1].max()))

    def block_bounds_m(self, row0: int, row1: int, col0: int, col1: int) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax) [m] in the world of the cells ``row0..row1 x col0..col1``
        (inclusive): the axis-aligned box around the block's four outer corners."""
        rows = np.array([row0, row0, row1 + 1, row1 + 1], dtype=float)
        cols = np.array([col0, col1 + 1, col0, col1 + 1], dtype=float)
        c = self.cell_to_world(rows, cols)
        return (float(c[:, 0].min()), float(c[:, 0].max()), float(c[:, 1].min()), float(c[:, 1].max()))

    def world_to_local(self, xy: np.ndarray) -> np.ndarray:
        """Local-frame (x, y) [m] of world points ``xy`` (..., 2): ``R(-yaw) @ (xy - origin)``."""
        xy = np.asarray(xy, dtype=float)
        dx = xy[..., 0] - self.origin_xy_m[0]
        dy = xy[..., 1] - self.origin_xy_m[1]
        if not self.rotated:
            return np.stack([dx, dy], axis=-1)
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        return np.stack([c * dx + s * dy, -s * dx + c * dy], axis=-1)

    def local_to_world(self, xy: np.ndarray) -> np.ndarray:
        """World (x, y) [m] of local-frame points ``xy`` (..., 2): ``origin + R(yaw) @ xy``."""
        xy = np.asarray(xy, dtype=float)
        lx, ly = xy[..., 0], xy[..., 1]
        if not self.rotated:
            return np.stack([self.origin_xy_m[0] + lx, self.origin_xy_m[1] + ly], axis=-1)
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        return np.stack([self.origin_xy_m[0] + c * lx - s * ly, self.origin_xy_m[1] + s * lx + c * ly], axis=-1)

    def kernel_frame(self, xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
        """Positions and origin to hand a kernel that reads the cell array axis-aligned.

        Returns ``(xs, ys, ox, oy)``: for an unrotated grid the arrays as given and the
        grid's origin (nothing is computed, so kernels give the same bits as ever); for a
        rotated grid contiguous float64 local-frame positions and origin ``(0, 0)``.
        """
        if not self.rotated:
            return xs, ys, self.origin_xy_m[0], self.origin_xy_m[1]
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        dx = np.asarray(xs, dtype=np.float64) - self.origin_xy_m[0]
        dy = np.asarray(ys, dtype=np.float64) - self.origin_xy_m[1]
        return (np.ascontiguousarray(c * dx + s * dy), np.ascontiguousarray(-s * dx + c * dy), 0.0, 0.0)

    def kernel_theta(self, thetas: np.ndarray) -> np.ndarray:
        """Headings [rad] in the grid's local frame (``thetas - yaw_rad``; unchanged, not
        copied, for an unrotated grid). Not wrapped: kernels take their cos and sin."""
        if not self.rotated:
            return thetas
        return np.ascontiguousarray(np.asarray(thetas, dtype=np.float64) - self.yaw_rad)

    @property
    def geo(self) -> np.ndarray:
        """``[ox, oy, res, cos(yaw), sin(yaw)]``: the world-to-cell transform for the motion
        kernels (:func:`teamnav.sim.collisions.move_discs`)."""
        return np.array([self.origin_xy_m[0], self.origin_xy_m[1], self.resolution_m,
                         math.cos(self.yaw_rad), math.sin(self.yaw_rad)])

    def world_to_cell(self, xy: np.ndarray) -> np.ndarray:
        """Integer (row, col) of world points ``xy`` of shape (..., 2); may be out of range."""
        xy = np.asarray(xy, dtype=float)
        if self.rotated:
            local = self.world_to_local(xy)
            col = np.floor(local[..., 0] / self.resolution_m).astype(np.int64)
            row = np.floor(local[..., 1] / self.resolution_m).astype(np.int64)
            return np.stack([row, col], axis=-1)
        col = np.floor((xy[..., 0] - self.origin_xy_m[0]) / self.resolution_m).astype(np.int64)
        row = np.floor((xy[..., 1] - self.origin_xy_m[1]) / self.resolution_m).astype(np.int64)
        return np.stack([row, col], axis=-1)

    def cell_to_world(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """World (x, y) of fractional cell coordinates, shape (..., 2): ``(rows, cols) = (0, 0)``
        is the lower-left corner of cell (0, 0), ``(0.5, 0.5)`` its centre."""
        lx = np.asarray(cols, dtype=float) * self.resolution_m
        ly = np.asarray(rows, dtype=float) * self.resolution_m
        return self.local_to_world(np.stack([lx, ly], axis=-1))

    def cell_centers(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """World (x, y) of cell centres, shape (..., 2)."""
        if self.rotated:
            return self.cell_to_world(np.asarray(rows) + 0.5, np.asarray(cols) + 0.5)
        x = self.origin_xy_m[0] + (np.asarray(cols) + 0.5) * self.resolution_m
        y = self.origin_xy_m[1] + (np.asarray(rows) + 0.5) * self.resolution_m
        return np.stack([x, y], axis=-1)

    # ------------------------------------------------------------------ materials
    def material_id(self, name: str) -> int:
        try:
            return self.materials.index(name)
        except ValueError:
            raise ValueError(f"map {self.name}: unknown material {name!r}; known: {', '.join(self.materials)}") from None

    def visible_ids(self, sees: Iterable[str]) -> np.ndarray:
        """Boolean table of shape (n_materials,): which material ids block a sensor that sees ``sees``.

        Names the map does not contain are allowed (the sensor just never meets them).
        """
        table = np.zeros(len(self.materials), dtype=np.bool_)
        for name in sees:
            if name == "free":
                raise ValueError("a sensor cannot 'see' free space; remove 'free' from its materials")
            if name in self.materials:
                table[self.materials.index(name)] = True
        return table

    def blocking(self, sees: Iterable[str] | None = None) -> np.ndarray:
        """uint8 (H, W) mask, 1 where a cell stops a ray of a sensor that sees ``sees``.

        ``sees=None`` means every obstacle (what blocks motion). Masks are cached per grid; on a
        map of free and wall cells only, a mask that blocks walls is ``cells`` itself.
        """
        key = None if sees is None else tuple(sorted(set(sees)))
        mask = self._masks.get(key)
        if mask is None:
            table = None if key is None else self.visible_ids(key)  # (checks the names)
            top = self._masks.get("max id")
            if top is None:
                top = self._masks["max id"] = int(self.cells.max())
            if top == FREE or (top == WALL and (table is None or table[WALL])):
                # free and wall cells only, walls block: the mask is the cells, byte for byte;
                # hand out the (read-only) cells rather than a copy (25 MB for a 10 000-robot arena)
                mask = self.cells
            elif key is None:
                mask = (self.cells != FREE).astype(np.uint8)
            else:
                mask = table[self.cells].astype(np.uint8)
            mask.setflags(write=False)
            self._masks[key] = mask
        return mask

    def occupied(self) -> np.ndarray:
        """bool (H, W): cells a robot cannot enter (any non-free material)."""
        return self.cells != FREE

    def is_free_xy(self, xy: np.ndarray) -> np.ndarray:
        """bool (...): world points inside the map and in a free cell."""
        rc = self.world_to_cell(xy)
        h, w = self.shape
        inside = (rc[..., 0] >= 0) & (rc[..., 0] < h) & (rc[..., 1] >= 0) & (rc[..., 1] < w)
        out = np.zeros(inside.shape, dtype=bool)
        r = np.clip(rc[..., 0], 0, h - 1)
        c = np.clip(rc[..., 1], 0, w - 1)
        out[inside] = self.cells[r[inside], c[inside]] == FREE
        return out

    def free_cells(self) -> np.ndarray:
        """(n, 2) int array of (row, col) of free cells."""
        return np.argwhere(self.cells == FREE)
