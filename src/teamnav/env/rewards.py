"""Task rewards for environments, found by name like controllers (:func:`register`, :func:`names`).

A reward scores; it never steers (DESIGN: metrics may read the truth to score). It may read
the simulation's truth (true poses, stall flags, the events that fired), and it returns one
number per agent per step. An environment's reward is the sum of the terms its ``reward``
setting selects, each with its own parameters and ``weight``; the per-term values of a step
are in the agents' ``info["reward_terms"]``.

Built-in terms:

``progress``
    Metres gained towards a goal this step: the decrease of the true straight-line distance
    from the robot's centre to ``goal`` (a place of the scenario, by name) or ``goal_xy``.
    Default goal: the place named ``goal``.
``collision``
    ``-1`` for every step the robot's commanded motion was blocked (by a wall or a robot):
    the simulator's stall flag, the bumper a brain also sees.
``delivery``
    ``+1`` for every unit of the trail task delivered: the ``drop`` event
    (``given_resource``) firing for a robot that fired ``pick_up`` (``took_resource``) since
    its last drop, the rule by which the trail metrics count deliveries.
``localization``
    ``-error`` [m]: the distance from the robot's true position to its believed one, the
    pose the agent reported through ``RobotPort.report_pose`` or, until it does, its
    odometry drawn from its true start pose (as the figures draw believed paths).

Default when neither the scenario's ``env.reward`` nor the constructor names any: ``collision``,
plus ``delivery`` when a place fires ``given_resource`` and ``progress`` when a place is named
``goal``.

A term of your own: subclass :class:`Reward` (a pydantic ``Params`` with a ``weight``, ``reset``
and ``__call__`` returning an ``(n_agents,)`` array) and :func:`register` it.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from teamnav.experiments.errors import Problem, ScenarioError, from_validation_error

__all__ = ["Collision", "Delivery", "Localization", "Progress", "Reward", "RewardContext", "StepView", "build_terms",
           "default_terms", "names", "register"]


class RewardParams(BaseModel):
    """Parameters every term takes: ``weight`` multiplies it."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    weight: float = Field(1.0, ge=-1e6, le=1e6)


@dataclass(frozen=True)
class RewardContext:
    """What a term knows for a whole episode setup: the scenario and which robots are agents."""

    scenario: Any
    agent_ids: np.ndarray
    file: str = "<code>"


@dataclass
class StepView:
    """One step as rewards see it: the simulation (truth), the agents' ids, this step's events
    per agent (the ``events`` of their observations) and their ports (poses they reported)."""

    sim: Any
    agent_ids: np.ndarray
    events: list[tuple[str, ...]]
    ports: list[Any]

    @property
    def estimates(self) -> list[np.ndarray | None]:
        """Per agent, the world pose it last reported (``RobotPort.report_pose``) or None."""
        return [p._estimate for p in self.ports]


class Reward:
    """A reward term (see the module docstring)."""

    Params: ClassVar[type[BaseModel]] = RewardParams

    def __init__(self, params: BaseModel, ctx: RewardContext) -> None:
        self.params = params
        self.ctx = ctx
        self.weight = float(params.weight)

    def reset(self, view: StepView) -> None:
        """Start of an episode (the observation of step 0)."""

    def __call__(self, view: StepView) -> np.ndarray:  # pragma: no cover - interface
        raise NotImplementedError


_REGISTRY: dict[str, type[Reward]] = {}


def register(name: str, cls: type[Reward]) -> None:
    """Make reward term ``cls`` available as ``name`` (a second registration raises)."""
    if name in _REGISTRY:
        raise ValueError(f"reward {name!r} is already registered ({_REGISTRY[name].__name__})")
    if not (isinstance(cls, type) and issubclass(cls, Reward)):
        raise ValueError(f"reward {name!r} must be a subclass of teamnav.env.rewards.Reward, got {cls!r}")
    _REGISTRY[name] = cls


def names() -> list[str]:
    """Registered reward names, sorted."""
    return sorted(_REGISTRY)


# ---------------------------------------------------------------------------- built-in terms
class Progress(Reward):
    class Params(RewardParams):
        goal: str | None = None
        goal_xy: tuple[float, float] | None = None

    def __init__(self, params, ctx) -> None:
        super().__init__(params, ctx)
        places = {p.name: p for p in ctx.scenario.places}
        if params.goal is not None and params.goal_xy is not None:
            raise ScenarioError.one(ctx.file, "env.reward.progress", "give goal (a place) or goal_xy, not both")
        if params.goal_xy is not None:
            self.goal = np.asarray(params.goal_xy, dtype=np.float64)
        else:
            name = params.goal if params.goal is not None else "goal"
            if name not in places:
                known = ", ".join(places) or "none"
                raise ScenarioError.one(ctx.file, "env.reward.progress.goal",
                                        f"expected a place of the scenario (places: {known}) or give goal_xy: [x, y]",
                                        repr(name))
            self.goal = np.array([places[name].x_m, places[name].y_m], dtype=np.float64)
        self._d = np.zeros(len(ctx.agent_ids))

    def _dist(self, view: StepView) -> np.ndarray:
        s = view.sim.state
        ids = view.agent_ids
        return np.hypot(s.x_m[ids] - self.goal[0], s.y_m[ids] - self.goal[1])

    def reset(self, view):
        self._d = self._dist(view)

    def __call__(self, view):
        d = self._dist(view)
        out = (self._d - d) * self.weight
        self._d = d
        return out


class Collision(Reward):
    def __init__(self, params, ctx) -> None:
        super().__init__(params, ctx)
        ids = ctx.agent_ids
        lo, hi = int(ids[0]), int(ids[-1])
        self._index = slice(lo, hi + 1) if hi - lo + 1 == len(ids) else ids  # a view for consecutive robots
        self._few = len(ids) <= 16
        self._hit = 0.0 - self.weight  # 0.0 - ...: no -0.0

    def __call__(self, view):
        stalled = view.sim.state.stalled[self._index]
        if self._few:  # a few agents: a Python pass costs less than numpy's two scalar operations (same values)
            hit = self._hit
            return np.array([hit if s else 0.0 for s in stalled.tolist()])
        return 0.0 - self.weight * stalled


class Delivery(Reward):
    class Params(RewardParams):
        pick_up: str = "took_resource"
        drop: str = "given_resource"

    def reset(self, view):
        self._loaded = np.zeros(len(view.agent_ids), dtype=bool)

    def __call__(self, view):
        out = np.zeros(len(view.agent_ids))
        pick, drop = self.params.pick_up, self.params.drop
        for j, ev in enumerate(view.events):
            if not ev:
                continue
            for e in ev:  # in the places' order, as the event log
                if e == pick:
                    self._loaded[j] = True
                elif e == drop:
                    if self._loaded[j]:
                        out[j] += self.weight
                    self._loaded[j] = False
        return out


class Localization(Reward):
    def reset(self, view):
        s = view.sim.state
        ids = view.agent_ids
        odom = view.sim.odometry.pose[ids]
        th = s.theta_rad[ids] - odom[:, 2]
        c, si = np.cos(th), np.sin(th)
        self._rot = (c, si)
        self._t = np.stack([s.x_m[ids] - (c * odom[:, 0] - si * odom[:, 1]),
                            s.y_m[ids] - (si * odom[:, 0] + c * odom[:, 1])], axis=1)

    def __call__(self, view):
        s = view.sim.state
        ids = view.agent_ids
        odom = view.sim.odometry.pose[ids]
        c, si = self._rot
        bx = c * odom[:, 0] - si * odom[:, 1] + self._t[:, 0]
        by = si * odom[:, 0] + c * odom[:, 1] + self._t[:, 1]
        for j, est in enumerate(view.estimates):
            if est is not None:
                bx[j], by[j] = est[0], est[1]
        return np.hypot(bx - s.x_m[ids], by - s.y_m[ids]) * -self.weight


register("progress", Progress)
register("collision", Collision)
register("delivery", Delivery)
register("localization", Localization)


# ---------------------------------------------------------------------------- building
def default_terms(scenario) -> dict[str, dict[str, Any]]:
    """The terms used when none is selected (see the module docstring)."""
    terms: dict[str, dict[str, Any]] = {"collision": {}}
    if any(p.event == "given_resource" for p in scenario.places):
        terms["delivery"] = {}
    if any(p.name == "goal" for p in scenario.places):
        terms["progress"] = {}
    return terms


def build_terms(terms: dict[str, dict[str, Any]], ctx: RewardContext) -> list[tuple[str, Reward]]:
    """Instantiate the terms ``{name: params}``; unknown names and bad parameters are a
    :class:`ScenarioError` naming ``env.reward.NAME``."""
    out = []
    problems = []
    for name, raw in terms.items():
        cls = _REGISTRY.get(name)
        if cls is None:
            close = difflib.get_close_matches(str(name), _REGISTRY, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            problems.append(Problem("env.reward", f"unknown reward {name!r}{hint} (known: {', '.join(names())})"))
            continue
        try:
            params = cls.Params.model_validate(dict(raw or {}))
        except ValidationError as exc:
            problems.extend(from_validation_error(exc, ctx.file, raw, model=cls.Params, prefix=f"env.reward.{name}").problems)
            continue
        out.append((name, cls(params, ctx)))
    if problems:
        raise ScenarioError(ctx.file, problems)
    return out

