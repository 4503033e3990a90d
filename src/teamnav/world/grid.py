"""Occupancy grid with a material layer.

Every cell holds a material id (``uint8``): ``0`` is free space, any other id is an
obstacle made of the material named ``grid.materials[id]``. Robots collide with every
non-free cell. Range sensors, however, declare which materials they *see* (a laser passes
through glass, a sonar echoes off it), so the Fox et al. hexagon (§5.2.2), whose obstacles
only one sensor type perceives, is just a map with two materials.

Conventions (ROS REP 103 and map_server):

- ``cells[row, col]``: row 0 is the *lowest* y (the bottom of the map image), so the array
  is the image flipped vertically.
- cell ``(row, col)`` covers ``[ox + col*res, ox + (col+1)*res) x [oy + row*res, oy + (row+1)*res)``
  where ``(ox, oy) = origin_xy_m``.
"""

from __future__ import annotations

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
        return OccupancyGrid(cells, self.resolution_m, self.origin_xy_m, self.materials, self.name)

    # ------------------------------------------------------------------ geometry
    @property
    def shape(self) -> tuple[int, int]:
        return self.cells.shape  # type: ignore[return-value]

    @property
    def size_m(self) -> tuple[float, float]:
        """(width, height) [m]."""
        return (self.cells.shape[1] * self.resolution_m, self.cells.shape[0] * self.resolution_m)

    @property
    def bounds_m(self) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax) [m]."""
        ox, oy = self.origin_xy_m
        w, h = self.size_m
        return (ox, ox + w, oy, oy + h)

    def world_to_cell(self, xy: np.ndarray) -> np.ndarray:
        """Integer (row, col) of world points ``xy`` of shape (..., 2); may be out of range."""
        xy = np.asarray(xy, dtype=float)
        col = np.floor((xy[..., 0] - self.origin_xy_m[0]) / self.resolution_m).astype(np.int64)
        row = np.floor((xy[..., 1] - self.origin_xy_m[1]) / self.resolution_m).astype(np.int64)
        return np.stack([row, col], axis=-1)

    def cell_centers(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """World (x, y) of cell centres, shape (..., 2)."""
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

        ``sees=None`` means every obstacle (what blocks motion). Masks are cached per grid.
        """
        key = None if sees is None else tuple(sorted(set(sees)))
        mask = self._masks.get(key)
        if mask is None:
            if key is None:
                mask = (self.cells != FREE).astype(np.uint8)
            else:
                mask = self.visible_ids(key)[self.cells].astype(np.uint8)
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
