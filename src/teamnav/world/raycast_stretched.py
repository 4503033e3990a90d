"""The stretched quadrant-jump ray caster: the ranges of :mod:`teamnav.world.raycast`, bit for
bit, in about half the jumps.

The beam model of Monte Carlo localization (Fox et al. §3.2) casts the rays of every particle
on every update, so it takes this traversal (``RayCaster(..., stretched=True)``); the
simulator's sensors and the tiled maps of huge arenas keep the square one. A ray jumps over
the free square of its quadrant (:func:`~teamnav.world.raycast.clearance_map`) stretched along
its major axis into a free rectangle (:func:`stretch_map`); a jump whose exit point lies near
a grid line goes back to the square traversal, so that no rounding decision differs (the
argument is in :func:`stretch_map`).

This module holds the stretched kernels, :func:`stretch_map` and its cache per read-only mask.
The square traversal whose inlined kernels these call (``_code``, ``_start``, ``_wave``, ...),
the clearance maps, the shared per-mask cache and :class:`~teamnav.world.raycast.RayCaster`
stay in :mod:`teamnav.world.raycast`, which re-exports this module's names (they were defined
there until 2026-11-29).
"""

from __future__ import annotations

import math
import weakref

import numpy as np
from numba import njit, prange

from teamnav.world.raycast import (
    _MAX_CLEAR,
    _cached_per_mask,
    _code,
    _inv,
    _quadrant,
    _ray_dir,
    _start,
    _wave,
    clearance_map,  # noqa: F401 (the examples of stretch_map use it)
)

__all__ = ["STRETCH_GUARD_CELLS", "STRETCH_MIN_COMPONENT", "stretch_map"]


#: A stretched jump (:func:`_jump_st`) whose exit point lies within this of a grid line on the
#: other axis [cells], and a ray starting within it of a grid line, go back to the square
#: traversal (see :func:`stretch_map`): 10 000 times :data:`VERTEX_TOL_CELLS`.
STRETCH_GUARD_CELLS: float = 1e-5
#: Rays whose direction has a component below this in magnitude (but not 0) take the square
#: traversal from the start (a near-axis ray meets its exit rows through rounding).
STRETCH_MIN_COMPONENT: float = 1e-3


#: Poses whose rays advance together in :func:`_cast_serial_st` (split 8 ways, by octant).
_POSES_PER_WAVE_ST = 16


@njit(cache=True, inline="always")
def _jump_st(clear, ext, q, m, sx, sy, fx, fy, dx, dy, idx, idy, r, c, v, tmax):
    """:func:`_jump_s` over the stretched rectangle of :func:`stretch_map` (``m = 0``: the square
    of side ``v`` stretched along x to width ``ext[2 q, r, c, 1]``; ``m = 1``: along y).

    Returns ``(r, c, v, t, done, risky)``. ``risky``: the exit point lies within
    :data:`STRETCH_GUARD_CELLS` of a grid line on the other axis (this includes every vertex
    case, which is therefore not handled here); the caller then casts the ray again with the
    square traversal, and the answer is that traversal's. Otherwise the exit is evaluated with
    the same arithmetic on the same plane as the square traversal evaluates it there.
    """
    j = np.uint64(2 * q + m)
    e = np.int64(ext[j, np.uint64(r), np.uint64(c), np.uint64(1)]) - 1
    k = np.int64(v) - 1
    kx = e if m == 0 else k
    ky = k if m == 0 else e
    offx = 0 if sx > 0 else -1
    offy = 0 if sy > 0 else -1
    ck = c + sx * kx
    rk = r + sy * ky
    tx = ((ck + offx) - fx) * idx
    ty = ((rk + offy) - fy) * idy
    # both exit points, then selects: whether the ray leaves through an x- or a y-plane is
    # what a branch predictor would lose (5 % of the cast; written ``tx if ex else ty``, LLVM
    # branches). ``min`` gives the same bits as that select: tx and ty are > 0 here (the pose
    # is off the grid lines: _cast_serial_st), never NaN, and equal values are equal bits
    oex = fy + tx * dy
    oey = fx + ty * dx
    ex = tx < ty
    t = min(tx, ty)
    if t >= tmax:
        return r, c, v, tmax, True, False
    oe = oex if ex else oey
    fl = math.floor(oe)
    frac = oe - fl
    ifl = int(fl)
    risky = (frac <= STRETCH_GUARD_CELLS) | (frac >= 1.0 - STRETCH_GUARD_CELLS)
    lo = (r if sy > 0 else rk) if ex else (c if sx > 0 else ck)
    hi = (rk if sy > 0 else r) if ex else (ck if sx > 0 else c)
    of = min(max(ifl + 1, lo), hi)
    c = ck + sx if ex else of
    r = of if ex else rk + sy
    v = ext[j, np.uint64(r), np.uint64(c), np.uint64(0)]  # clear[r, c, q], in the plane just read
    return r, c, v, t, (v == 0) | risky, risky


@njit(cache=True, inline="always")
def _wave_st(clear, ext, q, m, sx, sy, act, n, fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res, fb, nf):
    """:func:`_wave` with stretched jumps; rays whose jump is risky are appended to
    ``fb[nf:]`` and dropped. Returns the new ``nf``."""
    while n > 0:
        k = 0
        for a in range(n):
            i = act[a]
            r, c, v, t, done, risky = _jump_st(clear, ext, q, m, sx, sy, fxs[i], fys[i], dxs[i], dys[i], idxs[i],
                                               idys[i], rs[i], cs[i], vs[i], tmax)
            ranges[i] = t * res
            rs[i] = r
            cs[i] = c
            vs[i] = v
            act[k] = i
            k += 0 if done else 1
            fb[nf] = i
            nf += 1 if risky else 0
        n = k
    return nf


@njit(cache=True, inline="always")
def _scratch_st(nb):
    """Scratch arrays of :func:`_cast_group_st` for poses of ``nb`` rays."""
    nr = _POSES_PER_WAVE_ST * nb
    return (np.empty(nr), np.empty(nr), np.empty(nr), np.empty(nr), np.empty(nr), np.empty(nr),
            np.empty(nr, np.int64), np.empty(nr, np.int64), np.empty(nr, np.uint8),
            np.empty((12, nr), np.uint64),  # 0-3: square traversal by quadrant; 4 + 2 q + m: stretched
            np.zeros(12, np.int64), np.empty(nr, np.uint64), np.empty(nr))


@njit(cache=True, inline="always")
def _cast_group_st(clear, ext, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, g0, g1, scratch):
    """Ranges [m] of poses ``g0 .. g1 - 1`` (at most :data:`_POSES_PER_WAVE_ST`) into
    ``scratch[-1]``: ray ``b`` of pose ``p`` at ``(p - g0) * B + b`` (see :func:`_cast_serial_st`)."""
    fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, act, cnt, fb, ranges = scratch
    inv = 1.0 / res
    nb = cb.shape[0]
    gd = STRETCH_GUARD_CELLS
    mc = STRETCH_MIN_COMPONENT
    cnt[:] = 0
    for p in range(g0, g1):
        fx = (xs[p] - ox) * inv
        fy = (ys[p] - oy) * inv
        r0, c0, ok = _start(clear, fx, fy)
        first = (p - g0) * nb
        if not ok:
            for b in range(nb):
                ranges[first + b] = 0.0
            continue
        free = np.int64(min(min(_code(clear, r0, c0, 0), _code(clear, r0, c0, 1)),
                            min(_code(clear, r0, c0, 2), _code(clear, r0, c0, 3)))) - 2
        if free >= tmax:
            for b in range(nb):
                ranges[first + b] = tmax * res
            continue
        ax = fx - math.floor(fx)
        ay = fy - math.floor(fy)
        on_line = ax <= gd or ax >= 1.0 - gd or ay <= gd or ay >= 1.0 - gd
        for b in range(nb):
            i = first + b
            dx, dy = _ray_dir(ct[p], st[p], cb[b], sb[b])
            fxs[i] = fx
            fys[i] = fy
            dxs[i] = dx
            dys[i] = dy
            idxs[i] = _inv(dx)
            idys[i] = _inv(dy)
            q = _quadrant(dx, dy)
            rs[i] = r0
            cs[i] = c0
            vs[i] = _code(clear, r0, c0, q)
            adx = abs(dx)
            ady = abs(dy)
            square = on_line or (adx < mc and adx != 0.0) or (ady < mc and ady != 0.0)
            j = q if square else 4 + 2 * q + (0 if adx >= ady else 1)
            act[j, cnt[j]] = i
            cnt[j] += 1
    nf = 0
    # octant j = 4 + 2 q + m: quadrant q = (dx < 0) + 2 (dy < 0), m = 1 when |dy| > |dx|
    nf = _wave_st(clear, ext, 0, 0, 1, 1, act[4], cnt[4], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res, fb, nf)
    nf = _wave_st(clear, ext, 0, 1, 1, 1, act[5], cnt[5], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res, fb, nf)
    nf = _wave_st(clear, ext, 1, 0, -1, 1, act[6], cnt[6], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res, fb, nf)
    nf = _wave_st(clear, ext, 1, 1, -1, 1, act[7], cnt[7], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res, fb, nf)
    nf = _wave_st(clear, ext, 2, 0, 1, -1, act[8], cnt[8], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res, fb, nf)
    nf = _wave_st(clear, ext, 2, 1, 1, -1, act[9], cnt[9], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res, fb, nf)
    nf = _wave_st(clear, ext, 3, 0, -1, -1, act[10], cnt[10], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res, fb, nf)
    nf = _wave_st(clear, ext, 3, 1, -1, -1, act[11], cnt[11], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res, fb, nf)
    for a in range(nf):  # the risky rays, again from their start with the square traversal
        i = fb[a]
        r0, c0, _ = _start(clear, fxs[i], fys[i])
        q = _quadrant(dxs[i], dys[i])
        rs[i] = r0
        cs[i] = c0
        vs[i] = _code(clear, r0, c0, q)
        act[q, cnt[q]] = i
        cnt[q] += 1
    _wave(clear, 0, 1, 1, act[0], cnt[0], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res)
    _wave(clear, 1, -1, 1, act[1], cnt[1], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res)
    _wave(clear, 2, 1, -1, act[2], cnt[2], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res)
    _wave(clear, 3, -1, -1, act[3], cnt[3], fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res)


@njit(cache=True)
def _cast_serial_st(clear, ext, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, out, p0, p1):
    """:func:`_cast_serial` with the stretched rectangles of :func:`stretch_map`: the same
    ranges, bit for bit, in about half the jumps.

    A ray takes the rectangle stretched along its major axis. Near-axis rays
    (:data:`STRETCH_MIN_COMPONENT`), poses within :data:`STRETCH_GUARD_CELLS` of a grid line
    and rays with a risky jump (:func:`_jump_st`) are cast with the square traversal of
    :func:`_cast_serial` instead, from their start.
    """
    nb = cb.shape[0]
    scratch = _scratch_st(nb)
    ranges = scratch[-1]
    for g0 in range(p0, p1, _POSES_PER_WAVE_ST):
        g1 = min(p1, g0 + _POSES_PER_WAVE_ST)
        _cast_group_st(clear, ext, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, g0, g1, scratch)
        for p in range(g0, g1):
            first = (p - g0) * nb
            for b in range(nb):
                out[p, b] = ranges[first + b]


@njit(cache=True, parallel=True)
def _cast_parallel_st(clear, ext, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, out, chunk):
    n = xs.shape[0]
    nchunks = (n + chunk - 1) // chunk
    for i in prange(nchunks):
        _cast_serial_st(clear, ext, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, out, i * chunk,
                        min(n, (i + 1) * chunk))


@njit(cache=True)
def _stretch_into(clear, out):
    """Fill ``out`` (8, H + 2, W + 2, 2) from the padded clearance maps ``clear`` (see :func:`stretch_map`)."""
    h = clear.shape[0]
    w = clear.shape[1]
    runx = np.zeros((h, w), np.uint8)  # free cells from (r, c) on towards the quadrant, along x
    runy = np.zeros((h, w), np.uint8)  # ... along y
    for q in range(4):
        dr = -1 if q & 2 else 1
        dc = -1 if q & 1 else 1
        for i in range(h):
            r = h - 1 - i if dr == 1 else i
            for j in range(w):
                c = w - 1 - j if dc == 1 else j
                if clear[r, c, q] == 0:
                    runx[r, c] = 0
                    runy[r, c] = 0
                else:  # the ring holds 0, so (r + dr, c + dc) is inside
                    runx[r, c] = min(np.int64(runx[r, c + dc]) + 1, _MAX_CLEAR)
                    runy[r, c] = min(np.int64(runy[r + dr, c]) + 1, _MAX_CLEAR)
        for r in range(h):
            for c in range(w):
                s = np.int64(clear[r, c, q])
                wx = _MAX_CLEAR
                hy = _MAX_CLEAR
                for k in range(s):  # the s rows (columns) of the square, each free for runx (runy) cells
                    wx = min(wx, np.int64(runx[r + dr * k, c]))
                    hy = min(hy, np.int64(runy[r, c + dc * k]))
                out[2 * q, r, c, 0] = s
                out[2 * q, r, c, 1] = wx if s > 0 else 0
                out[2 * q + 1, r, c, 0] = s
                out[2 * q + 1, r, c, 1] = hy if s > 0 else 0


def stretch_map(clear: np.ndarray) -> np.ndarray:
    """Free rectangles for the stretched jumps of the ray caster, from :func:`clearance_map`.

    Returns
    -------
    ndarray of shape (8, H + 2, W + 2, 2), uint8
        ``[2 q, r, c]``: ``(s, w)``, ``s = clear[r, c, q]`` and a width ``w >= s`` such that
        the rectangle of ``w`` columns and ``s`` rows from padded cell ``(r, c)`` towards
        quadrant ``q`` is free (the quadrant's square stretched along x); ``[2 q + 1, r, c]``:
        ``(s, h)``, the square stretched along y to height ``h``. 0 where ``s`` is 0; capped at
        255. One plane per octant, the code beside the extent: the rays of one wave read one
        plane, and each jump one byte pair (a jump ends by reading the code of the cell it
        enters, the next one starts with its extent). The widest (tallest) such rectangle:
        the least free run along the square's rows (columns); O(sum of the codes).

    A ray that runs along a wall or a corridor crosses many small squares (their side is its
    distance to the wall); the square stretched along the ray's major axis lets it cross the
    same free cells in one jump: 2.3 jumps a ray instead of 4.5 for the 60 000 rays of a
    1000-particle MCL update on the MIT basement map.

    Why the ranges stay the same bit for bit: every jump ends on a grid plane, and the
    distance ``t = (plane - origin) / direction`` and the exit point on the other axis are
    computed from that plane alone, with the same operations in both traversals; wherever both
    evaluate a plane they get the same bits. The range is the ``t`` of the plane through which
    the ray enters its first blocking cell, and both traversals end on it, unless a decision
    depends on more than the plane: the vertex rule (an exit point within
    :data:`VERTEX_TOL_CELLS` of a grid vertex) and the clamp of the exit row to the square
    (the rounding of a near-axis ray). So a stretched jump whose exit point lies within
    :data:`STRETCH_GUARD_CELLS` (10 000 times the vertex tolerance) of a grid line, a ray with
    a direction component under :data:`STRETCH_MIN_COMPONENT`, and a pose within the guard of
    a grid line are cast with the squares from their start (:func:`_cast_serial_st`). A vertex
    beside a blocking cell, where the vertex rule can stop the square traversal, lies on the
    border of every free rectangle around the ray, so the stretched jump exits near it and is
    caught. ``tests/test_raycast_stretched.py`` compares the two bit for bit; without the
    guard its vertex cases differ.

    Memory: 16 bytes a cell (the code repeated in each octant's plane beside the extent) on
    top of the 4 of the clearance maps, 23 MB for the MIT basement: opt-in
    (``RayCaster(..., stretched=True)``), which the beam model of MCL takes; the simulator's
    sensors and the tiled maps of huge arenas keep the squares.

    Examples
    --------
    >>> b = np.zeros((3, 6), np.uint8); b[2, 1] = 1
    >>> e = stretch_map(clearance_map(b))
    >>> e[0, 1, 1].tolist(), e[1, 1, 1].tolist(), e[0, 2, 2].tolist()  # grid cell (0, 0) towards +x, +y; (1, 1)
    ([2, 6], [2, 2], [1, 5])
    """
    clear = np.ascontiguousarray(clear, dtype=np.uint8)
    if clear.ndim != 3 or clear.shape[2] != 4:
        raise ValueError(f"clear must be clearance_map(...) of shape (H + 2, W + 2, 4), got {clear.shape}")
    out = np.empty((8, clear.shape[0], clear.shape[1], 2), np.uint8)
    _stretch_into(clear, out)
    return out


_STRETCH_CACHE: dict[int, tuple[weakref.ref, np.ndarray]] = {}


def _cached_stretch(blocking: np.ndarray, clear: np.ndarray) -> np.ndarray:
    """:func:`stretch_map` of ``clear = clearance_map(blocking)``, cached while a read-only mask
    is alive (:func:`_cached_per_mask`): every filter on one map shares it (~75 ms and 16 bytes
    a cell for the MIT basement)."""
    return _cached_per_mask(_STRETCH_CACHE, blocking, lambda: stretch_map(clear))
