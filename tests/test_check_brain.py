"""check_brain over every registered controller, and proof that it catches broken brains."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict

from teamnav.control import registry
from teamnav.control.check import BrainCheckError, check_brain
from teamnav.control.protocol import NoParams
from teamnav.control.types import Action, BatchAction


@pytest.mark.parametrize("name", registry.names())
def test_every_registered_controller_conforms(name):
    check_brain(name, seed=3, n_steps=30)


class _Nondeterministic:
    """Uses a fresh OS-seeded generator: two same-seed copies disagree."""

    Params = NoParams

    def __init__(self, params, rng, info):
        self._rng = np.random.default_rng()

    def step(self, obs):
        return Action(float(self._rng.random()), 0.0), []

    def log(self):
        return {}


class _WrongTypes(_Nondeterministic):
    def step(self, obs):
        return (0.1, 0.0), []


class _IntSpeed(_Nondeterministic):
    def step(self, obs):
        return Action(1, 0.0), []


class _LooseParams(BaseModel):
    model_config = ConfigDict(extra="allow")


class _Loose(_Nondeterministic):
    Params = _LooseParams


class _BadBatch:
    Params = NoParams
    batched = True

    def __init__(self, params, rngs, infos):
        self.range_sensor = "laser"
        self.n = len(infos)

    def step_batch(self, obs):
        return BatchAction(np.zeros(self.n + 1), np.zeros(self.n + 1))


class _UnknownSensor(_BadBatch):
    def __init__(self, params, rngs, infos):
        super().__init__(params, rngs, infos)
        self.range_sensor = "sonar"


@pytest.fixture
def fake(monkeypatch):
    """Register a class under a temporary name."""

    def add(cls):
        name = f"fake-{cls.__name__.lower()}-v1"
        monkeypatch.setitem(registry._REGISTRY, name, f"{__name__}:{cls.__name__}")
        return name

    return add


@pytest.mark.parametrize(
    ("cls", "message"),
    [
        (_Nondeterministic, "disagree"),
        (_WrongTypes, "must be an Action"),
        (_IntSpeed, "finite float"),
        (_Loose, "forbid unknown keys"),
        (_BadBatch, "shape (4,)"),
        (_UnknownSensor, "range_sensor"),
    ],
)
def test_broken_brains_are_caught(fake, cls, message):
    with pytest.raises(BrainCheckError, match=message.replace("(", r"\(").replace(")", r"\)")):
        check_brain(fake(cls))


def test_unknown_name_and_bad_arguments():
    with pytest.raises(KeyError, match="did you mean"):
        check_brain("wander-v2")
    with pytest.raises(ValueError, match="n_steps must be an int >= 1, got 0"):
        check_brain("idle-v1", n_steps=0)
    with pytest.raises(ValueError, match="n_robots"):
        check_brain("idle-v1", n_robots=-1)
