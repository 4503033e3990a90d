"""Conformance check for registered brains, after Gymnasium's ``check_env`` (STYLE habit 12).

:func:`check_brain` builds a registered controller twice from its default parameters and two
``Generator`` s of the same seed, feeds both the same synthetic observations (random scans,
zero odometry, random stall flags, made here from a :class:`RobotInfo`, never from a
simulator) and checks that

- ``Params`` is a pydantic model that forbids unknown keys and builds with no arguments, or
  from the class's example ``check_params`` dict when a field is required (a route's waypoints);
- a brain that declares ``needs_map = True`` (prior map knowledge, e.g. MCL) gets a walled
  10 m x 8 m room with a pillar as ``RobotInfo.known_map``;
- per-robot brains satisfy :class:`Controller`, return ``(Action, list of Message)`` with
  finite numbers, and ``log()`` returns a dict;
- batched brains satisfy :class:`BatchedController`, name a ``range_sensor`` the robots carry,
  and return a :class:`BatchAction` of finite float arrays of shape (n,);
- the two copies give identical outputs at every step (same seed, same behaviour).

A failed check raises :class:`BrainCheckError` naming the controller, the step and the rule.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from pydantic import BaseModel

from teamnav.control import registry
from teamnav.control.protocol import BatchedController, Controller, RobotInfo, SensorInfo
from teamnav.control.types import Action, BatchAction, BatchObservation, Message, Observation, RangeScan


class BrainCheckError(AssertionError):
    """A controller broke the brain contract."""


def synthetic_infos(n_robots: int, dt_s: float = 0.1) -> list[RobotInfo]:
    """RobotInfos of ``n_robots`` unicycle robots with a 180-beam 10 m laser and 7 proximity rays."""
    laser = SensorInfo("laser", "laser", np.linspace(-np.pi / 2, np.pi / 2, 180), 10.0, 0.01)
    prox = SensorInfo("proximity", "proximity",
                      np.radians([-40.0, -20.0, 0.0, 20.0, 40.0, 160.0, 200.0]), 0.14, 0.0)
    return [
        RobotInfo(robot_id=i, team_size=n_robots, radius_m=0.2, kinematics="unicycle", max_v_mps=0.5,
                  max_omega_radps=math.radians(90.0), step_length_m=0.1, dt_s=dt_s,
                  sensors={"laser": laser, "proximity": prox})
        for i in range(n_robots)
    ]


def _random_ranges(rng: np.random.Generator, shape: tuple[int, ...], max_range_m: float) -> np.ndarray:
    """Ranges in (0, max]: uniform, a quarter of them "no return" (= max), some very short."""
    r = rng.uniform(0.02 * max_range_m, max_range_m, size=shape)
    r[rng.random(shape) < 0.25] = max_range_m
    r[rng.random(shape) < 0.05] = 0.01 * max_range_m
    return r


def synthetic_observation(info: RobotInfo, step: int, rng: np.random.Generator) -> Observation:
    """A random observation of the robot described by ``info`` at ``step`` (zero odometry)."""
    scans = {
        name: RangeScan(_random_ranges(rng, s.angles_rad.shape, s.max_range_m), s.angles_rad.copy(), s.max_range_m)
        for name, s in info.sensors.items()
    }
    return Observation(robot_id=info.robot_id, step=step, time_s=step * info.dt_s, odom_pose=np.zeros(3),
                       odom_delta=np.zeros(3), scans=scans, stalled=bool(rng.random() < 0.1))


def _same(a: Any, b: Any) -> bool:
    """Exact equality that also walks arrays, dataclasses and containers (for message bodies)."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and a.shape == b.shape and bool(
            np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        return type(a) is type(b) and all(
            _same(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a))
    if isinstance(a, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    return bool(a == b)


def _fail(name: str, what: str) -> BrainCheckError:
    return BrainCheckError(f"controller {name!r}: {what}")


def _check_params(name: str, cls: Any) -> BaseModel:
    params_cls = getattr(cls, "Params", None)
    if not (isinstance(params_cls, type) and issubclass(params_cls, BaseModel)):
        raise _fail(name, f"Params must be a pydantic BaseModel subclass, got {params_cls!r}")
    if params_cls.model_config.get("extra") != "forbid":
        raise _fail(name, "Params must forbid unknown keys (model_config extra='forbid')")
    example = getattr(cls, "check_params", None)
    try:
        return params_cls(**example) if example is not None else params_cls()
    except Exception as exc:  # noqa: BLE001 - reported as a contract failure
        how = f"Params(**check_params) with {example!r}" if example is not None else "Params() from defaults"
        raise _fail(name, f"{how} must build (give required fields example values in a class attribute "
                          f"check_params), raised {exc!r}") from exc


def check_map():
    """The map a ``needs_map`` brain is checked with: a walled 10 m x 8 m room with a pillar."""
    from teamnav.world.generators import MapBuilder

    return MapBuilder(10.0, 8.0, 0.1).border(0.2).rect(6.0, 3.0, 7.0, 5.0).build("check:room")


def _check_action(name: str, step: int, out: Any) -> tuple[Action, list[Message]]:
    if not (isinstance(out, tuple) and len(out) == 2):
        raise _fail(name, f"step {step}: step() must return (Action, list of Message), got {out!r}")
    action, outbox = out
    if not isinstance(action, Action):
        raise _fail(name, f"step {step}: first return value must be an Action, got {type(action).__name__}")
    for field in ("v_mps", "omega_radps"):
        value = getattr(action, field)
        if not (isinstance(value, float) and math.isfinite(value)):
            raise _fail(name, f"step {step}: Action.{field} must be a finite float, got {value!r}")
    if action.direction_rad is not None and not math.isfinite(action.direction_rad):
        raise _fail(name, f"step {step}: Action.direction_rad must be None or finite, got {action.direction_rad!r}")
    if not (isinstance(outbox, list) and all(isinstance(m, Message) for m in outbox)):
        raise _fail(name, f"step {step}: second return value must be a list of Message, got {outbox!r}")
    return action, outbox


def _check_batch_action(name: str, step: int, out: Any, n: int) -> BatchAction:
    if not isinstance(out, BatchAction):
        raise _fail(name, f"step {step}: step_batch() must return a BatchAction, got {type(out).__name__}")
    for field in ("v_mps", "omega_radps"):
        a = getattr(out, field)
        if not (isinstance(a, np.ndarray) and a.shape == (n,) and a.dtype.kind == "f"):
            got = f"{a.dtype} {a.shape}" if isinstance(a, np.ndarray) else type(a).__name__
            raise _fail(name, f"step {step}: BatchAction.{field} must be a float ndarray of shape ({n},), got {got}")
        if not np.all(np.isfinite(a)):
            raise _fail(name, f"step {step}: BatchAction.{field} must be finite, got {a}")
    return out


def check_brain(name: str, *, seed: int = 0, n_steps: int = 50, n_robots: int = 4) -> None:
    """Check that the controller registered as ``name`` keeps the brain contract.

    Parameters
    ----------
    name : str
        A registered controller name (``teamnav.control.registry.names()``).
    seed : int, default 0
        Seed of the two identical Generators and of the synthetic observations.
    n_steps : int, default 50
        Observations fed to each copy.
    n_robots : int, default 4
        Rows for a batched controller (a per-robot one is checked as robot 0 of this team).

    Raises
    ------
    KeyError
        ``name`` is not registered (with a "did you mean" hint).
    ValueError
        A parameter is out of range.
    BrainCheckError
        The controller broke a rule; the message names it.

    Examples
    --------
    >>> check_brain("idle-v1")
    """
    if not isinstance(n_steps, int) or n_steps < 1:
        raise ValueError(f"n_steps must be an int >= 1, got {n_steps!r}")
    if not isinstance(n_robots, int) or n_robots < 1:
        raise ValueError(f"n_robots must be an int >= 1, got {n_robots!r}")
    if not isinstance(seed, int) or seed < 0:
        raise ValueError(f"seed must be an int >= 0, got {seed!r}")
    cls = registry.lookup(name)
    params = _check_params(name, cls)
    infos = synthetic_infos(n_robots)
    if getattr(cls, "needs_map", False):
        grid = check_map()
        infos = [dataclasses.replace(info, known_map=grid) for info in infos]
    obs_rng = np.random.default_rng([seed, 1])

    if getattr(cls, "batched", False):
        copies = [cls(params, [np.random.default_rng([seed, i]) for i in range(n_robots)], infos) for _ in range(2)]
        if not isinstance(copies[0], BatchedController):
            raise _fail(name, "a batched controller must satisfy the BatchedController protocol")
        sensor = getattr(copies[0], "range_sensor", None)
        if sensor not in infos[0].sensors:
            raise _fail(name, f"range_sensor must name a sensor the robots carry ({sorted(infos[0].sensors)}), got {sensor!r}")
        s = infos[0].sensors[sensor]
        for step in range(n_steps):
            obs = BatchObservation(
                robot_ids=np.arange(n_robots, dtype=np.int64), step=step, time_s=step * infos[0].dt_s,
                odom_pose=np.zeros((n_robots, 3)), ranges_m=_random_ranges(obs_rng, (n_robots, s.angles_rad.size), s.max_range_m),
                angles_rad=s.angles_rad.copy(), max_range_m=s.max_range_m, stalled=obs_rng.random(n_robots) < 0.1,
            )
            a = _check_batch_action(name, step, copies[0].step_batch(obs), n_robots)
            b = _check_batch_action(name, step, copies[1].step_batch(obs), n_robots)
            if not (np.array_equal(a.v_mps, b.v_mps) and np.array_equal(a.omega_radps, b.omega_radps)):
                raise _fail(name, f"step {step}: two copies built with the same seed disagree: {a} vs {b}")
        return

    copies = [cls(params, np.random.default_rng([seed, 0]), infos[0]) for _ in range(2)]
    if not isinstance(copies[0], Controller):
        raise _fail(name, "a per-robot controller must satisfy the Controller protocol (step, log, Params)")
    for step in range(n_steps):
        obs = synthetic_observation(infos[0], step, obs_rng)
        a = _check_action(name, step, copies[0].step(obs))
        b = _check_action(name, step, copies[1].step(obs))
        if not _same(a, b):
            raise _fail(name, f"step {step}: two copies built with the same seed disagree: {a} vs {b}")
        log = copies[0].log()
        if not isinstance(log, dict):
            raise _fail(name, f"step {step}: log() must return a dict, got {type(log).__name__}")
