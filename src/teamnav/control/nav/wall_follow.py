"""Wall following with the sliding-box algorithm on a laser scan.

Vaughan, Støy, Sukhatme & Matarić, *Blazing a trail* §4.2 and Fig. 3 (the low-level controller
reused unchanged in *Try to see it my way* §3.3):

    "A virtual box a little bigger than the robot is placed to the left in the laser scan. The
    box is moved left to right in front of the robot until the laser scan shows no obstacles
    within the box. The robot moves forwards at a constant speed, turning towards the center of
    this box. If there are no obstacles in the first box that is placed it is assumed that the
    robot is in a big open space and therefore moves forward. [...] If no open space is found
    the control system turns the robot in the opposite direction of the nearest obstacle."

Geometry (body frame, x forward, y left, laser at the robot's centre): the box spans
``x in [box_near_m, box_length_m]`` ahead and ``box_width_m`` across; its lateral centre slides from
``+offset_max_m`` (left) to ``-offset_max_m`` (right) in steps of ``slide_step_m``. The robot
keeps the wall at about half a box width (its radius plus the box margin): the box is just
clear of the wall when its centre lies straight ahead.

Gaps the paper leaves open, filled here:

- **Occlusion.** A box is *blocked* when any beam that crosses it ends before leaving it
  (``range < exit distance``): a return inside the box, or an obstacle between the robot and
  the box that hides it. Counting only returns inside the box would call a box behind a wall
  "free" (the laser sees nothing there because the wall hides it).
- **"Big open space".** The robot goes straight when the first (leftmost) box is free *and* the
  box straight ahead is free; when the first box is free but the way ahead is blocked it turns
  towards the first box (a robot crossing an open hall towards a wall would otherwise hit it).
- **Speed.** "Constant speed" while the chosen box lies ahead; the speed scales with the cosine
  of the heading error (at least ``min_speed_fraction``) so sharp steering does not swing the
  robot into the wall; when no box is free it turns on the spot.
- **Near edge.** The box starts ``box_near_m`` (default 0.1 m) ahead of the laser, not at it,
  and returns short of that line (beside the robot) neither block nor hide a box: the end of
  the wall the robot is passing at an opening is not in its way. Counting it made the robot
  curl round every left corner: the passed corner hides the first box while smaller boxes
  further right already fit into the side corridor, so the robot steered into it, and turning
  left made the side beams see more of the passed wall.
- **Hysteresis.** The on-the-spot turn keeps the direction it started with until a box is
  free: the nearest obstacle changes side as the robot turns, and re-deciding every step would
  make it rock in place.
- ``side="right"`` mirrors the rule (slide from the right) for right-hand wall following.

Known limitation: the boxes are aligned with the robot's heading, so a robot closing in on its
wall at an angle (e.g. from the middle of a corridor after a turn) can find a box that fits
diagonally through a door right ahead on that side, and follow it into the room; driving
parallel to the wall it passes doors and side corridors (then the opening rules decide).

Every exit distance is precomputed once per sensor (:func:`box_exit_ranges`), so one step is a
compiled scan (:func:`first_free_box`, stopping at the first free box) with
:meth:`SlidingBox.blocked` as its NumPy reference; no Python loop over beams.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

__all__ = ["BoxCommand", "SlidingBox", "box_exit_ranges", "first_free_box"]


def box_exit_ranges(angles_rad: np.ndarray, x0_m: float, x1_m: float, y0_m: np.ndarray, y1_m: np.ndarray) -> np.ndarray:
    """Distance at which each beam leaves each box, or -inf where it does not cross the box.

    Slab test of rays from the origin along ``angles_rad`` against axis-aligned boxes
    ``[x0_m, x1_m] x [y0_m[k], y1_m[k]]``.

    Parameters
    ----------
    angles_rad : ndarray of shape (B,)
        Beam directions in the body frame [rad].
    x0_m, x1_m : float
        Near and far edges of every box along x [m], ``x0_m < x1_m``.
    y0_m, y1_m : ndarray of shape (K,)
        Right and left edges of each box [m], ``y0_m < y1_m``.

    Returns
    -------
    ndarray of shape (K, B)
        Exit distance [m] of beam b from box k (the ray meets the box in ``(t_in, t_out]``
        with ``t_out > max(t_in, 0)``), else ``-inf`` so that ``range < exit`` never holds.

    Examples
    --------
    >>> t = box_exit_ranges(np.array([0.0, np.pi / 2]), 0.0, 1.0, np.array([-0.5]), np.array([0.5]))
    >>> t.round(6).tolist()
    [[1.0, 0.5]]
    """
    a = np.asarray(angles_rad, dtype=np.float64)[None, :]
    y0 = np.asarray(y0_m, dtype=np.float64)[:, None]
    y1 = np.asarray(y1_m, dtype=np.float64)[:, None]
    c, s = np.cos(a), np.sin(a)
    eps = 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        # x slab (the same for every box)
        tx0, tx1 = x0_m / c, x1_m / c
        tx_in = np.where(np.abs(c) > eps, np.minimum(tx0, tx1), np.where((x0_m <= 0) & (0 <= x1_m), -np.inf, np.inf))
        tx_out = np.where(np.abs(c) > eps, np.maximum(tx0, tx1), np.where((x0_m <= 0) & (0 <= x1_m), np.inf, -np.inf))
        ty0, ty1 = y0 / s, y1 / s
        inside_y = (y0 <= 0) & (0 <= y1)
        ty_in = np.where(np.abs(s) > eps, np.minimum(ty0, ty1), np.where(inside_y, -np.inf, np.inf))
        ty_out = np.where(np.abs(s) > eps, np.maximum(ty0, ty1), np.where(inside_y, np.inf, -np.inf))
    t_in = np.maximum(np.maximum(tx_in, ty_in), 0.0)
    t_out = np.minimum(tx_out, ty_out)
    return np.where(t_out > t_in, t_out, -np.inf)


@njit(cache=True)
def first_free_box(ranges_m: np.ndarray, cos_a: np.ndarray, near_m: float, exit_m: np.ndarray) -> tuple[int, bool]:
    """Slide the box: the first free slide position, and whether the box straight ahead is blocked.

    Kernel twin of :meth:`SlidingBox.blocked` (which is its NumPy reference): box ``k`` of
    ``exit_m`` (rows 0..K-1 in slide order, row K straight ahead) is blocked when a beam whose
    return lies at or beyond the near edge (``range * cos >= near_m``) ends before leaving it.
    Stops at the first free position, so a robot in the open checks one box.

    Returns
    -------
    (int, bool)
        Index of the first free slide position (-1: none), and "straight ahead blocked".
    """
    n_rows, n_beams = exit_m.shape
    first = -1
    for k in range(n_rows - 1):
        free = True
        for b in range(n_beams):
            r = ranges_m[b]
            if r * cos_a[b] >= near_m and r < exit_m[k, b]:
                free = False
                break
        if free:
            first = k
            break
    ahead = False
    for b in range(n_beams):
        r = ranges_m[b]
        if r * cos_a[b] >= near_m and r < exit_m[n_rows - 1, b]:
            ahead = True
            break
    return first, ahead


@dataclass(frozen=True, slots=True)
class BoxCommand:
    """What the sliding box decided this step.

    Attributes
    ----------
    v_mps, omega_radps : float
        The command (speed before the caller's limits).
    offset_m : float
        Lateral centre of the chosen box [m] (left positive); NaN when no box is free.
    state : str
        ``"open"`` (first box and the way ahead free: straight on), ``"follow"`` (turning
        towards the first free box) or ``"blocked"`` (no box free: turning on the spot away
        from the nearest obstacle).
    """

    v_mps: float
    omega_radps: float
    offset_m: float
    state: str


class SlidingBox:
    """The sliding-box wall follower for one laser (Vaughan et al., *Blazing a trail* §4.2, Fig. 3).

    Parameters
    ----------
    angles_rad : ndarray of shape (B,)
        The laser's beam directions in the body frame [rad].
    box_width_m : float
        Box width across the heading [m] ("a little bigger than the robot": the caller passes
        the robot's diameter plus twice a margin).
    box_length_m : float
        Far edge of the box ahead of the robot [m].
    box_near_m : float
        Near edge of the box ahead of the robot [m].
    offset_max_m : float
        Lateral centre of the first (leftmost) box [m]; the box slides to ``-offset_max_m``.
    slide_step_m : float
        Lateral step of the slide [m].
    cruise_speed_mps, steer_gain_per_s, turn_rate_radps, min_speed_fraction : float
        Forward speed; turn rate per radian of heading error to the box centre; the
        on-the-spot turn rate when no box is free; the least fraction of cruise speed while
        steering.
    side : {"left", "right"}
        Which wall the robot follows (the paper: left).
    ahead_must_be_free : bool, default True
        Straight on only when the box straight ahead is free as well as the first box (a
        gap-fill; False: the paper's "no obstacles in the first box ... moves forward").

    Examples
    --------
    >>> angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    >>> box = SlidingBox(angles, 0.8, 1.0, 0.1, 0.8, 0.05, 0.4, 2.0, 1.5, 0.25)
    >>> box.command(np.full(181, 8.0)).state      # nothing in sight: straight on
    'open'
    """

    def __init__(self, angles_rad: np.ndarray, box_width_m: float, box_length_m: float, box_near_m: float,
                 offset_max_m: float,
                 slide_step_m: float, cruise_speed_mps: float, steer_gain_per_s: float, turn_rate_radps: float,
                 min_speed_fraction: float, side: str = "left", *, ahead_must_be_free: bool = True) -> None:
        if side not in ("left", "right"):
            raise ValueError(f"side must be 'left' or 'right', got {side!r}")
        self.angles_rad = np.asarray(angles_rad, dtype=np.float64).copy()
        self.box_width_m = float(box_width_m)
        self.box_length_m = float(box_length_m)
        self.box_near_m = float(box_near_m)
        if not self.box_near_m < self.box_length_m:
            raise ValueError(f"box_near_m must be < box_length_m ({self.box_length_m}), got {self.box_near_m}")
        self.cruise_speed_mps = float(cruise_speed_mps)
        self.steer_gain_per_s = float(steer_gain_per_s)
        self.turn_rate_radps = float(turn_rate_radps)
        self.min_speed_fraction = float(min_speed_fraction)
        self.sign = 1.0 if side == "left" else -1.0
        self.ahead_must_be_free = bool(ahead_must_be_free)
        n = int(math.floor(2.0 * offset_max_m / slide_step_m + 1e-9)) + 1
        # Slide order: first box on the followed side, then towards the other side.
        self.offsets_m = self.sign * (offset_max_m - slide_step_m * np.arange(n))
        half = 0.5 * self.box_width_m
        centres = np.concatenate([self.offsets_m, [0.0]])  # last row: the box straight ahead
        #: (K + 1, B) exit distances; row K is the box straight ahead
        self.exit_m = box_exit_ranges(self.angles_rad, self.box_near_m, self.box_length_m,
                                      centres - half, centres + half)
        self._sin = np.sin(self.angles_rad)
        self._cos = np.cos(self.angles_rad)
        self._away = 0.0  # turn direction kept while no box is free (0: none yet)

    def reset(self) -> None:
        """Forget the kept turn direction."""
        self._away = 0.0

    def blocked(self, ranges_m: np.ndarray) -> np.ndarray:
        """(K + 1,) bool: each slide position (in slide order), then the box straight ahead, blocked.

        Returns that end short of the near edge (beside the robot) neither block nor hide a box.
        """
        r = np.where(ranges_m * self._cos < self.box_near_m, np.inf, ranges_m)
        return (r[None, :] < self.exit_m).any(axis=1)

    def command(self, ranges_m: np.ndarray) -> BoxCommand:
        """The sliding-box command for one scan (``ranges_m`` of shape (B,), no-return = max range).

        Paper rule, *Blazing a trail* §4.2: slide from the followed side until the box is free,
        turn towards its centre; first box free and the way ahead free: straight; no free box:
        turn on the spot away from the nearest obstacle.
        """
        first, ahead_blocked = first_free_box(ranges_m, self._cos, self.box_near_m, self.exit_m)
        if first == 0 and not (ahead_blocked and self.ahead_must_be_free):
            self._away = 0.0
            return BoxCommand(self.cruise_speed_mps, 0.0, float(self.offsets_m[0]), "open")
        if first < 0:
            if self._away == 0.0:
                nearest = int(np.argmin(ranges_m))
                side = self._sin[nearest]
                # Turn away from the nearest obstacle; dead ahead: away from the followed wall.
                self._away = -math.copysign(1.0, side) if abs(side) > 1e-9 else -self.sign
            return BoxCommand(0.0, self._away * self.turn_rate_radps, math.nan, "blocked")
        self._away = 0.0
        offset = float(self.offsets_m[first])
        err = math.atan2(offset, 0.5 * (self.box_near_m + self.box_length_m))
        omega = max(-self.turn_rate_radps, min(self.turn_rate_radps, self.steer_gain_per_s * err))
        v = self.cruise_speed_mps * max(self.min_speed_fraction, math.cos(err))
        return BoxCommand(v, omega, offset, "follow")
