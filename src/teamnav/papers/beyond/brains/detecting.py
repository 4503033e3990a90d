"""Brain ``detecting-trails-v1``: a trail robot that corrects its pose when it sees a teammate.

Beyond the papers, combination 3 ("detections help the trail team"). The trail papers' robots have only
drifting odometry and no map (Vaughan et al. 2000 §4.1, §5.1; 2002 §3.6); collaborative MCL's
robots share beliefs when one detects another (Fox et al. §2.3, §3.2, eqs. 13-14). This brain
composes the two, without a map and without copying either:

- **The belief** is a sample set moved by the odometry motion model only
  (:class:`~teamnav.localization.odometry_belief.OdometryBelief`: Fox et al. eqs. 6 and 11, no
  sensor update, eq. 12, since there is no map to read a scan against), each sample with its own
  heading drift rate (a gap-fill, documented there). Between detections it only spreads.
- **Detections** go through the library's :class:`~teamnav.localization.BeliefSync`, as
  ``mcl-wander-v1`` uses it: robot m, seeing teammate n (its detector, looked at once per
  ``detection_period_s``, 1 s as Fox et al. §4.1), sends n the density tree of n's position drawn
  from m's samples through the detection model (eq. 13); n multiplies it into its weights (eq. 14)
  and, with ``sync.symmetric`` (default, §2.3), answers with its own position tree, which m folds
  into its own samples: a detection updates both robots. §2.3's rule 2 (one use of a teammate per
  ``sync.min_travel_m`` = 2.5 m of travel) guards against counting one meeting twice. Eq. 14
  alone, no sensor resetting: both beliefs start at the aligned start and only spread, so the
  true pose always has samples near it.
- **Everything else** is the inner brain (``brain``, default ``blazing-trail-v1``; any registered
  brain) with its own rules unchanged, as in ``localized-v1``
  (:mod:`teamnav.papers.beyond.brains.localized`): its observation's ``odom_pose`` is the belief's
  estimate (moved on by odometry between belief updates); crumbs are dropped and looked up
  there (Blazing §4.1). All beliefs share the world frame, because the trail robots' odometry
  frames start aligned (``odometry: {frame: world}``; Blazing §4.1 "frames start aligned").

``collaborate=False`` keeps the same belief and sends nothing: the odometric team with a sample
set, the ablation that isolates what the detections buy.

What a relative detection cannot correct: it says where n is *relative to m*, so only the
spread of the team's errors shrinks; a drift the whole team shares (the mean of the rates:
+0.59 k deg/min in the 2002 pattern Bug -1, Ant +1, Fly +2, Tanis +0.35) stays in every
belief. The brain sees only its observation and messages, no truth.

Where it fills gaps (each a parameter): ``min_update_m`` / ``min_update_deg`` (the motion steps
between are composed; a belief update is forced before a tree is built or applied, so trees
describe the robots now); ``pose`` (``"mean"`` or the heaviest cluster's mean); ``init_std_m``,
``init_std_deg`` (the start Gaussian); the belief's own gap-fills
(:class:`~teamnav.localization.odometry_belief.OdometryBeliefParams`).

Logs: as ``localized-v1`` (``mcl_spread_m``, ``mcl_updates``, ``pts`` for the ``localization``
metric), plus ``syncs`` (trees applied, the metric's ``loc_syncs``) and ``det_sent``.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

from teamnav.papers.beyond.brains.localized import _child_rng, belief_log
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Action, Message, Observation
from teamnav.geometry import se2
from teamnav.localization import BeliefSync, SyncParams
from teamnav.localization.odometry_belief import OdometryBelief, OdometryBeliefParams
from teamnav.localization.sync import SYNC_KIND

__all__ = ["DetectingTrails", "DetectingTrailsParams"]


class DetectingTrailsParams(BaseModel):
    """Parameters of ``detecting-trails-v1`` (see the module docstring).

    Attributes
    ----------
    brain, brain_params
        The inner brain (registered name) and its parameters.
    belief : OdometryBeliefParams
        The map-less sample belief (samples, motion noise, drift-rate prior).
    collaborate : bool
        Belief sync on detections (eqs. 13-14); False: the belief alone (prediction only).
    detection_model : str
        A shipped detection model (``default``: Fox et al.'s, learned) or a .json file.
    detection_period_s : float
        Detections are looked at once per this period (Fox et al. §4.1: 1 Hz).
    sync : SyncParams
        Rule 2's travel, trees, symmetric answers (the library's defaults).
    min_update_m, min_update_deg : float
        Belief update once odometry accumulated this much motion.
    init_std_m, init_std_deg : float
        Spread of the start Gaussian at the first odometry pose.
    pose : {"mean", "cluster"}
        The estimate handed to the inner brain.
    """

    model_config = ConfigDict(extra="forbid")

    brain: str = Field("blazing-trail-v1", min_length=1)
    brain_params: dict[str, Any] = Field(default_factory=dict)
    belief: OdometryBeliefParams = OdometryBeliefParams()
    collaborate: bool = True
    detection_model: str = Field("default", min_length=1)
    detection_period_s: float = Field(1.0, ge=0.0, le=3600.0)
    sync: SyncParams = SyncParams()
    min_update_m: float = Field(0.1, ge=0.0)
    min_update_deg: float = Field(5.0, ge=0.0)
    init_std_m: float = Field(0.05, gt=0.0)
    init_std_deg: float = Field(2.0, gt=0.0)
    pose: Literal["mean", "cluster"] = "mean"

    @field_validator("brain")
    @classmethod
    def _not_a_wrapper(cls, v: str) -> str:
        if v in ("detecting-trails-v1", "localized-v1"):
            raise ValueError(f"brain: expected a brain that reads odom_pose (e.g. 'blazing-trail-v1'), received {v!r}")
        return v


class DetectingTrails:
    """``detecting-trails-v1``: the inner brain on a map-less belief synced on detections.

    Parameters
    ----------
    params : DetectingTrailsParams
    rng : numpy.random.Generator
        The inner brain's stream (the belief and the sync get streams spawned from it).
    info : RobotInfo
    """

    Params = DetectingTrailsParams
    needs_map = False

    def __init__(self, params: DetectingTrailsParams, rng: np.random.Generator, info: RobotInfo) -> None:
        from teamnav.control import registry
        from teamnav.papers.collab_mcl.brains.localizing import load_detection_model

        if not isinstance(params, DetectingTrailsParams):
            raise ValueError(f"params must be a DetectingTrails.Params, got {type(params).__name__}")
        self.params = params
        self.robot_id = int(info.robot_id)
        cls = registry.lookup(params.brain)
        self.inner = cls(cls.Params(**params.brain_params), rng, info)
        self.belief = OdometryBelief(params.belief, _child_rng(rng))
        self.sync = (BeliefSync(self.robot_id, load_detection_model(params.detection_model), params.sync,
                                _child_rng(self.belief.rng)) if params.collaborate else None)
        self._log_rng = _child_rng(self.belief.rng)
        self._started = False
        self._acc = np.zeros(3)  # odometry composed since the last belief update
        self._acc_s = 0.0  # time since the last belief update [s]
        self._last_s = 0.0
        self._base = np.zeros(3)  # the belief's estimate at its last update
        self._min_rot = math.radians(params.min_update_deg)
        self._next_frame_s = 0.0
        self._spread = float("nan")
        self._updates = 0
        self.sent = 0

    def _flush(self) -> None:
        """Move the belief by the pending odometry (the steps since the last update)."""
        self.belief.predict(self._acc, self._acc_s)
        self._acc = np.zeros(3)
        self._acc_s = 0.0
        self._updates += 1
        self._estimate()

    def _estimate(self) -> None:
        est = self.belief.estimate()
        self._base = np.array(est.cluster_pose if self.params.pose == "cluster" else est.pose, dtype=float)
        self._spread = float(math.sqrt(max(0.0, est.cov[0, 0] + est.cov[1, 1])))

    def step(self, obs: Observation) -> tuple[Action, list[Message]]:
        """Belief (motion, trees received, trees sent), then the inner brain on its estimate."""
        p = self.params
        t = float(obs.time_s)
        if not self._started:
            sd, sa = p.init_std_m, math.radians(p.init_std_deg)
            self.belief.init_pose(np.asarray(obs.odom_pose, dtype=float), np.diag([sd * sd, sd * sd, sa * sa]))
            self._last_s = t
            self._started = True
            self._estimate()
        self._acc = se2.compose(self._acc, np.asarray(obs.odom_delta, dtype=float))
        self._acc_s += max(0.0, t - self._last_s)
        self._last_s = t
        if math.hypot(self._acc[0], self._acc[1]) >= p.min_update_m or abs(self._acc[2]) >= self._min_rot:
            self._flush()
        out: list[Message] = []
        if self.sync is not None:
            self.sync.travel(obs.odom_delta)
            mine = [m for m in obs.inbox if m.kind == SYNC_KIND and m.to == self.robot_id]
            frame = t + 1e-9 >= self._next_frame_s
            seen = [d for d in obs.detections if d.robot_id is not None and d.robot_id != self.robot_id] if frame else []
            if frame:
                self._next_frame_s = t + p.detection_period_s
            if mine or seen:
                if self._acc_s > 0.0 or self._acc.any():
                    self._flush()
                before = sum(self.sync.applied.values())
                for msg in mine:
                    out += self.sync.on_message(self.belief, msg, t)
                if seen:
                    sent = self.sync.on_detections(self.belief, seen, t)
                    self.sent += len(sent)
                    out += sent
                if sum(self.sync.applied.values()) != before:
                    self._estimate()
        action, msgs = self.inner.step(dataclasses.replace(obs, odom_pose=se2.compose(self._base, self._acc)))
        return action, list(msgs) + out

    def log(self) -> dict[str, Any]:
        """``localized-v1``'s log (:func:`~teamnav.papers.beyond.brains.localized.belief_log`), plus
        ``syncs`` (trees applied) and ``det_sent`` (detection trees sent)."""
        out = belief_log(self.inner, self.belief if self._started else None, self._log_rng, self._spread,
                         self._updates)
        out["syncs"] = int(sum(self.sync.applied.values())) if self.sync is not None else 0
        out["det_sent"] = int(self.sent)
        return out
