"""Negative detections (Fox et al. §7.2 future work): the likelihood over the detector's
range, field of view and line of sight, checked against the simulator's own detector, and the
brain's use of it (broadcast points, the frame rule, the 2.5 m rate rule, the paper's default)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.papers.collab_mcl.brains.localizing import MCLWander, MCLWanderParams
from teamnav.papers.collab_mcl.brains.negative_sights import BELIEF_KIND, BeliefPoints
from teamnav.control.protocol import RobotInfo, SensorInfo
from teamnav.control.types import Detection, Message, Observation, RangeScan
from teamnav.localization.negative_detection import negative_factors, visible_mass
from teamnav.sim.config import DetectorConfig
from teamnav.sim.sensors.detector import RobotDetector
from teamnav.world import builtin_map
from teamnav.world.grid import DEFAULT_SEES, OccupancyGrid

VISION = DEFAULT_SEES["vision"]


def _room_with_wall() -> OccupancyGrid:
    """10 x 10 m, 0.1 m cells, a wall at x in [5, 5.2) for y < 8 (a gap above)."""
    g = OccupancyGrid.empty(10.0, 10.0, 0.1)
    cells = g.cells.copy()
    cells[:80, 50:52] = g.materials.index("wall")
    return g.with_cells(cells)


ROOM = _room_with_wall()


def _vis(pose, pt, grid=ROOM, rng=4.0, fov=180.0):
    return float(visible_mass(np.array([pose], float), np.array([pt], float), np.ones(1), grid,
                              grid.blocking(VISION), rng, fov)[0])


def test_outside_range_fov_or_behind_a_wall_the_factor_is_one():
    assert _vis((1.0, 1.0, 0.0), (4.5, 1.0)) == 1.0  # 3.5 m ahead, clear
    assert _vis((1.0, 1.0, 0.0), (4.95, 1.0)) == 1.0  # 3.95 m, just before the wall
    assert _vis((1.0, 1.0, 0.0), (5.1, 1.0)) == 0.0  # in the wall
    assert _vis((1.0, 1.0, 0.0), (1.0 + 4.01, 1.0)) == 0.0  # beyond 4 m
    assert _vis((1.0, 1.0, math.pi), (3.0, 1.0)) == 0.0  # behind the observer (180 deg field)
    assert _vis((1.0, 1.0, math.pi), (3.0, 1.0), fov=360.0) == 1.0
    assert _vis((4.0, 2.0, 0.0), (7.0, 2.0)) == 0.0  # the wall between them
    assert _vis((4.0, 9.0, 0.0), (7.0, 9.0)) == 1.0  # through the gap above the wall
    f = negative_factors(np.array([0.0, 1.0]), 0.067)
    assert f[0] == 1.0 and abs(f[1] - 0.067) < 1e-12
    # with a prior that the teammate is lost, a sure sight leaves more than p_fn
    assert abs(negative_factors(np.array([1.0]), 0.067, 0.1)[0] - (1 - 0.933 * 0.9)) < 1e-12


def test_visible_mass_is_the_share_of_the_teammate_points_in_sight():
    pts = np.array([[3.0, 1.0], [3.0, 1.2], [7.0, 1.0], [0.0, 1.0]])  # 2 in sight, 1 behind the wall, 1 behind
    v = visible_mass(np.array([[1.0, 1.0, 0.0]]), pts, np.array([1.0, 3.0, 2.0, 4.0]), ROOM, ROOM.blocking(VISION),
                     5.0, 180.0)
    assert abs(v[0] - 0.4) < 1e-12  # (1 + 3) / 10


HALL = builtin_map("symmetric_hallway").grid


@settings(max_examples=60, deadline=None)
@given(x=st.floats(0.0, 1.0), y=st.floats(0.0, 1.0), th=st.floats(-math.pi, math.pi),
       r=st.floats(0.3, 6.0), a=st.floats(-math.pi, math.pi), fov=st.sampled_from([90.0, 180.0, 360.0]))
def test_the_likelihood_agrees_with_the_simulators_detector(x, y, th, r, a, fov):
    """One observer pose and one teammate point on the hallway map: visible exactly when the
    simulator's detector (noise-free, no misses) sees a robot there."""
    lo = np.array(HALL.origin_xy_m)
    size = np.array(HALL.cells.shape[::-1]) * HALL.resolution_m
    ox, oy = lo + np.array([x, y]) * size
    tx, ty = ox + r * math.cos(a), oy + r * math.sin(a)
    cfg = DetectorConfig(fov_deg=fov, max_range_m=5.0, line_of_sight=True)
    det = RobotDetector(cfg, HALL)
    seen = det.detect(np.array([ox, tx]), np.array([oy, ty]), np.array([th, 0.0]), np.full(2, 0.25),
                      np.array([0]), np.random.default_rng(0), np.arange(2))[0]
    v = _vis((ox, oy, th), (tx, ty), grid=HALL, rng=5.0, fov=fov)
    if abs(r - 5.0) < 1e-6 or abs(abs(math.remainder(a - th, 2 * math.pi)) - math.radians(fov) / 2) < 1e-6:
        return  # on the boundary: the two formulas may round differently
    assert v == (1.0 if len(seen) == 1 else 0.0)


@settings(max_examples=30, deadline=None)
@given(x=st.floats(1.0, 9.0), y=st.floats(1.0, 9.0), th=st.floats(-math.pi, math.pi), r=st.floats(0.3, 3.0),
       a=st.floats(-1.4, 1.4), yaw=st.floats(-math.pi, math.pi))
def test_a_rotated_map_gives_the_same_answer_as_the_map_in_its_own_frame(x, y, th, r, a, yaw):
    """The kernel works in the grid's frame: the same scene turned with the map sees the same."""
    flat = _vis((x, y, th), (x + r * math.cos(th + a), y + r * math.sin(th + a)))
    g = ROOM.with_pose((2.0, -1.0), yaw)
    c, s = math.cos(yaw), math.sin(yaw)

    def w(px, py):
        return 2.0 + c * px - s * py, -1.0 + s * px + c * py

    tx, ty = w(x + r * math.cos(th + a), y + r * math.sin(th + a))
    turned = _vis((*w(x, y), th + yaw), (tx, ty), grid=g)
    assert turned == flat


def test_bad_input_names_the_field():
    with pytest.raises(ValueError, match="teammate_w"):
        visible_mass(np.zeros((2, 3)), np.zeros((3, 2)), np.ones(2), ROOM, ROOM.blocking(VISION), 5.0, 180.0)
    with pytest.raises(ValueError, match="fov_deg"):
        visible_mass(np.zeros((2, 3)), np.zeros((1, 2)), np.ones(1), ROOM, ROOM.blocking(VISION), 5.0, 0.0)
    with pytest.raises(ValueError, match="particles"):
        visible_mass(np.zeros((2, 2)), np.zeros((1, 2)), np.ones(1), ROOM, ROOM.blocking(VISION), 5.0, 90.0)
    with pytest.raises(ValueError, match="p_false_negative"):
        negative_factors(np.zeros(1), 1.5)
    with pytest.raises(ValueError, match="collaborate"):
        MCLWanderParams(negative_detections=True)


# ---------------------------------------------------------------------------- the brain
ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 19)
LASER = SensorInfo("laser", "laser", ANGLES, 8.0)


def _brain(i: int, **over) -> MCLWander:
    kw = {"max_particles": 2000, "min_particles": 2000, **over}
    p = MCLWanderParams(collaborate=True, adaptive=False, negative_detections=True, neg_teammate_lost_prior=0.0, **kw)
    info = RobotInfo(i, 2, 0.25, "unicycle", 0.5, 1.5, 0.1, 0.1, sensors={"laser": LASER}, known_map=ROOM)
    return MCLWander(p, np.random.default_rng(i), info)


def _frame(brain: MCLWander, step: int, *, move_m: float = 0.0, dets=(), inbox=()):
    scan = RangeScan(np.full(ANGLES.shape[0], 8.0), ANGLES, 8.0)
    obs = Observation(brain.robot_id, step, step * 0.1, np.zeros(3), np.array([move_m, 0.0, 0.0]),
                      scans={"laser": scan}, detections=tuple(dets), inbox=tuple(inbox))
    return brain.step(obs)


def _points_msg(xy) -> Message:
    return Message(1, 0.0, BeliefPoints(np.asarray(xy, np.float32)), to=None, kind=BELIEF_KIND)


def test_a_frame_without_the_teammate_weighs_down_the_samples_that_would_see_it():
    # neg_when_concentrated: the 2.5 m rule alone decides below, not whether the random cloud
    # happens to have shrunk under neg_max_spread_m by step 30 (the next test covers that rule)
    a = _brain(0, neg_when_concentrated=True)
    _frame(a, 0)  # first filter update (uniform belief: its weights come from the scan only)
    before = a.mcl.weights.copy()
    parts = a.mcl.particles.copy()
    there = np.array([[2.0, 5.0]] * 24)  # the teammate's belief: a point left of the wall
    _frame(a, 10, inbox=[_points_msg(there)])  # step 10 = the next camera frame (1 s)
    assert a._neg.stats["neg_used"] == 1
    pv = visible_mass(parts, there, np.ones(24), ROOM, ROOM.blocking(VISION), 5.0, 180.0)
    ratio = a.mcl.weights / before
    ratio /= ratio[pv == 0].mean()
    p_fn = a.model.p_false_negative
    assert np.allclose(ratio[pv == 1.0], p_fn, rtol=1e-6) and np.allclose(ratio[pv == 0.0], 1.0)
    # the 2.5 m rule: the next frame without travel uses nothing; after 2.5 m it does again
    w = a.mcl.weights.copy()
    _frame(a, 20, inbox=[_points_msg(there)])
    assert a._neg.stats["neg_used"] == 1 and np.array_equal(a.mcl.weights, w)
    for k in range(21, 30):
        _frame(a, k, move_m=0.3)
    _frame(a, 30, inbox=[_points_msg(there)])
    assert a._neg.stats["neg_used"] == 2


def test_seen_anonymous_or_stale_teammates_give_no_negative_sight():
    there = [[2.0, 5.0]] * 24
    a = _brain(0)
    _frame(a, 0)
    _frame(a, 10, inbox=[_points_msg(there)], dets=[Detection(2.0, 0.0, 1)])  # n seen: a positive sight
    _frame(a, 20, inbox=[_points_msg(there)], dets=[Detection(2.0, 0.0, None)])  # someone unnamed
    assert a._neg.stats["neg_used"] == 0 and a._neg.stats["neg_skipped_anon"] == 1
    b = _brain(0, neg_max_age_s=0.5)
    _frame(b, 0)
    _frame(b, 1, inbox=[_points_msg(there)])  # received at 0.1 s, too old at the 1 s frame
    _frame(b, 10)
    assert b._neg.stats["neg_used"] == 0


def test_a_concentrated_robot_broadcasts_its_points_the_step_before_a_frame():
    b = _brain(1, init_pose=(2.0, 5.0, 0.0), max_particles=500, min_particles=500)
    sent = {k: _frame(b, k)[1] for k in range(0, 11)}
    kinds = {k: [m.kind for m in v] for k, v in sent.items()}
    assert [k for k, v in kinds.items() if BELIEF_KIND in v] == [9]  # 0.9 s: one step before the 1 s frame
    (msg,) = [m for m in sent[9] if m.kind == BELIEF_KIND]
    assert msg.body.xy.shape == (24, 2) and msg.size_bytes() == 24 + 24 * 2 * 4
    assert np.abs(msg.body.xy - [2.0, 5.0]).max() < 1.5
    lost = _brain(1)  # uniform belief (before any scan): not concentrated, sends nothing
    cov = lost.mcl.estimate().cov
    assert cov[0, 0] + cov[1, 1] > 4.0
    assert lost._neg.broadcast(lost.mcl, np.random.default_rng(0), 0.9, 1.0) == []
    assert len(b._neg.broadcast(b.mcl, np.random.default_rng(0), 1.9, 2.0)) == 1


def test_paper_rules_refuse_negative_sights():
    with pytest.raises(ValueError, match="negative_detections"):
        MCLWanderParams(paper_rules=True, collaborate=True, negative_detections=True)
    assert MCLWanderParams(paper_rules=True).negative_detections is False


def test_a_concentrated_observer_uses_no_negative_sight_unless_asked():
    there = [[2.0, 5.0]] * 24
    for always, used in ((False, 0), (True, 1)):
        a = _brain(0, init_pose=(1.0, 5.0, 0.0), max_particles=500, min_particles=500, neg_when_concentrated=always)
        _frame(a, 0)
        _frame(a, 10, inbox=[_points_msg(there)])  # 1 m ahead of its belief, not detected
        assert a._neg.stats["neg_used"] == used


@pytest.mark.parametrize("name", ["collab-mcl-hallway", "collab-mcl-hexagon"])
def test_the_brains_detector_datasheet_is_the_scenarios_detector(name):
    """The sweeps turn negative sights on with the brain's defaults: they must describe the detector
    the simulator runs in those scenarios (range, field of view, what hides a robot)."""
    from teamnav.experiments.spec import load_scenario

    p = MCLWanderParams()
    for g in load_scenario(name).robots:
        d = g.detector
        assert (d.max_range_m, d.fov_deg, tuple(d.sees), d.line_of_sight) == (p.neg_max_range_m, p.neg_fov_deg,
                                                                              tuple(p.neg_sees), True)
