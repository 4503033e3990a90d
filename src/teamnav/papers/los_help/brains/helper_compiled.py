"""The helpers R2..R4 of the line-of-sight help system compiled whole: the group brain of
``los-helper-v1`` (Sgorbissa & Arkin §3-§6; ``docs/concepts/group-brains.md``).

The readable reference is :class:`~.helper.LosHelper` with the step it shares with R1
(:class:`~.brain._LosBrain`). A team of helpers steps in four calls per step, each over every
row:

1. :func:`helpers_advance`: the patrol (§6: helpers "patrol the corridors"): the next waypoint
   when the current one is reached within ε or timed out (``waypoint_timeout_steps``), ping-pong
   or cycle; each new waypoint is a new goal k, shared with ``Id = k·M`` (§3.1);
2. :func:`~.goal_sharing_compiled.gs_begin_step`: the history ring, the inbox (frames from
   mutual bearings, Id rule, D arbitration, §3.1-§4.2) and the §4.3 bookkeeping;
3. :func:`helpers_decide`: head straight for the waypoint in sight (§2 point 4; sliding along
   a blocked corridor with ``slide_when_blocked``), else algorithm A towards it; Pr, Tr, Nt
   from this step's progress (§5); a helper never leaves its patrol to help;
4. :func:`~.goal_sharing_compiled.gs_end_step`: the outgoing message (§4.4).

The messages a compiled helper sends are the reference's :class:`~.messages.LosHelpMsg`
(unpacked from its row, :mod:`.packed`, without loss), so that R1's per-robot brain, which is
not compiled with teammates yet, reads them as before. Every branch is the reference's,
operation for operation (the navigators and the straight / slide heading of the compiled R1,
:mod:`.compiled`); ``tests/test_goal_sharing_compiled.py`` runs R1..R4 with and without this
group brain and demands the same run.
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
from teamnav.control.types import Message
from teamnav.papers.los_help.brains import compiled as C
from teamnav.papers.los_help.brains import goal_sharing_compiled as GC
from teamnav.papers.los_help.brains.goal_sharing import max_beam_gap
from teamnav.papers.los_help.brains.messages import (
    MESSAGE_KIND,
    LosHelpMsg,
    message_size_bytes,
)
from teamnav.papers.los_help.brains.packed import pack, unpack

__all__ = ["LosHelperGroup", "helpers_advance", "helpers_decide"]

# ----------------------------------------------------------------- the patrol's columns (hist), beside R1's epar/efst/eist
H_WI = 0  # waypoint_index
H_DIR = 1  # ping-pong direction (+1 / -1)
H_REACHED = 2  # waypoints_reached
H_SKIPPED = 3  # waypoints_skipped
H_ON_WP = 4  # _steps_on_waypoint
H_NP = 5  # number of waypoints
H_CYCLE = 6  # patrol_mode == "cycle"
H_TIMEOUT = 7  # waypoint_timeout_steps
H_MODE = 8  # MODE_*
H_STEPS = 9  # mode_steps: H_STEPS + MODE_*
N_H = 11

MODE_PATROL = 0
MODE_STAY = 1
MODES = ("patrol", "stay")
# eist[r, C.J_IDX] holds the goal index k (the key ("waypoint", k) of ``_head_to``)


@njit(cache=True)
def helper_advance_row(r, odom, epar, eist, hist, patrol, own_set, own_k, own_xy):
    """``LosHelper._advance_task`` of row ``r``; ``own_set[r]`` / ``own_k[r]`` / ``own_xy[r]``: the
    ``set_own_goal`` call it makes (for :func:`~.goal_sharing_compiled.gs_begin_step`)."""
    own_set[r] = 0
    n = hist[r, H_NP]
    if n == 0:
        return
    wi = hist[r, H_WI]
    reached = N.py_hypot(patrol[r, wi, 0] - odom[r, 0], patrol[r, wi, 1] - odom[r, 1]) < epar[r, C.Q_TOL]
    hist[r, H_ON_WP] += 1
    timeout = hist[r, H_TIMEOUT]
    timed_out = not reached and timeout > 0 and hist[r, H_ON_WP] > timeout
    if not (reached or timed_out):
        return
    if n == 1:
        return  # one waypoint: it stays there
    if hist[r, H_CYCLE] != 0:
        wi = (wi + 1) % n
    else:
        if not (0 <= wi + hist[r, H_DIR] < n):
            hist[r, H_DIR] = -hist[r, H_DIR]
        wi += hist[r, H_DIR]
    hist[r, H_WI] = wi
    if reached:
        hist[r, H_REACHED] += 1
    else:
        hist[r, H_SKIPPED] += 1
    hist[r, H_ON_WP] = 0
    eist[r, C.J_IDX] += 1
    eist[r, C.J_LAST] = 0  # _last_target = None
    own_set[r] = 1
    own_k[r] = eist[r, C.J_IDX]
    own_xy[r, 0] = patrol[r, wi, 0]
    own_xy[r, 1] = patrol[r, wi, 1]
    if epar[r, C.Q_RESET_TR] != 0.0:  # TroubleState.reset
        eist[r, C.J_PR] = 0
        eist[r, C.J_NT_TR] = 1
        eist[r, C.J_TR] = 0


@njit(cache=True)
def helpers_advance(odom, epar, eist, hist, patrol, own_set, own_k, own_xy):
    """``LosHelper._advance_task`` of every row (:func:`helper_advance_row`)."""
    for r in range(odom.shape[0]):
        helper_advance_row(r, odom, epar, eist, hist, patrol, own_set, own_k, own_xy)


@njit(cache=True)
def nav_needs_room(r, px, py, epar, npar, nist, grid, grow):
    """Before any row steps: 2 when row ``r``'s potential field / Avoid-Past has fewer than two
    normals left, 1 (``grow`` = row, cell i, cell j) when its Avoid-Past visit would fall outside
    its grid; else 0 (VisBug-21 rows: always 0)."""
    if epar[r, C.Q_VISBUG] != 0.0:
        return 0
    if nist[r, N.I_NORMAL] > N.NORMALS - 2:
        return 2
    out, ci, cj = N.visit_cell_outside(npar, nist, grid, r, px, py)
    if out:
        grow[0] = r
        grow[1] = ci
        grow[2] = cj
        return 1
    return 0


@njit(cache=True)
def helper_decide_row(r, odom, ranges, vis, angles, max_range, gap, epar, efst, eist, hist, patrol, npar, nfst, nist,
                      grid, normals, nav):
    """``LosHelper._decide`` of row ``r``, with the step's move count and mode count; returns the
    body-frame direction of the next step (NaN: none)."""
    px = odom[r, 0]
    py = odom[r, 1]
    th = odom[r, 2]
    c = math.cos(th)
    s = math.sin(th)
    efst[r, C.X_PX] = px
    efst[r, C.X_PY] = py
    efst[r, C.X_TH] = th
    d = math.nan
    np_ = hist[r, H_NP]
    if np_ == 0:
        hist[r, H_MODE] = MODE_STAY
    else:
        wi = hist[r, H_WI]
        wx = patrol[r, wi, 0]
        wy = patrol[r, wi, 1]
        if np_ == 1 and N.py_hypot(wx - px, wy - py) < epar[r, C.Q_TOL]:
            hist[r, H_MODE] = MODE_STAY
        else:
            hist[r, H_MODE] = MODE_PATROL
            if C._sees(r, wx, wy, 0.0, px, py, c, s, vis, angles, gap, epar[r, C.Q_VIS_R]):
                d, progressing = C._head_to(r, wx, wy, 0.5 * epar[r, C.Q_TOL], px, py, th, c, s, ranges, angles,
                                            max_range, gap, epar, efst, eist, npar, nfst, nist, grid, normals, nav,
                                            vis)
            else:  # _drive: A towards the waypoint
                eist[r, C.J_LAST] = 0
                d, progressing = C._navigate(r, wx, wy, px, py, th, ranges, angles, max_range, epar, efst, eist,
                                             npar, nfst, nist, grid, normals, nav)
            trouble_update(r, progressing, epar, eist)
    if not math.isnan(d):
        eist[r, C.J_MOVES] += 1
    hist[r, H_STEPS + hist[r, H_MODE]] += 1
    return d


@njit(cache=True)
def trouble_update(r, progressing, epar, eist):
    """§5: ``TroubleState.update(progressing)`` of row ``r``."""
    bound = eist[r, C.J_NT_TR] * int(epar[r, C.Q_CR])
    if progressing:
        eist[r, C.J_PR] = max(eist[r, C.J_PR] - 1, 0)
    else:
        eist[r, C.J_PR] = min(eist[r, C.J_PR] + eist[r, C.J_NT_TR], bound)
    if eist[r, C.J_TR] == 0 and eist[r, C.J_PR] >= bound:
        eist[r, C.J_TR] = 1
    elif eist[r, C.J_TR] == 1 and eist[r, C.J_PR] == 0:
        eist[r, C.J_TR] = 0
        eist[r, C.J_NT_TR] += 1


@njit(cache=True)
def helpers_decide(odom, ranges, vis, angles, max_range, gap, epar, efst, eist, hist, patrol, npar, nfst, nist, grid,
                   normals, out_dir, grow, nav):
    """``LosHelper._decide`` of every row (:func:`helper_decide_row`); ``out_dir[r]``: the
    body-frame direction of the next step (NaN: none). Returns, changing nothing, 1 (grow
    Avoid-Past's grid: ``grow`` = row, cell i, cell j) or 2 (refill the normals), as
    :func:`~.compiled.r1_alone_step`; else 0."""
    n = odom.shape[0]
    for r in range(n):
        if hist[r, H_NP] > 0:
            code = nav_needs_room(r, odom[r, 0], odom[r, 1], epar, npar, nist, grid, grow)
            if code != 0:
                return code
    for r in range(n):
        out_dir[r] = helper_decide_row(r, odom, ranges, vis, angles, max_range, gap, epar, efst, eist, hist, patrol,
                                       npar, nfst, nist, grid, normals, nav)
    return 0


class _HelperView:
    """Robot r's face of :class:`LosHelperGroup`: what experiments read off a
    :class:`~.helper.LosHelper` (``log()`` and its counters; like it, no ``finished``)."""

    def __init__(self, group: LosHelperGroup, r: int) -> None:
        self._g = group
        self._r = r
        self.me = int(group.infos[r].robot_id)
        self.params = group.params[r]
        self.patrol = [(float(x), float(y)) for x, y in self.params.patrol_xy]
        self.msgs_sent = 0
        self.bytes_sent = 0

    def _i(self, col: int) -> int:
        return int(self._g.eist[self._r, col])

    def _h(self, col: int) -> int:
        return int(self._g.hist[self._r, col])

    moves = property(lambda self: self._i(C.J_MOVES))
    slide_steps = property(lambda self: self._i(C.J_SLIDES))
    nav_restarts = property(lambda self: self._i(C.J_NAV_RESTARTS))
    waypoint_index = property(lambda self: self._h(H_WI))
    waypoints_reached = property(lambda self: self._h(H_REACHED))
    waypoints_skipped = property(lambda self: self._h(H_SKIPPED))
    mode = property(lambda self: MODES[self._h(H_MODE)])
    msgs_received = property(lambda self: int(self._g.gs.gist[self._r, GC.I_MSGS_RECEIVED]))
    temp_switches = 0

    @property
    def mode_steps(self) -> dict[str, int]:
        return {m: self._h(H_STEPS + k) for k, m in enumerate(MODES) if self._h(H_STEPS + k) > 0}

    def log(self) -> dict[str, Any]:
        """:meth:`~.helper.LosHelper.log`, the same keys in the same order."""
        g, r = self._g, self._r
        gs = g.gs
        paths = gs.path_rows(r)
        me_x, me_y = float(g.efst[r, C.X_PX]), float(g.efst[r, C.X_PY])
        own_d = -1.0
        for o, p in paths:
            if o == self.me:
                own_d = float(math.hypot(float(p[GC.P_PX]) - me_x, float(p[GC.P_PY]) - me_y) + float(p[GC.P_D]))
        out = {
            "mode": self.mode,
            "moves": self.moves,
            "tr": bool(self._i(C.J_TR)),
            "pr": self._i(C.J_PR),
            "nt": self._i(C.J_NT_TR),
            "msgs_sent": int(self.msgs_sent),
            "bytes_sent": int(self.bytes_sent),
            "msgs_received": self.msgs_received,
            "nav_restarts": self.nav_restarts,
            "known_goals": int(gs.gist[r, GC.I_N_KNOWN]),
            "ghosts": sum(1 for _, p in paths if p[GC.P_KIND] != GC.KIND_DIRECT),
            "own_d_m": own_d,
            **{f"steps_{m}": int(k) for m, k in sorted(self.mode_steps.items())},
            "slide_steps": self.slide_steps,
            "temp_switches": 0,
        }
        out.update(target_index=self.waypoint_index, targets_reached=self.waypoints_reached,
                   waypoints_skipped=self.waypoints_skipped)
        if self.params.log_layers:
            goal = gs.own_goal(r)
            ghosts = [(float(p[GC.P_PX]), float(p[GC.P_PY])) for _, p in paths if p[GC.P_KIND] != GC.KIND_DIRECT]
            out["layers"] = {
                "los_goal": {"kind": "markers", "frame": "odom", "hold": True,
                             "data": np.array([goal[1:]], dtype=np.float64) if goal is not None else np.zeros((0, 2)),
                             "description": "Sgorbissa & Arkin: the robot's current goal (target or patrol waypoint)"},
                "los_ghosts": {"kind": "markers", "frame": "odom", "hold": True,
                               "data": np.array(ghosts, dtype=np.float64).reshape(-1, 2),
                               "description": "Sgorbissa & Arkin §4: ghost robots and own past viewpoints kept for goals"},
            }
        return out


class LosHelperGroup:
    """Every helper of a team in one compiled step (the group brain of ``los-helper-v1``; see the
    module docstring). Built as the engine builds a group brain: one validated
    :class:`~.helper.LosHelperParams`, Generator and RobotInfo per robot."""

    @classmethod
    def unsupported(cls, params: Sequence[Any], infos: Sequence[RobotInfo]) -> str | None:
        """Why these robots need the reference brain (None: this group brain runs them)."""
        from teamnav.papers.los_help.brains.helper import LosHelperParams

        for p, info in zip(params, infos):
            if type(p) is not LosHelperParams:
                return f"params of type {type(p).__name__}"
            if p.navigator not in ("potential_field", "avoid_past", "visbug21"):
                return f"navigator {p.navigator!r} (compiled: potential_field, avoid_past, visbug21)"
            if p.navigator == "visbug21":
                nav_p = NAVIGATORS[p.navigator].Params(**dict(p.navigator_params))
                if nav_p.turn not in V.TURNS:
                    return f"VisBug-21 turn {nav_p.turn!r} (a draw per goal; compiled: {', '.join(V.TURNS)})"
            if p.frame_source != "bearings":
                return f"frame_source {p.frame_source!r}"
            if p.navigate_past_teammates_beyond_m is not None:
                return "navigate_past_teammates_beyond_m (a second scan for A)"
            if p.laser not in info.sensors:
                return f"no range sensor {p.laser!r}"
        lasers = {(p.laser, info.sensors[p.laser].angles_rad.shape[0]) for p, info in zip(params, infos)}
        if len(lasers) != 1:
            return "robots of one group must read one laser layout"
        return None

    def __init__(self, params: Sequence[Any], rngs: Sequence[np.random.Generator], infos: Sequence[RobotInfo]) -> None:
        why = self.unsupported(params, infos)
        if why is not None:
            raise ValueError(f"LosHelperGroup cannot run these robots: {why}")
        n = len(params)
        self.params = list(params)
        self.infos = list(infos)
        self.rngs = list(rngs)
        self.laser = params[0].laser
        ids = [int(info.robot_id) for info in infos]
        team_sizes = [int(p.id_gain_k or max(1, info.team_size)) for p, info in zip(params, infos)]
        self.m = max(max(ids) + 1, max(int(info.team_size) for info in infos), 1)
        w_max = max([len(p.patrol_xy) for p in params] + [1])
        self.patrol = np.zeros((n, w_max, 2))
        self.epar = np.zeros((n, C.N_Q))
        self.efst = np.zeros((n, C.N_X))
        self.eist = np.zeros((n, C.N_J), dtype=np.int64)
        self.hist = np.zeros((n, N_H), dtype=np.int64)
        npar, vpar, vis_r, radius, step = [], [], [], [], []
        for r, (p, info) in enumerate(zip(params, infos)):
            sensor = info.sensors[p.laser]
            step_m, rad = float(info.step_length_m), float(info.radius_m)
            if p.patrol_xy:
                self.patrol[r, :len(p.patrol_xy)] = [(float(x), float(y)) for x, y in p.patrol_xy]
            e = self.epar[r]
            e[C.Q_TOL] = p.goal_tolerance_m
            e[C.Q_BUDGET] = -1.0
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
            self.eist[r, C.J_IDX] = 1  # _k
            h = self.hist[r]
            h[H_DIR] = 1
            h[H_NP] = len(p.patrol_xy)
            h[H_CYCLE] = int(p.patrol_mode == "cycle")
            h[H_TIMEOUT] = int(p.waypoint_timeout_steps)
            h[H_MODE] = MODE_PATROL if p.patrol_xy else MODE_STAY
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
        # the gap is measured on the first step (the beam layout); goal sharing reads it from gpar
        self.gs = GC.GoalSharingArrays(self.params, ids, team_sizes, radius, step, vis_r, [0.0] * n, self.m)
        for r, p in enumerate(self.params):
            if p.patrol_xy:  # LosHelper.__init__: set_own_goal(1, patrol[0])
                self.gs.set_own_goal(r, 1, self.patrol[r, 0])
        self._ids = np.array(ids, dtype=np.int64)
        self._see_past = np.array([bool(p.see_past_teammates) for p in self.params])
        self._radius = np.array(radius, dtype=np.float64)
        self._state_sharing = np.array([p.state_sharing for p in self.params])
        self._gap_for: Any = None
        self._gap = 0.0
        self._dir = np.empty(n)
        self._grow = np.zeros(3, dtype=np.int64)
        self._own_set = np.zeros(n, dtype=np.int64)
        self._own_k = np.zeros(n, dtype=np.int64)
        self._own_xy = np.zeros((n, 2))
        self._sent: dict[int, tuple[LosHelpMsg, np.ndarray]] = {}
        self._n = n
        self.robots = [_HelperView(self, r) for r in range(n)]

    def step_group(self, obs: GroupObservation) -> GroupAction:
        """One step of every helper (see the module docstring)."""
        angles = obs.angles_rad[self.laser]
        if self._gap_for is not angles:  # as the reference: the beam layout's gap, measured once
            self._a64 = np.ascontiguousarray(angles, dtype=np.float64)
            self._gap_for, self._gap = angles, max_beam_gap(self._a64)
            self.gs.gpar[:, GC.G_GAP] = self._gap
            order, a_sorted = V.beam_order(self._a64)
            self._nav = (self.vpar, self.vfst, self.vist, order, a_sorted)
        ranges = np.ascontiguousarray(obs.ranges_m[self.laser], dtype=np.float64)
        odom = np.ascontiguousarray(obs.odom_pose, dtype=np.float64)
        step = int(obs.step)
        max_range = float(obs.max_range_m[self.laser])
        n, m = self._n, self.m
        # this step's sightings and the visibility scan (the brain's ``_vis_r64``)
        sight = np.empty((n, m, 2))
        vis = np.empty_like(ranges)
        GC.team_sightings(self._ids, obs.det_count, obs.det_id, obs.det_range_m, obs.det_bearing_rad, ranges, self._a64,
                          max_range, self._radius, self._see_past, sight, vis)
        # the inbox as packed rows (the reference reads LosHelpMsg bodies only); a body this
        # group sent keeps its row (``_sent``: the bodies of the last steps, by identity)
        rows, senders, start = [], [], [0]
        sent_rows = self._sent
        for box in obs.inbox:
            for msg in box:
                body = msg.body
                if isinstance(body, LosHelpMsg):
                    known = sent_rows.get(id(body))
                    rows.append(known[1] if known is not None and known[0] is body else pack(body, m))
                    senders.append(int(msg.sender))
            start.append(len(rows))
        in_rows = np.array(rows).reshape(-1, self.gs.width)
        helpers_advance(odom, self.epar, self.eist, self.hist, self.patrol, self._own_set, self._own_k, self._own_xy)
        self.gs.begin_step(step, odom, sight, self._own_set, self._own_k, self._own_xy, in_rows,
                           np.array(senders, dtype=np.int64), np.array(start, dtype=np.int64), vis, self._a64)
        while True:
            code = helpers_decide(odom, ranges, vis, self._a64, max_range, self._gap, self.epar, self.efst, self.eist,
                                  self.hist, self.patrol, self.npar, self.nfst, self.nist, self.grid, self.normals,
                                  self._dir, self._grow, self._nav)
            if code == 0:
                break
            if code == 1:
                r, ci, cj = (int(v) for v in self._grow)
                self.grid = N.grow_grid(self.grid, self.nist, r, ci, cj)
            else:
                N.refill_normals(self.nist, self.normals, self.rngs)
        trouble = np.where(self._state_sharing, self.eist[:, C.J_TR].astype(np.float64), -1.0)
        sent = self.gs.end_step(step, odom, sight, trouble)
        outbox = []
        t = float(obs.time_s)
        if len(sent_rows) > 8 * n:  # keep a few steps' bodies (the radio delivers at the next step)
            for key in list(sent_rows)[:len(sent_rows) - 4 * n]:
                del sent_rows[key]
        for r in np.flatnonzero(sent):
            row = self.gs.out[r].copy()
            body = unpack(row)
            sent_rows[id(body)] = (body, row)
            view = self.robots[r]
            outbox.append((view.me, Message(view.me, t, body, kind=MESSAGE_KIND)))
            view.msgs_sent += 1
            view.bytes_sent += message_size_bytes(body)
        return GroupAction(np.zeros(n), np.zeros(n), self._dir.copy(), outbox)


def _renew_caches() -> None:
    """This module's kernels call the compiled R1's, the navigators' and goal sharing's: renew
    their numba caches when one of those changes (:func:`~teamnav.control.group.renew_stale_caches`)."""
    import sys

    from teamnav.control.group import renew_stale_caches
    from teamnav.control.nav.local import (
        avoid_past,
        base,
        potential_field,
        visbug21,
        visbug21_geometry,
    )
    from teamnav.papers.los_help.brains import goal_sharing

    here = sys.modules[__name__]
    kernels = [f for f in vars(here).values() if hasattr(f, "_cache") and hasattr(f, "py_func")
               and f.py_func.__module__ == __name__]
    renew_stale_caches(kernels, [m.__file__ for m in (N, V, C, GC, avoid_past, base, potential_field, visbug21,
                                                      visbug21_geometry, goal_sharing)])


_renew_caches()
