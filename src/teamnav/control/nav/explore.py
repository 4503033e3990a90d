"""Random exploration: Navigate with no trail to follow (Vaughan et al.'s initial search).

Vaughan, Støy, Sukhatme & Matarić, *Blazing a trail* §4.1: "the robots initially search the
environment by random exploration: following walls and turning at random at intersections";
*Try to see it my way* §3.4 the same. This brain is :class:`~teamnav.control.nav.navigate.Navigate`
called with no preferred heading every step: sliding-box wall following, a 50 % chance to take
each detected opening with a sharp 90 deg turn, and Panic when an obstacle is critically close.
It sends no messages.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from teamnav.control.nav.navigate import Navigate, NavigateParams
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Action, Message, Observation

__all__ = ["Explore", "ExploreParams"]


class ExploreParams(NavigateParams):
    """:class:`NavigateParams` plus the name of the laser to read."""

    sensor: str = Field("laser", min_length=1)


class Explore:
    """One robot exploring at random (a :class:`~teamnav.control.protocol.Controller`).

    Parameters
    ----------
    params : ExploreParams
    rng : numpy.random.Generator
        The robot's own stream (random turns at openings, Panic's direction).
    info : RobotInfo

    Examples
    --------
    >>> from teamnav.control.check import synthetic_infos, synthetic_observation
    >>> info = synthetic_infos(1)[0]
    >>> brain = Explore(Explore.Params(), np.random.default_rng(0), info)
    >>> action, outbox = brain.step(synthetic_observation(info, 0, np.random.default_rng(1)))
    >>> outbox, brain.log()["mode"] in ("navigate", "advance", "turn", "panic")
    ([], True)
    """

    Params = ExploreParams

    def __init__(self, params: ExploreParams, rng: np.random.Generator, info: RobotInfo) -> None:
        if not isinstance(params, ExploreParams):
            raise ValueError(f"params must be an Explore.Params, got {type(params).__name__}")
        self.params = params
        self.nav = Navigate(params, rng, info, laser=params.sensor)

    def step(self, obs: Observation) -> tuple[Action, list[Message]]:
        """Navigate with no preferred heading; sends nothing."""
        v, w = self.nav.step(obs, None)
        return Action(v, w), []

    def log(self) -> dict[str, Any]:
        """Navigate's mode and the sliding box's state."""
        return {"mode": self.nav.mode, "box": self.nav.box_state}
