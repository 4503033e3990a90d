"""The line-of-sight team R1..R4 compiled whole: one group brain for the explorer and the helpers
(Sgorbissa & Arkin §2-§6; ``docs/concepts/group-brains.md``).

Both ``los-explorer-v1`` and ``los-helper-v1`` name :class:`LosTeamGroup`, so the engine merges
R1's group and the helpers' groups into one team, stepped in one call. Each row has a role:

- **R1 with teammates, compiled** (:func:`r1_team_advance_row`, :func:`r1_team_decide_row`): the
  explorer's step of :mod:`.explorer` (the readable reference) with goal sharing: its own goal
  when it sees it (§2 point 4); else the point with the shortest D: a teammate that reports now
  (``follow_teammate``, §3 rule 5) or a ghost or its own past viewpoint (``ghost``, §4.2-§4.3),
  reached within ε or ``ghost_tolerance_m``; at the reached point on to the reporter's via point
  (``share_via``, ``via_in_sight``), else the point is kept only to arbitrate (§4.2) and, with
  ``trust_direct_promise``, a promise of the goal itself is followed straight (``promised``); a
  point R1 does not close in on for Cr steps is dropped (``drop_stalled_ghost``); in trouble
  with nothing else leading it, the nearest teammate in sight that is not
  (``trouble_follow``, §5 rule 3, :mod:`.trouble_following`, with its gap-fills
  ``trouble_sighting_at_send``, ``trouble_helper_towards_goal``, ``keep_trouble_helper``,
  ``trouble_drop_stalled_helper``, ``trouble_progress`` and ``trouble_near_helper_m``); else
  algorithm A towards its goal; Pr, Tr, Nt (§5); the broadcast (§4.4). Algorithm A is the
  potential field, Avoid-Past or VisBug-21; with VisBug-21 a teammate, a ghost or a trouble
  helper is a temporary goal (the task goal's Bug2 memory suspended and resumed), VisBug starts
  again at a reached ghost (``restart_navigator_at_ghost``, ``visbug_reverse_walk_factor``), a
  point it finds unreachable is dropped (``drop_unreachable_ghost``), and it is started afresh
  when it gives up on the task goal (``restart_navigator_on_give_up``);
- **a helper** (:mod:`.helper_compiled`'s rows: the patrol, goal sharing, the broadcast);
- **a reference row**: a robot whose parameters the compiled step declines runs its own
  per-robot brain inside this group brain, fed the same observation the engine would give it
  (:func:`row_observation`), so the rest of the team stays compiled.

Goal sharing (:mod:`.goal_sharing_compiled`) runs over every compiled row in one call per phase.
When every robot of the simulation is a compiled row, messages travel as packed rows
(:class:`~.packed.PackedLosMsg`, sized as the :class:`~.messages.LosHelpMsg` they stand for);
else they are the reference's :class:`~.messages.LosHelpMsg`, which per-robot brains read.

What R1's compiled step declines (its row runs the reference instead): VisBug-21's
``turn="random"`` (a draw of the Generator per task goal), the trouble gap-fills
``trouble_return`` and ``trouble_release_to_helper`` (off in both columns), ``frame_source``
other than ``"bearings"`` and ``navigate_past_teammates_beyond_m``. R1 alone (no teammate) is
:class:`~.compiled.LosExplorerGroup`.

Every branch is the reference's, operation for operation, as in :mod:`.compiled`;
``tests/test_team_compiled.py`` runs both side by side and demands the same run.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numba import njit

from teamnav.control.group import GroupAction, GroupObservation
from teamnav.control.nav.local import NAVIGATORS
from teamnav.control.nav.local import compiled as N
from teamnav.control.nav.local import visbug21_compiled as V
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Detection, Message, Observation, RangeScan
from teamnav.papers.los_help.brains import compiled as C
from teamnav.papers.los_help.brains import goal_sharing_compiled as GC
from teamnav.papers.los_help.brains import helper_compiled as HC
from teamnav.papers.los_help.brains.goal_sharing import max_beam_gap
from teamnav.papers.los_help.brains.messages import MESSAGE_KIND, LosHelpMsg, message_size_bytes
from teamnav.papers.los_help.brains.packed import PackedLosMsg, pack, row_sizes, unpack

__all__ = ["LosTeamGroup", "r1_team_unsupported", "row_observation"]

ROLE_R1 = 1
ROLE_HELPER = 2

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


@njit(cache=True)
def team_advance(step, odom, role, epar, eist, rist, hist, patrol, targets, target_steps, own_set, own_k, own_xy,
                 mg_n):
    """Each compiled row's task (R1: its targets; a helper: its patrol) and the ``set_own_goal``
    call it makes."""
    for r in range(odom.shape[0]):
        if role[r] == ROLE_R1:
            r1_team_advance_row(r, step, odom, epar, eist, rist, targets, target_steps, own_set, own_k, own_xy, mg_n)
        else:
            HC.helper_advance_row(r, odom, epar, eist, hist, patrol, own_set, own_k, own_xy)


@njit(cache=True)
def team_decide(step, odom, role, ranges, vis, angles, max_range, gap, sight, epar, efst, eist, rist, rpar, hist,
                patrol, targets, paths, npar, nfst, nist, grid, normals, out_dir, grow, nav, tf):
    """Each compiled row's decision (``out_dir[r]``: the body-frame direction, NaN: none). Returns,
    changing nothing, 1 (grow Avoid-Past's grid: ``grow`` = row, cell i, cell j) or 2 (refill the
    normals), as :func:`~.compiled.r1_alone_step`; else 0."""
    n = odom.shape[0]
    for r in range(n):
        if (hist[r, HC.H_NP] > 0) if role[r] == ROLE_HELPER else (eist[r, C.J_FINISHED] == 0):
            code = HC.nav_needs_room(r, odom[r, 0], odom[r, 1], epar, npar, nist, grid, grow)
            if code != 0:
                return code
    for r in range(n):
        if role[r] == ROLE_R1:
            out_dir[r] = r1_team_decide_row(r, step, odom, ranges, vis, angles, max_range, gap, sight, epar, efst,
                                            eist, rist, rpar, targets, paths, npar, nfst, nist, grid, normals, nav, tf)
        else:
            out_dir[r] = HC.helper_decide_row(r, odom, ranges, vis, angles, max_range, gap, epar, efst, eist, hist,
                                              patrol, npar, nfst, nist, grid, normals, nav)
    return 0


# ----------------------------------------------------------------- what is compiled (Python)
def r1_team_unsupported(p: Any, info: RobotInfo) -> str | None:
    """Why R1 with teammates needs its reference brain (None: :func:`r1_team_decide_row` runs it)."""
    from teamnav.papers.los_help.brains.explorer_params import LosExplorerParams

    if type(p) is not LosExplorerParams:
        return f"params of type {type(p).__name__}"
    if p.navigator not in ("potential_field", "avoid_past", "visbug21"):
        return f"navigator {p.navigator!r} with teammates (compiled: potential_field, avoid_past, visbug21)"
    if p.navigator == "visbug21":
        turn = NAVIGATORS["visbug21"].Params(**dict(p.navigator_params)).turn
        if turn not in V.TURNS:
            return f"VisBug-21 turn {turn!r} (a draw per goal; compiled: {', '.join(V.TURNS)})"
    if p.state_sharing and p.trouble_return:
        return "trouble_return (§5: back to where a teammate was last seen; not compiled)"
    if p.state_sharing and p.trouble_release_to_helper:
        return "trouble_release_to_helper (§5: on to a released teammate's last position; not compiled)"
    if p.frame_source != "bearings":
        return f"frame_source {p.frame_source!r}"
    if p.navigate_past_teammates_beyond_m is not None:
        return "navigate_past_teammates_beyond_m (a second scan for A)"
    if p.laser not in info.sensors:
        return f"no range sensor {p.laser!r}"
    return None


def row_observation(obs: GroupObservation, r: int) -> Observation:
    """Row ``r`` of a group observation as the :class:`~teamnav.control.types.Observation` the
    engine gives a per-robot brain (the same arrays' values, detections with ``None`` for no id)."""
    scans = {name: RangeScan(obs.ranges_m[name][r], obs.angles_rad[name], obs.max_range_m[name])
             for name in obs.ranges_m}
    k = int(obs.det_count[r])
    dets = tuple(Detection(float(obs.det_range_m[r, j]), float(obs.det_bearing_rad[r, j]),
                           None if obs.det_id[r, j] < 0 else int(obs.det_id[r, j])) for j in range(k))
    return Observation(int(obs.robot_ids[r]), int(obs.step), float(obs.time_s), obs.odom_pose[r], obs.odom_delta[r],
                       scans, dets, bool(obs.stalled[r]), obs.inbox[r],
                       obs.events[r] if obs.events is not None else ())


class _R1TeamView:
    """Robot r's face of :class:`LosTeamGroup` (compiled R1 with teammates): what experiments read
    off a :class:`~.explorer.LosExplorer` (``finished``, ``log()``, the counters)."""

    def __init__(self, group: "_Compiled", r: int) -> None:
        self._g = group
        self._r = r
        self.me = int(group.infos[r].robot_id)
        self.params = group.params[r]
        self.targets = [(float(x), float(y)) for x, y in self.params.targets_xy]
        self.msgs_sent = 0
        self.bytes_sent = 0

    def _i(self, col: int) -> int:
        return int(self._g.eist[self._r, col])

    def _q(self, col: int) -> int:
        return int(self._g.rist[self._r, col])

    finished = property(lambda self: bool(self._i(C.J_FINISHED)))
    gave_up = property(lambda self: bool(self._i(C.J_GAVE_UP)))
    target_index = property(lambda self: self._i(C.J_IDX))
    targets_reached = property(lambda self: self._i(C.J_REACHED))
    moves = property(lambda self: self._i(C.J_MOVES))
    goal_seen_steps = property(lambda self: self._i(C.J_GOAL_SEEN))
    slide_steps = property(lambda self: self._i(C.J_SLIDES))
    nav_restarts = property(lambda self: self._i(C.J_NAV_RESTARTS))
    mode = property(lambda self: MODES[self._q(R_MODE)])
    promised_steps = property(lambda self: self._q(R_PROMISED_STEPS))
    temp_switches = property(lambda self: self._q(R_TEMP_SWITCHES))
    temp_dropped = property(lambda self: self._q(R_TEMP_DROPPED))
    vias_taken = property(lambda self: self._q(R_VIAS))
    msgs_received = property(lambda self: int(self._g.gs.gist[self._r, GC.I_MSGS_RECEIVED]))
    target_steps = property(lambda self: [int(v) for v in self._g.target_steps[self._r, :self._i(C.J_REACHED)]])
    trouble_helpers_dropped = property(lambda self: self._q(R_HELPERS_DROPPED))
    ghosts_unreachable = property(lambda self: self._q(R_GHOSTS_UNREACH))

    @property
    def mode_steps(self) -> dict[str, int]:
        return {m: self._q(R_STEPS + k) for k, m in enumerate(MODES) if self._q(R_STEPS + k) > 0}

    def log(self) -> dict[str, Any]:
        """:meth:`~.explorer.LosExplorer.log`, the same keys in the same order."""
        out = HC.common_log(self, self.temp_switches)
        out.update(target_index=self.target_index, targets_reached=self.targets_reached, finished=self.finished,
                   gave_up=self.gave_up, goal_seen_steps=self.goal_seen_steps, promised_steps=self.promised_steps,
                   temp_dropped=self.temp_dropped, ghosts_unreachable=self.ghosts_unreachable,
                   vias_taken=self.vias_taken, trouble_helpers_dropped=self.trouble_helpers_dropped)
        if self.params.log_layers:
            out["layers"] = HC.log_layers(self)
        return out


class _Compiled:
    """The compiled rows of a team (R1 and helpers) as arrays, one row each, in robot order."""

    def __init__(self, params: list, rngs: list, infos: list, roles: list[int], m: int) -> None:
        n = len(params)
        self.params, self.rngs, self.infos = params, rngs, infos
        self.laser = params[0].laser
        self.m = m
        self.role = np.array(roles, dtype=np.int64)
        ids = [int(info.robot_id) for info in infos]
        team_sizes = [int(p.id_gain_k or max(1, info.team_size)) for p, info in zip(params, infos)]
        t_max = max([len(getattr(p, "targets_xy", ())) for p in params] + [1])
        w_max = max([len(getattr(p, "patrol_xy", ())) for p in params] + [1])
        self.targets = np.zeros((n, t_max, 2))
        self.target_steps = np.zeros((n, t_max), dtype=np.int64)
        self.patrol = np.zeros((n, w_max, 2))
        self.epar = np.zeros((n, C.N_Q))
        self.efst = np.zeros((n, C.N_X))
        self.eist = np.zeros((n, C.N_J), dtype=np.int64)
        self.hist = np.zeros((n, HC.N_H), dtype=np.int64)
        self.rpar = np.zeros((n, N_RP))
        self.rist = np.zeros((n, N_R), dtype=np.int64)
        self.rfst = np.zeros((n, N_RF))
        self.rfst[:, F_TT_BEST] = math.inf
        self.rfst[:, F_PREV_GOAL_D] = math.inf
        self.rist[:, R_TT_ID] = -1
        # the teammates' recent distances to the goal (``_mate_goal_d``): at most
        # trouble_heading_steps + 1 kept, one more before the old ones are dropped
        depth = max([int(getattr(p, "trouble_heading_steps", 0)) for p in params] + [0]) + 2
        self.mg_step = np.zeros((n, m, depth), dtype=np.int64)
        self.mg_d = np.zeros((n, m, depth))
        self.mg_n = np.zeros((n, m), dtype=np.int64)
        npar, vpar, vis_r, radius, step = [], [], [], [], []
        for r, (p, info) in enumerate(zip(params, infos)):
            sensor = info.sensors[p.laser]
            step_m, rad = float(info.step_length_m), float(info.radius_m)
            e = self.epar[r]
            e[C.Q_TOL] = p.goal_tolerance_m
            e[C.Q_VIS_R] = float(p.visibility_radius_m or sensor.max_range_m)
            e[C.Q_STEP] = step_m
            e[C.Q_RADIUS] = rad
            e[C.Q_PMF] = p.progress_min_fraction
            e[C.Q_STRAIGHT] = float(p.straight_when_visible)
            e[C.Q_SLIDE] = float(p.slide_when_blocked)
            e[C.Q_LOOKAHEAD] = p.slide_lookahead_m
            e[C.Q_KEEP] = float(p.keep_direct_view)
            e[C.Q_SHARING] = float(p.goal_sharing)
            e[C.Q_RESET_TR] = float(p.reset_trouble_on_target)
            e[C.Q_CR] = float(p.trouble_cr)
            e[C.Q_RESTART] = float(p.restart_navigator_on_give_up)
            self.efst[r, C.X_SLIDE_SIDE] = 1.0
            self.eist[r, C.J_NT_TR] = 1
            q = self.rist[r]
            q[R_ROLE] = roles[r]
            q[R_PROMISED] = -1
            q[R_TEMP_KEY] = -1
            if roles[r] == ROLE_R1:
                e[C.Q_BUDGET] = -1.0 if p.max_steps_per_target is None else float(p.max_steps_per_target)
                if p.targets_xy:
                    self.targets[r, :len(p.targets_xy)] = [(float(x), float(y)) for x, y in p.targets_xy]
                self.eist[r, C.J_NT] = len(p.targets_xy)
                if not p.targets_xy:  # finished at once, mode "done"
                    self.eist[r, C.J_FINISHED] = 1
                    q[R_MODE] = MODE_DONE
                rp = self.rpar[r]
                rp[RP_GHOST_TOL] = p.ghost_tolerance_m
                rp[RP_SHARE_VIA] = float(p.share_via)
                rp[RP_VIA_IN_SIGHT] = float(p.via_in_sight)
                rp[RP_TRUST] = float(p.trust_direct_promise)
                rp[RP_DROP_STALLED] = float(p.drop_stalled_ghost)
                rp[RP_POINT_MARGIN] = 2.5 * rad
                rp[RP_ME] = ids[r]
                rp[RP_STATE] = float(p.state_sharing)
                rp[RP_TOWARDS] = float(p.trouble_helper_towards_goal)
                rp[RP_HEADING_STEPS] = p.trouble_heading_steps
                rp[RP_RECEDE] = p.trouble_recede_m
                rp[RP_AT_SEND] = float(p.trouble_sighting_at_send)
                rp[RP_KEEP_HELPER] = float(p.keep_trouble_helper)
                rp[RP_DROP_HELPER] = float(p.trouble_drop_stalled_helper)
                rp[RP_DROP_AFTER] = p.trouble_drop_after_steps
                rp[RP_PROGRESS] = PROGRESS.index(p.trouble_progress)
                rp[RP_NEAR_HELPER] = math.nan if p.trouble_near_helper_m is None else p.trouble_near_helper_m
                rp[RP_RESTART_AT_GHOST] = float(p.restart_navigator_at_ghost)
                # LosExplorer: the factor only with VisBug-21 (else start_again() without one)
                rp[RP_REVERSE] = (math.nan if p.navigator != "visbug21" or p.visbug_reverse_walk_factor is None
                                  else float(p.visbug_reverse_walk_factor))
                rp[RP_DROP_UNREACH] = float(p.drop_unreachable_ghost)
            else:
                e[C.Q_BUDGET] = -1.0
                if p.patrol_xy:
                    self.patrol[r, :len(p.patrol_xy)] = [(float(x), float(y)) for x, y in p.patrol_xy]
                self.eist[r, C.J_IDX] = 1  # the helper's goal index k
                h = self.hist[r]
                h[HC.H_DIR] = 1
                h[HC.H_NP] = len(p.patrol_xy)
                h[HC.H_CYCLE] = int(p.patrol_mode == "cycle")
                h[HC.H_TIMEOUT] = int(p.waypoint_timeout_steps)
                h[HC.H_MODE] = HC.MODE_PATROL if p.patrol_xy else HC.MODE_STAY
            nav_p = NAVIGATORS[p.navigator].Params(**dict(p.navigator_params))
            if p.navigator == "visbug21":
                e[C.Q_VISBUG] = 1.0
                npar.append(np.zeros(N.N_P))
                vpar.append(V.vb_params(nav_p, step_m, rad))
            else:
                npar.append(N.nav_params(p.navigator, nav_p, step_m, rad))
                vpar.append(np.zeros(V.NV_P))
            vis_r.append(e[C.Q_VIS_R])
            radius.append(rad)
            step.append(step_m)
        self.npar = np.array(npar)
        self.vpar = np.array(vpar)
        self.vfst, self.vist = V.vb_state(self.vpar)
        self.nfst, self.nist, self.grid, self.normals = N.new_state(n)
        self.nist[self.epar[:, C.Q_VISBUG] != 0.0, N.I_NORMAL] = 0
        self.gs = GC.GoalSharingArrays(params, ids, team_sizes, radius, step, vis_r, [0.0] * n, m)
        for r, p in enumerate(params):
            if roles[r] == ROLE_R1 and p.targets_xy:  # LosExplorer._set_goal: set_own_goal(1, targets[0])
                self.gs.set_own_goal(r, 1, self.targets[r, 0])
            elif roles[r] == ROLE_HELPER and p.patrol_xy:  # LosHelper: set_own_goal(1, patrol[0])
                self.gs.set_own_goal(r, 1, self.patrol[r, 0])
        self.ids = np.array(ids, dtype=np.int64)
        self.see_past = np.array([bool(p.see_past_teammates) for p in params])
        self.radius = np.array(radius, dtype=np.float64)
        self.state_sharing = np.array([p.state_sharing for p in params])
        self.gap_for: Any = None
        self.gap = 0.0
        self.dir = np.empty(n)
        self.grow = np.zeros(3, dtype=np.int64)
        self.own_set = np.zeros(n, dtype=np.int64)
        self.own_k = np.zeros(n, dtype=np.int64)
        self.own_xy = np.zeros((n, 2))
        self.n = n
        self.views = [_R1TeamView(self, r) if roles[r] == ROLE_R1 else HC._HelperView(self, r) for r in range(n)]

    def step(self, obs: GroupObservation, in_rows: np.ndarray, senders: np.ndarray, start: np.ndarray):
        """One step of every compiled row; the directions are in ``self.dir``, and the rows that
        send a message this step are returned (their rows in ``self.gs.out``)."""
        angles = obs.angles_rad[self.laser]
        if self.gap_for is not angles:  # as the reference: the beam layout's gap, measured once
            self.a64 = np.ascontiguousarray(angles, dtype=np.float64)
            self.gap_for, self.gap = angles, max_beam_gap(self.a64)
            self.gs.gpar[:, GC.G_GAP] = self.gap
            order, a_sorted = V.beam_order(self.a64)
            self.nav = (self.vpar, self.vfst, self.vist, order, a_sorted)
        ranges = np.ascontiguousarray(obs.ranges_m[self.laser], dtype=np.float64)
        odom = np.ascontiguousarray(obs.odom_pose, dtype=np.float64)
        step = int(obs.step)
        max_range = float(obs.max_range_m[self.laser])
        n, m = self.n, self.m
        sight = np.empty((n, m, 2))
        vis = np.empty_like(ranges)
        GC.team_sightings(self.ids, obs.det_count, obs.det_id, obs.det_range_m, obs.det_bearing_rad, ranges, self.a64,
                          max_range, self.radius, self.see_past, sight, vis)
        team_advance(step, odom, self.role, self.epar, self.eist, self.rist, self.hist, self.patrol, self.targets,
                     self.target_steps, self.own_set, self.own_k, self.own_xy, self.mg_n)
        self.gs.begin_step(step, odom, sight, self.own_set, self.own_k, self.own_xy, in_rows, senders, start, vis,
                           self.a64)
        tf = (self.rfst, self.mg_step, self.mg_d, self.mg_n, self.gs.tr, self.gs.tr_xy,
              np.ascontiguousarray(obs.stalled, dtype=np.bool_))
        while True:
            code = team_decide(step, odom, self.role, ranges, vis, self.a64, max_range, self.gap, sight, self.epar,
                               self.efst, self.eist, self.rist, self.rpar, self.hist, self.patrol, self.targets,
                               self.gs.paths, self.npar, self.nfst, self.nist, self.grid, self.normals, self.dir,
                               self.grow, self.nav, tf)
            if code == 0:
                break
            if code == 1:
                r, ci, cj = (int(v) for v in self.grow)
                self.grid = N.grow_grid(self.grid, self.nist, r, ci, cj)
            else:
                N.refill_normals(self.nist, self.normals, self.rngs)
        trouble = np.where(self.state_sharing, self.eist[:, C.J_TR].astype(np.float64), -1.0)
        return self.gs.end_step(step, odom, sight, trouble)


class LosTeamGroup:
    """R1..R4 of the line-of-sight help system in one group brain (see the module docstring):
    the group brain of ``los-explorer-v1`` and ``los-helper-v1``. Built as the engine builds a
    group brain: one validated Params, Generator and RobotInfo per robot, in robot order."""

    @classmethod
    def _plan(cls, params: Sequence[Any], infos: Sequence[RobotInfo]):
        """(R1 alone, roles per row (0: its reference brain), why nothing is compiled or None)."""
        from teamnav.papers.los_help.brains.explorer_params import LosExplorerParams
        from teamnav.papers.los_help.brains.helper import LosHelperParams

        for p in params:
            if type(p) not in (LosExplorerParams, LosHelperParams):
                return False, [], f"params of type {type(p).__name__}"
        if all(type(p) is LosExplorerParams and int(info.team_size) == 1 for p, info in zip(params, infos)):
            return True, [], C.LosExplorerGroup.unsupported(params, infos)
        helpers = [(p, info) for p, info in zip(params, infos) if type(p) is LosHelperParams]
        helpers_why = (HC.helpers_unsupported([p for p, _ in helpers], [i for _, i in helpers])
                       if helpers else "no helpers")
        roles = []
        for p, info in zip(params, infos):
            if type(p) is LosHelperParams:
                roles.append(ROLE_HELPER if helpers_why is None else 0)
            else:
                why = r1_team_unsupported(p, info) if int(info.team_size) > 1 else "R1 alone among teammates' rows"
                roles.append(ROLE_R1 if why is None else 0)
        compiled = [(p, info) for p, info, role in zip(params, infos, roles) if role]
        if not compiled:
            r1 = [r1_team_unsupported(p, info) for p, info in zip(params, infos) if type(p) is LosExplorerParams]
            return False, roles, "; ".join([w for w in r1 if w] + ([f"helpers: {helpers_why}"] if helpers else []))
        lasers = {(p.laser, info.sensors[p.laser].angles_rad.shape[0]) for p, info in compiled}
        if len(lasers) != 1:
            return False, roles, "robots of one group must read one laser layout"
        return False, roles, None

    @classmethod
    def unsupported(cls, params: Sequence[Any], infos: Sequence[RobotInfo]) -> str | None:
        """Why these robots need their reference brains (None: this group brain runs them, each row
        compiled or, where the compiled step declines it, on its own reference brain inside)."""
        return cls._plan(params, infos)[2]

    def __init__(self, params: Sequence[Any], rngs: Sequence[np.random.Generator], infos: Sequence[RobotInfo]) -> None:
        alone, roles, why = self._plan(params, infos)
        if why is not None:
            raise ValueError(f"LosTeamGroup cannot run these robots: {why}")
        self._alone = C.LosExplorerGroup(params, rngs, infos) if alone else None
        #: robots whose step is compiled (the others run their reference brains inside)
        self.compiled_robots = sum(1 for role in roles if role) if not alone else len(params)
        if alone:
            self.robots = self._alone.robots
            return
        from teamnav.papers.los_help.brains.explorer import LosExplorer
        from teamnav.papers.los_help.brains.explorer_params import LosExplorerParams
        from teamnav.papers.los_help.brains.helper import LosHelper

        n = len(params)
        ids = [int(info.robot_id) for info in infos]
        m = max(max(ids) + 1, max(int(info.team_size) for info in infos), 1)
        self._cidx = [r for r in range(n) if roles[r]]
        self._ridx = [r for r in range(n) if not roles[r]]
        self._part = _Compiled([params[r] for r in self._cidx], [rngs[r] for r in self._cidx],
                               [infos[r] for r in self._cidx], [roles[r] for r in self._cidx], m)
        # reference rows: the per-robot brain itself, built as the engine builds it
        self._ref = {r: (LosExplorer if type(params[r]) is LosExplorerParams else LosHelper)(params[r], rngs[r],
                                                                                             infos[r])
                     for r in self._ridx}
        robots: list = [None] * n
        for k, r in enumerate(self._cidx):
            robots[r] = self._part.views[k]
        for r, brain in self._ref.items():
            robots[r] = brain
        self.robots = robots
        # packed bodies on the radio only when every robot of the run is a compiled row
        self._packed = not self._ridx and all(int(info.team_size) == n for info in infos)
        self._all = not self._ridx
        self._sent: dict[int, tuple[LosHelpMsg, np.ndarray]] = {}
        self._n = n
        self._m = m

    def step_group(self, obs: GroupObservation) -> GroupAction:
        """One step of every robot (see the module docstring)."""
        if self._alone is not None:
            return self._alone.step_group(obs)
        part, n, m = self._part, self._n, self._m
        cidx = self._cidx
        sub = obs if self._all else _rows(obs, cidx)
        # the compiled rows' inbox as packed rows (a body this team sent keeps its row)
        rows, senders, start = [], [], [0]
        sent_rows = self._sent
        for box in sub.inbox:
            for msg in box:
                body = msg.body
                if type(body) is PackedLosMsg:
                    rows.append(body.row)
                    senders.append(int(msg.sender))
                elif isinstance(body, LosHelpMsg):
                    known = sent_rows.get(id(body))
                    rows.append(known[1] if known is not None and known[0] is body else pack(body, m))
                    senders.append(int(msg.sender))
            start.append(len(rows))
        in_rows = np.array(rows).reshape(-1, part.gs.width)
        sent = part.step(sub, in_rows, np.array(senders, dtype=np.int64), np.array(start, dtype=np.int64))
        out_dir = part.dir.copy() if self._all else np.full(n, math.nan)
        if not self._all:
            out_dir[cidx] = part.dir
        outbox = []
        t = float(obs.time_s)
        if not self._packed and len(sent_rows) > 8 * n:  # keep a few steps' bodies (delivered at the next step)
            for key in list(sent_rows)[:len(sent_rows) - 4 * n]:
                del sent_rows[key]
        sent_idx = np.flatnonzero(sent)
        if len(sent_idx):
            out_rows = part.gs.out[sent_idx]  # one fresh copy of this step's rows (each body keeps its own row)
            sizes = row_sizes(part.gs.out, sent_idx).tolist() if self._packed else None
            views = part.views
            for i, k in enumerate(sent_idx.tolist()):
                row = out_rows[i]
                view = views[k]
                if sizes is not None:
                    body = PackedLosMsg(row, sizes[i])  # sized once, as PackedLosMsg.sized
                    size = 24 + sizes[i]  # message_size_bytes: the 24-byte header and the body
                else:
                    body = unpack(row)
                    sent_rows[id(body)] = (body, row)
                    size = message_size_bytes(body)
                outbox.append((view.me, Message(view.me, t, body, kind=MESSAGE_KIND)))
                view.msgs_sent += 1
                view.bytes_sent += size
        for r, brain in self._ref.items():  # the reference rows, on their own brains
            # the class's own step: not an attribute set on the instance (a benchmark's timer
            # wraps the brains it finds in Simulation.brains; this call is inside step_group)
            action, msgs = type(brain).step(brain, row_observation(obs, r))
            out_dir[r] = math.nan if action.direction_rad is None else action.direction_rad
            rid = int(obs.robot_ids[r])
            outbox.extend((rid, msg) for msg in msgs)
        if self._ref:
            outbox.sort(key=lambda item: item[0])  # robot order (stable: a robot's own messages keep theirs)
        return GroupAction(np.zeros(n), np.zeros(n), out_dir, outbox)


def _rows(obs: GroupObservation, idx: list[int]) -> GroupObservation:
    """The rows ``idx`` of a group observation (fresh arrays)."""
    ix = np.array(idx, dtype=np.int64)
    return GroupObservation(obs.robot_ids[ix], obs.step, obs.time_s, obs.odom_pose[ix], obs.odom_delta[ix],
                            obs.stalled[ix], {k: v[ix] for k, v in obs.ranges_m.items()}, obs.angles_rad,
                            obs.max_range_m, obs.det_count[ix], obs.det_id[ix], obs.det_range_m[ix],
                            obs.det_bearing_rad[ix], tuple(obs.inbox[r] for r in idx),
                            tuple(obs.events[r] for r in idx) if obs.events is not None else None)


def _renew_caches() -> None:
    """This module's kernels call the compiled R1's and helpers', the navigators' and goal
    sharing's: renew their numba caches when one of those changes
    (:func:`~teamnav.control.group.renew_stale_caches`)."""
    import sys

    from teamnav.control.group import renew_stale_caches
    from teamnav.control.nav.local import avoid_past, base, potential_field, visbug21, visbug21_geometry
    from teamnav.papers.los_help.brains import goal_sharing

    here = sys.modules[__name__]
    kernels = [f for f in vars(here).values() if hasattr(f, "_cache") and hasattr(f, "py_func")
               and f.py_func.__module__ == __name__]
    renew_stale_caches(kernels, [m.__file__ for m in (N, V, C, GC, HC, avoid_past, base, potential_field, visbug21,
                                                      visbug21_geometry, goal_sharing)])


_renew_caches()
