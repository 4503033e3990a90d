"""SE(2) and similarity transforms, angles, frames from mutual bearings."""

from teamnav.geometry.angles import angle_diff, mean_angle, wrap_angle
from teamnav.geometry.bearings import relative_frame_from_bearings, transform_goal
from teamnav.geometry.se2 import compose, from_matrix, identity, inverse, relative, to_matrix, transform_points
from teamnav.geometry.similarity import Similarity, similarity_from_two_pairs

__all__ = [
    "wrap_angle",
    "angle_diff",
    "mean_angle",
    "compose",
    "inverse",
    "relative",
    "identity",
    "transform_points",
    "to_matrix",
    "from_matrix",
    "Similarity",
    "similarity_from_two_pairs",
    "relative_frame_from_bearings",
    "transform_goal",
]
