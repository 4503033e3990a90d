"""Group brains: a whole team of per-robot brains stepped in one call, from arrays.

A per-robot :class:`~teamnav.control.protocol.Controller` class may name a *group brain*
(its class attribute ``group_brain``, a ``"module:Class"`` string, imported only when used):
a class that steps every robot of a team at once, its state held as arrays (one row per
robot), its step compiled. The per-robot class stays the readable reference; a run with
``Simulation(..., group_brains=True)`` uses the group brain wherever it says it can run the
robots' parameters (:meth:`GroupBrain.unsupported` returns None) and gives the same run, bit
for bit (the group brain's identity test says so). See ``docs/concepts/group-brains.md``.

What a group brain is given is what the per-robot brains of its robots are given, row by
row, and nothing else (truth and belief never mix): :class:`GroupObservation`. What it gives
back is what they would: :class:`GroupAction`. Its public per-robot face (the ``finished``
flag, ``log()``, counters that experiments read) is one view object per robot,
``GroupBrain.robots``, which the simulator puts where the per-robot brains would be
(``Simulation.brains``), so readers do not change.
"""

from __future__ import annotations

import hashlib
import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, Sequence, runtime_checkable

import numpy as np

from teamnav.control.protocol import RobotInfo
from teamnav.control.types import _fast_frozen_init

__all__ = ["GroupAction", "GroupBrain", "GroupObservation", "empty_inbox", "group_brain_class", "pad_detections",
           "renew_stale_caches"]


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class GroupObservation:
    """One step's observations of every robot of a team, row r for ``robot_ids[r]``.

    Arrays are fresh for this step (never views of the simulator's state); each row is
    exactly what that robot's :class:`~teamnav.control.types.Observation` carries.

    Attributes
    ----------
    robot_ids : ndarray (n,) int64
    step : int
    time_s : float
    odom_pose : ndarray (n, 3) float64
        Own odometry pose of each robot, in its own odometry frame.
    odom_delta : ndarray (n, 3) float64
        Odometry increment of the last step.
    stalled : ndarray (n,) bool
    ranges_m : dict of str to ndarray (n, B) float64
        Each range sensor's readings (every robot of a team has the sensors the group brain reads).
    angles_rad : dict of str to ndarray (B,) float64
        Beam directions in the body frame (read-only).
    max_range_m : dict of str to float
    det_count : ndarray (n,) int64
        Detections of robot r are the first ``det_count[r]`` entries of its rows below.
    det_id : ndarray (n, K) int64
        Identity reported (-1: none, and the padding).
    det_range_m, det_bearing_rad : ndarray (n, K) float64
        Range and body-frame bearing of each detection (NaN padding).
    inbox : tuple of n tuples of Message
        Messages delivered this step to each robot.
    events : tuple of n tuples, or None
        Task events of each robot (None: no place fired this step).
    waiting : ndarray (n,) bool, or None
        Robots not started yet (a scenario's ``launch``: one at a time from one spot): their
        brains are off this step, as the per-robot path does not call them, and their commands
        are ignored (zeroed by the engine). None: every robot runs. Only a group brain class with
        ``handles_waiting = True`` is given a run with a launch.
    """

    robot_ids: np.ndarray
    step: int
    time_s: float
    odom_pose: np.ndarray
    odom_delta: np.ndarray
    stalled: np.ndarray
    ranges_m: dict
    angles_rad: dict
    max_range_m: dict
    det_count: np.ndarray
    det_id: np.ndarray
    det_range_m: np.ndarray
    det_bearing_rad: np.ndarray
    inbox: tuple
    events: tuple | None
    waiting: np.ndarray | None = None


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class GroupAction:
    """Every robot's command of this step and the messages it sends.

    ``direction_rad`` is NaN where a robot commands no fixed step (``Action.direction_rad``
    None); ``outbox`` lists ``(sender robot id, Message)`` in robot order.
    """

    v_mps: np.ndarray
    omega_radps: np.ndarray
    direction_rad: np.ndarray
    outbox: list


@runtime_checkable
class GroupBrain(Protocol):
    """The interface of a group brain class (constructed as ``cls(params, rngs, infos)``: one
    validated Params, one Generator and one RobotInfo per robot of the team, in robot order:
    what the per-robot brains would be built from)."""

    #: one view per robot (``finished``, ``log()``, the reference brain's public counters)
    robots: list

    @classmethod
    def unsupported(cls, params: Sequence[Any], infos: Sequence[RobotInfo]) -> str | None:
        """Why this group brain cannot run these robots exactly as the reference would, or None."""

    def step_group(self, obs: GroupObservation) -> GroupAction:
        """One step of every robot."""


def group_brain_class(controller_cls: type) -> type | None:
    """The group brain a controller class names (``group_brain = "module:Class"``), or None.

    Only the class that declares it: a subclass (which changes the step) is not run by its
    parent's group brain unless it names one itself."""
    spec = vars(controller_cls).get("group_brain")
    if spec is None:
        return None
    if isinstance(spec, type):
        return spec
    module, _, name = str(spec).partition(":")
    return getattr(importlib.import_module(module), name)


def pad_detections(per_robot: Sequence[Sequence[Any]] | None, n: int) -> tuple[np.ndarray, ...]:
    """``(det_count, det_id, det_range_m, det_bearing_rad)`` of :class:`GroupObservation` from
    each robot's tuple of :class:`~teamnav.control.types.Detection` (None: none at all)."""
    k = max((len(d) for d in per_robot), default=0) if per_robot is not None else 0
    if k == 0:  # nobody detected anybody (the common case: fresh empty arrays, no filling)
        return np.zeros(n, dtype=np.int64), np.empty((n, 0), dtype=np.int64), np.empty((n, 0)), np.empty((n, 0))
    count = np.zeros(n, dtype=np.int64)
    ids = np.full((n, k), -1, dtype=np.int64)
    rng = np.full((n, k), np.nan)
    brg = np.full((n, k), np.nan)
    if per_robot is not None and k:
        for r, dets in enumerate(per_robot):
            count[r] = len(dets)
            for j, d in enumerate(dets):
                ids[r, j] = -1 if d.robot_id is None else int(d.robot_id)
                rng[r, j] = d.range_m
                brg[r, j] = d.bearing_rad
    return count, ids, rng, brg


def empty_inbox(n: int) -> tuple:
    """n empty inboxes."""
    return ((),) * n



def renew_module_caches(module_name: str, callees: Sequence[Any]) -> bool:
    """:func:`renew_stale_caches` for every cached numba kernel defined in the module
    ``module_name``, against the source files of the modules ``callees`` (each compiled module
    calls this once at import, naming the modules whose numba functions it calls)."""
    import sys

    here = sys.modules[module_name]
    kernels = [f for f in vars(here).values() if hasattr(f, "_cache") and hasattr(f, "py_func")
               and f.py_func.__module__ == module_name]
    return renew_stale_caches(kernels, [m.__file__ for m in callees])


def renew_stale_caches(dispatchers: Sequence[Any], sources: Sequence[str | Path]) -> bool:
    """Empty the numba caches of ``dispatchers`` when a module they call has changed.

    numba's on-disk cache (``cache=True``) checks only the source file of the function it
    compiled: a compiled group brain calls numba functions of other modules (the reference's
    kernels, the compiled navigators), and after one of those changes it would go on running
    their old code from the cache. A stamp of the ``sources`` (the callee modules' files) is
    kept beside each cache; when it no longer matches, the cache's index is emptied (the
    kernel compiles afresh, once) and the stamp rewritten. Returns whether any was renewed.
    A cache folder that cannot be written is left alone.
    """
    digest = hashlib.sha256()
    for src in sorted(str(p) for p in sources):
        digest.update(src.encode())
        digest.update(Path(src).read_bytes())
    stamp = digest.hexdigest()
    renewed = False
    for d in dispatchers:
        cache = getattr(d, "_cache", None)
        path = getattr(cache, "cache_path", None)
        if path is None:
            continue
        mark = Path(path) / f"{Path(d.py_func.__code__.co_filename).stem}.{d.py_func.__name__}.deps"
        try:
            if mark.is_file() and mark.read_text() == stamp:
                continue
            cache.flush()
            mark.parent.mkdir(parents=True, exist_ok=True)
            mark.write_text(stamp)
            renewed = True
        except OSError:
            continue
    return renewed
