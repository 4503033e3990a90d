"""The wanderer's decision for many robots in one compiled call, and its counter-based RNG.

Random exploration as Vaughan et al. use it (*Blazing a trail* §4; *Try to see it my way*
§3): follow walls, take side openings with a fixed probability, turn away from what blocks
the way. :mod:`teamnav.control.nav.wander` wraps this kernel twice, as a per-robot
:class:`~teamnav.control.nav.wander.Wander` (:func:`wander_row`: one row, its beam classes
computed once and everything else in one vector, so a call from Python costs little) and as
a batched :class:`~teamnav.control.nav.wander.WanderBatched` (:func:`wander_step`: n rows);
both run the one loop :func:`_wander_rows`, so both forms drive exactly the same by
construction.

Randomness is counter-based so that it does not depend on how robots are grouped: robot i
holds one 64-bit ``key`` (drawn once from its own ``Generator``), and the k-th uniform number
it may use at step ``step`` is ``uniform01(key, step, k)``, a pure function (splitmix64
finaliser, Steele et al. 2014, applied twice). No generator state advances, so a row gives the
same draws whether it is stepped alone or among a thousand others, and whether or not the
draw is used.

Per-robot state lives in a float64 array of shape (n, N_STATE) with the columns ``S_*``;
parameters in a float64 vector of length N_PARAMS with the entries ``P_*`` (built once by
:func:`teamnav.control.nav.wander.kernel_params`). Kernels do no validation (STYLE habit 10).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

# ----------------------------------------------------------------- parameter vector layout
P_CRUISE_MPS = 0  # forward speed in open space [m/s]
P_TURN_RADPS = 1  # turn rate when turning on the spot [rad/s]
P_SAFE_M = 2  # front range below which the way is blocked [m]
P_SLOW_M = 3  # front range below which the robot slows down [m]
P_WALL_M = 4  # side range kept while following a wall [m]
P_WALL_MAX_M = 5  # a side range below this is a wall to follow [m]
P_KP = 6  # wall following: turn rate per metre of side error [rad/s/m]
P_KD = 7  # wall following: turn rate per m/s of side range change [rad/m]
P_P_OPEN = 8  # probability of taking a side opening
P_OPEN_JUMP_M = 9  # side range jump that marks an opening [m]
P_FRONT_HALF_RAD = 10  # half-width of the front sector [rad]
P_SIDE_MIN_RAD = 11  # side sectors cover |angle| in [SIDE_MIN, SIDE_MAX] [rad]
P_SIDE_MAX_RAD = 12
P_BACKOFF_MPS = 13  # reverse speed after a stall [m/s]
P_BACKOFF_STEPS = 14  # steps of reversing after a stall
P_MIN_TURN_STEPS = 15  # least steps of an avoidance turn
P_EXTRA_TURN_STEPS = 16  # up to this many more steps, uniformly at random
P_OPEN_ADVANCE_STEPS = 17  # steps driven past an opening's near edge before turning into it
P_OPEN_TURN_STEPS = 18  # steps of the quarter turn into an opening
P_DT_S = 19  # control period [s]
N_PARAMS = 20

# ----------------------------------------------------------------- state columns
S_MODE = 0  # one of MODE_*
S_COUNT = 1  # steps left in the current timed manoeuvre
S_SIGN = 2  # turn direction of the current manoeuvre: +1 left (ccw), -1 right
S_WALL = 3  # wall being followed: +1 on the left, -1 on the right, 0 none
S_PREV_PERP_L = 4  # last step's range of the beam nearest +90° (NaN: none yet) [m]
S_PREV_PERP_R = 5  # same, nearest -90° [m]
S_PREV_SIDE_L = 6  # last step's minimum range in the left side sector (NaN: none yet) [m]
S_PREV_SIDE_R = 7  # same, right side sector [m]
N_STATE = 8

MODE_CRUISE = 0
MODE_TURN = 1
MODE_BACKOFF = 2
MODE_OPEN_ADVANCE = 3
MODE_OPEN_TURN = 4

# ----------------------------------------------------------------- draw indices k
# np.int64, not int: numba types a plain int global as a literal, and compiled uniform01 once
# per index (five specializations on a first run); an int64 constant shares one.
K_OPEN_LEFT = np.int64(0)
K_OPEN_RIGHT = np.int64(1)
K_TIE_SIGN = np.int64(2)
K_EXTRA_TURN = np.int64(3)
K_BACKOFF_SIGN = np.int64(4)
N_DRAWS = 8  # draws reserved per (robot, step); indices above are < N_DRAWS

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30 = np.uint64(30)
_S27 = np.uint64(27)
_S31 = np.uint64(31)
_S11 = np.uint64(11)
_TWO_M53 = 1.0 / 9007199254740992.0  # 2**-53


@njit(cache=True)
def splitmix64_mix(z: np.uint64) -> np.uint64:
    """The splitmix64 output finaliser: a bijective avalanche mix of a 64-bit word."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@njit(cache=True)
def uniform01(key: np.uint64, step: np.int64, k: np.int64) -> float:
    """The k-th uniform number in [0, 1) of a robot with ``key`` at ``step``.

    ``mix(key + φ·mix(step·N_DRAWS + k + 1))`` with φ the 64-bit golden ratio and ``mix`` the
    splitmix64 finaliser; the top 53 bits make the double. Wrapping uint64 arithmetic.
    """
    c = np.uint64(step) * np.uint64(N_DRAWS) + np.uint64(k) + np.uint64(1)
    z = splitmix64_mix(key + _GOLDEN * splitmix64_mix(c))
    return float(z >> _S11) * _TWO_M53


def uniform01_reference(key: int, step: int, k: int) -> float:
    """Pure-Python reference of :func:`uniform01` (arbitrary-precision ints, masked)."""
    mask = (1 << 64) - 1

    def mix(z: int) -> int:
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & mask
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & mask
        return z ^ (z >> 31)

    c = (step * N_DRAWS + k + 1) & mask
    z = mix((key + 0x9E3779B97F4A7C15 * mix(c)) & mask)
    return (z >> 11) * 2.0**-53


@njit(cache=True)
def _wrap(a: float) -> float:
    """Angle to (-π, π]."""
    a = (a + np.pi) % (2.0 * np.pi) - np.pi
    if a <= -np.pi:
        a += 2.0 * np.pi
    return a


@njit(cache=True)
def _random_turn_steps(p: np.ndarray, key: np.uint64, step: np.int64) -> float:
    extra = np.floor(uniform01(key, step, K_EXTRA_TURN) * (p[P_EXTRA_TURN_STEPS] + 1.0))
    return p[P_MIN_TURN_STEPS] + extra


# Beam classes: the rows of the array :func:`beam_classes` returns.
C_FRONT = 0  # |angle| <= front half-angle
C_SIDE_L = 1  # left side sector
C_SIDE_R = 2  # right side sector
C_HALF_L = 3  # left half (|angle| <= side max, angle > 0)
C_HALF_R = 4  # right half
N_CLASSES = 5


@njit(cache=True)
def beam_classes(angles_rad: np.ndarray, p: np.ndarray) -> tuple:
    """Each beam's classes, and the side beams nearest ±90°, from the beam directions and ``p``.

    Returns
    -------
    cls : ndarray of shape (N_CLASSES, B), bool
        ``cls[C_*, b]``: beam b is in that class.
    perp_l, perp_r : int
        The left / right side beam nearest +90° / -90° (-1: none).
    """
    nb = angles_rad.shape[0]
    cls = np.zeros((N_CLASSES, nb), np.bool_)
    front, side_l, side_r, half_l, half_r = cls[C_FRONT], cls[C_SIDE_L], cls[C_SIDE_R], cls[C_HALF_L], cls[C_HALF_R]
    perp_l = -1
    perp_r = -1
    best_l = 1e9
    best_r = 1e9
    half_pi = 0.5 * np.pi
    for b in range(nb):
        a = _wrap(angles_rad[b])
        aa = abs(a)
        front[b] = aa <= p[P_FRONT_HALF_RAD]
        in_side = aa >= p[P_SIDE_MIN_RAD] and aa <= p[P_SIDE_MAX_RAD]
        if aa <= p[P_SIDE_MAX_RAD]:
            half_l[b] = a > 0.0
            half_r[b] = a < 0.0
        if in_side and a > 0.0:
            side_l[b] = True
            d = abs(a - half_pi)
            if d < best_l:
                best_l = d
                perp_l = b
        elif in_side and a < 0.0:
            side_r[b] = True
            d = abs(a + half_pi)
            if d < best_r:
                best_r = d
                perp_r = b

    return cls, perp_l, perp_r


@njit(cache=True, inline="always")
def _wander_rows(ranges_m, front, side_l, side_r, half_l, half_r, perp_l, perp_r, max_range_m, stalled, keys, step, p,
                 state, v_out, omega_out) -> None:
    """:func:`wander_step` with the beam classes given (both forms of the wanderer run this loop)."""
    n, nb = ranges_m.shape
    for i in range(n):
        # ---------------------------------------------------------- what the scan says
        fmin = max_range_m
        sl = max_range_m
        sr = max_range_m
        sum_l = 0.0
        cnt_l = 0
        sum_r = 0.0
        cnt_r = 0
        for b in range(nb):
            r = ranges_m[i, b]
            if front[b] and r < fmin:
                fmin = r
            if side_l[b] and r < sl:
                sl = r
            if side_r[b] and r < sr:
                sr = r
            if half_l[b]:
                sum_l += r
                cnt_l += 1
            if half_r[b]:
                sum_r += r
                cnt_r += 1
        mean_l = sum_l / cnt_l if cnt_l > 0 else max_range_m
        mean_r = sum_r / cnt_r if cnt_r > 0 else max_range_m
        pl = ranges_m[i, perp_l] if perp_l >= 0 else max_range_m
        pr = ranges_m[i, perp_r] if perp_r >= 0 else max_range_m
        blocked = fmin < p[P_SAFE_M]
        key = keys[i]

        mode = state[i, S_MODE]
        count = state[i, S_COUNT]
        sign = state[i, S_SIGN]
        wall = state[i, S_WALL]

        # ---------------------------------------------------------- transitions
        if stalled[i]:
            if mode == MODE_BACKOFF:
                # Reversing is blocked too: turn on the spot instead.
                mode = MODE_TURN
                count = _random_turn_steps(p, key, step)
            elif mode != MODE_TURN:
                mode = MODE_BACKOFF
                count = p[P_BACKOFF_STEPS]
                sign = 1.0 if uniform01(key, step, K_BACKOFF_SIGN) < 0.5 else -1.0
                wall = 0.0
        if blocked and (mode == MODE_CRUISE or mode == MODE_OPEN_ADVANCE):
            mode = MODE_TURN
            count = _random_turn_steps(p, key, step)
            wall = 0.0
            if mean_l > mean_r + 1e-9:
                sign = 1.0
            elif mean_r > mean_l + 1e-9:
                sign = -1.0
            else:
                sign = 1.0 if uniform01(key, step, K_TIE_SIGN) < 0.5 else -1.0
        if mode == MODE_CRUISE:
            # Vaughan et al. (Blazing a trail §4): take a side opening with probability p.
            prev_l = state[i, S_PREV_PERP_L]
            prev_r = state[i, S_PREV_PERP_R]
            if (
                prev_l == prev_l
                and prev_l < p[P_WALL_MAX_M]
                and pl > prev_l + p[P_OPEN_JUMP_M]
                and uniform01(key, step, K_OPEN_LEFT) < p[P_P_OPEN]
            ):
                mode = MODE_OPEN_ADVANCE
                sign = 1.0
                count = p[P_OPEN_ADVANCE_STEPS]
            elif (
                prev_r == prev_r
                and prev_r < p[P_WALL_MAX_M]
                and pr > prev_r + p[P_OPEN_JUMP_M]
                and uniform01(key, step, K_OPEN_RIGHT) < p[P_P_OPEN]
            ):
                mode = MODE_OPEN_ADVANCE
                sign = -1.0
                count = p[P_OPEN_ADVANCE_STEPS]

        # ---------------------------------------------------------- command of the mode
        v = 0.0
        w = 0.0
        if mode == MODE_BACKOFF:
            v = -p[P_BACKOFF_MPS]
            count -= 1.0
            if count <= 0.0:
                mode = MODE_TURN
                count = _random_turn_steps(p, key, step)
        elif mode == MODE_TURN:
            w = sign * p[P_TURN_RADPS]
            count -= 1.0
            if count <= 0.0 and not blocked:
                mode = MODE_CRUISE
        elif mode == MODE_OPEN_TURN:
            w = sign * p[P_TURN_RADPS]
            count -= 1.0
            if count <= 0.0:
                mode = MODE_CRUISE
                wall = 0.0
        elif mode == MODE_OPEN_ADVANCE and count > 0.0:
            v = p[P_CRUISE_MPS]
            count -= 1.0
        elif mode == MODE_OPEN_ADVANCE:
            mode = MODE_OPEN_TURN
            count = p[P_OPEN_TURN_STEPS] - 1.0
            w = sign * p[P_TURN_RADPS]
            if count <= 0.0:
                mode = MODE_CRUISE
                wall = 0.0
        else:
            # Cruise: slow down as the front closes in, keep a wall on one side.
            span = p[P_SLOW_M] - p[P_SAFE_M]
            scale = 1.0
            if span > 0.0 and fmin < p[P_SLOW_M]:
                scale = max(0.25, (fmin - p[P_SAFE_M]) / span)
            v = p[P_CRUISE_MPS] * scale
            if wall > 0.0 and not sl < p[P_WALL_MAX_M]:
                wall = 0.0
            elif wall < 0.0 and not sr < p[P_WALL_MAX_M]:
                wall = 0.0
            if wall == 0.0:
                if sl < p[P_WALL_MAX_M] and sl <= sr:
                    wall = 1.0
                elif sr < p[P_WALL_MAX_M]:
                    wall = -1.0
            if wall != 0.0:
                side = sl if wall > 0.0 else sr
                prev = state[i, S_PREV_SIDE_L] if wall > 0.0 else state[i, S_PREV_SIDE_R]
                rate = (side - prev) / p[P_DT_S] if prev == prev else 0.0
                w = wall * (p[P_KP] * (side - p[P_WALL_M]) + p[P_KD] * rate)
                if w > p[P_TURN_RADPS]:
                    w = p[P_TURN_RADPS]
                elif w < -p[P_TURN_RADPS]:
                    w = -p[P_TURN_RADPS]

        state[i, S_MODE] = mode
        state[i, S_COUNT] = count
        state[i, S_SIGN] = sign
        state[i, S_WALL] = wall
        state[i, S_PREV_PERP_L] = pl
        state[i, S_PREV_PERP_R] = pr
        state[i, S_PREV_SIDE_L] = sl
        state[i, S_PREV_SIDE_R] = sr
        v_out[i] = v
        omega_out[i] = w


# ----------------------------------------------------------------- one robot (the per-robot Wander)
# Its parameters (P_*), state, beams nearest ±90°, key, stall flag and command in one float64
# vector: a call from Python then passes three arrays (each costs ~70 ns to hand to numba).
R_STATE = N_PARAMS  # the state columns S_* start here
R_PERP_L = R_STATE + N_STATE  # index of the beam nearest +90° (-1: none), as a float
R_PERP_R = R_PERP_L + 1
R_KEY = R_PERP_L + 2  # the RNG key's 64 bits (read through a uint64 view)
R_STALLED = R_KEY + 1  # this step's stall flag (1.0 / 0.0)
R_V = R_STALLED + 1  # the command decided (0.0, 0.0 before the first call)
R_W = R_V + 1
N_ROW = R_W + 1


@njit(cache=True)
def wander_row(ranges: np.ndarray, cls: np.ndarray, row: np.ndarray, max_range_m: float, stalled: bool,
               step: np.int64) -> tuple:
    """One robot's ``(v, omega, same)``: :func:`_wander_rows` on one row, with the beam classes
    ``cls`` computed once (:func:`beam_classes`) and ``row`` (shape (N_ROW,), ``R_*``) holding
    the parameters, the state (updated in place), the key and the command (``same``: bit for
    bit the command of the previous call, so the caller may hand out its previous Action)."""
    bits = row.view(np.uint64)
    last_v = bits[R_V]
    last_w = bits[R_W]
    row[R_STALLED] = 1.0 if stalled else 0.0
    _wander_rows(ranges[np.newaxis, :], cls[C_FRONT], cls[C_SIDE_L], cls[C_SIDE_R], cls[C_HALF_L], cls[C_HALF_R],
                 np.int64(row[R_PERP_L]), np.int64(row[R_PERP_R]), max_range_m,
                 row[R_STALLED:R_STALLED + 1], row.view(np.uint64)[R_KEY:R_KEY + 1], np.int64(step), row,
                 row[np.newaxis, R_STATE:R_STATE + N_STATE], row[R_V:R_V + 1], row[R_W:R_W + 1])
    return row[R_V], row[R_W], bits[R_V] == last_v and bits[R_W] == last_w


@njit(cache=True)
def wander_step(
    ranges_m: np.ndarray,
    angles_rad: np.ndarray,
    max_range_m: float,
    stalled: np.ndarray,
    keys: np.ndarray,
    step: np.int64,
    p: np.ndarray,
    state: np.ndarray,
    v_out: np.ndarray,
    omega_out: np.ndarray,
) -> None:
    """Decide every row's command and advance its state in place.

    Parameters
    ----------
    ranges_m : ndarray of shape (n, B), float64
        Each robot's ranges [m] (``max_range_m`` = no return).
    angles_rad : ndarray of shape (B,), float64
        Beam directions in the body frame [rad] (any layout; wrapped here).
    max_range_m : float
        The sensor's maximum range [m].
    stalled : ndarray of shape (n,), bool
        Each robot's stall flag.
    keys : ndarray of shape (n,), uint64
        Each robot's RNG key.
    step : int
        Step index (the counter of the counter-based RNG).
    p : ndarray of shape (N_PARAMS,), float64
        Parameters, see ``P_*``.
    state : ndarray of shape (n, N_STATE), float64
        Per-robot state, see ``S_*``; updated in place.
    v_out, omega_out : ndarray of shape (n,), float64
        Receive the commands [m/s], [rad/s].
    """
    cls, perp_l, perp_r = beam_classes(angles_rad, p)  # once per call
    _wander_rows(ranges_m, cls[C_FRONT], cls[C_SIDE_L], cls[C_SIDE_R], cls[C_HALF_L], cls[C_HALF_R], perp_l, perp_r, max_range_m, stalled, keys, step, p, state, v_out, omega_out)


#: Fewest rows for which :class:`~teamnav.control.nav.wander.WanderBatched` spreads them over
#: numba's threads (:func:`wander_step_parallel`): a row takes ~0.5 µs, so below ~1 ms of work
#: waking the threads costs more than it saves.
PARALLEL_MIN_ROWS = 2048


@njit(cache=True, parallel=True)
def wander_step_parallel(ranges_m, angles_rad, max_range_m, stalled, keys, step, p, state, v_out, omega_out,
                         chunk) -> None:
    """:func:`wander_step` with chunks of ``chunk`` rows spread over numba's threads.

    Exact by construction: a row reads only its own ranges, stall flag, key and state, and its
    random draws are ``uniform01(key, step, k)`` (module docstring), so its command and state are
    the same on any thread count and in any chunk.
    """
    cls, perp_l, perp_r = beam_classes(angles_rad, p)  # once per call
    n = ranges_m.shape[0]
    nchunks = (n + chunk - 1) // chunk
    for c in prange(nchunks):
        a = c * chunk
        b = min(n, a + chunk)
        _wander_rows(ranges_m[a:b], cls[C_FRONT], cls[C_SIDE_L], cls[C_SIDE_R], cls[C_HALF_L], cls[C_HALF_R], perp_l,
                     perp_r, max_range_m, stalled[a:b], keys[a:b], step, p, state[a:b], v_out[a:b],
                     omega_out[a:b])


def initial_state(n: int) -> np.ndarray:
    """Fresh state for ``n`` robots: cruising, no wall, no previous ranges (NaN)."""
    state = np.zeros((n, N_STATE), dtype=np.float64)
    state[:, S_SIGN] = 1.0
    state[:, S_PREV_PERP_L:] = np.nan
    return state
