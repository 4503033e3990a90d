"""Whether the ``los-help`` verdicts move with the step budget (FIDELITY §3: units that carry over).

§6 gives no step budget (the potential field alone "does not guarantee the robot to reach its
target"); ours, :data:`~teamnav.papers.los_help.tasks.BUDGET_STEPS_PER_TARGET`, was fixed in
steps before any rule of FIDELITY, so this block shows what it does, from the section's own rows
and without a run of its own:

- the budget per target as a multiple of each task's shortest path per target
  (:func:`~teamnav.papers.los_help.tasks.shortest_steps_per_target`, the unit that carries over);
- the runs that gave up on the budget (``los_gave_up``): a larger budget can change only those,
  so they are named;
- every claim's verdict recomputed after the fact with the budget cut to 1/2 and 1/4
  (:data:`CUTS`). The budget changes nothing before R1 gives up (it only ends the task), so a run
  would have given up under the cut exactly when one of its reached targets took more steps than
  the cut: ``los_max_target_steps`` (metric ``los_help``). Such a run counts as not finished
  (:func:`cut_rows`) and the verdicts are computed again by the section's own functions. The
  metric is read from samples kept every ``record_every`` steps, so a run within that many steps
  of a cut may fall on either side (the block counts them).

Ours, not the paper's. One thing a cut cannot give: R1 alone's level of Figs. 16-17 when an
R1-alone run is cut (that level counts the steps to the abandoned target, which the row of a
finished run does not hold): those two claims then read "not recomputed" for that map.
"""

from __future__ import annotations

import json
from typing import Any, Mapping, Sequence

import numpy as np

from teamnav.experiments.report.model import Table, Text
from teamnav.papers.los_help import tasks as L
from teamnav.papers.los_help.report._los_common import ERR_KEY, NAV_KEY, NAV_LABEL, TARGETS_KEY, TEAM_LABEL, _metric

#: The budget fractions judged: the budget as run, then cut to 1/2 and 1/4 after the fact.
CUTS: tuple[float, ...] = (1.0, 0.5, 0.25)
#: The claims whose verdict reads R1 alone's level of Figs. 16-17 (``alone_levels``), per map.
ALONE_LEVEL_CLAIMS: dict[str, tuple[str, ...]] = {"simple": ("fig16-below-alone",), "complex": ("fig17-help-fades",)}
METRIC = "los_max_target_steps"


def over_cut(row: Mapping[str, Any], limit: float) -> bool | None:
    """Whether a finished run's slowest reached target took more than ``limit`` steps (None: the
    row does not hold ``los_max_target_steps``, e.g. a row stored before the metric existed); a run
    that did not finish is False (it fails under any budget)."""
    if not _metric(dict(row), "los_finished") > 0.5 or not np.isfinite(limit):
        return False
    v = _metric(dict(row), METRIC)
    return None if not np.isfinite(v) else bool(v > limit)


def cut_rows(rows: Sequence[Mapping[str, Any]], limit: float) -> list[dict] | None:
    """``rows`` as they would read with a per-target budget of ``limit`` steps: a finished run
    whose slowest target took more (:func:`over_cut`) counts as not finished and given up
    (``los_finished`` 0, ``los_gave_up`` 1, ``los_budget_cut`` 1); None when a finished row lacks
    the metric (the cut cannot be read).

    Examples
    --------
    >>> rows = [{"metrics": {"los_finished": 1, "los_max_target_steps": 900}},
    ...         {"metrics": {"los_finished": 1, "los_max_target_steps": 400}}]
    >>> [r["metrics"]["los_finished"] for r in cut_rows(rows, 500)]
    [0, 1]
    """
    out = []
    for r in rows:
        over = over_cut(r, limit)
        if over is None:
            return None
        r = dict(r)
        if over:
            r["metrics"] = {**(r.get("metrics") or {}), "los_finished": 0, "los_gave_up": 1, "los_budget_cut": 1}
        out.append(r)
    return out


def _cut_team(by_team: Mapping[int, Sequence[dict]], limit: float) -> dict[int, list[dict]] | None:
    out = {}
    for h, rs in by_team.items():
        got = cut_rows(rs, limit)
        if got is None:
            return None
        out[h] = got
    return out


def verdicts_at(col_in: Mapping[str, Any], frac: float, budgets: Mapping[str, float]) -> dict[str, tuple] | None:
    """Each claim's verdict on one column's rows with every map's budget times ``frac``: claim id ->
    (holds, how it was read), from the section's own verdict functions
    (:func:`._los_verdicts.table_comparisons`, :func:`._los_verdicts.noise_comparisons`); None
    when a row lacks ``los_max_target_steps``.

    ``col_in``: ``{"tables": {map: {team: rows}}, "plans": {map: [plan rows, plan A first] or None},
    "noise": {map: rows}}`` as the section ran them; ``budgets``: map -> steps per target."""
    from teamnav.papers.los_help.report._los_tables import noise_plot, table_block
    from teamnav.papers.los_help.report._los_verdicts import alone_levels, noise_comparisons, table_comparisons

    record: dict[str, tuple] = {}
    if frac >= 1.0:  # the budget as run: no cut (the sampled metric may read up to record_every over it)
        budgets = {m: float("inf") for m in budgets}
    alone_cut: dict[str, bool] = {}
    tables: dict[str, dict[int, list[dict]]] = {}
    for m, by_team in col_in.get("tables", {}).items():
        limit = budgets[m] * frac
        cut = _cut_team(by_team, limit)
        if cut is None:
            return None
        tables[m] = cut
        alone_cut[m] = any(over_cut(r, limit) for r in by_team.get(0, []))
        plans = (col_in.get("plans") or {}).get(m)
        cplans = None
        if plans:
            cplans = [cut] + [_cut_team(p, limit) for p in plans[1:]]
            if any(p is None for p in cplans):
                return None
        _tab, means = table_block(m, cut)
        table_comparisons(m, means, cut, plans=cplans, record=record)
    for m, rows in col_in.get("noise", {}).items():
        limit = budgets[m] * frac
        cut = cut_rows(rows, limit)
        if cut is None:
            return None
        alone = alone_levels(tables.get(m, {}).get(0, []))
        _plot, nmeans = noise_plot(m, cut, alone)
        noise_comparisons(m, nmeans, alone, cut, record=record)
        if alone_cut.get(m):
            for cid in ALONE_LEVEL_CLAIMS[m]:
                record[cid] = ({}, (None, "not recomputed: an R1-alone run is over the cut, and its level counts "
                                          "the steps to the abandoned target, which its row does not hold"))
    return {cid: got for cid, (_values, got) in record.items()}


def verdict_word(got: tuple | None) -> str:
    """"holds" / "does not hold" / the reason it is not judged."""
    if got is None:
        return "not judged"
    holds, text = got
    if holds is None:
        return text if text.startswith(("not judged", "not recomputed")) else "not judged"
    return "holds" if holds else "does not hold"


def span(lo: float, hi: float) -> str:
    """"12-14", or "13" when both round alike."""
    a, b = f"{lo:.0f}", f"{hi:.0f}"
    return a if a == b else f"{a}-{b}"


def task_lookup(tasks: Mapping[str, Sequence[int]], n_targets: int) -> dict[str, dict[str, int]]:
    """map -> {the targets_xy of a task, as JSON: its task number}."""
    return {m: {json.dumps(L.task_targets_xy(m, t, n_targets)): t for t in ts} for m, ts in tasks.items()}


def budget_multiples(budgets: Mapping[str, float], tasks: Mapping[str, Sequence[int]], n_targets: int
                     ) -> dict[str, tuple[float, float]]:
    """map -> (fewest, most) times the shortest path per target of its tasks that the budget is."""
    out = {}
    for m, ts in tasks.items():
        xs = [budgets[m] / L.shortest_steps_per_target(m, t, n_targets) for t in ts]
        out[m] = (min(xs), max(xs))
    return out


def _runs(inputs: Mapping[str, Mapping[str, Any]]):
    """Every run of the section once: (column, map, experiment, navigator, team, row). The noise
    figures' err_max 0 rows (the tables' R1..R4 runs) and route plans B-C's R1-alone rows (plan A's)
    are left out: they are listed under the tables."""
    for col, col_in in inputs.items():
        for m, by_team in col_in.get("tables", {}).items():
            plans = (col_in.get("plans") or {}).get(m) or [by_team]
            for k, p in enumerate(plans):
                exp = f"Table {1 if m == 'simple' else 2}" + (f" plan {'ABC'[k]}" if len(plans) > 1 else "")
                for h, rs in sorted(p.items()):
                    if k and h == 0:
                        continue
                    for r in rs:
                        yield col, m, exp, (r.get("params") or {}).get(NAV_KEY), h, r
        for m, rows in col_in.get("noise", {}).items():
            for r in rows:
                e = float((r.get("params") or {}).get(ERR_KEY, 0.0) or 0.0)
                if e > 0:
                    yield col, m, f"Fig. {16 if m == 'simple' else 17} err_max {e:g}", \
                        (r.get("params") or {}).get(NAV_KEY), 3, r


def budget_blocks(inputs: Mapping[str, Mapping[str, Any]], budgets: Mapping[str, float],
                  tasks: Mapping[str, Sequence[int]], n_targets: int, claims: Any,
                  heads: Mapping[str, str], quick: bool = False) -> list:
    """The budget block (see the module docstring): a text with the budgets in shortest paths and
    the cuts' counts, the runs that gave up, and the verdicts at each cut per column.

    ``inputs``: column -> :func:`verdicts_at`'s ``col_in``; ``budgets``: map -> steps per target as
    run; ``tasks``: map -> the task numbers run; ``heads``: column -> its heading."""
    lookup = task_lookup(tasks, n_targets)
    mult = budget_multiples(budgets, tasks, n_targets)
    runs = list(_runs(inputs))

    def task_of(m: str, r: dict) -> str:
        t = (r.get("params") or {}).get(TARGETS_KEY)
        return str(lookup.get(m, {}).get(json.dumps(t), "?")) if t is not None else "?"

    gave = [(col, m, exp, nav, h, r) for col, m, exp, nav, h, r in runs if _metric(r, "los_gave_up") > 0.5]
    grouped: dict[tuple, list[str]] = {}
    for col, m, exp, nav, h, r in gave:
        grouped.setdefault((heads.get(col, col), exp, NAV_LABEL.get(nav, str(nav)), TEAM_LABEL.get(h, str(h))),
                           []).append(f"{task_of(m, r)} ({int(_metric(r, 'los_targets_reached'))})")
    gave_rows = [[*k, ", ".join(v)] for k, v in grouped.items()]
    per_cut: list[str] = []
    for frac in CUTS[1:]:
        parts = []
        for col in inputs:
            rs = [(m, r) for c, m, _e, _n, _h, r in runs if c == col]
            over = [r for m, r in rs if over_cut(r, budgets[m] * frac)]
            near = [r for m, r in rs if _metric(r, "los_finished") > 0.5
                    and abs(_metric(r, METRIC) - budgets[m] * frac) < L.RECORD_EVERY]
            parts.append(f"{heads.get(col, col)} {len(over)}" + (f" ({len(near)} within {L.RECORD_EVERY} steps of it)"
                                                                   if near else ""))
        per_cut.append(f"cut to {frac:g}: finished runs over the cut: " + ", ".join(parts))
    budget_text = "; ".join(
        f"{L.MAPS[m]} {budgets[m]:g} steps per target = {span(lo, hi)} times the task's shortest path per target "
        f"(1/2: {span(lo / 2, hi / 2)}, 1/4: {span(lo / 4, hi / 4)})" for m, (lo, hi) in mult.items())
    n_runs = {col: sum(1 for c, *_ in runs if c == col) for col in inputs}
    n_gave = {col: sum(1 for c, *_ in gave if c == col) for col in inputs}
    blocks: list = [Text(
        "Does the step budget move the verdicts? §6 gives no budget; ours is fixed in steps. In units that carry "
        f"over (the tasks run here: {', '.join(f'{L.MAPS[m]} {ts[0]}-{ts[-1]}' if len(ts) > 1 else f'{L.MAPS[m]} {ts[0]}' for m, ts in tasks.items())}): "
        + budget_text + ". Runs that gave up on the budget: "
        + ", ".join(f"{heads.get(c, c)} {n_gave[c]} of {n_runs[c]}" for c in inputs)
        + " (a larger budget can change only these: the table below names them). A smaller budget is judged from the "
        "same runs: the budget changes nothing before R1 gives up, so a run would have given up under a cut exactly "
        "when its slowest reached target (los_max_target_steps, read every "
        f"{L.RECORD_EVERY} steps) took more steps than the cut; such a run counts as not finished and every verdict is "
        "computed again by the section's own rules. " + "; ".join(per_cut) + "."
        + (" Quick mode: one target per task, 1 task; indicative only." if quick else ""))]
    if gave_rows:
        blocks.append(Table("Runs that gave up on the step budget (a larger budget can change only these)",
                            ["column", "experiment", "algorithm", "team", "tasks given up (targets reached)"],
                            gave_rows))
    got = {col: {frac: verdicts_at(inputs[col], frac, budgets) for frac in CUTS} for col in inputs}
    head_cells = [f"{heads.get(col, col)}, budget x {frac:g}" for col in inputs for frac in CUTS]
    rows = []
    for c in claims.claims:
        cells = []
        for col in inputs:
            for frac in CUTS:
                v = got[col][frac]
                cells.append("not measured (rows without los_max_target_steps)" if v is None
                             else verdict_word(v.get(c.id)))
        rows.append([c.title, *cells])
    blocks.append(Table("The verdicts with the step budget cut after the fact (the same runs)",
                        ["claim", *head_cells], rows,
                        note="budget x 1: the verdict as judged; x 0.5 and x 0.25: a finished run whose slowest target "
                             "took more than the cut counts as not finished. A verdict that moves with the cut rests "
                             "on slow targets; one that does not is unit-free in the budget. Readings, not verdicts."))
    return blocks
