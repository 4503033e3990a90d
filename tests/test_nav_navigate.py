"""Navigate, the sliding box, opening detection and Panic (Vaughan et al., Blazing a trail §4.2).

Hand-made situations: synthetic scans cast against line segments, and a tiny kinematic loop
(unicycle, perfect odometry, walls as segments) for the closed-loop rules; then the real
simulator on the trail office.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import Field, ValidationError

from teamnav.control import registry
from teamnav.control.nav.navigate import Navigate, NavigateParams
from teamnav.control.nav.openings import OpeningDetector
from teamnav.control.nav.panic import Panic
from teamnav.control.nav.wall_follow import SlidingBox, box_exit_ranges
from teamnav.control.protocol import RobotInfo, SensorInfo
from teamnav.control.types import Action, Observation, RangeScan

ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 181)  # 1 deg apart
MAX_R = 8.0
RADIUS = 0.25
LASER = SensorInfo("laser", "laser", ANGLES, MAX_R)
INFO = RobotInfo(0, 1, RADIUS, "unicycle", 0.6, 2.0, 0.1, 0.1, sensors={"laser": LASER})
WIDTH = 2 * RADIUS + 2 * NavigateParams().box_margin_m  # 0.8 m box


# ------------------------------------------------------------------------ helpers
def cast(segments, pose=(0.0, 0.0, 0.0), angles=ANGLES, max_r=MAX_R):
    """Ranges from ``pose`` against segments [(x0, y0, x1, y1), ...] (world frame), capped at max_r."""
    seg = np.asarray(segments, float).reshape(-1, 4)
    x, y, th = pose
    d = np.stack([np.cos(th + angles), np.sin(th + angles)], axis=1)[:, None, :]  # (B, 1, 2)
    p0, p1 = seg[None, :, :2], seg[None, :, 2:]
    e = p1 - p0
    w = p0 - np.array([x, y])
    den = d[..., 0] * e[..., 1] - d[..., 1] * e[..., 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[..., 0] * e[..., 1] - w[..., 1] * e[..., 0]) / den
        u = (w[..., 0] * d[..., 1] - w[..., 1] * d[..., 0]) / den
    hit = (np.abs(den) > 1e-12) & (t > 0) & (u >= -1e-9) & (u <= 1 + 1e-9)  # closed: corners do not leak
    return np.minimum(np.where(hit, t, np.inf).min(axis=1), max_r)


def observe(ranges, pose=(0.0, 0.0, 0.0), step=0, stalled=False):
    return Observation(0, step, step * 0.1, np.asarray(pose, float), np.zeros(3),
                       scans={"laser": RangeScan(np.asarray(ranges, float), ANGLES, MAX_R)}, stalled=stalled)


def drive(nav, walls, pose, n_steps, preferred=None, dt=0.1):
    """Closed loop: unicycle with perfect odometry among wall segments. Returns poses, commands, modes."""
    pose = np.array(pose, float)
    poses, cmds, modes = [pose.copy()], [], []
    for k in range(n_steps):
        v, w = nav.step(observe(cast(walls, pose), pose, k), preferred)
        cmds.append((v, w))
        modes.append(nav.mode)
        pose = pose + dt * np.array([v * math.cos(pose[2]), v * math.sin(pose[2]), w])
        pose[2] = math.remainder(pose[2], 2 * math.pi)
        poses.append(pose.copy())
    return np.array(poses), np.array(cmds), modes


def clearance(walls, poses):
    """Smallest distance from the robot centres to any wall segment [m]."""
    seg = np.asarray(walls, float).reshape(-1, 4)
    p = np.asarray(poses)[:, None, :2]
    a, b = seg[None, :, :2], seg[None, :, 2:]
    ab = b - a
    t = np.clip(((p - a) * ab).sum(-1) / (ab * ab).sum(-1), 0, 1)
    return float(np.hypot(*(a + t[..., None] * ab - p).transpose(2, 0, 1)).min())


def nav(seed=0, **kw):
    return Navigate(NavigateParams(**{"cruise_speed_mps": 0.4, **kw}), np.random.default_rng(seed), INFO)


def sliding_box(**kw):
    args = dict(box_width_m=WIDTH, box_length_m=1.0, box_near_m=0.1, offset_max_m=0.8, slide_step_m=0.05,
                cruise_speed_mps=0.4, steer_gain_per_s=1.5, turn_rate_radps=1.0, min_speed_fraction=0.3)
    args.update(kw)
    return SlidingBox(ANGLES, **args)


# ------------------------------------------------------------------------ sliding box
def test_box_exit_ranges_match_a_hand_computation():
    t = box_exit_ranges(np.radians([0.0, 45.0, 90.0, -90.0]), 0.0, 1.0, np.array([-0.5, 0.6]), np.array([0.5, 1.0]))
    np.testing.assert_allclose(t[0], [1.0, 0.5 * math.sqrt(2), 0.5, 0.5], atol=1e-12)
    assert t[1, 0] == -np.inf and t[1, 3] == -np.inf  # those beams miss the side box
    np.testing.assert_allclose(t[1, 1:3], [1.0 * math.sqrt(2), 1.0], atol=1e-12)


def test_open_space_goes_straight_at_cruise_speed():
    cmd = sliding_box().command(np.full(181, MAX_R))
    assert (cmd.state, cmd.v_mps, cmd.omega_radps) == ("open", 0.4, 0.0)


@pytest.mark.parametrize(("wall_m", "offset_m", "turn"), [(1.02, 0.6, 1), (0.47, 0.05, 1), (0.32, -0.1, -1)])
def test_box_slides_until_clear_of_a_left_wall(wall_m, offset_m, turn):
    """Blazing §4.2 / Fig. 3: first free box from the left; the robot turns towards its centre."""
    cmd = sliding_box().command(cast([(-5, wall_m, 10, wall_m)]))
    assert cmd.state == "follow"
    assert cmd.offset_m == pytest.approx(offset_m, abs=1e-9)
    assert math.copysign(1, cmd.omega_radps) == turn
    # The chosen box is clear of the wall, the next one to the left is not.
    assert cmd.offset_m + WIDTH / 2 <= wall_m < cmd.offset_m + 0.05 + WIDTH / 2


def test_right_hand_box_mirrors_the_left_one():
    left = sliding_box().command(cast([(-5, 1.0, 10, 1.0)]))
    right = sliding_box(side="right").command(cast([(-5, -1.0, 10, -1.0)]))
    assert right.offset_m == pytest.approx(-left.offset_m) and right.omega_radps == pytest.approx(-left.omega_radps)


def test_blocked_ahead_turns_on_the_spot_away_from_the_nearest_obstacle_and_keeps_turning():
    box = sliding_box()
    # A dead end 0.6 m ahead, its left side nearer: turn right, on the spot.
    walls = [(0.6, -3, 0.6, 3), (-1, 0.5, 0.6, 0.5), (-1, -0.9, 0.6, -0.9)]
    cmd = box.command(cast(walls))
    assert (cmd.state, cmd.v_mps) == ("blocked", 0.0) and cmd.omega_radps < 0
    # Now the nearest obstacle is on the right, but the turn keeps its direction until a box is free.
    walls2 = [(0.6, -3, 0.6, 3), (-1, 0.9, 0.6, 0.9), (-1, -0.45, 0.6, -0.45)]
    assert box.command(cast(walls2)).omega_radps < 0
    box.reset()
    assert box.command(cast(walls2)).omega_radps > 0


def test_obstacle_ahead_with_room_on_the_left_steers_left():
    cmd = sliding_box().command(cast([(0.7, -0.6, 0.7, 0.2)]))  # a block ahead, right of centre
    assert cmd.state == "follow" and cmd.omega_radps > 0 and cmd.offset_m > 0.2


def test_wall_beside_the_robot_hides_no_box():
    """A wall ending just beside the robot (an opening begins) leaves the first box free."""
    cmd = sliding_box().command(cast([(-5, 0.45, 0.05, 0.45)]))
    assert cmd.state == "open"


def test_closed_loop_holds_the_left_wall_at_half_a_box():
    wall = [(-5, 1.0, 60, 1.0)]
    poses, cmds, _ = drive(nav(), wall, (0.0, 0.0, 0.0), 250)
    gap = 1.0 - poses[-50:, 1]
    assert np.all(gap >= WIDTH / 2 - 0.02) and np.all(gap <= WIDTH / 2 + 0.1)
    assert np.abs(poses[-50:, 2]).max() < 0.1
    assert clearance(wall, poses) > RADIUS
    assert poses[-1, 0] > 0.8 * 0.4 * 25  # kept moving at about cruise speed


def test_closed_loop_keeps_left_in_a_wide_corridor_and_centred_in_a_narrow_one():
    """Left-wall following: in a 1.8 m corridor the robot keeps to its left lane (two robots in
    opposite directions pass each other, Blazing §4.2); in a corridor barely wider than the box
    the only free box is the centred one."""
    wide = [(-5, 0.9, 60, 0.9), (-5, -0.9, 60, -0.9)]
    poses, _, _ = drive(nav(), wide, (0.0, -0.3, 0.0), 250)
    assert np.all(np.abs(0.9 - poses[-50:, 1] - WIDTH / 2) < 0.1)
    assert clearance(wide, poses) > RADIUS
    narrow = [(-5, 0.5, 60, 0.5), (-5, -0.5, 60, -0.5)]
    poses, _, _ = drive(nav(), narrow, (0.0, -0.08, 0.05), 250)
    assert np.abs(poses[-50:, 1]).max() < 0.1
    assert clearance(narrow, poses) > RADIUS and poses[-1, 0] > 5.0


def test_trail_brains_cross_back_to_their_lane_from_the_oncoming_one():
    """A robot that turned 180 deg on the spot at a place sits in the oncoming lane of a 1.8 m
    corridor, 0.45 m from its right wall and 1.35 m from its left one (traced at the source of
    ``try-to-see-it-my-way``). With Navigate's default reach (1.2 m) the first box is free and
    the robot drives straight on in that lane ("big open space", Blazing §4.2); the trail
    brains' ``box_reach_m = 2.0`` spans the corridor, so it crosses to its own (left) lane."""
    from teamnav.papers.trails.brains.blazing_trail import NAVIGATE_DEFAULTS, navigate_params

    assert NAVIGATE_DEFAULTS["box_reach_m"] >= 1.8  # the trail office's corridor width
    wide = [(-5, 0.9, 60, 0.9), (-5, -0.9, 60, -0.9)]
    start = (0.0, -0.45, 0.0)
    trail = Navigate(navigate_params({}, 0.4), np.random.default_rng(0), INFO)
    poses, _, _ = drive(trail, wide, start, 250, preferred=0.0)  # a trail hint along the corridor
    in_lane = np.flatnonzero(np.abs(0.9 - poses[:, 1] - WIDTH / 2) < 0.1)
    assert in_lane.size and poses[in_lane[0], 0] < 2.5  # in its lane within 2.5 m
    assert np.all(np.abs(0.9 - poses[-50:, 1] - WIDTH / 2) < 0.1)
    assert clearance(wide, poses) > RADIUS
    short = Navigate(navigate_params({"box_reach_m": 1.2}, 0.4), np.random.default_rng(0), INFO)
    poses, _, _ = drive(short, wide, start, 250, preferred=0.0)
    assert poses[-1, 0] > 8.0 and np.all(poses[:, 1] < 0.0)  # 8 m on, still in the oncoming lane


# ------------------------------------------------------------------------ openings
def side_corridor(width_m, wall_m=0.45, edge_x_m=0.05, depth_m=5.0, side=1):
    """Corridor walls at +-wall_m / -1.35 m; a side corridor of width_m opens on ``side`` at edge_x_m."""
    s = side
    x1 = edge_x_m + width_m
    return [(-5, s * wall_m, edge_x_m, s * wall_m), (x1, s * wall_m, 20, s * wall_m),
            (edge_x_m, s * wall_m, edge_x_m, s * (wall_m + depth_m)), (x1, s * wall_m, x1, s * (wall_m + depth_m)),
            (edge_x_m, s * (wall_m + depth_m), x1, s * (wall_m + depth_m)), (-5, -s * 1.35, 20, -s * 1.35)]


def detector():
    return OpeningDetector(ANGLES, near_m=2.0, jump_m=1.5, min_width_m=2 * RADIUS + 0.2, extreme_deg=20.0,
                           sector_deg=80.0, wall_tolerance_m=0.4)


@pytest.mark.parametrize("side", [1, -1])
def test_opening_wider_than_the_robot_is_reported_with_its_direction(side):
    left, right = detector().detect(cast(side_corridor(1.0, side=side)))
    found, other = (left, right) if side == 1 else (right, left)
    assert other is None and found is not None
    assert found.side == side
    assert found.direction_rad == pytest.approx(side * math.pi / 2, abs=0.05)
    assert found.width_m == pytest.approx(1.0, abs=0.05)
    assert found.advance_m == pytest.approx(0.55, abs=0.05)


def test_opening_narrower_than_the_robot_is_not_reported():
    assert detector().detect(cast(side_corridor(0.5))) == (None, None)


def test_large_discontinuity_without_a_far_edge_is_an_opening_and_a_shallow_niche_is_not():
    hall = [(-5, 0.45, 0.05, 0.45), (-5, -1.35, 20, -1.35)]  # the left wall ends: open hall
    left, _ = detector().detect(cast(hall))
    assert left is not None and left.width_m == math.inf and left.direction_rad == pytest.approx(math.pi / 2)
    assert detector().detect(cast(side_corridor(2.0, depth_m=1.0))) == (None, None)  # a passing place
    assert detector().detect(cast(side_corridor(1.0, edge_x_m=0.6))) == (None, None)  # edge not yet at the side


@settings(max_examples=40, deadline=None)
@given(width=st.floats(0.8, 3.0), wall=st.floats(0.35, 1.4), edge=st.floats(0.0, 0.1), side=st.sampled_from([1, -1]))
def test_opening_width_and_centre_are_measured_within_the_beam_spacing(width, wall, edge, side):
    found = detector().detect(cast(side_corridor(width, wall_m=wall, edge_x_m=edge, side=side)))[0 if side == 1 else 1]
    assert found is not None and found.side == side
    far = edge + width
    tol = (wall**2 + far**2) / wall * math.radians(1.0) + 0.02  # x step of 1-deg beams at the far edge
    assert found.width_m == pytest.approx(width, abs=tol)
    assert found.advance_m == pytest.approx(edge + width / 2, abs=tol)


# ------------------------------------------------------------------------ panic
def test_panic_stops_turns_until_free_moves_then_returns_to_navigate():
    wall = [(0.35, -5, 0.35, 5)]  # facing a wall 0.1 m from the body
    n = nav()
    poses, cmds, modes = drive(n, wall, (0.0, 0.0, 0.0), 100)
    assert modes[0] == "panic" and tuple(cmds[0]) == (0.0, 0.0)  # emergency stop
    end = modes.index("navigate")
    assert end * 0.1 <= 8.0  # back to Navigate within the timeout
    turning = [k for k in range(1, end) if cmds[k][0] == 0.0]
    moving = [k for k in range(1, end) if cmds[k][0] > 0.0]
    assert turning and moving and max(turning) < min(moving)  # turn on the spot first, then move
    assert len({math.copysign(1, cmds[k][1]) for k in turning}) == 1  # one direction throughout
    assert abs(math.remainder(poses[min(moving), 2], 2 * math.pi)) > math.radians(45)  # turned away
    assert clearance(wall, poses) > RADIUS


def test_panic_turn_direction_is_random_and_seeded():
    wall = [(0.35, -5, 0.35, 5)]
    dirs = [drive(nav(seed), wall, (0.0, 0.0, 0.0), 3)[1][2][1] for seed in range(16)]
    assert {math.copysign(1, d) for d in dirs} == {1.0, -1.0}
    assert dirs == [drive(nav(seed), wall, (0.0, 0.0, 0.0), 3)[1][2][1] for seed in range(16)]


def test_stall_flag_triggers_panic():
    n = nav()
    assert n.step(observe(np.full(181, MAX_R), stalled=True)) == (0.0, 0.0) and n.mode == "panic"


def test_panic_gives_up_turning_after_its_timeout():
    p = Panic(ANGLES, RADIUS, 0.12, 60.0, WIDTH, 0.8, 0.3, 1.0, 2.0, 1.0, 0.1)
    p.start(np.random.default_rng(0))
    boxed_in = np.full(181, 0.3)
    steps = 0
    while p.active:
        v, _ = p.step(boxed_in)
        assert v == 0.0
        steps += 1
    assert steps == 12  # the stop step, 10 turning steps (1 s), then control goes back


# ------------------------------------------------------------------------ sharp turns and trails
T_JUNCTION = [(-5, 0.9, 3.0, 0.9), (4.8, 0.9, 30, 0.9), (-5, -0.9, 30, -0.9),
              (3.0, 0.9, 3.0, 12.0), (4.8, 0.9, 4.8, 12.0)]  # corridor along x, side corridor north at x 3..4.8


@pytest.mark.parametrize(("preferred", "p_take", "turns"), [(math.pi / 2, 0.5, True), (0.0, 0.5, False),
                                                             (None, 1.0, True), (None, 0.0, False)])
def test_opening_taken_by_trail_or_by_chance(preferred, p_take, turns):
    poses, _, modes = drive(nav(p_take_opening=p_take), T_JUNCTION, (0.0, 0.0, 0.0), 300, preferred)
    assert clearance(T_JUNCTION, poses) > RADIUS
    if turns:
        assert "advance" in modes and "turn" in modes
        assert poses[-1, 1] > 4.0 and 3.0 < poses[-1, 0] < 4.8  # up the side corridor
    else:
        assert "turn" not in modes and poses[-1, 0] > 8.0 and abs(poses[-1, 1]) < 0.9


def test_turn_into_an_opening_is_made_at_its_centre():
    poses, _, modes = drive(nav(p_take_opening=1.0), T_JUNCTION, (0.0, 0.0, 0.0), 200)
    k = modes.index("turn")
    assert poses[k, 0] == pytest.approx(3.9, abs=0.25)  # the side corridor's centre line


def test_explore_takes_openings_about_half_the_time():
    taken = sum("turn" in drive(nav(seed), T_JUNCTION, (0.0, 0.0, 0.0), 110)[2] for seed in range(40))
    assert 10 <= taken <= 30  # binomial(40, 0.5): outside this with probability < 0.2 %


def test_heading_against_the_trail_makes_a_sharp_right_turn_then_progress():
    corridor = [(-30, 0.9, 30, 0.9), (-30, -0.9, 30, -0.9)]
    poses, cmds, modes = drive(nav(), corridor, (0.0, 0.0, math.pi), 250, preferred=0.0)
    assert modes[0] == "turn" and cmds[0][0] == 0.0 and cmds[0][1] < 0  # 180 deg right turn, on the spot
    end = modes.index("navigate")
    assert abs(math.remainder(poses[end, 2], 2 * math.pi)) < math.radians(15)
    assert poses[-1, 0] > 5.0 and clearance(corridor, poses) > RADIUS


@pytest.mark.parametrize(("off_deg", "reverses"), [(135.0, False), (145.0, False), (155.0, True)])
def test_reverse_threshold_is_150_degrees(off_deg, reverses):
    # 150, not 135: at a corner the averaged trail points 45 deg between its two legs, and a
    # robot coming back out of the dead end beyond it is 135 deg off; it must not reverse there.
    n = nav()
    n.step(observe(np.full(181, MAX_R), (0.0, 0.0, math.radians(off_deg))), 0.0)
    assert (n.mode == "turn") == reverses


def test_a_vetoed_reversal_is_not_made_and_the_next_waits_for_distance_driven():
    n = nav()
    n.step(observe(np.full(181, MAX_R), (0.0, 0.0, math.pi)), 0.0, allow_reverse=False)
    assert n.mode == "navigate"
    n = nav(reverse_cooldown_s=0.0, reverse_cooldown_m=3.0)
    x = 0.0
    n.step(observe(np.full(181, MAX_R), (x, 0.0, math.pi), 0), 0.0)
    assert n.mode == "turn"
    n.mode = "navigate"  # as if the turn had ended with the robot still facing away
    reversals = []
    for k in range(1, 100):  # drives 0.04 m per step, still facing against the hint
        x -= 0.04
        n.step(observe(np.full(181, MAX_R), (x, 0.0, math.pi), k), 0.0)
        if n.mode == "turn":
            reversals.append(-x)
            n.mode = "navigate"
    assert reversals and reversals[0] == pytest.approx(3.0, abs=0.05)


def test_turn_around_at_a_place_turns_right_180_then_leaves_without_trail_rules():
    corridor = [(-10.0, 0.9, 10.0, 0.9), (-10.0, -0.9, 10.0, -0.9)]
    n = nav(reverse_cooldown_m=0.0, reverse_cooldown_s=0.0)
    n.turn_around(2.0)
    assert n.mode == "turn" and n.leaving
    # the hint says "go on east" (against the turn) all along: no reversal until 2 m are driven
    poses, cmds, modes = drive(n, corridor, (0.0, 0.0, 0.0), 120, preferred=0.0)
    assert cmds[0][0] == 0.0 and cmds[0][1] < 0  # a right turn on the spot
    end = modes.index("navigate")
    assert abs(abs(poses[end, 2]) - math.pi) < math.radians(10)
    first_reverse = next(k for k in range(end, len(modes)) if modes[k] == "turn")
    assert poses[first_reverse, 0] == pytest.approx(-2.0, abs=0.1)
    with pytest.raises(ValueError, match="leave_m"):
        n.turn_around(-1.0)


def test_reset_forgets_a_manoeuvre():
    n = nav()
    n.step(observe(np.full(181, MAX_R), (0.0, 0.0, math.pi)), 0.0)
    assert n.mode == "turn"
    n.reset()
    assert n.mode == "navigate"
    assert n.step(observe(np.full(181, MAX_R), (0.0, 0.0, math.pi))) == (0.4, 0.0)


# ------------------------------------------------------------------------ bad input
def test_bad_parameters_and_inputs_are_refused():
    with pytest.raises(ValidationError, match="extra"):
        NavigateParams(cruise_speed=0.3)
    with pytest.raises(ValidationError, match="box_near_m must be < box_length_m"):
        NavigateParams(box_near_m=1.0, box_length_m=1.0)
    with pytest.raises(ValidationError, match="opening_sector_deg"):
        NavigateParams(opening_sector_deg=10.0, opening_extreme_deg=20.0)
    with pytest.raises(ValueError, match="laser must name one of robot 0's range sensors"):
        Navigate(NavigateParams(), np.random.default_rng(0), INFO, laser="sonar")
    n = nav()
    with pytest.raises(ValueError, match="must have 181 beams"):
        n.step(observe(np.full(90, MAX_R)))


def test_speed_and_turn_rate_are_capped_by_the_robot():
    slow = RobotInfo(0, 1, RADIUS, "unicycle", 0.2, 0.5, 0.1, 0.1, sensors={"laser": LASER})
    n = Navigate(NavigateParams(cruise_speed_mps=1.0, turn_rate_radps=3.0), np.random.default_rng(0), slow)
    assert n.step(observe(np.full(181, MAX_R))) == (0.2, 0.0)
    n.step(observe(np.full(181, MAX_R), (0.0, 0.0, math.pi)), 0.0)
    assert n.mode == "turn" and n.step(observe(np.full(181, MAX_R), (0.0, 0.0, math.pi), 1), 0.0)[1] == -0.5


# ------------------------------------------------------------------------ in the simulator
def trail_office_scenario(controller, count, duration_s, params=None, start=None, seed=1, map_name="trail_office"):
    return {
        "name": "nav-test", "map": {"builtin": map_name}, "duration_s": duration_s, "dt_s": 0.1, "seed": seed,
        "robots": [{
            "name": "r", "count": count, "radius_m": RADIUS, "max_v_mps": 0.6, "max_omega_degps": 120,
            "controller": controller, "params": {"cruise_speed_mps": 0.4, **(params or {})},
            "sensors": [{"kind": "laser", "n_beams": 180, "fov_deg": 180, "max_range_m": 8.0, "noise_std_m": 0.01}],
            "odometry": {"frame": "world"},
            "start": start or {"near": "home", "spread_m": 1.0},
        }],
        "metrics": ["collisions", "stall_fraction", "path_length"],
    }


def run_scenario(spec):
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import Scenario

    return run(Scenario.model_validate(spec), progress=False)


def test_explore_v1_two_robots_on_the_trail_office():
    result = run_scenario(trail_office_scenario("explore-v1", 2, 120.0))
    m = result.metrics
    assert m["collisions_wall"] == 0 and m["collisions_robot"] == 0
    assert m["stall_fraction"] < 0.02
    assert m["path_length_m_min"] > 0.7 * 0.4 * 120  # moving at cruise speed most of the time
    modes = {log["values"]["mode"] for log in result.data.logs}
    assert {"navigate", "advance", "turn"} <= modes  # it took openings


class _FixedHeadingParams(NavigateParams):
    heading_deg: float = Field(0.0, ge=-360.0, le=360.0)


class FixedHeading:
    """Navigate with a constant preferred heading in the odometry frame (a stand-in trail)."""

    Params = _FixedHeadingParams

    def __init__(self, params, rng, info):
        self.nav = Navigate(params, rng, info)
        self.heading_rad = math.radians(params.heading_deg)

    def step(self, obs):
        return Action(*self.nav.step(obs, self.heading_rad)), []

    def log(self):
        return {"mode": self.nav.mode}


def test_preferred_heading_along_the_corridor_makes_progress(monkeypatch):
    monkeypatch.setitem(registry._REGISTRY, "fixed-heading-test-v1", f"{__name__}:FixedHeading")
    # In C1 facing west (towards home); the trail says east along C1.
    spec = trail_office_scenario("fixed-heading-test-v1", 1, 60.0, {"heading_deg": 0.0},
                                 {"poses": [[10.0, 4.9, 180.0]]})
    result = run_scenario(spec)
    odom = result.data.odom_pose[:, 0]
    assert "turn" in [log["values"]["mode"] for log in result.data.logs[:5]]
    assert odom[-1, 0] - odom[0, 0] > 15.0  # ~0.4 m/s east for most of a minute
    assert np.all(np.abs(odom[odom.shape[0] // 4:, 1] - 4.9) < 0.9)  # stayed in C1, passed the doors
    assert result.metrics["collisions_wall"] == 0


# ------------------------------------------------------------------------ kernels vs NumPy references
@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), scale=st.sampled_from([0.5, 1.5, 4.0]))
def test_kernels_match_their_numpy_references(seed, scale):
    from teamnav.control.nav.openings import any_near_edge
    from teamnav.control.nav.wall_follow import first_free_box

    rng = np.random.default_rng(seed)
    r = np.minimum(rng.exponential(scale, 181), MAX_R)
    box = sliding_box()
    ref = box.blocked(r)
    free = np.flatnonzero(~ref[:-1])
    expected = (int(free[0]) if free.size else -1, bool(ref[-1]))
    assert first_free_box(r, np.cos(ANGLES), box.box_near_m, box.exit_m) == expected
    det = detector()
    quick = any_near_edge(r, det._head, det.near_m, det.jump_m)
    assert quick or det.detect_side(r, 0) is None and det.detect_side(r, 1) is None  # never misses a near edge
    p = Panic(ANGLES, RADIUS, 0.12, 60.0, WIDTH, 0.8, 0.3, 1.0, 2.0, 8.0, 0.1)
    assert p.critical(r) == bool((r[np.abs(ANGLES) <= math.radians(60.0)] < RADIUS + 0.12).any())


class _RouteParams(NavigateParams):
    back: bool = False
    shape: str = "u"


class RouteHint:
    """A perfect trail stand-in on the trail office: the home -> source heading from the robot's
    own (drift-free, world-aligned) odometry: east along C1, north up C2, then west along C3
    (``shape="u"``, the default map) or east (``"z"``, trail_office_z)."""

    Params = _RouteParams

    def __init__(self, params, rng, info):
        self.nav = Navigate(params, rng, info)
        self.back = params.back
        self.shape = params.shape

    def heading(self, x, y):
        if self.shape == "u":
            if not self.back:
                return 0.0 if (y < 6.0 and x < 13.5) else (math.pi if y >= 14.5 else math.pi / 2)
            return 0.0 if (x < 13.5 and y > 14.5) else (math.pi if y <= 6.3 else -math.pi / 2)
        if not self.back:
            return 0.0 if (y < 6.0 and x < 13.5) or y >= 14.5 else math.pi / 2
        return math.pi if (x > 16.3 and y > 14.5) or y <= 6.3 else -math.pi / 2

    def step(self, obs):
        return Action(*self.nav.step(obs, self.heading(*obs.odom_pose[:2]))), []

    def log(self):
        return {"mode": self.nav.mode}


@pytest.mark.parametrize("shape", ["u", "z"])
@pytest.mark.parametrize("back", [False, True])
def test_trail_hint_takes_both_corners_at_near_cruise_efficiency(monkeypatch, back, shape):
    """The hint only matters at openings and for 180 deg turns (Blazing §4.2): with a perfect one
    the robot makes both correct turns, passes every wrong turn and door, and covers the ~31.5 m
    home -> source route at >= 85 % of cruise speed (the 2002 paper measured 92 %, §3.6)."""
    monkeypatch.setitem(registry._REGISTRY, "route-hint-test-v1", f"{__name__}:RouteHint")
    sx, sth = (5.4, 0.0) if shape == "u" else (24.4, 180.0)
    start, goal = ([sx, 15.9, sth], (2.0, 4.9)) if back else ([2.0, 4.9, 0.0], (sx, 15.9))
    spec = trail_office_scenario("route-hint-test-v1", 1, 110.0, {"back": back, "shape": shape}, {"poses": [start]},
                                 map_name="trail_office" if shape == "u" else "trail_office_z")
    result = run_scenario(spec)
    xy = result.data.true_pose[:, 0, :2]
    arrived = np.flatnonzero(np.hypot(*(xy - goal).T) < 1.0)
    assert arrived.size, "never reached the goal"
    assert result.data.t_s[arrived[0]] <= 31.5 / 0.4 / 0.85
    assert result.metrics["collisions_wall"] == 0 and result.metrics["stall_fraction"] == 0.0


def test_two_robots_meeting_head_on_in_a_corridor_pass_each_other(monkeypatch):
    """Each keeps to its left wall, so robots driving opposite ways pass (Blazing §4.2: "passing
    within as little as 40cm of each other")."""
    monkeypatch.setitem(registry._REGISTRY, "fixed-heading-test-v1", f"{__name__}:FixedHeading")
    east = trail_office_scenario("fixed-heading-test-v1", 1, 25.0, {"heading_deg": 0.0}, {"poses": [[6.0, 4.9, 0.0]]})
    west = dict(east["robots"][0], name="w", params={"cruise_speed_mps": 0.4, "heading_deg": 180.0},
                start={"poses": [[12.5, 4.9, 180.0]]})
    east["robots"].append(west)
    result = run_scenario(east)
    xy = result.data.true_pose[:, :, :2]
    assert xy[-1, 0, 0] > 12.5 and xy[-1, 1, 0] < 6.0  # each got past the other's start
    gap = np.hypot(*(xy[:, 0] - xy[:, 1]).T) - 2 * RADIUS
    assert gap.min() > 0.2
    assert result.metrics["collisions_robot"] == 0 and result.metrics["stall_fraction"] == 0.0


# ------------------------------------------------------------------------ gaps filled for efficiency
def t_junction(x_cross_m=1.0, width_m=1.8, left_m=0.45, right_m=1.35):
    """Robot's corridor along +x ends in a crossing corridor (along y) open both ways: a T-junction."""
    far = x_cross_m + width_m
    return [(-5.0, left_m, x_cross_m, left_m), (-5.0, -right_m, x_cross_m, -right_m),
            (x_cross_m, left_m, x_cross_m, 8.0), (x_cross_m, -right_m, x_cross_m, -8.0), (far, -8.0, far, 8.0)]


def test_opening_at_a_t_junction_is_square_to_the_wall_beside_the_robot():
    # The far wall of the crossing corridor must not tilt the wall's direction (it used to give a
    # 45 deg turn, and the wall follower then drifted into the other branch).
    r = cast(t_junction(), (0.6, 0.0, 0.0))
    _, right = detector().detect(r)
    assert right is not None and right.side == -1
    assert math.degrees(right.direction_rad) == pytest.approx(-90.0, abs=5.0)
    assert right.advance_m == pytest.approx(1.9 - 0.6, abs=0.2)  # the crossing corridor's centre line


def test_side_rule_takes_an_opening_on_any_hint_to_its_side_only_when_straight_on_is_blocked():
    from teamnav.control.nav.openings import Opening

    n = nav(trail_rule="side", side_rule_min_deg=20.0)
    right = Opening(-1, -math.pi / 2, 0.0, 1.8, 1.0, 1.3)
    blocked = np.full(181, 1.5)  # a wall 1.5 m ahead: no way straight on
    clear = np.full(181, MAX_R)
    hint = math.radians(-10.0)  # slightly to the right of straight on
    assert n._choose_opening([right], blocked, 0.0, hint) is right
    assert n._choose_opening([right], clear, 0.0, hint) is None
    assert n._choose_opening([right], blocked, 0.0, math.radians(10.0)) is None  # the hint is to the left
    assert n._choose_opening([right], clear, 0.0, math.radians(-30.0)) is right


def test_advance_swung_past_the_opening_turns_the_long_way_round():
    n = nav()
    n.mode, n._pending_dir, n._pending_heading_rad = "advance", -1.0, -math.pi  # chose: right, to face west
    n._advance_to_m, n._advance_max_steps = 0.0, 10
    v, w = n.step(observe(np.full(181, MAX_R), (0.0, 0.0, 0.1)), None)  # but it faces east (+0.1 rad)
    assert n.mode == "turn" and v == 0.0 and w < 0.0  # a right turn on the spot...
    assert n._turn_goal_rad == pytest.approx(math.pi + 0.1)  # ...all the way round to west


def test_no_second_reversal_near_a_spot_of_this_legs_reversals():
    n = nav(reverse_cooldown_s=0.0, reverse_cooldown_m=0.0, reverse_memory_m=3.0)
    scan = np.full(181, MAX_R)

    def reverses(x, k):
        n.mode = "navigate"
        n.step(observe(scan, (x, 0.0, math.pi), k), 0.0)
        return n.mode == "turn"

    assert reverses(0.0, 0)
    assert not reverses(1.0, 1)  # back near the spot: it would loop in a dead end
    assert reverses(5.0, 2)
    n.turn_around(0.0)  # a new leg forgets the spots
    assert reverses(0.0, 3)
