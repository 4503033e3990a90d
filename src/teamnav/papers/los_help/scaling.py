"""Teams larger than the paper's: R1 and up to 63 helpers on a larger office (the benchmarks' scaling row).

Sgorbissa & Arkin §6 run a team of four (R1 explorer, R2..R4 helpers) on the simple office of
Fig. 11. Nothing in the rules limits the team: goal sharing (§3-§4), ghosts (§4.3) and state
sharing (§5) are written for robots R1..RM. This module places teams of any size up to 64 on
:func:`~teamnav.papers.los_help.maps.office_simple_grid` (21 wings, each the simple office) by
the section's own rules, so that the cost of a team step can be measured as the team grows
(``benchmarks/bench_los_brains.py``, the scaling row) and the compiled group brain checked
against the reference brains at sizes beyond four (``tests/test_los_scaling.py``).

What is ours (not the paper's; it measures cost, no claim is judged on it)
-------------------------------------------------------------------------
- R1 starts where it starts on Fig. 11 (wing 0's ``base``, heading 90°) and gets exploration
  tasks drawn as :func:`~teamnav.papers.los_help.tasks.task_rooms` draws them (room centres,
  consecutive targets different, SHA-256 counter stream), over the 210 rooms of every wing.
- Helpers are placed wing by wing, three per wing, with the routes and start poses that R2,
  R3 and R4 have on Fig. 11 (``LAYOUTS["simple"]``) moved to the wing: helper ``k`` (0-based)
  is in wing ``k // 3`` with R(``k % 3`` + 2)'s route. A team of four is thus the section's
  R1..R4 in wing 0; a team of 64 has three helpers in every wing, as dense as the paper's team.
- Every robot's body, sensing, radio and parameters are those of ``los-help-simple``
  (:func:`~teamnav.papers.los_help.tasks.scenario_data`); the paper column is every robot at
  ``paper_rules: true``, as in the report's paper column.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np

from teamnav.papers.los_help import tasks as T
from teamnav.papers.los_help.maps import wing_origin

__all__ = ["MAP", "MAX_ROBOTS", "SIZES", "WINGS", "helper_layout", "scenario_data", "task_rooms", "targets_xy"]

#: The larger office (built-in map name), 3 x 7 wings.
MAP = "office_simple_grid"
WINGS = 21
COLS = 3
#: Helpers per wing (Fig. 11's R2..R4).
HELPERS_PER_WING = 3
#: R1 and three helpers in each of the 21 wings.
MAX_ROBOTS = 1 + HELPERS_PER_WING * WINGS
#: The team sizes of the scaling row.
SIZES: tuple[int, ...] = (4, 8, 16, 32, 64)


def _shift(pts, dx: float, dy: float) -> tuple[tuple[float, float], ...]:
    return tuple((round(x + dx, 6), round(y + dy, 6)) for x, y in pts)


def helper_layout(k: int) -> tuple[tuple[float, float, float], tuple[tuple[float, float], ...]]:
    """Helper ``k``'s (0-based: R(k+2)) start pose (x_m, y_m, theta_deg) and patrol route
    (world [m]): R(k % 3 + 2)'s of Fig. 11 (``LAYOUTS["simple"]``), moved to wing ``k // 3``."""
    if not 0 <= k < MAX_ROBOTS - 1:
        raise ValueError(f"helper index must be in [0, {MAX_ROBOTS - 2}] ({WINGS} wings of {HELPERS_PER_WING}), got {k}")
    (x, y, th), route = T.LAYOUTS["simple"].helpers[k % HELPERS_PER_WING]
    dx, dy = wing_origin(k // HELPERS_PER_WING, COLS)
    return (round(x + dx, 6), round(y + dy, 6), th), _shift(route, dx, dy)


def room_centres() -> dict[str, tuple[float, float]]:
    """Places ``room_*`` of the larger office, sorted by name (every wing's room centres)."""
    from teamnav.world import builtin_map

    places = builtin_map(MAP).places
    return {k: tuple(map(float, places[k])) for k in sorted(places) if k.startswith("room_")}


def task_rooms(task: int, n_targets: int = T.N_TARGETS) -> list[str]:
    """R1's task ``task`` on the larger office: room names drawn as
    :func:`~teamnav.papers.los_help.tasks.task_rooms` draws them (its own stream, key ``grid``)."""
    if task < 1 or n_targets < 1:
        raise ValueError(f"task and n_targets must be >= 1, got {task}, {n_targets}")
    names = list(room_centres())
    out: list[str] = []
    prev = -1
    for i in range(n_targets):
        k = T._draw("grid", task, i, len(names) - (prev >= 0))
        if prev >= 0:
            k += k >= prev
        out.append(names[k])
        prev = k
    return out


def targets_xy(task: int, n_targets: int = T.N_TARGETS) -> list[list[float]]:
    """R1's ``targets_xy`` for task ``task`` (R1's start frame [m], rounded to 0.1 mm)."""
    rooms = room_centres()
    world = np.array([rooms[r] for r in task_rooms(task, n_targets)], dtype=float)
    return T._rounded(T.world_to_frame(T.LAYOUTS["simple"].r1_start, world))


def scenario_data(n_robots: int, *, task: int = 1001, n_targets: int = 20, navigator: str = "visbug21",
                  paper: bool = False, duration_s: float = 60.0) -> dict[str, Any]:
    """The scenario (as data for :func:`teamnav.experiments.spec.Scenario`) of R1 and
    ``n_robots - 1`` helpers on the larger office.

    ``navigator``: R1's (state sharing with the potential field only, as in Tables 1-2);
    ``paper``: every robot at ``paper_rules: true``. The default task 1001 is a tuning task
    (FIDELITY §3); nothing is judged on these runs.
    """
    if not 2 <= n_robots <= MAX_ROBOTS:
        raise ValueError(f"n_robots must be in [2, {MAX_ROBOTS}] (R1 and 1-{MAX_ROBOTS - 1} helpers), got {n_robots}")
    base = T.scenario_data("simple", task=task, n_targets=1, navigator=navigator, helpers=1)  # bodies, sensing, radio
    r1, helper = base["robots"][0], base["robots"][1]
    r1 = copy.deepcopy(r1)
    r1["params"]["targets_xy"] = targets_xy(task, n_targets)
    r1["params"]["state_sharing"] = navigator == "potential_field"
    groups = [r1]
    for k in range(n_robots - 1):
        (x, y, th), route = helper_layout(k)
        g = copy.deepcopy(helper)
        g["name"] = f"R{k + 2}"
        g["count"] = 1
        g["params"]["patrol_xy"] = T._rounded(T.world_to_frame((x, y, th), route))
        g["start"] = {"region": [x - 0.005, x + 0.005, y - 0.005, y + 0.005], "theta_deg": th}
        groups.append(g)
    if paper:
        for g in groups:
            g["params"]["paper_rules"] = True
    for g in groups:  # one detector dict per robot (YAML anchors are a file's matter)
        g["detector"] = copy.deepcopy(g["detector"])
    return {
        "name": f"los-help-grid-{n_robots}",
        "description": (f"Beyond the paper (scaling): R1 and {n_robots - 1} helpers on {MAP} (21 copies of Sgorbissa & "
                        f"Arkin's Fig. 11), R1 on tuning task {task}; helpers three per wing on R2..R4's routes."),
        "map": {"builtin": MAP},
        "duration_s": float(duration_s),
        "dt_s": T.DT_S,
        "seed": 0,
        "record_every": T.RECORD_EVERY,
        "stop_when_finished": True,
        "metrics": ["los_help", "steps", "messages", "collisions"],
        "robots": groups,
        "radio": dict(base["radio"]),
    }


def load(n_robots: int, **kwargs: Any):
    """:func:`scenario_data` loaded and validated (:func:`teamnav.experiments.spec.load_scenario`)."""
    from teamnav.experiments.spec import Scenario, load_scenario

    return load_scenario(Scenario.model_validate(scenario_data(n_robots, **kwargs)))
