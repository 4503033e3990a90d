"""R1 of the line-of-sight help system with teammates, compiled: its row of the team's group brain
(Sgorbissa & Arkin §2-§6; ``docs/concepts/group-brains.md``).

:class:`~.team_compiled.LosTeamGroup` steps R1..R4 in one call; its team step
(:func:`~.team_compiled.team_advance`, :func:`~.team_compiled.team_decide`) gives R1's row to
:func:`r1_team_advance_row` and :func:`r1_team_decide_row` here, and the helpers' rows to
:mod:`.helper_compiled`. This module holds R1's columns (``rpar``, ``rist``, ``rfst`` beside
the explorer's ``epar``/``efst``/``eist`` of :mod:`.compiled`) and the kernels of its step: the
explorer's step of :mod:`.explorer` (the readable reference) with goal sharing, following a
teammate or a ghost, trouble following (§5 rule 3, :mod:`.trouble_following`) and algorithm A
(the potential field, Avoid-Past or VisBug-21); the list of each rule and gap-fill is in
:mod:`.team_compiled`. R1 alone (no teammate) is :mod:`.compiled`
(:class:`~.compiled.LosExplorerGroup`).

Every branch is the reference's, operation for operation, as in :mod:`.compiled`;
``tests/test_team_compiled.py`` runs both side by side and demands the same run. These kernels
were part of :mod:`.team_compiled` until 2026-11-29, which still re-exports their names.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from teamnav.control.nav.local import compiled as N
from teamnav.control.nav.local import visbug21_compiled as V
from teamnav.papers.los_help.brains import compiled as C
from teamnav.papers.los_help.brains import goal_sharing_compiled as GC
from teamnav.papers.los_help.brains import helper_compiled as HC

__all__ = ["r1_team_advance_row", "r1_team_decide_row"]

# ----------------------------------------------------------------- R1's columns beside epar/efst/eist (rpar, rist)
RP_GHOST_TOL = 0  # ghost_tolerance_m
RP_SHARE_VIA = 1  # share_via
RP_VIA_IN_SIGHT = 2  # via_in_sight
RP_TRUST = 3  # trust_direct_promise
RP_DROP_STALLED = 4  # drop_stalled_ghost
RP_POINT_MARGIN = 5  # goal sharing's point_margin_m (2.5 radii)
RP_ME = 6  # the row's robot id (its own slot in ``paths``)
RP_STATE = 7  # state_sharing (§5: trouble following, :mod:`.trouble_following`)
RP_TOWARDS = 8  # trouble_helper_towards_goal
RP_HEADING_STEPS = 9  # trouble_heading_steps
RP_RECEDE = 10  # trouble_recede_m
RP_AT_SEND = 11  # trouble_sighting_at_send
RP_KEEP_HELPER = 12  # keep_trouble_helper
RP_DROP_HELPER = 13  # trouble_drop_stalled_helper
RP_DROP_AFTER = 14  # trouble_drop_after_steps
RP_PROGRESS = 15  # trouble_progress: PROGRESS_*
RP_NEAR_HELPER = 16  # trouble_near_helper_m (NaN: None)
RP_RESTART_AT_GHOST = 17  # restart_navigator_at_ghost (VisBug-21's start_again)
RP_REVERSE = 18  # visbug_reverse_walk_factor (NaN: None)
RP_DROP_UNREACH = 19  # drop_unreachable_ghost
N_RP = 20

PROGRESS_HELPER = 0
PROGRESS_MOVED = 1
PROGRESS_GOAL = 2
PROGRESS = ("helper", "moved", "goal")

# R1's float state (rfst)
F_TT_X = 0  # _trouble_target's position (own frame)
F_TT_Y = 1
F_TT_BEST = 2  # _tt_best_d
F_PREV_GOAL_D = 3  # _prev_goal_d
N_RF = 4

R_ROLE = 0
R_MODE = 1  # MODE_*
R_LAST_KIND = 2  # _last_target's key: KEY_* (KEY_NONE: None), with two integers
R_LAST_A = 3
R_LAST_B = 4
R_NAV_TEMP = 5  # the goal last given to A was temporary (``_nav_goal``'s flag)
R_PROMISED = 6  # _promised (-1: None)
R_TEMP_STALL = 7
R_TEMP_DROPPED = 8
R_VIAS = 9
R_PROMISED_STEPS = 10
R_TEMP_SWITCHES = 11
R_TEMP_KEY = 12  # _temp_key: (kind, id) as R_TEMP_KIND and the id (-1: None)
R_TEMP_KIND = 13
R_TT_ID = 14  # _trouble_target's teammate (-1: None)
R_TT_STALL = 15  # _tt_stall
R_HELPERS_DROPPED = 16  # trouble_helpers_dropped
R_GHOSTS_UNREACH = 17  # ghosts_unreachable
R_TEMP_UNREACH = 18  # _temp_unreachable: A found this step's temporary point unreachable
R_STEPS = 19  # mode_steps: R_STEPS + MODE_*
N_R = R_STEPS + 6

MODE_OWN_GOAL = 0
MODE_DONE = 1
MODE_GAVE_UP = 2
MODE_FOLLOW = 3
MODE_GHOST = 4
MODE_TROUBLE = 5
MODES = ("own_goal", "done", "gave_up", "follow_teammate", "ghost", "trouble_follow")

KEY_NONE = 0
KEY_GOAL = 1  # ("goal", target index)
KEY_PATH = 2  # ("path", source, step): a temporary point for A
KEY_PROMISED = 3  # ("promised", target index)
KEY_HELPER = 4  # ("helper", teammate): §5 rule 3's temporary goal


@njit(cache=True)
def r1_team_advance_row(r, step, odom, epar, eist, rist, targets, target_steps, own_set, own_k, own_xy, mg_n):
    """``LosExplorer._advance_task`` of row ``r`` (§2): the target reached within ε, then the
    next; a target not reached within ``max_steps_per_target`` ends the task. ``own_set`` /
    ``own_k`` / ``own_xy``: the ``set_own_goal`` call it makes (-1: None)."""
    own_set[r] = 0
    px = odom[r, 0]
    py = odom[r, 1]
    while eist[r, C.J_FINISHED] == 0:
        i = eist[r, C.J_IDX]
        if N.py_hypot(targets[r, i, 0] - px, targets[r, i, 1] - py) >= epar[r, C.Q_TOL]:
            budget = epar[r, C.Q_BUDGET]
            if budget >= 0.0 and step - eist[r, C.J_SINCE] >= budget:
                eist[r, C.J_GAVE_UP] = 1
                eist[r, C.J_FINISHED] = 1
                own_set[r] = 1
                own_k[r] = -1
            return
        eist[r, C.J_SINCE] = step
        target_steps[r, eist[r, C.J_REACHED]] = eist[r, C.J_MOVES] - eist[r, C.J_MOVES_SINCE]
        eist[r, C.J_MOVES_SINCE] = eist[r, C.J_MOVES]
        eist[r, C.J_IDX] = i + 1
        eist[r, C.J_REACHED] += 1
        own_set[r] = 1
        if eist[r, C.J_IDX] >= eist[r, C.J_NT]:
            eist[r, C.J_FINISHED] = 1
            own_k[r] = -1
            rist[r, R_MODE] = MODE_DONE
        else:
            own_k[r] = eist[r, C.J_IDX] + 1
            own_xy[r, 0] = targets[r, i + 1, 0]
            own_xy[r, 1] = targets[r, i + 1, 1]
        rist[r, R_LAST_KIND] = KEY_NONE
        mg_n[r, :] = 0  # _mate_goal_d = {} (the teammates' distances were to the old goal)
        if epar[r, C.Q_RESET_TR] != 0.0:
            eist[r, C.J_PR] = 0
            eist[r, C.J_NT_TR] = 1
            eist[r, C.J_TR] = 0


@njit(cache=True)
def _navigate_t(r, gx, gy, temporary, px, py, th, ranges, angles, max_range, epar, efst, eist, rist, npar, nfst, nist,
                grid, normals, nav):
    """``_Driving._navigate``: (heading relative to the body or NaN for none, progressing);
    ``temporary``: an excursion to a teammate, a ghost or a trouble helper (A keeps its task
    goal's memory, ``set_goal(temporary=True)``). The potential field and Avoid-Past always give a
    heading once a goal is set. VisBug-21 gives none once it finds its goal unreachable: for a
    temporary point, no move and ``R_TEMP_UNREACH`` set (the explorer's
    ``drop_unreachable_ghost`` reads it); for the task goal, with ``restart_navigator_on_give_up``,
    a fresh navigator next step."""
    tmp = 1 if temporary else 0
    visbug = epar[r, C.Q_VISBUG] != 0.0
    if (eist[r, C.J_NAV_SET] == 0 or efst[r, C.X_NAV_GX] != gx or efst[r, C.X_NAV_GY] != gy
            or rist[r, R_NAV_TEMP] != tmp):
        if visbug:
            V.vb_set_goal_t(nav[0], nav[1], nav[2], r, gx, gy, temporary)
        else:
            N.set_goal(npar, nfst, nist, grid, r, gx, gy, temporary)
        eist[r, C.J_NAV_SET] = 1
        efst[r, C.X_NAV_GX] = gx
        efst[r, C.X_NAV_GY] = gy
        rist[r, R_NAV_TEMP] = tmp
    if not visbug:
        h = N.direction(npar, nfst, nist, grid, normals, r, px, py, th, ranges[r], angles, max_range)
        return N.py_wrap(h - th), N.progressing(npar, nist, r)
    vpar, vfst, vist, order, a_sorted = nav
    h = V.vb_direction(vpar, vfst, vist, r, px, py, th, ranges[r], angles, order, a_sorted, max_range)
    progressing = V.vb_progressing(vpar, vfst, vist, r)
    rist[r, R_TEMP_UNREACH] = 0
    if h != h:
        if temporary:
            rist[r, R_TEMP_UNREACH] = 1  # A keeps the point (and the suspended task memory)
        elif epar[r, C.Q_RESTART] != 0.0:  # A gave up: a fresh navigator next step (``self._nav = None``)
            V.vb_new_navigator(vpar, vfst, vist, r)
            eist[r, C.J_NAV_SET] = 0
            eist[r, C.J_NAV_RESTARTS] += 1
        return math.nan, progressing
    return N.py_wrap(h - th), progressing


@njit(cache=True)
def _head_to_k(r, tx, ty, kind, ka, kb, stop_within, end_margin, trust, px, py, th, c, s, ranges, vis, angles,
               max_range, gap, epar, efst, eist, rist, npar, nfst, nist, grid, normals, nav):
    """``_Driving._head_to`` with the key ``(kind, ka, kb)``: (heading relative to the body or NaN
    for none, progressing)."""
    step_m = epar[r, C.Q_STEP]
    dist = N.py_hypot(tx - px, ty - py)
    progressing = True
    best = dist
    if rist[r, R_LAST_KIND] == kind and rist[r, R_LAST_A] == ka and rist[r, R_LAST_B] == kb:
        progressing = dist < efst[r, C.X_LAST_BEST] - epar[r, C.Q_PMF] * step_m
        best = dist if progressing else efst[r, C.X_LAST_BEST]
    rist[r, R_LAST_KIND] = kind
    rist[r, R_LAST_A] = ka
    rist[r, R_LAST_B] = kb
    efst[r, C.X_LAST_BEST] = best
    if dist <= stop_within:
        return math.nan, True
    heading = math.atan2(ty - py, tx - px)
    if epar[r, C.Q_STRAIGHT] != 0.0:
        length = dist - end_margin
        if not (length > step_m):
            length = step_m  # max(step_m, dist - end_margin)
        if C._corridor(r, heading, length, th, ranges, angles, max_range, epar):
            return N.py_wrap(heading - th), progressing
        if epar[r, C.Q_SLIDE] != 0.0 and (trust or C._sees(r, tx, ty, 2.0 * epar[r, C.Q_RADIUS], px, py, c, s, vis,
                                                            angles, gap, epar[r, C.Q_VIS_R])):
            look = epar[r, C.Q_LOOKAHEAD]
            length = look if look < dist - end_margin else dist - end_margin
            if not (length > step_m):
                length = step_m
            side = efst[r, C.X_SLIDE_SIDE]
            for k in range(1, 19):
                for q in range(2):
                    sgn = side if q == 0 else -side
                    h = heading + sgn * ((5.0 * k) * C._DEG)
                    if C._corridor(r, h, length, th, ranges, angles, max_range, epar):
                        efst[r, C.X_SLIDE_SIDE] = sgn
                        eist[r, C.J_SLIDES] += 1
                        return N.py_wrap(h - th), progressing
    temporary = not (kind == KEY_GOAL or kind == KEY_PROMISED)
    d, _ = _navigate_t(r, tx, ty, temporary, px, py, th, ranges, angles, max_range, epar, efst, eist, rist, npar, nfst,
                       nist, grid, normals, nav)
    return d, progressing


@njit(cache=True)
def r1_team_decide_row(r, step, odom, ranges, vis, angles, max_range, gap, sight, epar, efst, eist, rist, rpar,
                       targets, paths, npar, nfst, nist, grid, normals, nav, tf):
    """``LosExplorer._decide`` of row ``r`` without state sharing (see the module docstring), with
    the step's move count and mode count; returns the body-frame direction (NaN: none)."""
    px = odom[r, 0]
    py = odom[r, 1]
    th = odom[r, 2]
    c = math.cos(th)
    s = math.sin(th)
    efst[r, C.X_PX] = px
    efst[r, C.X_PY] = py
    efst[r, C.X_TH] = th
    d = math.nan
    if eist[r, C.J_FINISHED] != 0:
        rist[r, R_MODE] = MODE_GAVE_UP if eist[r, C.J_GAVE_UP] != 0 else MODE_DONE
    else:
        d, progressing = _r1_decide_task(r, step, px, py, th, c, s, ranges, vis, angles, max_range, gap, sight, epar,
                                         efst, eist, rist, rpar, targets, paths, npar, nfst, nist, grid, normals, nav,
                                         tf)
        HC.trouble_update(r, progressing, epar, eist)
        mode = rist[r, R_MODE]
        if mode == MODE_FOLLOW or mode == MODE_GHOST or mode == MODE_TROUBLE:  # _decide: a new point headed for
            kind = rist[r, R_LAST_KIND]  # the key's first two fields: ("path", source) or ("helper", teammate)
            key = rist[r, R_LAST_A] if (kind == KEY_PATH or kind == KEY_HELPER) else -1
            if key != rist[r, R_TEMP_KEY] or (key >= 0 and kind != rist[r, R_TEMP_KIND]):
                rist[r, R_TEMP_SWITCHES] += 1
            rist[r, R_TEMP_KEY] = key
            rist[r, R_TEMP_KIND] = kind
        else:
            rist[r, R_TEMP_KEY] = -1
    if not math.isnan(d):
        eist[r, C.J_MOVES] += 1
    rist[r, R_STEPS + rist[r, R_MODE]] += 1
    return d


@njit(cache=True)
def _r1_decide_task(r, step, px, py, th, c, s, ranges, vis, angles, max_range, gap, sight, epar, efst, eist, rist,
                    rpar, targets, paths, npar, nfst, nist, grid, normals, nav, tf):
    """``LosExplorer._decide_task`` of row ``r`` (without ``trouble_return`` and
    ``trouble_release_to_helper``, which are declined): (direction relative to the body or NaN,
    progressing)."""
    idx = eist[r, C.J_IDX]
    gx = targets[r, idx, 0]
    gy = targets[r, idx, 1]
    step_m = epar[r, C.Q_STEP]
    radius = epar[r, C.Q_RADIUS]
    tol = epar[r, C.Q_TOL]
    me = int(rpar[r, RP_ME])
    kind = GC.KIND_NONE
    if epar[r, C.Q_SHARING] != 0.0:
        kind = int(paths[r, me, GC.P_KIND])
    has_action = False
    d = math.nan
    progressing = True
    if kind == GC.KIND_DIRECT:
        rist[r, R_MODE] = MODE_OWN_GOAL  # §2 point 4: it sees its goal, A is suppressed
        eist[r, C.J_GOAL_SEEN] += 1
        d, progressing = _head_to_k(r, gx, gy, KEY_GOAL, idx, 0, 0.0, 0.5 * tol, False, px, py, th, c, s, ranges,
                                    vis, angles, max_range, gap, epar, efst, eist, rist, npar, nfst, nist, grid,
                                    normals, nav)
        has_action = True
    elif (kind == GC.KIND_GHOST or kind == GC.KIND_SELF) and paths[r, me, GC.P_REACHED] == 0.0:
        qx = paths[r, me, GC.P_PX]
        qy = paths[r, me, GC.P_PY]
        source = int(paths[r, me, GC.P_SOURCE])
        # the mirror itself still stands where it promised (§3), or only its ghost does (§4.2)
        live = False
        if not math.isnan(sight[r, source, 0]):  # _seen_now.get(source)
            rg = sight[r, source, 0]
            b = sight[r, source, 1]
            bx = rg * math.cos(b)
            by = rg * math.sin(b)
            sx = px + c * bx - s * by
            sy = py + s * bx + c * by
            live = N.py_hypot(sx - qx, sy - qy) <= 2.0 * radius + step_m
        if live:
            near = 2.0 * radius + step_m
            reach = near if near > tol else tol  # max(goal_tolerance_m, 2 radii + a step)
        else:
            reach = rpar[r, RP_GHOST_TOL]
        dq = N.py_hypot(qx - px, qy - py)
        via = False
        if dq < reach and rpar[r, RP_SHARE_VIA] != 0.0:
            vd = paths[r, me, GC.P_VD]
            if (rpar[r, RP_VIA_IN_SIGHT] == 0.0 or math.isnan(vd)
                    or C._sees(r, paths[r, me, GC.P_VX], paths[r, me, GC.P_VY], rpar[r, RP_POINT_MARGIN], px, py, c,
                               s, vis, angles, gap, epar[r, C.Q_VIS_R])):
                via = GC.gs_go_via(paths, r, me, step)
        if via:
            # at the teammate's point without seeing the goal: on to where its D leads (share_via)
            rist[r, R_VIAS] += 1
            rist[r, R_MODE] = MODE_GHOST
            d, progressing = _head_to_k(r, paths[r, me, GC.P_PX], paths[r, me, GC.P_PY], KEY_PATH,
                                        int(paths[r, me, GC.P_SOURCE]), int(paths[r, me, GC.P_STEP]), 0.0,
                                        rpar[r, RP_GHOST_TOL], False, px, py, th, c, s, ranges, vis, angles,
                                        max_range, gap, epar, efst, eist, rist, npar, nfst, nist, grid, normals, nav)
            has_action = True
        elif dq < reach:
            # §4.2: at the ghost without seeing the goal: A again, the promise kept to arbitrate
            GC.gs_mark_reached(paths, r, me)
            if rpar[r, RP_RESTART_AT_GHOST] != 0.0 and epar[r, C.Q_VISBUG] != 0.0:
                # restart_navigator_at_ghost: VisBug-21's start_again (the potential field and
                # Avoid-Past have none); on a navigator not yet built (after a give-up), whose
                # compiled row is fresh, it changes nothing, as the reference skips it
                V.vb_start_again(nav[0], nav[1], nav[2], r, rpar[r, RP_REVERSE])
            if (rpar[r, RP_TRUST] != 0.0
                    and paths[r, me, GC.P_D] <= N.py_hypot(gx - qx, gy - qy) + step_m):
                rist[r, R_PROMISED] = idx
        else:
            rist[r, R_MODE] = MODE_FOLLOW if live else MODE_GHOST
            rist[r, R_TEMP_UNREACH] = 0
            d, progressing = _head_to_k(r, qx, qy, KEY_PATH, source, int(paths[r, me, GC.P_STEP]), 0.0, reach, False,
                                        px, py, th, c, s, ranges, vis, angles, max_range, gap, epar, efst, eist, rist,
                                        npar, nfst, nist, grid, normals, nav)
            has_action = True
            if rist[r, R_TEMP_UNREACH] != 0 and rpar[r, RP_DROP_UNREACH] != 0.0:
                # drop_unreachable_ghost: A (VisBug-21) declared the point unreachable; dropped
                # as a reached one, A starts again on R1's own goal (no action this branch)
                rist[r, R_GHOSTS_UNREACH] += 1
                rist[r, R_TEMP_STALL] = 0
                GC.gs_mark_reached(paths, r, me)
                rist[r, R_LAST_KIND] = KEY_NONE
                d = math.nan
                progressing = False
                has_action = False
            # a point R1 makes no progress towards for Cr steps is given up like a reached one
            rist[r, R_TEMP_STALL] = 0 if (progressing or not has_action) else rist[r, R_TEMP_STALL] + 1
            if has_action and rpar[r, RP_DROP_STALLED] != 0.0 and rist[r, R_TEMP_STALL] >= int(epar[r, C.Q_CR]):
                rist[r, R_TEMP_STALL] = 0
                rist[r, R_TEMP_DROPPED] += 1
                GC.gs_mark_reached(paths, r, me)
    # _watch_mates(goal)
    if eist[r, C.J_TR] == 0:
        rist[r, R_TT_ID] = -1
    state = rpar[r, RP_STATE] != 0.0
    rfst, mg_step, mg_d, mg_n, tr, tr_xy, stalled = tf
    if state and rpar[r, RP_TOWARDS] != 0.0:
        _track_mates(r, step, gx, gy, px, py, c, s, sight, rpar, mg_step, mg_d, mg_n)
    goal_d = N.py_hypot(gx - px, gy - py)
    if not has_action and state and eist[r, C.J_TR] != 0:
        d, progressing, has_action = _follow_in_trouble(r, step, px, py, th, c, s, gx, gy, goal_d, progressing,
                                                        ranges, vis, angles, max_range, gap, sight, epar, efst, eist,
                                                        rist, rpar, npar, nfst, nist, grid, normals, nav, tf)
    if not has_action and rist[r, R_PROMISED] == idx and eist[r, C.J_TR] == 0:
        rist[r, R_MODE] = MODE_OWN_GOAL
        rist[r, R_PROMISED_STEPS] += 1
        d, progressing = _head_to_k(r, gx, gy, KEY_PROMISED, idx, 0, 0.0, 0.5 * tol, True, px, py, th, c, s, ranges,
                                    vis, angles, max_range, gap, epar, efst, eist, rist, npar, nfst, nist, grid,
                                    normals, nav)
        has_action = True
    if not has_action:  # _unseen_goal -> _drive: A towards the goal
        rist[r, R_MODE] = MODE_OWN_GOAL
        rist[r, R_LAST_KIND] = KEY_NONE
        d, progressing = _navigate_t(r, gx, gy, False, px, py, th, ranges, angles, max_range, epar, efst, eist, rist,
                                     npar, nfst, nist, grid, normals, nav)
    rfst[r, F_PREV_GOAL_D] = goal_d
    return d, progressing


@njit(cache=True)
def _seen_xy(r, o, px, py, c, s, sight):
    """Where teammate ``o`` is seen now (own frame; the brain's ``_seen_now``), NaN when not seen."""
    if math.isnan(sight[r, o, 0]):
        return math.nan, math.nan
    rg = sight[r, o, 0]
    b = sight[r, o, 1]
    bx = rg * math.cos(b)
    by = rg * math.sin(b)
    return px + c * bx - s * by, py + s * bx + c * by


@njit(cache=True)
def _track_mates(r, step, gx, gy, px, py, c, s, sight, rpar, mg_step, mg_d, mg_n):
    """``_TroubleFollowing._track_mates``: each teammate's straight distance to the goal over the
    last ``trouble_heading_steps`` steps it was seen (oldest first)."""
    keep = step - int(rpar[r, RP_HEADING_STEPS])
    m_slots = sight.shape[1]
    for o in range(m_slots):
        x, y = _seen_xy(r, o, px, py, c, s, sight)
        if not math.isnan(x):
            k = mg_n[r, o]
            mg_step[r, o, k] = step
            mg_d[r, o, k] = N.py_hypot(x - gx, y - gy)
            mg_n[r, o] = k + 1
    for o in range(m_slots):
        k = mg_n[r, o]
        drop = 0
        while drop < k and mg_step[r, o, drop] < keep:
            drop += 1
        if drop > 0:
            for j in range(k - drop):
                mg_step[r, o, j] = mg_step[r, o, j + drop]
                mg_d[r, o, j] = mg_d[r, o, j + drop]
            mg_n[r, o] = k - drop


@njit(cache=True)
def _mate_recedes(r, o, rpar, mg_d, mg_n):
    """``_TroubleFollowing._mate_recedes``: teammate ``o`` went farther from the goal over its kept sightings."""
    k = mg_n[r, o]
    if k < 2:
        return False
    return mg_d[r, o, k - 1] > mg_d[r, o, 0] + 0.1 * rpar[r, RP_RECEDE]


@njit(cache=True)
def _follow_in_trouble(r, step, px, py, th, c, s, gx, gy, goal_d, progressing, ranges, vis, angles, max_range, gap,
                       sight, epar, efst, eist, rist, rpar, npar, nfst, nist, grid, normals, nav, tf):
    """``_TroubleFollowing._follow_in_trouble`` (§5 rule 3 and its gap-fills; ``trouble_return``
    and ``trouble_release_to_helper`` are declined): (direction or NaN, progressing, whether an
    action was chosen)."""
    rfst, mg_step, mg_d, mg_n, tr, tr_xy, stalled = tf
    m_slots = sight.shape[1]
    step_m = epar[r, C.Q_STEP]
    near = 2.0 * epar[r, C.Q_RADIUS] + step_m
    towards_goal = rpar[r, RP_TOWARDS] != 0.0
    keep_helper = rpar[r, RP_KEEP_HELPER] != 0.0
    at_send = rpar[r, RP_AT_SEND] != 0.0
    # seen: seen now, or (trouble_sighting_at_send) seen when it sent the Tr bit that arrived now
    now_x = np.empty(m_slots)
    now_y = np.empty(m_slots)
    seen_x = np.empty(m_slots)
    seen_y = np.empty(m_slots)
    for o in range(m_slots):
        x, y = _seen_xy(r, o, px, py, c, s, sight)
        now_x[o] = x
        now_y[o] = y
        if math.isnan(x) and at_send and not math.isnan(tr_xy[r, o, 0]):
            x = tr_xy[r, o, 0]
            y = tr_xy[r, o, 1]
        seen_x[o] = x
        seen_y[o] = y
    tt = rist[r, R_TT_ID]
    tx = rfst[r, F_TT_X]
    ty = rfst[r, F_TT_Y]
    if tt >= 0 and not math.isnan(now_x[tt]) and towards_goal:
        d_mate = mg_d[r, tt, mg_n[r, tt] - 1]
        if d_mate < rfst[r, F_TT_BEST]:  # min(best, d_mate)
            rfst[r, F_TT_BEST] = d_mate
        if d_mate > rfst[r, F_TT_BEST] + rpar[r, RP_RECEDE]:
            tt = -1  # it turned away from the goal: let it go
            rist[r, R_TT_ID] = -1
    vis_x = now_x if keep_helper else seen_x
    vis_y = now_y if keep_helper else seen_y
    if tt >= 0 and not math.isnan(vis_x[tt]):
        tx = vis_x[tt]
        ty = vis_y[tt]
        rfst[r, F_TT_X] = tx
        rfst[r, F_TT_Y] = ty
    elif tt < 0 or N.py_hypot(tx - px, ty - py) <= near:
        # choose_helper: the nearest candidate not in trouble (ties: the lowest id)
        helper = -1
        best_d = math.inf
        for o in range(m_slots):
            if math.isnan(seen_x[o]) or tr[r, o] != 0.0:  # unknown (-1) or in trouble (1)
                continue
            if towards_goal and _mate_recedes(r, o, rpar, mg_d, mg_n):
                continue
            dd = N.py_hypot(seen_x[o] - px, seen_y[o] - py)
            if dd < best_d:
                helper = o
                best_d = dd
        tt = helper
        rist[r, R_TT_ID] = helper
        rist[r, R_TT_STALL] = 0
        if helper >= 0:
            tx = seen_x[helper]
            ty = seen_y[helper]
            rfst[r, F_TT_X] = tx
            rfst[r, F_TT_Y] = ty
            if towards_goal:
                k = mg_n[r, helper]
                rfst[r, F_TT_BEST] = mg_d[r, helper, k - 1] if k > 0 else N.py_hypot(tx - gx, ty - gy)
    if tt >= 0 and (not math.isnan(vis_x[tt]) or keep_helper):
        rist[r, R_MODE] = MODE_TROUBLE
        d, towards = _head_to_k(r, tx, ty, KEY_HELPER, tt, 0, near, near, False, px, py, th, c, s, ranges, vis, angles,
                                max_range, gap, epar, efst, eist, rist, npar, nfst, nist, grid, normals, nav)
        in_now = not math.isnan(now_x[tt])
        if rpar[r, RP_DROP_HELPER] != 0.0:
            rist[r, R_TT_STALL] = 0 if (towards or in_now) else rist[r, R_TT_STALL] + 1
            if rist[r, R_TT_STALL] >= int(rpar[r, RP_DROP_AFTER]):
                rist[r, R_TT_STALL] = 0
                rist[r, R_HELPERS_DROPPED] += 1
                rist[r, R_TT_ID] = -1
        mode = int(rpar[r, RP_PROGRESS])
        if mode == PROGRESS_HELPER:
            progressing = towards  # Fig. 10: progress towards G_icurr = R_j
        elif mode == PROGRESS_MOVED:
            progressing = not stalled[r]
        else:
            progressing = goal_d < rfst[r, F_PREV_GOAL_D] - epar[r, C.Q_PMF] * step_m
        near_m = rpar[r, RP_NEAR_HELPER]
        if not math.isnan(near_m) and in_now and N.py_hypot(tx - px, ty - py) <= near_m:
            progressing = True
        return d, progressing, True
    return math.nan, progressing, False


def _renew_caches() -> None:
    """This module's kernels call the compiled R1's and helpers', the navigators' and goal
    sharing's: renew their numba caches when one of those changes
    (:func:`~teamnav.control.group.renew_stale_caches`)."""
    from teamnav.control.group import renew_module_caches
    from teamnav.control.nav.local import (
        avoid_past,
        base,
        potential_field,
        visbug21,
        visbug21_geometry,
    )
    from teamnav.papers.los_help.brains import goal_sharing

    renew_module_caches(__name__, (N, V, C, GC, HC, avoid_past, base, potential_field, visbug21, visbug21_geometry,
                                   goal_sharing))


_renew_caches()
