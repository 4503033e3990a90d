"""Validated configuration of the simulated robots, sensors, odometry, radio and places.

These pydantic models are the single source of truth for what a scenario file may say about
the simulation (``teamnav.experiments.spec.Scenario`` extends :class:`SimConfig` with the map,
duration and metrics). Every model forbids unknown keys and bounds its numbers, so a typo or a
NaN stops the run before it starts with a message naming the field (STYLE habit 10).

Units are in the field names: ``_m``, ``_s``, ``_deg`` (degrees are for humans writing YAML;
the code converts to radians once, at the boundary).

The ``faults`` section (:class:`FaultsConfig`: robots that die or lose their radio, radio
blackouts, sensor dropouts, kidnappings, bursts of false detections) is validated here too,
robots named by global index or by group name and index; :mod:`teamnav.sim.faults` applies it.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, ClassVar, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_serializer, model_validator

from teamnav.world.grid import DEFAULT_SEES


class Model(BaseModel):
    """Base: unknown keys are errors, values are immutable, NaN/inf are refused."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


Prob = Annotated[float, Field(ge=0.0, le=1.0)]
PosFloat = Annotated[float, Field(gt=0.0)]
NonNegFloat = Annotated[float, Field(ge=0.0)]


# ---------------------------------------------------------------------------- range sensors
class LaserConfig(Model):
    """A scanning laser range finder (e.g. SICK LMS: 180 beams over 180°).

    Readings: the ray-cast range plus Gaussian noise ``noise_std_m``; with probability
    ``p_max`` a beam returns ``max_range_m`` (a missed return), with probability ``p_short``
    a uniform random range shorter than the true one (an unexpected object), as in the
    mixture that Fox et al. §2.2 (Fig. 1) and Thrun et al. (*Probabilistic Robotics* §6.3)
    model. Deviation: short readings are uniform on [0, true range) here, where Fox et al. model
    them as geometric; the filter's model, not the simulator's, is what the paper specifies.
    """

    kind: Literal["laser"] = "laser"
    name: str = "laser"
    n_beams: int = Field(180, ge=1, le=8192)
    fov_deg: float = Field(180.0, gt=0.0, le=360.0)
    max_range_m: float = Field(10.0, gt=0.0, le=1000.0)
    noise_std_m: NonNegFloat = 0.01
    p_max: Prob = 0.0
    p_short: Prob = 0.0
    sees: tuple[str, ...] = DEFAULT_SEES["laser"]
    sees_robots: bool = True


class SonarConfig(Model):
    """A ring of sonar transducers, each a cone (e.g. 16 on a Pioneer / B21 ring).

    Each transducer returns the *nearest* return over ``rays_per_cone`` rays spread over its
    ``cone_deg`` opening, plus Gaussian noise; with probability ``p_specular`` it returns
    ``max_range_m`` (a specular reflection that never came back), with ``p_short`` a short
    random reading (crosstalk).
    """

    kind: Literal["sonar"] = "sonar"
    name: str = "sonar"
    n_transducers: int = Field(16, ge=1, le=256)
    fov_deg: float = Field(360.0, gt=0.0, le=360.0)
    cone_deg: float = Field(15.0, gt=0.0, le=90.0)
    rays_per_cone: int = Field(5, ge=1, le=64)
    max_range_m: float = Field(5.0, gt=0.0, le=100.0)
    noise_std_m: NonNegFloat = 0.02
    p_specular: Prob = 0.02
    p_short: Prob = 0.0
    sees: tuple[str, ...] = DEFAULT_SEES["sonar"]
    sees_robots: bool = True


class ProximityConfig(Model):
    """Short-range infrared proximity sensors at given body-frame angles (e.g. a Thymio's 7)."""

    kind: Literal["proximity"] = "proximity"
    name: str = "proximity"
    angles_deg: tuple[float, ...] = (-40.0, -20.0, 0.0, 20.0, 40.0, 160.0, 200.0)
    max_range_m: float = Field(0.14, gt=0.0, le=10.0)
    noise_std_m: NonNegFloat = 0.0
    sees: tuple[str, ...] = DEFAULT_SEES["proximity"]
    sees_robots: bool = True

    @field_validator("angles_deg")
    @classmethod
    def _some_angles(cls, v: tuple[float, ...]) -> tuple[float, ...]:
        if not v:
            raise ValueError("needs at least one angle")
        return v


RangeSensorConfig = Annotated[Union[LaserConfig, SonarConfig, ProximityConfig], Field(discriminator="kind")]


# ---------------------------------------------------------------------------- robot detector
class DetectorConfig(Model):
    """Sees teammates: omnidirectional visibility (``fov_deg=360``) or a camera cone.

    A teammate is detected when within ``max_range_m``, inside the field of view and, if
    ``line_of_sight``, not hidden by a cell the detector ``sees``. Noise:

    - ``noise_model="gaussian"``: range + N(0, ``range_noise_std_m``), bearing +
      N(0, ``bearing_noise_std_deg``) (Fox et al. §4);
    - ``noise_model="occlusion"``: Sgorbissa & Arkin eqs. 1–2,
      ``d_p = d_r + d_r·d_noise``, ``α_p = α_r + atan(size / 2 d_r)·α_noise`` with
      ``d_noise ~ U[-err_max, err_max]``, ``α_noise ~ U[-1, 1]`` (§6.1: the bearing error is
      bounded by the seen robot's angular half-width whatever ``err_max`` is) and ``size``
      the seen robot's diameter. Perfect sensing is the gaussian model with zero deviations.

    ``p_false_negative``: a visible teammate is missed. ``p_false_positive``: per step, a
    phantom detection at a uniform range/bearing within the field of view.
    ``report_identity``: whether the detector says *which* teammate it saw.
    """

    fov_deg: float = Field(360.0, gt=0.0, le=360.0)
    max_range_m: float = Field(5.0, gt=0.0, le=1000.0)
    line_of_sight: bool = True
    noise_model: Literal["gaussian", "occlusion"] = "gaussian"
    range_noise_std_m: NonNegFloat = 0.0
    bearing_noise_std_deg: NonNegFloat = 0.0
    err_max: float = Field(0.0, ge=0.0, le=1.0)
    p_false_negative: Prob = 0.0
    p_false_positive: Prob = 0.0
    report_identity: bool = True
    sees: tuple[str, ...] = DEFAULT_SEES["vision"]


# ---------------------------------------------------------------------------- odometry
class OdometryConfig(Model):
    """Wheel odometry: random noise plus systematic drift.

    Random part: the odometry motion model of Thrun et al. (*Probabilistic Robotics* Table
    5.6), ``alpha = (α1, α2, α3, α4)``: rotation noise from rotation, rotation noise from
    translation, translation noise from translation, translation noise from rotation.
    Systematic part: a heading drift of ``heading_drift_deg_per_min`` (Vaughan et al. saw
    0.35°–2°/min) and a translation ``scale_error`` (reported = true × (1 + scale_error): a wheel
    diameter off by that fraction). Wheel slip (:mod:`teamnav.sim.odometry`): random walks per
    metre driven, whatever the step: ``slip_std_m_per_sqrt_m`` (distance error, std √L m after
    L m) and ``heading_slip_deg_per_sqrt_m`` (heading error, std √L deg after L m).

    ``frame``: ``"start"`` — the odometry frame is the robot's start pose (odom starts at
    (0, 0, 0)); ``"world"`` — frames start aligned with the world (Vaughan et al.: robots start
    at home with aligned frames), so odometry starts at the true start pose.
    """

    alpha: tuple[NonNegFloat, NonNegFloat, NonNegFloat, NonNegFloat] = (0.0, 0.0, 0.0, 0.0)
    heading_drift_deg_per_min: float = Field(0.0, ge=-360.0, le=360.0)
    scale_error: float = Field(0.0, gt=-0.5, lt=0.5)
    slip_std_m_per_sqrt_m: float = Field(0.0, ge=0.0, le=0.5)
    heading_slip_deg_per_sqrt_m: float = Field(0.0, ge=0.0, le=30.0)
    frame: Literal["start", "world"] = "start"


# ---------------------------------------------------------------------------- start poses
class StartConfig(Model):
    """Where a group's robots start: explicit ``poses`` [[x_m, y_m, theta_deg], ...] (robot k
    takes pose k; a list longer than the group's ``count`` is allowed and its first ``count``
    poses are used, so a sweep can grid ``count`` over one list of start poses), or
    uniformly at random in free space inside ``region`` [xmin, xmax, ymin, ymax] (or the whole
    map when neither is given), with heading ``theta_deg`` or uniform when None, never
    overlapping a wall or another robot."""

    poses: tuple[tuple[float, float, float], ...] | None = None
    region: tuple[float, float, float, float] | None = None
    theta_deg: float | None = None

    @model_validator(mode="after")
    def _one_way(self) -> "StartConfig":
        if self.poses is not None and self.region is not None:
            raise ValueError("give either 'poses' or 'region', not both")
        if self.region is not None:
            xmin, xmax, ymin, ymax = self.region
            if not (xmin < xmax and ymin < ymax):
                raise ValueError(f"region must be [xmin, xmax, ymin, ymax] with xmin < xmax and ymin < ymax, got {list(self.region)}")
        return self


class LaunchConfig(Model):
    """Robots started one at a time from one spot, as an experimenter starts real robots
    (Vaughan et al. 2000 §5 and 2002 §3.5: "The robots are started one at a time from the same
    spot at the home position, with the same orientation").

    Every robot starts at ``spot`` [x_m, y_m, theta_deg] (each group's ``start`` is not used),
    in robot id order. Robot 0 starts at step 0; each later robot starts at the first step at
    which every robot already started is at least ``clear_m`` from the spot (centre to centre).
    Until then the robot is not in the arena: the engine (:class:`~teamnav.sim.engine.Simulation`)
    never steps its brain, commands it nothing, delivers it no message, and no other robot's
    sensors, detector or body meet it; its odometry starts from the spot when it starts. The
    truth keeps it at the spot (recorded there, so its path starts there) and place events are
    withheld from it while it waits. A batched brain (one brain for a whole group) is still
    handed its waiting robots' rows, sensed from outside the map (every range 0), and their
    commands are ignored until they start. :mod:`teamnav.env` drops the section (its agents act
    for every robot from step 0) and uses the groups' ``start``.
    """

    spot: tuple[float, float, float]
    clear_m: float = Field(gt=0.0, le=100.0)


# ---------------------------------------------------------------------------- robots
class RobotGroupConfig(Model):
    """``count`` identical robots running the same controller.

    ``kinematics="unicycle"``: (v, ω) commands clipped to ``max_v_mps`` / ``max_omega_degps``.
    ``kinematics="holonomic_step"``: each step the robot turns to a chosen direction and moves
    ``step_length_m`` (Sgorbissa & Arkin §6 count such motion steps).
    """

    name: str = "robot"
    count: int = Field(1, ge=0, le=100_000)
    radius_m: float = Field(0.2, gt=0.0, le=10.0)
    kinematics: Literal["unicycle", "holonomic_step"] = "unicycle"
    max_v_mps: float = Field(0.5, gt=0.0, le=100.0)
    max_omega_degps: float = Field(90.0, gt=0.0, le=3600.0)
    step_length_m: float = Field(0.1, gt=0.0, le=10.0)
    controller: str = "wander-v1"
    params: dict[str, Any] = Field(default_factory=dict)
    sensors: tuple[RangeSensorConfig, ...] = (LaserConfig(),)
    detector: DetectorConfig | None = None
    odometry: OdometryConfig = OdometryConfig()
    start: StartConfig = StartConfig()

    @field_validator("sensors")
    @classmethod
    def _unique_names(cls, v):
        names = [s.name for s in v]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ValueError(f"sensor names must be unique, repeated: {sorted(dup)}")
        return v

    @model_validator(mode="after")
    def _start_count(self) -> "RobotGroupConfig":
        if self.start.poses is not None and len(self.start.poses) < self.count:
            raise ValueError(
                f"start.poses must list at least count={self.count} poses (the first {self.count} are used), "
                f"got {len(self.start.poses)}"
            )
        return self


# ---------------------------------------------------------------------------- radio
class RadioConfig(Model):
    """Who hears a message: everyone (``broadcast``), robots within ``range_m`` (``range``),
    or robots within ``range_m`` *and* in line of sight (``line_of_sight``: Sgorbissa & Arkin's
    robots talk only while they see each other). Each delivery is lost with ``p_loss``; a
    message sent at step k is delivered at step k+1.

    ``bandwidth_bps`` (bytes per second per sender; None, the default, is unlimited: every
    paper's rule, none of the four papers caps its radio) is ours (a restricted radio for every
    system, added 2026-11-27): a token bucket per sender, full at the start, refilled every step by
    ``bandwidth_bps * dt_s`` up to a burst of ``bandwidth_burst_s`` seconds of the cap
    (default 1 s; it must hold the largest message a system sends, or that message never
    goes out: a trail robot's 100-B crumb needs ``bandwidth_bps * bandwidth_burst_s >= 100``). Each
    message the sender sends (in outbox order, sized by :meth:`Message.size_bytes`) goes out when
    it fits in the bucket, and takes its bytes out; one that does not fit is **dropped** at the
    sender (not sent, counted under ``over_cap`` in the radio's counts), not queued: every
    system here broadcasts its latest state (poses, goals, trees, crumbs), which a later message
    replaces, so a queue would deliver stale news late and break the one-step delay. A message
    larger than the burst can never go out. The cap counts transmissions, not receivers (one
    broadcast costs its size once). Without the cap the radio is unchanged, bit for bit.
    """

    mode: Literal["broadcast", "range", "line_of_sight"] = "broadcast"
    range_m: float = Field(1e9, gt=0.0)
    p_loss: Prob = 0.0
    sees: tuple[str, ...] = DEFAULT_SEES["vision"]
    bandwidth_bps: float | None = Field(None, gt=0.0, le=1e12)
    bandwidth_burst_s: float = Field(1.0, gt=0.0, le=86400.0)

    @model_serializer(mode="wrap")
    def _without_unlimited_bandwidth(self, handler):
        # an uncapped radio dumps as before the cap existed (config hashes and stored trials stay)
        data = handler(self)
        if isinstance(data, dict) and self.bandwidth_bps is None:
            data.pop("bandwidth_bps", None)
            if self.bandwidth_burst_s == 1.0:
                data.pop("bandwidth_burst_s", None)
        return data


# ---------------------------------------------------------------------------- places / events
#: a place coordinate or waypoint time: finite and bounded, like the faults' [m], [s]
PlaceCoord = Annotated[float, Field(ge=-1e6, le=1e6)]


class PlaceWaypoint(Model):
    """Where a moving place is at time ``t_s`` [s] (world metres ``x_m``, ``y_m``)."""

    t_s: float = Field(gt=0.0, le=1e7)
    x_m: PlaceCoord
    y_m: PlaceCoord


class PlaceMotion(Model):
    """How a place moves (beyond the papers: Vaughan et al. 2000 §6 names a moving resource as
    future work and gives no motion; this is ours). The place is at its own ``x_m``, ``y_m`` at
    t = 0 and at each waypoint of ``path`` at that waypoint's ``t_s`` (strictly increasing).

    - ``mode="linear"``: straight-line, constant-speed motion between consecutive positions
      (slow motion); after the last waypoint the place stays there.
    - ``mode="jump"``: the place stays where it is until the next waypoint's time, then is there
      at once (it is at waypoint k from ``t_s[k]`` inclusive).
    - ``period_s`` (optional, > the last ``t_s``): the motion repeats with this period; from the
      last waypoint the place goes back to its start, moving in ``linear`` mode, jumping at
      ``period_s`` in ``jump`` mode.

    :func:`teamnav.sim.events.place_positions` evaluates it.
    """

    mode: Literal["linear", "jump"] = "linear"
    path: tuple[PlaceWaypoint, ...] = Field(min_length=1, max_length=10_000)
    period_s: float | None = Field(None, gt=0.0, le=1e7)

    @model_validator(mode="after")
    def _times_increase(self) -> "PlaceMotion":
        ts = [w.t_s for w in self.path]
        for j in range(1, len(ts)):
            if not ts[j] > ts[j - 1]:
                raise ValueError(f"path[{j}].t_s: waypoint times must increase strictly; expected > "
                                 f"{ts[j - 1]} (path[{j - 1}].t_s), got {ts[j]}")
        if self.period_s is not None and not self.period_s > ts[-1]:
            raise ValueError(f"period_s: expected more than the last waypoint time {ts[-1]} s, got {self.period_s}")
        return self


class PlaceConfig(Model):
    """A named disc region. A robot entering it (centre within ``radius_m``) fires ``event``
    for that robot (the trail scenarios: "took_resource" at the source, "given_resource" at
    home); with ``on="inside"`` it fires every step the robot is inside instead of on entry.

    ``motion`` (:class:`PlaceMotion`, optional; beyond the papers) moves the disc over time from
    ``x_m``, ``y_m`` (its position at t = 0). Without it the place is static and the field is left
    out of the resolved scenario (config hashes unchanged)."""

    name: str
    x_m: float
    y_m: float
    radius_m: float = Field(1.0, gt=0.0)
    event: str | None = None
    on: Literal["enter", "inside"] = "enter"
    motion: PlaceMotion | None = None

    @model_serializer(mode="wrap")
    def _without_static_motion(self, handler):
        data = handler(self)
        if isinstance(data, dict) and self.motion is None:
            data.pop("motion", None)
        return data


# ---------------------------------------------------------------------------- faults
#: most entries of one kind a ``faults`` section may list
MAX_FAULTS = 1000
FaultTime = Annotated[float, Field(ge=0.0, le=1e7)]
#: a world coordinate of a fault [m] and a heading [deg]
FaultCoord = Annotated[float, Field(ge=-1e6, le=1e6)]
FaultHeading = Annotated[float, Field(ge=-3600.0, le=3600.0)]


class GroupRobot(Model):
    """A robot named by its group: the ``index``-th robot (from 0) of the group ``group``
    (``robots[g].name``; the name must belong to one group only)."""

    group: str = Field(min_length=1, max_length=100)
    index: int = Field(0, ge=0, le=100_000)


#: a robot: its global index (robot ids follow the groups in order), or ``{group, index}``
RobotRef = Union[Annotated[int, Field(ge=0, le=10_000_000)], GroupRobot]


class _Window(Model):
    """A time window ``[t0_s, t1_s]`` (both ends included) [s]."""

    t0_s: FaultTime
    t1_s: FaultTime

    @model_validator(mode="after")
    def _ordered(self):
        if self.t1_s < self.t0_s:
            raise ValueError(f"t1_s must be >= t0_s ({self.t0_s}), got {self.t1_s}")
        return self


class RobotDeath(Model):
    """Robot ``robot`` dies at ``t_s``: from the first step at or after ``t_s`` its brain is no
    longer stepped, its commands are zero (it stops where it is and stays there, an obstacle
    that other robots' sensors, detectors and bodies still meet) and its radio is off."""

    robot: RobotRef
    t_s: FaultTime


class RadioDropout(Model):
    """Robot ``robot``'s radio fails at ``t_s`` (until ``until_s``, or for good when None): it
    sends nothing and receives nothing; everything else works."""

    robot: RobotRef
    t_s: FaultTime
    until_s: FaultTime | None = None

    @model_validator(mode="after")
    def _ordered(self):
        if self.until_s is not None and self.until_s <= self.t_s:
            raise ValueError(f"until_s must be > t_s ({self.t_s}), got {self.until_s}")
        return self


class RadioBlackout(_Window):
    """No radio at all in ``[t0_s, t1_s]``: a message sent in the window is lost, and so is one
    that would be delivered in it."""


class SensorDropout(_Window):
    """Robot ``robot``'s sensor ``sensor`` returns nothing in ``[t0_s, t1_s]``.

    ``sensor``: the index of a range sensor in the group's ``sensors`` list, a range sensor's
    ``name`` or ``kind`` (a kind must be unique in the group), or ``"detector"`` (the robot
    detector). What "nothing" is, for a range sensor, is ``reading``:

    - ``"no_return"`` (default): every beam reads ``max_range_m``, the
      :class:`~teamnav.control.types.RangeScan` value for "no return" (a laser whose receiver
      sees no echo; a brain cannot tell it from open space);
    - ``"no_scan"``: the sensor publishes nothing, its key is absent from ``Observation.scans``
      (a driver that stopped; the brains shipped with teamnav refuse an observation without
      their scan, so the run then ends with that error).

    The detector returns no detection at all (true or false). The sensor is still simulated
    (its noise stream draws as usual), only its output is withheld.
    """

    robot: RobotRef
    sensor: Union[Annotated[int, Field(ge=0, le=8192)], Annotated[str, Field(min_length=1, max_length=100)]]
    reading: Literal["no_return", "no_scan"] = "no_return"


class Kidnapping(Model):
    """Robot ``robot`` is carried away at ``t_s`` (truth only: its odometry never sees the jump).

    To ``pose`` ``[x_m, y_m, theta_deg]``, or, when ``pose`` is None, to a pose drawn uniformly
    over the free space of ``region`` ``[xmin, xmax, ymin, ymax]`` (or of the whole map) with a
    uniform heading, from the run's fault stream. A target overlapping another robot at that
    moment is tried again at the next steps (explicit pose) or redrawn (random pose).
    """

    robot: RobotRef
    t_s: float = Field(gt=0.0, le=1e7)
    pose: tuple[FaultCoord, FaultCoord, FaultHeading] | None = None
    region: tuple[FaultCoord, FaultCoord, FaultCoord, FaultCoord] | None = None

    @model_validator(mode="after")
    def _one_way(self):
        if self.pose is not None and self.region is not None:
            raise ValueError("give either 'pose' or 'region' (a random pose in it), not both")
        if self.region is not None:
            xmin, xmax, ymin, ymax = self.region
            if not (xmin < xmax and ymin < ymax):
                raise ValueError(f"region must be [xmin, xmax, ymin, ymax] with xmin < xmax and ymin < ymax, "
                                 f"got {list(self.region)}")
        return self


class FalsePositiveBurst(_Window):
    """In ``[t0_s, t1_s]`` the robot detector of ``robot`` (every robot with a detector when
    None) reports phantom robots: per step a Poisson number of them with mean
    ``rate_hz * dt_s``, each at a range uniform in ``(0, max_range_m]`` and a bearing uniform
    over the field of view, with the identity of a uniformly drawn other robot when the
    detector reports identities (else none), as the detector's own ``p_false_positive`` rule."""

    robot: RobotRef | None = None
    rate_hz: float = Field(gt=0.0, le=1000.0)


class FaultsConfig(Model):
    """What goes wrong during a run, applied on the truth side by :mod:`teamnav.sim.faults`
    (brains learn of a fault only through what they observe). Each list holds at most
    :data:`MAX_FAULTS` entries; a time is applied at the first step at or after it."""

    deaths: tuple[RobotDeath, ...] = Field((), max_length=MAX_FAULTS)
    radio_dropouts: tuple[RadioDropout, ...] = Field((), max_length=MAX_FAULTS)
    blackouts: tuple[RadioBlackout, ...] = Field((), max_length=MAX_FAULTS)
    sensor_dropouts: tuple[SensorDropout, ...] = Field((), max_length=MAX_FAULTS)
    kidnappings: tuple[Kidnapping, ...] = Field((), max_length=MAX_FAULTS)
    false_positives: tuple[FalsePositiveBurst, ...] = Field((), max_length=MAX_FAULTS)

    @property
    def empty(self) -> bool:
        """True when no fault is listed."""
        return not any(getattr(self, k) for k in type(self).model_fields)


def resolve_robot(ref: Any, robots: tuple[RobotGroupConfig, ...], field: str) -> int:
    """The global robot index of ``ref`` (an int or a :class:`GroupRobot`).

    Raises
    ------
    ValueError
        ``"<field>: ..."``: an index past the team, an unknown or shared group name, an index
        past the group's count.

    Examples
    --------
    >>> groups = (RobotGroupConfig(name="a", count=2), RobotGroupConfig(name="b", count=3))
    >>> resolve_robot(GroupRobot(group="b", index=1), groups, "robot"), resolve_robot(4, groups, "robot")
    (3, 4)
    """
    n = sum(g.count for g in robots)
    if isinstance(ref, GroupRobot):
        where = [gi for gi, g in enumerate(robots) if g.name == ref.group]
        if not where:
            names = ", ".join(repr(g.name) for g in robots)
            raise ValueError(f"{field}.group: expected the name of a robot group ({names}), got {ref.group!r}")
        if len(where) > 1:
            raise ValueError(f"{field}.group: group name {ref.group!r} is shared by robots[{where[0]}] and "
                             f"robots[{where[1]}]; expected a unique name (or give the robot's global index)")
        g = robots[where[0]]
        if ref.index >= g.count:
            raise ValueError(f"{field}.index: expected a robot index in [0, {g.count}) of group {ref.group!r} "
                             f"(count {g.count}), got {ref.index}")
        return sum(x.count for x in robots[: where[0]]) + ref.index
    if not 0 <= int(ref) < n:
        raise ValueError(f"{field}: expected a robot index in [0, {n}) (the scenario has {n} robots), got {ref}")
    return int(ref)


def group_of_robot(i: int, robots: tuple[RobotGroupConfig, ...]) -> int:
    """The index of the group robot ``i`` belongs to."""
    start = 0
    for gi, g in enumerate(robots):
        if start <= i < start + g.count:
            return gi
        start += g.count
    raise ValueError(f"robot index {i} is past the team of {start} robots")


def resolve_sensor(ref: int | str, group: RobotGroupConfig, field: str) -> int | None:
    """The index in ``group.sensors`` of range sensor ``ref``, or None for ``"detector"``.

    Raises
    ------
    ValueError
        ``"<field>: ..."``: an index past the list, an unknown name or kind, a kind shared by
        several sensors, ``"detector"`` for a group without one.
    """
    names = [s.name for s in group.sensors]
    if isinstance(ref, int):
        if ref >= len(names):
            raise ValueError(f"{field}: expected a sensor index in [0, {len(names)}) (group {group.name!r} has "
                             f"{len(names)} range sensors), got {ref}")
        return ref
    if ref == "detector":
        if group.detector is None:
            raise ValueError(f"{field}: group {group.name!r} has no detector, got 'detector'")
        return None
    if ref in names:
        return names.index(ref)
    kinds = [s.kind for s in group.sensors]
    if kinds.count(ref) == 1:
        return kinds.index(ref)
    if kinds.count(ref) > 1:
        raise ValueError(f"{field}: group {group.name!r} has {kinds.count(ref)} sensors of kind {ref!r}; expected "
                         f"a sensor name ({', '.join(names)}) or index, got {ref!r}")
    known = ", ".join([repr(x) for x in names] + ["'detector'"] * (group.detector is not None))
    raise ValueError(f"{field}: expected a sensor index, name, kind or 'detector' of group {group.name!r} "
                     f"({known or 'none'}), got {ref!r}")


class SimConfig(Model):
    """Everything the engine needs besides the map."""

    robots: tuple[RobotGroupConfig, ...] = (RobotGroupConfig(),)
    radio: RadioConfig = RadioConfig()
    places: tuple[PlaceConfig, ...] = ()
    dt_s: float = Field(0.1, gt=0.0, le=10.0)
    seed: int = Field(0, ge=0, le=2**63 - 1)
    robot_collisions: bool = True
    record_every: int = Field(1, ge=1, le=1_000_000)
    #: also record, at every recorded step, what robots sensed and said: each range sensor's
    #: scan, the robot detector's detections and the delivered radio messages (the recorder's
    #: ``scan.*`` arrays and ``detections`` / ``messages`` segment layers, for replays and MCAP)
    record_scans: bool = False
    #: what goes wrong during the run (:class:`FaultsConfig`); None: nothing. A run without
    #: faults (None or an empty section) is the same, bit for bit, as before faults existed,
    #: and the section is left out of the resolved scenario then.
    faults: FaultsConfig | None = None
    #: robots started one at a time from one spot (:class:`LaunchConfig`); None: all at step 0
    #: from their groups' ``start``. Left out of the resolved scenario when None (config
    #: hashes unchanged).
    launch: LaunchConfig | None = None
    #: fields a subclass adds that serialisation leaves out when None (config hashes unchanged)
    _OMIT_WHEN_NONE: ClassVar[tuple[str, ...]] = ()

    @field_validator("robots")
    @classmethod
    def _some_robots(cls, v):
        if not v:
            raise ValueError("needs at least one robot group")
        return v

    @model_validator(mode="after")
    def _faults_refer_to_robots(self) -> "SimConfig":
        """Every robot and sensor a fault names exists (the first problem, its field named)."""
        f = self.faults
        if f is None:
            return self
        robots = self.robots
        for kind in ("deaths", "radio_dropouts", "sensor_dropouts", "kidnappings", "false_positives"):
            for j, entry in enumerate(getattr(f, kind)):
                field = f"faults.{kind}[{j}]"
                if entry.robot is None:  # a false-positive burst for every robot with a detector
                    if not any(g.detector is not None for g in robots):
                        raise ValueError(f"{field}.robot: no robot group has a detector to report false positives")
                    continue
                i = resolve_robot(entry.robot, robots, f"{field}.robot")
                g = robots[group_of_robot(i, robots)]
                if kind == "sensor_dropouts":
                    resolve_sensor(entry.sensor, g, f"{field}.sensor")
                elif kind == "false_positives" and g.detector is None:
                    raise ValueError(f"{field}.robot: robot {i} (group {g.name!r}) has no detector to report false "
                                     "positives")
        return self

    @model_serializer(mode="wrap")
    def _without_empty_faults(self, handler):
        """Leave ``faults`` out when there are none, so a resolved scenario without faults (and
        its sweeps' config hash) is what it was before the section existed."""
        data = handler(self)
        if isinstance(data, dict) and (self.faults is None or self.faults.empty):
            data.pop("faults", None)
        if isinstance(data, dict) and self.launch is None:
            data.pop("launch", None)
        if isinstance(data, dict):  # sections of subclasses that are left out when absent (Scenario.env)
            for key in self._OMIT_WHEN_NONE:
                if data.get(key, 0) is None:
                    data.pop(key)
        return data

    @property
    def n_robots(self) -> int:
        return sum(g.count for g in self.robots)


def deg(v: float) -> float:
    """Degrees to radians (one place for the YAML boundary)."""
    return math.radians(v)
