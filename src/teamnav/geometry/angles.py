"""Angles: wrapping to (-pi, pi], differences and circular means.

Every angle in teamnav is in radians and, once wrapped, lies in the half-open interval
(-pi, pi] (ROS REP 103). This module is the single place that wraps angles.
"""

from __future__ import annotations

import numpy as np

__all__ = ["wrap_angle", "angle_diff", "mean_angle"]

_TWO_PI = 2.0 * np.pi


def wrap_angle(a):
    """Wrap angles to (-pi, pi].

    Angles already in (-pi, pi] are returned unchanged (so wrapping is idempotent,
    bit for bit); others are shifted by a multiple of 2*pi. ``-pi`` maps to ``pi``.
    NaN stays NaN.

    Parameters
    ----------
    a : float or array_like
        Angles [rad].

    Returns
    -------
    float or ndarray
        A Python float for a scalar input, else an array of the input's shape.

    Examples
    --------
    >>> wrap_angle(3 * np.pi / 2) == -np.pi / 2
    True
    >>> wrap_angle(-np.pi) == np.pi
    True
    >>> wrap_angle([0.0, 2 * np.pi + 0.5]).round(6).tolist()
    [0.0, 0.5]
    """
    arr = np.asarray(a, dtype=np.float64)
    inside = (arr > -np.pi) & (arr <= np.pi)
    w = np.mod(arr + np.pi, _TWO_PI) - np.pi  # [-pi, pi] up to rounding
    w = np.where(w <= -np.pi, w + _TWO_PI, w)
    w = np.where(w > np.pi, np.pi, w)  # rounding guard: mod can return 2*pi for tiny negatives
    out = np.where(inside, arr, w)
    if out.ndim == 0:
        return float(out)
    return out


def angle_diff(a, b):
    """Signed smallest rotation from ``b`` to ``a``: ``wrap_angle(a - b)`` in (-pi, pi].

    Parameters
    ----------
    a, b : float or array_like
        Angles [rad], broadcast together.

    Examples
    --------
    >>> round(angle_diff(np.pi - 0.1, -np.pi + 0.1), 12)
    -0.2
    """
    return wrap_angle(np.subtract(a, b, dtype=np.float64))


def mean_angle(angles, weights=None, axis=None):
    """Circular mean: the direction of the (weighted) sum of unit vectors.

    ``atan2(sum(w * sin a), sum(w * cos a))``. Vaughan et al. ("Blazing a trail")
    steer along "the average heading of all those crumbs that lie within a threshold
    radius of its current position estimate" (§4.1, trail laying algorithm); this is that average.

    Parameters
    ----------
    angles : array_like
        Angles [rad].
    weights : array_like, optional
        Non-negative weights broadcastable to ``angles``; default all 1.
    axis : int, optional
        Axis to average over; default all elements.

    Returns
    -------
    float or ndarray
        Mean angle in (-pi, pi]. NaN where the unit vectors cancel out (resultant length
        below 1e-12 of the total weight), where the mean direction is undefined.

    Raises
    ------
    ValueError
        If ``angles`` is empty, or ``weights`` has a negative or non-finite entry.

    Examples
    --------
    >>> round(mean_angle([np.pi - 0.1, -np.pi + 0.1]), 12) == round(np.pi, 12)
    True
    >>> round(mean_angle([0.0, np.pi / 2], weights=[3.0, 1.0]), 6)
    0.321751
    """
    a = np.asarray(angles, dtype=np.float64)
    if a.size == 0:
        raise ValueError("mean_angle: angles must not be empty, got an empty array")
    if weights is None:
        w = np.ones_like(a)
    else:
        w = np.broadcast_to(np.asarray(weights, dtype=np.float64), a.shape)
        if not np.all(np.isfinite(w)) or np.any(w < 0):
            raise ValueError(f"mean_angle: weights must be finite and >= 0, got {np.asarray(weights)!r}")
    s = np.sum(w * np.sin(a), axis=axis)
    c = np.sum(w * np.cos(a), axis=axis)
    total = np.sum(w, axis=axis)
    out = wrap_angle(np.arctan2(s, c))
    degenerate = np.hypot(s, c) <= 1e-12 * np.maximum(total, np.finfo(float).tiny)
    out = np.where(degenerate, np.nan, out)
    if np.ndim(out) == 0:
        return float(out)
    return out
