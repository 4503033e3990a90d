"""The line-of-sight team R1..R4 compiled whole: one group brain for the explorer and the helpers
(Sgorbissa & Arkin §2-§6; ``docs/concepts/group-brains.md``).

Both ``los-explorer-v1`` and ``los-helper-v1`` name :class:`LosTeamGroup`, so the engine merges
R1's group and the helpers' groups into one team, stepped in one call. Each row has a role:

- **R1 with teammates, compiled** (:mod:`.r1_team_compiled`: ``r1_team_advance_row``, ``r1_team_decide_row``): the
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
from teamnav.papers.los_help.brains.messages import (
    MESSAGE_KIND,
    LosHelpMsg,
    message_size_bytes,
)
from teamnav.papers.los_help.brains.packed import PackedLosMsg, pack, row_sizes, unpack
from teamnav.papers.los_help.brains.r1_team_compiled import (
    F_PREV_GOAL_D,
    F_TT_BEST,
    MODE_DONE,
    MODES,
    N_R,
    N_RF,
    N_RP,
    PROGRESS,
    R_GHOSTS_UNREACH,
    R_HELPERS_DROPPED,
    R_MODE,
    R_PROMISED,
    R_PROMISED_STEPS,
    R_ROLE,
    R_STEPS,
    R_TEMP_DROPPED,
    R_TEMP_KEY,
    R_TEMP_SWITCHES,
    R_TT_ID,
    R_VIAS,
    RP_AT_SEND,
    RP_DROP_AFTER,
    RP_DROP_HELPER,
    RP_DROP_STALLED,
    RP_DROP_UNREACH,
    RP_GHOST_TOL,
    RP_HEADING_STEPS,
    RP_KEEP_HELPER,
    RP_ME,
    RP_NEAR_HELPER,
    RP_POINT_MARGIN,
    RP_PROGRESS,
    RP_RECEDE,
    RP_RESTART_AT_GHOST,
    RP_REVERSE,
    RP_SHARE_VIA,
    RP_STATE,
    RP_TOWARDS,
    RP_TRUST,
    RP_VIA_IN_SIGHT,
    r1_team_advance_row,
    r1_team_decide_row,
)

__all__ = ["LosTeamGroup", "r1_team_unsupported", "row_observation"]

ROLE_R1 = 1
ROLE_HELPER = 2

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
    """This module's kernels call the compiled R1's (alone and with teammates) and helpers', the
    navigators' and goal sharing's: renew their numba caches when one of those changes
    (:func:`~teamnav.control.group.renew_stale_caches`)."""
    from teamnav.control.group import renew_module_caches
    from teamnav.control.nav.local import (
        avoid_past,
        base,
        potential_field,
        visbug21,
        visbug21_geometry,
    )
    from teamnav.papers.los_help.brains import goal_sharing, r1_team_compiled

    renew_module_caches(__name__, (N, V, C, GC, HC, avoid_past, base, potential_field, visbug21, visbug21_geometry,
                                   goal_sharing, r1_team_compiled))


_renew_caches()
