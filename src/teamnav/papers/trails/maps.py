"""The map of Vaughan, Støy, Sukhatme & Matarić's two trail papers.

:func:`trail_office`: the office of *Blazing a trail: insect-inspired resource transportation
by a robot team* (§5, Fig. 4) and *Try to see it my way: using task-level features to
transform between reference frames in robot teams* (§3.2, Fig. 1); its variants are the
builtins ``trail_office_corridors``, ``trail_office_z`` and ``trail_office_z_corridors``.

The papers give no numbers beyond two corners and the route length: what the map keeps from
them, and what is ours, is written in the function's docstring and in
:attr:`EnvironmentMap.notes`. It is reached by name through
:func:`teamnav.world.generators.builtin_map`.
"""

from __future__ import annotations

from teamnav.world.map_builder import EnvironmentMap, MapBuilder, _res

__all__ = ["trail_office"]


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

    ``shape="z"`` (builtin ``trail_office_z``): the map until 9fe1783 (2026-11-27), Z-shaped (left, then
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
