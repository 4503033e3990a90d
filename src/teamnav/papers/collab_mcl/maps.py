"""The maps of Fox, Burgard, Kruppa & Thrun, *A probabilistic approach to collaborative multi-robot localization*.

- :func:`symmetric_hallway`: the symmetric hallway environment of §5.2.1, Fig. 12(a);
- :func:`hexagon`: the hexagon with 8 m edges of §5.2.2, Fig. 13;
- :func:`lab_and_corridor`: the cluttered lab beside a long corridor of §5.1, Fig. 8.

The paper gives them only as figures: what each map keeps from the text and figures, and
what is ours, is written in each function's docstring and in :attr:`EnvironmentMap.notes`.
They are reached by name through :func:`teamnav.world.generators.builtin_map`.
"""

from __future__ import annotations

import math

import numpy as np

from teamnav.world.map_builder import EnvironmentMap, MapBuilder, _res

__all__ = ["symmetric_hallway", "hexagon", "lab_and_corridor"]


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
