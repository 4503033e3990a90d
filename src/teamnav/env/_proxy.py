"""The brain the engine steps for a robot of an environment's agent group.

Every robot of a group that holds an agent gets an :class:`EnvProxy` as its controller (the
engine builds it like any controller: validated ``Params``, the robot's own random stream and
its :class:`~teamnav.control.protocol.RobotInfo`). A proxy either

- *stands in for an agent*: ``step(obs)`` keeps the observation for the environment and
  returns ``Action.stop()``, a placeholder the environment replaces by the agent's action
  before the next motion (:mod:`teamnav.env._engine`); or, for a group whose robots are all
  agents (:class:`AgentProxy`, ``observes_whole_group``) in a run without faults, is not
  stepped at all: the engine builds no per-robot observation, the environment reads the
  group's arrays (``Simulation.observed``) and builds an agent's observation object only
  when :attr:`RobotPort.observation` asks for it, as the engine would have built it; or
- *wraps the scenario's own brain* for a robot of that group that is not an agent (a
  teammate of :class:`~teamnav.env.SingleRobotEnv`'s robot in the same group): that brain is
  built with the same parameters, random stream and ``RobotInfo`` as the engine would build
  it, and every call is passed through, so the teammate behaves bit for bit as in ``teamnav
  run``.

:class:`RobotPort` is what a user of the environment holds for one agent: the observation
object exactly as a brain receives it, outgoing radio messages, values for the recorder's
logs, the ``finished`` flag and the scenario's own brain for that robot.
"""

from __future__ import annotations

import copy
from typing import Any, ClassVar

import numpy as np

from teamnav.control.protocol import NoParams, RobotInfo
from teamnav.control.types import Action, Message, Observation

__all__ = ["AGENT_ENTRY_POINT", "ENTRY_POINT", "AgentProxy", "EnvProxy", "RobotPort"]

#: the controller an agent group is given in the episode's scenario when some of its robots
#: are not agents (their proxies wrap the scenario's brain)
ENTRY_POINT = "teamnav.env._proxy:EnvProxy"
#: ... and when all its robots are agents (no log() to call: the environment records their logs)
AGENT_ENTRY_POINT = "teamnav.env._proxy:AgentProxy"

_STOP = (Action(), [])


class EnvProxy:
    """A robot's brain inside an environment (see the module docstring)."""

    Params: ClassVar[type] = NoParams

    __slots__ = ("rng", "info", "obs", "brain", "port_finished")

    def __init__(self, params: Any, rng: np.random.Generator, info: RobotInfo) -> None:
        self.rng = rng
        self.info = info
        self.obs: Observation | None = None
        self.brain: Any = None  # the wrapped scenario brain, for a robot that is not an agent
        self.port_finished: bool | None = None

    def step(self, obs: Observation):
        if self.brain is not None:
            return self.brain.step(obs)
        self.obs = obs
        return _STOP

    def log(self) -> dict[str, Any]:
        # an agent's log values reach the recorder through the environment, at the step they
        # belong to (after the agent decided); a wrapped brain logs as it would in `teamnav run`
        if self.brain is not None:
            log = getattr(self.brain, "log", None)
            return log() if callable(log) else {}
        return {}

    @property
    def finished(self) -> bool | None:
        """The wrapped brain's ``finished`` flag, or the one the agent's port set (None: no task)."""
        if self.brain is not None:
            return getattr(self.brain, "finished", None)
        return self.port_finished


class RobotPort:
    """One agent's side door: what a brain gets and gives besides ``(v, omega)``.

    Attributes
    ----------
    name : str
        The agent's name.
    robot_id : int
        Its robot's id in the simulation.
    info : RobotInfo
        What the robot knows about itself (as a brain is built with).
    """

    def __init__(self, name: str, robot_id: int, core: Any) -> None:
        self.name = name
        self.robot_id = int(robot_id)
        self._core = core
        self._outbox: list[Message] = []
        self._log: dict[str, Any] | None = None
        self._last_log: dict[str, Any] | None = None
        self._estimate: np.ndarray | None = None

    # ---------------------------------------------------------------- reading
    @property
    def _proxy(self) -> EnvProxy:
        return self._core.proxy(self.robot_id)

    @property
    def info(self) -> RobotInfo:
        return self._proxy.info

    @property
    def observation(self) -> Observation | None:
        """This step's :class:`~teamnav.control.types.Observation`, the object a built-in brain
        would be handed (scans, odometry, detections, inbox with message bodies, events): the
        engine's, or built from the same arrays as the engine builds it (one object per step)."""
        return self._core.observation(self.robot_id)

    # ---------------------------------------------------------------- writing
    def send(self, messages) -> None:
        """Radio messages to send with this step's action (as the second item a brain's
        ``step`` returns): sent when :meth:`step` is called, heard from where the robot is
        now, delivered in the observation of the next step."""
        for m in messages:
            if not isinstance(m, Message):
                raise ValueError(f"agent {self.name!r}: send() takes teamnav.control.Message objects, got {type(m).__name__}")
            self._outbox.append(m)
        self._core._ports_dirty = True  # the next step puts it on the radio

    def log(self, values: dict[str, Any]) -> None:
        """Values the recorder keeps for this robot at this step, as a brain's ``log()`` returns
        them (a ``"layers"`` entry draws in replays). Recorded with the observation's step, on
        the steps the scenario's ``record_every`` samples; at the episode's last step, the
        values given after it (else the latest) are recorded when the run folder is written."""
        if not isinstance(values, dict):
            raise ValueError(f"agent {self.name!r}: log() takes a dict, got {type(values).__name__}")
        self._log = values
        self._core._ports_dirty = True

    @property
    def finished(self) -> bool | None:
        """The agent's own "my task is done" flag, as a brain's ``finished`` attribute: with the
        scenario's ``stop_when_finished``, the episode terminates once every robot that has one
        says True. None (the default) means this robot has no such task."""
        return self._proxy.port_finished

    @finished.setter
    def finished(self, value: bool | None) -> None:
        self._proxy.port_finished = None if value is None else bool(value)

    def report_pose(self, pose_xyt) -> None:
        """The agent's estimate of its own pose in the world frame ``(x [m], y [m], theta [rad])``,
        scored by the ``localization`` reward (until then it scores its odometry)."""
        p = np.asarray(pose_xyt, dtype=np.float64).reshape(-1)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise ValueError(f"agent {self.name!r}: report_pose() takes a finite (x, y, theta), got {pose_xyt!r}")
        self._estimate = p

    # ---------------------------------------------------------------- the scenario's brain
    def scenario_controller(self) -> Any:
        """A fresh instance of the controller the scenario gives this robot, built as the engine
        builds it: same validated parameters, same ``RobotInfo`` and a copy of the same random
        stream (so calling its ``step`` on :attr:`observation` each step reproduces the built-in
        brain). Call it right after ``reset``: the stream copy is the episode's initial one.
        """
        return self._core.build_scenario_brain(self.robot_id, copy.deepcopy(self._proxy.rng))

    # ---------------------------------------------------------------- internals
    def _take(self) -> tuple[list[Message], dict[str, Any] | None]:
        out, log = self._outbox, self._log
        self._outbox, self._log = [], None
        return out, log

    def _clear(self) -> None:
        self._outbox, self._log, self._last_log, self._estimate = [], None, None, None


class AgentProxy:
    """:class:`EnvProxy` for a group whose robots are all agents: no ``log()`` (so the engine
    skips asking), nothing to wrap."""

    Params: ClassVar[type] = NoParams

    __slots__ = ("rng", "info", "obs", "port_finished")

    brain = None
    #: the engine hands this group no per-robot observation in a run without faults (its
    #: ``step`` is not called); the environment reads ``Simulation.observed`` and builds an
    #: agent's observation object only when asked (``RobotPort.observation``)
    observes_whole_group = True

    def __init__(self, params: Any, rng: np.random.Generator, info: RobotInfo) -> None:
        self.rng = rng
        self.info = info
        self.obs: Observation | None = None
        self.port_finished: bool | None = None

    def step(self, obs: Observation):
        self.obs = obs
        return _STOP

    @property
    def finished(self) -> bool | None:
        """The flag the agent's port set (None: no task)."""
        return self.port_finished
