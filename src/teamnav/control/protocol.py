"""The brain interfaces: per-robot :class:`Controller` and :class:`BatchedController`.

A controller class declares its parameters as a pydantic model ``Params`` (``extra="forbid"``,
bounded fields) so scenario files are validated before a run starts. It is built from those
parameters, its own seeded ``numpy.random.Generator`` and a :class:`RobotInfo` (what the robot
knows about its own body and sensors), and never sees the simulator.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np
from pydantic import BaseModel, ConfigDict

from teamnav.control.types import Action, BatchAction, BatchObservation, Message, Observation


class NoParams(BaseModel):
    """Parameters of a controller that takes none."""

    model_config = ConfigDict(extra="forbid", frozen=True)


@dataclass(frozen=True)
class SensorInfo:
    """What a robot knows of one of its range sensors (its datasheet, not the world)."""

    name: str
    kind: str  # "laser" | "sonar" | "proximity"
    angles_rad: np.ndarray
    max_range_m: float
    noise_std_m: float = 0.0


@dataclass(frozen=True)
class RobotInfo:
    """What a robot knows about itself: its id, body, limits and sensors.

    ``known_map`` is a map the scenario *gives* the robot (e.g. for MCL): prior knowledge,
    the same kind of thing a real robot loads from disk, never the simulator's live state.
    """

    robot_id: int
    team_size: int
    radius_m: float
    kinematics: str  # "unicycle" | "holonomic_step"
    max_v_mps: float
    max_omega_radps: float
    step_length_m: float
    dt_s: float
    sensors: dict[str, SensorInfo] = field(default_factory=dict)
    known_map: Any = None
    extras: dict[str, Any] = field(default_factory=dict)


@runtime_checkable
class Controller(Protocol):
    """One robot's brain.

    ``step`` turns the robot's observation into an action and outgoing messages.
    ``log()`` returns small per-robot values the recorder may keep (optional; may be {}).
    """

    Params: ClassVar[type[BaseModel]]

    def __init__(self, params: BaseModel, rng: np.random.Generator, info: RobotInfo) -> None: ...

    def step(self, obs: Observation) -> tuple[Action, list[Message]]: ...

    def log(self) -> dict[str, Any]: ...


@runtime_checkable
class BatchedController(Protocol):
    """A brain that steps every robot running it in one call, row by row.

    Built once for the group with one ``Generator`` per robot row (``rngs``) and their
    :class:`RobotInfo` s. ``range_sensor`` names the sensor whose ranges go into
    :class:`BatchObservation`. Batched brains take no radio (swarm behaviours).
    """

    Params: ClassVar[type[BaseModel]]
    batched: ClassVar[bool]
    range_sensor: str

    def __init__(self, params: BaseModel, rngs: list[np.random.Generator], infos: list[RobotInfo]) -> None: ...

    def step_batch(self, obs: BatchObservation) -> BatchAction: ...
