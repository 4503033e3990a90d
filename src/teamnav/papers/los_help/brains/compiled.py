"""R1 of the line-of-sight help system compiled whole, for robots without teammates: the group
brain of ``los-explorer-v1`` (Sgorbissa & Arkin §2, §5, §6; Tables 1-2's "R1 alone" rows).

The first piece of the group-brain path (``docs/concepts/group-brains.md``): the explorer of
:mod:`.explorer` (the readable reference) as one numba step over every row of a group, its
state as named columns of arrays, with the potential field or Avoid-Past
(:mod:`teamnav.control.nav.local.compiled`) or VisBug-21
(:mod:`teamnav.control.nav.local.visbug21_compiled`) as algorithm A. It covers the explorer's step where no teammate
exists (``team_size == 1``), which is all of it that R1 alone reaches:

1. the pose of this step (its odometry) and the scan (``laser``);
2. §2: the current target is reached within ε (``goal_tolerance_m``), then the next one; the
   step budget per target (``max_steps_per_target``) ends a hopeless task;
3. §2 point 4, through goal sharing's own-goal bookkeeping (§3-§4 with nobody to share with):
   the robot sees its goal (the beam nearest its bearing reaches it; with
   ``keep_direct_view``, kept while any beam near it does) or not;
4. seeing it, it heads straight for it while the corridor is wide enough for its body (else,
   with ``slide_when_blocked``, along the nearest free direction; else A); not seeing it, A
   drives towards it; when VisBug-21 finds the goal unreachable the robot stays put that
   step, and with ``restart_navigator_on_give_up`` A starts afresh the next (``nav_restarts``);
5. §5: Pr, Tr, Nt from this step's progress (with no teammate, state sharing changes nothing
   else: nobody to follow, nothing to say);
6. no broadcast (§4.4: a robot sends when it sees a teammate).

Every branch is the reference's, operation for operation, with Python's float arithmetic
where the reference computes in Python (:func:`~teamnav.control.nav.local.compiled.py_hypot`,
:func:`~teamnav.control.nav.local.compiled.py_wrap`) and the reference's own numba kernels
where it calls them (``nearest_beam_visible``, ``beam_near_reaches``, ``corridor_clear``):
``tests/test_group_brains.py`` runs both on the same scenarios and demands the same bits.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np
from numba import njit

from teamnav.control.group import GroupAction, GroupObservation
from teamnav.control.nav.local import NAVIGATORS
from teamnav.control.nav.local import compiled as N
from teamnav.control.nav.local import visbug21_compiled as V
from teamnav.control.nav.local.base import corridor_clear
from teamnav.control.protocol import RobotInfo
from teamnav.papers.los_help.brains.goal_sharing import beam_near_reaches, max_beam_gap, nearest_beam_visible

__all__ = ["LosExplorerGroup"]

# ----------------------------------------------------------------- parameter columns (epar)
Q_TOL = 0  # goal_tolerance_m (ε, §2)
Q_BUDGET = 1  # max_steps_per_target (-1: None)
Q_VIS_R = 2  # visibility radius of V(R) (§2) [m]
Q_STEP = 3  # step length [m]
Q_RADIUS = 4  # robot radius [m]
Q_PMF = 5  # progress_min_fraction
Q_STRAIGHT = 6  # straight_when_visible
Q_SLIDE = 7  # slide_when_blocked
Q_LOOKAHEAD = 8  # slide_lookahead_m
Q_KEEP = 9  # keep_direct_view
Q_SHARING = 10  # goal_sharing
Q_RESET_TR = 11  # reset_trouble_on_target
Q_CR = 12  # trouble_cr (Cr of §5)
Q_VISBUG = 13  # 1.0: algorithm A is VisBug-21 (vpar/vfst/vist), 0.0: the potential field or Avoid-Past
Q_RESTART = 14  # restart_navigator_on_give_up
N_Q = 15

# ----------------------------------------------------------------- state columns
X_PX = 0  # this step's pose (own odometry frame)
X_PY = 1
X_TH = 2
X_LAST_BEST = 3  # _head_to's best distance so far to the point headed for
X_SLIDE_SIDE = 4  # side of the last slide (+1 / -1)
X_NAV_GX = 5  # the goal last given to A (``_nav_goal``)
X_NAV_GY = 6
N_X = 7

J_IDX = 0  # target_index
J_NT = 1  # number of targets
J_REACHED = 2  # targets_reached
J_FINISHED = 3
J_GAVE_UP = 4
J_SINCE = 5  # step the current target became current (_target_since)
J_MOVES = 6
J_MOVES_SINCE = 7
J_MODE = 8  # MODE_*
J_DIRECT = 9  # goal sharing's own path is "direct" (the goal is in sight, §2 point 4)
J_LAST = 10  # _last_target is ("goal", J_LAST_IDX) (0: None)
J_LAST_IDX = 11
J_GOAL_SEEN = 12  # goal_seen_steps
J_SLIDES = 13  # slide_steps
J_PR = 14  # §5: Pr, Nt, Tr
J_NT_TR = 15
J_TR = 16
J_NAV_SET = 17  # A has been given a goal (``_nav_goal`` is not None)
J_STEPS_OWN = 18  # mode_steps per mode (a mode is "met" once its count is positive)
J_STEPS_DONE = 19
J_STEPS_GAVE_UP = 20
J_NAV_RESTARTS = 21  # nav_restarts (VisBug-21 gave up on the goal and was started afresh)
N_J = 22

MODE_OWN_GOAL = 0
MODE_DONE = 1
MODE_GAVE_UP = 2
MODES = ("own_goal", "done", "gave_up")

_DEG = math.pi / 180.0  # CPython's math.radians multiplies by this


@njit(cache=True)
def _in_body(x, y, px, py, c, s):
    """A point in the robot's own frame at (px, py) with heading cos/sin (c, s): (bx, by, distance)."""
    dx = x - px
    dy = y - py
    bx = c * dx + s * dy
    by = -s * dx + c * dy
    return bx, by, N.py_hypot(bx, by)


@njit(cache=True)
def _sees(r, x, y, margin, px, py, c, s, ranges, angles, gap, vis_r):
    """``_LosBrain._sees``: V(R) of a point (own frame), §2."""
    bx, by, d = _in_body(x, y, px, py, c, s)
    if d > vis_r:
        return False
    if d < 1e-9:
        return True
    return nearest_beam_visible(ranges[r], angles, d, math.atan2(by, bx), margin, gap)


@njit(cache=True)
def _keeps(r, x, y, px, py, c, s, ranges, angles, gap, vis_r):
    """``_LosBrain._keeps``: the lenient test that keeps a goal seen directly (``keep_direct_view``)."""
    bx, by, d = _in_body(x, y, px, py, c, s)
    if d > vis_r:
        return False
    if d < 1e-9:
        return True
    g = gap if not (1e-6 > gap) else 1e-6  # Python's max(gap, 1e-6)
    return beam_near_reaches(ranges[r], angles, d, math.atan2(by, bx), 1.5 * g)


@njit(cache=True)
def _corridor(r, heading, length, th, ranges, angles, max_range, epar):
    """``_Driving._corridor_clear``."""
    if length > epar[r, Q_VIS_R]:
        return False
    return corridor_clear(ranges[r], angles, max_range, th, heading, length, epar[r, Q_RADIUS] * 1.05)


@njit(cache=True)
def _navigate(r, gx, gy, px, py, th, ranges, angles, max_range, epar, efst, eist, npar, nfst, nist, grid, normals,
              nav):
    """``_Driving._navigate`` towards the own goal (never a temporary point alone): (heading
    relative to the body or NaN for none, progressing). The potential field and Avoid-Past
    always give a heading once a goal is set; VisBug-21 gives none once it finds the goal
    unreachable, and then (``restart_navigator_on_give_up``) is started afresh for the next step."""
    visbug = epar[r, Q_VISBUG] != 0.0
    if eist[r, J_NAV_SET] == 0 or efst[r, X_NAV_GX] != gx or efst[r, X_NAV_GY] != gy:
        if visbug:
            V.vb_set_goal(nav[0], nav[1], nav[2], r, gx, gy)
        else:
            N.set_goal(npar, nfst, nist, grid, r, gx, gy, False)
        eist[r, J_NAV_SET] = 1
        efst[r, X_NAV_GX] = gx
        efst[r, X_NAV_GY] = gy
    if not visbug:
        h = N.direction(npar, nfst, nist, grid, normals, r, px, py, th, ranges[r], angles, max_range)
        return N.py_wrap(h - th), N.progressing(npar, nist, r)
    vpar, vfst, vist, order, a_sorted = nav
    h = V.vb_direction(vpar, vfst, vist, r, px, py, th, ranges[r], angles, order, a_sorted, max_range)
    progressing = V.vb_progressing(vpar, vfst, vist, r)
    if h != h:
        if epar[r, Q_RESTART] != 0.0:  # A gave up: a fresh navigator next step (``self._nav = None``)
            V.vb_new_navigator(vpar, vfst, vist, r)
            eist[r, J_NAV_SET] = 0
            eist[r, J_NAV_RESTARTS] += 1
        return math.nan, progressing
    return N.py_wrap(h - th), progressing


@njit(cache=True)
def _head_to(r, gx, gy, end_margin, px, py, th, c, s, ranges, angles, max_range, gap, epar, efst, eist,
             npar, nfst, nist, grid, normals, nav, vis):
    """``_Driving._head_to`` the own goal in sight (key ``("goal", J_IDX)``; a helper's
    ``("waypoint", k)`` with k in J_IDX): (heading relative to the body or NaN, progressing).
    ``vis``: the scan of the visibility test (the brain's ``_vis_r64``; R1 alone: ``ranges``)."""
    step_m = epar[r, Q_STEP]
    dist = N.py_hypot(gx - px, gy - py)
    progressing = True
    best = dist
    if eist[r, J_LAST] == 1 and eist[r, J_LAST_IDX] == eist[r, J_IDX]:
        progressing = dist < efst[r, X_LAST_BEST] - epar[r, Q_PMF] * step_m
        best = dist if progressing else efst[r, X_LAST_BEST]
    eist[r, J_LAST] = 1
    eist[r, J_LAST_IDX] = eist[r, J_IDX]
    efst[r, X_LAST_BEST] = best
    if dist <= 0.0:
        return math.nan, True
    heading = math.atan2(gy - py, gx - px)
    if epar[r, Q_STRAIGHT] != 0.0:
        length = dist - end_margin
        if not (length > step_m):
            length = step_m  # Python's max(step_m, dist - end_margin)
        if _corridor(r, heading, length, th, ranges, angles, max_range, epar):
            return N.py_wrap(heading - th), progressing
        if epar[r, Q_SLIDE] != 0.0 and _sees(r, gx, gy, 2.0 * epar[r, Q_RADIUS], px, py, c, s, vis, angles, gap,
                                              epar[r, Q_VIS_R]):
            # _slide_heading(heading, min(dist - end_margin, slide_lookahead_m))
            look = epar[r, Q_LOOKAHEAD]
            length = look if look < dist - end_margin else dist - end_margin
            if not (length > step_m):
                length = step_m
            side = efst[r, X_SLIDE_SIDE]
            for k in range(1, 19):
                for q in range(2):
                    sgn = side if q == 0 else -side
                    h = heading + sgn * ((5.0 * k) * _DEG)
                    if _corridor(r, h, length, th, ranges, angles, max_range, epar):
                        efst[r, X_SLIDE_SIDE] = sgn
                        eist[r, J_SLIDES] += 1
                        return N.py_wrap(h - th), progressing
    d, _ = _navigate(r, gx, gy, px, py, th, ranges, angles, max_range, epar, efst, eist, npar, nfst, nist, grid,
                     normals, nav)
    return d, progressing


@njit(cache=True)
def r1_alone_step(step, odom, ranges, angles, max_range, gap, epar, efst, eist, targets, target_steps,
                  npar, nfst, nist, grid, normals, out_dir, grow, nav):
    """One step of every row (see the module docstring); ``out_dir[r]``: the body-frame
    direction of robot r's next step, NaN for none. Returns, without changing anything, 1
    when a row's Avoid-Past visit would fall outside its grid (``grow``: row, cell i, cell j;
    the caller grows the grid and calls again) and 2 when a row has fewer than two normals
    left (the caller refills the buffers and calls again); else 0 after the step. ``nav``:
    VisBug-21's ``(vpar, vfst, vist, order, a_sorted)`` (:mod:`~teamnav.control.nav.local.visbug21_compiled`)
    for the rows whose algorithm A it is."""
    n = odom.shape[0]
    for r in range(n):
        if eist[r, J_FINISHED] == 0 and epar[r, Q_VISBUG] == 0.0:
            if nist[r, N.I_NORMAL] > N.NORMALS - 2:
                return 2
            out, ci, cj = N.visit_cell_outside(npar, nist, grid, r, odom[r, 0], odom[r, 1])
            if out:
                grow[0] = r
                grow[1] = ci
                grow[2] = cj
                return 1
    for r in range(n):
        px = odom[r, 0]
        py = odom[r, 1]
        th = odom[r, 2]
        c = math.cos(th)
        s = math.sin(th)
        efst[r, X_PX] = px
        efst[r, X_PY] = py
        efst[r, X_TH] = th
        vis_r = epar[r, Q_VIS_R]
        # §2: the current target reached within ε -> the next one (LosExplorer._advance_task)
        while eist[r, J_FINISHED] == 0:
            i = eist[r, J_IDX]
            if N.py_hypot(targets[r, i, 0] - px, targets[r, i, 1] - py) >= epar[r, Q_TOL]:
                budget = epar[r, Q_BUDGET]
                if budget >= 0.0 and step - eist[r, J_SINCE] >= budget:
                    eist[r, J_GAVE_UP] = 1
                    eist[r, J_FINISHED] = 1
                    eist[r, J_DIRECT] = 0  # sharing.set_own_goal(None)
                break
            eist[r, J_SINCE] = step
            target_steps[r, eist[r, J_REACHED]] = eist[r, J_MOVES] - eist[r, J_MOVES_SINCE]
            eist[r, J_MOVES_SINCE] = eist[r, J_MOVES]
            eist[r, J_IDX] = i + 1
            eist[r, J_REACHED] += 1
            eist[r, J_DIRECT] = 0  # a new own goal (or none) forgets the old path
            if eist[r, J_IDX] >= eist[r, J_NT]:
                eist[r, J_FINISHED] = 1
                eist[r, J_MODE] = MODE_DONE
            eist[r, J_LAST] = 0
            if epar[r, Q_RESET_TR] != 0.0:
                eist[r, J_PR] = 0
                eist[r, J_NT_TR] = 1
                eist[r, J_TR] = 0
        # §2 point 4 through goal sharing's refresh: is the own goal in sight?
        if epar[r, Q_SHARING] != 0.0 and eist[r, J_FINISHED] == 0:
            i = eist[r, J_IDX]
            gx = targets[r, i, 0]
            gy = targets[r, i, 1]
            kept = (epar[r, Q_KEEP] != 0.0 and eist[r, J_DIRECT] == 1
                    and _keeps(r, gx, gy, px, py, c, s, ranges, angles, gap, vis_r))
            if kept or _sees(r, gx, gy, 0.0, px, py, c, s, ranges, angles, gap, vis_r):
                eist[r, J_DIRECT] = 1
            else:
                eist[r, J_DIRECT] = 0
        # decide (LosExplorer._decide / _decide_task)
        d = math.nan
        if eist[r, J_FINISHED] != 0:
            eist[r, J_MODE] = MODE_GAVE_UP if eist[r, J_GAVE_UP] != 0 else MODE_DONE
        else:
            i = eist[r, J_IDX]
            gx = targets[r, i, 0]
            gy = targets[r, i, 1]
            eist[r, J_MODE] = MODE_OWN_GOAL
            if eist[r, J_DIRECT] == 1:
                eist[r, J_GOAL_SEEN] += 1
                d, progressing = _head_to(r, gx, gy, 0.5 * epar[r, Q_TOL], px, py, th, c, s, ranges, angles,
                                          max_range, gap, epar, efst, eist, npar, nfst, nist, grid, normals, nav,
                                          ranges)
            else:  # _unseen_goal -> _drive: A towards the goal
                eist[r, J_LAST] = 0
                d, progressing = _navigate(r, gx, gy, px, py, th, ranges, angles, max_range, epar, efst, eist, npar,
                                           nfst, nist, grid, normals, nav)
            # §5: TroubleState.update(progressing)
            bound = eist[r, J_NT_TR] * int(epar[r, Q_CR])
            if progressing:
                eist[r, J_PR] = max(eist[r, J_PR] - 1, 0)
            else:
                eist[r, J_PR] = min(eist[r, J_PR] + eist[r, J_NT_TR], bound)
            if eist[r, J_TR] == 0 and eist[r, J_PR] >= bound:
                eist[r, J_TR] = 1
            elif eist[r, J_TR] == 1 and eist[r, J_PR] == 0:
                eist[r, J_TR] = 0
                eist[r, J_NT_TR] += 1
        if d == d:
            eist[r, J_MOVES] += 1
        eist[r, J_STEPS_OWN + eist[r, J_MODE]] += 1
        out_dir[r] = d
    return 0


class _R1View:
    """Robot r's face of :class:`LosExplorerGroup`: what experiments read off a
    :class:`~.explorer.LosExplorer` (``finished``, ``log()``, the counters), from the arrays."""

    def __init__(self, group: "LosExplorerGroup", r: int) -> None:
        self._g = group
        self._r = r
        self.me = int(group.infos[r].robot_id)
        self.params = group.params[r]
        self.targets = [(float(x), float(y)) for x, y in self.params.targets_xy]

    def _i(self, col: int) -> int:
        return int(self._g.eist[self._r, col])

    finished = property(lambda self: bool(self._i(J_FINISHED)))
    gave_up = property(lambda self: bool(self._i(J_GAVE_UP)))
    target_index = property(lambda self: self._i(J_IDX))
    targets_reached = property(lambda self: self._i(J_REACHED))
    moves = property(lambda self: self._i(J_MOVES))
    goal_seen_steps = property(lambda self: self._i(J_GOAL_SEEN))
    slide_steps = property(lambda self: self._i(J_SLIDES))
    mode = property(lambda self: MODES[self._i(J_MODE)])
    target_steps = property(lambda self: [int(v) for v in self._g.target_steps[self._r, :self._i(J_REACHED)]])
    # what R1 alone never does (no teammate, no message, A never gives up)
    nav_restarts = property(lambda self: self._i(J_NAV_RESTARTS))
    msgs_sent = bytes_sent = msgs_received = promised_steps = temp_switches = 0
    temp_dropped = ghosts_unreachable = vias_taken = trouble_helpers_dropped = 0

    @property
    def mode_steps(self) -> dict[str, int]:
        return {m: self._i(J_STEPS_OWN + k) for k, m in enumerate(MODES) if self._i(J_STEPS_OWN + k) > 0}

    def log(self) -> dict[str, Any]:
        """:meth:`~.explorer.LosExplorer.log`, the same keys in the same order."""
        g, r = self._g, self._r
        direct = self._i(J_DIRECT) == 1
        finished = self.finished
        idx = self._i(J_IDX)
        own_d = -1.0
        if direct:
            gx, gy = self.targets[idx]
            own_d = float(math.hypot(gx - float(g.efst[r, X_PX]), gy - float(g.efst[r, X_PY])) + 0.0)
        out = {
            "mode": self.mode,
            "moves": self.moves,
            "tr": bool(self._i(J_TR)),
            "pr": self._i(J_PR),
            "nt": self._i(J_NT_TR),
            "msgs_sent": 0,
            "bytes_sent": 0,
            "msgs_received": 0,
            "nav_restarts": self.nav_restarts,
            "known_goals": 0,
            "ghosts": 0,
            "own_d_m": own_d,
            **{f"steps_{m}": int(k) for m, k in sorted(self.mode_steps.items())},
            "slide_steps": self.slide_steps,
            "temp_switches": 0,
        }
        out.update(target_index=idx, targets_reached=self.targets_reached, finished=finished, gave_up=self.gave_up,
                   goal_seen_steps=self.goal_seen_steps, promised_steps=0, temp_dropped=0, ghosts_unreachable=0,
                   vias_taken=0, trouble_helpers_dropped=0)
        if self.params.log_layers:
            goal = self.targets[idx] if not finished else None
            out["layers"] = {
                "los_goal": {"kind": "markers", "frame": "odom", "hold": True,
                             "data": np.array([goal], dtype=np.float64) if goal is not None else np.zeros((0, 2)),
                             "description": "Sgorbissa & Arkin: the robot's current goal (target or patrol waypoint)"},
                "los_ghosts": {"kind": "markers", "frame": "odom", "hold": True,
                               "data": np.array([], dtype=np.float64).reshape(-1, 2),
                               "description": "Sgorbissa & Arkin §4: ghost robots and own past viewpoints kept for goals"},
            }
        return out


class LosExplorerGroup:
    """Every R1 of a group without teammates in one compiled step (the group brain of
    ``los-explorer-v1``; see the module docstring). Built as the engine builds a group brain:
    one validated :class:`~.explorer_params.LosExplorerParams`, Generator and RobotInfo per robot."""

    @classmethod
    def unsupported(cls, params: Sequence[Any], infos: Sequence[RobotInfo]) -> str | None:
        """Why these robots need the reference brain (None: this group brain runs them)."""
        from teamnav.papers.los_help.brains.explorer_params import LosExplorerParams

        for p, info in zip(params, infos):
            if type(p) is not LosExplorerParams:
                return f"params of type {type(p).__name__}"
            if int(info.team_size) != 1:
                return "teammates (only R1 alone is compiled so far)"
            if p.navigator not in ("potential_field", "avoid_past", "visbug21"):
                return f"navigator {p.navigator!r} (compiled: potential_field, avoid_past, visbug21)"
            if p.navigator == "visbug21":
                nav_p = NAVIGATORS[p.navigator].Params(**dict(p.navigator_params))
                if nav_p.turn not in V.TURNS:
                    return f"VisBug-21 turn {nav_p.turn!r} (a draw per goal; compiled: {', '.join(V.TURNS)})"
            if p.frame_source != "bearings":
                return f"frame_source {p.frame_source!r}"
            if p.laser not in info.sensors:
                return f"no range sensor {p.laser!r}"
        lasers = {(p.laser, info.sensors[p.laser].angles_rad.shape[0]) for p, info in zip(params, infos)}
        if len(lasers) != 1:
            return "robots of one group must read one laser layout"
        return None

    def __init__(self, params: Sequence[Any], rngs: Sequence[np.random.Generator], infos: Sequence[RobotInfo]) -> None:
        why = self.unsupported(params, infos)
        if why is not None:
            raise ValueError(f"LosExplorerGroup cannot run these robots: {why}")
        n = len(params)
        self.params = list(params)
        self.infos = list(infos)
        self.rngs = list(rngs)
        self.laser = params[0].laser
        t_max = max([len(p.targets_xy) for p in params] + [1])
        self.targets = np.zeros((n, t_max, 2))
        self.target_steps = np.zeros((n, t_max), dtype=np.int64)
        self.epar = np.zeros((n, N_Q))
        self.efst = np.zeros((n, N_X))
        self.eist = np.zeros((n, N_J), dtype=np.int64)
        npar, vpar = [], []
        for r, (p, info) in enumerate(zip(params, infos)):
            sensor = info.sensors[p.laser]
            step_m, radius = float(info.step_length_m), float(info.radius_m)
            if p.targets_xy:
                self.targets[r, :len(p.targets_xy)] = [(float(x), float(y)) for x, y in p.targets_xy]
            e = self.epar[r]
            e[Q_TOL] = p.goal_tolerance_m
            e[Q_BUDGET] = -1.0 if p.max_steps_per_target is None else float(p.max_steps_per_target)
            e[Q_VIS_R] = float(p.visibility_radius_m or sensor.max_range_m)
            e[Q_STEP] = step_m
            e[Q_RADIUS] = radius
            e[Q_PMF] = p.progress_min_fraction
            e[Q_STRAIGHT] = float(p.straight_when_visible)
            e[Q_SLIDE] = float(p.slide_when_blocked)
            e[Q_LOOKAHEAD] = p.slide_lookahead_m
            e[Q_KEEP] = float(p.keep_direct_view)
            e[Q_SHARING] = float(p.goal_sharing)
            e[Q_RESET_TR] = float(p.reset_trouble_on_target)
            e[Q_CR] = float(p.trouble_cr)
            e[Q_RESTART] = float(p.restart_navigator_on_give_up)
            self.efst[r, X_SLIDE_SIDE] = 1.0
            self.eist[r, J_NT] = len(p.targets_xy)
            self.eist[r, J_NT_TR] = 1
            if not p.targets_xy:  # finished at once (LosExplorer: ``finished = not targets``, mode "done")
                self.eist[r, J_FINISHED] = 1
                self.eist[r, J_MODE] = MODE_DONE
            nav_p = NAVIGATORS[p.navigator].Params(**dict(p.navigator_params))
            if p.navigator == "visbug21":
                e[Q_VISBUG] = 1.0
                npar.append(np.zeros(N.N_P))  # unused (the potential field's row)
                vpar.append(V.vb_params(nav_p, step_m, radius))
            else:
                npar.append(N.nav_params(p.navigator, nav_p, step_m, radius))
                vpar.append(np.zeros(V.NV_P))  # unused
        self.npar = np.array(npar)
        self.vpar = np.array(vpar)
        self.vfst, self.vist = V.vb_state(self.vpar)
        self.nfst, self.nist, self.grid, self.normals = N.new_state(n)
        # VisBug-21 rows read no normals: never "low", so a refill never draws from their Generators
        self.nist[self.epar[:, Q_VISBUG] != 0.0, N.I_NORMAL] = 0
        self._gap_for: Any = None
        self._gap = 0.0
        self._dir = np.empty(n)
        self._grow = np.zeros(3, dtype=np.int64)
        self._n = n
        self.robots = [_R1View(self, r) for r in range(n)]

    def step_group(self, obs: GroupObservation) -> GroupAction:
        """One step of every robot (the kernel :func:`r1_alone_step`)."""
        angles = obs.angles_rad[self.laser]
        if self._gap_for is not angles:  # as the reference: the beam layout's gap, measured once
            self._a64 = np.ascontiguousarray(angles, dtype=np.float64)
            self._gap_for, self._gap = angles, max_beam_gap(self._a64)
            order, a_sorted = V.beam_order(self._a64)  # VisBug's obstacle cut, per beam layout
            self._nav = (self.vpar, self.vfst, self.vist, order, a_sorted)
        ranges = np.ascontiguousarray(obs.ranges_m[self.laser], dtype=np.float64)
        odom = np.ascontiguousarray(obs.odom_pose, dtype=np.float64)
        step = int(obs.step)
        max_range = float(obs.max_range_m[self.laser])
        while True:
            code = r1_alone_step(step, odom, ranges, self._a64, max_range, self._gap, self.epar, self.efst, self.eist,
                                 self.targets, self.target_steps, self.npar, self.nfst, self.nist, self.grid,
                                 self.normals, self._dir, self._grow, self._nav)
            if code == 0:
                break
            if code == 1:
                r, ci, cj = (int(v) for v in self._grow)
                self.grid = N.grow_grid(self.grid, self.nist, r, ci, cj)
            else:
                N.refill_normals(self.nist, self.normals, self.rngs)
        return GroupAction(np.zeros(self._n), np.zeros(self._n), self._dir.copy(), [])


def _renew_caches() -> None:
    """This module's kernels call the compiled navigators and the reference's kernels (base,
    goal_sharing, the navigators'): renew their numba caches when one of those changes
    (:func:`~teamnav.control.group.renew_stale_caches`)."""
    from teamnav.control.group import renew_module_caches
    from teamnav.control.nav.local import avoid_past, base, potential_field, visbug21, visbug21_geometry
    from teamnav.papers.los_help.brains import goal_sharing

    renew_module_caches(__name__, (N, V, avoid_past, base, potential_field, visbug21, visbug21_geometry, goal_sharing))


_renew_caches()
