"""A robot that wanders while it localizes itself, alone or with its team (Fox et al.).

Fox, Burgard, Kruppa & Thrun, "A probabilistic approach to collaborative multi-robot
localization", Autonomous Robots 8(3), 2000. The brain ``mcl-wander-v1``:

- *moves* with the wanderer of :mod:`teamnav.control.nav.wander` (wall following, random
  turns at openings, obstacle avoidance from the range scan; the paper's robots are driven
  by an operator or a random walk, §5);
- *localizes* with its own :class:`~teamnav.localization.MCL` (§3.1): global initialisation
  uniform over the free space of ``info.known_map`` (§2.2, Fig. 4a), odometry motion model,
  beam model of its sensor (sonar cones or laser, Fig. 1) or the likelihood field, a few
  uniform random samples per step, KLD-adaptive sample count (§3.1 "MCL determines the
  sample set size on-the-fly");
- with ``collaborate`` it *synchronises* beliefs on detections (§2.3, §3.2, eqs. 10, 13, 14)
  through :class:`~teamnav.localization.BeliefSync`: a detection becomes a density tree of
  the seen robot's position, sent over the radio (its bytes counted by ``Message.size_bytes``);
  the seen robot multiplies it into its weights and answers with its own position tree so that
  the observer is constrained too; negative sights are ignored and a robot is not used again
  until the user has travelled ``min_travel_m`` = 2.5 m (§2.3 rules 1 and 2).

Detections are looked at once per ``detection_period_s`` (1 s: "images are analyzed at a
rate of 1 Hz", §4.1); the simulator's detector reports every step, so its false-positive rate
per step is the rate per camera frame as the brain sees it.

Where the brain fills gaps of the paper (each a parameter, the paper's behaviour reachable):
the filter runs once odometry accumulated ``min_update_m`` / ``min_update_deg`` (the steps in
between are composed, as AMCL does); it resamples only when the effective sample size fell
below ``resample_ess_fraction`` of the set (1 = every update, as §3.1); the likelihood is
tempered by ``likelihood_exponent`` (neighbouring beams are not independent); and with
``inject_fraction`` > 0 a received tree first replaces that share of the samples by draws from
it (sensor resetting) before eq. 14 reweights them, because our sample sets (thousands per
robot) lose the true mode of a symmetric belief long before a detection arrives, and eq. 14
alone cannot move weight onto samples that do not exist.

Against double counting and wrong senders (measured on the failing runs of the first version,
each fix a parameter with the first behaviour one flag away):

- the draws get the posterior probability that the receiver is lost (``inject_weighting``,
  ``inject_lost_prior``), not the tree's density a second time: drawing from the tree and then
  multiplying the tree in counted the detection twice and handed a receiver to any sender
  whose tree contradicted it, right or wrong (in the hexagon, pairs of robots swapped their
  right and wrong beliefs at every exchange);
- the §2.3 reply is built from the belief before the draws (``inject_before_reply``): it
  carried the sender's own claim back to it, which then confirmed its own belief;
- the draws take headings from the own belief (``inject_heading_belief_share``): a detection
  sees no heading, and with uniform headings the mirror pose of a featureless corridor (other
  side of the axis, heading reversed) won a §5.1 run;
- ``provenance``: rule 2 made transitive (:class:`~teamnav.localization.SyncParams`): a robot
  drops a tree holding its own information from less than 2.5 m of travel ago that came back
  through a third robot.

Beyond the paper (each behind a flag, measured in the ``collab-mcl`` report section):

``false_positive_filter`` (§7.2: "a rate of 3.5 % ... turns out to cause major problems")
    Three gates, two at the observer and one at the detected robot:

    1. *map consistency*: the detected position, sampled through the detection model from
       the observer's belief, must fall in free space of the known map with at least
       ``fp_min_free_mass`` of the belief's weight (a phantom at a uniform range and bearing
       lands in a wall or outside the building most of the time in hallways);
    2. *confirmation*: a detection is used only when the same robot was also seen on the
       previous camera frame (at most ``fp_confirm_window_s`` before) at a consistent place:
       the two detected points, each expressed in the observer's odometry frame, lie within
       ``fp_confirm_gate_m`` of each other. Phantoms are independent per frame with random
       identities and positions, so two consistent phantoms are rare (≈ p_fp² × gate area /
       field area), while a true teammate is seen on consecutive frames;
    3. *belief agreement* (at the detected robot, off by default: ``fp_min_real_prob`` = 0):
       the posterior probability that the detection is real, ``(1 - p_fp) E / ((1 - p_fp) E +
       p_fp / A)`` with ``E = sum_i w_i tree(x_i)`` the tree's density under the own belief and
       ``A`` the free area, must be at least ``fp_min_real_prob``. Measured on the §5.1 setting
       it also drops the *true* detections that matter most: those that reach a robot whose
       belief has collapsed onto a wrong place, which cannot tell them from phantoms.

``anonymous`` (§7.2 "Identification of robots"; :mod:`teamnav.papers.collab_mcl.brains.anonymous_association`)
    A detection without identity (``robot_id`` None) is *associated by belief*: the observer
    broadcasts its tree, every teammate answers with the tree's density under its own belief, and
    the detection goes to the one that clearly fits best, or is dropped when none does. With
    ``anonymous="ignore"`` the brain does what the paper's method does with anonymous sights: nothing.

``negative_detections`` (§7.2 "Not seeing each other"; :mod:`teamnav.papers.collab_mcl.brains.negative_sights`)
    Not seeing a teammate where its broadcast belief says it should be visible weighs the own
    samples down, by a likelihood over the detector's range and field of view with line of sight
    on the known map (:mod:`teamnav.localization.negative_detection`). Off by default (§2.3 rule 1).

``unsure_detections`` (§7.2 "Delayed integration"; :mod:`teamnav.papers.collab_mcl.brains.delayed_integration`)
    A detection made while unsure: sent at once (the paper's §3.2 rule, default), dropped, or
    delayed until the belief is concentrated and applied at its time by both robots.

``paper_rules=True`` is the paper as written
(:attr:`~teamnav.papers.collab_mcl.brains.mcl_wander_params.MCLWanderParams.PAPER_RULES`, :mod:`teamnav.control.paper_rules`;
the reports' "paper as written" column): eq. 14 alone on a received tree (no sensor resetting), the
untempered likelihood (eq. 12), resampling at every update (§3.1), §2.3's two rules only (no
provenance, no gate on the receiving side), every detection sent (§3.2), no false-positive filter,
anonymous and negative sights ignored (§7.2, §2.3). Setting one of those fields as well is an
error. What the paper gives no value for is kept in both columns and listed in
:attr:`~teamnav.papers.collab_mcl.brains.mcl_wander_params.MCLWanderParams.GAP_FILLS_KEPT` (the KLD floor among them).

Every setting named here is a field of :class:`~teamnav.papers.collab_mcl.brains.mcl_wander_params.MCLWanderParams`
(:mod:`teamnav.papers.collab_mcl.brains.mcl_wander_params`, importable from this module too), documented there with
what was measured.

The filter never sees a true pose; experiments score it from what :meth:`MCLWander.log`
records (a weighted subsample of the particles every recorded step, see
:mod:`teamnav.papers.collab_mcl.metrics`).
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from teamnav.papers.collab_mcl.brains.anonymous_association import ASSOC_KIND, AnonymousAssociation, to_odom
from teamnav.papers.collab_mcl.brains.delayed_integration import DelayedIntegration, past_frame
from teamnav.papers.collab_mcl.brains.mcl_wander_params import MCLWanderParams
from teamnav.control.nav.wander import Wander
from teamnav.papers.collab_mcl.brains.negative_sights import NegativeSights
from teamnav.control.protocol import RobotInfo
from teamnav.papers.collab_mcl.brains.tree_injection import inject_tree
from teamnav.control.types import Action, Message, Observation
from teamnav.localization import BeliefSync, DetectionModel, MCL, SyncMessage, SyncParams
from teamnav.localization.resample import low_variance_kernel
from teamnav.localization.sync import SYNC_KIND
from teamnav.world.grid import FREE

# MCLWanderParams lives in teamnav.papers.collab_mcl.brains.mcl_wander_params; it stays importable from here
__all__ = ["MCLWander", "MCLWanderParams", "load_detection_model", "MODEL_DIR"]

#: Folder of the detection models shipped with teamnav (``detection_model: default`` is
#: ``MODEL_DIR / "detection-default.json"``).
MODEL_DIR: Path = Path(str(resources.files("teamnav.localization"))) / "models"


def load_detection_model(name: str) -> DetectionModel:
    """A detection model by name (``MODEL_DIR/detection-NAME.json``) or by file path."""
    p = Path(name)
    if p.suffix.lower() != ".json":
        p = MODEL_DIR / f"detection-{name}.json"
    if not p.is_file():
        known = sorted(q.stem.removeprefix("detection-") for q in MODEL_DIR.glob("detection-*.json"))
        raise ValueError(f"detection_model must name a shipped model ({', '.join(known)}) or a .json file, "
                         f"got {name!r} (no file {p})")
    return DetectionModel.load(p)


class MCLWander(AnonymousAssociation):
    """``mcl-wander-v1``: wander and localize, optionally with the team (see the module docstring).

    Parameters
    ----------
    params : MCLWanderParams
    rng : numpy.random.Generator
    info : RobotInfo
        Must carry ``known_map`` (scenario ``give_map: true``) and the range sensor.
    """

    Params = MCLWanderParams
    #: check_brain gives it a small known map (it needs one, like a scenario with give_map: true)
    needs_map = True

    def __init__(self, params: MCLWanderParams, rng: np.random.Generator, info: RobotInfo) -> None:
        if not isinstance(params, MCLWanderParams):
            raise ValueError(f"params must be an MCLWander.Params, got {type(params).__name__}")
        if info.known_map is None:
            raise ValueError(f"robot {info.robot_id}: mcl-wander-v1 needs a map; set 'give_map: true' in the scenario")
        self.params = params
        self.info = info
        self.robot_id = int(info.robot_id)
        self.rng = rng
        self.wander = Wander(params.wander.model_copy(update={"sensor": params.sensor}), rng, info)
        self.sensor = info.sensors[self.wander.sensor]
        self.mcl = MCL(params.mcl_params(), info.known_map, self.sensor, rng)
        if params.init_pose is None:
            self.mcl.init_global()
        else:
            x, y, th = params.init_pose
            self.mcl.init_pose([x, y, math.radians(th)], np.diag([params.init_std_m ** 2, params.init_std_m ** 2,
                                                                  math.radians(params.init_std_deg) ** 2]))
        self.model = load_detection_model(params.detection_model) if params.collaborate else None
        self.sync = (BeliefSync(self.robot_id, self.model, SyncParams(min_travel_m=params.min_travel_m,
                                                                      tree_min_samples=params.tree_min_samples,
                                                                      tree_max_depth=params.tree_max_depth,
                                                                      provenance=params.provenance,
                                                                      receive_gate=params.receive_gate), rng)
                     if params.collaborate else None)
        self._free = (info.known_map.cells == FREE)
        self._next_frame_s = 0.0
        self._last_seen: dict[Any, tuple[float, np.ndarray]] = {}  # id -> (time, point in odom frame)
        self._init_association()  # §7.2 anonymous detections: queries waiting for answers
        self._odom = np.zeros(3)
        self._scan: np.ndarray | None = None  # this step's ranges (scan-picked headings of draws)
        self._acc = np.zeros(3)  # odometry composed since the last filter update
        self._stepped = False
        self._min_rot = math.radians(params.min_update_deg)
        self._n_log = 0
        self._time_s = 0.0
        #: one record per detection tree received (time, sender, the belief's sample count, spread and
        #: heaviest cluster's weight just before it, whether it was applied); logged as "det_belief"
        self._det_log: list[dict[str, Any]] = []
        self._det_logged = 0
        #: Counters for logs: detections seen / sent, phantoms filtered, messages dropped, associations.
        self.stats = {"seen": 0, "sent": 0, "filtered": 0, "rejected": 0, "assoc": 0, "assoc_dropped": 0}
        # §7.2 delayed integration: odometry history, detections kept while unsure
        self._delay = DelayedIntegration(params.delay_max_age_s, keep_history=params.collaborate)
        # §7.2 negative sights (beyond the paper): teammates' broadcast points and the rate rule
        self._neg = (NegativeSights(params, self.robot_id, info.known_map, self.model.p_false_negative, info.dt_s)
                     if params.negative_detections else None)

    # ------------------------------------------------------------------ step
    def step(self, obs: Observation) -> tuple[Action, list[Message]]:
        """Localize (motion + scan), apply teammates' messages, look for teammates, wander."""
        p = self.params
        self._odom = np.asarray(obs.odom_pose, dtype=float)
        self._time_s = float(obs.time_s)
        scan = obs.scans[self.wander.sensor]
        self._scan = np.asarray(scan.ranges_m, dtype=float)
        self._accumulate(np.asarray(obs.odom_delta, dtype=float))
        acc = self._acc
        filtered = False
        if not self._stepped or math.hypot(acc[0], acc[1]) >= p.min_update_m or abs(acc[2]) >= self._min_rot:
            self._filter_step(acc, scan.ranges_m)
            self._acc = np.zeros(3)
            self._stepped = True
            filtered = True
        self._delay.record(obs.time_s, self._odom, self._scan, filtered)
        out: list[Message] = []
        if self.sync is not None:
            self.sync.travel(obs.odom_delta)
            neg = self._neg
            if neg is not None:
                neg.travel(obs.odom_delta)
            for msg in obs.inbox:
                if neg is None or not neg.on_message(msg, obs.time_s):
                    out += self._on_message(msg, obs)
            if obs.time_s + 1e-9 >= self._next_frame_s:
                self._next_frame_s = obs.time_s + p.detection_period_s
                out += self._on_detections(obs)
                if neg is not None:
                    neg.on_frame(self.mcl, obs.detections, obs.time_s)
            out += self._close_queries(obs)
            if neg is not None:
                out += neg.broadcast(self.mcl, self.rng, obs.time_s, self._next_frame_s)
        action, _ = self.wander.step(obs)
        if p.motion_mode == "stay":
            action = Action.stop()
        return action, out

    def _filter_step(self, odom_delta: np.ndarray, ranges: np.ndarray) -> None:
        """Resample (only when the effective sample size fell below ``resample_ess_fraction``
        of the set), predict, weight: :meth:`MCL.step` with selective resampling."""
        w = self.mcl.weights
        if self._stepped and 1.0 / float(np.dot(w, w)) < self.params.resample_ess_fraction * w.shape[0]:
            self.mcl.resample()
        self.mcl.predict(odom_delta)
        self.mcl.update(ranges)

    def _accumulate(self, d: np.ndarray) -> None:
        """Compose this step's odometry ``d`` (previous body frame) onto the pending motion."""
        a = self._acc
        c, s_ = math.cos(a[2]), math.sin(a[2])
        th = a[2] + d[2]
        self._acc = np.array([a[0] + c * d[0] - s_ * d[1], a[1] + s_ * d[0] + c * d[1],
                              math.atan2(math.sin(th), math.cos(th))])

    # ------------------------------------------------------------------ detections
    def _free_mass(self, det) -> float:
        """Weight of the observer's belief that puts the detected robot in free space (gate 1)."""
        pos = self.model.sample_positions(self.mcl.particles, det.range_m, det.bearing_rad, self.rng)
        g = self.info.known_map
        iy, ix = np.moveaxis(g.world_to_cell(pos[:, :2]), -1, 0)  # the map's own transform (any yaw)
        h, w = self._free.shape
        inside = (ix >= 0) & (ix < w) & (iy >= 0) & (iy < h)
        ok = np.zeros(pos.shape[0], dtype=bool)
        ok[inside] = self._free[iy[inside], ix[inside]]
        return float(np.dot(self.mcl.weights, ok))

    def _confirmed(self, key, det, t_s: float) -> bool:
        """Gate 2: the same robot seen on a recent frame at a consistent place (odometry frame)."""
        pt = to_odom(self._odom, det.range_m, det.bearing_rad)
        prev = self._last_seen.get(key)
        self._last_seen[key] = (t_s, pt)
        if prev is None or t_s - prev[0] > self.params.fp_confirm_window_s:
            return False
        return bool(np.hypot(*(pt - prev[1])) <= self.params.fp_confirm_gate_m)

    def _on_detections(self, obs: Observation) -> list[Message]:
        p = self.params
        out: list[Message] = []
        keep = []
        for det in obs.detections:
            self.stats["seen"] += 1
            if det.robot_id is not None and det.robot_id == self.robot_id:
                continue
            if p.false_positive_filter:
                key = det.robot_id if det.robot_id is not None else ("anon", self._anon_key(det))
                if not self._confirmed(key, det, obs.time_s) or self._free_mass(det) < p.fp_min_free_mass:
                    self.stats["filtered"] += 1
                    continue
            keep.append(det)
        if p.unsure_detections != "integrate" and not self._concentrated():
            if p.unsure_detections == "delay":  # §7.2: keep the named ones for later
                self._delay.keep(keep, obs.time_s)
            return out
        named = [d for d in keep if d.robot_id is not None]
        if named:
            msgs = self.sync.on_detections(self.mcl, named, obs.time_s)
            self.stats["sent"] += len(msgs)
            out += msgs
        if p.unsure_detections == "delay" and len(self._delay.store):
            msgs = self._delay.send_stored(self.sync, self.mcl, obs.time_s, self._past)
            self.stats["sent"] += len(msgs)
            out += msgs
        if p.anonymous == "associate":
            for det in keep:
                if det.robot_id is None:
                    out += self._query(det, obs)
        return out

    def _concentrated(self) -> bool:
        """§7.2's "more certain", as declared by ``send_min_cluster_weight`` and
        ``send_max_cluster_spread_m`` (gap-fills: the heaviest cluster is heavy *and* narrow)."""
        p, est = self.params, self.mcl.estimate()
        if est.cluster_weight < p.send_min_cluster_weight:
            return False
        return p.send_max_cluster_spread_m is None or est.cluster_spread_m <= p.send_max_cluster_spread_m

    # ------------------------------------------------------------------ §7.2 delayed integration
    @contextmanager
    def _past(self, t_s: float, motion: np.ndarray):
        """The samples (and the scan the draws' headings use) as they were at time ``t_s``, and back."""
        saved = self._scan
        self._scan = self._delay.history.scan_at(t_s)
        try:
            with past_frame(self.mcl, motion):
                yield
        finally:
            self._scan = saved

    # ------------------------------------------------------------------ messages
    def _on_message(self, msg: Message, obs: Observation) -> list[Message]:
        """Handle one message; a tree of a delayed detection (§7.2, ``SyncMessage.detected_s``) is
        applied to the samples moved back to the detection's time, then moved forward again."""
        body = msg.body
        if isinstance(body, SyncMessage) and body.detected_s is not None and (
                (body.kind == "detection" and body.target == self.robot_id)
                or (body.kind == "inverse" and body.observer == self.robot_id)):
            motion = self._delay.motion_since(body.detected_s)
            if motion is None:  # older than this robot's history: cannot be applied retrospectively
                self.stats["stale"] = self.stats.get("stale", 0) + 1
                return []
            with self._past(body.detected_s, motion):
                return self._on_message_now(msg, obs)
        return self._on_message_now(msg, obs)

    def _on_message_now(self, msg: Message, obs: Observation) -> list[Message]:
        """Handle one message; a detection tree addressed to this robot is logged with the belief it
        met (the paper's Fig. 10a shows that belief still spread along the corridor)."""
        body = msg.body
        if not (msg.kind == SYNC_KIND and isinstance(body, SyncMessage) and body.kind == "detection"
                and body.target == self.robot_id):
            return self._handle(msg, obs)
        est = self.mcl.estimate()
        before = self.sync.applied["detection"]
        out = self._handle(msg, obs)
        self._det_log.append({"t_s": round(float(obs.time_s), 2), "from": int(body.observer),
                              "n_particles": int(est.n_particles),
                              "spread_m": round(float(math.sqrt(max(0.0, est.cov[0, 0] + est.cov[1, 1]))), 3),
            "loglik_per_beam": (round(float(self.mcl.last_log_mean_likelihood_per_beam), 4)
                                if math.isfinite(self.mcl.last_log_mean_likelihood) else None),
                              "cluster_weight": round(float(est.cluster_weight), 3),
                              "applied": bool(self.sync.applied["detection"] > before)})
        return out

    def _handle(self, msg: Message, obs: Observation) -> list[Message]:
        p = self.params
        body = msg.body
        if msg.kind == ASSOC_KIND:
            return self._on_assoc_message(msg, obs)
        if msg.kind != SYNC_KIND or not isinstance(body, SyncMessage):
            return []
        if p.false_positive_filter and body.kind == "detection" and body.target == self.robot_id:
            e = self._evidence(body.tree)
            pf = body.p_false_positive
            real = (1 - pf) * e / ((1 - pf) * e + pf / self.mcl.free_area_m2) if pf > 0 else 1.0
            if real < p.fp_min_real_prob:
                self.stats["rejected"] += 1
                return []
        if (p.inject_fraction > 0 and body.kind == "detection" and body.target == self.robot_id
                and self.sync.receive_allowed(body.observer)):
            return self._inject_and_apply(msg, obs)
        return self.sync.on_message(self.mcl, msg, obs.time_s)

    def _inject_and_apply(self, msg: Message, obs: Observation) -> list[Message]:
        """Apply a detection tree with sensor resetting; the reply (§2.3 symmetry) carries the
        belief from before the draws unless ``inject_before_reply`` (the first version)."""
        if self.params.inject_before_reply:
            factors = self._inject(self.mcl, msg.body)
            return self.sync.on_message(self.mcl, msg, obs.time_s, evidence=lambda mcl, body: factors)
        return self.sync.on_message(self.mcl, msg, obs.time_s, evidence=self._inject)

    def _inject(self, mcl: MCL, body: SyncMessage) -> np.ndarray:
        """Sensor resetting on a received tree, then eq. 14: :func:`~teamnav.papers.collab_mcl.brains.tree_injection.inject_tree`."""
        return inject_tree(self.params, self.rng, self._scan, mcl, body)

    # ------------------------------------------------------------------ logs
    def _subsample(self, k: int) -> np.ndarray:
        """``k`` particles drawn by weight (low-variance), so their plain mean is the weighted one."""
        w = self.mcl.weights
        k = min(k, w.shape[0])
        idx = low_variance_kernel(w, k, float(self.rng.random()), np.empty(k, dtype=np.int64))
        return self.mcl.particles[idx]

    def log(self) -> dict[str, Any]:
        """Belief summary every recorded step; a particle layer every ``layer_every`` calls.

        ``pts``: ``log_points`` particles drawn by weight, flattened ``[x0, y0, x1, y1, ...]`` [m]
        rounded to cm: the metric's estimate of the paper's "average distance of all samples
        from the reference position" (§5.1) is their mean distance to the true position.
        """
        p = self.params
        est = self.mcl.estimate()
        sub = self._subsample(p.log_points)
        out: dict[str, Any] = {
            "est_x": round(float(est.cluster_pose[0]), 3),
            "est_y": round(float(est.cluster_pose[1]), 3),
            "est_th": round(float(est.cluster_pose[2]), 3),
            "n_particles": int(est.n_particles),
            "spread_m": round(float(math.sqrt(max(0.0, est.cov[0, 0] + est.cov[1, 1]))), 3),
            "loglik_per_beam": (round(float(self.mcl.last_log_mean_likelihood_per_beam), 4)
                                if math.isfinite(self.mcl.last_log_mean_likelihood) else None),
            "syncs": int(sum(self.sync.applied.values())) if self.sync is not None else 0,
            "looped": int(self.sync.looped) if self.sync is not None else 0,
            "pts": [round(float(v), 2) for v in sub[:, :2].ravel()],
        }
        if len(self._det_log) > self._det_logged:
            out["det_belief"] = self._det_log[self._det_logged:]
            self._det_logged = len(self._det_log)
        if self._n_log == 0:
            out["sensor_kind"] = self.sensor.kind
            out["group"] = str(self.info.extras.get("group", ""))
        if self.sync is not None and self._n_log % p.layer_every == 0:
            out.update({k: v for k, v in self.stats.items()})
            if p.unsure_detections == "delay":
                out.update(self._delay.stats)
            if self._neg is not None:
                out.update(self._neg.stats)
        if self._n_log % p.layer_every == 0:
            pts = self._subsample(p.layer_points)[:, :2].astype(np.float32)
            out["layers"] = {"particles": {"data": pts, "kind": "points", "frame": "world", "hold": True,
                                           "description": "MCL samples (drawn by weight), map frame"}}
        self._n_log += 1
        return out
