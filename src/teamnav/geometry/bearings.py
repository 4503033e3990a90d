"""Relative frames from mutual bearings.

Sgorbissa & Arkin, "Local navigation strategies for a team of robots", §3.1 (Fig. 4):
two robots that see each other share the directions in which each sees the other; with
the distance between them, each can compute the other's frame relative to its own, with no
global frame and no estimate of the other's heading.

Notation. The paper writes ``α21`` for the direction in which R1 sees R2 (measured in R1's
frame F1) and ``α12`` for the direction in which R2 sees R1 (in F2), and states
``θ21 = 180° + α21 - α12`` for "the orientation of R2 with respect to F1". To avoid the
subscript confusion, this module names the arguments by what they measure:

- ``bearing_2_in_1_rad``: bearing of R2 measured by R1 in F1 (the paper's ``α21``);
- ``bearing_1_in_2_rad``: bearing of R1 measured by R2 in F2 (the paper's ``α12``).

Derivation. Put R1 at the origin of F1, heading 0. R2 is at ``d (cos β1, sin β1)`` with
``β1 = bearing_2_in_1``; let ``θ`` be R2's heading in F1. The direction from R2 to R1 is
``β1 + π`` in F1, i.e. ``β1 + π - θ`` in F2, and that is ``β2 = bearing_1_in_2``.
Hence ``θ = π + β1 - β2``: the rotation of F2 relative to F1 (F2's x axis in F1), which is
exactly the paper's ``θ21 = 180 + α21 - α12``. The result is the SE(2) pose of F2 in F1,
equal to ``se2.relative(pose_1, pose_2)`` for true poses in any common frame (the tests
check this).
"""

from __future__ import annotations

import numpy as np

from teamnav.geometry.angles import wrap_angle
from teamnav.geometry.se2 import transform_points

__all__ = ["relative_frame_from_bearings", "transform_goal"]


def relative_frame_from_bearings(bearing_2_in_1_rad, bearing_1_in_2_rad, distance_m) -> np.ndarray:
    """Pose of R2's frame in R1's frame from the two mutual bearings and the distance.

    Sgorbissa & Arkin §3.1: ``θ21 = 180° + α21 - α12`` (see the module docstring for the
    notation and the derivation).

    Parameters
    ----------
    bearing_2_in_1_rad : float or array_like
        Direction [rad] in which R1 sees R2, in R1's frame (paper: ``α21``).
    bearing_1_in_2_rad : float or array_like
        Direction [rad] in which R2 sees R1, in R2's frame (paper: ``α12``).
    distance_m : float or array_like
        Distance between the robots [m], >= 0. All three broadcast together.

    Returns
    -------
    ndarray of shape (..., 3)
        ``(x, y, θ21)``: R2's position [m] and heading [rad] in R1's frame; ``θ21`` in
        (-pi, pi].

    Raises
    ------
    ValueError
        If a distance is negative or any input is not finite.

    Examples
    --------
    Two robots facing each other 2 m apart along R1's x axis:

    >>> relative_frame_from_bearings(0.0, 0.0, 2.0).round(12).tolist()
    [2.0, 0.0, 3.14159265359]
    """
    b21 = np.asarray(bearing_2_in_1_rad, dtype=np.float64)
    b12 = np.asarray(bearing_1_in_2_rad, dtype=np.float64)
    d = np.asarray(distance_m, dtype=np.float64)
    for name, v in (("bearing_2_in_1_rad", b21), ("bearing_1_in_2_rad", b12), ("distance_m", d)):
        if not np.all(np.isfinite(v)):
            raise ValueError(f"relative_frame_from_bearings: {name} must be finite, got {v!r}")
    if np.any(d < 0):
        raise ValueError(f"relative_frame_from_bearings: distance_m must be >= 0 m, got {d!r}")
    b21, b12, d = np.broadcast_arrays(b21, b12, d)
    x = d * np.cos(b21)
    y = d * np.sin(b21)
    theta21 = wrap_angle(np.pi + b21 - b12)
    return np.stack([x, y, np.asarray(theta21, dtype=np.float64).reshape(x.shape)], axis=-1)


def transform_goal(goal_in_2, bearing_2_in_1_rad, bearing_1_in_2_rad, distance_m) -> np.ndarray:
    """Express a point given in R2's frame in R1's frame.

    Sgorbissa & Arkin §3.1: R2 tells R1 where a goal is in R2's own frame; R1 maps it
    through the frame from mutual bearings (:func:`relative_frame_from_bearings`).

    Parameters
    ----------
    goal_in_2 : array_like of shape (..., 2)
        Point(s) [m] in R2's frame.
    bearing_2_in_1_rad, bearing_1_in_2_rad, distance_m : float
        As in :func:`relative_frame_from_bearings`.

    Returns
    -------
    ndarray of shape (..., 2)
        The point(s) in R1's frame.

    Examples
    --------
    R2 2 m ahead of R1, facing it; a goal 1 m in front of R2 is 1 m in front of R1:

    >>> transform_goal([1.0, 0.0], 0.0, 0.0, 2.0).round(12).tolist()
    [1.0, 0.0]
    """
    pose = relative_frame_from_bearings(bearing_2_in_1_rad, bearing_1_in_2_rad, distance_m)
    return transform_points(pose, goal_in_2)
