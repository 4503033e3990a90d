"""Navigate's step as one compiled call: state as arrays, the rules of the reference, bit for bit.

:class:`~teamnav.control.nav.navigate.Navigate` (Vaughan, Støy, Sukhatme & Matarić, *Blazing a
trail* §4.2, reused by *Try to see it my way* §3.3: sliding-box wall following, openings, the
180° rule, sharp turns, Panic) stays the readable reference. :func:`nav_step` is the same step
over a float and an integer state row, for the compiled trail brains
(``docs/concepts/group-brains.md``); :class:`CompiledNavigate` wraps one robot's row behind the
reference's interface (``step``, ``turn_around``, ``leaving``, ``mode``, ``n_reversals``...), so
a trail brain runs unchanged over it. Its identity test (``tests/test_trail_compiled.py``) runs
both on the trail sections' scenarios and demands the same runs.

Where the reference computes in Python, this module computes as Python does:

- ``math.hypot`` is CPython's own algorithm (:func:`~teamnav.control.nav.local.compiled.py_hypot`),
  not libm's, which numba calls (they differ in the last bit for ~0.6 % of arguments);
- ``math.remainder`` (Navigate's angle wrap) is CPython's ``m_remainder``, written out
  (:func:`py_remainder`: ``fmod``, exact, then the half-way rule);
- ``min``/``max`` of two floats keep Python's order of comparison (the first argument on a tie);
- the robot's Generator is the reference's own, passed in: numba's ``Generator.random`` and
  ``Generator.integers(0, n)`` draw from the same bit generator as numpy's ``random()`` and
  ``integers(n)``, so draws interleave exactly with any made outside.

Not compiled (:func:`unsupported` names them; the caller runs the reference Navigate): the
meeting flags ``give_way_s`` > 0, ``meet_guard_deg`` > 0 and ``face_hint_after_panic`` (all off in
every trail scenario and in both report columns). Everything else of ``NavigateParams`` is.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from teamnav.control.nav.local.compiled import py_hypot
from teamnav.control.nav.navigate import Navigate, NavigateParams
from teamnav.control.nav.openings import NEAR_WALL_MIN_M, any_near_edge

__all__ = ["CompiledNavigate", "box_beams", "first_free_box_sparse", "nav_step", "nav_step_rng", "py_remainder", "unsupported"]

_TWO_PI = 2.0 * math.pi
_MODES = ("navigate", "advance", "turn", "panic")
_BOX_STATES = ("open", "follow", "blocked")

# ----------------------------------------------------------------- parameter columns (P_*)
P_CRUISE = 0  # min(cruise_speed_mps, max_v)
P_TURN_RATE = 1  # min(turn_rate_radps, max_omega)
P_MAX_V = 2
P_MAX_W = 3
P_SIDE = 4  # side_sign: +1 left wall, -1 right
P_STRAIGHT_HALF = 5  # radians(straight_half_angle_deg)
P_STRAIGHT_CLEAR = 6
P_REVERSE = 7  # radians(reverse_threshold_deg)
P_SIDE_RULE = 8  # radians(side_rule_min_deg)
P_TURN_TOL = 9  # radians(turn_tolerance_deg)
P_TURN_MAX = 10  # turn timeout in steps
P_REV_COOL_S = 11
P_REV_COOL_M = 12
P_REV_MEM_M = 13
P_OPEN_COOL = 14  # opening_cooldown_m
P_P_TAKE = 15  # p_take_opening
P_RULE_SIDE = 16  # 1.0: trail_rule "side", 0.0: "closest"
P_HOLD = 17  # advance_hold_heading
P_MIN_FRAC = 18  # min_speed_fraction
P_STEER = 19  # steer_gain_per_s
P_DT = 20
P_PANIC_STALL = 21  # panic_on_stall
P_SKIP_COOL = 22  # hint_skips_cooldown
P_MAX_RANGE = 23
# the sliding box
P_BOX_NEAR = 24
P_BOX_LEN = 25
P_BOX_AHEAD = 26  # ahead_must_be_free
# openings
P_OPEN_NEAR = 27
P_OPEN_JUMP = 28
P_OPEN_WIDTH = 29  # min_width_m
P_OPEN_TOL = 30  # wall_tolerance_m
P_OPEN_QUICK = 31  # the detector has extreme beams at all
P_N_EXT_L = 32
P_N_EXT_R = 33
# Panic
P_CRIT = 34  # critical_m
P_PANIC_V = 35
P_PANIC_W = 36
P_PANIC_FWD = 37  # forward steps
P_PANIC_TURN = 38  # turn timeout steps
N_P = 39

# ----------------------------------------------------------------- float state (F_*)
F_ODO = 0
F_LX = 1  # last pose
F_LY = 2
F_LTH = 3
F_TURN_DIR = 4
F_TURN_GOAL = 5
F_TURNED = 6
F_REV_S = 7  # _reverse_after_s
F_REV_M = 8  # _reverse_after_m
F_ADV_TO = 9
F_PEND_DIR = 10
F_PEND_HEAD = 11
F_ADV_HEAD = 12
F_LEAVE = 13
F_COOL_L = 14
F_COOL_R = 15
F_BOX_OFFSET = 16
F_AWAY = 17  # the sliding box's kept turn direction
F_PANIC_DIR = 18
N_F = 19

# ----------------------------------------------------------------- integer state (I_*)
I_MODE = 0  # index into _MODES
I_HAS_LAST = 1
I_TURN_STEPS = 2
I_ADV_STEPS = 3
I_ADV_MAX = 4
I_REVERSALS = 5
I_COOL_MAN_L = 6
I_COOL_MAN_R = 7
I_BOX_STATE = 8  # index into _BOX_STATES
I_PANIC_PHASE = 9  # 0 idle, 1 stop, 2 turn, 3 forward
I_PANIC_COUNT = 10
I_LAST_OPENING = 11  # 0 None, 1 left, 2 right
I_N_REV_AT = 12  # spots in the reversal memory (at most REV_AT)
N_I = 13

#: the reversal memory keeps the last 16 spots (``self._reversed_at[-15:] + [(x, y)]``)
REV_AT = 16

M_NAV, M_ADV, M_TURN, M_PANIC = 0, 1, 2, 3
B_OPEN, B_FOLLOW, B_BLOCKED = 0, 1, 2
PH_IDLE, PH_STOP, PH_TURN, PH_FWD = 0, 1, 2, 3


def unsupported(params: NavigateParams) -> str | None:
    """Why :func:`nav_step` cannot run these parameters as the reference does, or None."""
    if params.give_way_s > 0.0:
        return "give_way_s > 0 (the give-way's front history is not compiled)"
    if params.meet_guard_deg > 0.0:
        return "meet_guard_deg > 0 (the meeting guard is not compiled)"
    if params.face_hint_after_panic:
        return "face_hint_after_panic (not compiled)"
    return None


# ----------------------------------------------------------------- Python's float arithmetic
@njit(cache=True)
def py_remainder(x, y):
    """``math.remainder(x, y)`` of CPython (``Modules/mathmodule.c``, ``m_remainder``) for finite
    ``x`` and ``y != 0``: ``fmod`` (exact), then the nearer of the two candidates, ties to even."""
    absx = abs(x)
    absy = abs(y)
    m = np.fmod(absx, absy)
    c = absy - m
    if m < c:
        r = m
    elif m > c:
        r = -c
    else:
        r = m - 2.0 * np.fmod(0.5 * (absx - m), absy)
    return math.copysign(1.0, x) * r


@njit(cache=True, inline="always")
def _wrap(a):
    return py_remainder(a, _TWO_PI)


@njit(cache=True, inline="always")
def _pmax(a, b):
    """Python's ``max(a, b)``: b only when it is larger."""
    return b if b > a else a


@njit(cache=True, inline="always")
def _pmin(a, b):
    """Python's ``min(a, b)``: b only when it is smaller."""
    return b if b < a else a


# ----------------------------------------------------------------- pieces of the step
@njit(cache=True)
def _turn_command(fst, ist, par):
    """Navigate._turn_command: (done, v, w)."""
    remaining = fst[F_TURN_GOAL] - fst[F_TURN_DIR] * fst[F_TURNED]
    ist[I_TURN_STEPS] += 1
    if remaining <= par[P_TURN_TOL] or ist[I_TURN_STEPS] > par[P_TURN_MAX]:
        return True, 0.0, 0.0
    rate = par[P_TURN_RATE] * _pmin(1.0, _pmax(0.3, remaining / 0.3))
    return False, 0.0, fst[F_TURN_DIR] * rate


@njit(cache=True, inline="always")
def _start_turn(fst, ist, direction, amount):
    ist[I_MODE] = M_TURN
    fst[F_TURN_DIR] = direction
    fst[F_TURN_GOAL] = amount
    fst[F_TURNED] = 0.0
    ist[I_TURN_STEPS] = 0


@njit(cache=True, inline="always")
def _cool(fst, ist, extra):
    fst[F_COOL_L] = fst[F_ODO] + extra
    fst[F_COOL_R] = fst[F_ODO] + extra
    ist[I_COOL_MAN_L] = 1
    ist[I_COOL_MAN_R] = 1


@njit(cache=True, inline="always")
def _clip(par, v, w):
    return _pmin(_pmax(v, 0.0), par[P_MAX_V]), _pmin(_pmax(w, -par[P_MAX_W]), par[P_MAX_W])


@njit(cache=True)
def _critical(r, front, crit):
    for i in front:
        if r[i] < crit:
            return True
    return False


@njit(cache=True)
def _panic_step(fst, ist, par, r, front, free_exit):
    """Panic.step: (v, w); the phase goes back to idle when done."""
    ph = ist[I_PANIC_PHASE]
    if ph == PH_STOP:
        ist[I_PANIC_PHASE] = PH_TURN
        ist[I_PANIC_COUNT] = 0
        return 0.0, 0.0
    if ph == PH_TURN:
        free = True
        for b in range(r.shape[0]):
            if r[b] < free_exit[b]:
                free = False
                break
        if free:
            ist[I_PANIC_PHASE] = PH_FWD
            ist[I_PANIC_COUNT] = 0
            ph = PH_FWD
        else:
            ist[I_PANIC_COUNT] += 1
            if ist[I_PANIC_COUNT] > par[P_PANIC_TURN]:
                ist[I_PANIC_PHASE] = PH_IDLE
                ist[I_PANIC_COUNT] = 0
                return 0.0, 0.0
            return 0.0, fst[F_PANIC_DIR] * par[P_PANIC_W]
    if ph == PH_FWD:
        if _critical(r, front, par[P_CRIT]):
            ist[I_PANIC_PHASE] = PH_TURN
            ist[I_PANIC_COUNT] = 0
            return 0.0, fst[F_PANIC_DIR] * par[P_PANIC_W]
        ist[I_PANIC_COUNT] += 1
        if ist[I_PANIC_COUNT] >= par[P_PANIC_FWD]:
            ist[I_PANIC_PHASE] = PH_IDLE
            ist[I_PANIC_COUNT] = 0
        return par[P_PANIC_V], 0.0
    return 0.0, 0.0


def box_beams(exit_m: np.ndarray, side_sign: float) -> tuple[np.ndarray, np.ndarray]:
    """For each box (row of ``exit_m``), the beams that cross it (``exit > -inf``), the followed
    side's first, padded: ``(idx (K+1, M) int64, count (K+1,) int64)``. A beam that does not cross
    a box can never block it (``range < -inf`` never holds), and whether a box is blocked does not
    depend on the order its beams are looked at, so :func:`first_free_box_sparse` over these gives
    :func:`~teamnav.control.nav.wall_follow.first_free_box`'s answer, looking at fewer beams (the
    wall, on the followed side, blocks a box at its first beams)."""
    rows = []
    for k in range(exit_m.shape[0]):
        b = np.flatnonzero(exit_m[k] > -np.inf)
        rows.append(b[::-1] if side_sign > 0 else b)  # beams run right to left: left side first = last first
    m = max((len(b) for b in rows), default=0)
    idx = np.zeros((exit_m.shape[0], max(m, 1)), dtype=np.int64)
    cnt = np.zeros(exit_m.shape[0], dtype=np.int64)
    for k, b in enumerate(rows):
        idx[k, : len(b)] = b
        cnt[k] = len(b)
    return idx, cnt


@njit(cache=True)
def first_free_box_sparse(r, cos_a, near_m, exit_m, idx, cnt):
    """:func:`~teamnav.control.nav.wall_follow.first_free_box` over each box's crossing beams
    (:func:`box_beams`): the same (first free slide position or -1, straight ahead blocked)."""
    n_rows = exit_m.shape[0]
    first = -1
    for k in range(n_rows - 1):
        free = True
        for j in range(cnt[k]):
            b = idx[k, j]
            rb = r[b]
            if rb * cos_a[b] >= near_m and rb < exit_m[k, b]:
                free = False
                break
        if free:
            first = k
            break
    ahead = False
    k = n_rows - 1
    for j in range(cnt[k]):
        b = idx[k, j]
        rb = r[b]
        if rb * cos_a[b] >= near_m and rb < exit_m[k, b]:
            ahead = True
            break
    return first, ahead


@njit(cache=True)
def _box_command(fst, ist, par, r, cos_a, sin_a, exit_m, offsets, box_idx, box_cnt):
    """SlidingBox.command: (v, w, offset, state); keeps the on-the-spot turn direction."""
    first, ahead_blocked = first_free_box_sparse(r, cos_a, par[P_BOX_NEAR], exit_m, box_idx, box_cnt)
    if first == 0 and not (ahead_blocked and par[P_BOX_AHEAD] != 0.0):
        fst[F_AWAY] = 0.0
        return par[P_CRUISE], 0.0, offsets[0], B_OPEN
    if first < 0:
        if fst[F_AWAY] == 0.0:
            nearest = np.argmin(r)
            side = sin_a[nearest]
            fst[F_AWAY] = -math.copysign(1.0, side) if abs(side) > 1e-9 else -par[P_SIDE]
        return 0.0, fst[F_AWAY] * par[P_TURN_RATE], math.nan, B_BLOCKED
    fst[F_AWAY] = 0.0
    offset = offsets[first]
    err = math.atan2(offset, 0.5 * (par[P_BOX_NEAR] + par[P_BOX_LEN]))
    omega = _pmax(-par[P_TURN_RATE], _pmin(par[P_TURN_RATE], par[P_STEER] * err))
    v = par[P_CRUISE] * _pmax(par[P_MIN_FRAC], math.cos(err))
    return v, omega, offset, B_FOLLOW


@njit(cache=True)
def _detect_side(r, side, order, cos_s, sin_s, n_ext, near_m, jump_m, min_width, tol, out):
    """OpeningDetector.detect_side into ``out`` = (side, direction, wall, width, advance, lateral);
    returns whether an opening was found."""
    if n_ext == 0:
        return False
    j = -1
    for i in range(n_ext):
        h0 = r[order[i]]
        if h0 < near_m and r[order[i + 1]] - h0 > jump_m:
            j = i
            break
    if j < 0:
        return False
    n = order.shape[0]
    x1 = r[order[j]] * cos_s[j]
    y1 = r[order[j]] * sin_s[j]
    k = -1
    last = -1
    lim = y1 + tol
    for i in range(j + 1, n):
        xi = r[order[i]] * cos_s[i]
        yi = r[order[i]] * sin_s[i]
        if yi <= lim and xi > x1:
            if k < 0:
                k = i
            last = i
    if k >= 0:
        x0 = r[order[0]] * cos_s[0]
        y0 = r[order[0]] * sin_s[0]
        dx = x1 - x0
        dy = y1 - y0
        if j == 0 or py_hypot(dx, dy) < NEAR_WALL_MIN_M:
            dx = r[order[last]] * cos_s[last] - x1
            dy = r[order[last]] * sin_s[last] - y1
        norm = py_hypot(dx, dy)
        if norm > 1e-9:
            ux = dx / norm
            uy = dy / norm
        else:
            ux = 1.0
            uy = 0.0
        wall = side * math.atan2(uy, ux)
        x2 = r[order[k]] * cos_s[k]
        y2 = r[order[k]] * sin_s[k]
        width = (x2 - x1) * ux + (y2 - y1) * uy
        advance = 0.5 * ((x1 + x2) * ux + (y1 + y2) * uy)
    else:
        width = math.inf
        wall = 0.0
        advance = x1 + 0.5 * min_width
    if width < min_width:
        return False
    out[0] = side
    out[1] = wall + side * 0.5 * math.pi
    out[2] = wall
    out[3] = width
    out[4] = _pmax(0.0, advance)
    out[5] = y1
    return True


@njit(cache=True)
def _finite_scan(r_in, max_range):
    """The scan with no-returns (non-finite) at max range: ``r_in`` itself when all are finite.
    (A function of its own: an array variable reassigned inside the step made numba's step ~3x
    slower even where the reassignment never ran.)"""
    for b in range(r_in.shape[0]):
        if not math.isfinite(r_in[b]):
            return np.where(np.isfinite(r_in), r_in, max_range)
    return r_in


@njit(cache=True)
def _straight_ok(r, angles, along, half, clear):
    best = -math.inf
    anyb = False
    for b in range(angles.shape[0]):
        if abs(angles[b] - along) <= half:
            if not anyb or r[b] > best:
                best = r[b]
            anyb = True
    return anyb and best >= clear


@njit(cache=True)
def _nav_core(fst, ist, par, rev_at, r_in, x, y, th, t, stalled, has_pref, pref, allow_reverse, ignore_memory, rng,
              angles, cos_a, sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r, sin_r,
             head, front, free_exit):
    """One :meth:`Navigate.step <teamnav.control.nav.navigate.Navigate.step>` of one robot (module
    docstring): the command ``(v, w)``, state updated in place.

    ``fst``, ``ist``, ``par``: the robot's float state, integer state and parameters (``F_*``,
    ``I_*``, ``P_*``); ``rev_at`` (REV_AT, 2): the reversal memory; ``r_in``: the scan; ``x, y,
    th``: the odometry pose; ``t``: the time [s]; ``has_pref``/``pref``: the preferred heading;
    ``rng``: the robot's Generator, or None for a fast call (numba types a Generator argument
    in Python on every call, ~15 µs): a step that must draw (a Panic starts, or openings are
    found while exploring) then leaves the state as it was and returns ``(nan, nan)``, and the
    caller steps again with the Generator; the rest: the sensor's precomputed geometry
    (:class:`CompiledNavigate`).
    """
    if rng is None:  # no Generator (a fast call): a step that must draw is undone and returns NaN
        f0 = fst.copy()
        i0 = ist.copy()
    r = _finite_scan(r_in, par[P_MAX_RANGE])
    if ist[I_HAS_LAST] != 0:
        fst[F_ODO] += py_hypot(x - fst[F_LX], y - fst[F_LY])
        fst[F_TURNED] += _wrap(th - fst[F_LTH])
    fst[F_LX] = x
    fst[F_LY] = y
    fst[F_LTH] = th
    ist[I_HAS_LAST] = 1

    # 1. Panic overrides Navigate.
    if ist[I_MODE] == M_PANIC:
        v, w = _panic_step(fst, ist, par, r, front, free_exit)
        if ist[I_PANIC_PHASE] == PH_IDLE:
            ist[I_MODE] = M_NAV
            _cool(fst, ist, par[P_OPEN_COOL])
        return _clip(par, v, w)
    if (stalled and par[P_PANIC_STALL] != 0.0) or _critical(r, front, par[P_CRIT]):
        if rng is None:
            fst[:] = f0
            ist[:] = i0
            return math.nan, math.nan
        ist[I_PANIC_PHASE] = PH_STOP
        fst[F_PANIC_DIR] = 1.0 if rng.random() < 0.5 else -1.0
        ist[I_PANIC_COUNT] = 0
        ist[I_MODE] = M_PANIC
        v, w = _panic_step(fst, ist, par, r, front, free_exit)
        return _clip(par, v, w)

    # 2. Manoeuvres under way.
    if ist[I_MODE] == M_TURN:
        done, v, w = _turn_command(fst, ist, par)
        if not done:
            return _clip(par, v, w)
        ist[I_MODE] = M_NAV
        _cool(fst, ist, par[P_OPEN_COOL])
    elif ist[I_MODE] == M_ADV:
        ist[I_ADV_STEPS] += 1
        if fst[F_ODO] >= fst[F_ADV_TO] or ist[I_ADV_STEPS] > ist[I_ADV_MAX]:
            amount = fst[F_PEND_DIR] * _wrap(fst[F_PEND_HEAD] - th)
            _start_turn(fst, ist, fst[F_PEND_DIR], amount + _TWO_PI if amount < -0.5 * math.pi else _pmax(0.0, amount))
            done, v, w = _turn_command(fst, ist, par)
            if not done:
                return _clip(par, v, w)
            ist[I_MODE] = M_NAV
        else:
            v, w, off, st = _box_command(fst, ist, par, r, cos_a, sin_a, exit_m, offsets, box_idx, box_cnt)
            ist[I_BOX_STATE] = st
            fst[F_BOX_OFFSET] = off
            if par[P_HOLD] != 0.0 and st != B_BLOCKED:
                err = _wrap(fst[F_ADV_HEAD] - th)
                return _clip(par, par[P_CRUISE] * _pmax(par[P_MIN_FRAC], math.cos(err)), par[P_STEER] * err)
            return _clip(par, v, w)

    leaving = fst[F_ODO] < fst[F_LEAVE]
    if leaving:
        has_pref = False
    # 3. Heading against the trail: a sharp 180 deg right turn.
    if has_pref and allow_reverse and t >= fst[F_REV_S] and abs(_wrap(pref - th)) > par[P_REVERSE]:
        ok = ignore_memory
        if not ok and fst[F_ODO] >= fst[F_REV_M]:
            near = False
            r2 = par[P_REV_MEM_M] ** 2
            for i in range(ist[I_N_REV_AT]):
                if (x - rev_at[i, 0]) ** 2 + (y - rev_at[i, 1]) ** 2 < r2:
                    near = True
                    break
            ok = not near
        if ok:
            n = ist[I_N_REV_AT]
            if n == REV_AT:  # keep the last REV_AT - 1, then this spot
                for i in range(REV_AT - 1):
                    rev_at[i, 0] = rev_at[i + 1, 0]
                    rev_at[i, 1] = rev_at[i + 1, 1]
                n = REV_AT - 1
            rev_at[n, 0] = x
            rev_at[n, 1] = y
            ist[I_N_REV_AT] = n + 1
            ist[I_REVERSALS] += 1
            fst[F_REV_S] = t + par[P_REV_COOL_S]
            fst[F_REV_M] = fst[F_ODO] + par[P_REV_COOL_M]
            _start_turn(fst, ist, -par[P_SIDE], math.pi)
            done, v, w = _turn_command(fst, ist, par)
            if not done:
                return _clip(par, v, w)
            ist[I_MODE] = M_NAV

    bv, bw, boff, bst = _box_command(fst, ist, par, r, cos_a, sin_a, exit_m, offsets, box_idx, box_cnt)
    ist[I_BOX_STATE] = bst
    fst[F_BOX_OFFSET] = boff
    # 4. Openings.
    if bst != B_BLOCKED and not leaving and par[P_OPEN_QUICK] != 0.0 and any_near_edge(
            r, head, par[P_OPEN_NEAR], par[P_OPEN_JUMP]):
        ops = np.empty((2, 6))
        got_l = _detect_side(r, 1.0, order_l, cos_l, sin_l, int(par[P_N_EXT_L]), par[P_OPEN_NEAR], par[P_OPEN_JUMP],
                             par[P_OPEN_WIDTH], par[P_OPEN_TOL], ops[0])
        got_r = _detect_side(r, -1.0, order_r, cos_r, sin_r, int(par[P_N_EXT_R]), par[P_OPEN_NEAR], par[P_OPEN_JUMP],
                             par[P_OPEN_WIDTH], par[P_OPEN_TOL], ops[1])
        skip = par[P_SKIP_COOL] != 0.0 and has_pref
        found = np.empty(2, dtype=np.int64)
        nf = 0
        if got_l and (fst[F_ODO] >= fst[F_COOL_L] or (skip and ist[I_COOL_MAN_L] != 0)):
            found[nf] = 0
            nf += 1
        if got_r and (fst[F_ODO] >= fst[F_COOL_R] or (skip and ist[I_COOL_MAN_R] != 0)):
            found[nf] = 1
            nf += 1
        if nf > 0:
            choice = -1
            if not has_pref:
                if rng is None:
                    fst[:] = f0
                    ist[:] = i0
                    return math.nan, math.nan
                taken = np.empty(2, dtype=np.int64)
                nt = 0
                for q in range(nf):
                    u = rng.random()
                    if u < par[P_P_TAKE]:
                        taken[nt] = found[q]
                        nt += 1
                if nt > 1:
                    choice = taken[rng.integers(0, nt)]
                elif nt == 1:
                    choice = taken[0]
            else:
                along = ops[found[0], 2]
                if par[P_RULE_SIDE] != 0.0:
                    rel = _wrap(pref - th - along)
                    margin = par[P_SIDE_RULE] if _straight_ok(r, angles, along, par[P_STRAIGHT_HALF],
                                                               par[P_STRAIGHT_CLEAR]) else 0.0
                    for q in range(nf):
                        if ops[found[q], 0] * rel > margin:
                            choice = found[q]
                            break
                else:
                    best_err = abs(_wrap(pref - th - along)) if _straight_ok(
                        r, angles, along, par[P_STRAIGHT_HALF], par[P_STRAIGHT_CLEAR]) else math.inf
                    for q in range(nf):
                        o = found[q]
                        err = abs(_wrap(pref - (th + ops[o, 1])))
                        if err < best_err:
                            choice = o
                            best_err = err
            if not has_pref or choice >= 0:
                for q in range(nf):
                    o = found[q]
                    span = ops[o, 3] if math.isfinite(ops[o, 3]) else 0.0
                    until = fst[F_ODO] + _pmax(par[P_OPEN_COOL], span)
                    if ops[o, 0] > 0:
                        fst[F_COOL_L] = until
                        ist[I_COOL_MAN_L] = 0
                    else:
                        fst[F_COOL_R] = until
                        ist[I_COOL_MAN_R] = 0
            if choice >= 0:
                side = ops[choice, 0]
                ist[I_LAST_OPENING] = 1 if side > 0 else 2
                ist[I_MODE] = M_ADV
                fst[F_PEND_DIR] = side
                fst[F_PEND_HEAD] = th + ops[choice, 1]
                fst[F_ADV_HEAD] = th + ops[choice, 2]
                fst[F_ADV_TO] = fst[F_ODO] + ops[choice, 4]
                ist[I_ADV_STEPS] = 0
                ist[I_ADV_MAX] = int(np.rint((ops[choice, 4] / par[P_CRUISE] + 3.0) / par[P_DT]))  # round(): half to even
    # 5. Wall following.
    return _clip(par, bv, bw)


@njit(cache=True)
def nav_step(fst, ist, par, rev_at, r_in, x, y, th, t, stalled, has_pref, pref, allow_reverse, ignore_memory,
             angles, cos_a, sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r, sin_r,
             head, front, free_exit):
    """One :meth:`Navigate.step <teamnav.control.nav.navigate.Navigate.step>` of one robot, without
    its Generator (:func:`_nav_core` with ``rng=None``): ``(nan, nan)`` and the state untouched when
    a draw is due; then :func:`nav_step_rng`. Two entry points, one signature each (the fast one
    takes no Generator argument at all, whose typing costs ~15 µs a call)."""
    return _nav_core(fst, ist, par, rev_at, r_in, x, y, th, t, stalled, has_pref, pref, allow_reverse, ignore_memory,
                     None, angles, cos_a, sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r,
                     cos_r, sin_r, head, front, free_exit)


@njit(cache=True)
def nav_step_rng(fst, ist, par, rev_at, r_in, x, y, th, t, stalled, has_pref, pref, allow_reverse, ignore_memory, rng,
                 angles, cos_a, sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r, cos_r, sin_r,
                 head, front, free_exit):
    """:func:`nav_step` with the robot's Generator (a step that draws)."""
    return _nav_core(fst, ist, par, rev_at, r_in, x, y, th, t, stalled, has_pref, pref, allow_reverse, ignore_memory,
                     rng, angles, cos_a, sin_a, exit_m, offsets, box_idx, box_cnt, order_l, cos_l, sin_l, order_r,
                     cos_r, sin_r, head, front, free_exit)


class CompiledNavigate:
    """One robot's :class:`~teamnav.control.nav.navigate.Navigate` with its step compiled
    (:func:`nav_step`); the same constructor, public methods and attributes the trail brains use.

    Built from a reference :class:`Navigate` (its geometry: box exits, opening beam orders, Panic's
    sectors), which it keeps only for those arrays. Raises ValueError for parameters
    :func:`unsupported` names.
    """

    def __init__(self, params: NavigateParams, rng: np.random.Generator, info: Any, laser: str = "laser", *,
                 reference: Navigate | None = None, shared: dict | None = None) -> None:
        why = unsupported(params)
        if why is not None:
            raise ValueError(f"CompiledNavigate: {why}")
        # ``reference``: a Navigate already built from the same inputs (its geometry is read, not
        # built again); ``shared``: a dict in which robots of one team with the same parameters,
        # limits and sensor share their parameter row and geometry (read-only in the kernel)
        ref = reference if reference is not None else Navigate(params, rng, info, laser=laser)
        key = None
        if shared is not None:
            sensor = info.sensors[laser]
            key = (params, float(info.radius_m), float(info.max_v_mps), float(info.max_omega_radps),
                   float(info.dt_s), laser, np.asarray(sensor.angles_rad, dtype=np.float64).tobytes(),
                   float(sensor.max_range_m))
            hit = shared.get(key)
            if hit is not None:
                self.params, self.info, self.rng, self.laser = params, info, rng, laser
                self.angles_rad = ref.angles_rad
                self._par, self._geo = hit
                self.fst = np.zeros(N_F)
                self.ist = np.zeros(N_I, dtype=np.int64)
                self.rev_at = np.zeros((REV_AT, 2))
                self.reset()
                return
        self.params = params
        self.info = info
        self.rng = rng
        self.laser = laser
        self.angles_rad = ref.angles_rad
        p = params
        par = np.zeros(N_P)
        par[P_CRUISE] = ref.cruise_mps
        par[P_TURN_RATE] = ref.turn_rate_radps
        par[P_MAX_V] = ref.max_v_mps
        par[P_MAX_W] = ref.max_omega_radps
        par[P_SIDE] = ref.side_sign
        par[P_STRAIGHT_HALF] = ref._straight_half_rad
        par[P_STRAIGHT_CLEAR] = p.straight_clear_m
        par[P_REVERSE] = ref._reverse_rad
        par[P_SIDE_RULE] = ref._side_rule_rad
        par[P_TURN_TOL] = ref._turn_tol_rad
        par[P_TURN_MAX] = ref._turn_max_steps
        par[P_REV_COOL_S] = p.reverse_cooldown_s
        par[P_REV_COOL_M] = p.reverse_cooldown_m
        par[P_REV_MEM_M] = p.reverse_memory_m
        par[P_OPEN_COOL] = p.opening_cooldown_m
        par[P_P_TAKE] = p.p_take_opening
        par[P_RULE_SIDE] = 1.0 if p.trail_rule == "side" else 0.0
        par[P_HOLD] = 1.0 if p.advance_hold_heading else 0.0
        par[P_MIN_FRAC] = p.min_speed_fraction
        par[P_STEER] = p.steer_gain_per_s
        par[P_DT] = ref.dt_s
        par[P_PANIC_STALL] = 1.0 if p.panic_on_stall else 0.0
        par[P_SKIP_COOL] = 1.0 if p.hint_skips_cooldown else 0.0
        par[P_MAX_RANGE] = ref.max_range_m
        box = ref.box
        if box.cruise_speed_mps != ref.cruise_mps or box.min_speed_fraction != p.min_speed_fraction:
            raise AssertionError("the sliding box drives at Navigate's cruise speed")
        par[P_BOX_NEAR] = box.box_near_m
        par[P_BOX_LEN] = box.box_length_m
        par[P_BOX_AHEAD] = 1.0 if box.ahead_must_be_free else 0.0
        det = ref.openings
        par[P_OPEN_NEAR] = det.near_m
        par[P_OPEN_JUMP] = det.jump_m
        par[P_OPEN_WIDTH] = det.min_width_m
        par[P_OPEN_TOL] = det.wall_tolerance_m
        par[P_OPEN_QUICK] = 1.0 if det._quick else 0.0
        (_, order_l, cos_l, sin_l, n_l), (_, order_r, cos_r, sin_r, n_r) = det._sides
        par[P_N_EXT_L] = n_l
        par[P_N_EXT_R] = n_r
        pan = ref.panic
        par[P_CRIT] = pan.critical_m
        par[P_PANIC_V] = pan.speed_mps
        par[P_PANIC_W] = pan.turn_rate_radps
        par[P_PANIC_FWD] = pan._forward_steps
        par[P_PANIC_TURN] = pan._turn_steps
        self._par = par
        head = det._head if det._quick else np.zeros((2, 1), dtype=np.int64)
        i64 = lambda a: np.ascontiguousarray(a, dtype=np.int64)  # noqa: E731
        f64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
        box_idx, box_cnt = box_beams(box.exit_m, ref.side_sign)
        self._geo = (f64(ref.angles_rad), f64(box._cos), f64(box._sin), f64(box.exit_m), f64(box.offsets_m),
                     box_idx, box_cnt, i64(order_l), f64(cos_l), f64(sin_l), i64(order_r), f64(cos_r), f64(sin_r), i64(head),
                     i64(pan._front), f64(pan._free_exit))
        if key is not None:
            shared[key] = (self._par, self._geo)
        self.fst = np.zeros(N_F)
        self.ist = np.zeros(N_I, dtype=np.int64)
        self.rev_at = np.zeros((REV_AT, 2))
        self.reset()

    def reset(self) -> None:
        """:meth:`Navigate.reset`."""
        f, i = self.fst, self.ist
        f[:] = 0.0
        i[:] = 0
        f[F_REV_S] = -math.inf
        f[F_REV_M] = -math.inf
        f[F_BOX_OFFSET] = math.nan
        f[F_PANIC_DIR] = 1.0
        self.guarded = False

    def turn_around(self, leave_m: float = 0.0) -> None:
        """:meth:`Navigate.turn_around`."""
        if not (leave_m >= 0.0 and math.isfinite(leave_m)):
            raise ValueError(f"leave_m must be a finite number of metres >= 0, got {leave_m!r}")
        f, i = self.fst, self.ist
        i[I_PANIC_PHASE] = PH_IDLE
        i[I_PANIC_COUNT] = 0
        f[F_AWAY] = 0.0
        i[I_MODE] = M_TURN
        f[F_TURN_DIR] = -self._par[P_SIDE]
        f[F_TURN_GOAL] = math.pi
        f[F_TURNED] = 0.0
        i[I_TURN_STEPS] = 0
        f[F_LEAVE] = f[F_ODO] + leave_m
        f[F_REV_S] = -math.inf
        f[F_REV_M] = -math.inf
        i[I_N_REV_AT] = 0

    @property
    def leaving(self) -> bool:
        """:attr:`Navigate.leaving`."""
        return bool(self.fst[F_ODO] < self.fst[F_LEAVE])

    @property
    def mode(self) -> str:
        return _MODES[int(self.ist[I_MODE])]

    @property
    def n_reversals(self) -> int:
        return int(self.ist[I_REVERSALS])

    @property
    def box_state(self) -> str:
        return _BOX_STATES[int(self.ist[I_BOX_STATE])]

    @property
    def box_offset_m(self) -> float:
        return float(self.fst[F_BOX_OFFSET])

    @property
    def last_opening(self) -> str | None:
        return (None, "left", "right")[int(self.ist[I_LAST_OPENING])]

    @property
    def _odo_m(self) -> float:
        return float(self.fst[F_ODO])

    def step(self, obs: Any, preferred_heading_rad: float | None = None, *, allow_reverse: bool = True,
             reverse_ignore_memory: bool = False, bold: bool = False) -> tuple[float, float]:
        """:meth:`Navigate.step` (``bold`` matters only with a give-way, which is not compiled)."""
        try:
            scan = obs.scans[self.laser]
        except KeyError:
            raise ValueError(
                f"observation of robot {obs.robot_id} must carry scan {self.laser!r}, has {sorted(obs.scans)}"
            ) from None
        r = np.asarray(scan.ranges_m, dtype=np.float64)
        if r.shape != self.angles_rad.shape:
            raise ValueError(f"scan {self.laser!r} must have {self.angles_rad.size} beams, got shape {r.shape}")
        x, y, th = np.asarray(obs.odom_pose, dtype=np.float64)[:3].tolist()
        has = preferred_heading_rad is not None
        args = (self.fst, self.ist, self._par, self.rev_at, r, x, y, th, float(obs.time_s), bool(obs.stalled),
                has, float(preferred_heading_rad) if has else 0.0, bool(allow_reverse), bool(reverse_ignore_memory))
        v, w = nav_step(*args, *self._geo)
        if v != v:  # a draw was due: the step again, with the robot's Generator
            v, w = nav_step_rng(*args, self.rng, *self._geo)
        return v, w


def warm_up() -> None:
    """Load (or compile) both forms of :func:`nav_step`, the fast one and the one with a
    Generator, so that neither is loaded inside a timed run (a benchmark's warm-up calls this:
    the form with a Generator is first needed only when a robot first panics or explores)."""
    from teamnav.control.protocol import RobotInfo, SensorInfo
    from teamnav.control.types import Observation, RangeScan

    angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    info = RobotInfo(0, 1, 0.25, "unicycle", 0.5, 2.0, 0.1, 0.1,
                     sensors={"laser": SensorInfo("laser", "laser", angles, 8.0)})
    nav = CompiledNavigate(NavigateParams(), np.random.default_rng(0), info)
    for r in (8.0, 0.3):  # open space (no draw), then an obstacle critically close (Panic draws)
        scan = RangeScan(np.full(181, r), angles, 8.0)
        nav.step(Observation(0, 0, 0.0, np.zeros(3), np.zeros(3), scans={"laser": scan}))


def _renew_caches() -> None:
    """This module's kernels call the reference's kernels (the openings' quick test) and CPython's
    hypot (``local/compiled.py``): renew their numba caches when one of those changes
    (:func:`~teamnav.control.group.renew_stale_caches`)."""
    from teamnav.control.group import renew_module_caches
    from teamnav.control.nav import openings
    from teamnav.control.nav.local import compiled as local_compiled

    renew_module_caches(__name__, (openings, local_compiled))


_renew_caches()
