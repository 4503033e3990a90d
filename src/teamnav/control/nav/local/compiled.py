"""The potential field and Avoid-Past (Sgorbissa & Arkin §6, algorithms A = 1 and 2) for many
robots in one compiled call: state as named columns of arrays, one row per robot.

This is the group-brain form (``docs/concepts/group-brains.md``) of
:class:`~teamnav.control.nav.local.potential_field.PotentialField` and
:class:`~teamnav.control.nav.local.avoid_past.AvoidPast`, which stay the readable reference.
The law is theirs, operation for operation, so that a row gives the same bits as the
reference navigator fed the same goals and scans:

- move-to-goal plus avoid-static-obstacle (Arkin 1989, the motor schemas of MissionLab, which
  Sgorbissa & Arkin §6 run), each beam weighted by ``2π / n_beams``
  (:func:`~teamnav.control.nav.local.potential_field.field_vector`, whose numba kernel
  ``_repulsion_terms`` is called here as is);
- Avoid-Past (Balch & Arkin 1993, their [17]): metres of path per cell of side ``cell_m`` in
  the own odometry frame, decayed by ``memory_half_life_steps`` as inflation, pushing within
  ``memory_radius_m`` up to ``avoid_max`` (``_avoid_terms`` as is), forgotten at a new own
  goal with ``memory_scope="goal"``;
- the symmetry-breaking perturbation, the collision guard (``_safe_heading`` as is) and the
  progress estimate of §5 (:class:`~teamnav.control.nav.local.base.ProgressMonitor`).

Where the reference computes in Python, this module computes as Python does:

- ``math.hypot`` on Python floats is CPython's own correctly-rounded-ish algorithm (its
  ``vector_norm``), not libm's ``hypot``, which numba calls: they differ in the last bit for
  about 0.1-0.6 % of arguments. :func:`py_hypot` is CPython 3.11's algorithm (Dekker's exact
  products and a compensated sum, then one Newton correction), written out;
- ``coef @ away`` (numpy's matmul, OpenBLAS's ``dgemv``) is ``np.dot`` here, which numba
  sends to the same BLAS routine (SciPy's OpenBLAS) and so sums in the same order; a loop
  would not (3000 of 3000 random cases differed);
- ``2.0 ** x`` is libm's ``pow`` in Python; with a constant base LLVM rewrites it to ``exp2``
  (another last bit), so the base is read from the parameters at run time;
- ``rng.standard_normal(2)`` per call reads two numbers of a per-robot buffer filled with
  ``rng.standard_normal(NORMALS)`` from the robot's own Generator: numpy's ziggurat draws
  the same sequence in one call as in many (the Generator then stands further on, but the
  navigator is its only reader).

State layout: float columns ``F_*`` of ``fst`` (n, N_F), integer columns ``I_*`` of ``ist``
(n, N_I), parameters ``P_*`` of ``par`` (n, N_P), visit grids ``grid`` (n, H, W) with each
row's origin cell in ``ist[:, I_GI0]``, ``ist[:, I_GJ0]``. Kernels do no validation.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from teamnav.control.nav.local.avoid_past import _avoid_terms
from teamnav.control.nav.local.base import GOAL_SAME_TOL_M, GUARD_STEP_RAD, _safe_heading, _scan_points, pymod
from teamnav.control.nav.local.potential_field import _repulsion_terms

__all__ = ["NORMALS", "nav_params", "new_state", "py_hypot", "py_wrap", "set_goal", "direction", "progressing",
           "visit_cell_outside", "grow_grid"]

#: Normals drawn per refill of a robot's perturbation buffer (even: two per navigator call).
NORMALS = 256

# ----------------------------------------------------------------- parameter columns
P_ATTRACT = 0  # attraction_gain
P_REPULSE = 1  # repulsion_gain
P_INFLUENCE = 2  # influence_m
P_SAFETY = 3  # safety_margin_m
P_GUARD = 4  # guard_margin_m
P_PERTURB = 5  # perturbation
P_WINDOW = 6  # progress_window_steps
P_MIN_GAIN = 7  # progress_fraction * step_length_m (ProgressMonitor.min_gain_m)
P_STEP = 8  # step_length_m
P_RADIUS = 9  # radius_m
P_AVOID = 10  # 1.0: Avoid-Past, 0.0: the plain potential field
P_CELL = 11  # cell_m
P_MEM_R = 12  # memory_radius_m
P_AVOID_GAIN = 13  # avoid_gain_per_m
P_AVOID_MAX = 14  # avoid_max
P_SCOPE_GOAL = 15  # 1.0: memory_scope "goal", 0.0: "robot"
P_HALF_LIFE = 16  # memory_half_life_steps (NaN: None, no decay)
P_K = 17  # int(ceil(memory_radius_m / cell_m)) + 1: the window of cells that push
P_TWO = 18  # 2.0, read at run time: LLVM turns pow(2.0, x) with a constant base into exp2(x),
#            which rounds differently from the libm pow that Python's 2.0 ** x calls
N_P = 19

# ----------------------------------------------------------------- state columns
F_GX = 0  # goal (own frame) [m]
F_GY = 1
F_REF = 2  # ProgressMonitor.ref_m (inf: none yet)
F_OWN_GX = 3  # Avoid-Past's last own (non-temporary) goal
F_OWN_GY = 4
N_F = 5

I_HAS_GOAL = 0  # a goal is set
I_TEMP = 1  # the goal is temporary
I_STEPS = 2  # ProgressMonitor.steps
I_LAST_GAIN = 3  # ProgressMonitor.last_gain_step
I_HAS_OWN = 4  # Avoid-Past has an own goal
I_DECAY_T = 5  # Avoid-Past: steps since the visits were last rescaled
I_GI0 = 6  # visit grid origin (cell indices)
I_GJ0 = 7
I_NORMAL = 8  # next unread normal of the buffer
N_I = 9

_DBL_MIN = 2.2250738585072014e-308
_GUARD_N = int(round(math.pi / GUARD_STEP_RAD))


# ----------------------------------------------------------------- Python's float arithmetic
@njit(cache=True, inline="always")
def _split(x):
    t = x * 134217729.0  # Veltkamp: 2 ** 27 + 1
    hi = t - (t - x)
    return hi, x - hi


@njit(cache=True, inline="always")
def _mul(x, y):
    """Dekker's exact product: (hi, lo) with hi + lo = x · y."""
    xh, xl = _split(x)
    yh, yl = _split(y)
    p = xh * yh
    q = xh * yl + xl * yh
    z = p + q
    return z, p - z + q + xl * yl


@njit(cache=True)
def py_hypot(x, y):
    """``math.hypot(x, y)`` of CPython 3.11 (``Modules/mathmodule.c``, ``vector_norm``), bit for bit.

    Scale by a power of two, square exactly (Dekker), sum with compensation, take the root and
    apply one differential correction. libm's ``hypot`` (what numba's ``math.hypot`` calls)
    rounds differently in the last bit for a fraction of a percent of arguments.
    """
    x = abs(x)
    y = abs(y)
    if math.isinf(x) or math.isinf(y):
        return math.inf
    if x != x or y != y:
        return math.nan
    mx = x if x > y else y
    if mx == 0.0:
        return mx
    _, e = math.frexp(mx)
    mult = 1.0
    if e < -1023:  # subnormal: to normal numbers first (CPython: DBL_MIN * vector_norm(v / DBL_MIN))
        x = x / _DBL_MIN
        y = y / _DBL_MIN
        mx = mx / _DBL_MIN
        mult = _DBL_MIN
        _, e = math.frexp(mx)
    scale = math.ldexp(1.0, -e)
    csum = 1.0
    frac1 = 0.0
    frac2 = 0.0
    for i in range(2):
        v = (x if i == 0 else y) * scale
        ph, pl = _mul(v, v)
        s = csum + ph
        frac2 += (csum - s) + ph
        csum = s
        frac1 += pl
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    ph, pl = _mul(-h, h)
    s = csum + ph
    frac2 += (csum - s) + ph
    csum = s
    frac1 += pl
    h += (csum - 1.0 + (frac1 + frac2)) / (2.0 * h)
    return mult * (h / scale)


_TWO_PI = 2.0 * math.pi


@njit(cache=True)
def py_wrap(a):
    """:func:`~teamnav.control.nav.local.base.wrap_scalar` (Python's float ``%`` is ``pymod``)."""
    if (-math.pi < a and a <= math.pi) or a != a:
        return a
    w = pymod(a + math.pi, _TWO_PI) - math.pi
    if w <= -math.pi:
        w += _TWO_PI
    if w > math.pi:
        w = math.pi
    return w


# ----------------------------------------------------------------- construction (Python)
def nav_params(name: str, params, step_length_m: float, radius_m: float) -> np.ndarray:
    """One row of ``par`` from a navigator's validated Params (``potential_field`` or ``avoid_past``)."""
    p = np.zeros(N_P)
    p[P_ATTRACT] = params.attraction_gain
    p[P_REPULSE] = params.repulsion_gain
    p[P_INFLUENCE] = params.influence_m
    p[P_SAFETY] = params.safety_margin_m
    p[P_GUARD] = params.guard_margin_m
    p[P_PERTURB] = params.perturbation
    p[P_WINDOW] = int(params.progress_window_steps)
    p[P_MIN_GAIN] = float(params.progress_fraction) * float(step_length_m)
    p[P_STEP] = float(step_length_m)
    p[P_TWO] = 2.0
    p[P_RADIUS] = float(radius_m)
    if name == "avoid_past":
        p[P_AVOID] = 1.0
        p[P_CELL] = params.cell_m
        p[P_MEM_R] = params.memory_radius_m
        p[P_AVOID_GAIN] = params.avoid_gain_per_m
        p[P_AVOID_MAX] = params.avoid_max
        p[P_SCOPE_GOAL] = 1.0 if params.memory_scope == "goal" else 0.0
        h = params.memory_half_life_steps
        p[P_HALF_LIFE] = math.nan if h is None else float(h)
        p[P_K] = int(math.ceil(params.memory_radius_m / params.cell_m)) + 1
    elif name != "potential_field":
        raise ValueError(f"compiled navigators: potential_field or avoid_past, got {name!r}")
    return p


def new_state(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(fst, ist, grid, normals)`` of ``n`` navigators without a goal (grids empty, buffers
    empty: :func:`refill_normals` fills them before the first step)."""
    fst = np.zeros((n, N_F))
    fst[:, F_REF] = math.inf
    ist = np.zeros((n, N_I), dtype=np.int64)
    ist[:, I_NORMAL] = NORMALS
    return fst, ist, np.zeros((n, 0, 0)), np.zeros((n, NORMALS))


def refill_normals(ist: np.ndarray, normals: np.ndarray, rngs) -> None:
    """Give every row at least two unread normals (a navigator call reads two), from its own
    Generator, in the order the reference's ``standard_normal(2)`` calls would draw them."""
    low = np.flatnonzero(ist[:, I_NORMAL] > NORMALS - 2)
    for r in low.tolist():
        k = int(ist[r, I_NORMAL])
        left = normals[r, k:].copy()
        normals[r, :left.shape[0]] = left
        normals[r, left.shape[0]:] = rngs[r].standard_normal(NORMALS - left.shape[0])
        ist[r, I_NORMAL] = 0


def grow_grid(grid: np.ndarray, ist: np.ndarray, r: int, ci: int, cj: int, pad: int = 32) -> np.ndarray:
    """The visit grids with row ``r``'s grid extended to hold cell (ci, cj) (``pad`` cells
    around it); every row keeps its cells, only the layout changes (the avoid-past window
    reads visited cells by index, so the values it sums do not depend on the layout)."""
    n, h, w = grid.shape
    i0, j0 = int(ist[r, I_GI0]), int(ist[r, I_GJ0])
    if h == 0:
        lo_i, lo_j, hi_i, hi_j = ci - pad, cj - pad, ci + pad + 1, cj + pad + 1
    else:
        lo_i, lo_j = min(ci - pad, i0), min(cj - pad, j0)
        hi_i, hi_j = max(ci + pad + 1, i0 + h), max(cj + pad + 1, j0 + w)
    h2, w2 = max(h, hi_i - lo_i), max(w, hi_j - lo_j)
    out = np.zeros((n, h2, w2))
    for q in range(n):
        if q == r:
            out[q, i0 - lo_i:i0 - lo_i + h, j0 - lo_j:j0 - lo_j + w] = grid[q]
        else:
            out[q, :h, :w] = grid[q]
    if h == 0:
        for q in range(n):  # empty grids: every row takes the new origin (row r's)
            ist[q, I_GI0], ist[q, I_GJ0] = lo_i, lo_j
    ist[r, I_GI0], ist[r, I_GJ0] = lo_i, lo_j
    return out


# ----------------------------------------------------------------- kernels
@njit(cache=True)
def visit_cell_outside(par, ist, grid, r, px, py):
    """The cell Avoid-Past would add a visit to at (px, py) lies outside row ``r``'s grid:
    (True, ci, cj); else (False, ci, cj). The caller grows the grid before stepping."""
    if par[r, P_AVOID] == 0.0:
        return False, 0, 0
    cell = par[r, P_CELL]
    ci = int(math.floor(px / cell))
    cj = int(math.floor(py / cell))
    gi = ci - ist[r, I_GI0]
    gj = cj - ist[r, I_GJ0]
    return not (0 <= gi < grid.shape[1] and 0 <= gj < grid.shape[2]), ci, cj


@njit(cache=True)
def set_goal(par, fst, ist, grid, r, gx, gy, temporary):
    """``LocalNavigator.set_goal`` of row ``r`` (PotentialField's, with AvoidPast's ``_new_goal``)."""
    ist[r, I_TEMP] = 1 if temporary else 0
    if ist[r, I_HAS_GOAL] == 1 and py_hypot(gx - fst[r, F_GX], gy - fst[r, F_GY]) <= GOAL_SAME_TOL_M:
        return
    fst[r, F_GX] = gx
    fst[r, F_GY] = gy
    ist[r, I_HAS_GOAL] = 1
    # ProgressMonitor.reset
    fst[r, F_REF] = math.inf
    ist[r, I_STEPS] = 0
    ist[r, I_LAST_GAIN] = 0
    if par[r, P_AVOID] == 0.0 or temporary:
        return
    if (par[r, P_SCOPE_GOAL] != 0.0 and ist[r, I_HAS_OWN] == 1
            and py_hypot(gx - fst[r, F_OWN_GX], gy - fst[r, F_OWN_GY]) > GOAL_SAME_TOL_M):
        grid[r, :, :] = 0.0  # visits = {}
        ist[r, I_DECAY_T] = 0
    fst[r, F_OWN_GX] = gx
    fst[r, F_OWN_GY] = gy
    ist[r, I_HAS_OWN] = 1


@njit(cache=True)
def progressing(par, ist, r):
    """``ProgressMonitor.progressing`` of row ``r``."""
    return ist[r, I_STEPS] - 1 - ist[r, I_LAST_GAIN] <= par[r, P_WINDOW]


@njit(cache=True)
def _field(par, fst, r, px, py, pts, n_beams):
    """:func:`~teamnav.control.nav.local.potential_field.field_vector` of row ``r``."""
    t0 = fst[r, F_GX] - px
    t1 = fst[r, F_GY] - py
    dist = py_hypot(t0, t1)
    gain = par[r, P_ATTRACT]
    if dist > 0.0:
        v0 = gain * t0 / dist
        v1 = gain * t1 / dist
    else:
        v0 = 0.0
        v1 = 0.0
    if pts.shape[0]:
        r_safe = par[r, P_RADIUS] + par[r, P_SAFETY]
        s_inf = r_safe + par[r, P_INFLUENCE]
        nb = n_beams if n_beams > 1 else 1
        coef, away = _repulsion_terms(px, py, pts[:, 0], pts[:, 1], r_safe, s_inf,
                                      par[r, P_REPULSE] * 2.0 * math.pi / nb)
        rep = np.dot(coef, away)  # numpy's matmul in the reference: the same BLAS dgemv
        v0 = v0 + rep[0]
        v1 = v1 + rep[1]
    return v0, v1


@njit(cache=True)
def _avoid_past(par, fst, ist, grid, r, px, py, pts, n_beams):
    """``AvoidPast._vector`` of row ``r``: a visit added, the field, then the push of the past.
    The caller has made sure the visited cell is inside the row's grid."""
    cell = par[r, P_CELL]
    ci = int(math.floor(px / cell))
    cj = int(math.floor(py / cell))
    h = par[r, P_HALF_LIFE]
    decays = h == h
    inflate = 1.0
    if decays:
        ist[r, I_DECAY_T] += 1
        if ist[r, I_DECAY_T] > 500.0 * h:
            f = par[r, P_TWO] ** (-ist[r, I_DECAY_T] / h)
            grid[r, :, :] *= f  # {c: n * f}, zeros stay zeros
            ist[r, I_DECAY_T] = 0
        inflate = par[r, P_TWO] ** (ist[r, I_DECAY_T] / h)
    gi = ci - ist[r, I_GI0]
    gj = cj - ist[r, I_GJ0]
    step = par[r, P_STEP]
    grid[r, gi, gj] = grid[r, gi, gj] + (step * inflate if decays else step)
    v0, v1 = _field(par, fst, r, px, py, pts, n_beams)
    coef, away = _avoid_terms(grid[r], ist[r, I_GI0], ist[r, I_GJ0], ci, cj, int(par[r, P_K]), px, py, cell,
                              par[r, P_MEM_R])
    if not coef.shape[0]:
        return v0 + 0.0, v1 + 0.0
    rep = np.dot(coef, away)
    gain = par[r, P_AVOID_GAIN]
    va0 = gain * rep[0]
    va1 = gain * rep[1]
    if decays:
        va0 = va0 / inflate
        va1 = va1 / inflate
    norm = py_hypot(va0, va1)
    amax = par[r, P_AVOID_MAX]
    if norm > amax:
        f = amax / norm
        va0 = va0 * f
        va1 = va1 * f
    return v0 + va0, v1 + va1


@njit(cache=True)
def direction(par, fst, ist, grid, normals, r, px, py, th, ranges, angles, max_range):
    """``LocalNavigator.direction`` of row ``r`` (a goal is set): the wrapped heading of the
    next step [rad, own frame]. Reads two normals of the row's buffer."""
    # ProgressMonitor.update(distance to the goal)
    d = py_hypot(fst[r, F_GX] - px, fst[r, F_GY] - py)
    if fst[r, F_REF] == math.inf:
        fst[r, F_REF] = d
        ist[r, I_LAST_GAIN] = ist[r, I_STEPS]
    elif d < fst[r, F_REF] - par[r, P_MIN_GAIN]:
        fst[r, F_REF] = d
        ist[r, I_LAST_GAIN] = ist[r, I_STEPS]
    ist[r, I_STEPS] += 1
    pts = _scan_points(px, py, th, ranges, angles, max_range * (1.0 - 1e-9))
    n_beams = ranges.shape[0]
    if par[r, P_AVOID] != 0.0:
        v0, v1 = _avoid_past(par, fst, ist, grid, r, px, py, pts, n_beams)
    else:
        v0, v1 = _field(par, fst, r, px, py, pts, n_beams)
    gain = par[r, P_ATTRACT]
    norm = py_hypot(v0, v1)
    scale = gain if gain > norm else norm  # Python's max(norm, gain)
    k = par[r, P_PERTURB] * scale
    j = ist[r, I_NORMAL]
    n0 = normals[r, j]
    n1 = normals[r, j + 1]
    ist[r, I_NORMAL] = j + 2
    heading = math.atan2(v1 + k * n1, v0 + k * n0)
    if pts.shape[0] == 0:
        return py_wrap(heading)
    h = _safe_heading(heading, px, py, pts[:, 0], pts[:, 1], par[r, P_STEP], par[r, P_RADIUS] + par[r, P_GUARD],
                      _GUARD_N, GUARD_STEP_RAD)
    return py_wrap(h)


def _renew_caches() -> None:
    """This module's kernels call the reference's kernels in base, potential_field and
    avoid_past: renew their numba caches when those change (:func:`~teamnav.control.group.renew_stale_caches`)."""
    from teamnav.control.group import renew_module_caches
    from teamnav.control.nav.local import avoid_past, base, potential_field

    renew_module_caches(__name__, (avoid_past, base, potential_field))


_renew_caches()
