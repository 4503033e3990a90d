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

The ``env:`` section is read here and removed before the rest of the file is validated as a
:class:`~teamnav.experiments.spec.Scenario`. Deviation: ``teamnav run`` and ``teamnav validate``
validate the scenario model, which does not know ``env:`` yet, so a file with an ``env:``
section is for environments only (teamnav.experiments.spec would need an ``env`` field).
Overrides ``env.KEY=VALUE`` set this section like any other field.
"""

from __future__ import annotations

import copy
import os
from pathlib import Path
from typing import Any, Mapping, Sequence, Union

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from teamnav.experiments.errors import Problem, ScenarioError, from_validation_error
from teamnav.experiments.spec import Scenario, apply_overrides, load_scenario, read_yaml

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


def _looks_like_path(s: str) -> bool:
    return s.lower().endswith((".yaml", ".yml")) or "/" in s or os.sep in s or Path(s).exists()


def _split_overrides(overrides) -> tuple[Any, Any]:
    """(scenario overrides, env overrides without their ``env.`` prefix)."""
    if overrides is None:
        return None, None
    if isinstance(overrides, Mapping):
        scn = {k: v for k, v in overrides.items() if not str(k).startswith("env.")}
        env = {str(k)[4:]: v for k, v in overrides.items() if str(k).startswith("env.")}
        return scn or None, env or None
    scn_l, env_l = [], []
    for item in overrides:
        if isinstance(item, str) and item.strip().startswith("env."):
            env_l.append(item.strip()[4:])
        else:
            scn_l.append(item)
    return scn_l or None, env_l or None


def load_env_scenario(
    name_or_path: str | os.PathLike | Scenario,
    *,
    overrides: Mapping[str, Any] | Sequence[str] | None = None,
    seed: int | None = None,
    duration_s: float | None = None,
) -> tuple[Scenario, dict[str, Any], str]:
    """Load a scenario as :func:`~teamnav.experiments.spec.load_scenario` does, keeping its
    ``env:`` section apart.

    Returns
    -------
    scenario : Scenario
        Fully validated (map loaded, controllers checked).
    env : dict
        The raw ``env:`` section with ``env.*`` overrides applied ({} when absent).
    file : str
        The file the scenario came from, for messages.

    Raises
    ------
    ScenarioError
        Anything wrong, naming the file and the field.
    """
    scn_over, env_over = _split_overrides(overrides)
    env_raw: dict[str, Any] = {}
    if isinstance(name_or_path, Scenario):
        scn = load_scenario(name_or_path, overrides=scn_over, seed=seed, duration_s=duration_s)
        file = scn.source
    else:
        text = os.fspath(name_or_path)
        data = None
        try:
            if _looks_like_path(text):
                path = Path(text)
            else:
                from teamnav.experiments import registry as scenarios

                path = scenarios.path(text)
            data = read_yaml(path.read_text(encoding="utf-8"))
        except Exception:  # noqa: BLE001 - load_scenario below reports the problem in its own words
            data = None
        if not isinstance(data, dict) or "env" not in data:
            scn = load_scenario(name_or_path, overrides=scn_over, seed=seed, duration_s=duration_s)
            file = scn.source
        else:
            file = str(path)
            section = data.pop("env")
            if section is not None and not isinstance(section, dict):
                raise ScenarioError.one(file, "env", "expected a mapping of environment settings", type(section).__name__)
            env_raw = dict(section or {})
            data.setdefault("name", path.stem if path.stem[:1].isalnum() else "scenario")
            data = copy.deepcopy(data)
            notes = apply_overrides(data, scn_over, file)
            if seed is not None:
                data["seed"] = seed
                notes["seed"] = "from seed"
            if duration_s is not None:
                data["duration_s"] = duration_s
                notes["duration_s"] = "from duration_s"
            spec = data.get("map")
            if isinstance(spec, dict) and isinstance(spec.get("file"), str) and spec["file"]:
                p = Path(os.path.expanduser(spec["file"]))
                spec["file"] = str(p if p.is_absolute() else (path.resolve().parent / p))
            try:
                base = Scenario.model_validate(data)
            except ValidationError as exc:
                raise from_validation_error(exc, file, data, model=Scenario, notes=notes) from None
            base._source = file
            scn = load_scenario(base)  # the remaining checks: controllers' parameters, the map
    if env_over:
        holder = {"env": env_raw}
        apply_overrides(holder["env"], env_over, file)
        env_raw = holder["env"]
    return scn, env_raw, file


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
