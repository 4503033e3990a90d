"""Corridor (opening) detection on the extreme left and right of a laser scan.

Vaughan, Støy, Sukhatme & Matarić, *Blazing a trail* §4.2:

    "At each time step the behaviour detects corridors to the left and right of the robot using
    the laser scanner. A corridor is identified if the extreme left and rightmost laser samples
    show a nearby obstacle followed by a large discontinuity and an opening wide enough to
    accommodate the robot."

Read here, per side, walking the beams from the outermost one (+90 deg on the left of a
180 deg laser) towards the front:

1. *nearby obstacle followed by a large discontinuity*: within the outermost ``extreme_deg`` of
   the scan, a beam whose range is below ``near_m`` and whose inward neighbour reads more than
   ``jump_m`` further: the near edge of an opening, ``P1``;
2. *an opening wide enough*: the first beam past the jump whose return lies back on the wall
   line (its lateral distance at most ``wall_tolerance_m`` beyond ``P1``'s) is the far edge
   ``P2``; the wall's direction is that of the returns beside the robot up to ``P1`` (the wall
   the opening is cut into; when they span less than ``NEAR_WALL_MIN_M``, from ``P1`` to the
   furthest return back on the wall line); the opening's width is ``P1 -> P2`` measured along the wall (infinite when the wall
   does not come back within the side sector, e.g. a hall), and it counts when at least
   ``min_width_m`` (the robot's diameter plus a margin).

The detection fires while the near edge is beside the robot (the extreme beams), so the
opening's centre lies ``advance_m`` ahead along the wall (``P1 -> P2``): that is where the robot
should make its sharp 90 deg turn, square to the wall (so a robot still angled towards the
wall it follows turns into the corridor, not into the door post). Gaps the paper leaves open:
the three thresholds and the width measure; a passing place shallower than ``jump_m`` is not an
opening.

All per-beam work is NumPy over the side's beams (index arrays precomputed from the sensor's
angles): no Python loop over beams.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

__all__ = ["NEAR_WALL_MIN_M", "Opening", "OpeningDetector", "any_near_edge"]

#: The returns beside the robot up to the near edge give the wall's direction when they span at
#: least this much [m] (see :meth:`OpeningDetector.detect_side`).
NEAR_WALL_MIN_M = 0.2


@njit(cache=True)
def any_near_edge(ranges_m: np.ndarray, head: np.ndarray, near_m: float, jump_m: float) -> bool:
    """True when either side's extreme beams show a nearby return followed by a large jump.

    ``head`` (2, n) holds each side's extreme beam indices, outermost first. The quick test
    before :meth:`OpeningDetector.detect_side` (its NumPy reference) looks closer.
    """
    for s in range(head.shape[0]):
        for j in range(head.shape[1] - 1):
            r0 = ranges_m[head[s, j]]
            if r0 < near_m and ranges_m[head[s, j + 1]] - r0 > jump_m:
                return True
    return False


@dataclass(frozen=True, slots=True)
class Opening:
    """A detected opening (side corridor, door, hall) on one side of the robot.

    Attributes
    ----------
    side : int
        +1 left, -1 right.
    direction_rad : float
        Direction into the opening in the body frame [rad]: square to the wall,
        ``wall_rad + side * pi / 2``.
    wall_rad : float
        Direction of the wall the opening is cut into (from its near to its far edge) in the
        body frame [rad]: 0 when the robot drives parallel to it (or the far edge is not in
        sight); the robot's way straight on along the corridor.
    width_m : float
        Width from the near to the far edge [m] (``inf`` when the far edge is not in sight).
    advance_m : float
        Distance ahead, along the wall, to the opening's centre [m]: drive this far, then
        make the sharp turn into it.
    lateral_m : float
        Lateral distance of the wall whose edge was found [m].
    """

    side: int
    direction_rad: float
    wall_rad: float
    width_m: float
    advance_m: float
    lateral_m: float


class OpeningDetector:
    """Finds openings on the left and right extremes of one laser's scan (*Blazing a trail* §4.2).

    Parameters
    ----------
    angles_rad : ndarray of shape (B,)
        The laser's beam directions in the body frame [rad].
    near_m : float
        An extreme beam shorter than this sees a "nearby obstacle" [m].
    jump_m : float
        A "large discontinuity": the next beam inwards reads at least this much further [m].
    min_width_m : float
        Narrowest opening that "accommodates the robot" [m].
    extreme_deg : float
        How far in from the outermost beam the near edge may lie [deg].
    sector_deg : float
        How far in from the outermost beam the far edge is searched for [deg].
    wall_tolerance_m : float
        A return at most this much further out than the near edge is back on the wall line [m].

    Examples
    --------
    >>> angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    >>> det = OpeningDetector(angles, 2.0, 1.5, 0.7, 20.0, 80.0, 0.4)
    >>> det.detect(np.full(181, 8.0))   # nothing nearby: no opening
    (None, None)
    """

    def __init__(self, angles_rad: np.ndarray, near_m: float, jump_m: float, min_width_m: float,
                 extreme_deg: float, sector_deg: float, wall_tolerance_m: float) -> None:
        a = np.asarray(angles_rad, dtype=np.float64)
        self.near_m = float(near_m)
        self.jump_m = float(jump_m)
        self.min_width_m = float(min_width_m)
        self.wall_tolerance_m = float(wall_tolerance_m)
        self._sides = []
        for side in (1, -1):
            sa = side * a  # angle towards this side
            outer = float(sa.max()) if sa.size else 0.0
            keep = np.flatnonzero(sa >= outer - math.radians(sector_deg))
            order = keep[np.argsort(-sa[keep], kind="stable")]  # outermost first
            n_ext = int(np.count_nonzero(sa[order] >= outer - math.radians(extreme_deg)))
            n_ext = max(0, min(n_ext, order.size - 1))
            self._sides.append((side, order, np.cos(a[order]), side * np.sin(a[order]), n_ext))
        # Both sides' extreme beams in one index array (outermost first), for a quick first test.
        n = max(s[4] for s in self._sides)
        self._quick = n > 0
        if self._quick:
            self._head = np.stack([s[1][: n + 1] if s[4] == n else np.resize(s[1][: s[4] + 1], n + 1)
                                   for s in self._sides])

    def detect_side(self, ranges_m: np.ndarray, k: int) -> Opening | None:
        """The opening on side ``k`` (0 left, 1 right), or None."""
        side, order, cos_a, sin_a, n_ext = self._sides[k]
        if n_ext == 0:
            return None
        r = ranges_m[order]
        head = r[: n_ext + 1]
        cand = np.flatnonzero((head[:-1] < self.near_m) & (np.diff(head) > self.jump_m))
        if cand.size == 0:
            return None
        j = int(cand[0])
        x = r * cos_a
        y = r * sin_a  # lateral distance towards this side
        x1, y1 = float(x[j]), float(y[j])
        on_wall = (y[j + 1:] <= y1 + self.wall_tolerance_m) & (x[j + 1:] > x1)
        back = np.flatnonzero(on_wall)
        if back.size:
            k, last = j + 1 + int(back[0]), j + 1 + int(back[-1])
            # The wall's direction: along the returns beside the robot up to P1 (the wall the
            # opening is cut into), when they span at least NEAR_WALL_MIN_M; else from P1 to the
            # furthest return back on the wall line. (At a T-junction the far "wall" is the
            # crossing corridor's far wall, and P1 -> it runs diagonally: the robot then turned
            # 45 deg instead of 90 and wall-followed into the wrong branch.)
            dx, dy = x1 - float(x[0]), y1 - float(y[0])
            if j == 0 or math.hypot(dx, dy) < NEAR_WALL_MIN_M:
                dx, dy = float(x[last]) - x1, float(y[last]) - y1
            norm = math.hypot(dx, dy)
            ux, uy = (dx / norm, dy / norm) if norm > 1e-9 else (1.0, 0.0)
            wall_rad = side * math.atan2(uy, ux)
            x2, y2 = float(x[k]), float(y[k])
            width = (x2 - x1) * ux + (y2 - y1) * uy
            advance = 0.5 * ((x1 + x2) * ux + (y1 + y2) * uy)
        else:
            width = math.inf
            wall_rad = 0.0
            advance = x1 + 0.5 * self.min_width_m
        if width < self.min_width_m:
            return None
        return Opening(side, wall_rad + side * 0.5 * math.pi, wall_rad, width, max(0.0, advance), y1)

    def detect(self, ranges_m: np.ndarray) -> tuple[Opening | None, Opening | None]:
        """(left, right) openings in one scan (``ranges_m`` of shape (B,), no return = max range)."""
        if not self._quick:
            return None, None
        if not any_near_edge(ranges_m, self._head, self.near_m, self.jump_m):
            return None, None  # the usual case: no near edge in either extreme
        return self.detect_side(ranges_m, 0), self.detect_side(ranges_m, 1)
