"""The simulator's truth about every robot, as struct-of-arrays.

This is the only place a true pose lives (DESIGN "truth and belief never mix"): one array per
quantity for all ``N`` robots, indexed by robot id (ids are ``0 .. N-1`` in the order of the
scenario's groups). The engine updates these arrays in place; nothing here is ever handed to
a brain — observations are built from the sensor, odometry and radio models instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["RobotState"]


@dataclass(eq=False)
class RobotState:
    """True state of all robots.

    Attributes
    ----------
    x_m, y_m : ndarray of shape (N,), float64
        True position of each robot's centre in the world frame [m].
    theta_rad : ndarray of shape (N,), float64
        True heading in the world frame [rad], wrapped to (-pi, pi].
    v_mps : ndarray of shape (N,), float64
        Forward speed applied in the last step after clipping to the robot's limit [m/s]
        (holonomic-step robots: step length / dt when they moved, else 0). What was
        *commanded*; a stalled robot covered less.
    omega_radps : ndarray of shape (N,), float64
        Turn rate applied in the last step after clipping [rad/s] (holonomic-step robots:
        the turn to the chosen direction / dt).
    radius_m : ndarray of shape (N,), float64
        Radius of each robot's disc body [m].
    stalled : ndarray of shape (N,), bool
        True when the robot's last motion was blocked by a wall or another robot (the
        stall/bumper flag its next observation carries).
    group : ndarray of shape (N,), int64
        Index of the robot's group in ``SimConfig.robots``.
    """

    x_m: np.ndarray
    y_m: np.ndarray
    theta_rad: np.ndarray
    v_mps: np.ndarray
    omega_radps: np.ndarray
    radius_m: np.ndarray
    stalled: np.ndarray
    group: np.ndarray

    @classmethod
    def from_poses(cls, poses: np.ndarray, radius_m: np.ndarray, group: np.ndarray) -> "RobotState":
        """A state at rest at ``poses``.

        Parameters
        ----------
        poses : ndarray of shape (N, 3)
            (x [m], y [m], theta [rad]) per robot.
        radius_m : ndarray of shape (N,)
            Body radius per robot [m], > 0.
        group : ndarray of shape (N,), int
            Group index per robot.

        Examples
        --------
        >>> s = RobotState.from_poses(np.array([[1.0, 2.0, 0.5]]), np.array([0.2]), np.array([0]))
        >>> s.n, s.poses().tolist()
        (1, [[1.0, 2.0, 0.5]])
        """
        poses = np.asarray(poses, dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] != 3:
            raise ValueError(f"poses must have shape (N, 3) (x_m, y_m, theta_rad), got shape {poses.shape}")
        if not np.all(np.isfinite(poses)):
            raise ValueError(f"poses must be finite, got {poses[~np.isfinite(poses).all(axis=1)].tolist()}")
        n = poses.shape[0]
        radius_m = np.asarray(radius_m, dtype=np.float64)
        if radius_m.shape != (n,) or not np.all(radius_m > 0):
            raise ValueError(f"radius_m must be (N,)={n} positive radii [m], got {radius_m!r}")
        group = np.asarray(group, dtype=np.int64)
        if group.shape != (n,):
            raise ValueError(f"group must have shape ({n},), got {group.shape}")
        return cls(
            x_m=np.ascontiguousarray(poses[:, 0]),
            y_m=np.ascontiguousarray(poses[:, 1]),
            theta_rad=np.ascontiguousarray(poses[:, 2]),
            v_mps=np.zeros(n),
            omega_radps=np.zeros(n),
            radius_m=radius_m.copy(),
            stalled=np.zeros(n, dtype=np.bool_),
            group=group.copy(),
        )

    @property
    def n(self) -> int:
        """Number of robots."""
        return int(self.x_m.shape[0])

    def poses(self) -> np.ndarray:
        """A copy of the true poses, shape (N, 3): (x [m], y [m], theta [rad])."""
        return np.stack([self.x_m, self.y_m, self.theta_rad], axis=1)
