"""The toy paper's map: an empty walled box."""

from teamnav.world.map_builder import EnvironmentMap, MapBuilder


def toy_box(resolution_m: float = 0.1, width_m: float = 6.0) -> EnvironmentMap:
    grid = MapBuilder(width_m, 4.0, resolution_m).border(0.2).build("toy_box")
    return EnvironmentMap(grid=grid, places={"centre": (width_m / 2, 2.0)}, notes="an empty box")
