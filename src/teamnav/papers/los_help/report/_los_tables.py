"""The ``los-help`` section's tables and figures: Tables 1-2 (Figs. 12, 14), Figs. 16-17, the
ablation, §4.4 traffic and where R1's steps go (Sgorbissa & Arkin).

Split from :mod:`.section` (no behaviour change).
"""

from __future__ import annotations

import numpy as np

from teamnav.papers.los_help import tasks as L
from teamnav.experiments.report.model import Plot, Series, Table
from teamnav.papers.los_help.report._los_common import (
    DELAYED_KEY, ERR_KEY, NAV_KEY, NAV_LABEL, PAPER_TABLES, STATE_KEY, TARGETS_KEY, TEAM_LABEL, _mean, _metric,
    _paper_cell, cell, finished_of, group, stats, steps_of, targets_per_task,
)


def table_block(map_key: str, by_team: dict[int, list[dict]]) -> tuple[Table, dict[str, list[float]]]:
    """Table 1 or 2 (ours beside the paper's) and our mean steps per algorithm and team size."""
    teams = sorted(by_team)
    rows: list[list[str]] = []
    means: dict[str, list[float]] = {}
    for nav in L.NAVIGATORS:
        ours, mm = [], []
        for h in range(4):
            rs = group(by_team.get(h, []), NAV_KEY).get(nav, [])
            st, fin = steps_of(rs), finished_of(rs)
            ours.append(cell(st, fin) if h in by_team else "not run")
            ok = fin > 0.5
            mm.append(stats(st[ok])[0] if ok.any() else float("nan"))
        means[nav] = mm
        rows.append([NAV_LABEL[nav], "ours", *ours])
        rows.append(["", "paper", *(_paper_cell(v) for v in PAPER_TABLES[map_key][nav])])
    n = max((len(v) for v in by_team.values()), default=0)
    title = (f"Table {1 if map_key == 'simple' else 2} ({L.MAPS[map_key]}): R1's motion steps per target, mean "
             "(std as % of the mean) tasks finished / run")
    n_t = targets_per_task(by_team)
    note = (f"Ours: R1's motion steps per target (a task's steps over its targets; step {L.STEP_LENGTH_M} m), "
            f"mean and std over the finished tasks of the {n // max(len(L.NAVIGATORS), 1)} run per cell, "
            f"{n_t} targets per task; teams run: {', '.join(TEAM_LABEL[h] for h in teams)}. "
            "The paper's numbers must be per "
            "target too (a 200-target task cannot take 554 steps), but its step length and maps are not ours: "
            "compare ratios along a row, not values.")
    return Table(title, ["algorithm", "", *TEAM_LABEL.values()], rows, note), means

def robots_plot(map_key: str, by_team: dict[int, list[dict]]) -> Plot:
    series = []
    for nav in L.NAVIGATORS:
        xs, ys, lo, hi = [], [], [], []
        for h in sorted(by_team):
            rs = group(by_team[h], NAV_KEY).get(nav, [])
            st, fin = steps_of(rs), finished_of(rs)
            ok = fin > 0.5
            if not ok.any() or not ok.all():
                continue  # a failing cell is not plotted (the paper leaves PF alone out)
            m = float(st.mean())
            sd = float(st.std(ddof=1)) if st.size > 1 else 0.0
            xs.append(h + 1)
            ys.append(m)
            lo.append(m - sd)
            hi.append(m + sd)
        series.append(Series(NAV_LABEL[nav], xs, ys, lo, hi, style="line+points"))
    fig = 12 if map_key == "simple" else 14
    return Plot(f"Fig. {fig} ({L.MAPS[map_key]}): R1's steps vs number of robots", "number of robots",
                "R1's motion steps per target", series,
                caption="Mean over tasks, band ± 1 std; the potential field alone does not finish and is not drawn.")

def noise_plot(map_key: str, rows: list[dict], alone: dict[str, float]) -> tuple[Plot, dict[str, dict[float, float]]]:
    by_nav = group(rows, NAV_KEY)
    series, means = [], {}
    unfinished: list[str] = []
    for nav in L.NAVIGATORS:
        per = group(by_nav.get(nav, []), ERR_KEY)
        xs = sorted(float(e) for e in per)
        ys, lo, hi = [], [], []
        for e in xs:
            st = steps_of(per[e])
            fin = finished_of(per[e]) > 0.5
            if not fin.all():
                unfinished.append(f"{NAV_LABEL[nav]} at {e:g}: {int(fin.sum())}/{fin.size}")
            st = st[fin]  # failures have no step count to average
            m = float(np.nanmean(st)) if st.size else float("nan")
            sd = float(np.nanstd(st, ddof=1)) if st.size > 1 else 0.0
            ys.append(m)
            lo.append(m - sd)
            hi.append(m + sd)
        means[nav] = dict(zip(xs, ys))
        series.append(Series(NAV_LABEL[nav], xs, ys, lo, hi, style="line+points"))
    hl = [(v, f"{NAV_LABEL[k]} alone") for k, v in alone.items() if np.isfinite(v)]
    fig = 16 if map_key == "simple" else 17
    return Plot(f"Fig. {fig} ({L.MAPS[map_key]}): R1's steps vs err_max, R2..R4 present", "err_max (eqs. 1-2)",
                "R1's motion steps per target (finished tasks)", series, hlines=hl,
                caption="Horizontal lines: R1 alone (Tables 1-2, noise has no effect without teammates; where R1 "
                        "alone failed tasks, its steps per reached target with the abandoned target's budget, "
                        "alone_levels); "
                        "the potential field alone fails and has no line. Means over finished tasks only"
                        + (" (finished: " + "; ".join(unfinished) + ")." if unfinished else "; every task finished.")), means

def noise_table(map_key: str, rows: list[dict], alone_rows: list[dict]) -> Table:
    """Figs. 16-17 as a table: R1's steps per target with R1..R4 per err_max, and R1 alone."""
    by_nav = group(rows, NAV_KEY)
    alone_by_nav = group(alone_rows, NAV_KEY)
    errs = sorted({float(e) for r in rows if (e := (r.get("params") or {}).get(ERR_KEY)) is not None})
    out = []
    for nav in L.NAVIGATORS:
        per = {float(k): v for k, v in group(by_nav.get(nav, []), ERR_KEY).items() if k is not None}
        if not per:
            continue
        cells = [cell(steps_of(per.get(e, [])), finished_of(per.get(e, []))) for e in errs]
        a = alone_by_nav.get(nav, [])
        out.append([NAV_LABEL[nav], *cells, cell(steps_of(a), finished_of(a))])
    fig = 16 if map_key == "simple" else 17
    n_t = targets_per_task({0: rows})
    return Table(f"Fig. {fig} ({L.MAPS[map_key]}) as a table: R1's steps per target with R2..R4 vs err_max, "
                 "mean (std %) tasks finished / run",
                 ["algorithm", *(f"err_max {e:g}" for e in errs), "R1 alone"], out,
                 f"{n_t} targets per task; eqs. 1-2 noise on every robot's detector; 'R1 alone' is Table "
                 f"{1 if map_key == 'simple' else 2}'s first column (no detector in use).")

def ablation_block(rows: list[dict]) -> Table:
    variants = [((False, False), "reflected visibility only (§3)"), ((True, False), "+ ghost robots (§4)"),
                ((True, True), "+ state sharing (§5)"), ((False, True), "reflected + state sharing")]
    table_rows = []
    for nav in L.NAVIGATORS:
        rs = group(rows, NAV_KEY).get(nav, [])
        cells = []
        for (dv, ss), _ in variants:
            sel = [r for r in rs if (r["params"].get(DELAYED_KEY), r["params"].get(STATE_KEY)) == (dv, ss)]
            cells.append(cell(steps_of(sel), finished_of(sel)))
        table_rows.append([NAV_LABEL[nav], *cells])
    return Table("Ablation (office_simple, R1..R4): what each rule buys — R1's steps, mean (std %)",
                 ["algorithm", *(v[1] for v in variants)], table_rows,
                 "Goal sharing on in every column; the tables use '+ state sharing' for the potential field and "
                 "'+ ghost robots' for the others. The flags are R1's: the "
                 "helpers keep their §4.3 bookkeeping in every column (one grid key cannot set four robots' flags).")

def traffic_block(rows_by_map: dict[str, list[dict]]) -> Table:
    out = []
    for m, rows in rows_by_map.items():
        for nav in L.NAVIGATORS:
            rs = group(rows, NAV_KEY).get(nav, [])
            if not rs:
                continue
            msgs = np.array([_metric(r, "los_msgs_per_robot") for r in rs])
            nbytes = np.array([_metric(r, "los_bytes_per_robot") for r in rs])
            steps = np.array([_metric(r, "los_steps") for r in rs], dtype=float)
            out.append([L.MAPS[m], NAV_LABEL[nav], f"{np.nanmean(msgs):.0f}", f"{np.nanmean(nbytes) / 1024:.1f}",
                        f"{np.nanmean(nbytes / np.maximum(steps, 1)):.1f}"])
    return Table("§4.4 traffic with R1..R4 (per robot and task)", ["map", "algorithm", "messages", "KiB", "bytes per R1 step"],
                 out, "Messages are sent only to teammates in line of sight; O(M) bytes per meeting (§4.4).")

FRACTIONS = (("goal_seen", "goal in sight"), ("follow_teammate", "to a teammate"), ("ghost", "to a ghost"),
             ("promised", "on a promise"), ("trouble_follow", "to a helper (in trouble)"))

def where_steps_go_block(tables: dict[str, dict[int, list[dict]]]) -> Table:
    """Where R1's steps went with helpers (§3-§5): share of its steps per temporary-goal kind,
    the rest being the navigator towards its unseen goal; and how often the temporary goal
    changed per target (oscillation between temporary goals would show there)."""
    out = []
    for m, by_team in tables.items():
        for h in sorted(by_team):
            if h == 0:
                continue
            for nav in L.NAVIGATORS:
                rs = group(by_team[h], NAV_KEY).get(nav, [])
                if not rs:
                    continue
                fr = [_mean([_metric(r, f"los_frac_{k}") for r in rs]) for k, _ in FRACTIONS]
                if not np.isfinite(fr).any():
                    continue  # runs without these logs
                rest = 1.0 - float(np.nansum(fr))
                sw = _mean([_metric(r, "los_temp_switches") / max(_metric(r, "los_targets_reached"), 1.0)
                            for r in rs])
                out.append([L.MAPS[m], TEAM_LABEL[h], NAV_LABEL[nav], *(f"{100 * f:.0f} %" for f in fr),
                            f"{100 * rest:.0f} %", f"{sw:.1f}"])
    return Table("Where R1's steps go with helpers (share of its steps, mean over tasks)",
                 ["map", "team", "algorithm", *(t for _, t in FRACTIONS), "navigator to goal", "switches / target"],
                 out, "'to a teammate': heading for a teammate in sight that offers the shortest D (§3); 'to a ghost': "
                      "for where a teammate promised it (§4); 'on a promise': for its goal from a ghost where the "
                      "teammate saw the goal itself; 'switches': changes of temporary goal per target reached.")

LEGS = (("leave", "leaving its room"), ("corridor", "corridors"), ("other_rooms", "wrong rooms"),
        ("enter", "entering the target's room"))


def _floor_of(map_key: str, rows: list[dict]) -> float:
    """Mean shortest-path steps per target over the tasks of ``rows`` (:func:`los_tasks.shortest_steps_for_targets`)."""
    floors = []
    for r in rows:
        t = (r.get("params") or {}).get(TARGETS_KEY)
        if t:
            try:
                floors.append(L.shortest_steps_for_targets(map_key, L.frame_to_world(L.LAYOUTS[map_key].r1_start, t)))
            except ValueError:
                return float("nan")  # targets that are not the map's room centres: no floor
    return float(np.mean(floors)) if floors else float("nan")


def legs_block(tables: dict[str, dict[int, list[dict]]]) -> Table:
    """Where R1's path goes, per target (metric ``los_legs``), against the shortest path.

    Ours, not the paper's (§6 reports the total only): it shows which part of R1's path the
    helpers shorten. They stand in the corridors, so they can shorten the corridor legs and the
    wrong rooms; a room R1 must leave it leaves on its navigator's own until a helper that knows
    its new goal's way comes into its sight."""
    out = []
    for m, by_team in tables.items():
        for nav in L.NAVIGATORS:
            for h in sorted(by_team):
                rs = group(by_team[h], NAV_KEY).get(nav, [])
                fin = finished_of(rs)
                done = [r for r, f in zip(rs, fin) if f > 0.5]
                # the finished tasks, as in Tables 1-2; a cell that finished none shows the targets it
                # reached, with no ratio (its floor would be the whole task's)
                use = done or rs
                parts = [_mean([_metric(r, f"los_leg_{k}") for r in use]) for k, _ in LEGS]
                if not rs or not np.isfinite(parts).any():
                    continue  # runs without the metric
                floor = _floor_of(m, use)
                total = float(np.nansum(parts))
                ratio = f"{total / floor:.2f}" if done and floor > 0 else "n/a (no task finished)" if not done else "n/a"
                out.append([L.MAPS[m], NAV_LABEL[nav], TEAM_LABEL[h], *(f"{p:.0f}" for p in parts), f"{total:.0f}",
                            f"{floor:.0f}", ratio, f"{int((fin > 0.5).sum())}/{fin.size}"])
    return Table("Where R1's path goes, motion steps per target reached (mean over tasks), against the shortest path",
                 ["map", "algorithm", "team", *(t for _, t in LEGS), "total", "shortest path", "total / shortest",
                  "finished"],
                 out, "From R1's true positions at the kept samples: 'leaving its room' runs from the last target until "
                      "R1 first stands in a corridor, 'entering' from its last corridor sample to the target, 'wrong "
                      "rooms' are the rooms it stepped into in between. 'Shortest path': the shortest collision-free "
                      "path through the task's targets for R1's body, less ε at each end of a leg (grid estimate within "
                      "3 %; teamnav.world.shortest_path). Means over the finished tasks, as in Tables 1-2; a cell that "
                      "finished none shows the legs of the targets it reached.")


# ---------------------------------------------------------------------------- two columns and route plans
#: the section's two columns: (key, heading); the trail and collab-mcl sections use the same
COLUMNS = (("paper_rules", "paper as written"), ("teamnav", "teamnav"))
HEAD = dict(COLUMNS)


def table_block_cols(map_key: str, by_col: dict[str, dict[int, list[dict]]]) -> tuple[Table, dict[str, dict[str, list[float]]]]:
    """Table 1 or 2 with both columns beside the paper's: per algorithm a row "paper as written"
    (``paper_rules: true``), a row "teamnav" (our gap-fills) and the paper's row; and each
    column's mean steps per algorithm and team size (:func:`table_block`)."""
    per = {col: table_block(map_key, by_col.get(col, {})) for col, _ in COLUMNS}
    rows: list[list[str]] = []
    for i, nav in enumerate(L.NAVIGATORS):
        for col, head in COLUMNS:
            rows.append([NAV_LABEL[nav] if col == COLUMNS[0][0] else "", head, *per[col][0].rows[2 * i][2:]])
        rows.append(["", "paper", *per[COLUMNS[0][0]][0].rows[2 * i + 1][2:]])
    first = per[COLUMNS[0][0]][0]
    note = (first.note + " Rows: 'paper as written' runs both brains with paper_rules: true (every gap-fill whose "
            "other value is the paper's rule at the paper's value, the gap-fill table below); 'teamnav' runs our "
            "gap-fills; verdicts are judged on the paper-as-written rows.")
    return Table(first.title, first.columns, rows, note), {col: per[col][1] for col, _ in COLUMNS}


def robots_plot_cols(map_key: str, by_col: dict[str, dict[int, list[dict]]]) -> Plot:
    """Fig. 12 or 14 with a curve per algorithm and column."""
    plots = {col: robots_plot(map_key, by_col.get(col, {})) for col, _ in COLUMNS}
    first = plots[COLUMNS[0][0]]
    series = [Series(f"{s.label} ({head})", s.x, s.y, s.lo, s.hi, style=("line+points" if col == "paper_rules" else "points"))
              for col, head in COLUMNS for s in plots[col].series]
    return Plot(first.title, first.xlabel, first.ylabel, series,
                caption=first.caption + " Lines with points: paper as written; points only: teamnav.")


def noise_plot_cols(map_key: str, rows_by_col: dict[str, list[dict]], alone_by_col: dict[str, dict[str, float]]
                    ) -> tuple[Plot, dict[str, dict[str, dict[float, float]]]]:
    """Fig. 16 or 17 with a curve per algorithm and column; R1 alone's lines of the paper-as-written
    column (R1 alone runs the same rules as its column; both levels are in the table)."""
    got = {col: noise_plot(map_key, rows_by_col.get(col, []), alone_by_col.get(col, {})) for col, _ in COLUMNS}
    first = got[COLUMNS[0][0]][0]
    series = [Series(f"{s.label} ({head})", s.x, s.y, s.lo, s.hi, style=("line+points" if col == "paper_rules" else "points"))
              for col, head in COLUMNS for s in got[col][0].series]
    hl = [(y, f"{lab} ({HEAD[col]})") for col, _ in COLUMNS for y, lab in got[col][0].hlines]
    cap = " ".join(f"{HEAD[col]}: {got[col][0].caption}" for col, _ in COLUMNS)
    return (Plot(first.title, first.xlabel, first.ylabel, series, hlines=hl,
                 caption="Lines with points: paper as written; points only: teamnav. " + cap),
            {col: got[col][1] for col, _ in COLUMNS})


def noise_table_cols(map_key: str, rows_by_col: dict[str, list[dict]], alone_by_col: dict[str, list[dict]]) -> Table:
    """Figs. 16-17 as a table, a row per algorithm and column (:func:`noise_table`)."""
    per = {col: noise_table(map_key, rows_by_col.get(col, []), alone_by_col.get(col, [])) for col, _ in COLUMNS}
    cols = max((t.columns for t in per.values()), key=len)
    by_label = {col: {r[0]: r for r in per[col].rows} for col, _ in COLUMNS}
    rows = [[NAV_LABEL[nav], HEAD[col], *by_label[col][NAV_LABEL[nav]][1:]] for nav in L.NAVIGATORS
            for col, _ in COLUMNS if NAV_LABEL[nav] in by_label[col]]
    first = per[COLUMNS[0][0]]
    return Table(first.title, [cols[0], "column", *cols[1:]], rows, first.note)


def route_plans_block(plans_by_col: dict[str, list[dict[int, list[dict]]]], labels: tuple[str, ...]) -> Table:
    """Table 2's robustness column: R1's steps per target per algorithm, column and
    route plan for R2..R4, and the mean over the plans that the Table 2 verdicts read
    (claims/los-help.yaml; per plan the tasks finished, unpaired here: the verdicts pair by task)."""
    from teamnav.papers.los_help.report._los_verdicts import _team_mean

    rows: list[list[str]] = []
    for nav in L.NAVIGATORS:
        for col, head in COLUMNS:
            plans = plans_by_col.get(col, [])
            for label, p in zip(labels, plans):
                cells = []
                for h in range(4):
                    rs = group(p.get(h, []), NAV_KEY).get(nav, [])
                    cells.append(cell(steps_of(rs), finished_of(rs)) if h in p else "not run")
                rows.append([NAV_LABEL[nav], head, label, *cells])
            if plans:
                ms = [[_team_mean(p, nav, h) for p in plans] for h in range(4)]
                rows.append([NAV_LABEL[nav], head, f"mean over {len(plans)} plans",
                             *("n/a" if not np.isfinite(m).all() else f"{np.mean(m):.0f}" for m in ms)])
    return Table("Table 2 over route plans for R2..R4 (robustness column): R1's motion steps per target, "
                 "mean (std %) tasks finished / run",
                 ["algorithm", "column", "route plan", *TEAM_LABEL.values()], rows,
                 "Plans chosen before their runs (report/sections/_los_common.ROUTE_PLANS; scenarios los-help-complex, "
                 "-plan-b, -plan-c); R1 alone is the same run in every plan. 'mean over plans': the mean of the plans' "
                 "means over finished tasks (n/a when a plan finished none); the Table 2 verdicts read the mean over "
                 "the plans of the paired-by-task means (claims/los-help.yaml).")


def gap_fill_blocks() -> list[Table]:
    """The gap-fills of both brains with teamnav's value and the paper's (``paper_rules: true``
    sets the paper's), and the rules the paper leaves unspecified with how each is filled (kept in
    both columns)."""
    from teamnav.control import registry
    from teamnav.papers.los_help.brains.params import los_gap_fills
    from teamnav.experiments.spec import load_scenario

    scn = load_scenario("los-help-simple")
    rows, seen = [], set()
    for brain, group_i, navs in (("los-explorer-v1", 0, L.NAVIGATORS), ("los-helper-v1", 1, ("visbug21",))):
        cls = registry.lookup(brain).Params
        ours = {k: v for k, v in scn.robots[group_i].params.items() if k not in ("targets_xy", "patrol_xy")}
        for nav in navs:
            for g in los_gap_fills(cls, nav, {**ours, "navigator": nav}):
                key = (brain, g.field if not g.field.startswith("navigator_params") else f"{g.field} ({nav})")
                if key in seen:
                    continue
                seen.add(key)
                rows.append([brain, key[1], repr(g.teamnav_value), repr(g.paper_value), g.note])
    kept = []
    for brain in ("los-explorer-v1", "los-helper-v1"):
        for k, v in registry.lookup(brain).Params.GAP_FILLS_KEPT.items():
            kept.append([brain, k, v])
    return [Table("Gap-fills of the two brains: teamnav's value and the paper's (paper_rules: true sets the paper's)",
                  ["brain", "parameter", "teamnav", "paper as written", "where the paper says so"], rows,
                  "Each a flag of the brain's Params (PAPER_RULES); the 'paper as written' column of Tables 1-2 and "
                  "Figs. 16-17 runs every one at the paper's value."),
            Table("What the paper leaves unspecified, and how we fill it (the same in both columns)",
                  ["brain", "parameter", "the gap and our value"], kept,
                  "GAP_FILLS_KEPT of the brains: the paper gives no value, so both columns use ours. The maps' room "
                  "layouts beyond Figs. 11 and 13, the targets and the helpers' routes are ours too "
                  "(teamnav.papers.los_help.tasks).")]
