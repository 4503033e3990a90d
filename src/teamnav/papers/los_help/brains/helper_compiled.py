"""The helpers R2..R4 of the line-of-sight help system, compiled: their rows of the team's group
brain (Sgorbissa & Arkin §3-§6; ``docs/concepts/group-brains.md``).

The readable reference is :class:`~.helper.LosHelper` with the step it shares with R1
(:class:`~.brain._LosBrain`). :class:`~.team_compiled.LosTeamGroup` steps R1..R4 in one call
and takes from here what is a helper's own:

- :func:`helper_advance_row`: the patrol (§6: helpers "patrol the corridors"): the next
  waypoint when the current one is reached within ε or timed out (``waypoint_timeout_steps``),
  ping-pong or cycle; each new waypoint is a new goal k, shared with ``Id = k·M`` (§3.1);
- :func:`helper_decide_row`: head straight for the waypoint in sight (§2 point 4; sliding along
  a blocked corridor with ``slide_when_blocked``), else algorithm A towards it; Pr, Tr, Nt from
  this step's progress (:func:`trouble_update`, §5); a helper never leaves its patrol to help;
- :class:`_HelperView`: what experiments read off a helper (``log()``, the counters), and
  :func:`common_log`, the keys every line-of-sight robot's log shares;
- :func:`helpers_unsupported`: what the compiled rows cannot run exactly (the team then runs
  those robots on their reference brains).

Goal sharing (the inbox, §4.3 bookkeeping, the broadcast) is
:mod:`.goal_sharing_compiled`'s, over every compiled row at once. Every branch is the
reference's, operation for operation; ``tests/test_goal_sharing_compiled.py`` and
``tests/test_team_compiled.py`` run teams with and without the group brain and demand the same
run.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numba import njit

from teamnav.control.nav.local import NAVIGATORS
from teamnav.control.nav.local import compiled as N
from teamnav.control.nav.local import visbug21_compiled as V
from teamnav.control.protocol import RobotInfo
from teamnav.papers.los_help.brains import compiled as C
from teamnav.papers.los_help.brains import goal_sharing_compiled as GC

__all__ = ["common_log", "helper_advance_row", "helper_decide_row", "helpers_unsupported"]

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


class _HelperView:
    """Robot r's face of a team's compiled rows (:class:`~.team_compiled.LosTeamGroup`): what
    experiments read off a :class:`~.helper.LosHelper` (``log()`` and its counters; like it, no
    ``finished``)."""

    def __init__(self, group: Any, r: int) -> None:
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
        out = common_log(self, 0)
        out.update(target_index=self.waypoint_index, targets_reached=self.waypoints_reached,
                   waypoints_skipped=self.waypoints_skipped)
        if self.params.log_layers:
            out["layers"] = log_layers(self)
        return out


@njit(cache=True)
def log_paths(paths, r, me, me_x, me_y):
    """(ghosts, own_d_m) of row ``r``'s log: its stored paths that are not direct views, and its
    own goal's promised distance from where it stands (``math.hypot`` to the point plus the
    point's D, as CPython computes it: :func:`~teamnav.control.nav.local.compiled.py_hypot`;
    -1 when it keeps no path to its own goal). One call per row: reading the paths in Python
    was O(team) per robot, O(team²) per recorded step of a 64-robot team."""
    ghosts = 0
    own_d = -1.0
    for o in range(paths.shape[1]):
        kind = paths[r, o, GC.P_KIND]
        if kind == GC.KIND_NONE:
            continue
        if kind != GC.KIND_DIRECT:
            ghosts += 1
        if o == me:
            own_d = N.py_hypot(paths[r, o, GC.P_PX] - me_x, paths[r, o, GC.P_PY] - me_y) + paths[r, o, GC.P_D]
    return ghosts, own_d


def common_log(view: Any, temp_switches: int) -> dict[str, Any]:
    """The keys, in the reference's order, that :meth:`~.brain._LosBrain.log` writes for every
    robot (R1 and helpers), read off a compiled row's view (``_g``: the team's rows, ``_r``: the
    row, ``me``, the counters)."""
    g, r = view._g, view._r
    gs = g.gs
    ghosts, own_d = log_paths(gs.paths, r, view.me, g.efst[r, C.X_PX], g.efst[r, C.X_PY])
    return {
        "mode": view.mode,
        "moves": view.moves,
        "tr": bool(view._i(C.J_TR)),
        "pr": view._i(C.J_PR),
        "nt": view._i(C.J_NT_TR),
        "msgs_sent": int(view.msgs_sent),
        "bytes_sent": int(view.bytes_sent),
        "msgs_received": view.msgs_received,
        "nav_restarts": view.nav_restarts,
        "known_goals": int(gs.gist[r, GC.I_N_KNOWN]),
        "ghosts": int(ghosts),
        "own_d_m": float(own_d),
        **{f"steps_{m}": int(k) for m, k in sorted(view.mode_steps.items())},
        "slide_steps": view.slide_steps,
        "temp_switches": temp_switches,
    }


def log_layers(view: Any) -> dict[str, Any]:
    """The ``layers`` of a robot's log (``log_layers``): its goal and its ghosts, odometry frame."""
    g, r = view._g, view._r
    gs = g.gs
    paths = gs.path_rows(r)
    goal = gs.own_goal(r)
    ghosts = [(float(p[GC.P_PX]), float(p[GC.P_PY])) for _, p in paths if p[GC.P_KIND] != GC.KIND_DIRECT]
    return {
        "los_goal": {"kind": "markers", "frame": "odom", "hold": True,
                     "data": np.array([goal[1:]], dtype=np.float64) if goal is not None else np.zeros((0, 2)),
                     "description": "Sgorbissa & Arkin: the robot's current goal (target or patrol waypoint)"},
        "los_ghosts": {"kind": "markers", "frame": "odom", "hold": True,
                       "data": np.array(ghosts, dtype=np.float64).reshape(-1, 2),
                       "description": "Sgorbissa & Arkin §4: ghost robots and own past viewpoints kept for goals"},
    }


def helpers_unsupported(params: Sequence[Any], infos: Sequence[RobotInfo]) -> str | None:
    """Why these helpers need the reference brain (None: the compiled helper rows run them
    exactly; :class:`~.team_compiled.LosTeamGroup` steps them)."""
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


def _renew_caches() -> None:
    """This module's kernels call the compiled R1's, the navigators' and goal sharing's: renew
    their numba caches when one of those changes (:func:`~teamnav.control.group.renew_stale_caches`)."""
    from teamnav.control.group import renew_module_caches
    from teamnav.control.nav.local import (
        avoid_past,
        base,
        potential_field,
        visbug21,
        visbug21_geometry,
    )
    from teamnav.papers.los_help.brains import goal_sharing

    renew_module_caches(__name__, (N, V, C, GC, avoid_past, base, potential_field, visbug21, visbug21_geometry,
                                   goal_sharing))


_renew_caches()
