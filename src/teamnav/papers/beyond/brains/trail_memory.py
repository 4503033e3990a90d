"""Brain ``los-trail-explorer-v1``: R1 of the line-of-sight help system with a Trail of its viewpoints.

Beyond the papers, combination 4 ("trails as LOS memory"): Sgorbissa & Arkin's R1 forgets where it saw
its goal as soon as it loses sight of it (the owner of a goal keeps no §4.3 viewpoint: it falls
back to its navigator A, :mod:`~teamnav.papers.los_help.brains.goal_sharing`), and its tasks
send it to the same rooms again and again (§6: 200 targets among the rooms' centres). Vaughan
et al.'s robots keep a Trail of crumbs (2002 §2.1). This brain composes the two without copying
either:

- **Everything of R1** is :class:`~teamnav.papers.los_help.brains.explorer.LosExplorer`
  (``los-explorer-v1``): goal sharing (§3-§4), state sharing (§5), its navigator A and all its
  gap-fills, with their parameters. With ``goal_memory: "off"`` (the default, the paper) this
  brain *is* ``los-explorer-v1``: its runs are identical (a test checks it).
- **The memory** is a :class:`~teamnav.papers.trails.brains.trails.Trail` (Try §2.1.3) in R1's own
  odometry frame: one Place per target position of its task (§2.1.1: a task event's name and
  where it happened; here the name is the target's coordinates, which R1's task repeats
  whenever a room recurs), and a Crumb ``[P x y s t]`` (§2.1.2) at each position from which R1
  *acquired* a direct view of that Place (the brain's own V(R) test, §2, without the
  ``keep_direct_view`` hysteresis: a crumb is a point from which the goal is seen again), with
  ``s`` = the straight distance to the Place (the §4.3 "D(t1) = dist(R_i(t1), G)") and ``t``
  the step; crumbs closer than ``goal_memory_spacing_m`` to one of the same Place are not laid.
- **The use rule**: when R1's current goal is out of sight and nothing else leads it (no
  teammate or ghost offers a D, §3 rule 5 / §4.2; no teammate to follow in trouble, §5 rule 3;
  i.e. exactly where ``los-explorer-v1`` hands over to A), R1 heads for the crumb of its goal's
  Place with the shortest ``D = dist(R1, crumb) + s`` among those it sees (§4.3's estimate
  through a "ghost robot" R_i(t1), applied to its own viewpoints of all earlier visits), straight
  when the corridor is clear (as to any point in sight, :meth:`~teamnav.papers.los_help.brains.driving._Driving._head_to`).
  There it sees its goal and heads straight in (§2 point 4).

Gaps filled (none of the papers has this; each is a parameter, and ``goal_memory: "off"`` is
the paper's rule):

- ``goal_memory_places``: ``"task"`` (default) lays crumbs for every target Place of the task
  R1 sees (R1 is given its whole task, §6, so a room passed on the way is remembered before it
  is a goal); ``"current"`` for the current target only.
- ``goal_memory_when``: ``"always"`` (default) uses the memory wherever A would drive;
  ``"trouble"`` only while R1 is in trouble (Tr of §5, whatever ``state_sharing`` says: the
  bit is R1's own).
- ``goal_memory_reach``: ``"visible"`` (default) heads only for crumbs in sight (§4.3's
  "checks if R_i(t1) ∈ V(R_i)"); ``"any"`` also, with none in sight, for the crumb with the
  shortest straight D anywhere, as a waypoint of A (the Try §2.3 trail-following idea: a
  remembered point, reached by local navigation).

  The defaults were chosen on tuning tasks 1001-1004 only (office_complex_closed, R1 alone,
  first 20 targets, 3000 steps per target at most; docs/report/beyond.md): Avoid-Past, targets
  reached of 80 (tasks finished of 4), steps per target: off 57 (2) 977; current/always/visible
  65 (2) 804; task/always/visible 80 (4) 722; current/trouble 56 (1) 845; current/any 69 (3)
  720; task/any 80 (4) 709 (no gain over visible, so the §4.3 rule stays). The potential field
  alone is trapped at the first or second target under every setting (3-5 of 80): memory
  needs a revisit to pay. VisBug-21 alone (tasks 1001-1002): off 40/40 targets, task/always/
  visible 29/40 (one task lost): the memory *hurts* VisBug alone (it interrupts a boundary
  walk that would have reached the goal).
- A crumb reached (within ``ghost_tolerance_m``) without the goal coming into view, or headed
  for ``trouble_cr`` steps without progress, is dropped for the rest of that target (as
  ``drop_stalled_ghost`` drops a ghost), so R1 does not circle a bad crumb.

Crumbs live in R1's odometry frame: with exact odometry (the LOS scenarios, §6.1) they stay
where they were laid; with drifting odometry they drift with the frame (and so do R1's targets,
given in the same frame). Memory grows with the area R1 saw its goals from, bounded by the
spacing: O(places x area / spacing²), not O(M) as §4.4's messages; nothing is sent.

Log keys, beside ``los-explorer-v1``'s: ``memory_crumbs`` (crumbs held), ``memory_steps``
(steps R1 headed for a crumb, cumulative), ``memory_dropped`` (crumbs dropped, cumulative);
mode ``"memory"`` while it heads for one (``steps_memory``).
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np
from pydantic import Field

from teamnav.papers.los_help.brains.brain import XY
from teamnav.papers.los_help.brains.explorer import LosExplorer, LosExplorerParams
from teamnav.papers.trails.brains.trails import Trail
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Action, Observation

__all__ = ["LosTrailExplorer", "LosTrailExplorerParams", "place_name"]

#: crumbs tested for visibility per step, shortest D first (cost bound; ours)
_MAX_TESTS = 24


def place_name(xy: XY) -> str:
    """The Place name of a target (its coordinates to the millimetre, own frame).

    >>> place_name((-6.6, -26.5))
    '-6.600,-26.500'
    """
    return f"{float(xy[0]):.3f},{float(xy[1]):.3f}"


class LosTrailExplorerParams(LosExplorerParams):
    """``los-explorer-v1``'s parameters plus the memory (module docstring).

    Attributes
    ----------
    goal_memory : {"off", "trail"}
        ``"off"``: Sgorbissa & Arkin's R1 (the default; runs identical to ``los-explorer-v1``).
        ``"trail"``: keep a Trail of the viewpoints of its goals and head back to them.
    goal_memory_places : {"current", "task"}
        Places crumbs are laid for: the current target only, or every target of the task in sight.
    goal_memory_when : {"always", "trouble"}
        Use the memory wherever A would drive, or only while in trouble (§5 Tr).
    goal_memory_reach : {"visible", "any"}
        Head only for crumbs in sight, or also (none in sight) for the best one anywhere via A.
    goal_memory_spacing_m : float
        No crumb is laid closer than this [m] to one of the same Place.
    """

    goal_memory: Literal["off", "trail"] = "off"
    goal_memory_places: Literal["current", "task"] = "task"
    goal_memory_when: Literal["always", "trouble"] = "always"
    goal_memory_reach: Literal["visible", "any"] = "visible"
    goal_memory_spacing_m: float = Field(0.4, gt=0.0, le=100.0)


class LosTrailExplorer(LosExplorer):
    """R1 with a Trail of the places where it saw its goals (``los-trail-explorer-v1``).

    Examples
    --------
    >>> import numpy as np
    >>> from teamnav.control import Observation, RangeScan, RobotInfo, SensorInfo
    >>> angles = np.linspace(-np.pi, np.pi, 360, endpoint=False)
    >>> info = RobotInfo(0, 1, 0.2, "holonomic_step", 0.5, 1.5, 0.1, 0.1,
    ...                  sensors={"laser": SensorInfo("laser", "laser", angles, 8.0)})
    >>> p = LosTrailExplorer.Params(targets_xy=[(3.0, 0.0)], goal_memory="trail")
    >>> brain = LosTrailExplorer(p, np.random.default_rng(0), info)
    >>> scan = RangeScan(np.full(360, 8.0), angles, 8.0)
    >>> _ = brain.step(Observation(0, 0, 0.0, np.zeros(3), np.zeros(3), scans={"laser": scan}))
    >>> brain.trail.crumb_place, brain.trail.crumb_s.tolist()
    (['3.000,0.000'], [3.0])
    """

    Params = LosTrailExplorerParams

    def __init__(self, params: LosTrailExplorerParams, rng: np.random.Generator, info: RobotInfo) -> None:
        super().__init__(params, rng, info)
        self.trail = Trail()
        self._names = [place_name(t) for t in self.targets]
        self._places = sorted({(n, t) for n, t in zip(self._names, self.targets)})
        for n, (x, y) in self._places:
            self.trail.set_place(n, x, y)
        #: crumbs dropped for the current target (indices into the trail), and its index
        self._dropped: set[int] = set()
        self._dropped_for = -1
        self._crumb: int | None = None
        self._crumb_stall = 0
        self.memory_steps = 0
        self.memory_dropped = 0

    # ------------------------------------------------------------------ laying crumbs
    def _lay_crumbs(self) -> None:
        """A Crumb where a Place comes into direct view (module docstring)."""
        p = self.params
        places = self._places if p.goal_memory_places == "task" else (
            [(self._names[self.target_index], self.targets[self.target_index])] if not self.finished else [])
        me = self._me_xy()
        for name, (gx, gy) in places:
            if not self._sees(gx, gy, 0.0):
                continue
            if self.trail.nearest_crumb(name, me[0], me[1], p.goal_memory_spacing_m) is not None:
                continue
            self.trail.add_crumbs([name], [me], [math.hypot(gx - me[0], gy - me[1])], [float(self._step)])

    def _decide_task(self, obs: Observation) -> Action:
        if self.params.goal_memory == "trail":
            if self._dropped_for != self.target_index:
                self._dropped, self._dropped_for, self._crumb, self._crumb_stall = set(), self.target_index, None, 0
            self._lay_crumbs()
        return super()._decide_task(obs)

    # ------------------------------------------------------------------ using them
    def choose_crumb(self, goal: XY) -> tuple[int, bool] | None:
        """The crumb of ``goal``'s Place to head for and whether it is in sight, or None.

        Among the crumbs not dropped for this target: the one in sight with the shortest
        ``dist(me, crumb) + s`` (§4.3), testing at most ``_MAX_TESTS`` in order of that D; with
        ``goal_memory_reach="any"`` and none in sight, the shortest D among all of them."""
        n = len(self.trail)
        if n == 0:
            return None
        mask = self.trail.place_mask(place_name(goal))
        if self._dropped:
            mask[list(self._dropped)] = False
        idx = np.flatnonzero(mask)
        if idx.size == 0:
            return None
        me = self._me_xy()
        xy = self.trail.crumb_xy_m[idx]
        d_me = np.hypot(xy[:, 0] - me[0], xy[:, 1] - me[1])
        dd = d_me + self.trail.crumb_s[idx]
        order = np.argsort(dd, kind="stable")
        tests = 0
        for j in order:
            if d_me[j] > self.vis_radius_m:
                continue
            if self._sees(float(xy[j, 0]), float(xy[j, 1]), self.radius_m):
                return int(idx[j]), True
            tests += 1
            if tests >= _MAX_TESTS:
                break
        if self.params.goal_memory_reach == "any":
            return int(idx[order[0]]), False
        return None

    def _unseen_goal(self, goal: XY) -> tuple[Action, bool]:
        p = self.params
        if p.goal_memory != "trail" or (p.goal_memory_when == "trouble" and not self.trouble.tr):
            return super()._unseen_goal(goal)
        while True:
            pick = self.choose_crumb(goal)
            if pick is None:
                self._crumb = None
                return super()._unseen_goal(goal)
            i, _ = pick
            cx, cy = (float(v) for v in self.trail.crumb_xy_m[i])
            me = self._me_xy()
            if math.hypot(cx - me[0], cy - me[1]) >= p.ghost_tolerance_m:
                break
            self._drop(i)  # reached without the goal in view: not a viewpoint any more
        if i != self._crumb:
            self._crumb, self._crumb_stall = i, 0
        self.mode = "memory"
        self.memory_steps += 1
        action, progressing = self._head_to((cx, cy), ("memory", i), end_margin_m=0.0)
        self._crumb_stall = 0 if progressing else self._crumb_stall + 1
        if self._crumb_stall >= p.trouble_cr:
            self._drop(i)
        return action, progressing

    def _drop(self, i: int) -> None:
        self._dropped.add(int(i))
        self.memory_dropped += 1
        if self._crumb == i:
            self._crumb, self._crumb_stall = None, 0

    def log(self) -> dict[str, Any]:
        """``los-explorer-v1``'s log plus ``memory_crumbs``, ``memory_steps``, ``memory_dropped``
        (with ``goal_memory: "trail"`` only, so that ``"off"`` logs exactly as ``los-explorer-v1``)."""
        out = super().log()
        if self.params.goal_memory == "trail":
            out.update(memory_crumbs=len(self.trail), memory_steps=int(self.memory_steps),
                       memory_dropped=int(self.memory_dropped))
        return out
