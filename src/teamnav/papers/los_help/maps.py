"""The maps of Sgorbissa & Arkin, *Local navigation strategies for a team of robots*.

- :func:`office_simple`: the simple office of §6, Fig. 11 (and the scenario of Fig. 1);
- :func:`office_complex`: the complex office of §6, Fig. 13, built to trap local methods
  (``alleys=False`` is the builtin ``office_complex_closed``);
- :func:`office_simple_grid`: not the paper's, a larger office of 21 copies of Fig. 11's for
  teams of up to 64 robots (the benchmarks' scaling row).

The paper gives both only as figures: what each map keeps from the text and figures, and
what is ours, is written in each function's docstring and in :attr:`EnvironmentMap.notes`.
They are reached by name through :func:`teamnav.world.generators.builtin_map`.
"""

from __future__ import annotations

from teamnav.world.map_builder import EnvironmentMap, MapBuilder, _res

__all__ = ["office_simple", "office_simple_grid", "office_complex", "wing_origin"]


def office_simple(resolution_m: float = 0.1) -> EnvironmentMap:
    """Sgorbissa & Arkin §6, Fig. 11 (and the scenario of Fig. 1): the simple office.

    A 30 m x 14 m building: one 2.4 m wide corridor along its length, five 5.8 m x 5.4 m
    rooms on each side, each with a 1.2 m door onto the corridor. Doors sit near one end of
    the room (not in front of the centre) so a robot heading for a room's centre from the
    corridor faces a wall: the local minimum that a potential field cannot leave (§6: PF
    alone fails in both scenarios). Walls are 0.2 m.

    Places: ``room_S1``..``room_S5`` (south, west to east) and ``room_N1``..``room_N5``
    (north) at room centres (R1's exploration targets are "in the middle of the rooms",
    §6); ``base`` at the corridor's west end (the base station at the entrance, Fig. 1);
    ``patrol_1``..``patrol_5`` along the corridor's centre line (helpers "patrol the
    corridors", §6).
    """
    res = _res(resolution_m)
    b = MapBuilder(30.0, 14.0, res).fill("wall")
    places: dict[str, tuple[float, float]] = {}
    _simple_wing(b, 0.0, 0.0, places, "")
    notes = (
        "Sgorbissa & Arkin §6 Fig. 11 (simple office): 30x14 m, corridor y in [5.8, 8.2] m, "
        "5 rooms each side (5.8x5.4 m) with 1.2 m doors near one end; targets at room centres; "
        "base station at the corridor's west end; helpers patrol the corridor centre line."
    )
    regions = {"corridor": (0.2, 5.8, 29.8, 8.2)}
    return EnvironmentMap(b.build("builtin:office_simple"), places, notes, regions)


#: Width and height [m] of one wing of :func:`office_simple_grid`: the simple office itself.
WING_W_M, WING_H_M = 30.0, 14.0
#: Width [m] of the north-south corridor between two columns of wings (the simple office's own
#: corridor width, 2.4 m).
CONNECTOR_W_M = 2.4


def _simple_wing(b: "MapBuilder", x0: float, y0: float, places: dict[str, tuple[float, float]], tag: str) -> None:
    """Carve the simple office of Fig. 11 (:func:`office_simple`) into a filled builder, its
    lower-left corner at (``x0``, ``y0``); its places are named with ``tag`` after the prefix
    (``room_S1`` with tag "" is office_simple's own name, ``room_w03_S1`` with tag "w03_")."""
    b.clear_rect(x0 + 0.2, y0 + 5.8, x0 + 29.8, y0 + 8.2)  # corridor
    xs = [(0.2, 5.8), (6.0, 11.8), (12.0, 17.8), (18.0, 23.8), (24.0, 29.8)]
    for k, (xa, xb) in enumerate(xs, start=1):
        xa, xb = x0 + xa, x0 + xb
        b.clear_rect(xa, y0 + 0.2, xb, y0 + 5.6)  # south room
        b.clear_rect(xa + 0.6, y0 + 5.6, xa + 1.8, y0 + 5.8)  # door near its west wall
        b.clear_rect(xa, y0 + 8.4, xb, y0 + 13.8)  # north room
        b.clear_rect(xb - 1.8, y0 + 8.2, xb - 0.6, y0 + 8.4)  # door near its east wall
        places[f"room_{tag}S{k}"] = (round((xa + xb) / 2, 3), round(y0 + 2.9, 3))
        places[f"room_{tag}N{k}"] = (round((xa + xb) / 2, 3), round(y0 + 11.1, 3))
    places[f"base{'_' + tag.rstrip('_') if tag else ''}"] = (round(x0 + 1.0, 3), round(y0 + 7.0, 3))
    for k, x in enumerate((3.0, 9.0, 15.0, 21.0, 27.0), start=1):
        places[f"patrol_{tag}{k}"] = (round(x0 + x, 3), round(y0 + 7.0, 3))


def wing_origin(wing: int, cols: int = 3) -> tuple[float, float]:
    """Lower-left corner [m] of wing ``wing`` (row-major from the south-west, ``cols`` per row)
    of :func:`office_simple_grid`."""
    if wing < 0:
        raise ValueError(f"wing must be >= 0, got {wing}")
    c, r = wing % cols, wing // cols
    return c * (WING_W_M + CONNECTOR_W_M), r * WING_H_M


def office_simple_grid(resolution_m: float = 0.1, cols: int = 3, rows: int = 7) -> EnvironmentMap:
    """A larger office for team sizes beyond the paper's: ``cols`` x ``rows`` copies ("wings") of
    the simple office of Fig. 11 (:func:`office_simple`), joined by their corridors.

    Not a map of the paper: §6 runs four robots on Fig. 11. This building is for scaling the
    team to 64 robots (the benchmarks' scaling row) while keeping what each robot meets what
    R1..R4 meet on Fig. 11: every wing is the simple office cell for cell (rooms of 5.8 x 5.4 m,
    1.2 m doors near one end, a 2.4 m corridor, 0.2 m walls; the same traps for a potential
    field), so a robot's laser, sightings and navigation see the paper's geometry. The default
    3 x 7 = 21 wings hold 63 helpers at three per wing, the paper's R2..R4 per office, so a
    64-robot team is as dense as the paper's team of four. Our choices: the wings sit in rows
    (row-major from the south-west, :func:`wing_origin`); between two columns runs a 2.4 m
    north-south corridor the height of the building, into which the east-west corridors of the
    wings beside it open (their end walls removed over the corridor's width); the north wall
    of one row's north rooms and the south wall of the next row's south rooms are back to back
    (0.4 m). The building is (30 cols + 2.4 (cols - 1)) m x 14 rows m: 94.8 m x 98 m by default.

    Places: per wing ``k`` (two digits), ``room_wKK_S1``..``room_wKK_N5``, ``base_wKK`` and
    ``patrol_wKK_1``..5, as office_simple's names; ``base`` is wing 0's base (R1's start).
    """
    res = _res(resolution_m)
    if int(cols) != cols or int(rows) != rows or cols < 1 or rows < 1:
        raise ValueError(f"cols and rows must be integers >= 1, got {cols!r} x {rows!r}")
    cols, rows = int(cols), int(rows)
    width, height = cols * WING_W_M + (cols - 1) * CONNECTOR_W_M, rows * WING_H_M
    b = MapBuilder(width, height, res).fill("wall")
    places: dict[str, tuple[float, float]] = {}
    regions: dict[str, tuple[float, float, float, float]] = {}
    for w in range(cols * rows):
        x0, y0 = wing_origin(w, cols)
        _simple_wing(b, x0, y0, places, f"w{w:02d}_")
        regions[f"corridor_w{w:02d}"] = (x0 + 0.2, y0 + 5.8, x0 + 29.8, y0 + 8.2)
    for c in range(cols - 1):  # north-south corridors between columns, the wings' corridors opening into them
        xa = (c + 1) * WING_W_M + c * CONNECTOR_W_M
        b.clear_rect(xa, 0.2, xa + CONNECTOR_W_M, height - 0.2)
        regions[f"connector_{c + 1}"] = (xa, 0.2, xa + CONNECTOR_W_M, height - 0.2)
        for r in range(rows):
            y0 = r * WING_H_M
            b.clear_rect(xa - 0.2, y0 + 5.8, xa + CONNECTOR_W_M + 0.2, y0 + 8.2)
    places["base"] = places["base_w00"]
    notes = (
        f"Beyond the paper (scaling): {cols}x{rows} wings, each Sgorbissa & Arkin §6 Fig. 11's simple office "
        f"(30x14 m), joined by {CONNECTOR_W_M} m north-south corridors between the columns into which the wings' "
        f"corridors open; {width:g}x{height:g} m; targets at room centres."
    )
    return EnvironmentMap(b.build("builtin:office_simple_grid" if (cols, rows) == (3, 7) else f"builtin:office_simple_grid_{cols}x{rows}"), places, notes, regions)


def _u_obstacle(b: "MapBuilder", xmin: float, ymin: float, xmax: float, ymax: float, opens: str,
                thickness_m: float = 0.3) -> None:
    """A U-shaped wall ``thickness_m`` thick on the box, open on side ``opens`` (N, S, E or W).

    Used by :func:`office_complex` only: the classic concave trap of a potential field
    (Koren & Borenstein, Sgorbissa & Arkin [6]) when it opens towards the robot."""
    t = thickness_m
    b.rect(xmin, ymin, xmax, ymax, filled=False, thickness_m=t)
    gap = {"N": (xmin + t, ymax - t, xmax - t, ymax), "S": (xmin + t, ymin, xmax - t, ymin + t),
           "E": (xmax - t, ymin + t, xmax, ymax - t), "W": (xmin, ymin + t, xmin + t, ymax - t)}[opens]
    b.clear_rect(*gap)


def office_complex(resolution_m: float = 0.1, alleys: bool = True) -> EnvironmentMap:
    """Sgorbissa & Arkin §6, Fig. 13: the complex office, built to trap local methods.

    A 36 m x 24 m building with a cross of 2.4 m corridors (east-west ``H`` at
    y in [10.8, 13.2] m, north-south ``V`` at x in [16.8, 19.2] m) and eight rooms in the
    four quarters, every one with a 1.2 m door onto ``H`` (room 6, 16.4 m wide, two; rooms 2,
    3, 6, 7 also one onto ``V``).

    What §6 asks of it, and how:

    - "target positions which are located in the middle of the rooms": places ``room_1`` ..
      ``room_8`` are the rooms' exact centres, with at least 1.5 m of free space around.
    - "other robots ... patrolling the corridors and supporting R1": the room's centre is in
      sight (line of sight within the 8 m visibility radius of the experiments) from its H
      doorway (place ``door_<k>``, 0.3 m past the corridor's edge), and so is every spot where a
      potential field stops in that room (the U pockets' bottoms, the walls' feet facing other
      rooms' targets): a helper stepping into the doorways on its patrol sees every target and
      a robot stuck in any room (§5 needs a teammate in sight). The first version opened rooms
      1, 2, 4, 6 and 8 to no corridor and hid their centres behind obstacles: helpers saw only
      rooms 3, 5 and 7 and made no measurable difference, unlike Table 2.
    - "more complex" than Fig. 11, with local minima a potential field cannot leave
      ("1) does not guarantee the robot to reach its target without the help of other robots
      because of the presence of local minima"): doors sit 1.5-4 m off the rooms' centre
      lines, so a robot heading at a centre from the corridor (or at a target across the
      corridor from inside a room) stops at a wall; rooms 1, 2, 4 and 8 hold U-shaped walls
      opening towards the room's centre where a robot leaving the centre for a target in the
      next room drives into them; rooms 6 and 7 hold pillars; rooms 3 and 4, and 7 and 8, are
      joined by inner doors (suites), and a second corridor gives a boundary follower long
      ways round. Gaps between an obstacle and a wall are >= 1.6 m or closed (VisBug-21
      circled a U standing 1 m from a wall).

    Where we fill a gap: the paper gives Fig. 13 as a picture only (no sizes or coordinates).

    ``alleys=False`` (builtin ``office_complex_closed``, b4059b2 of 2026-11-24, H7trap; the map of
    ``los-help-complex`` and of Table 2 / Fig. 17 since then): the 1.6 m alleys between the backs of the U walls of rooms 1, 2 and 8 and the
    room's wall are filled, so the U's back is flush with the wall. Why: Table 2's potential
    field with helpers finishes every task, so no trap of the paper's map was out of every
    helper's sight; on ``office_complex`` a potential field leaving the room's centre for the
    next room drives round the U into the alley and stops there, out of sight of every patrol
    route and of the doorway (tests/test_los_complex_traps.py); on the closed variant it stops
    inside the U instead, in sight of the doorway, as Fig. 13 draws it. Measured (40-target
    prefixes of tasks 1-5, default brains, office_complex -> closed; tasks finished, targets
    reached): potential field alone 0/5 (4/200) -> 0/5 (4/200), R1+R2 2/5 (116/200) -> 4/5
    (168/200), R1..R4 (tasks 1-4) 1/4 (65/160) -> 3/4 (121/160); VisBug-21 alone 350 -> 321 steps
    per target, R1..R4 286 -> 283; Avoid-Past alone 309 -> 345, R1..R4 -> 337 (measured before
    ``los-help-complex`` switched to it).

    Places: ``room_1``..``room_8`` (targets), ``door_<k>`` (H doorways; ``door_6w`` room 6's
    west one) and ``door_<k>v`` (V doorways, 0.3 m into the room), ``base`` at the west end of H
    (R1's start), ``patrol_*`` waypoints on both corridors and the ``junction``.
    """
    res = _res(resolution_m)
    b = MapBuilder(36.0, 24.0, res).fill("wall")
    b.clear_rect(0.2, 10.8, 35.8, 13.2)  # corridor H
    b.clear_rect(16.8, 0.2, 19.2, 23.8)  # corridor V
    # rooms: (xmin, ymin, xmax, ymax); south row's corridor wall is y 10.6-10.8, north row's 13.2-13.4
    rooms = {
        1: (0.2, 0.2, 8.2, 10.6), 2: (8.4, 0.2, 16.6, 10.6), 3: (19.4, 0.2, 24.6, 10.6),
        4: (24.8, 0.2, 30.2, 10.6), 5: (30.4, 0.2, 35.8, 10.6),
        6: (0.2, 13.4, 16.6, 23.8), 7: (19.4, 13.4, 27.4, 23.8), 8: (27.6, 13.4, 35.8, 23.8),
    }
    for box in rooms.values():
        b.clear_rect(*box)
    # doors on H (x range), 1.5-4 m off the room's centre line (room 6, 16.4 m wide, has two)
    h_doors = {1: (1.6, 2.8), 2: (9.8, 11.0), 3: (23.0, 24.2), 4: (28.8, 30.0), 5: (34.2, 35.4),
               6: (11.8, 13.0), "6w": (3.8, 5.0), 7: (20.8, 22.0), 8: (33.2, 34.4)}
    south = {1, 2, 3, 4, 5}
    for k, (x0, x1) in h_doors.items():
        y0, y1 = (10.6, 10.8) if k in south else (13.2, 13.4)
        b.clear_rect(x0, y0, x1, y1)
    # doors on V (y range): west side (rooms 2, 6: wall x 16.6-16.8), east side (3, 7: x 19.2-19.4)
    v_doors = {2: (1.0, 2.2), 3: (8.8, 10.0), 6: (22.0, 23.2), 7: (14.2, 15.4)}
    for k, (y0, y1) in v_doors.items():
        x0, x1 = (16.6, 16.8) if k in (2, 6) else (19.2, 19.4)
        b.clear_rect(x0, y0, x1, y1)
    b.clear_rect(24.6, 1.0, 24.8, 2.2)  # suite door room 3 <-> room 4 (south end)
    b.clear_rect(27.4, 22.2, 27.6, 23.4)  # suite door room 7 <-> room 8 (north end)
    # traps: U walls open towards the room's centre, on the way out to other rooms, their
    # pockets in sight from the room's doorway (so a helper there sees a robot stuck inside)
    _u_obstacle(b, 5.2, 3.4, 6.6, 7.4, "W")  # room 1: east of the centre (4.2, 5.4)
    _u_obstacle(b, 13.6, 3.4, 15.0, 7.4, "W")  # room 2: east of the centre (12.5, 5.4)
    _u_obstacle(b, 24.8, 3.6, 26.0, 7.2, "E")  # room 4: a bay in its west wall, west of the centre (27.5, 5.4)
    _u_obstacle(b, 29.2, 16.2, 30.6, 21.0, "E")  # room 8: west of the centre (31.7, 18.6)
    if not alleys:  # the U's back flush with the room's wall (builtin office_complex_closed)
        b.rect(6.6, 3.4, 8.2, 7.4).rect(15.0, 3.4, 16.6, 7.4).rect(27.6, 16.2, 29.2, 21.0)
    b.disc(5.0, 20.6, 0.4).disc(12.0, 20.6, 0.4)  # room 6: pillars north of its centre
    b.disc(22.4, 21.4, 0.4).disc(25.4, 16.0, 0.4)  # room 7: pillars off the door-centre line
    places: dict[str, tuple[float, float]] = {}
    for k, (x0, y0, x1, y1) in rooms.items():
        places[f"room_{k}"] = (round((x0 + x1) / 2, 3), round((y0 + y1) / 2, 3))
    for k, (x0, x1) in h_doors.items():
        places[f"door_{k}"] = (round((x0 + x1) / 2, 3), 10.5 if k in south else 13.5)
    for k, (y0, y1) in v_doors.items():
        places[f"door_{k}v"] = (16.5 if k in (2, 6) else 19.5, round((y0 + y1) / 2, 3))
    places.update({
        "base": (1.0, 12.0),
        "patrol_H1": (8.0, 12.0),
        "patrol_H2": (28.0, 12.0),
        "patrol_V1": (18.0, 5.0),
        "patrol_V2": (18.0, 19.0),
        "junction": (18.0, 12.0),
    })
    notes = (
        "Sgorbissa & Arkin §6 Fig. 13 (complex office): 36x24 m, cross-shaped 2.4 m corridors, "
        "8 rooms each with a 1.2 m door off its centre line on the east-west corridor (rooms 2, 3, 6, 7 "
        "also on the north-south one), U-shaped walls opening towards four room centres, pillars, and two "
        "suites of joined rooms; targets at room centres, each in sight from its doorway."
    )
    regions = {"corridor_H": (0.2, 10.8, 35.8, 13.2), "corridor_V": (16.8, 0.2, 19.2, 23.8)}
    name = "builtin:office_complex" if alleys else "builtin:office_complex_closed"
    return EnvironmentMap(b.build(name), places, notes, regions)
