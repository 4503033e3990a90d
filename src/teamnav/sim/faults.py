"""Faults injected into a run on the truth side: deaths, radio failures, sensor dropouts,
kidnappings and bursts of false detections (scenario section ``faults``,
:class:`~teamnav.sim.config.FaultsConfig`).

The engine (:class:`~teamnav.sim.engine.Simulation`) owns one :class:`FaultInjector` when a
scenario lists faults, and none otherwise: a run without faults takes none of the paths here
and stays the same bit for bit. Brains are never told of a fault; they learn of it only
through what they observe (a teammate that stops answering, a scan with no echo, a jump their
odometry did not feel), as on real robots. Everything here reads and writes the truth and is
for the engine only (DESIGN "truth and belief never mix").

Timing
------
A fault at ``t`` takes effect at the first step ``k`` with ``k * dt_s >= t`` (a window
``[t0, t1]`` covers the steps with ``t0 <= k * dt_s <= t1``). At step ``k`` the engine calls
:meth:`FaultInjector.begin_step` before anything else, so everything of that step (motion
excepted, which executes the commands decided at step ``k - 1``) sees the fault:

- **death** at step ``k``: the robot's brain is not stepped from step ``k`` on and its
  commands are zero, so it stops where step ``k``'s motion left it; its radio is off. Its body
  stays in the world: other robots' lasers, sonars, detectors and collisions still meet it.
  A batched group (one brain for many robots) still steps its brain, whose commands for the
  dead robots are zeroed. The brain's ``log()`` is still recorded (its last state).
- **radio dropout**: the robot's outbox is dropped before the radio, and nothing is delivered
  to it (messages already in the air for it are lost too).
- **blackout**: messages sent in the window are lost, and so are those due for delivery in it
  (sent at the step before the window opened); messages sent after the window are delivered
  one step later as usual.
- **sensor dropout**: the sensor is simulated as usual (its noise stream draws the same
  numbers), then its output is withheld: every beam at ``max_range_m`` (``no_return``), the
  key left out of ``Observation.scans`` (``no_scan``), or no detections at all (detector).
- **kidnapping** at step ``k``: after the motion and the odometry of step ``k`` the robot's
  true pose is set to the target (odometry integrated the motion before the jump and never
  sees it); places fire and sensors sense from the new pose in the same step.
- **false positives**: appended after the detector's own detections of the step (after its
  true ones and its own ``p_false_positive`` phantom), drawn from the run's fault stream, so
  the detector's own stream is not disturbed.

Every fault, when it takes effect (and a window when it ends), is written to the run's event
log (``events.json``) as ``{"step", "t_s", "robot", "place": None, "event": None, "fault":
KIND, ...}`` with ``robot`` -1 for a blackout; ``event`` is None so that task metrics, which
count place events, ignore it. Kinds: ``died``, ``radio_off``, ``radio_on``,
``blackout_start``, ``blackout_end``, ``sensor_off``, ``sensor_on``, ``kidnapped`` (with
``from`` and ``to`` poses, heading in radians), ``false_positives_start``,
``false_positives_end``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamnav.control.types import Detection
from teamnav.geometry.angles import wrap_angle
from teamnav.sim.collisions import discs_hit_walls
from teamnav.sim.config import FaultsConfig, SimConfig, group_of_robot, resolve_robot, resolve_sensor

__all__ = ["FaultInjector", "first_step", "last_step"]

#: random draws allowed for a random kidnapping target in one step before it is tried again
#: at the next step
KIDNAP_TRIES_PER_STEP = 2000
_EPS = 1e-9


def first_step(t_s: float, dt_s: float) -> int:
    """The first step ``k`` with ``k * dt_s >= t_s``.

    Examples
    --------
    >>> first_step(1.0, 0.1), first_step(1.05, 0.1), first_step(0.0, 0.1)
    (10, 11, 0)
    """
    return max(0, math.ceil(t_s / dt_s - _EPS))


def last_step(t_s: float, dt_s: float) -> int:
    """The last step ``k`` with ``k * dt_s <= t_s``.

    Examples
    --------
    >>> last_step(1.0, 0.1), last_step(1.05, 0.1)
    (10, 10)
    """
    return math.floor(t_s / dt_s + _EPS)


@dataclass
class _Window:
    robot: int  # -1: every robot (a blackout, a burst for every detector)
    s0: int
    s1: float  # last step (inclusive); inf for "for good"
    active: bool = False


@dataclass
class _Dropout(_Window):
    group: int = 0
    sensor: int | None = None  # index in the group's sensors list; None: the detector
    name: str = ""
    reading: str = "no_return"


@dataclass
class _Burst(_Window):
    rate_hz: float = 0.0


@dataclass
class _Kidnap:
    robot: int
    step: int
    pose: tuple[float, float, float] | None  # (x, y, theta_rad)
    region: tuple[float, float, float, float] | None
    field: str
    done: bool = False


class FaultInjector:
    """The faults of one run, applied by the engine (see the module docstring).

    Parameters
    ----------
    faults : FaultsConfig
    config : SimConfig
        The run's configuration (robots are resolved against its groups).
    grid : OccupancyGrid
        The true map.
    blocking, clear_m : ndarray of shape (H, W)
        The engine's blocking mask (uint8) and its distance field [m].
    dt_s : float
    rng : numpy.random.Generator
        The run's fault stream (random kidnapping targets, phantom detections).
    events : list of dict
        The run's event log, appended to as faults take effect.

    Attributes
    ----------
    dead : ndarray of shape (N,), bool
        Robots that died (read-only for the engine).
    radio_off : ndarray of shape (N,), bool
        Robots whose radio is off now (dead ones included).
    any_radio_off : bool
    blackout : bool
        Whether the radio carries nothing at this step.
    any_dead : bool
    stats : dict of str to int
        Counts for the run's record: deaths, kidnappings done, phantoms reported, scans withheld.

    Raises
    ------
    ValueError
        A kidnapping pose that puts the robot in a wall or off the map, or a fault on a robot
        of a batched group that its brain cannot feel (a detector or ``no_scan``), naming the field.
    """

    def __init__(self, faults: FaultsConfig, config: SimConfig, grid, blocking, clear_m, dt_s: float,
                 rng: np.random.Generator, events: list) -> None:
        self.cfg = faults
        self.dt_s = float(dt_s)
        self.rng = rng
        self.events = events
        self.grid = grid
        self._blocking = blocking
        self._clear = clear_m
        self._geo = grid.geo
        robots = config.robots
        self.n = n = config.n_robots
        self.radius_m = np.repeat([g.radius_m for g in robots], [g.count for g in robots]).astype(np.float64)
        self.group_index = np.repeat(np.arange(len(robots)), [g.count for g in robots])
        self.dead = np.zeros(n, dtype=bool)
        self.radio_off = np.zeros(n, dtype=bool)
        self.any_dead = False
        self.any_radio_off = False
        self.blackout = False
        self.stats = {"deaths": 0, "kidnappings": 0, "phantoms": 0, "scans_withheld": 0, "detections_withheld": 0}
        self._step = -1
        dt = self.dt_s

        def robot(ref, field):
            return resolve_robot(ref, robots, field)

        self._deaths = [(robot(d.robot, f"faults.deaths[{j}].robot"), first_step(d.t_s, dt))
                        for j, d in enumerate(faults.deaths)]
        self._dropouts_radio = [
            _Window(robot(d.robot, f"faults.radio_dropouts[{j}].robot"), first_step(d.t_s, dt),
                    math.inf if d.until_s is None else last_step(d.until_s, dt))
            for j, d in enumerate(faults.radio_dropouts)
        ]
        self._blackouts = [_Window(-1, first_step(b.t0_s, dt), last_step(b.t1_s, dt)) for b in faults.blackouts]
        self._sensor = []
        for j, d in enumerate(faults.sensor_dropouts):
            field = f"faults.sensor_dropouts[{j}]"
            i = robot(d.robot, f"{field}.robot")
            gi = group_of_robot(i, robots)
            k = resolve_sensor(d.sensor, robots[gi], f"{field}.sensor")
            name = "detector" if k is None else robots[gi].sensors[k].name
            self._sensor.append(_Dropout(i, first_step(d.t0_s, dt), last_step(d.t1_s, dt), group=gi, sensor=k,
                                         name=name, reading=d.reading))
        self._bursts = []
        for j, b in enumerate(faults.false_positives):
            i = -1 if b.robot is None else robot(b.robot, f"faults.false_positives[{j}].robot")
            self._bursts.append(_Burst(i, first_step(b.t0_s, dt), last_step(b.t1_s, dt), rate_hz=float(b.rate_hz)))
        self._kidnaps = []
        for j, kd in enumerate(faults.kidnappings):
            field = f"faults.kidnappings[{j}]"
            i = robot(kd.robot, f"{field}.robot")
            pose = None
            if kd.pose is not None:
                x, y, th_deg = (float(v) for v in kd.pose)
                if discs_hit_walls(blocking, clear_m, self._geo, np.array([x]), np.array([y]),
                                   np.array([self.radius_m[i]]))[0]:
                    raise ValueError(f"{field}.pose: expected a pose where robot {i} (radius {self.radius_m[i]} m) "
                                     f"lies in free space inside the map, got ({x}, {y}), which overlaps a wall or "
                                     "the map edge")
                pose = (x, y, float(wrap_angle(math.radians(th_deg))))
            region = kd.region if kd.region is not None else None
            self._kidnaps.append(_Kidnap(i, max(1, first_step(kd.t_s, dt)), pose, region, field))
        self._kidnaps.sort(key=lambda kd: kd.step)
        self._kidnap_steps = {kd.step for kd in self._kidnaps}
        #: (group index, sensor index) -> rows of the group whose output is withheld now
        self.dropped: dict[tuple[int, int | None], np.ndarray] = {}
        #: (N,) phantoms per second per robot now (0: none)
        self.fp_rate = np.zeros(n)
        self.any_fp = False

    # ------------------------------------------------------------------ per step
    def _log(self, step: int, robot: int, kind: str, **extra) -> None:
        self.events.append({"step": int(step), "t_s": float(step * self.dt_s), "robot": int(robot), "place": None,
                            "event": None, "fault": kind, **extra})

    def begin_step(self, step: int) -> None:
        """Update who is dead, whose radio and sensors are off and which bursts run at ``step``."""
        self._step = step
        for i, s in self._deaths:
            if s <= step and not self.dead[i]:
                self.dead[i] = True
                self.any_dead = True
                self.stats["deaths"] += 1
                self._log(step, i, "died")
        radio = self.dead.copy()
        for w in self._dropouts_radio:
            on = w.s0 <= step <= w.s1
            if on != w.active:
                w.active = on
                self._log(step, w.robot, "radio_off" if on else "radio_on")
            radio[w.robot] |= on
        self.radio_off = radio
        self.any_radio_off = bool(radio.any())
        blackout = False
        for w in self._blackouts:
            on = w.s0 <= step <= w.s1
            if on != w.active:
                w.active = on
                self._log(step, -1, "blackout_start" if on else "blackout_end")
            blackout |= on
        self.blackout = blackout
        dropped: dict[tuple[int, int | None], np.ndarray] = {}
        for d in self._sensor:
            on = d.s0 <= step <= d.s1
            if on != d.active:
                d.active = on
                self._log(step, d.robot, "sensor_off" if on else "sensor_on", sensor=d.name, reading=d.reading)
            if on:
                dropped.setdefault((d.group, d.sensor), np.zeros(self.n, dtype=bool))[d.robot] = True
        self.dropped = dropped
        rate = np.zeros(self.n)
        for b in self._bursts:
            on = b.s0 <= step <= b.s1
            if on != b.active:
                b.active = on
                self._log(step, b.robot, "false_positives_start" if on else "false_positives_end", rate_hz=b.rate_hz)
            if on:
                if b.robot < 0:
                    rate += b.rate_hz
                else:
                    rate[b.robot] += b.rate_hz
        self.fp_rate = rate
        self.any_fp = bool(rate.any())

    # ------------------------------------------------------------------ motion
    def zero_commands(self, v_cmd: np.ndarray, w_cmd: np.ndarray, dir_cmd: np.ndarray) -> None:
        """Dead robots command nothing (holonomic robots: no direction, they stay)."""
        if self.any_dead:
            d = self.dead
            v_cmd[d] = 0.0
            w_cmd[d] = 0.0
            dir_cmd[d] = np.nan

    @property
    def kidnap_due(self) -> bool:
        """Whether a kidnapping waits at this step (or from an earlier one)."""
        return any(not kd.done and kd.step <= self._step for kd in self._kidnaps)

    def kidnap(self, state) -> None:
        """Move every robot whose kidnapping is due to its target (true pose only)."""
        for kd in self._kidnaps:
            if kd.done or kd.step > self._step:
                continue
            i = kd.robot
            target = kd.pose if kd.pose is not None else self._random_pose(i, kd.region, state)
            if target is None or self._overlaps_robot(i, target[0], target[1], state):
                continue  # try again at the next step
            before = [float(state.x_m[i]), float(state.y_m[i]), float(state.theta_rad[i])]
            state.x_m[i], state.y_m[i], state.theta_rad[i] = target
            kd.done = True
            self.stats["kidnappings"] += 1
            self._log(self._step, i, "kidnapped", **{"from": before, "to": [float(v) for v in target]})

    def _overlaps_robot(self, i: int, x: float, y: float, state) -> bool:
        d2 = (state.x_m - x) ** 2 + (state.y_m - y) ** 2
        reach = (state.radius_m + self.radius_m[i]) ** 2
        d2[i] = np.inf
        return bool((d2 < reach).any())

    def _random_pose(self, i: int, region, state) -> tuple[float, float, float] | None:
        xmin, xmax, ymin, ymax = region if region is not None else self.grid.bounds_m
        r = float(self.radius_m[i])
        rng = self.rng
        for _ in range(KIDNAP_TRIES_PER_STEP // 64):
            xs = rng.uniform(xmin, xmax, 64)
            ys = rng.uniform(ymin, ymax, 64)
            hit = discs_hit_walls(self._blocking, self._clear, self._geo, xs, ys, np.full(64, r))
            for x, y in zip(xs[~hit].tolist(), ys[~hit].tolist()):
                if not self._overlaps_robot(i, x, y, state):
                    return (x, y, float(rng.uniform(-math.pi, math.pi)))
        return None

    # ------------------------------------------------------------------ sensing
    def readings(self, grp_index: int, start: int, readings: list) -> tuple[list, list | None]:
        """A per-robot group's range readings with this step's dropouts applied.

        ``readings``: ``[(name, ranges (n, B), angles, max_range_m)]`` in the group's sensor
        order. Returns the readings (a dropped row set to ``max_range_m`` in a fresh copy) and,
        per row, the names to leave out of ``scans`` (None when nothing is left out).
        """
        if not self.dropped:
            return readings, None
        omit = None
        out = []
        for k, (name, r, a, m) in enumerate(readings):
            rows = self.dropped.get((grp_index, k))
            if rows is not None:
                sel = rows[start:start + r.shape[0]]
                if sel.any():
                    self.stats["scans_withheld"] += int(sel.sum())
                    no_scan = [d.robot - start for d in self._sensor
                               if d.active and d.group == grp_index and d.sensor == k and d.reading == "no_scan"]
                    if no_scan:
                        omit = omit or [() for _ in range(r.shape[0])]
                        for row in no_scan:
                            omit[row] = omit[row] + (name,)
                    r = r.copy()
                    r[sel] = m
            out.append((name, r, a, m))
        return out, omit

    def batch_ranges(self, grp_index: int, k: int, start: int, ranges: np.ndarray, max_range_m: float) -> np.ndarray:
        """A batched group's ranges (sensor index ``k`` of the group) with dropouts applied."""
        rows = self.dropped.get((grp_index, k))
        if rows is None:
            return ranges
        sel = rows[start:start + ranges.shape[0]]
        if sel.any():
            self.stats["scans_withheld"] += int(sel.sum())
            ranges = ranges.copy()
            ranges[sel] = max_range_m
        return ranges

    def detections(self, grp_index: int, start: int, dets: list, detector) -> list:
        """A group's detections (one tuple per robot) with dropouts and phantoms applied."""
        rows = self.dropped.get((grp_index, None))
        if rows is None and not self.any_fp:
            return dets
        dets = list(dets)
        n_all = self.n
        cfg = detector.cfg
        for k in range(len(dets)):
            i = start + k
            if rows is not None and rows[i]:
                self.stats["detections_withheld"] += len(dets[k])
                dets[k] = ()
                continue
            rate = self.fp_rate[i]
            if rate <= 0.0:
                continue
            m = int(self.rng.poisson(rate * self.dt_s))
            if m == 0:
                continue
            u = self.rng.random((2, m))
            rng_m = detector.max_range_m * (1.0 - u[0])  # (0, max_range]
            if detector.full_circle:
                bearing = math.pi - 2.0 * math.pi * u[1]  # (-pi, pi]
            else:
                bearing = detector.fov_rad * (u[1] - 0.5)
            if cfg.report_identity and n_all >= 2:
                other = self.rng.integers(0, n_all - 1, m)
                other = other + (other >= i)
                ids = other.tolist()
            else:
                ids = [None] * m
            self.stats["phantoms"] += m
            dets[k] = tuple(dets[k]) + tuple(Detection(float(r), float(b), d)
                                             for r, b, d in zip(rng_m.tolist(), np.atleast_1d(bearing).tolist(), ids))
        return dets
