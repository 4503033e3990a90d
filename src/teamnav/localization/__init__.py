"""Collaborative multi-robot Monte Carlo localization (Fox, Burgard, Kruppa & Thrun 2000).

The belief side of the truth/belief rule: everything here sees only a robot's own map,
sensor datasheet, odometry, ranges, detections and messages; nothing imports the simulator.

- :class:`MCL` (§3.1): the per-robot particle filter — odometry motion model, beam model
  (laser, sonar cones) or likelihood field, low-variance resampling, random samples or
  augmented MCL, KLD-sampling, estimates;
- :class:`DensityTree` (§3.2): weighted samples as a piecewise-constant density;
- :class:`DetectionModel`, :func:`fit_detection_model` (§4): the learned detection model;
- :class:`BeliefSync`, :class:`SyncMessage` (§2.3, §3.2): synchronising beliefs on detections.
"""

from teamnav.localization.beam_model import BeamModelParams
from teamnav.localization.density_tree import DensityTree
from teamnav.localization.detection_model import DetectionModel, DetectionSamples, fit_detection_model
from teamnav.localization.kld import KLDParams
from teamnav.localization.likelihood_field import LikelihoodFieldParams
from teamnav.localization.mcl import MCL, Estimate, MCLParams, pose_error, sample_error_m
from teamnav.localization.motion import MotionParams
from teamnav.localization.sync import BeliefSync, SightingGate, SyncMessage, SyncParams

__all__ = [
    "BeamModelParams", "BeliefSync", "DensityTree", "DetectionModel", "DetectionSamples", "Estimate",
    "KLDParams", "LikelihoodFieldParams", "MCL", "MCLParams", "MotionParams", "SightingGate", "SyncMessage",
    "SyncParams", "fit_detection_model", "pose_error", "sample_error_m",
]
