"""VisBug-21's boundary geometry on a range scan: the heading that follows a boundary, and the
numba kernels behind :class:`~teamnav.control.nav.local.visbug21.VisBug21`'s obstacle cut and
sensed ends (Lumelsky & Skewis 1990, as used by Sgorbissa & Arkin §6; the rules are documented in
:mod:`teamnav.control.nav.local.visbug21`). Split from that module to keep the algorithm's state
machine and these per-beam loops apart; each kernel is pinned bit for bit against the numpy code
it replaced (kept in :mod:`teamnav.control.nav.local.visbug21_reference`) by
``tests/test_los_speed_equivalence.py`` and ``tests/test_los_speed_kernels.py``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["END_TOL_FRACTION", "END_TOL_M", "FOLLOW_GAP_M", "boundary_heading"]

#: Two neighbouring beams' points closer than this [m] (or 2.5 beam gaps) lie on one obstacle.
FOLLOW_GAP_M: float = 0.3
#: ``turn="nearer_end"``: a beam reading up to this much beyond the surface's line continues it [m] ...
END_TOL_M: float = 0.1
#: ... plus this fraction of the range.
END_TOL_FRACTION: float = 0.1


def boundary_heading(xy: np.ndarray, points: np.ndarray, follow_distance_m: float, side: int,
                     gain: float) -> float | None:
    """Heading [rad] that follows the boundary through the nearest sensed point.

    ``side = +1`` keeps the obstacle on the right, ``-1`` on the left. The heading is the
    tangent at the nearest point, turned away from the obstacle by
    ``gain · (follow_distance − d) / follow_distance`` (clipped to ±60°) when closer than
    ``follow_distance_m`` and towards it when farther. None when nothing is sensed.

    Examples
    --------
    >>> pts = np.array([[0.0, -0.5], [1.0, -0.5]])   # a wall 0.5 m to the right
    >>> round(boundary_heading(np.zeros(2), pts, 0.5, +1, 1.5), 6)
    0.0
    """
    if points.shape[0] == 0:
        return None
    pts = np.asarray(points, dtype=np.float64)
    # speed (H7a): the nearest point in a kernel (same squared distances, first of equals)
    i, d2 = _nearest_sq(pts[:, 0], pts[:, 1], float(xy[0]), float(xy[1]))
    rx, ry = float(pts[i, 0] - xy[0]), float(pts[i, 1] - xy[1])
    d = math.sqrt(d2)
    err = max(-1.0, min(1.0, (follow_distance_m - d) / follow_distance_m))
    corr = max(-math.pi / 3, min(math.pi / 3, gain * err))
    return math.atan2(ry, rx) + side * (0.5 * math.pi + corr)


@njit(cache=True)
def _nearest_sq(px, py, x, y):
    """(index, squared distance) of the point nearest (x, y): ``np.argmin`` of
    ``einsum("ij,ij->i", rel, rel)`` with ``rel = points − xy``."""
    best = 0
    rx = px[0] - x
    ry = py[0] - y
    best_d2 = rx * rx + ry * ry
    if best_d2 == best_d2:
        for k in range(1, px.shape[0]):
            rx = px[k] - x
            ry = py[k] - y
            d2 = rx * rx + ry * ry
            if d2 != d2:
                return k, d2
            if d2 < best_d2:
                best, best_d2 = k, d2
    return best, best_d2


@njit(cache=True)
def _nearest_hit(pts, hit, x, y):
    """Index of the returned beam (``hit``) whose point is nearest to (x, y), and that distance
    (the first of equals; -1 and inf when no beam returned)."""
    k = -1
    best = np.inf
    for i in range(pts.shape[0]):
        if hit[i]:
            d = math.hypot(pts[i, 0] - x, pts[i, 1] - y)
            if k < 0 or d < best:
                k, best = i, d
    return k, best


@njit(cache=True)
def _follow_kernel(px, py, th, r, a, thr, has_ref, refx, refy, ref_lim, gap_per_m, want_ends):
    """:meth:`VisBugReference._followed_numpy` and :meth:`VisBugReference._sensed_ends`
    (:mod:`~teamnav.control.nav.local.visbug21_reference`) in one pass (numba),
    on beams sorted by angle. Returns (number of members, member indices, nearest member,
    points (n, 2), ends found, ends (2, 2)); -1 members when no beam returned."""
    n = r.shape[0]
    pts = np.empty((n, 2))
    dirs = np.empty((n, 2))
    hit = np.empty(n, dtype=np.bool_)
    any_hit = False
    for i in range(n):
        ang = th + a[i]
        c = math.cos(ang)
        s = math.sin(ang)
        pts[i, 0] = px + r[i] * c
        pts[i, 1] = py + r[i] * s
        dirs[i, 0] = c
        dirs[i, 1] = s
        hit[i] = r[i] < thr
        any_hit = any_hit or hit[i]
    e = np.zeros((2, 2))
    members = np.empty(n, dtype=np.int64)
    if not any_hit:
        return -1, members, -1, pts, False, e
    joined = np.empty(n, dtype=np.bool_)
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        gap = math.hypot(pts[j, 0] - pts[i, 0], pts[j, 1] - pts[i, 1])
        allowed = gap_per_m * max(r[i], r[j])
        if not allowed > FOLLOW_GAP_M:
            allowed = FOLLOW_GAP_M if allowed == allowed else allowed
        joined[i] = hit[i] and hit[j] and gap <= allowed
    labels = np.empty(n, dtype=np.int64)
    labels[0] = 0
    for i in range(1, n):
        labels[i] = labels[i - 1] + (0 if joined[i - 1] else 1)
    if joined[n - 1]:
        last = labels[n - 1]
        for i in range(n):
            if labels[i] == last:
                labels[i] = labels[0]
    choice, best = _nearest_hit(pts, hit, px, py)
    if has_ref:
        k, best = _nearest_hit(pts, hit, refx, refy)
        if best <= ref_lim:
            choice = k
    m = 0
    near = -1
    best = np.inf
    for i in range(n):
        if hit[i] and labels[i] == labels[choice]:
            members[m] = i
            m += 1
            d = math.hypot(pts[i, 0] - px, pts[i, 1] - py)
            if near < 0 or d < best:
                near, best = i, d
    found = False
    if want_ends:
        found = True
        for side in range(2):
            step = 1 if side == 0 else -1
            i = near
            j = near
            walked = 0
            while walked < n:
                k = (i + step) % n
                close = joined[i] if step == 1 else joined[k]
                if not (close and hit[k]) and not (j != i and _continues(pts, dirs, r, hit, px, py, i, j, k)):
                    break
                j = i
                i = k
                walked += 1
            if walked >= n:
                found = False
                break
            e[side, 0] = pts[i, 0]
            e[side, 1] = pts[i, 1]
    return m, members, near, pts, found, e


@njit(cache=True)
def _continues(pts, dirs, r, hit, px, py, i, j, k):
    """Does beam k continue the surface through points j (older) and i (newest)?
    (:meth:`VisBugReference._sensed_ends`'s ``continues``, numba)."""
    if not hit[k]:
        return False
    v0 = pts[i, 0] - pts[j, 0]
    v1 = pts[i, 1] - pts[j, 1]
    den = dirs[k, 0] * v1 - dirs[k, 1] * v0
    w0 = pts[i, 0] - px
    w1 = pts[i, 1] - py
    if abs(den) <= 1e-12:
        return False
    r_line = (w0 * v1 - w1 * v0) / den
    if not r_line > 0.0:
        return False
    return r[k] <= r_line + END_TOL_M + END_TOL_FRACTION * min(r[k], r_line)


@njit(cache=True)
def _last_visible(x, y, px, py, cx, cy, r_safe, reach_m, slack_rad):
    """Step 1's Ti search (numba): the index of the *last* candidate point (``cx``, ``cy``)
    that :meth:`~teamnav.control.nav.local.visbug21_reference.VisBugReference._visible` finds visible from
    (``x``, ``y``), or -1; the candidates after it are tested, the ones before it are not.

    The same arithmetic per candidate as ``_visible`` and ``segment_clear``: a candidate is
    visible when ``hypot(c - xy) <= reach_m`` and no sensed point with ``hypot(p - xy) <=
    reach_m + 2 r_safe`` lies nearer than ``r_safe`` to the segment xy -> c, a point counting
    ``slack_rad · hypot(p - xy)`` nearer (``math.hypot`` is libm's ``hypot``, as ``np.hypot``).
    Testing from the goal end backwards stops at the answer instead of testing every M-line
    sample (``_intermediate_target`` only uses the last visible one).
    """
    nk = px.shape[0]
    kx = np.empty(nk)
    ky = np.empty(nk)
    ks = np.empty(nk)
    lim_p = reach_m + 2.0 * r_safe
    m = 0
    for k in range(nk):
        rp = math.hypot(px[k] - x, py[k] - y)
        if rp <= lim_p:
            kx[m] = px[k]
            ky[m] = py[k]
            ks[m] = slack_rad * rp
            m += 1
    last = -1  # the point that blocked the previous candidate: tested first (the same answer)
    for j in range(cx.shape[0] - 1, -1, -1):
        if not math.hypot(cx[j] - x, cy[j] - y) <= reach_m:
            continue
        if m == 0:
            return j
        d0 = cx[j] - x
        d1 = cy[j] - y
        len2 = d0 * d0 + d1 * d1
        if len2 < 1e-24:
            len2 = 1e-24
        block = _first_blocking(kx, ky, ks, m, x, y, d0, d1, len2, r_safe, last)
        if block < 0:
            return j
        last = block
    return -1


@njit(cache=True, inline="always")
def _clear_of(px, py, slack, x, y, d0, d1, len2, lim):
    """``segment_clear``'s test of one point: its distance to the segment from (x, y) along
    (d0, d1), less its slack, is at least ``lim`` (False for NaN)."""
    rx = px - x
    ry = py - y
    t = (rx * d0 + ry * d1) / len2
    if t < 0.0:
        t = 0.0
    if t > 1.0:
        t = 1.0
    ex = rx - t * d0
    ey = ry - t * d1
    return math.sqrt(ex * ex + ey * ey) - slack >= lim


@njit(cache=True)
def _first_blocking(kx, ky, ks, m, x, y, d0, d1, len2, lim, first):
    """Index of a point among the first ``m`` that is not clear of the segment (``_clear_of``),
    or -1 when all are; point ``first`` (if >= 0) is tested before the others. Which points
    block does not depend on the order, so neither does "some point blocks"."""
    if first >= 0 and not _clear_of(kx[first], ky[first], ks[first], x, y, d0, d1, len2, lim):
        return first
    for k in range(m):
        if k != first and not _clear_of(kx[k], ky[k], ks[k], x, y, d0, d1, len2, lim):
            return k
    return -1


@njit(cache=True)
def _leave_candidates(x, y, pts, cand, t, gx, gy, d_max, mgx, mgy, ux, uy, r_vis, r_run, reach_m, slack_rad,
                      leave_run_m):
    """Step 2's leave test up to its last part (numba): which M-line samples are leave-point
    candidates before the "seen free" test, with the arithmetic of the numpy code of
    :meth:`~teamnav.control.nav.local.visbug21.VisBug21._leave_point` it replaces.

    ``pts`` (K, 2) are the sensed points, ``cand`` (J, 2) the M-line samples, ``t`` their
    M-line parameters. Returns ``(sel, ok, tested, run, n_ok)``: ``sel`` the indices of the samples closer to the goal
    (``gx``, ``gy``) than ``d_max`` (``hypot < d_max``); per selected sample, ``ok``: visible from
    (``x``, ``y``) through a corridor of half-width ``r_vis`` (``_visible``), and, for a sample
    short of the goal (``t < 1 − 1e-12``, then ``tested``), the run ``run = min(leave_run_m,
    hypot(g − c))`` along ``(ux, uy)`` clear by ``r_run`` of every sensed point, a point counting
    ``slack_rad · hypot(p − xy)`` nearer (``segment_clear``); the run's ``g`` is the M-line's end
    (``mgx``, ``mgy``); ``n_ok`` counts ``ok``. ``math.hypot`` is libm's, as ``np.hypot``.
    """
    px = pts[:, 0]
    py = pts[:, 1]
    cx = cand[:, 0]
    cy = cand[:, 1]
    nc = cx.shape[0]
    nk = px.shape[0]
    sel = np.empty(nc, dtype=np.int64)
    ns = 0
    for j in range(nc):
        if math.hypot(cx[j] - gx, cy[j] - gy) < d_max:
            sel[ns] = j
            ns += 1
    sel = sel[:ns]
    ok = np.zeros(ns, dtype=np.bool_)
    tested = np.zeros(ns, dtype=np.bool_)
    run = np.zeros(ns)
    if ns == 0:
        return sel, ok, tested, run, 0
    # _visible: points within reach + 2 r_vis, with their slack
    rp = np.empty(nk)
    kx = np.empty(nk)
    ky = np.empty(nk)
    ks = np.empty(nk)
    lim_p = reach_m + 2.0 * r_vis
    m = 0
    for k in range(nk):
        rp[k] = math.hypot(px[k] - x, py[k] - y)
        if rp[k] <= lim_p:
            kx[m] = px[k]
            ky[m] = py[k]
            ks[m] = slack_rad * rp[k]
            m += 1
    t_goal = 1.0 - 1e-12
    slack_all = np.empty(nk)
    for k in range(nk):
        slack_all[k] = slack_rad * rp[k]
    last_vis = -1  # blocking points tested first (``_first_blocking``: the same answers)
    last_run = -1
    n_ok = 0
    for i in range(ns):
        j = sel[i]
        if not math.hypot(cx[j] - x, cy[j] - y) <= reach_m:
            continue
        if m > 0:
            d0 = cx[j] - x
            d1 = cy[j] - y
            len2 = d0 * d0 + d1 * d1
            if len2 < 1e-24:
                len2 = 1e-24
            block = _first_blocking(kx, ky, ks, m, x, y, d0, d1, len2, r_vis, last_vis)
            if block >= 0:
                last_vis = block
                continue
        ok[i] = True
        n_ok += 1
        if not t[j] < t_goal:
            continue
        tested[i] = True
        h = math.hypot(mgx - cx[j], mgy - cy[j])
        rr = leave_run_m if leave_run_m < h else h  # np.minimum (h >= 0; NaN propagates)
        if h != h:
            rr = h
        run[i] = rr
        if nk == 0:
            continue
        sx = cx[j]
        sy = cy[j]
        d0 = (sx + rr * ux) - sx
        d1 = (sy + rr * uy) - sy
        len2 = d0 * d0 + d1 * d1
        if len2 < 1e-24:
            len2 = 1e-24
        block = _first_blocking(px, py, slack_all, nk, sx, sy, d0, d1, len2, r_run, last_run)
        if block >= 0:
            last_run = block
            ok[i] = False
            n_ok -= 1
    return sel, ok, tested, run, n_ok


@njit(cache=True)
def _boundary_pick(x, y, fx, fy, delta, follow_m, step_m, px, py, r_safe, reach_m, slack_rad):
    """Step 2's boundary target (``boundary_shortcut``) after its bearings (numba; commit 8e3551b, 2026-11-27).

    The arithmetic of :meth:`~teamnav.control.nav.local.visbug21_reference.VisBugReference._boundary_target_numpy`
    from its stood-off points on: per followed point ``k`` (``fx``, ``fy``) the chord through its
    neighbours in beam order (the ends repeat themselves), its unit normal turned towards
    (``x``, ``y``), the point stood off by ``follow_m`` along it; the candidates are those with
    ``delta > 0`` and at least ``step_m`` away, in decreasing ``delta`` (ties in beam order, as
    the stable argsort); the first one that ``_visible`` finds visible is the target. The
    visibility search is :func:`_last_visible` on the reversed order, which stops at the answer
    instead of testing every candidate (``math.hypot`` is libm's, as ``np.hypot``). ``delta``
    (the bearings past the nearest point) stays NumPy's: its ``arctan2`` is not libm's.

    Returns ``(k, cx, cy)``: the followed point's index and the target, or ``(-1, nan, nan)``.
    """
    nk = fx.shape[0]
    cx = np.empty(nk)
    cy = np.empty(nk)
    order = np.empty(nk, dtype=np.int64)
    n = 0
    for k in range(nk):
        if k + 1 < nk:
            ax, ay = fx[k + 1], fy[k + 1]
        else:
            ax, ay = fx[nk - 1], fy[nk - 1]
        if k > 0:
            bx, by = fx[k - 1], fy[k - 1]
        else:
            bx, by = fx[0], fy[0]
        tx = ax - bx
        ty = ay - by
        tn = math.hypot(tx, ty)
        if tn < 1e-12:
            tn = 1e-12
        nx = -ty / tn
        ny = tx / tn
        flip = -1.0 if nx * (fx[k] - x) + ny * (fy[k] - y) > 0.0 else 1.0
        cx[k] = fx[k] + follow_m * (flip * nx)
        cy[k] = fy[k] + follow_m * (flip * ny)
        if delta[k] > 0.0 and math.hypot(cx[k] - x, cy[k] - y) >= step_m:
            # insertion into decreasing delta, after any equal one (a stable sort of -delta)
            j = n
            while j > 0 and delta[order[j - 1]] < delta[k]:
                order[j] = order[j - 1]
                j -= 1
            order[j] = k
            n += 1
    if n == 0:
        return -1, np.nan, np.nan
    rx = np.empty(n)
    ry = np.empty(n)
    for j in range(n):
        rx[n - 1 - j] = cx[order[j]]
        ry[n - 1 - j] = cy[order[j]]
    jr = _last_visible(x, y, px, py, rx, ry, r_safe, reach_m, slack_rad)
    if jr < 0:
        return -1, np.nan, np.nan
    k = order[n - 1 - jr]
    return k, cx[k], cy[k]
