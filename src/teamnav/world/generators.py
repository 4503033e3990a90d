"""Maps built from code: the registry of built-in maps, and the one place that names them all.

The papers show their environments only as figures, so these maps are faithful to what the
text and figures say (sizes, topology, what makes each one hard) and are otherwise plain
office geometry. Every choice is written in the generator's docstring and in
:attr:`EnvironmentMap.notes`.

All lengths are metres; all maps default to 0.1 m cells. Nothing here is random.

Where things are:

- :mod:`teamnav.world.map_builder`: the drawing tool, :class:`MapBuilder` (and its
  rasterisation rule), and :class:`EnvironmentMap`;
- :mod:`teamnav.world.maps_los_help`: Sgorbissa & Arkin's offices (``office_simple``,
  ``office_complex``);
- :mod:`teamnav.world.maps_collab_mcl`: Fox et al.'s ``symmetric_hallway``, ``hexagon`` and
  ``lab_and_corridor``;
- :mod:`teamnav.world.maps_trails`: Vaughan et al.'s ``trail_office``.

This module keeps :data:`BUILTIN_MAPS` and :func:`builtin_map`, and every name in
``__all__`` stays importable from here.
"""

from __future__ import annotations

import difflib
import functools
from typing import Callable

from teamnav.world.map_builder import EnvironmentMap, MapBuilder
from teamnav.world.maps_collab_mcl import hexagon, lab_and_corridor, symmetric_hallway
from teamnav.world.maps_los_help import office_complex, office_simple
from teamnav.world.maps_trails import trail_office

__all__ = [
    "MapBuilder",
    "EnvironmentMap",
    "office_simple",
    "office_complex",
    "symmetric_hallway",
    "hexagon",
    "lab_and_corridor",
    "trail_office",
    "BUILTIN_MAPS",
    "builtin_map",
]


# ---------------------------------------------------------------------------- registry
BUILTIN_MAPS: dict[str, Callable[[], EnvironmentMap]] = {
    "office_simple": office_simple,
    "office_complex": office_complex,
    "office_complex_closed": functools.partial(office_complex, alleys=False),
    "symmetric_hallway": symmetric_hallway,
    "hexagon": hexagon,
    "lab_and_corridor": lab_and_corridor,
    "trail_office": trail_office,
    "trail_office_corridors": functools.partial(trail_office, doors=False),
    "trail_office_z": functools.partial(trail_office, shape="z"),
    "trail_office_z_corridors": functools.partial(trail_office, doors=False, shape="z"),
}


def builtin_map(name: str) -> EnvironmentMap:
    """Build the built-in environment ``name`` (a key of :data:`BUILTIN_MAPS`).

    Raises
    ------
    ValueError
        For an unknown name, with a "did you mean" hint and the known names.

    Examples
    --------
    >>> builtin_map("hexagon").grid.shape
    (150, 170)
    """
    try:
        factory = BUILTIN_MAPS[name]
    except (KeyError, TypeError):
        close = difflib.get_close_matches(str(name), BUILTIN_MAPS, n=1)
        hint = f" Did you mean {close[0]!r}?" if close else ""
        raise ValueError(f"unknown built-in map {name!r}.{hint} Known maps: {', '.join(sorted(BUILTIN_MAPS))}") from None
    return factory()
