"""Goal sharing: reflected and delayed visibility, ghost robots (Sgorbissa & Arkin §3–§4).

Paper: A. Sgorbissa and R. C. Arkin, "Local navigation strategies for a team of robots".

Every robot runs the same five rules (§3, generalised to moving robots in §4):

1. *Share my goal* — broadcast the current goal G_k with ``Id = k·M`` (§3.1).
2. *Share other robots' goals* — relay every goal it knows with ``Id − 1`` (§3.1); a robot
   accepts a report of robot l's goal only if its Id is ≥ the one stored for l (§3.1, §4.1),
   so a second-hand report never overrides a direct one, and a new goal (k + 1) always
   replaces the old one.
3. *Check visibility* — for every known goal, report the estimated path length D to it (§3
   rule 3, §4.2).
4. *Reflect visibility* — a robot that hears "I see G with D_j" from R_j, which it sees,
   sees G by reflection with ``D = dist(me, R_j) + D_j`` (§4.2) and reports that in turn.
5. *Head to goal* — the goal's owner heads to the robot (or ghost) that offers the shortest D,
   or straight to G when it sees it (no reported D can be shorter, §3.1).

Memory of a robot about one goal is a :class:`GoalPath`: a *point* from which the goal is
seen and the promised distance ``d_point_m`` from that point to the goal; the robot's own
estimate is ``D = dist(me, point) + d_point_m``. The three kinds of point:

- ``"direct"``: the goal itself (``d_point_m = 0``) while the robot sees it (§2 point 4);
- ``"self"``: the robot's own last position from which the goal (or the previous point) was
  visible — the §4.3 bookkeeping: "R_i recalls the last position R_i(t1) from which G was
  visible and computes D(t1) = dist(R_i(t1), G) ... D = D(t1) + dist(R_i, R_i(t1)); if
  R_i(t1) is no longer visible, R_i(t1), D(t1) are substituted with R_i(t2), D(t2)";
- ``"ghost"``: the position a teammate had when it promised its D (§4.2, Fig. 7).

Delayed visibility V_D (``delayed=True``) keeps these points across steps ("ghost robots");
reflected visibility only (``delayed=False``) forgets every non-direct point at the start of
each step, so only teammates that report *now* count (V_R, §3).

Gaps filled here (the paper is silent; written down as the style guide asks):

- The §4.3 substitution rule is applied to any point that goes out of sight, ghosts included
  (a ghost is "a robot which sees the goal", Fig. 8), by robots relaying others' goals. The
  owner of a goal does not substitute: it heads to its point (the brain drives there), and when
  it loses a direct view of its own goal it falls back to its navigator.
- A relay is sent only while the hop count ``Nr = Id − (k − 1)·M`` is above 1, so a relayed Id
  never falls into the range of the previous goal (§3.1: Nr = 1 when all robots handled it);
  ``relay_hop_limit=False`` relays every known goal with ``Id − 1`` as §3.1 writes it.
- A report is matched to a stored goal by goal index ``k = 1 + (Id − 1) // M``.
- "Sees a point": within the visibility radius and the omnidirectional range reading along
  the point's bearing is at least the distance to it minus ``margin_m`` (0 for goals; a robot
  radius or two for points a teammate may be standing on).

Memory is O(M): at most one :class:`KnownGoal` and one :class:`GoalPath` per robot (§4.4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Callable, Iterable

import numpy as np
from numba import njit

from teamnav.control.nav.local.base import mod_two_pi
from teamnav.control.types import _fast_frozen_init
from teamnav.geometry.bearings import relative_frame_from_bearings, transform_goal
from teamnav.geometry.se2 import compose, transform_points

__all__ = [
    "GoalPath",
    "GoalSharing",
    "KnownGoal",
    "accept_goal_id",
    "beam_near_reaches",
    "nearest_beam_visible",
    "goal_in_own_frame",
    "see_past_teammates",
    "sender_frame",
    "sender_pose_in_own_frame",
    "can_relay",
    "goal_id",
    "goal_index",
    "hops",
    "max_beam_gap",
    "point_visible",
    "relayed_id",
]


# ------------------------------------------------------------------ identifiers (§3.1)
def goal_id(k: int, team_size: int) -> int:
    """``Id_k = k·M``: the identifier of a robot's k-th goal (k ≥ 1) when shared first-hand (§3.1).

    Examples
    --------
    >>> goal_id(3, 4)
    12
    """
    if k < 1 or team_size < 1:
        raise ValueError(f"goal_id: k and team_size must be >= 1, got k={k!r}, team_size={team_size!r}")
    return int(k) * int(team_size)


def relayed_id(gid: int) -> int:
    """``Id − 1``: the identifier a robot attaches when it relays another robot's goal (§3.1)."""
    return int(gid) - 1


def goal_index(gid: int, team_size: int) -> int:
    """``k = 1 + (Id − 1) / M`` (integer division): which goal of its owner ``gid`` names (§3.1).

    Examples
    --------
    >>> [goal_index(i, 4) for i in (8, 7, 5, 4)]
    [2, 2, 2, 1]
    """
    return 1 + (int(gid) - 1) // int(team_size)


def hops(gid: int, team_size: int) -> int:
    """``Nr = Id − (k − 1)·M``: M for a first-hand report, one less per relay (§3.1)."""
    return int(gid) - (goal_index(gid, team_size) - 1) * int(team_size)


def can_relay(gid: int, team_size: int) -> bool:
    """Whether a goal stored with ``gid`` may be relayed (its ``Id − 1`` still names goal k)."""
    return hops(gid, team_size) > 1


def accept_goal_id(stored: int | None, new: int) -> bool:
    """§3.1/§4.1: accept a report of a robot's goal only if its Id is ≥ the stored one."""
    return stored is None or int(new) >= int(stored)


# ------------------------------------------------------------------ frames (§3.1)
def sender_pose_in_own_frame(own_pose, bearing_sender_in_me_rad: float, bearing_me_in_sender_rad: float,
                             distance_m: float) -> np.ndarray:
    """Pose (x, y, θ) of the sender's body frame in the receiver's own odometry frame (§3.1).

    The receiver's pose ``own_pose`` (own odometry frame) and its bearing of the sender are of
    the step the sender sent at; the sender's bearing of the receiver comes in the message.
    θ21 = 180° + α21 − α12 (:func:`teamnav.geometry.bearings.relative_frame_from_bearings`).

    Examples
    --------
    >>> sender_pose_in_own_frame([1.0, 0.0, 0.0], 0.0, 0.0, 2.0).round(12).tolist()
    [3.0, 0.0, 3.14159265359]
    """
    rel = relative_frame_from_bearings(bearing_sender_in_me_rad, bearing_me_in_sender_rad, distance_m)
    return compose(np.asarray(own_pose, dtype=np.float64), rel)


def sender_frame(bearing_sender_in_me_rad: float, bearing_me_in_sender_rad: float,
                 distance_m: float) -> tuple[float, float, float]:
    """Scalar twin of :func:`teamnav.geometry.bearings.relative_frame_from_bearings` (same formula,
    §3.1 θ21 = 180° + α21 − α12): the sender's body frame (x, y, θ) in the receiver's body frame.

    The brains call it once per received message; the tests check it equals the array version.

    Examples
    --------
    >>> [round(v, 12) for v in sender_frame(0.0, 0.0, 2.0)]
    [2.0, 0.0, 3.14159265359]
    """
    theta = math.pi + bearing_sender_in_me_rad - bearing_me_in_sender_rad
    theta = math.atan2(math.sin(theta), math.cos(theta))
    if theta <= -math.pi:
        theta = math.pi
    return (distance_m * math.cos(bearing_sender_in_me_rad), distance_m * math.sin(bearing_sender_in_me_rad), theta)


def goal_in_own_frame(goal_in_sender_body, own_pose, bearing_sender_in_me_rad: float,
                      bearing_me_in_sender_rad: float, distance_m: float) -> np.ndarray:
    """A point the sender gave in its body frame, in the receiver's own odometry frame (§3.1).

    ``G_1,2 = T_21 G_1,1`` through :func:`teamnav.geometry.bearings.transform_goal`, then the
    receiver's pose at the sending step.

    Examples
    --------
    R2 2 m ahead of R1 and facing it; a goal 1 m in front of R2 is 1 m in front of R1:

    >>> goal_in_own_frame([1.0, 0.0], [0.0, 0.0, 0.0], 0.0, 0.0, 2.0).round(12).tolist()
    [1.0, 0.0]
    """
    in_body = transform_goal(np.asarray(goal_in_sender_body, dtype=np.float64), bearing_sender_in_me_rad,
                             bearing_me_in_sender_rad, distance_m)
    return transform_points(np.asarray(own_pose, dtype=np.float64), in_body)


# ------------------------------------------------------------------ visibility (§2)
def point_visible(point_body_xy, ranges_m: np.ndarray, angles_rad: np.ndarray, radius_m: float,
                  margin_m: float = 0.0, max_gap_rad: float | None = None) -> bool:
    """Whether the robot sees a point, from its own omnidirectional range scan (§2, V(R_i)).

    The point is seen when it is within ``radius_m`` (the visibility radius) and the reading of
    the beam nearest its bearing is at least its distance minus ``margin_m`` (nothing in
    between). A point whose bearing falls between beams farther than ``max_gap_rad`` from the
    nearest one (outside a limited field of view) is not seen.

    Parameters
    ----------
    point_body_xy : array_like of shape (2,)
        The point [m] in the robot's body frame.
    ranges_m, angles_rad : ndarray of shape (B,)
        The scan (no return = max range).
    radius_m : float
        Visibility radius [m].
    margin_m : float
        Tolerance [m] (0 for goals; about a robot diameter for a point a teammate stands on).
    max_gap_rad : float, optional
        Largest bearing error accepted [rad]; default: the largest gap between adjacent beams
        (at least 2°).

    Examples
    --------
    >>> angles = np.linspace(-np.pi, np.pi, 360, endpoint=False)
    >>> ranges = np.full(360, 10.0); ranges[np.abs(angles) < 0.1] = 2.0   # a wall 2 m ahead
    >>> point_visible([1.5, 0.0], ranges, angles, 8.0), point_visible([3.0, 0.0], ranges, angles, 8.0)
    (True, False)
    """
    x, y = float(point_body_xy[0]), float(point_body_xy[1])
    d = math.hypot(x, y)
    if d > radius_m:
        return False
    if d < 1e-9:
        return True
    b = math.atan2(y, x)
    angles = np.ascontiguousarray(angles_rad, dtype=np.float64)
    if max_gap_rad is None:
        max_gap_rad = max_beam_gap(angles)
    return nearest_beam_visible(np.ascontiguousarray(ranges_m, dtype=np.float64), angles, d, b, float(margin_m),
                                float(max_gap_rad))


_TWO_PI = 2 * math.pi


@njit(cache=True)
def nearest_beam_visible(ranges_m, angles_rad, d_m, bearing_rad, margin_m, max_gap_rad):
    """The core of :func:`point_visible` (numba): the beam nearest ``bearing_rad`` (the first
    of equals, as ``np.argmin``) reads at least ``d_m − margin_m``, and lies within
    ``max_gap_rad`` of it. Angular distance ``|mod(angle − b + π, 2π) − π|`` as numpy computes it."""
    n = angles_rad.shape[0]
    if n == 0:
        raise ValueError("attempt to get argmin of an empty sequence")
    best = 0
    best_diff = abs(mod_two_pi(angles_rad[0] - bearing_rad + math.pi) - math.pi)
    if best_diff == best_diff:  # NaN: np.argmin returns the first NaN
        for i in range(1, n):
            diff = abs(mod_two_pi(angles_rad[i] - bearing_rad + math.pi) - math.pi)
            if diff != diff:
                best, best_diff = i, diff
                break
            if diff < best_diff:
                best, best_diff = i, diff
    if best_diff > max_gap_rad:
        return False
    return ranges_m[best] >= d_m - margin_m


@njit(cache=True)
def beam_near_reaches(ranges_m, angles_rad, d_m, bearing_rad, max_diff_rad):
    """Some beam within ``max_diff_rad`` of ``bearing_rad`` reads at least ``d_m`` (numba; the
    brains' lenient ``keep_direct_view`` test)."""
    for i in range(angles_rad.shape[0]):
        diff = abs(mod_two_pi(angles_rad[i] - bearing_rad + math.pi) - math.pi)
        if diff <= max_diff_rad and ranges_m[i] >= d_m:
            return True
    return False


@njit(cache=True)
def see_past_teammates(ranges_m, angles_rad, max_range_m, ranges_det_m, bearings_det_rad, radius_m):
    """A copy of ``ranges_m`` in which the beams that end on a detected teammate read what the
    beams beside its body read (numba): the scan the brains' visibility tests use with
    ``see_past_teammates``.

    A beam is taken to end on the teammate detected at (``ranges_det_m[j]``,
    ``bearings_det_rad[j]``, body frame) when its bearing is within ``2 atan(1.5 radius / d)``
    of the detected bearing and its reading is at most ``1.7 d + 2 radius``. Why these bounds:
    the teammate subtends ``atan(radius / d_r)`` each side, eq. 2's bearing error adds up to
    as much again, and eq. 1's range error is at most ``err_max d_r`` with the paper's largest
    ``err_max = 0.4`` (``d_r <= d / 0.6``); the detector reports a teammate only in line of
    sight, so no wall stands between (§2). Teammates share the observer's radius (the paper's
    robots are identical). What lies behind the body is unknown to the laser: such a beam
    reads the smaller of the two nearest unmasked beams on either side (the body's flanks),
    so a wall seen past both flanks stays a wall; with every beam masked it keeps its reading.
    ``angles_rad`` must be sorted (a scan's beam order).
    """
    n = angles_rad.shape[0]
    out = ranges_m.copy()
    masked = np.zeros(n, dtype=np.bool_)
    any_masked = False
    for j in range(ranges_det_m.shape[0]):
        d = max(ranges_det_m[j], 1e-6)
        half = 2.0 * math.atan(1.5 * radius_m / d)
        reach = 1.7 * d + 2.0 * radius_m
        for i in range(n):
            diff = abs(mod_two_pi(angles_rad[i] - bearings_det_rad[j] + math.pi) - math.pi)
            if diff <= half and ranges_m[i] <= reach:
                masked[i] = True
                any_masked = True
    if not any_masked:
        return out
    for i in range(n):
        if not masked[i]:
            continue
        left = -1.0
        for k in range(1, n):
            m = (i - k) % n
            if not masked[m]:
                left = ranges_m[m]
                break
        if left < 0.0:
            continue  # every beam is masked
        right = left
        for k in range(1, n):
            m = (i + k) % n
            if not masked[m]:
                right = ranges_m[m]
                break
        out[i] = min(max_range_m, left, right)
    return out


def max_beam_gap(angles: np.ndarray) -> float:
    """Largest gap [rad] between adjacent beams (the blind sector of a limited field of view excluded)."""
    if angles.size < 2:
        return math.radians(2.0)
    a = np.sort(np.mod(angles, 2 * math.pi))
    gaps = np.diff(np.concatenate([a, a[:1] + 2 * math.pi]))
    gaps.sort()
    g = float(gaps[-1])
    if g > 2.0 * float(np.median(gaps)):  # the blind sector of a limited field of view
        g = float(gaps[-2])
    return max(g, 1e-6)


# ------------------------------------------------------------------ memory (§4.2–§4.4)
@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class KnownGoal:
    """Robot ``owner``'s goal as this robot stores it: identifier and position in its own frame."""

    owner: int
    goal_id: int
    gx_m: float
    gy_m: float


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class GoalPath:
    """Where a robot believes one goal is seen from (see the module docstring).

    Attributes
    ----------
    goal_id : int
        The goal this path leads to (matched by goal index).
    px_m, py_m : float
        The point [m] in the robot's own odometry frame.
    d_point_m : float
        Promised path length [m] from the point to the goal.
    kind : str
        ``"direct"``, ``"self"`` (§4.3) or ``"ghost"`` (§4.2).
    source : int
        Robot that made the promise (this robot for direct/self).
    step : int
        Step of the promise.
    reached : bool
        The owner has reached the point without seeing its goal; kept only to arbitrate.
    """

    goal_id: int
    px_m: float
    py_m: float
    d_point_m: float
    kind: str
    source: int
    step: int
    reached: bool = False
    d_promised_m: float = math.inf
    via_x_m: float | None = None
    via_y_m: float | None = None
    via_d_m: float | None = None

    def distance_m(self, me_xy) -> float:
        """``D = dist(me, point) + d_point`` (§4.2, §4.3)."""
        return math.hypot(self.px_m - me_xy[0], self.py_m - me_xy[1]) + self.d_point_m


class GoalSharing:
    """One robot's goal-sharing memory and rules (§3–§4), independent of sensing and radio.

    The brain feeds it, in this order each step: :meth:`begin_step`; for each received
    message, :meth:`receive_goal` and :meth:`receive_report` (positions already mapped to its
    own frame through the mutual-bearing frame); :meth:`refresh` with its own visibility test;
    then :meth:`shares` / :meth:`reports` to build its broadcast.

    Parameters
    ----------
    robot_id : int
    team_size : int
        M in ``Id = k·M``.
    delayed : bool
        Delayed visibility V_D with ghost robots (§4) when True; reflected visibility only (§3).
    point_margin_m : float
        Tolerance [m] of the visibility test of stored points (a teammate may stand on one).
    report_margin_m : float
        A report replaces a stored (unreached) path only when its ``D`` is shorter by more than
        this [m]. Gap filled: §4.2 says "shorter"; a teammate walking along the light path
        (towards the goal's owner, or away from it) leaves ``dist + D_j`` unchanged, and with
        the lateral wobble of a real patrol every other step came out a few millimetres
        shorter: R1 followed a helper walking *away* from its goal (office_simple, Avoid-Past,
        task 3: 18 steps back along the corridor, then the target was lost). 0: the paper's
        strict rule.
    lead_on : bool
        Owner only: once the stored point is *reached* without seeing the goal, a report whose
        ``D`` is no longer than the robot's current ``D`` plus ``report_margin_m`` and whose
        point lies more than ``report_margin_m`` from the reached one is accepted (a teammate
        further along the same light path "leads on"; one behind the robot cannot, its
        ``dist + D_j`` counts the way back twice). Each point so accepted promises a
        strictly smaller distance, so the robot cannot loop. Gap filled: §4.2 only says the
        robot "will have to start again ... with A"; with the strict rule a chain of ghosts
        along a corridor was followed only to its first link (a tie). False: the paper's rule.
    relay_hop_limit : bool
        Relay a goal only while :func:`can_relay` (hop count above 1; gap filled, the default).
        False: §3.1 as written, every known goal with ``Id − 1`` (not an Id of 0, which names
        no goal).

    Examples
    --------
    R1 (id 0) of a team of 2 hears R2 report that it sees R1's goal 1 with D = 3 m, from 2 m away:

    >>> gs = GoalSharing(0, 2, delayed=True)
    >>> gs.set_own_goal(1, (10.0, 0.0))
    >>> gs.receive_report(0, 2, 1, (2.0, 0.0), 3.0, me_xy=(0.0, 0.0), step=5)
    True
    >>> p = gs.path(0); (p.kind, p.source, p.distance_m((0.0, 0.0)))
    ('ghost', 1, 5.0)
    """

    def __init__(self, robot_id: int, team_size: int, *, delayed: bool = True, point_margin_m: float = 0.5,
                 report_margin_m: float = 0.0, lead_on: bool = False, relay_hop_limit: bool = True) -> None:
        if team_size < 1:
            raise ValueError(f"team_size must be >= 1, got {team_size!r}")
        self.me = int(robot_id)
        self.team_size = int(team_size)
        self.delayed = bool(delayed)
        self.point_margin_m = float(point_margin_m)
        self.report_margin_m = float(report_margin_m)
        self.lead_on = bool(lead_on)
        self.relay_hop_limit = bool(relay_hop_limit)
        self.own_k: int | None = None
        self.own_goal: tuple[float, float] | None = None
        self.known: dict[int, KnownGoal] = {}
        self.paths: dict[int, GoalPath] = {}

    # ------------------------------------------------------------------ own goal
    @property
    def own_id(self) -> int | None:
        """``Id = k·M`` of the current own goal (None without a goal)."""
        k = self.own_k
        if k is None:
            return None
        if k < 1:
            return goal_id(k, self.team_size)  # raises
        return int(k) * self.team_size

    def set_own_goal(self, k: int | None, goal_xy=None) -> None:
        """Set the robot's own k-th goal (own frame), or none; a new k forgets the old path."""
        if k is None:
            self.own_k, self.own_goal = None, None
            self.paths.pop(self.me, None)
            return
        if k != self.own_k:
            self.paths.pop(self.me, None)
        self.own_k = int(k)
        self.own_goal = (float(goal_xy[0]), float(goal_xy[1]))

    def goal_of(self, owner: int) -> tuple[int, float, float] | None:
        """(Id, x, y) of ``owner``'s goal as stored here (own frame), or None."""
        if owner == self.me:
            if self.own_k is None:
                return None
            return self.own_id, self.own_goal[0], self.own_goal[1]
        g = self.known.get(owner)
        return None if g is None else (g.goal_id, g.gx_m, g.gy_m)

    def path(self, owner: int) -> GoalPath | None:
        """The stored path to ``owner``'s goal, or None."""
        return self.paths.get(owner)

    # ------------------------------------------------------------------ rules
    def begin_step(self) -> None:
        """Reflected visibility only (``delayed=False``): forget every non-direct point (§3)."""
        if not self.delayed:
            for owner in [o for o, p in self.paths.items() if p.kind != "direct"]:
                del self.paths[owner]

    def receive_goal(self, owner: int, gid: int, goal_xy) -> bool:
        """Rules 1–2 on the receiving side: store ``owner``'s goal if ``gid`` ≥ stored (§3.1, §4.1).

        A goal with a different goal index (a new goal of ``owner``) forgets the old path.
        Reports of this robot's own goal are ignored (it knows its goal). Returns whether the
        report was accepted.
        """
        if owner == self.me:
            return False
        old = self.known.get(owner)
        if old is not None:
            # accept_goal_id and goal_index, inline (speed: called per goal per message)
            og = int(old.goal_id)
            if not int(gid) >= og:
                return False
            m = int(self.team_size)
            if (og - 1) // m != (int(gid) - 1) // m:
                self.paths.pop(owner, None)
        self.known[owner] = KnownGoal(int(owner), int(gid), float(goal_xy[0]), float(goal_xy[1]))
        return True

    def receive_report(self, owner: int, gid: int, reporter: int, reporter_xy, d_m: float, *, me_xy,
                       step: int, via_xy=None, via_d_m: float | None = None) -> bool:
        """Rules 3–5 on the receiving side: arbitrate a visibility report by shortest D (§4.2).

        ``reporter`` at ``reporter_xy`` (own frame, where it was when it reported) sees
        ``owner``'s goal with path length ``d_m``. The candidate ``dist(me, reporter) + d_m``
        replaces the stored path only if it is strictly shorter than the stored ``D`` — also
        when the same robot reports again later (§4.2: the robot keeps heading to the ghost
        that promised the shortest path). A direct view is never replaced (§3.1).

        The stored ``D``: for the goal's owner, the smaller of the value stored when the path
        was adopted (§4.2: "R1 stores in its memory D11(t1) ... compares ... > D11(t1)") and its
        current ``dist(me, point) + d_point`` (it may have come closer since); so an owner that
        reached a ghost and wandered off with its navigator is not pulled back by a promise no
        better than the one it already followed (that made robots loop between a ghost and
        the navigator's detour). For a robot relaying another's goal, its current ``D`` (§4.3).
        ``via_xy`` (own frame) and ``via_d_m``: the point the reporter's D leads through and its
        own distance to the goal (see :class:`~.messages.VisReport`), kept with the path.
        Returns whether the report was accepted.
        """
        if not (math.isfinite(d_m) and d_m >= 0.0):
            return False
        # goal_of and goal_index, inline (speed: called per report per message)
        if owner == self.me:
            if self.own_k is None:
                return False
            stored_id = self.own_id
        else:
            g = self.known.get(owner)
            if g is None:
                return False
            stored_id = g.goal_id
        m = int(self.team_size)
        if (int(stored_id) - 1) // m != (int(gid) - 1) // m:
            return False
        path = self.paths.get(owner)
        cand = math.hypot(reporter_xy[0] - me_xy[0], reporter_xy[1] - me_xy[1]) + float(d_m)
        if path is not None:
            if path.kind == "direct":
                return False
            now = math.hypot(path.px_m - me_xy[0], path.py_m - me_xy[1]) + path.d_point_m  # path.distance_m
            margin = self.report_margin_m
            if owner == self.me and path.reached and self.lead_on:
                # a teammate further along the light path leads on (see ``lead_on``)
                if (cand > now + margin
                        or math.hypot(reporter_xy[0] - path.px_m, reporter_xy[1] - path.py_m) <= margin):
                    return False
            elif cand >= (min(now, path.d_promised_m) if owner == self.me else now) - margin:
                return False
        via = (None, None, None)
        if via_xy is not None and via_d_m is not None and math.isfinite(via_d_m):
            via = (float(via_xy[0]), float(via_xy[1]), float(via_d_m))
        self.paths[owner] = GoalPath(stored_id, float(reporter_xy[0]), float(reporter_xy[1]), float(d_m), "ghost",
                                     int(reporter), int(step), d_promised_m=cand,
                                     via_x_m=via[0], via_y_m=via[1], via_d_m=via[2])
        return True

    def go_via(self, owner: int, step: int) -> bool:
        """At the reached point of ``owner``'s path, go on to the reporter's via point.

        The path becomes the via point (not reached, no further via) with its own promised
        distance; returns False (nothing changed) when the path has no via point."""
        p = self.paths.get(owner)
        if p is None or p.via_d_m is None:
            return False
        self.paths[owner] = replace(p, px_m=p.via_x_m, py_m=p.via_y_m, d_point_m=p.via_d_m, reached=False,
                                    step=int(step), via_x_m=None, via_y_m=None, via_d_m=None)
        return True

    def refresh(self, me_xy, prev_me_xy, sees: Callable[[float, float, float], bool], step: int,
                keeps: Callable[[float, float], bool] | None = None) -> None:
        """Check visibility of every known goal and keep the §4.3 bookkeeping, once per step.

        Parameters
        ----------
        me_xy : (x, y)
            The robot's position now (own frame).
        prev_me_xy : (x, y) or None
            Its position at the previous step (from which every stored point was visible).
        sees : callable (x, y, margin_m) -> bool
            The robot's own visibility test of a point in its own frame.
        step : int
        keeps : callable (x, y) -> bool, optional
            A more lenient test that keeps a goal the robot already sees directly (hysteresis:
            a goal seen through a door at a slant flickers in and out of the one beam nearest
            its bearing as the robot moves; see the brain's ``keep_direct_view``). None: ``sees``.
        """
        # goal_of per owner, inline (speed): the own goal first, then the known ones in order
        goals = [(g.owner, g.goal_id, g.gx_m, g.gy_m) for g in self.known.values()]
        if self.own_k is not None:
            goals.insert(0, (self.me, self.own_id, self.own_goal[0], self.own_goal[1]))
        paths = self.paths
        me = self.me
        for owner, gid, gx, gy in goals:
            path = paths.get(owner)
            kept = (keeps is not None and path is not None and path.kind == "direct"
                    and (path.px_m, path.py_m) == (gx, gy) and keeps(gx, gy))
            if kept or sees(gx, gy, 0.0):  # rule 3: direct view (§2 point 4); beats any report (§3.1)
                paths[owner] = GoalPath(gid, gx, gy, 0.0, "direct", me, int(step))
                continue
            if path is None:
                continue
            if owner == me:
                if path.kind == "direct":  # the owner lost its view: back to its navigator
                    del self.paths[owner]
                continue
            if not self.delayed:
                if path.kind == "direct":
                    del self.paths[owner]
                continue
            if prev_me_xy is not None and (path.kind == "direct" or not sees(path.px_m, path.py_m, self.point_margin_m)):
                # §4.3: the point left the view: substitute the last own position from which it
                # was visible, with its distance to the goal.
                d_prev = math.hypot(path.px_m - prev_me_xy[0], path.py_m - prev_me_xy[1]) + path.d_point_m
                # (``replace(path, px_m=..., py_m=..., d_point_m=d_prev, kind="self", source=me,
                # step=step)``, written out: dataclasses.replace walks the fields each call)
                self.paths[owner] = GoalPath(path.goal_id, float(prev_me_xy[0]), float(prev_me_xy[1]), d_prev, "self",
                                             me, int(step), path.reached, path.d_promised_m, path.via_x_m,
                                             path.via_y_m, path.via_d_m)

    def mark_reached(self, owner: int) -> None:
        """The owner reached its path's point without seeing the goal: keep it only to arbitrate."""
        p = self.paths.get(owner)
        if p is not None:
            self.paths[owner] = replace(p, reached=True)

    # ------------------------------------------------------------------ outgoing (§4.4)
    def shares(self) -> list[tuple[int, int, float, float]]:
        """(owner, Id, x, y) terms to broadcast, in own frame: own goal with k·M, others with Id − 1."""
        out = []
        if self.own_k is not None:
            out.append((self.me, self.own_id, self.own_goal[0], self.own_goal[1]))
        m = int(self.team_size)
        limit = self.relay_hop_limit
        for g in self.known.values():
            gid = int(g.goal_id)
            # can_relay: hops(gid) > 1, inline (speed); without the limit (§3.1) any Id - 1 >= 1
            if (gid - ((gid - 1) // m) * m > 1) if limit else gid > 1:
                out.append((g.owner, gid - 1, g.gx_m, g.gy_m))
        return out

    def reports(self, me_xy) -> list[tuple[int, int, float]]:
        """(owner, Id, D) for every other robot's goal this robot sees (directly, V_R or V_D)."""
        return [(o, gid, d) for o, gid, d, _, _, _ in self.reports_via(me_xy)]

    def reports_via(self, me_xy) -> list[tuple[int, int, float, float, float, float]]:
        """(owner, Id, D, via_x, via_y, via_d) for every other robot's goal this robot sees:
        :meth:`reports` plus the point its D leads through (own frame) and that point's
        promised distance (see :class:`~.messages.VisReport`)."""
        mx, my = me_xy[0], me_xy[1]
        me = self.me
        return [(owner, p.goal_id, math.hypot(p.px_m - mx, p.py_m - my) + p.d_point_m, p.px_m, p.py_m, p.d_point_m)
                for owner, p in self.paths.items() if owner != me]

    def points(self) -> Iterable[GoalPath]:
        """All stored paths (for drawing)."""
        return self.paths.values()
