"""Range-sensor rays that stop on other robots' bodies (discs).

The ray caster of :mod:`teamnav.world.raycast` only knows the map. Robots are discs that
move every step, so they are not burnt into the grid; instead, once the map ranges of a step
are known, this module shortens every ray that meets another robot's disc first:

``range[i, b] = min(range[i, b], t)`` where ``t`` is the distance from robot ``i`` along ray
``b`` to the nearest intersection with any *other* robot's disc.

The sensing robot's own disc is skipped (its sensor sits inside it), as Stage does
(``libstage/model_ranger.cc``: the ranger's raytrace ignores the model that owns it).

Scaling
-------
Robot centres are bucketed once per call in a dense grid of square cells (side
``(max_range_m + max(radius)) / 2`` by default, enlarged so that there are at most 4 cells
per robot: memory O(N) whatever the size of the world; a counting sort, so O(N)). Robot
``i`` visits only the cells overlapping the square of half-side ``reach_i + max(radius)``
around it, where ``reach_i`` is the longest map range among its own rays (a robot behind a
wall that every ray already stops at cannot be hit). A disc ``j`` is then dropped, before any
angle is computed, when ``|c_j - p_i| - r_j >= reach_i`` or when it lies wholly behind a fan
no wider than a half-turn. The survivors are intersected only with the rays inside their
angular window ``bearing +- (r / sqrt(d^2 - r^2) + margin)`` (wider than ``asin(r / d)``):
for an even fan the window's ray indices are floor/ceil of ``(angle - first) / step``, for
any other set of directions a binary search over the sorted directions; the bearing comes
from a polynomial ``atan2`` good to 4e-8 rad, well inside the margin. Every ray of a window is
intersected with the same arithmetic as :func:`robot_hits_reference`, so the result is
identical to testing every ray against every disc (the tests compare bit for bit).
A robot without another disc within that reach (a first look at its cells, with the same
window and test) skips the rest: its row could not change.
Sensing robots are spread over numba's threads (``prange``) once there are
``PARALLEL_MIN_RAYS`` rays: on the 2-core development machine smaller calls gained nothing.
Cost per step: O(N) for the hash plus O(sum over i of (candidates_i + window rays_i)).
The engine's sensors call the per-robot core :func:`_robot_hits_row` from their one-pass
kernel (:meth:`~teamnav.sim.sensors.range_sensors.RangeSensor._pass`): near discs before the
map cast, far ones after it, within a box.

Measured (1000 robots x 180 beams on the MIT basement map, one thread, busy 2-core box):
21 ms with the former sorted-key hash, ``atan2``/``asin`` and binary searches per disc;
12.7 ms with the dense hash, arithmetic windows and the ``tan`` bound; 9.9 ms with the
polynomial ``atan2``; 8.4 ms without per-ray or per-block "already shorter" tests (they
mispredict more than they save: one front disc in seven is hidden, and its window is ~3
rays); 7.3 ms with the half-plane cull; 6.8 ms rotating the rays once per robot; 6.0 ms
wrapping the bearing by a conditional add instead of ``floor`` of a division. Per robot:
~210 candidates, ~155 within reach, half of them behind, ~480 ray-disc intersections.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

__all__ = ["PARALLEL_MIN_RAYS", "BeamPlan", "apply_robot_hits", "beam_plan", "check_bodies", "default_cell_m",
           "robot_hits_reference", "robot_hits_unchecked"]

#: Extra half-width [rad] of the angular window of rays tested against a disc, so that a
#: ray grazing the disc is never skipped: covers :func:`_fast_atan2`'s error (< 4e-8 rad)
#: and rounding.
_ANGLE_MARGIN_RAD: float = 1e-6
#: Odd minimax polynomial ``atan(a) ~ a P(a^2)`` on ``[0, 1]`` (8 terms, |error| < 4e-8 rad;
#: Abramowitz & Stegun 4.4.49 form, coefficients refitted), tested in tests/test_sensors.py.
_ATAN_COEFFS = (0.9999993355776595, -0.33329860775195863, 0.19946565505954247, -0.13908628679642634,
                0.09642194818765205, -0.055912289332481796, 0.021862930032968544, -0.00405455905160092)
#: Fewest rays (sensing robots x rays) for which :func:`apply_robot_hits` goes parallel by default.
PARALLEL_MIN_RAYS: int = 20_000
#: Added to a robot's longest ray [m] before discs are culled by distance, so that a hit
#: at (almost) exactly that range is never lost to rounding of ``d - r``.
_REACH_SLACK_M: float = 1e-9
#: Largest deviation [rad] of a ray from the even fan ``first + k * step`` for the fan to
#: be indexed by arithmetic (far below ``_ANGLE_MARGIN_RAD``).
_EVEN_TOL_RAD: float = 1e-12
#: The ``box`` of :func:`_robot_hits_row` that holds every disc.
_ALL = (-np.inf, np.inf, -np.inf, np.inf)
#: Hash cells per robot at most (the cell side grows beyond that: sparse, huge worlds).
_CELLS_PER_ROBOT: int = 4
#: Sensing robots per chunk of :func:`_robot_hits_parallel` (one pair of scratch arrays each).
_HITS_CHUNK: int = 64
#: :func:`_robot_hits_row` reads, in each hash column of a window wider than this many
#: columns, only the rows that can hold a disc its culls keep (narrower windows: the
#: arithmetic costs about what it saves). Measured 2026-11-29, the near pass (6 m) of
#: 10 000 laser robots in bench_scale's open arena, one thread: 49.5 -> 47 ms.
_CLIP_MIN_COLUMNS: int = 3
#: Rounding margin [m] of those rows (far above the rounding of metre-scale coordinates).
_CLIP_SLACK_M: float = 1e-6


# ---------------------------------------------------------------------------- kernels
@njit(cache=True)
def _lower(keys, k):
    """First index of sorted ``keys`` with ``keys[idx] >= k``."""
    lo = 0
    hi = keys.shape[0]
    while lo < hi:
        mid = (lo + hi) >> 1
        if keys[mid] < k:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True)
def _upper(keys, k):
    """First index of sorted ``keys`` with ``keys[idx] > k``."""
    lo = 0
    hi = keys.shape[0]
    while lo < hi:
        mid = (lo + hi) >> 1
        if keys[mid] <= k:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, inline="always")
def _fast_atan2(y, x):
    """``atan2(y, x)`` in ``[-pi, pi]`` to within 4e-8 rad (polynomial, no libm call; 0 at the origin)."""
    ax = abs(x)
    ay = abs(y)
    mx = max(ax, ay)
    if mx == 0.0:
        return 0.0
    a = min(ax, ay) / mx
    s = a * a
    c0, c1, c2, c3, c4, c5, c6, c7 = _ATAN_COEFFS
    r = a * (c0 + s * (c1 + s * (c2 + s * (c3 + s * (c4 + s * (c5 + s * (c6 + s * c7)))))))
    if ay > ax:
        r = 0.5 * math.pi - r
    if x < 0.0:
        r = math.pi - r
    if y < 0.0:
        r = -r
    return r


@njit(cache=True, inline="always")
def _disc_hit(fx, fy, dx, dy, r2):
    """Distance along unit ray ``(dx, dy)`` from a point at offset ``f = origin - centre``
    to the first crossing of a disc of squared radius ``r2``: 0 when the origin is inside
    or on the disc, ``inf`` when the ray misses it or the disc is behind."""
    cc = fx * fx + fy * fy - r2
    if cc <= 0.0:
        return 0.0
    b = fx * dx + fy * dy
    if b >= 0.0:  # centre behind (or abeam of) an origin outside the disc
        return np.inf
    disc = b * b - cc
    if disc < 0.0:
        return np.inf
    return -b - math.sqrt(disc)


@njit(cache=True, inline="always")
def _even_span(lo, hi, inv_step, nb):
    """Beams ``[k0, k1)`` of an even fan (beam ``k`` at ``k * step`` past the first) inside ``[lo, hi]``."""
    k0 = max(0, int(math.ceil(lo * inv_step)))
    k1 = min(nb, int(math.floor(hi * inv_step)) + 1)
    return k0, k1


@njit(cache=True)
def _build_hash(all_x, all_y, all_r, cell_m, max_cells):
    """Bucket the discs in a dense grid of square cells (counting sort).

    Returns ``(sx, sy, sr, sid, start, x0, y0, cell, nkx, nky)``: disc coordinates, radii
    and indices in cell order (cell ``kx * nky + ky`` holds ``start[c]:start[c + 1]``). The
    cell side grows past ``cell_m`` if the grid would have more than ``max_cells`` cells.
    """
    n = all_x.shape[0]
    x0 = all_x.min()
    y0 = all_y.min()
    wx = all_x.max() - x0
    wy = all_y.max() - y0
    cell = cell_m
    while (math.floor(wx / cell) + 1.0) * (math.floor(wy / cell) + 1.0) > max_cells:
        cell *= 1.5
    nkx = int(math.floor(wx / cell)) + 1
    nky = int(math.floor(wy / cell)) + 1
    key = np.empty(n, np.int64)
    start = np.zeros(nkx * nky + 1, np.int64)
    for j in range(n):
        kx = min(nkx - 1, int(math.floor((all_x[j] - x0) / cell)))
        ky = min(nky - 1, int(math.floor((all_y[j] - y0) / cell)))
        key[j] = kx * nky + ky
        start[key[j] + 1] += 1
    for c in range(nkx * nky):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    sx = np.empty(n)
    sy = np.empty(n)
    sr = np.empty(n)
    sid = np.empty(n, np.int64)
    for j in range(n):  # ascending j within a cell: a stable order
        s = fill[key[j]]
        fill[key[j]] += 1
        sx[s] = all_x[j]
        sy[s] = all_y[j]
        sr[s] = all_r[j]
        sid[s] = j
    return sx, sy, sr, sid, start, x0, y0, cell, nkx, nky


@njit(cache=True)
def _robot_hits_rows(i0, i1, xs, ys, ct, st, self_idx, beams, even, hsh, out):
    """Shorten rows ``i0:i1`` of ``out`` (map ranges, modified in place) by other robots' discs.

    A disc is skipped before any angle is computed when ``d - r`` is beyond the longest map
    ray of robot ``i`` (no hit on it could shorten a ray); :func:`_robot_hits_row` does the rest.
    The rays' world directions go to scratch arrays allocated once for the rows (each row
    fills them before reading them): two allocations per robot cost a 7-ray proximity ring
    more than its intersections.
    """
    nb = out.shape[1]
    rdx = np.empty(nb)
    rdy = np.empty(nb)
    sx, sy, sr, sid, start, x0, y0, cell, nkx, nky, rmax = hsh
    for i in range(i0, i1):
        reach = 0.0
        for b in range(nb):
            reach = max(reach, out[i, b])
        if reach <= 0.0:
            continue
        # a first look at the discs within reach, with _robot_hits_row's own window and test:
        # most robots of a sparse swarm have none, and then the row would change nothing
        px = xs[i]
        py = ys[i]
        me = self_idx[i]
        lim0 = reach + _REACH_SLACK_M
        half = lim0 + rmax
        kx0 = max(0, int(math.floor((px - half - x0) / cell)))
        kx1 = min(nkx - 1, int(math.floor((px + half - x0) / cell)))
        ky0 = max(0, int(math.floor((py - half - y0) / cell)))
        ky1 = min(nky - 1, int(math.floor((py + half - y0) / cell)))
        near = False
        if ky0 <= ky1:
            for kx in range(kx0, kx1 + 1):
                for s in range(start[kx * nky + ky0], start[kx * nky + ky1 + 1]):
                    gx = sx[s] - px
                    gy = sy[s] - py
                    lim = lim0 + sr[s]
                    if gx * gx + gy * gy < lim * lim and sid[s] != me:
                        near = True
                        break
                if near:
                    break
        if near:
            _robot_hits_row(px, py, ct[i], st[i], me, 0.0, reach, beams, even, hsh, out[i], rdx, rdy, True, _ALL)


@njit(cache=True, inline="always")
def _robot_hits_row(px, py, cti, sti, me, inner, reach, beams, even, hsh, row, rdx, rdy, set_dirs, box):
    """``row[b] = min(row[b], first hit of ray b on a disc other than ``me``)`` for a sensor
    at ``(px, py)`` heading ``(cti, sti)`` (cos, sin); discs whose nearest point is ``reach``
    or more away are skipped (``reach <= 0``: none is tested), and with ``inner > 0`` also
    those a call of ``reach = inner`` tests (the same comparison, so two calls, ``reach = a``
    then ``inner = a``, test every disc exactly once). ``rdx, rdy`` (R,): the rays' world
    directions, filled when ``set_dirs`` (else as a previous call for this pose left them).
    ``box = (x0, x1, y0, y1)`` [m]: only discs centred in it are tested (infinite: all).

    ``beams = (cb, sb, sorted_ang, ray_order)``: cos/sin of the ray directions, the
    directions wrapped to ``[-pi, pi)`` in ascending order and their ray indices.
    ``even = (is_even, first, inv_step)``: when the rays form an even fan (ray ``k`` at
    ``first + k * step``, all within one turn; then ``ray_order`` is the identity) a disc's
    rays are found by arithmetic, otherwise by binary search in ``sorted_ang``.
    ``hsh``: :func:`_build_hash`'s result and the largest radius.

    A disc of radius ``r`` at distance ``d`` and body-frame bearing ``phi`` can only be met
    by rays within ``asin(r / d)`` of ``phi``; the window used is the wider
    ``r / sqrt(d^2 - r^2)`` (``tan >= angle``, and no ``asin``) plus ``_ANGLE_MARGIN_RAD``,
    and every ray inside it is intersected exactly, so the result is that of testing every
    ray. The ``min`` is order-free, so any ``reach`` at least the row's longest entry gives
    the same row bit for bit.
    """
    cb, sb, sorted_ang, ray_order = beams
    is_even, first, inv_step, front, mid = even
    sx, sy, sr, sid, start, x0, y0, cell, nkx, nky, rmax = hsh
    nb = cb.shape[0]
    two_pi = 2.0 * math.pi
    # rays of a fan no wider than a half-turn stay in the half-plane ahead of its middle
    # direction: a disc wholly behind that line is skipped before any angle is computed
    hx = math.cos(mid) * cti - math.sin(mid) * sti if front else 0.0
    hy = math.cos(mid) * sti + math.sin(mid) * cti if front else 0.0
    if set_dirs:
        for b in range(nb):  # world directions of the rays (the reference's arithmetic, once per robot)
            rdx[b] = cti * cb[b] - sti * sb[b]
            rdy[b] = sti * cb[b] + cti * sb[b]
    if reach <= 0.0 or reach <= inner:
        return
    reach += _REACH_SLACK_M
    has_inner = inner > 0.0
    inner += _REACH_SLACK_M
    half = reach + rmax
    bx0, bx1, by0, by1 = box
    kx0 = max(0, int(math.floor((max(px - half, bx0) - x0) / cell)))
    kx1 = min(nkx - 1, int(math.floor((min(px + half, bx1) - x0) / cell)))
    ky0 = max(0, int(math.floor((max(py - half, by0) - y0) / cell)))
    ky1 = min(nky - 1, int(math.floor((min(py + half, by1) - y0) / cell)))
    if ky0 > ky1:  # the window misses the hash grid (a far box beyond every disc): nothing to test,
        return     # and start[kx * nky + ky0] could lie past the end of `start` (read out of bounds)
    # a window of _CLIP_MIN_COLUMNS + 1 columns or more reads in each column only the rows
    # that can hold a centre the culls below would keep: within `half` of the sensor, and
    # (a fan no wider than a half-turn) not wholly behind its half-plane, for any radius up to
    # rmax; 1e-6 m more for rounding (the culls decide, exactly as before, for every disc read)
    clip = kx1 - kx0 >= _CLIP_MIN_COLUMNS
    hcut = -(rmax + _REACH_SLACK_M) - _CLIP_SLACK_M  # gx hx + gy hy below this: culled, whatever r
    for kx in range(kx0, kx1 + 1):
        kya = ky0
        kyb = ky1
        if clip:
            ua = x0 + kx * cell - _CLIP_SLACK_M - px  # the column's x offsets from the sensor
            ub = x0 + (kx + 1) * cell + _CLIP_SLACK_M - px
            un = ua if ua > 0.0 else (ub if ub < 0.0 else 0.0)  # the nearest
            w2 = half * half - un * un
            if w2 < 0.0:
                continue
            wy = math.sqrt(w2) + _CLIP_SLACK_M
            lo = -wy  # the rows' y offsets from the sensor
            hi = wy
            if front:
                gxh = max(ua * hx, ub * hx)  # the column's largest gx hx
                if abs(hy) > 0.25:
                    lim_y = (hcut - gxh) / hy  # kept: gy hy >= hcut - gx hx
                    if hy > 0.0:
                        lo = max(lo, lim_y - _CLIP_SLACK_M)
                    else:
                        hi = min(hi, lim_y + _CLIP_SLACK_M)
                if gxh + max(lo * hy, hi * hy) < hcut:  # the whole column behind
                    continue
            kya = max(ky0, int(math.floor((py + lo - y0) / cell)))
            kyb = min(ky1, int(math.floor((py + hi - y0) / cell)))
            if kya > kyb:
                continue
        # cells (kx, kya..kyb) are contiguous
        s0 = start[kx * nky + kya]
        s1 = start[kx * nky + kyb + 1]
        for s in range(s0, s1):
            gx = sx[s] - px  # sensor -> centre
            gy = sy[s] - py
            r = sr[s]
            d2 = gx * gx + gy * gy
            lim = reach + r
            if d2 >= lim * lim or sid[s] == me or gx * hx + gy * hy < -r - _REACH_SLACK_M:
                continue
            if has_inner:
                lin = inner + r  # as `lim` of the call with reach = inner
                if d2 < lin * lin:
                    continue
            r2 = r * r
            if d2 <= r2:  # sensor inside the disc: every ray stops at once
                for b in range(nb):
                    row[b] = 0.0
                continue
            # bearing of the centre in the body frame, in [-pi, pi]
            phi = _fast_atan2(cti * gy - sti * gx, cti * gx + sti * gy)
            beta = r / math.sqrt(d2 - r2) + _ANGLE_MARGIN_RAD
            # the rays to intersect: positions [ka0, ka1) and [kb0, kb1) in ray_order
            kb0 = 0
            kb1 = 0
            if beta >= math.pi:
                ka0 = 0
                ka1 = nb
            elif is_even:
                u = phi - first
                if u < 0.0:
                    u += two_pi
                if not (0.0 <= u < two_pi):  # first far outside [-pi, pi]
                    u -= two_pi * math.floor(u / two_pi)  # [0, 2 pi)
                ka0, ka1 = _even_span(u - beta, u + beta, inv_step, nb)
                if u - beta < 0.0:
                    kb0, kb1 = _even_span(u - beta + two_pi, u + beta + two_pi, inv_step, nb)
                elif u + beta >= two_pi:
                    kb0, kb1 = _even_span(u - beta - two_pi, u + beta - two_pi, inv_step, nb)
            else:
                if phi >= math.pi:
                    phi -= two_pi
                a0 = phi - beta
                a1 = phi + beta
                ka0 = _lower(sorted_ang, a0)
                ka1 = _upper(sorted_ang, a1)
                if a0 < -math.pi:
                    kb0 = _lower(sorted_ang, a0 + two_pi)
                    kb1 = nb
                elif a1 >= math.pi:
                    kb1 = _upper(sorted_ang, a1 - two_pi)
            # written out here rather than in a helper: numba increfs/decrefs every array
            # handed to a call (even an inlined one), which cost more than the rays
            fx = -gx  # origin - centre
            fy = -gy
            cc = d2 - r2  # > 0: the origin is outside the disc
            for part in range(2):
                k0 = ka0 if part == 0 else kb0
                k1 = ka1 if part == 0 else kb1
                if is_even:  # ray k is ray k: unit-stride loads, which the compiler vectorizes
                    if k1 <= k0:
                        continue
                    wx = rdx[k0:k1]
                    wy = rdy[k0:k1]
                    wr = row[k0:k1]
                    for j in range(k1 - k0):
                        bb = fx * wx[j] + fy * wy[j]
                        disc = bb * bb - cc
                        t = -bb - math.sqrt(disc if disc > 0.0 else 0.0)
                        t = t if (bb < 0.0) & (disc >= 0.0) else np.inf
                        o = wr[j]
                        wr[j] = t if t < o else o
                    continue
                for k in range(k0, k1):
                    # _disc_hit's arithmetic with selects for branches (short spans mispredict)
                    b = ray_order[k]
                    dx = rdx[b]
                    dy = rdy[b]
                    bb = fx * dx + fy * dy
                    disc = bb * bb - cc
                    t = -bb - math.sqrt(max(disc, 0.0))
                    t = t if (bb < 0.0 and disc >= 0.0) else np.inf
                    row[b] = min(row[b], t)


@njit(cache=True)
def _prepare(all_x, all_y, all_r, max_range_m, cell_m):
    """:func:`_build_hash` (cell side :func:`default_cell_m` when ``cell_m <= 0``) plus the
    largest radius, as the ``hsh`` tuple of :func:`_robot_hits_rows`."""
    rmax = 0.0
    for j in range(all_r.shape[0]):
        rmax = max(rmax, all_r[j])
    if cell_m <= 0.0:
        cell_m = max(1e-3, 0.5 * (max_range_m + rmax))
    sx, sy, sr, sid, start, x0, y0, cell, nkx, nky = _build_hash(all_x, all_y, all_r, cell_m,
                                                                 _CELLS_PER_ROBOT * all_x.shape[0] + 16)
    return (sx, sy, sr, sid, start, x0, y0, cell, nkx, nky, rmax)


@njit(cache=True, parallel=True)
def _robot_hits_parallel(xs, ys, ct, st, self_idx, beams, even, all_x, all_y, all_r, max_range_m, cell_m, out):
    """:func:`_robot_hits_rows` for every sensing robot, in chunks of :data:`_HITS_CHUNK`
    spread over numba's threads."""
    hsh = _prepare(all_x, all_y, all_r, max_range_m, cell_m)
    n = xs.shape[0]
    for c in prange((n + _HITS_CHUNK - 1) // _HITS_CHUNK):
        _robot_hits_rows(c * _HITS_CHUNK, min(n, (c + 1) * _HITS_CHUNK), xs, ys, ct, st, self_idx, beams, even, hsh,
                         out)


@njit(cache=True)
def _robot_hits_serial(xs, ys, ct, st, self_idx, beams, even, all_x, all_y, all_r, max_range_m, cell_m, out):
    """:func:`_robot_hits_rows` for every sensing robot, in this thread (one call: small teams
    pay a single dispatch)."""
    hsh = _prepare(all_x, all_y, all_r, max_range_m, cell_m)
    _robot_hits_rows(0, xs.shape[0], xs, ys, ct, st, self_idx, beams, even, hsh, out)


@njit(cache=True)
def _reference_kernel(xs, ys, ct, st, cb, sb, self_idx, all_x, all_y, all_r, out):
    """Every sensing robot against every robot, no hash (for tests)."""
    for i in range(xs.shape[0]):
        for j in range(all_x.shape[0]):
            if j == self_idx[i]:
                continue
            fx = xs[i] - all_x[j]
            fy = ys[i] - all_y[j]
            r2 = all_r[j] * all_r[j]
            for b in range(cb.shape[0]):
                dx = ct[i] * cb[b] - st[i] * sb[b]
                dy = st[i] * cb[b] + ct[i] * sb[b]
                t = _disc_hit(fx, fy, dx, dy, r2)
                if t < out[i, b]:
                    out[i, b] = t


# ---------------------------------------------------------------------------- API
class BeamPlan(NamedTuple):
    """What :func:`_robot_hits_rows` needs to know of a sensor's ray directions (built once).

    Attributes
    ----------
    beams : tuple of 4 ndarrays
        ``(cos (R,), sin (R,), sorted_ang (R,), ray_order (R,) int64)``: the directions
        wrapped to ``[-pi, pi)`` in ascending order and the ray index of each (the identity
        for an even fan).
    even : tuple (bool, float, float, bool, float)
        ``(is_even, first_rad, 1 / step_rad, front, mid_rad)``: ray ``k`` is at
        ``first + k * step`` to within ``_EVEN_TOL_RAD`` and the fan spans less than a turn;
        ``front``: the fan spans at most a half-turn around ``mid_rad`` (so no ray leaves
        the half-plane ahead of that direction).
    """

    beams: tuple
    even: tuple


def beam_plan(angles_rad: np.ndarray) -> BeamPlan:
    """The :class:`BeamPlan` of ray directions ``angles_rad`` (R,) [rad] (unchecked)."""
    angles = np.ascontiguousarray(angles_rad, dtype=np.float64)
    nb = angles.shape[0]
    even = False
    first, inv_step = 0.0, 0.0
    if nb == 1:
        even, first, inv_step = True, float(angles[0]), 1.0 / (2 * np.pi)
    elif nb > 1:
        step = (angles[-1] - angles[0]) / (nb - 1)
        fan = angles[0] + step * np.arange(nb)
        if step > 0 and step * nb <= 2 * np.pi + _EVEN_TOL_RAD and np.max(np.abs(angles - fan)) <= _EVEN_TOL_RAD:
            even, first, inv_step = True, float(angles[0]), 1.0 / step
    front, mid = False, 0.0
    if even and nb > 1:
        mid = float(0.5 * (angles[0] + angles[-1]))
        front = bool(angles[-1] - angles[0] <= np.pi and np.max(np.abs(angles - mid)) <= 0.5 * np.pi)
    wrapped = angles - 2 * np.pi * np.floor((angles + np.pi) / (2 * np.pi))  # [-pi, pi)
    ray_order = np.arange(nb, dtype=np.int64) if even else np.argsort(wrapped, kind="stable").astype(np.int64)
    beams = (np.cos(angles), np.sin(angles), np.ascontiguousarray(wrapped[ray_order]), ray_order)
    return BeamPlan(beams, (even, first, inv_step, front, mid))


def robot_hits_unchecked(xs, ys, thetas, plan: BeamPlan, all_x, all_y, all_r, self_idx, ranges, max_range_m,
                         cell_m, parallel: bool, cs_theta=None) -> np.ndarray:
    """:func:`apply_robot_hits` without input checks, for callers whose arrays are known good.

    ``xs, ys, thetas, all_x, all_y, all_r`` contiguous float64, ``self_idx`` int64,
    ``ranges`` (n, R) C-contiguous float64, ``plan`` from :func:`beam_plan`, ``cell_m`` the
    hash cell side [m] or 0 for :func:`default_cell_m`, ``cs_theta`` None or
    ``(np.cos(thetas), np.sin(thetas))`` when the caller has them. The engine's sensors call
    this every step.
    """
    if xs.shape[0] == 0 or all_x.shape[0] == 0 or ranges.shape[1] == 0:
        return ranges
    kernel = _robot_hits_parallel if parallel else _robot_hits_serial
    # cos/sin by NumPy, as robot_hits_reference: the rays' directions agree to the last bit
    ct, st = (np.cos(thetas), np.sin(thetas)) if cs_theta is None else cs_theta
    kernel(xs, ys, ct, st, self_idx, plan.beams, plan.even, all_x, all_y, all_r, float(max_range_m), float(cell_m),
           ranges)
    return ranges


def _vec(name: str, value, n: int | None = None, dtype=np.float64) -> np.ndarray:
    arr = np.ascontiguousarray(value, dtype=dtype)
    if arr.ndim != 1 or (n is not None and arr.shape[0] != n):
        want = "(n,)" if n is None else f"({n},)"
        raise ValueError(f"{name} must be a 1-D array of shape {want}, got shape {arr.shape}")
    if dtype == np.float64 and not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr[~np.isfinite(arr)][:3].tolist()}")
    return arr


def check_bodies(bodies, n: int) -> tuple:
    """Validated ``bodies`` tuple ``(all_x (N,), all_y (N,), all_radius (N,) >= 0, self_index (n,) int64)``."""
    if not (isinstance(bodies, tuple) and len(bodies) == 4):
        raise ValueError(
            "bodies must be a tuple (all_x (N,), all_y (N,), all_radius (N,), self_index (n,)), "
            f"got {type(bodies).__name__}"
        )
    all_x = _vec("bodies[0] (all_x)", bodies[0])
    nn = all_x.shape[0]
    all_y = _vec("bodies[1] (all_y)", bodies[1], nn)
    all_r = _vec("bodies[2] (all_radius)", bodies[2], nn)
    if np.any(all_r < 0.0):
        raise ValueError(f"bodies[2] (all_radius) must be >= 0 [m], got min {float(all_r.min())}")
    self_idx = _vec("bodies[3] (self_index)", bodies[3], n, dtype=np.int64)
    return all_x, all_y, all_r, self_idx


def _check_inputs(xs, ys, thetas, angles_rad, bodies, ranges):
    xs = _vec("xs", xs)
    n = xs.shape[0]
    ys = _vec("ys", ys, n)
    thetas = _vec("thetas", thetas, n)
    angles = _vec("angles_rad", angles_rad)
    all_x, all_y, all_r, self_idx = check_bodies(bodies, n)
    if not (isinstance(ranges, np.ndarray) and ranges.dtype == np.float64 and ranges.shape == (n, angles.shape[0])
            and ranges.flags.c_contiguous and ranges.flags.writeable):
        raise ValueError(
            f"ranges must be a writeable C-contiguous float64 array of shape ({n}, {angles.shape[0]}), got "
            f"{getattr(ranges, 'dtype', type(ranges).__name__)} {getattr(ranges, 'shape', '')}"
        )
    return xs, ys, thetas, angles, all_x, all_y, all_r, self_idx


def apply_robot_hits(xs, ys, thetas, angles_rad, bodies, ranges, max_range_m, cell_m=None, parallel=None) -> np.ndarray:
    """Shorten map ranges by the first hit on another robot's disc, in place.

    Parameters
    ----------
    xs, ys, thetas : ndarray of shape (n,)
        True poses of the sensing robots [m, m, rad].
    angles_rad : ndarray of shape (R,)
        Ray directions in the body frame [rad].
    bodies : tuple of 4 ndarrays
        ``(all_x (N,), all_y (N,), all_radius (N,), self_index (n,))``: every robot's disc
        [m] and, for each sensing robot, its own index into them (skipped; -1 skips none).
    ranges : ndarray of shape (n, R), float64
        Ranges already limited by the map and by ``max_range_m`` [m]; modified in place.
    max_range_m : float
        Sensor range [m]; sets the default hash cell.
    cell_m : float, optional
        Side of the hash cells [m]; default :func:`default_cell_m` (half the sensor's reach).
    parallel : bool or None, default None
        Spread sensing robots over numba's threads. None: only when there are at least
        ``PARALLEL_MIN_RAYS`` rays in all (below that, waking the threads costs more than
        it saves, and far more on a loaded machine).

    Returns
    -------
    ndarray of shape (n, R)
        ``ranges`` itself: ``min(map range, distance to the nearest other disc)``; 0 for a
        ray whose origin lies inside another robot's disc.

    Examples
    --------
    >>> r = np.full((1, 2), 5.0)
    >>> bodies = (np.array([0.0, 2.0]), np.array([0.0, 0.0]), np.array([0.2, 0.5]), np.array([0]))
    >>> apply_robot_hits(np.array([0.0]), np.array([0.0]), np.array([0.0]), np.array([0.0, np.pi]),
    ...                  bodies, r, 5.0).tolist()
    [[1.5, 5.0]]
    """
    xs, ys, thetas, angles, all_x, all_y, all_r, self_idx = _check_inputs(xs, ys, thetas, angles_rad, bodies, ranges)
    if not (np.isfinite(max_range_m) and max_range_m > 0):
        raise ValueError(f"max_range_m must be a positive number of metres, got {max_range_m!r}")
    n, nn = xs.shape[0], all_x.shape[0]
    if n == 0 or nn == 0 or angles.shape[0] == 0:
        return ranges
    if parallel is None:
        parallel = n * angles.shape[0] >= PARALLEL_MIN_RAYS
    cell = default_cell_m(max_range_m, all_r) if cell_m is None else cell_m
    if not (np.isfinite(cell) and cell > 0):
        raise ValueError(f"cell_m must be a positive number of metres, got {cell_m!r}")
    return robot_hits_unchecked(xs, ys, thetas, beam_plan(angles), all_x, all_y, all_r, self_idx, ranges,
                                max_range_m, cell, bool(parallel))


def default_cell_m(max_range_m: float, all_radius: np.ndarray) -> float:
    """Default hash cell side [m]: ``(max_range_m + max radius) / 2``, floored at 1 mm."""
    return max(1e-3, 0.5 * (float(max_range_m) + float(np.max(all_radius, initial=0.0))))


def robot_hits_reference(xs, ys, thetas, angles_rad, bodies, ranges) -> np.ndarray:
    """Same result as :func:`apply_robot_hits` by testing every ray against every disc (O(n N R)).

    For tests and small teams; modifies ``ranges`` in place and returns it.
    """
    xs, ys, thetas, angles, all_x, all_y, all_r, self_idx = _check_inputs(xs, ys, thetas, angles_rad, bodies, ranges)
    if xs.shape[0] and all_x.shape[0] and angles.shape[0]:
        _reference_kernel(xs, ys, np.cos(thetas), np.sin(thetas), np.cos(angles), np.sin(angles), self_idx,
                          all_x, all_y, all_r, ranges)
    return ranges
