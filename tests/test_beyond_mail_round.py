"""N places, a mail round (Vaughan et al. 2002 §2.1 and §4 future work): the legs the
block counts follow the round as the brain does, the efficiency is the §3.6 measure, bad input is
named, the scenario's places lie in order on one loop, and the block runs quick and full."""

from __future__ import annotations

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from _report_fakes import FakeFullContext
from teamnav.papers.beyond.report import _beyond_mail_round as M

ROUND = ["a", "b", "c", "d"]
EVENT_OF = {p: p for p in ROUND}


@settings(max_examples=200, deadline=None)
@given(st.integers(2, 4), st.lists(st.tuples(st.floats(0.0, 1e4), st.integers(0, 2), st.sampled_from(ROUND)),
                                   max_size=60))
def test_legs_follow_the_round_in_order_and_only_at_the_sought_place(n, events):
    rnd = ROUND[:n]
    arrivals = [[t, r, p] for t, r, p in events if p in rnd]
    legs = M.round_legs(arrivals, 3, rnd, EVENT_OF)
    for r in range(3):
        mine = [(t, i) for rr, t, i in legs if rr == r]
        # leg k of a robot is leg k mod N of the round (starting at round[0]), in time order
        assert [i for _, i in mine] == [k % n for k in range(len(mine))]
        assert [t for t, _ in mine] == sorted(t for t, _ in mine)
        # each ends with an arrival of that robot, at that time, at the place the leg goes to
        for t, i in mine:
            assert [t, r, rnd[(i + 1) % n]] in arrivals
    # a robot that only ever arrives at its start place makes no leg
    assert M.round_legs([[1.0, 0, "a"], [5.0, 0, "a"]], 1, rnd, EVENT_OF) == []


def test_passing_a_place_out_of_turn_is_not_a_leg():
    arr = [[10.0, 0, "c"], [20.0, 0, "b"], [30.0, 0, "b"], [40.0, 0, "a"], [50.0, 0, "c"]]
    assert M.round_legs(arr, 1, ["a", "b", "c"], {"a": "a", "b": "b", "c": "c"}) == [(0, 20.0, 0), (0, 50.0, 1)]


def _setup(**kw):
    args = dict(round_=["a", "b"], event_of={"a": "a", "b": "b"}, leg_m=[10.0, 10.0], n_robots=2, cruise_mps=0.5)
    args.update(kw)
    return M.RoundSetup(**args)


def test_efficiency_is_route_over_lifetime_over_cruise_and_idle_robots_count_the_whole_run():
    row = {"arrivals_series": json.dumps([[40.0, 0, "b"], [80.0, 0, "a"], [90.0, 0, "a"]]), "crumbs_max": 12,
           "bytes_sent": 6000}
    v = M.run_values(row, _setup(), 100.0)
    # robot 0: 2 legs of 10 m, last at 80 s; robot 1: no leg, working for all 100 s
    assert v["efficiency"] == pytest.approx(20.0 / (80.0 + 100.0) / 0.5)
    assert v["legs_per_hour"] == pytest.approx(2 * 36.0) and v["rounds_per_hour"] == pytest.approx(36.0)
    assert v["legs_per_robot_hour"] == pytest.approx(36.0)
    assert v["crumbs_max"] == 12 and v["bytes_per_robot_min"] == pytest.approx(6000 / 2 / (100 / 60))
    one = M.run_values({"arrivals_series": json.dumps([[40.0, 0, "b"], [80.0, 0, "a"]])}, _setup(n_robots=1), 100.0)
    assert one["efficiency"] == pytest.approx(20.0 / 80.0 / 0.5) and "crumbs_max" not in one


@pytest.mark.parametrize("row, words", [
    ({}, "arrivals_series"),
    ({"arrivals_series": json.dumps([[1.0, 0, "z"]])}, "place 'z'"),
    ({"arrivals_series": json.dumps([[1.0, 5, "b"]])}, "robot 5"),
])
def test_bad_rows_are_named(row, words):
    with pytest.raises(ValueError, match=words):
        M.run_values(row, _setup(), 100.0)


def test_bad_setups_are_named():
    with pytest.raises(ValueError, match="one route per leg"):
        _setup(leg_m=[1.0])
    with pytest.raises(ValueError, match="cruise_mps must be > 0"):
        _setup(cruise_mps=0.0)
    case = {"case": "mixed", "robots.1.params.round": ["mailroom", "east_hall", "south_hall"]}
    with pytest.raises(ValueError, match="params.round must be the same"):
        M.case_setup("beyond-mail-round", case)
    with pytest.raises(ValueError, match="no place fires"):
        M.case_setup("beyond-mail-round", {"case": "x", **{f"robots.{k}.params.round": ["mailroom", "attic"]
                                                           for k in range(4)}})


def test_the_scenarios_places_lie_in_round_order_on_one_loop():
    """The five places were chosen on the basement's corridor loop, clockwise: every round of 3-5
    of them is that loop (about 139 m), and a leg is never shorter than the straight line."""
    from teamnav.experiments.sweep import load_sweep

    spec = load_sweep(M.MAIL_SWEEP)
    cases = {c["case"]: c for c in spec.cases}
    setups = {n: M.case_setup(spec.scenario, cases[f"n{n}"]) for n in (2, 3, 4, 5)}
    assert setups[2].leg_m == pytest.approx([45.7, 45.7], abs=0.5)  # there and back the same route
    loops = [sum(setups[n].leg_m) for n in (3, 4, 5)]
    assert loops == pytest.approx([139.0] * 3, abs=2.0)
    assert setups[5].round[:4] == setups[4].round and setups[4].round[:3] == setups[3].round
    solo = M.case_setup(spec.scenario, cases["n3-solo"])
    assert solo.n_robots == 1 and setups[3].n_robots == 4 and solo.leg_m == setups[3].leg_m


def test_mail_round_block_quick_runs_n2_and_n3(tmp_path):
    from teamnav.experiments.report.context import SweepContext
    from teamnav.experiments.report.model import Plot, Table

    blocks = M.mail_round(SweepContext(tmp_path, quick=True, workers=1, section="beyond"))
    (table,) = [b for b in blocks if isinstance(b, Table)]
    assert [r[0] for r in table.rows] == ["2", "3"]
    assert all("(n = 1)" in r[3] for r in table.rows), table.rows  # one seed each, and it finished
    assert any(isinstance(b, Plot) for b in blocks)


def _fake_full():
    """Full mode without running: each case's robot 0 makes 2 legs per seed, at 600 and 1200 s."""

    def rows_for(spec, seeds):
        rows = []
        for c in spec.cases:
            first, second = c["robots.0.params.round"][1], c["robots.0.params.round"][2 % len(c["robots.0.params.round"])]
            arr = [[600.0, 0, first], [1200.0, 0, second]]
            rows += [{"status": "ok", "params": {"case": c["case"]}, "seed": s, "arrivals_series": json.dumps(arr),
                      "crumbs_max": 100 + s, "bytes_sent": 1000} for s in seeds]
        return rows

    return FakeFullContext(rows_for)


def test_mail_round_block_full_mode_reads_every_case_for_ten_seeds():
    from teamnav.experiments.report.model import Plot, Table

    ctx = _fake_full()
    blocks = M.mail_round(ctx)
    assert [(s, d) for _, s, d in ctx.asked] == [(list(range(10)), M.FULL_DURATION_S)]
    (table,) = [b for b in blocks if isinstance(b, Table)]
    assert [r[0] for r in table.rows] == ["2", "3", "4", "5", "3", "4", "5", "2", "3", "4", "5"]
    assert all("(n = 10)" in r[3] for r in table.rows)
    # 2 legs in 30 min: 4 legs per hour for the team, whatever N
    assert {r[3] for r in table.rows} == {"4.0 ± 0.0 (n = 10)"}
    eff, thr, mem = [b for b in blocks if isinstance(b, Plot)]
    assert [s.x for s in eff.series] == [[2.0, 3.0, 4.0, 5.0], [3.0, 4.0, 5.0], [2.0, 3.0, 4.0, 5.0]]
    assert "no verdict" in eff.caption and mem.series[0].lo[0] == 100.0
    # 2 legs in 30 min shared by 4 robots against 2 legs by one robot alone: 1 against 4 legs per robot-hour
    assert thr.series[0].y == [1.0] * 4 and thr.series[2].y == [4.0] * 4
    assert "N = 2: -3.0 ± 0.0 legs/robot/h (s.e., 10 seeds): the team's robots make fewer legs each" in thr.caption


def test_sharing_text_says_when_there_is_no_difference():
    team_setup, solo_setup = _setup(n_robots=2), _setup(n_robots=1)

    def rows(legs_by_seed):
        return [{"seed": s, "arrivals_series": json.dumps([[10.0 * (k + 1), 0, "ba"[k % 2]] for k in range(n)])}
                for s, n in legs_by_seed.items()]

    # team: 2 robots share the legs; solo: one robot. Per robot per hour (a 3600-s run): team n/2, solo n
    same = M.sharing_text(rows({0: 4, 1: 6, 2: 2}), rows({0: 2, 1: 3, 2: 1}), team_setup, solo_setup, 3600.0)
    assert same.startswith("+0.0 ± 0.0") and "no difference" in same
    noisy = M.sharing_text(rows({0: 6, 1: 2, 2: 4}), rows({0: 1, 1: 3, 2: 2}), team_setup, solo_setup, 3600.0)
    assert "no difference beyond the seeds' spread" in noisy  # +2, -2, 0: mean 0
    more = M.sharing_text(rows({0: 10, 1: 12, 2: 10}), rows({0: 2, 1: 3, 2: 1}), team_setup, solo_setup, 3600.0)
    assert "more legs each" in more
    assert M.sharing_text(rows({0: 2}), rows({0: 1}), team_setup, solo_setup, 3600.0) == "too few paired seeds to compare"
