"""How both line-of-sight help brains drive towards a point (Sgorbissa & Arkin §2, §3, §5, §6).

Paper: A. Sgorbissa and R. C. Arkin, "Local navigation strategies for a team of robots".

:class:`_Driving` is a mixin of :class:`~.brain._LosBrain`: the step in :mod:`.brain` chooses
*what* to head for, these helpers decide *how* to get there:

- :meth:`_Driving._head_to`: a point the robot sees (its goal, a teammate, a ghost, a trouble
  helper) is headed for straight, suppressing algorithm A (§2 point 4), when the corridor to it
  is wide enough for the robot's body (:meth:`_Driving._corridor_clear`); else, gap filled
  (the paper's robots are points), it slides along the nearest free direction
  (:meth:`_Driving._slide_heading`, ``slide_when_blocked``) or asks A. Progress towards it (§5
  rule 1) is the distance falling below its best so far by ``progress_min_fraction`` of a step.
- :meth:`_Driving._navigate` / :meth:`_Driving._drive`: a heading from the local navigation
  algorithm A (§6: potential field, Avoid-Past, VisBug-21), its own estimate of progress; an
  excursion to a teammate, a ghost or a trouble helper (§3 rule 5, §4.2, §5 rule 3) is a
  temporary goal that A suspends its task goal's memory for.

A is built lazily by the host's ``_navigator()`` (:func:`~.brain.make_navigator`, which tests
replace). The host also provides ``params``, ``step_m``, ``radius_m``, ``vis_radius_m``, this
step's pose (``_pose``, ``_th``, ``_me_xy()``) and scan (``_r64``, ``_a64``, ``_max_range``,
``_nav_scan``), the visibility test ``_sees`` and the counters ``nav_restarts`` and
``slide_steps``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from teamnav.control.nav.local.base import corridor_clear, wrap_scalar
from teamnav.control.types import Action

#: A point [m] in the robot's own odometry frame.
XY = tuple[float, float]


class _Driving:
    """The motion helpers of :class:`~.brain._LosBrain` (see the module docstring)."""

    def _navigate(self, target: XY, temporary: bool = False) -> tuple[Action, bool]:
        """A heading from the navigator towards ``target`` (own frame); (action, progressing).

        ``temporary``: an excursion to a teammate, a ghost or a trouble helper (§3 rule 5, §4.2,
        §5 rule 3: "R_j temporarily becomes R_i goal"); A suspends its task goal's memory
        (VisBug's M-line and hit point) and resumes it when the task goal is set again
        (``LocalNavigator.set_goal(..., temporary=True)``)."""
        nav = self._navigator()
        key = (target, bool(temporary))
        if self._nav_goal is None or self._nav_goal != key:
            nav.set_goal(np.array(target, dtype=np.float64), temporary=bool(temporary))
            self._nav_goal = key
        heading = nav.direction(self._pose.copy(), self._nav_scan)
        progressing = bool(nav.progressing)
        self._temp_unreachable = False
        if heading is None:
            if temporary:
                # A found the temporary point unreachable: no move this step, keeping A (and
                # the task's suspended memory); the host drops the point (the explorer's
                # ``drop_unreachable_ghost``), else A is asked again next step and says the same
                self._temp_unreachable = True
                return Action(), progressing
            if self.params.restart_navigator_on_give_up:
                # gap filled: A gave up on this target (VisBug's "unreachable", which on a grid
                # with a robot radius can be wrong): start A afresh from here next step
                self._nav, self._nav_goal = None, None
                self.nav_restarts += 1
            return Action(), progressing
        return Action(direction_rad=wrap_scalar(heading - self._th)), progressing

    def _corridor_clear(self, heading_rad: float, length_m: float) -> bool:
        """Whether the robot's body can travel ``length_m`` straight along ``heading_rad`` (own
        frame) without touching any return of this step's scan (every return at least
        1.05 radius from the segment), and the laser sees that far."""
        if length_m > self.vis_radius_m:
            return False
        return corridor_clear(self._r64, self._a64, self._max_range, self._th, heading_rad, length_m,
                              self.radius_m * 1.05)

    def _head_to(self, target: XY, key: Any, *, stop_within_m: float = 0.0,
                 end_margin_m: float = 0.0, trust: bool = False) -> tuple[Action, bool]:
        """Head for a point: straight (§2 point 4) when the robot sees it with a corridor wide
        enough for its body (up to ``end_margin_m`` short of it: a teammate may stand there),
        else via the navigator towards it. Checking the whole corridor, not only the next
        step, keeps the choice the same all along the approach (checking one step made the
        robot alternate between a straight step and the navigator's way round)."""
        me = self._me_xy()
        dist = math.hypot(target[0] - me[0], target[1] - me[1])
        last = self._last_target
        progressing = True
        best = dist
        if last is not None and last[0] == key:
            # progress against the best distance so far, not the last step's: a robot rocking
            # between two cells got halfway progress (measured: 700 steps in place before a ghost)
            progressing = dist < last[2] - self.params.progress_min_fraction * self.step_m
            best = dist if progressing else last[2]
        self._last_target = (key, target, best)
        if dist <= stop_within_m:
            return Action(), True
        heading = math.atan2(target[1] - me[1], target[0] - me[0])
        if self.params.straight_when_visible and self._corridor_clear(heading, max(self.step_m, dist - end_margin_m)):
            return Action(direction_rad=wrap_scalar(heading - self._th)), progressing
        if (self.params.straight_when_visible and self.params.slide_when_blocked
                and (trust or self._sees(*target, 2.0 * self.radius_m))):
            slide = self._slide_heading(heading, min(dist - end_margin_m, self.params.slide_lookahead_m))
            if slide is not None:
                self.slide_steps += 1
                return Action(direction_rad=wrap_scalar(slide - self._th)), progressing
        temporary = not (isinstance(key, tuple) and key and key[0] in ("goal", "waypoint", "promised"))
        action, _ = self._navigate(target, temporary=temporary)
        return action, progressing

    def _slide_heading(self, heading_rad: float, length_m: float) -> float | None:
        """The free heading nearest to ``heading_rad`` (own frame) whose corridor of
        ``length_m`` is clear for the body, within ±90° in 5° steps; None if there is none.

        Gap filled: the paper's robots are points, so a point in line of sight can be reached
        in a straight line; ours have a radius, and a line of sight through a door at a
        slant grazes its jamb. Sliding along the nearest free direction (the side tried first
        at each angle is the side of the last slide, so the robot does not dither) keeps the
        robot on its way to the point it sees instead of handing it to the navigator, whose
        own memory (Avoid-Past) or boundary state (VisBug) is about its task goal, not about
        this point (measured: handing over sent R1 back into the room it was leaving)."""
        length_m = max(self.step_m, length_m)
        side = getattr(self, "_slide_side", 1.0)
        for k in range(1, 19):
            for sgn in (side, -side):
                h = heading_rad + sgn * math.radians(5.0 * k)
                if self._corridor_clear(h, length_m):
                    self._slide_side = sgn
                    return h
        return None

    def _drive(self, target: XY) -> tuple[Action, bool]:
        """Drive towards an unseen target with the navigator (algorithm A)."""
        self._last_target = None
        return self._navigate(target)
