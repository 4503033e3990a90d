"""Random exploration: wall following with random turns at openings, per robot and batched.

Vaughan et al., *Blazing a trail* §4 and *Try to see it my way* §3: a robot that has no trail
to follow explores by following walls and, where a side opening appears, takes it with 50 %
chance. This is the simple, robust form of that behaviour (a later module builds the full
sliding-box navigation):

- drive forward at ``cruise_speed_mps``, slowing down linearly between ``slow_distance_m``
  and ``safe_distance_m`` of front range (to a quarter of cruise speed);
- when the front sector (``±front_half_angle_deg``) has a range below ``safe_distance_m``,
  turn on the spot towards the more open half (mean range of the left vs the right half; a
  tie is broken at random) for at least ``min_turn_s`` plus up to ``max_extra_turn_s`` more
  (uniform), and until the front is clear;
- when a wall is within ``wall_follow_max_m`` in a side sector (``|angle|`` between
  ``side_min_deg`` and ``side_max_deg``), keep it at ``wall_distance_m`` with a PD law on the
  sector's minimum range (the derivative damps the weave a pure P law gives a unicycle);
- when the beam nearest ±90° jumps by more than ``opening_jump_m`` from a wall-near range, an
  opening has appeared on that side: take it with probability ``p_turn_at_opening`` (drive
  ``opening_advance_m`` on to clear the near edge, then a quarter turn on the spot);
- when stalled, reverse at ``backoff_speed_mps`` for ``backoff_s``, then turn on the spot in
  a random direction; if reversing stalls too, turn at once.

The robot reads one range sensor: ``sensor`` by name, or its first range sensor when None,
so it works with any beam layout (a 180-beam laser, 7 proximity rays, a sonar ring). Beams
without a return read the sensor's maximum range.

Both :class:`Wander` (a per-robot :class:`~teamnav.control.protocol.Controller`) and
:class:`WanderBatched` (a :class:`~teamnav.control.protocol.BatchedController`) call the one
kernel :func:`teamnav.control.nav.wander_kernel.wander_step`, the first with one row, the
second with a row per robot, and draw random numbers from the counter-based
:func:`~teamnav.control.nav.wander_kernel.uniform01` with a 64-bit key each robot draws from
its own ``Generator`` at construction: the same seed drives the same in both forms.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from teamnav.control.nav import wander_kernel as K
from teamnav.control.protocol import RobotInfo, SensorInfo
from teamnav.control.types import Action, BatchAction, BatchObservation, Message, Observation


class WanderParams(BaseModel):
    """Parameters of the wanderer (units in the names; see the module docstring for the rules).

    Thresholds larger than the sensor can see are capped at construction: ``safe_distance_m``
    to half the sensor's maximum range and ``slow_distance_m``, ``wall_follow_max_m`` to just
    under it (a 14 cm proximity sensor then turns at any return in its front sector), and
    ``wall_distance_m`` to half the capped ``wall_follow_max_m``.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    sensor: str | None = Field(None, min_length=1)
    cruise_speed_mps: float = Field(0.4, gt=0.0, le=10.0)
    turn_rate_radps: float = Field(1.0, gt=0.0, le=20.0)
    safe_distance_m: float = Field(0.5, gt=0.0, le=100.0)
    slow_distance_m: float = Field(1.0, gt=0.0, le=100.0)
    wall_distance_m: float = Field(0.5, gt=0.0, le=100.0)
    wall_follow_max_m: float = Field(1.0, gt=0.0, le=100.0)
    wall_kp_radps_per_m: float = Field(1.5, ge=0.0, le=100.0)
    wall_kd_rad_per_m: float = Field(1.0, ge=0.0, le=100.0)
    p_turn_at_opening: float = Field(0.5, ge=0.0, le=1.0)
    opening_jump_m: float = Field(1.0, gt=0.0, le=100.0)
    opening_advance_m: float = Field(0.4, ge=0.0, le=100.0)
    front_half_angle_deg: float = Field(30.0, gt=0.0, le=90.0)
    side_min_deg: float = Field(30.0, ge=0.0, le=180.0)
    side_max_deg: float = Field(150.0, gt=0.0, le=180.0)
    backoff_speed_mps: float = Field(0.1, ge=0.0, le=10.0)
    backoff_s: float = Field(1.0, ge=0.0, le=60.0)
    min_turn_s: float = Field(0.5, ge=0.0, le=60.0)
    max_extra_turn_s: float = Field(1.5, ge=0.0, le=60.0)

    @model_validator(mode="after")
    def _ordered(self) -> "WanderParams":
        if self.slow_distance_m < self.safe_distance_m:
            raise ValueError(
                f"slow_distance_m must be >= safe_distance_m ({self.safe_distance_m}), got {self.slow_distance_m}"
            )
        if self.wall_follow_max_m <= self.wall_distance_m:
            raise ValueError(
                f"wall_follow_max_m must be > wall_distance_m ({self.wall_distance_m}), got {self.wall_follow_max_m}"
            )
        if self.side_max_deg <= self.side_min_deg:
            raise ValueError(f"side_max_deg must be > side_min_deg ({self.side_min_deg}), got {self.side_max_deg}")
        return self


def pick_sensor(params: WanderParams, info: RobotInfo) -> SensorInfo:
    """The range sensor the wanderer reads: ``params.sensor``, or the robot's first one."""
    if not info.sensors:
        raise ValueError(f"robot {info.robot_id}: the wanderer needs a range sensor, the robot has none")
    if params.sensor is None:
        return next(iter(info.sensors.values()))
    try:
        return info.sensors[params.sensor]
    except KeyError:
        raise ValueError(
            f"sensor must name one of robot {info.robot_id}'s range sensors "
            f"({', '.join(sorted(info.sensors))}), got {params.sensor!r}"
        ) from None


_F64 = np.dtype(np.float64)
_ROW_CALL: Any = None


def _row_call() -> Any:
    """:func:`~teamnav.control.nav.wander_kernel.wander_row`'s compiled code for a 1-D float64
    scan of any layout, called without numba's type dispatch (which costs about as much as the
    kernel itself: every other argument's type is fixed by :class:`Wander`, and
    :meth:`Wander.step` converts a scan of another kind first). The dispatcher itself where
    this numba keeps its compiled code elsewhere."""
    global _ROW_CALL
    if _ROW_CALL is None:
        call = K.wander_row
        try:
            from numba import types as nt

            sig = (nt.Array(nt.float64, 1, "A"), nt.Array(nt.bool_, 2, "C"), nt.Array(nt.float64, 1, "C"), nt.float64,
                   nt.boolean, nt.int64)
            K.wander_row.compile(sig)
            call = K.wander_row.overloads[sig].entry_point
        except (AttributeError, KeyError, TypeError):
            call = K.wander_row  # numba keeps its compiled code elsewhere: the dispatcher, as documented
        _ROW_CALL = call
    return _ROW_CALL


def _steps(duration_s: float, dt_s: float) -> float:
    return float(max(0, round(duration_s / dt_s)))


def kernel_params(params: WanderParams, max_range_m: float, dt_s: float) -> np.ndarray:
    """The kernel's parameter vector (layout ``wander_kernel.P_*``), thresholds capped to the sensor.

    Parameters
    ----------
    params : WanderParams
    max_range_m : float
        The read sensor's maximum range [m].
    dt_s : float
        Control period [s], to turn durations into step counts.

    Returns
    -------
    ndarray of shape (N_PARAMS,), float64
    """
    if not (math.isfinite(max_range_m) and max_range_m > 0):
        raise ValueError(f"max_range_m must be a positive finite number of metres, got {max_range_m!r}")
    if not (math.isfinite(dt_s) and dt_s > 0):
        raise ValueError(f"dt_s must be a positive finite number of seconds, got {dt_s!r}")
    under = 0.999 * max_range_m
    safe = min(params.safe_distance_m, 0.5 * max_range_m)
    slow = max(safe, min(params.slow_distance_m, under))
    wall_max = min(params.wall_follow_max_m, under)
    wall = min(params.wall_distance_m, 0.5 * wall_max)
    p = np.zeros(K.N_PARAMS, dtype=np.float64)
    p[K.P_CRUISE_MPS] = params.cruise_speed_mps
    p[K.P_TURN_RADPS] = params.turn_rate_radps
    p[K.P_SAFE_M] = safe
    p[K.P_SLOW_M] = slow
    p[K.P_WALL_M] = wall
    p[K.P_WALL_MAX_M] = wall_max
    p[K.P_KP] = params.wall_kp_radps_per_m
    p[K.P_KD] = params.wall_kd_rad_per_m
    p[K.P_P_OPEN] = params.p_turn_at_opening
    p[K.P_OPEN_JUMP_M] = params.opening_jump_m
    p[K.P_FRONT_HALF_RAD] = math.radians(params.front_half_angle_deg)
    p[K.P_SIDE_MIN_RAD] = math.radians(params.side_min_deg)
    p[K.P_SIDE_MAX_RAD] = math.radians(params.side_max_deg)
    p[K.P_BACKOFF_MPS] = params.backoff_speed_mps
    p[K.P_BACKOFF_STEPS] = _steps(params.backoff_s, dt_s)
    p[K.P_MIN_TURN_STEPS] = max(1.0, _steps(params.min_turn_s, dt_s))
    p[K.P_EXTRA_TURN_STEPS] = _steps(params.max_extra_turn_s, dt_s)
    p[K.P_OPEN_ADVANCE_STEPS] = _steps(params.opening_advance_m / params.cruise_speed_mps, dt_s)
    p[K.P_OPEN_TURN_STEPS] = max(1.0, _steps(0.5 * math.pi / params.turn_rate_radps, dt_s))
    p[K.P_DT_S] = dt_s
    return p


def draw_key(rng: np.random.Generator) -> np.uint64:
    """A robot's 64-bit key for the counter-based RNG, drawn once from its own Generator."""
    return rng.integers(0, np.iinfo(np.uint64).max, dtype=np.uint64, endpoint=True)


class Wander:
    """One robot's wanderer (a :class:`~teamnav.control.protocol.Controller`).

    Parameters
    ----------
    params : WanderParams
    rng : numpy.random.Generator
        The robot's own stream; one 64-bit key is drawn from it here.
    info : RobotInfo
        Its sensors (to pick the range sensor) and ``dt_s``.

    Examples
    --------
    >>> import numpy as np
    >>> from teamnav.control import Observation, RangeScan, RobotInfo, SensorInfo
    >>> angles = np.linspace(-np.pi / 2, np.pi / 2, 180)
    >>> info = RobotInfo(0, 1, 0.2, "unicycle", 0.5, 1.5, 0.1, 0.1,
    ...                  sensors={"laser": SensorInfo("laser", "laser", angles, 10.0)})
    >>> brain = Wander(Wander.Params(), np.random.default_rng(0), info)
    >>> scan = RangeScan(np.full(180, 10.0), angles, 10.0)
    >>> obs = Observation(0, 0, 0.0, np.zeros(3), np.zeros(3), scans={"laser": scan})
    >>> action, outbox = brain.step(obs)
    >>> action.v_mps, action.omega_radps, outbox
    (0.4, 0.0, [])
    """

    Params = WanderParams

    def __init__(self, params: WanderParams, rng: np.random.Generator, info: RobotInfo) -> None:
        if not isinstance(params, WanderParams):
            raise ValueError(f"params must be a Wander.Params, got {type(params).__name__}")
        sensor = pick_sensor(params, info)
        self.params = params
        self.info = info
        self.sensor = sensor.name
        # Parameters, state, beams nearest ±90° and key in one vector (K.R_*): one array to pass.
        self._row = np.zeros(K.N_ROW, dtype=np.float64)
        self._row[:K.N_PARAMS] = kernel_params(params, float(sensor.max_range_m), float(info.dt_s))
        self._row[K.R_STATE:K.R_STATE + K.N_STATE] = K.initial_state(1)[0]
        self._row.view(np.uint64)[K.R_KEY] = draw_key(rng)
        self._angles: Any = None  # the beam directions the classes below were computed from
        self._angles_fixed = False  # they are an array nobody can change (its own, read-only)
        self._cls = np.zeros((K.N_CLASSES, 0), dtype=np.bool_)
        self._n_beams = 0
        self._action = Action(0.0, 0.0)  # the command in self._row (K.R_V, K.R_W) before the first step

    def step(self, obs: Observation) -> tuple[Action, list[Message]]:
        """Command for this step from the robot's own scan and stall flag; sends nothing."""
        try:
            scan = obs.scans[self.sensor]
        except KeyError:
            raise ValueError(
                f"observation of robot {obs.robot_id} must carry scan {self.sensor!r}, has {sorted(obs.scans)}"
            ) from None
        ranges = scan.ranges_m
        if not (type(ranges) is np.ndarray and ranges.dtype is _F64 and ranges.ndim == 1):
            ranges = np.ascontiguousarray(ranges, dtype=np.float64).reshape(-1)
        angles = scan.angles_rad
        if angles is not self._angles or not self._angles_fixed:
            self._classify(angles)
        if len(ranges) != self._n_beams:
            raise ValueError(f"scan {self.sensor!r} of robot {obs.robot_id}: {len(ranges)} ranges for "
                             f"{self._n_beams} beam angles")
        call = _ROW_CALL or _row_call()
        v, w, same = call(ranges, self._cls, self._row, float(scan.max_range_m), bool(obs.stalled), obs.step)
        if not same:  # an Action is immutable: the same command bit for bit is handed out again
            self._action = Action(v, w)
        return self._action, []

    def _classify(self, angles) -> None:
        """The beam classes of ``angles`` (kept while the scans carry this same unchangeable array)."""
        a = np.ascontiguousarray(angles, dtype=np.float64).reshape(-1)
        if self._cls.shape[1] != a.shape[0] or self._angles is None or not np.array_equal(a, self._angles_copy):
            cls, perp_l, perp_r = K.beam_classes(a, self._row)
            self._cls = cls
            self._n_beams = a.shape[0]
            self._row[K.R_PERP_L] = perp_l
            self._row[K.R_PERP_R] = perp_r
            self._angles_copy = a.copy()
        self._angles = angles
        self._angles_fixed = type(angles) is np.ndarray and angles.base is None and not angles.flags.writeable

    def log(self) -> dict[str, Any]:
        """The current mode (0 cruise, 1 turn, 2 back off, 3/4 taking an opening) and wall side."""
        return {"mode": int(self._row[K.R_STATE + K.S_MODE]), "wall": int(self._row[K.R_STATE + K.S_WALL])}


class WanderBatched:
    """The wanderer for a whole group in one kernel call (a :class:`~teamnav.control.protocol.BatchedController`).

    Row i drives exactly as a :class:`Wander` built with ``rngs[i]`` and ``infos[i]`` would.

    Parameters
    ----------
    params : WanderParams
    rngs : list of numpy.random.Generator
        One per robot row; each gives that robot's key.
    infos : list of RobotInfo
        One per row; all must share the read sensor's maximum range and ``dt_s``.
    """

    Params = WanderParams
    batched = True

    def __init__(self, params: WanderParams, rngs: list[np.random.Generator], infos: list[RobotInfo]) -> None:
        if not isinstance(params, WanderParams):
            raise ValueError(f"params must be a WanderBatched.Params, got {type(params).__name__}")
        if len(rngs) != len(infos) or not infos:
            raise ValueError(f"rngs and infos must be non-empty and of one length, got {len(rngs)} and {len(infos)}")
        sensors = [pick_sensor(params, info) for info in infos]
        names = {s.name for s in sensors}
        ranges = {float(s.max_range_m) for s in sensors}
        dts = {float(info.dt_s) for info in infos}
        if len(names) != 1 or len(ranges) != 1 or len(dts) != 1:
            raise ValueError(
                "infos must share one range sensor, max range and dt_s, got sensors "
                f"{sorted(names)}, max ranges {sorted(ranges)}, dt_s {sorted(dts)}"
            )
        self.params = params
        self.infos = list(infos)
        self.range_sensor: str = names.pop()
        self._p = kernel_params(params, ranges.pop(), dts.pop())
        self._keys = np.array([draw_key(rng) for rng in rngs], dtype=np.uint64)
        self._state = K.initial_state(len(infos))
        self._v = np.zeros(len(infos))
        self._w = np.zeros(len(infos))

    def step_batch(self, obs: BatchObservation) -> BatchAction:
        """Commands for every row; ``obs.ranges_m`` has one row per robot, in construction order."""
        n = self._keys.shape[0]
        ranges = np.ascontiguousarray(obs.ranges_m, dtype=np.float64)
        if ranges.ndim != 2 or ranges.shape[0] != n:
            raise ValueError(f"obs.ranges_m must have shape ({n}, n_beams), got {ranges.shape}")
        stalled = np.ascontiguousarray(obs.stalled, dtype=np.bool_)
        angles = np.ascontiguousarray(obs.angles_rad, dtype=np.float64)
        threads = numba.get_num_threads()
        if n >= K.PARALLEL_MIN_ROWS and threads > 1:  # rows are independent: the same on any thread count
            K.wander_step_parallel(ranges, angles, float(obs.max_range_m), stalled, self._keys, np.int64(obs.step),
                                   self._p, self._state, self._v, self._w, np.int64(min(512, n // (4 * threads))))
        else:
            K.wander_step(ranges, angles, float(obs.max_range_m), stalled, self._keys,
                          np.int64(obs.step), self._p, self._state, self._v, self._w)
        return BatchAction(self._v.copy(), self._w.copy())

    def log(self) -> dict[str, Any]:
        """Per-row modes and wall sides, as int arrays of shape (n,)."""
        return {"mode": self._state[:, K.S_MODE].astype(np.int64), "wall": self._state[:, K.S_WALL].astype(np.int64)}
