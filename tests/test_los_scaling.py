"""Teams beyond the paper's four (``papers/los_help/scaling.py``) on the larger office
(``maps.office_simple_grid``), and the compiled team step at those sizes.

The larger office must be the paper's simple office (Sgorbissa & Arkin §6, Fig. 11) wing by
wing, connected; a team of four on it must be the section's R1..R4; and the compiled group
brain (``team_compiled.LosTeamGroup``) must give the reference brains' run, bit for bit, at 8
and 16 robots as it does at four (``tests/test_team_compiled.py``).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

from teamnav.experiments.spec import build_grid
from teamnav.papers.los_help import scaling as S
from teamnav.papers.los_help import tasks as T
from teamnav.papers.los_help.maps import CONNECTOR_W_M, WING_H_M, WING_W_M, wing_origin
from teamnav.sim.engine import Simulation
from teamnav.world import builtin_map

from test_team_compiled import _same_log


@pytest.fixture(scope="module")
def grid_map():
    return builtin_map(S.MAP)


@pytest.fixture(scope="module")
def simple_map():
    return builtin_map("office_simple")


def test_every_wing_is_the_simple_office(grid_map, simple_map):
    """Each of the 21 wings is office_simple cell for cell, except the corridor's end walls
    opened onto a north-south corridor (west end when a wing has a column to its west, east end
    when it has one to its east); its room centres are office_simple's, moved."""
    g, s = grid_map.grid, simple_map.grid
    res = g.resolution_m
    h, w = s.cells.shape
    assert g.cells.shape == (round(7 * WING_H_M / res), round((3 * WING_W_M + 2 * CONNECTOR_W_M) / res))
    corridor_rows = slice(round(5.8 / res), round(8.2 / res))
    for wing in range(S.WINGS):
        x0, y0 = wing_origin(wing)
        i0, j0 = round(y0 / res), round(x0 / res)
        block = g.cells[i0:i0 + h, j0:j0 + w].copy()
        expect = s.cells.copy()
        col = wing % S.COLS
        for opened, cols in ((col > 0, slice(0, 2)), (col < S.COLS - 1, slice(w - 2, w))):
            if opened:  # the 0.2 m end wall over the corridor's width: free here, wall in office_simple
                assert (block[corridor_rows, cols] == 0).all() and (expect[corridor_rows, cols] != 0).all()
                block[corridor_rows, cols] = expect[corridor_rows, cols]
        assert np.array_equal(block, expect), f"wing {wing} differs from office_simple"
        for name, (x, y) in simple_map.places.items():
            if name.startswith("room_"):
                gx, gy = grid_map.places[f"room_w{wing:02d}_{name[5:]}"]
                assert (gx, gy) == pytest.approx((x + x0, y + y0), abs=1e-9)


def test_every_room_is_reachable_from_the_base(grid_map):
    """One connected building: every room centre in the free component of R1's start (a body of
    0.2 m fits through every door and corridor: they are office_simple's, >= 1.2 m wide)."""
    from scipy import ndimage

    g = grid_map.grid
    labels, _ = ndimage.label(g.cells == 0)
    res = g.resolution_m

    def label_at(x, y):
        return labels[int(y / res), int(x / res)]

    base = label_at(*grid_map.places["base"])
    rooms = S.room_centres()
    assert len(rooms) == 10 * S.WINGS
    assert {label_at(x, y) for x, y in rooms.values()} == {base}


def test_four_robots_are_the_sections_team():
    """n = 4: R1 and R2..R4 in wing 0 with the routes, starts and parameters of ``los-help-simple``
    (Table 1's team), R1 with its own task on the larger office."""
    ours = S.scenario_data(4)
    sec = T.scenario_data("simple")
    assert [g["name"] for g in ours["robots"]] == ["R1", "R2", "R3", "R4"]
    assert ours["robots"][0]["start"] == sec["robots"][0]["start"]
    for a, b in zip(ours["robots"][1:], sec["robots"][1:]):
        assert a["params"] == b["params"] and a["start"] == b["start"] and a["controller"] == b["controller"]
    assert ours["radio"] == sec["radio"]
    assert ours["robots"][0]["params"]["targets_xy"] == S.targets_xy(1001, 20)


@given(st.integers(min_value=0, max_value=S.MAX_ROBOTS - 2))
def test_helpers_patrol_their_wing_on_the_sections_routes(k):
    """Helper k walks R(k % 3 + 2)'s route of Fig. 11, moved to wing k // 3: its start and every
    waypoint lie inside that wing, in free space, the same distance apart as on office_simple."""
    (x, y, th), route = S.helper_layout(k)
    (sx, sy, sth), sroute = T.LAYOUTS["simple"].helpers[k % 3]
    x0, y0 = wing_origin(k // 3)
    assert (x - x0, y - y0, th) == pytest.approx((sx, sy, sth), abs=1e-6)
    assert np.allclose(np.asarray(route) - (x0, y0), np.asarray(sroute), atol=1e-6)
    grid = builtin_map(S.MAP).grid
    for px, py in ((x, y), *route):
        assert x0 < px < x0 + WING_W_M and y0 < py < y0 + WING_H_M
        assert grid.cells[int(py / grid.resolution_m), int(px / grid.resolution_m)] == 0


def test_sizes_out_of_range_are_refused():
    with pytest.raises(ValueError, match=r"n_robots must be in \[2, 64\]"):
        S.scenario_data(65)
    with pytest.raises(ValueError, match="helper index"):
        S.helper_layout(63)


def test_tasks_are_room_centres_and_change_room():
    rooms = S.task_rooms(1001, 200)
    assert len(rooms) == 200 and all(a != b for a, b in zip(rooms, rooms[1:]))
    assert len({r.split("_")[1] for r in rooms}) > 15  # targets over most wings
    assert S.task_rooms(1001, 20) == rooms[:20]


@pytest.mark.parametrize("n,navigator,paper", [(16, "visbug21", False), (8, "potential_field", True)],
                         ids=["16-teamnav-visbug21", "8-paper-potential_field"])
def test_compiled_team_is_the_reference_at_n(n, navigator, paper):
    """The compiled group brain runs 8 and 16 robots as the reference brains do: at every step
    of 300, equal true poses, odometry, commands and every robot's log; the whole team compiled
    in one group brain, its messages heard (goal sharing at work)."""
    steps = 300
    scn = S.load(n, navigator=navigator, paper=paper, duration_s=steps * 0.1)
    ref = Simulation(build_grid(scn), scn)
    grp = Simulation(build_grid(scn), scn, group_brains=True)
    assert [(type(t).__name__, a, b, t.compiled_robots) for t, a, b, _ in grp.group_teams] == [
        ("LosTeamGroup", 0, n, n)]
    brains_ref = [b for g in ref.brains for b in g]
    brains_grp = [b for g in grp.brains for b in g]
    for _ in range(steps):
        ref.step()
        grp.step()
        where = f"step {ref.step_index}"
        assert np.array_equal(ref.state.poses(), grp.state.poses()), f"true poses differ at {where}"
        assert np.array_equal(ref.odometry.pose, grp.odometry.pose), f"odometry differs at {where}"
        assert np.array_equal(ref._dir_cmd, grp._dir_cmd, equal_nan=True), f"commands differ at {where}"
        if ref.step_index % 10 == 0 or ref.step_index == steps:
            for i, (a, b) in enumerate(zip(brains_ref, brains_grp)):
                _same_log(a.log(), b.log(), f"{where}, R{i + 1}")
    heard = [b.msgs_received for b in brains_ref]
    assert sum(h > 0 for h in heard) >= n // 2, f"too few robots heard a teammate: {heard}"
    assert brains_ref[0].target_steps == brains_grp[0].target_steps


@pytest.mark.parametrize("m", [1, 4, 64])
def test_row_sizes_is_size_bytes(m):
    """The compiled team sizes its sent rows in one kernel call (``packed.row_sizes``): the same
    integers as :meth:`PackedLosMsg.size_bytes` and as the :class:`LosHelpMsg` each row packs
    (random messages with up to ``m`` sightings, goals and reports, via fields sent or not, Tr
    bit or none), for any choice of rows."""
    from teamnav.control.types import payload_size_bytes
    from teamnav.papers.los_help.brains.packed import PackedLosMsg, pack, row_sizes

    from test_group_brains import _random_msgs

    rng = np.random.default_rng(11)
    msgs = list(_random_msgs(rng, m, 120))
    rows = np.stack([pack(msg, m) for msg in msgs])
    idx = np.sort(rng.choice(len(msgs), size=50, replace=False)).astype(np.int64)
    got = row_sizes(rows, idx)
    assert got.dtype == np.int64
    assert got.tolist() == [PackedLosMsg(rows[i]).size_bytes() for i in idx]
    assert got.tolist() == [payload_size_bytes(msgs[i]) for i in idx]
    assert row_sizes(rows, np.zeros(0, dtype=np.int64)).shape == (0,)
