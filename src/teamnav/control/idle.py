"""A brain that never moves: a baseline and a placeholder for passive robots."""

from __future__ import annotations

from typing import Any

import numpy as np

from teamnav.control.protocol import NoParams, RobotInfo
from teamnav.control.types import Action, Message, Observation


class Idle:
    """Stands still, sends nothing."""

    Params = NoParams

    def __init__(self, params: NoParams, rng: np.random.Generator, info: RobotInfo) -> None:
        self.info = info

    def step(self, obs: Observation) -> tuple[Action, list[Message]]:
        return Action.stop(), []

    def log(self) -> dict[str, Any]:
        return {}
