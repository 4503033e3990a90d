"""The trail brains as group brains: a team stepped in one call, Navigate compiled.

``blazing-trail-v1`` (:class:`~teamnav.papers.trails.brains.blazing_trail.BlazingTrail`, Blazing
§4.1-4.2) and ``trail-share-v1`` (:class:`~teamnav.papers.trails.brains.trail_share.TrailShare`,
Try §3) under ``group_brains`` (``docs/concepts/group-brains.md``). What is compiled so far is
Navigate (§4.2's wall following, openings, 180° rule and Panic), the larger part of a trail
robot's step: each robot's brain is its reference brain with its Navigate replaced by
:class:`~teamnav.control.nav.navigate_compiled.CompiledNavigate` (the same rules, state as
arrays, one numba call per robot). The crumb lists, the Trails, the waggle dance and the task
round run as the reference's own code, so they are the reference by construction; the runs are
the same bit for bit (``tests/test_trail_compiled.py``, both columns, both sections, with drift).

Not compiled yet (the plan in ``docs/concepts/group-brains.md``): the crumb queries (the
circular mean needs numpy's own ``sin`` and pairwise sum to give the same bits), the Trails'
transforms, and one kernel call for the whole team instead of one per robot.

A robot whose Navigate parameters the kernel declines
(:func:`~teamnav.control.nav.navigate_compiled.unsupported`: the meeting flags) keeps the
reference Navigate inside the group, so a run is never inexact. Robots started one at a time
(a scenario's ``launch``) are skipped while they wait (``GroupObservation.waiting``), as the
per-robot path skips them.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from teamnav.control.group import GroupAction, GroupObservation
from teamnav.control.nav import navigate_compiled as NC
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Observation, RangeScan

__all__ = ["BlazingTrailGroup", "TrailShareGroup"]


def _row_observation(obs: GroupObservation, r: int) -> Observation:
    """Row ``r`` as the :class:`Observation` the engine hands a per-robot brain (the trail
    robots have no detector)."""
    scans = {name: RangeScan(obs.ranges_m[name][r], obs.angles_rad[name], obs.max_range_m[name])
             for name in obs.ranges_m}
    return Observation(int(obs.robot_ids[r]), int(obs.step), float(obs.time_s), obs.odom_pose[r], obs.odom_delta[r],
                       scans, (), bool(obs.stalled[r]), obs.inbox[r],
                       obs.events[r] if obs.events is not None else ())


class _TrailGroup:
    """A team of one trail brain class: each robot its reference brain over a compiled Navigate."""

    #: the reference brain class (set by the subclasses, imported lazily)
    controller: str = ""
    #: robots started one at a time are skipped while they wait
    handles_waiting = True

    @classmethod
    def _cls(cls) -> type:
        import importlib

        module, _, name = cls.controller.partition(":")
        return getattr(importlib.import_module(module), name)

    @classmethod
    def unsupported(cls, params: Sequence[Any], infos: Sequence[RobotInfo]) -> str | None:
        """None when some robot's Navigate compiles; else why not (the team runs per robot)."""
        whys = []
        for p in params:
            try:
                nav = cls._probe_params(p)
            except ValueError as exc:
                whys.append(str(exc))
                continue
            why = NC.unsupported(nav)
            if why is None:
                return None
            whys.append(why)
        return "; ".join(sorted(set(whys))) or "no robots"

    @classmethod
    def _probe_params(cls, params: Any):
        """The Navigate parameters the reference brain builds for ``params``."""
        raise NotImplementedError

    def __init__(self, params: Sequence[Any], rngs: Sequence[np.random.Generator], infos: Sequence[RobotInfo]) -> None:
        ctl = self._cls()
        self.robots: list[Any] = []
        #: robots whose Navigate is compiled (the others keep the reference's)
        self.compiled_robots = 0
        for p, rng, info in zip(params, rngs, infos):
            brain = ctl(p, rng, info)
            nav = brain.nav
            if NC.unsupported(nav.params) is None:
                brain.nav = NC.CompiledNavigate(nav.params, rng, info, laser=nav.laser)
                self.compiled_robots += 1
            self.robots.append(brain)
        self._n = len(self.robots)

    def step_group(self, obs: GroupObservation) -> GroupAction:
        """Every robot's step (a waiting robot's brain is off: command 0, no messages)."""
        n = self._n
        v = np.zeros(n)
        w = np.zeros(n)
        d = np.full(n, math.nan)
        outbox: list = []
        waiting = obs.waiting
        for r, brain in enumerate(self.robots):
            if waiting is not None and waiting[r]:
                continue
            action, msgs = brain.step(_row_observation(obs, r))
            v[r] = action.v_mps
            w[r] = action.omega_radps
            if action.direction_rad is not None:
                d[r] = action.direction_rad
            if msgs:
                rid = int(obs.robot_ids[r])
                outbox.extend((rid, m) for m in msgs)
        return GroupAction(v, w, d, outbox)


class BlazingTrailGroup(_TrailGroup):
    """``blazing-trail-v1`` teams (module docstring)."""

    controller = "teamnav.papers.trails.brains.blazing_trail:BlazingTrail"

    @classmethod
    def _probe_params(cls, params: Any):
        from teamnav.papers.trails.brains.blazing_trail import navigate_params

        return navigate_params(params.navigate, params.cruise_speed_mps)


class TrailShareGroup(_TrailGroup):
    """``trail-share-v1`` teams (module docstring)."""

    controller = "teamnav.papers.trails.brains.trail_share:TrailShare"

    @classmethod
    def _probe_params(cls, params: Any):
        from teamnav.papers.trails.brains.blazing_trail import navigate_params
        from teamnav.papers.trails.brains.trail_share import TRAIL_SHARE_NAVIGATE

        return navigate_params({**TRAIL_SHARE_NAVIGATE, **params.navigate}, params.cruise_speed_mps)
