"""The ``beyond`` section's block on trails as LOS memory (combination 4).

``los-trail-explorer-v1`` (:mod:`teamnav.papers.beyond.brains.trail_memory`) is Sgorbissa & Arkin's R1
with a Trail (Vaughan et al. 2002 §2.1) of the places from which it saw its targets; with its
goal out of sight and nothing else leading it, it heads for the remembered viewpoint in sight
with the shortest §4.3 D. Its parts: the same R1 with ``goal_memory: off`` (the paper's R1,
identical runs to ``los-explorer-v1``), alone and with the Table 2 helpers R2..R4.

Sweep ``beyond-trail-memory`` (scenario of the same name, office_complex_closed): cases
``<navigator>/<team>/<memory>`` for the potential field (with state sharing, §5, as in Table 2),
Avoid-Past and VisBug-21, R1 alone and R1..R4, memory off and trail; its grid runs the first 30
targets of tasks 1-10 (:func:`teamnav.papers.los_help.tasks.task_targets_xy`), one run each at
seed 0: the tasks are the sample (the LOS runs have exact odometry and no sensor noise), and the
memory is compared *paired by task*. At most 6000 steps per target.

Shown per navigator and team: targets reached (of 30) and tasks finished, R1's motion steps per
target reached (``los_steps_per_target``: a task given up counts its steps until the give-up),
the paired difference memory minus none per task (mean ± standard error) of both, and the
paired difference of steps per target over the tasks both finished. Verdicts: claims
``trail-memory-r1`` (Avoid-Past alone) and ``trail-memory-helpers`` (R1..R4, every navigator)
of ``claims/beyond.yaml``. The text says plainly where the memory does not help.

Quick mode (CI): Avoid-Past alone, memory off and on, the first 8 targets of task 1 (two short
runs, a few seconds): the pipeline works; no verdict. Full mode: the sweep's 120 runs (the CPU
cost is in docs/report/beyond.md).
"""

from __future__ import annotations

import json
import math
from typing import Sequence

import numpy as np

from teamnav.experiments.report.model import Comparison, Missing, Table, Text
from teamnav.papers.trails.report import _trails as T

__all__ = ["NAVS", "QUICK_CASES", "SWEEP", "TEAMS", "claim_values", "paired", "per_task", "trail_memory"]

SWEEP = "beyond-trail-memory"
TARGETS_KEY = "robots.0.params.targets_xy"
#: (case tag, label)
NAVS = (("pot-field", "potential field (+ §5 state sharing)"), ("avoid-past", "Avoid-Past"), ("visbug21", "VisBug-21"))
TEAMS = (("R1", "R1 alone"), ("R1-4", "R1..R4"))
QUICK_CASES = ("avoid-past/R1/off", "avoid-past/R1/trail")
QUICK_TARGETS = 8


def per_task(rows: Sequence[dict], grid: Sequence[Sequence[Sequence[float]]]) -> dict[int, dict]:
    """Task number (1-based position of the row's target list in ``grid``) -> row.

    Raises
    ------
    ValueError
        A row whose target list is not one of ``grid``'s, or two rows of one task.
    """
    index = {json.dumps([[float(x), float(y)] for x, y in g]): k + 1 for k, g in enumerate(grid)}
    out: dict[int, dict] = {}
    for r in rows:
        raw = r.get(TARGETS_KEY, (r.get("params") or {}).get(TARGETS_KEY))
        if isinstance(raw, str):
            raw = json.loads(raw)
        key = json.dumps([[float(x), float(y)] for x, y in raw]) if raw is not None else None
        if key not in index:
            raise ValueError(f"{TARGETS_KEY}: a row's target list is not one of the {len(grid)} tasks of the grid")
        k = index[key]
        if k in out:
            raise ValueError(f"{TARGETS_KEY}: two rows of task {k} in one case")
        out[k] = r
    return out


def _metric(row: dict, key: str) -> float:
    v = row.get(key, (row.get("metrics") or {}).get(key))
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else float("nan")


def paired(a: dict[int, dict], b: dict[int, dict], key: str, *, both_finished: bool = False) -> np.ndarray:
    """Per task, ``a``'s metric ``key`` minus ``b``'s, over the tasks both ran (and, with
    ``both_finished``, both finished); NaN-free.

    >>> a = {1: {"x": 5.0, "los_finished": 1}, 2: {"x": 3.0, "los_finished": 0}}
    >>> b = {1: {"x": 2.0, "los_finished": 1}, 2: {"x": 1.0, "los_finished": 1}}
    >>> paired(a, b, "x").tolist(), paired(a, b, "x", both_finished=True).tolist()
    ([3.0, 2.0], [3.0])
    """
    out = []
    for k in sorted(set(a) & set(b)):
        if both_finished and not (_metric(a[k], "los_finished") == 1 and _metric(b[k], "los_finished") == 1):
            continue
        d = _metric(a[k], key) - _metric(b[k], key)
        if math.isfinite(d):
            out.append(d)
    return np.asarray(out, dtype=float)


def _se(d: np.ndarray) -> float:
    return float(d.std(ddof=1) / math.sqrt(d.size)) if d.size > 1 else float("nan")


def _diff_text(d: np.ndarray, fmt: str) -> str:
    if d.size == 0:
        return "n/a"
    if d.size == 1:
        return f"{fmt.format(float(d[0]))} (n = 1)"
    m, se = float(d.mean()), _se(d)
    sign = "" if abs(m) <= 2.0 * se else " (beyond 2 s.e.)"
    return f"{'+' if m >= 0 else ''}{fmt.format(m)} ± {fmt.format(se)} (s.e., n = {d.size}){sign}"


def _mean(by: dict[int, dict], key: str) -> float:
    v = [_metric(r, key) for r in by.values()]
    v = [x for x in v if math.isfinite(x)]
    return float(np.mean(v)) if v else float("nan")


def claim_values(cases: dict[str, dict[int, dict]]) -> dict[str, float]:
    """The claims' metrics (claims/beyond.yaml, ``trail-memory-*``) from the runs by case and task."""
    off, on = cases.get("avoid-past/R1/off", {}), cases.get("avoid-past/R1/trail", {})
    gain = paired(on, off, "los_targets_reached")
    vals = {"reached_gain_lo_ap_r1": float(gain.mean() - 2.0 * _se(gain)) if gain.size > 1 else float("nan"),
            "spt_ap_r1_trail_mean": _mean(on, "los_steps_per_target"),
            "spt_ap_r1_off_mean": _mean(off, "los_steps_per_target")}
    ratios = []
    for tag, _ in NAVS:
        a, b = cases.get(f"{tag}/R1-4/trail", {}), cases.get(f"{tag}/R1-4/off", {})
        common = sorted(set(a) & set(b))  # the tasks both ran: a ratio of means over the same tasks
        a, b = {k: a[k] for k in common}, {k: b[k] for k in common}
        ratios.append(_mean(a, "los_steps_per_target") / _mean(b, "los_steps_per_target") if common else float("nan"))
    vals["spt_r14_ratio_max"] = float(max(ratios)) if all(math.isfinite(x) for x in ratios) else float("nan")
    return vals


def _verdict_line(d_reached: np.ndarray, d_spt: np.ndarray) -> str:
    """Plain words: does the memory help this navigator and team?"""
    if d_reached.size < 2:
        return "too few tasks"
    more = d_reached.mean() > 2.0 * _se(d_reached)
    fewer_reached = d_reached.mean() < -2.0 * _se(d_reached)
    faster = d_spt.size > 1 and d_spt.mean() < -2.0 * _se(d_spt)
    slower = d_spt.size > 1 and d_spt.mean() > 2.0 * _se(d_spt)
    if fewer_reached or slower:
        return "the memory hurts"
    if more or faster:
        return "the memory helps"
    return "no difference beyond the tasks' spread: the memory does not help"


def trail_memory(ctx) -> list:
    """The block: a table of the twelve cases' parts side by side, and the two verdicts."""
    from teamnav.papers.los_help import tasks as L
    from teamnav.experiments.claims import history_text, judge, load_claims, rule_text
    from teamnav.experiments.sweep import load_sweep

    missing = T.brains_missing(["los-trail-explorer-v1", "los-helper-v1"])
    if missing is not None:
        return [missing]
    quick = bool(ctx.quick)
    spec = load_sweep(SWEEP)
    if quick:
        targets = [[float(x), float(y)] for x, y in L.task_targets_xy("complex", 1, QUICK_TARGETS)]
        res = ctx.sweep(T.case_spec(SWEEP, QUICK_CASES), seeds=[0], set={TARGETS_KEY: targets})
        grid = [targets]
        labels = list(QUICK_CASES)
    else:
        res = ctx.sweep(SWEEP, seeds=list(spec.seed_list), duration_s=spec.duration_s)
        grid = list(spec.grid[TARGETS_KEY])
        labels = [str(c["case"]) for c in spec.cases]
    rows = T.by_case(T.ok(res))
    if not rows:
        return [Missing("trails as LOS memory: runs", f"sweep {res.name} finished none of {res.total} trials")]
    cases = {lab: per_task(rows.get(lab, []), grid) for lab in labels}
    n_targets = len(grid[0])
    table, plain = [], []
    for tag, nav in NAVS:
        for team, team_text in TEAMS:
            off, on = cases.get(f"{tag}/{team}/off"), cases.get(f"{tag}/{team}/trail")
            if not off or not on:
                continue  # a case without runs (quick mode, or a sweep cut short)
            cells = []
            for by in (off, on):
                reached = np.array([_metric(r, "los_targets_reached") for r in by.values()])
                fin = np.array([_metric(r, "los_finished") for r in by.values()])
                spt = np.array([_metric(r, "los_steps_per_target") for r in by.values()])
                cells.append((f"{reached.sum():.0f}/{n_targets * reached.size} ({fin.sum():.0f}/{fin.size})",
                              T.msd(spt[np.isfinite(spt)], "{:.0f}")))
            d_reached = paired(on, off, "los_targets_reached")
            d_spt = paired(on, off, "los_steps_per_target")
            d_fin = paired(on, off, "los_steps_per_target", both_finished=True)
            table.append([nav, team_text, cells[0][0], cells[1][0], cells[0][1], cells[1][1],
                          _diff_text(d_reached, "{:.1f}"), _diff_text(d_spt, "{:.0f}"), _diff_text(d_fin, "{:.0f}")])
            plain.append(f"{nav}, {team_text}: {_verdict_line(d_reached, d_spt)}")
    tasks = f"task 1's first {n_targets} targets" if quick else f"the first {n_targets} targets of tasks 1-{len(grid)}"
    blocks: list = [Text(
        "Combination 4, trails as LOS memory: Sgorbissa & Arkin's R1 keeps a Trail (Vaughan et al. 2002 "
        "§2.1: one Place per target, a Crumb where a target came into view, its value the straight distance to it) "
        "and, with its goal out of sight and no teammate or ghost leading it, heads for the remembered viewpoint in "
        "sight with the shortest D = dist(R1, crumb) + crumb-to-goal (§4.3's estimate through a 'ghost robot', applied "
        "to its own viewpoints of earlier visits; los-trail-explorer-v1). Office_complex_closed (Table 2's map), "
        f"{tasks}, one run per task (the tasks are the sample; differences are paired by task)"
        + (" (quick mode: Avoid-Past alone only; the pipeline works, the numbers are not the result)." if quick else "."))]
    blocks.append(Table(
        "Trails as LOS memory: R1's targets and steps, memory off (the paper) against on",
        ["navigator A", "team", "targets reached (tasks finished), off", "same, memory", "steps per target, off",
         "steps per target, memory", "paired: targets reached, memory - off", "paired: steps per target, memory - off",
         "paired: steps per target, tasks both finished"],
        table, note=f"sweep {SWEEP}; mean ± sd over tasks (n = tasks); paired differences mean ± standard error over "
                    "tasks. Steps per target = R1's motion steps over targets reached (a task given up at a target's "
                    "6000-step budget counts its steps until then)."))
    if plain:
        blocks.append(Text("Where the memory helps, in plain words (a paired mean beyond 2 standard errors counts): "
                           + "; ".join(plain) + "."))
    vals = claim_values(cases)
    done = sum(len(v) for v in cases.values())
    short = "" if done == len(labels) * len(grid) else f"only {done} of the {len(labels) * len(grid)} runs finished"
    for cid in ("trail-memory-r1", "trail-memory-helpers"):
        claim = load_claims("beyond")[cid]
        if quick:
            holds, how = None, "not judged in quick mode (one short task, Avoid-Past alone)"
        elif short:
            holds, how = None, f"not judged: {short}"
        else:
            holds, how = judge(claim, vals)
        blocks.append(Comparison(f"{claim.title} ({rule_text(claim)})",
                                 f"{claim.paper_number} ({claim.statement.section}: \u201c{claim.statement.quote}\u201d)",
                                 how, holds, "our rule (no paper keeps a memory across targets). History of the rule: "
                                             + history_text(claim)))
    return blocks
