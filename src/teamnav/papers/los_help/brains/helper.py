"""R2..R4 of the line-of-sight help system: ``los-helper-v1`` (Sgorbissa & Arkin §6).

Helpers patrol the corridors and help by sharing only; the step shared with R1 is
:class:`~.brain._LosBrain` (see :mod:`.brain`).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import Field

from teamnav.papers.los_help.brains.brain import _LosBrain
from teamnav.papers.los_help.brains.params import _CommonParams
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Action, Observation

__all__ = ["LosHelper", "LosHelperParams"]


class LosHelperParams(_CommonParams):
    """A helper's parameters: :class:`_CommonParams` plus its patrol.

    Attributes
    ----------
    patrol_xy : list of (x, y)
        Waypoints [m] in the robot's own odometry frame. Empty: stays where it is.
    patrol_mode : {"ping_pong", "cycle"}
        After the last waypoint, go back through them (ping-pong) or start again (cycle).
    waypoint_timeout_steps : int
        A waypoint not reached within this many steps is passed over for the next one (0: never).
        Ours, not the paper's (§6 only says helpers "patrol the corridors"): two helpers
        heading for the same doorway from opposite sides, or a helper meeting R1 in a door,
        block each other for good under a potential field (each is the other's local minimum;
        measured on office_complex: R2 and R4 stood 2000 steps in room 5's doorway while R1
        waited, out of their sight, for help).
    """

    GAP_FILLS_KEPT: ClassVar[dict[str, str]] = {
        **_CommonParams.GAP_FILLS_KEPT,
        "patrol_xy": "the helpers' routes (§6: they 'patrol the corridors'; the paper gives no route)",
        "waypoint_timeout_steps": "a waypoint not reached in time is passed over (no paper rule)",
    }

    patrol_xy: list[tuple[float, float]] = Field(default_factory=list, max_length=10_000)
    patrol_mode: Literal["ping_pong", "cycle"] = "ping_pong"
    waypoint_timeout_steps: int = Field(0, ge=0, le=1_000_000)



class LosHelper(_LosBrain):
    """R2..R4: patrols its waypoints and helps by sharing only (``los-helper-v1``).

    It has no ``finished`` attribute (a run with ``stop_when_finished`` waits for R1 only).
    """

    Params = LosHelperParams
    #: the compiled form of this brain with its team (``Simulation(..., group_brains=True)``;
    #: ``docs/concepts/group-brains.md``): R1 and the helpers in one team (:mod:`.team_compiled`)
    group_brain = "teamnav.papers.los_help.brains.team_compiled:LosTeamGroup"

    def __init__(self, params: LosHelperParams, rng: np.random.Generator, info: RobotInfo) -> None:
        super().__init__(params, rng, info)
        self.patrol = [(float(x), float(y)) for x, y in params.patrol_xy]
        self.waypoint_index = 0
        self._dir = 1
        self.waypoints_reached = 0
        self.waypoints_skipped = 0
        self._steps_on_waypoint = 0
        self._k = 1
        self.mode = "patrol" if self.patrol else "stay"
        if self.patrol:
            self.sharing.set_own_goal(self._k, self.patrol[0])

    def _advance_task(self) -> None:
        """Next waypoint when within ε; each new waypoint is a new goal k (new Id = k·M)."""
        if not self.patrol:
            return
        wx, wy = self.patrol[self.waypoint_index]
        reached = math.hypot(wx - self._px, wy - self._py) < self.params.goal_tolerance_m  # _px: float(_pose[0])
        self._steps_on_waypoint += 1
        timeout = self.params.waypoint_timeout_steps
        timed_out = not reached and timeout > 0 and self._steps_on_waypoint > timeout
        if not (reached or timed_out):
            return
        if len(self.patrol) == 1:
            return  # one waypoint: it stays there
        n = len(self.patrol)
        if self.params.patrol_mode == "cycle":
            self.waypoint_index = (self.waypoint_index + 1) % n
        else:
            if not 0 <= self.waypoint_index + self._dir < n:
                self._dir = -self._dir
            self.waypoint_index += self._dir
        if reached:
            self.waypoints_reached += 1
        else:
            self.waypoints_skipped += 1
        self._steps_on_waypoint = 0
        self._k += 1
        self._last_target = None
        self.sharing.set_own_goal(self._k, self.patrol[self.waypoint_index])
        if self.params.reset_trouble_on_target:
            self.trouble.reset()

    def _decide(self, obs: Observation) -> Action:
        if not self.patrol:
            self.mode = "stay"
            return Action()
        wp = self.patrol[self.waypoint_index]
        me = self._me_xy()
        if len(self.patrol) == 1 and math.hypot(wp[0] - me[0], wp[1] - me[1]) < self.params.goal_tolerance_m:
            self.mode = "stay"
            return Action()
        self.mode = "patrol"
        if self._sees(*wp):
            action, progressing = self._head_to(wp, ("waypoint", self._k), end_margin_m=0.5 * self.params.goal_tolerance_m)
        else:
            action, progressing = self._drive(wp)
        self.trouble.update(progressing)
        return action

    def log(self) -> dict[str, Any]:
        """As :meth:`LosExplorer.log` where meaningful: ``mode`` is ``"patrol"`` or ``"stay"``;
        ``target_index`` is the current waypoint index, ``targets_reached`` counts waypoints
        reached and ``waypoints_skipped`` those passed over (``waypoint_timeout_steps``)."""
        out = self._common_log()
        out.update(target_index=int(self.waypoint_index), targets_reached=int(self.waypoints_reached),
                   waypoints_skipped=int(self.waypoints_skipped))
        layers = self._layers()
        if layers:
            out["layers"] = layers
        return out
