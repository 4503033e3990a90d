"""scripts/collab_mcl_collapse.py: one factor at a time on top of the paper's
rules, tuning seeds only, and the measures it reports (Fox, Burgard, Kruppa & Thrun §5.1, Fig. 10a)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from teamnav.papers.collab_mcl.brains.localizing import MCLWanderParams
from teamnav.experiments.spec import load_scenario

_PATH = Path(__file__).resolve().parents[1] / "scripts" / "collab_mcl_collapse.py"
_spec = importlib.util.spec_from_file_location("collab_mcl_collapse", _PATH)
cc = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cc)


def test_report_seeds_are_refused():
    assert cc.parse_seeds("1000-1002,1010") == [1000, 1001, 1002, 1010]
    with pytest.raises(ValueError, match="report seeds"):
        cc.parse_seeds("7")
    with pytest.raises(ValueError, match="report seeds"):
        cc.parse_seeds("998-1001")


def test_paper_baseline_is_paper_rules_on_robin_and_keeps_marian():
    over = cc.overrides("detection", "paper", collaborate=False)
    robin, marian = over["robots.1.params"], over["robots.0.params"]
    assert robin["paper_rules"] is True and robin["collaborate"] is False
    # Marian keeps sending in both conditions: only Robin's use of detections is switched
    assert marian["collaborate"] is True and marian["paper_rules"] is True
    load_scenario("collab-mcl-detection", overrides=over, seed=1000, duration_s=1.0)


def test_a_factor_changes_only_its_own_setting():
    over = cc.overrides("detection", "sigma", collaborate=True)
    beam = over["robots.1.params"].get("beam", {})
    assert beam["sigma_hit_m"] == 1.0
    # the factor is on Robin only; Marian's filter is the paper-rules one
    assert "beam" not in over["robots.0.params"] or over["robots.0.params"]["beam"].get("sigma_hit_m") != 1.0
    hall = cc.overrides("hallway", "sigma", collaborate=False)["robots.0.params"]
    # the scenario's other beam-mixture weights stay (a nested merge, not a replacement)
    assert hall["beam"]["sigma_hit_m"] == 1.0 and hall["beam"]["z_hit"] == 0.7
    assert hall["paper_rules"] is True and hall["collaborate"] is False


@pytest.mark.parametrize("factor, field, value", [("temper", "likelihood_exponent", 0.03),
                                                  ("ess", "resample_ess_fraction", 0.5)])
def test_a_factor_that_is_a_paper_rule_writes_the_other_rules_out(factor, field, value):
    p = cc.overrides("detection", factor, collaborate=True)["robots.1.params"]
    assert "paper_rules" not in p and p[field] == value
    for k, v in MCLWanderParams.PAPER_RULES.items():
        if k != field:
            assert p[k] == v, k
    load_scenario("collab-mcl-detection", overrides=cc.overrides("detection", factor, True), seed=1000,
                  duration_s=1.0)


def test_one_short_run_measures_the_belief_and_a_flatter_likelihood_keeps_it_wider():
    """The script's measures on one short run; a flatter likelihood (exponent 0.03) keeps the belief
    wider. Until 2026-11-29 (90 beams at sigma_hit 0.2 m, the bare corridor) the paper-rules belief was
    within a metre at 5 s on seed 1000 (the collapse the script was written for); with the beam fill
    (10 beams, 0.8 m) it is still spread over metres."""
    paper = cc.one_run(("detection", "paper_rules", "paper", 1000, True, 6.0))
    temper = cc.one_run(("detection", "paper_rules", "temper", 1000, True, 6.0))
    for r in (paper, temper):
        assert {"n_5s", "spread_5s_m", "final_error_m", "det_n"} <= set(r)
        assert r["det_n"] is None  # no detection in 6 s
    assert paper["spread_5s_m"] > 1.0
    assert temper["spread_5s_m"] > paper["spread_5s_m"]


def test_teamnav_checks_load():
    for name, (scen, _, _) in cc.TEAMNAV_CHECKS.items():
        part = next(k for k, v in cc.PART_SCENARIO.items() if v == scen)
        over = cc.overrides(part, name, collaborate=True, column="teamnav")
        assert all("paper_rules" not in p for p in over.values())
        load_scenario(scen, overrides=over, seed=1000, duration_s=1.0)
    p = cc.overrides("detection", "detection-prior0.6", True, "teamnav")["robots.1.params"]
    assert p["inject_lost_prior"] == 0.6 and p["inject_fraction"] == 0.2


# ---------------------------------------------------------------------------- the section's copy of the results
_DATA = Path(__file__).resolve().parents[1] / "docs" / "report" / "collab-mcl-collapse.jsonl"


def test_section_numbers_are_the_committed_runs():
    """The report section quotes TUNING_RUNS; they must be the script's summary of the committed runs."""
    import json

    from teamnav.papers.collab_mcl.report import section as sec

    rows = [json.loads(x) for x in _DATA.read_text().splitlines() if x.strip()]
    assert all(r["seed"] >= cc.TUNING_SEED_MIN for r in rows)
    assert list(sec.TUNING_RUNS) == cc.table_rows(rows)
    assert sec.COLLAPSE_FACTORS == {k: (w, st) for k, (w, _, st) in cc.FACTORS.items()}


def _det_row(team_final_m, team_localized, alone_final_m=6.9):
    return {"part": "detection", "column": "teamnav", "factor": "detection", "seeds": list(range(1000, 1020)),
            "alone_final_m": alone_final_m, "alone_localized": 10, "alone_runs": 20,
            "team_final_m": team_final_m, "team_localized": team_localized, "team_runs": 20}


@pytest.mark.parametrize("row, holds", [(_det_row(1.2, 19), True), (_det_row(2.49, 18), False),
                                        (_det_row(1.2, 17), False), (_det_row(1.2, 19, alone_final_m=0.2), False)])
def test_tuning_rows_are_judged_by_the_claim_files_rule(row, holds):
    from teamnav.experiments.claims import judge, load_claims
    from teamnav.papers.collab_mcl.report.section import tuning_claim_values

    assert judge(load_claims("collab-mcl")["single-detection"], tuning_claim_values(row))[0] is holds


def test_hallway_tuning_row_needs_the_paired_reduction():
    from teamnav.experiments.claims import judge, load_claims
    from teamnav.papers.collab_mcl.report.section import tuning_claim_values

    row = {"part": "hallway", "alone_ttl_s": 150.0, "team_ttl_s": 139.0, "alone_final_localized": 0.78,
           "team_final_localized": 0.91, "paired_s": -11.0, "paired_se_s": 33.0, "pairs": 12}
    claim = load_claims("collab-mcl")["hallway-faster"]
    assert judge(claim, tuning_claim_values(row))[0] is False  # -11 + 2 x 33 > 0
    assert judge(claim, tuning_claim_values({**row, "paired_se_s": 5.0}))[0] is True


def test_the_tuning_blocks_have_rows():
    from teamnav.experiments.report.model import Table
    from teamnav.papers.collab_mcl.report.section import _tuning_blocks

    blocks = _tuning_blocks()
    assert [type(b) for b in blocks] == [Table, Table, Table]
    factors = {row[0] for row in blocks[0].rows}
    assert {"paper", "floor", "motion", "sigma", "beams", "temper", "ess"} <= factors
    assert {row[0] for row in blocks[2].rows} == {"hallway-faster", "hexagon-together", "single-detection"}
