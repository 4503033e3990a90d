"""The drawing tool of the built-in maps: :class:`MapBuilder` and :class:`EnvironmentMap`.

:class:`MapBuilder` draws an :class:`~teamnav.world.grid.OccupancyGrid` from rectangles,
polygons, thick segments, discs, corridors and rooms; :class:`EnvironmentMap` is what a
built-in map is (the grid plus named places and regions). The papers' maps drawn with it, and
their registry, are reached through :mod:`teamnav.world.generators`.

All lengths are metres. Nothing here is random.

Rasterisation rule: a shape covers the cells whose *centres* lie inside it (boundaries
included), except :meth:`MapBuilder.segment`, which also covers every cell its centre line
passes through, so a thin wall never leaks a ray or a robot.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field
from typing import Iterable, Sequence

import numpy as np

from teamnav.world.grid import DEFAULT_MATERIALS, OccupancyGrid

__all__ = ["MapBuilder", "EnvironmentMap"]

SIDES: tuple[str, ...] = ("north", "south", "east", "west")


def _finite(name: str, v) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v):
        raise ValueError(f"{name} must be a finite number of metres, got {v!r}")
    return float(v)


def _positive(name: str, v) -> float:
    v = _finite(name, v)
    if v <= 0:
        raise ValueError(f"{name} must be > 0 m, got {v!r}")
    return v


class MapBuilder:
    """Draw a map with rectangles, polygons, thick segments, discs, corridors and rooms.

    Every drawing method returns the builder, so calls chain. Later calls paint over
    earlier ones, with one exception that makes buildings easy to draw: cells opened by
    :meth:`clear_rect`, :meth:`corridor` or :meth:`room` (interiors and doors) are
    *carved*, and the walls that :meth:`corridor` and :meth:`room` draw never close a
    carved cell. So corridors that cross stay open, and a room drawn against a corridor
    does not block it. Explicit obstacles (:meth:`rect`, :meth:`polygon`, :meth:`segment`,
    :meth:`disc`, :meth:`border`, :meth:`fill`) paint over everything.

    Parameters
    ----------
    width_m, height_m : float
        Map size [m], positive.
    resolution_m : float
        Cell side [m], positive, at most the map size.
    origin_xy_m : (float, float), default (0, 0)
        World coordinates [m] of the lower-left corner.

    Examples
    --------
    >>> g = (MapBuilder(4.0, 3.0, 0.5).border(0.5)
    ...      .rect(1.5, 1.0, 2.5, 2.0, material="glass").build("demo"))
    >>> g.shape, int((g.cells == 3).sum())
    ((6, 8), 4)
    """

    def __init__(self, width_m: float, height_m: float, resolution_m: float, origin_xy_m=(0.0, 0.0)) -> None:
        self.width_m = _positive("width_m", width_m)
        self.height_m = _positive("height_m", height_m)
        self.resolution_m = _positive("resolution_m", resolution_m)
        if self.resolution_m > min(self.width_m, self.height_m):
            raise ValueError(
                f"resolution_m must be at most the map's width and height ({min(self.width_m, self.height_m)} m), got {resolution_m!r}"
            )
        if not isinstance(origin_xy_m, (tuple, list)) or len(origin_xy_m) != 2:
            raise ValueError(f"origin_xy_m must be a pair (x_m, y_m), got {origin_xy_m!r}")
        self.origin_xy_m = (_finite("origin_xy_m[0]", origin_xy_m[0]), _finite("origin_xy_m[1]", origin_xy_m[1]))
        w = int(round(self.width_m / self.resolution_m))
        h = int(round(self.height_m / self.resolution_m))
        self._cells = np.zeros((h, w), dtype=np.uint8)
        self._carved = np.zeros((h, w), dtype=bool)
        self._materials: list[str] = list(DEFAULT_MATERIALS)
        self._xc = self.origin_xy_m[0] + (np.arange(w) + 0.5) * self.resolution_m  # cell centres
        self._yc = self.origin_xy_m[1] + (np.arange(h) + 0.5) * self.resolution_m

    # ------------------------------------------------------------------ helpers
    def _mat(self, material: str) -> int:
        if not isinstance(material, str) or not material:
            raise ValueError(f"material must be a non-empty material name, got {material!r}")
        if material not in self._materials:
            if len(self._materials) >= 256:
                raise ValueError(f"a map holds at most 256 materials; cannot add {material!r}")
            self._materials.append(material)
        return self._materials.index(material)

    def _box(self, name: str, xmin, ymin, xmax, ymax) -> tuple[float, float, float, float]:
        xmin, ymin = _finite(f"{name}: xmin", xmin), _finite(f"{name}: ymin", ymin)
        xmax, ymax = _finite(f"{name}: xmax", xmax), _finite(f"{name}: ymax", ymax)
        if not (xmin < xmax and ymin < ymax):
            raise ValueError(f"{name}: need xmin < xmax and ymin < ymax, got ({xmin}, {ymin}, {xmax}, {ymax})")
        return xmin, ymin, xmax, ymax

    def _rect_mask(self, xmin, ymin, xmax, ymax) -> np.ndarray:
        cols = (self._xc >= xmin) & (self._xc <= xmax)
        rows = (self._yc >= ymin) & (self._yc <= ymax)
        return rows[:, None] & cols[None, :]

    def _paint(self, mask: np.ndarray, material: str, *, respect_carved: bool = False) -> None:
        mid = self._mat(material)
        if respect_carved:
            mask = mask & ~self._carved
        self._cells[mask] = mid

    def _carve(self, mask: np.ndarray) -> None:
        self._cells[mask] = 0
        self._carved |= mask

    def _centres(self) -> tuple[np.ndarray, np.ndarray]:
        return np.meshgrid(self._xc, self._yc)

    # ------------------------------------------------------------------ drawing
    def fill(self, material: str = "wall") -> "MapBuilder":
        """Paint the whole map with ``material`` (start a building as solid, then carve)."""
        self._paint(np.ones_like(self._carved), material)
        self._carved[:] = False
        return self

    def border(self, thickness_m: float, material: str = "wall") -> "MapBuilder":
        """A closed wall of ``thickness_m`` (>= one cell) along the map's edges."""
        t = _positive("border: thickness_m", thickness_m)
        if t < self.resolution_m:
            raise ValueError(f"border: thickness_m must be at least one cell ({self.resolution_m} m), got {thickness_m!r}")
        x0, y0 = self.origin_xy_m
        inner = self._rect_mask(x0 + t, y0 + t, x0 + self.width_m - t, y0 + self.height_m - t)
        self._paint(~inner, material)
        return self

    def rect(self, xmin, ymin, xmax, ymax, material: str = "wall", filled: bool = True, thickness_m: float | None = None) -> "MapBuilder":
        """An axis-aligned rectangle, filled, or its outline with walls ``thickness_m`` thick
        drawn inside the rectangle's bounds (required when ``filled=False``)."""
        xmin, ymin, xmax, ymax = self._box("rect", xmin, ymin, xmax, ymax)
        mask = self._rect_mask(xmin, ymin, xmax, ymax)
        if not filled:
            if thickness_m is None:
                raise ValueError("rect: thickness_m is required for an outline (filled=False)")
            t = _positive("rect: thickness_m", thickness_m)
            if t < self.resolution_m:
                raise ValueError(f"rect: thickness_m must be at least one cell ({self.resolution_m} m), got {thickness_m!r}")
            if 2 * t < min(xmax - xmin, ymax - ymin):
                mask &= ~self._rect_mask(xmin + t, ymin + t, xmax - t, ymax - t)
        self._paint(mask, material)
        return self

    def clear_rect(self, xmin, ymin, xmax, ymax) -> "MapBuilder":
        """Carve free space (see the class docstring for *carved* cells)."""
        xmin, ymin, xmax, ymax = self._box("clear_rect", xmin, ymin, xmax, ymax)
        self._carve(self._rect_mask(xmin, ymin, xmax, ymax))
        return self

    def clear_polygon(self, vertices: Sequence[Sequence[float]]) -> "MapBuilder":
        """Carve a filled polygon out of the map."""
        self._carve(self._polygon_mask(vertices, "clear_polygon"))
        return self

    def _polygon_mask(self, vertices, name: str) -> np.ndarray:
        v = np.asarray(vertices, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3 or not np.all(np.isfinite(v)):
            raise ValueError(f"{name}: vertices must be at least 3 finite (x_m, y_m) points, got {vertices!r}")
        px, py = self._centres()
        inside = np.zeros(px.shape, dtype=bool)
        xj, yj = v[-1]
        for xi, yi in v:  # even-odd rule, one pass per edge, vectorised over cells
            crosses = (yi > py) != (yj > py)
            with np.errstate(divide="ignore", invalid="ignore"):
                x_at = (xj - xi) * (py - yi) / (yj - yi) + xi
            inside ^= crosses & (px < x_at)
            xj, yj = xi, yi
        return inside

    def polygon(self, vertices: Sequence[Sequence[float]], material: str = "wall") -> "MapBuilder":
        """A filled polygon (any simple or self-intersecting outline, even-odd rule)."""
        self._paint(self._polygon_mask(vertices, "polygon"), material)
        return self

    def segment(self, x0, y0, x1, y1, thickness_m: float, material: str = "wall") -> "MapBuilder":
        """A thick straight wall: cells within ``thickness_m / 2`` of the segment, and at
        least every cell the segment passes through (within half a cell diagonal)."""
        x0, y0 = _finite("segment: x0", x0), _finite("segment: y0", y0)
        x1, y1 = _finite("segment: x1", x1), _finite("segment: y1", y1)
        t = _positive("segment: thickness_m", thickness_m)
        reach = max(t / 2.0, self.resolution_m / math.sqrt(2.0))
        px, py = self._centres()
        dx, dy = x1 - x0, y1 - y0
        length2 = dx * dx + dy * dy
        if length2 == 0.0:
            s = np.zeros_like(px)
        else:
            s = np.clip(((px - x0) * dx + (py - y0) * dy) / length2, 0.0, 1.0)
        dist = np.hypot(px - (x0 + s * dx), py - (y0 + s * dy))
        self._paint(dist <= reach, material)
        return self

    def disc(self, x, y, r, material: str = "wall") -> "MapBuilder":
        """A filled disc of radius ``r`` [m] centred at (x, y)."""
        x, y = _finite("disc: x", x), _finite("disc: y", y)
        r = _positive("disc: r", r)
        px, py = self._centres()
        self._paint(np.hypot(px - x, py - y) <= r, material)
        return self

    def corridor(self, x0, y0, x1, y1, width_m: float, wall_thickness_m: float) -> "MapBuilder":
        """A straight corridor from (x0, y0) to (x1, y1): free space ``width_m`` wide with a
        wall ``wall_thickness_m`` thick along each side; both ends are left open."""
        x0, y0 = _finite("corridor: x0", x0), _finite("corridor: y0", y0)
        x1, y1 = _finite("corridor: x1", x1), _finite("corridor: y1", y1)
        w = _positive("corridor: width_m", width_m)
        t = _positive("corridor: wall_thickness_m", wall_thickness_m)
        if t < self.resolution_m:
            raise ValueError(f"corridor: wall_thickness_m must be at least one cell ({self.resolution_m} m), got {wall_thickness_m!r}")
        length = math.hypot(x1 - x0, y1 - y0)
        if length == 0.0:
            raise ValueError(f"corridor: the two ends must differ, got ({x0}, {y0}) twice")
        ux, uy = (x1 - x0) / length, (y1 - y0) / length
        px, py = self._centres()
        along = (px - x0) * ux + (py - y0) * uy
        across = np.abs(-(px - x0) * uy + (py - y0) * ux)
        span = (along >= 0.0) & (along <= length)
        inside = span & (across <= w / 2.0)
        walls = span & (across > w / 2.0) & (across <= w / 2.0 + t)
        self._paint(walls, "wall", respect_carved=True)
        self._carve(inside)
        return self

    def room(
        self,
        xmin,
        ymin,
        xmax,
        ymax,
        wall_thickness_m: float,
        doors: Iterable[tuple[str, float, float]] = (),
    ) -> "MapBuilder":
        """A room: walls ``wall_thickness_m`` thick inside the bounds, a carved interior and
        door openings.

        Parameters
        ----------
        xmin, ymin, xmax, ymax : float
            Outer bounds of the walls [m].
        wall_thickness_m : float
            At least one cell.
        doors : iterable of (side, offset_m, width_m)
            ``side`` in {"north", "south", "east", "west"}; ``offset_m`` is the distance
            from the side's west end (north/south sides) or south end (east/west sides),
            i.e. from ``xmin`` or ``ymin``, to the door's centre; ``width_m`` its width.
            The opening must lie between the two corner walls.
        """
        xmin, ymin, xmax, ymax = self._box("room", xmin, ymin, xmax, ymax)
        t = _positive("room: wall_thickness_m", wall_thickness_m)
        if t < self.resolution_m:
            raise ValueError(f"room: wall_thickness_m must be at least one cell ({self.resolution_m} m), got {wall_thickness_m!r}")
        if 2 * t >= min(xmax - xmin, ymax - ymin):
            raise ValueError(f"room: walls of {t} m leave no interior in ({xmin}, {ymin}, {xmax}, {ymax})")
        openings = []
        for i, door in enumerate(doors):
            if not isinstance(door, (tuple, list)) or len(door) != 3:
                raise ValueError(f"room: doors[{i}] must be (side, offset_m, width_m), got {door!r}")
            side, offset, width = door
            if side not in SIDES:
                close = difflib.get_close_matches(str(side), SIDES, n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                raise ValueError(f"room: doors[{i}] side must be one of {SIDES}{hint}, got {side!r}")
            offset = _finite(f"room: doors[{i}] offset_m", offset)
            width = _positive(f"room: doors[{i}] width_m", width)
            side_len = (xmax - xmin) if side in ("north", "south") else (ymax - ymin)
            if offset - width / 2 < t or offset + width / 2 > side_len - t:
                raise ValueError(
                    f"room: doors[{i}] must lie between the corner walls: need {t + width / 2} <= offset_m <= {side_len - t - width / 2}, got {offset}"
                )
            a, b = offset - width / 2, offset + width / 2
            if side == "south":
                openings.append((xmin + a, ymin, xmin + b, ymin + t))
            elif side == "north":
                openings.append((xmin + a, ymax - t, xmin + b, ymax))
            elif side == "west":
                openings.append((xmin, ymin + a, xmin + t, ymin + b))
            else:
                openings.append((xmax - t, ymin + a, xmax, ymin + b))
        outer = self._rect_mask(xmin, ymin, xmax, ymax)
        interior = self._rect_mask(xmin + t, ymin + t, xmax - t, ymax - t)
        self._paint(outer & ~interior, "wall", respect_carved=True)
        self._carve(interior)
        for box in openings:
            self._carve(self._rect_mask(*box))
        return self

    def build(self, name: str) -> OccupancyGrid:
        """The finished :class:`OccupancyGrid` (a copy; the builder can keep drawing)."""
        return OccupancyGrid(self._cells.copy(), self.resolution_m, self.origin_xy_m, tuple(self._materials), name)


@dataclass(frozen=True)
class EnvironmentMap:
    """A built-in environment: the grid plus named places for experiments.

    Attributes
    ----------
    grid : OccupancyGrid
    places : dict of str to (float, float)
        Named points [m] in free space (targets, home/source, start spots, patrol
        waypoints); all reachable from one another by a robot of radius 0.25 m.
    notes : str
        Where the geometry comes from and which choices were made.
    regions : dict of str to (xmin, ymin, xmax, ymax)
        Named areas [m], e.g. the hallways "A"–"D" of Fox et al. Fig. 12(a).
    """

    grid: OccupancyGrid
    places: dict[str, tuple[float, float]]
    notes: str
    regions: dict[str, tuple[float, float, float, float]] = field(default_factory=dict)


def _res(resolution_m: float) -> float:
    r = _positive("resolution_m", resolution_m)
    if r > 0.25:
        raise ValueError(f"resolution_m must be at most 0.25 m for the built-in maps (walls are 0.2-0.3 m), got {resolution_m!r}")
    return r
