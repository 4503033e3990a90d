"""§7.2 "Delayed integration": detections made while unsure, applied once the belief is concentrated.

Fox, Burgard, Kruppa & Thrun (2000), §7.2 (Limitations and Discussion):

    "the robots update their position instantly whenever they perceive another robot. In
    situations in which both robots are highly uncertain at the time of the detection it might
    be more appropriate to delay the update. For example, if one of the robots afterwards becomes
    more certain [...], then the synchronization result can be much better if it is done
    retrospectively. This, however, requires that the robots keep track of their actions and
    measurements after detecting other robots."

The paper's rule (§3.2, Table 1) is to integrate every detection at once; this is the default
of ``mcl-wander-v1`` and what ``paper_rules: true`` keeps. The brain's flag
``unsure_detections`` (:class:`~teamnav.papers.collab_mcl.brains.mcl_wander_params.MCLWanderParams`) chooses what the
detecting robot does with a detection made while its own belief is *not concentrated*:

``"integrate"``
    §3.2: send it at once (the paper's rule).
``"drop"``
    Send nothing (the brain's earlier ``send_min_cluster_weight`` > 0 behaviour).
``"delay"``
    §7.2: keep it and send it once the belief is concentrated, "retrospectively".

Gaps filled here (the paper states the idea only; each is a declared choice, not the paper's):

1. *Concentrated* means the heaviest cluster of the belief holds at least
   ``send_min_cluster_weight`` of the weight (:meth:`MCL.estimate`, cells of 0.5 m) and its
   position spread is at most ``send_max_cluster_spread_m``. The weight alone (before 349d51d)
   called a lost robot's uniform belief concentrated: once the samples fill the free space it is
   one connected cluster of weight 1.
2. One stored detection per detected robot, the latest: a newer sight of the same robot carries
   the same constraint with less odometry in between. When the belief becomes concentrated the
   stored detections are sent, each exactly once, unless §2.3's rule 2 blocks the robot (a
   fresher detection of it was used within the last 2.5 m): then the stored one is dropped.
3. A stored detection older than ``delay_max_age_s`` is dropped (odometry drift grows with time).
4. Detections without identity made while unsure are dropped (association needs the beliefs of
   now; :mod:`teamnav.papers.collab_mcl.brains.anonymous_association`).
5. *Retrospective* update. Robots know their own odometry: each keeps a short history
   (:class:`OdometryHistory`: odometry pose and scan per step). The observer moves its samples
   back to the detection time by its odometry since then (:func:`poses_before`), builds the
   detection tree there (eq. 13: the seen robot's position *at the detection time*) and moves
   them forward again; the message carries the detection time. The receiver does the same with
   its own odometry: it moves its samples back to that time, applies the tree (eq. 14, and the
   sensor resetting of the teamnav column, whose scan-picked headings then use the scan of that
   time) and moves every sample, the draws included, forward by its odometry since. The §2.3
   reply is built in the same past frame and carries the same time, so the observer applies it
   to its past samples as well. Moving back and forth is exact composition (no motion noise is
   added for the replayed odometry: the filter's samples already carry the motion noise of
   that stretch, and the odometry since then is the same for every sample).

This module holds the pieces (SE(2) moves, the history, the store, the past frame); the brain
calls them. Belief only: own odometry, own samples, own scans; no true pose.
"""

from __future__ import annotations

import math
from collections import deque
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Iterator

import numpy as np

from teamnav.geometry import se2

if TYPE_CHECKING:
    from teamnav.localization import MCL

__all__ = ["DelayedIntegration", "resolve_unsure_detections", "DetectionStore", "HISTORY_MARGIN_S", "OdometryHistory", "StoredDetection", "detected_point_now", "motion_since",
           "past_frame", "poses_after", "poses_before"]


#: the odometry history covers ``delay_max_age_s`` plus this [s]: a tree sent at the maximum age
#: reaches its receiver a step later, and the reply comes back a step after that
HISTORY_MARGIN_S = 5.0


def motion_since(odom_then, odom_now) -> np.ndarray:
    """The motion from odometry pose ``odom_then`` to ``odom_now``, in the body frame of ``odom_then``.

    ``odom_then ∘ motion_since(odom_then, odom_now) == odom_now`` (SE(2), :mod:`teamnav.geometry.se2`).
    """
    return se2.relative(odom_then, odom_now)


def poses_before(poses, motion) -> np.ndarray:
    """Where each pose in ``poses`` (shape (n, 3)) was before the body moved by ``motion``: ``pose ∘ motion⁻¹``."""
    return se2.compose(poses, se2.inverse(motion))


def poses_after(poses, motion) -> np.ndarray:
    """Each pose moved by ``motion`` (given in its body frame): ``pose ∘ motion`` (inverse of :func:`poses_before`)."""
    return se2.compose(poses, motion)


def detected_point_now(range_m: float, bearing_rad: float, motion) -> tuple[float, float]:
    """A detection made before the observer moved by ``motion``, as (range [m], bearing [rad]) from
    the observer's body now: the stored detection "moved forward" by the odometry since.

    (It is the seen robot's position *at the detection time*; that robot moved too, which the
    receiver accounts for with its own odometry, see the module docstring.)
    """
    a = float(bearing_rad)
    pt = se2.transform_points(se2.inverse(motion), [float(range_m) * math.cos(a), float(range_m) * math.sin(a)])
    return float(math.hypot(pt[0], pt[1])), float(math.atan2(pt[1], pt[0]))


class OdometryHistory:
    """A robot's own odometry pose (and scan) per step for the last ``max_age_s`` seconds.

    >>> h = OdometryHistory(10.0)
    >>> h.record(0.0, [0.0, 0.0, 0.0]); h.record(1.0, [1.0, 0.0, 0.0])
    >>> h.pose_at(0.0).tolist(), h.pose_at(0.5) is None
    ([0.0, 0.0, 0.0], True)
    """

    def __init__(self, max_age_s: float) -> None:
        if not (isinstance(max_age_s, (int, float)) and math.isfinite(max_age_s) and max_age_s > 0):
            raise ValueError(f"max_age_s must be a finite number of seconds > 0, got {max_age_s!r}")
        self.max_age_s = float(max_age_s)
        self._items: deque[tuple[float, np.ndarray, np.ndarray | None]] = deque()

    def record(self, t_s: float, odom_pose, scan=None) -> None:
        """Add this step's odometry pose (and scan); forget steps older than ``max_age_s``."""
        self._items.append((float(t_s), np.array(odom_pose, dtype=float), scan))
        while self._items and self._items[0][0] < float(t_s) - self.max_age_s - 1e-9:
            self._items.popleft()

    def _find(self, t_s: float):
        for item in reversed(self._items):
            if abs(item[0] - t_s) <= 1e-6:
                return item
            if item[0] < t_s:
                break
        return None

    def pose_at(self, t_s: float) -> np.ndarray | None:
        """The odometry pose recorded at time ``t_s`` (None: not recorded, or forgotten)."""
        item = self._find(float(t_s))
        return None if item is None else item[1].copy()

    def scan_at(self, t_s: float):
        """The scan recorded at time ``t_s`` (None when not recorded)."""
        item = self._find(float(t_s))
        return None if item is None else item[2]


@dataclass(frozen=True)
class StoredDetection:
    """A detection kept for later (§7.2): of robot ``target``, at ``range_m`` / ``bearing_rad`` in the
    observer's body frame at time ``t_s``."""

    target: int
    range_m: float
    bearing_rad: float
    t_s: float


class DetectionStore:
    """The detections a robot made while unsure, one per detected robot (the latest), for ``max_age_s``.

    >>> s = DetectionStore(30.0)
    >>> s.put(StoredDetection(2, 3.0, 0.1, 5.0)); s.put(StoredDetection(2, 2.5, 0.0, 6.0))
    >>> len(s), s.expire(40.0), len(s)
    (1, 1, 0)
    """

    def __init__(self, max_age_s: float) -> None:
        if not (isinstance(max_age_s, (int, float)) and math.isfinite(max_age_s) and max_age_s > 0):
            raise ValueError(f"delay_max_age_s must be a finite number of seconds > 0, got {max_age_s!r}")
        self.max_age_s = float(max_age_s)
        self._by_target: dict[int, StoredDetection] = {}

    def __len__(self) -> int:
        return len(self._by_target)

    def put(self, det: StoredDetection) -> None:
        """Keep ``det``, replacing an older stored detection of the same robot."""
        self._by_target[int(det.target)] = det

    def expire(self, now_s: float) -> int:
        """Drop the detections older than ``max_age_s``; return how many were dropped."""
        old = [k for k, d in self._by_target.items() if now_s - d.t_s > self.max_age_s + 1e-9]
        for k in old:
            del self._by_target[k]
        return len(old)

    def take(self) -> list[StoredDetection]:
        """Every stored detection, oldest first; the store is empty afterwards (each is used once)."""
        out = sorted(self._by_target.values(), key=lambda d: d.t_s)
        self._by_target.clear()
        return out


def resolve_unsure_detections(params):
    """The ``unsure_detections`` flag of an ``MCLWanderParams`` checked against its threshold.

    ``send_min_cluster_weight`` > 0 with ``unsure_detections`` not given keeps the earlier meaning
    of the threshold (``"drop"``); ``"integrate"`` given with a threshold > 0, or ``"drop"`` /
    ``"delay"`` without one, is an error naming both fields. Returns ``params``.
    """
    given = "unsure_detections" in params.model_fields_set
    w = params.send_min_cluster_weight
    if not given and w > 0:
        object.__setattr__(params, "unsure_detections", "drop")
    elif given and params.unsure_detections == "integrate" and w > 0:
        raise ValueError(f"unsure_detections 'integrate' sends every detection at once, but "
                         f"send_min_cluster_weight = {w} > 0 holds back unsure ones: set unsure_detections to "
                         f"'drop' or 'delay', or send_min_cluster_weight to 0")
    elif params.unsure_detections in ("drop", "delay") and w <= 0:
        raise ValueError(f"unsure_detections {params.unsure_detections!r} needs the threshold of a concentrated "
                         f"belief: send_min_cluster_weight in (0, 1], got {w}")
    return params


@contextmanager
def past_frame(mcl: MCL, motion) -> Iterator[None]:
    """Inside the block the filter's samples stand where they were before the body moved by
    ``motion`` (:func:`poses_before`); on leaving, every sample (also those added inside, e.g. draws
    from a received tree) is moved forward by ``motion`` again (:func:`poses_after`). Weights are
    untouched by the moves."""
    mcl.move_samples(poses_before(mcl.particles, motion))
    try:
        yield
    finally:
        mcl.move_samples(poses_after(mcl.particles, motion))


class DelayedIntegration:
    """One brain's §7.2 state and steps: its odometry history, the detections it keeps, and the
    pose its samples stand for (the odometry at its last filter update).

    The brain calls :meth:`record` every step, :meth:`keep` with the detections of an unsure frame,
    :meth:`send_stored` once its belief is concentrated, and :meth:`motion_since` plus its own past
    frame (:func:`past_frame` and the scan of that time) for a tree that carries a detection time.

    Parameters
    ----------
    max_age_s : float
        ``delay_max_age_s``: stored detections older than this are dropped [s].
    keep_history : bool
        Keep the odometry history (every collaborating robot: it may receive delayed trees). It
        covers ``max_age_s`` plus :data:`HISTORY_MARGIN_S` (the reply's round trip).
    """

    def __init__(self, max_age_s: float, keep_history: bool) -> None:
        self.store = DetectionStore(max_age_s)
        self.history = OdometryHistory(max_age_s + HISTORY_MARGIN_S) if keep_history else None
        self.filter_odom = np.zeros(3)
        #: counters for the brain's log (only robots with ``unsure_detections="delay"`` show them)
        self.stats = {"stored": 0, "delayed_sent": 0, "expired": 0, "superseded": 0}

    def record(self, t_s: float, odom_pose: np.ndarray, scan, filtered: bool) -> None:
        """This step's odometry pose and scan; ``filtered``: the filter updated its samples to it."""
        if filtered:
            self.filter_odom = odom_pose
        if self.history is not None:
            self.history.record(t_s, odom_pose, scan)

    def motion_since(self, t_s: float) -> np.ndarray | None:
        """Own odometry from time ``t_s`` to the pose the samples stand for (None: not in the history)."""
        then = None if self.history is None else self.history.pose_at(t_s)
        return None if then is None else motion_since(then, self.filter_odom)

    def keep(self, detections, t_s: float) -> None:
        """Store the named detections of an unsure frame (anonymous ones are dropped) and forget old ones."""
        for det in detections:
            if det.robot_id is not None:
                self.store.put(StoredDetection(int(det.robot_id), float(det.range_m), float(det.bearing_rad),
                                               float(t_s)))
                self.stats["stored"] += 1
        self.stats["expired"] += self.store.expire(t_s)

    def send_stored(self, sync, mcl: MCL, now_s: float, past) -> list:
        """The stored detections, each sent once through ``sync`` (:class:`~teamnav.localization.BeliefSync`)
        with ``mcl``'s samples moved back to its time inside ``past(t_s, motion)`` (a context manager of
        the brain), unless §2.3's rule 2 blocks the robot (a fresher sight was used) or it is too old."""
        from teamnav.control.types import Detection

        out: list = []
        self.stats["expired"] += self.store.expire(now_s)
        for sd in self.store.take():
            if not sync.detect_gate.allowed(sd.target):
                self.stats["superseded"] += 1
                continue
            motion = self.motion_since(sd.t_s)
            if motion is None:
                self.stats["expired"] += 1
                continue
            with past(sd.t_s, motion):
                msgs = sync.on_detections(mcl, [Detection(sd.range_m, sd.bearing_rad, sd.target)], now_s,
                                          detected_s=sd.t_s)
            self.stats["delayed_sent"] += len(msgs)
            out += msgs
        return out
