"""Pieces shared by the local navigation algorithms of Sgorbissa & Arkin's set A (§2, §6).

Sgorbissa & Arkin §2: a local navigation algorithm *A* "returns, at each computation step,
what is considered as the best choice for reaching the goal" from the goal and the robot's
current perception only. Here that is :class:`LocalNavigator`: the goal in the robot's own
odometry frame, the pose in that frame, one omnidirectional range scan in the body frame, and
back the heading of the next fixed-length motion step (§6: "at each motion step, the distance
traveled by the simulated robots is fixed, since only the direction of motion changes").

Also here:

- :func:`scan_points` — the scan's returns as obstacle points in the own frame;
- :func:`safe_heading` — the collision guard every navigator applies last: the step's swept
  disc must stay ``hard_clearance_m`` away from every sensed point, else the nearest heading
  (in 5° increments) whose step does is taken. It is a guard against touching a wall (a touch
  stalls the robot in the simulator), not an escape heuristic: it only ever removes headings
  that would hit something;
- :class:`ProgressMonitor` — the "am I progressing?" estimate §5 asks each algorithm for
  (the ``Tr``/``Pr``/``Cr``/``Nt`` counters of §5 are built on top of it by the brains).
"""

from __future__ import annotations

import math
from typing import Protocol, runtime_checkable

import numpy as np
from numba import njit

from teamnav.control.types import RangeScan
from teamnav.geometry import wrap_angle

__all__ = [
    "GOAL_SAME_TOL_M", "LocalNavigator", "ProgressMonitor", "check_goal", "check_pose", "check_scan",
    "corridor_clear", "safe_heading", "scan_points", "seen_free", "segment_clear", "segment_clearance", "wrap_scalar",
]

#: Two goals closer than this [m] are "the same goal" for :meth:`LocalNavigator.set_goal`.
GOAL_SAME_TOL_M: float = 1e-6
#: Angular increment [rad] of the collision guard's search for a safe heading.
GUARD_STEP_RAD: float = math.radians(5.0)


@runtime_checkable
class LocalNavigator(Protocol):
    """A local navigation algorithm *A* of Sgorbissa & Arkin §2 (one robot, own frame).

    Attributes
    ----------
    name : str
        Registry key (``"potential_field"``, ``"avoid_past"``, ``"visbug21"``).
    temporary : bool
        Whether the current goal was set with ``temporary=True``.
    """

    name: str
    temporary: bool

    def set_goal(self, goal_xy: np.ndarray, temporary: bool = False) -> None:
        """Set the current goal ``G_icurr`` (x, y) [m] in the robot's own odometry frame.

        Setting the same goal again (within ``GOAL_SAME_TOL_M``) changes nothing; a different
        goal restarts goal-specific memory (progress estimate, VisBug's M-line and hit point),
        not Avoid-Past's memory of visited places.

        ``temporary=True`` marks an excursion (Sgorbissa & Arkin §3 rule 5 and §4.2: head to a
        teammate or a ghost; §5 rule 3: "R_j temporarily becomes R_i goal"): the task goal's
        memory is suspended, not dropped, and setting the task goal again (non-temporary)
        resumes it. Only VisBug-21 has such memory (M-line, hit point); the potential fields
        restart their progress estimate on every change either way. The default (False) is
        the old behaviour.
        """

    def direction(self, pose: np.ndarray, scan: RangeScan) -> float | None:
        """Heading [rad, own frame, wrapped] of the next fixed-length step, or None to stay.

        ``pose`` is (x [m], y [m], theta [rad]) in the own odometry frame and ``scan`` an
        omnidirectional range scan with beam angles in the body frame. None before any goal
        is set (and, for VisBug-21, once the goal is proved unreachable).
        """

    @property
    def progressing(self) -> bool:
        """After the last :meth:`direction` call: is the robot making progress to the goal (§5)?"""


# ---------------------------------------------------------------------------- fast scalar paths
# Speed only (H7a): these give the same bits as the numpy expressions they replace (same IEEE
# operations in the same order; numba's math.cos/sin/atan2/hypot call the same libm as numpy's
# ufuncs; ``tests/test_los_speed_equivalence.py`` pins them against the numpy versions).
_TWO_PI = 2.0 * math.pi


@njit(cache=True, inline="always")
def pymod(a, b):
    """``np.mod(a, b)`` for floats (numpy's ``npy_divmod``: the result takes the sign of ``b``)."""
    m = np.fmod(a, b)
    if m != 0.0:
        if (b < 0.0) != (m < 0.0):
            m += b
    else:
        m = math.copysign(0.0, b)
    return m


@njit(cache=True, inline="always")
def mod_two_pi(x):
    """``pymod(x, 2π)`` (``np.mod(x, 2π)``, 2π the float ``2.0 * math.pi``), the same bits, without
    ``fmod`` on ``(−2π, 4π)``, where the beam tests' ``angle − bearing + π`` falls: there
    ``fmod`` is ``x`` (``0 < x < 2π``), exactly ``x − 2π`` (``2π ≤ x < 4π``: Sterbenz, the
    difference is exact and equals ``fmod``'s exact result) or ``x`` and then ``+ 2π`` in
    pymod's own sign fix (``−2π < x < 0``); zeros (−0.0 too) give +0.0 as pymod; anything
    else (NaN, far angles) goes through :func:`pymod`."""
    if x > 0.0:
        if x < _TWO_PI:
            return x
        if x < 2.0 * _TWO_PI:
            return x - _TWO_PI
    elif x < 0.0:
        if x > -_TWO_PI:
            return x + _TWO_PI
    elif x == 0.0:
        return 0.0
    return pymod(x, _TWO_PI)


def wrap_scalar(a: float) -> float:
    """``float(wrap_angle(a))`` for one angle, on Python floats (the same operations:
    Python's float ``%`` is numpy's ``np.mod``)."""
    a = float(a)
    if -math.pi < a <= math.pi or a != a:
        return a
    w = (a + math.pi) % _TWO_PI - math.pi
    if w <= -math.pi:
        w += _TWO_PI
    if w > math.pi:
        w = math.pi
    return w


@njit(cache=True)
def corridor_clear(ranges_m, angles_rad, max_range_m, theta_rad, heading_rad, length_m, min_clear_m):
    """Whether a body can travel ``length_m`` from the robot along ``heading_rad`` (own frame)
    keeping ``min_clear_m`` from every return of the scan (beams reading less than
    ``max_range_m · (1 − 1e-9)``); the robot's heading is ``theta_rad``.

    The brains' ``_corridor_clear`` test: for each return at ``rel = angle + (θ − heading)``,
    ``along = r cos rel``, ``across = |r sin rel|``, distance ``hypot(along − clip(along, 0, L),
    across)``; clear when the smallest is at least ``min_clear_m``.
    """
    thr = max_range_m * (1.0 - 1e-9)
    off = theta_rad - heading_rad
    # speed: a return farther than L + min_clear (with a wide margin for rounding) from the
    # robot is at least min_clear from the segment (triangle inequality), so its test passes
    # whatever its bearing; skipping it does not change the answer (a NaN bearing is tested)
    far = length_m + min_clear_m + 1e-9 * (1.0 + length_m + min_clear_m)
    if not (length_m >= 0.0 and min_clear_m >= 0.0):
        far = math.inf
    for i in range(ranges_m.shape[0]):
        r = ranges_m[i]
        if r < thr:
            rel = angles_rad[i] + off
            if r > far and r < 1e6 and rel == rel:
                continue
            along = r * math.cos(rel)
            across = abs(r * math.sin(rel))
            t = along
            if t < 0.0:
                t = 0.0
            if t > length_m:
                t = length_m
            if not math.hypot(along - t, across) >= min_clear_m:
                return False
    return True


# ---------------------------------------------------------------------------- input checks
def check_goal(goal_xy) -> np.ndarray:
    """``goal_xy`` as a finite float (2,) array, or ValueError."""
    g = np.asarray(goal_xy, dtype=np.float64).reshape(-1)
    if g.shape != (2,) or not np.all(np.isfinite(g)):
        raise ValueError(f"goal_xy must be two finite numbers (x, y) in metres, got {goal_xy!r}")
    return g


def check_pose(pose) -> np.ndarray:
    """``pose`` as a finite float (3,) array, or ValueError."""
    if (type(pose) is np.ndarray and pose.dtype == np.float64 and pose.shape == (3,)
            and math.isfinite(pose[0]) and math.isfinite(pose[1]) and math.isfinite(pose[2])):
        return pose
    p = np.asarray(pose, dtype=np.float64).reshape(-1)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ValueError(f"pose must be three finite numbers (x [m], y [m], theta [rad]), got {pose!r}")
    return p


def check_scan(scan) -> RangeScan:
    """``scan`` if it is a RangeScan with matching beams, or ValueError."""
    if not isinstance(scan, RangeScan):
        raise ValueError(f"scan must be a RangeScan, got {type(scan).__name__}")
    r, a = scan.ranges_m, scan.angles_rad
    if type(r) is np.ndarray and type(a) is np.ndarray and r.ndim == 1 and r.shape == a.shape:
        return scan  # the common case, without np.shape / np.ndim calls (the same test)
    if np.shape(scan.ranges_m) != np.shape(scan.angles_rad) or np.ndim(scan.ranges_m) != 1:
        raise ValueError(
            f"scan.ranges_m and scan.angles_rad must be 1-D of one length, got {np.shape(scan.ranges_m)} "
            f"and {np.shape(scan.angles_rad)}"
        )
    return scan


# ---------------------------------------------------------------------------- geometry
def scan_points(pose: np.ndarray, scan: RangeScan) -> np.ndarray:
    """Obstacle points (x, y) [m] in the own frame of every beam that returned.

    Beams reading ``max_range_m`` (no return) give no point.

    Returns
    -------
    ndarray of shape (K, 2), float64

    Examples
    --------
    >>> s = RangeScan(np.array([1.0, 5.0]), np.array([0.0, np.pi]), 5.0)
    >>> scan_points(np.array([1.0, 2.0, np.pi / 2]), s).round(6).tolist()
    [[1.0, 3.0]]
    """
    r = np.ascontiguousarray(scan.ranges_m, dtype=np.float64)
    a = np.ascontiguousarray(scan.angles_rad, dtype=np.float64)
    return _scan_points(float(pose[0]), float(pose[1]), float(pose[2]), r, a, float(scan.max_range_m) * (1.0 - 1e-9))


@njit(cache=True)
def _scan_points(px, py, th, r, a, thr):
    """:func:`scan_points` (numba): ``(px + r cos(th + a), py + r sin(th + a))`` of each r < thr."""
    k = 0
    for i in range(r.shape[0]):
        if r[i] < thr:
            k += 1
    out = np.empty((k, 2))
    k = 0
    for i in range(r.shape[0]):
        if r[i] < thr:
            ang = th + a[i]
            out[k, 0] = px + r[i] * math.cos(ang)
            out[k, 1] = py + r[i] * math.sin(ang)
            k += 1
    return out


def _scan_points_numpy(pose: np.ndarray, scan: RangeScan) -> np.ndarray:
    """The numpy :func:`scan_points` (kept for the equivalence tests and the benchmark)."""
    r = np.asarray(scan.ranges_m, dtype=np.float64)
    a = np.asarray(scan.angles_rad, dtype=np.float64)
    hit = r < float(scan.max_range_m) * (1.0 - 1e-9)
    ang = pose[2] + a[hit]
    return np.column_stack((pose[0] + r[hit] * np.cos(ang), pose[1] + r[hit] * np.sin(ang)))


def segment_clearance(points: np.ndarray, start_xy: np.ndarray, ends_xy: np.ndarray,
                      slack_m: np.ndarray | None = None) -> np.ndarray:
    """Smallest distance [m] from ``points`` (K, 2) to each segment ``start -> ends[j]``.

    Returns ``inf`` per segment when there are no points. With ``slack_m`` (K,), point k
    counts as ``slack_m[k]`` nearer than it is (an obstacle may hide between two beams).

    Parameters
    ----------
    points : ndarray of shape (K, 2)
    start_xy : ndarray of shape (2,) or (J, 2)
        One start for all segments, or one per segment.
    ends_xy : ndarray of shape (J, 2)

    Returns
    -------
    ndarray of shape (J,)

    Examples
    --------
    >>> segment_clearance(np.array([[1.0, 1.0]]), np.zeros(2), np.array([[2.0, 0.0], [0.0, -2.0]])).tolist()
    [1.0, 1.4142135623730951]
    """
    ends_xy = np.atleast_2d(ends_xy)
    if points.shape[0] == 0:
        return np.full(ends_xy.shape[0], np.inf)
    ends = np.asarray(ends_xy, dtype=np.float64)
    starts = np.asarray(start_xy, dtype=np.float64)
    if starts.ndim == 1:
        starts = np.broadcast_to(starts, ends.shape)
    pts = np.asarray(points, dtype=np.float64)
    slack = _NO_SLACK if slack_m is None else np.ascontiguousarray(slack_m, dtype=np.float64)
    return _segment_clearance(pts[:, 0], pts[:, 1], starts[:, 0], starts[:, 1], ends[:, 0], ends[:, 1], slack,
                              slack_m is not None)


_NO_SLACK = np.zeros(0)


def segment_clear(points: np.ndarray, start_xy: np.ndarray, ends_xy: np.ndarray, min_clear_m: float,
                  slack_m: np.ndarray | None = None) -> np.ndarray:
    """``segment_clearance(points, start_xy, ends_xy, slack_m) >= min_clear_m``, stopping at the
    first point that is too close to a segment (the same distances, so the same answers).

    Returns
    -------
    ndarray of shape (J,), bool
    """
    ends = np.atleast_2d(np.asarray(ends_xy, dtype=np.float64))
    if points.shape[0] == 0:
        return np.full(ends.shape[0], np.inf) >= min_clear_m
    starts = np.asarray(start_xy, dtype=np.float64)
    if starts.ndim == 1:
        starts = np.broadcast_to(starts, ends.shape)
    pts = np.asarray(points, dtype=np.float64)
    slack = _NO_SLACK if slack_m is None else np.ascontiguousarray(slack_m, dtype=np.float64)
    return _segment_clear(pts[:, 0], pts[:, 1], starts[:, 0], starts[:, 1], ends[:, 0], ends[:, 1], slack,
                          slack_m is not None, float(min_clear_m))


@njit(cache=True)
def _segment_clear(px, py, sx, sy, ex, ey, slack, has_slack, lim):
    """:func:`segment_clear` (numba): per segment, no point's distance (less its slack) is
    below ``lim`` or NaN."""
    nj = ex.shape[0]
    out = np.empty(nj, dtype=np.bool_)
    for j in range(nj):
        d0 = ex[j] - sx[j]
        d1 = ey[j] - sy[j]
        len2 = d0 * d0 + d1 * d1
        if len2 < 1e-24:
            len2 = 1e-24
        ok = True
        for k in range(px.shape[0]):
            v = _point_segment(px[k], py[k], sx[j], sy[j], d0, d1, len2)
            if has_slack:
                v = v - slack[k]
            if not v >= lim:
                ok = False
                break
        out[j] = ok
    return out


@njit(cache=True, inline="always")
def _point_segment(px, py, sx, sy, d0, d1, len2):
    """Distance from (px, py) to the segment from (sx, sy) along (d0, d1), as
    :func:`segment_clearance` computes it (t clipped to [0, 1])."""
    rx = px - sx
    ry = py - sy
    t = (rx * d0 + ry * d1) / len2
    if t < 0.0:
        t = 0.0
    if t > 1.0:
        t = 1.0
    ex = rx - t * d0
    ey = ry - t * d1
    return math.sqrt(ex * ex + ey * ey)


@njit(cache=True)
def _segment_clearance(px, py, sx, sy, ex, ey, slack, has_slack):
    """:func:`segment_clearance` (numba; the same operations per point and segment, the
    minimum over points propagating NaN as ``ndarray.min``)."""
    nj = ex.shape[0]
    out = np.empty(nj)
    for j in range(nj):
        d0 = ex[j] - sx[j]
        d1 = ey[j] - sy[j]
        len2 = d0 * d0 + d1 * d1
        if len2 < 1e-24 or len2 != len2:
            len2 = 1e-24 if len2 == len2 else len2
        best = np.inf
        for k in range(px.shape[0]):
            v = _point_segment(px[k], py[k], sx[j], sy[j], d0, d1, len2)
            if has_slack:
                v = v - slack[k]
            if v != v:
                best = v
                break
            if v < best:
                best = v
        out[j] = best
    return out


def _segment_clearance_numpy(points: np.ndarray, start_xy: np.ndarray, ends_xy: np.ndarray,
                             slack_m: np.ndarray | None = None) -> np.ndarray:
    """The numpy :func:`segment_clearance` (kept for the equivalence tests and the benchmark)."""
    ends_xy = np.atleast_2d(ends_xy)
    if points.shape[0] == 0:
        return np.full(ends_xy.shape[0], np.inf)
    starts = np.broadcast_to(np.asarray(start_xy, dtype=np.float64), ends_xy.shape)
    d = ends_xy - starts  # (J, 2)
    len2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-24)
    rx = points[:, :1] - starts[:, 0]  # (K, J)
    ry = points[:, 1:] - starts[:, 1]
    t = np.clip((rx * d[:, 0] + ry * d[:, 1]) / len2, 0.0, 1.0)
    dist = np.sqrt((rx - t * d[:, 0]) ** 2 + (ry - t * d[:, 1]) ** 2)
    if slack_m is not None:
        dist = dist - np.asarray(slack_m, dtype=np.float64)[:, None]
    return dist.min(axis=0)


def seen_free(pose: np.ndarray, scan: RangeScan, points_xy: np.ndarray) -> np.ndarray:
    """Which points (own frame) the scan *saw* to be free: in range and not behind a return.

    A point at distance ``d`` and bearing ``b`` from the robot is seen free when ``d`` is within
    the scan's maximum range and the beam nearest ``b`` and both its neighbours read more than
    ``d`` (a wall face the beams hit hides everything behind it; the neighbours guard against a
    corner between two beams). A range sensor tells nothing about the far side of what it hits:
    this is the test for "the robot knows this place is free", as opposed to "no sensed point
    is near it" (:func:`segment_clearance`), which is true of the inside of an unseen wall.

    Parameters
    ----------
    pose : ndarray of shape (3,)
    scan : RangeScan
    points_xy : ndarray of shape (M, 2)

    Returns
    -------
    ndarray of shape (M,), bool

    Examples
    --------
    >>> a = np.linspace(-np.pi, np.pi, 8, endpoint=False)
    >>> s = RangeScan(np.where(np.abs(a) < 1e-9, 1.0, 4.0), a, 4.0)     # a return 1 m ahead
    >>> seen_free(np.zeros(3), s, np.array([[0.5, 0.0], [2.0, 0.0], [0.0, 2.0], [0.0, 4.5]])).tolist()
    [True, False, True, False]
    """
    pts = np.atleast_2d(np.asarray(points_xy, dtype=np.float64))
    r = np.asarray(scan.ranges_m, dtype=np.float64)
    a = np.asarray(scan.angles_rad, dtype=np.float64)
    if pts.shape[0] == 0 or r.size == 0:
        return np.zeros(pts.shape[0], dtype=bool)
    order = np.argsort(np.mod(a, 2.0 * math.pi), kind="stable")
    r, a = r[order], np.mod(a[order], 2.0 * math.pi)
    dx, dy = pts[:, 0] - pose[0], pts[:, 1] - pose[1]
    d = np.hypot(dx, dy)
    b = np.mod(np.arctan2(dy, dx) - pose[2], 2.0 * math.pi)
    # nearest beam in angle (circular)
    k = np.searchsorted(a, b) % r.size
    km = (k - 1) % r.size
    dk = np.abs(np.mod(a[k] - b + math.pi, 2.0 * math.pi) - math.pi)
    dkm = np.abs(np.mod(a[km] - b + math.pi, 2.0 * math.pi) - math.pi)
    i = np.where(dk <= dkm, k, km)
    n = r.size
    least = np.minimum(np.minimum(r[i], r[(i - 1) % n]), r[(i + 1) % n])
    return (d <= float(scan.max_range_m)) & (least > d)


def safe_heading(heading_rad: float, xy: np.ndarray, points: np.ndarray, step_length_m: float,
                 hard_clearance_m: float) -> float:
    """The collision guard: ``heading_rad`` if its step stays clear, else the nearest clear one.

    The step is the segment from ``xy`` of length ``step_length_m``; it is clear when every
    sensed point is at least ``hard_clearance_m`` from it. Otherwise headings ``heading ± k·5°``
    are tried, nearest first (ties: counter-clockwise first); if none is clear the heading whose
    step keeps the largest clearance is returned (with a robot already too close that is the
    step straight away from the nearest point).
    """
    if points.shape[0] == 0:
        return wrap_scalar(heading_rad)
    pts = np.asarray(points, dtype=np.float64)
    h = _safe_heading(float(heading_rad), float(xy[0]), float(xy[1]), pts[:, 0], pts[:, 1], float(step_length_m),
                      float(hard_clearance_m), int(round(math.pi / GUARD_STEP_RAD)), GUARD_STEP_RAD)
    return wrap_scalar(h)


@njit(cache=True)
def _safe_heading(heading, x, y, px, py, step, hard, n, guard):
    """:func:`safe_heading` before wrapping (numba): the headings ``heading + 0, +g, −g, +2g, …``
    in that order, the first whose step is clear, else the one whose end is farthest from the
    points near the robot (first of equals, as ``np.argmax``)."""
    lim = step + hard + 1e-9
    m = 0
    for k in range(px.shape[0]):
        if math.hypot(px[k] - x, py[k] - y) < lim:
            m += 1
    nx = np.empty(m)
    ny = np.empty(m)
    m = 0
    for k in range(px.shape[0]):
        if math.hypot(px[k] - x, py[k] - y) < lim:
            nx[m] = px[k]
            ny[m] = py[k]
            m += 1
    heads = np.empty(2 * n + 1)
    heads[0] = heading + 0.0
    for k in range(1, n + 1):
        heads[2 * k - 1] = heading + k * guard
        heads[2 * k] = heading + (-k) * guard
    best_j = 0
    best_d = -np.inf
    for j in range(2 * n + 1):
        ex = x + step * math.cos(heads[j])
        ey = y + step * math.sin(heads[j])
        d0 = ex - x
        d1 = ey - y
        len2 = d0 * d0 + d1 * d1
        if len2 < 1e-24:
            len2 = 1e-24
        clear = np.inf
        for k in range(m):
            v = _point_segment(nx[k], ny[k], x, y, d0, d1, len2)
            if v != v or v < clear:
                clear = v
                if v != v:
                    break
        if clear >= hard:
            return heading if j == 0 else heads[j]
        # the fallback's score: the nearest point to the step's end (m > 0 here)
        d_end = np.inf
        for k in range(m):
            v = math.hypot(nx[k] - ex, ny[k] - ey)
            if v != v or v < d_end:
                d_end = v
                if v != v:
                    break
        if d_end > best_d or (d_end != d_end and best_d == best_d):
            best_d = d_end
            best_j = j
            if d_end != d_end:
                best_d = d_end
    return heads[best_j]


def _safe_heading_numpy(heading_rad: float, xy: np.ndarray, points: np.ndarray, step_length_m: float,
                        hard_clearance_m: float) -> float:
    """The numpy :func:`safe_heading` (kept for the equivalence tests and the benchmark)."""
    if points.shape[0] == 0:
        return float(wrap_angle(heading_rad))
    near = points[np.hypot(points[:, 0] - xy[0], points[:, 1] - xy[1]) < step_length_m + hard_clearance_m + 1e-9]
    want_end = xy + step_length_m * np.array([[math.cos(heading_rad), math.sin(heading_rad)]])
    if _segment_clearance_numpy(near, xy, want_end)[0] >= hard_clearance_m:
        return float(wrap_angle(heading_rad))
    n = int(round(math.pi / GUARD_STEP_RAD))
    k = np.arange(1, n + 1)
    offs = np.concatenate(([0.0], np.column_stack((k, -k)).reshape(-1) * GUARD_STEP_RAD))
    heads = heading_rad + offs
    ends = xy + step_length_m * np.column_stack((np.cos(heads), np.sin(heads)))
    clear = _segment_clearance_numpy(near, xy, ends)
    ok = np.flatnonzero(clear >= hard_clearance_m)
    if ok.size:
        return float(wrap_angle(heads[ok[0]]))
    d_end = np.hypot(near[:, None, 0] - ends[None, :, 0], near[:, None, 1] - ends[None, :, 1]).min(axis=0)
    return float(wrap_angle(heads[int(np.argmax(d_end))]))


# ---------------------------------------------------------------------------- progress (§5)
class ProgressMonitor:
    """Is the robot getting closer to its goal? (Sgorbissa & Arkin §5, "Evaluate my progress").

    §5 leaves the measure to the algorithm ("in a simple potential field approach ... it is easy
    for the robot to evaluate its progress to the goal and to realize when it is stuck in a
    local minimum"). This one: a *reference distance* starts at the distance when the goal is
    set; whenever the distance to the goal falls below the reference by more than
    ``fraction × step_length_m``, the reference drops to it and the robot counts as having
    progressed at that step. ``progressing`` is True while the last such improvement is at most
    ``window_steps`` steps old (so also for the first ``window_steps`` steps after a new goal).
    A robot oscillating in a local minimum never beats its reference again: after
    ``window_steps`` steps it is not progressing.

    Parameters
    ----------
    window_steps : int
    fraction : float
        Of a step; the least improvement that counts.
    step_length_m : float
    """

    def __init__(self, window_steps: int, fraction: float, step_length_m: float) -> None:
        self.window_steps = int(window_steps)
        self.min_gain_m = float(fraction) * float(step_length_m)
        self.reset()

    def reset(self) -> None:
        """Forget the goal: the next :meth:`update` starts a new reference."""
        self.ref_m = math.inf
        self.steps = 0
        self.last_gain_step = 0

    def update(self, distance_m: float) -> bool:
        """Record one step at ``distance_m`` from the goal; returns :attr:`progressing`."""
        if self.ref_m == math.inf:
            self.ref_m = distance_m
            self.last_gain_step = self.steps
        elif distance_m < self.ref_m - self.min_gain_m:
            self.ref_m = distance_m
            self.last_gain_step = self.steps
        self.steps += 1
        return self.progressing

    @property
    def progressing(self) -> bool:
        return self.steps - 1 - self.last_gain_step <= self.window_steps
