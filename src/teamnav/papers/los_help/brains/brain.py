"""The step both brains of the line-of-sight help system share (Sgorbissa & Arkin §2–§6).

The brains themselves live in :mod:`.explorer` and :mod:`.helper`.

Paper: A. Sgorbissa and R. C. Arkin, "Local navigation strategies for a team of robots".

- :class:`~.explorer.LosExplorer` (``los-explorer-v1``) is R1: it is given targets in its own frame,
  reached in sequence within ε (§2), drives with a local navigation algorithm A
  (``navigator``), and is helped by teammates through goal sharing (§3–§4) and state sharing
  (§5).
- :class:`~.helper.LosHelper` (``los-helper-v1``) is R2..R4: it patrols waypoints (§6: helpers "patrol
  the corridors") with the same navigator family, runs the same sharing rules (shares its
  own patrol goal, relays the goals it knows, reports D for every goal it sees, keeps ghosts)
  and never leaves its patrol to help.

One step of either brain (belief only: its odometry pose, its omnidirectional range scan
``laser``, its robot detector's detections with identities, its inbox):

1. remember its pose and its sightings of this step (a message sent at step k arrives at
   k + 1; the receiver pairs it with its own sighting of the sender *at k*);
2. read the inbox: for each :class:`~.messages.LosHelpMsg` whose sender it saw at the sending
   step and which carries the sender's bearing of it, compute the sender's frame from the
   mutual bearings (§3.1), map the goals and the sender's position into its own frame and
   apply the Id rule and the shortest-D arbitration (:mod:`.goal_sharing`); keep the
   sender's Tr bit (§5);
3. advance its own task (target reached within ε → next target, §2);
4. check visibility of every known goal and keep the §4.3 bookkeeping;
5. choose what to head to (explorer, in this priority): its goal when it sees it (straight,
   suppressing A, §2 point 4) — ``own_goal``; the point offering the shortest D: a teammate
   that reports now (``follow_teammate``) or a ghost (``ghost``) (§3 rule 5, §4.2); when in
   trouble, the nearest teammate it sees that is not (``trouble_follow``, §5 rule 3; by
   default not one walking away from its goal, ``trouble_helper_towards_goal``); else
   its navigator towards its goal (``own_goal``);
6. update Pr/Tr/Nt from this step's progress (§5);
7. broadcast its sightings, goals, reports and Tr if it sees a teammate (§4.4: O(M) terms).

Heading to a visible point (goal, teammate, ghost) goes straight while the laser shows a
corridor as wide as the body all the way to it; else, if the point is in sight, the robot slides
along the blocked side (``slide_when_blocked``), and otherwise the navigator is asked for a
heading towards it (gap filled: the paper's robots are points, ours have a radius;
:meth:`.driving._Driving._head_to`). Progress (§5) is the
navigator's own estimate while it drives, and "the distance to the point being headed for fell
by at least ``progress_min_fraction`` of a step below its best so far" otherwise (:mod:`.driving`).

``Action(direction_rad=...)`` is a body-frame direction for ``holonomic_step`` kinematics
(Sgorbissa & Arkin count motion steps); ``Action()`` stays and does not count as a move.

Scenario use: robots need ``kinematics: holonomic_step``, an omnidirectional laser (``fov_deg:
360``; its name is ``laser``), a ``detector`` that reports identities (``report_identity``,
the default; detections without an id are ignored) and ``radio: {mode: line_of_sight}``.
``targets_xy`` / ``patrol_xy`` are in each robot's own odometry frame (``frame: start``): a
world point ``w`` is ``R(-θ0)(w - p0)`` for a robot starting at ``(p0, θ0)``. With
``stop_when_finished`` a run ends once R1 is ``finished`` (helpers have no such attribute).

Parameters, log keys and layers are documented on :class:`~.explorer_params.LosExplorerParams`,
:meth:`~.explorer.LosExplorer.log` and :class:`~.helper.LosHelperParams`; keep them stable (experiments and
the report read them).
"""

from __future__ import annotations

import abc
import math
from typing import Any

import numpy as np

from teamnav.papers.los_help.brains.driving import XY, _Driving
from teamnav.papers.los_help.brains.goal_sharing import (
    GoalSharing,
    beam_near_reaches,
    max_beam_gap,
    nearest_beam_visible,
    see_past_teammates,
    sender_frame,
)
from teamnav.papers.los_help.brains.messages import (
    MESSAGE_KIND,
    GoalShare,
    LosHelpMsg,
    Sighting,
    VisReport,
    message_size_bytes,
)
from teamnav.papers.los_help.brains.params import _CommonParams, los_gap_fills  # los_gap_fills: re-exported
from teamnav.papers.los_help.brains.state_sharing import TroubleState
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Action, Message, Observation, RangeScan

__all__ = ["los_gap_fills", "make_navigator"]

#: Steps of own pose/sightings kept to pair delayed messages with (O(1) memory).
_HISTORY_STEPS = 4


def make_navigator(name: str, params: dict | None, *, rng: np.random.Generator, step_length_m: float,
                   radius_m: float):
    """The local navigation algorithm A (``teamnav.control.nav.local``), built lazily.

    Tests replace this module attribute with a trivial navigator; brains call it only when
    they first need to navigate (a brain with nothing to do needs no navigator).
    """
    from teamnav.control.nav.local import make_navigator as _make

    return _make(name, params or None, rng=rng, step_length_m=step_length_m, radius_m=radius_m)


class _LosBrain(_Driving, abc.ABC):
    """What both brains share: sensing, the receive path, sharing rules, motion and logs."""

    Params: type[_CommonParams] = _CommonParams

    def __init__(self, params: _CommonParams, rng: np.random.Generator, info: RobotInfo) -> None:
        if not isinstance(params, self.Params):
            raise ValueError(f"params must be a {type(self).__name__}.Params, got {type(params).__name__}")
        if params.laser not in info.sensors:
            raise ValueError(
                f"laser must name one of robot {info.robot_id}'s range sensors ({', '.join(sorted(info.sensors))}), "
                f"got {params.laser!r}"
            )
        self.params = params
        self.info = info
        self.me = int(info.robot_id)
        self.team_size = int(params.id_gain_k or max(1, info.team_size))
        sensor = info.sensors[params.laser]
        self.vis_radius_m = float(params.visibility_radius_m or sensor.max_range_m)
        self.step_m = float(info.step_length_m)
        self.radius_m = float(info.radius_m)
        self._rng = rng
        self._nav = None
        self._nav_goal: tuple[float, float] | None = None
        #: A (the navigator) found the temporary point of this step unreachable (``_Driving._navigate``)
        self._temp_unreachable = False
        self.sharing = GoalSharing(self.me, self.team_size, delayed=params.delayed_visibility,
                                   point_margin_m=2.5 * self.radius_m,
                                   report_margin_m=params.report_margin_steps * self.step_m,
                                   lead_on=params.lead_on, relay_hop_limit=params.relay_hop_limit)
        self.trouble = TroubleState(int(params.trouble_cr))
        self._history: dict[int, tuple[np.ndarray, dict[int, tuple[float, float]]]] = {}
        self._teammate_tr: dict[int, bool | None] = {}
        #: where each teammate whose Tr bit arrived this step stood (own frame) when it sent it,
        #: from my own sighting of it at the sending step (None: I did not see it then)
        self._teammate_tr_xy: dict[int, XY] = {}
        self._seen_now: dict[int, tuple[float, float]] = {}
        self._prev_xy: XY | None = None
        self._last_target: tuple[str, Any, float] | None = None
        self.mode = "own_goal"
        self.moves = 0
        self.nav_restarts = 0
        self.msgs_sent = 0
        self.bytes_sent = 0
        self.msgs_received = 0
        self._scan: RangeScan | None = None
        self._nav_scan: RangeScan | None = None
        self._gap_for: Any = None
        self._gap_rad = 0.0
        self._a64 = self._r64 = self._vis_r64 = np.zeros(0)
        self._max_range = 0.0
        self._set_pose(np.zeros(3))
        self._step = 0
        #: frame_source "fused": this robot's pose covariance (set by ``localized-v1`` through
        #: :meth:`set_pose_cov`; None: unknown, the floor) and its value per recent step
        self._pose_cov: np.ndarray | None = None
        self._cov_history: dict[int, np.ndarray | None] = {}
        #: frames taken from poses, and of those fused with a bearing frame (frame_source != "bearings")
        self.frames_from_poses = 0
        self.frames_fused = 0
        #: steps spent per mode, cumulative (where the steps go: own goal seen, navigator,
        #: teammate, ghost, trouble helper)
        self.mode_steps: dict[str, int] = {}
        #: steps heading straight to a seen point, and steps where its corridor was blocked and
        #: the robot slid along the free direction nearest to it (see :meth:`_head_to`)
        self.slide_steps = 0
        #: times the point headed for (a teammate, a ghost or a trouble helper) changed
        self.temp_switches = 0
        self._temp_key: Any = None

    # ------------------------------------------------------------------ sensing helpers
    # Speed (H7a): the pose is kept as Python floats with its cosine and sine, once per step
    # (``_px``, ``_py``, ``_th``, ``_c``, ``_s``), and the scan as float64 arrays (``_r64``,
    # ``_a64``); the per-point tests run in numba kernels. Same arithmetic in the same order as
    # before: the results are bit-identical (benchmarks/los_fingerprint.py).
    def _set_pose(self, pose: np.ndarray) -> None:
        self._pose = pose
        self._px, self._py, self._th = float(pose[0]), float(pose[1]), float(pose[2])
        self._c, self._s = math.cos(self._th), math.sin(self._th)

    def _odom_to_body(self, x: float, y: float) -> XY:
        dx, dy = x - self._px, y - self._py
        c, s = self._c, self._s
        return c * dx + s * dy, -s * dx + c * dy

    def _body_to_odom(self, pose, bx: float, by: float) -> XY:
        c, s = math.cos(pose[2]), math.sin(pose[2])
        return pose[0] + c * bx - s * by, pose[1] + s * bx + c * by

    def _set_scan(self, scan: RangeScan | None) -> None:
        self._scan = scan
        if scan is None:
            return
        angles = scan.angles_rad
        if self._gap_for is not angles:  # the beam layout rarely changes: measure its gaps once
            self._a64 = np.ascontiguousarray(angles, dtype=np.float64)
            self._gap_for, self._gap_rad = angles, max_beam_gap(self._a64)
        self._r64 = np.ascontiguousarray(scan.ranges_m, dtype=np.float64)
        self._max_range = float(scan.max_range_m)

    def _sees(self, x: float, y: float, margin_m: float = 0.0) -> bool:
        """V(R): the point (own frame) is in sight, from this step's omnidirectional scan (§2)
        (:func:`~.goal_sharing.point_visible`)."""
        if self._scan is None:
            return False
        dx, dy = x - self._px, y - self._py  # _odom_to_body, inline (speed: ~5 calls per step)
        c, s = self._c, self._s
        bx, by = c * dx + s * dy, -s * dx + c * dy
        d = math.hypot(bx, by)
        if d > self.vis_radius_m:
            return False
        if d < 1e-9:
            return True
        return nearest_beam_visible(self._vis_r64, self._a64, d, math.atan2(by, bx), margin_m, self._gap_rad)

    def _keeps(self, x: float, y: float) -> bool:
        """The lenient test that keeps a goal already seen directly (``keep_direct_view``): in
        range and *some* beam within 1.5 beam spacings of its bearing reaches past it."""
        if self._scan is None:
            return False
        dx, dy = x - self._px, y - self._py  # _odom_to_body, inline
        c, s = self._c, self._s
        bx, by = c * dx + s * dy, -s * dx + c * dy
        d = math.hypot(bx, by)
        if d > self.vis_radius_m:
            return False
        if d < 1e-9:
            return True
        return beam_near_reaches(self._vis_r64, self._a64, d, math.atan2(by, bx), 1.5 * max(self._gap_rad, 1e-6))

    def _me_xy(self) -> XY:
        return self._px, self._py

    def set_pose_cov(self, cov) -> None:
        """This step's covariance (3 x 3) of the pose ``odom_pose`` carries: ``localized-v1`` calls it
        with its filter's sample covariance before each step (frame_source "fused" reads it)."""
        self._pose_cov = None if cov is None else np.array(cov, dtype=np.float64).reshape(3, 3)

    # ------------------------------------------------------------------ the step
    def step(self, obs: Observation) -> tuple[Action, list[Message]]:
        """One step (see the module docstring)."""
        try:
            scan = obs.scans[self.params.laser]
        except KeyError:
            raise ValueError(
                f"observation of robot {obs.robot_id} must carry scan {self.params.laser!r}, has {sorted(obs.scans)}"
            ) from None
        self._set_scan(scan)
        self._set_pose(np.asarray(obs.odom_pose, dtype=np.float64).copy())
        self._step = step = int(obs.step)
        sightings = {}
        my_id = self.me
        for det in obs.detections:
            rid = det.robot_id
            if rid is None or rid == my_id:
                continue  # without an identity a teammate cannot be paired with its messages
            sightings[int(rid)] = (float(det.range_m), float(det.bearing_rad))
        history = self._history
        history[step] = ((self._px, self._py, self._th), sightings)
        limit = step - _HISTORY_STEPS
        for old in [k for k in history if k <= limit]:
            del history[old]
        if self.params.frame_source == "fused":
            self._cov_history[step] = self._pose_cov
            for old in [k for k in self._cov_history if k <= step - _HISTORY_STEPS]:
                del self._cov_history[old]
        px, py, c, sn = self._px, self._py, self._c, self._s
        seen_now = {}
        for rid, (r, b) in sightings.items():
            bx, by = r * math.cos(b), r * math.sin(b)
            seen_now[rid] = (px + c * bx - sn * by, py + sn * bx + c * by)
        self._seen_now = seen_now
        self._vis_r64 = self._r64
        self._nav_scan = self._scan
        if sightings and self._scan is not None:
            det = np.array(list(sightings.values()), dtype=np.float64)
            if self.params.see_past_teammates:
                self._vis_r64 = see_past_teammates(self._r64, self._a64, self._max_range, det[:, 0], det[:, 1],
                                                   self.radius_m)
            beyond = self.params.navigate_past_teammates_beyond_m
            if beyond is not None:
                far = det[det[:, 0] > beyond]
                if far.shape[0]:
                    nav_r = see_past_teammates(self._r64, self._a64, self._max_range, far[:, 0], far[:, 1],
                                               self.radius_m)
                    self._nav_scan = RangeScan(nav_r, self._scan.angles_rad, self._scan.max_range_m)

        if self.params.goal_sharing:
            self.sharing.begin_step()
        self._advance_task()
        self._receive(obs)
        me = self._me_xy()
        if self.params.goal_sharing:
            self.sharing.refresh(me, self._prev_xy, self._sees, int(obs.step),
                                 keeps=self._keeps if self.params.keep_direct_view else None)
        action = self._decide(obs)
        if action.direction_rad is not None:
            self.moves += 1
        self.mode_steps[self.mode] = self.mode_steps.get(self.mode, 0) + 1
        outbox = self._broadcast(obs, sightings)
        self._prev_xy = me
        return action, outbox

    @abc.abstractmethod
    def _advance_task(self) -> None:
        """Move on along the robot's own task (R1: next target; a helper: next patrol point)."""

    @abc.abstractmethod
    def _decide(self, obs: Observation) -> Action:
        """This step's motion (R1: own goal, teammate, ghost or trouble helper; a helper: patrol)."""

    # ------------------------------------------------------------------ receive path (§3.1)
    def _receive(self, obs: Observation) -> None:
        """Read the inbox: frames from mutual bearings, Id rule, D arbitration, Tr bits."""
        self._teammate_tr = {}
        self._teammate_tr_xy = {}
        me = self.me
        history = self._history
        goal_sharing = self.params.goal_sharing
        by_bearings = self.params.frame_source == "bearings"
        receive_goal, receive_report = self.sharing.receive_goal, self.sharing.receive_report
        for msg in obs.inbox:
            body = msg.body
            if not isinstance(body, LosHelpMsg) or msg.sender == me:
                continue
            self.msgs_received += 1
            s = int(msg.sender)
            if body.trouble is not None:
                self._teammate_tr[s] = bool(body.trouble)
                sent = history.get(int(body.step))
                if sent is not None and s in sent[1]:
                    rng_s, b_s = sent[1][s]
                    self._teammate_tr_xy[s] = self._body_to_odom(sent[0], rng_s * math.cos(b_s), rng_s * math.sin(b_s))
            if not goal_sharing:
                continue
            hist = history.get(int(body.step))
            if by_bearings:
                rel = self._bearing_frame(body, hist, s)
                if rel is None:
                    continue  # no mutual sighting at the sending step: no frame
            else:
                if hist is None or body.pose is None:
                    continue  # no pose of mine at the sending step, or none sent: no frame
                rel = self._frame_from_poses(body, hist, s)
            (kx, ky, kth), seen_k = hist
            ck, sk = math.cos(kth), math.sin(kth)
            r0, r1 = rel[0], rel[1]
            sender_xy = (kx + ck * r0 - sk * r1, ky + sk * r0 + ck * r1)
            c, sn = math.cos(rel[2]), math.sin(rel[2])
            for g in body.goals:
                if g.owner == me:
                    continue
                bx, by = r0 + c * g.gx_m - sn * g.gy_m, r1 + sn * g.gx_m + c * g.gy_m
                receive_goal(g.owner, g.goal_id, (kx + ck * bx - sk * by, ky + sk * bx + ck * by))
            me_k = (kx, ky)
            step_k = int(body.step)
            for r in body.reports:
                via = None
                if r.via_d_m is not None:
                    bx, by = r0 + c * r.via_x_m - sn * r.via_y_m, r1 + sn * r.via_x_m + c * r.via_y_m
                    via = (kx + ck * bx - sk * by, ky + sk * bx + ck * by)
                receive_report(r.owner, r.goal_id, s, sender_xy, r.d_m, me_xy=me_k, step=step_k, via_xy=via,
                               via_d_m=r.via_d_m)

    def _bearing_frame(self, body: LosHelpMsg, hist, sender: int) -> tuple[float, float, float] | None:
        """§3.1: the sender's body frame in mine at the sending step from the mutual bearings,
        θ21 = 180° + α21 − α12; None when I did not see the sender then (``hist``: my pose and
        sightings of that step) or it did not see me."""
        if hist is None or sender not in hist[1]:
            return None
        back = None
        for sg in body.sightings:
            if sg.robot_id == self.me:
                back = sg
                break
        if back is None:
            return None
        rng_m, bearing = hist[1][sender]
        return sender_frame(bearing, back.bearing_rad, rng_m)

    def _frame_from_poses(self, body: LosHelpMsg, hist, sender: int) -> tuple[float, float, float]:
        """frame_source "mcl" / "fused": the sender's body frame in mine at the sending step from
        the two poses; "fused" combines it with §3.1's bearing frame when both robots saw each
        other then (:mod:`teamnav.papers.beyond.brains.localized_los`)."""
        from teamnav.papers.beyond.brains import localized_los as LL

        own = hist[0]
        rel = LL.frame_from_poses(own, body.pose)
        self.frames_from_poses += 1
        by_b = self._bearing_frame(body, hist, sender) if self.params.frame_source == "fused" else None
        if by_b is None:
            return rel
        rng_m, bearing = hist[1][sender]
        size = self.params.frame_robot_size_m or 2.0 * self.radius_m
        cov_b = LL.bearing_frame_cov(rng_m, bearing, self.params.frame_err_max, size)
        zero = np.zeros((3, 3))
        own_cov = self._cov_history.get(int(body.step))
        snd_cov = LL.cov_from_upper(body.pose_cov) if body.pose_cov is not None else zero
        cov_m = LL.pose_frame_cov(own, zero if own_cov is None else own_cov, body.pose, snd_cov)
        self.frames_fused += 1
        return LL.fuse_frames(rel, cov_m, by_b, cov_b)[0]

    # ------------------------------------------------------------------ broadcast (§4.4)
    def _broadcast(self, obs: Observation, sightings: dict[int, tuple[float, float]]) -> list[Message]:
        p = self.params
        if not sightings or not (p.goal_sharing or p.state_sharing):
            return []
        goals: tuple[GoalShare, ...] = ()
        reports: tuple[VisReport, ...] = ()
        sights: tuple[Sighting, ...] = ()
        if p.goal_sharing:
            sights = tuple([Sighting(rid, b, r) for rid, (r, b) in sorted(sightings.items())])
            # _odom_to_body of each point, inline (speed; the same operations)
            px, py, c, s = self._px, self._py, self._c, self._s
            goals = tuple([GoalShare(owner, gid, c * (x - px) + s * (y - py), -s * (x - px) + c * (y - py))
                           for owner, gid, x, y in self.sharing.shares()])
            if p.share_via:
                reports = tuple([VisReport(owner, gid, d, c * (vx - px) + s * (vy - py), -s * (vx - px) + c * (vy - py), vd)
                                 for owner, gid, d, vx, vy, vd in self.sharing.reports_via((px, py))])
            else:
                reports = tuple(VisReport(owner, gid, d) for owner, gid, d in self.sharing.reports(self._me_xy()))
        tr = bool(self.trouble.tr) if p.state_sharing else None
        if p.frame_source == "bearings":
            body = LosHelpMsg(int(obs.step), sights, goals, reports, tr)
        else:  # beyond the paper: the sender's pose (and its covariance) for the receiver's frame
            cov = None
            if p.frame_source == "fused" and self._pose_cov is not None:
                from teamnav.papers.beyond.brains.localized_los import cov_upper

                cov = cov_upper(self._pose_cov)
            body = LosHelpMsg(int(obs.step), sights, goals, reports, tr, (self._px, self._py, self._th), cov)
        msg = Message(self.me, float(obs.time_s), body, kind=MESSAGE_KIND)
        self.msgs_sent += 1
        self.bytes_sent += message_size_bytes(body)
        return [msg]

    # ------------------------------------------------------------------ motion (the rest: .driving)
    def _navigator(self):
        """Algorithm A, built on first use by this module's :func:`make_navigator` (which tests
        replace); :class:`~.driving._Driving` drives with it."""
        if self._nav is None:
            self._nav = make_navigator(self.params.navigator, dict(self.params.navigator_params), rng=self._rng,
                                       step_length_m=self.step_m, radius_m=self.radius_m)
        return self._nav

    # ------------------------------------------------------------------ logs
    def _layers(self) -> dict[str, Any]:
        if not self.params.log_layers:
            return {}
        goal = self.sharing.own_goal
        ghosts = [(p.px_m, p.py_m) for p in self.sharing.points() if p.kind != "direct"]
        return {
            "los_goal": {"kind": "markers", "frame": "odom", "hold": True,
                         "data": np.array([goal], dtype=np.float64) if goal is not None else np.zeros((0, 2)),
                         "description": "Sgorbissa & Arkin: the robot's current goal (target or patrol waypoint)"},
            "los_ghosts": {"kind": "markers", "frame": "odom", "hold": True,
                           "data": np.array(ghosts, dtype=np.float64).reshape(-1, 2),
                           "description": "Sgorbissa & Arkin §4: ghost robots and own past viewpoints kept for goals"},
        }

    def _common_log(self) -> dict[str, Any]:
        own = self.sharing.path(self.me)
        return {
            "mode": self.mode,
            "moves": int(self.moves),
            "tr": bool(self.trouble.tr),
            "pr": int(self.trouble.pr),
            "nt": int(self.trouble.nt),
            "msgs_sent": int(self.msgs_sent),
            "bytes_sent": int(self.bytes_sent),
            "msgs_received": int(self.msgs_received),
            "nav_restarts": int(self.nav_restarts),
            "known_goals": len(self.sharing.known),
            "ghosts": sum(1 for p in self.sharing.points() if p.kind != "direct"),
            "own_d_m": float(own.distance_m(self._me_xy())) if own is not None else -1.0,
            **{f"steps_{m}": int(n) for m, n in sorted(self.mode_steps.items())},
            "slide_steps": int(self.slide_steps),
            "temp_switches": int(self.temp_switches),
        }
