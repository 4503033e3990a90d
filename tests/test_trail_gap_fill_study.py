"""scripts/trail_gap_fill_study.py: its configurations are the report's two columns
and single gap-fills between them (Vaughan et al. 2000 §4), and its drift cases are blazing-drift's."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

from teamnav.papers.trails.brains.blazing_trail import BlazingTrailParams, navigate_params
from teamnav.experiments.spec import load_scenario
from teamnav.experiments.sweep import load_sweep
from teamnav.experiments.report.model import Missing
from teamnav.papers.trails.report import _trails_gap_fills as GF

_PATH = Path(__file__).resolve().parents[1] / "scripts" / "trail_gap_fill_study.py"
_spec = importlib.util.spec_from_file_location("trail_gap_fill_study", _PATH)
gs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(gs)


def _dump(params: dict) -> dict:
    """The brain's parameters, its nested Navigate dict resolved as the brain resolves it
    (as the brain builds it; its cruise speed is the brain's own), ``paper_rules`` itself left out."""
    p = BlazingTrailParams(**params)
    out = p.model_dump(exclude={"paper_rules"})
    out["navigate"] = navigate_params(p.navigate, p.cruise_speed_mps).model_dump(exclude={"paper_rules", "cruise_speed_mps"})
    return out


def test_paper_config_is_paper_rules_true_as_the_study_ran_it():
    """The study's "paper" configuration, written out field by field, validates to the same
    brain parameters as ``paper_rules: true`` with the two settings the study's stored runs had
    then (0.25 m/s, crumbs laid while carrying not reversed), which are no longer paper rules."""
    assert _dump(gs.params_for("paper")) == _dump({**gs.BASE_PARAMS, "paper_rules": True, "cruise_speed_mps": 0.25,
                                                   "reverse_carried_crumbs": False})
    assert _dump(gs.params_for("paper")) != _dump({**gs.BASE_PARAMS, "paper_rules": True})


def test_teamnav_config_is_the_scenario_column():
    assert _dump(gs.params_for("teamnav")) == _dump({**gs.BASE_PARAMS, "cruise_speed_mps": 0.4})


@pytest.mark.parametrize("field", [g.field for g in gs.gap_fill_table()])
def test_one_gap_fill_differs_from_its_column(field):
    """``paper+G`` differs from ``paper`` in G alone; ``teamnav-G`` from ``teamnav`` in G alone."""
    head, _, tail = field.partition(".")

    def get(d):
        return d[head][tail] if tail else d[head]

    for base, config in (("paper", f"paper+{field}"), ("teamnav", f"teamnav-{field}")):
        a, b = _dump(gs.params_for(base)), _dump(gs.params_for(config))
        assert get(a) != get(b)
        diff = {k for k in a if a[k] != b[k]}
        assert diff == {head}
        if tail:
            assert {k for k in a[head] if a[head][k] != b[head][k]} == {tail}


def test_unknown_configuration_names_the_known_ones():
    with pytest.raises(ValueError, match="reverse_carried_crumbs"):
        gs.params_for("paper+no_such_fill")


def test_drift_cases_match_the_blazing_drift_sweep():
    """The study's drift cases set the same non-zero odometry errors as ``blazing-drift``'s cases."""
    sweep = load_sweep("blazing-drift")
    cases = {c["case"]: c for c in sweep.cases}

    def nonzero(d):
        return {k: float(v) for k, v in d.items() if k != "case" and float(v) != 0.0}

    for case in gs.DRIFT_CASES:
        mine = nonzero(gs.drift_overrides(case))
        assert mine == pytest.approx(nonzero(cases[case]))
        assert set(mine) == set(nonzero(cases[case]))
    load_scenario("blazing-a-trail", overrides=gs.drift_overrides("x1-slip"), seed=100, duration_s=1.0)
    with pytest.raises(ValueError, match="x1-slip"):
        gs.drift_overrides("x1-wobble")


def test_report_seeds_are_refused():
    assert gs.parse_seeds("100-102,110") == [100, 101, 102, 110]
    with pytest.raises(SystemExit, match="report"):
        gs.parse_seeds("5-105")


def test_study_tables_pair_by_seed():
    """The paired column is the mean over seeds of (config - paper) on the same seed, with its
    standard error and the count of seeds where the config delivered more."""
    from teamnav.papers.trails.report._trails_gap_fills import table_rows

    def run(config, seed, units, bd=None):
        return {"part": "gapfills", "case": "", "config": config, "seed": seed, "duration_s": 1800.0,
                "units": units, "units_second_half": units // 2, "breakdown_s": bd or 1800.0,
                "breakdown_censored": bd is None, "cpu_s": 1.0}

    runs = [run("paper", 1, 2, 600.0), run("paper", 2, 4, 1200.0), run("paper", 3, 6),
            run("paper+x", 1, 12), run("paper+x", 2, 10), run("paper+x", 3, 6),
            run("teamnav", 1, 30), run("teamnav", 2, 30), run("teamnav", 3, 30),
            run("teamnav-x", 1, 20), run("teamnav-x", 2, 24), run("teamnav-x", 3, 30)]
    rows = {r[0]: r for r in table_rows(runs, "gapfills", "")}
    # differences 10, 6, 0: mean 5.3, std 5.03, s.e. 2.9; 2 of 3 seeds more
    assert rows["paper+x"][2] == "+5.3 ± 2.9 (2/3)"
    assert rows["paper"][2] == "reference"
    assert rows["paper"][1] == "4.0 ± 2.0" and rows["paper"][4] == "2/3"
    assert rows["paper"][5] == "20"  # median of 10, 20 and 30+ (censored at the run's end) min
    assert rows["paper+x"][5] == "30+"
    # leaving a gap-fill out of ours is paired with ours: -10, -6, 0
    assert rows["teamnav-x"][2] == "-5.3 ± 2.9 (0/3)"


@pytest.mark.parametrize("system, files", [
    ("blazing", ("blazing-gap-fill-study.jsonl", "blazing-drift-study.jsonl", "blazing-breakdown-study.jsonl")),
    ("try", ("try-gap-fill-study.jsonl", "try-reversal-study.jsonl")),
])
def test_stored_study_runs_are_the_docs_jsonl(system, files):
    """The sections' package data hold exactly the runs recorded in docs/report/."""
    from teamnav.papers.trails.report._trails_gap_fills import study_runs

    docs = Path(__file__).resolve().parents[1] / "docs" / "report"
    lines = []
    for name in files:
        path = docs / name
        if path.exists():
            lines += [json.loads(x) for x in path.read_text().splitlines() if x.strip()]

    def key(r):
        return (r["part"], r["case"], r["config"], r["seed"])

    assert sorted(study_runs(system), key=key) == sorted(lines, key=key)
    assert all(r.get("system", "blazing") == system for r in lines)


def test_try_configs_are_trail_share_columns():
    """``--system try``: the paper configuration is trail-share-v1's paper_rules column."""
    from teamnav.papers.trails.brains.trail_share import TrailShareParams

    p = TrailShareParams(**gs.params_for("paper", "try")).model_dump(exclude={"paper_rules", "navigate"})
    q = TrailShareParams(**{**gs.SYSTEMS["try"][2], "paper_rules": True}).model_dump(exclude={"paper_rules", "navigate"})
    assert p == q
    assert {g.field for g in gs.gap_fill_table("try")} >= {"descend_only", "recover_radius_m"}


def test_paper_2000_config_is_the_report_paper_column():
    """The breakdown study's "paper-2000" is the 2000 paper column the report judges: paper_rules, the
    single trail followed backwards (reversed carried crumbs) and the implied 0.4 m/s."""
    from teamnav.papers.trails.report._trails import BLAZING_IMPLIED_CRUISE_MPS

    assert _dump(gs.params_for("paper-2000")) == _dump({**gs.BASE_PARAMS, "paper_rules": True,
                                                        "cruise_speed_mps": BLAZING_IMPLIED_CRUISE_MPS})


@pytest.mark.parametrize("case, h", [("x1-slip", 1.0), ("x1-slip0.5", 0.5), ("x1-slip2", 2.0)])
def test_slip_cases_name_their_heading_random_walk(case, h):
    ov = gs.drift_overrides(case)
    assert {ov[f"robots.{i}.odometry.heading_slip_deg_per_sqrt_m"] for i in range(4)} == {h}
    assert ov["robots.2.odometry.heading_drift_deg_per_min"] == 2.0  # k = 1: Fly's 2 deg/min
    with pytest.raises(ValueError, match="unknown drift case"):
        gs.drift_overrides("x1-slipper")


def test_breakdown_table_reports_runs_that_never_worked_apart_and_counts_within_30_min():
    def run(seed, times, case="x1-slip"):
        cens = bool(times) and 3600.0 - times[-1] < 180.0
        return {"part": "breakdown", "config": "paper-2000", "case": case, "seed": seed, "duration_s": 3600.0,
                "units": len(times), "breakdown_censored": cens, "reversals": 40, "delivery_times_s": times}

    rows = [run(1000, [100.0, 200.0]),                    # 2 units in 30 min: never worked
            run(1001, [100.0 * k for k in range(1, 15)]),  # last at 1400 s: broke down within 30 min
            run(1002, [100.0 * k for k in range(1, 36)]),  # working until 3500 s: no breakdown
            run(1003, [100.0 * k for k in range(1, 25)])]  # 1700 s < 1800 - 180 is false: breaks down at 2400 s
    (row,) = GF.breakdown_rows(rows)
    assert row[:3] == ["paper-2000", "x1-slip", "4"]
    assert row[3] == "1 (seeds 1000)"
    assert row[4] == "1/3" and row[5] == "2/3"  # within 30 min: seed 1001 only; within the hour: 1001 and 1003
    assert row[7] == "40"


def _probe(config, case, seed, units, broke, reversals=100, cruise=0.4, probe="precondition-2000"):
    return {"probe": probe, "part": "drift", "config": config, "case": case, "seed": seed, "duration_s": 1800.0,
            "units": units, "units_second_half": units // 2, "first_delivery_s": 200.0, "breakdown_s": 900.0,
            "breakdown_censored": not broke, "cpu_s": 7.0, "reversals": reversals, "cruise_mps": cruise}


@pytest.mark.parametrize("units, broke, holds", [
    ([20, 18, 16, 15, 14], [False] * 4 + [True], True),   # mean 16.6 >= 14, one breakdown
    ([20, 18, 16, 15, 14], [False] * 3 + [True] * 2, False),  # two breakdowns
    ([13, 14, 12, 15, 14], [False] * 5, False),            # mean 13.6 < 14 (half the paper's 28)
])
def test_the_2000_precondition_reads_the_k0_probe_runs(units, broke, holds):
    runs = [_probe("paper-2000", "x0", 1000 + i, u, b) for i, (u, b) in enumerate(zip(units, broke))]
    runs += [_probe("paper-2000", "", 1000, 1, True)]  # the scenario's drift: not part of the check
    pre = GF.precondition_2000(runs)
    assert pre.holds is holds and pre.seeds == "1000-1004" and pre.claims == ("drift-breakdown",)
    assert ("precondition not met" in pre.result) is (not holds)
    assert GF.precondition_2000([]).holds is None


def test_probe_table_has_turns_per_hour_and_per_km():
    runs = [_probe("teamnav", "x0", 1000, 30, False, reversals=36, probe="speed-0.25"),
            _probe("teamnav@0.25", "x0", 1000, 15, False, reversals=36, cruise=0.25, probe="speed-0.25")]
    t = GF.probe_table("speed-0.25", runs)
    fast, slow = t.rows
    assert fast[0] == "teamnav" and slow[0] == "teamnav@0.25"
    assert fast[7] == slow[7] == "72.0"  # 36 turns in 30 min
    # per km at cruise: 72 / (4 robots x 1.44 km/h) = 12.5 at 0.4 m/s, 72 / (4 x 0.9) = 20 at 0.25 m/s
    assert fast[8] == "12.5" and slow[8] == "20.0"
    assert isinstance(GF.probe_table("speed-0.25", []), Missing)


def test_stored_probe_runs_are_the_docs_jsonl():
    """The probes on tuning seeds in package data are the lines of docs/report/trails-probes.jsonl,
    every one on a tuning seed (1000-1999)."""
    docs = Path(__file__).resolve().parents[1] / "docs" / "report" / "trails-probes.jsonl"
    lines = [json.loads(x) for x in docs.read_text().splitlines() if x.strip()] if docs.exists() else []

    def key(r):
        return (r["probe"], r["case"], r["config"], r["seed"])

    assert sorted(GF.probe_runs(), key=key) == sorted(lines, key=key)
    assert all(1000 <= r["seed"] < 2000 for r in lines)


def test_the_decompositions_seeds_are_its_own_not_those_of_the_turn_count():
    """The 'each gap-fill alone' text names the decomposition's paired seeds; the turn-count table
    (tuning seeds) names its own."""
    def run(part, seed):
        return {"part": part, "case": "", "config": "paper", "seed": seed, "duration_s": 1800.0, "units": 3,
                "units_second_half": 1, "breakdown_s": 1800.0, "breakdown_censored": True, "cpu_s": 1.0,
                "reversals": 10}

    out = GF.blocks([run("gapfills", s) for s in (100, 101)] + [run("reversals", s) for s in (1000, 1001)],
                    system="try")
    assert "paired seeds 100-101," in out[0].text
    assert any("seeds 1000-1001" in getattr(b, "title", "") for b in out[1:])
