"""What makes a scenario an environment: which robots are agents, the reward, what they observe.

Settings come from an ``env:`` section of the scenario file and from the environment's
constructor (which wins, key by key)::

    env:
      agents_from: [ant, bee]          # groups whose robots are agents (default: every group)
      reward: {delivery: {}, collision: {weight: 0.1}}   # or a name, or a list of names
      terminate_on: [at_goal]          # an agent's episode ends when one of these events fires for it
      observe_truth: false             # true: observations add `privileged_true_pose`
      max_inbox: 8                     # rows of the padded inbox array
      max_detections: 8                # rows of the padded detections array

The scenario model keeps the section as it is (:attr:`Scenario.env`; ``teamnav run`` and
``teamnav validate`` accept and ignore it) and :class:`EnvSpec` validates it here. Overrides
``env.KEY=VALUE`` set this section like any other field.
"""

from __future__ import annotations

import copy
import os
from typing import Any, Mapping, Sequence, Union

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from teamnav.experiments.errors import Problem, ScenarioError, from_validation_error
from teamnav.experiments.spec import Scenario, load_scenario

__all__ = ["EnvSpec", "load_env_scenario"]

RewardSpec = Union[str, tuple[str, ...], dict[str, dict[str, Any]]]


class EnvSpec(BaseModel):
    """The ``env:`` section (see the module docstring)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    agents_from: tuple[Union[str, int], ...] | None = None
    reward: RewardSpec | None = None
    terminate_on: tuple[str, ...] = ()
    observe_truth: bool = False
    max_inbox: int = Field(8, ge=0, le=10_000)
    max_detections: int = Field(8, ge=0, le=10_000)

    @field_validator("agents_from")
    @classmethod
    def _some(cls, v):
        if v is not None and len(v) == 0:
            raise ValueError("expected at least one group name (or leave agents_from out for every group)")
        return v

    def reward_terms(self) -> dict[str, dict[str, Any]]:
        """``reward`` as ``{name: params}`` (None: {})."""
        r = self.reward
        if r is None:
            return {}
        if isinstance(r, str):
            return {r: {}}
        if isinstance(r, tuple):
            return {name: {} for name in r}
        return {k: dict(v or {}) for k, v in r.items()}


def load_env_scenario(
    name_or_path: str | os.PathLike | Scenario,
    *,
    overrides: Mapping[str, Any] | Sequence[str] | None = None,
    seed: int | None = None,
    duration_s: float | None = None,
) -> tuple[Scenario, dict[str, Any], str]:
    """Load a scenario with :func:`~teamnav.experiments.spec.load_scenario` and return its
    ``env:`` section (:attr:`Scenario.env`) beside it.

    Returns
    -------
    scenario : Scenario
        Fully validated (map loaded, controllers checked).
    env : dict
        The ``env:`` section with ``env.*`` overrides applied ({} when absent).
    file : str
        The file the scenario came from, for messages.

    Raises
    ------
    ScenarioError
        Anything wrong, naming the file and the field.
    """
    scn = load_scenario(name_or_path, overrides=overrides, seed=seed, duration_s=duration_s)
    return scn, copy.deepcopy(dict(scn.env or {})), scn.source


def env_spec(raw: Mapping[str, Any], given: Mapping[str, Any], file: str) -> EnvSpec:
    """The scenario's ``env:`` section ``raw`` with the constructor's ``given`` settings on top."""
    data = {**dict(raw), **{k: v for k, v in given.items() if v is not None}}
    try:
        return EnvSpec.model_validate(data)
    except ValidationError as exc:
        raise from_validation_error(exc, file, data, model=EnvSpec, prefix="env") from None


def unknown_group_problem(spec: EnvSpec, scenario: Scenario, file: str) -> None:
    """Raise a ScenarioError when ``agents_from`` names a group the scenario lacks."""
    if spec.agents_from is None:
        return
    names = [g.name for g in scenario.robots]
    bad = []
    for ref in spec.agents_from:
        if isinstance(ref, int) and not isinstance(ref, bool):
            if not 0 <= ref < len(names):
                bad.append(Problem("env.agents_from", f"expected a group index in 0..{len(names) - 1} or a group name", str(ref)))
        elif ref not in names:
            bad.append(Problem("env.agents_from", f"expected one of the scenario's groups ({', '.join(dict.fromkeys(names))})",
                               repr(ref)))
    if bad:
        raise ScenarioError(file, bad)
