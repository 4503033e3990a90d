"""Validated configuration of the simulated robots, sensors, odometry, radio and places.

These pydantic models are the single source of truth for what a scenario file may say about
the simulation (``teamnav.experiments.spec.Scenario`` extends :class:`SimConfig` with the map,
duration and metrics). Every model forbids unknown keys and bounds its numbers, so a typo or a
NaN stops the run before it starts with a message naming the field (STYLE habit 10).

Units are in the field names: ``_m``, ``_s``, ``_deg`` (degrees are for humans writing YAML;
the code converts to radians once, at the boundary).
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

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
    message sent at step k is delivered at step k+1."""

    mode: Literal["broadcast", "range", "line_of_sight"] = "broadcast"
    range_m: float = Field(1e9, gt=0.0)
    p_loss: Prob = 0.0
    sees: tuple[str, ...] = DEFAULT_SEES["vision"]


# ---------------------------------------------------------------------------- places / events
class PlaceConfig(Model):
    """A named disc region. A robot entering it (centre within ``radius_m``) fires ``event``
    for that robot (the trail scenarios: "took_resource" at the source, "given_resource" at
    home); with ``on="inside"`` it fires every step the robot is inside instead of on entry."""

    name: str
    x_m: float
    y_m: float
    radius_m: float = Field(1.0, gt=0.0)
    event: str | None = None
    on: Literal["enter", "inside"] = "enter"


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

    @field_validator("robots")
    @classmethod
    def _some_robots(cls, v):
        if not v:
            raise ValueError("needs at least one robot group")
        return v

    @property
    def n_robots(self) -> int:
        return sum(g.count for g in self.robots)


def deg(v: float) -> float:
    """Degrees to radians (one place for the YAML boundary)."""
    return math.radians(v)
