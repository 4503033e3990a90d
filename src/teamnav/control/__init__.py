"""The robot's brain: controllers see only their own observations and messages.

Nothing under this package imports ``teamnav.sim``, ``teamnav.experiments``, ``teamnav.viz``
or ``teamnav.cli``, or reads a true pose (enforced by ``tests/test_import_boundary.py``).
"""

from teamnav.control.protocol import BatchedController, Controller, NoParams, RobotInfo, SensorInfo
from teamnav.control.types import (
    Action,
    BatchAction,
    BatchObservation,
    Detection,
    Message,
    Observation,
    RangeScan,
)

__all__ = [
    "Action", "BatchAction", "BatchObservation", "BatchedController", "Controller", "Detection",
    "Message", "NoParams", "Observation", "RangeScan", "RobotInfo", "SensorInfo",
]
