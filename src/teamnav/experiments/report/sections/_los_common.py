"""The ``los-help`` section's row helpers: sweep-row keys, the paper's Tables 1-2 and a table
cell's "mean (std %) finished/run" (Sgorbissa & Arkin §6).

Split from :mod:`.los_help` (no behaviour change); what the section measured over time is in
``docs/report/los-help.md``.
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
