"""2-D similarity transforms from two common Places.

Vaughan, Støy, Sukhatme & Matarić, "LOST: Localization-space trails for robot teams"
("Try to see it my way"), §2.1.5 *Combining trails*: two Trails that share two Places
``A`` and ``B`` are related by "a simple linear coordinate transform consisting of a
translation, scaling and rotation", the unique ``T`` with ``T(A_α B_α) = A_β B_β``; every
Crumb and every other Place of one Trail is then mapped through ``T`` into the other.

With points as complex numbers ``z = x + iy`` the transform is ``T(z) = a z + b`` with
``a = scale * exp(i rotation)``; two pairs fix ``a = (q2 - q1) / (p2 - p1)`` and
``b = q1 - a p1``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamnav.geometry.angles import wrap_angle

__all__ = ["Similarity", "similarity_from_two_pairs"]

#: Two Places closer than this [m] cannot define a transform (direction undefined).
DEGENERATE_TOL_M: float = 1e-9


@dataclass(frozen=True)
class Similarity:
    """``T(p) = scale * R(rotation_rad) p + (tx, ty)``.

    Parameters
    ----------
    scale : float
        Uniform scale, positive and finite.
    rotation_rad : float
        Rotation [rad], stored wrapped to (-pi, pi].
    tx, ty : float
        Translation [m].

    Examples
    --------
    >>> T = Similarity(2.0, np.pi / 2, 1.0, 0.0)
    >>> T.apply([1.0, 0.0]).round(12).tolist()
    [1.0, 2.0]
    >>> T.inverse().apply(T.apply([0.3, -0.4])).round(12).tolist()
    [0.3, -0.4]
    """

    scale: float = 1.0
    rotation_rad: float = 0.0
    tx: float = 0.0
    ty: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.scale) and self.scale > 0):
            raise ValueError(f"Similarity: scale must be a positive finite number, got {self.scale!r}")
        for name in ("rotation_rad", "tx", "ty"):
            v = getattr(self, name)
            if not math.isfinite(v):
                raise ValueError(f"Similarity: {name} must be finite, got {v!r}")
        object.__setattr__(self, "scale", float(self.scale))
        object.__setattr__(self, "rotation_rad", wrap_angle(float(self.rotation_rad)))
        object.__setattr__(self, "tx", float(self.tx))
        object.__setattr__(self, "ty", float(self.ty))

    @classmethod
    def identity(cls) -> "Similarity":
        """The transform that changes nothing."""
        return cls()

    def apply(self, points) -> np.ndarray:
        """Map points of shape (..., 2) [m]; returns the same shape."""
        p = np.asarray(points, dtype=np.float64)
        if p.ndim < 1 or p.shape[-1] != 2:
            raise ValueError(f"Similarity.apply: points must have shape (..., 2), got shape {p.shape}")
        c = self.scale * math.cos(self.rotation_rad)
        s = self.scale * math.sin(self.rotation_rad)
        x = c * p[..., 0] - s * p[..., 1] + self.tx
        y = s * p[..., 0] + c * p[..., 1] + self.ty
        return np.stack([x, y], axis=-1)

    def apply_heading(self, theta):
        """Map headings [rad] (a scale does not change directions): ``wrap(theta + rotation)``."""
        return wrap_angle(np.add(theta, self.rotation_rad, dtype=np.float64))

    def compose(self, other: "Similarity") -> "Similarity":
        """``self ∘ other``: apply ``other`` first, then ``self``."""
        c = math.cos(self.rotation_rad)
        s = math.sin(self.rotation_rad)
        tx = self.scale * (c * other.tx - s * other.ty) + self.tx
        ty = self.scale * (s * other.tx + c * other.ty) + self.ty
        return Similarity(self.scale * other.scale, self.rotation_rad + other.rotation_rad, tx, ty)

    def inverse(self) -> "Similarity":
        """The transform undoing this one."""
        inv_s = 1.0 / self.scale
        c = math.cos(-self.rotation_rad)
        s = math.sin(-self.rotation_rad)
        tx = -inv_s * (c * self.tx - s * self.ty)
        ty = -inv_s * (s * self.tx + c * self.ty)
        return Similarity(inv_s, -self.rotation_rad, tx, ty)

    def matrix(self) -> np.ndarray:
        """3x3 homogeneous matrix."""
        c = self.scale * math.cos(self.rotation_rad)
        s = self.scale * math.sin(self.rotation_rad)
        return np.array([[c, -s, self.tx], [s, c, self.ty], [0.0, 0.0, 1.0]])


def _point(p, name: str) -> complex:
    arr = np.asarray(p, dtype=np.float64)
    if arr.shape != (2,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"similarity_from_two_pairs: {name} must be a finite point (x_m, y_m), got {p!r}")
    return complex(arr[0], arr[1])


def similarity_from_two_pairs(p1, p2, q1, q2, *, tol_m: float = DEGENERATE_TOL_M) -> Similarity:
    """The similarity ``T`` with ``T(p1) = q1`` and ``T(p2) = q2``.

    Vaughan et al., "Try to see it my way" §2.1.5: ``p1, p2`` are Places A and B in one
    Trail's frame, ``q1, q2`` the same Places in the other Trail's frame.

    Parameters
    ----------
    p1, p2, q1, q2 : array_like of shape (2,)
        Points [m].
    tol_m : float, default 1e-9
        Pairs of points closer than this are degenerate.

    Returns
    -------
    Similarity

    Raises
    ------
    ValueError
        If ``p1`` and ``p2`` (or ``q1`` and ``q2``) coincide within ``tol_m``: the
        rotation is then undefined (or the scale zero).

    Examples
    --------
    >>> T = similarity_from_two_pairs([0, 0], [1, 0], [1, 1], [1, 3])
    >>> T.scale, round(T.rotation_rad, 12), T.tx, T.ty
    (2.0, 1.570796326795, 1.0, 1.0)
    """
    zp1, zp2 = _point(p1, "p1"), _point(p2, "p2")
    zq1, zq2 = _point(q1, "q1"), _point(q2, "q2")
    dp = zp2 - zp1
    dq = zq2 - zq1
    if abs(dp) <= tol_m:
        raise ValueError(
            f"similarity_from_two_pairs: p1 and p2 must be distinct (more than {tol_m} m apart), got p1={p1!r}, p2={p2!r}"
        )
    if abs(dq) <= tol_m:
        raise ValueError(
            f"similarity_from_two_pairs: q1 and q2 must be distinct (more than {tol_m} m apart), got q1={q1!r}, q2={q2!r}"
        )
    a = dq / dp
    b = zq1 - a * zp1
    return Similarity(abs(a), math.atan2(a.imag, a.real), b.real, b.imag)
