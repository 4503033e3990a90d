"""Goal sharing of the line-of-sight help system compiled for a whole team: the receive path
(the 4-step history, frames from mutual bearings), the Id rule, D arbitration, ghosts, the §4.3
bookkeeping and the outgoing message, for every robot of a group in one numba call
(Sgorbissa & Arkin §3-§4; ``docs/concepts/group-brains.md``, "Next: goal sharing").

The readable reference is :class:`~.goal_sharing.GoalSharing` with the receive path and the
broadcast of :class:`~.brain._LosBrain` (``_receive``, ``_bearing_frame``, ``_broadcast``). This
module does the same operations in the same order on arrays, with Python's float arithmetic
written out where the reference computes in Python
(:func:`~teamnav.control.nav.local.compiled.py_hypot`) and the reference's own numba kernels
where it calls them (``nearest_beam_visible``, ``beam_near_reaches``, through the compiled R1's
``_sees`` / ``_keeps``). ``tests/test_goal_sharing_compiled.py`` replays what the reference's
brains received in 4-robot runs (both of the report's columns) and demands the same bits.

One step of a brain, in the reference's order, and where it is here:

1. remember the pose and the sightings of this step (a message sent at step k arrives at
   k + 1 and is paired with the receiver's own sighting of the sender *at k*; four steps kept,
   §3.1): :func:`gs_begin_step`;
2. reflected visibility only (``delayed_visibility`` false, §3): forget every non-direct point:
   :func:`gs_begin_step`;
3. the robot's own task sets its goal k (``set_own_goal``; a new k forgets the old path):
   :func:`gs_begin_step`, from the ``own_set`` / ``own_k`` / ``own_xy`` columns;
4. the inbox: each sender's Tr bit (§5) and, when the robot saw the sender at the sending
   step, where it stood then (the brain's ``_teammate_tr`` / ``_teammate_tr_xy``, which §5's
   trouble following reads); for each message of a sender seen at the sending step that carries the sender's
   bearing of the receiver, the sender's frame from the mutual bearings (§3.1, θ21 = 180° + α21
   − α12), the goals mapped to the receiver's own frame and the Id rule (§3.1, §4.1: accept
   an Id ≥ the stored one; a new goal index forgets the path), then the reports arbitrated by
   the shortest D (§4.2, with the gap-fills ``report_margin`` and ``lead_on`` of the reference):
   :func:`gs_begin_step`;
5. visibility of every known goal (§2 point 4, rule 3 of §3) and the §4.3 bookkeeping (a point
   that leaves the view is replaced by the robot's own previous position and its distance to
   the goal): :func:`gs_begin_step`;
6. the brain decides; what it changes in goal sharing is :func:`gs_mark_reached` and
   :func:`gs_go_via` (the explorer, at a reached ghost);
7. the outgoing message as a packed row (:mod:`.packed`): the sightings, the own goal with
   ``Id = k·M`` and the relayed ones with ``Id − 1`` (§3.1), and for every other robot's goal
   it sees its D (§3 rule 3, §4.2; with ``share_via`` the point the D leads through), the Tr bit
   of §5 as given; and the position of this step kept as the next step's "previous" one:
   :func:`gs_end_step`.

State, one row per robot (named columns, as the compiled R1):

- ``gpar`` (n, N_G) parameters ``G_*``; ``gist`` (n, N_I) integers ``I_*`` (own goal index,
  counters); ``gfst`` (n, N_F) floats ``F_*`` (own goal, previous position);
- ``known`` (n, M, 3): owner's (Id, x, y) in the row's own frame, Id NaN when unknown; the
  order of first report (the reference's dict order, which its broadcast follows) in
  ``kord`` (n, M) with ``I_N_KNOWN`` entries;
- ``paths`` (n, M, N_P): the stored path to each owner's goal, columns ``P_*`` (kind 0: none);
  ``P_SEQ`` numbers insertions, so that the outgoing reports keep the reference's dict order;
- ``hist_step`` (n, 4), ``hist_pose`` (n, 4, 3), ``hist_sight`` (n, 4, M, 2): the ring of the last
  four steps' poses and sightings (range, bearing; NaN: not seen), slot ``step % 4``;
- ``tr`` (n, M), ``tr_xy`` (n, M, 2) with their arrival orders ``tr_ord`` / ``tr_xy_ord``: the Tr
  bits of this step's inbox (see :func:`gs_begin_step`).

``M`` is the number of owner slots: robot ids must be below it. ``G_IDM`` is the M of
``Id = k·M`` (the brains' ``team_size``), which may differ from the slots.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numba import njit

from teamnav.control.nav.local import compiled as N
from teamnav.papers.los_help.brains import packed as PK
from teamnav.papers.los_help.brains.compiled import _keeps, _sees
from teamnav.papers.los_help.brains.goal_sharing import see_past_teammates

__all__ = ["HISTORY_STEPS", "GoalSharingArrays", "gs_begin_step", "gs_end_step", "gs_go_via", "gs_mark_reached",
           "path_columns", "team_sightings"]

#: Steps of own pose and sightings kept to pair delayed messages with (``brain._HISTORY_STEPS``).
HISTORY_STEPS = 4

# ----------------------------------------------------------------- parameter columns (gpar)
G_ME = 0  # the row's robot id
G_IDM = 1  # M of Id = k·M (team_size)
G_SHARING = 2  # goal_sharing
G_DELAYED = 3  # delayed_visibility (V_D with ghosts, §4); 0: reflected only (§3)
G_POINT_MARGIN = 4  # point_margin_m (2.5 radii)
G_REPORT_MARGIN = 5  # report_margin_steps · step length [m]
G_LEAD_ON = 6  # lead_on
G_RELAY_LIMIT = 7  # relay_hop_limit
G_SHARE_VIA = 8  # share_via
G_KEEP = 9  # keep_direct_view
G_STATE_SHARING = 10  # state_sharing (a message is sent with Tr even without goal sharing)
G_VIS_R = 11  # visibility radius [m]
G_GAP = 12  # largest gap between beams [rad] (max_beam_gap)
N_G = 13

# ----------------------------------------------------------------- integer state (gist)
I_OWN_K = 0  # own goal index k (-1: none)
I_N_KNOWN = 1  # entries of kord
I_SEQ = 2  # next insertion number of paths
I_HAS_PREV = 3  # a previous position exists
I_MSGS_RECEIVED = 4  # LosHelpMsg messages from others read (the brain's msgs_received)
I_N_TR = 5  # entries of tr_ord: teammates whose Tr bit arrived this step
I_N_TR_XY = 6  # entries of tr_xy_ord: those of them seen at the sending step
N_I = 7

# ----------------------------------------------------------------- float state (gfst)
F_OWN_GX = 0
F_OWN_GY = 1
F_PREV_X = 2  # the position of the previous step (own frame)
F_PREV_Y = 3
N_F = 4

# ----------------------------------------------------------------- path columns (paths[r, owner])
P_KIND = 0  # KIND_*
P_GID = 1
P_PX = 2  # the point (own frame)
P_PY = 3
P_D = 4  # d_point_m: promised path length from the point to the goal
P_SOURCE = 5
P_STEP = 6
P_REACHED = 7
P_PROMISED = 8  # d_promised_m (inf: none)
P_VX = 9  # via point and its distance (NaN: None)
P_VY = 10
P_VD = 11
P_SEQ = 12
N_P = 13

KIND_NONE = 0
KIND_DIRECT = 1
KIND_SELF = 2
KIND_GHOST = 3
KINDS = (None, "direct", "self", "ghost")


# ----------------------------------------------------------------- sensing: sightings and the visibility scan
@njit(cache=True)
def team_sightings(ids, det_count, det_id, det_range, det_bearing, ranges, angles, max_range, radius, see_past, sight,
                   vis):
    """The first lines of ``_LosBrain.step`` for every row: this step's sightings by robot id
    (``sight`` (n, M, 2): range, bearing; NaN: not seen) from the detection arrays (identities
    only, not itself; a later detection of a robot replaces an earlier one, as the brain's
    dict), and ``vis`` (n, B), the scan of the visibility tests: ``ranges`` with the beams that
    end on a detected teammate filled in (``see_past_teammates``, where ``see_past[r]``).
    Returns the number of sightings per row."""
    n = ranges.shape[0]
    m_slots = sight.shape[1]
    counts = np.zeros(n, dtype=np.int64)
    dr = np.empty(m_slots)
    db = np.empty(m_slots)
    for r in range(n):
        for o in range(m_slots):
            sight[r, o, 0] = math.nan
            sight[r, o, 1] = math.nan
        for j in range(det_count[r]):
            rid = det_id[r, j]
            if rid < 0 or rid == ids[r]:
                continue
            sight[r, rid, 0] = det_range[r, j]
            sight[r, rid, 1] = det_bearing[r, j]
        k = 0
        for o in range(m_slots):
            if not math.isnan(sight[r, o, 0]):
                dr[k] = sight[r, o, 0]
                db[k] = sight[r, o, 1]
                k += 1
        counts[r] = k
        if k > 0 and see_past[r]:
            # the masks of the detections are united, so their order does not matter
            vis[r] = see_past_teammates(ranges[r], angles, max_range, dr[:k], db[:k], radius[r])
        else:
            vis[r] = ranges[r]
    return counts


# ----------------------------------------------------------------- paths: insert, delete
@njit(cache=True)
def _put_path(paths, gist, r, o, gid, px, py, d, kind, source, step, reached, promised, vx, vy, vd):
    """``paths[o] = GoalPath(...)``: a new key is inserted last (dict order), an old one keeps its place."""
    if paths[r, o, P_KIND] == KIND_NONE:
        paths[r, o, P_SEQ] = gist[r, I_SEQ]
        gist[r, I_SEQ] += 1
    paths[r, o, P_KIND] = kind
    paths[r, o, P_GID] = gid
    paths[r, o, P_PX] = px
    paths[r, o, P_PY] = py
    paths[r, o, P_D] = d
    paths[r, o, P_SOURCE] = source
    paths[r, o, P_STEP] = step
    paths[r, o, P_REACHED] = reached
    paths[r, o, P_PROMISED] = promised
    paths[r, o, P_VX] = vx
    paths[r, o, P_VY] = vy
    paths[r, o, P_VD] = vd


@njit(cache=True)
def _pop_path(paths, r, o):
    paths[r, o, P_KIND] = KIND_NONE


# ----------------------------------------------------------------- the rules (§3.1, §4.1-§4.3)
@njit(cache=True)
def _receive_goal(gpar, gist, known, kord, paths, r, owner, gid, gx, gy):
    """``GoalSharing.receive_goal``: store ``owner``'s goal if ``gid`` ≥ the stored Id (§3.1,
    §4.1); a new goal index forgets the old path. Returns whether it was accepted."""
    me = int(gpar[r, G_ME])
    if owner == me:
        return False
    og_f = known[r, owner, 0]
    if not math.isnan(og_f):  # known
        og = int(og_f)
        if not gid >= og:
            return False
        m = int(gpar[r, G_IDM])
        if (og - 1) // m != (gid - 1) // m:
            _pop_path(paths, r, owner)
    else:
        kord[r, gist[r, I_N_KNOWN]] = owner
        gist[r, I_N_KNOWN] += 1
    known[r, owner, 0] = gid
    known[r, owner, 1] = gx
    known[r, owner, 2] = gy
    return True


@njit(cache=True)
def _receive_report(gpar, gist, known, paths, r, owner, gid, reporter, rx, ry, d_m, mx, my, step, vx, vy, vd):
    """``GoalSharing.receive_report``: arbitrate a visibility report by the shortest D (§4.2).

    ``vd`` NaN: no via point (the reference's None)."""
    if not (math.isfinite(d_m) and d_m >= 0.0):
        return False
    me = int(gpar[r, G_ME])
    if owner == me:
        k = gist[r, I_OWN_K]
        if k < 0:
            return False
        stored_id = k * int(gpar[r, G_IDM])
    else:
        g = known[r, owner, 0]
        if math.isnan(g):
            return False
        stored_id = int(g)
    m = int(gpar[r, G_IDM])
    if (stored_id - 1) // m != (gid - 1) // m:
        return False
    cand = N.py_hypot(rx - mx, ry - my) + d_m
    kind = paths[r, owner, P_KIND]
    if kind != KIND_NONE:
        if kind == KIND_DIRECT:
            return False
        ppx = paths[r, owner, P_PX]
        ppy = paths[r, owner, P_PY]
        now = N.py_hypot(ppx - mx, ppy - my) + paths[r, owner, P_D]
        margin = gpar[r, G_REPORT_MARGIN]
        if owner == me and paths[r, owner, P_REACHED] != 0.0 and gpar[r, G_LEAD_ON] != 0.0:
            if cand > now + margin or N.py_hypot(rx - ppx, ry - ppy) <= margin:
                return False
        else:
            if owner == me:
                promised = paths[r, owner, P_PROMISED]
                ref = promised if promised < now else now  # Python's min(now, promised)
            else:
                ref = now
            if cand >= ref - margin:
                return False
    if not math.isfinite(vd):  # the reference keeps a via point only with a finite distance
        vx = math.nan
        vy = math.nan
        vd = math.nan
    _put_path(paths, gist, r, owner, stored_id, rx, ry, d_m, KIND_GHOST, reporter, step, 0.0, cand, vx, vy, vd)
    return True


@njit(cache=True)
def _sender_frame(b_sender_in_me, b_me_in_sender, distance):
    """:func:`~.goal_sharing.sender_frame`: the sender's body frame in the receiver's (§3.1)."""
    theta = math.pi + b_sender_in_me - b_me_in_sender
    theta = math.atan2(math.sin(theta), math.cos(theta))
    if theta <= -math.pi:
        theta = math.pi
    return distance * math.cos(b_sender_in_me), distance * math.sin(b_sender_in_me), theta


@njit(cache=True)
def _receive(r, gpar, gist, known, kord, paths, hist_step, hist_pose, hist_sight, in_rows, in_sender, lo, hi,
             m_slots, tr, tr_ord, tr_xy, tr_xy_ord):
    """``_LosBrain._receive`` for row ``r``: messages ``lo:hi`` of the inbox; the teammates' Tr
    bits (§5) and where each stood when it sent it, then goal sharing (§3.1, §4)."""
    me = int(gpar[r, G_ME])
    sharing = gpar[r, G_SHARING] != 0.0
    at_s = PK.N_HEADER
    at_g = PK.N_HEADER + PK.SIGHT_W * m_slots
    at_r = PK.N_HEADER + (PK.SIGHT_W + PK.GOAL_W) * m_slots
    for o in range(m_slots):  # the brain's _teammate_tr and _teammate_tr_xy start empty each step
        tr[r, o] = -1.0
        tr_xy[r, o, 0] = math.nan
        tr_xy[r, o, 1] = math.nan
    gist[r, I_N_TR] = 0
    gist[r, I_N_TR_XY] = 0
    for i in range(lo, hi):
        s = in_sender[i]
        if s == me:
            continue
        gist[r, I_MSGS_RECEIVED] += 1
        row = in_rows[i]
        step_k = int(row[PK.H_STEP])
        slot = step_k % HISTORY_STEPS
        in_hist = hist_step[r, slot] == step_k
        bit = row[PK.H_TROUBLE]
        if bit >= 0.0:  # the sender shares its state (§5)
            if tr[r, s] < 0.0:
                tr_ord[r, gist[r, I_N_TR]] = s
                gist[r, I_N_TR] += 1
            tr[r, s] = bit
            if in_hist and not math.isnan(hist_sight[r, slot, s, 0]):
                rng_s = hist_sight[r, slot, s, 0]
                b_s = hist_sight[r, slot, s, 1]
                bx = rng_s * math.cos(b_s)
                by = rng_s * math.sin(b_s)
                c0 = math.cos(hist_pose[r, slot, 2])
                s0 = math.sin(hist_pose[r, slot, 2])
                if math.isnan(tr_xy[r, s, 0]):
                    tr_xy_ord[r, gist[r, I_N_TR_XY]] = s
                    gist[r, I_N_TR_XY] += 1
                tr_xy[r, s, 0] = hist_pose[r, slot, 0] + c0 * bx - s0 * by  # _body_to_odom
                tr_xy[r, s, 1] = hist_pose[r, slot, 1] + s0 * bx + c0 * by
        if not sharing:
            continue
        if not in_hist:
            continue  # no pose of mine at the sending step
        rng_m = hist_sight[r, slot, s, 0]
        if math.isnan(rng_m):
            continue  # I did not see the sender then
        back = -1
        for j in range(int(row[PK.H_N_SIGHT])):
            if int(row[at_s + PK.SIGHT_W * j]) == me:
                back = j
                break
        if back < 0:
            continue  # it did not see me
        r0, r1, rth = _sender_frame(hist_sight[r, slot, s, 1], row[at_s + PK.SIGHT_W * back + 1], rng_m)
        kx = hist_pose[r, slot, 0]
        ky = hist_pose[r, slot, 1]
        kth = hist_pose[r, slot, 2]
        ck = math.cos(kth)
        sk = math.sin(kth)
        sx = kx + ck * r0 - sk * r1
        sy = ky + sk * r0 + ck * r1
        c = math.cos(rth)
        sn = math.sin(rth)
        for j in range(int(row[PK.H_N_GOAL])):
            e = at_g + PK.GOAL_W * j
            owner = int(row[e])
            if owner == me:
                continue
            gx = row[e + 2]
            gy = row[e + 3]
            bx = r0 + c * gx - sn * gy
            by = r1 + sn * gx + c * gy
            _receive_goal(gpar, gist, known, kord, paths, r, owner, int(row[e + 1]), kx + ck * bx - sk * by,
                          ky + sk * bx + ck * by)
        for j in range(int(row[PK.H_N_REPORT])):
            e = at_r + PK.REPORT_W * j
            vd = row[e + 5]
            vx = math.nan
            vy = math.nan
            if not math.isnan(vd):
                ux = row[e + 3]
                uy = row[e + 4]
                bx = r0 + c * ux - sn * uy
                by = r1 + sn * ux + c * uy
                vx = kx + ck * bx - sk * by
                vy = ky + sk * bx + ck * by
            _receive_report(gpar, gist, known, paths, r, int(row[e]), int(row[e + 1]), s, sx, sy, row[e + 2], kx, ky,
                            step_k, vx, vy, vd)


@njit(cache=True)
def _refresh(r, step, px, py, c, s, vis, angles, gpar, gist, gfst, known, kord, paths):
    """``GoalSharing.refresh``: visibility of every known goal (rule 3, §2 point 4) and the §4.3
    bookkeeping, with the brain's ``_sees`` (and ``_keeps`` with ``keep_direct_view``)."""
    me = int(gpar[r, G_ME])
    gap = gpar[r, G_GAP]
    vis_r = gpar[r, G_VIS_R]
    keep = gpar[r, G_KEEP] != 0.0
    delayed = gpar[r, G_DELAYED] != 0.0
    has_prev = gist[r, I_HAS_PREV] != 0
    k_own = gist[r, I_OWN_K]
    idm = int(gpar[r, G_IDM])
    n_goals = gist[r, I_N_KNOWN] + (1 if k_own >= 0 else 0)
    for j in range(n_goals):
        if k_own >= 0 and j == 0:
            owner = me
            gid = k_own * idm
            gx = gfst[r, F_OWN_GX]
            gy = gfst[r, F_OWN_GY]
        else:
            owner = kord[r, j - 1 if k_own >= 0 else j]
            gid = int(known[r, owner, 0])
            gx = known[r, owner, 1]
            gy = known[r, owner, 2]
        kind = paths[r, owner, P_KIND]
        kept = (keep and kind == KIND_DIRECT and paths[r, owner, P_PX] == gx and paths[r, owner, P_PY] == gy
                and _keeps(r, gx, gy, px, py, c, s, vis, angles, gap, vis_r))
        if kept or _sees(r, gx, gy, 0.0, px, py, c, s, vis, angles, gap, vis_r):
            _put_path(paths, gist, r, owner, gid, gx, gy, 0.0, KIND_DIRECT, me, step, 0.0, math.inf, math.nan,
                      math.nan, math.nan)
            continue
        if kind == KIND_NONE:
            continue
        if owner == me:
            if kind == KIND_DIRECT:  # the owner lost its view: back to its navigator
                _pop_path(paths, r, owner)
            continue
        if not delayed:
            if kind == KIND_DIRECT:
                _pop_path(paths, r, owner)
            continue
        if has_prev and (kind == KIND_DIRECT or not _sees(r, paths[r, owner, P_PX], paths[r, owner, P_PY],
                                                           gpar[r, G_POINT_MARGIN], px, py, c, s, vis, angles,
                                                           gap, vis_r)):
            # §4.3: the point left the view: the last own position from which it was visible
            qx = gfst[r, F_PREV_X]
            qy = gfst[r, F_PREV_Y]
            d_prev = N.py_hypot(paths[r, owner, P_PX] - qx, paths[r, owner, P_PY] - qy) + paths[r, owner, P_D]
            _put_path(paths, gist, r, owner, paths[r, owner, P_GID], qx, qy, d_prev, KIND_SELF, me, step,
                      paths[r, owner, P_REACHED], paths[r, owner, P_PROMISED], paths[r, owner, P_VX],
                      paths[r, owner, P_VY], paths[r, owner, P_VD])


@njit(cache=True)
def gs_begin_step(step, pose, sight, own_set, own_k, own_xy, in_rows, in_sender, in_start, vis, angles, gpar, gist,
                  gfst, known, kord, paths, hist_step, hist_pose, hist_sight, tr, tr_ord, tr_xy, tr_xy_ord):
    """Steps 1-5 of the module docstring for every row: the history ring, ``begin_step``, the own
    goal, the inbox, ``refresh``.

    Parameters
    ----------
    step : int
    pose : (n, 3) float64
        Each robot's odometry pose of this step (own frame).
    sight : (n, M, 2) float64
        This step's sightings by robot id: (range, bearing) in the body frame, NaN when not seen.
    own_set : (n,) int64
        1 where the robot's task set its goal this step (``set_own_goal``), with ``own_k``
        (-1: none) and ``own_xy`` (n, 2).
    in_rows, in_sender, in_start : (k, W) float64, (k,) int64, (n + 1,) int64
        The inbox: packed rows (:mod:`.packed`, ``row_width(M)``) of the messages delivered to
        row r, with their senders, are ``in_start[r]:in_start[r + 1]``, in delivery order.
    vis : (n, B) float64
        Each robot's scan for visibility tests (the brain's ``_vis_r64``).
    angles : (B,) float64
        The beam angles.
    tr, tr_ord, tr_xy, tr_xy_ord : (n, M), (n, M), (n, M, 2), (n, M)
        Written: the Tr bits (§5) that arrived this step by sender (-1: none) and the order
        they arrived in (``I_N_TR`` entries), and where each sender stood (own frame) when it
        sent, from the robot's own sighting of it then (NaN: not seen; ``I_N_TR_XY`` entries
        in order): the brain's ``_teammate_tr`` and ``_teammate_tr_xy``.
    """
    n = pose.shape[0]
    m_slots = known.shape[1]
    for r in range(n):
        px = pose[r, 0]
        py = pose[r, 1]
        th = pose[r, 2]
        slot = step % HISTORY_STEPS
        hist_step[r, slot] = step
        hist_pose[r, slot, 0] = px
        hist_pose[r, slot, 1] = py
        hist_pose[r, slot, 2] = th
        for o in range(m_slots):
            hist_sight[r, slot, o, 0] = sight[r, o, 0]
            hist_sight[r, slot, o, 1] = sight[r, o, 1]
        sharing = gpar[r, G_SHARING] != 0.0
        if sharing and gpar[r, G_DELAYED] == 0.0:  # begin_step: reflected visibility only (§3)
            for o in range(m_slots):
                if paths[r, o, P_KIND] != KIND_DIRECT:
                    _pop_path(paths, r, o)
        if own_set[r] != 0:  # set_own_goal
            me = int(gpar[r, G_ME])
            if own_k[r] < 0:
                gist[r, I_OWN_K] = -1
                _pop_path(paths, r, me)
            else:
                if own_k[r] != gist[r, I_OWN_K]:
                    _pop_path(paths, r, me)
                gist[r, I_OWN_K] = own_k[r]
                gfst[r, F_OWN_GX] = own_xy[r, 0]
                gfst[r, F_OWN_GY] = own_xy[r, 1]
        _receive(r, gpar, gist, known, kord, paths, hist_step, hist_pose, hist_sight, in_rows, in_sender,
                 in_start[r], in_start[r + 1], m_slots, tr, tr_ord, tr_xy, tr_xy_ord)
        if sharing:
            _refresh(r, step, px, py, math.cos(th), math.sin(th), vis, angles, gpar, gist, gfst, known, kord, paths)


@njit(cache=True)
def gs_mark_reached(paths, r, owner):
    """``GoalSharing.mark_reached``: the owner reached its path's point without seeing the goal
    (§4.2: kept only to arbitrate later reports)."""
    if paths[r, owner, P_KIND] != KIND_NONE:
        paths[r, owner, P_REACHED] = 1.0


@njit(cache=True)
def gs_go_via(paths, r, owner, step):
    """``GoalSharing.go_via``: at the reached point, on to the reporter's via point (``share_via``);
    False (nothing changed) without one."""
    if paths[r, owner, P_KIND] == KIND_NONE or math.isnan(paths[r, owner, P_VD]):
        return False
    paths[r, owner, P_PX] = paths[r, owner, P_VX]
    paths[r, owner, P_PY] = paths[r, owner, P_VY]
    paths[r, owner, P_D] = paths[r, owner, P_VD]
    paths[r, owner, P_REACHED] = 0.0
    paths[r, owner, P_STEP] = step
    paths[r, owner, P_VX] = math.nan
    paths[r, owner, P_VY] = math.nan
    paths[r, owner, P_VD] = math.nan
    return True


@njit(cache=True)
def _path_order(paths, r, out):
    """Owners with a stored path, in insertion order (the reference's dict order); returns the count."""
    m_slots = paths.shape[1]
    n = 0
    for o in range(m_slots):
        if paths[r, o, P_KIND] == KIND_NONE:
            continue
        seq = paths[r, o, P_SEQ]
        j = n
        while j > 0 and paths[r, out[j - 1], P_SEQ] > seq:
            out[j] = out[j - 1]
            j -= 1
        out[j] = o
        n += 1
    return n


@njit(cache=True)
def gs_end_step(step, pose, sight, trouble, gpar, gist, gfst, known, kord, paths, out):
    """Step 7 of the module docstring for every row: the outgoing message (``_broadcast``, §4.4)
    as a packed row ``out[r]`` (NaN where unused), and this step's position kept as the previous
    one. Returns (n,) 1 where a message is sent (the robot sees a teammate and shares goals or
    state), else 0.

    ``trouble`` (n,): the Tr bit of §5 (0 / 1; -1: state not shared).
    """
    n = pose.shape[0]
    m_slots = known.shape[1]
    sent = np.zeros(n, dtype=np.int64)
    order = np.empty(m_slots, dtype=np.int64)
    at_s = PK.N_HEADER
    at_g = PK.N_HEADER + PK.SIGHT_W * m_slots
    at_r = PK.N_HEADER + (PK.SIGHT_W + PK.GOAL_W) * m_slots
    for r in range(n):
        px = pose[r, 0]
        py = pose[r, 1]
        n_sight = 0
        for o in range(m_slots):
            if not math.isnan(sight[r, o, 0]):
                n_sight += 1
        sharing = gpar[r, G_SHARING] != 0.0
        if n_sight > 0 and (sharing or gpar[r, G_STATE_SHARING] != 0.0):
            sent[r] = 1
            row = out[r]
            row[:] = math.nan
            row[PK.H_STEP] = step
            row[PK.H_TROUBLE] = trouble[r]
            row[PK.H_N_SIGHT] = 0.0
            row[PK.H_N_GOAL] = 0.0
            row[PK.H_N_REPORT] = 0.0
            if sharing:
                th = pose[r, 2]
                c = math.cos(th)
                s = math.sin(th)
                j = 0
                for o in range(m_slots):  # sorted by robot id
                    if not math.isnan(sight[r, o, 0]):
                        e = at_s + PK.SIGHT_W * j
                        row[e] = o
                        row[e + 1] = sight[r, o, 1]
                        row[e + 2] = sight[r, o, 0]
                        j += 1
                row[PK.H_N_SIGHT] = j
                # shares(): own goal with k·M, the known ones in order with Id − 1 (§3.1)
                me = int(gpar[r, G_ME])
                idm = int(gpar[r, G_IDM])
                limit = gpar[r, G_RELAY_LIMIT] != 0.0
                j = 0
                if gist[r, I_OWN_K] >= 0:
                    x = gfst[r, F_OWN_GX]
                    y = gfst[r, F_OWN_GY]
                    e = at_g + PK.GOAL_W * j
                    row[e] = me
                    row[e + 1] = gist[r, I_OWN_K] * idm
                    row[e + 2] = c * (x - px) + s * (y - py)
                    row[e + 3] = -s * (x - px) + c * (y - py)
                    j += 1
                for q in range(gist[r, I_N_KNOWN]):
                    o = kord[r, q]
                    gid = int(known[r, o, 0])
                    ok = (gid - ((gid - 1) // idm) * idm > 1) if limit else gid > 1
                    if ok:
                        x = known[r, o, 1]
                        y = known[r, o, 2]
                        e = at_g + PK.GOAL_W * j
                        row[e] = o
                        row[e + 1] = gid - 1
                        row[e + 2] = c * (x - px) + s * (y - py)
                        row[e + 3] = -s * (x - px) + c * (y - py)
                        j += 1
                row[PK.H_N_GOAL] = j
                # reports_via(): every other robot's goal in sight, its D (§3 rule 3, §4.2)
                via = gpar[r, G_SHARE_VIA] != 0.0
                n_p = _path_order(paths, r, order)
                j = 0
                for q in range(n_p):
                    o = order[q]
                    if o == me:
                        continue
                    vx = paths[r, o, P_PX]
                    vy = paths[r, o, P_PY]
                    vd = paths[r, o, P_D]
                    e = at_r + PK.REPORT_W * j
                    row[e] = o
                    row[e + 1] = paths[r, o, P_GID]
                    row[e + 2] = N.py_hypot(vx - px, vy - py) + vd
                    if via:
                        row[e + 3] = c * (vx - px) + s * (vy - py)
                        row[e + 4] = -s * (vx - px) + c * (vy - py)
                        row[e + 5] = vd
                    j += 1
                row[PK.H_N_REPORT] = j
        gfst[r, F_PREV_X] = px
        gfst[r, F_PREV_Y] = py
        gist[r, I_HAS_PREV] = 1
    return sent


# ----------------------------------------------------------------- construction and views (Python)
class GoalSharingArrays:
    """The state of a team's goal sharing as arrays (see the module docstring), built from the
    brains' own parameters, with views of a row in the reference's shapes for the tests.

    Parameters
    ----------
    params : sequence of Params
        Each robot's ``LosExplorerParams`` / ``LosHelperParams``, in row order.
    robot_ids : sequence of int
    team_sizes : sequence of int
        Each robot's M of ``Id = k·M`` (the brains' ``team_size``: ``id_gain_k`` or the team size).
    radius_m, step_m, vis_radius_m, gap_rad : sequences of float
        Each robot's radius, step length, visibility radius and largest beam gap.
    m_slots : int, optional
        Owner slots (default: the largest robot id + 1, at least ``team_size``).
    """

    def __init__(self, params: Sequence[Any], robot_ids: Sequence[int], team_sizes: Sequence[int],
                 radius_m: Sequence[float], step_m: Sequence[float], vis_radius_m: Sequence[float],
                 gap_rad: Sequence[float], m_slots: int | None = None) -> None:
        n = len(params)
        for p in params:
            if p.frame_source != "bearings":
                raise ValueError(f"frame_source {p.frame_source!r}: only 'bearings' (§3.1) is compiled")
        m = int(m_slots if m_slots is not None else max(max(robot_ids) + 1, 1))
        if max(robot_ids) >= m:
            raise ValueError(f"robot ids must be below m_slots={m}")
        self.n, self.m = n, m
        self.width = PK.row_width(m)
        self.gpar = np.zeros((n, N_G))
        for r, p in enumerate(params):
            g = self.gpar[r]
            g[G_ME] = robot_ids[r]
            g[G_IDM] = team_sizes[r]
            g[G_SHARING] = p.goal_sharing
            g[G_DELAYED] = p.delayed_visibility
            g[G_POINT_MARGIN] = 2.5 * float(radius_m[r])
            g[G_REPORT_MARGIN] = p.report_margin_steps * float(step_m[r])
            g[G_LEAD_ON] = p.lead_on
            g[G_RELAY_LIMIT] = p.relay_hop_limit
            g[G_SHARE_VIA] = p.share_via
            g[G_KEEP] = p.keep_direct_view
            g[G_STATE_SHARING] = p.state_sharing
            g[G_VIS_R] = vis_radius_m[r]
            g[G_GAP] = gap_rad[r]
        self.gist = np.zeros((n, N_I), dtype=np.int64)
        self.gist[:, I_OWN_K] = -1
        self.gfst = np.zeros((n, N_F))
        self.known = np.full((n, m, 3), np.nan)
        self.kord = np.full((n, m), -1, dtype=np.int64)
        self.paths = np.zeros((n, m, N_P))
        self.hist_step = np.full((n, HISTORY_STEPS), -1, dtype=np.int64)
        self.hist_pose = np.zeros((n, HISTORY_STEPS, 3))
        self.hist_sight = np.full((n, HISTORY_STEPS, m, 2), np.nan)
        self.out = np.full((n, self.width), np.nan)
        self.tr = np.full((n, m), -1.0)
        self.tr_ord = np.full((n, m), -1, dtype=np.int64)
        self.tr_xy = np.full((n, m, 2), np.nan)
        self.tr_xy_ord = np.full((n, m), -1, dtype=np.int64)

    def set_own_goal(self, r: int, k: int | None, xy=None) -> None:
        """``GoalSharing.set_own_goal`` of row ``r`` (the brains call it at construction too)."""
        me = int(self.gpar[r, G_ME])
        if k is None:
            self.gist[r, I_OWN_K] = -1
            self.paths[r, me, P_KIND] = KIND_NONE
            return
        if k != self.gist[r, I_OWN_K]:
            self.paths[r, me, P_KIND] = KIND_NONE
        self.gist[r, I_OWN_K] = int(k)
        self.gfst[r, F_OWN_GX], self.gfst[r, F_OWN_GY] = float(xy[0]), float(xy[1])

    def begin_step(self, step: int, pose, sight, own_set, own_k, own_xy, in_rows, in_sender, in_start, vis,
                   angles) -> None:
        gs_begin_step(int(step), pose, sight, own_set, own_k, own_xy, in_rows, in_sender, in_start, vis, angles,
                      self.gpar, self.gist, self.gfst, self.known, self.kord, self.paths, self.hist_step,
                      self.hist_pose, self.hist_sight, self.tr, self.tr_ord, self.tr_xy, self.tr_xy_ord)

    def end_step(self, step: int, pose, sight, trouble) -> np.ndarray:
        return gs_end_step(int(step), pose, sight, trouble, self.gpar, self.gist, self.gfst, self.known, self.kord,
                           self.paths, self.out)

    # ------------------------------------------------------------------ views (the reference's shapes)
    def known_goals(self, r: int) -> list[tuple[int, int, float, float]]:
        """(owner, Id, x, y) of the known goals of row ``r``, in the reference's dict order."""
        out = []
        for q in range(int(self.gist[r, I_N_KNOWN])):
            o = int(self.kord[r, q])
            gid, x, y = self.known[r, o]
            out.append((o, int(gid), float(x), float(y)))
        return out

    def path_rows(self, r: int) -> list[tuple[int, np.ndarray]]:
        """(owner, path columns ``P_*`` without ``P_SEQ``) of row ``r``, in the reference's dict order."""
        order = np.empty(self.m, dtype=np.int64)
        n_p = _path_order(self.paths, r, order)
        return [(int(o), self.paths[r, o, :P_SEQ].copy()) for o in order[:n_p]]

    def teammate_tr(self, r: int) -> dict[int, bool]:
        """The brain's ``_teammate_tr`` of row ``r`` (sender → Tr bit, in arrival order)."""
        return {int(o): bool(self.tr[r, o]) for o in self.tr_ord[r, :int(self.gist[r, I_N_TR])]}

    def teammate_tr_xy(self, r: int) -> dict[int, tuple[float, float]]:
        """The brain's ``_teammate_tr_xy`` of row ``r`` (sender → where it stood when it sent)."""
        return {int(o): (float(self.tr_xy[r, o, 0]), float(self.tr_xy[r, o, 1]))
                for o in self.tr_xy_ord[r, :int(self.gist[r, I_N_TR_XY])]}

    def own_goal(self, r: int) -> tuple[int, float, float] | None:
        k = int(self.gist[r, I_OWN_K])
        return None if k < 0 else (k, float(self.gfst[r, F_OWN_GX]), float(self.gfst[r, F_OWN_GY]))


def path_columns(p) -> np.ndarray:
    """A reference :class:`~.goal_sharing.GoalPath` as the ``P_*`` columns (without ``P_SEQ``;
    None as NaN), for comparing with :meth:`GoalSharingArrays.path_rows`."""
    row = np.empty(P_SEQ)
    row[P_KIND] = KINDS.index(p.kind)
    row[P_GID] = p.goal_id
    row[P_PX], row[P_PY], row[P_D] = p.px_m, p.py_m, p.d_point_m
    row[P_SOURCE], row[P_STEP], row[P_REACHED] = p.source, p.step, float(p.reached)
    row[P_PROMISED] = p.d_promised_m
    for col, v in ((P_VX, p.via_x_m), (P_VY, p.via_y_m), (P_VD, p.via_d_m)):
        row[col] = math.nan if v is None else v
    return row


def _renew_caches() -> None:
    """This module's kernels call the compiled R1's and the reference's kernels and the packed
    row's layout: renew their numba caches when one of those changes
    (:func:`~teamnav.control.group.renew_stale_caches`)."""
    import sys

    from teamnav.control.group import renew_stale_caches
    from teamnav.control.nav.local import base
    from teamnav.papers.los_help.brains import compiled as C
    from teamnav.papers.los_help.brains import goal_sharing

    here = sys.modules[__name__]
    kernels = [f for f in vars(here).values() if hasattr(f, "_cache") and hasattr(f, "py_func")
               and f.py_func.__module__ == __name__]
    renew_stale_caches(kernels, [m.__file__ for m in (N, C, PK, base, goal_sharing)])


_renew_caches()
