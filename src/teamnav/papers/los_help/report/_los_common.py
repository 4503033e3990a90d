"""The ``los-help`` section's row helpers: sweep-row keys, the paper's Tables 1-2 and a table
cell's "mean (std %) finished/run" (Sgorbissa & Arkin §6).

Split from :mod:`.section` (no behaviour change); what the section measured over time is in
``docs/report/los-help.md``. Also the route plans of Table 2's robustness column
(:data:`ROUTE_PLANS`) and the scenario files of plans B and C (:func:`write_route_plan_files`).
"""

from __future__ import annotations

import json
from typing import Any, Iterable, Sequence

import numpy as np

NAV_KEY = "robots.0.params.navigator"
TARGETS_KEY = "robots.0.params.targets_xy"
ERR_KEY = "robots.0.detector.err_max"
DELAYED_KEY = "robots.0.params.delayed_visibility"
STATE_KEY = "robots.0.params.state_sharing"
BUDGET_KEY = "robots.0.params.max_steps_per_target"
NAV_LABEL = {"potential_field": "Pot. Fields", "avoid_past": "Av. Past", "visbug21": "VisBug"}
TEAM_LABEL = {0: "R1", 1: "R1,2", 2: "R1,2,3", 3: "R1,2,3,4"}

#: Tables 1-2 (§6): average motion steps and std as % of the mean, per algorithm and team
#: size (None: the potential field alone has no result, it fails).
PAPER_TABLES: dict[str, dict[str, list[tuple[float, float] | None]]] = {
    "simple": {
        "avoid_past": [(554.2, 11.7), (426.2, 8.1), (302.0, 14.2), (257.2, 5.6)],
        "visbug21": [(840.6, 7.6), (294.0, 6.6), (255.4, 6.1), (201.2, 3.7)],
        "potential_field": [None, (618.6, 3.6), (310.0, 10.0), (235.2, 5.4)],
    },
    "complex": {
        "avoid_past": [(1132.2, 4.5), (953.6, 6.4), (731.8, 7.9), (682.6, 6.9)],
        "visbug21": [(513.6, 10.5), (441.8, 12.0), (397.4, 9.0), (373.4, 10.3)],
        "potential_field": [None, (1246.4, 5.9), (1130.4, 6.7), (913.6, 4.7)],
    },
}

# ---------------------------------------------------------------------------- row helpers
def ok_rows(result: Any) -> list[dict]:
    """Rows of a sweep call that ran to the end (status ``ok``)."""
    return [r for r in result.rows() if r.get("status") == "ok"]


def _metric(row: dict, key: str) -> float:
    v = (row.get("metrics") or {}).get(key)
    return float("nan") if v is None else float(v)


def steps_of(rows: Iterable[dict]) -> np.ndarray:
    """R1's motion steps per target (``los_steps_per_target``) of each row (NaN where missing).

    Per target, as the paper's numbers must be: its 200-target tasks could not take 554 steps."""
    return np.array([_metric(r, "los_steps_per_target") for r in rows], dtype=float)


def finished_of(rows: Iterable[dict]) -> np.ndarray:
    return np.array([_metric(r, "los_finished") for r in rows], dtype=float)


def group(rows: Iterable[dict], key: str) -> dict[Any, list[dict]]:
    """Rows by the value of override ``key`` (a JSON-able value; lists become tuples)."""
    out: dict[Any, list[dict]] = {}
    for r in rows:
        v = (r.get("params") or {}).get(key)
        if isinstance(v, list):
            v = json.dumps(v)
        out.setdefault(v, []).append(r)
    return out


def stats(steps: np.ndarray) -> tuple[float, float]:
    """(mean, std as % of the mean) of a task sample (std with ddof=1; 0 for one task)."""
    xs = steps[np.isfinite(steps)]
    if xs.size == 0:
        return float("nan"), float("nan")
    m = float(xs.mean())
    sd = float(xs.std(ddof=1)) if xs.size > 1 else 0.0
    return m, (100.0 * sd / m if m > 0 else float("nan"))


def cell(steps: np.ndarray, finished: np.ndarray) -> str:
    """A table cell: "mean (std %) k/n" (mean steps per target and std as % of the mean over the
    finished tasks, then tasks finished of tasks run), or a failure note."""
    n = int(steps.size)
    if n == 0:
        return "not run"
    done = int(np.nansum(finished))
    if done == 0:
        return f"fails (0/{n} finished)"
    m, pct = stats(steps[finished > 0.5])
    return f"{m:.0f} ({pct:.1f} %) {done}/{n}"


def _paper_cell(v: tuple[float, float] | None) -> str:
    return "fails (no result)" if v is None else f"{v[0]:.1f} ({v[1]:.1f} %)"


def strictly_falling(means: Sequence[float]) -> bool:
    xs = [m for m in means]
    return len(xs) >= 2 and all(np.isfinite(xs)) and all(b < a for a, b in zip(xs, xs[1:]))

def _mean(xs: Sequence[float]) -> float:
    a = np.asarray(xs, dtype=float)
    a = a[np.isfinite(a)]
    return float(a.mean()) if a.size else float("nan")


def targets_per_task(by_team: dict[int, list[dict]]) -> str:
    """The number of targets per task in the rows ("200", "20", "1-20" when mixed; "?" unknown)."""
    ns = sorted({len(t) for rs in by_team.values() for r in rs
                 if isinstance(t := (r.get("params") or {}).get(TARGETS_KEY), list)})
    return "?" if not ns else str(ns[0]) if len(ns) == 1 else f"{ns[0]}-{ns[-1]}"


# ---------------------------------------------------------------------------- route plans
#: The paper gives no layout for Fig. 13: office_complex_closed, its rooms, U walls and the helpers'
#: routes are ours. Table 2 is therefore also run over three route plans for R2..R4, chosen on
#: 2026-11-27 before any run of plans B and C, and judged on the mean over the plans
#: (claims/los-help.yaml). Each plan: (label, one line, per helper R2, R3, R4 its start pose
#: (x_m, y_m, theta_deg) and route [(x_m, y_m), ...] in world coordinates, run back and forth).
#: Plan A is the scenario ``los-help-complex`` (the Table 2 runs); B and C are the scenario files
#: ``los-help-complex-plan-b`` / ``-plan-c`` (:func:`route_plan_scenario`, written by
#: ``python -m teamnav.papers.los_help.report._los_common``).
def _route_plans() -> dict[str, tuple[str, tuple]]:
    from teamnav.papers.los_help import tasks as L

    a = L.LAYOUTS["complex"].helpers
    doors = L.COMPLEX_DOORS_H
    return {
        "A": ("as drawn (the Table 2 runs): R2 and R4 walk the east-west corridor H end to end in opposite phases "
              "stepping into every H door, R3 walks the north-south corridor V into its four doors", a),
        "B": ("R3 and R4 swapped: the second helper walks H in the phase opposite R2's, the third walks V "
              "(so the R1..R3 team covers H twice and V never)", (a[0], a[2], a[1])),
        "C": ("split corridor: R2 walks the west half of H (x 1.0-18.0) and R4 the east half (18.0-35.2), each "
              "stepping into the doors of its half; R3 walks V as in A (so R1,2 has help in the west half only)",
              (((3.0, 11.6, 0.0), L._doors_route(11.6, doors, 1.0, 18.0)), a[1],
               ((33.0, 12.4, 180.0), L._doors_route(12.4, doors, 18.0, 35.2)[::-1]))),
    }


#: plan label -> (description, helpers); see :func:`_route_plans`
ROUTE_PLANS: dict[str, tuple[str, tuple]] = _route_plans()
#: plan label -> the scenario it runs in (A: the tables' own)
PLAN_SCENARIOS: dict[str, str] = {"A": "los-help-complex", "B": "los-help-complex-plan-b",
                                  "C": "los-help-complex-plan-c"}


def route_plan_scenario(plan: str) -> dict[str, Any]:
    """The scenario (YAML data) of route plan ``plan`` (B or C): ``los-help-complex`` with the
    plan's helper starts and routes (each route in its helper's start frame, as
    :func:`teamnav.papers.los_help.tasks.patrol_xy` writes them)."""
    from teamnav.papers.los_help import tasks as L

    if plan not in ROUTE_PLANS or plan == "A":
        raise ValueError(f"plan must be one of B, C (A is los-help-complex), got {plan!r}")
    text, helpers = ROUTE_PLANS[plan]
    data = L.scenario_data("complex", name=PLAN_SCENARIOS[plan], description=(
        f"Sgorbissa & Arkin §6 (Fig. 13), route plan {plan} of Table 2's robustness column: {text}. "
        "The plans: " + " | ".join(f"{k}: {v[0]}" for k, v in ROUTE_PLANS.items()) + "."))
    for k, (start, route) in enumerate(helpers):
        g = data["robots"][k + 1]
        x, y, th = start
        g["start"] = {"region": [x - 0.005, x + 0.005, y - 0.005, y + 0.005], "theta_deg": th}
        g["params"]["patrol_xy"] = L._rounded(L.world_to_frame(start, route))
    return data


def write_route_plan_files(scenario_dir=None) -> list:
    """(Re)write the scenario files of route plans B and C; returns the paths written."""
    from pathlib import Path

    from teamnav.papers.los_help import tasks as L

    folder = Path(scenario_dir or Path(__file__).resolve().parents[1] / "scenarios")  # the paper's folder
    out = []
    for plan in ("B", "C"):
        p = folder / f"{PLAN_SCENARIOS[plan]}.yaml"
        p.write_text(L.to_yaml(route_plan_scenario(plan), (
            "# GENERATED by `python -m teamnav.papers.los_help.report._los_common` (ROUTE_PLANS there): edit\n"
            f"# that module, not this file. Route plan {plan} of Table 2's robustness column.\n")),
            encoding="utf-8")
        out.append(p)
    return out


if __name__ == "__main__":  # pragma: no cover - regenerates the shipped plan files
    for path in write_route_plan_files():
        print(path)
