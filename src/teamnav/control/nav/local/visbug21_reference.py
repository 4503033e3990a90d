"""VisBug-21's numpy reference versions: the code that each numba fast path of
:class:`~teamnav.control.nav.local.visbug21.VisBug21` replaced, kept so that the two can be pinned
bit for bit (``tests/test_los_speed_equivalence.py``, ``tests/test_los_speed_kernels.py``) and
timed against each other (``benchmarks/bench_los_brains.py``). No step of a run calls them.

They implement the rules of Lumelsky & Skewis 1990 (VisBug-21, as Sgorbissa & Arkin §6 run it)
that :mod:`teamnav.control.nav.local.visbug21` documents, each next to its kernel in
:mod:`teamnav.control.nav.local.visbug21_geometry`:

- :meth:`VisBugReference._visible`: Step 1's free corridor to an M-line point (and the leave
  test's), every candidate tested (kernels ``_last_visible``, ``_leave_candidates``,
  ``_boundary_pick``);
- :meth:`VisBugReference._followed_numpy` and :meth:`VisBugReference._sensed_ends`: Step 2's
  cut of the scan into obstacles, the one being followed, and its sensed ends for
  ``turn="nearer_end"`` (TangentBug's endpoints, Kamon, Rimon & Rivlin 1998) (``_follow_kernel``);
- :meth:`VisBugReference._leave_point_numpy`: Step 2's leave test (``_leave_candidates``);
- :meth:`VisBugReference._boundary_target_numpy`: Step 2's boundary target, Lumelsky & Skewis'
  farthest visible boundary point (``boundary_shortcut``) (``_boundary_pick``).

A mixin of :class:`~teamnav.control.nav.local.visbug21.VisBug21`, so that a test runs both
versions on one navigator's state (``params``, ``side``, ``mline``, ``goal_xy``, ``hit_dist_m``,
``_follow_ref``, ``_slack``, ...) and the fast path's helpers (``_mline_samples``,
``_boundary_bearings``, ``_run_seen``, ``_nearest_leave_point``).
"""

from __future__ import annotations

import math

import numpy as np

from teamnav.control.nav.local.base import segment_clear
from teamnav.control.nav.local.visbug21_geometry import END_TOL_FRACTION, END_TOL_M, FOLLOW_GAP_M
from teamnav.control.types import RangeScan

__all__ = ["VisBugReference"]


class VisBugReference:
    """The numpy reference versions of :class:`~teamnav.control.nav.local.visbug21.VisBug21`'s
    fast paths (module docstring); a mixin, with no state of its own."""

    def _visible(self, xy: np.ndarray, pts: np.ndarray, cand: np.ndarray, r_safe: float, reach_m: float) -> np.ndarray:
        """Which candidate points the robot reaches through a free corridor of half-width ``r_safe``
        (Step 1, the leave test), every candidate tested: the arithmetic of the kernels
        ``_last_visible``, ``_leave_candidates`` and ``_boundary_pick``."""
        dist = np.hypot(cand[:, 0] - xy[0], cand[:, 1] - xy[1])
        ok = dist <= reach_m
        if ok.any() and pts.shape[0]:
            rng_p = np.hypot(pts[:, 0] - xy[0], pts[:, 1] - xy[1])
            keep = rng_p <= reach_m + 2.0 * r_safe
            idx = np.flatnonzero(ok)
            ok[idx] = segment_clear(pts[keep], xy, cand[idx], r_safe, self._slack * rng_p[keep])
        return ok

    def _followed_numpy(self, pose: np.ndarray, scan: RangeScan) -> np.ndarray:
        """The numpy :meth:`~teamnav.control.nav.local.visbug21.VisBug21._followed` (kept for the
        equivalence tests and the benchmark): the same obstacle cut and choice of the followed
        obstacle, and for ``turn="nearer_end"`` its sensed ends (:meth:`_sensed_ends`); shape (K, 2)."""
        r = np.asarray(scan.ranges_m, dtype=np.float64)
        a = np.asarray(scan.angles_rad, dtype=np.float64)
        order = np.argsort(np.mod(a, 2.0 * math.pi), kind="stable")
        r, a = r[order], a[order]
        hit = r < float(scan.max_range_m) * (1.0 - 1e-9)
        if not hit.any():
            self._follow_ref = None
            return np.zeros((0, 2))
        ang = pose[2] + a
        pts = np.column_stack((pose[0] + r * np.cos(ang), pose[1] + r * np.sin(ang)))
        nxt = np.roll(np.arange(r.size), -1)
        gap = np.hypot(*(pts[nxt] - pts).T)
        allowed = np.maximum(FOLLOW_GAP_M, 2.5 * (2.0 * math.pi / r.size) * np.maximum(r, r[nxt]))
        joined = hit & hit[nxt] & (gap <= allowed)  # beam i joined to beam i+1
        # labels: a new obstacle starts after every break; the wrap-around joins last and first
        labels = np.concatenate(([0], np.cumsum(~joined[:-1])))
        if joined[-1]:
            labels[labels == labels[-1]] = labels[0]
        idx = np.flatnonzero(hit)
        d_robot = np.hypot(pts[idx, 0] - pose[0], pts[idx, 1] - pose[1])
        choice = idx[int(np.argmin(d_robot))]
        if self._follow_ref is not None:
            d_ref = np.hypot(pts[idx, 0] - self._follow_ref[0], pts[idx, 1] - self._follow_ref[1])
            k = int(np.argmin(d_ref))
            if d_ref[k] <= self.step_length_m + FOLLOW_GAP_M:
                choice = idx[k]
        members = idx[labels[idx] == labels[choice]]
        near = members[int(np.argmin(np.hypot(pts[members, 0] - pose[0], pts[members, 1] - pose[1])))]
        self._follow_ref = pts[near].copy()
        if self.params.turn == "nearer_end":
            self._ends = self._sensed_ends(pose[:2], r, ang, hit, joined, near)
        return pts[members]

    @staticmethod
    def _sensed_ends(xy: np.ndarray, r: np.ndarray, ang: np.ndarray, hit: np.ndarray, joined: np.ndarray,
                     start: int):
        """The two sensed ends (counter-clockwise first: the one side +1 walks to) of the
        surface holding beam ``start`` (beams sorted by angle), or None when it is seen all round.

        TangentBug's endpoints (Kamon, Rimon & Rivlin 1998): the surface ends where the range
        jumps *beyond* it. Walking from beam to beam, the surface is the line through the last
        two points; the next beam continues it when it meets that line ahead and reads no
        farther than the line (plus ``END_TOL_M + END_TOL_FRACTION × range``): a wall seen at a
        grazing angle (on the line) and a concave corner (nearer than the line) continue it; a
        door, a jamb's edge (the line turns away from the beam) or a beam without return end
        it. Neighbouring points closer than the following's joining gap always continue it.
        """
        n = r.size
        pts = np.column_stack((xy[0] + r * np.cos(ang), xy[1] + r * np.sin(ang)))
        d = np.column_stack((np.cos(ang), np.sin(ang)))

        def continues(i: int, j: int, k: int) -> bool:
            """Does beam k continue the surface through points j (older) and i (newest)?"""
            if not hit[k]:
                return False
            v = pts[i] - pts[j]
            den = d[k, 0] * v[1] - d[k, 1] * v[0]
            w = pts[i] - xy
            if abs(den) <= 1e-12:
                return False
            r_line = (w[0] * v[1] - w[1] * v[0]) / den
            if not r_line > 0.0:
                return False  # the surface turns away from the beam: a convex edge (a jamb)
            return bool(r[k] <= r_line + END_TOL_M + END_TOL_FRACTION * min(r[k], r_line))

        ends = []
        for step in (1, -1):  # counter-clockwise, then clockwise
            i, j, walked = start, start, 0
            while walked < n:
                k = (i + step) % n
                close = joined[i] if step == 1 else joined[k]
                if not (close and hit[k]) and not (j != i and continues(i, j, k)):
                    break
                j, i, walked = i, k, walked + 1
            if walked >= n:
                return None
            ends.append(pts[i].copy())
        return ends[0], ends[1]

    def _leave_point_numpy(self, pose, scan, points, r_safe, reach_m) -> np.ndarray | None:
        """The numpy :meth:`~teamnav.control.nav.local.visbug21.VisBug21._leave_point` (kept for the
        equivalence tests and the benchmark)."""
        xy = pose[:2]
        cand, t = self._mline_samples(0.0)
        closer = np.hypot(cand[:, 0] - self.goal_xy[0], cand[:, 1] - self.goal_xy[1]) < self.hit_dist_m - self.params.leave_margin_m
        if not closer.any():
            return None
        cand, t = cand[closer], t[closer]
        ok = self._visible(xy, points, cand, r_safe, reach_m)
        idx = np.flatnonzero(ok & (t < 1.0 - 1e-12))
        if idx.size:
            s, g = self.mline
            u = (g - s) / max(math.hypot(*(g - s)), 1e-12)
            run = np.minimum(self.params.leave_run_m, np.hypot(g[0] - cand[idx, 0], g[1] - cand[idx, 1]))
            ahead = cand[idx] + run[:, None] * u
            if points.shape[0]:
                slack = self._slack * np.hypot(points[:, 0] - xy[0], points[:, 1] - xy[1])
                ok[idx] = segment_clear(points, cand[idx], ahead, r_safe - self.params.leave_hysteresis_m, slack)
            keep = ok[idx]
            if keep.any():
                ok[idx[keep]] = self._run_seen(pose, scan, cand[idx[keep]], run[keep], u,
                                               r_safe - self.params.leave_hysteresis_m)
        return self._nearest_leave_point(xy, cand, t, ok)

    def _boundary_target_numpy(self, xy: np.ndarray, followed: np.ndarray, points: np.ndarray, r_safe: float,
                               follow_m: float, reach_m: float) -> np.ndarray | None:
        """The numpy :meth:`~teamnav.control.nav.local.visbug21.VisBug21._boundary_target` (kept for
        the equivalence tests): its rule, with every candidate tested for visibility (:meth:`_visible`)."""
        delta = self._boundary_bearings(xy, followed)
        if delta is None:
            return None
        rel = followed - xy
        nxt = np.concatenate((followed[1:], followed[-1:]))
        prv = np.concatenate((followed[:1], followed[:-1]))
        tx, ty = nxt[:, 0] - prv[:, 0], nxt[:, 1] - prv[:, 1]
        tn = np.maximum(np.hypot(tx, ty), 1e-12)
        nx, ny = -ty / tn, tx / tn
        flip = np.where(nx * rel[:, 0] + ny * rel[:, 1] > 0.0, -1.0, 1.0)  # the normal towards the robot
        cand = followed + follow_m * np.column_stack((flip * nx, flip * ny))
        far = np.hypot(cand[:, 0] - xy[0], cand[:, 1] - xy[1])
        ok = (delta > 0.0) & (far >= self.step_length_m)
        if not ok.any():
            return None
        idx = np.flatnonzero(ok)
        idx = idx[np.argsort(-delta[idx], kind="stable")]
        vis = self._visible(xy, points, cand[idx], r_safe, reach_m)
        if not vis.any():
            return None
        return cand[idx[int(np.argmax(vis))]]
