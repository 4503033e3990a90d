"""The world: occupancy grids with materials, map I/O, map generators and numba kernels."""

from teamnav.world.grid import DEFAULT_MATERIALS, DEFAULT_SEES, OccupancyGrid

__all__ = ["DEFAULT_MATERIALS", "DEFAULT_SEES", "OccupancyGrid"]
