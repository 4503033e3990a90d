"""Negative detections: not seeing a teammate where the belief says it should be visible.

Fox, Burgard, Kruppa & Thrun (2000) process positive detections only: §2.3 rule 1 ("Our approach
ignores *negative* sights, i.e., events where a robot does *not* see another robot"), §4.3
("Negative detection events ... are beyond the scope of this paper and will be ignored"), and
§7.2 names them future work: "Not seeing another robot is also informative, even though not as
informative as positive detections. Incorporating such negative detections is generally possible
in the context of our statistical framework (using the inverse weighing scheme). However, such an
extension would drastically increase the computational overhead".

This module is that likelihood, in the form of eq. 14 (a factor per sample of the observer's
belief). Observer ``m`` looks on a camera frame and does *not* detect robot ``n``. For each of its
own samples ``x_i = (x, y, theta)``::

    P(no detection of n | x_i) = 1 - (1 - p_fn) (1 - eps) P_vis(n | x_i)

    P_vis(n | x_i) = sum_j v_j [ |y_j - x_i| <= max_range  and  |bearing(x_i -> y_j)| <= fov / 2
                                 and  the segment x_i -> y_j crosses no cell that stops sight ]

with ``y_j`` a subsample of n's belief (weights ``v_j``, summing to 1), ``p_fn`` the detector's
false-negative rate (Table 2: 6.7 %) and the three conditions the detector's own rules 1-3
(:mod:`teamnav.sim.sensors.detector`): range centre to centre, field of view in the observer's
body frame, line of sight through the same grid kernel (:func:`teamnav.world.los._segment_visible`,
the detector's ray walk) on the observer's *known* map.

Gaps the paper leaves (declared; each is a parameter of the brain, ``mcl-wander-v1``):

1. ``eps`` (``neg_teammate_lost_prior``): the probability that n's belief is wrong. Under "n is
   lost" its belief says nothing about where n is, and n is then almost never where the belief
   puts it, so that branch contributes a factor of about 1. With ``eps`` = 0 the factor is the
   plain marginal (a sample from which n is surely visible keeps ``p_fn`` of its weight).
2. n's belief enters as a subsample of ``K`` points drawn by weight (equal weights ``1 / K``),
   the paper's "very large" sample sets being too costly to send every frame; the factorial
   representation (§2.2) treats it as independent of the observer's belief, as eq. 13 does.
3. The detector's geometry (range, field of view, false-negative rate) is a datasheet the brain
   is given in its parameters, as its detection model (§4.2) is: the brain never reads the
   simulator's detector.

Belief only: own samples, a teammate's broadcast samples, the known map; no true pose.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from teamnav.world.los import _segment_visible

__all__ = ["negative_factors", "visible_mass"]


@njit(cache=True)
def _visible_mass_kernel(px, py, pth, tx, ty, tw, max_r2, half_fov, full, los, blocking, ox, oy, inv, out):
    """``out[i] = sum_j tw[j] [y_j in range, in the field of view and in sight of x_i]`` (kernel frame)."""
    n, k = px.shape[0], tx.shape[0]
    for i in range(n):
        s = 0.0
        c = math.cos(pth[i])
        si = math.sin(pth[i])
        for j in range(k):
            dx = tx[j] - px[i]
            dy = ty[j] - py[i]
            if dx * dx + dy * dy > max_r2:
                continue
            if not full:
                # bearing in the sample's body frame, |atan2(.)| without wrapping
                b = math.atan2(-si * dx + c * dy, c * dx + si * dy)
                if abs(b) > half_fov:
                    continue
            if los and not _segment_visible(blocking, (px[i] - ox) * inv, (py[i] - oy) * inv,
                                            (tx[j] - ox) * inv, (ty[j] - oy) * inv):
                continue
            s += tw[j]
        out[i] = s


def _check_poses(name: str, a, cols: int) -> np.ndarray:
    arr = np.asarray(a, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] < cols:
        raise ValueError(f"{name} must have shape (n, {cols}) or wider, got {arr.shape}")
    if not np.all(np.isfinite(arr[:, :cols])):
        raise ValueError(f"{name} must be finite")
    return arr


def visible_mass(particles, teammate_xy, teammate_w, grid, blocking, max_range_m: float, fov_deg: float,
                 line_of_sight: bool = True) -> np.ndarray:
    """``P_vis(n | x_i)`` for every own sample (module docstring).

    Parameters
    ----------
    particles : ndarray (N, 3)
        The observer's samples ``(x, y, theta)`` [m, m, rad], world frame.
    teammate_xy : ndarray (K, 2)
        Points of teammate n's belief [m], world frame.
    teammate_w : ndarray (K,)
        Their weights, >= 0 (normalised here).
    grid : OccupancyGrid
        The known map (its frame: :meth:`~teamnav.world.grid.OccupancyGrid.kernel_frame`).
    blocking : ndarray (H, W) uint8
        ``grid.blocking(sees)``: the cells that stop the detector's sight.
    max_range_m, fov_deg : float
        The detector's range (centre to centre) and field of view (360: all around).
    line_of_sight : bool
        Test occlusion (the detector's rule 3).

    Returns
    -------
    ndarray (N,)
        In [0, 1].

    Examples
    --------
    >>> from teamnav.world.grid import OccupancyGrid
    >>> g = OccupancyGrid.empty(10, 10, 0.5)
    >>> p = np.array([[1.0, 1.0, 0.0], [1.0, 1.0, np.pi]])
    >>> visible_mass(p, np.array([[3.0, 1.0]]), np.ones(1), g, g.blocking(("wall",)), 5.0, 180.0).tolist()
    [1.0, 0.0]
    """
    p = _check_poses("particles", particles, 3)
    t = _check_poses("teammate_xy", teammate_xy, 2)
    w = np.asarray(teammate_w, dtype=np.float64)
    if w.shape != (t.shape[0],):
        raise ValueError(f"teammate_w must have shape ({t.shape[0]},) like teammate_xy, got {w.shape}")
    if (w < 0).any() or not np.isfinite(w).all() or not w.sum() > 0:
        raise ValueError("teammate_w must be finite, >= 0, with a positive sum")
    if not (math.isfinite(max_range_m) and max_range_m > 0):
        raise ValueError(f"max_range_m must be > 0 [m], got {max_range_m!r}")
    if not (0 < fov_deg <= 360):
        raise ValueError(f"fov_deg must be in (0, 360] [deg], got {fov_deg!r}")
    px, py, ox, oy = grid.kernel_frame(np.ascontiguousarray(p[:, 0]), np.ascontiguousarray(p[:, 1]))
    pth = grid.kernel_theta(np.ascontiguousarray(p[:, 2]))
    tx, ty = grid.kernel_frame(np.ascontiguousarray(t[:, 0]), np.ascontiguousarray(t[:, 1]))[:2]
    out = np.empty(p.shape[0])
    full = fov_deg >= 360.0 - 1e-9
    _visible_mass_kernel(np.ascontiguousarray(px, dtype=np.float64), np.ascontiguousarray(py, dtype=np.float64),
                         np.ascontiguousarray(pth, dtype=np.float64), np.ascontiguousarray(tx, dtype=np.float64),
                         np.ascontiguousarray(ty, dtype=np.float64), np.ascontiguousarray(w / w.sum()),
                         float(max_range_m) ** 2, math.radians(fov_deg) / 2.0, full, bool(line_of_sight),
                         blocking, float(ox), float(oy), 1.0 / grid.resolution_m, out)
    return out


def negative_factors(p_visible: np.ndarray, p_false_negative: float, teammate_lost_prior: float = 0.0) -> np.ndarray:
    """``1 - (1 - p_fn) (1 - eps) P_vis``: the factor eq. 14 multiplies into each own sample.

    >>> negative_factors(np.array([0.0, 0.5, 1.0]), 0.1).round(3).tolist()
    [1.0, 0.55, 0.1]
    """
    for name, v in (("p_false_negative", p_false_negative), ("teammate_lost_prior", teammate_lost_prior)):
        if not (0.0 <= v <= 1.0):
            raise ValueError(f"{name} must be in [0, 1], got {v!r}")
    return 1.0 - (1.0 - p_false_negative) * (1.0 - teammate_lost_prior) * np.asarray(p_visible, dtype=np.float64)
