"""Simulated range sensors: scanning laser, sonar ring, infrared proximity.

Simulator side (truth): each sensor ray-casts from the robots' *true* poses through the map
cells its configuration ``sees`` (a laser passes through glass, a sonar echoes off it;
:meth:`OccupancyGrid.blocking`), optionally stops on other robots' discs
(:mod:`teamnav.sim.sensors.robot_hits`), then corrupts the ranges with a beam-model mixture:

- Gaussian measurement noise ``N(0, noise_std_m)``, clipped to ``[0, max_range_m]``;
- a *max-range* reading with probability ``p_max`` (laser) / ``p_specular`` (sonar: the
  echo was reflected away and never came back);
- a *short* reading, uniform in ``[0, true range)``, with probability ``p_short`` (an
  unmodelled object, or sonar crosstalk).

These are the three parts of the perception model of Fox et al. §2.2 (Fig. 1: a Gaussian
around the expected distance, overly short readings, a Dirac at max range), as in Thrun et
al., *Probabilistic Robotics* §6.3, which MCL (``teamnav.localization``) then models. Fox et
al. fit the short readings with a geometric distribution; the simulator draws them uniformly
below the true range, as :class:`~teamnav.sim.config.LaserConfig` specifies (Thrun's
exponential "short" term fitted to such data is then a modelling approximation, as on a real
robot). The three cases are exclusive: a beam is max with probability ``p_max``, short with
probability ``p_short``, else true + noise (so ``p_max + p_short`` may not exceed 1).

Random numbers. :class:`RangeSensor` takes one uint64 *key* per call from its ``Generator``
and draws every beam's numbers inside the kernel from counter-based streams
(:func:`beam_noise_keyed`: SplitMix64 per beam, ziggurat normals), so no ``(n, B)`` arrays of
draws are made and a run is deterministic given the ``Generator``, on any number of threads.
:func:`apply_beam_noise` is the same model with NumPy's draws (one ``standard_normal((n, B))``
and one ``random((n, B))``), kept as the readable reference. Either way the short reading
reuses the beam's uniform (``(u - p_max) / p_short`` is again uniform on ``[0, 1)`` given the
beam is short).

One pass per robot. The engine's sensing (:meth:`RangeSensor._pass`) runs one numba loop over
the robots that, for each, intersects the other robots' discs within ``_NEAR_M`` first, casts
the map only up to those hits (:func:`~teamnav.world.raycast._cast_pose_capped`), tests the
farther discs that could still shorten a ray (runs of rays still longer than the near reach
against the discs of the box around their segments), takes each beam's nearest ray and adds its keyed
noise: the ranges of cast -> robot bodies -> noise, bit for bit, for a third of the work at
1000 laser robots (``benchmarks/README.md``, 2026-11-27). Sensors of fewer than
``ONE_PASS_MIN_RAYS`` rays a robot run those three passes as such.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import njit, prange

from teamnav.control.protocol import SensorInfo
from teamnav.geometry.angles import wrap_angle
from teamnav.sim.config import LaserConfig, ProximityConfig, SonarConfig
from teamnav.sim.sensors.robot_hits import (_ALL, PARALLEL_MIN_RAYS, _prepare, _robot_hits_row, beam_plan,
                                              check_bodies, robot_hits_unchecked)
from teamnav.world.grid import OccupancyGrid
from teamnav.world.raycast import RayCaster, _cast_pose_capped, _code, _start

__all__ = ["RangeSensor", "apply_beam_noise", "beam_angles", "beam_noise_keyed", "build_range_sensor", "draw_noise_key"]


# ---------------------------------------------------------------------------- geometry
def beam_angles(n: int, fov_rad: float) -> np.ndarray:
    """``n`` directions evenly spread over a field of view centred on the front (body x axis).

    For ``fov < 2 pi`` both edges get a beam (``linspace(-fov/2, fov/2, n)``; one beam points
    straight ahead). For a full circle the spacing is ``2 pi / n`` with a beam straight ahead
    and no duplicate at ``+-pi``: ``k 2 pi / n`` for ``k = -(n-1)//2 .. n//2``, ascending, in
    ``(-pi, pi]``.

    Parameters
    ----------
    n : int
        Number of beams, >= 1.
    fov_rad : float
        Field of view [rad], in ``(0, 2 pi]``.

    Returns
    -------
    ndarray of shape (n,), float64

    Examples
    --------
    >>> np.degrees(beam_angles(4, 2 * np.pi)).round(6).tolist()
    [-90.0, 0.0, 90.0, 180.0]
    >>> np.degrees(beam_angles(3, np.pi)).round(6).tolist()
    [-90.0, 0.0, 90.0]
    """
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise ValueError(f"n must be an integer >= 1, got {n!r}")
    if not (np.isfinite(fov_rad) and 0.0 < fov_rad <= 2 * np.pi + 1e-12):
        raise ValueError(f"fov_rad must be in (0, 2 pi], got {fov_rad!r}")
    if n == 1:
        return np.zeros(1)
    if fov_rad >= 2 * np.pi - 1e-12:
        k = np.arange(n) - (n - 1) // 2
        return np.minimum(k * (2 * np.pi / n), np.pi)  # k = n/2 may round past pi
    return np.linspace(-fov_rad / 2, fov_rad / 2, n)


# ---------------------------------------------------------------------------- noise kernels
@njit(cache=True, inline="always")
def _mixture_one(t, v, z, use_u, use_z, sigma, p_max, p_short, max_range):
    """One beam of the mixture from its true range ``t``, uniform ``v`` and normal ``z``."""
    if use_u:
        if v < p_max:
            return max_range
        if v < p_max + p_short:
            return t * ((v - p_max) / p_short)
    r = t + sigma * z if use_z else t
    return min(max(r, 0.0), max_range)


@njit(cache=True)
def _mixture_kernel(true, z, u, sigma, p_max, p_short, max_range, out):
    """Beam mixture, elementwise; ``z`` / ``u`` may be empty (that part is off)."""
    n, nb = true.shape
    use_z = z.shape[0] > 0
    use_u = u.shape[0] > 0
    for i in range(n):
        for b in range(nb):
            out[i, b] = _mixture_one(true[i, b], u[i, b] if use_u else 0.0, z[i, b] if use_z else 0.0, use_u, use_z,
                                     sigma, p_max, p_short, max_range)


# Counter-based streams (no array of draws): a call keyed by ``key`` reads the SplitMix64
# sequence (Steele, Lea & Flood, OOPSLA 2014) ``out[m] = mix64(key + m * _GAMMA)`` by random
# access; beam ``c = i * B + b`` owns the block ``m = c * _SLOTS + 1, ...``: its 1st draw is
# the mixture's uniform, the next ones feed the ziggurat normal (Marsaglia & Tsang, J. Stat.
# Softw. 5(8), 2000; 256 layers, 52-bit, as numpy's ``standard_normal``), which needs more
# than two draws about once in 100 and more than _SLOTS never in practice (< 1e-100).
_GAMMA = np.uint64(0x9E3779B97F4A7C15)
_SLOTS = 64
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_ZIG_R: float = 3.6541528853610088  # start of the tail
_ZIG_V: float = 0.00492867323399  # area of each layer


def _ziggurat_tables() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(ki, wi, fi)`` of the 256-layer normal ziggurat (Marsaglia & Tsang 2000, §3, for 52 bits)."""
    m1 = 2.0**52
    dn = tn = _ZIG_R
    q = _ZIG_V / math.exp(-0.5 * dn * dn)
    ki = np.zeros(256)
    wi = np.zeros(256)
    fi = np.zeros(256)
    ki[0] = (dn / q) * m1
    wi[0] = q / m1
    wi[255] = dn / m1
    fi[0] = 1.0
    fi[255] = math.exp(-0.5 * dn * dn)
    for i in range(254, 0, -1):
        dn = math.sqrt(-2.0 * math.log(_ZIG_V / dn + math.exp(-0.5 * dn * dn)))
        ki[i + 1] = (dn / tn) * m1
        tn = dn
        fi[i] = math.exp(-0.5 * dn * dn)
        wi[i] = dn / m1
    return ki, wi, fi


# module constants: numba freezes them into the kernels (no arrays passed, no refcounting)
_ZIG_KI, _ZIG_WI, _ZIG_FI = _ziggurat_tables()


@njit(cache=True, inline="always")
def _mix64(z):
    """SplitMix64's output function (a bijection of uint64)."""
    z = (z ^ (z >> np.uint64(30))) * _M1
    z = (z ^ (z >> np.uint64(27))) * _M2
    return z ^ (z >> np.uint64(31))


@njit(cache=True, inline="always")
def _unit(z):
    """Uniform double in ``[0, 1)`` from the top 53 bits of ``z``."""
    return float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True)
def _normal_slow(s, rabs, idx, x):
    """The ziggurat's rare branches (about 1 draw in 100), continuing stream state ``s``."""
    while True:
        if idx == 0:  # the tail beyond _ZIG_R
            while True:
                s += _GAMMA
                xx = -math.log1p(-_unit(_mix64(s))) / _ZIG_R
                s += _GAMMA
                yy = -math.log1p(-_unit(_mix64(s)))
                if yy + yy > xx * xx:
                    return -(_ZIG_R + xx) if (rabs >> np.uint64(8)) & np.uint64(1) else _ZIG_R + xx
        s += _GAMMA
        if (_ZIG_FI[idx - 1] - _ZIG_FI[idx]) * _unit(_mix64(s)) + _ZIG_FI[idx] < math.exp(-0.5 * x * x):
            return x
        s += _GAMMA
        r = _mix64(s)
        idx = int(r & np.uint64(0xFF))
        r >>= np.uint64(8)
        rabs = (r >> np.uint64(1)) & np.uint64(0x000FFFFFFFFFFFFF)
        x = float(np.int64(rabs)) * _ZIG_WI[idx]
        if r & np.uint64(1):
            x = -x
        if float(np.int64(rabs)) < _ZIG_KI[idx]:
            return x


@njit(cache=True, inline="always")
def _normal(s):
    """Standard normal from the stream whose last state is ``s`` (ziggurat fast path inline)."""
    s += _GAMMA
    r = _mix64(s)
    idx = int(r & np.uint64(0xFF))
    r >>= np.uint64(8)
    rabs = (r >> np.uint64(1)) & np.uint64(0x000FFFFFFFFFFFFF)
    x = float(np.int64(rabs)) * _ZIG_WI[idx]
    if r & np.uint64(1):
        x = -x
    if float(np.int64(rabs)) < _ZIG_KI[idx]:
        return x
    return _normal_slow(s, rabs, idx, x)


@njit(cache=True, inline="always")
def _keyed_beam(t, s, use_u, use_z, sigma, p_max, p_short, max_range):
    """One beam of the mixture from its true range ``t`` and its stream, whose state before
    the first draw is ``s`` (beam ``c`` of a call keyed ``key``: ``key + 64 c * gamma``)."""
    v = 0.0
    if use_u:
        s += _GAMMA
        v = _unit(_mix64(s))
    z = 0.0
    if use_z and not (use_u and v < p_max + p_short):
        z = _normal(s)
    return _mixture_one(t, v, z, use_u, use_z, sigma, p_max, p_short, max_range)


@njit(cache=True, error_model="numpy")  # no zero-division branch: the loop vectorizes
def _noise_row(row, s0, use_u, use_z, sigma, p_max, p_short, max_range, slow):
    """``row[b] = _keyed_beam(row[b], s0 + 64 b * gamma, ...)`` for every beam ``b``, in place.

    Two loops, same numbers: the first takes every beam through the ziggurat's fast path
    with no call and no early exit (so the compiler vectorizes it: 64-bit multiplies, table
    gathers) and marks the ~1 % of beams that need its slow path; the second redoes just
    those with :func:`_keyed_beam`. ``slow`` (B,): scratch."""
    nb = row.shape[0]
    block = np.uint64(_SLOTS) * _GAMMA
    any_slow = False
    for b in range(nb):
        s = s0 + np.uint64(b) * block
        t = row[b]
        v = 0.0
        if use_u:
            s += _GAMMA
            v = _unit(_mix64(s))
        s += _GAMMA
        r = _mix64(s)
        idx = r & np.uint64(0xFF)
        r >>= np.uint64(8)
        rabs = (r >> np.uint64(1)) & np.uint64(0x000FFFFFFFFFFFFF)
        fr = float(np.int64(rabs))
        x = fr * _ZIG_WI[idx]
        x = -x if r & np.uint64(1) else x
        need = use_z and not (use_u and v < p_max + p_short)
        sl = need and not (fr < _ZIG_KI[idx])
        slow[b] = sl
        any_slow |= sl
        m = _mixture_one(t, v, x if need else 0.0, use_u, use_z, sigma, p_max, p_short, max_range)
        row[b] = t if sl else m  # a slow beam is redone below from its true range
    if any_slow:
        for b in range(nb):
            if slow[b]:
                row[b] = _keyed_beam(row[b], s0 + np.uint64(b) * block, use_u, use_z, sigma, p_max, p_short, max_range)


@njit(cache=True)
def _counter_noise_rows(true, key, i0, i1, sigma, p_max, p_short, max_range, out):
    """Rows ``[i0, i1)`` of :func:`beam_noise_keyed` (``out`` may be ``true``)."""
    nb = true.shape[1]
    use_u = p_max + p_short > 0.0
    use_z = sigma > 0.0
    block = np.uint64(_SLOTS) * _GAMMA
    s0 = key + np.uint64(i0 * nb * _SLOTS) * _GAMMA
    for i in range(i0, i1):
        for b in range(nb):
            out[i, b] = _keyed_beam(true[i, b], s0, use_u, use_z, sigma, p_max, p_short, max_range)
            s0 += block


@njit(cache=True, parallel=True)
def _counter_noise_parallel(true, key, sigma, p_max, p_short, max_range, out):
    """:func:`_counter_noise_rows` over all rows, in chunks spread over numba's threads
    (each beam's draws depend only on ``key`` and its index: same result on any thread count)."""
    n = true.shape[0]
    chunks = (n + 63) // 64
    for c in prange(chunks):
        _counter_noise_rows(true, key, c * 64, min(n, c * 64 + 64), sigma, p_max, p_short, max_range, out)


@njit(cache=True)
def _counter_noise_blocks(true, keys, starts, sigma, p_max, p_short, max_range, out):
    """Rows ``[starts[g], starts[g + 1])`` as one :func:`beam_noise_keyed` call of key
    ``keys[g]`` each (the row index restarts at 0 in every block): several groups' scans of
    one shared cast get their own streams' noise in one dispatch."""
    for g in range(keys.shape[0]):
        r0 = starts[g]
        r1 = starts[g + 1]
        _counter_noise_rows(true[r0:r1], keys[g], 0, r1 - r0, sigma, p_max, p_short, max_range, out[r0:r1])


# ---------------------------------------------------------------------------- one pass per robot
#: Robots' discs whose nearest point is within this distance [m] of a sensor are met before
#: its map cast (their hits cap the rays' traversal), the rest after it, and only those
#: nearer than the longest ray left (measured 2026-11-27: at 1000 laser robots on the basement map 98 %
#: of the beams end within 3 m, and 9 of the ~86 discs ahead of a robot shorten a ray).
_NEAR_M: float = 4.0
#: The near reach [m] of a pose with at least ``_NEAR_M`` of free map all around it (its
#: quadrants' free squares): in open space many rays pass ``_NEAR_M``, and each of them
#: then tests the discs of a box around its segment beyond the near reach, so taking the
#: discs up to ``_OPEN_NEAR_M`` first costs less. Measured 2026-11-29 on 10 000 laser robots
#: in the open swarm arena (bench_scale's laser cell), one thread, sensing pass CPU ms, one
#: process each, the same minutes, one box a ray: 4 m 104.6 (4.5 m), 5 m 96-98, 5.5 m 96.1,
#: 6 m 95.7, 6.5 m 96.1, 8 m 106-108; later, with the clipped columns of the near pass:
#: 5.5 m 93.5-93.7, 6 m 92.2-92.7, 7 m 97.5-98.3 (with one box around all the long rays,
#: 2026-11-29 earlier: 8 m 110 against 116 with 4 m). On the MIT basement map the walls end 99 % of the rays within
#: 4 m and few poses have 4 m free. Which discs go first changes no range (two reaches
#: test every disc at least once, and a disc met twice changes nothing).
_OPEN_NEAR_M: float = 6.0
#: Fewest rays a robot for :meth:`RangeSensor._pass` to sense robot by robot in one kernel
#: (below, e.g. 7 proximity rays, three passes over all robots are faster: 0.55 against
#: 0.68 ms a step for 1000 swarm robots).
ONE_PASS_MIN_RAYS: int = 24
#: Largest side [m] of the hash cells of the one-pass sensing (its windows are a few metres).
_HASH_CELL_M: float = 1.5
#: Most consecutive rays longer than the near reach that test the discs of one box around
#: their segments (beyond the near reach) together: 10 000 laser robots in bench_scale's open
#: arena, one thread, 2026-11-29, sensing pass CPU ms: 90.6 one ray a box, 83.9 up to 4,
#: 84.8 up to 8, 85.2 up to 16 (a long run's box grows with its angle).
_FAR_RUN: int = 8


@njit(cache=True)
def _hash_or_none(use_hits, all_x, all_y, all_r, max_range_m):
    """:func:`~teamnav.sim.sensors.robot_hits._prepare` with the default cell, or an empty
    hash of the same type when no bodies are tested."""
    if use_hits and all_x.shape[0] > 0:
        # the default cell (half the reach) for short sensors, at most _HASH_CELL_M
        cell = min(_HASH_CELL_M, max(1e-3, 0.5 * (max_range_m + all_r.max())))
        return _prepare(all_x, all_y, all_r, max_range_m, cell)
    z = np.zeros(0)
    return (z, z, z, np.zeros(0, np.int64), np.zeros(2, np.int64), 0.0, 0.0, 1.0, 1, 1, 0.0)


@njit(cache=True, inline="always")
def _open_m(clear, fx, fy, res):
    """Free map [m] all around cell-unit point ``(fx, fy)``: the least of its cell's four
    quadrant free squares, less a cell (0 outside the map or in a blocking cell)."""
    r0, c0, ok = _start(clear, fx, fy)
    if not ok:
        return 0.0
    return float(np.int64(min(min(_code(clear, r0, c0, 0), _code(clear, r0, c0, 1)),
                              min(_code(clear, r0, c0, 2), _code(clear, r0, c0, 3)))) - 1) * res


@njit(cache=True)
def _sense_rows(i0, i1, clear, cast, hits, beams, even, hsh, noise, out):
    """Rows ``[i0, i1)`` of :func:`_sense_serial`, robot by robot: other robots' discs first
    (:func:`~teamnav.sim.sensors.robot_hits._robot_hits_row`, into the rays' caps), then
    the map cast of the pose, each ray traversed only up to its cap
    (:func:`~teamnav.world.raycast._cast_pose_capped`: ``min(map range, disc hit)`` bit for
    bit), then runs of up to ``_FAR_RUN`` consecutive rays still longer than the near reach
    against the discs of the box around their segments, the nearest ray of each beam, then
    the beam's keyed noise (row ``i``'s streams of :func:`_counter_noise_rows`)."""
    ox, oy, res, kxs, kys, kct, kst, cb, sb, tmax, rpb = cast
    use_hits, xs, ys, ct, st, self_idx, reach = hits
    use_noise, key, sigma, p_max, p_short, max_range = noise
    hsx, hsy, hsr, hsid, hstart, hx0, hy0, hcell, hnkx, hnky, hrmax = hsh
    nr = cb.shape[0]
    nb = out.shape[1]
    inv = 1.0 / res
    cap = np.full(nr, np.inf)
    rr = np.empty(nr)
    rdx = np.empty(nr)
    rdy = np.empty(nr)
    dxs = np.empty(nr)
    dys = np.empty(nr)
    idxs = np.empty(nr)
    idys = np.empty(nr)
    rs = np.empty(nr, np.int64)
    cs = np.empty(nr, np.int64)
    vs = np.empty(nr, np.uint8)
    qs = np.empty(nr, np.int64)
    act = np.empty(nr, np.int64)
    slow = np.empty(nb, np.bool_)
    use_u = p_max + p_short > 0.0
    use_z = sigma > 0.0
    for i in range(i0, i1):
        if use_hits:
            for b in range(nr):
                cap[b] = np.inf
            near = min(reach, _NEAR_M)
            if reach > _NEAR_M and _open_m(clear, (kxs[i] - ox) * inv, (kys[i] - oy) * inv, res) >= _NEAR_M:
                near = min(reach, _OPEN_NEAR_M)
            _robot_hits_row(xs[i], ys[i], ct[i], st[i], self_idx[i], 0.0, near, beams, even, hsh, cap, rdx, rdy, True,
                            _ALL)
        _cast_pose_capped(clear, (kxs[i] - ox) * inv, (kys[i] - oy) * inv, res, kct[i], kst[i], cb, sb, tmax, cap,
                          use_hits, rr, dxs, dys, idxs, idys, rs, cs, vs, qs, act)
        if use_hits:
            # the discs beyond `near` that could still shorten a ray longer than `near`: a hit
            # at t >= near on ray b lies on [near, rr[b]] of it, so the disc's centre lies
            # within rmax of that segment. Runs of consecutive such rays test the discs of the
            # box around their segments, each disc against every ray of the run with
            # robot_hits_reference's arithmetic (a disc met twice, or missed, changes nothing)
            px = xs[i]
            py = ys[i]
            me = self_idx[i]
            m = hrmax + 1e-6  # largest radius, and rounding
            t0 = near - 1e-6  # a hit beyond `near` (to within rounding)
            b = 0
            while b < nr:
                if not rr[b] > near:
                    b += 1
                    continue
                # a run of up to _FAR_RUN consecutive long rays: one box around their segments
                e = b
                bx0 = np.inf
                bx1 = -np.inf
                by0 = np.inf
                by1 = -np.inf
                while e < nr and e - b < _FAR_RUN and rr[e] > near:
                    t1 = rr[e]
                    ax = px + t0 * rdx[e]
                    bx = px + t1 * rdx[e]
                    ay = py + t0 * rdy[e]
                    by = py + t1 * rdy[e]
                    bx0 = min(bx0, min(ax, bx))
                    bx1 = max(bx1, max(ax, bx))
                    by0 = min(by0, min(ay, by))
                    by1 = max(by1, max(ay, by))
                    e += 1
                kx0 = max(0, int(math.floor((bx0 - m - hx0) / hcell)))
                kx1 = min(hnkx - 1, int(math.floor((bx1 + m - hx0) / hcell)))
                ky0 = max(0, int(math.floor((by0 - m - hy0) / hcell)))
                ky1 = min(hnky - 1, int(math.floor((by1 + m - hy0) / hcell)))
                if ky0 <= ky1:  # else the box misses the hash grid (hstart[...] could lie past its end)
                    for kx in range(kx0, kx1 + 1):
                        for s in range(hstart[kx * hnky + ky0], hstart[kx * hnky + ky1 + 1]):
                            if hsid[s] == me:
                                continue
                            fx = px - hsx[s]
                            fy = py - hsy[s]
                            r = hsr[s]
                            cc = fx * fx + fy * fy - r * r
                            for k in range(b, e):
                                # _disc_hit's arithmetic, selects for its branches
                                bb = fx * rdx[k] + fy * rdy[k]
                                disc = bb * bb - cc
                                h = -bb - math.sqrt(disc if disc > 0.0 else 0.0)
                                h = h if (bb < 0.0) & (disc >= 0.0) else np.inf
                                h = 0.0 if cc <= 0.0 else h
                                o = rr[k]
                                rr[k] = h if h < o else o
                b = e
        row = out[i]
        if rpb == 1:
            for b in range(nb):
                row[b] = rr[b]
        else:
            for b in range(nb):
                t = rr[b * rpb]
                for k in range(b * rpb + 1, (b + 1) * rpb):
                    t = min(t, rr[k])
                row[b] = t
        if use_noise:
            _noise_row(row, key + np.uint64(i * nb * _SLOTS) * _GAMMA, use_u, use_z, sigma, p_max, p_short, max_range,
                       slow)


@njit(cache=True)
def _sense_serial(clear, cast, hits, beams, even, bodies, noise, out):
    """Every robot's ranges (:func:`_sense_rows`) in this thread; ``bodies = (all_x, all_y,
    all_r)`` are hashed once per call."""
    all_x, all_y, all_r = bodies
    hsh = _hash_or_none(hits[0], all_x, all_y, all_r, hits[6])
    # np.int64(0), not 0: a literal 0 would make numba compile _sense_rows a second time, for
    # Literal[int](0), beside the int64 one _sense_parallel uses (~13 s on 2 cores)
    _sense_rows(np.int64(0), out.shape[0], clear, cast, hits, beams, even, hsh, noise, out)


@njit(cache=True, parallel=True)
def _sense_parallel(clear, cast, hits, beams, even, bodies, noise, out, chunk):
    """:func:`_sense_serial` with chunks of ``chunk`` robots spread over numba's threads (each
    robot's result depends on nothing but its own pose: the same on any thread count)."""
    all_x, all_y, all_r = bodies
    hsh = _hash_or_none(hits[0], all_x, all_y, all_r, hits[6])
    n = out.shape[0]
    nchunks = (n + chunk - 1) // chunk
    for c in prange(nchunks):
        _sense_rows(c * chunk, min(n, (c + 1) * chunk), clear, cast, hits, beams, even, hsh, noise, out)


def _check_noise_args(true_m, noise_std_m, p_max, p_short, max_range_m, out):
    true_m = np.asarray(true_m, dtype=np.float64)
    if true_m.ndim != 2:
        raise ValueError(f"true_m must be a 2-D array (n, B), got shape {true_m.shape}")
    for name, v in (("noise_std_m", noise_std_m), ("p_max", p_max), ("p_short", p_short)):
        if not (np.isfinite(v) and v >= 0):
            raise ValueError(f"{name} must be a finite number >= 0, got {v!r}")
    if p_max + p_short > 1.0 + 1e-12:
        raise ValueError(f"p_max + p_short must be <= 1, got {p_max} + {p_short}")
    if not (np.isfinite(max_range_m) and max_range_m > 0):
        raise ValueError(f"max_range_m must be a positive number of metres, got {max_range_m!r}")
    if out is None:
        out = np.empty(true_m.shape, dtype=np.float64)
    elif not (isinstance(out, np.ndarray) and out.shape == true_m.shape and out.dtype == np.float64
              and out.flags.writeable):
        raise ValueError(
            f"out must be a writeable float64 array of shape {true_m.shape}, got "
            f"{getattr(out, 'dtype', type(out).__name__)} {getattr(out, 'shape', '')}"
        )
    return true_m, out


def apply_beam_noise(true_m, rng, noise_std_m, p_max, p_short, max_range_m, out=None) -> np.ndarray:
    """Observed ranges from true ranges: the beam mixture of Fox et al. §2.2 (Fig. 1).

    Parameters
    ----------
    true_m : ndarray of shape (n, B), float64
        Noise-free ranges [m].
    rng : numpy.random.Generator
        Draws ``standard_normal((n, B))`` if ``noise_std_m > 0``, then ``random((n, B))`` if
        ``p_max + p_short > 0``.
    noise_std_m : float
        Standard deviation of the Gaussian part [m].
    p_max, p_short : float
        Probabilities of a max-range reading and of a uniform short reading in
        ``[0, true)``; ``p_max + p_short`` must not exceed 1.
    max_range_m : float
        Sensor range [m]; readings are clipped to ``[0, max_range_m]``.
    out : ndarray of shape (n, B), optional
        Filled and returned (may be ``true_m`` itself).

    Returns
    -------
    ndarray of shape (n, B), float64

    Examples
    --------
    >>> r = apply_beam_noise(np.array([[1.0, 9.0]]), np.random.default_rng(0), 0.0, 0.0, 0.0, 5.0)
    >>> r.tolist()
    [[1.0, 5.0]]
    """
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    true_m, out = _check_noise_args(true_m, noise_std_m, p_max, p_short, max_range_m, out)
    empty = np.empty((0, 0))
    z = rng.standard_normal(true_m.shape) if noise_std_m > 0 else empty
    u = rng.random(true_m.shape) if p_max + p_short > 0 else empty
    _mixture_kernel(true_m, z, u, float(noise_std_m), float(p_max), float(p_short), float(max_range_m), out)
    return out


#: Fewest beams (rows x beams) for which the keyed noise is spread over numba's threads: it
#: takes ~4 ns a beam, so below ~4 ms of work waking threads on a busy machine costs more.
NOISE_PARALLEL_MIN_BEAMS: int = 1_000_000


def draw_noise_key(rng: np.random.Generator) -> int:
    """The one draw a keyed-noise call takes from its ``Generator``: 64 raw bits of its bit
    generator (``rng.bit_generator.random_raw()``; 0.4 us against 3 us for ``rng.integers``)."""
    return int(rng.bit_generator.random_raw())


def _keyed_noise(true_m, key, noise_std_m, p_max, p_short, max_range_m, out) -> np.ndarray:
    """:func:`beam_noise_keyed` without input checks."""
    n, nb = true_m.shape
    args = (np.uint64(key), float(noise_std_m), float(p_max), float(p_short), float(max_range_m), out)
    if n * nb >= NOISE_PARALLEL_MIN_BEAMS:
        _counter_noise_parallel(true_m, *args)
    else:
        _counter_noise_rows(true_m, args[0], 0, n, *args[1:])
    return out


def beam_noise_keyed(true_m, key, noise_std_m, p_max, p_short, max_range_m, out=None) -> np.ndarray:
    """The beam mixture of :func:`apply_beam_noise`, with draws from counter-based streams.

    Same model, other random numbers: no ``(n, B)`` arrays of draws are made. The call
    reads the SplitMix64 sequence (Steele, Lea & Flood, OOPSLA 2014)
    ``out[m] = mix64(key + m * 0x9E3779B97F4A7C15)`` by random access; beam
    ``c = i * B + b`` owns the 64 outputs from ``m = 64 c + 1``: the first is the mixture's
    uniform (drawn only when ``p_max + p_short > 0``), the next ones feed a 256-layer
    ziggurat standard normal (Marsaglia & Tsang, J. Stat. Softw. 5(8), 2000; drawn only for
    a beam that is neither max nor short and when ``noise_std_m > 0``). The result depends
    only on ``key``, ``true_m`` and the parameters, on any number of threads.
    :class:`RangeSensor` takes one ``key`` per call from its ``Generator``
    (:func:`draw_noise_key`).

    Parameters
    ----------
    true_m : ndarray of shape (n, B), float64
        Noise-free ranges [m].
    key : int
        Stream key in ``[0, 2**64)``.
    noise_std_m, p_max, p_short, max_range_m, out
        As in :func:`apply_beam_noise`.

    Returns
    -------
    ndarray of shape (n, B), float64

    Examples
    --------
    >>> r = beam_noise_keyed(np.array([[1.0, 9.0]]), 7, 0.0, 0.0, 0.0, 5.0)
    >>> r.tolist()
    [[1.0, 5.0]]
    """
    if isinstance(key, bool) or not isinstance(key, (int, np.integer)) or not 0 <= int(key) < 2**64:
        raise ValueError(f"key must be an integer in [0, 2**64), got {key!r}")
    true_m, out = _check_noise_args(true_m, noise_std_m, p_max, p_short, max_range_m, out)
    return _keyed_noise(np.ascontiguousarray(true_m), int(key), noise_std_m, p_max, p_short, max_range_m, out)


# ---------------------------------------------------------------------------- the sensor
_EMPTY_F = np.zeros(0)
_EMPTY_I = np.zeros(0, np.int64)


class RangeSensor:
    """One range sensor model, shared by every robot of a group that carries it.

    Build it with :func:`build_range_sensor`. A sensor casts ``R = B * rays_per_beam`` rays
    per robot (``rays_per_beam`` is 1 except for a sonar's cone) and reports ``B`` ranges:
    the nearest return of each beam's rays.

    Attributes
    ----------
    name : str
        The sensor's name in observations (``Observation.scans[name]``).
    kind : str
        ``"laser"``, ``"sonar"`` or ``"proximity"``.
    angles_rad : ndarray of shape (B,)
        Reported beam directions in the body frame [rad] (read-only; a sonar's transducer
        axes).
    ray_angles_rad : ndarray of shape (B * rays_per_beam,)
        Directions of every ray cast, beam by beam [rad].
    max_range_m : float
        Range reported for "no return" [m].
    noise_std_m, p_max, p_short : float
        Beam-mixture parameters (:func:`beam_noise_keyed`); for a sonar ``p_max`` is its
        ``p_specular``.
    sees_robots : bool
        Whether rays stop on other robots' discs (when ``bodies`` are passed).

    Examples
    --------
    >>> from teamnav.world.grid import OccupancyGrid
    >>> g = OccupancyGrid.empty(10.0, 4.0, 0.1)
    >>> s = build_range_sensor(LaserConfig(n_beams=3, fov_deg=180, noise_std_m=0.0), g)
    >>> s.true_ranges(np.array([5.0]), np.array([2.0]), np.array([0.0])).round(6).tolist()
    [[2.0, 5.0, 2.0]]
    """

    def __init__(self, name: str, kind: str, grid: OccupancyGrid, sees, angles_rad: np.ndarray,
                 ray_offsets_rad: np.ndarray, max_range_m: float, noise_std_m: float, p_max: float,
                 p_short: float, sees_robots: bool):
        if not isinstance(grid, OccupancyGrid):
            raise ValueError(f"grid must be an OccupancyGrid, got {type(grid).__name__}")
        self.name = str(name)
        self.kind = str(kind)
        angles = np.ascontiguousarray(angles_rad, dtype=np.float64)
        angles.setflags(write=False)
        self.angles_rad = angles
        offsets = np.asarray(ray_offsets_rad, dtype=np.float64)
        self.rays_per_beam = int(offsets.shape[0])
        rays = (angles[:, None] + offsets[None, :]).ravel()
        rays.setflags(write=False)
        self.ray_angles_rad = rays
        self.max_range_m = float(max_range_m)
        self.noise_std_m = float(noise_std_m)
        self.p_max = float(p_max)
        self.p_short = float(p_short)
        if self.p_max + self.p_short > 1.0:
            raise ValueError(
                f"sensor {self.name!r}: the max-range and short-reading probabilities must sum to <= 1, "
                f"got {self.p_max} + {self.p_short}"
            )
        self.sees_robots = bool(sees_robots)
        self.sees = tuple(sees)
        self.caster = RayCaster(grid, self.sees, self.max_range_m)
        self._plan = beam_plan(rays)
        self._cos_rays = np.cos(rays)  # what RayCaster.cast_xyt would compute on every call
        self._sin_rays = np.sin(rays)

    def __repr__(self) -> str:
        return (f"RangeSensor(name={self.name!r}, kind={self.kind!r}, beams={self.angles_rad.shape[0]}, "
                f"rays_per_beam={self.rays_per_beam}, max_range_m={self.max_range_m}, sees={self.sees})")

    def info(self) -> SensorInfo:
        """What a robot knows of this sensor: name, kind, beam directions, range, noise."""
        return SensorInfo(self.name, self.kind, self.angles_rad.copy(), self.max_range_m, self.noise_std_m)

    # ------------------------------------------------------------------ truth
    def true_ranges(self, xs, ys, thetas, bodies=None) -> np.ndarray:
        """Noise-free ranges from true poses.

        Parameters
        ----------
        xs, ys, thetas : ndarray of shape (n,)
            True poses of the robots carrying the sensor [m, m, rad].
        bodies : tuple or None
            ``(all_x (N,), all_y (N,), all_radius (N,), self_index (n,))``: every robot's
            disc, and each sensing robot's own index into them (its own disc is skipped).
            Used only when the sensor ``sees_robots``.

        Returns
        -------
        ndarray of shape (n, B), float64
            Range [m] of each beam (nearest over its rays), in ``[0, max_range_m]``.
        """
        xs = np.ascontiguousarray(xs, dtype=np.float64)
        ys = np.ascontiguousarray(ys, dtype=np.float64)
        thetas = np.ascontiguousarray(thetas, dtype=np.float64)
        if not (xs.ndim == 1 and ys.shape == xs.shape and thetas.shape == xs.shape):
            raise ValueError(f"xs, ys and thetas must be 1-D arrays of one shape (n,), got {xs.shape}, {ys.shape}, "
                             f"{thetas.shape}")
        if not (np.isfinite(xs).all() and np.isfinite(ys).all() and np.isfinite(thetas).all()):
            raise ValueError("xs, ys and thetas must be finite")
        if bodies is not None and self.sees_robots:
            bodies = check_bodies(bodies, xs.shape[0])
        return self._true_ranges(xs, ys, thetas, bodies)

    def _true_ranges(self, xs, ys, thetas, bodies) -> np.ndarray:
        """:meth:`true_ranges` without input checks (the engine's per-step path).

        ``xs, ys, thetas``: contiguous float64 (n,); ``bodies``: None or as returned by
        :func:`~teamnav.sim.sensors.robot_hits.check_bodies`.
        """
        return self._pass(xs, ys, thetas, bodies, None)

    def _pass(self, xs, ys, thetas, bodies, key) -> np.ndarray:
        """One kernel pass per robot (:func:`_sense_rows`): other robots' discs, the map cast
        cut at them, each beam's nearest ray, then the keyed noise of ``key`` (None: no
        noise), into a fresh (n, B) array. Calls of fewer than ``PARALLEL_MIN_RAYS`` rays,
        and every call when numba runs one thread, stay in this thread (below that, waking
        numba's threads costs more than it saves)."""
        n = xs.shape[0]
        nr = self.ray_angles_rad.shape[0]
        use_hits = bodies is not None and self.sees_robots and bodies[0].shape[0] > 0
        if nr < ONE_PASS_MIN_RAYS:
            # few rays a robot (proximity rings): a fixed cost per robot of the one pass
            # outweighs what it saves; three passes over all robots give the same bits
            parallel = n * nr >= PARALLEL_MIN_RAYS
            cs_theta = (np.cos(thetas), np.sin(thetas))  # once for the cast and the robot hits
            true = self.caster._cast_cs(xs, ys, thetas, self._cos_rays, self._sin_rays, parallel, cs_theta)
            if use_hits:
                all_x, all_y, all_r, self_idx = bodies
                robot_hits_unchecked(xs, ys, thetas, self._plan, all_x, all_y, all_r, self_idx, true, self.max_range_m,
                                     0.0, parallel, cs_theta)
            if self.rays_per_beam > 1:
                true = true.reshape(n, self.angles_rad.shape[0], self.rays_per_beam).min(axis=2)
            if key is None:
                return true
            return _keyed_noise(true, key, self.noise_std_m, self.p_max, self.p_short, self.max_range_m, true)
        out = np.empty((n, self.angles_rad.shape[0]), dtype=np.float64)
        if n == 0:
            return out
        grid = self.caster.grid
        kxs, kys, ox, oy = grid.kernel_frame(xs, ys)
        kth = grid.kernel_theta(thetas)
        ct = np.cos(thetas)
        st = np.sin(thetas)
        kct, kst = (ct, st) if kth is thetas else (np.cos(kth), np.sin(kth))
        res = self.caster._res
        # the clearance maps apart from the rest: a huge map's tiles are a tuple, which numba's
        # parallel loops take as an argument of their own but not inside another tuple
        clear = self.caster.clearance
        cast = (float(ox), float(oy), res, kxs, kys, kct, kst, self._cos_rays, self._sin_rays, self.max_range_m / res,
                self.rays_per_beam)
        if use_hits:
            all_x, all_y, all_r, self_idx = bodies
        else:
            all_x = all_y = all_r = _EMPTY_F
            self_idx = _EMPTY_I
        hits = (use_hits, xs, ys, ct, st, self_idx, self.max_range_m)
        noise = (key is not None, np.uint64(0 if key is None else key), self.noise_std_m, self.p_max, self.p_short,
                 self.max_range_m)
        if n * nr >= PARALLEL_MIN_RAYS and numba.get_num_threads() > 1:
            chunk = min(256, max(1, n // (4 * numba.get_num_threads())))
            _sense_parallel(clear, cast, hits, self._plan.beams, self._plan.even, (all_x, all_y, all_r), noise, out, chunk)
        else:
            _sense_serial(clear, cast, hits, self._plan.beams, self._plan.even, (all_x, all_y, all_r), noise, out)
        return out

    # ------------------------------------------------------------------ observation
    def sense(self, xs, ys, thetas, rng: np.random.Generator, bodies=None, out: np.ndarray | None = None) -> np.ndarray:
        """Observed ranges: :meth:`true_ranges` corrupted by the beam mixture.

        Parameters
        ----------
        xs, ys, thetas : ndarray of shape (n,)
            True poses [m, m, rad].
        rng : numpy.random.Generator
            The sensor's stream: one key is drawn from it (:func:`draw_noise_key`), then
            every beam's numbers come from :func:`beam_noise_keyed`.
        bodies : tuple or None
            As in :meth:`true_ranges`.
        out : ndarray of shape (n, B), float64, optional
            Filled and returned; otherwise a fresh array is returned.

        Returns
        -------
        ndarray of shape (n, B), float64
            Observed ranges [m] in ``[0, max_range_m]``, ``max_range_m`` meaning no return.
        """
        if not isinstance(rng, np.random.Generator):
            raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
        true = self.true_ranges(xs, ys, thetas, bodies)
        if out is None:
            out = true  # a fresh array already; noise is applied in place
        elif not (isinstance(out, np.ndarray) and out.shape == true.shape and out.dtype == np.float64
                  and out.flags.writeable):
            raise ValueError(f"out must be a writeable float64 array of shape {true.shape}, got "
                             f"{getattr(out, 'dtype', type(out).__name__)} {getattr(out, 'shape', '')}")
        return _keyed_noise(true, draw_noise_key(rng), self.noise_std_m, self.p_max, self.p_short, self.max_range_m,
                            out)

    def _sense(self, xs, ys, thetas, rng: np.random.Generator, bodies=None) -> np.ndarray:
        """:meth:`sense` without input checks, into a fresh array (the engine's per-step path;
        arrays as in :meth:`_true_ranges`)."""
        return self._pass(xs, ys, thetas, bodies, draw_noise_key(rng))


def build_range_sensor(cfg: LaserConfig | SonarConfig | ProximityConfig, grid: OccupancyGrid) -> RangeSensor:
    """The sensor model a configuration describes, bound to a map.

    - :class:`LaserConfig`: ``n_beams`` over ``fov_deg`` (:func:`beam_angles`), one ray each;
      mixture ``noise_std_m``, ``p_max``, ``p_short``.
    - :class:`SonarConfig`: ``n_transducers`` axes over ``fov_deg``; each a cone of
      ``cone_deg`` sampled by ``rays_per_cone`` rays evenly from edge to edge (one ray on the
      axis when ``rays_per_cone`` is 1); its reading is the nearest return over the cone,
      then the mixture with ``p_max = p_specular``.
    - :class:`ProximityConfig`: one ray per ``angles_deg`` (wrapped to ``(-pi, pi]``),
      Gaussian noise only.

    Parameters
    ----------
    cfg : LaserConfig, SonarConfig or ProximityConfig
    grid : OccupancyGrid

    Returns
    -------
    RangeSensor

    Examples
    --------
    >>> from teamnav.world.grid import OccupancyGrid
    >>> s = build_range_sensor(SonarConfig(n_transducers=8, rays_per_cone=3), OccupancyGrid.empty(4, 4, 0.5))
    >>> s.angles_rad.shape, s.ray_angles_rad.shape, s.kind
    ((8,), (24,), 'sonar')
    """
    if isinstance(cfg, LaserConfig):
        return RangeSensor(cfg.name, "laser", grid, cfg.sees, beam_angles(cfg.n_beams, math.radians(cfg.fov_deg)),
                           np.zeros(1), cfg.max_range_m, cfg.noise_std_m, cfg.p_max, cfg.p_short, cfg.sees_robots)
    if isinstance(cfg, SonarConfig):
        axes = beam_angles(cfg.n_transducers, math.radians(cfg.fov_deg))
        half = math.radians(cfg.cone_deg) / 2
        offsets = np.zeros(1) if cfg.rays_per_cone == 1 else np.linspace(-half, half, cfg.rays_per_cone)
        return RangeSensor(cfg.name, "sonar", grid, cfg.sees, axes, offsets, cfg.max_range_m, cfg.noise_std_m,
                           cfg.p_specular, cfg.p_short, cfg.sees_robots)
    if isinstance(cfg, ProximityConfig):
        angles = np.atleast_1d(wrap_angle(np.radians(np.asarray(cfg.angles_deg, dtype=np.float64))))
        return RangeSensor(cfg.name, "proximity", grid, cfg.sees, angles, np.zeros(1), cfg.max_range_m,
                           cfg.noise_std_m, 0.0, 0.0, cfg.sees_robots)
    raise ValueError(
        f"cfg must be a LaserConfig, SonarConfig or ProximityConfig, got {type(cfg).__name__}"
    )
