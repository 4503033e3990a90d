"""The compiled VisBug-21 row (``control/nav/local/visbug21_compiled.py``) against the reference
navigator (``VisBug21``) on random sequences of task goals, temporary goals
(``set_goal(temporary=True)``: a teammate, a ghost or a helper as R1's goal, Sgorbissa & Arkin
§3 rule 5, §4.2, §5 rule 3), ``start_again`` with and without ``reverse_walk_factor`` (§4.2)
and steps of a robot moved where the navigator heads, in a room with a box in it: the same
heading bits, ``progressing``, mode, side and suspended task goal after every call.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from teamnav.control.nav.local import visbug21_compiled as V
from teamnav.control.nav.local.visbug21 import VisBug21, VisBugParams
from teamnav.control.types import RangeScan

STEP_M = 0.1
RADIUS_M = 0.25
MAX_RANGE_M = 4.0
ANGLES = np.linspace(-np.pi, np.pi, 72, endpoint=False)
#: the room (0..8 x 0..6) and a box in it, as (x0, y0, x1, y1)
ROOM = (0.0, 0.0, 8.0, 6.0)
BOX = (3.0, 1.5, 4.5, 4.5)
GOALS = ((6.5, 3.0), (1.5, 3.2), (3.7, 5.4), (6.0, 0.8))


def _ray_box(px, py, dx, dy, box, inside):
    """Distance along (dx, dy) from (px, py) to the box's boundary (inf if none)."""
    x0, y0, x1, y1 = box
    t_lo, t_hi = -math.inf, math.inf
    for p, d, lo, hi in ((px, dx, x0, x1), (py, dy, y0, y1)):
        if abs(d) < 1e-15:
            if p < lo or p > hi:
                return math.inf
            continue
        a, b = (lo - p) / d, (hi - p) / d
        t_lo, t_hi = max(t_lo, min(a, b)), min(t_hi, max(a, b))
    if t_hi < max(t_lo, 0.0):
        return math.inf
    return t_hi if inside else (t_lo if t_lo >= 0.0 else math.inf)


def _scan(pose):
    out = np.empty(ANGLES.shape[0])
    for i, a in enumerate(ANGLES):
        dx, dy = math.cos(pose[2] + a), math.sin(pose[2] + a)
        r = min(_ray_box(pose[0], pose[1], dx, dy, ROOM, True), _ray_box(pose[0], pose[1], dx, dy, BOX, False))
        out[i] = min(r, MAX_RANGE_M)
    return RangeScan(out, ANGLES, MAX_RANGE_M)


def _free(x, y):
    m = RADIUS_M
    if not (ROOM[0] + m < x < ROOM[2] - m and ROOM[1] + m < y < ROOM[3] - m):
        return False
    return not (BOX[0] - m < x < BOX[2] + m and BOX[1] - m < y < BOX[3] + m)


#: (op, argument, steps): a goal (task or temporary), start_again, a few steps, or an excursion
#: (a temporary goal for some steps, then the last task goal set again, as R1 does)
OPS = st.lists(st.one_of(
    st.tuples(st.sampled_from(["goal", "temporary"]), st.integers(0, len(GOALS) - 1), st.integers(0, 30)),
    st.tuples(st.just("again"), st.sampled_from([None, 1.5, 3.0]), st.integers(0, 30)),
    st.tuples(st.just("excursion"), st.integers(0, len(GOALS) - 1), st.integers(1, 30)),
    st.tuples(st.just("steps"), st.just(0), st.integers(1, 60)),
), min_size=2, max_size=10)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(ops=OPS, turn=st.sampled_from(["left", "right", "nearer_end"]), shortcut=st.booleans(),
       reverse=st.sampled_from([None, 2.0]))
def test_temporary_goals_and_start_again_are_the_reference(ops, turn, shortcut, reverse):
    params = VisBugParams(turn=turn, boundary_shortcut=shortcut, reverse_walk_factor=reverse)
    ref = VisBug21(params, np.random.default_rng(0), STEP_M, RADIUS_M)
    vpar = V.vb_params(params, STEP_M, RADIUS_M)[None, :]
    vfst, vist = V.vb_state(vpar)
    order, a_sorted = V.beam_order(ANGLES)
    pose = np.array([0.8, 0.9, 0.3])
    task = 0

    def set_goal(k, temporary):
        g = np.array(GOALS[k])
        ref.set_goal(g, temporary=temporary)
        V.vb_set_goal_t(vpar, vfst, vist, 0, float(g[0]), float(g[1]), temporary)

    def steps(n):
        nonlocal pose
        for _ in range(n):
            scan = _scan(pose)
            h_ref = ref.direction(pose.copy(), scan)
            h = V.vb_direction(vpar, vfst, vist, 0, pose[0], pose[1], pose[2], scan.ranges_m, ANGLES, order,
                               a_sorted, MAX_RANGE_M)
            assert (h_ref is None and math.isnan(h)) or (h_ref is not None and h_ref == h), (h_ref, h)
            assert ref.progressing == V.vb_progressing(vpar, vfst, vist, 0)
            if h_ref is None:
                return
            x, y = pose[0] + STEP_M * math.cos(h_ref), pose[1] + STEP_M * math.sin(h_ref)
            if _free(x, y):
                pose = np.array([x, y, h_ref])

    set_goal(task, False)
    steps(30)
    for op, a, n in ops:
        if op in ("goal", "temporary"):
            set_goal(a, op == "temporary")
            task = a if op == "goal" else task
        elif op == "again":
            ref.start_again(reverse_walk_factor=a)
            V.vb_start_again(vpar, vfst, vist, 0, math.nan if a is None else float(a))
        elif op == "excursion":
            set_goal(a, True)
            steps(n)
            set_goal(task, False)
            n = 1 + n % 7
        steps(n)
        assert ref.mode == vist[0, V.VI_MODE] and ref.side == vist[0, V.VI_SIDE], (op, a, n)
        assert ref.temporary == bool(vist[0, V.VI_TEMP])
        sus = ref.suspended_goal_xy
        assert (sus is None) == (vist[0, V.VI_HAS_SUS] == 0)
        if sus is not None:
            assert tuple(sus) == (vfst[0, V.VF_SUS + V.VF_GX], vfst[0, V.VF_SUS + V.VF_GY])
        assert (ref.hit_xy is None) == (vist[0, V.VI_HAS_HIT] == 0)
        assert ref.hit_dist_m == vfst[0, V.VF_HIT_D]
        assert (ref._reverse_for is None) == (vist[0, V.VI_HAS_RF] == 0)
        assert ref._reverse_limit_m == vfst[0, V.VF_REV_LIMIT]
