"""Beyond the papers, combination 2, "localized LOS help": the LOS helpers' relative frames from MCL poses.

Which paper rules this composes (no copies; each stays in its own module):

- **Sgorbissa & Arkin** (the whole LOS help system, :mod:`teamnav.papers.los_help.brains`): R1's
  targets, the helpers' patrols, goal sharing (§3, rules 1-5), delayed visibility (§4), state
  sharing (§5), the line-of-sight radio (§1: "robots are allowed to communicate only when they
  are in sight of each other") and its eqs. 1-2 detector noise (§6.1). Only the *source of the
  frame* between sender and receiver changes, the brains' parameter ``frame_source``:

  - ``"bearings"`` (default, the paper's §3.1 rule): the sender's body frame in the receiver's
    from the mutual bearings and the receiver's range, θ21 = 180° + α21 − α12
    (:func:`~teamnav.papers.los_help.brains.goal_sharing.sender_frame`); both robots must see each
    other at the sending step.
  - ``"mcl"`` (ours): every message carries the sender's pose (its ``odom_pose`` at the sending
    step), and the receiver takes the frame from the two poses, ``inverse(own) ∘ sender``
    (:func:`frame_from_poses`). No bearing is needed, so neither robot has to see the other for the
    frame; the radio still delivers only between robots in line of sight, and a robot still
    broadcasts only while it sees a teammate (§4.4), so who talks to whom is the paper's.
  - ``"fused"`` (ours): both, when both exist (mutual sightings): the inverse-covariance weighted
    mean of the two frames (:func:`fuse_frames`), the bearing frame's covariance from the error
    bounds of eqs. 1-2 (:func:`bearing_frame_cov`, the robots' model of their own detector:
    ``frame_err_max`` and the teammate's size), the MCL frame's from the two filters' sample
    covariances (:func:`pose_frame_cov`, sent with the pose); the MCL frame alone otherwise.

- **Fox et al. §3.1** (Monte Carlo localization, :class:`teamnav.localization.MCL`) through
  ``localized-v1`` (:mod:`teamnav.papers.beyond.brains.localized`), which wraps each LOS brain: the
  robot's omnidirectional ``laser`` through the likelihood field, the map given
  (``give_map: true``), tracking from the known start pose.

Frames, written down (the part that must be consistent)
-------------------------------------------------------
The LOS brains keep everything (targets, patrol points, goals, ghosts, their pose) in *their
own odometry frame*: the frame of ``obs.odom_pose``. The paper's scenarios use ``odometry:
{frame: start}`` (each robot's frame is its start pose) and exact odometry (§6.1). Under
``localized-v1`` the brain's ``odom_pose`` is the filter's pose, which lives in the *map*
frame; so the scenarios of this combination (``beyond-localized-los-*``) give every robot
``odometry: {frame: world}`` (odometry starts at the true start pose, which is how the wrapper's
``init: odometry`` starts the filter at the known start: tracking, not global localization),
and ``targets_xy`` / ``patrol_xy`` in world (= map) coordinates. Every robot's own frame is then
the one map frame, and

- ``"mcl"``: the receiver's pose at the sending step ``P_r`` and the sender's ``P_s`` are both
  map-frame filter poses; the sender's body frame in the receiver's body frame is
  ``inverse(P_r) ∘ P_s``, which the receive path composes with ``P_r`` again: a goal the sender
  gave in its body frame lands at ``P_s ∘ g`` in the map. With exact poses this equals the
  bearing frame with exact bearings (the tests check it).
- ``"bearings"`` under the wrapper: each robot's frame is its own filter's map frame, and the
  bearing rule is frame-agnostic, so it works unchanged; it is the comparison case, driving on
  the same filter as the other two, so that only the frame source differs.

``"mcl"`` and ``"fused"`` are wrong when the robots' ``odom_pose`` frames differ (``frame:
start`` without the wrapper): the brain cannot tell, so the scenario must give a common frame.

Where this fills gaps (none of the papers combines these; each is a parameter of the LOS brains
whose default is the paper's rule): ``frame_source``; ``frame_err_max`` (the detector model the
``fused`` rule assumes, eqs. 1-2's err_max); ``frame_robot_size_m`` (eq. 2's "robotsize", None:
twice the robot's own radius, the team is homogeneous). The two covariances are treated as
independent (two filters that never exchange beliefs) and both get a floor (:data:`FLOOR_STD_M`,
:data:`FLOOR_STD_RAD`) so that a noise-free source (err_max 0 leaves the range exact) stays
invertible. The uniform noises of eqs. 1-2 enter by their variances (a² / 3 for U[-a, a]).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["FLOOR_STD_M", "FLOOR_STD_RAD", "FRAME_SOURCES", "bearing_frame_cov", "cov_from_upper", "cov_upper",
           "frame_from_poses", "fuse_frames", "pose_frame_cov"]

#: the values of the LOS brains' ``frame_source`` parameter ("bearings": Sgorbissa & Arkin §3.1)
FRAME_SOURCES = ("bearings", "mcl", "fused")
#: standard deviations added to every frame covariance (position [m], heading [rad])
FLOOR_STD_M = 1e-3
FLOOR_STD_RAD = 1e-3


def frame_from_poses(own_pose, sender_pose) -> tuple[float, float, float]:
    """The sender's body frame (x, y, θ) in the receiver's body frame, from the two robots' poses
    in one common frame: ``inverse(own) ∘ sender`` (scalar twin of :func:`teamnav.geometry.se2.relative`).

    Examples
    --------
    >>> [round(v, 12) for v in frame_from_poses((1.0, 1.0, math.pi / 2), (1.0, 3.0, -math.pi / 2))]
    [2.0, 0.0, 3.14159265359]
    """
    x, y, th = float(own_pose[0]), float(own_pose[1]), float(own_pose[2])
    dx, dy = float(sender_pose[0]) - x, float(sender_pose[1]) - y
    c, s = math.cos(th), math.sin(th)
    t = float(sender_pose[2]) - th
    t = math.atan2(math.sin(t), math.cos(t))
    if t <= -math.pi:
        t = math.pi
    return c * dx + s * dy, -s * dx + c * dy, t


def bearing_frame_cov(distance_m: float, bearing_sender_in_me_rad: float, err_max: float,
                      robot_size_m: float) -> np.ndarray:
    """Covariance (3 x 3, receiver's body frame) of the §3.1 bearing frame
    ``(d cos α12, d sin α12, 180° + α12 − α21)`` under eqs. 1-2's noise.

    Eq. 1: ``d_p = d (1 + U[-err_max, err_max])``, variance ``(d err_max)² / 3``; eq. 2: each bearing
    ``α_p = α + atan(size / 2d) U[-1, 1]``, variance ``atan(size / 2d)² / 3``, the receiver's α12
    and the sender's α21 independent. First-order propagation through the Jacobian, plus the floor.

    Examples
    --------
    >>> c = bearing_frame_cov(4.0, 0.0, 0.1, 0.4)
    >>> round(math.sqrt(c[0, 0]), 4), round(math.sqrt(c[2, 2]), 4)  # sd of the range, of θ21
    (0.2309, 0.0408)
    """
    d = max(float(distance_m), 1e-6)
    var_d = (d * float(err_max)) ** 2 / 3.0
    var_a = math.atan(float(robot_size_m) / (2.0 * d)) ** 2 / 3.0
    c, s = math.cos(bearing_sender_in_me_rad), math.sin(bearing_sender_in_me_rad)
    # rows: x, y, θ; columns: d, α12, α21
    j = np.array([[c, -d * s, 0.0], [s, d * c, 0.0], [0.0, 1.0, -1.0]])
    cov = j @ np.diag([var_d, var_a, var_a]) @ j.T
    return cov + np.diag([FLOOR_STD_M ** 2, FLOOR_STD_M ** 2, FLOOR_STD_RAD ** 2])


def pose_frame_cov(own_pose, own_cov, sender_pose, sender_cov) -> np.ndarray:
    """Covariance of :func:`frame_from_poses` (3 x 3, receiver's body frame) from the two poses'
    covariances (common frame; independent): ``J_s Σ_s J_sᵀ + J_r Σ_r J_rᵀ``, plus the floor.

    Examples
    --------
    >>> c = pose_frame_cov((0, 0, 0), np.diag([0.01, 0.01, 0.0]), (2, 0, 0), np.diag([0.01, 0.01, 0.0]))
    >>> round(float(c[0, 0]), 6), round(float(c[1, 1]), 6)
    (0.020001, 0.020001)
    """
    th = float(own_pose[2])
    c, s = math.cos(th), math.sin(th)
    rx, ry, _ = frame_from_poses(own_pose, sender_pose)
    js = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    jr = np.array([[-c, -s, ry], [s, -c, -rx], [0.0, 0.0, -1.0]])
    cov = js @ np.asarray(sender_cov, dtype=float) @ js.T + jr @ np.asarray(own_cov, dtype=float) @ jr.T
    return cov + np.diag([FLOOR_STD_M ** 2, FLOOR_STD_M ** 2, FLOOR_STD_RAD ** 2])


def fuse_frames(a, cov_a, b, cov_b) -> tuple[tuple[float, float, float], np.ndarray]:
    """The inverse-covariance weighted mean of two estimates (x, y, θ) of one frame, and its
    covariance ``(Σa⁻¹ + Σb⁻¹)⁻¹``. The heading of ``b`` is first taken within ±π of ``a``'s, and
    the result's heading is wrapped to (-π, π].

    Examples
    --------
    >>> m, c = fuse_frames((0.0, 0.0, 0.0), np.eye(3), (2.0, 4.0, 0.2), np.eye(3))
    >>> [round(v, 12) for v in m], round(float(c[0, 0]), 12)
    ([1.0, 2.0, 0.1], 0.5)
    """
    a = np.asarray(a, dtype=float)
    b = np.array(b, dtype=float)
    b[2] = a[2] + math.atan2(math.sin(b[2] - a[2]), math.cos(b[2] - a[2]))
    ia, ib = np.linalg.inv(np.asarray(cov_a, dtype=float)), np.linalg.inv(np.asarray(cov_b, dtype=float))
    cov = np.linalg.inv(ia + ib)
    cov = 0.5 * (cov + cov.T)
    m = cov @ (ia @ a + ib @ b)
    t = math.atan2(math.sin(m[2]), math.cos(m[2]))
    if t <= -math.pi:
        t = math.pi
    return (float(m[0]), float(m[1]), t), cov


def cov_upper(cov) -> tuple[float, ...]:
    """The six numbers of a symmetric 3 x 3 covariance sent in a message: xx, xy, xθ, yy, yθ, θθ."""
    c = np.asarray(cov, dtype=float)
    return (float(c[0, 0]), float(c[0, 1]), float(c[0, 2]), float(c[1, 1]), float(c[1, 2]), float(c[2, 2]))


def cov_from_upper(u) -> np.ndarray:
    """Inverse of :func:`cov_upper`.

    >>> cov_from_upper(cov_upper(np.diag([1.0, 2.0, 3.0]))).tolist()
    [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]]
    """
    xx, xy, xt, yy, yt, tt = (float(v) for v in u)
    return np.array([[xx, xy, xt], [xy, yy, yt], [xt, yt, tt]])
