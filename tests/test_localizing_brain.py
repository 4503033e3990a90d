"""mcl-wander-v1: localizing from a known start, syncing on detections, the §2.3 rules, the
false-positive filter and identity association (Fox et al., collaborative MCL)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from teamnav.control import registry
from teamnav.papers.collab_mcl.brains.localizing import ASSOC_KIND, MCLWander, MCLWanderParams, load_detection_model
from teamnav.control.protocol import RobotInfo, SensorInfo
from teamnav.control.types import Detection, Message, Observation, RangeScan
from teamnav.experiments.runner import run
from teamnav.experiments.spec import load_scenario
from teamnav.localization.sync import SYNC_KIND, SyncMessage
from teamnav.world import builtin_map

def _bare_corridor():
    """The brain's unit tests feed synthetic scans: a bare 40 m corridor with a lab behind one
    opening (the §5.1 map before 2026-11-29), where those scans fit everywhere along the corridor."""
    from teamnav.world.map_builder import MapBuilder

    b = MapBuilder(42.0, 12.0, 0.1).fill("wall")
    b.clear_rect(1.0, 8.5, 41.0, 10.7).clear_rect(22.0, 1.0, 30.0, 8.3).clear_rect(23.0, 8.3, 24.6, 8.5)
    b.rect(26.0, 1.0, 29.6, 2.0).rect(29.4, 3.0, 30.0, 6.6).disc(25.6, 4.4, 0.7).rect(22.0, 1.0, 23.3, 3.0)
    b.rect(27.2, 6.6, 28.4, 8.3)
    return b.build("builtin:lab_and_corridor")


GRID = _bare_corridor()
ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 19)
LASER = SensorInfo("laser", "laser", ANGLES, 8.0)


def _info(i: int, n: int = 2) -> RobotInfo:
    return RobotInfo(i, n, 0.25, "unicycle", 0.5, 1.5, 0.1, 0.1, sensors={"laser": LASER}, known_map=GRID,
                     extras={"group": "g"})


def _brain(i: int, seed: int = 0, pose=(20.0, 9.6, 0.0), n: int = 2, **over) -> MCLWander:
    p = MCLWanderParams(collaborate=True, max_particles=400, min_particles=100, init_pose=pose, **over)
    return MCLWander(p, np.random.default_rng(seed), _info(i, n))


def _obs(i: int, step: int, *, move_m: float = 0.0, dets=(), inbox=()) -> Observation:
    scan = RangeScan(np.full(ANGLES.shape[0], 8.0), ANGLES, 8.0)
    return Observation(i, step, step * 0.1, np.array([move_m * step, 0.0, 0.0]), np.array([move_m, 0.0, 0.0]),
                       scans={"laser": scan}, detections=tuple(dets), inbox=tuple(inbox))


def test_registered_and_params_validated():
    assert registry.lookup("mcl-wander-v1") is MCLWander
    with pytest.raises(ValueError):
        MCLWanderParams(collaborat=True)
    with pytest.raises(ValueError, match="give_map"):
        MCLWander(MCLWanderParams(), np.random.default_rng(0),
                  RobotInfo(0, 1, 0.25, "unicycle", 0.5, 1.5, 0.1, 0.1, sensors={"laser": LASER}))
    with pytest.raises(ValueError, match="detection_model"):
        load_detection_model("no-such-model")


def test_shipped_model_is_the_trained_one():
    m = load_detection_model("default")
    assert m.n_detections > 1000
    assert abs(m.range_std_m - 0.483) < 0.05 and abs(math.degrees(m.bearing_std_rad) - 2.2) < 0.3
    assert abs(m.p_false_negative - 0.067) < 0.02 and abs(m.p_false_positive - 0.035) < 0.01


def test_localizes_from_a_known_start_in_the_lab():
    """Position tracking: a laser robot wandering the lab from a known start stays within 0.5 m."""
    scn = load_scenario("collab-mcl-detection", duration_s=20.0, overrides={
        "robots.0.params.motion_mode": "wander", "robots.0.params.collaborate": False,
        "robots.0.params.init_pose": [22.5, 7.0, 0.0], "robots.0.start.poses": [[22.5, 7.0, 0.0]],
        "robots.1.count": 0,
    })
    m = run(scn, progress=False).metrics
    assert m["loc_final_error_m"] < 0.5
    assert m["loc_localized_fraction"] == 1.0


def test_two_robots_sync_when_one_detects_the_other():
    """Robin right in front of Marian's opening: a detection is sent as a tree (bytes counted)
    and collapses Robin's global uncertainty (§5.1)."""
    scn = load_scenario("collab-mcl-detection", duration_s=12.0, overrides={
        "robots.1.start.region": [23.0, 24.6, 9.3, 9.9], "robots.1.params.max_particles": 4000})
    res = run(scn, progress=False)
    m = res.metrics
    assert m["messages_sent"] >= 2  # Marian's tree + Robin's inverse reply (§2.3 symmetry)
    assert m["bytes_sent"] > 1000
    assert m["loc_syncs"] >= 2
    assert m["loc_final_error_m_g_robin"] < 1.5
    alone = run(load_scenario(scn, overrides={"robots.1.params.collaborate": False}), progress=False).metrics
    assert alone["messages_sent"] >= 1 and alone["loc_final_error_m_g_robin"] > 3.0


def _exchange(a: MCLWander, b: MCLWander, steps: range, move_m: float, det: Detection):
    """A sees B on every step while both move ``move_m`` per step; messages go back and forth."""
    to_a: list[Message] = []
    to_b: list[Message] = []
    sent = 0
    for k in steps:
        _, out_a = a.step(_obs(0, k, move_m=move_m, dets=[det], inbox=to_a))
        _, out_b = b.step(_obs(1, k, move_m=move_m, inbox=to_b))
        sent += sum(1 for m in out_a if m.kind == SYNC_KIND and m.body.kind == "detection")
        to_b, to_a = out_a, out_b
    return sent


def test_the_2_5_m_rule_blocks_a_second_use_in_a_closed_loop():
    a, b = _brain(0, 0, detection_period_s=0.0), _brain(1, 1, detection_period_s=0.0)
    det = Detection(1.5, 0.0, 1)
    # 30 steps x 0.06 m = 1.8 m of travel: one use only, though B is seen on every step
    assert _exchange(a, b, range(0, 30), 0.06, det) == 1
    assert b.sync.applied["detection"] == 1 and a.sync.applied["inverse"] == 1
    # 30 more steps: 3.6 m in all, past 2.5 m: a second use (B has travelled as far, so it
    # accepts a second tree from A: the rule holds on the receiving side too)
    assert _exchange(a, b, range(30, 60), 0.06, det) == 1
    assert b.sync.applied["detection"] == 2 and a.sync.applied["inverse"] == 2


def test_false_positive_filter_needs_a_confirmed_sighting():
    """Gate 2: a lone (phantom-like) sight is not sent; the same robot seen again next frame
    at a consistent place is."""
    a = _brain(0, 0, false_positive_filter=True)
    _, out = a.step(_obs(0, 0, dets=[Detection(1.5, 0.0, 1)]))
    assert not [m for m in out if m.kind == SYNC_KIND] and a.stats["filtered"] == 1
    _, out = a.step(_obs(0, 10, dets=[Detection(1.6, 0.05, 1)]))
    assert len([m for m in out if m.kind == SYNC_KIND]) == 1
    b = _brain(0, 0, false_positive_filter=True)
    b.step(_obs(0, 0, dets=[Detection(1.5, 0.0, 1)]))
    _, out = b.step(_obs(0, 10, dets=[Detection(4.5, 1.0, 1)]))  # inconsistent: 3+ m away
    assert not [m for m in out if m.kind == SYNC_KIND]
    # without the filter the lone sight is used at once
    c = _brain(0, 0)
    _, out = c.step(_obs(0, 0, dets=[Detection(1.5, 0.0, 1)]))
    assert len([m for m in out if m.kind == SYNC_KIND]) == 1


def test_receiver_drops_a_tree_its_belief_calls_a_phantom():
    """Gate 3: a localized robot (at x = 20 m) rejects a tree that puts it 15 m away."""
    obs_brain = _brain(0, 3, pose=(5.0, 9.6, 0.0))
    _, out = obs_brain.step(_obs(0, 0, dets=[Detection(1.0, 0.0, 1)]))
    msg = next(m for m in out if m.kind == SYNC_KIND)
    strict = _brain(1, 4, false_positive_filter=True, fp_min_real_prob=0.5)
    strict.step(_obs(1, 1, inbox=[msg]))
    assert strict.stats["rejected"] == 1 and strict.sync.applied["detection"] == 0
    plain = _brain(1, 4)
    plain.step(_obs(1, 1, inbox=[msg]))
    assert plain.sync.applied["detection"] == 1


def test_identity_withheld_is_associated_by_belief():
    """An anonymous sight: query broadcast, answers, and the robot whose belief fits gets the tree."""
    a = _brain(0, 0, n=3)  # at (20, 9.6) facing +x, sees someone 1.5 m ahead
    b = _brain(1, 1, pose=(21.5, 9.6, 0.0), n=3)  # believes it is there
    c = _brain(2, 2, pose=(5.0, 9.6, 0.0), n=3)  # believes it is far away
    _, out = a.step(_obs(0, 0, dets=[Detection(1.5, 0.0, None)]))
    query = [m for m in out if m.kind == ASSOC_KIND]
    assert len(query) == 1 and query[0].to is None
    _, ans_b = b.step(_obs(1, 1, inbox=query))
    _, ans_c = c.step(_obs(2, 1, inbox=query))
    assert ans_b[0].body.evidence > 10 * ans_c[0].body.evidence
    _, out = a.step(_obs(0, 2, inbox=ans_b + ans_c))
    sync = [m for m in out if m.kind == SYNC_KIND]
    assert len(sync) == 1 and sync[0].to == 1 and isinstance(sync[0].body, SyncMessage)
    ignoring = _brain(0, 0, anonymous="ignore")
    _, out = ignoring.step(_obs(0, 0, dets=[Detection(1.5, 0.0, None)]))
    assert out == []


def test_log_is_small_and_scores_the_belief():
    a = _brain(0, 0)
    a.step(_obs(0, 0))
    first = a.log()
    assert first["sensor_kind"] == "laser" and "layers" in first
    assert len(first["pts"]) == 2 * 64 and first["n_particles"] == 400
    pts = np.asarray(first["pts"]).reshape(-1, 2)
    assert np.all(np.hypot(pts[:, 0] - 20.0, pts[:, 1] - 9.6) < 1.5)
    second = a.log()
    assert "layers" not in second and "sensor_kind" not in second


# ---------------------------------------------------------------- received trees (sensor resetting)
def _tree_msg(center_xy, observer: int = 0, target: int = 1, std_m: float = 0.3, seed: int = 9) -> Message:
    """A detection message whose tree puts the receiver around ``center_xy`` (the sender's claim)."""
    from teamnav.localization.density_tree import DensityTree

    pts = np.random.default_rng(seed).normal(center_xy, std_m, size=(2000, 2))
    tree = DensityTree.fit(pts, np.full(2000, 1 / 2000), min_samples=20, max_depth=20)
    body = SyncMessage("detection", observer, target, 1.5, 0.0, 0.035, tree)
    return Message(observer, 0.0, body, to=target, kind=SYNC_KIND)


def _mass_near(b: MCLWander, xy, r_m: float = 1.5) -> float:
    p = b.mcl.particles
    return float(b.mcl.weights[np.hypot(p[:, 0] - xy[0], p[:, 1] - xy[1]) < r_m].sum())


HERE, THERE = (20.0, 9.6), (35.0, 9.6)


@pytest.mark.parametrize("weighting", ["tree", "bayes"])
def test_a_localized_robot_does_not_follow_a_wrong_sender(weighting):
    """A receiver sure to be at x = 20 m gets a tree that puts it at x = 35 m (the sender is wrong).
    The first version's draws took all the weight (eq. 14 on draws from the tree counts the tree
    twice, and the kept samples get only the p_fp floor): the receiver jumped to the sender's
    claim. With the lost-prior weighting the draws get the posterior probability of "lost",
    eps / (eps + (1 - eps) p_fp), and the own belief keeps the rest."""
    b = _brain(1, 5, inject_fraction=0.2, inject_weighting=weighting, inject_lost_prior=0.02)
    b.step(_obs(1, 0))
    b.step(_obs(1, 1, inbox=[_tree_msg(THERE)]))
    assert b.sync.applied["detection"] == 1
    if weighting == "tree":
        assert _mass_near(b, THERE) > 0.95
    else:
        share = 0.02 / (0.02 + 0.98 * 0.035)
        assert abs(_mass_near(b, THERE) - share) < 0.03
        assert _mass_near(b, HERE) > 0.6


def test_a_tree_the_belief_confirms_leaves_the_draws_almost_nothing():
    b = _brain(1, 5, inject_fraction=0.2, inject_lost_prior=0.3)
    b.step(_obs(1, 0))
    before = b.mcl.estimate().cluster_pose[:2].copy()
    b.step(_obs(1, 1, inbox=[_tree_msg(HERE)]))
    assert np.hypot(*(b.mcl.estimate().cluster_pose[:2] - before)) < 0.2
    assert _mass_near(b, HERE, 1.0) > 0.99


@pytest.mark.parametrize("before_reply", [True, False])
def test_the_reply_carries_only_the_receivers_own_belief(before_reply):
    """§2.3 symmetry: the detected robot answers with its position tree. The first version drew
    the tree's samples first, so the reply held the sender's own claim (x = 35 m) and the sender
    multiplied its own belief into itself again (double counting)."""
    b = _brain(1, 5, inject_fraction=0.2, inject_before_reply=before_reply)
    b.step(_obs(1, 0))
    _, out = b.step(_obs(1, 1, inbox=[_tree_msg(THERE)]))
    reply = next(m for m in out if m.kind == SYNC_KIND and m.body.kind == "inverse")
    claim = float(reply.body.tree(np.array([THERE]))[0])
    if before_reply:
        assert claim > 0.01
    else:
        assert claim == 0.0
        assert float(reply.body.tree(np.array([HERE]))[0]) > 0.1


@pytest.mark.parametrize("share", [0.0, 1.0])
def test_draws_take_their_heading_from_the_belief(share):
    """A detection sees no heading. Uniform headings (share 0) put draws on the mirror pose of a
    corridor (other side of the axis, heading reversed) that the scan cannot tell apart; headings
    from the own belief (facing +x here) do not."""
    b = _brain(1, 5, inject_fraction=0.5, inject_lost_prior=0.5, inject_heading_belief_share=share)
    b.step(_obs(1, 0))
    b.step(_obs(1, 1, inbox=[_tree_msg(THERE)]))
    p = b.mcl.particles
    th = p[np.hypot(p[:, 0] - THERE[0], p[:, 1] - THERE[1]) < 1.5, 2]
    assert th.size > 100
    facing = float(np.mean(np.abs(np.angle(np.exp(1j * th))) < math.radians(30)))
    if share == 1.0:
        assert facing > 0.9
    else:
        assert 0.08 < facing < 0.3


def _true_scan(pose) -> np.ndarray:
    from teamnav.world.raycast import cast_rays

    r = cast_rays(GRID.blocking(None), GRID.origin_xy_m[0], GRID.origin_xy_m[1], GRID.resolution_m,
                  np.array([pose[0]]), np.array([pose[1]]), np.array([pose[2]]), ANGLES, 8.0, parallel=False)
    return np.asarray(r, dtype=float).reshape(-1)


def test_pose_log_likelihood_matches_the_sample_set_and_leaves_it_alone():
    b = _brain(1, 5)
    z = _true_scan((20.0, 9.6, 0.0))
    before_p, before_w = b.mcl.particles.copy(), b.mcl.weights.copy()
    q = np.array([[20.0, 9.6, 0.0], [20.0, 9.6, math.pi / 2], [35.0, 9.6, 0.0]])
    ll = b.mcl.pose_log_likelihood(q, z)
    assert ll.shape == (3,) and ll[0] > ll[1]
    np.testing.assert_array_equal(b.mcl.particles, before_p)
    np.testing.assert_array_equal(b.mcl.weights, before_w)
    np.testing.assert_allclose(b.mcl.log_likelihood(z)[:1], b.mcl.pose_log_likelihood(b.mcl.particles[:1], z))


@pytest.mark.parametrize("scan_share", [0.0, 1.0])
def test_draws_can_take_their_heading_from_the_scan(scan_share):
    """Hallway case: the receiver's own heading is wrong (it faces +y, the corridor runs along x),
    so neither its belief's heading nor a uniform one fits. Headings picked by the scan lie along
    the corridor's axis (either way: a featureless corridor cannot tell the two apart)."""
    b = _brain(1, 5, pose=(20.0, 9.6, 90.0), inject_fraction=0.5, inject_lost_prior=0.5,
               inject_heading_belief_share=0.0, inject_heading_scan_share=scan_share)
    scan = RangeScan(_true_scan((35.0, 9.6, 0.0)), ANGLES, 8.0)
    obs = _obs(1, 0)
    b.step(Observation(1, 0, 0.0, obs.odom_pose, obs.odom_delta, scans={"laser": scan}))
    b.step(Observation(1, 1, 0.1, obs.odom_pose, obs.odom_delta, scans={"laser": scan}, inbox=(_tree_msg(THERE),)))
    p = b.mcl.particles
    th = p[np.hypot(p[:, 0] - THERE[0], p[:, 1] - THERE[1]) < 1.5, 2]
    assert th.size > 50
    along = float(np.mean(np.abs(np.sin(th)) < math.sin(math.radians(30))))
    if scan_share == 1.0:
        assert along > 0.85
    else:
        assert 0.2 < along < 0.5


def test_min_draws_are_added_and_get_the_bayes_share():
    """A confident robot carries few samples; ``inject_min_draws`` adds draws instead of replacing
    a tenth of them, and the draws together get the posterior share of "lost" (the kept samples
    all stay, with the rest)."""
    b = _brain(1, 5, inject_fraction=0.1, inject_lost_prior=0.3, inject_min_draws=300)
    b.step(_obs(1, 0))
    n = b.mcl.n_particles
    b.step(_obs(1, 1, inbox=[_tree_msg(THERE)]))
    assert b.sync.applied["detection"] == 1
    assert b.mcl.n_particles == n + 300
    share = 0.3 / (0.3 + 0.7 * 0.035)
    assert abs(_mass_near(b, THERE) - share) < 0.03
    assert abs(_mass_near(b, HERE) - (1 - share)) < 0.03


@pytest.mark.parametrize("sender_prior", [0.0, 0.3])
def test_a_disagreement_between_confident_robots_is_split_when_the_sender_may_be_wrong(sender_prior):
    """The receiver is sure of x = 20 m, the tree says x = 35 m: one of the two robots is wrong.
    The first version (sender_prior 0) weighs "I am lost" only against a false positive and hands
    the draws 92 % of the weight; with the sender's own lost prior the split is about 57 / 43."""
    b = _brain(1, 5, inject_fraction=0.1, inject_lost_prior=0.3, inject_min_draws=300,
               inject_sender_lost_prior=sender_prior)
    b.step(_obs(1, 0))
    b.step(_obs(1, 1, inbox=[_tree_msg(THERE)]))
    floor = 0.035 + 0.965 * sender_prior
    share = 0.3 / (0.3 + 0.7 * floor)
    assert abs(_mass_near(b, THERE) - share) < 0.03
    assert (share > 0.9) == (sender_prior == 0.0)


# ---------------------------------------------------------------------------- paper_rules
from teamnav.control.paper_rules import gap_fills  # noqa: E402

#: a value other than the paper's for every PAPER_RULES field
_NOT_PAPER = {"inject_fraction": 0.1, "inject_min_draws": 500, "inject_sender_lost_prior": 0.3,
              "likelihood_exponent": 0.1, "resample_ess_fraction": 0.5, "provenance": True, "receive_gate": True,
              "send_min_cluster_weight": 0.5, "false_positive_filter": True, "anonymous": "associate",
              "unsure_detections": "delay", "negative_detections": True, "adapt": "kld"}


def test_paper_rules_sets_every_listed_field():
    p = MCLWanderParams(paper_rules=True)
    assert set(MCLWanderParams.PAPER_RULES) == set(MCLWanderParams.PAPER_RULE_NOTES) == set(_NOT_PAPER)
    for key, value in MCLWanderParams.PAPER_RULES.items():
        assert getattr(p, key) == value, key
    # the list of the paper's rules: no sensor resetting, untempered likelihood, resampling every update, the
    # two rules of §2.3 only (no provenance, no receive gate), anonymous sights ignored
    assert (p.inject_fraction, p.likelihood_exponent, p.resample_ess_fraction) == (0.0, 1.0, 1.0)
    assert not p.provenance and not p.receive_gate and p.anonymous == "ignore"
    # defaults stay teamnav's (existing runs do not move)
    q = MCLWanderParams()
    assert not q.paper_rules and q.likelihood_exponent == 0.5 and q.resample_ess_fraction == 0.5
    assert q.provenance and q.receive_gate and q.anonymous == "associate"
    # the kept gap-fills name fields, the KLD floor among them, and no field is both kept and a rule
    kept = set(MCLWanderParams.GAP_FILLS_KEPT)
    assert "min_particles" in kept and kept <= set(MCLWanderParams.model_fields)
    assert not kept & set(MCLWanderParams.PAPER_RULES)


@pytest.mark.parametrize("key", sorted(_NOT_PAPER))
def test_paper_rules_refuses_a_conflicting_value(key):
    with pytest.raises(ValueError, match=key):
        MCLWanderParams(paper_rules=True, **{key: _NOT_PAPER[key]})
    # the paper's value given as well is fine
    assert getattr(MCLWanderParams(paper_rules=True, **{key: MCLWanderParams.PAPER_RULES[key]}), key) \
        == MCLWanderParams.PAPER_RULES[key]


def test_gap_fill_table_takes_the_scenario_values():
    ours = load_scenario("collab-mcl-hallway").robots[0].params
    g = {x.field: x for x in gap_fills(MCLWanderParams, ours)}
    assert g["inject_fraction"].teamnav_value == 0.1 and g["inject_fraction"].paper_value == 0.0
    # untempered in both columns since the sonar fill (rule 8 of docs/report/collab-mcl.md)
    assert g["likelihood_exponent"].teamnav_value == 1.0 == g["likelihood_exponent"].paper_value
    assert g["receive_gate"].teamnav_value is True and g["receive_gate"].paper_value is False


def test_paper_rules_brain_has_no_receive_gate():
    """With paper_rules the seen robot applies a second tree from the same observer at once (only
    the observer's 2.5 m rule gates); teamnav's default drops it until it has moved 2.5 m."""
    from teamnav.localization.sync import detection_tree

    for paper, expect in ((True, 2), (False, 1)):
        robin = _brain(1, seed=3, pose=(20.0, 9.6, 0.0),
                       **({"paper_rules": True, "adapt_ref_loglik_per_beam": -1.0} if paper else {}))
        assert robin.sync.params.receive_gate is (not paper)
        model = robin.model
        for k in range(2):
            tree = detection_tree(np.array([[17.0, 9.6, 0.0]]), np.array([1.0]), 3.0, 0.0, model,
                                  np.random.default_rng(k))
            body = SyncMessage("detection", 0, 1, 3.0, 0.0, model.p_false_positive, tree)
            robin.step(_obs(1, k + 1, inbox=[Message(0, 0.1 * k, body, to=1, kind=SYNC_KIND)]))
        assert robin.sync.applied["detection"] == expect, paper


def test_every_received_detection_tree_is_logged_with_the_belief_it_met():
    """Robin's sample count, spread and heaviest cluster at every detection tree, in
    the next log() record (once), whether the tree was applied or gated."""
    from teamnav.localization.sync import detection_tree

    robin = _brain(1, seed=5, pose=(20.0, 9.6, 0.0))
    model = robin.model
    for k in range(2):  # the second tree, 0 m later, is gated by the receive side's 2.5 m rule
        tree = detection_tree(np.array([[17.0, 9.6, 0.0]]), np.array([1.0]), 3.0, 0.0, model,
                              np.random.default_rng(k))
        body = SyncMessage("detection", 0, 1, 3.0, 0.0, model.p_false_positive, tree)
        robin.step(_obs(1, k + 1, inbox=[Message(0, 0.1 * k, body, to=1, kind=SYNC_KIND)]))
    first = robin.log()["det_belief"]
    assert [r["applied"] for r in first] == [True, False] and [r["from"] for r in first] == [0, 0]
    assert first[0]["n_particles"] == robin.mcl.n_particles or first[0]["n_particles"] >= 100
    assert 0.0 < first[0]["spread_m"] < 2.0 and 0.0 < first[0]["cluster_weight"] <= 1.0
    assert "det_belief" not in robin.log()  # logged once
