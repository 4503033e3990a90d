"""§7.2 delayed integration (Fox, Burgard, Kruppa & Thrun 2000): the SE(2) moves, the store, and the
brain's use of them (:mod:`teamnav.papers.collab_mcl.brains.delayed_integration`)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.papers.collab_mcl.brains.delayed_integration import (
    DetectionStore, OdometryHistory, StoredDetection, detected_point_now, motion_since, poses_after, poses_before,
)
from teamnav.papers.collab_mcl.brains.localizing import MCLWander, MCLWanderParams
from teamnav.control.types import Detection, Message
from teamnav.geometry import se2
from teamnav.localization.sync import SYNC_KIND, SyncMessage

from tests.test_localizing_brain import _info, _mass_near, _obs

coord = st.floats(-50.0, 50.0, allow_nan=False)
angle = st.floats(-math.pi, math.pi, allow_nan=False)
pose = st.tuples(coord, coord, angle).map(np.array)


def _same_pose(a, b, tol=1e-7) -> bool:
    """Whether poses a and b agree: positions within ``tol`` and headings within ``tol`` (wrapped)."""
    a, b = np.asarray(a), np.asarray(b)
    d = np.angle(np.exp(1j * (a[..., 2] - b[..., 2])))
    return bool(np.allclose(a[..., :2], b[..., :2], atol=tol) and np.all(np.abs(d) < tol))


@settings(max_examples=200, deadline=None)
@given(pose, pose)
def test_moving_back_then_forward_is_the_identity(p, m):
    assert _same_pose(poses_after(poses_before(p[None], m), m), p[None])
    assert _same_pose(poses_before(poses_after(p[None], m), m), p[None])


@settings(max_examples=200, deadline=None)
@given(pose, st.lists(pose.map(lambda v: v * np.array([0.05, 0.05, 0.1])), min_size=1, max_size=20))
def test_motion_since_is_the_odometry_composed_step_by_step(start, steps):
    """The history stores odometry poses; the motion between two of them is the per-step odometry
    deltas (each in the previous body frame, as the brain receives them) composed."""
    odom, acc = start.copy(), np.zeros(3)
    for d in steps:
        odom = se2.compose(odom, d)
        acc = se2.compose(acc, d)
    assert _same_pose(motion_since(start, odom), acc, tol=1e-6)


@settings(max_examples=200, deadline=None)
@given(pose, pose, st.floats(0.3, 5.0), st.floats(-math.pi / 2, math.pi / 2))
def test_a_stored_detection_moved_forward_points_at_the_same_place(p0, m, r, b):
    """The observer saw a point at (r, b) from pose p0, then moved by m: from its pose now the
    moved-forward detection points at the same world point; and the samples moved back by m stand
    at p0, so a tree built there is the seen robot's position at the detection time."""
    p1 = se2.compose(p0, m)
    seen = se2.transform_points(p0, [r * math.cos(b), r * math.sin(b)])
    r1, b1 = detected_point_now(r, b, m)
    assert _same_pose(poses_before(p1[None], m), p0[None], tol=1e-6)
    assert np.allclose(se2.transform_points(p1, [r1 * math.cos(b1), r1 * math.sin(b1)]), seen, atol=1e-6)


def test_history_and_store_forget_old_entries_and_refuse_bad_ages():
    h = OdometryHistory(2.0)
    for k in range(40):
        h.record(0.1 * k, [0.1 * k, 0.0, 0.0], scan=np.full(3, k))
    assert h.pose_at(0.5) is None  # 3.4 s ago > 2 s
    assert np.allclose(h.pose_at(2.0), [2.0, 0.0, 0.0]) and h.scan_at(2.0)[0] == 20
    s = DetectionStore(5.0)
    s.put(StoredDetection(1, 2.0, 0.0, 0.0))
    s.put(StoredDetection(2, 2.0, 0.0, 3.0))
    s.put(StoredDetection(1, 1.5, 0.1, 4.0))  # replaces robot 1's older one
    assert len(s) == 2 and s.expire(8.5) == 1 and [d.target for d in s.take()] == [1] and len(s) == 0
    with pytest.raises(ValueError, match="delay_max_age_s"):
        DetectionStore(0.0)
    with pytest.raises(ValueError, match="max_age_s"):
        OdometryHistory(float("nan"))


def test_flag_maps_the_old_parameter_and_refuses_conflicts():
    assert MCLWanderParams().unsure_detections == "integrate"  # §3.2: at once
    assert MCLWanderParams(send_min_cluster_weight=0.5).unsure_detections == "drop"  # the earlier behaviour
    with pytest.raises(ValueError, match="send_min_cluster_weight = 0.5 > 0"):
        MCLWanderParams(send_min_cluster_weight=0.5, unsure_detections="integrate")
    with pytest.raises(ValueError, match=r"'delay' needs .* send_min_cluster_weight in \(0, 1\]"):
        MCLWanderParams(unsure_detections="delay")
    with pytest.raises(ValueError, match="unsure_detections"):
        MCLWanderParams(paper_rules=True, unsure_detections="delay")
    assert MCLWanderParams(paper_rules=True).unsure_detections == "integrate"


# ---------------------------------------------------------------------------- the brain
def _delay_brain(i: int, seed: int, pose, **over) -> MCLWander:
    p = MCLWanderParams(collaborate=True, max_particles=400, min_particles=100, init_pose=pose,
                        send_min_cluster_weight=0.99, unsure_detections="delay", detection_period_s=0.0, **over)
    return MCLWander(p, np.random.default_rng(seed), _info(i))


def _split(b: MCLWander, far_x: float = 5.0) -> None:
    """Unsure: every other sample moved to ``far_x`` (two clusters of about half the weight; the
    scans of the next filter update leave the heaviest one below 0.99)."""
    p = b.mcl.particles.copy()
    p[np.cumsum(b.mcl.weights) <= 0.5, 0] = far_x
    b.mcl.move_samples(p)


def _join(b: MCLWander, far_x: float = 5.0) -> None:
    """Concentrated again: the far samples put back onto the others."""
    p = b.mcl.particles.copy()
    far = np.abs(p[:, 0] - far_x) < 3.0
    near = p[~far]
    p[far] = near[np.arange(int(far.sum())) % near.shape[0]]
    b.mcl.move_samples(p)


def _sync_out(out: list[Message]) -> list[Message]:
    return [m for m in out if m.kind == SYNC_KIND and m.body.kind == "detection"]


def test_a_stored_detection_is_sent_once_when_the_belief_concentrates_and_not_before():
    a = _delay_brain(0, 0, (20.0, 9.6, 0.0))
    a.step(_obs(0, 0, move_m=0.1))
    for k in range(1, 6):  # B seen on every frame while A is unsure: nothing is sent
        _split(a)
        _, out = a.step(_obs(0, k, move_m=0.1, dets=[Detection(1.5, 0.0, 1)]))
        assert _sync_out(out) == []
    seen_then = se2.transform_points(a.mcl.estimate().cluster_pose, [1.5, 0.0])  # B at t = 0.5 s
    assert a._delay.stats["stored"] == 5 and len(a._delay.store) == 1
    for k in range(6, 21):  # A drives on, unsure, B out of sight
        _split(a)
        _, out = a.step(_obs(0, k, move_m=0.1))
        assert _sync_out(out) == []
    _join(a)
    seen_now = se2.transform_points(a.mcl.estimate().cluster_pose, [1.5, 0.0])  # the detection read as now
    _, out = a.step(_obs(0, 21, move_m=0.1))
    sent = _sync_out(out)
    assert len(sent) == 1 and sent[0].to == 1
    body = sent[0].body
    assert body.detected_s == pytest.approx(0.5)  # the latest sight (step 5)
    # the tree is B where it was at t = 0.5 s, not 1.5 m ahead of where A is now (1.5 m further on)
    centre = body.tree.sample(4000, np.random.default_rng(0)).mean(axis=0)
    assert np.hypot(*(centre - seen_then)) < 0.3 and np.hypot(*(centre - seen_now)) > 1.2
    assert a._delay.stats["delayed_sent"] == 1
    for k in range(22, 30):  # exactly once
        _, out = a.step(_obs(0, k, move_m=0.1))
        assert _sync_out(out) == []


def test_a_fresher_sight_used_now_supersedes_the_stored_one():
    a = _delay_brain(0, 0, (20.0, 9.6, 0.0))
    a.step(_obs(0, 0))
    _split(a)
    a.step(_obs(0, 1, dets=[Detection(1.5, 0.0, 1)]))
    _join(a)
    _, out = a.step(_obs(0, 2, dets=[Detection(1.5, 0.0, 1)]))
    sent = _sync_out(out)
    assert len(sent) == 1 and sent[0].body.detected_s is None  # the live one, §2.3 rule 2 blocks the other
    assert a._delay.stats["superseded"] == 1 and a._delay.stats["delayed_sent"] == 0


def test_a_stored_detection_older_than_the_max_age_is_dropped():
    a = _delay_brain(0, 0, (20.0, 9.6, 0.0), delay_max_age_s=1.0)
    a.step(_obs(0, 0))
    _split(a)
    a.step(_obs(0, 1, dets=[Detection(1.5, 0.0, 1)]))  # t = 0.1 s
    assert a._delay.stats["stored"] == 1
    for k in range(2, 13):
        _split(a)
        a.step(_obs(0, k))
    _join(a)
    _, out = a.step(_obs(0, 13))  # t = 1.3 s: 1.2 s old
    assert _sync_out(out) == [] and a._delay.stats["expired"] == 1 and a._delay.stats["delayed_sent"] == 0


def _delayed_msg(center_xy, detected_s: float, seed: int = 9) -> Message:
    from teamnav.localization.density_tree import DensityTree

    pts = np.random.default_rng(seed).normal(center_xy, 0.3, size=(2000, 2))
    tree = DensityTree.fit(pts, np.full(2000, 1 / 2000), min_samples=20, max_depth=20)
    return Message(0, 2.5, SyncMessage("detection", 0, 1, 1.5, 0.0, 0.035, tree, (), detected_s), to=1,
                   kind=SYNC_KIND)


def _receiver(**over) -> MCLWander:
    """B from x = 21 m, 0.1 m per step for 25 steps (x ~ 23.5 m at t = 2.5 s), then bimodal:
    half its samples moved to x = 10 m."""
    b = MCLWander(MCLWanderParams(collaborate=True, max_particles=400, min_particles=100,
                                  init_pose=(21.0, 9.6, 0.0), **over), np.random.default_rng(4), _info(1))
    for k in range(25):
        b.step(_obs(1, k, move_m=0.1))
    _split(b, far_x=10.0)
    return b


def test_the_receiver_applies_a_delayed_tree_to_its_samples_at_the_detection_time():
    """The tree says B was at x = 21.5 m at t = 0.5 s; B has driven 2 m since. Moved back by its own
    odometry, B's right mode (x ~ 23.5 now) matches it; applied as if made now it matches neither."""
    b = _receiver()
    b.step(_obs(1, 25, move_m=0.1, inbox=[_delayed_msg((21.5, 9.6), 0.5)]))
    assert b.sync.applied["detection"] == 1
    assert _mass_near(b, (23.6, 9.6)) > 0.9
    c = _receiver()  # the same tree, no detection time: read as "now" (x = 21.5), both modes miss it
    msg = _delayed_msg((21.5, 9.6), 0.5)
    c.step(_obs(1, 25, move_m=0.1, inbox=[Message(0, 2.5, SyncMessage(**{**msg.body.__dict__, "detected_s": None}),
                                                  to=1, kind=SYNC_KIND)]))
    assert _mass_near(c, (23.6, 9.6)) < 0.7


def test_draws_from_a_delayed_tree_are_moved_forward_by_the_receivers_odometry():
    """Sensor resetting (teamnav's column) in the past frame: the draws land where the tree put B at
    the detection time and then follow B's odometry (2 m along +x), headings from the own belief."""
    b = _receiver(inject_fraction=0.1, inject_min_draws=300, inject_heading_belief_share=1.0)
    b.mcl.move_samples(np.column_stack([np.full(b.mcl.n_particles, 10.0), b.mcl.particles[:, 1:]]))  # all wrong
    b.step(_obs(1, 25, move_m=0.1, inbox=[_delayed_msg((21.5, 9.6), 0.5)]))
    assert _mass_near(b, (23.6, 9.6), r_m=1.0) > 0.5
    assert _mass_near(b, (21.5, 9.6), r_m=0.8) < 0.05


def test_a_delayed_tree_older_than_the_receivers_history_is_not_applied():
    b = _receiver(delay_max_age_s=1.0)  # history 1 + 5 s: t = 0.5 s is still in it
    b.step(_obs(1, 25, move_m=0.1, inbox=[_delayed_msg((21.5, 9.6), -10.0)]))
    assert b.sync.applied["detection"] == 0 and b.stats["stale"] == 1


# ---------------------------------------------------------------------------- the report's numbers
def test_cotravel_values_pair_by_seed_and_feed_the_claim():
    from teamnav.experiments.claims import judge, load_claims
    from teamnav.papers.collab_mcl.report._collab_delayed import cotravel_values

    ttl = {"alone": [300, 200, 250], "integrate": [250, 400, 300], "drop": [260, 380, 290], "delay": [200, 300, 310]}
    rows = [{"seed": s, "params": {"case": c}, "metrics": {"loc_time_to_localize_s": t[s],
                                                           "loc_final_localized_fraction": 0.5 + 0.1 * s}}
            for c, t in ttl.items() for s in range(3)]
    v = cotravel_values(rows)
    d = np.array([200 - 250, 300 - 400, 310 - 300])
    assert v["delay_paired_mean_s"] == pytest.approx(d.mean())
    assert v["delay_paired_se_s"] == pytest.approx(d.std(ddof=1) / math.sqrt(3))
    assert v["delay_faster_pairs"] == 2 and v["delay_n_pairs"] == 3
    assert v["integrate_ttl_mean_s"] == pytest.approx(950 / 3)
    assert v["delay_vs_drop_paired_mean_s"] == pytest.approx((-60 - 80 + 20) / 3)
    # three pairs are fewer than the claim's minimum of five: not judged
    claim = load_claims("collab-mcl")["delayed-integration"]
    ok, text = judge(claim, v)
    assert ok is None and "n = 3" in text
    # with five pairs, the upper bound -20 + 2 * 33 > 0: not clearly faster, so the claim does not hold
    ok, _ = judge(claim, {**v, "delay_n_pairs": 5.0})
    assert ok is False


def test_cotravel_sweep_runs_the_claims_seeds_with_valid_params():
    """The sweep's four cases on the claim's judged seeds; every case's params validate (integrate with
    no threshold, drop and delay with the same one); the robots start together, heading north."""
    from teamnav.experiments.claims import load_claims
    from teamnav.experiments.spec import load_scenario
    from teamnav.experiments.sweep import expand, load_sweep

    trials = expand(load_sweep("collab-mcl-cotravel"))
    cases = {t.params["case"] for t in trials}
    assert cases == {"alone", "integrate", "drop", "delay"} and len(trials) == 80
    assert sorted({t.seed for t in trials}) == load_claims("collab-mcl")["delayed-integration"].seed_list
    by_case = {t.params["case"]: t.params for t in trials}
    assert by_case["drop"]["robots.0.params.send_min_cluster_weight"] == \
        by_case["delay"]["robots.0.params.send_min_cluster_weight"] > 0
    for case, params in by_case.items():
        over = {k: v for k, v in params.items() if k not in ("case", "duration_s")}
        scn = load_scenario("collab-mcl-hallway", overrides=over, duration_s=1.0)
        p = MCLWanderParams.model_validate(scn.robots[0].params)
        assert p.unsure_detections == {"alone": "integrate", "integrate": "integrate", "drop": "drop",
                                       "delay": "delay"}[case]
        assert scn.robots[0].count == 4 and scn.robots[0].start.theta_deg == 90.0


def test_report_part_is_full_mode_only_and_builds_from_rows():
    from types import SimpleNamespace

    from teamnav.experiments.report.model import Comparison, Missing, Table
    from teamnav.papers.collab_mcl.report._collab_delayed import _delayed

    assert isinstance(_delayed(SimpleNamespace(quick=True))[0], Missing)  # CI's quick mode stays short
    ttl = {"alone": 250.0, "integrate": 300.0, "drop": 260.0, "delay": 200.0}
    rows = [{"status": "ok", "seed": s, "params": {"case": c},
             "metrics": {"loc_time_to_localize_s": t + 7.0 * (s % 3), "loc_final_localized_fraction": 0.75,
                         "loc_censored": 1, "loc_syncs": 50}}
            for c, t in ttl.items() for s in range(20)]
    res = SimpleNamespace(rows=lambda: rows, total=len(rows))
    out = {"paper_rules": {}, "teamnav": {}}
    blocks = _delayed(SimpleNamespace(quick=False, sweep=lambda *a, **k: res), out)
    assert isinstance(blocks[0], Table) and len(blocks[0].rows) == 4
    comps = [b for b in blocks if isinstance(b, Comparison)]
    assert [c.holds for c in comps] == [True, True]  # 100 s and 60 s faster on every seed
    assert out["teamnav"]["delayed-integration"]["delay_paired_mean_s"] == pytest.approx(-100.0)
    assert out["paper_rules"]["delayed-integration"] == {}


# ---------------------------------------------------------------------------- what "concentrated" means
def _hallway_brain(**over) -> MCLWander:
    """A lost robot in the real symmetric hallway: global initialisation with 4000 samples."""
    from teamnav.control.protocol import RobotInfo
    from teamnav.papers.collab_mcl.maps import symmetric_hallway

    from tests.test_localizing_brain import LASER

    info = RobotInfo(0, 2, 0.25, "unicycle", 0.5, 1.5, 0.1, 0.1, sensors={"laser": LASER},
                     known_map=symmetric_hallway().grid, extras={"group": "g"})
    p = MCLWanderParams(collaborate=True, max_particles=4000, min_particles=100, send_min_cluster_weight=0.6,
                        unsure_detections="drop", detection_period_s=0.0, **over)
    b = MCLWander(p, np.random.default_rng(3), info)
    b.mcl.init_global()
    return b


def test_a_lost_robots_uniform_belief_is_not_concentrated():
    """Found 2026-11-27 (commit 349d51d): a uniform belief over the connected hallway is one 0.5-m-cell cluster
    of weight 1, so the weight alone (None, the rule before 349d51d) calls a lost robot sure."""
    b = _hallway_brain()
    est = b.mcl.estimate()
    assert est.n_clusters == 1 and est.cluster_weight > 0.99 and est.cluster_spread_m > 5.0
    assert not b._concentrated()
    assert _hallway_brain(send_max_cluster_spread_m=None)._concentrated()  # the earlier definition
    # a tight belief at a known pose is concentrated under both
    b.mcl.init_pose([20.0, 9.6, 0.0], np.diag([0.04, 0.04, 0.01]))
    assert b.mcl.estimate().cluster_spread_m < 0.5 and b._concentrated()


def test_drop_holds_back_a_lost_robots_detection_that_the_weight_alone_sent():
    sent = {}
    for spread in (2.0, None):
        b = _hallway_brain(send_max_cluster_spread_m=spread)
        _, out = b.step(_obs(0, 0, dets=[Detection(1.5, 0.0, 1)]))
        sent[spread] = len(_sync_out(out))
    assert sent == {2.0: 0, None: 1}


def test_the_spread_threshold_is_validated_with_field_and_range():
    with pytest.raises(ValueError, match="send_max_cluster_spread_m"):
        MCLWanderParams(send_max_cluster_spread_m=0.0)
    with pytest.raises(ValueError, match="send_max_cluster_spread_m"):
        MCLWanderParams(send_max_cluster_spread_m=-1.0)
