"""VisBug-21: algorithm A = 3 of Sgorbissa & Arkin §6.

Sgorbissa & Arkin §6 run "the VisBug21 algorithm [7]" (Lumelsky & Skewis 1990, "Incorporating
range sensing in the robot navigation function", IEEE Trans. SMC 20(5), pp. 1058-1068), which
"is guaranteed to find a path to the goal (whenever it exists) even when no helping robots
are present". VisBug-21 is Bug2 with a range sensor of radius ``r``: the robot keeps the
*M-line* from its start S to the target T and repeatedly moves to an *intermediate target*
``Ti`` computed from what it sees.

Our version, on an omnidirectional range scan and fixed-length steps:

Step 1 (``MODE_TO_GOAL``, "move towards Ti")
    ``Ti`` is the point of the M-line nearest T (sampled every ``mline_sample_m``, and not
    behind the last leave point) that the robot sees with a free corridor: the segment from
    the robot to it passes at least ``R = radius_m + safety_margin_m`` from every sensed
    point and is no longer than the sensor's range minus ``R``. A point sensed at range
    ``ρ`` counts as ``ρ · π / n_beams`` nearer (half the gap between two beams there: a
    wall corner can hide between two far beams). When T itself is such a point the robot
    heads straight for it. When no such ``Ti`` lies at least one step away, an obstacle
    blocks the M-line: the robot's position is the *hit point* H and Step 2 starts.
Step 2 (``MODE_FOLLOW``, "follow the boundary in the local direction")
    The robot follows the obstacle it hit, keeping it on its right (``turn="left"``, the
    default) or left, at ``R + follow_margin_m``: heading = tangent at the obstacle's
    nearest sensed point, turned towards or away from it in proportion to the distance
    error. The scan is cut into obstacles (neighbouring beams with close points) and the
    robot keeps following the one it hit, not whichever wall is nearest. At every step it
    looks for a *leave point* Q on the M-line such that

    - ``|QT| < d_H − leave_margin_m``, where ``d_H`` is the smallest hit distance so far
      for this goal (Bug2's progress argument needs every leave point closer than all
      earlier hit points);
    - Q is seen through a free corridor as in Step 1 but of half-width
      ``R + leave_hysteresis_m`` (hysteresis: a point at the edge of visibility would
      otherwise make the robot leave and hit again at every step), and is at least a step
      away or is T;
    - the M-line runs on free from Q (corridor half-width R) for ``leave_run_m`` or up to
      T (Bug2: "the robot can move towards T from Q"; we ask for a finite run: otherwise an
      M-line slipping into a door at an angle the robot cannot pass makes it leave, hit a
      few centimetres further on, and walk the whole boundary again, lap after lap);
    - that run was *seen* free (:func:`~teamnav.control.nav.local.base.seen_free`: points
      along it and ``RUN_SEEN_FRACTION · R`` to its sides lie in front of their beams'
      returns). No sensed point near the run is not enough: from the corridor a robot sees
      the near face of a door jamb, never its far side, and took an M-line point just
      inside a door as a leave point, hit the jamb's hidden face at once and walked the
      whole building again, lap after lap (R1 alone on ``office_simple``, task 4).

    It takes the such Q nearest to T (VisBug-21's shortcut: with range sensing the robot
    leaves for a visible M-line point instead of walking the boundary to it) and drives to
    Q before testing the M-line again (within ``2 d / step + 5`` steps), so that the next
    hit point lies on the M-line, closer to T, as in Bug2. Back within ``return_tol_m`` of H
    (after having been ``2·return_tol_m`` away) for the *second* time, T is unreachable
    (Bug2's termination test, taken on the second lap because our H lies off the followed
    path by up to a step: one pass near H while turning into a door next to it is not yet a
    closed lap); :meth:`direction` then returns None until a new goal is set.

The local direction (``turn``): Lumelsky & Skewis fix it a priori. With a fixed direction
R1 alone finished 0 of 5 ``los-help-simple`` tasks (10 targets, 1500 steps per target): in
an office every wrong guess is a lap of the whole building (~270 m, 1350 steps), as the
rooms' doors all sit on one side. Our default ``turn="nearer_end"`` chooses it afresh at
every hit point: towards the sensed end O of the hit obstacle (a door jamb, a corner's edge,
the range limit) with the shorter ``|xO| + |OT|`` (TangentBug's heuristic distance, Kamon,
Rimon & Rivlin 1998), and keeps it until the next leave. Completeness does not rest on the
direction: every hit is closer to T than the previous one by ``leave_margin_m`` and each
boundary walk ends at a leave point or back at H, whichever direction it takes.

Where we deviate: Lumelsky & Skewis also let ``Ti`` be the farthest visible point of the
obstacle boundary in the local direction (so a robot cuts across concave stretches of the
boundary); by default we follow the boundary reactively at a constant offset instead, since
the boundary is only known as scan points (``boundary_shortcut=True``, set by
``paper_rules``, restores their rule on the sensed points, :meth:`VisBug21._boundary_target`). The M-line shortcut above keeps VisBug's main gain
(leaving early for a visible M-line point). On a grid map and with fixed steps the
convergence proof does not carry over exactly; the leave margin keeps every leave point
strictly closer to T than its hit point, as in Bug2.

A new goal (:meth:`set_goal` with a goal more than 1 µm away from the current one) restarts
the algorithm: the M-line runs from wherever the robot is at the next :meth:`direction`
call (Sgorbissa & Arkin §3: a robot heading for a teammate resets its goal often; set as a
plain goal, each time VisBug starts over: see temporary goals below).

Temporary goals (``set_goal(g, temporary=True)``): Sgorbissa & Arkin send R1 to a teammate
or a ghost (§3 rule 5, §4.2) or to a helper (§5 rule 3, "R_j temporarily becomes R_i goal")
and back to its own goal; Fig. 9 says what happens back on it: R1 resumes algorithm A from
where the excursion left it ("once R1 has reached R2(t3), it is not in a better position for
finding a path to its goal, and gets trapped again"). The paper does not say whether A's
memory survives. We keep it: a temporary goal suspends the task's M-line, hit point H,
``d_H``, mode and lap count, runs a fresh VisBug to the temporary goal, and the task goal
set again resumes them (Bug2's progress memory is what makes it complete; restarting it at
every excursion made helpers *lengthen* R1's tasks). Back on the task the robot goes on
with the M-line and H of before, except when the excursion ended closer to T than
``d_H − leave_margin_m``: that point is as good as a leave point, and Bug2 starts over from
there (a new M-line; the distances at which it restarts fall each time, so Bug2's
progress argument still holds). Resuming a boundary walk more than ``RESUME_FOLLOW_M``
from where it was suspended, it takes Step 1 on the kept M-line instead (the nearest
obstacle there is not the one it was walking). A plain ``set_goal(g)`` with another goal drops the
suspended task (the old behaviour).

``progressing`` (§5): in Step 1, the distance to T beats its best-so-far for this goal
within ``progress_window_steps`` steps (as for the potential field); in Step 2, the walk
along the boundary since H is shorter than ``follow_patience_m`` (Lumelsky's progress is
made at leave points, each closer to T than its hit point; a boundary walk much longer
than expected is "trouble"); False once T is found unreachable.

Where the rest lives: the parameters, with the paper's values of our gap-fills
(``PAPER_RULES``), in :mod:`~teamnav.control.nav.local.visbug21_params`; the boundary-following
heading and the numba kernels of the scan geometry in
:mod:`~teamnav.control.nav.local.visbug21_geometry`; the numpy reference versions those kernels
replaced (for the equivalence tests) in :mod:`~teamnav.control.nav.local.visbug21_reference`.
"""

from __future__ import annotations

import math

import numpy as np

from teamnav.control.nav.local.base import (
    GOAL_SAME_TOL_M,
    ProgressMonitor,
    check_goal,
    check_pose,
    check_scan,
    safe_heading,
    scan_points,
    seen_free,
)
from teamnav.control.nav.local.visbug21_geometry import (
    FOLLOW_GAP_M,
    _follow_kernel,
    _boundary_pick,
    _last_visible,
    _leave_candidates,
    boundary_heading,
)
from teamnav.control.nav.local.visbug21_params import VisBugParams
from teamnav.control.nav.local.visbug21_reference import VisBugReference
from teamnav.control.types import RangeScan

__all__ = ["MODE_FOLLOW", "MODE_TO_GOAL", "MODE_UNREACHABLE", "VisBug21", "VisBugParams", "boundary_heading"]

MODE_TO_GOAL = 0
MODE_FOLLOW = 1
MODE_UNREACHABLE = 2
#: Back from a temporary goal farther than this [m] from where it left the boundary walk,
#: VisBug resumes with Step 1 (on the kept M-line and d_H), not the walk.
RESUME_FOLLOW_M: float = 1.0
#: Two ends' costs closer than this [m] are a tie for ``turn="nearer_end"``.
NEARER_END_TIE_M: float = 0.05
#: The leave test's run must be seen free this fraction of its half-width to either side.
RUN_SEEN_FRACTION: float = 0.8


class VisBug21(VisBugReference):
    """VisBug-21 local navigator (Sgorbissa & Arkin §6, algorithm 3; Lumelsky & Skewis 1990).

    Parameters
    ----------
    params : VisBugParams
    rng : numpy.random.Generator
        Used only with ``turn="random"`` (one draw per new goal).
    step_length_m : float
    radius_m : float

    Attributes
    ----------
    mode : int
        ``MODE_TO_GOAL``, ``MODE_FOLLOW`` or ``MODE_UNREACHABLE``.
    side : int
        +1: the followed obstacle is kept on the right (turn left at a hit), -1: on the left.
    mline : tuple of ndarray or None
        (S, T) of the current M-line, own frame.
    temporary : bool
        The current goal was set with ``temporary=True`` (a task goal is suspended).
    hit_xy : ndarray or None
        The current hit point H.

    The numpy reference versions of its fast paths (``_*_numpy``, ``_visible``, ``_sensed_ends``)
    come from :class:`~teamnav.control.nav.local.visbug21_reference.VisBugReference`.

    Examples
    --------
    >>> nav = VisBug21(VisBugParams(), np.random.default_rng(0), 0.1, 0.25)
    >>> nav.set_goal(np.array([3.0, 0.0]))
    >>> scan = RangeScan(np.full(72, 4.0), np.linspace(-np.pi, np.pi, 72, endpoint=False), 4.0)
    >>> round(nav.direction(np.array([0.0, 0.0, 2.0]), scan), 6), nav.mode
    (0.0, 0)
    """

    name = "visbug21"
    Params = VisBugParams

    def __init__(self, params: VisBugParams, rng: np.random.Generator, step_length_m: float,
                 radius_m: float) -> None:
        self.params = params
        self.rng = rng
        self.step_length_m = float(step_length_m)
        self.radius_m = float(radius_m)
        self.goal_xy: np.ndarray | None = None
        self.side = 1 if params.turn == "left" else -1
        self.temporary = False
        self._suspended: dict | None = None
        self._suspended_at: np.ndarray | None = None
        #: (task goal, reverse_walk_factor) set by start_again, kept while that goal stays
        self._reverse_for: tuple[np.ndarray, float] | None = None
        self._order_for = None
        self._samples_key = None
        self._dir_key = None
        self._monitor = ProgressMonitor(params.progress_window_steps, params.progress_fraction, self.step_length_m)
        self._restart()

    def _restart(self) -> None:
        self.mode = MODE_TO_GOAL
        self.mline: tuple[np.ndarray, np.ndarray] | None = None
        self.hit_xy: np.ndarray | None = None
        self.hit_dist_m = math.inf
        self._t_anchor = 0.0
        self._walked_m = 0.0
        self._left_hit = False
        self._returns = 0
        self._dir_walked_m = 0.0
        self._reverse_limit_m = math.inf
        self._reverse_reach_m = math.inf
        self._last_xy: np.ndarray | None = None
        self._leave_target: np.ndarray | None = None
        self._leave_steps = 0
        self._follow_ref: np.ndarray | None = None
        self._ends: tuple[np.ndarray, np.ndarray] | None = None
        self._blocked_xy: np.ndarray | None = None
        self._resumed = False
        self._monitor.reset()
        self._samples_key: tuple | None = None

    # the task's Bug2 memory, kept across a temporary goal
    _TASK_STATE = ("goal_xy", "side", "mode", "mline", "hit_xy", "hit_dist_m", "_t_anchor", "_walked_m",
                   "_left_hit", "_returns", "_dir_walked_m", "_reverse_limit_m", "_reverse_reach_m")

    # ------------------------------------------------------------------ protocol
    def set_goal(self, goal_xy: np.ndarray, temporary: bool = False) -> None:
        """Set the goal (own frame); a different goal restarts VisBug (new M-line, no hit point).

        ``temporary=True`` (a teammate, a ghost, a helper in §5: "R_j temporarily becomes R_i
        goal") suspends the current task goal with its M-line, hit point H, ``d_H`` and mode,
        and drives to the temporary goal with a fresh VisBug. Setting the suspended task goal
        again (``temporary=False``, the same point within ``GOAL_SAME_TOL_M``) resumes it (see
        the module docstring, "Temporary goals"); any other non-temporary goal drops it.
        """
        g = check_goal(goal_xy)
        same = self.goal_xy is not None and math.hypot(*(g - self.goal_xy)) <= GOAL_SAME_TOL_M
        if temporary:
            if same and self.temporary:
                return
            if self._suspended is None and self.goal_xy is not None and not self.temporary:
                self._suspended = {k: getattr(self, k) for k in self._TASK_STATE}
                self._suspended_at = None if self._last_xy is None else self._last_xy.copy()
            self.temporary = True
            self.goal_xy = g
            self._restart()
            return
        if same and not self.temporary:
            return
        task = self._suspended
        self._suspended = None
        self.temporary = False
        if task is not None and math.hypot(*(g - task["goal_xy"])) <= GOAL_SAME_TOL_M:
            self._restart()
            for k, v in task.items():
                setattr(self, k, v)
            self._resumed = True
            return
        self.goal_xy = g
        self._restart()
        if self._reverse_for is not None and math.hypot(*(g - self._reverse_for[0])) > GOAL_SAME_TOL_M:
            self._reverse_for = None
        if self.params.turn == "random":
            self.side = 1 if self.rng.random() < 0.5 else -1

    def start_again(self, reverse_walk_factor: float | None = None) -> None:
        """Forget the task goal's M-line, hit point and mode: the next step on the task goal
        starts VisBug afresh from where the robot is then (Sgorbissa & Arkin §4.2: at a ghost
        without its goal in sight the robot "will have to start again to explore the
        environment by relying on its own navigation algorithm A, possibly from a better
        position"). During a temporary goal, the suspended task memory is dropped instead, so
        that setting the task goal again starts afresh rather than resuming.

        ``reverse_walk_factor``: the boundary walks towards this task goal are alternating
        (see ``VisBugParams.reverse_walk_factor``) until the goal changes; None: the params'."""
        task_goal = self._suspended["goal_xy"] if self._suspended is not None else (
            None if self.temporary else self.goal_xy)
        if reverse_walk_factor is not None and task_goal is not None:
            self._reverse_for = (np.array(task_goal, dtype=np.float64), float(reverse_walk_factor))
        if self._suspended is not None or self.temporary:
            self._suspended = None
        elif self.goal_xy is not None:
            self._restart()

    @property
    def suspended_goal_xy(self) -> np.ndarray | None:
        """The task goal suspended by the current temporary goal (own frame), or None."""
        return None if self._suspended is None else self._suspended["goal_xy"]

    def _resume(self, xy: np.ndarray) -> None:
        """First step back on the task goal after a temporary one (module docstring)."""
        self._resumed = False
        if self.hit_xy is not None and math.hypot(*(self.goal_xy - xy)) < self.hit_dist_m - self.params.leave_margin_m:
            # the excursion ended closer to T than every hit point: as good as a leave point,
            # Bug2 starts over from here (its progress argument holds: d falls at each restart)
            self._restart()
        elif (self.mode == MODE_FOLLOW and self._suspended_at is not None
              and math.hypot(*(xy - self._suspended_at)) > RESUME_FOLLOW_M):
            # far from the boundary it was walking, "the nearest obstacle" is another one:
            # Step 1 on the kept M-line instead (a new hit keeps the smaller d_H)
            self.mode = MODE_TO_GOAL
        # else: M-line, H, d_H and the mode are those of before the excursion; the followed
        # obstacle is picked afresh (nearest) and the excursion's path is not boundary walk

    def direction(self, pose: np.ndarray, scan: RangeScan) -> float | None:
        """Heading of the next step (Step 1 or Step 2 above); None without a goal or once unreachable."""
        pose = check_pose(pose)
        scan = check_scan(scan)
        if self.goal_xy is None or self.mode == MODE_UNREACHABLE:
            return None
        xy = pose[:2]
        goal = self.goal_xy
        if self._resumed:
            self._resume(xy)
        if self.mline is None:
            self.mline = (xy.copy(), goal.copy())
        if self._last_xy is not None and self.mode == MODE_FOLLOW:
            lx = self._last_xy  # on scalars: the same subtractions as the arrays' (speed)
            step_m = math.hypot(xy[0] - lx[0], xy[1] - lx[1])
            self._walked_m += step_m
            self._dir_walked_m += step_m
        self._last_xy = xy.copy()
        self._monitor.update(math.hypot(goal[0] - xy[0], goal[1] - xy[1]))
        p = self.params
        points = scan_points(pose, scan)
        self._slack = math.pi / max(len(scan.ranges_m), 1)  # half the beam spacing [rad]
        r_safe = self.radius_m + p.safety_margin_m
        reach_m = float(scan.max_range_m) - r_safe

        heading: float | None = None
        if self.mode == MODE_FOLLOW:
            ti = self._leave_point(pose, scan, points, r_safe + p.leave_hysteresis_m, reach_m)
            if ti is not None:
                self.mode = MODE_TO_GOAL
                self._monitor.reset()
                self._leave_target = ti
                self._leave_steps = 2 * int(math.ceil(math.hypot(*(ti - xy)) / self.step_length_m)) + 5
            else:
                d_hit = math.hypot(xy[0] - self.hit_xy[0], xy[1] - self.hit_xy[1])
                if d_hit >= 2.0 * p.return_tol_m:
                    self._left_hit = True
                elif self._left_hit and d_hit <= p.return_tol_m:
                    self._left_hit = False
                    self._returns += 1
                    if self._returns >= 2:
                        self.mode = MODE_UNREACHABLE
                        return None
                if self._dir_walked_m > self._reverse_limit_m:
                    # alternating walk (``reverse_walk_factor``): back the other way, twice as far
                    self.side = -self.side
                    self._dir_walked_m = 0.0
                    self._reverse_limit_m = 3.0 * self._reverse_reach_m  # back to H, then twice as far
                    self._reverse_reach_m *= 2.0
                    self._left_hit = False
                    self._returns = 0
                followed = self._followed(pose, scan)
                heading = boundary_heading(xy, followed, r_safe + p.follow_margin_m, self.side, p.follow_gain)
                if heading is not None and p.boundary_shortcut:
                    bt = self._boundary_target(xy, followed, points, r_safe, r_safe + p.follow_margin_m, reach_m)
                    if bt is not None:
                        heading = math.atan2(bt[1] - xy[1], bt[0] - xy[0])
                if heading is None:  # nothing sensed at all: the obstacle is gone
                    self.mode = MODE_TO_GOAL
        if self.mode == MODE_TO_GOAL and self._leave_target is not None:
            # on the way from the boundary to the leave point: go there (Bug2 hits only on the M-line)
            lt = self._leave_target
            if math.hypot(lt[0] - xy[0], lt[1] - xy[1]) < self.step_length_m or self._leave_steps <= 0:
                self._leave_target = None
            else:
                self._leave_steps -= 1
                heading = math.atan2(self._leave_target[1] - xy[1], self._leave_target[0] - xy[0])
        if self.mode == MODE_TO_GOAL and heading is None:
            ti = self._intermediate_target(xy, points, r_safe, reach_m)
            if ti is None:
                self._hit(xy)
                followed = self._followed(pose, scan)
                if p.turn == "nearer_end":
                    self._choose_side(xy)
                heading = boundary_heading(xy, followed, r_safe + p.follow_margin_m, self.side, p.follow_gain)
                if heading is None:
                    heading = math.atan2(goal[1] - xy[1], goal[0] - xy[0])
            else:
                heading = math.atan2(ti[1] - xy[1], ti[0] - xy[0])
        assert heading is not None
        return safe_heading(heading, xy, points, self.step_length_m, self.radius_m + p.guard_margin_m)

    @property
    def progressing(self) -> bool:
        """Step 1: distance beats its reference within the window; Step 2: walk since H < patience."""
        if self.mode == MODE_UNREACHABLE:
            return False
        if self.mode == MODE_FOLLOW:
            return self._walked_m < self.params.follow_patience_m
        return self._monitor.progressing

    # ------------------------------------------------------------------ steps
    def _hit(self, xy: np.ndarray) -> None:
        """Step 1 -> Step 2 at hit point ``xy``.

        ``d_H`` is measured from the first M-line point Step 1 found blocked when there is one
        (Bug2's hit point lies on the M-line, where the obstacle cuts it; the robot stops up to
        a step short of it), else from ``xy``. Measured from ``xy``, M-line points between the
        robot and the obstacle counted as leave points: the robot left for them and hit the
        same obstacle again, a lap of the building for every ``leave_margin_m`` gained.
        """
        self.mode = MODE_FOLLOW
        self.hit_xy = xy.copy()
        at = self._blocked_xy if self._blocked_xy is not None else xy
        self.hit_dist_m = min(self.hit_dist_m, math.hypot(*(self.goal_xy - at)))
        self._walked_m = 0.0
        self._left_hit = False
        self._returns = 0
        self._follow_ref = None
        self._dir_walked_m = 0.0
        f = self.params.reverse_walk_factor
        rf = self._reverse_for
        if rf is not None and math.hypot(*(self.goal_xy - rf[0])) <= GOAL_SAME_TOL_M:
            f = rf[1]  # set by start_again for this goal
        self._reverse_limit_m = math.inf if f is None else max(2.0, f * math.hypot(*(self.goal_xy - xy)))
        self._reverse_reach_m = self._reverse_limit_m

    def _boundary_bearings(self, xy: np.ndarray, followed: np.ndarray) -> np.ndarray | None:
        """δ of each followed boundary point: its bearing from the robot less the nearest point's
        bearing φ, wrapped to (-π, π] and signed by the followed side (see
        :meth:`_boundary_target`); None with fewer than 3 points."""
        if followed.shape[0] < 3:
            return None
        rel = followed - xy
        d = np.hypot(rel[:, 0], rel[:, 1])
        i = int(np.argmin(d))
        phi = math.atan2(rel[i, 1], rel[i, 0])
        return self.side * (np.mod(np.arctan2(rel[:, 1], rel[:, 0]) - phi + math.pi, 2.0 * math.pi) - math.pi)

    def _boundary_target(self, xy: np.ndarray, followed: np.ndarray, points: np.ndarray, r_safe: float,
                         follow_m: float, reach_m: float) -> np.ndarray | None:
        """Step 2's other intermediate target (``boundary_shortcut``, Lumelsky & Skewis): the
        farthest visible point of the followed obstacle's boundary in the local direction.

        The boundary is the followed obstacle's sensed points. Seen from the robot, the
        nearest of them is at bearing φ; walking with the obstacle on the right (``side=+1``)
        the boundary ahead lies at bearings ``φ + δ``, δ in (0, π) (on the left, ``φ − δ``).
        Each point stands off the boundary by ``follow_m`` along its normal on the robot's
        side (the normal of the chord through its two neighbours in beam order), so that the
        robot keeps the follower's offset. The target is the stood-off point with the largest δ
        that the robot reaches through a free corridor of half-width ``r_safe`` (Step 1's
        test, which counts a point sensed at range ρ as ``ρ π / n_beams`` nearer, so along a
        straight wall the target lies a metre or two ahead) and that lies at least one step
        away; None when there is none (the reactive follower steers this step).

        Speed (commit 8e3551b, 2026-11-27): the part after the bearings in one kernel (``_boundary_pick``: it
        stops at the first visible candidate instead of testing all of them), with the arithmetic
        of :meth:`VisBugReference._boundary_target_numpy`; equal bit for bit
        (``tests/test_los_speed_equivalence.py``)."""
        delta = self._boundary_bearings(xy, followed)
        if delta is None:
            return None
        k, cx, cy = _boundary_pick(float(xy[0]), float(xy[1]), followed[:, 0], followed[:, 1], delta, float(follow_m),
                                   float(self.step_length_m), points[:, 0], points[:, 1], float(r_safe), float(reach_m),
                                   float(self._slack))
        if k < 0:
            return None
        return np.array((cx, cy))

    def _followed(self, pose: np.ndarray, scan: RangeScan) -> np.ndarray:
        """Sensed points of the obstacle being followed (own frame), shape (K, 2).

        The scan is cut into obstacles: beams adjacent in angle whose points are closer than
        ``FOLLOW_GAP_M`` (or 2.5 beam gaps at that range) belong to one. The followed one is
        the obstacle holding the point nearest to last step's followed point; at the hit point
        (or when that point is lost) the obstacle nearest the robot. Without this, a robot
        passing between two obstacles (a U in a room, a pillar near a wall) would switch to
        following the other one, which is not Bug2.

        With ``turn="nearer_end"`` it also keeps the followed obstacle's two sensed ends for
        :meth:`_choose_side` (TangentBug's endpoints; the rule: :meth:`VisBugReference._sensed_ends`).

        Speed (H7a): one numba kernel (:func:`_follow_kernel`) with the arithmetic of
        :meth:`VisBugReference._followed_numpy`, the beams' angular order kept per beam layout.
        """
        angles = scan.angles_rad
        if self._order_for is not angles:
            a = np.asarray(angles, dtype=np.float64)
            self._order = np.argsort(np.mod(a, 2.0 * math.pi), kind="stable")
            self._a_sorted = np.ascontiguousarray(a[self._order])
            self._order_for = angles
        r = np.asarray(scan.ranges_m, dtype=np.float64)[self._order]
        ref = self._follow_ref
        ends = self.params.turn == "nearer_end"
        n_members, members, near, pts, found, e = _follow_kernel(
            float(pose[0]), float(pose[1]), float(pose[2]), r, self._a_sorted,
            float(scan.max_range_m) * (1.0 - 1e-9), ref is not None,
            0.0 if ref is None else float(ref[0]), 0.0 if ref is None else float(ref[1]),
            self.step_length_m + FOLLOW_GAP_M, 2.5 * (2.0 * math.pi / r.size), ends)
        if n_members < 0:
            self._follow_ref = None
            return np.zeros((0, 2))
        self._follow_ref = pts[near].copy()
        if ends:
            self._ends = (e[0].copy(), e[1].copy()) if found else None
        return pts[members[:n_members]]

    def _choose_side(self, xy: np.ndarray) -> None:
        """``turn="nearer_end"``: at a hit, the side whose sensed end O of the hit obstacle
        gives the shorter ``|xO| + |OT|`` (TangentBug's heuristic, Kamon, Rimon & Rivlin 1998);
        ties, or an obstacle seen all round, keep the current side."""
        if self._ends is None:
            return
        cost = [math.hypot(*(e - xy)) + math.hypot(*(self.goal_xy - e)) for e in self._ends]
        if abs(cost[0] - cost[1]) > NEARER_END_TIE_M:
            self.side = 1 if cost[0] < cost[1] else -1

    def _mline_samples(self, t_from: float) -> tuple[np.ndarray, np.ndarray]:
        """M-line points with parameter t in [t_from, 1] (goal last), and their t."""
        # speed (H7a): kept while the M-line and t_from are the same (read-only arrays)
        key = self._samples_key
        if key is not None and key[0] is self.mline and key[1] == t_from:
            return key[2], key[3]
        s, g = self.mline
        length = math.hypot(*(g - s))
        n = max(1, int(math.ceil(length / self.params.mline_sample_m)))
        t = np.linspace(0.0, 1.0, n + 1)
        t = t[t >= t_from - 1e-12]
        pts = s + t[:, None] * (g - s)
        pts.flags.writeable = False
        t.flags.writeable = False
        self._samples_key = (self.mline, t_from, pts, t)
        return pts, t

    def _mline_dir(self) -> tuple[np.ndarray, np.ndarray]:
        """The M-line's end T and its unit direction ``(g − s) / max(|g − s|, 1e-12)`` (kept
        while the M-line is the same object)."""
        key = self._dir_key
        if key is not None and key[0] is self.mline:
            return key[1], key[2]
        s, g = self.mline
        u = (g - s) / max(math.hypot(*(g - s)), 1e-12)
        self._dir_key = (self.mline, g, u)
        return g, u

    def _intermediate_target(self, xy, points, r_safe, reach_m) -> np.ndarray | None:
        """Step 1's Ti: the visible M-line point nearest the goal, at least one step away (else None)."""
        cand, t = self._mline_samples(self._t_anchor)
        # speed: the last visible candidate, searched from the goal end (``_last_visible``: the
        # arithmetic of ``_visible``, which tests every candidate; kept in visbug21_reference for the tests)
        j = int(_last_visible(float(xy[0]), float(xy[1]), points[:, 0], points[:, 1], cand[:, 0], cand[:, 1],
                              float(r_safe), float(reach_m), float(self._slack)))
        self._blocked_xy = None
        if j < 0:
            return None
        ti = cand[j]
        if t[j] >= 1.0 - 1e-12 or math.hypot(*(ti - xy)) >= self.step_length_m:
            return ti
        if j + 1 < cand.shape[0]:
            self._blocked_xy = cand[j + 1]  # where the obstacle cuts the M-line: Bug2's H
        return None

    def _leave_point(self, pose, scan, points, r_safe, reach_m) -> np.ndarray | None:
        """Step 2's leave test: a visible M-line point closer to the goal than H by the margin."""
        xy = pose[:2]
        cand, t = self._mline_samples(0.0)
        g, u = self._mline_dir()
        # speed: the samples closer to the goal than d_H less the margin, visible
        # (``_visible``), and with a clear run on towards T when short of it, in one kernel
        # with the arithmetic of the numpy code it replaced (``_leave_point_numpy``)
        p = self.params
        sel, ok, tested, run, n_ok = _leave_candidates(
            float(xy[0]), float(xy[1]), points, cand, t, float(self.goal_xy[0]), float(self.goal_xy[1]),
            self.hit_dist_m - p.leave_margin_m, float(g[0]), float(g[1]), float(u[0]), float(u[1]), float(r_safe),
            float(r_safe - p.leave_hysteresis_m), float(reach_m), float(self._slack), float(p.leave_run_m))
        if n_ok == 0:
            return None  # no sample closer than d_H, or none visible with a clear run
        cand, t = cand[sel], t[sel]
        # Bug2: from Q the robot must be able to move on towards T (or Q is T), and the robot
        # must have *seen* that run free, not merely sensed nothing near it: from afar it sees
        # the near face of a wall, never its far side (a door jamb's thickness), and a run
        # grazing an unseen face made it leave, hit at once, and walk the whole boundary
        # again, lap after lap (office_simple, R1 alone, task 4)
        keep = np.flatnonzero(ok & tested)
        if keep.size:
            ok[keep] = self._run_seen(pose, scan, cand[keep], run[keep], u, r_safe - self.params.leave_hysteresis_m)
        return self._nearest_leave_point(xy, cand, t, ok)

    def _nearest_leave_point(self, xy: np.ndarray, cand: np.ndarray, t: np.ndarray,
                             ok: np.ndarray) -> np.ndarray | None:
        """The leave test's last part, shared with
        :meth:`VisBugReference._leave_point_numpy`: of the M-line
        samples ``cand`` (parameters ``t``) that passed (``ok``), the one nearest the goal, kept
        as the new anchor of Step 1's search; None when none passed or it is less than a step
        away and short of the goal."""
        if not ok.any():
            return None
        j = int(np.flatnonzero(ok)[-1])
        # moving to it must be possible: it is at least a step away, or it is the goal
        if t[j] < 1.0 - 1e-12 and math.hypot(*(cand[j] - xy)) < self.step_length_m:
            return None
        self._t_anchor = float(t[j])
        return cand[j]

    def _run_seen(self, pose, scan, starts: np.ndarray, runs_m: np.ndarray, u: np.ndarray,
                  half_width_m: float) -> np.ndarray:
        """Whether each run ``starts[k] -> starts[k] + runs_m[k]·u`` was seen free by the scan.

        Seen free (:func:`~teamnav.control.nav.local.base.seen_free`): points along the run
        every ``mline_sample_m``, each with two points ``RUN_SEEN_FRACTION · half_width_m`` to
        its sides, all in front of the returns of their beams.
        """
        n = max(1, int(math.ceil(self.params.leave_run_m / self.params.mline_sample_m)))
        f = np.linspace(0.0, 1.0, n + 1)
        normal = np.array([-u[1], u[0]]) * (RUN_SEEN_FRACTION * half_width_m)
        centres = starts[:, None, :] + (runs_m[:, None] * f[None, :])[:, :, None] * u  # (K, n+1, 2)
        probe = np.concatenate((centres, centres + normal, centres - normal), axis=1)  # (K, 3(n+1), 2)
        seen = seen_free(pose, scan, probe.reshape(-1, 2)).reshape(probe.shape[:2])
        return seen.all(axis=1)
