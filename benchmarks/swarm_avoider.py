"""The per-robot Python brain of the swarm benchmark: Enki's Python ``Avoider`` rule, in teamnav.

``benchmarks/peers/enki_peer.py`` steps Enki's Thymio II robots with a Python ``controlStep``
that reads 7 proximity distances and turns away from the nearer front side (else straight on).
This is that rule as a teamnav per-robot :class:`~teamnav.control.protocol.Controller`, loaded
the way every outside brain is (``benchmarks.swarm_avoider:Avoider``, ``--controller
module:Class``): the benchmark's per-robot Python row then compares the engine's per-robot path
with Enki's, brain for brain.

teamnav's proximity sensors sit at -40, -20, 0, 20, 40, 160, 200 degrees (``ProximityConfig``):
rays 3 and 4 look front-left, 0 and 1 front-right, 2 ahead. Enki's speeds (cm/s per wheel):
15/15 straight, ±10 turning on the spot with the Thymio's 9.4 cm wheel base, i.e. 0.15 m/s and
2.13 rad/s. The threshold is Enki's 8 cm.
"""

from __future__ import annotations

from teamnav.control.protocol import NoParams
from teamnav.control.types import Action

STRAIGHT = Action(0.15, 0.0)
TURN_LEFT = Action(0.0, 2.13)
TURN_RIGHT = Action(0.0, -2.13)
NEAR_M = 0.08


class Avoider:
    """Straight ahead; turn on the spot away from the nearer front side when one is within 8 cm."""

    Params = NoParams

    def __init__(self, params, rng, info) -> None:
        self.sensor = "proximity"

    def step(self, obs):
        d = obs.scans[self.sensor].ranges_m.tolist()
        right = min(d[0], d[1])
        left = min(d[3], d[4])
        if min(left, d[2], right) < NEAR_M:
            return (TURN_RIGHT if left < right else TURN_LEFT), []
        return STRAIGHT, []

    def log(self) -> dict:
        return {}
