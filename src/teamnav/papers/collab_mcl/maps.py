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

__all__ = ["CORRIDOR_DOORS_X", "LAB_DOOR_X", "symmetric_hallway", "hexagon", "lab_and_corridor"]


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

    - ``glass`` (sonar only), at polar angles 100°, 220° and 340°, 2.5 m from the centre:
      kept by the 120° and 240° turns, so a sonar robot keeps three hypotheses;
    - ``foam`` (laser only), at 20° and 200°, 4.5 m from the centre: the hexagon's symmetries
      that keep them are the identity and the 180° turn, so a laser robot keeps two.

    §5.2.2: "robots using sonar sensors for localization cannot distinguish between three
    possible robot locations (see Fig. 13(c)), robots equipped with laser range-finders remain
    uncertain about two possible locations". Until 2026-11-29 the materials were the other way
    round (sonar two, laser three).

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
    for k, deg in enumerate((100.0, 220.0, 340.0), start=1):
        x, y = cx + 2.5 * math.cos(math.radians(deg)), cy + 2.5 * math.sin(math.radians(deg))
        b.disc(x, y, r_obs, material="glass")
        regions[f"glass_{k}"] = (x - r_obs, y - r_obs, x + r_obs, y + r_obs)
    for k, deg in enumerate((20.0, 200.0), start=1):
        x, y = cx + 4.5 * math.cos(math.radians(deg)), cy + 4.5 * math.sin(math.radians(deg))
        b.disc(x, y, r_obs, material="foam")
        regions[f"foam_{k}"] = (x - r_obs, y - r_obs, x + r_obs, y + r_obs)
    places = {"centre": (cx, cy)}
    for k, a in enumerate(angles):
        places[f"start_{k}"] = (round(cx + (radius - 2.0) * math.cos(a), 6), round(cy + (radius - 2.0) * math.sin(a), 6))
    notes = (
        "Fox et al. §5.2.2 Fig. 13: regular hexagon, 8 m edges; glass discs (sonar only) at 100/220/340 deg "
        "(3-fold symmetric: sonar robots keep 3 locations), foam discs (laser only) at 20/200 deg (2-fold: "
        "laser robots keep 2); together unique."
    )
    return EnvironmentMap(b.build("builtin:hexagon"), places, notes, regions)


#: Door centres along the §5.1 corridor [m]: every 5 m on both sides; the lab's is 23.8 m.
CORRIDOR_DOORS_X: tuple[float, ...] = tuple(3.8 + 5.0 * k for k in range(12))
#: The lab's door centre [m] (Marian faces it).
LAB_DOOR_X: float = 23.8


def _office(b: MapBuilder, xc: float, south: bool) -> None:
    """One office of :func:`lab_and_corridor`: a 4.6 m x 4 m room behind a 1.6 m door centred at
    ``xc``, with a desk along its far wall and a round table beside the door's east jamb. A north
    office is the south one turned by 180° about the point (xc, 9.6) (the corridor's centre line),
    so the corridor looks the same driven east or west."""
    def box(x0, y0, x1, y1, clear=False):
        if not south:  # 180° turn about (xc, 9.6)
            x0, y0, x1, y1 = 2 * xc - x1, 19.2 - y1, 2 * xc - x0, 19.2 - y0
        (b.clear_rect if clear else b.rect)(x0, y0, x1, y1)

    def disc(x, y, r):
        if not south:
            x, y = 2 * xc - x, 19.2 - y
        b.disc(x, y, r)

    box(xc - 2.3, 4.3, xc + 2.3, 8.3, clear=True)  # room
    box(xc - 0.8, 8.3, xc + 0.8, 8.5, clear=True)  # door
    box(xc - 1.6, 4.3, xc + 1.2, 5.0)              # desk along the far wall
    disc(xc + 1.4, 6.4, 0.45)                      # round table


def lab_and_corridor(resolution_m: float = 0.1) -> EnvironmentMap:
    """Fox, Burgard, Kruppa & Thrun §5.1, Fig. 8: a long corridor with many similar offices, one
    of them the lab.

    A 60.6 m x 2.2 m corridor (x 1.0 .. 61.6 m, y 8.5 .. 10.7 m) with 12 doors on each side,
    1.6 m wide, every 5 m (:data:`CORRIDOR_DOORS_X`), each into a 4.6 m x 4 m office with a desk and
    a round table. The offices are alike and the north ones are the south ones turned by 180°
    about the corridor's centre line, so the whole corridor is symmetric under the 180° turn about
    its centre (31.3, 9.6) and, away from its ends, periodic with the door spacing. The lab is the
    south office at x = 23.8 m (:data:`LAB_DOOR_X`). Marian, in the lab, faces its door
    (``observer``, heading +90°); Robin travels the corridor eastwards.

    From the paper: Fig. 8 shows a long corridor lined with doors and offices; Robin, passing the
    lab after "several meters" of travel, is "still highly uncertain about its exact location
    within the corridor and even does not know its global heading direction ... due to the lack of
    features in the corridor the robots generally have to travel a long distance" (§5.1). Ours:
    the sizes, the 5 m spacing, the furniture and the exact symmetry, chosen (2026-11-29, on tuning
    seeds 1000-1009, docs/report/collab-mcl.md) so that the precondition holds: Robin alone is
    still multi-modal when it passes the lab. Until 2026-11-29 the corridor was bare with a single
    opening, the lab's, which localized Robin by itself before the detection.
    """
    res = _res(resolution_m)
    b = MapBuilder(62.6, 16.0, res).fill("wall")
    b.clear_rect(1.0, 8.5, 61.6, 10.7)  # corridor
    for xc in CORRIDOR_DOORS_X:
        _office(b, xc, south=True)
        _office(b, xc, south=False)
    lab = (LAB_DOOR_X - 2.3, 4.3, LAB_DOOR_X + 2.3, 8.3)
    places = {
        "observer": (LAB_DOOR_X, 6.6),
        "lab_centre": (LAB_DOOR_X, 6.3),
        "lab_door": (LAB_DOOR_X, 9.6),
        "corridor_west": (2.5, 9.6),
        "corridor_east": (60.1, 9.6),
    }
    regions = {"corridor": (1.0, 8.5, 61.6, 10.7), "lab": lab}
    notes = (
        "Fox et al. §5.1 Fig. 8: a 60.6x2.2 m corridor with 12 alike offices (4.6x4 m, desk and round table) on "
        "each side behind 1.6 m doors every 5 m, north ones the south ones turned by 180 deg; the lab is the "
        f"south office with its door at x = {LAB_DOOR_X} m; the observer (Marian) faces that door (heading +90 deg)."
    )
    return EnvironmentMap(b.build("builtin:lab_and_corridor"), places, notes, regions)
