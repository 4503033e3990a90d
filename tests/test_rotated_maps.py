"""Rotated maps (map_server ``origin: [x, y, yaw]``): the transform, and runs that are their
axis-aligned twin's, turned.

A map turned by ``yaw`` about its origin must give the same sensing, collisions and runs as
the same cells laid axis-aligned at the world origin (its *twin*), up to the rotation: the
kernels read the same cell array and only the frame the positions are given in changes.
"""

from __future__ import annotations

import logging
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import teamnav.world
from teamnav.cli import app
from teamnav.experiments.spec import load_scenario
from teamnav.sim.collisions import discs_hit_walls
from teamnav.sim.engine import Simulation
from teamnav.world.distance import distance_field
from teamnav.world.grid import OccupancyGrid
from teamnav.world.mapio import load_map
from teamnav.world.raycast import RayCaster

DATA = Path(teamnav.world.__file__).parent / "maps"

yaws = st.floats(-2 * math.pi, 2 * math.pi, allow_nan=False).filter(lambda a: abs(a) > 1e-3)
origins = st.tuples(st.floats(-50, 50), st.floats(-50, 50))


@st.composite
def grids(draw, min_side=3, max_side=12):
    h = draw(st.integers(min_side, max_side))
    w = draw(st.integers(min_side, max_side))
    cells = np.array(draw(st.lists(st.sampled_from([0, 0, 0, 1]), min_size=h * w, max_size=h * w)), np.uint8).reshape(h, w)
    res = draw(st.sampled_from([0.05, 0.1, 0.25, 0.5]))
    return cells, res


def _twin_and_rotated(cells, res, origin, yaw):
    return OccupancyGrid(cells, res), OccupancyGrid(cells, res, origin, yaw_rad=yaw)


@settings(max_examples=80, deadline=None)
@given(g=grids(), origin=origins, yaw=yaws, data=st.data())
def test_world_cell_transform_round_trips(g, origin, yaw, data):
    cells, res = g
    twin, rot = _twin_and_rotated(cells, res, origin, yaw)
    h, w = cells.shape
    r = data.draw(st.integers(0, h - 1))
    c = data.draw(st.integers(0, w - 1))
    centre = rot.cell_centers(r, c)
    assert rot.world_to_cell(centre).tolist() == [r, c]
    # the centre is the twin's centre turned about the origin
    tc = twin.cell_centers(r, c)
    expect = (origin[0] + math.cos(yaw) * tc[0] - math.sin(yaw) * tc[1],
              origin[1] + math.sin(yaw) * tc[0] + math.cos(yaw) * tc[1])
    assert np.allclose(centre, expect, atol=1e-9)
    p = np.array(data.draw(st.tuples(st.floats(-100, 100), st.floats(-100, 100))))
    assert np.allclose(rot.local_to_world(rot.world_to_local(p)), p, atol=1e-9)
    x0, x1, y0, y1 = rot.bounds_m
    corners = rot.corners_m
    assert (corners[:, 0] >= x0 - 1e-9).all() and (corners[:, 0] <= x1 + 1e-9).all()
    assert (corners[:, 1] >= y0 - 1e-9).all() and (corners[:, 1] <= y1 + 1e-9).all()
    assert rot.is_free_xy(centre) == (cells[r, c] == 0)


def _turn(poses, origin, yaw):
    c, s = math.cos(yaw), math.sin(yaw)
    out = np.empty_like(poses)
    out[:, 0] = origin[0] + c * poses[:, 0] - s * poses[:, 1]
    out[:, 1] = origin[1] + s * poses[:, 0] + c * poses[:, 1]
    out[:, 2] = poses[:, 2] + yaw
    return out


@settings(max_examples=60, deadline=None)
@given(g=grids(), origin=origins, yaw=yaws, data=st.data())
def test_rays_on_a_rotated_map_are_the_twins(g, origin, yaw, data):
    cells, res = g
    twin, rot = _twin_and_rotated(cells, res, origin, yaw)
    h, w = cells.shape
    n = data.draw(st.integers(1, 6))
    u = np.array(data.draw(st.lists(st.tuples(st.floats(0.01, 0.99), st.floats(0.01, 0.99), st.floats(-math.pi, math.pi)),
                                    min_size=n, max_size=n)))
    poses = np.stack([u[:, 0] * w * res, u[:, 1] * h * res, u[:, 2]], axis=1)
    beams = np.linspace(-math.pi, math.pi, 17)
    ranges_twin = RayCaster(twin, max_range_m=5.0).cast(poses, beams)
    ranges_rot = RayCaster(rot, max_range_m=5.0).cast(_turn(poses, origin, yaw), beams)
    # rounding moves a ray by ~1e-13 m: only a ray that grazes a cell corner may change; keep
    # the beams whose twin range is stable under such a nudge
    nudged = [RayCaster(twin, max_range_m=5.0).cast(poses + d, beams)
              for d in ([1e-9, 0, 0], [0, 1e-9, 0], [-1e-9, 0, 0], [0, -1e-9, 0], [0, 0, 1e-9], [0, 0, -1e-9])]
    stable = np.max([np.abs(x - ranges_twin) for x in nudged], axis=0) < 1e-6
    assume(stable.mean() > 0.5)
    np.testing.assert_allclose(ranges_rot[stable], ranges_twin[stable], atol=1e-6)


@settings(max_examples=60, deadline=None)
@given(g=grids(), origin=origins, yaw=yaws, data=st.data())
def test_disc_collisions_on_a_rotated_map_are_the_twins(g, origin, yaw, data):
    cells, res = g
    twin, rot = _twin_and_rotated(cells, res, origin, yaw)
    h, w = cells.shape
    n = data.draw(st.integers(1, 8))
    u = np.array(data.draw(st.lists(st.tuples(st.floats(-0.2, 1.2), st.floats(-0.2, 1.2), st.floats(0.05, 0.6)),
                                    min_size=n, max_size=n)))
    xy = np.stack([u[:, 0] * w * res, u[:, 1] * h * res], axis=1)
    r = u[:, 2] * res * 2
    clear = distance_field(twin.blocking(None), res)
    hit_twin = discs_hit_walls(twin.blocking(None), clear, twin.geo, xy[:, 0], xy[:, 1], r)
    moved = _turn(np.column_stack([xy, np.zeros(n)]), origin, yaw)
    hit_rot = discs_hit_walls(rot.blocking(None), clear, rot.geo, moved[:, 0], moved[:, 1], r)
    # a disc that just touches a cell edge may go either way under rounding
    near = [discs_hit_walls(twin.blocking(None), clear, twin.geo, xy[:, 0], xy[:, 1], r + d) for d in (-1e-9, 1e-9)]
    stable = near[0] == near[1]
    np.testing.assert_array_equal(hit_rot[stable], hit_twin[stable])


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(origin=origins, yaw=yaws, seed=st.integers(0, 1000))
def test_a_team_on_a_rotated_map_runs_as_on_its_twin(origin, yaw, seed):
    """Wanderers with lasers, drifting odometry and a radio: 60 steps on the sandbox turned by
    ``yaw`` follow the twin's poses turned by ``yaw`` (spawn included)."""
    base = load_map(DATA / "nav2" / "tb3_sandbox.yaml")
    twin, rot = base.with_pose((0.0, 0.0)), base.with_pose(origin, yaw)
    scn = load_scenario("demo", overrides=["robots.0.start.region=null", "robots.0.count=4"], seed=seed, duration_s=6.0)
    runs = []
    for grid in (twin, rot):
        sim = Simulation(grid, scn)
        poses = []
        for _ in range(60):
            sim.step()
            poses.append(np.stack([sim.state.x_m, sim.state.y_m, sim.state.theta_rad], axis=1))
        runs.append(np.array(poses))
    a, b = runs
    turned = _turn(a.reshape(-1, 3), origin, yaw).reshape(a.shape)
    np.testing.assert_allclose(b[..., :2], turned[..., :2], atol=1e-6)
    dth = np.angle(np.exp(1j * (b[..., 2] - turned[..., 2])))
    assert np.abs(dth).max() < 1e-6
    assert np.abs(a[-1, :, :2] - a[0, :, :2]).max() > 0.3  # the robots did move


def test_rotated_map_with_an_extra_key_runs_through_teamnav_run(tmp_path, caplog):
    """``teamnav run`` on a map with origin [2, 3, 1] and a ``map_type`` key: the run folder's
    map keeps the yaw, the poses are the twin's turned, and the ignored key is warned about."""
    shutil.copy(DATA / "nav2" / "tb3_sandbox.pgm", tmp_path / "sandbox.pgm")
    fields = "image: sandbox.pgm\nresolution: 0.05\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    (tmp_path / "twin.yaml").write_text(fields + "origin: [0.0, 0.0, 0.0]\n")
    (tmp_path / "rotated.yaml").write_text("map_type: occupancy\n" + fields + "origin: [2.0, 3.0, 1.0]\n")
    runner = CliRunner()
    caplog.set_level(logging.WARNING, logger="teamnav.world.mapio")
    poses = {}
    for name in ("twin", "rotated"):
        out = tmp_path / f"run_{name}"
        result = runner.invoke(app, ["run", "demo", "--duration", "3", "--seed", "4", "--quiet", "--out", str(out),
                                     "--set", f"map={{file: {tmp_path / (name + '.yaml')}}}",
                                     "--set", "robots.0.start.region=null", "--set", "robots.0.count=3"])
        assert result.exit_code == 0, result.output
        if name == "rotated":
            warned = [r.getMessage() for r in caplog.records if "map_type" in r.getMessage()]
            assert len(warned) == 1 and "rotated.yaml: ignoring key 'map_type'" in warned[0]
        doc = yaml.safe_load((out / "map.yaml").read_text())
        assert doc["origin"] == ([2.0, 3.0, 1.0] if name == "rotated" else [0.0, 0.0, 0.0])
        assert load_map(out / "map.yaml").yaw_rad == (1.0 if name == "rotated" else 0.0)
        poses[name] = np.load(out / "trajectories.npz", allow_pickle=False)["true_pose"]
    a, b = poses["twin"], poses["rotated"]
    turned = _turn(a.reshape(-1, 3), (2.0, 3.0), 1.0).reshape(a.shape)
    np.testing.assert_allclose(b[..., :2], turned[..., :2], atol=1e-6)


def test_unrotated_grid_hands_kernels_the_arrays_it_was_given():
    """No yaw: kernel_frame returns the very arrays and the origin (bit-for-bit old results)."""
    g = OccupancyGrid(np.zeros((4, 4), np.uint8), 0.5, (1.0, 2.0))
    xs, ys = np.array([1.5]), np.array([2.5])
    kx, ky, ox, oy = g.kernel_frame(xs, ys)
    assert kx is xs and ky is ys and (ox, oy) == (1.0, 2.0)
    th = np.array([0.3])
    assert g.kernel_theta(th) is th
    assert not g.rotated and g.with_pose((0.0, 0.0), 0.5).rotated


def test_nonfinite_yaw_is_refused():
    with pytest.raises(ValueError, match="yaw must be a finite angle"):
        OccupancyGrid(np.zeros((2, 2), np.uint8), 0.1, yaw_rad=float("nan"))
