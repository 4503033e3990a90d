"""The trail brains as group brains: Navigate and the trail rules compiled, a team in one call.

``blazing-trail-v1`` (:class:`~teamnav.papers.trails.brains.blazing_trail.BlazingTrail`, Blazing
§4.1-4.2) and ``trail-share-v1`` (:class:`~teamnav.papers.trails.brains.trail_share.TrailShare`,
Try §3) under ``group_brains`` (``docs/concepts/group-brains.md``, "The trail brains"). Each
robot keeps its reference brain, with its Navigate replaced by
:class:`~teamnav.control.nav.navigate_compiled.CompiledNavigate` (§4.2's wall following,
openings, 180° rule and Panic; the same rules, state as arrays). On a step without task events
the hot part of the brain is compiled too: for blazing-trail-v1 the path, crumb dropping and
loop pruning, the crumbs' mean heading, the 180° rule's count, the recovery, then Navigate
(:func:`blazing_row_step`); for trail-share-v1 the descend-only bound, the lowest
time-to-place crumb, the recovery, then Navigate (:func:`share_row_step`). From
``TEAM_MIN`` robots sharing one Navigate geometry on, the team steps in one call
(:func:`blazing_team_step`, :func:`share_team_step`), its state in arrays; below, one call per
robot. What stays the reference's own code, run as the reference runs it: steps with task
events (the waggle dance, Places set), the inbox rules (crumbs appended, Trails combined through
the Places), the Trails' expiry and trail-share's broadcast steps. The runs are the same bit for
bit (``tests/test_trail_compiled.py``: both columns, both sections, with drift and launch, both
forms of the call).

A robot whose Navigate parameters the kernel declines
(:func:`~teamnav.control.nav.navigate_compiled.unsupported`: the meeting flags) keeps the
reference Navigate and its reference step inside the group, so a run is never inexact; so does a
blazing-trail-v1 robot whose global crumbs expire (``global_crumb_ttl_s``). Robots started one at
a time (a scenario's ``launch``) are skipped while they wait (``GroupObservation.waiting``), as
the per-robot path skips them.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any, Sequence

import numpy as np
from numba import njit

from teamnav.control.group import GroupAction, GroupObservation
from teamnav.control.nav import navigate_compiled as NC
from teamnav.control.nav.local.compiled import py_hypot
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Observation, RangeScan
from teamnav.papers.trails.brains.crumbs import CrumbBatch
from teamnav.papers.trails.brains.trails import TrailMessage

__all__ = ["BlazingTrailGroup", "TrailShareGroup", "average_heading_kernel", "blazing_row_step", "pairwise_sum"]

_TWO_PI = 2.0 * math.pi

# blazing-trail-v1's parameter columns (B_*)
B_MIN_MOVE = 0  # crumb_min_move_m
B_INTERVAL = 1  # crumb_interval_s
B_REV_CARRIED = 2  # reverse_carried_crumbs
B_PRUNE = 3  # prune_loops
B_PRUNE_R = 4  # prune_radius_m
B_PRUNE_LOOP = 5  # prune_min_loop_m
B_LOOK = 6  # lookahead_m
B_RADIUS = 7  # radius_m
B_REV_MIN = 8  # reverse_min_crumbs
B_RECOVER = 9  # recover_radius_m
N_B = 10

# blazing-trail-v1's scalar state in a team's array (BS_*)
BS_PATH = 0  # _path_m
BS_HAS_LAST = 1  # _last_xy is not None
BS_LX = 2
BS_LY = 3
BS_HAS_CRUMB = 4  # _crumb_xy is not None
BS_CX = 5
BS_CY = 6
BS_NEXT = 7  # _next_crumb_s
BS_CUT = 8  # loops_cut
BS_FOLLOW = 9  # _following
BS_RECOVER = 10  # _recovering
N_BS = 11


# ----------------------------------------------------------------- numpy's arithmetic, written out
@njit(cache=True)
def _pairwise_block(a, lo, n):
    """numpy's ``pairwise_sum`` for ``n <= 128``: a plain sum below 8, else eight accumulators."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[lo + i]
        return res
    r0 = a[lo]
    r1 = a[lo + 1]
    r2 = a[lo + 2]
    r3 = a[lo + 3]
    r4 = a[lo + 4]
    r5 = a[lo + 5]
    r6 = a[lo + 6]
    r7 = a[lo + 7]
    i = 8
    m = n - (n % 8)
    while i < m:
        r0 += a[lo + i]
        r1 += a[lo + i + 1]
        r2 += a[lo + i + 2]
        r3 += a[lo + i + 3]
        r4 += a[lo + i + 4]
        r5 += a[lo + i + 5]
        r6 += a[lo + i + 6]
        r7 += a[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True)
def pairwise_sum(a, lo, n):
    """numpy's ``pairwise_sum`` for float64 (``loops_utils.h.src``) over ``a[lo:lo + n]``: up to 128
    :func:`_pairwise_block`, above that the two halves (the first rounded down to a multiple of 8)
    summed. ``0.0 + pairwise_sum(a, 0, a.size)`` is ``a.sum()`` bit for bit (its identity, then the
    loop). The recursion is unrolled onto a stack: numba's cache reloads a recursive function
    wrongly (a process that loaded it crashed)."""
    if n <= 128:
        return _pairwise_block(a, lo, n)
    f_lo = np.empty(192, dtype=np.int64)  # frames: (lo, n, combine?) ; depth <= log2(n) < 64
    f_n = np.empty(192, dtype=np.int64)
    f_comb = np.empty(192, dtype=np.bool_)
    vals = np.empty(128)
    top = 0
    nv = 0
    f_lo[0] = lo
    f_n[0] = n
    f_comb[0] = False
    top = 1
    while top > 0:
        top -= 1
        flo = f_lo[top]
        fn = f_n[top]
        if f_comb[top]:  # both halves done: left + right
            right = vals[nv - 1]
            left = vals[nv - 2]
            nv -= 2
            vals[nv] = left + right
            nv += 1
        elif fn <= 128:
            vals[nv] = _pairwise_block(a, flo, fn)
            nv += 1
        else:
            n2 = fn // 2
            n2 -= n2 % 8
            f_lo[top] = flo  # then: combine
            f_n[top] = fn
            f_comb[top] = True
            f_lo[top + 1] = flo + n2  # the right half, done second
            f_n[top + 1] = fn - n2
            f_comb[top + 1] = False
            f_lo[top + 2] = flo  # the left half, done first
            f_n[top + 2] = n2
            f_comb[top + 2] = False
            top += 3
    return vals[0]


@njit(cache=True, inline="always")
def _wrap_scalar(a):
    """:func:`teamnav.papers.trails.brains.crumbs._wrap_scalar`: (-pi, pi]."""
    w = NC.py_remainder(a, _TWO_PI)
    return math.pi if w == -math.pi else w


@njit(cache=True, inline="always")
def _toward(cx, cy, x, y):
    """The recovery's hint (both brains' ``recover_radius_m``, a gap-fill: the heading from the
    robot at (x, y) to the nearest crumb (cx, cy)): ``(ok, heading)``, not ok when the crumb is
    where the robot is, as the reference's ``> 1e-12`` test."""
    ex = cx - x
    ey = cy - y
    if ex * ex + ey * ey > 1e-12:
        return True, math.atan2(cy - y, cx - x)
    return False, 0.0


@njit(cache=True)
def average_heading_kernel(buf, n, x, y, radius):
    """:func:`teamnav.papers.trails.brains.crumbs.average_heading` over ``buf[:n]`` (x, y, heading,
    path): ``(found, mean)``. ``np.sin``/``np.cos`` of numpy are libm's on the machines the tests
    run on (checked there), and the sums are numpy's pairwise sums."""
    if n == 0:
        return False, 0.0
    r2 = radius * radius
    sins = np.empty(n)
    coss = np.empty(n)
    k = 0
    for i in range(n):
        dx = buf[i, 0] - x
        dy = buf[i, 1] - y
        if dx * dx + dy * dy <= r2:
            h = buf[i, 2]
            sins[k] = math.sin(h)
            coss[k] = math.cos(h)
            k += 1
    if k == 0:
        return False, 0.0
    s = 0.0 + pairwise_sum(sins, 0, k)
    c = 0.0 + pairwise_sum(coss, 0, k)
    if py_hypot(s, c) <= 1e-9 * k:
        return False, 0.0
    return True, _wrap_scalar(math.atan2(s, c))


@njit(cache=True)
def blazing_row_step(path_m, has_last, lx, ly, has_crumb, cx, cy, next_crumb_s, carrying, priv, priv_n, glob, glob_n,
                     bpar, fst, ist, par, rev_at, r, x, y, th, t, stalled, angles, cos_a, sin_a, exit_m, offsets,
                     box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r, sin_r, head, front, free_exit):
    """One ``blazing-trail-v1`` step of one robot on a step without events or messages
    (:meth:`BlazingTrail.step <teamnav.papers.trails.brains.blazing_trail.BlazingTrail.step>`:
    the path, crumb dropping with or without loop pruning, the crumbs' mean heading around the
    point ahead, the 180° rule's crumb count, the recovery towards the nearest crumb, then Navigate
    without its Generator). ``priv`` must have room for one more crumb.

    Returns ``(v, w, path_m, has_crumb, cx, cy, next_crumb_s, priv_n, cut, following, recovering,
    has_pref, pref, allow)``; ``v`` NaN: Navigate must draw (its state untouched; the caller steps
    it with the Generator, the brain's part being done).
    """
    if has_last:
        path_m += py_hypot(x - lx, y - ly)
    moved = (not has_crumb) or py_hypot(x - cx, y - cy) >= bpar[B_MIN_MOVE]
    cut = False
    if t >= next_crumb_s and moved:
        cx = x
        cy = y
        has_crumb = True
        outbound = not (carrying and bpar[B_REV_CARRIED] != 0.0)
        drop = True
        if bpar[B_PRUNE] != 0.0 and priv_n > 0:
            rr = bpar[B_PRUNE_R] * bpar[B_PRUNE_R]
            lim = path_m - bpar[B_PRUNE_LOOP]
            for i in range(priv_n):
                dx = priv[i, 0] - x
                dy = priv[i, 1] - y
                if dx * dx + dy * dy <= rr and priv[i, 3] <= lim:
                    priv_n = i + 1
                    cut = True
                    drop = False
                    break
        if drop:
            h = th if outbound else th + math.pi
            priv[priv_n, 0] = x
            priv[priv_n, 1] = y
            priv[priv_n, 2] = _wrap_scalar(h)
            priv[priv_n, 3] = path_m
            priv_n += 1
        next_crumb_s = t + bpar[B_INTERVAL] - 1e-9
    look = bpar[B_LOOK]
    qx = x + look * math.cos(th)
    qy = y + look * math.sin(th)
    found, mean = average_heading_kernel(glob, glob_n, qx, qy, bpar[B_RADIUS])
    pref = 0.0
    if found:
        pref = _wrap_scalar(mean + math.pi) if carrying else _wrap_scalar(mean)
    following = found
    allow = found
    if found and bpar[B_REV_MIN] > 1.0:
        rr = bpar[B_RADIUS] * bpar[B_RADIUS]
        cnt = 0
        for i in range(glob_n):
            dx = glob[i, 0] - qx
            dy = glob[i, 1] - qy
            if dx * dx + dy * dy <= rr:
                cnt += 1
        allow = cnt >= bpar[B_REV_MIN]
    recovering = False
    if not found and bpar[B_RECOVER] > 0.0 and not (fst[NC.F_ODO] < fst[NC.F_LEAVE]) and glob_n > 0:
        best = -1
        bd = math.inf
        for i in range(glob_n):
            dx = glob[i, 0] - x
            dy = glob[i, 1] - y
            d2 = dx * dx + dy * dy
            if d2 < bd:
                bd = d2
                best = i
        if not (bd > bpar[B_RECOVER] * bpar[B_RECOVER]):
            recovering, h = _toward(glob[best, 0], glob[best, 1], x, y)
            if recovering:
                pref = h
                found = allow = True
    v, w = NC.nav_step(fst, ist, par, rev_at, r, x, y, th, t, stalled, found, pref, allow, False, angles, cos_a,
                       sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r, sin_r, head,
                       front, free_exit)
    return (v, w, path_m, has_crumb, cx, cy, next_crumb_s, priv_n, cut, following, recovering, found, pref, allow)


def _row_observation(obs: GroupObservation, r: int) -> Observation:
    """Row ``r`` as the :class:`Observation` the engine hands a per-robot brain (the trail
    robots have no detector)."""
    scans = {name: RangeScan(obs.ranges_m[name][r], obs.angles_rad[name], obs.max_range_m[name])
             for name in obs.ranges_m}
    return Observation(int(obs.robot_ids[r]), int(obs.step), float(obs.time_s), obs.odom_pose[r], obs.odom_delta[r],
                       scans, (), bool(obs.stalled[r]), obs.inbox[r],
                       obs.events[r] if obs.events is not None else ())


@njit(cache=True)
def blazing_team_step(rows, bs, pn, privs, gn, globs, bpar, carry, nf, ni, par, nrev, ranges, poses, t, stalled, angles,
                      cos_a, sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r, sin_r,
                      head, front, free_exit, out_v, out_w, hint):
    """:func:`blazing_row_step` for the robots ``rows`` of a team in one call (their Navigate
    parameters and geometry shared), state in the team's arrays: ``bs`` (n, N_BS) the brains'
    scalars (``BS_*``), ``pn``/``gn`` the private and global crumb counts, ``privs``/``globs``
    their buffers, ``nf``/``ni``/``nrev`` Navigate's states. Commands into ``out_v``/``out_w``;
    a robot whose Navigate must draw gets ``out_v`` NaN and its hint in ``hint`` (has_pref,
    pref, allow_reverse, ignore_memory: the last always 0) for the caller's
    :func:`~teamnav.control.nav.navigate_compiled.nav_step_rng`."""
    for k in range(rows.shape[0]):
        r = rows[k]
        b = bs[r]
        pose = poses[r]
        out = blazing_row_step(b[BS_PATH], b[BS_HAS_LAST] != 0.0, b[BS_LX], b[BS_LY], b[BS_HAS_CRUMB] != 0.0,
                               b[BS_CX], b[BS_CY], b[BS_NEXT], carry[r], privs[r], pn[r], globs[r], gn[r], bpar[r],
                               nf[r], ni[r], par, nrev[r], ranges[r], pose[0], pose[1], pose[2], t, stalled[r], angles,
                               cos_a, sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r,
                               sin_r, head, front, free_exit)
        b[BS_PATH] = out[2]
        b[BS_HAS_LAST] = 1.0
        b[BS_LX] = pose[0]
        b[BS_LY] = pose[1]
        if out[3]:
            b[BS_HAS_CRUMB] = 1.0
            b[BS_CX] = out[4]
            b[BS_CY] = out[5]
        b[BS_NEXT] = out[6]
        pn[r] = out[7]
        if out[8]:
            b[BS_CUT] += 1.0
        b[BS_FOLLOW] = 1.0 if out[9] else 0.0
        b[BS_RECOVER] = 1.0 if out[10] else 0.0
        out_v[r] = out[0]
        out_w[r] = out[1]
        hint[r, 0] = 1.0 if out[11] else 0.0
        hint[r, 1] = out[12]
        hint[r, 2] = 1.0 if out[13] else 0.0
        hint[r, 3] = 0.0


# trail-share-v1's parameter columns (S_*)
S_DESCEND = 0  # descend_only
S_REACH = 1  # reach_m
S_LOOK = 2  # lookahead_m
S_RADIUS = 3  # radius_m
S_RECOVER = 4  # recover_radius_m
S_RECOVER_REV = 5  # recover_reverse
N_S = 6


@njit(cache=True)
def _best_crumb(xys, codes, n, code, x, y, radius, below):
    """:meth:`Trail.best_crumb <teamnav.papers.trails.brains.trails.Trail.best_crumb>`: (index or
    -1, time-to-place); ties to the earliest."""
    r2 = radius * radius
    best = -1
    bs = math.inf
    for i in range(n):
        if codes[i] != code:
            continue
        dx = xys[i, 0] - x
        dy = xys[i, 1] - y
        if not (dx * dx + dy * dy <= r2):
            continue
        si = xys[i, 2]
        if below != math.inf and not (si < below):
            continue
        if best < 0 or si < bs:
            best = i
            bs = si
    return best, bs


@njit(cache=True)
def share_row_step(bound_s, bound_t, code, xys, codes, n, spar, fst, ist, par, rev_at, r, x, y, th, t, stalled,
                   angles, cos_a, sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r,
                   sin_r, head, front, free_exit):
    """The trail-using part of one ``trail-share-v1`` step (:meth:`TrailShare.step
    <teamnav.papers.trails.brains.trail_share.TrailShare.step>` after the events, messages,
    expiry and broadcast, which the caller has run or ruled out): the ``descend_only`` bound, the
    lowest time-to-place crumb around the point ahead (§2.3 step 1), the recovery towards the
    nearest crumb, then Navigate without its Generator. ``code``: the goal Place's code in the
    Trail (-1: none).

    Returns ``(v, w, bound_s, bound_t, following, recovering, has_pref, pref, ignore_memory)``;
    ``v`` NaN: Navigate must draw (the caller steps it with the Generator).
    """
    has_code = code >= 0 and n > 0
    below = math.inf
    if spar[S_DESCEND] != 0.0:
        bound = bound_s + (t - bound_t)
        if has_code:
            i, si = _best_crumb(xys, codes, n, code, x, y, spar[S_REACH], math.inf)
            if i >= 0 and si < bound:
                bound_s = si
                bound_t = t
                bound = si
        below = bound
    look = spar[S_LOOK]
    qx = x + look * math.cos(th)
    qy = y + look * math.sin(th)
    found = False
    pref = 0.0
    if has_code:
        i, _ = _best_crumb(xys, codes, n, code, qx, qy, spar[S_RADIUS], below)
        if i >= 0:
            dx = xys[i, 0] - x
            dy = xys[i, 1] - y
            if not (dx * dx + dy * dy < 1e-12):
                found = True
                pref = math.atan2(dy, dx)
    following = found
    recovering = False
    if not found and spar[S_RECOVER] > 0.0 and not (fst[NC.F_ODO] < fst[NC.F_LEAVE]) and has_code:
        best = -1
        bd = math.inf
        for j in range(n):
            d2 = math.inf
            if codes[j] == code:
                ex = xys[j, 0] - x
                ey = xys[j, 1] - y
                d2 = ex * ex + ey * ey
            if below != math.inf and not (xys[j, 2] < below):
                d2 = math.inf
            if best < 0 or d2 < bd:
                best = j
                bd = d2
        if bd <= spar[S_RECOVER] * spar[S_RECOVER]:
            recovering, h = _toward(xys[best, 0], xys[best, 1], x, y)
            if recovering:
                pref = h
                found = True
    ignore = recovering and spar[S_RECOVER_REV] != 0.0
    v, w = NC.nav_step(fst, ist, par, rev_at, r, x, y, th, t, stalled, found, pref, True, ignore, angles, cos_a,
                       sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r, sin_r, head,
                       front, free_exit)
    return v, w, bound_s, bound_t, following, recovering, found, pref, ignore


# trail-share-v1's scalar state in a team's array (SS_*)
SS_BOUND_S = 0  # _bound_s
SS_BOUND_T = 1  # _bound_t
SS_FOLLOW = 2  # _following
SS_RECOVER = 3  # _recovering
N_SS = 4


@njit(cache=True)
def share_team_step(rows, ss, code, xyss, ps, tn, spar, nf, ni, par, nrev, ranges, poses, t, stalled, angles, cos_a,
                    sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r, sin_r, head,
                    front, free_exit, out_v, out_w, hint):
    """:func:`share_row_step` for the robots ``rows`` of a team in one call (their Navigate
    parameters and geometry shared): ``ss`` (n, N_SS) the brains' scalars, ``code`` each robot's
    goal Place code (-1: none), ``xyss``/``ps``/``tn`` their Trails' crumbs, codes and counts (the
    reference's own buffers), ``nf``/``ni``/``nrev`` Navigate's states. Commands into ``out_v``/
    ``out_w``; a robot whose Navigate must draw gets ``out_v`` NaN and (has_pref, pref,
    allow_reverse, ignore_memory: the third always 1) in ``hint`` for the caller's
    :func:`~teamnav.control.nav.navigate_compiled.nav_step_rng`."""
    for k in range(rows.shape[0]):
        r = rows[k]
        b = ss[r]
        pose = poses[r]
        out = share_row_step(b[SS_BOUND_S], b[SS_BOUND_T], code[r], xyss[r], ps[r], tn[r], spar[r], nf[r], ni[r], par,
                             nrev[r], ranges[r], pose[0], pose[1], pose[2], t, stalled[r], angles, cos_a, sin_a,
                             exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r, sin_r, head,
                             front, free_exit)
        out_v[r] = out[0]
        out_w[r] = out[1]
        b[SS_BOUND_S] = out[2]
        b[SS_BOUND_T] = out[3]
        b[SS_FOLLOW] = 1.0 if out[4] else 0.0
        b[SS_RECOVER] = 1.0 if out[5] else 0.0
        hint[r, 0] = 1.0 if out[6] else 0.0
        hint[r, 1] = out[7]
        hint[r, 2] = 1.0
        hint[r, 3] = 1.0 if out[8] else 0.0


class _Buffers:
    """The team's per-robot numpy buffers (the reference brains' own) as the numba typed list a
    team kernel takes. A robot's buffer that grew is a new object: the typed list is built again,
    not assigned into, since a typed list's ``__setitem__`` compiles on first use, in whichever
    step needs it."""

    def __init__(self, bufs: Sequence[np.ndarray]) -> None:
        from numba.typed import List

        self._obj = list(bufs)
        self.typed = List(self._obj)

    def sync(self, r: int, buf: np.ndarray) -> None:
        """Robot r's buffer is ``buf``."""
        if buf is not self._obj[r]:
            from numba.typed import List

            self._obj[r] = buf
            self.typed = List(self._obj)


class _TeamView:
    """Robot r's face in a trail group that steps the team in one call: its reference brain,
    brought up to date from the team's arrays before anything is read."""

    def __init__(self, group: _TrailGroup, r: int) -> None:
        self._g = group
        self._r = r

    def log(self) -> dict:
        self._g._to_brain(self._r)
        return self._g._brains[self._r].log()

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__") or name in ("_g", "_r"):
            raise AttributeError(name)
        g = self._g
        g._to_brain(self._r)
        return getattr(g._brains[self._r], name)


class _TrailGroup(ABC):
    """A team of one trail brain class: each robot its reference brain over a compiled Navigate.

    The part both trail brains share: building the brains, the two forms of the step (one
    compiled call per robot; from ``TEAM_MIN`` robots sharing one Navigate geometry, the team in
    one call, its state in arrays, each robot's reference brain brought up to date from them
    whenever it is read (:class:`_TeamView`) or steps itself), the reference brain's own step
    where the compiled one does not apply, and Navigate's step with the robot's Generator where
    the compiled one must draw. What differs, each brain's class says: its parameter row
    (:meth:`_param_row`), when a robot may take the compiled step (:meth:`_fast_brain`,
    :meth:`_due`, :meth:`_team_due`), that step (:meth:`_row_step`, :meth:`_before_team`,
    :meth:`_team_kernel`) and its state in the team's arrays (:meth:`_init_state`,
    :meth:`_from_brain`, :meth:`_to_brain`).
    """

    #: the team steps in one call (its state in arrays) from this many robots on; below, one
    #: call per robot. Measured 2026-11-29 (step_group, ms per step, 2000 and 200 steps, tuning
    #: seed 1000): 4 robots, blazing paper column 0.047 in one call against 0.046 per robot,
    #: try-to-see-it-my-way paper column 0.103 against 0.087 (the team call's numpy set-up on
    #: four rows costs more than three calls); 100 robots, trail-share-v1 1.42 against 1.64,
    #: blazing-trail-v1 0.62-0.77 against 0.93.
    TEAM_MIN = 8

    #: the reference brain class (set by the subclasses, imported lazily)
    controller: str = ""
    #: robots started one at a time are skipped while they wait
    handles_waiting = True

    @classmethod
    def _cls(cls) -> type:
        import importlib

        module, _, name = cls.controller.partition(":")
        return getattr(importlib.import_module(module), name)

    @classmethod
    def unsupported(cls, params: Sequence[Any], infos: Sequence[RobotInfo]) -> str | None:
        """None when some robot's Navigate compiles; else why not (the team runs per robot)."""
        whys = []
        for p in params:
            try:
                nav = cls._probe_params(p)
            except ValueError as exc:
                whys.append(str(exc))
                continue
            why = NC.unsupported(nav)
            if why is None:
                return None
            whys.append(why)
        return "; ".join(sorted(set(whys))) or "no robots"

    @classmethod
    @abstractmethod
    def _probe_params(cls, params: Any):
        """The Navigate parameters the reference brain builds for ``params``."""
        raise NotImplementedError

    def __init__(self, params: Sequence[Any], rngs: Sequence[np.random.Generator], infos: Sequence[RobotInfo]) -> None:
        ctl = self._cls()
        self.robots: list[Any] = []
        #: robots whose Navigate is compiled (the others keep the reference's)
        self.compiled_robots = 0
        shared: dict = {}  # robots with the same Navigate inputs share its parameter row and geometry
        for p, rng, info in zip(params, rngs, infos):
            brain = ctl(p, rng, info)
            nav = brain.nav
            if NC.unsupported(nav.params) is None:
                brain.nav = NC.CompiledNavigate(nav.params, rng, info, laser=nav.laser, reference=nav, shared=shared)
                self.compiled_robots += 1
            self.robots.append(brain)
        self._n = len(self.robots)
        #: each robot's brain parameters as its kernel reads them
        self._par = [self._param_row(brain.params) for brain in self.robots]
        #: robots that take the compiled step on a step without task events
        self._fast = [isinstance(brain.nav, NC.CompiledNavigate) and self._fast_brain(brain) for brain in self.robots]
        navs = [brain.nav for brain in self.robots]
        self._team = len(navs) >= self.TEAM_MIN and all(self._fast) and all(
            nav._par is navs[0]._par and nav.laser == navs[0].laser for nav in navs)
        if self._team:
            self._init_team()

    # ------------------------------------------------------------------ what each brain says
    @staticmethod
    @abstractmethod
    def _param_row(p: Any) -> np.ndarray:
        """The brain's parameters ``p`` as its kernels' parameter row."""
        raise NotImplementedError

    @staticmethod
    @abstractmethod
    def _fast_brain(brain: Any) -> bool:
        """Whether a robot with a compiled Navigate takes the compiled step (on steps without task
        events)."""
        raise NotImplementedError

    @staticmethod
    def _due(brain: Any, t: float) -> bool:
        """One call per robot: whether this step is the reference brain's own even without task
        events."""
        return False

    @abstractmethod
    def _row_step(self, brain: Any, r: int, box: Sequence[Any], ranges: np.ndarray, x: float, y: float, th: float,
                  t: float, stalled: bool, step: int) -> tuple:
        """One call per robot: robot r's compiled step (inbox included), its brain's state
        written back; ``(v, w, has_pref, pref, allow_reverse, ignore_memory)``, ``v`` NaN where
        Navigate must draw (:meth:`_draw`)."""
        raise NotImplementedError

    @abstractmethod
    def _init_state(self) -> None:
        """The team in one call: the brains' own state in the team's arrays (allocated here,
        filled by :meth:`_from_brain`)."""
        raise NotImplementedError

    @abstractmethod
    def _from_brain(self, r: int) -> None:
        """Robot r's state, from its reference brain into the team's arrays."""
        raise NotImplementedError

    @abstractmethod
    def _to_brain(self, r: int) -> None:
        """Robot r's state, from the team's arrays into its reference brain."""
        raise NotImplementedError

    def _team_due(self, active: np.ndarray, t: float) -> np.ndarray:
        """The team in one call: the robots whose step is the reference brain's own even without
        task events (a new array)."""
        return np.zeros(self._n, dtype=np.bool_)

    @abstractmethod
    def _before_team(self, obs: GroupObservation, rows: np.ndarray, t: float) -> None:
        """The team in one call: the reference's rules the kernel does not run (the inbox), for
        the robots ``rows``, before it."""
        raise NotImplementedError

    @abstractmethod
    def _team_kernel(self, rows: np.ndarray, ranges: np.ndarray, poses: np.ndarray, t: float, stalled: np.ndarray,
                     out_v: np.ndarray, out_w: np.ndarray, hint: np.ndarray) -> None:
        """The team in one call: the brain's team kernel over ``rows``; a robot whose Navigate
        must draw gets ``out_v`` NaN and (has_pref, pref, allow_reverse, ignore_memory) in
        ``hint``."""
        raise NotImplementedError

    # ------------------------------------------------------------------ the shared machinery
    @staticmethod
    def _reference_step(brain: Any, obs: GroupObservation, r: int, v: np.ndarray, w: np.ndarray,
                        outbox: list) -> None:
        """Robot r's step as its reference brain's own: its command into ``v``/``w``, its
        messages onto ``outbox``."""
        action, msgs = brain.step(_row_observation(obs, r))
        v[r] = action.v_mps
        w[r] = action.omega_radps
        if msgs:
            rid = int(obs.robot_ids[r])
            outbox.extend((rid, m) for m in msgs)

    @staticmethod
    def _draw(nav: Any, ranges: np.ndarray, x: float, y: float, th: float, t: float, stalled: bool, has_pref: bool,
              pref: float, allow: bool, ignore: bool) -> tuple[float, float]:
        """Navigate must draw: its step again, with the robot's Generator (the brain's part is
        done; the compiled step left Navigate's state untouched)."""
        return NC.nav_step_rng(nav.fst, nav.ist, nav._par, nav.rev_at, ranges, x, y, th, t, stalled, has_pref, pref,
                               allow, ignore, nav.rng, *nav._geo)

    def step_group(self, obs: GroupObservation) -> GroupAction:
        """Every robot's step (module docstring); a waiting robot's brain is off."""
        if self._team:
            return self._step_team(obs)
        n = self._n
        v = np.zeros(n)
        w = np.zeros(n)
        d = np.full(n, math.nan)
        outbox: list = []
        waiting = obs.waiting
        events = obs.events
        inbox = obs.inbox
        poses = obs.odom_pose.tolist()
        stalled = obs.stalled.tolist()
        t = float(obs.time_s)
        step = int(obs.step)
        for r, brain in enumerate(self.robots):
            if waiting is not None and waiting[r]:
                continue
            if not self._fast[r] or (events is not None and events[r]) or self._due(brain, t):
                self._reference_step(brain, obs, r, v, w, outbox)
                continue
            x, y, th = poses[r][:3]
            ranges = obs.ranges_m[brain.params.sensor][r]
            vr, wr, has_pref, pref, allow, ignore = self._row_step(brain, r, inbox[r], ranges, x, y, th, t,
                                                                   stalled[r], step)
            if math.isnan(vr):  # Navigate must draw
                vr, wr = self._draw(brain.nav, ranges, x, y, th, t, stalled[r], has_pref, pref, allow, ignore)
            v[r] = vr
            w[r] = wr
        return GroupAction(v, w, d, outbox)

    # ------------------------------------------------------------------ the team in one call
    def _init_team(self) -> None:
        """Every robot's Navigate shares one geometry: the team steps in one call, Navigate's
        states and the brains' own in arrays (the reference Navigate's state arrays become views
        of the team's: one state)."""
        n = self._n
        self._brains = list(self.robots)
        self._nf = np.zeros((n, NC.N_F))
        self._ni = np.zeros((n, NC.N_I), dtype=np.int64)
        self._nrev = np.zeros((n, NC.REV_AT, 2))
        for r, brain in enumerate(self._brains):
            nav = brain.nav
            self._nf[r] = nav.fst
            self._ni[r] = nav.ist
            self._nrev[r] = nav.rev_at
            nav.fst, nav.ist, nav.rev_at = self._nf[r], self._ni[r], self._nrev[r]  # views: one state
        self._npar = self._brains[0].nav._par
        self._ngeo = self._brains[0].nav._geo
        self._laser = self._brains[0].nav.laser
        self._last_step = np.zeros(n, dtype=np.int64)
        self._par_all = np.ascontiguousarray(np.stack(self._par))
        self._hint = np.zeros((n, 4))
        self._init_state()
        for r in range(n):
            self._from_brain(r)
        self.robots = [_TeamView(self, r) for r in range(n)]

    def _step_team(self, obs: GroupObservation) -> GroupAction:
        n = self._n
        outbox: list = []
        events = obs.events
        t = float(obs.time_s)
        step = int(obs.step)
        v = np.zeros(n)
        w = np.zeros(n)
        active = np.ones(n, dtype=np.bool_) if obs.waiting is None else ~obs.waiting
        slow = self._team_due(active, t)  # the reference brain's own step: these, and those with task events
        if events is not None:
            for r, ev in enumerate(events):
                if ev and active[r]:
                    slow[r] = True
        for r in np.flatnonzero(slow).tolist():  # robot order: the messages go out in it
            self._to_brain(r)
            self._reference_step(self._brains[r], obs, r, v, w, outbox)
            self._from_brain(r)
            self._last_step[r] = step
        rows = np.flatnonzero(active & ~slow)
        if rows.size:
            self._before_team(obs, rows, t)
            ranges = np.ascontiguousarray(obs.ranges_m[self._laser])
            poses = np.ascontiguousarray(obs.odom_pose)
            stalled = np.ascontiguousarray(obs.stalled, dtype=np.bool_)
            out_v = np.zeros(n)
            out_w = np.zeros(n)
            hint = self._hint
            self._team_kernel(rows, ranges, poses, t, stalled, out_v, out_w, hint)
            self._last_step[rows] = step
            for r in rows[np.isnan(out_v[rows])].tolist():
                x, y, th = poses[r, :3].tolist()
                has_pref, pref, allow, ignore = hint[r].tolist()
                out_v[r], out_w[r] = self._draw(self._brains[r].nav, ranges[r], x, y, th, t, bool(stalled[r]),
                                                bool(has_pref), pref, bool(allow), bool(ignore))
            v[rows] = out_v[rows]
            w[rows] = out_w[rows]
        return GroupAction(v, w, np.full(n, math.nan), outbox)


class BlazingTrailGroup(_TrailGroup):
    """``blazing-trail-v1`` teams (module docstring). A robot's step without task events (nearly
    all of them) is the reference's inbox rule (received crumbs appended to the global list; the
    crumb dropping that precedes it in the reference touches only the private list) and one
    compiled call (:func:`blazing_row_step`: crumbs, the trail's hint and Navigate); a step with
    events, and every step of a robot whose global crumbs expire (``global_crumb_ttl_s``) or
    whose Navigate is the reference's, runs the reference brain's own step."""

    controller = "teamnav.papers.trails.brains.blazing_trail:BlazingTrail"

    @staticmethod
    def _param_row(p: Any) -> np.ndarray:
        b = np.zeros(N_B)
        b[B_MIN_MOVE] = p.crumb_min_move_m
        b[B_INTERVAL] = p.crumb_interval_s
        b[B_REV_CARRIED] = 1.0 if p.reverse_carried_crumbs else 0.0
        b[B_PRUNE] = 1.0 if p.prune_loops else 0.0
        b[B_PRUNE_R] = p.prune_radius_m
        b[B_PRUNE_LOOP] = p.prune_min_loop_m
        b[B_LOOK] = p.lookahead_m
        b[B_RADIUS] = p.radius_m
        b[B_REV_MIN] = p.reverse_min_crumbs
        b[B_RECOVER] = p.recover_radius_m
        return b

    @staticmethod
    def _fast_brain(brain: Any) -> bool:
        return brain.params.global_crumb_ttl_s is None

    @staticmethod
    def _take_inbox(brain: Any, box: Sequence[Any], t: float) -> bool:
        """The reference's inbox rule (:meth:`BlazingTrail.step
        <teamnav.papers.trails.brains.blazing_trail.BlazingTrail.step>`): received crumbs
        appended to the global list (it touches only that list, and the crumb dropping before it
        in the reference only the private one). Whether the robot communicates."""
        if not brain.params.communicate:
            return False
        me = brain.info.robot_id
        for msg in box:
            if msg.kind == "crumbs" and isinstance(msg.body, CrumbBatch) and msg.sender != me:
                brain._add_global(msg.body, t)
        return True

    def _row_step(self, brain, r, box, ranges, x, y, th, t, stalled, step) -> tuple:
        if box:
            self._take_inbox(brain, box, t)
        nav = brain.nav
        priv = brain.private
        priv._reserve(1)
        glob = brain.global_crumbs
        last = brain._last_xy
        crumb = brain._crumb_xy
        out = blazing_row_step(
            brain._path_m, last is not None, last[0] if last is not None else 0.0,
            last[1] if last is not None else 0.0, crumb is not None, crumb[0] if crumb is not None else 0.0,
            crumb[1] if crumb is not None else 0.0, brain._next_crumb_s, brain.carrying, priv._buf, priv._n,
            glob._buf, glob._n, self._par[r], nav.fst, nav.ist, nav._par, nav.rev_at, ranges, x, y, th, t,
            stalled, *nav._geo)
        (vr, wr, brain._path_m, has_crumb, cx, cy, brain._next_crumb_s, priv._n, cut, brain._following,
         brain._recovering, has_pref, pref, allow) = out
        brain._step = step
        brain._last_xy = (x, y)
        if has_crumb:
            brain._crumb_xy = (cx, cy)
        brain.loops_cut += cut
        return vr, wr, has_pref, pref, allow, False

    # ------------------------------------------------------------------ the team in one call
    def _init_state(self) -> None:
        """The brains' scalars (``BS_*``), crumb counts, the private lists' capacities, what
        they carry; the crumb buffers (the reference's own) as typed lists
        (:func:`blazing_team_step`)."""
        n = self._n
        self._bs = np.zeros((n, N_BS))
        self._pn = np.zeros(n, dtype=np.int64)
        self._gn = np.zeros(n, dtype=np.int64)
        self._cap = np.zeros(n, dtype=np.int64)
        self._carry = np.zeros(n, dtype=np.bool_)
        self._privs = _Buffers([b.private._buf for b in self._brains])
        self._globs = _Buffers([b.global_crumbs._buf for b in self._brains])

    def _from_brain(self, r: int) -> None:
        b = self._brains[r]
        row = self._bs[r]
        row[BS_PATH] = b._path_m
        last, crumb = b._last_xy, b._crumb_xy
        row[BS_HAS_LAST] = 0.0 if last is None else 1.0
        row[BS_LX], row[BS_LY] = (0.0, 0.0) if last is None else last
        row[BS_HAS_CRUMB] = 0.0 if crumb is None else 1.0
        row[BS_CX], row[BS_CY] = (0.0, 0.0) if crumb is None else crumb
        row[BS_NEXT] = b._next_crumb_s
        row[BS_CUT] = b.loops_cut
        row[BS_FOLLOW] = 1.0 if b._following else 0.0
        row[BS_RECOVER] = 1.0 if b._recovering else 0.0
        self._pn[r] = b.private._n
        self._sync_buffers(r)
        self._carry[r] = b.carrying
        self._last_step[r] = b._step

    def _sync_buffers(self, r: int) -> None:
        """Robot r's crumb buffers, the private list's capacity and the global list's count."""
        b = self._brains[r]
        self._privs.sync(r, b.private._buf)
        self._cap[r] = b.private._buf.shape[0]
        g = b.global_crumbs
        self._globs.sync(r, g._buf)
        self._gn[r] = g._n

    def _to_brain(self, r: int) -> None:
        b = self._brains[r]
        row = self._bs[r].tolist()
        b._path_m = row[BS_PATH]
        b._last_xy = (row[BS_LX], row[BS_LY]) if row[BS_HAS_LAST] else None
        b._crumb_xy = (row[BS_CX], row[BS_CY]) if row[BS_HAS_CRUMB] else None
        b._next_crumb_s = row[BS_NEXT]
        b.loops_cut = int(row[BS_CUT])
        b._following = bool(row[BS_FOLLOW])
        b._recovering = bool(row[BS_RECOVER])
        b.private._n = int(self._pn[r])
        b._step = int(self._last_step[r])

    def _before_team(self, obs, rows, t) -> None:
        inbox = obs.inbox
        for r in rows.tolist():
            if inbox[r] and self._take_inbox(self._brains[r], inbox[r], t):
                self._sync_buffers(r)
        full = rows[self._pn[rows] + 1 > self._cap[rows]]
        for r in full.tolist():  # room for one more private crumb
            priv = self._brains[r].private
            priv._n = int(self._pn[r])
            priv._reserve(1)
            self._sync_buffers(r)

    def _team_kernel(self, rows, ranges, poses, t, stalled, out_v, out_w, hint) -> None:
        blazing_team_step(rows, self._bs, self._pn, self._privs.typed, self._gn, self._globs.typed, self._par_all,
                          self._carry, self._nf, self._ni, self._npar, self._nrev, ranges, poses, t, stalled,
                          *self._ngeo, out_v, out_w, hint)

    @classmethod
    def _probe_params(cls, params: Any):
        from teamnav.papers.trails.brains.blazing_trail import navigate_params

        return navigate_params(params.navigate, params.cruise_speed_mps)


class TrailShareGroup(_TrailGroup):
    """``trail-share-v1`` teams (module docstring). A robot's step without task events or a
    broadcast due (nearly all of them: one broadcast per ``broadcast_interval_s``) runs the
    reference's inbox rule (§2.2 step 3, trails combined) and Trail expiry, then one compiled
    call (:func:`share_row_step`: the trail-using rule, the recovery, Navigate); any other step
    runs the reference brain's own step."""

    controller = "teamnav.papers.trails.brains.trail_share:TrailShare"

    @staticmethod
    def _param_row(p: Any) -> np.ndarray:
        sp = np.zeros(N_S)
        sp[S_DESCEND] = 1.0 if p.descend_only else 0.0
        sp[S_REACH] = p.reach_m
        sp[S_LOOK] = p.lookahead_m
        sp[S_RADIUS] = p.radius_m
        sp[S_RECOVER] = p.recover_radius_m
        sp[S_RECOVER_REV] = 1.0 if p.recover_reverse else 0.0
        return sp

    @staticmethod
    def _fast_brain(brain: Any) -> bool:
        return not brain._tell_bold

    @staticmethod
    def _due(brain: Any, t: float) -> bool:
        """A robot's first step, and one with a broadcast due."""
        return not brain._started or t >= brain._next_broadcast_s

    @staticmethod
    def _take_inbox(brain: Any, box: Sequence[Any]) -> bool:
        """§2.2 step 3, the reference's rule (:meth:`TrailShare.step
        <teamnav.papers.trails.brains.trail_share.TrailShare.step>`): each received Trail
        combined into the robot's own. Whether the robot communicates."""
        p = brain.params
        if not p.communicate:
            return False
        me = brain.info.robot_id
        trail = brain.trail
        for msg in box:
            if msg.kind == "trail" and isinstance(msg.body, TrailMessage) and msg.sender != me:
                if trail.combine(msg.body, p.policy, use_transforms=p.use_place_transforms) is None:
                    brain.refused += 1
                else:
                    brain.combined += 1
        return True

    def _row_step(self, brain, r, box, ranges, x, y, th, t, stalled, step) -> tuple:
        brain._step = step
        trail = brain.trail
        if box:
            self._take_inbox(brain, box)
        trail.expire(t, brain.params.crumb_max_age_s)  # §2.3 step 2 (the reference's own)
        code = trail._codes.get(brain.round.goal)
        nav = brain.nav
        vr, wr, brain._bound_s, brain._bound_t, brain._following, brain._recovering, has_pref, pref, ignore = \
            share_row_step(brain._bound_s, brain._bound_t, -1 if code is None else code, trail._xys, trail._p,
                           trail._n, self._par[r], nav.fst, nav.ist, nav._par, nav.rev_at, ranges, x, y, th, t,
                           stalled, *nav._geo)
        return vr, wr, has_pref, pref, True, ignore

    # ------------------------------------------------------------------ the team in one call
    def _init_state(self) -> None:
        """The brains' scalars (``SS_*``), goal codes, Trail counts, broadcast times; the Trails'
        buffers (the reference's own) as typed lists (:func:`share_team_step`)."""
        n = self._n
        self._ss = np.zeros((n, N_SS))
        self._code = np.full(n, -1, dtype=np.int64)
        self._tn = np.zeros(n, dtype=np.int64)
        self._started = np.zeros(n, dtype=np.bool_)
        self._next_b = np.zeros(n)
        self._xyss = _Buffers([b.trail._xys for b in self._brains])
        self._ps = _Buffers([b.trail._p for b in self._brains])

    def _from_brain(self, r: int) -> None:
        b = self._brains[r]
        row = self._ss[r]
        row[SS_BOUND_S] = b._bound_s
        row[SS_BOUND_T] = b._bound_t
        row[SS_FOLLOW] = 1.0 if b._following else 0.0
        row[SS_RECOVER] = 1.0 if b._recovering else 0.0
        self._started[r] = b._started
        self._next_b[r] = b._next_broadcast_s
        self._last_step[r] = b._step
        self._sync_trail(r)

    def _sync_trail(self, r: int) -> None:
        """Robot r's Trail buffers, count and goal code."""
        b = self._brains[r]
        tr = b.trail
        self._xyss.sync(r, tr._xys)
        self._ps.sync(r, tr._p)
        self._tn[r] = tr._n
        code = tr._codes.get(b.round.goal)
        self._code[r] = -1 if code is None else code

    def _to_brain(self, r: int) -> None:
        b = self._brains[r]
        row = self._ss[r].tolist()
        b._bound_s = row[SS_BOUND_S]
        b._bound_t = row[SS_BOUND_T]
        b._following = bool(row[SS_FOLLOW])
        b._recovering = bool(row[SS_RECOVER])
        b._step = int(self._last_step[r])

    def _team_due(self, active, t) -> np.ndarray:
        return active & ((~self._started) | (t >= self._next_b))

    def _before_team(self, obs, rows, t) -> None:
        inbox = obs.inbox
        for r in rows.tolist():
            b = self._brains[r]
            tr = b.trail
            age = b.params.crumb_max_age_s
            if inbox[r] and self._take_inbox(b, inbox[r]):
                tr.expire(t, age)  # §2.3 step 2
                self._sync_trail(r)
            elif tr._n and tr._t_min < t - age:  # expire() has crumbs to remove
                tr.expire(t, age)
                self._tn[r] = tr._n

    def _team_kernel(self, rows, ranges, poses, t, stalled, out_v, out_w, hint) -> None:
        share_team_step(rows, self._ss, self._code, self._xyss.typed, self._ps.typed, self._tn, self._par_all,
                        self._nf, self._ni, self._npar, self._nrev, ranges, poses, t, stalled, *self._ngeo, out_v,
                        out_w, hint)

    @classmethod
    def _probe_params(cls, params: Any):
        from teamnav.papers.trails.brains.blazing_trail import navigate_params
        from teamnav.papers.trails.brains.trail_share import TRAIL_SHARE_NAVIGATE

        return navigate_params({**TRAIL_SHARE_NAVIGATE, **params.navigate}, params.cruise_speed_mps)


def _renew_caches() -> None:
    """This module's kernels inline Navigate's compiled step (``navigate_compiled``) and what it
    calls: renew their numba caches when one of those changes (a cached kernel of this module
    went on calling an old form of the step, and crashed, 2026-11-29;
    :func:`~teamnav.control.group.renew_stale_caches`)."""
    from teamnav.control.group import renew_module_caches
    from teamnav.control.nav import openings
    from teamnav.control.nav.local import compiled as local_compiled

    renew_module_caches(__name__, (NC, openings, local_compiled))


_renew_caches()
