"""SE(2) poses: composition, inversion, relative poses and point transforms.

A pose is an array of shape (..., 3) holding ``(x [m], y [m], theta [rad])``: the frame
of a body, expressed in a parent frame. Every function broadcasts over the leading
dimensions, so one call handles all robots or all particles. Angles in results are wrapped
to (-pi, pi] by :func:`teamnav.geometry.angles.wrap_angle`.

Notation: ``compose(a, b)`` is ``a ∘ b``; if ``a`` is frame B in frame A and ``b`` is frame
C in frame B, then ``compose(a, b)`` is frame C in frame A.
"""

from __future__ import annotations

import numpy as np

from teamnav.geometry.angles import wrap_angle

__all__ = ["compose", "inverse", "relative", "transform_points", "to_matrix", "from_matrix", "identity"]


def _pose(p, name: str) -> np.ndarray:
    arr = np.asarray(p, dtype=np.float64)
    if arr.ndim < 1 or arr.shape[-1] != 3:
        raise ValueError(f"{name} must be a pose array of shape (..., 3) holding (x_m, y_m, theta_rad), got shape {arr.shape}")
    return arr


def _points(p, name: str) -> np.ndarray:
    arr = np.asarray(p, dtype=np.float64)
    if arr.ndim < 1 or arr.shape[-1] != 2:
        raise ValueError(f"{name} must be a point array of shape (..., 2) holding (x_m, y_m), got shape {arr.shape}")
    return arr


def identity(shape: tuple[int, ...] = ()) -> np.ndarray:
    """Identity poses, shape ``shape + (3,)`` (all zeros)."""
    return np.zeros(tuple(shape) + (3,))


def compose(a, b) -> np.ndarray:
    """``a ∘ b``: pose ``b`` (given in frame ``a``) expressed in ``a``'s parent frame.

    Parameters
    ----------
    a, b : array_like of shape (..., 3)
        Poses, broadcast together.

    Returns
    -------
    ndarray of shape (..., 3)

    Examples
    --------
    >>> compose([1.0, 0.0, np.pi / 2], [1.0, 0.0, 0.0]).round(12).tolist()
    [1.0, 1.0, 1.570796326795]
    """
    a = _pose(a, "a")
    b = _pose(b, "b")
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    x = a[..., 0] + c * b[..., 0] - s * b[..., 1]
    y = a[..., 1] + s * b[..., 0] + c * b[..., 1]
    th = wrap_angle(a[..., 2] + b[..., 2])
    return np.stack(np.broadcast_arrays(x, y, th), axis=-1)


def inverse(a) -> np.ndarray:
    """The inverse pose: ``compose(a, inverse(a))`` is the identity.

    Parameters
    ----------
    a : array_like of shape (..., 3)

    Returns
    -------
    ndarray of shape (..., 3)

    Examples
    --------
    >>> inverse([1.0, 2.0, np.pi / 2]).round(12).tolist()
    [-2.0, 1.0, -1.570796326795]
    """
    a = _pose(a, "a")
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    x = -(c * a[..., 0] + s * a[..., 1])
    y = -(-s * a[..., 0] + c * a[..., 1])
    th = wrap_angle(-a[..., 2])
    return np.stack([x, y, th], axis=-1)


def relative(a, b) -> np.ndarray:
    """Pose ``b`` expressed in the frame of pose ``a``: ``inverse(a) ∘ b``.

    ``a`` and ``b`` are both given in the same parent frame.

    Examples
    --------
    >>> relative([1.0, 1.0, np.pi / 2], [1.0, 3.0, np.pi / 2]).round(12).tolist()
    [2.0, 0.0, 0.0]
    """
    return compose(inverse(_pose(a, "a")), _pose(b, "b"))


def transform_points(pose, pts) -> np.ndarray:
    """Map points given in the frame of ``pose`` into the pose's parent frame.

    Parameters
    ----------
    pose : array_like of shape (..., 3)
    pts : array_like of shape (..., 2)
        Broadcast with ``pose`` over the leading dimensions (one pose and ``(N, 2)``
        points works; for ``M`` poses and ``N`` points each give ``(M, 1, 3)`` and
        ``(M, N, 2)``).

    Returns
    -------
    ndarray of shape (..., 2)

    Examples
    --------
    >>> transform_points([1.0, 0.0, np.pi / 2], [[1.0, 0.0], [0.0, 1.0]]).round(12).tolist()
    [[1.0, 1.0], [0.0, 0.0]]
    """
    pose = _pose(pose, "pose")
    pts = _points(pts, "pts")
    c, s = np.cos(pose[..., 2]), np.sin(pose[..., 2])
    x = pose[..., 0] + c * pts[..., 0] - s * pts[..., 1]
    y = pose[..., 1] + s * pts[..., 0] + c * pts[..., 1]
    return np.stack([x, y], axis=-1)


def to_matrix(pose) -> np.ndarray:
    """3x3 homogeneous matrices, shape (..., 3, 3), of poses (..., 3).

    Examples
    --------
    >>> to_matrix([1.0, 2.0, 0.0]).tolist()
    [[1.0, -0.0, 1.0], [0.0, 1.0, 2.0], [0.0, 0.0, 1.0]]
    """
    pose = _pose(pose, "pose")
    c, s = np.cos(pose[..., 2]), np.sin(pose[..., 2])
    m = np.zeros(pose.shape[:-1] + (3, 3))
    m[..., 0, 0] = c
    m[..., 0, 1] = -s
    m[..., 0, 2] = pose[..., 0]
    m[..., 1, 0] = s
    m[..., 1, 1] = c
    m[..., 1, 2] = pose[..., 1]
    m[..., 2, 2] = 1.0
    return m


def from_matrix(m) -> np.ndarray:
    """Poses (..., 3) from homogeneous matrices (..., 3, 3); the angle is read from the
    first column with ``atan2`` (a not exactly orthonormal rotation is projected).

    Examples
    --------
    >>> from_matrix(to_matrix([1.0, 2.0, 0.5])).round(12).tolist()
    [1.0, 2.0, 0.5]
    """
    m = np.asarray(m, dtype=np.float64)
    if m.ndim < 2 or m.shape[-2:] != (3, 3):
        raise ValueError(f"m must be homogeneous matrices of shape (..., 3, 3), got shape {m.shape}")
    th = wrap_angle(np.arctan2(m[..., 1, 0], m[..., 0, 0]))
    return np.stack(np.broadcast_arrays(m[..., 0, 2], m[..., 1, 2], th), axis=-1)
