"""Detections without identity, associated by belief (Fox et al. §7.2 "Identification of robots").

Fox, Burgard, Kruppa & Thrun, "A probabilistic approach to collaborative multi-robot
localization", Autonomous Robots 8(3), 2000, §7.2: the factorial representation "cannot deal
with measurements such as 'either robot A or robot B'", so the paper's method uses only
detections that name the robot seen (§2.3, §3.2). Beyond the paper, ``mcl-wander-v1``
(:class:`~teamnav.papers.collab_mcl.brains.localizing.MCLWander`, which inherits :class:`AnonymousAssociation`)
with ``anonymous="associate"`` (:class:`~teamnav.papers.collab_mcl.brains.mcl_wander_params.MCLWanderParams`)
associates a detection whose ``robot_id`` is None (a detector with ``report_identity: false``)
*by belief*:

1. the observer broadcasts the detection tree as a query (:class:`_AssocQuery`, message kind
   :data:`ASSOC_KIND`), at most once per ``min_travel_m`` of own travel for all anonymous
   detections together (§2.3 rule 2 with the robot id -1);
2. every robot that hears it answers with the tree's density under its own belief,
   ``E_n = sum_i w_i tree(x_i)`` (:class:`_AssocAnswer`, one float);
3. two steps later (query out, answers back) the observer picks the robot with the largest
   ``E_n``, provided it beats the uniform density ``1 / A`` (``A`` the free area) by
   ``assoc_min_ratio`` and the runner-up by ``assoc_margin``, and sends it the ordinary §3.2
   detection message (the tree it kept). Ambiguous detections (every robot still globally
   uncertain, or two robots equally plausible) are dropped.

With ``anonymous="ignore"`` (``paper_rules``) the brain does what the paper's method does with
anonymous sights: nothing.

The false-positive filter's gate 2 (confirmation on consecutive camera frames, see
:mod:`teamnav.papers.collab_mcl.brains.localizing`) keys an anonymous detection by the previous frame's nearest
anonymous one (:meth:`AnonymousAssociation._anon_key`); its gate 3 uses the same evidence ``E``
(:meth:`AnonymousAssociation._evidence`) as the answers of step 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from teamnav.control.types import Message, Observation
from teamnav.localization import SyncMessage
from teamnav.localization.density_tree import DensityTree
from teamnav.localization.sync import SYNC_KIND, detection_tree

if TYPE_CHECKING:
    from teamnav.papers.collab_mcl.brains.mcl_wander_params import MCLWanderParams
    from teamnav.localization import MCL, BeliefSync, DetectionModel

__all__ = ["ASSOC_KIND", "AnonymousAssociation", "to_odom"]

#: ``Message.kind`` of identity-association traffic.
ASSOC_KIND = "mcl_assoc"


def to_odom(odom_pose: np.ndarray, range_m: float, bearing_rad: float) -> np.ndarray:
    """A detection's point in the observer's odometry frame."""
    a = float(odom_pose[2]) + bearing_rad
    return np.array([odom_pose[0] + range_m * math.cos(a), odom_pose[1] + range_m * math.sin(a)])


@dataclass(frozen=True)
class _AssocQuery:
    """Broadcast: "whose belief fits this tree of the robot I saw?" (identity withheld)."""

    qid: int
    observer: int
    tree: DensityTree


@dataclass(frozen=True)
class _AssocAnswer:
    """Answer to :class:`_AssocQuery`: the tree's density under the answering robot's belief."""

    qid: int
    observer: int
    evidence: float


class AnonymousAssociation:
    """Mixin of :class:`~teamnav.papers.collab_mcl.brains.localizing.MCLWander`: the steps of the module docstring.

    It reads the brain's ``params``, ``rng``, ``robot_id``, ``mcl``, ``model``, ``sync``,
    ``stats``, ``_odom`` (this step's odometry pose) and ``_last_seen`` (gate 2's previous
    sights); :meth:`_init_association` sets up its own state.
    """

    params: MCLWanderParams
    rng: np.random.Generator
    robot_id: int
    mcl: MCL
    model: DetectionModel | None
    sync: BeliefSync | None
    stats: dict[str, int]
    _odom: np.ndarray
    _last_seen: dict[Any, tuple[float, np.ndarray]]

    def _init_association(self) -> None:
        self._pending: dict[int, dict] = {}  # association queries: query id -> {"tree", "det", "scores", "step"}
        self._query_seq = 0

    def _anon_key(self, det) -> int:
        """Anonymous detections are matched to the previous frame's nearest one (gate 2)."""
        pt = to_odom(self._odom, det.range_m, det.bearing_rad)
        best, best_d = None, math.inf
        for key, (_, q) in self._last_seen.items():
            if isinstance(key, tuple) and key[0] == "anon":
                d = float(np.hypot(*(pt - q)))
                if d < best_d:
                    best, best_d = key[1], d
        if best is not None and best_d <= self.params.fp_confirm_gate_m:
            return best
        self._query_seq += 1
        return -self._query_seq

    def _query(self, det, obs: Observation) -> list[Message]:
        """Broadcast the detection tree; teammates answer with its density under their beliefs."""
        if not self.sync.detect_gate.allowed(-1):  # one anonymous use per min_travel_m
            return []
        tree = detection_tree(self.mcl.particles, self.mcl.weights, det.range_m, det.bearing_rad, self.model,
                              self.rng, self.sync.params)
        self._query_seq += 1
        qid = self._query_seq
        self._pending[qid] = {"tree": tree, "det": det, "scores": {}, "step": obs.step}
        return [Message(self.robot_id, float(obs.time_s), _AssocQuery(qid, self.robot_id, tree), to=None,
                        kind=ASSOC_KIND)]

    def _close_queries(self, obs: Observation) -> list[Message]:
        """Pick the robot an anonymous detection was of, once the answers are in.

        The query reaches the others one step after it is sent and their answers come back one
        step later still, so a query is closed two steps after it was sent.
        """
        out: list[Message] = []
        p = self.params
        for qid in [q for q, v in self._pending.items() if obs.step >= v["step"] + 2]:
            pend = self._pending.pop(qid)
            scores = sorted(pend["scores"].items(), key=lambda kv: -kv[1])
            uniform = 1.0 / self.mcl.free_area_m2
            if not scores or scores[0][1] < p.assoc_min_ratio * uniform or (
                    len(scores) > 1 and not scores[0][1] > p.assoc_margin * scores[1][1]):
                self.stats["assoc_dropped"] += 1
                continue
            rid = int(scores[0][0])
            if not self.sync.detect_gate.allowed(rid):
                continue
            det = pend["det"]
            body = SyncMessage("detection", self.robot_id, rid, float(det.range_m), float(det.bearing_rad),
                               float(self.model.p_false_positive), pend["tree"], self.sync.outgoing_sources())
            out.append(Message(self.robot_id, float(obs.time_s), body, to=rid, kind=SYNC_KIND))
            self.sync.detect_gate.use(rid)
            self.sync.detect_gate.use(-1)
            self.stats["assoc"] += 1
            self.stats["sent"] += 1
        return out

    def _evidence(self, tree) -> float:
        """``E = sum_i w_i tree(x_i)``: the tree's density under this robot's belief [1/m²]."""
        return float(np.dot(self.mcl.weights, tree(self.mcl.particles[:, :2])))

    def _on_assoc_message(self, msg: Message, obs: Observation) -> list[Message]:
        """A message of kind :data:`ASSOC_KIND`: answer a teammate's query, or keep an answer to ours."""
        body = msg.body
        if isinstance(body, _AssocQuery) and body.observer != self.robot_id:
            return [Message(self.robot_id, float(obs.time_s), _AssocAnswer(body.qid, body.observer,
                                                                            self._evidence(body.tree)),
                            to=body.observer, kind=ASSOC_KIND)]
        if isinstance(body, _AssocAnswer) and body.observer == self.robot_id and body.qid in self._pending:
            self._pending[body.qid]["scores"][msg.sender] = body.evidence
        return []
