"""The beyond section's restricted-radio block: its sweeps, claims and numbers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.experiments.claims import load_claims
from teamnav.papers.beyond.report import _radio_beyond as R
from teamnav.experiments.sweep import expand, load_sweep


@pytest.mark.parametrize("system", R.SYSTEMS, ids=lambda s: s.key)
def test_each_sweep_has_the_cases_the_block_reads_and_ten_report_seeds(system):
    spec = load_sweep(system.sweep)
    cases = [str(c.get("case")) for c in spec.cases]
    for c, _ in R.LOSS_CASES:
        assert c in cases
    for c, _, _ in system.ranges:
        assert c in cases
    for c in system.extra:
        assert c in cases
    assert set(R.QUICK_CASES) <= set(cases)
    assert spec.seed_list == list(range(10))
    loss = {str(t.params["case"]): t.load().radio.p_loss for t in expand(spec) if t.seed == 0}
    assert [loss[c] for c, _ in R.LOSS_CASES] == [p for _, p in R.LOSS_CASES]


@pytest.mark.parametrize("system", R.SYSTEMS, ids=lambda s: s.key)
def test_each_claim_reads_only_metrics_the_block_computes(system):
    claim = load_claims("beyond")[system.claim]
    vals = R.claim_values({"p0": {0: 1.0, 1: 2.0}, "p0.3": {0: 1.0, 1: 2.0}}, system)
    for cond in claim.rule:
        assert cond.metric in vals and (cond.relative_to is None or cond.relative_to in vals)
    assert claim.seed_list == list(range(10)) and claim.n >= 10 * len(R.LOSS_CASES)


def test_a_bandwidth_case_caps_and_a_range_case_restricts():
    spec = load_sweep("beyond-radio-try")
    by = {str(t.params["case"]): t.load() for t in expand(spec) if t.seed == 0}
    assert by["bw-30"].radio.bandwidth_bps == 30.0 and by["bw-30"].radio.bandwidth_burst_s * 30.0 >= 129
    assert by["range-5m"].radio.mode == "range" and by["range-5m"].radio.range_m == 5.0
    assert by["p0"].radio.bandwidth_bps is None and by["p0"].radio.mode == "broadcast"


def test_units_per_hour_from_rows():
    rows = [{"seed": 0, "units_total": 15, "sim_time_s": 1800.0}, {"seed": 1, "units_total": 7, "sim_time_s": 900.0},
            {"seed": 2, "units_total": None, "sim_time_s": 1800.0}]
    trail = next(s for s in R.SYSTEMS if s.key == "try")
    assert R.headline(rows, trail) == {0: 30.0, 1: 28.0}
    los = next(s for s in R.SYSTEMS if s.key == "los")
    assert R.headline([{"seed": 3, "los_steps_per_target": 120.5}], los) == {3: 120.5}


def test_loss_reversals_counts_only_beyond_the_paired_noise():
    mono = {"p0": {0: 30.0, 1: 28.0, 2: 31.0}, "p0.3": {0: 29.0, 1: 28.5, 2: 30.0}, "p0.6": {0: 20.0, 1: 21.0, 2: 19.0},
            "p0.9": {0: 10.0, 1: 12.0, 2: 11.0}, "p1": {0: 5.0, 1: 6.0, 2: 5.5}}
    assert R.loss_reversals(mono, higher_is_better=True) == 0
    # read as lower-is-better, every falling step is a clear improvement with loss
    assert R.loss_reversals(mono, higher_is_better=False) == 3  # p0 -> p0.3 is within the noise
    noisy = dict(mono, **{"p0.6": {0: 35.0, 1: 20.0, 2: 25.0}})  # better on average, but within 2 s.e.
    assert R.loss_reversals(noisy, higher_is_better=True) == 0
    assert R.loss_reversals({"p0": {0: 1.0}, "p0.3": {0: 9.0}}, True) == 0  # one common seed: nothing judged


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(0.0, 100.0), min_size=3, max_size=12), st.floats(0.1, 50.0))
def test_a_uniform_shift_is_a_reversal_in_exactly_one_direction(base, shift):
    a = {i: v for i, v in enumerate(base)}
    b = {i: v + shift + 1e-3 * i for i, v in enumerate(base)}  # the lossier case higher on every seed
    up = R.loss_reversals({"p0": a, "p0.3": b}, True, ("p0", "p0.3"))
    down = R.loss_reversals({"p0": a, "p0.3": b}, False, ("p0", "p0.3"))
    assert (up, down) == (1, 0)


def test_the_claims_judge_the_block_values():
    from teamnav.experiments.claims import judge

    trail = next(s for s in R.SYSTEMS if s.key == "blazing")
    claim = load_claims("beyond")[trail.claim]
    good = {"p0": {s: 30.0 + s for s in range(10)}, "p0.3": {s: 28.0 + s for s in range(10)}}
    assert judge(claim, R.claim_values(good, trail), 1800.0)[0] is True
    bad = dict(good, **{"p0.3": {s: 25.0 + s for s in range(10)}})  # 25 + 4.5 < 0.9 x 34.5
    assert judge(claim, R.claim_values(bad, trail), 1800.0)[0] is False
    assert judge(claim, R.claim_values(good, trail), 300.0)[0] is None  # runs shorter than the rule's 30 min
    assert np.isnan(R.claim_values({}, trail)["units_p0_mean"])
