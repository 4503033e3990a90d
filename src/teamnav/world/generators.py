"""Maps built from code: the environments of the four papers, and the registry of built-in maps.

The papers show their environments only as figures, so these maps are faithful to what the
text and figures say (sizes, topology, what makes each one hard) and are otherwise plain
office geometry. Every choice is written in the generator's docstring and in
:attr:`EnvironmentMap.notes`.

All lengths are metres; all maps default to 0.1 m cells. Nothing here is random.

Where things are: the drawing tool (:class:`MapBuilder`, :class:`EnvironmentMap`, and its
rasterisation rule) is :mod:`teamnav.world.map_builder`. This module keeps
:data:`BUILTIN_MAPS` and :func:`builtin_map`, and every name above stays importable from here.
"""

from __future__ import annotations

import functools

import difflib
import math
from typing import Callable

import numpy as np

from teamnav.world.map_builder import EnvironmentMap, MapBuilder, _res
from teamnav.world.maps_los_help import office_simple, office_complex

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


# ---------------------------------------------------------------------------- Fox et al.
def symmetric_hallway(resolution_m: float = 0.1) -> EnvironmentMap:
    """Fox, Burgard, Kruppa & Thrun §5.2.1, Fig. 12(a): the symmetric hallway environment.

    A square ring of 2 m wide hallways, 26 m on a side (centre lines 24 m apart). The west
    hallway opens into a 6 m x 10 m open space ``A``; the north (``B``), east (``C``) and
    south (``D``) hallways are identical: each has two 1.5 m x 1 m alcoves in its outer wall,
    4 m either side of its midpoint. So the map's only symmetry is the mirror about the
    horizontal centre line, and locally every hallway B, C, D looks the same: a robot must
    "either pass the open space A, or move through all other hallways B, C and D" (§5.2.1)
    to know where it is.

    Places: ``A``, ``B``, ``C``, ``D`` (region centres) and ``corner_NE``, ``corner_SE``,
    ``corner_NW``, ``corner_SW``. Regions: the four named areas.
    """
    res = _res(resolution_m)
    lo, hi, w = 1.5, 27.5, 2.0  # ring's outer edge and hallway width
    mid = (lo + hi) / 2
    b = MapBuilder(29.0, 29.0, res).fill("wall")
    b.clear_rect(lo, hi - w, hi, hi)  # B north
    b.clear_rect(hi - w, lo, hi, hi)  # C east
    b.clear_rect(lo, lo, hi, lo + w)  # D south
    b.clear_rect(lo, lo, lo + w, hi)  # west hallway
    b.clear_rect(lo, mid - 5.0, lo + 6.0, mid + 5.0)  # open space A
    for off in (-4.0, 4.0):
        b.clear_rect(mid + off - 0.75, hi, mid + off + 0.75, hi + 1.0)  # B alcoves
        b.clear_rect(hi, mid + off - 0.75, hi + 1.0, mid + off + 0.75)  # C alcoves
        b.clear_rect(mid + off - 0.75, lo - 1.0, mid + off + 0.75, lo)  # D alcoves
    regions = {
        "A": (lo, mid - 5.0, lo + 6.0, mid + 5.0),
        "B": (lo + w, hi - w, hi - w, hi),
        "C": (hi - w, lo + w, hi, hi - w),
        "D": (lo + w, lo, hi - w, lo + w),
    }
    places = {k: ((r[0] + r[2]) / 2, (r[1] + r[3]) / 2) for k, r in regions.items()}
    c = w / 2
    places.update(
        {
            "corner_NE": (hi - c, hi - c),
            "corner_SE": (hi - c, lo + c),
            "corner_NW": (lo + c, hi - c),
            "corner_SW": (lo + c, lo + c),
        }
    )
    notes = (
        "Fox et al. §5.2.1 Fig. 12(a): square ring of 2 m hallways (26 m outer side); west side "
        "opens into a 6x10 m open space A; hallways B (north), C (east), D (south) are identical, "
        "each with two alcoves 4 m either side of its midpoint; only mirror symmetry about y=14.5 m."
    )
    return EnvironmentMap(b.build("builtin:symmetric_hallway"), places, notes, regions)


def hexagon(resolution_m: float = 0.1) -> EnvironmentMap:
    """Fox, Burgard, Kruppa & Thrun §5.2.2, Fig. 13: the hexagon with 8 m edges.

    A regular hexagon (circumradius 8 m, flat top and bottom) centred at (8.5, 7.5) m.
    Interior obstacles are discs of radius 0.6 m made of materials only one sensor sees:

    - ``glass`` (sonar only), at polar angles 20° and 200°, 4.5 m from the centre: the
      hexagon's symmetries that keep them are the identity and the 180° turn, so a
      sonar robot keeps two hypotheses;
    - ``foam`` (laser only), at 100°, 220° and 340°, 2.5 m from the centre: kept by the
      120° and 240° turns, so a laser robot keeps three hypotheses.

    No mirror of the hexagon keeps either set, and the only rotation keeping both is the
    identity, so only a team mixing sensors (sharing beliefs at detections) can localize
    uniquely, as §5.2.2 requires ("any robot equipped with only one of the sensor types is
    not able to determine uniquely where it is").

    Places: ``centre`` and ``start_0``..``start_5`` 2 m inside each vertex. Regions: the
    obstacles' bounding boxes (``glass_1``, ``glass_2``, ``foam_1``..``foam_3``).
    """
    res = _res(resolution_m)
    cx, cy, radius = 8.5, 7.5, 8.0
    angles = np.deg2rad(np.arange(6) * 60.0)
    verts = [(cx + radius * math.cos(a), cy + radius * math.sin(a)) for a in angles]
    b = MapBuilder(17.0, 15.0, res).fill("wall").clear_polygon(verts)
    regions: dict[str, tuple[float, float, float, float]] = {}
    r_obs = 0.6
    for k, deg in enumerate((20.0, 200.0), start=1):
        x, y = cx + 4.5 * math.cos(math.radians(deg)), cy + 4.5 * math.sin(math.radians(deg))
        b.disc(x, y, r_obs, material="glass")
        regions[f"glass_{k}"] = (x - r_obs, y - r_obs, x + r_obs, y + r_obs)
    for k, deg in enumerate((100.0, 220.0, 340.0), start=1):
        x, y = cx + 2.5 * math.cos(math.radians(deg)), cy + 2.5 * math.sin(math.radians(deg))
        b.disc(x, y, r_obs, material="foam")
        regions[f"foam_{k}"] = (x - r_obs, y - r_obs, x + r_obs, y + r_obs)
    places = {"centre": (cx, cy)}
    for k, a in enumerate(angles):
        places[f"start_{k}"] = (round(cx + (radius - 2.0) * math.cos(a), 6), round(cy + (radius - 2.0) * math.sin(a), 6))
    notes = (
        "Fox et al. §5.2.2 Fig. 13: regular hexagon, 8 m edges; glass discs (sonar only) at 20/200 deg "
        "(2-fold symmetric), foam discs (laser only) at 100/220/340 deg (3-fold); together unique."
    )
    return EnvironmentMap(b.build("builtin:hexagon"), places, notes, regions)


def lab_and_corridor(resolution_m: float = 0.1) -> EnvironmentMap:
    """Fox, Burgard, Kruppa & Thrun §5.1, Fig. 8: a cluttered lab beside a long corridor.

    A 40 m x 2.2 m corridor with bare, featureless walls (so a robot in it "generally has
    to travel a long distance" to resolve its position and even its heading, §5.1), and an
    8 m x 7.3 m lab south of it, joined by a 1.6 m opening near the lab's west end. The lab
    is cluttered and non-symmetric (desk, cabinet, round table, boxes) so a robot in it
    knows "fairly well where it is". Marian, in the lab, faces the opening (``observer``,
    heading +90°); Robin travels the corridor (``corridor_west`` to ``corridor_east``).
    """
    res = _res(resolution_m)
    b = MapBuilder(42.0, 12.0, res).fill("wall")
    b.clear_rect(1.0, 8.5, 41.0, 10.7)  # corridor
    b.clear_rect(22.0, 1.0, 30.0, 8.3)  # lab
    b.clear_rect(23.0, 8.3, 24.6, 8.5)  # opening
    b.rect(26.0, 1.0, 29.6, 2.0)  # desk along the south wall
    b.rect(29.4, 3.0, 30.0, 6.6)  # cabinet on the east wall
    b.disc(25.6, 4.4, 0.7)  # round table
    b.rect(22.0, 1.0, 23.3, 3.0)  # boxes in the south-west corner
    b.rect(27.2, 6.6, 28.4, 8.3)  # shelf against the north wall
    places = {
        "observer": (23.8, 6.6),
        "lab_centre": (27.0, 4.6),
        "lab_door": (23.8, 9.6),
        "corridor_west": (2.5, 9.6),
        "corridor_east": (39.5, 9.6),
    }
    regions = {"corridor": (1.0, 8.5, 41.0, 10.7), "lab": (22.0, 1.0, 30.0, 8.3)}
    notes = (
        "Fox et al. §5.1 Fig. 8: 40x2.2 m featureless corridor; 8x7.3 m cluttered, non-symmetric lab "
        "south of it with a 1.6 m opening at x in [23.0, 24.6] m; the observer (Marian) faces the "
        "opening (heading +90 deg)."
    )
    return EnvironmentMap(b.build("builtin:lab_and_corridor"), places, notes, regions)


# ---------------------------------------------------------------------------- Vaughan et al.
def trail_office(resolution_m: float = 0.1, *, doors: bool = True, shape: str = "u") -> EnvironmentMap:
    """Vaughan, Støy, Sukhatme & Matarić: the office used in both trail papers.

    "Blazing a trail" §5: "the resource separated from the home position by two corners and
    approximately 33 m of corridors"; §5.1: Ant came home "correctly turning right at both
    corners", and "The correct turn is the same at each of the two corners"; "Try to see it my
    way" §3.2: "two corners and 31 m of corridor ... the robots must make two correct turning
    decisions". Their Fig. 4 / Fig. 1 show part of an office building with narrow corridors and
    small rooms.

    What the papers give: two corners, the route length, the same turn at both corners, narrow
    corridors and small rooms. **Ours** (the papers give no numbers): the 1.8 m corridor width,
    0.2 m walls, the 36 m x 24 m building, the rooms and 1 m doors, the passing places and every
    dead-end branch (which junction offers which wrong turn, and how long it is).

    Geometry (``shape="u"``, the default: a C/U shape, left at both corners going out, right at
    both coming home, as the paper's robots turned):

    - ``home`` at the west end of the south corridor C1 (y = 4.9 m);
    - corner 1 at x = 14.9 m: turn north (left) into C2; C1 also carries on east (a wrong turn:
      a dead end past three rooms, 17.6 m to ``c1_dead_end``);
    - corner 2 at y = 15.9 m: turn west (left) into the north corridor C3; C2 also carries on
      north into a room, and C3 also runs east to a dead end (two more wrong turns);
    - ``source`` in C3 at x = 5.4 m, 9.5 m past corner 2; C3 goes on west to the wall (x = 0.2).

    ``shape="z"`` (builtin ``trail_office_z``): the map of sessions 1-11, Z-shaped (left, then
    right): C3 runs east from corner 2 to ``source`` at x = 24.4 m and on to a dead end, and west
    to x = 6.0 m (a wrong turn). Kept for comparison with the earlier measurements.

    Centre-line route length 12.9 + 11.0 + 9.5 = 33.4 m in both shapes; a robot of radius 0.25 m
    cutting the corners drives about 31.5 m, between the two papers' 31 m and 33 m. Rooms open off
    every corridor through 1 m doors. Each corridor has a 2 m long passing place on the route
    where it widens to 2.6–2.8 m (walled off from the room it cuts into), since the robots (50 cm
    wide) must pass each other ("passing within as little as 40 cm of each other", Blazing §4).

    ``doors=False`` closes every room door (builtin ``trail_office_corridors``,
    ``trail_office_z_corridors``): Blazing §6 "in these experiments we deliberately worked only in
    the corridors". The wrong turns at the junctions stay, as dead-end corridors.
    """
    if shape not in ("u", "z"):
        raise ValueError(f"shape must be 'u' or 'z', got {shape!r}")
    res = _res(resolution_m)
    b = MapBuilder(36.0, 24.0, res).fill("wall")
    # corridors
    b.clear_rect(0.2, 4.0, 34.0, 5.8)  # C1, y centre 4.9
    b.clear_rect(14.0, 4.0, 15.8, 23.8)  # C2, x centre 14.9; goes on north past C3 to a dead end
    if shape == "z":
        b.clear_rect(6.0, 15.0, 35.8, 16.8)  # C3, y centre 15.9
        b.clear_rect(19.0, 16.8, 21.0, 17.8)  # C3's passing place (into the wall below N2, which starts at y = 18)
    else:
        b.clear_rect(0.2, 15.0, 35.8, 16.8)  # C3, y centre 15.9, from the west wall to the east dead end

    def door(*rect: float) -> None:
        if doors:
            b.clear_rect(*rect)

    # rooms south of C1 (doors on C1)
    for x0, x1 in ((0.2, 5.8), (6.0, 11.8), (16.0, 22.0), (22.2, 28.0), (28.2, 34.0)):
        b.clear_rect(x0, 0.2, x1, 3.8)
        door(x0 + 1.0, 3.8, x0 + 2.0, 4.0)
    # rooms between C1 and C3, west and east of C2
    b.clear_rect(0.2, 6.0, 5.8, 14.8)  # W1, door on C1
    door(4.6, 5.8, 5.6, 6.0)
    b.clear_rect(6.0, 6.0, 13.8, 14.8)  # W2, door on C3
    door(6.5, 14.8, 7.5, 15.0)
    b.clear_rect(16.0, 6.0, 24.0, 14.8)  # E1, door on C1
    door(16.0, 5.8, 17.0, 6.0)
    b.clear_rect(24.2, 6.0, 35.8, 14.8)  # E2, door on C3
    door(33.0, 14.8, 34.0, 15.0)
    # rooms north of C3
    b.clear_rect(0.2, 17.0, 13.8, 23.8)  # N1 (west of C2)
    door(8.0, 16.8, 9.0, 17.0)
    b.clear_rect(16.0, 18.0, 24.0, 23.8)  # N2
    door(22.0, 17.8, 23.0, 18.0)
    b.clear_rect(24.2, 17.0, 35.8, 23.8)  # N3
    door(30.0, 16.8, 31.0, 17.0)
    door(15.8, 21.0, 16.0, 22.0)  # C2's north end also opens into N2
    # The passing places on C1 and C2 are pockets cut into rooms W2 and E1: wall them off from
    # the room (0.2 m walls), so they widen the corridor without opening a 2 m doorway.
    b.rect(6.8, 6.6, 9.2, 6.8).rect(6.8, 6.0, 7.0, 6.8).rect(9.0, 6.0, 9.2, 6.8)
    b.clear_rect(7.0, 5.8, 9.0, 6.6)
    b.rect(16.6, 8.8, 16.8, 11.2).rect(16.0, 8.8, 16.8, 9.0).rect(16.0, 11.0, 16.8, 11.2)
    b.clear_rect(15.8, 9.0, 16.6, 11.0)
    if shape == "u":
        # C3's passing place on the route (x 10-12, between corner 2 and the source): a pocket cut
        # into room N1, walled off from it like C1's, 0.8 m deep (C3 2.6 m wide there)
        b.rect(9.8, 17.6, 12.2, 17.8).rect(9.8, 17.0, 10.0, 17.8).rect(12.0, 17.0, 12.2, 17.8)
        b.clear_rect(10.0, 16.8, 12.0, 17.6)
    source_x = 5.4 if shape == "u" else 24.4
    places = {
        "home": (2.0, 4.9),
        "source": (source_x, 15.9),
        "corner_1": (14.9, 4.9),
        "corner_2": (14.9, 15.9),
        "c1_dead_end": (32.5, 4.9),
        "c3_west_end": (1.0, 15.9) if shape == "u" else (7.0, 15.9),
        "c3_east_end": (34.5, 15.9),
    }
    c3 = (0.2, 15.0, 35.8, 16.8) if shape == "u" else (6.0, 15.0, 35.8, 16.8)
    regions = {"C1": (0.2, 4.0, 34.0, 5.8), "C2": (14.0, 4.0, 15.8, 23.8), "C3": c3}
    turn = ("C1 east 12.9 m, left into C2 north 11.0 m, left into C3 west 9.5 m: the same turn at both corners"
            if shape == "u" else "C1 east 12.9 m, left into C2 north 11.0 m, right into C3 east 9.5 m (Z shape)")
    notes = (
        f"Vaughan et al. (Blazing §5, Try-to-see §3.2): home and source ~32 m apart through two "
        f"corners ({turn}); every junction offers a wrong turn into dead ends and rooms; 1.8 m corridors "
        f"with 2.6-2.8 m passing places (corridor width, passing places, rooms and dead ends are ours)."
    )
    name = {("u", True): "builtin:trail_office", ("u", False): "builtin:trail_office_corridors",
            ("z", True): "builtin:trail_office_z", ("z", False): "builtin:trail_office_z_corridors"}[(shape, doors)]
    return EnvironmentMap(b.build(name), places, notes, regions)


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
