"""Exact 2-D ray casting on an occupancy grid, accelerated by per-quadrant free-square maps.

Every range sensor of the simulator (laser, sonar, robot detector) and the beam models of
Monte Carlo localization (Fox et al. §3.2) cast rays through the same grid, so this module
is the hot path of the whole package. It answers "how far does a ray travel from ``(x, y)``
in direction ``theta + beam`` before it enters a cell that stops it?" for all poses ×
beams in one call.

Semantics (tested against :func:`brute_force_reference`)
-------------------------------------------------------
- The range is the Euclidean distance from the pose to the first point where the ray
  enters a blocking cell, capped at ``max_range_m``.
- A pose inside a blocking cell, or outside the grid, has range 0.
- Outside the grid counts as blocking: a ray that leaves the map stops at its edge.
- Cells are half-open (``[c, c+1) x [r, r+1)`` in cell units, as in
  :class:`~teamnav.world.grid.OccupancyGrid`). A ray that passes through a grid vertex
  (within ``VERTEX_TOL_CELLS``) also touches the two cells beside that vertex: it stops
  there if either of them blocks, so a ray can never slip between two diagonally touching
  wall cells, whatever the last bit of ``cos``/``sin`` says.
- Beam directions are ``(cos, sin)`` of ``theta + beam``; a component smaller than
  ``1e-12`` in magnitude is taken as exactly 0, so axis-aligned beams stay on their row or
  column (``cos(pi/2)`` is ``6e-17`` in floating point, not 0).

Algorithm
---------
The grid is padded with one ring of blocking cells (the map edge) and turned into four
*clearance maps*, one per quadrant of directions: for quadrant ``(+x, +y)`` cell ``(r, c)``
holds the side ``k + 1`` of the largest all-free square of cells whose corner is ``(r, c)``
and which grows towards ``+x, +y`` (a classic dynamic programme, O(H W)). A ray heading
into that quadrant cannot meet an obstacle before it leaves that square, and the exit point
of an axis-aligned square is exact arithmetic on two planes, so the ray jumps straight to
it. With ``k = 0`` the jump is one Amanatides–Woo step (Amanatides & Woo, "A fast voxel
traversal algorithm for ray tracing", Eurographics 1987), so the traversal is an exact DDA
next to walls and skips open space in a few jumps (4.4 per ray on the MIT basement map with
a 10 m range). No jump is longer than its free square, hence no obstacle is missed: the
result is the exact crossing distance up to floating-point rounding, not a sampled one.

The beams of a few poses advance together (one jump each per sweep, the rays of one
quadrant at a time), so the memory loads and arithmetic of different rays overlap; poses
are spread over numba's threads. ``benchmarks/README.md``
says what each of these choices bought.

The clearance maps are built once per blocking mask (:class:`RayCaster` holds them; the
free function :func:`cast_rays` caches them for read-only masks such as those of
:meth:`OccupancyGrid.blocking`).

The stretched traversal that the beam model of MCL takes (``RayCaster(..., stretched=True)``:
the same ranges in about half the jumps), its rectangle maps (``stretch_map``) and their cache
live in :mod:`teamnav.world.raycast_stretched`, which builds on this module's inlined kernels;
its public names are re-exported here.
"""

from __future__ import annotations

import math
import weakref
from typing import Iterable

import numba
import numpy as np
from numba import njit, prange, types
from numba.extending import overload

from teamnav.world.grid import OccupancyGrid

__all__ = ["TILED_CLEARANCE_CELLS", "RayCaster", "brute_force_reference", "cast_rays", "clearance_map", "clearance_tiles",  # noqa: F822
           "stretch_map"]  # stretch_map: re-exported from raycast_stretched by __getattr__ (end of module)

#: Direction components smaller than this are snapped to exactly 0 (see module docstring).
DIR_EPS: float = 1e-12
#: Two plane crossings closer than this [cells] count as passing exactly through the grid
#: vertex between them, so that the two cells beside the vertex are both tested. It makes the
#: vertex rule immune to the last-bit rounding of directions such as ``cos(3*pi/4)``.
VERTEX_TOL_CELLS: float = 1e-9
#: Sub-cell step of :func:`brute_force_reference` [cells].
REFERENCE_STEP_CELLS: float = 1e-3
#: Largest code stored (uint8): larger free squares are simply crossed in several jumps.
_MAX_CLEAR: int = 255
#: Maps of at least this many cells keep their clearance maps as shared tiles
#: (:func:`clearance_tiles`): the swarm arena at 2 cm has 2.5 M cells for 1000 robots, 25 M
#: for 10 000. The largest built-in map (the MIT basement, 1200 x 1200) has 1.44 M, so no
#: built-in run reads tiles.
TILED_CLEARANCE_CELLS: int = 2_000_000
_TILE_SHIFT = 5
#: Side [cells] of a clearance tile.
TILE_CELLS: int = 1 << _TILE_SHIFT
_TILE_MASK = TILE_CELLS - 1


# ---------------------------------------------------------------------------- kernels
def _code(clear, r, c, q):
    """Clearance code of padded cell ``(r, c)`` for quadrant ``q``: ``clear[r, c, q]`` of a
    :func:`clearance_map`, or the same code looked up in :func:`clearance_tiles` (in numba
    code the reading is chosen by the type of ``clear``, at compile time)."""
    if isinstance(clear, tuple):
        pool, index, _ = clear
        return pool[index[q, r >> _TILE_SHIFT, c >> _TILE_SHIFT], r & _TILE_MASK, c & _TILE_MASK]
    return clear[r, c, q]


def _dims(clear):
    """(rows, columns) of the padded clearance maps."""
    if isinstance(clear, tuple):
        return int(clear[2][0]), int(clear[2][1])
    return clear.shape[0], clear.shape[1]


@overload(_code, inline="always")
def _code_ol(clear, r, c, q):
    if isinstance(clear, types.BaseTuple):
        def tiled(clear, r, c, q):
            return clear[0][clear[1][q, r >> _TILE_SHIFT, c >> _TILE_SHIFT], r & _TILE_MASK, c & _TILE_MASK]
        return tiled

    def dense(clear, r, c, q):
        # unsigned indices: numba then skips its negative-index wraparound (every index here is
        # >= 0: a ray stops at the blocking outer ring): 6 % of the ray casting of an MCL update
        return clear[np.uint64(r), np.uint64(c), np.uint64(q)]
    return dense


@overload(_dims, inline="always")
def _dims_ol(clear):
    if isinstance(clear, types.BaseTuple):
        def tiled(clear):
            return clear[2][0], clear[2][1]
        return tiled

    def dense(clear):
        return clear.shape[0], clear.shape[1]
    return dense


@njit(cache=True, inline="always")
def _ray_dir(ct, st, cb, sb):
    """Unit direction of heading ``t + b`` from the cos/sin of ``t`` and ``b``, snapped."""
    dx = ct * cb - st * sb
    dy = st * cb + ct * sb
    if abs(dx) < DIR_EPS:
        dx = 0.0
    if abs(dy) < DIR_EPS:
        dy = 0.0
    return dx, dy


@njit(cache=True, inline="always")
def _inv(d):
    """1/d, or +inf for an axis-parallel ray (whose planes are then never reached)."""
    return 1.0 / d if d != 0.0 else np.inf


@njit(cache=True, inline="always")
def _start(clear, fx, fy):
    """Padded cell ``(r, c)`` of cell-unit point ``(fx, fy)`` and whether it is free
    (False also for a point outside the grid)."""
    hp, wp = _dims(clear)
    if not (fx >= 0.0 and fx < wp - 2.0 and fy >= 0.0 and fy < hp - 2.0):
        return 0, 0, False
    c = int(fx) + 1
    r = int(fy) + 1
    return r, c, _code(clear, r, c, 0) != 0


@njit(cache=True, inline="always")
def _quadrant(dx, dy):
    """Index into the clearance map of the quadrant a ray heads into."""
    return (1 if dx < 0.0 else 0) + (2 if dy < 0.0 else 0)


@njit(cache=True, inline="always")
def _jump(clear, q, fx, fy, dx, dy, idx, idy, r, c, v, tmax):
    """:func:`_jump_s` with the steps' signs taken from the direction."""
    return _jump_s(clear, q, 1 if dx >= 0.0 else -1, 1 if dy >= 0.0 else -1, fx, fy, dx, dy, idx, idy, r, c, v, tmax)


@njit(cache=True, inline="always")
def _jump_s(clear, q, sx, sy, fx, fy, dx, dy, idx, idy, r, c, v, tmax):
    """One jump of a ray standing in padded cell ``(r, c)`` with clearance code ``v > 0``.

    ``clear[:, :, q]`` is the padded clearance map of the ray's quadrant ``q`` (0 =
    blocking, ``k + 1`` = the ``(k+1) x (k+1)`` square of cells from ``(r, c)`` towards the
    quadrant is free); its outer ring is blocking, so no bounds checks are needed. Grid cell
    ``(r, c)`` is ``clear[r + 1, c + 1, q]``; ``(fx, fy)`` is the ray origin in grid cell
    units, ``(dx, dy)`` its unit direction, ``idx, idy`` their inverses, ``sx, sy`` the
    column and row steps of the quadrant (``1 if dx >= 0 else -1``, the same for ``dy``):
    called with them as constants, the compiled jump has no selects on the signs.

    Returns ``(r, c, v, t, done)``: the cell entered at distance ``t`` [cells] and its code,
    ``done`` when the ray ended there (blocking cell, or ``t`` capped at ``tmax``).
    Written with selects rather than branches: the only branches left are the rare vertex
    case and the ways a ray ends.
    """
    k = np.int64(v) - 1
    offx = 0 if sx > 0 else -1  # plane ahead of padded column c is at grid x = c + offx
    offy = 0 if sy > 0 else -1
    ck = c + sx * k  # far column / row of the free square
    rk = r + sy * k
    # exit of the free square: planes ck+offx and rk+offy
    tx = ((ck + offx) - fx) * idx
    ty = ((rk + offy) - fy) * idy
    ex = tx < ty  # leaves through the x-plane
    t = tx if ex else ty
    if t >= tmax:
        return r, c, v, tmax, True
    # the other axis (y when leaving through an x-plane): where is the exit point on it?
    od = dy if ex else dx
    oe = (fy if ex else fx) + t * od
    fl = math.floor(oe)
    frac = oe - fl
    ifl = int(fl)
    oc = r if ex else c
    ok = rk if ex else ck
    # on a grid vertex (within VERTEX_TOL_CELLS of travel), other than on the cell's rear
    # line (a ray that starts on a grid line)?
    tol = VERTEX_TOL_CELLS * abs(od)
    vertex = False
    iv = ifl
    if od != 0.0 and (frac <= tol or 1.0 - frac <= tol):
        iv = ifl if frac <= tol else ifl + 1
        vertex = iv != oc - 1 - (offy if ex else offx)
    if vertex:
        # through a vertex: the two cells beside it count (Amanatides-Woo tie)
        if ex:
            cb_ = ck
            ca_ = ck + sx
            rb_ = iv if dy > 0.0 else iv + 1
            ra_ = iv + 1 if dy > 0.0 else iv
        else:
            rb_ = rk
            ra_ = rk + sy
            cb_ = iv if dx > 0.0 else iv + 1
            ca_ = iv + 1 if dx > 0.0 else iv
        if _code(clear, rb_, ca_, q) == 0 or _code(clear, ra_, cb_, q) == 0:
            return r, c, v, t, True
        c = ca_
        r = ra_
    else:
        # min(oc, ok) and max(oc, ok), the signs known and k >= 0: selects instead of compares
        lo = (r if sy > 0 else rk) if ex else (c if sx > 0 else ck)
        hi = (rk if sy > 0 else r) if ex else (ck if sx > 0 else c)
        of = min(max(ifl + 1, lo), hi)
        c = ck + sx if ex else of
        r = of if ex else rk + sy
    v = _code(clear, r, c, q)
    return r, c, v, t, v == 0


#: Poses whose rays advance in one wavefront (:func:`_cast_serial`): more rays in flight hide
#: the latency of each jump's chain; 8 to 32 are equally fast for 60 beams.
_POSES_PER_WAVE = 8


@njit(cache=True, inline="always")
def _wave(clear, q, sx, sy, act, n, fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res):
    """Advance the ``n`` rays ``act[:n]``, all in quadrant ``q`` (steps ``sx, sy``), one jump per
    sweep until every one has ended; ``ranges[i]`` receives ray ``i``'s range [m]."""
    while n > 0:
        m = 0
        for a in range(n):
            i = act[a]
            r, c, v, t, done = _jump_s(clear, q, sx, sy, fxs[i], fys[i], dxs[i], dys[i], idxs[i], idys[i], rs[i],
                                       cs[i], vs[i], tmax)
            # without branches (whether a ray ends is unpredictable): a ray that goes on
            # overwrites its range at a later jump; act[m] with m <= a was already read
            ranges[i] = t * res
            rs[i] = r
            cs[i] = c
            vs[i] = v
            act[m] = i
            m += 0 if done else 1
        n = m


@njit(cache=True)
def _cast_serial(clear, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, out, p0, p1):
    """Fill ``out[p0:p1]`` (ranges [m]); poses in world metres, ``ct/st`` per pose, ``cb/sb`` per beam.

    The rays of :data:`_POSES_PER_WAVE` poses advance together, one jump per sweep over the
    rays still going (a wavefront): the jumps of different rays are independent, so their
    memory loads and arithmetic overlap instead of each ray waiting on its own chain. The
    rays of one quadrant go together, with the quadrant's signs as constants
    (:func:`_jump_s`). The order rays are advanced in changes no range.
    """
    inv = 1.0 / res
    nb = cb.shape[0]
    g = _POSES_PER_WAVE
    nr = g * nb
    fxs = np.empty(nr)
    fys = np.empty(nr)
    dxs = np.empty(nr)
    dys = np.empty(nr)
    idxs = np.empty(nr)
    idys = np.empty(nr)
    rs = np.empty(nr, np.int64)
    cs = np.empty(nr, np.int64)
    vs = np.empty(nr, np.uint8)
    act = np.empty((4, nr), np.uint64)  # rays of each quadrant; unsigned: no wraparound code
    ranges = np.empty(nr)
    for g0 in range(p0, p1, g):
        g1 = min(p1, g0 + g)
        n0 = 0
        n1 = 0
        n2 = 0
        n3 = 0
        for p in range(g0, g1):
            fx = (xs[p] - ox) * inv
            fy = (ys[p] - oy) * inv
            r0, c0, ok = _start(clear, fx, fy)
            first = (p - g0) * nb
            if not ok:
                for b in range(nb):
                    ranges[first + b] = 0.0
                continue
            # open space (most of a swarm's poses): when the free squares of all four quadrants
            # reach past tmax + 1 cells, every ray's first jump ends at tmax (a jump from the start
            # cell runs more than code - 1 cells before it can stop, and the spare cell covers the
            # last-bit rounding of the direction), so each range is tmax * res, what the wavefront
            # writes, without a traversal
            free = np.int64(min(min(_code(clear, r0, c0, 0), _code(clear, r0, c0, 1)),
                                min(_code(clear, r0, c0, 2), _code(clear, r0, c0, 3)))) - 2
            if free >= tmax:
                for b in range(nb):
                    ranges[first + b] = tmax * res
                continue
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
                if q == 0:
                    act[0, n0] = i
                    n0 += 1
                elif q == 1:
                    act[1, n1] = i
                    n1 += 1
                elif q == 2:
                    act[2, n2] = i
                    n2 += 1
                else:
                    act[3, n3] = i
                    n3 += 1
        # quadrant q = (dx < 0) + 2 (dy < 0): sx = -1 for q = 1, 3; sy = -1 for q = 2, 3
        _wave(clear, 0, 1, 1, act[0], n0, fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res)
        _wave(clear, 1, -1, 1, act[1], n1, fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res)
        _wave(clear, 2, 1, -1, act[2], n2, fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res)
        _wave(clear, 3, -1, -1, act[3], n3, fxs, fys, dxs, dys, idxs, idys, rs, cs, vs, tmax, ranges, res)
        for p in range(g0, g1):
            first = (p - g0) * nb
            for b in range(nb):
                out[p, b] = ranges[first + b]


@njit(cache=True)
def _cast_pose_capped(clear, fx, fy, res, ct, st, cb, sb, tmax, cap_m, use_cap, out, dxs, dys, idxs, idys, rs, cs, vs,
                      qs, act):
    """One pose of :func:`_cast_serial`, each ray ``b`` then cut to ``min(range, cap_m[b])``.

    ``(fx, fy)``: the pose in grid cell units; ``out`` (R,) receives the ranges [m]; the
    other arrays (R,) are scratch. With ``use_cap`` the answer is, bit for bit,
    ``min(range of _cast_serial, cap_m[b])``, but a ray stops being traversed once it is past
    its cap: it is cast with the limit ``cap_m[b] / res`` widened by a relative 2e-9 (so that
    a ray stopped by that limit lies, after rounding, strictly beyond ``cap_m[b]``, and its
    answer is the cap itself), and a ray that ends before the limit ends at the very jump
    :func:`_cast_serial` ends it at (the jumps do not depend on the limit). A ray whose
    widened limit lies within the free square centred on the start cell (whose half-side the
    four quadrant codes give) is not traversed at all: its answer is its cap. ``cap_m`` >= 0,
    ``inf`` for no cap.
    """
    nb = cb.shape[0]
    r0, c0, ok = _start(clear, fx, fy)
    if not ok:
        for b in range(nb):
            out[b] = 0.0  # min(0, cap) with cap >= 0
        return
    inv = 1.0 / res
    # every ray runs free for more than `free` cells: the four quadrant squares of the start
    # cell hold the centred square of half-side min(codes) - 1 around it
    free = float(min(min(_code(clear, r0, c0, 0), _code(clear, r0, c0, 1)),
                     min(_code(clear, r0, c0, 2), _code(clear, r0, c0, 3))) - 1)
    free = min(free, tmax)
    n = 0
    for b in range(nb):
        tm = tmax
        if use_cap:
            cap = cap_m[b] * inv * (1.0 + 2e-9)
            if cap < tmax:
                tm = cap
                if cap <= free or cap == 0.0:  # the map range lies beyond the cap: no traversal
                    out[b] = cap_m[b]
                    continue
        dx, dy = _ray_dir(ct, st, cb[b], sb[b])
        dxs[b] = dx
        dys[b] = dy
        idxs[b] = _inv(dx)
        idys[b] = _inv(dy)
        q = _quadrant(dx, dy)
        qs[b] = q
        rs[b] = r0
        cs[b] = c0
        vs[b] = _code(clear, r0, c0, q)
        out[b] = tm  # the ray's limit [cells] while it is traversed
        act[n] = b
        n += 1
    while n > 0:
        m = 0
        for a in range(n):
            b = act[a]
            tm = out[b]
            r, c, v, t, done = _jump(clear, qs[b], fx, fy, dxs[b], dys[b], idxs[b], idys[b], rs[b], cs[b], vs[b], tm)
            if done:
                if use_cap:
                    # stopped by a cap below tmax: the map range lies beyond the cap
                    out[b] = cap_m[b] if (t >= tm and tm < tmax) else min(t * res, cap_m[b])
                else:
                    out[b] = t * res
            else:
                rs[b] = r
                cs[b] = c
                vs[b] = v
                act[m] = b
                m += 1
        n = m


@njit(cache=True, parallel=True)
def _cast_parallel(clear, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, out, chunk):
    n = xs.shape[0]
    nchunks = (n + chunk - 1) // chunk
    for i in prange(nchunks):
        _cast_serial(clear, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, out, i * chunk, min(n, (i + 1) * chunk))


@njit(cache=True, parallel=True)
def _reference_kernel(blocking, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, step, out):
    h = blocking.shape[0]
    w = blocking.shape[1]
    inv = 1.0 / res
    n = xs.shape[0]
    nb = cb.shape[0]
    for p in prange(n):
        fx = (xs[p] - ox) * inv
        fy = (ys[p] - oy) * inv
        for b in range(nb):
            dx, dy = _ray_dir(ct[p], st[p], cb[b], sb[b])
            out[p, b] = _reference_ray(blocking, h, w, fx, fy, dx, dy, tmax, step) * res


@njit(cache=True)
def _blocked_cell(blocking, h, w, r, c):
    return r < 0 or r >= h or c < 0 or c >= w or blocking[r, c] != 0


@njit(cache=True)
def _reference_ray(blocking, h, w, fx, fy, dx, dy, tmax, step):
    """Sample the ray every ``step`` cells; between two samples that change both row and
    column, also test the side cell the ray crossed (both at an exact vertex), so that a
    corner clip shorter than ``step`` is not missed."""
    c = int(math.floor(fx))
    r = int(math.floor(fy))
    if _blocked_cell(blocking, h, w, r, c):
        return 0.0
    n = int(math.ceil(tmax / step))
    for i in range(1, n + 1):
        t = min(i * step, tmax)
        c1 = int(math.floor(fx + t * dx))
        r1 = int(math.floor(fy + t * dy))
        if c1 != c and r1 != r:
            bx = float(max(c, c1))
            by = float(max(r, r1))
            tx = (bx - fx) / dx
            ty = (by - fy) / dy
            if tx < ty - VERTEX_TOL_CELLS:
                if _blocked_cell(blocking, h, w, r, c1):
                    return min(tx, tmax)
            elif ty < tx - VERTEX_TOL_CELLS:
                if _blocked_cell(blocking, h, w, r1, c):
                    return min(ty, tmax)
            else:
                if _blocked_cell(blocking, h, w, r, c1) or _blocked_cell(blocking, h, w, r1, c):
                    return min(min(tx, ty), tmax)
        if c1 != c or r1 != r:
            if _blocked_cell(blocking, h, w, r1, c1):
                return t
            c = c1
            r = r1
    return tmax


# ---------------------------------------------------------------------------- helpers
def _check_blocking(blocking) -> np.ndarray:
    arr = np.asarray(blocking)
    if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise ValueError(f"blocking must be a non-empty 2-D array of shape (H, W), got shape {arr.shape}")
    if arr.dtype != np.uint8:
        if arr.dtype == np.bool_ or np.issubdtype(arr.dtype, np.integer):
            arr = (arr != 0).astype(np.uint8)
        else:
            raise ValueError(f"blocking must be a uint8 or bool array, got dtype {arr.dtype}")
    return np.ascontiguousarray(arr)


def _check_positive(name: str, value) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return v


def _check_finite(name: str, value) -> float:
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return v


def _check_vec(name: str, value, n: int | None = None) -> np.ndarray:
    arr = np.ascontiguousarray(value, dtype=np.float64)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, got shape {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ValueError(f"{name} must have length {n} (one per pose), got {arr.shape[0]}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr[~np.isfinite(arr)][:3]} among its values")
    return arr


def _check_out(out, shape) -> np.ndarray:
    if out is None:
        return np.empty(shape, dtype=np.float64)
    if not isinstance(out, np.ndarray) or out.shape != shape or out.dtype != np.float64 or not out.flags.c_contiguous:
        got = f"{type(out).__name__} {getattr(out, 'shape', '')} {getattr(out, 'dtype', '')}"
        raise ValueError(f"out must be a C-contiguous float64 array of shape {shape}, got {got}")
    if not out.flags.writeable:
        raise ValueError("out must be writeable, got a read-only array")
    return out


@njit(cache=True)
def _anchored_squares(free, out):
    """``out[r, c]`` = side of the largest all-free square whose lower-left cell is
    ``(r, c)`` (0 on blocked cells), capped at 255; classic dynamic programme, O(H W)."""
    h, w = free.shape
    for r in range(h - 1, -1, -1):
        for c in range(w - 1, -1, -1):
            if not free[r, c]:
                out[r, c] = 0
            elif r == h - 1 or c == w - 1:
                out[r, c] = 1
            else:
                m = min(out[r + 1, c], out[r, c + 1], out[r + 1, c + 1])
                out[r, c] = min(np.int64(m) + 1, _MAX_CLEAR)


@njit(cache=True)
def _clearance_into(blocking, out):
    """Fill ``out`` (H + 2, W + 2, 4) with :func:`clearance_map` of ``blocking`` (H, W) in place.

    For quadrant ``q`` it is :func:`_anchored_squares` of the padded free mask flipped towards
    the quadrant, run in the original axes: the same recurrence over the same cells, so the
    same codes, without the flipped copies, the four planes and their transposed copy (5 bytes
    a cell beside the 4 of the result: 125 MB for a 10 000-robot arena at 2 cm).
    """
    h = blocking.shape[0] + 2
    w = blocking.shape[1] + 2
    for q in range(4):
        dr = -1 if q & 2 else 1  # the neighbour towards the quadrant
        dc = -1 if q & 1 else 1
        for i in range(h):
            r = h - 1 - i if dr == 1 else i
            last_r = r == (h - 1 if dr == 1 else 0)
            for j in range(w):
                c = w - 1 - j if dc == 1 else j
                if r == 0 or r == h - 1 or c == 0 or c == w - 1 or blocking[r - 1, c - 1] != 0:
                    out[r, c, q] = 0
                elif last_r or c == (w - 1 if dc == 1 else 0):
                    out[r, c, q] = 1
                else:
                    m = min(out[r + dr, c, q], out[r, c + dc, q], out[r + dr, c + dc, q])
                    out[r, c, q] = min(np.int64(m) + 1, _MAX_CLEAR)


def clearance_map(blocking: np.ndarray) -> np.ndarray:
    """Padded per-quadrant clearance maps used by the ray caster.

    Parameters
    ----------
    blocking : ndarray of shape (H, W), uint8
        1 where a cell stops a ray.

    Returns
    -------
    ndarray of shape (H + 2, W + 2, 4), uint8
        Map ``[:, :, q]`` serves rays heading towards ``+x`` (``q & 1 == 0``) or ``-x`` and
        ``+y`` (``q & 2 == 0``) or ``-y``; the four codes of a cell share a cache line, as
        the beams of one pose use several quadrants at once. The grid sits at ``[1:-1, 1:-1]``; the one-cell ring
        around it (the map edge) and blocking cells hold 0; a free cell holds ``k + 1`` when
        the ``(k+1) x (k+1)`` square of cells starting at it and growing towards the
        quadrant is entirely free (capped at 255).

    Examples
    --------
    >>> b = np.zeros((3, 3), np.uint8); b[2, 2] = 1
    >>> m = clearance_map(b)
    >>> int(m[1, 1, 0]), int(m[3, 2, 3]), int(m[3, 3, 0])  # (+x,+y) from (0,0); (-x,-y) from (2,1); wall
    (2, 2, 0)
    """
    blocking = _check_blocking(blocking)
    out = np.empty((blocking.shape[0] + 2, blocking.shape[1] + 2, 4), dtype=np.uint8)
    _clearance_into(blocking, out)
    return out


@njit(cache=True)
def _clearance_rows(blocking, q, r0, r1, nxt, out):
    """Quadrant ``q``'s codes of padded rows ``r0 .. r1 - 1`` into ``out[: r1 - r0, : W + 2]``.

    The recurrence of :func:`_clearance_into` row by row in the quadrant's order: ``nxt``
    (W + 2,) holds the codes of the row before the strip in that order (row ``r1`` for a
    quadrant towards ``+y``, ``r0 - 1`` towards ``-y``; any values for the map's edge row,
    which is never read) and is left holding the strip's last row.
    """
    h = blocking.shape[0] + 2
    w = blocking.shape[1] + 2
    dr = -1 if q & 2 else 1
    dc = -1 if q & 1 else 1
    n = r1 - r0
    for i in range(n):
        r = r1 - 1 - i if dr == 1 else r0 + i
        k = r - r0
        last_r = r == (h - 1 if dr == 1 else 0)
        for j in range(w):
            c = w - 1 - j if dc == 1 else j
            if r == 0 or r == h - 1 or c == 0 or c == w - 1 or blocking[r - 1, c - 1] != 0:
                out[k, c] = 0
            elif last_r or c == (w - 1 if dc == 1 else 0):
                out[k, c] = 1
            else:
                up = nxt[c] if i == 0 else out[k + dr, c]
                upc = nxt[c + dc] if i == 0 else out[k + dr, c + dc]
                m = min(up, out[k, c + dc], upc)
                out[k, c] = min(np.int64(m) + 1, _MAX_CLEAR)
    last = 0 if dr == 1 else n - 1
    for c in range(w):
        nxt[c] = out[last, c]


def clearance_tiles(blocking: np.ndarray) -> tuple:
    """:func:`clearance_map` kept as shared tiles: the same codes at a fraction of the memory
    on open maps.

    Returns
    -------
    tuple ``(pool, index, dims)``
        ``pool`` (T, S, S) uint8: the distinct ``S x S`` tiles (``S =`` :data:`TILE_CELLS`) of
        the four padded clearance maps; ``index`` (4, ceil((H + 2) / S), ceil((W + 2) / S))
        int32: which tile holds each block of quadrant ``q``'s map; ``dims`` (2,) int64: H + 2,
        W + 2. ``clearance_map(blocking)[r, c, q]`` is
        ``pool[index[q, r // S, c // S], r % S, c % S]``, and the ray caster's kernels read
        either form (``_code``), so ranges are the same bit for bit.

    An open arena repeats a few tiles: away from its walls every code is the cap (255), and
    along a wall the codes depend only on the distance to it. The 10 000-robot arena at 2 cm
    (25 M cells) needs about 1 MB instead of 100 MB. The maps are built a strip of ``S`` rows
    at a time, so no full-size array is made; a map without repeats costs about what
    :func:`clearance_map` does.

    Examples
    --------
    >>> b = np.zeros((70, 90), np.uint8); b[30, 40] = 1
    >>> pool, index, dims = clearance_tiles(b)
    >>> dense = clearance_map(b)
    >>> S = TILE_CELLS
    >>> all(pool[index[q, r // S, c // S], r % S, c % S] == dense[r, c, q]
    ...     for q in range(4) for r in range(72) for c in range(92))
    True
    """
    blocking = _check_blocking(blocking)
    hp, wp = blocking.shape[0] + 2, blocking.shape[1] + 2
    s = TILE_CELLS
    hb, wb = -(-hp // s), -(-wp // s)
    index = np.empty((4, hb, wb), np.int32)
    tiles: list = []
    seen: dict = {}
    strip = np.zeros((s, wb * s), np.uint8)
    for q in range(4):
        nxt = np.zeros(wp, np.uint8)
        for i in (range(hb - 1, -1, -1) if not q & 2 else range(hb)):
            r0, r1 = i * s, min(hp, (i + 1) * s)
            strip[:] = 0
            _clearance_rows(blocking, q, r0, r1, nxt, strip)
            for j in range(wb):
                tile = strip[:, j * s:(j + 1) * s]
                key = tile.tobytes()
                k = seen.get(key)
                if k is None:
                    k = seen[key] = len(tiles)
                    tiles.append(tile.copy())
                index[q, i, j] = k
    seen.clear()
    pool = np.empty((len(tiles), s, s), np.uint8)
    for k in range(len(tiles)):
        pool[k] = tiles[k]
        tiles[k] = None  # no second copy of the pool at any time
    return (pool, index, np.array([hp, wp], np.int64))


def _clearance_of(blocking: np.ndarray):
    """:func:`clearance_tiles` for a map of at least :data:`TILED_CLEARANCE_CELLS` cells,
    else :func:`clearance_map`: the same codes either way."""
    return clearance_tiles(blocking) if blocking.size >= TILED_CLEARANCE_CELLS else clearance_map(blocking)


def _cached_per_mask(cache: dict, blocking: np.ndarray, make) -> np.ndarray:
    """``make()``, computed once per read-only mask ``blocking`` and kept in ``cache`` while the
    mask is alive.

    Only masks that nobody can write through are cached: read-only arrays whose bases are
    read-only too (a read-only view of a writeable array may still change underneath).
    """
    base = blocking
    while isinstance(base, np.ndarray):
        if base.flags.writeable:
            return make()
        base = base.base
    key = id(blocking)
    hit = cache.get(key)
    if hit is not None and hit[0]() is blocking:
        return hit[1]
    value = make()
    try:
        ref = weakref.ref(blocking, lambda _r, key=key: cache.pop(key, None))
    except TypeError:  # pragma: no cover - every ndarray supports weak references
        return value
    cache[key] = (ref, value)
    return value


_CLEAR_CACHE: dict[int, tuple[weakref.ref, np.ndarray]] = {}


def _cached_clearance(blocking: np.ndarray) -> np.ndarray:
    """Clearance maps of ``blocking``, cached while a read-only mask is alive
    (:func:`_cached_per_mask`)."""
    return _cached_per_mask(_CLEAR_CACHE, blocking, lambda: _clearance_of(blocking))


def _run(clear, ox, oy, res, xs, ys, thetas, beams, max_range_m, out, parallel, ext=None):
    return _run_cs(clear, ox, oy, res, xs, ys, thetas, np.cos(beams), np.sin(beams), max_range_m, out, parallel,
                   ext=ext)


def _run_cs(clear, ox, oy, res, xs, ys, thetas, cb, sb, max_range_m, out, parallel, cs_theta=None, ext=None):
    """:func:`_run` with the beams' ``cos`` and ``sin`` given (a sensor computes them once),
    and those of ``thetas`` too when ``cs_theta = (np.cos(thetas), np.sin(thetas))``;
    ``ext``: :func:`~teamnav.world.raycast_stretched.stretch_map` of ``clear`` for the
    stretched jumps (same ranges; :mod:`teamnav.world.raycast_stretched`)."""
    if cs_theta is None:
        ct = np.cos(thetas)
        st = np.sin(thetas)
    else:
        ct, st = cs_theta
    tmax = max_range_m / res
    if xs.shape[0] == 0 or cb.shape[0] == 0:
        return out
    if parallel:
        # a few chunks of poses per thread: balances load, amortises the per-chunk buffers
        chunk = min(256, max(1, xs.shape[0] // (4 * numba.get_num_threads())))
        if ext is not None:
            _stretched._cast_parallel_st(clear, ext, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, out, chunk)
        else:
            _cast_parallel(clear, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, out, chunk)
    elif ext is not None:
        _stretched._cast_serial_st(clear, ext, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, out, 0, xs.shape[0])
    else:
        _cast_serial(clear, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, out, 0, xs.shape[0])
    return out


# ---------------------------------------------------------------------------- public API
def cast_rays(
    blocking: np.ndarray,
    origin_x_m: float,
    origin_y_m: float,
    resolution_m: float,
    xs: np.ndarray,
    ys: np.ndarray,
    thetas: np.ndarray,
    beam_angles_rad: np.ndarray,
    max_range_m: float,
    out: np.ndarray | None = None,
    parallel: bool = True,
) -> np.ndarray:
    """Ranges of every beam from every pose.

    Parameters
    ----------
    blocking : ndarray of shape (H, W), uint8
        1 where a cell stops the ray (``grid.blocking(sees)``); row 0 is the lowest y.
    origin_x_m, origin_y_m : float
        World coordinates [m] of the lower-left corner of cell (0, 0).
    resolution_m : float
        Cell side [m].
    xs, ys, thetas : ndarray of shape (P,), float64
        World poses [m, m, rad].
    beam_angles_rad : ndarray of shape (B,), float64
        Beam directions relative to each pose's heading [rad].
    max_range_m : float
        Range returned when nothing is hit [m].
    out : ndarray of shape (P, B), float64, optional
        Filled in place and returned when given.
    parallel : bool, default True
        Spread poses over numba's threads (``numba.set_num_threads`` sets how many).

    Returns
    -------
    ndarray of shape (P, B), float64
        Range [m] of beam ``b`` from pose ``p``, in ``[0, max_range_m]``.

    Notes
    -----
    The clearance maps are rebuilt on every call for a writeable ``blocking`` (O(H W)); a
    read-only mask (``grid.blocking(...)`` returns one) is processed once and cached, and
    :class:`RayCaster` holds them explicitly.

    Examples
    --------
    >>> b = np.zeros((10, 10), np.uint8); b[:, 7] = 1          # wall: column 7, x in [7, 8)
    >>> r = cast_rays(b, 0.0, 0.0, 1.0, np.array([2.5]), np.array([5.5]), np.array([0.0]),
    ...               np.array([0.0, np.pi]), 20.0)
    >>> r.round(6).tolist()                                     # east: wall; west: map edge
    [[4.5, 2.5]]
    """
    blocking = _check_blocking(blocking)
    ox = _check_finite("origin_x_m", origin_x_m)
    oy = _check_finite("origin_y_m", origin_y_m)
    res = _check_positive("resolution_m", resolution_m)
    rmax = _check_positive("max_range_m", max_range_m)
    xs = _check_vec("xs", xs)
    ys = _check_vec("ys", ys, xs.shape[0])
    thetas = _check_vec("thetas", thetas, xs.shape[0])
    beams = _check_vec("beam_angles_rad", beam_angles_rad)
    out = _check_out(out, (xs.shape[0], beams.shape[0]))
    return _run(_cached_clearance(blocking), ox, oy, res, xs, ys, thetas, beams, rmax, out, bool(parallel))


class RayCaster:
    """Ray caster bound to one grid and one sensor's visible materials.

    Builds the clearance maps of ``grid.blocking(sees)`` once (:func:`clearance_map`);
    each :meth:`cast` is then O(poses × beams × jumps per ray).

    Parameters
    ----------
    grid : OccupancyGrid
        The map.
    sees : iterable of str or None, default None
        Materials that stop the rays (None: every obstacle).
    max_range_m : float, default 10.0
        Range returned when nothing is hit [m].
    stretched : bool, default False
        Also build :func:`stretch_map` (shared by the casters of one read-only mask) and jump
        over its rectangles: the same ranges bit for bit in about half the jumps, for 16
        bytes a cell. Ignored on a tiled map (:data:`TILED_CLEARANCE_CELLS`).

    Examples
    --------
    >>> g = OccupancyGrid.empty(4.0, 2.0, 0.5)
    >>> rc = RayCaster(g, max_range_m=10.0)
    >>> rc.cast(np.array([[1.0, 1.0, 0.0]]), np.array([0.0, np.pi / 2])).round(6).tolist()
    [[3.0, 1.0]]
    """

    def __init__(self, grid: OccupancyGrid, sees: Iterable[str] | None = None, max_range_m: float = 10.0,
                 stretched: bool = False):
        if not isinstance(grid, OccupancyGrid):
            raise ValueError(f"grid must be an OccupancyGrid, got {type(grid).__name__}")
        self.grid = grid
        self.sees = None if sees is None else tuple(sees)
        self.max_range_m = _check_positive("max_range_m", max_range_m)
        self.blocking = grid.blocking(self.sees)
        self.clearance = _clearance_of(self.blocking)  # an array, or tiles for a huge map
        # the stretched rectangles (same ranges, fewer jumps; 8 more bytes a cell): not for tiles
        self.stretch = (_stretched._cached_stretch(self.blocking, self.clearance)
                        if stretched and isinstance(self.clearance, np.ndarray) else None)
        self._res = grid.resolution_m

    def cast(self, poses: np.ndarray, angles_rad: np.ndarray, out: np.ndarray | None = None, parallel: bool = True) -> np.ndarray:
        """Ranges [m], shape (P, B), of beams ``angles_rad`` (B,) from ``poses`` (P, 3) = x, y, theta."""
        poses = np.asarray(poses, dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] != 3:
            raise ValueError(f"poses must have shape (P, 3) (x, y, theta), got {poses.shape}")
        return self.cast_xyt(poses[:, 0], poses[:, 1], poses[:, 2], angles_rad, out, parallel)

    def cast_xyt(self, xs, ys, thetas, angles_rad, out: np.ndarray | None = None, parallel: bool = True) -> np.ndarray:
        """Like :meth:`cast` with the pose components as separate (P,) arrays."""
        xs = _check_vec("xs", xs)
        ys = _check_vec("ys", ys, xs.shape[0])
        thetas = _check_vec("thetas", thetas, xs.shape[0])
        beams = _check_vec("angles_rad", angles_rad)
        out = _check_out(out, (xs.shape[0], beams.shape[0]))
        xs, ys, ox, oy = self.grid.kernel_frame(xs, ys)  # a rotated map: local frame (grid.py)
        thetas = self.grid.kernel_theta(thetas)
        return _run(self.clearance, ox, oy, self._res, xs, ys, thetas, beams, self.max_range_m, out, bool(parallel),
                    self.stretch)

    def _kernel_inputs(self, xs, ys, thetas) -> tuple:
        """``(clear, ext, ox, oy, res, xs, ys, cos thetas, sin thetas, tmax)``: what the serial
        stretched kernels take for poses ``xs, ys, thetas`` (finite float64 (P,), copied when
        strided), computed as :meth:`cast_xyt` computes them (the same bits). Requires
        ``stretched=True``."""
        if self.stretch is None:
            raise ValueError("_kernel_inputs needs a RayCaster built with stretched=True on an untiled map")
        xs, ys, ox, oy = self.grid.kernel_frame(np.ascontiguousarray(xs), np.ascontiguousarray(ys))
        thetas = self.grid.kernel_theta(np.ascontiguousarray(thetas))
        return (self.clearance, self.stretch, ox, oy, self._res, xs, ys, np.cos(thetas), np.sin(thetas),
                self.max_range_m / self._res)

    def _cast_into(self, xs, ys, thetas, cos_b, sin_b, out: np.ndarray, parallel: bool) -> np.ndarray:
        """:meth:`cast_xyt` into ``out`` (P, B) without input checks, the beams given by their
        ``cos`` and ``sin`` (as :meth:`_cast_cs`): a filter's per-update path, for finite
        float64 (P,) poses (copied when strided) and a C-contiguous float64 ``out``. The same
        bits as :meth:`cast_xyt`."""
        xs, ys, ox, oy = self.grid.kernel_frame(np.ascontiguousarray(xs), np.ascontiguousarray(ys))
        thetas = self.grid.kernel_theta(np.ascontiguousarray(thetas))
        return _run_cs(self.clearance, ox, oy, self._res, xs, ys, thetas, cos_b, sin_b, self.max_range_m, out,
                       parallel, None, self.stretch)

    def _cast_cs(self, xs, ys, thetas, cos_b, sin_b, parallel: bool, cs_theta=None) -> np.ndarray:
        """:meth:`cast_xyt` without input checks, the beams given by their ``cos`` and ``sin``
        (``np.cos(angles_rad)``, ``np.sin(angles_rad)``), into a fresh (P, B) array: the
        engine's per-step path, for contiguous finite float64 (P,) poses. ``cs_theta``:
        ``(np.cos(thetas), np.sin(thetas))`` when the caller has them (used on an unrotated
        map, whose kernel headings are ``thetas`` themselves)."""
        out = np.empty((xs.shape[0], cos_b.shape[0]), dtype=np.float64)
        xs, ys, ox, oy = self.grid.kernel_frame(xs, ys)
        kth = self.grid.kernel_theta(thetas)
        return _run_cs(self.clearance, ox, oy, self._res, xs, ys, kth, cos_b, sin_b, self.max_range_m,
                       out, parallel, cs_theta if kth is thetas else None, self.stretch)


def brute_force_reference(
    blocking: np.ndarray,
    origin_x_m: float,
    origin_y_m: float,
    resolution_m: float,
    xs: np.ndarray,
    ys: np.ndarray,
    thetas: np.ndarray,
    beam_angles_rad: np.ndarray,
    max_range_m: float,
) -> np.ndarray:
    """Slow reference ranges: sample each ray every 0.001 cell.

    Same parameters, semantics and result as :func:`cast_rays`. A sample is blocked when
    its (half-open) cell blocks or lies outside the grid; when two successive samples
    differ in both row and column, the side cell the ray crossed in between is tested too
    (both side cells at an exact vertex), so corner clips shorter than the step count.
    Cost is ~1000 samples per cell of range: use it on small inputs.

    Examples
    --------
    >>> b = np.zeros((10, 10), np.uint8); b[:, 7] = 1
    >>> r = brute_force_reference(b, 0.0, 0.0, 1.0, np.array([2.5]), np.array([5.5]),
    ...                           np.array([0.0]), np.array([0.0]), 20.0)
    >>> bool(abs(r[0, 0] - 4.5) <= 1e-3)
    True
    """
    blocking = _check_blocking(blocking)
    ox = _check_finite("origin_x_m", origin_x_m)
    oy = _check_finite("origin_y_m", origin_y_m)
    res = _check_positive("resolution_m", resolution_m)
    rmax = _check_positive("max_range_m", max_range_m)
    xs = _check_vec("xs", xs)
    ys = _check_vec("ys", ys, xs.shape[0])
    thetas = _check_vec("thetas", thetas, xs.shape[0])
    beams = _check_vec("beam_angles_rad", beam_angles_rad)
    out = np.empty((xs.shape[0], beams.shape[0]), dtype=np.float64)
    if out.size:
        _reference_kernel(
            blocking, ox, oy, res, xs, ys, np.cos(thetas), np.sin(thetas), np.cos(beams), np.sin(beams),
            rmax / res, REFERENCE_STEP_CELLS, out,
        )
    return out


# ---------------------------------------------------------------------------- the stretched caster
# Imported last: raycast_stretched imports this module's kernels, so it must find them defined
# whichever of the two modules is imported first. `from package import module` binds a module
# still being initialised (Python >= 3.7); its attributes are read only when called.
from teamnav.world import raycast_stretched as _stretched

#: names defined in :mod:`teamnav.world.raycast_stretched` that stay importable from here
_STRETCHED_NAMES = frozenset({"STRETCH_GUARD_CELLS", "STRETCH_MIN_COMPONENT", "stretch_map", "_POSES_PER_WAVE_ST",
                              "_jump_st", "_wave_st", "_scratch_st", "_cast_group_st", "_cast_serial_st",
                              "_cast_parallel_st", "_stretch_into", "_STRETCH_CACHE", "_cached_stretch"})


def __getattr__(name: str):
    """Re-export the stretched caster's names (PEP 562), read when asked for so that importing
    either module first works."""
    if name in _STRETCHED_NAMES:
        return getattr(_stretched, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
