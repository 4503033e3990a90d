"""The beyond section's block on Fox et al. §7.2's future work: negative sights and anonymous robots
(quick mode runs two short hallway runs; full mode reads the three sweeps for seeds 0-9 and judges
the claims)."""

from __future__ import annotations

import math

import pytest

from teamnav.experiments.report.model import Comparison, Missing, Table
from teamnav.papers.beyond.report import _beyond_negative_detections as N
from _report_fakes import FakeFullContext


def test_paired_and_claim_values():
    m, se, n, lower = N.paired({0: 100.0, 1: 200.0, 2: 50.0, 9: 1.0}, {0: 90.0, 1: 150.0, 2: 60.0})
    assert (n, lower) == (3, 2) and m == pytest.approx(-50 / 3) and se == pytest.approx(17.638, abs=1e-3)
    v = N.claim_values({0: 100.0, 1: 200.0}, {0: 100.0, 1: 200.0})
    assert v == {"ttl_off_mean": 150.0, "ttl_on_mean": 150.0, "ttl_paired_z": 0.0}
    assert math.isnan(N.claim_values({0: 1.0}, {0: 2.0}, ("ignore", "assoc"))["ttl_paired_z"])


def _rows(spec, seeds, ttl):
    return [{"status": "ok", "params": {"case": c["case"]}, "seed": s, "loc_time_to_localize_s": ttl(c["case"], s),
             "loc_censored": 0, "loc_final_localized_fraction": 1.0, "bytes_sent": 2400.0 * 8, "wall_time_s": 5.0}
            for c in spec.cases for s in seeds]


def test_full_mode_reads_the_three_sweeps_and_judges_the_claims():
    # negative sights 20 s faster on every seed but the hexagon (no change); association 50 % faster
    def ttl(case, s):
        return {"on": 80.0 + s, "off": 100.0 + s + (s % 2), "anon-ignore": 200.0 + s,
                "anon-associate": 100.0 + s}[case]

    def rows_for(spec, seeds):
        if spec.name.endswith("hexagon"):
            return _rows(spec, seeds, lambda c, s: 100.0 + s)
        return _rows(spec, seeds, ttl)

    ctx = FakeFullContext(rows_for)
    blocks = N.negative_detections(ctx)
    assert [(n, s, d) for n, s, d in ctx.asked] == [
        ("beyond-negative-detections-hallway", list(range(10)), 300.0),
        ("beyond-negative-detections-hexagon", list(range(10)), 300.0), ("beyond-anonymous-hallway", list(range(10)), 300.0)]
    verdicts = [b.holds for b in blocks if isinstance(b, Comparison)]
    assert verdicts == [True, False, True]
    neg, anon = [b for b in blocks if isinstance(b, Table)]
    assert neg.rows[2][3].startswith("-20 ± 0 s (s.e., 10 paired seeds, 10 lower)")
    assert "(n = 10)" in anon.rows[1][3] and anon.rows[3][3].startswith("-100 ± 0 s")
    assert anon.rows[0][3].startswith("105 ± 3") and anon.rows[4][3].startswith("-0 ± 0 s (s.e., 10 paired seeds, 5 lower)")  # the hallway's off case
    assert not any(isinstance(b, Missing) for b in blocks)


def test_quick_mode_runs_two_short_hallway_runs(tmp_path):
    from teamnav.experiments.report.context import SweepContext

    blocks = N.negative_detections(SweepContext(tmp_path, quick=True, workers=1, section="beyond"))
    (table,) = [b for b in blocks if isinstance(b, Table)]
    assert [r[1] for r in table.rows][:2] == ["off (the paper, §2.3 rule 1)", "on (negative sights)"]
    assert all("(n = 1)" in r[3] for r in table.rows[:2]), table.rows
    (comp,) = [b for b in blocks if isinstance(b, Comparison)]
    assert comp.holds is None and "not judged in quick mode" in comp.differs
    assert any(isinstance(b, Missing) for b in blocks)
