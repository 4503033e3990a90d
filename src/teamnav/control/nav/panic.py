"""Panic: the emergency stop and the "unstick" behaviour that overrides Navigate.

Vaughan, Støy, Sukhatme & Matarić, *Blazing a trail* §4.2:

    "An emergency-stop mechanism runs continuously in parallel, monitoring the laser sensor; if
    the robot gets too close to any obstacle it will stop and switch to the panic behaviour.
    Panic [...] 'unsticks' the robot from obstacles, dead ends and traffic jams by turning on the
    spot in a random direction until it detects free space and moves forward. After a few
    seconds the behaviour times-out and switches to the navigate behaviour."

and *Try to see it my way* §3.3 (Panic "subsumes" Navigate "until it finds enough space to
Navigate again"); Navigate keeps control "unless the emergency stop mechanism detects an
obstacle critically close to the front of the robot" (*Blazing* §4.2).

Phases: ``stop`` (one step at rest: the emergency stop) -> ``turn`` (on the spot, in the
direction drawn at the start, until the box straight ahead, ``free_m`` deep and a robot width
plus margins wide, is free) -> ``forward`` (straight on for ``forward_s``) -> done. Gaps filled
here: "critically close" is a return within ``clearance_m`` of the body inside
``±half_angle_deg`` of the heading (or the stall flag: the last motion was blocked); an obstacle
critically close again while moving forward sends the robot back to turning (same direction); a
turn that finds no free space within ``turn_timeout_s`` gives control back to Navigate (which
panics again, with a fresh random direction, if it is still stuck).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from teamnav.control.nav.wall_follow import box_exit_ranges

__all__ = ["Panic"]


@njit(cache=True)
def _any_below(ranges_m: np.ndarray, idx: np.ndarray, limit_m: float) -> bool:
    """``(ranges_m[idx] < limit_m).any()`` without the temporaries (the emergency-stop test)."""
    for i in idx:
        if ranges_m[i] < limit_m:
            return True
    return False


class Panic:
    """Emergency stop and recovery for one laser (*Blazing a trail* §4.2).

    Parameters
    ----------
    angles_rad : ndarray of shape (B,)
        Beam directions in the body frame [rad].
    radius_m : float
        The robot's radius [m].
    clearance_m : float
        A return closer than ``radius_m + clearance_m`` in the front sector is critical [m].
    half_angle_deg : float
        Half-width of the monitored front sector [deg].
    free_width_m, free_m : float
        The box straight ahead that must be free to stop turning: width and depth [m].
    speed_mps, turn_rate_radps : float
        Forward speed and on-the-spot turn rate while panicking.
    forward_s, turn_timeout_s, dt_s : float
        Duration of the forward phase, the longest turn, and the control period [s].

    Examples
    --------
    >>> angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    >>> p = Panic(angles, 0.25, 0.1, 60.0, 0.8, 0.8, 0.3, 1.5, 2.0, 8.0, 0.1)
    >>> p.critical(np.full(181, 8.0)), p.critical(np.full(181, 0.3))
    (False, True)
    """

    def __init__(self, angles_rad: np.ndarray, radius_m: float, clearance_m: float, half_angle_deg: float,
                 free_width_m: float, free_m: float, speed_mps: float, turn_rate_radps: float, forward_s: float,
                 turn_timeout_s: float, dt_s: float) -> None:
        a = np.asarray(angles_rad, dtype=np.float64)
        self._front = np.flatnonzero(np.abs(a) <= math.radians(half_angle_deg))
        self.critical_m = float(radius_m + clearance_m)
        half = 0.5 * float(free_width_m)
        self._free_exit = box_exit_ranges(a, -0.01, float(free_m), np.array([-half]), np.array([half]))[0]
        self.speed_mps = float(speed_mps)
        self.turn_rate_radps = float(turn_rate_radps)
        self._forward_steps = max(1, int(round(forward_s / dt_s)))
        self._turn_steps = max(1, int(round(turn_timeout_s / dt_s)))
        self.phase = "idle"
        self.direction = 1.0
        self._count = 0

    @property
    def active(self) -> bool:
        """True while the behaviour holds control."""
        return self.phase != "idle"

    def critical(self, ranges_m: np.ndarray) -> bool:
        """An obstacle critically close to the front: the emergency-stop condition."""
        return _any_below(ranges_m, self._front, self.critical_m)

    def free_ahead(self, ranges_m: np.ndarray) -> bool:
        """The box straight ahead is free (every beam crossing it leaves it before its return)."""
        return not bool((ranges_m < self._free_exit).any())

    def start(self, rng: np.random.Generator) -> None:
        """Emergency stop: take control, draw the turn direction (left or right, 50 % each)."""
        self.phase = "stop"
        self.direction = 1.0 if rng.random() < 0.5 else -1.0
        self._count = 0

    def reset(self) -> None:
        """Give control back."""
        self.phase = "idle"
        self._count = 0

    def step(self, ranges_m: np.ndarray) -> tuple[float, float]:
        """The command ``(v_mps, omega_radps)`` for this step; ``active`` turns False when done."""
        if self.phase == "stop":
            self.phase, self._count = "turn", 0
            return 0.0, 0.0
        if self.phase == "turn":
            if self.free_ahead(ranges_m):
                self.phase, self._count = "forward", 0
            else:
                self._count += 1
                if self._count > self._turn_steps:
                    self.reset()
                    return 0.0, 0.0
                return 0.0, self.direction * self.turn_rate_radps
        if self.phase == "forward":
            if self.critical(ranges_m):
                self.phase, self._count = "turn", 0
                return 0.0, self.direction * self.turn_rate_radps
            self._count += 1
            if self._count >= self._forward_steps:
                self.reset()
            return self.speed_mps, 0.0
        return 0.0, 0.0
