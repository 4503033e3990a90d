"""Avoid-Past's memory half-life with helpers: readings beside the judged verdict (paper column).

The paper gives Avoid-Past no memory lifetime (§6: "a potential field algorithm to which the Avoid
Past schema [17] has been added"), so the half-life is a fill, chosen on the tuning tasks by the
paper's precondition that R1 alone finishes (:data:`~teamnav.papers.los_help.tasks.HALF_LIFE_RULE`:
the longest such value, 1000 steps). Whether Table 1's Avoid-Past claim rests on that choice is
shown here: the claim's rule (``table1-avoid-past-falls``, claims/los-help.yaml) read on the
judged tasks for every half-life with which R1 alone finished all tuning tasks, and for 500 steps,
which did not (:func:`half_lives`). Paper column, office_simple, Table 1's teams R1..R4, Avoid-Past
only. These are readings, not the verdict: the verdict is the fill's, whose rows are the judged
table's own (not run again).

Cost (full mode only): :func:`trials` trials; :data:`CPU_NOTE` gives the estimate.
Quick mode does not run this block (it says so).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from teamnav.papers.los_help import tasks as L
from teamnav.papers.los_help.report._los_common import NAV_KEY, TEAM_LABEL, cell, finished_of, group, steps_of

#: The extra half-life the ablation always reads (beside every value that finished all tuning
#: tasks): 500 steps, between the short memories that finished and the fill.
ALWAYS: tuple[float, ...] = (500.0,)
#: The override that sets R1's half-life in a case (the paper column's ``paper_rules: true`` keeps
#: it: the half-life is a fill, not one of the navigator's paper rules).
NAV_PARAMS_KEY = "robots.0.params.navigator_params"
SWEEP = "los-avoid-past-half-life-teams"


def tuning_results() -> dict[float, tuple[int, int]]:
    """Half-life -> (tuning tasks finished, tasks run) of R1 alone, from
    :data:`._los_ledger.MEMORY_READINGS` (the rule's runs)."""
    from teamnav.papers.los_help.report._los_ledger import MEMORY_READINGS

    out = {}
    for name, fin, _steps, _where in MEMORY_READINGS:
        if name.startswith("half-life"):
            k, n = map(int, fin.split("/"))
            out[float(name.split()[1])] = (k, n)
    return out


def fill() -> float:
    """The half-life the fill's rule chose from the recorded tuning results."""
    return L.choose_half_life(tuning_results())


def half_lives() -> tuple[float, ...]:
    """The half-lives read with helpers: every one with which R1 alone finished all tuning tasks,
    and :data:`ALWAYS`, sorted; the fill among them (its rows are the judged table's)."""
    res = tuning_results()
    ok = {h for h, (k, n) in res.items() if k == n == len(L.TUNING_TASKS)}
    return tuple(sorted(ok | set(ALWAYS) | {fill()}))


def to_run() -> tuple[float, ...]:
    """:func:`half_lives` other than the fill (the fill's rows are the judged table's)."""
    return tuple(h for h in half_lives() if h != fill())


def trials() -> int:
    """Trials the block runs in full mode: each half-life to run x Table 1's 4 teams x the judged tasks."""
    return len(to_run()) * len(L.TEAMS) * len(L.JUDGED_TASKS)


#: CPU per trial used for the estimate [CPU-s]: R1 alone, Avoid-Past, paper column, 200 targets,
#: on the tuning tasks (2026-11-29, this 2-core machine at load 4-6, the sweep's worker CPU):
#: 11-13 CPU-s at the half-lives 125 and 250, 18 at 1000 (the trials that finished all 200 targets).
ALONE_CPU_S: tuple[float, float] = (11.0, 18.0)
#: One R1..R4 trial, Avoid-Past, paper column, 250-step half-life, tuning task 1001 (2026-11-29, the
#: same machine): 32.2 CPU-s (finished, 278 steps per target). Four robots cost more per step than
#: R1 alone saves in steps.
MEASURED_TEAM_CPU_S: float | None = 32.2


def cpu_note() -> str:
    """The block's added full-mode cost, estimated from the tuning runs' CPU per trial."""
    n = trials()
    lo, hi = ALONE_CPU_S
    team = MEASURED_TEAM_CPU_S
    hi2 = max(hi, team or hi)
    alone = len(to_run()) * len(L.JUDGED_TASKS)
    likely = (alone * (lo + hi) / 2 + (n - alone) * (team or hi)) / 3600
    return (f"Added cost in full mode: {n} trials ({len(to_run())} half-lives x {len(L.TEAMS)} teams x "
            f"{len(L.JUDGED_TASKS)} tasks), estimated at {n * lo / 3600:.1f}-{n * hi2 / 3600:.1f} CPU-hours, most "
            f"likely about {likely:.1f} (the R1-alone trials at {lo:g}-{hi:g} CPU-s, the helped ones at "
            f"{team or hi:g}), from the tuning runs' CPU per Avoid-Past trial (2026-11-29; not run on the judged "
            "tasks when this was written).")


def _half_life_of(row: dict) -> float | None:
    v = ((row.get("params") or {}).get(NAV_PARAMS_KEY) or {}).get("memory_half_life_steps")
    return None if v is None else float(v)


def spec():
    """The block's sweep: Table 1's Avoid-Past cases (teams R1..R4, the judged tasks), once per
    half-life of :func:`to_run` (cases ``avoid-past-h<half-life>/<team>``); run in the paper
    column by the section (``paper_rules: true``, named ``<SWEEP>-paper-rules``)."""
    from teamnav.papers.los_help.report.section import table_spec

    base = table_spec("simple", L.TEAMS)
    cases = []
    for h in to_run():
        for c in base.cases:
            if c[NAV_KEY] == "avoid_past":
                cases.append({**c, "case": c["case"].replace("avoid-past", f"avoid-past-h{h:g}", 1),
                              NAV_PARAMS_KEY: {"memory_half_life_steps": h}})
    return base.model_copy(update={"cases": cases, "name": SWEEP})


def by_half_life(rows: list[dict], fill_rows: dict[int, list[dict]], team_of) -> dict[float, dict[int, list[dict]]]:
    """Half-life -> team -> Avoid-Past rows: the fill's from the judged table (``fill_rows``, team
    -> rows), the others from the block's sweep (``rows``)."""
    out: dict[float, dict[int, list[dict]]] = {fill(): {h: group(rs, NAV_KEY).get("avoid_past", [])
                                                       for h, rs in fill_rows.items()}}
    for r in rows:
        h = _half_life_of(r)
        if h is not None:
            out.setdefault(h, {}).setdefault(team_of(r), []).append(r)
    return out


def half_life_block(rows_by_h: dict[float, dict[int, list[dict]]]) -> Any:
    """The readings: per half-life, R1 alone on the tuning tasks, each team's steps per target
    (finished / run), the last team over the first, and Table 1's Avoid-Past rule read on them."""
    from teamnav.experiments.report.model import Table
    from teamnav.papers.los_help.report._los_tables import table_block
    from teamnav.papers.los_help.report._los_verdicts import paired_means, table_comparisons

    res = tuning_results()
    rows = []
    for h in sorted(rows_by_h):
        by_team = {t: rows_by_h[h].get(t, []) for t in L.TEAMS}
        _tab, means = table_block("simple", by_team)
        record: dict = {}
        table_comparisons("simple", means, by_team, record=record)
        holds, text = record.get("table1-avoid-past-falls", ({}, (None, "not judged")))[1]
        word = ("holds" if holds else "does not hold") if holds is not None else text
        k, n = res.get(h, (0, 0))
        label = f"{h:g}" + (" (the fill: the judged verdict)" if h == fill() else "")
        cells = [cell(steps_of(by_team[t]), finished_of(by_team[t])) if by_team[t] else "not run" for t in L.TEAMS]
        paired = paired_means(by_team, "avoid_past", list(L.TEAMS))
        ms = paired[0] if paired is not None else [float("nan")]
        ratio = f"{ms[-1] / ms[0]:.2f} ({paired[1]} pairs)" if np.isfinite(ms[0]) and np.isfinite(ms[-1]) else "n/a"
        rows.append([label, f"{k}/{n}" + ("" if k == n else " (precondition not met)"), *cells, ratio, word])
    return Table("Avoid-Past's memory half-life with helpers: readings beside the verdict (paper column, "
                 f"office_simple, the judged tasks {L.JUDGED_TASKS[0]}-{L.JUDGED_TASKS[-1]})",
                 ["half-life [steps]", "R1 alone, tuning tasks finished", *(TEAM_LABEL[t] for t in L.TEAMS),
                  "last/first", "Table 1 Avoid-Past rule"], rows,
                 note="Readings, not the judged verdict (that is the fill's row, the judged table's own runs). "
                      "Each row reads claims/los-help.yaml's rule for 'Table 1: Av. Past steps fall as helpers are "
                      "added' (paired by task, at least 5 pairs) on that half-life's runs; cells are steps per target, "
                      "mean (std %) finished/run. The half-lives: every one with which R1 alone finished all tuning "
                      "tasks 1001-1005, and 500, which did not (so its row's precondition is not met). "
                      + cpu_note())
