"""The los-help step budget judged after the fact (report/_los_budget.py): a finished run whose
slowest target took more steps than a cut budget counts as not finished, and the verdicts are
computed again by the section's own rules."""

from __future__ import annotations

import pytest

from teamnav.experiments.claims import load_claims
from teamnav.experiments.report.model import Table, Text
from teamnav.papers.los_help import tasks as L
from teamnav.papers.los_help.report import _los_budget as B
from teamnav.papers.los_help.report._los_common import NAV_KEY, TARGETS_KEY

TASKS = list(range(1001, 1007))  # six tasks: the claim file's paired verdicts need at least 5 pairs
N = 20


def _row(task, h, steps, slowest, finished=1, gave_up=0, reached=N, nav="avoid_past"):
    return {"status": "ok",
            "params": {NAV_KEY: nav, TARGETS_KEY: L.task_targets_xy("simple", task, N),
                       **{f"robots.{k + 1}.count": int(k < h) for k in range(3)}},
            "metrics": {"los_finished": finished, "los_gave_up": gave_up, "los_steps_per_target": steps,
                        "los_steps": steps * reached, "los_targets_reached": reached,
                        "los_max_target_steps": slowest}}


def _tables(slowest_r1_4):
    """Avoid-Past steps falling 500 -> 400 -> 300 -> 200 on every task; R1..R4's slowest target
    took ``slowest_r1_4`` steps, every other team's 1000."""
    return {h: [_row(t, h, 500 - 100 * h + k, slowest_r1_4 if h == 3 else 1000) for k, t in enumerate(TASKS)]
            for h in range(4)}


def test_a_finished_run_over_the_cut_becomes_a_failure_and_others_stay():
    rows = [_row(1001, 0, 500, 2000), _row(1002, 0, 500, 1000), _row(1003, 0, 900, 7000, finished=0, gave_up=1)]
    cut = B.cut_rows(rows, 1500)
    assert [r["metrics"]["los_finished"] for r in cut] == [0, 1, 0]
    assert cut[0]["metrics"]["los_gave_up"] == 1 and cut[0]["metrics"]["los_budget_cut"] == 1
    assert rows[0]["metrics"]["los_finished"] == 1  # the section's own rows are not changed
    assert "los_budget_cut" not in cut[2]["metrics"]  # it had given up already
    # a finished row stored before the metric existed: the cut cannot be read
    old = _row(1004, 0, 500, 0)
    del old["metrics"]["los_max_target_steps"]
    assert B.cut_rows(rows + [old], 1500) is None
    assert B.over_cut(old, float("inf")) is False  # the budget as run needs no metric


def test_verdicts_recomputed_post_hoc_flip_when_the_most_helped_team_is_over_the_cut():
    budgets = {"simple": 6000.0}
    col_in = {"tables": {"simple": _tables(2000)}, "plans": {"simple": None}, "noise": {}}
    got = {frac: B.verdicts_at(col_in, frac, budgets) for frac in B.CUTS}
    # as run and at 3000 steps every team finishes, steps fall: holds; at 1500 R1..R4's tasks are
    # all over the cut, so the team with the most helpers fails what fewer helpers finished
    assert got[1.0]["table1-avoid-past-falls"][0] is True
    assert got[0.5]["table1-avoid-past-falls"][0] is True
    assert got[0.25]["table1-avoid-past-falls"][0] is False
    assert B.verdict_word(got[0.25]["table1-avoid-past-falls"]) == "does not hold"
    # a slowest target just below the cut changes nothing
    col_in["tables"]["simple"] = _tables(1500)
    assert B.verdicts_at(col_in, 0.25, budgets)["table1-avoid-past-falls"][0] is True


def test_a_run_that_read_over_the_budget_only_by_sampling_is_not_cut_at_the_budget_as_run():
    budgets = {"simple": 6000.0}
    col_in = {"tables": {"simple": _tables(6005)}, "plans": {"simple": None}, "noise": {}}
    assert B.verdicts_at(col_in, 1.0, budgets)["table1-avoid-past-falls"][0] is True


def test_a_cut_r1_alone_run_leaves_the_alone_level_claims_not_recomputed():
    budgets = {"simple": 6000.0}
    tables = _tables(1000)
    tables[0][0]["metrics"]["los_max_target_steps"] = 5000  # R1 alone, task 1001: over the 1/2 cut
    from teamnav.papers.los_help.report._los_common import ERR_KEY

    noise = [{**r, "params": {**r["params"], ERR_KEY: e}} for e in (0.0, 0.4) for r in tables[3]]
    col_in = {"tables": {"simple": tables}, "plans": {"simple": None}, "noise": {"simple": noise}}
    assert B.verdicts_at(col_in, 1.0, budgets)["fig16-below-alone"][0] is not None
    half = B.verdicts_at(col_in, 0.5, budgets)
    assert half["fig16-below-alone"][0] is None
    assert B.verdict_word(half["fig16-below-alone"]).startswith("not recomputed")


def test_the_block_names_the_runs_that_gave_up_and_states_the_budget_in_shortest_paths():
    tables = _tables(1000)
    tables[1][2] = _row(1003, 1, 900, 800, finished=0, gave_up=1, reached=7)
    inputs = {"paper_rules": {"tables": {"simple": tables}, "plans": {"simple": None}, "noise": {}}}
    blocks = B.budget_blocks(inputs, {"simple": 6000.0}, {"simple": TASKS}, N, load_claims("los-help"),
                             {"paper_rules": "paper as written"})
    text = blocks[0].text
    assert isinstance(blocks[0], Text) and "paper as written 1 of 24" in text
    lo, hi = B.budget_multiples({"simple": 6000.0}, {"simple": TASKS}, N)["simple"]
    assert 1 < lo <= hi and f"{B.span(lo, hi)} times the task's shortest path per target" in text
    assert B.span(12.6, 12.8) == "13" and B.span(12.4, 13.6) == "12-14"
    gave = [b for b in blocks if isinstance(b, Table) and b.title.startswith("Runs that gave up")][0]
    assert gave.rows == [["paper as written", "Table 1", "Av. Past", "R1,2", "1003 (7)"]]
    verdicts = [b for b in blocks if isinstance(b, Table) and b.title.startswith("The verdicts with")][0]
    assert verdicts.columns[1:] == [f"paper as written, budget x {f:g}" for f in B.CUTS]
    row = [r for r in verdicts.rows if r[0].startswith("Table 1: Av. Past")][0]
    assert len(verdicts.rows) == len(load_claims("los-help").claims)
    # the task R1,2 lost leaves 5 pairs (the claim file's least), every slowest target is under
    # the smallest cut: the same verdict at every budget
    assert row[1:] == ["holds"] * 3


@pytest.mark.parametrize("frac", B.CUTS)
def test_budget_multiples_scale_with_the_budget(frac):
    full = B.budget_multiples({"simple": 6000.0}, {"simple": TASKS}, N)["simple"]
    cut = B.budget_multiples({"simple": 6000.0 * frac}, {"simple": TASKS}, N)["simple"]
    assert cut == pytest.approx((full[0] * frac, full[1] * frac))


# ---------------------------------------------------------------------------- Avoid-Past half-lives with helpers
def test_the_half_lives_read_with_helpers_are_those_that_finished_all_tuning_tasks_and_500():
    from teamnav.control.nav.local import NAVIGATORS
    from teamnav.papers.los_help.report import _los_half_life as HL

    res = HL.tuning_results()
    assert HL.fill() == NAVIGATORS["avoid_past"].Params.model_fields["memory_half_life_steps"].default == 1000.0
    finished = {h for h, (k, n) in res.items() if k == n == len(L.TUNING_TASKS)}
    assert set(HL.half_lives()) == finished | {500.0, 1000.0}
    assert all(res[h][0] < res[h][1] or h in finished for h in HL.half_lives())
    assert 1000.0 not in HL.to_run() and 500.0 in HL.to_run()  # the fill's rows are the judged table's
    spec = HL.spec()
    assert len(spec.cases) == len(HL.to_run()) * len(L.TEAMS)
    assert {c[NAV_KEY] for c in spec.cases} == {"avoid_past"}
    assert sorted({c[HL.NAV_PARAMS_KEY]["memory_half_life_steps"] for c in spec.cases}) == list(HL.to_run())
    assert spec.grid[TARGETS_KEY] == [L.task_targets_xy("simple", t) for t in L.JUDGED_TASKS]
    assert f"{HL.trials()} trials" in HL.cpu_note() and HL.trials() == spec.n_trials
    # run as the section runs it (paper column): R1 keeps both the paper's rules and the half-life
    from teamnav.experiments.sweep import expand
    from teamnav.papers.trails.report._trails import paper_rules_spec

    trial = next(t for t in expand(paper_rules_spec(spec)) if t.params["case"] == "avoid-past-h500/R1-4")
    scen = trial.load()
    assert scen.robots[0].params["paper_rules"] is True and [g.count for g in scen.robots] == [1, 1, 1, 1]
    assert scen.robots[0].params["navigator_params"] == {"memory_half_life_steps": 500.0}


def test_the_half_life_block_reads_table_1s_avoid_past_rule_per_half_life_and_marks_the_fill():
    from teamnav.papers.los_help.report import _los_half_life as HL
    from teamnav.papers.los_help.report.section import team_of

    def rows(h, falling):
        out = []
        for t in range(4):
            for k, task in enumerate(TASKS):
                r = _row(task, t, (500 - 100 * t if falling else 300 + 50 * t) + k, 1000)
                r["params"][HL.NAV_PARAMS_KEY] = {"memory_half_life_steps": h}
                out.append(r)
        return out
    fill_rows = {t: [r for r in _tables(1000)[t]] for t in range(4)}
    got = HL.by_half_life(rows(250.0, True) + rows(500.0, False), fill_rows, team_of)
    assert sorted(got) == [250.0, 500.0, 1000.0] and len(got[250.0][3]) == len(TASKS)
    tab = HL.half_life_block(got)
    by = {r[0]: r for r in tab.rows}
    assert by["250"][-1] == "holds" and by["500"][-1] == "does not hold"
    assert by["1000 (the fill: the judged verdict)"][-1] == "holds"
    assert by["500"][1] == "0/1 (precondition not met)" and by["250"][1] == "5/5"
    assert by["250"][-2].startswith("0.4") and "6 pairs" in by["250"][-2]  # 200/500, paired over 6 tasks
