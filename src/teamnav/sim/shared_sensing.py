"""Sensing that groups of per-robot brains share: one pass per step where their sensors are alike.

The line-of-sight scenarios give each of Sgorbissa & Arkin's R1..R4 a group of its own, with
equal detectors and equal lasers. Sensed group by group, a 4-robot team pays four detector
calls and four casts a step; :class:`SharedSensing` plans, once per simulation, which groups
can share one call, and makes those calls each step:

- **Detectors** with equal configurations: the noise-free part (range, field of view, line of
  sight) once for all their observers
  (:meth:`~teamnav.sim.sensors.detector.RobotDetector._detect_groups`); each group still draws
  its noise from its own stream.
- **Range sensors** that cast the same rays (same materials, ray directions, range and robot
  bodies): one cast for the robots of all those groups while the call stays below the sensors'
  parallel threshold; each group's noise from its own stream and its own key, into an array of
  its own.

Every stream sees the same draws as with one call per group, so a run is the same bit for bit.
:class:`~teamnav.sim.engine.Simulation` builds one at start-up and reads it in its sensing
step; the truth (``RobotState``) is passed in, never kept.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

__all__ = ["SharedSensing"]


class SharedSensing:
    """Which per-robot groups share a detector pass or a cast, and those calls each step.

    Parameters
    ----------
    groups
        The simulation's groups (``engine._Group``: ``index``, ``batched``, ``cfg.count``,
        ``ids``, ``detector``, ``detector_rng``, ``sensors``, ``rngs``, ``bodies``). Batched
        groups never share: they sense only their controller's sensor, in their own call.
    state
        The truth, read for the robots' radii and positions when a shared cast sees robots.

    Attributes
    ----------
    det_sets : list of (detector, [groups])
        One detector pass per entry, for all its groups.
    scan_sets : list of (sensor, [(group, k)], robot ids, bodies, noise starts or None)
        One cast per entry (only entries of two or more groups): the first member's sensor, the
        members' sensor indices, the robots in cast order, the robot bodies the rays see (or
        None) and, when every member's noise parameters are equal, the members' first rows
        (all noise in one kernel call, each with its own key).
    shared_scan : set of (group index, sensor k)
        The sensors whose readings come from a shared cast.
    blocks : list of ndarray or None
        Per scan set, the last :meth:`readings`' array of all its rows (fresh each step) when
        its noise took one call, else None.
    """

    def __init__(self, groups: Sequence[Any], state: Any) -> None:
        from teamnav.sim.sensors.robot_hits import PARALLEL_MIN_RAYS

        self.det_sets: list[tuple[Any, list[Any]]] = []
        self.scan_sets: list[tuple[Any, list[tuple[Any, int]], np.ndarray, Any, np.ndarray | None]] = []
        for grp in groups:
            if grp.batched:
                continue
            if grp.detector is not None:
                for det, members in self.det_sets:
                    if det.cfg == grp.detector.cfg:
                        members.append(grp)
                        break
                else:
                    self.det_sets.append((grp.detector, [grp]))
        candidates: list[tuple[tuple, list[tuple[Any, int]]]] = []
        for grp in groups:
            if grp.batched:
                continue
            for k, sensor in enumerate(grp.sensors):
                key = (sensor.sees, sensor.ray_angles_rad.tobytes(), sensor.rays_per_beam, sensor.angles_rad.shape[0],
                       sensor.max_range_m, sensor.sees_robots, grp.bodies[k] is not None)
                n_rays = sensor.ray_angles_rad.shape[0]
                for skey, members in candidates:
                    rows = sum(g.cfg.count for g, _ in members) + grp.cfg.count
                    if skey == key and rows * n_rays < PARALLEL_MIN_RAYS:
                        members.append((grp, k))
                        break
                else:
                    candidates.append((key, [(grp, k)]))
        for _, members in candidates:
            if len(members) < 2:
                continue
            idx = np.concatenate([g.ids for g, _ in members])
            g0, k0 = members[0]
            bodies = None
            if g0.bodies[k0] is not None:
                bodies = (state.x_m, state.y_m, state.radius_m, idx)
            # equal noise parameters: every group's noise in one kernel call, with its own key
            noise = {(g.sensors[k].noise_std_m, g.sensors[k].p_max, g.sensors[k].p_short) for g, k in members}
            starts = np.cumsum([0] + [g.cfg.count for g, _ in members]).astype(np.int64)
            self.scan_sets.append((g0.sensors[k0], members, idx, bodies, starts if len(noise) == 1 else None))
        self.shared_scan = {(g.index, k) for _, members, _, _, _ in self.scan_sets for g, k in members}
        #: per scan set, the last step's ranges of all its rows when its noise took one kernel
        #: call (the members' readings are row blocks of it), else None
        self.blocks: list[np.ndarray | None] = [None] * len(self.scan_sets)

    def readings(self, state: Any) -> dict:
        """This step's ranges of the shared casts: ``{(group index, sensor k): (n, B) array}``."""
        from teamnav.sim.sensors.range_sensors import _counter_noise_blocks, _keyed_noise, draw_noise_key

        s = state
        out = {}
        for j, (sensor, members, idx, bodies, starts) in enumerate(self.scan_sets):
            true = sensor._true_ranges(s.x_m[idx], s.y_m[idx], s.theta_rad[idx], bodies)
            if starts is not None:
                keys = np.array([draw_noise_key(grp.rngs[k]) for grp, k in members], dtype=np.uint64)
                ranges = np.empty(true.shape)  # fresh this step; each group reads its own rows
                _counter_noise_blocks(true, keys, starts, sensor.noise_std_m, sensor.p_max, sensor.p_short,
                                      sensor.max_range_m, ranges)
                self.blocks[j] = ranges
                sl = starts.tolist()
                for j, (grp, k) in enumerate(members):
                    out[(grp.index, k)] = ranges[sl[j]:sl[j + 1]]
                continue
            r0 = 0
            for grp, k in members:
                r1 = r0 + grp.cfg.count
                own = grp.sensors[k]
                ranges = np.empty((r1 - r0, true.shape[1]))
                out[(grp.index, k)] = _keyed_noise(true[r0:r1], draw_noise_key(grp.rngs[k]), own.noise_std_m, own.p_max,
                                                   own.p_short, own.max_range_m, ranges)
                r0 = r1
        return out

    def detections(self, state: Any, ids_all: np.ndarray, padded: dict | None = None) -> dict:
        """This step's detections, ``{group index: list of tuples of Detection}``.

        ``padded`` (optional): ``{index into det_sets: None}``; each of those sets whose
        detector has rule 4 only is instead filled in with its groups' detections in a group
        brain's padded arrays (:meth:`Detector._detect_groups_padded`), and its groups are left
        out of the result (the same draws either way)."""
        s = state
        out = {}
        for j, (det, members) in enumerate(self.det_sets):
            if padded is not None and j in padded:
                got = det._detect_groups_padded(s.x_m, s.y_m, s.theta_rad, s.radius_m, [g.ids for g in members],
                                                [g.detector_rng for g in members], ids_all)
                if got is not None:
                    padded[j] = got
                    continue
            found = det._detect_groups(s.x_m, s.y_m, s.theta_rad, s.radius_m, [g.ids for g in members],
                                       [g.detector_rng for g in members], ids_all)
            for grp, d in zip(members, found):
                out[grp.index] = d
        return out
