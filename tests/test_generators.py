"""Map builder and the papers' built-in environments."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.ndimage as ndi
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from teamnav.world.generators import BUILTIN_MAPS, EnvironmentMap, MapBuilder, builtin_map
from teamnav.world.grid import FOAM, FREE, GLASS, WALL
from teamnav.world.mapio import load_map, save_map

ROBOT_RADIUS_M = 0.25
EIGHT = np.ones((3, 3), bool)


def _clear_of_obstacles(grid, radius_m=ROBOT_RADIUS_M) -> np.ndarray:
    """bool (H, W): free cells whose centre is farther than radius_m from any obstacle cell."""
    return ndi.distance_transform_edt(grid.cells == FREE) * grid.resolution_m > radius_m


def _shortest_path_m(grid, a, b, radius_m=ROBOT_RADIUS_M) -> float:
    """Dijkstra over 8-connected cells with clearance > radius_m (octile metric)."""
    ok = _clear_of_obstacles(grid, radius_m)
    h, w = ok.shape
    idx = -np.ones((h, w), np.int64)
    idx[ok] = np.arange(ok.sum())
    rows, cols, weights = [], [], []
    for dr, dc, cost in ((0, 1, 1.0), (1, 0, 1.0), (1, 1, math.sqrt(2)), (1, -1, math.sqrt(2))):
        r0, r1 = slice(0, h - dr), slice(dr, h)
        c0 = slice(max(0, -dc), w - max(0, dc))
        c1 = slice(max(0, dc), w + min(0, dc))
        both = ok[r0, c0] & ok[r1, c1]
        rows.append(idx[r0, c0][both])
        cols.append(idx[r1, c1][both])
        weights.append(np.full(int(both.sum()), cost))
    n = int(ok.sum())
    graph = coo_matrix((np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)).tocsr()
    (ra, ca), (rb, cb) = grid.world_to_cell(np.array(a)), grid.world_to_cell(np.array(b))
    assert idx[ra, ca] >= 0 and idx[rb, cb] >= 0, "endpoints need robot clearance"
    d = dijkstra(graph, directed=False, indices=int(idx[ra, ca]))
    return float(d[idx[rb, cb]]) * grid.resolution_m


@pytest.fixture(scope="module", params=sorted(BUILTIN_MAPS))
def env(request) -> EnvironmentMap:
    return builtin_map(request.param)


# ---------------------------------------------------------------------------- every built-in map
def test_border_is_closed(env):
    labels, _ = ndi.label(env.grid.cells == FREE, structure=EIGHT)  # 8-connected: stricter
    edge = np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]])
    assert not np.any(edge), f"{env.grid.name}: free space reaches the map edge"


def test_places_are_free_with_clearance_and_mutually_connected(env):
    g = env.grid
    assert len(env.places) >= 2
    ok = _clear_of_obstacles(g)
    labels, _ = ndi.label(ok)
    seen = set()
    for name, xy in env.places.items():
        assert g.is_free_xy(np.array(xy)), f"{g.name}: place {name} at {xy} is not in free space"
        r, c = g.world_to_cell(np.array(xy))
        assert ok[r, c], f"{g.name}: place {name} at {xy} is closer than {ROBOT_RADIUS_M} m to an obstacle"
        seen.add(int(labels[r, c]))
    assert len(seen) == 1, f"{g.name}: places lie in {len(seen)} disconnected regions"


def test_regions_lie_inside_the_map(env):
    xmin, xmax, ymin, ymax = env.grid.bounds_m
    for name, (x0, y0, x1, y1) in env.regions.items():
        assert xmin <= x0 < x1 <= xmax and ymin <= y0 < y1 <= ymax, name


def test_builtin_maps_are_deterministic_and_round_trip_through_files(env, tmp_path):
    name = env.grid.name.split(":", 1)[1]
    again = builtin_map(name)
    np.testing.assert_array_equal(again.grid.cells, env.grid.cells)
    assert again.places == env.places
    loaded = load_map(save_map(env.grid, tmp_path / f"{name}.yaml"))
    np.testing.assert_array_equal(loaded.cells, env.grid.cells)
    assert loaded.materials == env.grid.materials


# ---------------------------------------------------------------------------- paper-specific checks
def test_hexagon_has_glass_and_foam_and_8m_edges():
    env = builtin_map("hexagon")
    g = env.grid
    assert (g.cells == GLASS).sum() > 50 and (g.cells == FOAM).sum() > 50
    assert set(env.regions) == {"glass_1", "glass_2", "glass_3", "foam_1", "foam_2"}
    # a laser does not see glass, a sonar does not see foam
    laser = g.blocking(("wall", "unknown", "foam"))
    sonar = g.blocking(("wall", "unknown", "glass"))
    assert not laser[g.cells == GLASS].any() and sonar[g.cells == GLASS].all()
    assert not sonar[g.cells == FOAM].any() and laser[g.cells == FOAM].all()
    # flat-topped regular hexagon with 8 m edges: 16 m wide at the centre row, 8*sqrt(3) m tall
    cx, cy = env.places["centre"]
    r, c = g.world_to_cell(np.array([cx, cy]))
    row_free = np.flatnonzero(g.cells[r] != WALL)
    col_free = np.flatnonzero(g.cells[:, c] != WALL)
    assert row_free.size * g.resolution_m == pytest.approx(16.0, abs=2 * g.resolution_m)
    assert col_free.size * g.resolution_m == pytest.approx(8 * math.sqrt(3), abs=2 * g.resolution_m)


def test_hexagon_symmetries_per_sensor():
    """Sonar map keeps a 120° symmetry (three locations), laser map a 180° one (two), the union
    neither (Fox §5.2.2: sonar robots "cannot distinguish between three possible robot
    locations", laser robots "remain uncertain about two")."""
    env = builtin_map("hexagon")
    cx, cy = env.places["centre"]

    def centres(prefix):
        return np.array([((x0 + x1) / 2 - cx, (y0 + y1) / 2 - cy) for k, (x0, y0, x1, y1) in env.regions.items() if k.startswith(prefix)])

    def invariant(pts, deg):
        a = math.radians(deg)
        rot = pts @ np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])
        return all(np.min(np.hypot(*(pts - p).T)) < 1e-6 for p in rot)

    glass, foam = centres("glass"), centres("foam")
    assert invariant(glass, 120) and not invariant(glass, 180) and not invariant(glass, 60)
    assert invariant(foam, 180) and not invariant(foam, 120) and not invariant(foam, 60)


def test_trail_office_home_source_path_length():
    env = builtin_map("trail_office")
    length = _shortest_path_m(env.grid, env.places["home"], env.places["source"])
    # Vaughan et al.: ~31 m (Try to see it my way §3.2) / ~33 m (Blazing a trail §5) of corridor
    assert 31.0 * 0.9 <= length <= 33.0 * 1.1, length
    # straight-line distance is much shorter: the route really turns two corners
    straight = math.dist(env.places["home"], env.places["source"])
    assert straight < 0.8 * length


def test_trail_office_corridors_closes_rooms_but_keeps_the_route_and_wrong_turns():
    """Blazing §6: "we deliberately worked only in the corridors"."""
    open_env, closed = builtin_map("trail_office"), builtin_map("trail_office_corridors")
    route = _shortest_path_m(closed.grid, closed.places["home"], closed.places["source"])
    assert route == pytest.approx(_shortest_path_m(open_env.grid, open_env.places["home"], open_env.places["source"]))
    for env, rooms_reachable in ((open_env, True), (closed, False)):
        labels, _ = ndi.label(_clear_of_obstacles(env.grid))
        home = labels[tuple(env.grid.world_to_cell(np.array(env.places["home"])))]
        for room_xy in ((3.0, 10.0), (20.0, 10.0), (20.0, 21.0), (3.0, 2.0)):  # W1, E1, N2, a south room
            here = labels[tuple(env.grid.world_to_cell(np.array(room_xy)))]
            assert bool(here == home) is rooms_reachable, (env.grid.name, room_xy)
        for wrong_turn in ("c1_dead_end", "c3_west_end", "c3_east_end"):
            xy = np.array(env.places[wrong_turn])
            assert labels[tuple(env.grid.world_to_cell(xy))] == home


def _office_complex_rooms(env):
    """office_complex's rooms: free space eroded by 0.65 m (its 1.2 m doors close), one label per room."""
    yy, xx = np.mgrid[-7:8, -7:8]
    eroded = ndi.binary_erosion(env.grid.cells == FREE, structure=(xx ** 2 + yy ** 2) <= 6.5 ** 2)
    return ndi.label(eroded)[0]


def test_office_complex_targets_are_in_the_middle_of_eight_separate_rooms():
    """Sgorbissa & Arkin §6: "target positions which are located in the middle of the rooms"."""
    env = builtin_map("office_complex")
    g, res = env.grid, env.grid.resolution_m
    labels = _office_complex_rooms(env)
    corridor = labels[tuple(g.world_to_cell(np.array(env.places["junction"])))]
    seen = set()
    clear = ndi.distance_transform_edt(g.cells == FREE) * res
    for k in range(1, 9):
        xy = env.places[f"room_{k}"]
        cell = tuple(g.world_to_cell(np.array(xy)))
        lab = labels[cell]
        assert lab not in (0, corridor) and lab not in seen, k
        seen.add(lab)
        comp = labels == lab
        rows, cols = comp.sum(1), comp.sum(0)  # extents over the rows / columns that are most of the room
        ry, cx = np.nonzero(rows >= 0.2 * rows.max())[0], np.nonzero(cols >= 0.2 * cols.max())[0]
        mid = ((cx.min() + cx.max() + 1) * res / 2, (ry.min() + ry.max() + 1) * res / 2)
        assert mid == pytest.approx(xy, abs=0.15), (k, mid, xy)
        assert clear[cell] >= 1.5, (k, clear[cell])  # nothing sits on a target


def _sees(occ, res, a, b, max_range_m=8.0) -> bool:
    n = int(math.dist(a, b) / 0.02) + 2
    xs, ys = np.linspace(a[0], b[0], n), np.linspace(a[1], b[1], n)
    return math.dist(a, b) <= max_range_m and not occ[(ys / res).astype(int), (xs / res).astype(int)].any()


def test_office_complex_targets_are_seen_from_their_doorways_and_hardly_from_the_corridors():
    """A helper stepping into a doorway sees the room's target (8 m visibility); a robot on the
    corridors' centre lines sees any target from less than 8 % of them (the doors sit off the rooms'
    centre lines: a robot heading at a target from the corridor meets a wall)."""
    env = builtin_map("office_complex")
    occ, res = np.asarray(env.grid.occupied()), env.grid.resolution_m
    line = [(x, 12.0) for x in np.arange(1.0, 35.01, 0.25)] + [(18.0, y) for y in np.arange(1.0, 23.01, 0.25)]
    for k in range(1, 9):
        target = env.places[f"room_{k}"]
        assert _sees(occ, res, env.places[f"door_{k}"], target), k
        frac = np.mean([_sees(occ, res, p, target) for p in line])
        assert frac < 0.08, (k, frac)
        assert not _sees(occ, res, env.places["junction"], target)
    # and a doorway shows one room only: door k does not see another room's target
    for k in range(1, 9):
        others = [j for j in range(1, 9) if j != k and _sees(occ, res, env.places[f"door_{k}"], env.places[f"room_{j}"])]
        assert others == [], (k, others)


def test_symmetric_hallway_regions_and_mirror_symmetry():
    env = builtin_map("symmetric_hallway")
    assert set(env.regions) == {"A", "B", "C", "D"}
    free = env.grid.cells == FREE
    assert np.array_equal(free, free[::-1]), "mirror symmetry about the horizontal centre line"
    assert not np.array_equal(free, free[:, ::-1]), "open space A breaks the left-right symmetry"
    assert not np.array_equal(free, np.rot90(free, 2))
    # hallway C (east) looks exactly like hallway B (north) turned by 90 degrees
    g = env.grid

    def patch(x0, y0, x1, y1):
        (r0, c0), (r1, c1) = g.world_to_cell(np.array([[x0, y0], [x1, y1]]))
        return free[r0:r1, c0:c1]

    bx0, by0, bx1, by1 = env.regions["B"]
    cx0, cy0, cx1, cy1 = env.regions["C"]
    b = patch(bx0, by0 - 1.5, bx1, by1 + 1.5)
    c = patch(cx0 - 1.5, cy0, cx1 + 1.5, cy1)
    assert b.any() and c.any()
    assert np.array_equal(np.rot90(c, 1), b) or np.array_equal(np.rot90(c, -1), b)
    # ... while the west side (with A) does not
    w = patch(0.0, cy0, 5.0, cy1)  # west hallway, same span and depth as C's patch
    assert not (np.array_equal(np.rot90(w, 1), b) or np.array_equal(np.rot90(w, -1), b))


def test_corridor_has_alike_offices_and_looks_the_same_both_ways():
    """Fox §5.1 / Fig. 8: a long corridor lined with alike doors and offices, the lab one of them;
    the map is symmetric under the 180° turn about the corridor's centre and periodic with the
    door spacing away from its ends, so a robot in it stays unsure of its place and heading."""
    from teamnav.papers.collab_mcl.maps import CORRIDOR_DOORS_X, LAB_DOOR_X

    env = builtin_map("lab_and_corridor")
    g = env.grid
    x0, y0, x1, y1 = env.regions["corridor"]
    (r0, c0), (r1, c1) = g.world_to_cell(np.array([[x0 + 0.05, 4.35], [x1 - 0.05, 14.85]]))
    block = g.cells[r0:r1 + 1, c0:c1 + 1] == FREE
    assert np.array_equal(block, block[::-1, ::-1])  # 180° turn about (31.3, 9.6)
    period = int(round(5.0 / g.resolution_m))
    inner = block[:, period:-period]
    assert np.array_equal(inner[:, period:], inner[:, :-period])  # one office pair repeats every 5 m
    assert LAB_DOOR_X in CORRIDOR_DOORS_X
    lx0, ly0, lx1, ly1 = env.regions["lab"]
    (a0, b0), (a1, b1) = g.world_to_cell(np.array([[lx0 + 0.05, ly0 + 0.05], [lx1 - 0.05, ly1 - 0.05]]))
    lab = g.cells[a0:a1 + 1, b0:b1 + 1]
    assert 0.05 < (lab != FREE).mean() < 0.5  # furniture
    assert not np.array_equal(lab, lab[:, ::-1])  # not mirror symmetric across the door's axis
    # the observer stands in the lab, facing the lab's door
    ox, oy = env.places["observer"]
    assert lx0 < ox < lx1 and ly0 < oy < ly1 and ox == LAB_DOOR_X


# ---------------------------------------------------------------------------- registry
def test_builtin_map_unknown_name_suggests():
    with pytest.raises(ValueError, match=r"unknown built-in map 'hexagn'\. Did you mean 'hexagon'\?.*Known maps: .*trail_office"):
        builtin_map("hexagn")
    with pytest.raises(ValueError, match="unknown built-in map 'zzz'. Known maps"):
        builtin_map("zzz")


# ---------------------------------------------------------------------------- builder
def test_builder_rect_polygon_disc_segment_rasterise_by_cell_centres():
    b = MapBuilder(4.0, 2.0, 0.5)
    g = b.rect(0.0, 0.0, 1.0, 1.0).build("r")
    assert g.cells[:2, :2].tolist() == [[WALL, WALL], [WALL, WALL]] and g.cells.sum() == 4
    g = MapBuilder(4.0, 4.0, 1.0).polygon([(0, 0), (4, 0), (0, 4)], "glass").build("p")
    # cell centres (c+0.5, r+0.5) with x + y < 4 are inside the triangle
    r, c = np.mgrid[0:4, 0:4]
    np.testing.assert_array_equal(g.cells == GLASS, (r + c + 1) < 4)
    g = MapBuilder(2.0, 2.0, 0.1).disc(1.0, 1.0, 0.5, "foam").build("d")
    assert (g.cells == FOAM).sum() == pytest.approx(math.pi * 25, rel=0.1)
    # a thin diagonal segment still blocks 4-connected leaks across it
    g = MapBuilder(2.0, 2.0, 0.1).segment(0.0, 0.0, 2.0, 2.0, 0.01).build("s")
    labels, n = ndi.label(g.cells == FREE)  # 4-connectivity
    assert n == 2


def test_builder_custom_material_is_appended():
    g = MapBuilder(1.0, 1.0, 0.5).rect(0.0, 0.0, 0.5, 0.5, material="curtain").build("m")
    assert g.materials[-1] == "curtain" and g.cells[0, 0] == len(g.materials) - 1


def test_builder_corridors_cross_and_rooms_keep_doors():
    b = MapBuilder(10.0, 10.0, 0.1).border(0.2)
    b.corridor(0.2, 5.0, 9.8, 5.0, width_m=1.0, wall_thickness_m=0.2)
    b.corridor(5.0, 0.2, 5.0, 9.8, width_m=1.0, wall_thickness_m=0.2)
    g = b.build("x")
    assert g.is_free_xy(np.array([[5.0, 5.0], [5.0, 5.45], [5.45, 5.0], [1.0, 5.0], [5.0, 1.0]])).all()
    assert not g.is_free_xy(np.array([[2.0, 5.6], [2.0, 4.4], [5.6, 2.0]])).any()  # side walls
    b = MapBuilder(6.0, 6.0, 0.1).room(1.0, 1.0, 5.0, 5.0, 0.2, doors=[("south", 2.0, 1.0), ("east", 1.0, 0.6)])
    g = b.build("room")
    assert g.is_free_xy(np.array([[3.0, 1.1], [4.9, 2.0], [3.0, 3.0]])).all()  # doors and interior
    assert not g.is_free_xy(np.array([[1.5, 1.1], [4.9, 3.5], [3.0, 4.9], [1.1, 3.0]])).any()
    # the room's interior is enclosed except through its doors
    labels, _ = ndi.label(g.cells == FREE)
    inside = labels[g.world_to_cell(np.array([3.0, 3.0]))[0], g.world_to_cell(np.array([3.0, 3.0]))[1]]
    outside = labels[0, 0]
    assert inside == outside
    closed = MapBuilder(6.0, 6.0, 0.1).room(1.0, 1.0, 5.0, 5.0, 0.2).build("closed")
    labels, _ = ndi.label(closed.cells == FREE)
    assert labels[30, 30] != labels[0, 0]


def test_builder_clear_rect_and_outline():
    g = MapBuilder(3.0, 3.0, 0.5).fill().clear_rect(0.5, 0.5, 2.5, 2.5).build("c")
    assert (g.cells == FREE).sum() == 16
    g = MapBuilder(3.0, 3.0, 0.5).rect(0.0, 0.0, 3.0, 3.0, filled=False, thickness_m=0.5).build("o")
    assert (g.cells == WALL).sum() == 36 - 16


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: MapBuilder(-1.0, 2.0, 0.1), r"width_m must be > 0 m, got -1.0"),
        (lambda: MapBuilder(1.0, float("nan"), 0.1), r"height_m must be a finite number"),
        (lambda: MapBuilder(1.0, 1.0, 2.0), r"resolution_m must be at most"),
        (lambda: MapBuilder(1.0, 1.0, 0.1).rect(1.0, 0.0, 0.5, 1.0), r"rect: need xmin < xmax"),
        (lambda: MapBuilder(1.0, 1.0, 0.1).rect(0.0, 0.0, 1.0, 1.0, filled=False), r"thickness_m is required"),
        (lambda: MapBuilder(1.0, 1.0, 0.1).border(0.01), r"border: thickness_m must be at least one cell"),
        (lambda: MapBuilder(1.0, 1.0, 0.1).polygon([(0, 0), (1, 1)]), r"polygon: vertices must be at least 3"),
        (lambda: MapBuilder(1.0, 1.0, 0.1).disc(0.5, 0.5, 0.0), r"disc: r must be > 0 m"),
        (lambda: MapBuilder(1.0, 1.0, 0.1).rect(0, 0, 1, 1, material=""), r"material must be a non-empty"),
        (lambda: MapBuilder(1.0, 1.0, 0.1).corridor(0.5, 0.5, 0.5, 0.5, 0.3, 0.1), r"corridor: the two ends must differ"),
        (lambda: MapBuilder(6.0, 6.0, 0.1).room(1, 1, 5, 5, 0.2, doors=[("up", 1.0, 1.0)]), r"side must be one of .*got 'up'"),
        (lambda: MapBuilder(6.0, 6.0, 0.1).room(1, 1, 5, 5, 0.2, doors=[("nort", 1.0, 1.0)]), r"did you mean 'north'"),
        (lambda: MapBuilder(6.0, 6.0, 0.1).room(1, 1, 5, 5, 0.2, doors=[("north", 0.3, 1.0)]), r"doors\[0\] must lie between the corner walls"),
        (lambda: MapBuilder(6.0, 6.0, 0.1).room(1, 1, 5, 5, 0.2, doors=[("north", 1.0)]), r"doors\[0\] must be \(side, offset_m, width_m\)"),
        (lambda: BUILTIN_MAPS["hexagon"](resolution_m=1.0), r"resolution_m must be at most 0.25"),
    ],
)
def test_builder_bad_input_names_parameter_and_value(call, match):
    with pytest.raises(ValueError, match=match):
        call()
