"""Wheel odometry: each robot's believed pose, integrated from noisy measured motion.

Per step and robot, the *true* motion from the previous true pose to the new one is
decomposed as in Thrun, Burgard & Fox, *Probabilistic Robotics* §5.4 (Table 5.6) into a
rotation ``d_rot1``, a translation ``d_trans`` and a rotation ``d_rot2``, and the *measured*
motion is drawn from the odometry motion model (Table 5.6, ``alpha = (a1, a2, a3, a4)``)::

    m_rot1  = d_rot1  - N(0, a1 d_rot1^2 + a2 d_trans^2)
    m_trans = d_trans - N(0, a3 d_trans^2 + a4 d_rot1^2 + a4 d_rot2^2)
    m_rot2  = d_rot2  - N(0, a1 d_rot2^2 + a2 d_trans^2)

(``N(0, b^2)`` has variance ``b^2``, as in the book's ``sample(b^2)``), then wheel slip, a
random walk per metre driven (``L = |d_trans|``, the step's true distance)::

    m_trans += N(0, slip_std_m_per_sqrt_m^2 L)              (std sigma_t sqrt(L) m)
    m_rot1, m_rot2 += 0.5 N(0, heading_slip_deg_per_sqrt_m^2 L)  each (one draw, split)

and the systematic errors that make Vaughan et al.'s odometry drift:

- ``m_trans *= 1 + scale_error`` (a wheel diameter off by that fraction; applied after the slip,
  since the encoder ticks are converted to metres with the wrong diameter whatever the ground did);
- ``heading_drift_deg_per_min * dt / 60`` degrees are added to the measured rotation, half
  to ``m_rot1`` and half to ``m_rot2``. The drift is a rate in *time*, so it accumulates
  while a robot stands still too (like a gyro bias); it is exactly ``rate × elapsed time``.

What the papers say about their robots' odometry
------------------------------------------------
Both papers report *rotation* only. *Blazing a trail* §5.1 / Fig. 6: "the odometry of Ant and
Bee is worse than the odometry of Tanis and Punky whose odometry only rotates slightly", and
the system "breaks down completely at around 27 minutes" from "the unbounded accumulation of
odometry errors" (§6). *Try to see it my way* §3.6: "Bug's coordinate system rotated clockwise;
the other robots' systems drifted anti-clockwise. Tanis' system rotated only by around 0.35° per
minute, while Fly's rotated at 2° per minute", and one robot "suffered catastrophic odometry
failure". Neither gives a distance error; the 2002 transform between frames (§2.1.5) has a
*scale* besides the rotation and translation, which is what a wheel-diameter error needs.

Gap-fills (ours): the scale error and the slip are the two textbook translational errors of
wheel odometry (systematic: unequal or wrong wheel diameters; non-systematic: slip on the floor,
Borenstein & Feng's UMBmark split). The slip is given *per metre* and not through Table 5.6's
``a3``: that noise has variance ``a3 d_trans^2`` per step, so its variance over a path of length
``L`` is ``a3 L v dt`` and shrinks with the step; a random walk per metre is the same at any
``dt``. The slip draws come from the odometry stream *after* Table 5.6's, and only when a slip
parameter is non-zero, so runs without slip draw the same numbers as before it existed.

The believed pose integrates the measured motion::

    x += m_trans cos(theta + m_rot1);  y += m_trans sin(theta + m_rot1);  theta += m_rot1 + m_rot2

Choices the book leaves open
----------------------------
- Backward motion: when the true displacement points behind the robot (``|d_rot1| > pi/2``)
  the translation is taken as negative and ``d_rot1`` is flipped by pi, so a reversing robot
  has small rotations (the book's form would report two half turns and inflate the noise).
- A displacement shorter than ``1e-12`` m has ``d_rot1 = 0`` (a pure rotation).

``frame="start"``: the odometry frame is the robot's start pose, so odometry starts at
(0, 0, 0). ``frame="world"``: it starts at the true start pose (frames aligned with the world).
The per-step ``odom_delta`` is the measured motion in the previous odometry body frame:
``(m_trans cos m_rot1, m_trans sin m_rot1, wrap(m_rot1 + m_rot2))``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from teamnav.sim.kinematics import wrap

__all__ = ["Odometry", "odometry_reference", "odometry_step"]

_HALF_PI = 0.5 * math.pi
_MIN_TRANS_M = 1e-12


@njit(cache=True)
def odometry_step(x0, y0, th0, x1, y1, th1, noise, alpha, drift_rad, scale, pose, delta,
                  slip_noise, slip_m, slip_rad):
    """Advance every robot's odometry by one step (see the module docstring).

    Parameters
    ----------
    x0, y0, th0, x1, y1, th1 : (N,) float64
        True poses before and after the step [m, m, rad].
    noise : (N, 3) float64 or (0, 3)
        Standard normal draws (rot1, trans, rot2); an empty array means no random noise.
    alpha : (N, 4) float64
        Table 5.6 noise parameters.
    drift_rad : (N,) float64
        Heading drift per step [rad].
    scale : (N,) float64
        Translation scale factor ``1 + scale_error``.
    pose : (N, 3) float64
        Odometry poses, updated in place.
    delta : (N, 3) float64
        Written: measured motion in the previous odometry body frame.
    slip_noise : (N, 2) float64 or (0, 2)
        Standard normal draws (translation, heading) of the slip; empty means no slip.
    slip_m : (N,) float64
        Distance slip [m per sqrt(m) driven].
    slip_rad : (N,) float64
        Heading slip [rad per sqrt(m) driven].
    """
    noisy = noise.shape[0] > 0
    slipping = slip_noise.shape[0] > 0
    for i in range(x0.shape[0]):
        dx = x1[i] - x0[i]
        dy = y1[i] - y0[i]
        trans = math.sqrt(dx * dx + dy * dy)
        if trans < _MIN_TRANS_M:
            trans = 0.0
            rot1 = 0.0
        else:
            rot1 = wrap(math.atan2(dy, dx) - th0[i])
            if rot1 > _HALF_PI or rot1 < -_HALF_PI:  # moving backwards
                trans = -trans
                rot1 = wrap(rot1 + math.pi)
        rot2 = wrap(th1[i] - th0[i] - rot1)
        if noisy:
            a1 = alpha[i, 0]
            a2 = alpha[i, 1]
            a3 = alpha[i, 2]
            a4 = alpha[i, 3]
            t2 = trans * trans
            r1 = rot1 * rot1
            r2 = rot2 * rot2
            m_rot1 = rot1 - noise[i, 0] * math.sqrt(a1 * r1 + a2 * t2)
            m_trans = trans - noise[i, 1] * math.sqrt(a3 * t2 + a4 * r1 + a4 * r2)
            m_rot2 = rot2 - noise[i, 2] * math.sqrt(a1 * r2 + a2 * t2)
        else:
            m_rot1 = rot1
            m_trans = trans
            m_rot2 = rot2
        if slipping:
            root = math.sqrt(abs(trans))
            m_trans += slip_noise[i, 0] * slip_m[i] * root
            half = 0.5 * slip_noise[i, 1] * slip_rad[i] * root
            m_rot1 += half
            m_rot2 += half
        m_trans *= scale[i]
        m_rot1 += 0.5 * drift_rad[i]
        m_rot2 += 0.5 * drift_rad[i]
        th = pose[i, 2]
        pose[i, 0] += m_trans * math.cos(th + m_rot1)
        pose[i, 1] += m_trans * math.sin(th + m_rot1)
        pose[i, 2] = wrap(th + m_rot1 + m_rot2)
        delta[i, 0] = m_trans * math.cos(m_rot1)
        delta[i, 1] = m_trans * math.sin(m_rot1)
        delta[i, 2] = wrap(m_rot1 + m_rot2)


def odometry_reference(p0, p1, noise, alpha, drift_rad, scale, pose, slip_noise=None, slip_m=None, slip_rad=None):
    """Pure-NumPy reference of :func:`odometry_step`; returns ``(new_pose, delta)`` (N, 3) each."""
    from teamnav.geometry.angles import wrap_angle

    p0, p1, pose = (np.asarray(a, dtype=np.float64) for a in (p0, p1, pose))
    d = p1[:, :2] - p0[:, :2]
    trans = np.hypot(d[:, 0], d[:, 1])
    still = trans < _MIN_TRANS_M
    rot1 = np.where(still, 0.0, wrap_angle(np.arctan2(d[:, 1], d[:, 0]) - p0[:, 2]))
    trans = np.where(still, 0.0, trans)
    back = np.abs(rot1) > _HALF_PI
    trans = np.where(back, -trans, trans)
    rot1 = np.where(back, wrap_angle(rot1 + np.pi), rot1)
    rot2 = wrap_angle(p1[:, 2] - p0[:, 2] - rot1)
    a = np.asarray(alpha, dtype=np.float64)
    if noise is not None and len(noise):
        n = np.asarray(noise, dtype=np.float64)
        m1 = rot1 - n[:, 0] * np.sqrt(a[:, 0] * rot1**2 + a[:, 1] * trans**2)
        mt = trans - n[:, 1] * np.sqrt(a[:, 2] * trans**2 + a[:, 3] * rot1**2 + a[:, 3] * rot2**2)
        m2 = rot2 - n[:, 2] * np.sqrt(a[:, 0] * rot2**2 + a[:, 1] * trans**2)
    else:
        m1, mt, m2 = rot1, trans, rot2
    if slip_noise is not None and len(slip_noise):
        sn = np.asarray(slip_noise, dtype=np.float64)
        root = np.sqrt(np.abs(trans))
        mt = mt + sn[:, 0] * np.asarray(slip_m, dtype=np.float64) * root
        half = 0.5 * sn[:, 1] * np.asarray(slip_rad, dtype=np.float64) * root
        m1 = m1 + half
        m2 = m2 + half
    mt = mt * scale
    m1 = m1 + 0.5 * drift_rad
    m2 = m2 + 0.5 * drift_rad
    new = np.stack(
        [pose[:, 0] + mt * np.cos(pose[:, 2] + m1), pose[:, 1] + mt * np.sin(pose[:, 2] + m1),
         wrap_angle(pose[:, 2] + m1 + m2)], axis=1,
    )
    delta = np.stack([mt * np.cos(m1), mt * np.sin(m1), wrap_angle(m1 + m2)], axis=1)
    return new, delta


class Odometry:
    """Odometry of all robots: per-robot parameters unpacked once, one kernel call a step.

    Parameters
    ----------
    configs : sequence of OdometryConfig
        One per robot (robots of a group share their group's).
    start_poses : ndarray of shape (N, 3)
        True start poses (used by ``frame="world"``).
    dt_s : float
        Step [s].
    rng : numpy.random.Generator
        The odometry noise stream.

    Attributes
    ----------
    pose : ndarray of shape (N, 3)
        Believed poses, each in its robot's own odometry frame (engine-owned; copy before
        handing out).
    delta : ndarray of shape (N, 3)
        Last step's measured motion in the previous odometry body frame.
    """

    def __init__(self, configs, start_poses: np.ndarray, dt_s: float, rng: np.random.Generator) -> None:
        n = len(configs)
        start_poses = np.asarray(start_poses, dtype=np.float64)
        if start_poses.shape != (n, 3):
            raise ValueError(f"start_poses must have shape ({n}, 3), got {start_poses.shape}")
        if not (math.isfinite(dt_s) and dt_s > 0):
            raise ValueError(f"dt_s must be a positive finite number of seconds, got {dt_s!r}")
        self.alpha = np.array([c.alpha for c in configs], dtype=np.float64).reshape(n, 4)
        self.drift_rad = np.array([math.radians(c.heading_drift_deg_per_min) * dt_s / 60.0 for c in configs])
        self.scale = np.array([1.0 + c.scale_error for c in configs])
        self.slip_m = np.array([c.slip_std_m_per_sqrt_m for c in configs], dtype=np.float64)
        self.slip_rad = np.array([math.radians(c.heading_slip_deg_per_sqrt_m) for c in configs], dtype=np.float64)
        world = np.array([c.frame == "world" for c in configs], dtype=bool)
        self.pose = np.where(world[:, None], start_poses, 0.0)
        self.delta = np.zeros((n, 3))
        self.rng = rng
        self._noisy = bool(np.any(self.alpha > 0))
        self._noise = np.empty((n, 3)) if self._noisy else np.empty((0, 3))
        self._slipping = bool(np.any(self.slip_m > 0) or np.any(self.slip_rad > 0))
        self._slip_noise = np.empty((n, 2)) if self._slipping else np.empty((0, 2))

    def step(self, x0, y0, th0, x1, y1, th1) -> None:
        """Integrate one step of true motion (before → after) into the believed poses."""
        if self._noisy:
            self.rng.standard_normal(out=self._noise)
        if self._slipping:  # after Table 5.6's draws: runs without slip keep their numbers
            self.rng.standard_normal(out=self._slip_noise)
        odometry_step(x0, y0, th0, x1, y1, th1, self._noise, self.alpha, self.drift_rad, self.scale, self.pose,
                      self.delta, self._slip_noise, self.slip_m, self.slip_rad)
