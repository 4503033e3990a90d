"""R1 of the line-of-sight help system: ``los-explorer-v1`` (Sgorbissa & Arkin §2, §5, §6).

It reaches its targets in sequence, helped by teammates through goal sharing (§3–§4) and state
sharing (§5); the step shared with the helpers is :class:`~.brain._LosBrain` (see :mod:`.brain`
for the whole step and the scenario requirements). Its parameters, each gap-fill with what was
measured, are :class:`~.explorer_params.LosExplorerParams` (:mod:`.explorer_params`, importable
from this module too); what R1 does in trouble (§5 rule 3) is the mixin
:class:`~.trouble_following._TroubleFollowing` (:mod:`.trouble_following`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from teamnav.papers.los_help.brains.brain import XY, _LosBrain
from teamnav.papers.los_help.brains.explorer_params import LosExplorerParams
from teamnav.papers.los_help.brains.trouble_following import _TroubleFollowing
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Action, Observation

# LosExplorerParams lives in .explorer_params; it stays importable from here
__all__ = ["LosExplorer", "LosExplorerParams"]


class LosExplorer(_TroubleFollowing, _LosBrain):
    """R1: reaches its targets in sequence, helped by teammates (``los-explorer-v1``).

    Attributes
    ----------
    finished : bool
        True once the last target is reached (immediately with no targets).
    target_index : int
        Index (0-based) of the current target; ``len(targets_xy)`` when finished.

    Examples
    --------
    >>> import numpy as np
    >>> from teamnav.control import Observation, RangeScan, RobotInfo, SensorInfo
    >>> angles = np.linspace(-np.pi, np.pi, 360, endpoint=False)
    >>> info = RobotInfo(0, 2, 0.2, "holonomic_step", 0.5, 1.5, 0.1, 0.1,
    ...                  sensors={"laser": SensorInfo("laser", "laser", angles, 8.0)})
    >>> brain = LosExplorer(LosExplorer.Params(targets_xy=[(2.0, 0.0)]), np.random.default_rng(0), info)
    >>> scan = RangeScan(np.full(360, 8.0), angles, 8.0)
    >>> action, outbox = brain.step(Observation(0, 0, 0.0, np.zeros(3), np.zeros(3), scans={"laser": scan}))
    >>> round(action.direction_rad, 6), brain.mode, outbox
    (0.0, 'own_goal', [])
    """

    Params = LosExplorerParams
    #: the compiled form of this brain for a whole group (``Simulation(..., group_brains=True)``;
    #: :mod:`teamnav.control.group`): R1 and the helpers in one team (:mod:`.team_compiled`; R1
    #: alone: :mod:`.compiled`)
    group_brain = "teamnav.papers.los_help.brains.team_compiled:LosTeamGroup"

    def __init__(self, params: LosExplorerParams, rng: np.random.Generator, info: RobotInfo) -> None:
        super().__init__(params, rng, info)
        self.targets = [(float(x), float(y)) for x, y in params.targets_xy]
        self.target_index = 0
        self.targets_reached = 0
        self.finished = not self.targets
        self.gave_up = False
        self._target_since = 0
        self._moves_since = 0
        #: motion steps R1 took for each target reached so far (per-target pairing across teams)
        self.target_steps: list[int] = []
        self._promised: int | None = None
        self._temp_stall = 0
        self.temp_dropped = 0
        #: teammate or ghost points dropped because A declared them unreachable (``drop_unreachable_ghost``)
        self.ghosts_unreachable = 0
        #: times R1 went on from a teammate's reached point to the point its D led through
        self.vias_taken = 0
        self._prev_goal_d = math.inf
        self.promised_steps = 0
        self.goal_seen_steps = 0
        self._init_trouble_following()
        self._set_goal()

    def _set_goal(self) -> None:
        if self.finished:
            self.sharing.set_own_goal(None)
            self.mode = "done"
        else:
            self.sharing.set_own_goal(self.target_index + 1, self.targets[self.target_index])

    def _advance_task(self) -> None:
        """§2: the current goal is reached when dist < ε; then the next one becomes current.
        A target not reached within ``max_steps_per_target`` steps ends the task (gave up)."""
        while not self.finished:
            gx, gy = self.targets[self.target_index]
            if math.hypot(gx - self._px, gy - self._py) >= self.params.goal_tolerance_m:  # _px: float(_pose[0])
                budget = self.params.max_steps_per_target
                if budget is not None and self._step - self._target_since >= budget:
                    self.gave_up = True
                    self.finished = True
                    self.sharing.set_own_goal(None)
                return
            self._target_since = self._step
            self.target_steps.append(int(self.moves - self._moves_since))
            self._moves_since = self.moves
            self.target_index += 1
            self.targets_reached += 1
            self._mate_goal_d = {}
            self._release_xy = None
            self.finished = self.target_index >= len(self.targets)
            self._set_goal()
            self._last_target = None
            if self.params.reset_trouble_on_target:
                self.trouble.reset()

    def _decide(self, obs: Observation) -> Action:
        if self.finished:
            self.mode = "gave_up" if self.gave_up else "done"
            return Action()
        action = self._decide_task(obs)
        if self.mode in ("follow_teammate", "ghost", "trouble_follow"):
            key = self._last_target[0] if self._last_target is not None else None
            key = key[:2] if isinstance(key, tuple) else key  # the point's source, not its step
            if key != self._temp_key:
                self.temp_switches += 1
            self._temp_key = key
        else:
            self._temp_key = None
        return action

    def _decide_task(self, obs: Observation) -> Action:
        p = self.params
        goal = self.targets[self.target_index]
        path = self.sharing.path(self.me) if p.goal_sharing else None
        action: Action | None = None
        progressing = True
        if path is not None and path.kind == "direct":
            self.mode = "own_goal"  # §2 point 4: it sees its goal, A is suppressed
            self.goal_seen_steps += 1
            action, progressing = self._head_to(goal, ("goal", self.target_index),
                                                end_margin_m=0.5 * p.goal_tolerance_m)
        elif path is not None and path.kind in ("ghost", "self") and not path.reached:
            point = (path.px_m, path.py_m)
            # the mirror itself still stands where it promised (§3), or only its ghost does (§4.2)
            seen = self._seen_now.get(path.source)
            live = seen is not None and math.hypot(seen[0] - point[0], seen[1] - point[1]) <= 2.0 * self.radius_m + self.step_m
            # a ghost is reached closer than a target: the goal may be seen only from a narrow
            # stretch of corridor through a door (measured: stopping ε = 0.5 m short of it,
            # R1 often did not see the goal the helper had seen from there)
            reach = max(p.goal_tolerance_m, 2.0 * self.radius_m + self.step_m) if live else p.ghost_tolerance_m
            me = self._me_xy()
            if (math.hypot(point[0] - me[0], point[1] - me[1]) < reach and p.share_via
                    and (not p.via_in_sight or path.via_d_m is None
                         or self._sees(path.via_x_m, path.via_y_m, self.sharing.point_margin_m))
                    and self.sharing.go_via(self.me, self._step)):
                # at the teammate's point without seeing the goal: on to where its D leads
                # (``share_via``; a straight line, the teammate saw it from here, §4.3)
                self.vias_taken += 1
                self.mode = "ghost"
                path = self.sharing.path(self.me)
                action, progressing = self._head_to((path.px_m, path.py_m), ("path", path.source, path.step),
                                                    end_margin_m=p.ghost_tolerance_m)
            elif math.hypot(point[0] - me[0], point[1] - me[1]) < reach:
                # §4.2: at the ghost without seeing the goal: explore again with A, keeping the
                # promise only to arbitrate later reports
                self.sharing.mark_reached(self.me)
                if p.restart_navigator_at_ghost and self._nav is not None and hasattr(self._nav, "start_again"):
                    # "start again ... with A, possibly from a better position" (§4.2)
                    if p.navigator == "visbug21" and p.visbug_reverse_walk_factor is not None:
                        self._nav.start_again(reverse_walk_factor=p.visbug_reverse_walk_factor)
                    else:
                        self._nav.start_again()
                if p.trust_direct_promise and path.d_point_m <= math.hypot(goal[0] - point[0], goal[1] - point[1]) + self.step_m:
                    # the teammate saw the goal itself from here (its D is the straight
                    # distance): head straight for it (see ``trust_direct_promise``)
                    self._promised = self.target_index
            else:
                self.mode = "follow_teammate" if live else "ghost"
                self._temp_unreachable = False
                action, progressing = self._head_to(point, ("path", path.source, path.step),
                                                    end_margin_m=reach)
                if self._temp_unreachable and p.drop_unreachable_ghost:
                    # artifact fixed (both columns): A (VisBug-21's Bug2 test, on our grid with
                    # a robot radius) declared the point unreachable; §4.2 takes the ghost to be
                    # reachable ("we assume odometry to be adequate to guarantee R2(t2)
                    # reachability"), so the case does not arise in the paper. Drop it as a
                    # reached one (A starts again on R1's own goal) instead of standing still
                    self.ghosts_unreachable += 1
                    self._temp_stall = 0
                    self.sharing.mark_reached(self.me)
                    self._last_target = None
                    action, progressing = None, False
                # a point R1 makes no progress towards for Cr steps (A trapped on the way; a
                # teammate standing still in a doorway) is given up like a reached one, so
                # that A, or §5 when in trouble, takes over (gap filled: §4.2 assumes the
                # straight path to a ghost is free)
                self._temp_stall = 0 if progressing or action is None else self._temp_stall + 1
                if action is not None and p.drop_stalled_ghost and self._temp_stall >= p.trouble_cr:
                    self._temp_stall = 0
                    self.temp_dropped += 1
                    self.sharing.mark_reached(self.me)
        self._watch_mates(goal)
        me_xy = self._me_xy()
        goal_d = math.hypot(goal[0] - me_xy[0], goal[1] - me_xy[1])
        if action is None and p.state_sharing and self.trouble.tr:
            action, progressing = self._follow_in_trouble(obs, goal, me_xy, goal_d, progressing)
        if action is not None and self.mode == "own_goal":
            self._release_xy = None  # it sees its goal (§2 point 4)
        if action is None and self._release_xy is not None:
            action, progressing = self._go_to_release_point(me_xy, progressing)
        if action is None and self._promised == self.target_index and not self.trouble.tr:
            self.mode = "own_goal"
            self.promised_steps += 1
            action, progressing = self._head_to(goal, ("promised", self.target_index),
                                                end_margin_m=0.5 * p.goal_tolerance_m, trust=True)
        if action is None:
            action, progressing = self._unseen_goal(goal)
        self.trouble.update(progressing)
        self._prev_goal_d = goal_d
        return action

    def _unseen_goal(self, goal: XY) -> tuple[Action, bool]:
        """The goal is out of sight and nothing else leads R1 (no teammate, ghost or trouble
        helper): the navigator A drives towards it (§2). A hook: ``los-trail-explorer-v1``
        (:mod:`teamnav.papers.beyond.brains.trail_memory`) heads for a remembered viewpoint first."""
        self.mode = "own_goal"
        return self._drive(goal)

    def log(self) -> dict[str, Any]:
        """Per-step values (keep these keys stable; experiments read them).

        ``target_index`` (0-based current target), ``targets_reached``, ``moves`` (motion
        steps commanded so far), ``mode`` (``"own_goal"`` | ``"follow_teammate"`` |
        ``"ghost"`` | ``"trouble_follow"`` | ``"trouble_return"`` (``trouble_return``) | ``"done"`` |
        ``"gave_up"``), ``tr``, ``pr``, ``nt`` (§5),
        ``msgs_sent``, ``bytes_sent``, ``msgs_received`` (§4.4 traffic, cumulative),
        ``nav_restarts`` (times A gave up and was started afresh),
        ``known_goals`` and ``ghosts`` (memory, §4.4), ``own_d_m`` (D to its own goal, -1
        when none), ``finished``, ``gave_up`` (the step budget of a target ran out, see
        ``max_steps_per_target``); where the steps go, cumulative: ``steps_<mode>`` for each
        mode met so far, ``goal_seen_steps`` (own goal in sight), ``promised_steps`` (heading for it on a
        teammate's direct promise, ``trust_direct_promise``), ``slide_steps`` (heading to
        a seen point along a side direction), ``temp_switches`` (changes of the teammate, ghost
        or trouble helper headed for), ``temp_dropped`` (teammate or ghost points given up after
        ``trouble_cr`` steps without progress towards them), ``ghosts_unreachable`` (teammate or ghost
        points dropped because A declared them unreachable, ``drop_unreachable_ghost``),
        ``trouble_helpers_dropped`` (last seen
        helper positions given up, ``trouble_drop_stalled_helper``), ``vias_taken`` (times R1 went on from
        a teammate's reached point to the point its D led through, ``share_via``); and ``layers``: ``los_goal`` and ``los_ghosts`` markers in
        the odometry frame (when ``log_layers``).
        """
        out = self._common_log()
        out.update(target_index=int(self.target_index), targets_reached=int(self.targets_reached),
                   finished=bool(self.finished), gave_up=bool(self.gave_up),
                   goal_seen_steps=int(self.goal_seen_steps), promised_steps=int(self.promised_steps),
                   temp_dropped=int(self.temp_dropped), ghosts_unreachable=int(self.ghosts_unreachable),
                   vias_taken=int(self.vias_taken),
                   trouble_helpers_dropped=int(self.trouble_helpers_dropped))
        layers = self._layers()
        if layers:
            out["layers"] = layers
        return out
