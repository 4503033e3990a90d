"""Belief synchronisation on robot detections (Fox et al. §2.3, §3.2, eqs. 10, 13, 14).

When robot m detects robot n, n's belief is multiplied by m's belief about n (eq. 10)::

    Bel_n(l) <- Bel_n(l) int P(L_n = l | L_m = l', r_m) Bel_m(l') dl'

In the sample-based filter (§3.2) robot m draws, for each of its samples ``l'``, one
position of n through the detection model (:meth:`DetectionModel.sample_positions`), turns
these weighted samples into a density tree (:class:`~teamnav.localization.density_tree.DensityTree`,
2-D over (x, y): a detection says nothing about n's heading, see that module) and sends the
tree; n multiplies the tree's density at each of its samples into their weights (eq. 14,
:meth:`MCL.multiply_weights`). A detection is a false positive with probability
``p_false_positive`` (§4.2, Table 2); that case is mixed in as a uniform density over the free
space, ``f(l) = (1 - p_fp) tree(x, y) + p_fp / area``, so a phantom cannot wipe out a belief.

"By symmetry, the same detection can be used to constrain the m-th robot's position based
on the belief of the n-th robot" (§2.3): on receiving m's tree, n replies (before applying
it) with a tree of its own position belief; m evaluates it at its samples moved by a draw of
the detection, ``f(l') = (1 - p_fp) tree_n(l' + (rho, beta)) + p_fp / area``, a one-draw
Monte Carlo estimate of ``int P(r_m | l', l) Bel_n(l) dl``.

The two rules of §2.3 against the factorial representation's over-confidence:

1. negative sights are ignored: only reported detections (with an identity, §7.2: the
   factorial form cannot use "robot A or robot B") start a synchronisation;
2. once a robot has used a detection of another robot, it may not use that robot again until
   it has travelled ``min_travel_m`` (2.5 m in the paper), measured with its own odometry
   (:class:`SightingGate`): when it detects that robot and, with ``receive_gate`` (beyond the
   paper, below), also when it applies a tree coming from it. Two robots that detect each other
   then update each once, not twice.

Rule 2 as the paper states it gates the *detecting* robot ("blocks the ability to see the same
robot again until the detecting robot has traveled a prespecified distance"). Beyond the paper,
``SyncParams.receive_gate`` (default True) gates the *receiving* side too: a robot applies a tree
from a given teammate at most once per ``min_travel_m`` of its own travel, so two robots that see
each other on the same frame update each once; False is the paper's rule only.

Beyond the paper, ``SyncParams.provenance`` makes rule 2 transitive: trees carry the robots
whose information they hold, and a robot drops its own information coming back through a third
robot before it has travelled ``min_travel_m`` (:class:`SyncParams`).

Messages carry their tree as flat arrays (:class:`SyncMessage`), so
:meth:`Message.size_bytes` counts what the radio really carries. Trees describe the robots at
the time of the detection; the radio's delay (a step or more) is not compensated, as in the
paper (detections at 1 Hz, robots at 0.3 m/s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from teamnav.control.types import Detection, Message
from teamnav.localization._checks import array, generator, positive
from teamnav.localization.density_tree import DensityTree
from teamnav.localization.detection_model import DetectionModel
from teamnav.localization.mcl import MCL

__all__ = [
    "BeliefSync", "SightingGate", "SyncMessage", "SyncParams", "detection_factors", "detection_tree",
    "inverse_detection_factors", "position_tree",
]

#: ``Message.kind`` of synchronisation messages.
SYNC_KIND = "mcl_sync"


class SyncParams(BaseModel):
    """Parameters of belief synchronisation.

    ``min_travel_m``: rule 2 of §2.3 [m]; ``tree_min_samples`` / ``tree_max_depth``: stopping
    rule of the density trees; ``symmetric``: answer a received tree with one's own position
    tree so that the detecting robot is constrained too (§2.3).

    ``receive_gate`` (beyond the paper, default True; False: §2.3's rule 2 as written, which
    gates only the detecting robot): a robot applies trees (detection or answer) from a given
    teammate at most once per ``min_travel_m`` of its own travel.

    ``provenance`` (beyond the paper; False: the paper's two rules only): rule 2 made
    transitive. Rule 2 stops robot n from using robot m twice within ``min_travel_m``, but
    not from getting m's information back through a third robot (m -> n -> k -> m): in a
    team that detects each other often, such loops multiply one robot's belief into itself
    again and again, the double counting §2.3 warns about (measured in the hexagon, same
    seed and settings: 0 of 8 robots localized at the end without provenance, 8 of 8 with it).
    Every tree carries its sources, the
    robots whose information the sender's belief holds, each with that robot's odometer when
    the information left it; a robot drops a tree that holds its own information from less
    than ``min_travel_m`` of its own travel ago (:meth:`BeliefSync.on_message`).
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    min_travel_m: float = Field(2.5, ge=0.0, le=1000.0)
    tree_min_samples: int = Field(20, ge=1, le=100_000)
    tree_max_depth: int = Field(20, ge=1, le=64)
    symmetric: bool = True
    receive_gate: bool = True
    provenance: bool = False


@dataclass(frozen=True)
class SyncMessage:
    """Body of a synchronisation message (plain data, sized by ``Message.size_bytes``).

    Attributes
    ----------
    kind : str
        ``"detection"``: ``tree`` is the sender's belief about the addressee's position (eq.
        13); ``"inverse"``: ``tree`` is the sender's own position belief, the answer to a
        ``"detection"`` message.
    observer : int
        Robot that made the detection.
    target : int
        Robot that was detected.
    range_m, bearing_rad : float
        The detection, in the observer's body frame.
    p_false_positive : float
        The observer's detection model's false-positive rate.
    tree : DensityTree
        2-D density over (x, y) [1/m²].
    sources : tuple of (int, float)
        ``(robot id, that robot's odometer [m])`` for every robot whose information the
        sender's belief holds, the sender included (``SyncParams.provenance``; empty without).
    detected_s : float or None
        None: the tree describes the robots at the message's stamp (the detection was just made,
        §3.2). Else the time the detection was made: a detection integrated later (§7.2 "delayed
        integration", :mod:`teamnav.papers.collab_mcl.brains.delayed_integration`); the tree describes the robots
        at that time and the receiver applies it to its samples moved back to it. A reply
        (``"inverse"``) carries the time of the detection it answers.
    """

    kind: str
    observer: int
    target: int
    range_m: float
    bearing_rad: float
    p_false_positive: float
    tree: DensityTree
    sources: tuple = ()
    detected_s: float | None = None


class SightingGate:
    """Rule 2 of Fox et al. §2.3: one use of another robot per ``min_travel_m`` of own travel.

    Examples
    --------
    >>> g = SightingGate(2.5)
    >>> g.allowed(3)
    True
    >>> g.use(3); g.allowed(3)
    False
    >>> g.travel([1.5, 0.0, 0.0]); g.travel([0.0, 1.0, 0.0]); g.allowed(3)
    True
    """

    def __init__(self, min_travel_m: float = 2.5) -> None:
        self.min_travel_m = float(min_travel_m) if min_travel_m == 0 else positive("min_travel_m", min_travel_m)
        self.odometer_m = 0.0
        self._last: dict[int, float] = {}

    def travel(self, odom_delta) -> None:
        """Add one odometry step's distance ``hypot(dx, dy)`` [m]."""
        d = array("odom_delta", odom_delta, (3,))
        self.odometer_m += math.hypot(d[0], d[1])

    def allowed(self, robot_id: int) -> bool:
        last = self._last.get(int(robot_id))
        return last is None or self.odometer_m - last >= self.min_travel_m

    def use(self, robot_id: int) -> None:
        self._last[int(robot_id)] = self.odometer_m


def detection_tree(particles, weights, range_m: float, bearing_rad: float, model: DetectionModel,
                   rng: np.random.Generator, params: SyncParams = SyncParams()) -> DensityTree:
    """Tree of the detected robot's position from the observer's belief (eq. 13, §3.2).

    One position per observer sample, drawn through the detection model and carrying that
    sample's weight.
    """
    p = array("particles", particles, (-1, 3))
    w = array("weights", weights, (p.shape[0],))
    pos = model.sample_positions(p, range_m, bearing_rad, rng)
    return DensityTree.fit(pos, w, min_samples=params.tree_min_samples, max_depth=params.tree_max_depth)


def position_tree(particles, weights, params: SyncParams = SyncParams()) -> DensityTree:
    """Tree of a robot's own position belief (heading marginalised), for the inverse update."""
    p = array("particles", particles, (-1, 3))
    w = array("weights", weights, (p.shape[0],))
    return DensityTree.fit(p[:, :2], w, min_samples=params.tree_min_samples, max_depth=params.tree_max_depth)


def _mix(density: np.ndarray, p_false_positive: float, free_area_m2: float) -> np.ndarray:
    return (1.0 - p_false_positive) * density + p_false_positive / free_area_m2


def detection_factors(tree: DensityTree, particles, p_false_positive: float, free_area_m2: float) -> np.ndarray:
    """Eq. (14) factors for the detected robot's samples: ``(1 - p_fp) tree(x, y) + p_fp / area``."""
    p = array("particles", particles, (-1, 3))
    if not 0.0 <= p_false_positive < 1.0:
        raise ValueError(f"p_false_positive must be in [0, 1), got {p_false_positive!r}")
    return _mix(tree(p[:, :2]), p_false_positive, positive("free_area_m2", free_area_m2))


def inverse_detection_factors(tree: DensityTree, particles, range_m: float, bearing_rad: float,
                              model: DetectionModel, rng: np.random.Generator, free_area_m2: float) -> np.ndarray:
    """Factors for the observer's samples from the detected robot's position tree (§2.3 symmetry)."""
    p = array("particles", particles, (-1, 3))
    pos = model.sample_positions(p, range_m, bearing_rad, generator("rng", rng))
    return _mix(tree(pos), model.p_false_positive, positive("free_area_m2", free_area_m2))


class BeliefSync:
    """One robot's side of belief synchronisation: what a localizing brain calls each step.

    Parameters
    ----------
    robot_id : int
        This robot's id.
    model : DetectionModel
        This robot's detector model (learned, :func:`fit_detection_model`).
    params : SyncParams
    rng : numpy.random.Generator

    Notes
    -----
    Per step a brain calls :meth:`travel` with its odometry step, :meth:`on_detections` with
    its observation's detections (it returns the messages to send), and :meth:`on_message` for
    every message in its inbox (it applies the evidence to the filter and may return a reply).
    """

    def __init__(self, robot_id: int, model: DetectionModel, params: SyncParams, rng: np.random.Generator) -> None:
        if not isinstance(model, DetectionModel):
            raise ValueError(f"model must be a DetectionModel, got {type(model).__name__}")
        if not isinstance(params, SyncParams):
            raise ValueError(f"params must be a SyncParams, got {type(params).__name__}")
        self.robot_id = int(robot_id)
        self.model = model
        self.params = params
        self.rng = generator("rng", rng)
        self.detect_gate = SightingGate(params.min_travel_m)
        self.receive_gate = SightingGate(params.min_travel_m)
        #: Count of applied updates, by kind ("detection", "inverse"), for logs.
        self.applied = {"detection": 0, "inverse": 0}
        #: Trees dropped because they held this robot's own recent information (provenance).
        self.looped = 0
        #: Robots whose information this belief holds -> their odometer when it left them [m].
        self.sources: dict[int, float] = {}

    def outgoing_sources(self) -> tuple:
        """Sources a tree built from this robot's belief carries now (empty without provenance)."""
        if not self.params.provenance:
            return ()
        out = dict(self.sources)
        out[self.robot_id] = self.detect_gate.odometer_m
        return tuple(sorted((int(k), float(v)) for k, v in out.items()))

    def _looped(self, body: SyncMessage) -> bool:
        """The tree holds this robot's own information from less than ``min_travel_m`` ago."""
        if not self.params.provenance:
            return False
        for rid, odo in body.sources:
            if int(rid) == self.robot_id and self.detect_gate.odometer_m - float(odo) < self.params.min_travel_m:
                return True
        return False

    def _merge(self, body: SyncMessage) -> None:
        for rid, odo in body.sources:
            if int(rid) != self.robot_id:
                self.sources[int(rid)] = max(self.sources.get(int(rid), -math.inf), float(odo))

    def receive_allowed(self, other: int) -> bool:
        """Whether a tree from robot ``other`` may be applied now (always, without ``receive_gate``)."""
        return not self.params.receive_gate or self.receive_gate.allowed(other)

    def travel(self, odom_delta) -> None:
        """Advance both gates' odometers by this step's travel."""
        self.detect_gate.travel(odom_delta)
        self.receive_gate.travel(odom_delta)

    def on_detections(self, mcl: MCL, detections, stamp_s: float, detected_s: float | None = None) -> list[Message]:
        """Messages (one per usable detection) carrying this robot's belief about the robot seen.

        ``detected_s``: the time the detections were made when they are integrated later (§7.2;
        ``mcl`` then holds the samples moved back to that time); None: now (§3.2)."""
        out = []
        for det in detections:
            if not isinstance(det, Detection):
                raise ValueError(f"detections must hold Detection objects, got {type(det).__name__}")
            rid = det.robot_id
            if rid is None or rid == self.robot_id or not self.detect_gate.allowed(rid):
                continue
            tree = detection_tree(mcl.particles, mcl.weights, det.range_m, det.bearing_rad, self.model, self.rng,
                                  self.params)
            body = SyncMessage("detection", self.robot_id, int(rid), float(det.range_m), float(det.bearing_rad),
                               float(self.model.p_false_positive), tree, self.outgoing_sources(),
                               None if detected_s is None else float(detected_s))
            out.append(Message(self.robot_id, float(stamp_s), body, to=int(rid), kind=SYNC_KIND))
            self.detect_gate.use(rid)
        return out

    def on_message(self, mcl: MCL, msg: Message, stamp_s: float, evidence=None) -> list[Message]:
        """Apply a synchronisation message addressed to this robot; return a reply, if any.

        Messages of other kinds, or not for this robot, are ignored (``[]``).

        ``evidence``: for a ``"detection"`` message, a callable ``evidence(mcl, body) -> factors``
        that replaces eq. 14's ``detection_factors`` (it may change the sample set first, e.g.
        sensor resetting). It is called *after* the reply tree was built, so the reply carries
        only this robot's own belief: a reply built from a belief that already holds the
        sender's tree would hand the sender its own information back (double counting; the
        first version of the brain's sensor resetting did so, see ``tests/test_localizing_brain.py``).
        """
        body = msg.body
        if msg.kind != SYNC_KIND or not isinstance(body, SyncMessage):
            return []
        replies: list[Message] = []
        if body.kind == "detection" and body.target == self.robot_id:
            other = body.observer
            if not self.receive_allowed(other):
                return []
            if self.params.symmetric:
                tree = position_tree(mcl.particles, mcl.weights, self.params)
                reply = SyncMessage("inverse", other, self.robot_id, body.range_m, body.bearing_rad,
                                    body.p_false_positive, tree, self.outgoing_sources(), body.detected_s)
                replies.append(Message(self.robot_id, float(stamp_s), reply, to=other, kind=SYNC_KIND))
            if self._looped(body):
                self.looped += 1
                return replies
            if evidence is None:
                f = detection_factors(body.tree, mcl.particles, body.p_false_positive, mcl.free_area_m2)
            else:
                f = evidence(mcl, body)
            if mcl.multiply_weights(f):
                self.applied["detection"] += 1
                self._merge(body)
            self.receive_gate.use(other)
        elif body.kind == "inverse" and body.observer == self.robot_id:
            other = body.target
            if not self.receive_allowed(other):
                return []
            if self._looped(body):
                self.looped += 1
                return []
            f = inverse_detection_factors(body.tree, mcl.particles, body.range_m, body.bearing_rad, self.model,
                                          self.rng, mcl.free_area_m2)
            if mcl.multiply_weights(f):
                self.applied["inverse"] += 1
                self._merge(body)
            self.receive_gate.use(other)
        return replies
