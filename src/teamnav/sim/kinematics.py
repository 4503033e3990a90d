"""Robot kinematics: what path each robot's command asks for during one step.

Two drive models (``RobotGroupConfig.kinematics``):

``"unicycle"``
    ``(v, omega)`` held for the whole step ``dt``, clipped to ``[-max_v_mps, max_v_mps]``
    and ``[-max_omega, max_omega]``. The path is integrated *exactly*: a circular arc of
    length ``v dt`` turning by ``omega dt`` (a straight segment when ``omega = 0``), not an
    Euler step, so the pose does not depend on ``dt`` beyond the command being constant.
``"holonomic_step"``
    Sgorbissa & Arkin §6 count motion steps: the robot turns on the spot to face the
    body-frame ``Action.direction_rad`` and then moves ``step_length_m`` straight ahead.
    ``direction_rad=None`` (NaN in the arrays) means stay. A holonomic-step robot ignores
    ``v``/``omega``; a unicycle ignores ``direction_rad``.

Both are expressed as one *motion primitive* per robot: an instantaneous turn on the spot
``pre_turn_rad`` followed by an arc of length ``arc_m`` turning by ``turn_rad``. The
collision module moves along that primitive (:mod:`teamnav.sim.collisions`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["arc_point", "motion_primitives", "sinc", "unicycle_arc_reference", "wrap"]

_PI = math.pi
_TWO_PI = 2.0 * math.pi
#: Below this |x| :func:`sinc` uses its Taylor series ``1 - x^2/6 + x^4/120`` (next term
#: x^6/5040 < 2e-28: below the last bit of 1).
SINC_SERIES_BELOW: float = 1e-4


@njit(cache=True, inline="always")
def wrap(a):
    """Wrap an angle to (-pi, pi]; the compiled twin of :func:`teamnav.geometry.angles.wrap_angle`."""
    if a > -_PI and a <= _PI:
        return a
    w = ((a + _PI) % _TWO_PI) - _PI
    if w <= -_PI:
        w += _TWO_PI
    if w > _PI:
        w = _PI
    return w


@njit(cache=True, inline="always")
def sinc(x):
    """``sin(x) / x`` (1 at 0), accurate to the last bits for every x, tiny ones included."""
    if abs(x) < SINC_SERIES_BELOW:
        x2 = x * x
        return 1.0 - x2 / 6.0 + x2 * x2 / 120.0
    return math.sin(x) / x


@njit(cache=True, inline="always")
def arc_point(x, y, th, arc_m, turn_rad, u):
    """Pose after the fraction ``u`` in [0, 1] of an arc from ``(x, y, th)``.

    Returns ``(x_u, y_u, th_u)`` with ``th_u`` not wrapped. Exact circular-arc integration
    of the unicycle (Thrun et al., *Probabilistic Robotics* eq. 5.9), written without its
    cancellation: the arc of length ``s`` turning by ``phi`` ends at the chord of length
    ``s sinc(phi / 2)`` in the direction ``th + phi / 2``. Eq. 5.9's
    ``s/phi (sin(th + phi) - sin(th))`` is the same number in exact arithmetic, but for tiny
    turns it subtracts two nearly equal sines and loses digits (1.8e-6 m at s = 1 m,
    phi = 3.9e-11 rad); the chord form keeps full precision and needs no straight-line
    special case (``phi = 0`` gives exactly ``s cos(th), s sin(th)``).
    """
    phi = u * turn_rad
    half = 0.5 * phi
    chord = (u * arc_m) * sinc(half)
    h = th + half
    return (x + chord * math.cos(h), y + chord * math.sin(h), th + phi)


@njit(cache=True)
def motion_primitives(holonomic, v_cmd, w_cmd, dir_cmd, max_v, max_w, step_m, dt, v_out, w_out, pre_out, arc_out, turn_out):
    """Turn commands into motion primitives for all robots (see the module docstring).

    Parameters
    ----------
    holonomic : (N,) bool
    v_cmd, w_cmd, dir_cmd : (N,) float64
        Commands [m/s], [rad/s], [rad] (NaN direction = stay).
    max_v, max_w, step_m : (N,) float64
        Limits [m/s], [rad/s] and holonomic step length [m].
    dt : float
        Step [s].
    v_out, w_out : (N,) float64
        Applied (clipped) speed and turn rate, written.
    pre_out, arc_out, turn_out : (N,) float64
        Turn on the spot [rad], arc length [m], arc turn [rad], written.
    """
    for i in range(v_cmd.shape[0]):
        if holonomic[i]:
            d = dir_cmd[i]
            if math.isnan(d):
                pre_out[i] = 0.0
                arc_out[i] = 0.0
                v_out[i] = 0.0
                w_out[i] = 0.0
            else:
                d = wrap(d)
                pre_out[i] = d
                arc_out[i] = step_m[i]
                v_out[i] = step_m[i] / dt
                w_out[i] = d / dt
            turn_out[i] = 0.0
        else:
            v = min(max(v_cmd[i], -max_v[i]), max_v[i])
            w = min(max(w_cmd[i], -max_w[i]), max_w[i])
            v_out[i] = v
            w_out[i] = w
            pre_out[i] = 0.0
            arc_out[i] = v * dt
            turn_out[i] = w * dt


def unicycle_arc_reference(x, y, th, v_mps, omega_radps, dt_s):
    """Pure-NumPy reference of one exact unicycle step (for tests), poses wrapped.

    Examples
    --------
    >>> np.round(unicycle_arc_reference(0.0, 0.0, 0.0, 1.0, np.pi / 2, 1.0), 6).tolist()
    [0.63662, 0.63662, 1.570796]
    """
    x, y, th, v, w = (np.asarray(a, dtype=np.float64) for a in (x, y, th, v_mps, omega_radps))
    half = 0.5 * w * dt_s
    half2 = half * half
    small = np.abs(half) < SINC_SERIES_BELOW
    safe = np.where(small, 1.0, half)
    # the same formula as arc_point (the series of sinc below SINC_SERIES_BELOW)
    sinc_half = np.where(small, 1.0 - half2 / 6.0 + half2 * half2 / 120.0, np.sin(safe) / safe)
    chord = v * dt_s * sinc_half
    xs = x + chord * np.cos(th + half)
    ys = y + chord * np.sin(th + half)
    from teamnav.geometry.angles import wrap_angle

    return np.stack([xs, ys, np.asarray(wrap_angle(th + w * dt_s))], axis=-1)
