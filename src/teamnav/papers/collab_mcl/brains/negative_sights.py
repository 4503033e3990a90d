"""Negative sights for ``mcl-wander-v1``: the radio traffic and the rules around the likelihood.

Fox, Burgard, Kruppa & Thrun (2000) ignore negative sights (§2.3 rule 1; §7.2 lists them as
future work); ``negative_detections: false`` is that rule and the brain's default. With
``negative_detections: true`` ("the papers' own future work") the brain does, per robot:

1. *Broadcast*: on the step before each camera frame (so that the points are one step old when
   the frame is taken), a robot whose belief is concentrated (position spread ``sqrt(var x +
   var y)`` <= ``neg_max_spread_m``; not the heaviest cluster's weight, which is 1 for a uniform
   belief over a connected free space) broadcasts ``neg_points`` samples of its belief drawn by weight
   (low-variance, float32 x/y: 8 bytes a point): :class:`BeliefPoints`, kind ``mcl_belief``.
   A robot that is not concentrated sends nothing: its belief would make almost every own sample
   of an observer see "maybe" (gap-fill: §7.2 states the idea only).
2. *Use*: on each camera frame, for every teammate n whose points arrived within
   ``neg_max_age_s`` and that the frame does not name, the observer multiplies its weights by
   :func:`~teamnav.localization.negative_detection.negative_factors` (eq. 14's form;
   :func:`~teamnav.localization.negative_detection.visible_mass` is the numba kernel over own
   samples x teammate points, the detector's range, field of view and line of sight on the
   known map). A frame with a detection without identity uses no negative sight (the unnamed
   robot may be n). A frame from which no own sample could see any of n's points changes nothing.
3. *Only while unsure* (``neg_when_concentrated`` false, the default): an observer whose own belief
   is concentrated (the same spread test) uses none. Its samples then all see a teammate's claimed
   place alike, so a miss reweights only its few uniform recovery samples (up by ``1 / (1 - (1 -
   p_fn)(1 - eps))`` each time); a confidently *wrong* teammate, which the factorial representation
   cannot tell from a right one, then pulls a right robot off its place within a few misses.
4. *Rate*: §2.3 rule 2 applied to negative sights: after one use of n, the next waits until the
   observer has travelled ``neg_min_travel_m`` (its own :class:`~teamnav.localization.sync.SightingGate`).
   Consecutive frames that miss the same teammate are the same evidence (the factorial
   representation cannot tell), as consecutive sights are for the paper's 2.5 m rule.

The detector's false-negative rate is the brain's detection model's (§4.2, Table 2); its range
and field of view are ``neg_max_range_m`` and ``neg_fov_deg`` (a datasheet the scenario gives the
brain; the defaults are the collaborative scenarios' detector: 5 m, 180 deg), the cells that stop
sight ``neg_sees`` (the detector's default for vision).

Belief only: the brain's own samples, the points teammates sent, its known map.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from teamnav.control.types import Message
from teamnav.localization.negative_detection import negative_factors, visible_mass
from teamnav.localization.resample import low_variance_kernel
from teamnav.localization.sync import SightingGate

if TYPE_CHECKING:
    from teamnav.localization import MCL

__all__ = ["BELIEF_KIND", "BeliefPoints", "NegativeSights"]

#: ``Message.kind`` of the broadcast belief points
BELIEF_KIND = "mcl_belief"


@dataclass(frozen=True)
class BeliefPoints:
    """A robot's belief as ``xy`` (K, 2) float32 points drawn by weight (equal weights)."""

    xy: np.ndarray


class NegativeSights:
    """The broadcast, the store of teammates' points and the rate rule (module docstring).

    Parameters
    ----------
    params : MCLWanderParams
        Reads ``neg_*`` and ``detection_period_s``.
    robot_id : int
    known_map : OccupancyGrid
    p_false_negative : float
        The detection model's rate (§4.2).
    dt_s : float
        Simulation step [s] (the broadcast goes out one step before a frame).
    """

    def __init__(self, params, robot_id: int, known_map, p_false_negative: float, dt_s: float) -> None:
        self.p = params
        self.robot_id = int(robot_id)
        self.grid = known_map
        self.blocking = known_map.blocking(params.neg_sees)
        self.p_fn = float(p_false_negative)
        self.dt_s = float(dt_s)
        self.gate = SightingGate(params.neg_min_travel_m)
        self.points: dict[int, tuple[float, np.ndarray]] = {}  # sender -> (time received, (K, 2))
        self.stats: dict[str, Any] = {"neg_sent": 0, "neg_used": 0, "neg_skipped_anon": 0}

    def travel(self, odom_delta) -> None:
        self.gate.travel(odom_delta)

    def on_message(self, msg: Message, t_s: float) -> bool:
        """Keep a teammate's points; True when ``msg`` was one (handled here)."""
        if msg.kind != BELIEF_KIND:
            return False
        if isinstance(msg.body, BeliefPoints) and msg.sender != self.robot_id:
            self.points[int(msg.sender)] = (float(t_s), np.asarray(msg.body.xy, dtype=np.float64))
        return True

    def broadcast(self, mcl: "MCL", rng: np.random.Generator, t_s: float, next_frame_s: float) -> list[Message]:
        """This robot's points, on the step before a camera frame, when its belief is concentrated."""
        if t_s + self.dt_s + 1e-9 < next_frame_s:
            return []
        if not self.concentrated(mcl):
            return []
        w = mcl.weights
        k = int(self.p.neg_points)
        idx = low_variance_kernel(w, k, float(rng.random()), np.empty(k, dtype=np.int64))
        xy = np.ascontiguousarray(mcl.particles[idx, :2], dtype=np.float32)
        self.stats["neg_sent"] += 1
        return [Message(self.robot_id, float(t_s), BeliefPoints(xy), to=None, kind=BELIEF_KIND)]

    def concentrated(self, mcl: "MCL") -> bool:
        """The belief's position spread ``sqrt(var x + var y)`` is at most ``neg_max_spread_m``."""
        cov = mcl.estimate().cov
        return bool(cov[0, 0] + cov[1, 1] <= self.p.neg_max_spread_m ** 2)

    def on_frame(self, mcl: "MCL", detections, t_s: float) -> int:
        """Apply the negative sights of one camera frame; returns how many were applied."""
        if not self.p.neg_when_concentrated and self.concentrated(mcl):
            return 0
        if any(d.robot_id is None for d in detections):
            self.stats["neg_skipped_anon"] += 1
            return 0
        named = {int(d.robot_id) for d in detections}
        used = 0
        for sender, (t_rx, xy) in sorted(self.points.items()):
            if sender in named or t_s - t_rx > self.p.neg_max_age_s or not self.gate.allowed(sender):
                continue
            pv = visible_mass(mcl.particles, xy, np.ones(xy.shape[0]), self.grid, self.blocking,
                              self.p.neg_max_range_m, self.p.neg_fov_deg, True)
            if not pv.max() > 0.0:
                continue  # no own sample could see n: nothing to learn, the gate is not spent
            if mcl.multiply_weights(negative_factors(pv, self.p_fn, self.p.neg_teammate_lost_prior)):
                self.gate.use(sender)
                used += 1
        self.stats["neg_used"] += used
        return used
