"""Robots started one at a time from one spot (:class:`~teamnav.sim.config.LaunchConfig`).

Vaughan et al. 2000 §5 and 2002 §3.5: "The robots are started one at a time from the same spot
at the home position, with the same orientation". :class:`OneAtATime` keeps who waits and when
each robot started, starts the next robot when the spot is clear, and parks the waiting robots
far outside the map while the others move and sense, so that no sensor, detector, body or
radio meets them (:class:`~teamnav.sim.engine.Simulation` calls it around each step's motion
and sensing). It writes the truth (``RobotState``) and the odometry's start only for the robot
it starts.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["OneAtATime"]


class OneAtATime:
    """Who waits, when each robot started, and the start of the next one.

    Parameters
    ----------
    n
        Robots in the run; robot 0 starts at step 0.
    spot
        The start pose ``[x_m, y_m, theta_rad]`` shared by every robot.
    clear_m
        The next robot starts when every started robot is at least this far from the spot
        (centre to centre).
    odom0
        Each robot's odometry pose at its start, ``(n, 3)`` (copied).
    origin_xy_m
        The map's origin: waiting robots are parked 10 km beyond it, 10 m apart.

    Attributes
    ----------
    waiting : (n,) bool
        True where a robot has not started yet.
    launched_at : (n,) int64
        The step at which each robot started (-1 while it waits).
    """

    def __init__(self, n: int, spot: np.ndarray, clear_m: float, odom0: np.ndarray,
                 origin_xy_m: tuple[float, float]) -> None:
        self.waiting = np.ones(n, dtype=np.bool_)
        self.waiting[0] = False
        self.launched_at = np.full(n, -1, dtype=np.int64)
        self.launched_at[0] = 0
        self.spot = np.array(spot, dtype=np.float64)
        self.clear_m = float(clear_m)
        self._odom0 = np.array(odom0, dtype=np.float64)
        ox, oy = origin_xy_m
        # off-stage parking while hidden: far outside the map, 10 m apart (no sensor reaches)
        self._park_x = ox - 1.0e4 - 10.0 * np.arange(n, dtype=np.float64)
        self._park_y = np.full(n, oy - 1.0e4)

    def launch_next(self, step: int, t_s: float, state: Any, odometry: Any, log: list) -> None:
        """Start the next waiting robot (lowest id) when every started robot is at least
        ``clear_m`` from the spot; its odometry starts from the spot, and ``log`` (the places'
        event log) gets a ``launched`` record."""
        waiting = self.waiting
        if not waiting.any():
            return
        s = state
        on = ~waiting
        d2 = (s.x_m[on] - self.spot[0]) ** 2 + (s.y_m[on] - self.spot[1]) ** 2
        clear = self.clear_m
        if d2.size and float(d2.min()) < clear * clear:
            return
        i = int(np.flatnonzero(waiting)[0])
        waiting[i] = False
        self.launched_at[i] = step
        s.x_m[i], s.y_m[i], s.theta_rad[i] = self.spot
        s.v_mps[i] = 0.0
        s.omega_radps[i] = 0.0
        s.stalled[i] = False
        odometry.pose[i] = self._odom0[i]
        odometry.delta[i] = 0.0
        log.append({"step": int(step), "t_s": float(t_s), "robot": i, "place": None, "event": None, "launched": True})

    def hide(self, state: Any, waiting: np.ndarray) -> None:
        """Park the waiting robots far outside the map (:meth:`unhide` puts them back at the spot)."""
        state.x_m[waiting] = self._park_x[waiting]
        state.y_m[waiting] = self._park_y[waiting]

    def unhide(self, state: Any, waiting: np.ndarray) -> None:
        state.x_m[waiting] = self.spot[0]
        state.y_m[waiting] = self.spot[1]
        state.theta_rad[waiting] = self.spot[2]
