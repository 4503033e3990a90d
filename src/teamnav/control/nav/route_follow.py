"""Route following: the "one robot alone, under optimal conditions" baseline of the trail papers.

Vaughan et al., *Blazing a trail* §5.1: "Since the time for a round-trip from home to resource
is approximately 3 minutes the robot group performed three times better than a single robot
performing under optimal conditions." The paper gives no controller for that single robot: it
is the round-trip time of a robot that already knows the route. This brain is that robot. It
is told the optimal route as waypoints in its own odometry frame (the scenario gives the
corners of the map's home-source corridors; with ``odometry.frame: world`` and no drift the
frame is the world's) and shuttles home -> source -> home along it:

- pure pursuit: head for the first point of the route polyline ``lookahead_m`` ahead of the
  robot's projection onto the current leg (corners are cut smoothly);
- a leg ends when the robot's own position estimate is within ``reach_m`` of the last waypoint
  *or* the place's task event fires (``source_event`` at the source end, ``home_event`` at home);
  then the route is followed in reverse. ``trips`` counts the place events (a trip is one
  place-to-place traverse, as in *Try to see it my way* §3.5);
- minimal obstacle avoidance: slow down linearly between ``slow_distance_m`` and
  ``stop_distance_m`` of the nearest return in the front sector; steer away from returns closer
  than ``avoid_distance_m`` (a repulsive term summed over the scan); turn on the spot when the
  heading error is above 60 degrees; when stalled, back off for ``backoff_s``.

With odometric drift the waypoints slide away from the world's corridors and the robot runs
into walls or misses the places: that is expected (the optimal baseline runs without drift).
Gap filled here: the papers' optimal robot is a number, not a controller; this one is as simple
as it can be and still drives the optimal route at cruise speed.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

from teamnav.control.nav.wander import pick_sensor
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Action, Message, Observation
from teamnav.geometry import wrap_angle

__all__ = ["RouteFollow", "RouteFollowParams"]


class RouteFollowParams(BaseModel):
    """Parameters of the route follower (units in the names; rules in the module docstring)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    waypoints_m: tuple[tuple[float, float], ...] = Field(min_length=2, max_length=1000)
    home_event: str = Field("given_resource", min_length=1)
    source_event: str = Field("took_resource", min_length=1)
    sensor: str | None = Field(None, min_length=1)
    cruise_speed_mps: float = Field(0.4, gt=0.0, le=10.0)
    turn_gain: float = Field(2.0, gt=0.0, le=50.0)
    lookahead_m: float = Field(1.0, gt=0.0, le=20.0)
    reach_m: float = Field(0.5, gt=0.0, le=20.0)
    slow_distance_m: float = Field(1.0, gt=0.0, le=20.0)
    stop_distance_m: float = Field(0.35, gt=0.0, le=20.0)
    avoid_distance_m: float = Field(0.6, ge=0.0, le=20.0)
    avoid_gain: float = Field(0.6, ge=0.0, le=50.0)
    front_half_angle_deg: float = Field(30.0, gt=0.0, le=90.0)
    backoff_speed_mps: float = Field(0.1, ge=0.0, le=10.0)
    backoff_s: float = Field(1.0, ge=0.0, le=60.0)

    @field_validator("waypoints_m")
    @classmethod
    def _distinct_neighbours(cls, v):
        for a, b in zip(v, v[1:]):
            if math.hypot(b[0] - a[0], b[1] - a[1]) <= 1e-6:
                raise ValueError(f"consecutive waypoints must differ, got {list(a)} twice")
        return v


def pursuit_point(route: np.ndarray, seg: int, xy: np.ndarray, lookahead_m: float) -> tuple[np.ndarray, int]:
    """The point ``lookahead_m`` along the polyline ahead of ``xy``'s projection on segment ``seg``.

    Parameters
    ----------
    route : ndarray (K, 2)
        Polyline vertices [m], K >= 2.
    seg : int
        Index of the current segment (``route[seg] -> route[seg + 1]``).
    xy : ndarray (2,)
        Robot position [m].
    lookahead_m : float

    Returns
    -------
    target : ndarray (2,)
        The pursuit point (the last vertex when the route ends within the lookahead).
    seg : int
        The segment the robot is now on (advanced past segments it has passed the end of).
    """
    k = route.shape[0]
    # advance while the projection is past the end of the current segment
    while seg < k - 2:
        a, b = route[seg], route[seg + 1]
        ab = b - a
        t = float(np.dot(xy - a, ab) / np.dot(ab, ab))
        if t < 1.0:
            break
        seg += 1
    a, b = route[seg], route[seg + 1]
    ab = b - a
    L = float(np.hypot(*ab))
    t = float(np.clip(np.dot(xy - a, ab) / (L * L), 0.0, 1.0))
    remaining = lookahead_m + t * L
    i = seg
    while i < k - 1:
        seg_len = float(np.hypot(*(route[i + 1] - route[i])))
        if remaining <= seg_len:
            return route[i] + (route[i + 1] - route[i]) * (remaining / seg_len), seg
        remaining -= seg_len
        i += 1
    return route[-1].copy(), seg


class RouteFollow:
    """Shuttle along a given route between home and source (a per-robot Controller).

    Examples
    --------
    >>> import numpy as np
    >>> from teamnav.control import Observation, RangeScan, RobotInfo, SensorInfo
    >>> angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    >>> info = RobotInfo(0, 1, 0.25, "unicycle", 0.5, 1.5, 0.1, 0.1,
    ...                  sensors={"laser": SensorInfo("laser", "laser", angles, 10.0)})
    >>> brain = RouteFollow(RouteFollow.Params(waypoints_m=[[0, 0], [10, 0]]), np.random.default_rng(0), info)
    >>> obs = Observation(0, 0, 0.0, np.zeros(3), np.zeros(3),
    ...                   scans={"laser": RangeScan(np.full(181, 10.0), angles, 10.0)})
    >>> action, _ = brain.step(obs)
    >>> round(action.v_mps, 2), round(action.omega_radps, 2)
    (0.4, 0.0)
    """

    Params = RouteFollowParams
    #: example parameters for check_brain (a route has no sensible default)
    check_params = {"waypoints_m": [[1.0, 1.0], [4.0, 1.0]]}

    def __init__(self, params: RouteFollowParams, rng: np.random.Generator, info: RobotInfo) -> None:
        if not isinstance(params, RouteFollowParams):
            raise ValueError(f"params must be a RouteFollow.Params, got {type(params).__name__}")
        self.params = params
        self.info = info
        self.sensor = pick_sensor(params, info).name  # type: ignore[arg-type]
        self._route = np.asarray(params.waypoints_m, dtype=np.float64)
        self._rng = rng
        self._outbound = True  # home -> source
        self._seg = 0
        self._backoff_steps = 0
        self._backoff_turn = 1.0
        self.trips = 0
        self.carrying = False

    # the route as driven on the current leg
    def _leg(self) -> np.ndarray:
        return self._route if self._outbound else self._route[::-1]

    def _turn_round(self) -> None:
        self._outbound = not self._outbound
        self._seg = 0

    def step(self, obs: Observation) -> tuple[Action, list[Message]]:
        """Pursue the route; reverse at its ends or on the end place's event."""
        p = self.params
        for ev in obs.events:
            if ev == p.source_event:
                self.trips += 1
                self.carrying = True
                if self._outbound:
                    self._turn_round()
            elif ev == p.home_event:
                self.trips += 1
                self.carrying = False
                if not self._outbound:
                    self._turn_round()
        xy = np.asarray(obs.odom_pose[:2], dtype=np.float64)
        theta = float(obs.odom_pose[2])
        leg = self._leg()
        if float(np.hypot(*(leg[-1] - xy))) < p.reach_m:
            self._turn_round()
            leg = self._leg()
        target, self._seg = pursuit_point(leg, self._seg, xy, p.lookahead_m)

        scan = obs.scans[self.sensor]
        ranges = np.asarray(scan.ranges_m, dtype=np.float64)
        angles = np.asarray(scan.angles_rad, dtype=np.float64)
        if obs.stalled and self._backoff_steps == 0:
            self._backoff_steps = max(1, int(round(p.backoff_s / self.info.dt_s)))
            self._backoff_turn = 1.0 if self._rng.random() < 0.5 else -1.0
        if self._backoff_steps > 0:
            self._backoff_steps -= 1
            return Action(-p.backoff_speed_mps, 0.5 * self._backoff_turn * self.info.max_omega_radps), []

        err = wrap_angle(math.atan2(target[1] - xy[1], target[0] - xy[0]) - theta)
        omega = p.turn_gain * err
        # repulsion from near returns: beams on the left push right and vice versa
        near = ranges < p.avoid_distance_m
        if near.any() and p.avoid_gain > 0:
            push = (p.avoid_distance_m - ranges[near]) / p.avoid_distance_m
            omega += -p.avoid_gain * float(np.sum(push * np.sign(np.sin(angles[near])) * np.cos(angles[near]) ** 2))
        front = np.abs(angles) <= math.radians(p.front_half_angle_deg)
        front_min = float(ranges[front].min()) if front.any() else float(scan.max_range_m)
        slow = float(np.clip((front_min - p.stop_distance_m) / max(p.slow_distance_m - p.stop_distance_m, 1e-6), 0.0, 1.0))
        v = p.cruise_speed_mps * slow * max(0.0, math.cos(err))
        if abs(err) > math.radians(60.0):
            v = 0.0
        if front_min < p.stop_distance_m and abs(omega) < 0.3:
            # blocked ahead and no strong reason to turn: turn towards the more open half
            left = float(ranges[angles > 0].mean()) if (angles > 0).any() else 0.0
            right = float(ranges[angles < 0].mean()) if (angles < 0).any() else 0.0
            omega = 0.8 if left >= right else -0.8
        omega = float(np.clip(omega, -self.info.max_omega_radps, self.info.max_omega_radps))
        return Action(float(v), omega), []

    def log(self) -> dict[str, Any]:
        """``trips`` (place events so far), ``carrying``, ``leg`` (1 outbound, 0 back), ``seg``."""
        return {"trips": int(self.trips), "carrying": bool(self.carrying), "leg": int(self._outbound), "seg": int(self._seg)}
