"""Potential field plus Avoid-Past: algorithm A = 2 of Sgorbissa & Arkin §6.

Sgorbissa & Arkin §6 run "a potential field algorithm to which the Avoid Past schema [17] has
been added" (Balch & Arkin 1993, "Avoiding the past: a simple but effective strategy for
reactive navigation", ICRA, pp. 678-685). Balch & Arkin add "a local spatial memory [that]
allows a robot to avoid areas that have already been visited", implemented "within a
schema-based motor control model", as a solution to box canyons (their abstract, the only
part of the paper the reference search found, 2026-11-23: no MissionLab or TeamBots source of
an avoid-past schema was found either). The grid of visit counts, the repulsion law, its
saturation and the memory's lifetime below are therefore our reading of that description,
with our own choices marked.

Here:

- memory: a grid of square cells of side ``cell_m`` in the robot's **own odometry frame**
  (a dict keyed by cell index, so it grows with the explored area); every :meth:`direction`
  call adds the step length to the cell under the robot (a visit weighs the path it stands
  for, so the law below does not change with the step length);
- lifetime (``memory_scope``): ``"robot"`` (the default since 2026-11-27) keeps one memory for
  the robot's whole life, decayed by ``memory_half_life_steps`` (None: lifelong). Neither
  Sgorbissa & Arkin nor the abstract of Balch & Arkin (the only part of [17] found, again on
  2026-11-29: the full text is in no reachable source) says whether the memory is reset at a
  new goal or decays, so the lifetime is a fill, not the paper's rule (an earlier version of
  this docstring cited Balch & Arkin for "visits never decay": that citation had no source). ``"goal"`` (the default from
  2b5e0ce (2026-11-23) to bdfa8a8 (2026-11-27), a gap-fill measured only at the old 1500 / 2500-step budgets) forgets
  the visits when the robot is given a new goal of its own (not a temporary one: an
  excursion to a teammate or a ghost, Sgorbissa & Arkin §3-§5, keeps the memory, and so does
  the way back to the same goal), so that the robot avoids *this* trip's past. Why it was
  chosen then (2b5e0ce, traced): with ``"robot"`` the
  counts of the corridors grow with every target of a 200-target task and the vector below
  is linear in the counts, so after a few targets any asymmetry of the well-trodden corridor
  saturates the push (office_simple, task 1: the unsaturated magnitude's median 1.4 over the
  first 300 steps, 2.2 over the last 1500, saturated in 54 % of those steps with 1153 m of
  path in memory) and the memory, not the goal, steers: R1 was pushed from the corridor
  into rooms N4/N5/S5 for 1500 steps without entering S4's door 1.5 m from where it stood.
  With ``"goal"``: 28 % saturated, 12 m of path in memory over the same task's last 1500
  steps;
- decay (``memory_half_life_steps``; a fill, the same in both columns since 2026-11-29): the
  full section of 2026-11-27 (docs/report/los-help.md) ran the paper's lifelong memory at
  today's budgets (6000 / 12000 steps per target): R1 alone finished 0 of 5 200-target tasks on
  either map (19 and 34 targets reached on average), so the planned fallback (decay as a declared gap-fill) applies. The
  half-life was chosen by a rule fixed before its runs (sweep ``los-avoid-past-half-life``,
  commit of the sweep file): *the shortest of 125, 250, 500, 1000, 2000, 4000 navigator steps
  with which R1 alone finishes every one of tuning tasks 1001-1005 on office_simple*, no task
  of the tables. Measured (steps per target, tasks finished of 5): no decay 0/5 (12-42
  targets reached); 125: 284 5/5; 250: 330 5/5; 500: 409 4/5; 1000: 515 4/5; 2000: 672 3/5;
  4000: 725 1/5. So 125 (the grid's shortest: shorter ones were not tried; the trend says a
  longer memory only costs steps on these tasks). It is a short memory (25 m of path at half
  weight, at 0.2 m a step), closer to the old per-goal reset than to the lifelong one. That
  grid never bracketed its choice, and ran the teamnav column's R1; the rule of 2026-11-29
  (:data:`teamnav.papers.los_help.tasks.HALF_LIFE_RULE`, commit f9f094e, before its runs)
  replaces it: *the longest half-life of 16, 32, 64, 125, 250, 500, 1000, 2000, 4000 steps
  with which R1 alone, with the paper column's settings, finishes every tuning task
  1001-1005 on office_simple* (the paper's own precondition, Table 1: R1 alone finishes, in
  554.2 steps; the reading nearest the literal lifelong memory that meets it; a value fails
  at its first task not finished). Measured (sweep ``los-avoid-past-half-life``, 200 targets,
  6000 steps per target at most, steps per target): 4000 and 2000 fail on task 1001 (58 and
  57 targets reached); 1000 finishes 5/5, 555 / 520 / 546 / 565 / 538 (mean 545); so
  **1000** (an inner point: 2000 above fails, the grid goes on below), the default since then
  in both columns (200 m of path at half weight). Below it, for the record: 64 finishes 5/5
  (342 / 320 / 351 / 342 / 350, mean 341); 32 and 16 fail on task 1001 (95 and 11 targets):
  a very short memory degenerates to the plain potential field, trapped in the first local
  minimum it meets (Sgorbissa & Arkin §6's algorithm 1, which "does not guarantee the robot
  to reach its target"). The lifelong and reset-per-goal readings are the section's
  ablation rows (``docs/report/los-help.md``);
- avoid-past vector: ``avoid_gain_per_m · Σ_c n_c · (1 − d_c / memory_radius_m) · (x − c) / d_c``
  over the cells ``c`` whose centre is within ``memory_radius_m`` of the robot (``n_c`` metres
  of path in the cell, ``d_c`` distance from the cell centre to the robot ``x``): a discrete,
  distance-weighted estimate of minus the gradient of the visit density, so that a box canyon
  fills up with visits until the robot is pushed out of it (the linear distance weighting is
  our choice). The vector grows with the counts until its magnitude reaches ``avoid_max``
  (our choice, default twice the move-to-goal gain): enough to outweigh move-to-goal so that
  the trap is left given time, never so much that it pins the robot against a wall
  (unbounded, it would outgrow avoid-static-obstacle, which we measured trapping the robot on
  the cup's inner wall; Balch's own TeamBots ``v_Avoid_va`` bounds avoid-obstacle the same
  way, returning the largest term's magnitude in 0..1 instead of the sum, because a wall of
  many returns was too repulsive);
- the rest (move-to-goal, avoid-static-obstacle, collision guard, progress estimate) is the
  potential field of :mod:`teamnav.control.nav.local.potential_field` with the same parameters.

Defaults, measured (R1 alone, ``los-help-*`` scenarios, per-target budgets 1500 / 2500 steps,
tasks finished and mean steps per target): ``"robot"``, 2 m (the old default): 40-target
prefixes 0/5 on office_simple (4 to 14 targets reached) and 0/5 on office_complex (11 to 23);
``"robot"``, 3 m: 0/5 simple. ``"goal"``, 2 m: 5/5 simple, 2/5 complex (R1 pinned on room 1's
east wall 5 m from the door, the push reaching 2 m into a room 8 m wide); ``"goal"``, 3 m
(the default): 5/5 and 5/5 (steps per target 171-221 simple, 278-386 complex);
3 m with ``avoid_max`` 1.5: 4/5 simple; 4 m: 3/5 simple with ``avoid_max`` 2, 4/5 on both maps
with 1.5 (40-target prefixes; ``avoid_max`` 3 or 5 lost tasks on office_complex with 2-4 m).
Full 200-target tasks with the default, R1 alone: office_simple 5/5, 210 / 231 / 208 / 224 / 222
steps per target (Table 1: 554.2); office_complex 4/5, 333 / 338 / 281 / 301 on the four
finished (Table 2: 1132.2); task 4 gives up on its 174th target (room 1 -> room 3: ~1800 steps
to leave room 1, whose door is 5 m west of the wall facing the goal, then pushed from the
vertical corridor back into room 2 by its own visits). Paired on that task, ``avoid_gain_per_m``
2, ``memory_radius_m`` 3.5 or ``cell_m`` 0.2 give up sooner (targets 128, 27, 46).
With helpers (goal sharing, the nested teams of ``los_tasks.team_routes``, 5 tasks x 40
targets, mean steps per target over the finished tasks): office_simple R1 200 (5/5), R1+R2 234
(5/5), R1..3 227 (5/5), R1..4 190 (5/5); office_complex 310 (5/5), 321 (5/5), 316 (5/5), 309
(4/5). The helpers barely help here, unlike Tables 1-2 (554 -> 257, 1132 -> 683): R1 alone
already needs fewer steps than the paper's R1..R4. Forgetting the memory at every goal change
(excursions included) or at a ghost reached without the goal in sight (§4.2 "start again")
gave R1+R2 on office_simple 225 and 239 (paired, within the task-to-task spread): not kept.
Where the R1+R2 steps come from (041ed99, H7ap2, office_simple, 5 tasks x 40 targets, seed 0,
per target paired with R1 alone): the 136 targets without an excursion cost the same (180 vs
178 steps); the 64 with one (R1 followed a teammate or a ghost) cost 245 alone and 354 with R2,
but 276 of those 354 are spent *before* the first excursion (the helper reports only once R1
has wandered long enough for it to see the goal: a selection, not the excursion's cost);
excursions are 27 steps per target, own-goal steps after the first one 50, R1 within 0.8 m of R2 in 1 %
of the steps. The whole gap is the seed: R1 alone seeds 0 / 1 / 2 give 200 / 215 / 233 steps
per target, R1+R2 234 / 220 / 228 (means 216 vs 228; per-task spread across seeds up to 50
steps). Not recording visits during excursions (R1+R2, seed 0): 234 -> 234: not kept.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar, Literal

import numpy as np
from numba import njit
from pydantic import Field

from teamnav.control.nav.local.base import GOAL_SAME_TOL_M
from teamnav.control.nav.local.potential_field import PotentialField, PotentialFieldParams

__all__ = ["AvoidPast", "AvoidPastParams", "avoid_past_vector"]


class AvoidPastParams(PotentialFieldParams):
    """Potential-field parameters plus the avoid-past schema's (Balch & Arkin 1993).

    Attributes
    ----------
    cell_m : float, default 0.3
        Side of a memory cell [m].
    memory_radius_m : float, default 3.0
        Cells within this distance of the robot push it [m] (was 2.0: see the module
        docstring's measurements).
    avoid_gain_per_m : float, default 1.0
        Avoid-past magnitude per metre of path in a cell next to the robot (1.0 is 0.1 per
        visit with 0.1 m steps).
    avoid_max : float, default 2.0
        Largest avoid-past magnitude (saturation; see the module docstring).
    memory_scope : {"robot", "goal"}, default "robot"
        Lifetime of the memory: kept for the robot's life (with ``memory_half_life_steps``
        None: lifelong, the literal reading), or forgotten at each new goal of the robot's own,
        temporary goals keeping it ("reset per goal", the default from 2026-11-23 to 2026-11-27; see
        the module docstring). A fill, the same in both columns: neither Sgorbissa & Arkin nor
        the abstract of Balch & Arkin 1993 (all of it that was found) says how long the memory
        lasts.
    memory_half_life_steps : float or None, default 1000.0
        Decay of the memory (a fill, the same in both columns; None: no decay): a visit's weight
        halves every ``memory_half_life_steps`` navigator steps (calls of :meth:`direction`).
        Stored as visits inflated by ``2^(t / h)`` and a push deflated by the same factor, so a
        step stays O(cells near the robot). How its value was chosen: see the module docstring.
    """

    #: None: the memory's lifetime is a silence of Sgorbissa & Arkin (§6 names only "the Avoid
    #: Past schema [17]") and of the part of [17] found (its abstract), so it is a fill, the same
    #: in both columns (``memory_scope``, ``memory_half_life_steps``; see the module docstring).
    PAPER_RULES: ClassVar[dict[str, Any]] = {}
    PAPER_RULE_NOTES: ClassVar[dict[str, str]] = {}

    cell_m: float = Field(0.3, gt=0.0, le=10.0)
    memory_radius_m: float = Field(3.0, gt=0.0, le=50.0)
    avoid_gain_per_m: float = Field(1.0, ge=0.0, le=1000.0)
    avoid_max: float = Field(2.0, ge=0.0, le=1000.0)
    memory_scope: Literal["goal", "robot"] = "robot"
    memory_half_life_steps: float | None = Field(1000.0, gt=0.0)


def avoid_past_vector(xy: np.ndarray, visits: dict[tuple[int, int], float], cell_m: float,
                      memory_radius_m: float, avoid_gain_per_m: float, avoid_max: float = math.inf) -> np.ndarray:
    """The avoid-past schema's vector at ``xy`` (own frame), shape (2,).

    Examples
    --------
    >>> v = avoid_past_vector(np.array([0.25, 0.25]), {(0, 0): 10.0}, 0.5, 1.0, 0.1)
    >>> v.round(6).tolist()   # the visited cell is centred under the robot: no push
    [0.0, 0.0]
    >>> avoid_past_vector(np.array([1.0, 0.25]), {(0, 0): 10.0}, 0.5, 1.0, 0.1).round(6).tolist()
    [0.25, 0.0]
    """
    k = int(math.ceil(memory_radius_m / cell_m)) + 1
    ci, cj = int(math.floor(xy[0] / cell_m)), int(math.floor(xy[1] / cell_m))
    cells = [(i, j, n) for i in range(ci - k, ci + k + 1) for j in range(cj - k, cj + k + 1)
             if (n := visits.get((i, j), 0.0)) > 0.0]
    if not cells:
        return np.zeros(2)
    return _vector_of_cells(xy, np.asarray(cells, dtype=np.float64), cell_m, memory_radius_m, avoid_gain_per_m,
                            avoid_max)


def _vector_of_cells(xy: np.ndarray, arr: np.ndarray, cell_m: float, memory_radius_m: float,
                     avoid_gain_per_m: float, avoid_max: float) -> np.ndarray:
    """:func:`avoid_past_vector` from the visited cells near ``xy``: rows (i, j, metres), in
    row-major order (i, then j)."""
    away = xy - (arr[:, :2] + 0.5) * cell_m
    d = np.hypot(away[:, 0], away[:, 1])
    w = np.where((d < memory_radius_m) & (d > 1e-12), arr[:, 2] * (1.0 - d / memory_radius_m), 0.0)
    v = avoid_gain_per_m * ((w / np.maximum(d, 1e-12)) @ away)
    norm = math.hypot(v[0], v[1])
    return v * (avoid_max / norm) if norm > avoid_max else v


class _VisitGrid:
    """A dense mirror of ``AvoidPast.visits`` (speed only, H7a): the same metres per cell in an
    array that grows as the robot explores, so the cells near the robot are one window
    (:func:`_avoid_terms`), not (2k + 1)² dictionary look-ups; the window's visited cells are
    :func:`avoid_past_vector`'s ``cells`` (same order, same values)."""

    _PAD = 32

    def __init__(self) -> None:
        self.grid = np.zeros((0, 0))
        self.i0 = self.j0 = 0

    def set(self, i: int, j: int, value: float) -> None:
        gi, gj = i - self.i0, j - self.j0
        h, w = self.grid.shape
        if not (0 <= gi < h and 0 <= gj < w):
            pad = self._PAD
            lo_i, lo_j = min(i - pad, self.i0), min(j - pad, self.j0)
            hi_i = max(i + pad + 1, self.i0 + h) if h else i + pad + 1
            hi_j = max(j + pad + 1, self.j0 + w) if w else j + pad + 1
            if not h:
                lo_i, lo_j = i - pad, j - pad
            grid = np.zeros((hi_i - lo_i, hi_j - lo_j))
            if h:
                grid[self.i0 - lo_i:self.i0 - lo_i + h, self.j0 - lo_j:self.j0 - lo_j + w] = self.grid
            self.grid, self.i0, self.j0 = grid, lo_i, lo_j
            gi, gj = i - self.i0, j - self.j0
        self.grid[gi, gj] = value


class AvoidPast(PotentialField):
    """Potential field with the avoid-past schema (Sgorbissa & Arkin §6, algorithm 2).

    Same constructor and protocol as :class:`~teamnav.control.nav.local.potential_field.PotentialField`;
    ``visits`` is the robot's memory (cell index in the own frame -> metres of path in the cell);
    with ``memory_scope="robot"`` (the default) it is kept for the robot's life; with
    ``memory_scope="goal"`` a new goal of the robot's own (``temporary=False``, farther than
    ``GOAL_SAME_TOL_M`` from the last one) starts an empty memory. With a half-life
    (``memory_half_life_steps``, the default 1000) the stored metres are inflated by
    ``2^(t / h)`` (see the Params); without one (None, lifelong) they are the metres walked:

    Examples
    --------
    >>> from teamnav.control.types import RangeScan
    >>> nav = AvoidPast(AvoidPastParams(memory_half_life_steps=None), np.random.default_rng(0), 0.1, 0.25)
    >>> nav.set_goal(np.array([2.15, 0.15]))
    >>> scan = RangeScan(np.full(72, 4.0), np.linspace(-np.pi, np.pi, 72, endpoint=False), 4.0)
    >>> abs(round(nav.direction(np.array([0.15, 0.15, 0.0]), scan), 3)), nav.visits   # at a cell centre
    (0.0, {(0, 0): 0.1})
    """

    name = "avoid_past"
    Params = AvoidPastParams

    def __init__(self, params: AvoidPastParams, rng: np.random.Generator, step_length_m: float,
                 radius_m: float) -> None:
        super().__init__(params, rng, step_length_m, radius_m)
        self.visits: dict[tuple[int, int], float] = {}
        self._grid = _VisitGrid()
        self._grid_of: dict | None = None
        self._grid_len = 0
        self._own_goal: np.ndarray | None = None
        #: decay (``memory_half_life_steps``): steps since ``visits`` were last rescaled
        self._decay_t = 0

    def _new_goal(self) -> None:
        """Restart the progress estimate; with ``memory_scope="goal"`` forget the visits when the
        robot's own goal changed (an excursion to a temporary goal and back keeps them)."""
        super()._new_goal()
        p: AvoidPastParams = self.params  # type: ignore[assignment]
        if self.temporary:
            return
        g = self.goal_xy
        if (p.memory_scope == "goal" and self._own_goal is not None
                and math.hypot(g[0] - self._own_goal[0], g[1] - self._own_goal[1]) > GOAL_SAME_TOL_M):
            self.visits = {}
            self._decay_t = 0
        self._own_goal = g.copy()

    def _vector(self, pose: np.ndarray, points: np.ndarray, n_beams: int) -> np.ndarray:
        p: AvoidPastParams = self.params  # type: ignore[assignment]
        key = (int(math.floor(pose[0] / p.cell_m)), int(math.floor(pose[1] / p.cell_m)))
        # speed (H7a): the cells near the robot come from a dense mirror of ``visits`` (rebuilt
        # when ``visits`` was replaced or changed size behind its back): the same rows as
        # avoid_past_vector's dictionary walk, so the same vector to the bit
        h = p.memory_half_life_steps
        inflate = 1.0
        if h is not None:
            # decay as inflation: a visit deposited at step t weighs 2^(t/h); the push below is
            # deflated by 2^(-t/h), so every visit weighs 2^(-(now - then)/h) (rescaled before overflow)
            self._decay_t += 1
            if self._decay_t > 500.0 * h:
                f = 2.0 ** (-self._decay_t / h)
                self.visits = {c: n * f for c, n in self.visits.items()}
                self._decay_t = 0
            inflate = 2.0 ** (self._decay_t / h)
        stale = self._grid_of is not self.visits or self._grid_len != len(self.visits)
        self.visits[key] = self.visits.get(key, 0.0) + (self.step_length_m if h is None else self.step_length_m * inflate)
        v = super()._vector(pose, points, n_beams)
        if stale:
            self._grid, self._grid_of = _VisitGrid(), self.visits
            for (i, j), n in self.visits.items():
                self._grid.set(i, j, n)
        else:
            self._grid.set(key[0], key[1], self.visits[key])
        self._grid_len = len(self.visits)
        k = int(math.ceil(p.memory_radius_m / p.cell_m)) + 1
        xy = pose[:2]
        g = self._grid
        coef, away = _avoid_terms(g.grid, g.i0, g.j0, int(math.floor(xy[0] / p.cell_m)),
                                  int(math.floor(xy[1] / p.cell_m)), k, float(xy[0]), float(xy[1]), p.cell_m,
                                  p.memory_radius_m)
        v0, v1 = float(v[0]), float(v[1])
        if not coef.shape[0]:
            return np.array((v0 + 0.0, v1 + 0.0))  # v + np.zeros(2)
        rep = coef @ away  # numpy's matmul, as _vector_of_cells
        # the rest on floats, the same operations per component as the array expressions
        # ``va = gain * rep``, ``v + (va * (max / norm) if norm > max else va)``
        va0, va1 = p.avoid_gain_per_m * float(rep[0]), p.avoid_gain_per_m * float(rep[1])
        if h is not None:
            va0, va1 = va0 / inflate, va1 / inflate
        norm = math.hypot(va0, va1)
        if norm > p.avoid_max:
            f = p.avoid_max / norm
            va0, va1 = va0 * f, va1 * f
        return np.array((v0 + va0, v1 + va1))


@njit(cache=True)
def _avoid_terms(grid, i0, j0, ci, cj, k, x, y, cell_m, memory_radius_m):
    """The visited cells within ``k`` cells of (ci, cj), row-major, as :func:`_vector_of_cells`
    weighs them (numba): ``away = xy − (cell + 0.5)·cell_m`` and its weight
    ``w / max(d, 1e-12)``, ``w = n (1 − d / R)`` for ``1e-12 < d < R``, else 0."""
    h, w = grid.shape
    a0 = max(ci - k - i0, 0)
    a1 = min(ci + k + 1 - i0, h)
    b0 = max(cj - k - j0, 0)
    b1 = min(cj + k + 1 - j0, w)
    m = 0
    for a in range(a0, a1):
        for b in range(b0, b1):
            if grid[a, b] > 0.0:
                m += 1
    coef = np.empty(m)
    away = np.empty((m, 2))
    m = 0
    for a in range(a0, a1):
        for b in range(b0, b1):
            n = grid[a, b]
            if n > 0.0:
                ax = x - (float(a + i0) + 0.5) * cell_m
                ay = y - (float(b + j0) + 0.5) * cell_m
                d = math.hypot(ax, ay)
                wt = n * (1.0 - d / memory_radius_m) if (d < memory_radius_m and d > 1e-12) else 0.0
                coef[m] = wt / (d if d > 1e-12 or d != d else 1e-12)
                away[m, 0] = ax
                away[m, 1] = ay
                m += 1
    return coef, away
