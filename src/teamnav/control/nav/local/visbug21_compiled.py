"""VisBug-21 (Sgorbissa & Arkin §6, algorithm A = 3; Lumelsky & Skewis 1990) for many robots
in one compiled call: state as named columns of arrays, one row per robot.

The group-brain form (``docs/concepts/group-brains.md``) of
:class:`~teamnav.control.nav.local.visbug21.VisBug21`, which stays the readable reference and
documents the rules (Step 1 towards the intermediate target Ti on the M-line, the hit point H,
Step 2 along the boundary with its leave test, Bug2's termination test, ``turn="nearer_end"``,
``boundary_shortcut``, ``reverse_walk_factor``). The state machine of
:meth:`~teamnav.control.nav.local.visbug21.VisBug21.direction` is repeated here operation for
operation, and calls the reference's own numba kernels as they are (``_follow_kernel``,
``_last_visible``, ``_leave_candidates``, ``_boundary_pick``, ``_nearest_sq``, ``_scan_points``,
``_safe_heading``), so that a row gives the same bits as the reference navigator fed the same
goals and scans. Where the reference computes in Python, so does this module:
``math.hypot`` is :func:`~teamnav.control.nav.local.compiled.py_hypot`, Python's ``min``/``max``
keep their first argument on a tie, and ``np.linspace(0, 1, n + 1)`` is ``k · (1/n)`` with the
last point 1.0 (numpy 2's formula).

Two calls stay in numpy (numba's object mode, :func:`_bearings_py` and :func:`_run_seen_py`,
each the reference's own code): the reference calls ``np.arctan2`` on arrays there
(``VisBug21._boundary_bearings``, Step 2's boundary target, and ``base.seen_free``, the leave
test's "seen free" run), and NumPy's vectorised atan2 (SVML on an AVX-512 machine) differs
from libm's ``atan2``, which numba calls, in the last bit for about 7 % of arguments. The
bearings' only use is a sign test and an order, but the nearest point's own bearing (numpy's
atan2 less libm's of the same pair) is 0 or one ulp either side, and that ulp decides whether
it is a candidate: no libm-only rule gives numpy's answer there. The two calls cost about
1-2 µs of object-mode entry each; measured on R1 alone (office_simple, tuning task 1001,
2500 steps) the bearings run at 0.86 calls per step in the paper column (``boundary_shortcut``)
and the seen-free test at about 0.01 per step in either column.

Temporary goals (a teammate, a ghost or a helper as the goal, which R1 with teammates sets:
``set_goal(temporary=True)``, :func:`vb_set_goal_t`), ``start_again`` (:func:`vb_start_again`,
with its ``reverse_walk_factor``) and ``_resume`` are compiled as the reference does them (since
2026-11-29): the suspended task memory is a copy of the state columns ``VF_GX..VF_REV_REACH`` and
``VI_HAS_GOAL..VI_RETURNS``. ``turn="random"`` (a draw of the robot's Generator per goal) is
declined by the group brains.

State layout: float parameters ``VP_*`` of ``vpar`` (n, NV_P); float state ``VF_*`` of ``vfst``
(n, NV_F); integer state ``VI_*`` of ``vist`` (n, NV_I). Flags ``VI_HAS_*`` say whether an
optional point (``None`` in the reference) is set. Kernels do no validation.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
from numba import njit, objmode

from teamnav.control.nav.local import compiled as N
from teamnav.control.nav.local.base import GOAL_SAME_TOL_M, GUARD_STEP_RAD, _safe_heading, _scan_points
from teamnav.control.nav.local.visbug21 import (
    MODE_FOLLOW,
    MODE_TO_GOAL,
    MODE_UNREACHABLE,
    NEARER_END_TIE_M,
    RESUME_FOLLOW_M,
    VisBug21,
)
from teamnav.control.nav.local.visbug21_geometry import (
    FOLLOW_GAP_M,
    _boundary_pick,
    _follow_kernel,
    _last_visible,
    _leave_candidates,
    _nearest_sq,
)
from teamnav.control.types import RangeScan

__all__ = ["TURNS", "beam_order", "vb_direction", "vb_new_navigator", "vb_params", "vb_progressing", "vb_set_goal",
           "vb_set_goal_t", "vb_start_again", "vb_state"]

#: ``VisBugParams.turn`` as a number (``VP_TURN``); "random" is not compiled
TURNS = {"left": 0, "right": 1, "nearer_end": 2}

# ----------------------------------------------------------------- parameter columns
VP_STEP = 0  # step_length_m
VP_RADIUS = 1  # radius_m
VP_SAFETY = 2  # safety_margin_m
VP_FOLLOW = 3  # follow_margin_m
VP_HYST = 4  # leave_hysteresis_m
VP_GAIN = 5  # follow_gain
VP_LEAVE_MARGIN = 6  # leave_margin_m
VP_LEAVE_RUN = 7  # leave_run_m
VP_SAMPLE = 8  # mline_sample_m
VP_RETURN_TOL = 9  # return_tol_m
VP_GUARD = 10  # guard_margin_m
VP_PATIENCE = 11  # follow_patience_m
VP_WINDOW = 12  # progress_window_steps (ProgressMonitor.window_steps)
VP_MIN_GAIN = 13  # float(progress_fraction) * float(step_length_m) (ProgressMonitor.min_gain_m)
VP_REVERSE = 14  # reverse_walk_factor (NaN: None)
VP_SHORTCUT = 15  # boundary_shortcut (1.0 / 0.0)
VP_TURN = 16  # TURNS[turn]
NV_P = 17

# ----------------------------------------------------------------- float state
VF_GX = 0  # goal_xy
VF_GY = 1
VF_SX = 2  # mline S
VF_SY = 3
VF_TX = 4  # mline T
VF_TY = 5
VF_HX = 6  # hit_xy
VF_HY = 7
VF_HIT_D = 8  # hit_dist_m
VF_T_ANCHOR = 9  # _t_anchor
VF_WALKED = 10  # _walked_m
VF_DIR_WALKED = 11  # _dir_walked_m
VF_REV_LIMIT = 12  # _reverse_limit_m
VF_REV_REACH = 13  # _reverse_reach_m
VF_LX = 14  # _last_xy
VF_LY = 15
VF_QX = 16  # _leave_target
VF_QY = 17
VF_FX = 18  # _follow_ref
VF_FY = 19
VF_E0X = 20  # _ends (two points)
VF_E0Y = 21
VF_E1X = 22
VF_E1Y = 23
VF_BX = 24  # _blocked_xy
VF_BY = 25
VF_MON_REF = 26  # ProgressMonitor.ref_m
VF_SLACK = 27  # _slack
#: the task's Bug2 memory suspended by a temporary goal (``VisBug21._suspended``, its
#: ``_TASK_STATE``): columns VF_GX..VF_REV_REACH copied to VF_SUS + the same column
VF_SUS = 28
N_SUS_F = VF_REV_REACH + 1
VF_SUS_AT_X = VF_SUS + N_SUS_F  # _suspended_at
VF_SUS_AT_Y = VF_SUS_AT_X + 1
VF_RF_X = VF_SUS_AT_Y + 1  # _reverse_for: (task goal, reverse_walk_factor), set by start_again
VF_RF_Y = VF_RF_X + 1
VF_RF_F = VF_RF_Y + 1
NV_F = VF_RF_F + 1

# ----------------------------------------------------------------- integer state
VI_HAS_GOAL = 0
VI_SIDE = 1  # +1 / -1
VI_MODE = 2  # MODE_TO_GOAL, MODE_FOLLOW, MODE_UNREACHABLE
VI_HAS_MLINE = 3
VI_HAS_HIT = 4
VI_LEFT_HIT = 5
VI_RETURNS = 6
VI_HAS_LAST = 7
VI_HAS_Q = 8  # a leave target
VI_LEAVE_STEPS = 9
VI_HAS_FREF = 10
VI_HAS_ENDS = 11
VI_HAS_BLOCKED = 12
VI_MON_STEPS = 13  # ProgressMonitor.steps
VI_MON_LAST_GAIN = 14  # ProgressMonitor.last_gain_step
#: the suspended task's integer memory: columns VI_HAS_GOAL..VI_RETURNS copied to VI_SUS + the same
VI_SUS = 15
N_SUS_I = VI_RETURNS + 1
VI_TEMP = VI_SUS + N_SUS_I  # temporary
VI_HAS_SUS = VI_TEMP + 1  # _suspended is not None
VI_RESUMED = VI_HAS_SUS + 1  # _resumed
VI_HAS_SUS_AT = VI_RESUMED + 1  # _suspended_at is not None
VI_HAS_RF = VI_HAS_SUS_AT + 1  # _reverse_for is not None
NV_I = VI_HAS_RF + 1

_T_GOAL = 1.0 - 1e-12
_TWO_PI = 2.0 * math.pi
_FOLLOW_GAP_M = FOLLOW_GAP_M
_TIE_M = NEARER_END_TIE_M
_GUARD_N = int(round(math.pi / GUARD_STEP_RAD))
_GUARD_RAD = GUARD_STEP_RAD
_SAME_M = GOAL_SAME_TOL_M
_RESUME_M = RESUME_FOLLOW_M


# ----------------------------------------------------------------- construction (Python)
def vb_params(params, step_length_m: float, radius_m: float) -> np.ndarray:
    """One row of ``vpar`` from a validated :class:`~teamnav.control.nav.local.visbug21_params.VisBugParams`."""
    if params.turn not in TURNS:
        raise ValueError(f"compiled VisBug-21: turn {params.turn!r} is not compiled (known: {', '.join(TURNS)})")
    p = np.zeros(NV_P)
    p[VP_STEP] = float(step_length_m)
    p[VP_RADIUS] = float(radius_m)
    p[VP_SAFETY] = params.safety_margin_m
    p[VP_FOLLOW] = params.follow_margin_m
    p[VP_HYST] = params.leave_hysteresis_m
    p[VP_GAIN] = params.follow_gain
    p[VP_LEAVE_MARGIN] = params.leave_margin_m
    p[VP_LEAVE_RUN] = params.leave_run_m
    p[VP_SAMPLE] = params.mline_sample_m
    p[VP_RETURN_TOL] = params.return_tol_m
    p[VP_GUARD] = params.guard_margin_m
    p[VP_PATIENCE] = params.follow_patience_m
    p[VP_WINDOW] = int(params.progress_window_steps)
    p[VP_MIN_GAIN] = float(params.progress_fraction) * float(step_length_m)
    p[VP_REVERSE] = math.nan if params.reverse_walk_factor is None else float(params.reverse_walk_factor)
    p[VP_SHORTCUT] = 1.0 if params.boundary_shortcut else 0.0
    p[VP_TURN] = TURNS[params.turn]
    return p


def vb_state(vpar: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(vfst, vist)`` of fresh navigators (no goal yet), one row per row of ``vpar``."""
    n = vpar.shape[0]
    vfst = np.zeros((n, NV_F))
    vist = np.zeros((n, NV_I), dtype=np.int64)
    for r in range(n):
        vb_new_navigator(vpar, vfst, vist, r)
    return vfst, vist


def beam_order(angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``VisBug21._followed``'s beam order of a layout: (indices sorted by angle mod 2π, stably;
    the sorted angles)."""
    a = np.asarray(angles, dtype=np.float64)
    order = np.argsort(np.mod(a, 2.0 * math.pi), kind="stable")
    return order.astype(np.int64), np.ascontiguousarray(a[order])


# ----------------------------------------------------------------- numpy's atan2 (object mode)
def _bearings_py(x: float, y: float, followed: np.ndarray, side: int) -> np.ndarray:
    """``VisBug21._boundary_bearings`` itself (its numpy arctan2), for a row with ``side``."""
    return VisBug21._boundary_bearings(SimpleNamespace(side=int(side)), np.array((x, y)), followed)


def _run_seen_py(pose: np.ndarray, ranges: np.ndarray, angles: np.ndarray, max_range: float, starts: np.ndarray,
                 runs: np.ndarray, u: np.ndarray, half_width_m: float, leave_run_m: float,
                 mline_sample_m: float) -> np.ndarray:
    """``VisBug21._run_seen`` itself (``base.seen_free``, with its numpy arctan2)."""
    nav = SimpleNamespace(params=SimpleNamespace(leave_run_m=leave_run_m, mline_sample_m=mline_sample_m))
    scan = RangeScan(ranges, angles, max_range)
    return np.asarray(VisBug21._run_seen(nav, pose, scan, starts, runs, u, half_width_m), dtype=np.bool_)


# ----------------------------------------------------------------- kernels
@njit(cache=True)
def _restart(vfst, vist, r):
    """``VisBug21._restart``: Step 1, no M-line, no hit point, the progress estimate reset."""
    vist[r, VI_MODE] = MODE_TO_GOAL
    vist[r, VI_HAS_MLINE] = 0
    vist[r, VI_HAS_HIT] = 0
    vfst[r, VF_HIT_D] = math.inf
    vfst[r, VF_T_ANCHOR] = 0.0
    vfst[r, VF_WALKED] = 0.0
    vist[r, VI_LEFT_HIT] = 0
    vist[r, VI_RETURNS] = 0
    vfst[r, VF_DIR_WALKED] = 0.0
    vfst[r, VF_REV_LIMIT] = math.inf
    vfst[r, VF_REV_REACH] = math.inf
    vist[r, VI_HAS_LAST] = 0
    vist[r, VI_HAS_Q] = 0
    vist[r, VI_LEAVE_STEPS] = 0
    vist[r, VI_HAS_FREF] = 0
    vist[r, VI_HAS_ENDS] = 0
    vist[r, VI_HAS_BLOCKED] = 0
    vfst[r, VF_MON_REF] = math.inf
    vist[r, VI_MON_STEPS] = 0
    vist[r, VI_MON_LAST_GAIN] = 0
    vist[r, VI_RESUMED] = 0


@njit(cache=True)
def vb_new_navigator(vpar, vfst, vist, r):
    """Row ``r`` as a newly built ``VisBug21`` (no goal; side +1 for ``turn="left"``, else -1;
    not temporary, nothing suspended, no ``_reverse_for``)."""
    vist[r, VI_HAS_GOAL] = 0
    vist[r, VI_SIDE] = 1 if vpar[r, VP_TURN] == 0.0 else -1
    vist[r, VI_TEMP] = 0
    vist[r, VI_HAS_SUS] = 0
    vist[r, VI_HAS_SUS_AT] = 0
    vist[r, VI_HAS_RF] = 0
    _restart(vfst, vist, r)


@njit(cache=True)
def vb_set_goal(vpar, vfst, vist, r, gx, gy):
    """``VisBug21.set_goal(g)`` of a task goal (not temporary): a goal more than 1 µm from the
    current one restarts VisBug (new M-line, no hit point)."""
    vb_set_goal_t(vpar, vfst, vist, r, gx, gy, False)


@njit(cache=True)
def vb_set_goal_t(vpar, vfst, vist, r, gx, gy, temporary):
    """``VisBug21.set_goal(g, temporary)``: a temporary goal suspends the task goal's Bug2 memory
    (M-line, H, ``d_H``, mode, side, laps, the alternating walk) and runs a fresh VisBug; the
    suspended task goal set again (within 1 µm) resumes it; any other task goal drops it. As the
    reference, ``turn="random"`` is not compiled (its draw per task goal)."""
    same = vist[r, VI_HAS_GOAL] == 1 and N.py_hypot(gx - vfst[r, VF_GX], gy - vfst[r, VF_GY]) <= _SAME_M
    if temporary:
        if same and vist[r, VI_TEMP] == 1:
            return
        if vist[r, VI_HAS_SUS] == 0 and vist[r, VI_HAS_GOAL] == 1 and vist[r, VI_TEMP] == 0:
            vist[r, VI_HAS_SUS] = 1
            for k in range(N_SUS_F):
                vfst[r, VF_SUS + k] = vfst[r, k]
            for k in range(N_SUS_I):
                vist[r, VI_SUS + k] = vist[r, k]
            if vist[r, VI_HAS_LAST] == 1:
                vist[r, VI_HAS_SUS_AT] = 1
                vfst[r, VF_SUS_AT_X] = vfst[r, VF_LX]
                vfst[r, VF_SUS_AT_Y] = vfst[r, VF_LY]
            else:
                vist[r, VI_HAS_SUS_AT] = 0
        vist[r, VI_TEMP] = 1
        vfst[r, VF_GX] = gx
        vfst[r, VF_GY] = gy
        vist[r, VI_HAS_GOAL] = 1
        _restart(vfst, vist, r)
        return
    if same and vist[r, VI_TEMP] == 0:
        return
    task = vist[r, VI_HAS_SUS] == 1
    vist[r, VI_HAS_SUS] = 0
    vist[r, VI_TEMP] = 0
    if task and N.py_hypot(gx - vfst[r, VF_SUS + VF_GX], gy - vfst[r, VF_SUS + VF_GY]) <= _SAME_M:
        _restart(vfst, vist, r)
        for k in range(N_SUS_F):
            vfst[r, k] = vfst[r, VF_SUS + k]
        for k in range(N_SUS_I):
            vist[r, k] = vist[r, VI_SUS + k]
        vist[r, VI_RESUMED] = 1
        return
    vfst[r, VF_GX] = gx
    vfst[r, VF_GY] = gy
    vist[r, VI_HAS_GOAL] = 1
    _restart(vfst, vist, r)
    if vist[r, VI_HAS_RF] == 1 and N.py_hypot(gx - vfst[r, VF_RF_X], gy - vfst[r, VF_RF_Y]) > _SAME_M:
        vist[r, VI_HAS_RF] = 0


@njit(cache=True)
def vb_start_again(vpar, vfst, vist, r, reverse_walk_factor):
    """``VisBug21.start_again(reverse_walk_factor)`` (NaN: None): forget the task goal's M-line,
    hit point and mode (during a temporary goal: drop the suspended task memory instead); with a
    factor, the boundary walks towards the task goal alternate until the goal changes."""
    has_task = True
    if vist[r, VI_HAS_SUS] == 1:
        tx = vfst[r, VF_SUS + VF_GX]
        ty = vfst[r, VF_SUS + VF_GY]
    elif vist[r, VI_TEMP] == 1 or vist[r, VI_HAS_GOAL] == 0:
        has_task = False
        tx = 0.0
        ty = 0.0
    else:
        tx = vfst[r, VF_GX]
        ty = vfst[r, VF_GY]
    if reverse_walk_factor == reverse_walk_factor and has_task:
        vist[r, VI_HAS_RF] = 1
        vfst[r, VF_RF_X] = tx
        vfst[r, VF_RF_Y] = ty
        vfst[r, VF_RF_F] = reverse_walk_factor
    if vist[r, VI_HAS_SUS] == 1 or vist[r, VI_TEMP] == 1:
        vist[r, VI_HAS_SUS] = 0
    elif vist[r, VI_HAS_GOAL] == 1:
        _restart(vfst, vist, r)


@njit(cache=True)
def _resume(vpar, vfst, vist, r, px, py):
    """``VisBug21._resume``: the first step back on the task goal after a temporary one."""
    vist[r, VI_RESUMED] = 0
    if (vist[r, VI_HAS_HIT] == 1 and N.py_hypot(vfst[r, VF_GX] - px, vfst[r, VF_GY] - py)
            < vfst[r, VF_HIT_D] - vpar[r, VP_LEAVE_MARGIN]):
        _restart(vfst, vist, r)
    elif (vist[r, VI_MODE] == MODE_FOLLOW and vist[r, VI_HAS_SUS_AT] == 1
          and N.py_hypot(px - vfst[r, VF_SUS_AT_X], py - vfst[r, VF_SUS_AT_Y]) > _RESUME_M):
        vist[r, VI_MODE] = MODE_TO_GOAL


@njit(cache=True)
def vb_progressing(vpar, vfst, vist, r):
    """``VisBug21.progressing`` of row ``r``."""
    mode = vist[r, VI_MODE]
    if mode == MODE_UNREACHABLE:
        return False
    if mode == MODE_FOLLOW:
        return vfst[r, VF_WALKED] < vpar[r, VP_PATIENCE]
    return vist[r, VI_MON_STEPS] - 1 - vist[r, VI_MON_LAST_GAIN] <= vpar[r, VP_WINDOW]


@njit(cache=True)
def _mline_samples(vpar, vfst, r, t_from):
    """``VisBug21._mline_samples(t_from)``: M-line points with parameter t >= t_from − 1e-12
    (goal last), and their t (``np.linspace(0, 1, n + 1)``: ``k · (1/n)``, the last 1.0)."""
    sx = vfst[r, VF_SX]
    sy = vfst[r, VF_SY]
    dx = vfst[r, VF_TX] - sx
    dy = vfst[r, VF_TY] - sy
    length = N.py_hypot(dx, dy)
    n = int(math.ceil(length / vpar[r, VP_SAMPLE]))
    if n < 1:
        n = 1
    step = 1.0 / n
    lim = t_from - 1e-12
    t = np.empty(n + 1)
    pts = np.empty((n + 1, 2))
    j = 0
    for k in range(n + 1):
        tk = 1.0 if k == n else k * step
        if not (tk >= lim):
            continue
        t[j] = tk
        pts[j, 0] = sx + tk * dx
        pts[j, 1] = sy + tk * dy
        j += 1
    return pts[:j], t[:j]


@njit(cache=True)
def _mline_dir(vfst, r):
    """``VisBug21._mline_dir``: the unit direction ``(T − S) / max(|T − S|, 1e-12)``."""
    dx = vfst[r, VF_TX] - vfst[r, VF_SX]
    dy = vfst[r, VF_TY] - vfst[r, VF_SY]
    h = N.py_hypot(dx, dy)
    den = h if not (1e-12 > h) else 1e-12  # Python's max(h, 1e-12)
    return dx / den, dy / den


@njit(cache=True)
def _intermediate_target(vpar, vfst, vist, r, x, y, pts, r_safe, reach_m):
    """``VisBug21._intermediate_target``: (found, Ti); sets or clears the blocked M-line point."""
    cand, t = _mline_samples(vpar, vfst, r, vfst[r, VF_T_ANCHOR])
    j = _last_visible(x, y, pts[:, 0], pts[:, 1], cand[:, 0], cand[:, 1], r_safe, reach_m, vfst[r, VF_SLACK])
    vist[r, VI_HAS_BLOCKED] = 0
    if j < 0:
        return False, 0.0, 0.0
    tx = cand[j, 0]
    ty = cand[j, 1]
    if t[j] >= _T_GOAL or N.py_hypot(tx - x, ty - y) >= vpar[r, VP_STEP]:
        return True, tx, ty
    if j + 1 < cand.shape[0]:
        vist[r, VI_HAS_BLOCKED] = 1
        vfst[r, VF_BX] = cand[j + 1, 0]
        vfst[r, VF_BY] = cand[j + 1, 1]
    return False, 0.0, 0.0


@njit(cache=True)
def _leave_point(vpar, vfst, vist, r, px, py, th, ranges, angles, max_range, pts, r_safe, reach_m):
    """``VisBug21._leave_point`` (``r_safe`` is Step 1's plus the hysteresis, as the reference
    passes it): (found, Q); sets the anchor of Step 1's search when found."""
    cand, t = _mline_samples(vpar, vfst, r, 0.0)
    ux, uy = _mline_dir(vfst, r)
    hyst = vpar[r, VP_HYST]
    sel, ok, tested, run, n_ok = _leave_candidates(
        px, py, pts, cand, t, vfst[r, VF_GX], vfst[r, VF_GY], vfst[r, VF_HIT_D] - vpar[r, VP_LEAVE_MARGIN],
        vfst[r, VF_TX], vfst[r, VF_TY], ux, uy, r_safe, r_safe - hyst, reach_m, vfst[r, VF_SLACK],
        vpar[r, VP_LEAVE_RUN])
    if n_ok == 0:
        return False, 0.0, 0.0
    ns = sel.shape[0]
    m = 0
    for i in range(ns):
        if ok[i] and tested[i]:
            m += 1
    if m:
        starts = np.empty((m, 2))
        runs = np.empty(m)
        keep = np.empty(m, dtype=np.int64)
        m = 0
        for i in range(ns):
            if ok[i] and tested[i]:
                starts[m, 0] = cand[sel[i], 0]
                starts[m, 1] = cand[sel[i], 1]
                runs[m] = run[i]
                keep[m] = i
                m += 1
        pose = np.empty(3)
        pose[0] = px
        pose[1] = py
        pose[2] = th
        u = np.empty(2)
        u[0] = ux
        u[1] = uy
        hw = r_safe - hyst
        leave_run = vpar[r, VP_LEAVE_RUN]
        sample = vpar[r, VP_SAMPLE]
        with objmode(seen="boolean[:]"):
            seen = _run_seen_py(pose, ranges, angles, max_range, starts, runs, u, hw, leave_run, sample)
        for q in range(m):
            ok[keep[q]] = seen[q]
    # _nearest_leave_point
    j = -1
    for i in range(ns):
        if ok[i]:
            j = i
    if j < 0:
        return False, 0.0, 0.0
    qx = cand[sel[j], 0]
    qy = cand[sel[j], 1]
    if t[sel[j]] < _T_GOAL and N.py_hypot(qx - px, qy - py) < vpar[r, VP_STEP]:
        return False, 0.0, 0.0
    vfst[r, VF_T_ANCHOR] = t[sel[j]]
    return True, qx, qy


@njit(cache=True)
def _followed(vpar, vfst, vist, r, px, py, th, ranges, order, a_sorted, max_range):
    """``VisBug21._followed``: the sensed points of the followed obstacle (K, 2); keeps the
    followed point and, for ``turn="nearer_end"``, the obstacle's two sensed ends."""
    nb = order.shape[0]
    rs = np.empty(nb)
    for i in range(nb):
        rs[i] = ranges[order[i]]
    has_ref = vist[r, VI_HAS_FREF] == 1
    ends = vpar[r, VP_TURN] == 2.0
    n_members, members, near, pts, found, e = _follow_kernel(
        px, py, th, rs, a_sorted, max_range * (1.0 - 1e-9), has_ref,
        vfst[r, VF_FX] if has_ref else 0.0, vfst[r, VF_FY] if has_ref else 0.0,
        vpar[r, VP_STEP] + _FOLLOW_GAP_M, 2.5 * (2.0 * math.pi / nb), ends)
    if n_members < 0:
        vist[r, VI_HAS_FREF] = 0
        return np.zeros((0, 2))
    vist[r, VI_HAS_FREF] = 1
    vfst[r, VF_FX] = pts[near, 0]
    vfst[r, VF_FY] = pts[near, 1]
    if ends:
        if found:
            vist[r, VI_HAS_ENDS] = 1
            vfst[r, VF_E0X] = e[0, 0]
            vfst[r, VF_E0Y] = e[0, 1]
            vfst[r, VF_E1X] = e[1, 0]
            vfst[r, VF_E1Y] = e[1, 1]
        else:
            vist[r, VI_HAS_ENDS] = 0
    out = np.empty((n_members, 2))
    for k in range(n_members):
        out[k, 0] = pts[members[k], 0]
        out[k, 1] = pts[members[k], 1]
    return out


@njit(cache=True)
def _boundary_heading(x, y, fol, follow_m, side, gain):
    """:func:`~teamnav.control.nav.local.visbug21_geometry.boundary_heading` (NaN: None)."""
    if fol.shape[0] == 0:
        return math.nan
    i, d2 = _nearest_sq(fol[:, 0], fol[:, 1], x, y)
    rx = fol[i, 0] - x
    ry = fol[i, 1] - y
    d = math.sqrt(d2)
    v = (follow_m - d) / follow_m
    v = v if v < 1.0 else 1.0  # Python's min(1.0, v)
    err = v if v > -1.0 else -1.0  # max(-1.0, v)
    c = gain * err
    lim = math.pi / 3
    c = c if c < lim else lim
    corr = c if c > -math.pi / 3 else -math.pi / 3
    return math.atan2(ry, rx) + side * (0.5 * math.pi + corr)


@njit(cache=True)
def _choose_side(vfst, vist, r, x, y):
    """``VisBug21._choose_side``: towards the sensed end with the shorter ``|xO| + |OT|``."""
    if vist[r, VI_HAS_ENDS] == 0:
        return
    gx = vfst[r, VF_GX]
    gy = vfst[r, VF_GY]
    c0 = N.py_hypot(vfst[r, VF_E0X] - x, vfst[r, VF_E0Y] - y) + N.py_hypot(gx - vfst[r, VF_E0X], gy - vfst[r, VF_E0Y])
    c1 = N.py_hypot(vfst[r, VF_E1X] - x, vfst[r, VF_E1Y] - y) + N.py_hypot(gx - vfst[r, VF_E1X], gy - vfst[r, VF_E1Y])
    if abs(c0 - c1) > _TIE_M:
        vist[r, VI_SIDE] = 1 if c0 < c1 else -1


@njit(cache=True)
def _hit(vpar, vfst, vist, r, x, y):
    """``VisBug21._hit``: Step 1 -> Step 2 at (x, y)."""
    vist[r, VI_MODE] = MODE_FOLLOW
    vist[r, VI_HAS_HIT] = 1
    vfst[r, VF_HX] = x
    vfst[r, VF_HY] = y
    if vist[r, VI_HAS_BLOCKED] == 1:
        ax = vfst[r, VF_BX]
        ay = vfst[r, VF_BY]
    else:
        ax = x
        ay = y
    d = N.py_hypot(vfst[r, VF_GX] - ax, vfst[r, VF_GY] - ay)
    if d < vfst[r, VF_HIT_D]:  # Python's min(hit_dist_m, d)
        vfst[r, VF_HIT_D] = d
    vfst[r, VF_WALKED] = 0.0
    vist[r, VI_LEFT_HIT] = 0
    vist[r, VI_RETURNS] = 0
    vist[r, VI_HAS_FREF] = 0
    vfst[r, VF_DIR_WALKED] = 0.0
    f = vpar[r, VP_REVERSE]
    if vist[r, VI_HAS_RF] == 1 and N.py_hypot(vfst[r, VF_GX] - vfst[r, VF_RF_X],
                                              vfst[r, VF_GY] - vfst[r, VF_RF_Y]) <= _SAME_M:
        f = vfst[r, VF_RF_F]  # set by start_again for this goal
    if f != f:
        lim = math.inf
    else:
        v = f * N.py_hypot(vfst[r, VF_GX] - x, vfst[r, VF_GY] - y)
        lim = v if v > 2.0 else 2.0  # max(2.0, v)
    vfst[r, VF_REV_LIMIT] = lim
    vfst[r, VF_REV_REACH] = lim


@njit(cache=True)
def vb_direction(vpar, vfst, vist, r, px, py, th, ranges, angles, order, a_sorted, max_range):
    """``VisBug21.direction`` of row ``r`` at pose (px, py, th) with the scan ``ranges`` over
    ``angles`` (``order``, ``a_sorted``: :func:`beam_order` of them): the wrapped heading of the
    next step [rad, own frame], NaN for None (no goal, or the goal found unreachable)."""
    if vist[r, VI_HAS_GOAL] == 0 or vist[r, VI_MODE] == MODE_UNREACHABLE:
        return math.nan
    gx = vfst[r, VF_GX]
    gy = vfst[r, VF_GY]
    if vist[r, VI_RESUMED] == 1:
        _resume(vpar, vfst, vist, r, px, py)
    if vist[r, VI_HAS_MLINE] == 0:
        vist[r, VI_HAS_MLINE] = 1
        vfst[r, VF_SX] = px
        vfst[r, VF_SY] = py
        vfst[r, VF_TX] = gx
        vfst[r, VF_TY] = gy
    if vist[r, VI_HAS_LAST] == 1 and vist[r, VI_MODE] == MODE_FOLLOW:
        step_m = N.py_hypot(px - vfst[r, VF_LX], py - vfst[r, VF_LY])
        vfst[r, VF_WALKED] += step_m
        vfst[r, VF_DIR_WALKED] += step_m
    vist[r, VI_HAS_LAST] = 1
    vfst[r, VF_LX] = px
    vfst[r, VF_LY] = py
    # ProgressMonitor.update(distance to the goal)
    d = N.py_hypot(gx - px, gy - py)
    if vfst[r, VF_MON_REF] == math.inf:
        vfst[r, VF_MON_REF] = d
        vist[r, VI_MON_LAST_GAIN] = vist[r, VI_MON_STEPS]
    elif d < vfst[r, VF_MON_REF] - vpar[r, VP_MIN_GAIN]:
        vfst[r, VF_MON_REF] = d
        vist[r, VI_MON_LAST_GAIN] = vist[r, VI_MON_STEPS]
    vist[r, VI_MON_STEPS] += 1
    pts = _scan_points(px, py, th, ranges, angles, max_range * (1.0 - 1e-9))
    nb = ranges.shape[0]
    vfst[r, VF_SLACK] = math.pi / (nb if nb > 1 else 1)
    r_safe = vpar[r, VP_RADIUS] + vpar[r, VP_SAFETY]
    reach_m = max_range - r_safe
    step = vpar[r, VP_STEP]
    side_gain = vpar[r, VP_GAIN]
    heading = math.nan
    if vist[r, VI_MODE] == MODE_FOLLOW:
        found, qx, qy = _leave_point(vpar, vfst, vist, r, px, py, th, ranges, angles, max_range, pts,
                                     r_safe + vpar[r, VP_HYST], reach_m)
        if found:
            vist[r, VI_MODE] = MODE_TO_GOAL
            vfst[r, VF_MON_REF] = math.inf  # _monitor.reset()
            vist[r, VI_MON_STEPS] = 0
            vist[r, VI_MON_LAST_GAIN] = 0
            vist[r, VI_HAS_Q] = 1
            vfst[r, VF_QX] = qx
            vfst[r, VF_QY] = qy
            vist[r, VI_LEAVE_STEPS] = 2 * int(math.ceil(N.py_hypot(qx - px, qy - py) / step)) + 5
        else:
            d_hit = N.py_hypot(px - vfst[r, VF_HX], py - vfst[r, VF_HY])
            tol = vpar[r, VP_RETURN_TOL]
            if d_hit >= 2.0 * tol:
                vist[r, VI_LEFT_HIT] = 1
            elif vist[r, VI_LEFT_HIT] == 1 and d_hit <= tol:
                vist[r, VI_LEFT_HIT] = 0
                vist[r, VI_RETURNS] += 1
                if vist[r, VI_RETURNS] >= 2:
                    vist[r, VI_MODE] = MODE_UNREACHABLE
                    return math.nan
            if vfst[r, VF_DIR_WALKED] > vfst[r, VF_REV_LIMIT]:
                vist[r, VI_SIDE] = -vist[r, VI_SIDE]
                vfst[r, VF_DIR_WALKED] = 0.0
                vfst[r, VF_REV_LIMIT] = 3.0 * vfst[r, VF_REV_REACH]
                vfst[r, VF_REV_REACH] *= 2.0
                vist[r, VI_LEFT_HIT] = 0
                vist[r, VI_RETURNS] = 0
            fol = _followed(vpar, vfst, vist, r, px, py, th, ranges, order, a_sorted, max_range)
            follow_m = r_safe + vpar[r, VP_FOLLOW]
            heading = _boundary_heading(px, py, fol, follow_m, vist[r, VI_SIDE], side_gain)
            if heading == heading and vpar[r, VP_SHORTCUT] != 0.0 and fol.shape[0] >= 3:
                side = vist[r, VI_SIDE]
                with objmode(delta="float64[:]"):
                    delta = _bearings_py(px, py, fol, side)
                k, bx, by = _boundary_pick(px, py, fol[:, 0], fol[:, 1], delta, follow_m, step, pts[:, 0],
                                           pts[:, 1], r_safe, reach_m, vfst[r, VF_SLACK])
                if k >= 0:
                    heading = math.atan2(by - py, bx - px)
            if heading != heading:  # nothing sensed at all: the obstacle is gone
                vist[r, VI_MODE] = MODE_TO_GOAL
    if vist[r, VI_MODE] == MODE_TO_GOAL and vist[r, VI_HAS_Q] == 1:
        qx = vfst[r, VF_QX]
        qy = vfst[r, VF_QY]
        if N.py_hypot(qx - px, qy - py) < step or vist[r, VI_LEAVE_STEPS] <= 0:
            vist[r, VI_HAS_Q] = 0
        else:
            vist[r, VI_LEAVE_STEPS] -= 1
            heading = math.atan2(qy - py, qx - px)
    if vist[r, VI_MODE] == MODE_TO_GOAL and heading != heading:
        found, tx, ty = _intermediate_target(vpar, vfst, vist, r, px, py, pts, r_safe, reach_m)
        if not found:
            _hit(vpar, vfst, vist, r, px, py)
            fol = _followed(vpar, vfst, vist, r, px, py, th, ranges, order, a_sorted, max_range)
            if vpar[r, VP_TURN] == 2.0:
                _choose_side(vfst, vist, r, px, py)
            heading = _boundary_heading(px, py, fol, r_safe + vpar[r, VP_FOLLOW], vist[r, VI_SIDE], side_gain)
            if heading != heading:
                heading = math.atan2(gy - py, gx - px)
        else:
            heading = math.atan2(ty - py, tx - px)
    if pts.shape[0] == 0:
        return N.py_wrap(heading)
    h = _safe_heading(heading, px, py, pts[:, 0], pts[:, 1], step, vpar[r, VP_RADIUS] + vpar[r, VP_GUARD],
                      _GUARD_N, _GUARD_RAD)
    return N.py_wrap(h)


def _renew_caches() -> None:
    """This module's kernels call the reference's kernels (base, visbug21_geometry) and the
    compiled navigators' helpers: renew their numba caches when one of those changes
    (:func:`~teamnav.control.group.renew_stale_caches`)."""
    from teamnav.control.group import renew_module_caches
    from teamnav.control.nav.local import base, visbug21, visbug21_geometry

    renew_module_caches(__name__, (N, base, visbug21, visbug21_geometry))


_renew_caches()
