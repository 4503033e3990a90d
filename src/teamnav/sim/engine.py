"""The fixed-step simulation loop: truth in, observations out, actions back.

One :meth:`Simulation.step` (STYLE habit 4, f1tenth's "move everyone first, then sense"):

1. pre-step hooks (read truth);
2. apply every robot's stored action: clip to its limits (:mod:`~teamnav.sim.kinematics`)
   and move all robots in one kernel, walls and robots never penetrated
   (:mod:`~teamnav.sim.collisions`);
3. integrate odometry for all robots in one kernel (:mod:`~teamnav.sim.odometry`);
4. task events at places, from the new positions (:mod:`~teamnav.sim.events`);
5. the radio delivers the messages sent in the previous step (:mod:`~teamnav.sim.radio`);
6. sense: each group's range sensors in one call per sensor, the robot detector in one call
   per group; groups whose sensors are alike share one pass (one detector truth pass for
   equal detector configurations, one cast for equal range sensors: see
   :class:`~teamnav.sim.shared_sensing.SharedSensing`), each group still drawing from its own streams;
7. build observations (fresh arrays, belief only) and call the brains: each per-robot
   :class:`~teamnav.control.protocol.Controller` with its :class:`Observation`, each
   :class:`~teamnav.control.protocol.BatchedController` once with a
   :class:`BatchObservation` of all its robots;
8. store their actions for the next step and hand their outboxes to the radio;
9. record (every ``record_every`` steps) and post-step hooks.

The brains' first decision (observation of step 0, before any motion) is taken lazily by the
first :meth:`step`, so step 1 already executes a real action.

Truth and belief
----------------
``Simulation.state`` is the truth (for metrics and hooks). Brains are built only from their
validated parameters, their own ``Generator`` and a :class:`RobotInfo`; each observation
carries only sensor readings, the robot's own odometry, inbox, events and stall flag, in
arrays freshly allocated for that step (never views of the engine's arrays). The objects
around them (the Observation, its scans dict, its RangeScan) are last step's, refilled,
when the brain kept none of them (one sensor, no faults): building them was most of what the
per-robot path added to a step, and a brain that kept nothing cannot tell.

Determinism
-----------
``SeedSequence(config.seed)`` spawns two children: *subsystems* and *controllers*.
Subsystems spawn, in this order, the streams ``start``, ``odometry``, ``radio``,
``detector`` (then one per group) and ``sensors`` (then one per group, then one per
sensor). Controllers spawn one stream per robot (robot id order). A run is therefore
bit-for-bit repeatable on one machine, and adding a sensor to one group does not change
another group's noise.

Work nobody needs is skipped: no radio when no per-robot controller runs (batched brains
take no radio), no events without places that fire, no detector without a
``DetectorConfig``, and a batched group senses only its controller's ``range_sensor``.

Faults
------
A scenario's ``faults`` (:class:`~teamnav.sim.config.FaultsConfig`) are applied on the truth
side by a :class:`~teamnav.sim.faults.FaultInjector` (``Simulation.faults``; None without
faults, and then no fault code runs): at the start of each step it says who is dead, whose
radio and sensors are off, whether the radio is blacked out and where phantoms are reported;
kidnappings move true poses after the odometry step. Its random stream is a sixth child of
*subsystems*, spawned only when there are faults, so the other streams draw as without them.
A dead robot's brain is not stepped (batched: its commands are zeroed). Brains are told
nothing: they see only the observations the faults shaped.
"""

from __future__ import annotations

import contextlib
import math
import numbers
import sys
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Iterator

import numpy as np
from pydantic import ValidationError

from teamnav.control import registry
from teamnav.control.guard import (
    BrainBuildError, BrainReturnError, BrainStepError, BrainTimeoutError, BrainTimer, TimeUp, describe, robot_label,
)
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Action, BatchAction, BatchObservation, Message, Observation, RangeScan
from teamnav.geometry.angles import wrap_angle
from teamnav.sim.collisions import discs_hit_walls, move_discs
from teamnav.sim.config import SimConfig, resolve_robot, resolve_sensor
from teamnav.sim.events import Places
from teamnav.sim.kinematics import motion_primitives
from teamnav.sim.launch import OneAtATime
from teamnav.sim.odometry import Odometry
from teamnav.sim.radio import Radio
from teamnav.sim.recorder import Recorder
from teamnav.sim.shared_sensing import SharedSensing
from teamnav.sim.start import start_poses
from teamnav.sim.state import RobotState
from teamnav.world.distance import COARSE_FIELD_CELLS, clearance_bound, distance_field
from teamnav.world.grid import OccupancyGrid

__all__ = ["Simulation"]


_now = time.perf_counter
_refs = sys.getrefcount
#: Refilling handed-over observations reads reference counts, whose values are CPython's and
#: version-specific (3.14 borrows stack references, so a kept object can show the count of a
#: dropped one). Only on the versions whose counts the refill tests pin; elsewhere every step
#: builds new objects, as before the refill.
_REFILL_OK = sys.implementation.name == "cpython" and sys.version_info[:2] in ((3, 11), (3, 12), (3, 13))

# The slots of an Observation and a RangeScan, written directly when the engine refills the
# objects it handed over last step (both classes are frozen to brains; see _observe_and_decide).
_set_step = Observation.__dict__["step"].__set__
_set_time = Observation.__dict__["time_s"].__set__
_set_odom = Observation.__dict__["odom_pose"].__set__
_set_delta = Observation.__dict__["odom_delta"].__set__
_set_stalled = Observation.__dict__["stalled"].__set__
_set_detections = Observation.__dict__["detections"].__set__
_set_inbox = Observation.__dict__["inbox"].__set__
_set_events = Observation.__dict__["events"].__set__
_set_ranges = RangeScan.__dict__["ranges_m"].__set__


def _real_number(x) -> bool:
    """``x`` is a real number (a Python or numpy int or float; a NaN is one here: the
    finiteness check that follows names it), not a bool, a string, an array or None."""
    return isinstance(x, numbers.Real) and not isinstance(x, (bool, np.bool_))


def _finite_number(x) -> bool:
    return _real_number(x) and math.isfinite(float(x))


def _short(value: Any) -> str:
    """A returned value, briefly: its type and, when short, its repr."""
    text = repr(value)
    return f"{type(value).__name__} {text}" if len(text) <= 60 else type(value).__name__


def _sensor_factories():
    """``(build_range_sensor, RobotDetector)`` from :mod:`teamnav.sim.sensors` (imported lazily)."""
    from teamnav.sim.sensors import RobotDetector, build_range_sensor

    return build_range_sensor, RobotDetector


def _group_brain_class():
    """:func:`teamnav.control.group.group_brain_class` (imported lazily)."""
    return _group_api().group_brain_class


def _group_api():
    """:mod:`teamnav.control.group` (imported lazily: runs without group brains never load it)."""
    from teamnav.control import group

    return group


def _check_bodies():
    """:func:`teamnav.sim.sensors.robot_hits.check_bodies` (imported lazily)."""
    from teamnav.sim.sensors.robot_hits import check_bodies

    return check_bodies


@dataclass
class _Group:
    """Runtime of one robot group (engine-internal)."""

    index: int
    cfg: Any
    sl: slice
    ids: np.ndarray
    batched: bool
    brain: Any  # list of Controllers, or one BatchedController
    sensors: list = field(default_factory=list)  # range sensors sensed every step
    angles: list = field(default_factory=list)  # read-only copies of their beam angles
    bodies: list = field(default_factory=list)  # per sensed sensor: the `bodies` argument or None
    rngs: list = field(default_factory=list)
    detector: Any = None
    detector_rng: Any = None
    has_log: bool = False
    whole: bool = False  # its controller reads Simulation.observed instead of per-robot observations
    # Per robot, the (Observation, its scans dict, its RangeScan) handed over last step, to be
    # refilled when nobody kept any of them (see Simulation._observe_and_decide); None: none yet.
    handed: list = field(default_factory=list)
    extras_last: bool = False  # last step's observations carried an inbox, events or detections
    team: Any = None  # the group brain that steps its robots (``group_brains``), None: per-robot brains
    team_last: bool = False  # the last group of its team: the team steps after its readings
    # index into SharedSensing.det_sets whose detections its team takes as padded arrays
    # (Simulation._padded_sets), -1: as Detection tuples
    padded_det: int = -1
    # the first group of a team: {sensor name: index into SharedSensing.scan_sets} whose block
    # is the team's concatenated readings of that sensor (Simulation._step_team)
    team_blocks: dict = field(default_factory=dict)
    # set on every group of a team whose whole observation comes from arrays (every sensor a
    # shared cast's block, detections padded or none): the team's first group, its slice and,
    # per sensor in order, (name, scan set index, angles, max range); None: the general path
    team_fast: Any = None


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=np.float64, copy=True)
    a.setflags(write=False)
    return a


class Simulation:
    """A multi-robot simulation of one scenario.

    Parameters
    ----------
    grid : OccupancyGrid
        The true map.
    config : SimConfig
        Robots, sensors, odometry, radio, places, ``dt_s``, ``seed``, ``record_every``.
    known_map : OccupancyGrid, optional
        A map given to every robot as prior knowledge (``RobotInfo.known_map``).
    group_brains : bool, default False
        Step a team of per-robot brains whose controller names a group brain
        (:mod:`teamnav.control.group`) in one call of that group brain, where it says it runs
        those robots exactly as the reference brains do; elsewhere (and in runs with faults or a
        ``launch``) the per-robot brains run as without it. ``group_teams`` lists what ran so.

    Attributes
    ----------
    state : RobotState
        The truth (metrics and hooks only).
    step_index : int
        Steps done (0 at start).
    time_s : float
        ``step_index * dt_s`` [s].
    brains : list
        Per group: a list of per-robot controllers, or the group's batched controller (with
        ``group_brains``: for a team's groups, the group brain's per-robot views).
    recorder : Recorder
    group_of : ndarray of shape (N,), int64
        Group index of every robot (read-only).

    Raises
    ------
    ValueError
        Bad grid or config, unknown controller, invalid controller parameters (naming the
        group and the controller), impossible start poses.

    Examples
    --------
    >>> from teamnav.sim.config import RobotGroupConfig, SimConfig
    >>> sim = Simulation(OccupancyGrid.empty(4.0, 4.0, 0.1),
    ...                  SimConfig(robots=(RobotGroupConfig(count=2, controller="idle-v1", sensors=()),)))
    >>> sim.run(10); sim.step_index, round(sim.time_s, 6)
    (10, 1.0)
    """

    def __init__(self, grid: OccupancyGrid, config: SimConfig, *, known_map: OccupancyGrid | None = None,
                 group_brains: bool = False) -> None:
        if not isinstance(grid, OccupancyGrid):
            raise ValueError(f"grid must be an OccupancyGrid, got {type(grid).__name__}")
        if not isinstance(config, SimConfig):
            raise ValueError(f"config must be a teamnav.sim.config.SimConfig, got {type(config).__name__}")
        if known_map is not None and not isinstance(known_map, OccupancyGrid):
            raise ValueError(f"known_map must be an OccupancyGrid or None, got {type(known_map).__name__}")
        self.grid = grid
        self.config = config
        self.known_map = known_map
        self.dt_s = float(config.dt_s)
        groups = config.robots
        n = config.n_robots
        self.n_robots = n

        # ---- random streams
        root = np.random.SeedSequence(config.seed)
        sub_ss, ctrl_ss = root.spawn(2)
        start_ss, odom_ss, radio_ss, det_ss, sens_ss = sub_ss.spawn(5)
        det_group_ss = det_ss.spawn(len(groups))
        sens_group_ss = sens_ss.spawn(len(groups))
        robot_ss = ctrl_ss.spawn(n)

        # ---- truth
        self._blocking = grid.blocking(None)
        if self._blocking.size >= COARSE_FIELD_CELLS:  # a huge open arena: a block bound, the same moves
            self._clear_m = clearance_bound(self._blocking, grid.resolution_m)
        else:
            self._clear_m = distance_field(self._blocking, grid.resolution_m)
        self._geo = grid.geo  # origin, resolution, cos and sin of the map's yaw
        launch = config.launch
        if launch is None:
            poses = start_poses(grid, groups, np.random.default_rng(start_ss), self._clear_m)
        else:  # everyone at the spot; those not yet started are kept out of the arena (OneAtATime.hide)
            poses = np.tile([launch.spot[0], launch.spot[1], wrap_angle(math.radians(launch.spot[2]))], (n, 1))
            radii = np.repeat([g.radius_m for g in groups], [g.count for g in groups]).astype(np.float64)
            if discs_hit_walls(self._blocking, self._clear_m, grid.geo, poses[:, 0], poses[:, 1], radii).any():
                raise ValueError(f"launch.spot {list(launch.spot)}: a robot there would overlap a wall or leave the map")
        counts = [g.count for g in groups]
        group_idx = np.repeat(np.arange(len(groups)), counts)
        self.state = RobotState.from_poses(poses, np.repeat([g.radius_m for g in groups], counts), group_idx)
        self.group_of = group_idx.copy()
        self.group_of.setflags(write=False)
        self._holonomic = np.repeat([g.kinematics == "holonomic_step" for g in groups], counts).astype(np.bool_)
        self._max_v = np.repeat([g.max_v_mps for g in groups], counts).astype(np.float64)
        self._max_w = np.repeat([math.radians(g.max_omega_degps) for g in groups], counts).astype(np.float64)
        self._step_m = np.repeat([g.step_length_m for g in groups], counts).astype(np.float64)
        self.odometry = Odometry([g.odometry for g in groups for _ in range(g.count)], poses, self.dt_s,
                                 np.random.default_rng(odom_ss))

        # ---- sensors and brains
        self._infos: list[RobotInfo] = []
        self._groups: list[_Group] = []
        self.brains: list[Any] = []
        pending: list[tuple] = []  # groups whose controller names a group brain (``group_brains``)
        offsets = np.concatenate([[0], np.cumsum(counts)]).astype(int)
        factories = None
        for gi, g in enumerate(groups):
            label = f"robots[{gi}] ({g.name!r})"
            sl = slice(int(offsets[gi]), int(offsets[gi + 1]))
            needs_factory = bool(g.sensors) or g.detector is not None
            if needs_factory and factories is None:
                factories = _sensor_factories()
            sensors = [factories[0](c, grid) for c in g.sensors] if g.sensors else []
            sensor_infos = {s.name: s.info() for s in sensors}
            infos = [
                RobotInfo(
                    robot_id=i, team_size=n, radius_m=g.radius_m, kinematics=g.kinematics, max_v_mps=g.max_v_mps,
                    max_omega_radps=math.radians(g.max_omega_degps), step_length_m=g.step_length_m, dt_s=self.dt_s,
                    sensors=dict(sensor_infos), known_map=known_map,
                    extras={"group": g.name, "group_index": gi, "index_in_group": i - sl.start},
                )
                for i in range(sl.start, sl.stop)
            ]
            self._infos += infos
            try:
                cls = registry.lookup(g.controller)
            except KeyError as exc:
                raise ValueError(f"{label}.controller: {exc.args[0]}") from None
            try:
                params = cls.Params.model_validate(dict(g.params))
            except ValidationError as exc:
                problems = "; ".join(
                    f"params.{'.'.join(str(p) for p in e['loc']) or '<root>'}: {e['msg']}, got {e.get('input')!r}"
                    for e in exc.errors()
                )
                raise ValueError(f"{label}: invalid parameters for controller {g.controller!r}: {problems}") from None
            batched = bool(getattr(cls, "batched", False))
            rngs = [np.random.default_rng(robot_ss[i]) for i in range(sl.start, sl.stop)]
            if batched and g.kinematics != "unicycle":
                raise ValueError(f"{label}: controller {g.controller!r}: batched controllers command (v, omega) and "
                                 f"need kinematics 'unicycle', got {g.kinematics!r}")
            group_cls = None
            if (group_brains and not batched and g.count
                    and (config.faults is None or config.faults.empty)
                    and "group_brain" in vars(cls)):
                group_cls = _group_brain_class()(cls)
                # robots started one at a time: only a group brain that skips waiting rows
                # (GroupObservation.waiting) runs them
                if launch is not None and not getattr(group_cls, "handles_waiting", False):
                    group_cls = None
            if group_cls is not None:
                brain = None  # built with its team below (or per robot, where the group brain declines)
                pending.append((gi, cls, group_cls, params, rngs, infos))
            else:
                brain = self._build_brains(cls, batched, params, rngs, infos, g, sl)
            sens_rngs = [np.random.default_rng(s) for s in sens_group_ss[gi].spawn(len(sensors))]
            grp = _Group(index=gi, cfg=g, sl=sl, ids=np.arange(sl.start, sl.stop, dtype=np.int64), batched=batched,
                         brain=brain)
            if batched:
                name = getattr(brain, "range_sensor", None)
                names = [s.name for s in sensors]
                if name not in names:
                    raise ValueError(
                        f"{label}: controller {g.controller!r} reads range_sensor {name!r}, which must be one of the "
                        f"group's sensors ({', '.join(names) or 'none'})"
                    )
                k = names.index(name)
                grp.sensors, grp.rngs, cfgs = [sensors[k]], [sens_rngs[k]], [g.sensors[k]]
            else:
                grp.sensors, grp.rngs, cfgs = sensors, sens_rngs, list(g.sensors)
                grp.has_log = callable(getattr(brain[0], "log", None)) if brain else group_cls is not None
                grp.whole = bool(getattr(cls, "observes_whole_group", False))
                if g.detector is not None:
                    grp.detector = factories[1](g.detector, grid)
                    grp.detector_rng = np.random.default_rng(det_group_ss[gi])
            grp.angles = [_readonly(s.angles_rad) for s in grp.sensors]
            # Range sensors that see robots get every robot's true disc (sim side only). The
            # tuple holds the state's own arrays (updated in place every step); it is checked
            # here once, and the per-step sensing path does no checks.
            bodies = (self.state.x_m, self.state.y_m, self.state.radius_m, grp.ids)
            if any(c.sees_robots for c in cfgs) and n > 1:
                checked = _check_bodies()(bodies, g.count)
                assert all(a is b for a, b in zip(checked, bodies)), "bodies must be the state's own arrays"
            grp.bodies = [bodies if c.sees_robots and n > 1 else None for c in cfgs]
            self._groups.append(grp)
            self.brains.append(brain)

        #: the teams stepped by a group brain: (group brain, first robot id, end robot id, group indices)
        self.group_teams: list[tuple[Any, int, int, tuple[int, ...]]] = []
        if pending:
            self._build_teams(pending)
        self._sharing = SharedSensing(self._groups, self.state)
        self._any_per_robot = any(not grp.batched for grp in self._groups)
        self.radio = Radio(config.radio, grid, n, np.random.default_rng(radio_ss), dt_s=self.dt_s) if self._any_per_robot else None
        self.places = Places(config.places, self.state.x_m, self.state.y_m)
        self._ids_all = np.arange(n, dtype=np.int64)

        # ---- buffers
        self._v_cmd = np.zeros(n)
        self._w_cmd = np.zeros(n)
        self._dir_cmd = np.full(n, np.nan)
        self._pre = np.zeros(n)
        self._arc = np.zeros(n)
        self._turn = np.zeros(n)
        self._x0 = np.empty(n)
        self._y0 = np.empty(n)
        self._th0 = np.empty(n)
        self._decided = False
        #: robots not started yet (``launch``; None without one): True where a robot waits
        self.waiting: np.ndarray | None = None
        #: step at which each robot started (-1 while it waits; None without ``launch``)
        self.launched_at: np.ndarray | None = None
        #: the one-at-a-time start (None without ``launch``)
        self._launch: OneAtATime | None = None
        if launch is not None:
            self._launch = OneAtATime(n, poses[0].copy(), launch.clear_m, self.odometry.pose, grid.origin_xy_m)
            self.waiting = self._launch.waiting
            self.launched_at = self._launch.launched_at
        #: what the latest observations were built from, for readers of whole groups at once
        #: (:mod:`teamnav.env`): ``(step, odometry poses (n, 3), odometry deltas (n, 3) or None,
        #: {group index: [(sensor name, ranges (count, B), beam angles, max range)]}, inboxes,
        #: events, {group index: per robot, a tuple of Detection} or None)`` for the per-robot
        #: groups, after faults (inboxes and events: per robot, or None when no message / no
        #: event this step; detections before faults); the very arrays whose rows the
        #: per-robot observations view, so read them, never write them. None before the first
        #: observation. A controller class with ``observes_whole_group = True`` (the
        #: environment's agents) is handed no per-robot observation in a run without faults:
        #: its ``step`` is not called, its robots keep the commands last stored
        #: (:meth:`set_commands`), and it reads this instead.
        self.observed: tuple | None = None
        #: ``(group index, index in group or None for a batched call, step, perf_counter at the
        #: call)`` while a brain is being called, else None (see :meth:`waiting_on`)
        self.calling: tuple | None = None
        self._brain_timer: BrainTimer | None = None
        self._pre_hooks: list[Callable] = []
        self._post_hooks: list[Callable] = []

        self.step_index = 0
        self.recorder = Recorder(n, config.record_every)
        self.recorder.events = self.places.log
        if launch is not None:  # robot 0 starts at step 0 (the others in OneAtATime.launch_next)
            self.places.log.append({"step": 0, "t_s": 0.0, "robot": 0, "place": None, "event": None, "launched": True})
        #: the run's faults (None without a ``faults`` section, or with an empty one)
        self.faults = None
        if config.faults is not None and not config.faults.empty:
            from teamnav.sim.faults import FaultInjector

            (fault_ss,) = sub_ss.spawn(1)  # a sixth child: the five streams above are unchanged
            self.faults = FaultInjector(config.faults, config, grid, self._blocking, self._clear_m, self.dt_s,
                                        np.random.default_rng(fault_ss), self.places.log)
            self._check_faults()
            self.faults.begin_step(0)
        if self.radio is not None:
            self.recorder.comm_counts = self.radio.counts
        self._rec_sensing = bool(config.record_scans)
        # speed: a team whose groups are exactly one set of the shared detector, in order, gets
        # its detections straight as its observation's padded arrays (no Detection objects
        # built and read back: the same values and draws). Only where nothing else reads the
        # tuples: no faults, no recorded detections, no controller reading Simulation.observed.
        self._padded_sets: dict | None = None
        if self.faults is None and not self._rec_sensing and not any(g.whole for g in self._groups):
            for _team, _start, _stop, members in self.group_teams:
                for j, (det, dmembers) in enumerate(self._sharing.det_sets):
                    # (false negatives or positives: Detector._detect_groups_padded declines)
                    if (tuple(g.index for g in dmembers) == tuple(members) and det.cfg.p_false_negative == 0.0
                            and det.cfg.p_false_positive == 0.0):
                        self._padded_sets = {**(self._padded_sets or {}), j: None}
                        for gi in members:
                            self._groups[gi].padded_det = j
            # likewise a team whose groups are exactly one shared cast's members, in order, for
            # a sensor: its concatenated readings of that sensor are the cast's block
            for _team, _start, _stop, members in self.group_teams:
                for j, (_sensor, smembers, _idx, _bodies, starts) in enumerate(self._sharing.scan_sets):
                    if starts is None or tuple(g.index for g, _ in smembers) != tuple(members):
                        continue
                    names = {g.sensors[k].name for g, k in smembers}
                    if len(names) == 1:
                        self._groups[members[0]].team_blocks[names.pop()] = j
            for _team, start, stop, members in self.group_teams:
                grps = [self._groups[gi] for gi in members]
                first = grps[0]
                names = [sn.name for sn in first.sensors]
                dets = {g.detector is not None for g in grps}
                if (len(grps) > 1 and names and len(set(names)) == len(names) and all(n in first.team_blocks for n in names)
                        and all([sn.name for sn in g.sensors] == names for g in grps)
                        and (dets == {False} or (dets == {True} and first.padded_det >= 0))):
                    order = tuple((sn.name, first.team_blocks[sn.name], a, float(sn.max_range_m))
                                  for sn, a in zip(first.sensors, first.angles))
                    fast = (first, slice(start, stop), order)
                    for g in grps:
                        g.team_fast = fast
        self._n_track = 0
        if self.places.moving:  # replays and exports draw moving places where they are, not at their start
            self.recorder.declare_layer("moving_places", "markers", hold=True,
                                        description="moving places (Places.track: t = 0, every jump, every "
                                                    "0.25 m of glide); static places are in the scenario")
            self._record_moving_places()
        if self._rec_sensing:
            self.recorder.declare_layer("detections", "segments", description="robot detector: observer to detected robot")
            self.recorder.declare_layer("messages", "segments", description="radio message delivered: sender to receiver")
        self._record()

    def _build_brains(self, cls, batched: bool, params, rngs: list, infos: list, g, sl: slice):
        """A group's brains: its batched controller, or one per-robot controller per robot."""
        k = None
        try:  # the brain's own code: whatever it raises (even sys.exit) is reported as its failure
            if batched:
                return cls(params, rngs, infos)
            brain = []
            for k in range(g.count):
                brain.append(cls(params, rngs[k], infos[k]))
            return brain
        except (Exception, SystemExit) as exc:
            raise BrainBuildError(str(g.controller), robot_label(g.name, k, sl.start + k if k is not None else None),
                                  None, describe(exc)) from exc

    def _build_teams(self, pending: list) -> None:
        """Teams of consecutive groups (groups without robots between them do not count) whose
        controllers name the same group brain, each built as one group brain from its robots'
        params, streams and infos, in robot order; a team the group brain declines
        (``unsupported``) gets its per-robot brains, as without ``group_brains``."""
        runs: list[list[tuple]] = []
        for item in pending:
            gi = item[0]
            prev = runs[-1][-1] if runs else None
            if (prev is not None and prev[2] is item[2]
                    and all(self._groups[j].cfg.count == 0 for j in range(prev[0] + 1, gi))):
                runs[-1].append(item)
            else:
                runs.append([item])
        for run in runs:
            group_cls = run[0][2]
            params = []
            rngs: list = []
            infos: list = []
            for gi, _, _, p, rs, inf in run:
                params += [p] * len(rs)
                rngs += rs
                infos += inf
            why = group_cls.unsupported(params, infos)
            if why is None:
                first = self._groups[run[0][0]]
                try:
                    team = group_cls(params, rngs, infos)
                except (Exception, SystemExit) as exc:
                    raise BrainBuildError(str(first.cfg.controller), robot_label(first.cfg.name, None, None), None,
                                          describe(exc)) from exc
                start = first.sl.start
                members = tuple(gi for gi, *_ in run)
                for gi in members:
                    grp = self._groups[gi]
                    grp.brain = team.robots[grp.sl.start - start:grp.sl.stop - start]
                    grp.team = team
                    self.brains[gi] = grp.brain
                self._groups[members[-1]].team_last = True
                self.group_teams.append((team, start, self._groups[members[-1]].sl.stop, members))
            else:
                for gi, cls, _, p, rs, inf in run:
                    grp = self._groups[gi]
                    grp.brain = self._build_brains(cls, False, p, rs, inf, grp.cfg, grp.sl)
                    grp.has_log = callable(getattr(grp.brain[0], "log", None)) if grp.brain else False
                    self.brains[gi] = grp.brain

    def _record_moving_places(self) -> None:
        """One ``moving_places`` sample (robot -1) with every moving place where
        :attr:`Places.track` last put it, at the step of its newest record."""
        last: dict[str, tuple[float, float]] = {}
        for rec in self.places.track:
            last[rec["place"]] = (rec["x_m"], rec["y_m"])
        self.recorder.add_layer_sample("moving_places", int(self.places.track[-1]["step"]), -1, list(last.values()))
        self._n_track = len(self.places.track)

    # ------------------------------------------------------------------ public
    @property
    def time_s(self) -> float:
        return self.step_index * self.dt_s

    def robot_info(self, i: int) -> RobotInfo:
        """What robot ``i`` knows about itself (its brain was built with this)."""
        if not (isinstance(i, (int, np.integer)) and 0 <= i < self.n_robots):
            raise ValueError(f"i must be a robot id in [0, {self.n_robots}), got {i!r}")
        return self._infos[int(i)]

    def add_hook(self, pre_step: Callable[["Simulation"], None] | None = None,
                 post_step: Callable[["Simulation"], None] | None = None) -> None:
        """Register experiment hooks called with the simulation before / after each step.

        Hooks may read the truth and the brains' observable outputs; they must not write into
        a brain (STYLE habit 8).
        """
        for name, h in (("pre_step", pre_step), ("post_step", post_step)):
            if h is not None and not callable(h):
                raise ValueError(f"{name} must be callable or None, got {type(h).__name__}")
        if pre_step is not None:
            self._pre_hooks.append(pre_step)
        if post_step is not None:
            self._post_hooks.append(post_step)

    def run(self, n_steps: int, *, progress: Callable[[int], None] | None = None,
            is_finished: Callable[["Simulation"], bool] | None = None) -> None:
        """Step ``n_steps`` times, or until ``is_finished(sim)`` is true (checked after each step).

        ``progress(k)`` is called after the k-th step of this call.
        """
        if isinstance(n_steps, bool) or not isinstance(n_steps, (int, np.integer)) or n_steps < 0:
            raise ValueError(f"n_steps must be an int >= 0, got {n_steps!r}")
        step = self.step
        for k in range(int(n_steps)):
            step()
            if progress is not None:
                progress(k + 1)
            if is_finished is not None and is_finished(self):
                break

    def record_last_step(self) -> None:
        """Record the current step if ``record_every`` skipped it (a run that stops early, or
        whose length is not a multiple of ``record_every``, still ends on its final state)."""
        steps = self.recorder.steps
        if steps.shape[0] == 0 or int(steps[-1]) != self.step_index:
            self._record()

    def decide_first(self) -> None:
        """Take the first decision now: every brain sees the observation of step 0 and its
        commands are stored, with no motion (what the first :meth:`step` does lazily).
        Idempotent. An outside agent (:mod:`teamnav.env`) needs the step-0 observation before
        it acts."""
        if not self._decided:
            self._observe_and_decide(None, None)
            self._decided = True

    def set_commands(self, ids, v_mps, omega_radps, direction_rad=None, *, check: bool = True) -> None:
        """Replace the stored commands of robots ``ids`` before the next :meth:`step` moves
        them: what an outside agent decided on the observation it was given (the brain's
        own commands for those robots are overwritten).

        Parameters
        ----------
        ids : array of int, shape (k,), or a slice
            Robot indices, each in ``0..n_robots-1`` (a group's slice, e.g.).
        v_mps, omega_radps : array of float, shape (k,)
            Speed [m/s] and turn rate [rad/s] (unicycles); limited by the robot's own limits
            as any brain's command is.
        direction_rad : float or array of float, shape (k,), optional
            Heading of motion for holonomic robots (NaN: none, as for unicycles); a scalar
            applies to every robot of ``ids``; None leaves the stored directions as they are.
        check : bool, default True
            Check indices, shapes and finiteness (refusing with ValueError). A caller that has
            checked its actions already (:mod:`teamnav.env`) passes False: the checks cost more
            than the step of a one-robot team.
        """
        if not check:
            self._v_cmd[ids] = v_mps
            self._w_cmd[ids] = omega_radps
            if direction_rad is not None:
                self._dir_cmd[ids] = direction_rad
            return
        ids = np.arange(self.n_robots)[ids] if isinstance(ids, slice) else np.asarray(ids, dtype=np.int64).reshape(-1)
        k = ids.shape[0]
        if k and (ids.min() < 0 or ids.max() >= self.n_robots):
            raise ValueError(f"ids must be robot indices in 0..{self.n_robots - 1}, got {ids.tolist()}")
        v = np.asarray(v_mps, dtype=np.float64).reshape(-1)
        w = np.asarray(omega_radps, dtype=np.float64).reshape(-1)
        d = self._dir_cmd[ids] if direction_rad is None else np.asarray(direction_rad, dtype=np.float64).reshape(-1)
        if d.shape == (1,) and k != 1:
            d = np.full(k, d[0])
        for name, arr in (("v_mps", v), ("omega_radps", w), ("direction_rad", d)):
            if arr.shape != (k,):
                raise ValueError(f"{name} must have shape ({k},) like ids, got {arr.shape}")
        if not (np.isfinite(v).all() and np.isfinite(w).all()) or np.isinf(d).any():
            raise ValueError("v_mps and omega_radps must be finite, direction_rad finite or NaN")
        self._v_cmd[ids] = v
        self._w_cmd[ids] = w
        self._dir_cmd[ids] = d

    def step(self) -> None:
        """Advance the simulation by one fixed step ``dt_s`` (see the module docstring)."""
        self.decide_first()
        for h in self._pre_hooks:
            h(self)
        s = self.state
        self.step_index += 1
        fx = self.faults
        if fx is not None:
            fx.begin_step(self.step_index)
        waiting = self.waiting
        if waiting is not None:
            self._launch.launch_next(self.step_index, self.time_s, s, self.odometry, self.places.log)
            waiting = self.waiting if self.waiting.any() else None
            if waiting is not None:  # a robot that waits is commanded nothing (set_commands included)
                self._v_cmd[waiting] = 0.0
                self._w_cmd[waiting] = 0.0
                self._dir_cmd[waiting] = math.nan
        np.copyto(self._x0, s.x_m)
        np.copyto(self._y0, s.y_m)
        np.copyto(self._th0, s.theta_rad)
        motion_primitives(self._holonomic, self._v_cmd, self._w_cmd, self._dir_cmd, self._max_v, self._max_w,
                          self._step_m, self.dt_s, s.v_mps, s.omega_radps, self._pre, self._arc, self._turn)
        if waiting is not None:
            self._launch.hide(s, waiting)
        move_discs(s.x_m, s.y_m, s.theta_rad, s.radius_m, self._pre, self._arc, self._turn, self._blocking,
                   self._clear_m, self._geo, self.config.robot_collisions, s.stalled)
        if waiting is not None:
            self._launch.unhide(s, waiting)
        self.odometry.step(self._x0, self._y0, self._th0, s.x_m, s.y_m, s.theta_rad)
        if fx is not None and fx.kidnap_due:
            fx.kidnap(s)  # after the odometry step: odometry never feels the jump
        events = self.places.update(self.step_index, self.time_s, s.x_m, s.y_m, muted=waiting) \
            if self.places.active else None
        if len(self.places.track) != self._n_track:
            self._record_moving_places()
        if fx is None:
            inboxes = self.radio.collect(muted=waiting) if self.radio is not None and self.radio.has_pending else None
        else:
            muted = fx.radio_off if fx.any_radio_off else None
            if waiting is not None:
                muted = waiting if muted is None else (muted | waiting)
            inboxes = self.radio.collect(muted=muted, blocked=fx.blackout) \
                if self.radio is not None and self.radio.has_pending else None
        if inboxes is not None and self._rec_sensing and self.recorder.wants(self.step_index):
            self._record_messages(inboxes)
        if waiting is not None:
            self._launch.hide(s, waiting)  # unseen by every sensor and out of radio reach while it waits
            try:
                self._observe_and_decide(events, inboxes)
            finally:
                self._launch.unhide(s, waiting)
        else:
            self._observe_and_decide(events, inboxes)
        if self.recorder.wants(self.step_index):
            self._record()
        for h in self._post_hooks:
            h(self)

    # ------------------------------------------------------------------ internals
    def _check_faults(self) -> None:
        """Faults on robots of batched groups that their brain could never feel are refused:
        a batched group senses only its controller's range sensor and has no detector."""
        cfg = self.config.faults
        for kind in ("sensor_dropouts", "false_positives"):
            for j, entry in enumerate(getattr(cfg, kind)):
                if entry.robot is None:
                    continue
                field = f"faults.{kind}[{j}]"
                grp = self._groups[int(self.group_of[resolve_robot(entry.robot, self.config.robots, field + '.robot')])]
                if not grp.batched:
                    continue
                sensed = grp.sensors[0].name
                if kind == "false_positives":
                    raise ValueError(f"{field}.robot: robots of group {grp.cfg.name!r} run the batched controller "
                                     f"{grp.cfg.controller!r}, which has no detector to report false positives")
                k = resolve_sensor(entry.sensor, grp.cfg, field + ".sensor")
                if k is None or grp.cfg.sensors[k].name != sensed or entry.reading == "no_scan":
                    raise ValueError(f"{field}.sensor: robots of group {grp.cfg.name!r} run the batched controller "
                                     f"{grp.cfg.controller!r}, which senses only {sensed!r} and always gets its "
                                     f"ranges; expected that sensor with reading 'no_return', got "
                                     f"{entry.sensor!r} with {entry.reading!r}")

    def _record(self) -> None:
        logs = None
        if any(g.has_log for g in self._groups):
            logs = {}
            for g in self._groups:
                if g.has_log:
                    for k, brain in enumerate(g.brain):
                        try:
                            logs[g.sl.start + k] = brain.log()
                        except (Exception, SystemExit) as exc:  # the brain's own code
                            raise self._brain_failed(g, k, self.step_index, exc) from exc
        s = self.state
        self.recorder.record(self.step_index, self.time_s, s.poses(), self.odometry.pose, s.stalled, logs)

    def _observe_and_decide(self, events, inboxes) -> None:
        s = self.state
        step = self.step_index
        t = self.time_s
        odom = self.odometry.pose.copy()  # fresh belief arrays for this step's observations
        outgoing: list[tuple[int, Message]] = []
        xs, ys, ths = s.x_m, s.y_m, s.theta_rad
        sharing = self._sharing
        shared = sharing.readings(s) if sharing.scan_sets else None
        padded = None if self._padded_sets is None else dict(self._padded_sets)
        dets_of = sharing.detections(s, self._ids_all, padded) if sharing.det_sets else None
        delta = self.odometry.delta.copy() if self._any_per_robot else None  # fresh, one copy for all groups
        scans_of: dict[int, list] = {}
        self.observed = (step, odom, delta, scans_of, inboxes, events, dets_of)
        fx = self.faults
        omit = None
        timer = self._brain_timer
        team_readings: list = []
        for grp in self._groups:
            fast = grp.team_fast
            if fast is not None:  # the team's observation is all arrays (no per-group readings)
                if grp.team_last:
                    self._step_team_fast(grp.team, fast, step, t, odom, delta, inboxes, events, outgoing, padded)
                continue
            sl = grp.sl
            gx, gy, gth = xs[sl], ys[sl], ths[sl]
            if grp.batched:
                sensor = grp.sensors[0]
                ranges = sensor._sense(gx, gy, gth, grp.rngs[0], grp.bodies[0])
                if fx is not None and fx.dropped:
                    k_cfg = [c.name for c in grp.cfg.sensors].index(sensor.name)
                    ranges = fx.batch_ranges(grp.index, k_cfg, sl.start, ranges, float(sensor.max_range_m))
                obs = BatchObservation(
                    robot_ids=grp.ids.copy(), step=step, time_s=t, odom_pose=odom[sl], ranges_m=ranges,
                    angles_rad=grp.angles[0], max_range_m=float(sensor.max_range_m), stalled=s.stalled[sl].copy(),
                )
                if self._rec_sensing and self.recorder.wants(step):
                    self._record_sensing(grp, [(sensor.name, ranges)], None)
                self.calling = (grp.index, None, step, _now())
                try:
                    act = grp.brain.step_batch(obs) if timer is None else timer.call(grp.brain.step_batch, obs)
                    self.calling = None
                except (Exception, SystemExit) as exc:
                    raise self._brain_failed(grp, None, step, exc) from exc
                self._apply_batch(grp, act, step)
                continue
            readings = [
                (sensor.name,
                 shared[(grp.index, k)] if shared is not None and (grp.index, k) in sharing.shared_scan
                 else sensor._sense(gx, gy, gth, rng, bodies),
                 angles, float(sensor.max_range_m))
                for k, (sensor, rng, angles, bodies) in enumerate(zip(grp.sensors, grp.rngs, grp.angles, grp.bodies))
            ]
            # (None for a team group whose detections come padded: dets_of leaves it out)
            dets = dets_of.get(grp.index) if grp.detector is not None else None
            if fx is not None:
                readings, omit = fx.readings(grp.index, sl.start, readings)
                if dets is not None:
                    dets = fx.detections(grp.index, sl.start, dets, grp.detector)
            scans_of[grp.index] = readings
            if self._rec_sensing and self.recorder.wants(step):
                self._record_sensing(grp, [(r[0], r[1]) for r in readings], dets)
            if grp.whole and fx is None:
                continue  # its controller reads self.observed
            if grp.team is not None:  # stepped by its group brain once its team's last group is sensed
                team_readings.append((grp, readings, dets))
                if grp.team_last:
                    self._step_team(grp.team, team_readings, step, t, odom, delta, inboxes, events, outgoing,
                                    padded)
                    team_readings = []
                continue
            stalled = s.stalled[sl].tolist()
            # Per robot, only what must be per robot (an outside Python brain pays this path on
            # every step): row views, one Observation, the call; commands go into Python lists,
            # written to the command arrays once per group.
            rows = [(name, list(r), a, m) for name, r, a, m in readings]
            odom_rows = list(odom[sl])
            delta_rows = list(delta[sl])
            g_inbox = inboxes[sl] if inboxes is not None else None
            g_events = events[sl] if events is not None else None
            off = fx.dead[sl] if fx is not None else None
            if self.waiting is not None:
                off = self.waiting[sl] if off is None else (off | self.waiting[sl])
            dead = off.tolist() if off is not None else None
            vs = self._v_cmd[sl].tolist()
            ws = self._w_cmd[sl].tolist()
            ds = self._dir_cmd[sl].tolist()
            gi = grp.index
            i0 = sl.start
            # Refilling last step's objects: only with one sensor and no faults, and for a robot
            # whose brain kept none of them (counted references: the list `handed`, the local
            # name and getrefcount's argument; the dict and the scan also have their holder).
            # Such a brain cannot tell the objects apart from new ones, and the arrays in them
            # are fresh as always; a brain that kept any of them gets new ones.
            refill = _REFILL_OK and len(rows) == 1 and omit is None
            handed = grp.handed
            if refill:
                if len(handed) != len(grp.brain):
                    handed[:] = [None] * len(grp.brain)
                name, r, a, m = rows[0]
                extras = dets is not None or g_inbox is not None or g_events is not None
                set_extras = extras or grp.extras_last
                grp.extras_last = extras
            for k, brain in enumerate(grp.brain):
                if dead is not None and dead[k]:
                    continue  # a dead robot's brain is off (its commands are zeroed below)
                if refill:
                    h = handed[k]
                    if h is not None:
                        obs, scans, scan = h
                        if not (_refs(obs) == 3 and _refs(scans) == 4 and _refs(scan) == 4 and len(scans) == 1
                                and scans.get(name) is scan):
                            h = None
                    if h is not None:
                        _set_ranges(scan, r[k])
                        _set_step(obs, step)
                        _set_time(obs, t)
                        _set_odom(obs, odom_rows[k])
                        _set_delta(obs, delta_rows[k])
                        _set_stalled(obs, stalled[k])
                        if set_extras:
                            _set_detections(obs, tuple(dets[k]) if dets is not None else ())
                            _set_inbox(obs, g_inbox[k] if g_inbox is not None else ())
                            _set_events(obs, g_events[k] if g_events is not None else ())
                    else:
                        scan = RangeScan(r[k], a, m)
                        scans = {name: scan}
                        obs = Observation(
                            i0 + k, step, t, odom_rows[k], delta_rows[k], scans,
                            tuple(dets[k]) if dets is not None else (),
                            stalled[k],
                            g_inbox[k] if g_inbox is not None else (),
                            g_events[k] if g_events is not None else (),
                        )
                        handed[k] = (obs, scans, scan)
                    h = None
                else:
                    if len(rows) == 1:
                        name, r, a, m = rows[0]
                        scans = {name: RangeScan(r[k], a, m)}
                    else:
                        scans = {name: RangeScan(r[k], a, m) for name, r, a, m in rows}
                    if omit is not None and omit[k]:
                        for name in omit[k]:
                            del scans[name]  # a sensor that publishes nothing this step
                    obs = Observation(
                        i0 + k, step, t, odom_rows[k], delta_rows[k], scans,
                        tuple(dets[k]) if dets is not None else (),
                        stalled[k],
                        g_inbox[k] if g_inbox is not None else (),
                        g_events[k] if g_events is not None else (),
                    )
                self.calling = (gi, k, step, _now())
                try:  # the brain's own code: whatever it raises (even sys.exit) is reported as its failure
                    out = brain.step(obs) if timer is None else timer.call(brain.step, obs)
                    self.calling = None
                except (Exception, SystemExit) as exc:
                    raise self._brain_failed(grp, k, step, exc) from exc
                if not (type(out) is tuple and len(out) == 2 and isinstance(out[0], Action)):
                    if not (isinstance(out, tuple) and len(out) == 2 and isinstance(out[0], Action)):
                        raise self._bad_return(grp, k, step, "step() must return (Action, list of Message), got "
                                               f"{_short(out)}")
                action, outbox = out
                vs[k] = action.v_mps
                ws[k] = action.omega_radps
                d = action.direction_rad
                if d is None:
                    ds[k] = math.nan
                else:
                    ds[k] = d
                    if not (type(d) is float and math.isfinite(d)) and not _finite_number(d):
                        raise self._bad_return(grp, k, step, f"direction_rad must be finite or None, got {d!r}")
                if outbox:
                    for msg in outbox:
                        outgoing.append((i0 + k, msg))
            self._write_commands(grp, step, vs, ws, ds)
        if fx is not None:
            fx.zero_commands(self._v_cmd, self._w_cmd, self._dir_cmd)
        if not (np.isfinite(self._v_cmd).all() and np.isfinite(self._w_cmd).all()):
            bad = int(np.flatnonzero(~(np.isfinite(self._v_cmd) & np.isfinite(self._w_cmd)))[0])
            grp = self._groups[self.group_of[bad]]
            raise self._bad_return(grp, None if grp.batched else bad - grp.sl.start, step,
                                   f"must command finite v_mps and omega_radps, got ({self._v_cmd[bad]!r}, "
                                   f"{self._w_cmd[bad]!r}) for robot id {bad}")
        if outgoing:
            if fx is None:
                self.radio.send(outgoing, xs, ys, step=step)
            else:
                self.radio.send(outgoing, xs, ys, muted=fx.radio_off if fx.any_radio_off else None, blocked=fx.blackout,
                                step=step)

    def _step_team(self, team, members: list, step: int, t: float, odom, delta, inboxes, events, outgoing: list,
                   padded: dict | None = None) -> None:
        """One call of a group brain for its team: each robot's own readings, odometry,
        detections, inbox and events as arrays (:class:`~teamnav.control.group.GroupObservation`),
        its commands into the command arrays, its messages to the radio (robot order)."""
        first, last = members[0][0], members[-1][0]
        sl = slice(first.sl.start, last.sl.stop)
        n = sl.stop - sl.start
        readings = members[0][1]
        if len(members) == 1 and len(readings) == 1:
            name, r, a, m = readings[0]
            ranges, angles, max_range = {name: r}, {name: a}, {name: m}
        elif len(members) == 1:
            ranges = {name: r for name, r, _, _ in readings}
        else:
            blocks = first.team_blocks
            ranges = {name: self._sharing.blocks[blocks[name]] if name in blocks else
                      np.concatenate([dict((nm, rr) for nm, rr, _, _ in rd)[name] for _, rd, _ in members])
                      for name, _, _, _ in members[0][1]}
        if not (len(members) == 1 and len(readings) == 1):
            angles = {name: a for name, _, a, _ in readings}
            max_range = {name: m for name, _, _, m in readings}
        api = _group_api()
        pj = first.padded_det
        got = padded[pj] if pj >= 0 and padded is not None else None
        if got is not None:  # the team's detections, padded by the detector (Simulation._padded_sets)
            count, ids, rng, brg = got
        else:
            if len(members) == 1:
                dets = members[0][2]
            else:
                dets = None
                if any(d is not None for _, _, d in members):
                    dets = [row for grp, _, d in members for row in (d if d is not None else ((),) * grp.cfg.count)]
            count, ids, rng, brg = api.pad_detections(dets, n)
        self._call_team(api, team, first, sl, n, ranges, angles, max_range, count, ids, rng, brg, step, t, odom, delta,
                        inboxes, events, outgoing)

    def _step_team_fast(self, team, fast: tuple, step: int, t: float, odom, delta, inboxes, events, outgoing: list,
                        padded: dict | None) -> None:
        """:meth:`_step_team` for a team whose observation is all arrays (``_Group.team_fast``):
        each sensor's readings are its shared cast's block, the detections come padded (or
        there is no detector); the same observation, built without the per-group readings."""
        first, sl, order = fast
        n = sl.stop - sl.start
        blocks = self._sharing.blocks
        ranges, angles, max_range = {}, {}, {}
        for name, j, a, m in order:
            ranges[name] = blocks[j]
            angles[name] = a
            max_range[name] = m
        api = _group_api()
        pj = first.padded_det
        got = padded[pj] if pj >= 0 and padded is not None else None
        if got is not None:
            count, ids, rng, brg = got
        else:
            count, ids, rng, brg = api.pad_detections(None, n)
        self._call_team(api, team, first, sl, n, ranges, angles, max_range, count, ids, rng, brg, step, t, odom, delta,
                        inboxes, events, outgoing)

    def _call_team(self, api, team, first: _Group, sl: slice, n: int, ranges, angles, max_range, count, ids, rng, brg,
                   step: int, t: float, odom, delta, inboxes, events, outgoing: list) -> None:
        """The group brain's call with its observation; its commands and messages stored."""
        obs = api.GroupObservation(
            np.arange(sl.start, sl.stop, dtype=np.int64), step, t, odom[sl], delta[sl], self.state.stalled[sl].copy(),
            ranges, angles, max_range, count, ids, rng, brg,
            tuple(inboxes[sl]) if inboxes is not None else ((),) * n,
            tuple(events[sl]) if events is not None else None,
            self.waiting[sl].copy() if self.waiting is not None else None,
        )
        timer = self._brain_timer
        self.calling = (first.index, None, step, _now())
        try:
            act = team.step_group(obs) if timer is None else timer.call(team.step_group, obs)
            self.calling = None
        except (Exception, SystemExit) as exc:
            raise self._brain_failed(first, None, step, exc) from exc
        if not isinstance(act, api.GroupAction):
            raise self._bad_return(first, None, step, f"step_group() must return a GroupAction, got {_short(act)}")
        self._v_cmd[sl] = act.v_mps
        self._w_cmd[sl] = act.omega_radps
        self._dir_cmd[sl] = act.direction_rad
        outgoing.extend(act.outbox)

    def _write_commands(self, grp: _Group, step: int, vs: list, ws: list, ds: list) -> None:
        """A per-robot group's commands, from its brains' Actions, into the command arrays; a
        value that is not a real number names the robot that commanded it."""
        sl = grp.sl
        try:
            self._v_cmd[sl] = vs
            self._w_cmd[sl] = ws
            self._dir_cmd[sl] = ds
        except (TypeError, ValueError):
            for k, (v, w) in enumerate(zip(vs, ws)):
                if not (_real_number(v) and _real_number(w)):
                    raise self._bad_return(grp, k, step, f"must command real numbers v_mps and omega_radps, got "
                                           f"({_short(v)}, {_short(w)})") from None
            raise

    def _robot(self, grp: _Group, k: int | None) -> str:
        return robot_label(grp.cfg.name, k, None if k is None else grp.sl.start + k)

    def _brain_failed(self, grp: _Group, k: int | None, step: int, exc: BaseException) -> BrainStepError:
        """The error for a brain call that raised ``exc`` (a :class:`TimeoutError` of the
        brain timer: it ran past the limit)."""
        self.calling = None
        if isinstance(exc, TimeUp):
            return BrainTimeoutError(str(grp.cfg.controller), self._robot(grp, k), step, str(exc))
        return BrainStepError(str(grp.cfg.controller), self._robot(grp, k), step, describe(exc))

    def _bad_return(self, grp: _Group, k: int | None, step: int, what: str) -> BrainReturnError:
        self.calling = None
        return BrainReturnError(str(grp.cfg.controller), self._robot(grp, k), step, what)

    def waiting_on(self) -> tuple[str, str, int, float] | None:
        """``(controller, robot, step, seconds)`` of the brain call in progress, None between
        calls (safe to call from another thread: a progress line reads it)."""
        at = self.calling
        if at is None:
            return None
        gi, k, step, t0 = at
        grp = self._groups[gi]
        return str(grp.cfg.controller), self._robot(grp, k), step, _now() - t0

    @contextlib.contextmanager
    def brain_time_limit(self, seconds: float | None) -> Iterator[None]:
        """While inside, each brain call that takes longer than ``seconds`` stops the run with a
        :class:`~teamnav.control.guard.BrainTimeoutError` (None: no limit, nothing armed). Uses
        ``SIGALRM`` in the main thread (:class:`~teamnav.control.guard.BrainTimer`)."""
        if seconds is None:
            yield
            return
        with BrainTimer(seconds) as timer:
            self._brain_timer = timer
            try:
                yield
            finally:
                self._brain_timer = None

    def _apply_batch(self, grp: _Group, act, step: int) -> None:
        n = grp.cfg.count
        if not isinstance(act, BatchAction):
            raise self._bad_return(grp, None, step, f"step_batch() must return a BatchAction, got {_short(act)}")
        try:
            v = np.asarray(act.v_mps, dtype=np.float64)
            w = np.asarray(act.omega_radps, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise self._bad_return(grp, None, step, f"v_mps and omega_radps must be float arrays ({exc})") from None
        if v.shape != (n,) or w.shape != (n,):
            raise self._bad_return(grp, None, step, f"must return v_mps and omega_radps of shape ({n},), "
                                   f"got {v.shape} and {w.shape}")
        self._v_cmd[grp.sl] = v
        self._w_cmd[grp.sl] = w

    # ------------------------------------------------------------------ recording what was sensed and said
    def _record_sensing(self, grp: _Group, scans: list, dets) -> None:
        """Record a group's scans (``[(sensor name, ranges (n, B))]``) and its detections as
        world segments from each observer's true pose (``config.record_scans``)."""
        step = self.step_index
        for si, ((name, ranges), sensor, angles) in enumerate(zip(scans, grp.sensors, grp.angles)):
            key = f"g{grp.index}_" + "".join(c if c.isalnum() or c in "_-" else "_" for c in name)
            if len(key) > 64:  # the recorder's key limit: a long sensor name is cut, its index keeps it unique
                key = key[:58] + f"_s{si}"
            self.recorder.add_scan(key, step, grp.ids, ranges, angles_rad=angles, max_range_m=float(sensor.max_range_m),
                                   group=grp.cfg.name, sensor=name, kind=str(getattr(sensor, "kind", "")))
        if dets is None:
            return
        s = self.state
        for k, seen in enumerate(dets):
            if not seen:
                continue
            i = int(grp.ids[k])
            x, y, th = float(s.x_m[i]), float(s.y_m[i]), float(s.theta_rad[i])
            rows = [(x, y, x + d.range_m * math.cos(th + d.bearing_rad), y + d.range_m * math.sin(th + d.bearing_rad))
                    for d in seen]
            self.recorder.add_layer_sample("detections", step, i, rows)

    def _record_messages(self, inboxes) -> None:
        """Record this step's deliveries as world segments sender → receiver (true positions)."""
        xs, ys = self.state.x_m, self.state.y_m
        for r, box in enumerate(inboxes):
            if box:
                rows = [(xs[m.sender], ys[m.sender], xs[r], ys[r]) for m in box if 0 <= m.sender < self.n_robots]
                self.recorder.add_layer_sample("messages", self.step_index, r, rows)


