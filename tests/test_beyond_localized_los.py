"""Beyond the papers, combination 2 (localized LOS help): frames from MCL poses, fused frames, and the
paper's bearing rule left as it was (teamnav.papers.beyond.brains.localized_los)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from teamnav.control import Detection, Message, Observation, RangeScan, RobotInfo, SensorInfo
from teamnav.papers.beyond.brains import localized_los as LL
from teamnav.papers.los_help.brains import LosExplorer, LosHelper
from teamnav.papers.los_help.brains.goal_sharing import goal_id, sender_frame
from teamnav.papers.los_help.brains.messages import MESSAGE_KIND, GoalShare, LosHelpMsg, Sighting, message_size_bytes
from teamnav.geometry import wrap_angle
from teamnav.geometry.bearings import relative_frame_from_bearings
from teamnav.geometry.se2 import relative, transform_points

N_BEAMS = 72
ANGLES = np.linspace(-math.pi, math.pi, N_BEAMS, endpoint=False)
MAX_RANGE = 8.0
pose_st = st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(-math.pi, math.pi))


def info(robot_id: int = 0, team_size: int = 3) -> RobotInfo:
    laser = SensorInfo("laser", "laser", ANGLES, MAX_RANGE)
    return RobotInfo(robot_id, team_size, 0.2, "holonomic_step", 0.5, 1.5, 0.1, 0.1, sensors={"laser": laser})


def obs(step, pose, *, seen=(), inbox=(), robot_id=0) -> Observation:
    dets = tuple(Detection(float(r), float(b), int(i)) for i, r, b in seen)
    scan = RangeScan(np.full(N_BEAMS, MAX_RANGE), ANGLES.copy(), MAX_RANGE)
    return Observation(robot_id, step, 0.1 * step, np.array(pose, float), np.zeros(3), scans={"laser": scan},
                       detections=dets, stalled=False, inbox=tuple(inbox))


def polar(p_from, p_to):
    dx, dy = p_to[0] - p_from[0], p_to[1] - p_from[1]
    return math.hypot(dx, dy), float(wrap_angle(math.atan2(dy, dx) - p_from[2]))


def receive(params: dict, p1, p2, g_world, *, mutual: bool, sender_pose=None, pose_cov=None, own_cov=None):
    """R1 (robot 0, own frame = the world) at p1 receives robot 1's goal g (world) sent from p2;
    returns where R1 stores it, or None."""
    m = 3
    r1 = LosExplorer(LosExplorer.Params(**params), np.random.default_rng(0), info(0, m))
    if own_cov is not None:
        r1.set_pose_cov(own_cov)
    d, b21 = polar(p1, p2)
    _, b12 = polar(p2, p1)
    seen = [(1, d, b21)] if mutual else []
    g_in_2 = transform_points(relative(np.array(p2), np.zeros(3)), np.array(g_world))
    r1.step(obs(0, p1, seen=seen))
    body = LosHelpMsg(0, (Sighting(0, b12, d),) if mutual else (), (GoalShare(1, goal_id(1, m), *g_in_2),), (), None,
                      None if sender_pose is None else tuple(sender_pose), pose_cov)
    r1.step(obs(1, p1, seen=seen, inbox=[Message(1, 0.0, body, kind=MESSAGE_KIND)]))
    got = r1.sharing.goal_of(1)
    return None if got is None else np.array(got[1:])


# ---------------------------------------------------------------------------- the frame from two poses
@settings(max_examples=150, deadline=None)
@given(pose_st, pose_st)
def test_frame_from_exact_poses_is_the_true_relative_frame_and_the_exact_bearing_frame(p1, p2):
    d, b21 = polar(p1, p2)
    if d < 0.05:
        return
    _, b12 = polar(p2, p1)
    got = np.array(LL.frame_from_poses(p1, p2))
    want = relative(np.array(p1), np.array(p2))
    np.testing.assert_allclose(got[:2], want[:2], atol=1e-9)
    assert abs(wrap_angle(got[2] - want[2])) < 1e-9
    by_bearings = relative_frame_from_bearings(b21, b12, d)  # §3.1 with exact bearings
    np.testing.assert_allclose(got[:2], by_bearings[:2], atol=1e-7)
    assert abs(wrap_angle(got[2] - by_bearings[2])) < 1e-7


@settings(max_examples=60, deadline=None)
@given(pose_st, pose_st, st.tuples(st.floats(-20, 20), st.floats(-20, 20)))
def test_mcl_frames_place_a_teammates_goal_without_any_sighting(p1, p2, g):
    """frame_source mcl: exact poses put the sender's goal where it is, with neither robot seeing
    the other; the paper's rule drops the same message (no mutual bearing)."""
    if math.dist(p1[:2], p2[:2]) < 0.05:
        return
    got = receive({"frame_source": "mcl"}, p1, p2, g, mutual=False, sender_pose=p2)
    assert got is not None
    np.testing.assert_allclose(got, g, atol=1e-6)
    assert receive({}, p1, p2, g, mutual=False, sender_pose=p2) is None
    assert receive({"frame_source": "mcl"}, p1, p2, g, mutual=False, sender_pose=None) is None  # no pose sent


# ---------------------------------------------------------------------------- fusion
@settings(max_examples=150, deadline=None)
@given(st.tuples(st.floats(-10, 10), st.floats(-10, 10), st.floats(-3, 3)),
       st.tuples(st.floats(-10, 10), st.floats(-10, 10), st.floats(-0.5, 0.5)),
       st.tuples(*[st.floats(1e-3, 10.0)] * 3), st.tuples(*[st.floats(1e-3, 10.0)] * 3))
def test_fused_frame_lies_between_the_two_and_is_surer_than_either(a, delta, va, vb):
    b = (a[0] + delta[0], a[1] + delta[1], a[2] + delta[2])
    m, cov = LL.fuse_frames(a, np.diag(va), b, np.diag(vb))
    for k in range(2):
        assert min(a[k], b[k]) - 1e-9 <= m[k] <= max(a[k], b[k]) + 1e-9
    t = wrap_angle(m[2] - a[2])
    assert min(0.0, delta[2]) - 1e-9 <= t <= max(0.0, delta[2]) + 1e-9
    assert np.trace(cov) <= min(sum(va), sum(vb)) + 1e-12


def test_fusion_weights_by_inverse_variance_across_the_angle_wrap():
    m, cov = LL.fuse_frames((0.0, 0.0, math.pi - 0.1), np.diag([1.0, 1.0, 1.0]), (3.0, 0.0, -math.pi + 0.1),
                            np.diag([2.0, 1.0, 1.0]))
    assert m[0] == pytest.approx(1.0)  # weights 2/3 and 1/3
    assert abs(m[2]) == pytest.approx(math.pi)  # between the two headings across ±π, not 0
    assert cov[0, 0] == pytest.approx(2.0 / 3.0)


def test_bearing_frame_covariance_matches_eqs_1_2_sampled():
    """Monte Carlo of eqs. 1-2 (uniform range and bearing noise) against the propagated covariance."""
    rng = np.random.default_rng(5)
    d, a12, a21, err, size = 5.0, 0.7, -2.0, 0.2, 0.4
    n = 200_000
    dp = d + d * rng.uniform(-err, err, n)
    half = math.atan(size / (2 * d))
    b1 = a12 + half * rng.uniform(-1, 1, n)
    b2 = a21 + half * rng.uniform(-1, 1, n)
    frames = np.stack([dp * np.cos(b1), dp * np.sin(b1), np.pi + b1 - b2], axis=1)
    emp = np.cov(frames.T)
    want = LL.bearing_frame_cov(d, a12, err, size)
    np.testing.assert_allclose(emp, want, rtol=0.05, atol=2e-4)


def test_pose_frame_covariance_matches_sampled_poses():
    rng = np.random.default_rng(6)
    p1, p2 = np.array([1.0, 2.0, 0.4]), np.array([4.0, -1.0, 2.0])
    c1, c2 = np.diag([0.01, 0.02, 0.001]), np.diag([0.03, 0.01, 0.002])
    n = 100_000
    s1 = p1 + rng.multivariate_normal(np.zeros(3), c1, n)
    s2 = p2 + rng.multivariate_normal(np.zeros(3), c2, n)
    frames = np.array([LL.frame_from_poses(a, b) for a, b in zip(s1[:20000], s2[:20000])])
    emp = np.cov(frames.T)
    want = LL.pose_frame_cov(p1, c1, p2, c2)
    np.testing.assert_allclose(emp, want, rtol=0.1, atol=5e-4)


def test_brain_fusion_follows_the_surer_source():
    """fused: a sure pose pair wins over noisy bearings, and sure bearings win over unsure poses."""
    p1, p2, g = (0.0, 0.0, 0.3), (4.0, 1.0, 2.5), (6.0, 3.0)
    wrong = (4.3, 1.4, 2.6)  # the sender's pose, off by 0.5 m and 0.1 rad
    tiny, huge = LL.cov_upper(np.diag([1e-6] * 3)), LL.cov_upper(np.diag([100.0, 100.0, 10.0]))
    # bearings exact but assumed noisy (err_max 0.5); poses sure: the result follows the (wrong) pose
    got = receive({"frame_source": "fused", "frame_err_max": 0.5}, p1, p2, g, mutual=True, sender_pose=wrong,
                  pose_cov=tiny, own_cov=np.diag([1e-6] * 3))
    by_pose = receive({"frame_source": "mcl"}, p1, p2, g, mutual=True, sender_pose=wrong)
    np.testing.assert_allclose(got, by_pose, atol=0.05)
    # poses unsure: the result follows the exact bearings (err_max 0: the range is exact)
    got = receive({"frame_source": "fused", "frame_err_max": 0.0}, p1, p2, g, mutual=True, sender_pose=wrong,
                  pose_cov=huge, own_cov=np.diag([100.0, 100.0, 10.0]))
    assert np.linalg.norm(got - np.array(g)) < 0.1 < np.linalg.norm(by_pose - np.array(g))
    # without a mutual sighting fused is the pose frame alone
    got = receive({"frame_source": "fused"}, p1, p2, g, mutual=False, sender_pose=wrong, pose_cov=huge)
    np.testing.assert_allclose(got, receive({"frame_source": "mcl"}, p1, p2, g, mutual=False, sender_pose=wrong),
                               atol=1e-12)


# ---------------------------------------------------------------------------- messages and the default
def _first_message(params: dict, cov=None):
    r = LosHelper(LosHelper.Params(patrol_xy=[(1.0, 0.0), (5.0, 0.0)], **params), np.random.default_rng(0), info(2))
    if cov is not None:
        r.set_pose_cov(cov)
    _, out = r.step(obs(0, (1.0, 2.0, 0.5), seen=[(0, 2.0, 1.0)], robot_id=2))
    (m,) = out
    return m


def test_the_default_sends_the_papers_message_and_the_others_add_the_pose():
    paper = _first_message({})
    assert (paper.body.pose, paper.body.pose_cov) == (None, None)
    assert paper.body == _first_message({"frame_source": "bearings"}).body
    mcl = _first_message({"frame_source": "mcl"})
    assert mcl.body.pose == pytest.approx((1.0, 2.0, 0.5)) and mcl.body.pose_cov is None
    assert mcl.size_bytes() == paper.size_bytes() + 24
    fused = _first_message({"frame_source": "fused"}, cov=np.diag([0.01, 0.02, 0.003]))
    assert fused.body.pose_cov == pytest.approx((0.01, 0.0, 0.0, 0.02, 0.0, 0.003))
    assert fused.size_bytes() == paper.size_bytes() + 72
    for m in (paper, mcl, fused):
        assert message_size_bytes(m.body) == m.size_bytes()


@settings(max_examples=40, deadline=None)
@given(pose_st, pose_st, st.tuples(st.floats(-20, 20), st.floats(-20, 20)))
def test_bearings_is_bit_identical_to_the_papers_rule_whatever_pose_the_message_carries(p1, p2, g):
    if math.dist(p1[:2], p2[:2]) < 0.05:
        return
    a = receive({}, p1, p2, g, mutual=True, sender_pose=(99.0, -5.0, 1.0))  # a pose is ignored
    b = receive({}, p1, p2, g, mutual=True)
    d, b21 = polar(p1, p2)
    _, b12 = polar(p2, p1)
    rel = sender_frame(b21, b12, d)
    assert a is not None and np.array_equal(a, b)
    np.testing.assert_allclose(a, transform_points(np.array(p1), transform_points(np.array(rel), np.array(
        transform_points(relative(np.array(p2), np.zeros(3)), np.array(g))))), atol=1e-6)


@pytest.mark.parametrize("kwargs, field", [({"frame_source": "gps"}, "frame_source"),
                                           ({"frame_err_max": -0.1}, "frame_err_max"),
                                           ({"frame_robot_size_m": 0.0}, "frame_robot_size_m")])
def test_bad_frame_parameters_are_named(kwargs, field):
    with pytest.raises(ValidationError, match=field) as e:
        LosExplorer.Params(**kwargs)
    if field == "frame_source":
        assert "'bearings', 'mcl' or 'fused'" in str(e.value)


# ---------------------------------------------------------------------------- files and a run
def test_shipped_files_are_what_the_generator_writes(tmp_path):
    from teamnav.papers.beyond import localized_los_scenarios as B
    from teamnav.experiments import registry
    from teamnav.experiments.sweep import sweep_files

    (tmp_path / "sc").mkdir()
    (tmp_path / "sw").mkdir()
    for p in B.write_files(tmp_path / "sc", tmp_path / "sw"):
        shipped = registry.path(p.stem) if p.parent.name == "sc" else sweep_files()[p.stem]
        assert shipped.read_text(encoding="utf-8") == p.read_text(encoding="utf-8"), (
            f"{shipped.name} is stale: run python -m teamnav.papers.beyond.localized_los_scenarios")


def test_world_frame_targets_are_the_papers_targets():
    from teamnav.papers.beyond import localized_los_scenarios as B
    from teamnav.papers.los_help import tasks as L

    for m in B.MAPS:
        data = B.scenario_data(m)
        r1 = data["robots"][0]
        assert r1["controller"] == "localized-v1" and r1["odometry"] == {"frame": "world"} and data["give_map"]
        np.testing.assert_allclose(r1["params"]["brain_params"]["targets_xy"],
                                   L.task_targets_world(m, 1, B.N_TARGETS), atol=1e-3)
        for k, g in enumerate(data["robots"][1:]):
            np.testing.assert_allclose(g["params"]["brain_params"]["patrol_xy"], L.team_routes(m)[k], atol=1e-3)


def test_a_short_localized_run_with_mcl_frames_finishes_and_shares_poses(tmp_path):
    from teamnav.papers.beyond import localized_los_scenarios as B
    from teamnav.experiments import runner

    targets = B.scenario_data("simple")["robots"][0]["params"]["brain_params"]["targets_xy"][:2]
    ov = {"robots.0.params.brain_params.targets_xy": targets, "duration_s": 300.0}
    for k in range(4):
        ov[f"robots.{k}.params.brain_params.frame_source"] = "mcl"
    res = runner.run(runner.load_scenario("beyond-localized-los-simple", overrides=ov), out_dir=tmp_path / "r",
                     progress=False)
    m = res.metrics
    assert m["los_finished"] == 1 and m["los_targets_reached"] == 2
    assert m["loc_mean_error_m"] < 0.3  # the filters track (the frames' source)


# ---------------------------------------------------------------------------- the report block
def _fake_full(mcl_gain: float, fused_gain: float):
    """Full mode without running: bearings 150 (+1 per seed, +20 at err_max 0.4); mcl and fused
    ``gain`` steps per target faster at err_max 0.4 (with a seed-dependent wobble), equal at 0."""
    from _report_fakes import FakeFullContext

    def rows_for(spec, seeds):
        rows = []
        for c in spec.cases:
            source, e = c["case"].split("-e")
            e = float(e)
            for s in seeds:
                v = 150.0 + s + (20.0 if e else 0.0)
                if e and source != "bearings":
                    v -= (mcl_gain if source == "mcl" else fused_gain) + (s % 3 - 1)
                rows.append({"status": "ok", "seed": s, "params": {"case": c["case"]}, "los_steps_per_target": v,
                             "los_finished": 1, "loc_mean_error_m": 0.05})
        return rows

    return FakeFullContext(rows_for)


def test_full_mode_reads_both_maps_and_judges_with_the_paired_rule():
    from teamnav.experiments.report.model import Comparison, Table
    from teamnav.papers.beyond.report._beyond_localized_los import localized_los

    ctx = _fake_full(mcl_gain=10.0, fused_gain=0.0)
    blocks = localized_los(ctx)
    assert [a[0] for a in ctx.asked] == ["beyond-localized-los-simple", "beyond-localized-los-complex"]
    assert all(a[1] == list(range(10)) for a in ctx.asked)
    tables = [b for b in blocks if isinstance(b, Table)]
    assert len(tables) == 2 and [r[0] for r in tables[0].rows] == [
        "bearings-e0", "mcl-e0", "fused-e0", "bearings-e0.4", "mcl-e0.4", "fused-e0.4"]
    mcl04 = tables[0].rows[4]
    assert mcl04[3].startswith("165 ± 3") and mcl04[4] == "10/10" and mcl04[5].startswith("-9.9 ± 0.9")
    assert "faster on 10/10 seeds" in mcl04[5]
    text = " ".join(b.text for b in blocks if hasattr(b, "text"))
    assert "err_max 0.4, frames from MCL poses: helps" in text
    assert "err_max 0.4, frames from both, fused: no measurable difference" in text
    verdicts = [(b.claim, b.holds) for b in blocks if isinstance(b, Comparison)]
    assert [h for _, h in verdicts] == [True, False]  # mcl helps on both maps; fused equal to bearings
    assert "frames from MCL poses" in verdicts[0][0] and "fusing" in verdicts[1][0]


def test_quick_mode_runs_two_short_runs_and_judges_nothing(tmp_path):
    from teamnav.experiments.report.context import SweepContext
    from teamnav.experiments.report.model import Comparison, Table
    from teamnav.papers.beyond.report._beyond_localized_los import localized_los

    blocks = localized_los(SweepContext(tmp_path, quick=True, workers=1, section="beyond"))
    (table,) = [b for b in blocks if isinstance(b, Table)]
    assert [r[0] for r in table.rows] == ["bearings-e0.4", "mcl-e0.4"]
    assert all(r[4] == "1/1" for r in table.rows), table.rows  # 3 targets, both finished
    assert all(b.holds is None for b in blocks if isinstance(b, Comparison))


def test_each_sweep_case_sets_every_robots_source_noise_and_noise_model():
    from teamnav.papers.beyond import localized_los_scenarios as B
    from teamnav.experiments import runner
    from teamnav.experiments.sweep import expand, load_sweep

    for m in B.MAPS:
        spec = load_sweep(B.sweep_name(m))
        assert spec.seeds == 10 and [c["case"] for c in spec.cases] == [B.case_label(s, e) for s, e in B.CASES]
        trials = expand(spec)
        assert len(trials) == 60
        t = next(t for t in trials if t.params["case"] == "fused-e0.4")
        overrides = {k: v for k, v in t.params.items() if k != "case"}
        scn = runner.load_scenario(spec.scenario, overrides=overrides)
        assert len(scn.robots) == 4
        for g in scn.robots:
            assert g.detector.err_max == 0.4
            assert g.params["brain_params"]["frame_source"] == "fused"
            assert g.params["brain_params"]["frame_err_max"] == 0.4
