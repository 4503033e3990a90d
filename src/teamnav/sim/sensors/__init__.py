"""Sensor models (simulator side): they read the truth and produce what a robot observes.

- :func:`build_range_sensor` / :class:`RangeSensor`: laser, sonar ring and proximity
  sensors ray-cast through the materials they see, optionally stop on other robots' discs
  (:mod:`~teamnav.sim.sensors.robot_hits`), then add the beam-model noise of Fox et al. §2.2.
- :class:`RobotDetector`: teammates within range, field of view and line of sight, with the
  noise models of Fox et al. §4 and Sgorbissa & Arkin §6.1, false negatives and positives.

All of them work on struct-of-arrays poses of every robot at once; results are in each
robot's body frame.
"""

from teamnav.sim.sensors.detector import DetectionArrays, RobotDetector
from teamnav.sim.sensors.range_sensors import (
    RangeSensor,
    apply_beam_noise,
    beam_angles,
    beam_noise_keyed,
    build_range_sensor,
    draw_noise_key,
)
from teamnav.sim.sensors.robot_hits import apply_robot_hits, robot_hits_reference

__all__ = [
    "DetectionArrays",
    "RangeSensor",
    "RobotDetector",
    "apply_beam_noise",
    "apply_robot_hits",
    "beam_angles",
    "beam_noise_keyed",
    "build_range_sensor",
    "draw_noise_key",
    "robot_hits_reference",
]
