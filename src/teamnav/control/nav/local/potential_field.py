"""The standard potential field: algorithm A = 1 of Sgorbissa & Arkin §6.

Sgorbissa & Arkin §6 run R1 with "a standard potential field algorithm", which "does not
guarantee the robot to reach its target without the help of other robots because of the
presence of local minima in the potential fields" (Koren & Borenstein 1991, their [6]). Their
simulator is MissionLab, whose navigation is Arkin's motor schemas (Arkin 1989, "Motor
schema-based mobile robot navigation", IJRR 8(4), their [1]); this module follows those
schemas, with the obstacles being the points of an omnidirectional range scan:

- *move-to-goal*: a vector of constant magnitude ``attraction_gain`` towards the goal;
- *avoid-static-obstacle*, for every beam that returned a point at distance ``d`` from the
  robot's centre: a vector pointing from the point to the robot, of magnitude

  - 0 when ``d > S`` (outside the sphere of influence ``S = R + influence_m``),
  - ``repulsion_gain · (S − d) / (S − R)`` when ``R < d ≤ S``,
  - ``INSIDE_GAIN · repulsion_gain`` (standing for Arkin's infinity) when ``d ≤ R``,

  where ``R = radius_m + safety_margin_m``. Arkin's obstacles are discrete circles; a scan
  returns many points per wall, so each beam is weighted by the angle it stands for,
  ``2π / n_beams`` (a gap we fill: the field of a wall then does not depend on the beam count).

The heading of the next step is the angle of the sum. There is **no escape heuristic**: the
only randomness is a perturbation of relative size ``perturbation`` (default 1e-6) added to the
sum so that an exactly symmetric situation (a zero vector) still gives a heading. With fixed
steps a robot in a local minimum oscillates around it by about one step for ever; that is the
failure §6 reports ("potential field alone fails"). A collision guard
(:func:`~teamnav.control.nav.local.base.safe_heading`) removes headings whose step would come
closer than ``radius_m + guard_margin_m`` to a sensed point; it never adds a new way out.

``progressing`` (§5 "Evaluate my progress") is
:class:`~teamnav.control.nav.local.base.ProgressMonitor`: True while the distance to the goal
has beaten its best-so-far reference for this goal by at least ``progress_fraction`` of a step
within the last ``progress_window_steps`` steps. In a local minimum it turns False after
``progress_window_steps`` steps.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from teamnav.control.nav.local.base import (
    GOAL_SAME_TOL_M,
    ProgressMonitor,
    check_goal,
    check_pose,
    check_scan,
    safe_heading,
    scan_points,
)
from teamnav.control.paper_rules import paper_rules_validator
from teamnav.control.types import RangeScan

__all__ = ["INSIDE_GAIN", "PotentialField", "PotentialFieldParams", "field_vector"]

#: Magnitude (relative to ``repulsion_gain``) of a point inside the safety radius: Arkin's ∞.
INSIDE_GAIN: float = 1000.0


class PotentialFieldParams(BaseModel):
    """Parameters of the potential field (units in the names; module docstring gives the law).

    Attributes
    ----------
    attraction_gain : float, default 1.0
        Magnitude of move-to-goal.
    repulsion_gain : float, default 1.0
        Avoid-obstacle magnitude per radian of scan at the safety radius.
    influence_m : float, default 1.0
        Sphere of influence beyond the safety radius [m].
    safety_margin_m : float, default 0.1
        Safety radius ``R`` = robot radius + this [m].
    guard_margin_m : float, default 0.03
        The collision guard keeps each step this far beyond the robot's radius from sensed points [m].
    perturbation : float, default 1e-6
        Relative size of the random symmetry-breaking perturbation of the sum.
    progress_window_steps : int, default 30
        Steps without beating the reference distance before ``progressing`` turns False.
    progress_fraction : float, default 0.5
        Least improvement of the reference distance that counts, as a fraction of a step.
    paper_rules : bool, default False
        Every gap-fill of :attr:`PAPER_RULES` at its paper value
        (:mod:`teamnav.control.paper_rules`). The potential field has none (Arkin's schemas as
        written); Avoid-Past's subclass adds its own.
    """

    #: Gap-fills whose other value is the paper's rule: none here (see AvoidPastParams).
    PAPER_RULES: ClassVar[dict[str, Any]] = {}
    PAPER_RULE_NOTES: ClassVar[dict[str, str]] = {}

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    attraction_gain: float = Field(1.0, gt=0.0, le=100.0)
    repulsion_gain: float = Field(1.0, ge=0.0, le=1000.0)
    influence_m: float = Field(1.0, gt=0.0, le=20.0)
    safety_margin_m: float = Field(0.1, ge=0.0, le=2.0)
    guard_margin_m: float = Field(0.03, ge=0.0, le=1.0)
    perturbation: float = Field(1e-6, ge=0.0, le=0.1)
    progress_window_steps: int = Field(30, ge=1, le=100_000)
    progress_fraction: float = Field(0.5, gt=0.0, le=10.0)
    paper_rules: bool = False

    _paper_rules = paper_rules_validator()


def field_vector(pose: np.ndarray, goal_xy: np.ndarray, points: np.ndarray, n_beams: int,
                 params: PotentialFieldParams, radius_m: float) -> np.ndarray:
    """Move-to-goal plus avoid-static-obstacle (Arkin 1989) at ``pose``; shape (2,), own frame.

    Parameters
    ----------
    pose : ndarray of shape (3,)
    goal_xy : ndarray of shape (2,)
    points : ndarray of shape (K, 2)
        Sensed obstacle points (:func:`~teamnav.control.nav.local.base.scan_points`).
    n_beams : int
        Beams of the scan (each point stands for ``2π / n_beams`` rad).
    params : PotentialFieldParams
    radius_m : float
        Robot radius.

    Examples
    --------
    >>> p = PotentialFieldParams()
    >>> field_vector(np.zeros(3), np.array([3.0, 4.0]), np.zeros((0, 2)), 72, p, 0.25).tolist()
    [0.6, 0.8]
    """
    # speed: the attraction on floats (the same IEEE operations per component as the array
    # expression ``gain * (goal - xy) / dist``), one array at the end
    t0 = float(goal_xy[0]) - float(pose[0])
    t1 = float(goal_xy[1]) - float(pose[1])
    dist = math.hypot(t0, t1)
    gain = params.attraction_gain
    v0, v1 = (gain * t0 / dist, gain * t1 / dist) if dist > 0.0 else (0.0, 0.0)
    if points.shape[0]:
        r_safe = radius_m + params.safety_margin_m
        s_inf = r_safe + params.influence_m
        pts = np.asarray(points, dtype=np.float64)
        coef, away = _repulsion_terms(float(pose[0]), float(pose[1]), pts[:, 0], pts[:, 1], r_safe, s_inf,
                                      params.repulsion_gain * 2.0 * math.pi / max(n_beams, 1))
        rep = coef @ away  # numpy's matmul (its summation order), as before
        v0, v1 = v0 + float(rep[0]), v1 + float(rep[1])
    return np.array((v0, v1))


@njit(cache=True)
def _repulsion_terms(x, y, px, py, r_safe, s_inf, scale):
    """The per-point terms of avoid-static-obstacle (numba): ``away = (x, y) − point`` and its
    weight ``mag / max(d, 1e-9)`` (``mag`` as in :func:`field_vector`), so that the field's
    repulsion is ``weight @ away``; the same operations per point as the numpy version."""
    n = px.shape[0]
    coef = np.empty(n)
    away = np.empty((n, 2))
    for k in range(n):
        ax = x - px[k]
        ay = y - py[k]
        away[k, 0] = ax
        away[k, 1] = ay
        d = math.hypot(ax, ay)
        if d > s_inf:
            mag = 0.0
        elif d <= r_safe:
            mag = INSIDE_GAIN
        else:
            mag = (s_inf - d) / (s_inf - r_safe)
        mag = mag * scale
        dm = d if d > 1e-9 or d != d else 1e-9
        coef[k] = mag / dm
    return coef, away


def _field_vector_numpy(pose: np.ndarray, goal_xy: np.ndarray, points: np.ndarray, n_beams: int,
                        params: PotentialFieldParams, radius_m: float) -> np.ndarray:
    """The numpy :func:`field_vector` (kept for the equivalence tests and the benchmark)."""
    to_goal = goal_xy - pose[:2]
    dist = math.hypot(to_goal[0], to_goal[1])
    v = params.attraction_gain * to_goal / dist if dist > 0.0 else np.zeros(2)
    if points.shape[0]:
        r_safe = radius_m + params.safety_margin_m
        s_inf = r_safe + params.influence_m
        away = pose[:2] - points
        d = np.hypot(away[:, 0], away[:, 1])
        mag = np.where(d <= r_safe, INSIDE_GAIN, (s_inf - d) / (s_inf - r_safe))
        mag = np.where(d > s_inf, 0.0, mag) * (params.repulsion_gain * 2.0 * math.pi / max(n_beams, 1))
        v = v + (mag / np.maximum(d, 1e-9)) @ away
    return v


class PotentialField:
    """Potential-field local navigator (Sgorbissa & Arkin §6, algorithm 1).

    Parameters
    ----------
    params : PotentialFieldParams
    rng : numpy.random.Generator
        For the symmetry-breaking perturbation only.
    step_length_m : float
        Length of one motion step [m].
    radius_m : float
        Robot radius [m].

    Examples
    --------
    >>> nav = PotentialField(PotentialFieldParams(), np.random.default_rng(0), 0.1, 0.25)
    >>> nav.set_goal(np.array([0.0, 2.0]))
    >>> scan = RangeScan(np.full(72, 4.0), np.linspace(-np.pi, np.pi, 72, endpoint=False), 4.0)
    >>> round(nav.direction(np.array([0.0, 0.0, 1.0]), scan), 4), nav.progressing
    (1.5708, True)
    """

    name = "potential_field"
    Params = PotentialFieldParams

    def __init__(self, params: PotentialFieldParams, rng: np.random.Generator, step_length_m: float,
                 radius_m: float) -> None:
        self.params = params
        self.rng = rng
        self.step_length_m = float(step_length_m)
        self.radius_m = float(radius_m)
        self.goal_xy: np.ndarray | None = None
        self.temporary = False
        self._monitor = ProgressMonitor(params.progress_window_steps, params.progress_fraction, self.step_length_m)

    # ------------------------------------------------------------------ protocol
    def set_goal(self, goal_xy: np.ndarray, temporary: bool = False) -> None:
        """Set the goal (own frame); a different goal restarts the progress estimate.

        ``temporary`` is recorded (:attr:`temporary`) and otherwise changes nothing: the field
        has no memory of a goal to keep across an excursion (Sgorbissa & Arkin Fig. 9: back on
        its own goal the robot simply descends the field again from where it stands).
        Avoid-Past (a subclass) overrides ``_new_goal``: its memory of visited places is kept
        for the robot's life with ``memory_scope="robot"`` (the default) and forgotten at a new
        goal of the robot's own (not a temporary one) with ``memory_scope="goal"``.
        """
        g = check_goal(goal_xy)
        self.temporary = bool(temporary)
        if self.goal_xy is not None and math.hypot(*(g - self.goal_xy)) <= GOAL_SAME_TOL_M:
            return
        self.goal_xy = g
        self._new_goal()

    def direction(self, pose: np.ndarray, scan: RangeScan) -> float | None:
        """Angle of the field's sum at ``pose`` (guarded against collisions); None without a goal."""
        pose = check_pose(pose)
        scan = check_scan(scan)
        if self.goal_xy is None:
            return None
        g = self.goal_xy  # on scalars: the same subtractions as the arrays' (speed)
        self._monitor.update(math.hypot(g[0] - pose[0], g[1] - pose[1]))
        points = scan_points(pose, scan)
        v = self._vector(pose, points, len(scan.ranges_m))
        v0, v1 = float(v[0]), float(v[1])
        scale = max(math.hypot(v0, v1), self.params.attraction_gain)
        k = self.params.perturbation * scale
        noise = self.rng.standard_normal(2)
        # v + k · noise, on floats (the same two additions as the array expression)
        heading = math.atan2(v1 + k * float(noise[1]), v0 + k * float(noise[0]))
        return safe_heading(heading, pose[:2], points, self.step_length_m, self.radius_m + self.params.guard_margin_m)

    @property
    def progressing(self) -> bool:
        """Distance to the goal beat its reference within the window (see module docstring)."""
        return self._monitor.progressing

    # ------------------------------------------------------------------ hooks for subclasses
    def _new_goal(self) -> None:
        self._monitor.reset()

    def _vector(self, pose: np.ndarray, points: np.ndarray, n_beams: int) -> np.ndarray:
        assert self.goal_xy is not None
        return field_vector(pose, self.goal_xy, points, n_beams, self.params, self.radius_m)
