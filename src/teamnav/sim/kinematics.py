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

__all__ = ["arc_point", "motion_primitives", "unicycle_arc_reference", "wrap"]

_PI = math.pi
_TWO_PI = 2.0 * math.pi
#: Below this |turn| [rad] an arc is integrated as a straight segment.
STRAIGHT_EPS_RAD: float = 1e-12


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
def arc_point(x, y, th, arc_m, turn_rad, u):
    """Pose after the fraction ``u`` in [0, 1] of an arc from ``(x, y, th)``.

    Returns ``(x_u, y_u, th_u)`` with ``th_u`` not wrapped. Exact circular-arc integration
    of the unicycle (Thrun et al., *Probabilistic Robotics* eq. 5.9).
    """
    phi = u * turn_rad
    if abs(turn_rad) > STRAIGHT_EPS_RAD:
        rho = arc_m / turn_rad
        return (x + rho * (math.sin(th + phi) - math.sin(th)), y - rho * (math.cos(th + phi) - math.cos(th)), th + phi)
    s = u * arc_m
    return (x + s * math.cos(th), y + s * math.sin(th), th + phi)


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
    straight = np.abs(w * dt_s) <= STRAIGHT_EPS_RAD
    safe_w = np.where(straight, 1.0, w)
    xs = np.where(straight, x + v * dt_s * np.cos(th), x + v / safe_w * (np.sin(th + w * dt_s) - np.sin(th)))
    ys = np.where(straight, y + v * dt_s * np.sin(th), y - v / safe_w * (np.cos(th + w * dt_s) - np.cos(th)))
    from teamnav.geometry.angles import wrap_angle

    return np.stack([xs, ys, np.asarray(wrap_angle(th + w * dt_s))], axis=-1)
