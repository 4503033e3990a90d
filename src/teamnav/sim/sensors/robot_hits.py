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
Robot centres are bucketed once per call in a uniform spatial hash (square cells of side
``max_range_m + max(radius)`` by default; keys sorted, cells found by binary search, so
memory is O(N) whatever the size of the world). Robot ``i`` then visits only the hash cells
overlapping the square of half-side ``reach_i + max(radius)`` around it, where ``reach_i``
is the longest map range among its own rays (a robot behind a wall that every ray already
stops at cannot be hit), and only robots ``j`` with ``|c_j - p_i| - r_j < reach_i`` are
intersected with its rays, and of those rays only the ones inside the disc's angular window
``bearing +- asin(r_j / d)`` (binary search over the sorted ray directions). Sensing robots
are spread over numba's threads (``prange``) once there are ``PARALLEL_MIN_RAYS`` rays: on
the 2-core development machine smaller calls gained nothing from threads.
Cost per step: O(N log N) for the hash plus O(sum over i of neighbours_i × rays).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

__all__ = ["PARALLEL_MIN_RAYS", "apply_robot_hits", "robot_hits_reference"]

#: Extra half-width [rad] of the angular window of rays tested against a disc, so that a
#: ray grazing the disc is never skipped because of rounding in ``atan2``/``asin``.
_ANGLE_MARGIN_RAD: float = 1e-9
#: Fewest rays (sensing robots x rays) for which :func:`apply_robot_hits` goes parallel by default.
PARALLEL_MIN_RAYS: int = 20_000


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
def _rays_in(sorted_ang, a0, a1):
    """Index range ``[lo, hi)`` of ``sorted_ang`` (ascending) with ``a0 <= angle <= a1``."""
    return _lower(sorted_ang, a0), _upper(sorted_ang, a1)


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
def _hit_rays(out, i, lo, hi, ray_order, ct, st, cb, sb, fx, fy, r2):
    """Shorten ``out[i, ray_order[lo:hi]]`` by a disc at offset ``f = origin - centre``."""
    for k in range(lo, hi):
        b = ray_order[k]
        dx = ct * cb[b] - st * sb[b]
        dy = st * cb[b] + ct * sb[b]
        t = _disc_hit(fx, fy, dx, dy, r2)
        if t < out[i, b]:
            out[i, b] = t


@njit(cache=True)
def _robot_hits_one(i, xs, ys, ct, st, thetas, cb, sb, sorted_ang, ray_order, self_idx, all_x, all_y, all_r,
                    order, keys, x0, y0, cell, nky, nkx, rmax, out):
    """Shorten row ``i`` of ``out`` (map ranges, modified in place) by other robots' discs.

    ``order``: robot indices sorted by hash key, ``keys``: their sorted keys
    ``kx * nky + ky`` with ``kx = floor((x - x0) / cell)`` (``0 <= kx < nkx``).
    ``sorted_ang``: the ray directions wrapped to ``[-pi, pi)`` in ascending order,
    ``ray_order`` their ray indices. A disc at distance ``d`` and body-frame bearing ``phi``
    can only be met by rays within ``asin(r / d)`` of ``phi``: those are found by binary
    search and intersected exactly (a margin of ``_ANGLE_MARGIN_RAD`` absorbs rounding).
    """
    nb = cb.shape[0]
    two_pi = 2.0 * math.pi
    px = xs[i]
    py = ys[i]
    me = self_idx[i]
    reach = 0.0
    for b in range(nb):
        if out[i, b] > reach:
            reach = out[i, b]
    if reach <= 0.0:
        return
    half = reach + rmax
    kx0 = max(0, int(math.floor((px - half - x0) / cell)))
    kx1 = min(nkx - 1, int(math.floor((px + half - x0) / cell)))
    ky0 = max(0, int(math.floor((py - half - y0) / cell)))
    ky1 = min(nky - 1, int(math.floor((py + half - y0) / cell)))
    for kx in range(kx0, kx1 + 1):
        # cells (kx, ky0..ky1) are contiguous in key order
        lo = _lower(keys, kx * nky + ky0)
        hi = _lower(keys, kx * nky + ky1 + 1)
        for s in range(lo, hi):
            j = order[s]
            if j == me:
                continue
            fx = px - all_x[j]
            fy = py - all_y[j]
            r = all_r[j]
            d2 = fx * fx + fy * fy
            d = math.sqrt(d2)
            if d - r >= reach:
                continue
            if d2 <= r * r:  # sensor inside the disc: every ray stops at once
                for b in range(nb):
                    out[i, b] = 0.0
                continue
            # bearing of the centre in the body frame, wrapped to [-pi, pi)
            phi = math.atan2(-fy, -fx) - thetas[i]
            phi -= two_pi * math.floor((phi + math.pi) / two_pi)
            beta = math.asin(r / d) + _ANGLE_MARGIN_RAD
            a0 = phi - beta
            a1 = phi + beta
            r2 = r * r
            if a0 < -math.pi:
                l0, h0 = _rays_in(sorted_ang, a0 + two_pi, math.pi)
                _hit_rays(out, i, l0, h0, ray_order, ct[i], st[i], cb, sb, fx, fy, r2)
                a0 = -math.pi
            elif a1 >= math.pi:
                l0, h0 = _rays_in(sorted_ang, -math.pi, a1 - two_pi)
                _hit_rays(out, i, l0, h0, ray_order, ct[i], st[i], cb, sb, fx, fy, r2)
                a1 = math.pi
            l0, h0 = _rays_in(sorted_ang, a0, a1)
            _hit_rays(out, i, l0, h0, ray_order, ct[i], st[i], cb, sb, fx, fy, r2)


@njit(cache=True, parallel=True)
def _robot_hits_parallel(xs, ys, ct, st, thetas, cb, sb, sorted_ang, ray_order, self_idx, all_x, all_y, all_r,
                         order, keys, x0, y0, cell, nky, nkx, rmax, out):
    """:func:`_robot_hits_one` for every sensing robot, spread over numba's threads."""
    for i in prange(xs.shape[0]):
        _robot_hits_one(i, xs, ys, ct, st, thetas, cb, sb, sorted_ang, ray_order, self_idx, all_x, all_y, all_r,
                        order, keys, x0, y0, cell, nky, nkx, rmax, out)


@njit(cache=True)
def _robot_hits_serial(xs, ys, ct, st, thetas, cb, sb, sorted_ang, ray_order, self_idx, all_x, all_y, all_r,
                       order, keys, x0, y0, cell, nky, nkx, rmax, out):
    """:func:`_robot_hits_one` for every sensing robot, in this thread."""
    for i in range(xs.shape[0]):
        _robot_hits_one(i, xs, ys, ct, st, thetas, cb, sb, sorted_ang, ray_order, self_idx, all_x, all_y, all_r,
                        order, keys, x0, y0, cell, nky, nkx, rmax, out)


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
def _vec(name: str, value, n: int | None = None, dtype=np.float64) -> np.ndarray:
    arr = np.ascontiguousarray(value, dtype=dtype)
    if arr.ndim != 1 or (n is not None and arr.shape[0] != n):
        want = "(n,)" if n is None else f"({n},)"
        raise ValueError(f"{name} must be a 1-D array of shape {want}, got shape {arr.shape}")
    if dtype == np.float64 and not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr[~np.isfinite(arr)][:3].tolist()}")
    return arr


def _check_inputs(xs, ys, thetas, angles_rad, bodies, ranges):
    xs = _vec("xs", xs)
    n = xs.shape[0]
    ys = _vec("ys", ys, n)
    thetas = _vec("thetas", thetas, n)
    angles = _vec("angles_rad", angles_rad)
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
        Side of the hash cells [m]; default ``max_range_m + max(all_radius)``.
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
    rmax = float(all_r.max())
    cell = float(max_range_m) + rmax if cell_m is None else float(cell_m)
    if not (np.isfinite(cell) and cell > 0):
        raise ValueError(f"cell_m must be a positive number of metres, got {cell_m!r}")
    x0 = float(all_x.min())
    y0 = float(all_y.min())
    kx = np.floor((all_x - x0) / cell).astype(np.int64)
    ky = np.floor((all_y - y0) / cell).astype(np.int64)
    nkx = int(kx.max()) + 1
    nky = int(ky.max()) + 1
    keys = kx * nky + ky
    order = np.argsort(keys, kind="stable").astype(np.int64)
    skeys = np.ascontiguousarray(keys[order])
    wrapped = angles - 2 * np.pi * np.floor((angles + np.pi) / (2 * np.pi))  # [-pi, pi)
    ray_order = np.argsort(wrapped, kind="stable").astype(np.int64)
    kernel = _robot_hits_parallel if parallel else _robot_hits_serial
    kernel(
        xs, ys, np.cos(thetas), np.sin(thetas), thetas, np.cos(angles), np.sin(angles),
        np.ascontiguousarray(wrapped[ray_order]), ray_order, self_idx,
        all_x, all_y, all_r, order, skeys, x0, y0, cell, nky, nkx, rmax, ranges,
    )
    return ranges


def robot_hits_reference(xs, ys, thetas, angles_rad, bodies, ranges) -> np.ndarray:
    """Same result as :func:`apply_robot_hits` by testing every ray against every disc (O(n N R)).

    For tests and small teams; modifies ``ranges`` in place and returns it.
    """
    xs, ys, thetas, angles, all_x, all_y, all_r, self_idx = _check_inputs(xs, ys, thetas, angles_rad, bodies, ranges)
    if xs.shape[0] and all_x.shape[0] and angles.shape[0]:
        _reference_kernel(xs, ys, np.cos(thetas), np.sin(thetas), np.cos(angles), np.sin(angles), self_idx,
                          all_x, all_y, all_r, ranges)
    return ranges
