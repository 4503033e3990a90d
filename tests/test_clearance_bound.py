"""A huge map's block bound of the distance field gives the same start poses and moves as the field.

A 10 000-robot arena at 2 cm has 25 M cells: its dense float64 distance field took 200 MB (and
scipy's transform 400 MB more while it ran). The simulator keeps, for maps of at least
``COARSE_FIELD_CELLS`` cells (2 M), one lower bound per 16 x 16 block instead
(:func:`teamnav.world.distance.clearance_bound`). These tests check on small maps (the block
side and the size limit lowered) that the bound is a bound, that start poses are the dense
field's bit for bit, rotated maps and regions included, and that a run moves the same.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from teamnav.sim import collisions
from teamnav.sim.config import LaserConfig, ProximityConfig, RobotGroupConfig, SimConfig, StartConfig
from teamnav.sim.engine import Simulation
from teamnav.sim.start import _Candidates, start_poses
from teamnav.world import distance
from teamnav.world.distance import block_shift, clearance_bound, distance_field
from teamnav.world.grid import WALL, OccupancyGrid


def _walls(seed: int, h: int, w: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    cells = np.zeros((h, w), np.uint8)
    for _ in range(n):
        r, c = int(rng.integers(0, h)), int(rng.integers(0, w))
        cells[r:r + int(rng.integers(1, 12)), c:c + int(rng.integers(1, 12))] = WALL
    return cells


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), h=st.integers(1, 90), w=st.integers(1, 90), n=st.integers(0, 12),
       res=st.sampled_from([0.02, 0.05, 0.013, 0.3, 1.0]), k=st.integers(1, 6))
def test_the_bound_never_exceeds_the_field(seed, h, w, n, res, k):
    b = _walls(seed, h, w, n)
    lb = clearance_bound(b, res, 1 << k)
    assert lb.shape == (-(-h // (1 << k)), -(-w // (1 << k)))
    ks = block_shift(lb.shape, b.shape)  # tiny maps: several k fit, and all read block 0
    assert ks == k or lb.shape == (1, 1) or lb.shape == b.shape
    if not b.any():
        assert np.isinf(lb).all()
        return
    d = distance_field(b, res)
    up = np.repeat(np.repeat(lb, 1 << k, 0), 1 << k, 1)[:h, :w]
    assert (up <= d).all()
    assert (lb[b.reshape(h, w).nonzero()[0] >> k, b.nonzero()[1] >> k] == 0).all()  # a walled block: 0


def test_a_bound_of_another_map_is_refused():
    b = np.zeros((40, 40), np.uint8)
    with pytest.raises(ValueError, match="does not fit"):
        collisions.discs_hit_walls(b, np.zeros((7, 7)), (0.0, 0.0, 0.1), np.ones(1), np.ones(1), np.full(1, 0.1))


@settings(max_examples=30, deadline=None)
@given(mask=st.lists(st.booleans(), min_size=1, max_size=400), w=st.integers(1, 25), strip=st.integers(1, 9))
def test_candidate_runs_index_as_flatnonzero(mask, w, strip):
    ok = np.array(mask[: len(mask) // w * w] or [True] * w, bool).reshape(-1, w)
    cand = _Candidates((r0, ok[r0:r0 + strip]) for r0 in range(0, ok.shape[0], strip))
    want = np.flatnonzero(ok)
    assert cand.size == want.size
    if want.size:
        i = np.arange(want.size)
        assert np.array_equal(cand.take(i), want)


@pytest.mark.parametrize("yaw", [0.0, 0.4])
@pytest.mark.parametrize("block", [2, 4, 16])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_start_poses_are_the_dense_fields(yaw, block, seed):
    cells = _walls(seed, 230, 207, 40)
    g = OccupancyGrid(cells, 0.05, (1.0, -2.0), yaw_rad=yaw)
    b = g.blocking(None)
    groups = [RobotGroupConfig(count=40, radius_m=0.2),
              RobotGroupConfig(count=30, radius_m=0.08, start=StartConfig(region=(2.0, 8.0, 0.0, 10.0))),
              RobotGroupConfig(count=3, radius_m=0.11, start=StartConfig(poses=((5.0, 3.0, 0.0), (6.0, 3.0, 10.0),
                                                                                (7.0, 3.3, 20.0))))]
    try:
        want = start_poses(g, groups, np.random.default_rng(seed), distance_field(b, 0.05))
    except ValueError as e:  # an explicit pose in a wall: the bound must say so too
        with pytest.raises(ValueError, match=re.escape(str(e))):
            start_poses(g, groups, np.random.default_rng(seed), clearance_bound(b, 0.05, block))
        return
    got = start_poses(g, groups, np.random.default_rng(seed), clearance_bound(b, 0.05, block))
    assert np.array_equal(got.view(np.uint64), want.view(np.uint64))


def _run(cells, monkeypatch, coarse: bool, steps: int = 60):
    import teamnav.sim.engine as engine
    from teamnav.world import raycast

    monkeypatch.setattr(engine, "COARSE_FIELD_CELLS", 1 if coarse else 10**12)
    monkeypatch.setattr(raycast, "TILED_CLEARANCE_CELLS", 1 if coarse else 10**12)  # and tiled clearance maps
    g = OccupancyGrid(cells, 0.02, (-0.02, -0.02))
    cfg = SimConfig(robots=(RobotGroupConfig(count=150, radius_m=0.08, max_v_mps=0.2, controller="wander-batched-v1",
                                             params={"cruise_speed_mps": 0.15}, sensors=(ProximityConfig(),)),
                            RobotGroupConfig(count=10, radius_m=0.15, controller="wander-batched-v1",
                                             sensors=(LaserConfig(n_beams=90, fov_deg=270.0, max_range_m=3.0),))),
                    seed=3, record_every=1_000_000)
    sim = Simulation(g, cfg)
    assert (sim._clear_m.shape != cells.shape) == coarse
    assert all(isinstance(s.caster.clearance, tuple) == coarse for grp in sim._groups for s in grp.sensors
               if hasattr(s, "caster"))
    out = []
    for _ in range(steps):
        sim.step()
        out.append(np.stack([sim.state.x_m, sim.state.y_m, sim.state.theta_rad]).copy())
    return np.array(out), int(np.sum(sim.state.stalled))


def test_a_run_on_the_bound_moves_as_on_the_field(monkeypatch):
    """A crowded walled arena with pillars: robots hit walls (the exact test) and each other."""
    cells = _walls(7, 300, 300, 25)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = WALL
    dense, stalled_dense = _run(cells, monkeypatch, False)
    coarse, stalled_coarse = _run(cells, monkeypatch, True)
    assert stalled_dense > 0  # the exact wall test did decide some moves
    assert stalled_coarse == stalled_dense
    assert np.array_equal(coarse.view(np.uint64), dense.view(np.uint64))


def test_the_simulator_takes_the_bound_only_for_huge_maps():
    """The largest built-in map (the MIT basement, demo and papers) stays on the dense forms."""
    from teamnav.experiments.spec import build_grid, load_scenario
    from teamnav.world import raycast

    g = build_grid(load_scenario("demo"))
    assert g.cells.size == 1200 * 1200
    assert distance.COARSE_FIELD_CELLS > g.cells.size and raycast.TILED_CLEARANCE_CELLS > g.cells.size
