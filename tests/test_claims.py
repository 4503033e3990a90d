"""The claim files: strict schema, report seeds only, and the rules restored in defbca7."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from teamnav.experiments.claims import Claim, judge, load_claims

BASE = {"id": "x", "title": "t", "statement": {"quote": "q", "section": "§5"}, "paper_number": "2.8x",
        "metric": "r", "rule": [{"metric": "r", "op": ">=", "threshold": 2.5, "relative_to": "b"}],
        "seeds": "0-9", "n": 10, "judged": "paper_rules",
        "history": [{"date": "2026-11-27", "change": "c", "why": "w", "before_data": True}]}


@pytest.mark.parametrize("section", ["blazing-a-trail", "try-to-see-it-my-way"])
def test_the_trail_claim_files_load_and_judge_the_paper_rules_column(section):
    cf = load_claims(section)
    assert cf.section == section and cf.claims
    for c in cf.claims:
        assert c.judged == "paper_rules" and c.history
        assert not any(1000 <= s < 2000 for s in c.seed_list)  # never a tuning seed


def test_unknown_keys_tuning_seeds_and_bad_ops_are_refused():
    with pytest.raises(ValidationError, match="extra"):
        Claim.model_validate({**BASE, "threshold": 3})
    with pytest.raises(ValidationError, match="tuning seeds"):
        Claim.model_validate({**BASE, "seeds": "1000-1009"})
    with pytest.raises(ValidationError, match="tuning seeds"):
        Claim.model_validate({**BASE, "seeds": "1990-2009"})  # straddles the tuning range's end
    assert Claim.model_validate({**BASE, "seeds": "2000-2009"}).seed_list[0] == 2000  # fresh judged seeds
    with pytest.raises(ValidationError, match="seeds 1000-1999 are tuning seeds"):
        Claim.model_validate({**BASE, "seeds": "990-1000"})  # one tuning seed is enough to refuse
    with pytest.raises(ValidationError, match="tuning seeds"):
        Claim.model_validate({**BASE, "seeds": "1999-2000"})
    # fresh judged seeds (>= 2000, kept from tuning) are a report's
    assert Claim.model_validate({**BASE, "seeds": "2000-2009"}).seed_list[-1] == 2009
    with pytest.raises(ValidationError):
        Claim.model_validate({**BASE, "rule": [{"metric": "r", "op": "=>", "threshold": 1}]})


def test_relative_rule_and_missing_values():
    c = Claim.model_validate(BASE)
    assert judge(c, {"r": 5.0, "b": 2.0})[0] is True
    assert judge(c, {"r": 4.9, "b": 2.0})[0] is False
    assert judge(c, {"r": 4.9})[0] is None
    assert judge(Claim.model_validate({**BASE, "min_duration_s": 1800}), {"r": 5.0, "b": 1.0}, 300.0)[0] is None


def test_the_two_rules_changed_with_their_data_are_restored():
    two = load_claims("blazing-a-trail")["team-vs-one-robot"]
    assert [(c.metric, c.op, c.threshold, c.relative_to) for c in two.rule] == [
        ("team_units_mean", ">=", 2.5, "route_follow_units_mean")]
    assert any(not h.before_data and h.commit == "8ce20af" for h in two.history)
    drift = load_claims("try-to-see-it-my-way")["drift-collapse"]
    assert {c.metric for c in drift.rule} == {"share_last10_kmax", "blaze_last10_kmax"}
    assert any(not h.before_data and h.commit == "ece0e2d" for h in drift.history)


def test_a_paired_rule_with_too_few_pairs_is_not_judged():
    c = Claim.model_validate({**BASE, "min_pairs": 5, "pairs_metric": "pairs"})
    assert judge(c, {"r": 5.0, "b": 2.0, "pairs": 4.0}) == (None, "not judged (n = 4 pairs; the rule needs >= 5)")
    assert judge(c, {"r": 5.0, "b": 2.0, "pairs": 5.0})[0] is True
    assert judge(c, {"r": 5.0, "b": 2.0})[0] is None  # the count itself not measured
    with pytest.raises(ValidationError):
        Claim.model_validate({**BASE, "min_pairs": 2})  # FIDELITY §3: at least 5


def test_a_section_that_counts_its_own_pairs_still_gets_a_verdict():
    # line-of-sight help applies min_pairs per route plan and navigator before it asks the
    # judge; a claim that names min_pairs must not then read "n_pairs: not measured"
    from teamnav.papers.los_help.report import _los_verdicts as V

    assert V._claim("table1-potential-field-falls").min_pairs == 5
    assert V._judged("table1-potential-field-falls", {"max_rise": -5.0, "fails_first": 1.0}) is True
    assert V._judged("table1-potential-field-falls", {"max_rise": 5.0, "fails_first": 1.0}) is False
    assert V._judged("fig16-noise-grows", {"min_growth": 10.0}) is True
