"""Odometry motion model of MCL: sample new poses from ``P(l | l', a)``.

Fox, Burgard, Kruppa & Thrun, "A probabilistic approach to collaborative multi-robot
localization", §2.2 eq. (6) and §3.1 step 1: every sample ``l'`` is moved by a random draw
from the motion model given the odometry measurement ``a``. The model is the odometry motion
model of Thrun, Burgard & Fox, *Probabilistic Robotics* §5.4, Table 5.6 — the very model the
simulator's odometry (``teamnav.sim.odometry``) draws its noise from, with the same
conventions, so the filter believes what the wheels really do:

- ``a`` is the odometry step ``(dx, dy, dtheta)`` in the previous body frame
  (:attr:`teamnav.control.types.Observation.odom_delta`), decomposed as
  ``d_trans = hypot(dx, dy)``, ``d_rot1 = atan2(dy, dx)``, ``d_rot2 = dtheta - d_rot1``;
- backward motion (``|d_rot1| > pi/2``): ``d_trans`` is negative and ``d_rot1`` flipped by
  pi (small rotations for a reversing robot); a step shorter than 1e-12 m is a pure rotation;
- per particle (Table 5.6, ``N(0, b^2)`` of variance ``b^2``)::

      r1 = d_rot1  - N(0, a1 d_rot1^2 + a2 d_trans^2)
      t  = d_trans - N(0, a3 d_trans^2 + a4 d_rot1^2 + a4 d_rot2^2)
      r2 = d_rot2  - N(0, a1 d_rot2^2 + a2 d_trans^2)
      x += t cos(theta + r1);  y += t sin(theta + r1);  theta = wrap(theta + r1 + r2)

Ref: Thrun, Burgard & Fox, Probabilistic Robotics, MIT Press 2005, Table 5.6.
"""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
from numba import njit, prange
from pydantic import BaseModel, ConfigDict, Field

from teamnav.geometry.angles import wrap_angle
from teamnav.localization._checks import array, generator

__all__ = ["MotionParams", "decompose_odometry", "sample_motion", "sample_motion_reference", "motion_kernel",
           "motion_kernel_serial"]

_HALF_PI = 0.5 * math.pi
_Alpha = Annotated[float, Field(ge=0.0, le=10.0)]
_MIN_TRANS_M = 1e-12


class MotionParams(BaseModel):
    """Table 5.6 noise parameters of the filter's motion model.

    ``alpha = (a1, a2, a3, a4)``: rotation noise from rotation [rad²/rad²], rotation noise
    from translation [rad²/m²], translation noise from translation [m²/m²], translation noise
    from rotation [m²/rad²]. They should be at least the robot's true odometry noise
    (``OdometryConfig.alpha``); a filter usually inflates them a little.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    alpha: tuple[_Alpha, _Alpha, _Alpha, _Alpha] = (0.05, 0.05, 0.05, 0.05)


@njit(cache=True)
def _wrap(a):
    """Wrap one angle to (-pi, pi] (numba twin of :func:`teamnav.geometry.wrap_angle`)."""
    if -math.pi < a <= math.pi:
        return a
    a = a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))
    if a <= -math.pi:
        a += 2.0 * math.pi
    elif a > math.pi:
        a = math.pi
    return a


@njit(cache=True, inline="always")
def _decompose(dx, dy, dth):
    trans = math.sqrt(dx * dx + dy * dy)
    if trans < _MIN_TRANS_M:
        return 0.0, 0.0, _wrap(dth)
    rot1 = math.atan2(dy, dx)
    if rot1 > _HALF_PI or rot1 < -_HALF_PI:  # moving backwards
        trans = -trans
        rot1 = _wrap(rot1 + math.pi)
    return rot1, trans, _wrap(dth - rot1)


@njit(cache=True, inline="always")
def _sigmas(dx, dy, dth, alpha):
    """Table 5.6 lines 2-4 and the three noise deviations: ``(rot1, trans, rot2, s_r1, s_t, s_r2)``."""
    rot1, trans, rot2 = _decompose(dx, dy, dth)
    t2 = trans * trans
    s_r1 = math.sqrt(alpha[0] * rot1 * rot1 + alpha[1] * t2)
    s_t = math.sqrt(alpha[2] * t2 + alpha[3] * rot1 * rot1 + alpha[3] * rot2 * rot2)
    s_r2 = math.sqrt(alpha[0] * rot2 * rot2 + alpha[1] * t2)
    return rot1, trans, rot2, s_r1, s_t, s_r2


@njit(cache=True, inline="always")
def _move(particles, noise, i, rot1, trans, rot2, s_r1, s_t, s_r2):
    """Table 5.6 lines 5-10 for particle ``i``, in place."""
    r1 = rot1 - noise[i, 0] * s_r1
    t = trans - noise[i, 1] * s_t
    r2 = rot2 - noise[i, 2] * s_r2
    th = particles[i, 2]
    particles[i, 0] += t * math.cos(th + r1)
    particles[i, 1] += t * math.sin(th + r1)
    particles[i, 2] = _wrap(th + r1 + r2)


@njit(cache=True, parallel=True)
def motion_kernel(particles, dx, dy, dth, alpha, noise):
    """Move every particle by one draw of Table 5.6, in place.

    Parameters
    ----------
    particles : (n, 3) float64
        Poses ``x [m], y [m], theta [rad]``, updated in place.
    dx, dy, dth : float
        Odometry step in the previous body frame [m, m, rad].
    alpha : (4,) float64
        Table 5.6 parameters.
    noise : (n, 3) float64
        Standard normal draws (rot1, trans, rot2) per particle.
    """
    rot1, trans, rot2, s_r1, s_t, s_r2 = _sigmas(dx, dy, dth, alpha)
    for i in prange(particles.shape[0]):
        _move(particles, noise, i, rot1, trans, rot2, s_r1, s_t, s_r2)


@njit(cache=True)
def motion_kernel_serial(particles, dx, dy, dth, alpha, noise):
    """Serial twin of :func:`motion_kernel` (small calls on busy cores lose milliseconds to a
    thread launch).

    A function of its own, not ``njit(motion_kernel.py_func)``: numba's on-disk cache keys an
    entry by bytecode and signature but not by the ``parallel`` flag, so a twin built from the
    same ``py_func`` shares the parallel kernel's cache file and may load its threaded code.
    """
    rot1, trans, rot2, s_r1, s_t, s_r2 = _sigmas(dx, dy, dth, alpha)
    for i in range(particles.shape[0]):
        _move(particles, noise, i, rot1, trans, rot2, s_r1, s_t, s_r2)


def decompose_odometry(odom_delta) -> tuple[float, float, float]:
    """``(d_rot1 [rad], d_trans [m], d_rot2 [rad])`` of an odometry step (Table 5.6 lines 2–4).

    Examples
    --------
    >>> [round(v, 6) for v in decompose_odometry([0.0, 1.0, 0.0])]
    [1.570796, 1.0, -1.570796]
    >>> [round(v, 6) for v in decompose_odometry([-1.0, 0.0, 0.0])]   # reversing
    [0.0, -1.0, 0.0]
    """
    d = array("odom_delta", odom_delta, (3,))
    return _decompose(float(d[0]), float(d[1]), float(d[2]))


def sample_motion(particles: np.ndarray, odom_delta, params: MotionParams, rng: np.random.Generator) -> np.ndarray:
    """Move ``particles`` (n, 3) in place by samples of ``P(l | l', a)``; return them.

    Draws exactly one ``rng.standard_normal((n, 3))``.

    Examples
    --------
    >>> p = np.zeros((2, 3))
    >>> sample_motion(p, [1.0, 0.0, 0.0], MotionParams(alpha=(0, 0, 0, 0)), np.random.default_rng(0)).tolist()
    [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
    """
    if not (isinstance(particles, np.ndarray) and particles.dtype == np.float64 and particles.ndim == 2
            and particles.shape[1] == 3 and particles.flags.c_contiguous and particles.flags.writeable):
        raise ValueError(f"particles must be a writeable C-contiguous float64 array of shape (n, 3), got "
                         f"{getattr(particles, 'dtype', type(particles).__name__)} {getattr(particles, 'shape', '')}")
    d = array("odom_delta", odom_delta, (3,))
    rng = generator("rng", rng)
    noise = rng.standard_normal((particles.shape[0], 3))
    motion_kernel(particles, float(d[0]), float(d[1]), float(d[2]), np.asarray(params.alpha, dtype=np.float64), noise)
    return particles


def sample_motion_reference(particles, odom_delta, alpha, noise) -> np.ndarray:
    """Pure-NumPy reference of :func:`motion_kernel`; returns new poses (n, 3)."""
    p = np.asarray(particles, dtype=np.float64)
    dx, dy, dth = (float(v) for v in odom_delta)
    trans = math.hypot(dx, dy)
    if trans < _MIN_TRANS_M:
        rot1, trans = 0.0, 0.0
    else:
        rot1 = math.atan2(dy, dx)
        if abs(rot1) > _HALF_PI:
            trans, rot1 = -trans, float(wrap_angle(rot1 + math.pi))
    rot2 = float(wrap_angle(dth - rot1))
    a = np.asarray(alpha, dtype=np.float64)
    n = np.asarray(noise, dtype=np.float64)
    r1 = rot1 - n[:, 0] * math.sqrt(a[0] * rot1**2 + a[1] * trans**2)
    t = trans - n[:, 1] * math.sqrt(a[2] * trans**2 + a[3] * rot1**2 + a[3] * rot2**2)
    r2 = rot2 - n[:, 2] * math.sqrt(a[0] * rot2**2 + a[1] * trans**2)
    return np.stack([p[:, 0] + t * np.cos(p[:, 2] + r1), p[:, 1] + t * np.sin(p[:, 2] + r1),
                     wrap_angle(p[:, 2] + r1 + r2)], axis=1)
