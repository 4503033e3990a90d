"""Belief synchronisation (Fox et al. §2.3, §3.2): a detection resolves a teammate's ambiguity
(eqs. 13–14), the inverse update constrains the observer, and the two §2.3 rules hold."""

from __future__ import annotations

import math

import numpy as np
import pytest

from teamnav.control.protocol import SensorInfo
from teamnav.control.types import Detection, Message
from teamnav.localization import (
    MCL, BeliefSync, DetectionModel, MCLParams, SightingGate, SyncMessage, SyncParams,
)
from teamnav.world import MapBuilder

MODEL = DetectionModel(range_std_m=0.1, bearing_std_rad=math.radians(2.0), p_false_positive=0.01)


def hall():
    return MapBuilder(20.0, 6.0, 0.1).border(0.2).build("hall")


def filter_with_modes(modes, n=2000, seed=0):
    """An MCL whose samples sit in equal clusters around ``modes`` (each a pose)."""
    s = SensorInfo("laser", "laser", np.linspace(-np.pi / 2, np.pi / 2, 9), 8.0)
    f = MCL(MCLParams(n_particles=n), hall(), s, np.random.default_rng(seed))
    f.init_pose([0.0, 0.0, 0.0], np.diag([0.02, 0.02, 0.01]))
    p = f.particles.copy()
    k = len(modes)
    for i, m in enumerate(modes):
        p[i::k] += m
    f._set(p)
    return f


def mode_weight(f, pose, radius=0.6):
    near = np.hypot(f.particles[:, 0] - pose[0], f.particles[:, 1] - pose[1]) < radius
    return float(f.weights[near].sum())


def test_detection_resolves_the_detected_robots_ambiguity():
    m_pose = np.array([5.0, 3.0, 0.0])
    n_truth, n_mirror = np.array([8.0, 3.0, math.pi]), np.array([12.0, 3.0, 0.0])
    m = filter_with_modes([m_pose], seed=1)
    n = filter_with_modes([n_truth, n_mirror], seed=2)
    assert abs(mode_weight(n, n_truth) - 0.5) < 0.05
    sm = BeliefSync(0, MODEL, SyncParams(), np.random.default_rng(3))
    sn = BeliefSync(1, MODEL, SyncParams(), np.random.default_rng(4))
    msgs = sm.on_detections(m, (Detection(3.0, 0.0, 1),), 0.0)
    assert len(msgs) == 1 and msgs[0].to == 1 and isinstance(msgs[0].body, SyncMessage)
    assert msgs[0].size_bytes() == 24 + len("detection") + 5 * 8 + msgs[0].body.tree.nbytes
    replies = sn.on_message(n, msgs[0], 0.1)
    assert mode_weight(n, n_truth) > 0.95
    assert sn.applied["detection"] == 1
    # the inverse update: n's (pre-update, bimodal) position tree cannot move m, a localized m stays put
    assert len(replies) == 1 and replies[0].body.kind == "inverse" and replies[0].to == 0
    sm.on_message(m, replies[0], 0.2)
    assert mode_weight(m, m_pose) > 0.99 and sm.applied["inverse"] == 1


def test_inverse_update_resolves_the_observers_ambiguity():
    m_truth, m_mirror = np.array([5.0, 3.0, 0.0]), np.array([15.0, 3.0, math.pi])
    n_pose = np.array([8.0, 3.0, math.pi])
    m = filter_with_modes([m_truth, m_mirror], seed=5)
    n = filter_with_modes([n_pose], seed=6)
    sm = BeliefSync(0, MODEL, SyncParams(), np.random.default_rng(7))
    sn = BeliefSync(1, MODEL, SyncParams(), np.random.default_rng(8))
    (msg,) = sm.on_detections(m, (Detection(3.0, 0.0, 1),), 0.0)
    (reply,) = sn.on_message(n, msg, 0.1)
    # m's mirror hypothesis puts n at (12, 3), where n is not: n's weights barely change
    assert mode_weight(n, n_pose) > 0.99
    sm.on_message(m, reply, 0.2)
    assert mode_weight(m, m_truth) > 0.95


def test_rules_of_section_2_3():
    m = filter_with_modes([np.array([5.0, 3.0, 0.0])])
    sync = BeliefSync(0, MODEL, SyncParams(min_travel_m=2.5), np.random.default_rng(9))
    det = (Detection(2.0, 0.1, 1),)
    # rule 1: negative sights do not exist as data; unidentified detections and self are ignored
    assert sync.on_detections(m, (), 0.0) == []
    assert sync.on_detections(m, (Detection(2.0, 0.0, None), Detection(2.0, 0.0, 0)), 0.0) == []
    # rule 2: one use of robot 1, then blocked until 2.5 m of own odometry
    assert len(sync.on_detections(m, det, 0.0)) == 1
    assert sync.on_detections(m, det, 0.1) == []
    for _ in range(24):
        sync.travel([0.1, 0.0, 0.05])
    assert sync.on_detections(m, det, 2.0) == []  # 2.4 m
    assert len(sync.on_detections(m, (Detection(2.0, 0.1, 2),), 2.0)) == 1  # another robot is not blocked
    sync.travel([0.0, -0.1, 0.0])
    sync.travel([0.05, 0.0, 0.0])
    assert len(sync.on_detections(m, det, 3.0)) == 1  # 2.55 m


def test_mutual_detection_updates_each_robot_once():
    a = filter_with_modes([np.array([5.0, 3.0, 0.0])], seed=10)
    b = filter_with_modes([np.array([8.0, 3.0, math.pi])], seed=11)
    sa = BeliefSync(0, MODEL, SyncParams(), np.random.default_rng(12))
    sb = BeliefSync(1, MODEL, SyncParams(), np.random.default_rng(13))
    (ma,) = sa.on_detections(a, (Detection(3.0, 0.0, 1),), 0.0)
    (mb,) = sb.on_detections(b, (Detection(3.0, 0.0, 0),), 0.0)
    (ra,) = sb.on_message(b, ma, 0.1)
    (rb,) = sa.on_message(a, mb, 0.1)
    assert sa.on_message(a, ra, 0.2) == [] and sb.on_message(b, rb, 0.2) == []
    assert sa.applied == {"detection": 1, "inverse": 0} and sb.applied == {"detection": 1, "inverse": 0}
    # not addressed / not a sync message: ignored
    assert sa.on_message(a, Message(5, 0.0, {"x": 1.0}), 0.3) == []


def test_mutual_detection_without_the_receive_gate_is_the_papers_rule_2():
    """§2.3 rule 2 as written gates the detecting robot only: when two robots see each other on the
    same frame, each applies the other's detection tree and the answer to its own (twice each)."""
    a = filter_with_modes([np.array([5.0, 3.0, 0.0])], seed=10)
    b = filter_with_modes([np.array([8.0, 3.0, math.pi])], seed=11)
    p = SyncParams(receive_gate=False)
    sa = BeliefSync(0, MODEL, p, np.random.default_rng(12))
    sb = BeliefSync(1, MODEL, p, np.random.default_rng(13))
    (ma,) = sa.on_detections(a, (Detection(3.0, 0.0, 1),), 0.0)
    (mb,) = sb.on_detections(b, (Detection(3.0, 0.0, 0),), 0.0)
    (ra,) = sb.on_message(b, ma, 0.1)
    (rb,) = sa.on_message(a, mb, 0.1)
    sa.on_message(a, ra, 0.2)
    sb.on_message(b, rb, 0.2)
    assert sa.applied == {"detection": 1, "inverse": 1} and sb.applied == {"detection": 1, "inverse": 1}
    # the detecting side's gate still holds: no second detection of b within 2.5 m
    assert sa.on_detections(a, (Detection(3.0, 0.0, 1),), 1.0) == []
    assert sa.receive_allowed(1) and SyncParams().receive_gate


def test_gate_and_sync_validate_input():
    with pytest.raises(ValueError, match="min_travel_m"):
        SightingGate(-1.0)
    with pytest.raises(ValueError, match="model must be a DetectionModel"):
        BeliefSync(0, None, SyncParams(), np.random.default_rng(0))
    with pytest.raises(ValueError, match="extra"):
        SyncParams(min_travel=2.0)


@pytest.mark.parametrize("provenance", [False, True])
def test_own_information_coming_back_through_a_third_robot(provenance):
    """Rule 2 made transitive: A's belief reaches C through B (A sees B, B sees C); when C then
    sees A, its tree holds A's own information. The paper's rules let A multiply it in (rule 2
    only blocks A <-> C pairs): A's belief counted twice. With provenance A drops it until it
    has travelled min_travel_m, then takes it."""
    poses = {0: np.array([5.0, 3.0, 0.0]), 1: np.array([8.0, 3.0, 0.0]), 2: np.array([11.0, 3.0, math.pi])}
    f = {i: filter_with_modes([p], seed=20 + i) for i, p in poses.items()}
    s = {i: BeliefSync(i, MODEL, SyncParams(provenance=provenance, symmetric=False), np.random.default_rng(30 + i))
         for i in poses}
    (ab,) = s[0].on_detections(f[0], (Detection(3.0, 0.0, 1),), 0.0)  # A sees B 3 m ahead
    s[1].on_message(f[1], ab, 0.1)
    (bc,) = s[1].on_detections(f[1], (Detection(3.0, 0.0, 2),), 1.0)  # B sees C
    s[2].on_message(f[2], bc, 1.1)
    (ca,) = s[2].on_detections(f[2], (Detection(6.0, 0.0, 0),), 2.0)  # C sees A 6 m ahead
    assert s[1].applied["detection"] == 1 and s[2].applied["detection"] == 1
    if not provenance:
        assert ab.body.sources == () and ca.body.sources == ()
        s[0].on_message(f[0], ca, 2.1)
        assert s[0].applied["detection"] == 1
        return
    assert dict(ab.body.sources) == {0: 0.0}
    assert set(dict(ca.body.sources)) == {0, 1, 2}  # A's information, passed on by B, then C
    assert ca.size_bytes() > ab.size_bytes() - ab.body.tree.nbytes + ca.body.tree.nbytes  # sources are counted
    s[0].on_message(f[0], ca, 2.1)
    assert s[0].applied["detection"] == 0 and s[0].looped == 1
    for _ in range(26):  # 2.6 m later A's information in C's belief is old news: C's next tree is used
        s[0].travel([0.1, 0.0, 0.0])
        s[2].travel([0.1, 0.0, 0.0])
    (ca2,) = s[2].on_detections(f[2], (Detection(6.0, 0.0, 0),), 9.0)
    s[0].on_message(f[0], ca2, 9.1)
    assert s[0].applied["detection"] == 1 and s[0].looped == 1
