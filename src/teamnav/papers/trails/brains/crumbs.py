"""Crumbs of (position, heading) in odometric space: private and global crumb lists.

Vaughan, Støy, Sukhatme & Matarić, "Blazing a trail: insect-inspired resource transportation
by a robot team" (DARS 2000), §4.1 *Trail laying algorithm* and its Fig. 2:

- "As it moves through the environment each robot records its current position and heading
  estimate at regular time intervals. We refer to this as 'crumb dropping'" — crumbs go to an
  initially empty **private** list (:class:`CrumbList`).
- "Whenever a robot reaches the resource it announces the contents of its private crumb list on
  the broadcast channel ... All the robots (including the sender) receive the crumbs and add them
  to their initially empty **global** crumb list. The sender's private crumb list is cleared."
  (the "waggle dance"; the message body is :class:`CrumbBatch`). "On reaching home a robot also
  broadcasts and clears its private list."
- "At each timestep each robot examines its global crumb list and computes the average heading
  of all those crumbs that lie within a threshold radius of its current position estimate"
  (:func:`average_heading`, a circular mean). "If a robot is carrying resource ... it will follow
  the opposite heading back to the home position" (:func:`preferred_heading`).

Crumbs are dropped on both legs, and the average of the headings of an outbound and a homebound
crumb at one spot would cancel. So a crumb dropped while *carrying* stores the opposite of the
robot's heading (``outbound=False`` in :meth:`CrumbList.drop`): every crumb in every list points
*towards the source*, and a carrying robot follows the opposite of the average. The 2000 paper
does not say so, but its authors describe the method so in the 2002 paper (Try §1: "a single
crumb trail. The trail was followed forwards towards the 'goal' and backwards towards 'home'"),
and a single trail followed backwards works only if every crumb points goal-ward: it is the
paper's rule in both report columns. The brain's ``reverse_carried_crumbs`` flag turns it off
(``outbound=True`` for every crumb: Blazing §4.1 read literally, an ablation row of the reports).

Everything is in the robot's own odometry frame; the lists are numpy arrays (a global list
holds thousands of crumbs) and every query is vectorised.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


__all__ = ["CrumbBatch", "CrumbList", "average_heading", "preferred_heading"]


def _wrap_scalar(a_rad: float) -> float:
    """Scalar twin of :func:`teamnav.geometry.angles.wrap_angle` for the per-step path: (-pi, pi]."""
    w = math.remainder(a_rad, 2.0 * math.pi)
    return math.pi if w == -math.pi else w


@dataclass(frozen=True)
class CrumbBatch:
    """A waggle-dance message body: a robot's private crumbs (Blazing §4.1).

    Attributes
    ----------
    xy_m : ndarray of shape (k, 2), float64
        Crumb positions in the sender's odometry frame [m].
    heading_rad : ndarray of shape (k,), float64
        Crumb headings [rad], each pointing towards the source (see the module docstring).
    """

    xy_m: np.ndarray
    heading_rad: np.ndarray

    def __post_init__(self) -> None:
        xy = np.asarray(self.xy_m, dtype=np.float64).reshape(-1, 2)
        h = np.asarray(self.heading_rad, dtype=np.float64).reshape(-1)
        if xy.shape[0] != h.shape[0]:
            raise ValueError(f"CrumbBatch: xy_m has {xy.shape[0]} rows but heading_rad has {h.shape[0]}")
        object.__setattr__(self, "xy_m", xy)
        object.__setattr__(self, "heading_rad", h)

    def __len__(self) -> int:
        return int(self.heading_rad.shape[0])


class CrumbList:
    """A growable list of crumbs (x [m], y [m], heading [rad]) in one robot's odometry frame.

    Used for both the private and the global list of Blazing §4.1. Storage is a numpy buffer that
    doubles when full, so appending is amortised O(1) and queries see contiguous arrays.

    Parameters
    ----------
    max_crumbs : int or None, default None
        Keep at most this many crumbs, dropping the oldest (None: unbounded, as in the paper).

    Examples
    --------
    >>> c = CrumbList()
    >>> c.drop(1.0, 2.0, 0.5)
    >>> c.drop(3.0, 2.0, 0.5, outbound=False)   # carrying: stored pointing back to the source
    >>> len(c), c.heading_rad.round(3).tolist()
    (2, [0.5, -2.642])
    """

    def __init__(self, max_crumbs: int | None = None) -> None:
        if max_crumbs is not None and (not isinstance(max_crumbs, int) or max_crumbs < 1):
            raise ValueError(f"max_crumbs must be None or an int >= 1, got {max_crumbs!r}")
        self.max_crumbs = max_crumbs
        self._buf = np.empty((64, 4), dtype=np.float64)  # x, y, heading, odometric path length
        self._n = 0

    def __len__(self) -> int:
        return self._n

    @property
    def xy_m(self) -> np.ndarray:
        """Positions, shape (n, 2) [m] (a view; do not keep it across appends)."""
        return self._buf[: self._n, :2]

    @property
    def heading_rad(self) -> np.ndarray:
        """Headings, shape (n,) [rad] (a view)."""
        return self._buf[: self._n, 2]

    def _reserve(self, extra: int) -> None:
        need = self._n + extra
        if need > self._buf.shape[0]:
            cap = max(need, 2 * self._buf.shape[0])
            buf = np.empty((cap, 4), dtype=np.float64)
            buf[: self._n] = self._buf[: self._n]
            self._buf = buf

    def _trim(self) -> None:
        if self.max_crumbs is not None and self._n > self.max_crumbs:
            drop = self._n - self.max_crumbs
            self._buf[: self.max_crumbs] = self._buf[drop: self._n]
            self._n = self.max_crumbs

    @property
    def path_m(self) -> np.ndarray:
        """Odometric path length at each crumb, shape (n,) [m] (0 for received crumbs; a view)."""
        return self._buf[: self._n, 3]

    def drop(self, x_odom_m: float, y_odom_m: float, heading_rad: float, *, outbound: bool = True,
             path_m: float = 0.0) -> None:
        """Drop one crumb at the robot's pose estimate (Blazing §4.1 "crumb dropping").

        ``outbound=False`` (the robot carries resource, heading home) stores the opposite
        heading, so every crumb points towards the source (module docstring). ``path_m`` is the
        robot's odometric path length so far [m] (for :meth:`drop_pruning_loops`).
        """
        self._reserve(1)
        h = heading_rad if outbound else heading_rad + math.pi
        self._buf[self._n] = (x_odom_m, y_odom_m, _wrap_scalar(h), path_m)
        self._n += 1
        self._trim()

    def drop_pruning_loops(self, x_odom_m: float, y_odom_m: float, heading_rad: float, *, outbound: bool,
                           path_m: float, radius_m: float, min_loop_m: float) -> bool:
        """Drop a crumb unless the robot is back near its own earlier crumb: then cut the loop.

        Gap filled here (the paper does not prune): a private list with loops (a room circled,
        a dead end entered and left) broadcasts a vortex or a back-and-forth of headings, and
        robots averaging them circle or dither. If a crumb of this list lies within
        ``radius_m`` of the robot and at least ``min_loop_m`` of odometric path behind it, the
        crumbs after the earliest such crumb are deleted and no crumb is dropped: the list keeps
        the loop-free path (what the paper means by "the most time efficient path yet
        discovered", Blazing §4.1).

        Returns
        -------
        bool
            True when a loop was cut.
        """
        if self._n:
            b = self._buf[: self._n]
            dx = b[:, 0] - x_odom_m
            dy = b[:, 1] - y_odom_m
            back = (dx * dx + dy * dy <= radius_m * radius_m) & (b[:, 3] <= path_m - min_loop_m)
            if back.any():
                self._n = int(np.argmax(back)) + 1
                return True
        self.drop(x_odom_m, y_odom_m, heading_rad, outbound=outbound, path_m=path_m)
        return False

    def extend(self, batch: CrumbBatch) -> None:
        """Append a received batch (the global list's "add them", Blazing §4.1)."""
        k = len(batch)
        if k == 0:
            return
        self._reserve(k)
        self._buf[self._n: self._n + k, :2] = batch.xy_m
        self._buf[self._n: self._n + k, 2] = batch.heading_rad
        self._buf[self._n: self._n + k, 3] = 0.0
        self._n += k
        self._trim()

    def to_batch(self) -> CrumbBatch:
        """A copy of the list as a message body."""
        return CrumbBatch(self.xy_m.copy(), self.heading_rad.copy())

    def clear(self) -> None:
        """Empty the list (the sender's private list after its broadcast, Blazing §4.1)."""
        self._n = 0

    def average_heading(self, x_odom_m: float, y_odom_m: float, radius_m: float) -> float | None:
        """:func:`average_heading` over this list."""
        return average_heading(self.xy_m, self.heading_rad, x_odom_m, y_odom_m, radius_m)

    def nearest(self, x_odom_m: float, y_odom_m: float, radius_m: float) -> tuple[float, float] | None:
        """Position (x, y) [m] of the crumb nearest to (x, y) within ``radius_m`` (inclusive), or None.

        Examples
        --------
        >>> c = CrumbList()
        >>> c.drop(0.0, 0.0, 0.0); c.drop(3.0, 0.0, 0.0)
        >>> c.nearest(2.0, 0.5, 5.0), c.nearest(9.0, 0.0, 5.0)
        ((3.0, 0.0), None)
        """
        if self._n == 0:
            return None
        dx = self._buf[: self._n, 0] - x_odom_m
        dy = self._buf[: self._n, 1] - y_odom_m
        d2 = dx * dx + dy * dy
        i = int(np.argmin(d2))
        if d2[i] > radius_m * radius_m:
            return None
        return float(self._buf[i, 0]), float(self._buf[i, 1])

    def count_near(self, x_odom_m: float, y_odom_m: float, radius_m: float) -> int:
        """How many crumbs lie within ``radius_m`` (inclusive) of (x, y)."""
        if self._n == 0:
            return 0
        dx = self._buf[: self._n, 0] - x_odom_m
        dy = self._buf[: self._n, 1] - y_odom_m
        return int(np.count_nonzero(dx * dx + dy * dy <= radius_m * radius_m))


def average_heading(xy_m: np.ndarray, heading_rad: np.ndarray, x_odom_m: float, y_odom_m: float,
                    radius_m: float) -> float | None:
    """Circular mean heading of the crumbs within ``radius_m`` of (x, y) (Blazing §4.1).

    "computes the average heading of all those crumbs that lie within a threshold radius of its
    current position estimate". The mean is the direction of the sum of unit vectors
    (``atan2(sum sin, sum cos)``), so headings either side of ±pi average correctly.

    Parameters
    ----------
    xy_m : ndarray of shape (n, 2)
        Crumb positions [m].
    heading_rad : ndarray of shape (n,)
        Crumb headings [rad].
    x_odom_m, y_odom_m : float
        The robot's position estimate [m], same frame.
    radius_m : float
        Neighbourhood radius [m] (inclusive), > 0.

    Returns
    -------
    float or None
        Mean heading in (-pi, pi], or None when no crumb is within the radius or the headings
        cancel out (the robot then explores).

    Examples
    --------
    >>> xy = np.array([[0.0, 0.0], [1.0, 0.0], [9.0, 0.0]])
    >>> h = np.array([np.pi - 0.1, -np.pi + 0.1, 0.0])
    >>> round(abs(average_heading(xy, h, 0.5, 0.0, 2.0)), 6) == round(np.pi, 6)
    True
    >>> average_heading(xy, h, 5.0, 5.0, 1.0) is None
    True
    """
    if not (radius_m > 0 and math.isfinite(radius_m)):
        raise ValueError(f"radius_m must be a positive finite number of metres, got {radius_m!r}")
    if xy_m.shape[0] == 0:
        return None
    dx = xy_m[:, 0] - x_odom_m
    dy = xy_m[:, 1] - y_odom_m
    near = dx * dx + dy * dy <= radius_m * radius_m
    if not near.any():
        return None
    h = heading_rad[near]
    s = float(np.sin(h).sum())
    c = float(np.cos(h).sum())
    if math.hypot(s, c) <= 1e-9 * h.shape[0]:
        return None
    return _wrap_scalar(math.atan2(s, c))


def preferred_heading(mean_heading_rad: float | None, carrying: bool) -> float | None:
    """The heading to prefer: the crumbs' mean when seeking the source, its opposite when
    carrying resource home (Blazing §4.1); None when there is no mean.

    Examples
    --------
    >>> round(preferred_heading(0.25, carrying=True), 12) == round(0.25 - np.pi, 12)
    True
    """
    if mean_heading_rad is None:
        return None
    return _wrap_scalar(mean_heading_rad + math.pi) if carrying else _wrap_scalar(mean_heading_rad)
