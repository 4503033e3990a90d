"""The world: occupancy grids with materials, map I/O, map generators and numba kernels."""

from teamnav.world.generators import BUILTIN_MAPS, EnvironmentMap, MapBuilder, builtin_map
from teamnav.world.grid import DEFAULT_MATERIALS, DEFAULT_SEES, OccupancyGrid
from teamnav.world.mapio import MapError, load_map, save_map

__all__ = [
    "BUILTIN_MAPS", "DEFAULT_MATERIALS", "DEFAULT_SEES", "EnvironmentMap", "MapBuilder", "MapError",
    "OccupancyGrid", "builtin_map", "load_map", "save_map",
]
