"""Report section ``blazing-a-trail``: Vaughan, Støy, Sukhatme & Matarić (2000), *Blazing a trail*.

EXPERIMENTS.md rows, each a :class:`Comparison`:

Every verdict rule is read from ``papers/trails/claims/blazing-a-trail.yaml``
(:mod:`teamnav.experiments.claims`), never written here; every claim is measured in two columns
(``shared/FIDELITY.md``), each its own :class:`Comparison` naming its ``column``: "paper as
written", the 2000 paper as its authors ran it (``paper_rules: true``: every gap-fill whose other
value is the paper's rule off; the single trail followed forwards to the source and backwards home,
as the authors describe their 2000 method in Try §1, i.e. crumbs laid while carrying stored
reversed; cruise 0.4 m/s, the speed the 2000 paper's numbers imply, the route-follow baseline at it
too; :func:`_trails.paper_rules_spec` with ``cruise_mps``), and "teamnav" (our gap-fills, the
scenarios' 0.4 m/s), beside the paper's number. The verdict is judged on the paper column, on the
seeds the claim file names; the teamnav column says what the gap-fills buy. Blazing §4.1 read
literally (homebound crumbs keep the robot's heading) is an ablation table (full mode), never
judged. A ledger of both columns (:mod:`._trails_ledger`) says where every value comes from. The
map is trail_office's U shape (the same turn at both corners, Blazing §5.1).

1. "first robot finds resource, others follow the optimal route" → after the first broadcast,
   trips take about the optimal route's time: robot-seconds per unit delivered after the first
   source visit, pooled over runs with unfinished trips as censored time
   (:func:`robot_s_per_unit_after`), against the route-follow-v1 robot's round trip (claim
   ``first-trail``; the paper's own figure: 4 x 30 min / 28 units = 4.3 min against ~3 min).
2. "4 robots ≈ 3x a single optimal robot" (§5.1: "Since the time for a round-trip from home to
   resource is approximately 3 minutes the robot group performed three times better than a single
   robot performing under optimal conditions": 28 units vs 30 / 3 = 10, i.e. 2.8x) → two ratios.
   The paper's method: the team's units / the units one robot delivers at the optimal round-trip
   rate of the team's own controller, i.e. duration / (2 x the median trip time after its own
   first trail) of ONE blazing-trail-v1 robot with the team's params, alone and without drift
   (sweep trail-solo-blazing), shown, not judged. Judged (claim ``team-vs-one-robot``): the
   team's units / the units a measured route-follow-v1 robot delivers on the optimal route
   (trail-solo-optimal: pure pursuit that cuts the corners without sharp turns).
3. "odometry drift makes the system break down (~27 min)" → units over time flatten and breakdown
   time falls as the drift grows (blazing-drift sweep: each robot its own drift, k x the 2002
   paper's Bug -1, Ant +1, Fly +2, Tanis +0.35 deg/min, k = 0, 1, 2, 3, 4, 6, 10 seeds x 1 h):
   judged (claim ``drift-breakdown``) on :func:`drift_values`: the trend over all runs (rank
   correlations of breakdown time and last-10-minute units with k) and a collapse at the highest k.

Baselines beside them: one optimal robot (route-follow-v1), one robot with the team's own brain
and params alone without drift (trail-solo-blazing, the paper's "optimal conditions"), one
exploring robot (blazing-trail-v1 alone, trail-solo-explore) and the team without communication
(teamnav column only); the table of gap-fills with both values (:func:`_trails.gap_fill_rows`). Figures: units over time (Fig. 5
left), units per 10 min (Fig. 5 right); for the drift sweep breakdown time vs k (median and
25–75 %, every run marked, censored runs at the run's end), the fraction of runs not broken down
by time t per k (Kaplan–Meier), units over time per k and last-10-minute units vs k; the trails
each robot announced in its own frame (Fig. 6) and all of them in a fixed frame of the places.

Quick mode: 300 s runs (the drift sweep's too), seed 0 only, drift
k = 0 and 4 only, no explorer or no-communication baselines, no ablation. Full: the paper's 30 min on
the claim file's judged seeds; drift k = 0, 1, 2, 3, 4, 6 for 1 h on the same seeds (the sweep's
k = 0.5 case is there for ``teamnav sweep``; the drift sweep is shared with the
try-to-see-it-my-way section); the seeds every earlier version was measured on (0-9) again as a
second, labelled table, never judged.

What the section measured (the final drift sweep, the paper's conditions, one robot alone,
the full mode's cost, with commits): ``docs/report/blazing-a-trail.md``. Why the two columns
differ, each gap-fill alone and the drift models on paired seeds, is shown from the
stored runs of ``scripts/trail_gap_fill_study.py`` (:mod:`._trails_gap_fills`), not re-run.
"""

from __future__ import annotations

import math

import numpy as np

from teamnav.experiments.claims import judge, load_claims, rule_text
from teamnav.experiments.report.model import Comparison, Missing, Plot, SectionSpec, Series, Table, Text
from teamnav.experiments.spec import load_scenario
from teamnav.papers.trails.brains.blazing_trail import BlazingTrailParams
from teamnav.papers.trails.report import _trails as T
from teamnav.papers.trails.report import _trails_gap_fills as GF

PAPER = "vaughan-stoy-sukhatme-mataric-blazing-a-trail.txt"
#: §5.1 units per robot (Tanis, Ant, Bee, Punky) and total
PAPER_UNITS = {"Tanis": 7, "Ant": 7, "Bee": 6, "Punky": 8}
#: scenario blazing-a-trail's robot order
OUR_ROBOTS = ("ant", "bee", "punky", "tanis")
#: the drift sweep's scales k in full mode (blazing-drift cases x<k>, the judged seeds x 1 h each)
DRIFT_SCALES = (0.0, 1.0, 2.0, 3.0, 4.0, 6.0)
#: the seeds every version of the section before 2026-11-29 was measured on: a second table in
#: full mode, never the judged one (FIDELITY §3)
LOOKED_AT_SEEDS = tuple(range(10))


def _seed_text(seeds) -> str:
    """``[2000, ..., 2019]`` -> ``"2000-2019"``; other lists comma-separated.

    >>> _seed_text(range(2000, 2020)), _seed_text([0]), _seed_text([1, 5])
    ('2000-2019', '0', '1,5')
    """
    s = sorted(seeds)
    if len(s) > 1 and s == list(range(s[0], s[-1] + 1)):
        return f"{s[0]}-{s[-1]}"
    return ",".join(map(str, s))


def ablation_table(paper_rows, literal_rows, duration_s: float) -> Table:
    """The 2000 paper column beside its literal reading (crumbs laid while carrying not reversed): an
    ablation, never judged (FIDELITY §1)."""
    def line(label, rows):
        return [label, T.msd(T.values(rows, "units_total")), f"{robot_s_per_unit_after(rows, duration_s):.0f}",
                T.msd(T.values(rows, "first_trail_s") / 60, "{:.1f}"), _n_broke(rows)]
    return Table("Ablation: the 2000 paper read literally (not judged)",
                 ["paper column", f"units in {duration_s / 60:g} min", "robot-s per unit after the first trail",
                  "first source visit [min]", "broke down"],
                 [line("single trail followed backwards home (Try §1; judged)", paper_rows),
                  line("Blazing §4.1 literally: homebound crumbs keep the robot's heading (ablation)", literal_rows)],
                 note="the literal reading sends a carrying robot that follows the opposite of homebound crumbs "
                      "away from home: the paper's own results (28 units) rule it out")


def drift_values(rows, drift_dur_s: float) -> dict[str, float]:
    """Claim ``drift-breakdown``'s metrics from the drift sweep's runs (the rule is in the claim file).

    ``last10_k0_mean`` / ``last10_kmax_mean``: mean last-10-min units at k = 0 and at the highest k;
    ``min_median_breakdown_s``: the lowest per-k median breakdown time (censored runs at the run's
    length); ``drift_duration_s``; ``rho_breakdown_k`` / ``rho_last10_k``: Spearman correlation
    of breakdown time / last-10-min units with k over all runs. NaNs when fewer than two scales ran.
    """
    xs, bd, _, _ = T.per_drift(rows, "breakdown_s")
    _, last, _, _ = T.per_drift(rows, "units_per_10min_last", np.mean)
    nan = float("nan")
    two = len(xs) >= 2
    return {"last10_k0_mean": last[0] if two and xs[0] == 0.0 else nan, "last10_kmax_mean": last[-1] if two else nan,
            "min_median_breakdown_s": min(bd) if two else nan, "drift_duration_s": float(drift_dur_s),
            "rho_breakdown_k": _rho(T.drift_trend(rows, "breakdown_s"), two),
            "rho_last10_k": _rho(T.drift_trend(rows, "units_per_10min_last"), two)}


def _rho(r: float, two: bool) -> float:
    """A rank correlation; 0 (no trend) where one side is constant (NaN from spearman) and two scales ran."""
    return r if math.isfinite(r) or not two else 0.0


def drift_verdict(rows, drift_dur_s: float) -> tuple[bool | None, str]:
    """Claim ``drift-breakdown`` on the drift sweep's runs: (holds, how it was read), by the rule
    in ``papers/trails/claims/blazing-a-trail.yaml`` (None for fewer than two scales or runs shorter
    than the rule's ``min_duration_s``)."""
    return judge(load_claims("blazing-a-trail")["drift-breakdown"], drift_values(rows, drift_dur_s), drift_dur_s)


def paper_method_ratio(team_units: float, solo_trip_s, duration_s: float) -> tuple[float, float]:
    """§5.1's ratio: the team's units / the units of one robot at the optimal round-trip rate.

    The paper divides the run by "the time for a round-trip from home to resource" under optimal
    conditions (30 min / ~3 min = 10 units). A trip here is one way (home to source or back), so
    one robot delivers ``duration_s / (2 x median trip)`` units; the median is over the runs'
    medians of ``trip_time_s_after_median`` (the trips after the robot's own first trail).

    Parameters
    ----------
    team_units : float
        The team's mean units in ``duration_s``.
    solo_trip_s : array_like
        One robot's median one-way trip time per run [s].
    duration_s : float

    Returns
    -------
    ratio, solo_units : float
        NaN when no run has a trip time.

    >>> paper_method_ratio(28.0, [90.0, 90.0], 1800.0)
    (2.8, 10.0)
    """
    trips = np.asarray(solo_trip_s, float)
    trips = trips[np.isfinite(trips) & (trips > 0)]
    if not trips.size or not np.isfinite(team_units):
        return float("nan"), float("nan")
    solo_units = float(duration_s / (2.0 * np.median(trips)))
    return float(team_units / solo_units), solo_units


def robot_s_per_unit_after(rows, duration_s: float, n_robots: int = 4) -> float:
    """Claim ``first-trail``'s metric: robot-seconds per unit delivered after the first source visit,
    pooled over runs (unfinished trips count as censored time, not dropped).

    Each run gives ``n_robots x (duration - first_trail_s)`` robot-seconds and the units delivered
    after its ``first_trail_s`` (from ``units_series``); a run that never reached the source gives
    ``n_robots x duration`` and no unit. The ratio of the sums is the censored-rate estimate:
    robots still on a trip at the end, or a team that broke down, add time without units, so the
    figure does not improve by counting only finished trips. NaN with no unit at all.

    >>> rows = [{"first_trail_s": 100.0, "units_series": "[[0,0],[150,1],[400,2],[700,3]]"},
    ...         {"units_series": "[[0,0]]"}]
    >>> robot_s_per_unit_after(rows, 1000.0)  # (4 x 900 + 4 x 1000) s / 3 units
    2533.3333333333335
    """
    import json

    time_s, units = 0.0, 0
    for r in rows:
        first = r.get("first_trail_s")
        text = r.get("units_series")
        if not isinstance(first, (int, float)) or not math.isfinite(first):
            time_s += n_robots * float(duration_s)
            continue
        time_s += n_robots * max(0.0, float(duration_s) - float(first))
        if isinstance(text, str):
            units += sum(1 for t, k in json.loads(text) if k > 0 and t > first)
    return time_s / units if units else float("nan")


def literal_spec(cruise_mps: float):
    """blazing-paper in the paper column with Blazing §4.1 read literally: crumbs laid while carrying
    keep the robot's own heading (``reverse_carried_crumbs: false``), an ablation row, never judged."""
    spec = T.paper_rules_spec("blazing-paper", cruise_mps)
    sets = dict(spec.set)
    for key, value in list(sets.items()):
        if key.endswith(".params") and isinstance(value, dict) and value.get("paper_rules"):
            sets[key] = {**value, "reverse_carried_crumbs": False}
    return spec.model_copy(update={"set": sets, "name": f"{spec.sweep_name}-literal"})


def _runs(ctx, col: str, quick: bool, seeds, dur: float, drift_dur: float, scales: list) -> dict:
    """Every sweep of one column (``"paper_rules"`` or ``"teamnav"``); the paper column drives at the
    speed the 2000 paper implies (:data:`_trails.BLAZING_IMPLIED_CRUISE_MPS`)."""
    S = lambda *a, **k: T.column_sweep(ctx, col, *a, cruise_mps=T.BLAZING_IMPLIED_CRUISE_MPS, **k)  # noqa: E731
    out = {
        "paper": S("blazing-paper", seeds=seeds, duration_s=dur),
        "opt": S("trail-solo-optimal", seeds=list(seeds)[:1 if quick else 3], duration_s=dur),
        # the paper's "single robot performing under optimal conditions": the team's own brain alone, no drift
        "solo": S("trail-solo-blazing", seeds=list(seeds)[:1] if quick else seeds, duration_s=dur),
        "drift": S(T.drift_spec("blazing-drift", scales), seeds=seeds, duration_s=drift_dur),
    }
    out["drift0"] = T.by_scale(out["drift"]).get(0.0, [])
    return out


def _values(r: dict, dur: float, drift_dur: float) -> dict[str, dict[str, float]]:
    """Each claim's metrics (names as in the claim file) from one column's runs."""
    after = T.values(r["paper"], "trip_time_s_after_median")
    team = T.values(r["paper"], "units_total")
    opt_units = T.values(r["opt"], "units_total")
    ratio, solo_units = paper_method_ratio(T.mean(team), T.values(r["solo"], "trip_time_s_after_median"), dur)
    nan = float("nan")
    return {
        "first-trail": {"trip_after_median_s": float(np.median(after)) if after.size else nan,
                        "optimal_trip_s": T.mean(T.values(r["opt"], "trip_time_s_after_median")),
                        "robot_s_per_unit_after": robot_s_per_unit_after(r["paper"], dur),
                        "optimal_round_trip_s": 2.0 * T.mean(T.values(r["opt"], "trip_time_s_after_median"))},
        "team-vs-one-robot": {"team_units_mean": T.mean(team), "route_follow_units_mean": T.mean(opt_units),
                              "paper_method_ratio": ratio, "paper_method_solo_units": solo_units},
        "drift-breakdown": drift_values(r["drift"], drift_dur),
    }


def _seed_sets(claims, quick: bool) -> tuple[list[int], list[int]]:
    """(judged seeds, the second table's seeds): the claim file's seeds (every claim names the same),
    and :data:`LOOKED_AT_SEEDS` (full mode only); quick mode: seed 0 alone, no second table."""
    if quick:
        return [0], []
    seeds = sorted({s for c in claims.claims for s in c.seed_list})
    return seeds, [s for s in LOOKED_AT_SEEDS if s not in seeds]


def _judge_all(claims, vals, dur: float, drift_dur: float) -> dict:
    return {col: {c.id: judge(c, vals[col][c.id], drift_dur if c.id == "drift-breakdown" else dur)
                  for c in claims.claims} for col, _ in T.COLUMNS}


def build(ctx) -> list:
    missing = T.brains_missing(["blazing-trail-v1", "route-follow-v1"])
    if missing is not None:
        return [missing]
    from teamnav.papers.trails.report._trails_ledger import blazing_ledger, model_column

    claims = load_claims("blazing-a-trail")
    quick = bool(ctx.quick)
    seeds, old_seeds = _seed_sets(claims, quick)
    dur = 300.0 if quick else 1800.0
    drift_dur = 300.0 if quick else 3600.0
    scales = [0.0, 4.0] if quick else list(DRIFT_SCALES)
    cruise = T.cruise_mps("blazing-a-trail")
    paper_cruise = T.BLAZING_IMPLIED_CRUISE_MPS
    n = len(seeds)

    cols = {col: _runs(ctx, col, quick, seeds, dur, drift_dur, scales) for col, _ in T.COLUMNS}
    ours, pr = cols["teamnav"], cols["paper_rules"]
    paper, opt, solo = ours["paper"], ours["opt"], ours["solo"]
    # quick mode (CI) skips the baselines and the ablation: each sweep call costs a worker pool's start-up
    explore = [] if quick else T.ok(ctx.sweep("trail-solo-explore", seeds=seeds, duration_s=dur))
    # (the team with communication and no drift is the drift sweep's k = 0)
    nocomm = [] if quick else T.ok(ctx.sweep("trail-communication", seeds=seeds, duration_s=dur,
                                             set={"robots.0.controller": "blazing-trail-v1"},
                                             grid={"robots.0.params.communicate": [False]}))
    literal = [] if quick else T.ok(ctx.sweep(literal_spec(paper_cruise), seeds=seeds, duration_s=dur))

    blocks: list = [Text(
        f"Scenario blazing-a-trail: 4 robots on trail_office_corridors, the U shape (home and source ~31.5 m apart "
        f"through two corners, the same turn at both: left going out, right coming home, Blazing §5.1), "
        f"{dur / 60:g} min per run, per-robot heading drift (Ant 1.5, Bee 1.0, Punky 0.3, "
        f"Tanis -0.3 deg/min), the papers' laser (361 beams over 180°), judged seeds {_seed_text(seeds)} (n = {n}). "
        f"Two columns: \"paper as written\" (the paper as its authors ran it: paper_rules: true, every gap-fill "
        f"whose other value is the paper's rule off, the single trail followed backwards home as the authors describe "
        f"it (Try §1), cruise {paper_cruise:g} m/s, the speed the 2000 paper's numbers imply) and \"teamnav\" (our "
        f"gap-fills, cruise {cruise:g} m/s); verdicts by the rules of papers/trails/claims/blazing-a-trail.yaml, "
        "judged on the paper column. The ledger below says where each value comes from. The map's corridor width "
        "(1.8 m), passing places and dead-end branches are ours: the papers give no numbers for them. A unit is "
        "delivered when a robot that reached the source reaches home; breakdown = the last delivery when none "
        f"followed in the last {180:g} s of the run (otherwise censored at the run's end). The drift sweep gives each "
        f"robot its own drift, k x ({T.DRIFT_TEXT}) (the 2002 paper's robots), {drift_dur / 60:g} min per run.")]
    if not paper or not opt or not pr["paper"] or not pr["opt"]:
        return blocks + [Missing("blazing-a-trail runs", "every trial of the blazing-paper or trail-solo-optimal sweep "
                                                         "failed in a column")]
    vals = {col: _values(cols[col], dur, drift_dur) for col, _ in T.COLUMNS}
    verdicts = _judge_all(claims, vals, dur, drift_dur)
    # FIDELITY §1: a precondition checked on tuning seeds before the judged run; when it does not hold,
    # the claims that need it read "precondition not met" on the paper column, never "fails"
    pre = GF.precondition_2000()
    if pre.holds is False:
        for cid in pre.claims:
            verdicts["paper_rules"][cid] = (None, f"precondition not met ({verdicts['paper_rules'][cid][1]})")

    def rule(cid: str, col: str) -> str:
        c = claims[cid]
        judged = "judged" if col == c.judged else "not judged (the paper column is)"
        return f" Rule ({claims.section}.yaml, {judged}): {rule_text(c)}; {verdicts[col][cid][1]}."

    blocks.append(Table(f"Claims: the paper, the paper as written (judged), teamnav; seeds {_seed_text(seeds)}",
                        ["claim", "paper", "rule (claim file)", "paper as written", "teamnav", "rule history"],
                        T.claim_rows(claims, vals, verdicts),
                        note="verdicts judged on the paper-as-written column; the teamnav column is what the "
                             "gap-fills buy"))
    cause = failure_cause_text(verdicts["paper_rules"], cols["paper_rules"]["drift"], drift_dur)
    if cause:
        blocks.append(Text(cause))
    blocks.append(blazing_ledger())
    blocks += [pre, GF.probe_table("precondition-2000")]
    blocks.append(Table("Gap-fills: teamnav's value and the paper's (paper_rules: true sets the paper's)",
                        ["parameter (blazing-trail-v1)", "teamnav", "paper as written", "where the paper says so"],
                        T.gap_fill_rows(BlazingTrailParams, load_scenario("blazing-a-trail").robots[0].params),
                        note="kept in both columns: crumb interval 1 s and radius 2 m, the sliding box's 2.0 m reach "
                             "(lanes), trail_rule 'side' (§5.1's own wording), the 180° rule's 150° threshold for "
                             "'approximately opposite', crumbs laid while carrying stored reversed (Try §1); the "
                             "cruise speed per column (ledger)"))
    if literal:
        blocks.append(ablation_table(pr["paper"], literal, dur))
    else:
        blocks.append(Missing("ablation: the 2000 paper read literally (crumbs laid while carrying not reversed)",
                              "full mode only"))
    blocks += GF.blocks()  # each gap-fill alone, and the drift models (stored runs, not re-run)

    for col, head in T.COLUMNS:
        r, v = cols[col], vals[col]
        mcol = model_column(col)
        # 1. first trail, trip times after it vs the optimal robot
        c1 = claims["first-trail"]
        w = v["first-trail"]
        blocks.append(Comparison(
            "After the first broadcast, trips take about the optimal route's time",
            "first robot reaches the resource at 1.25 min; all four then take the optimal route (two correct turns); "
            "28 units by 4 robots in 30 min: 4.3 robot-min per unit against a ~3 min round trip (1.43x)",
            f"{head}: {w['robot_s_per_unit_after']:.0f} robot-s per unit delivered after the first source visit "
            f"(unfinished trips counted as time without a unit), optimal round trip {w['optimal_round_trip_s']:.0f} s; "
            f"first source visit at {T.msd(T.values(r['paper'], 'first_trail_s') / 60, '{:.1f}', 'min')}; median "
            f"finished trip {T.msd(T.values(r['paper'], 'trip_time_s_before_median'), '{:.0f}', 's')} before it, "
            f"{T.msd(T.values(r['paper'], 'trip_time_s_after_median'), '{:.0f}', 's')} after (no drift: "
            f"{T.msd(T.values(r['drift0'], 'trip_time_s_after_median'), '{:.0f}', 's')})",
            verdicts[col][c1.id][0],
            "our exploration is Navigate's random explorer on our office; the paper reports one trial, we report "
            "the pooled figure over seeds." + rule(c1.id, col), column=mcol))

        # 2. team vs one robot under optimal conditions (§5.1)
        c2 = claims["team-vs-one-robot"]
        w = v["team-vs-one-robot"]
        solo_trip = T.values(r["solo"], "trip_time_s_after_median")
        blocks.append(Comparison(
            "4 robots ≈ 3x a single robot under optimal conditions",
            "28 units in 30 min; one robot on a ~3 min round trip ≈ 10 units: 2.8x, which the paper calls three times",
            f"{head}: team {T.msd(T.values(r['paper'], 'units_total'))} units in {dur / 60:g} min; one route-follow-v1 "
            f"robot on the optimal route {T.msd(T.values(r['opt'], 'units_total'))}: "
            f"{w['team_units_mean'] / w['route_follow_units_mean']:.2f}x; the paper's method (one blazing-trail-v1 "
            f"robot alone, no drift, median trip after its first trail {T.msd(solo_trip, '{:.0f}', 's')} → "
            f"{w['paper_method_solo_units']:.1f} units): {w['paper_method_ratio']:.2f}x (shown, not judged)",
            verdicts[col][c2.id][0],
            "the paper's single robot is an estimate (a ~3 min round trip, no run); ours is a measured route-follow-v1 "
            "robot at the column's cruise speed; in quick mode the runs are short and the initial search weighs more."
            + rule(c2.id, col), column=mcol))

        # 3. breakdown vs drift
        c3 = claims["drift-breakdown"]
        groups = T.by_scale(r["drift"])
        xs, bd, _, _ = T.per_drift(r["drift"], "breakdown_s")
        _, last, _, _ = T.per_drift(r["drift"], "units_per_10min_last", np.mean)
        cens = T.values(r["paper"], "breakdown_censored")
        w = v["drift-breakdown"]
        blocks.append(Comparison(
            "Odometry drift makes the system break down; breakdown comes earlier as drift grows",
            "no unit after ~27 min of 30 (rate falls from the start, Fig. 5 right)",
            f"{head}: paper conditions: breakdown at {T.msd(T.values(r['paper'], 'breakdown_s') / 60, '{:.1f}', 'min')} "
            f"({int(cens.sum()) if cens.size else 0} of {cens.size} runs did not break down within {dur / 60:g} min); "
            f"drift sweep ({drift_dur / 60:g} min): "
            + ", ".join(f"k = {d:g}: {_n_broke(groups.get(d, []))} broke down, median {b / 60:.0f} min, "
                        f"last-10-min units {u:.1f}" for d, b, u in zip(xs, bd, last))
            + f"; rank correlation with k: breakdown {w['rho_breakdown_k']:+.2f}, last-10-min units "
              f"{w['rho_last10_k']:+.2f}",
            verdicts[col][c3.id][0],
            "the sweep scales the 2002 paper's per-robot drift (the 2000 paper gives no rates); heading drift only "
            "(both papers report rotation only; the wheel-scale and slip cases are in the try-to-see-it-my-way "
            "section); censored runs count at the run's length." + rule(c3.id, col), column=mcol))

    if old_seeds:
        old = {col: _runs(ctx, col, quick, old_seeds, dur, drift_dur, scales) for col, _ in T.COLUMNS}
        if all(old[col]["paper"] and old[col]["opt"] for col, _ in T.COLUMNS):
            ovals = {col: _values(old[col], dur, drift_dur) for col, _ in T.COLUMNS}
            blocks.append(Table(f"Seeds {_seed_text(old_seeds)}: looked at many times before, a second table, "
                                "not judged", ["claim", "paper", "rule (claim file)", "paper as written", "teamnav",
                                               "rule history"],
                                T.claim_rows(claims, ovals, _judge_all(claims, ovals, dur, drift_dur)),
                                note="the same runs on the seeds every earlier version of this section was "
                                     "measured on (FIDELITY §3: never the judged table)"))

    # per-robot units (paper's table)
    rows = []
    for i, name in enumerate(OUR_ROBOTS):
        rows.append([name.capitalize(), PAPER_UNITS[name.capitalize()]]
                    + [T.msd(T.values(cols[col]["paper"], f"units.robot{i}")) for col, _ in T.COLUMNS])
    rows.append(["Total", sum(PAPER_UNITS.values())]
                + [T.msd(T.values(cols[col]["paper"], "units_total")) for col, _ in T.COLUMNS])
    blocks.append(Table("Units transported per robot (§5.1)", ["Robot", "paper (30 min, 1 trial)"]
                        + [f"{head} ({dur / 60:g} min)" for _, head in T.COLUMNS], rows))

    # baselines side by side, both columns where both ran
    def cell(rows_, key, fmt="{:.1f}"):
        return T.msd(T.values(rows_, key), fmt)

    base = []
    for label, key in (("4 robots, paper drift", "paper"), ("4 robots, no drift", "drift0"),
                       ("1 robot, the team's brain alone, no drift (trail-solo-blazing; its units include its search)", "solo"),
                       ("1 robot on the optimal route (route-follow-v1)", "opt")):
        suffix = "" if key != "drift0" or drift_dur == dur else f" (in {drift_dur / 60:g} min)"
        base.append([label] + [cell(cols[col][key], "units_total") + suffix for col, _ in T.COLUMNS]
                    + [cell(cols[col][key], "trip_time_s_after_median", "{:.0f}") for col, _ in T.COLUMNS])
    base += [["4 robots, no communication (teamnav only)", "", cell(nocomm, "units_total"), "",
              cell(nocomm, "trip_time_s_after_median", "{:.0f}")],
             ["1 robot exploring (blazing-trail-v1, teamnav only)", "", cell(explore, "units_total"), "",
              cell(explore, "trip_time_s_after_median", "{:.0f}")]]
    if quick:
        blocks.append(Missing("baselines: one exploring robot, no communication", "full mode only"))
    blocks.append(Table("Baselines", ["condition"] + [f"units in {dur / 60:g} min, {h}" for _, h in T.COLUMNS]
                        + [f"median trip after first trail [s], {h}" for _, h in T.COLUMNS], base))

    # Fig. 5 left: units over time
    t = T.time_grid(dur)
    series = [s for s in (
        T.band_series("4 robots, paper drift, paper as written", pr["paper"], t),
        T.band_series("4 robots, paper drift, teamnav", paper, t),
        T.band_series("4 robots, no communication", nocomm, t),
        T.band_series("1 robot exploring", explore, t),
        T.band_series("1 robot, the team's brain, no drift", solo, t),
        T.band_series("1 robot, optimal route", opt, t),
    ) if s is not None]
    blocks.append(Plot("Units transported over time (Fig. 5 left)", "time [min]", "units (cumulative)", series,
                       caption="mean over seeds with a 10–90 % band"))
    # Fig. 5 right: units per 10 min
    sers = []
    for col, head in T.COLUMNS:
        win = [np.asarray(__import__("json").loads(r["units_per_10min_series"]), float) for r in cols[col]["paper"]
               if isinstance(r.get("units_per_10min_series"), str)]
        if win:
            n = min(w.size for w in win)
            W = np.stack([w[:n] for w in win])
            sers.append(Series(f"4 robots, paper drift, {head}", [10.0 * (k + 1) for k in range(n)], W.mean(0).tolist(),
                               W.min(0).tolist(), W.max(0).tolist(), style="bar"))
    if sers:
        blocks.append(Plot("Units per 10 minutes (Fig. 5 right)", "window end [min]", "units", sers,
                           caption="mean over seeds, band min..max"))
    for col, head in T.COLUMNS:
        if T.by_scale(cols[col]["drift"]):
            blocks += drift_plots(f"blazing-trail-v1 (2000), {head}", cols[col]["drift"], drift_dur)
    blocks += T.crumb_views(paper[0], [n.capitalize() for n in OUR_ROBOTS], "blazing-a-trail, teamnav")
    return blocks


def failure_cause_text(paper_verdicts: dict, drift_rows, drift_dur_s: float) -> str:
    """FIDELITY §1/§4: one paragraph on why the paper column fails claims 1-2, when it does.

    The 2000 paper puts its breakdown on drift alone (§5.1: before 20 min "all robots made
    consistently correct turning decisions"). When the paper column also breaks down in runs
    *without* drift (the drift sweep's k = 0), the failure is not the mechanism the paper
    reports: the paper's 180° rule (§4.2) works there through two values the paper leaves open
    (the crumbs' threshold radius, "approximately opposite"), which are our fills. The text says
    so beside the verdicts, which it does not change. Empty when claims 1-2 hold.
    """
    failing = [cid for cid in ("first-trail", "team-vs-one-robot")
               if cid in paper_verdicts and paper_verdicts[cid][0] is False]
    if not failing:
        return ""
    k0 = T.by_scale(drift_rows).get(0.0, [])
    c = T.values(k0, "breakdown_censored")
    broke = int((c == 0).sum())
    head = (f"Why the paper column fails {' and '.join(failing)}: ")
    if not c.size:
        return head + "the drift sweep's k = 0 runs are missing, so whether it works without drift is not known here."
    if broke == 0:
        return (head + f"without drift it never broke down ({c.size} runs of {drift_dur_s / 60:g} min), so its "
                "losses come with drift, the mechanism the paper reports (§5.1).")
    return (head + f"it also broke down without any drift, in {broke} of {c.size} runs of {drift_dur_s / 60:g} min "
            "(the drift sweep's k = 0). The paper puts its breakdown on drift alone (§5.1: until 20 minutes \"all "
            "robots made consistently correct turning decisions\"). Our robots turn round by the paper's 180° rule "
            "(§4.2: \"If the robot is heading in approximately the opposite direction to the trail it makes a sharp "
            "180° right turn\") through two values the paper does not give: the crumbs' threshold radius (2 m, a fill "
            "in the ledger) and what \"approximately opposite\" means (Navigate's reverse_threshold_deg, 150°, the "
            "library default, untuned). So these verdicts are measured, but their cause is not shown to be the "
            "paper's.")


def _n_broke(rows) -> str:
    c = T.values(rows, "breakdown_censored")
    return f"{int((c == 0).sum())}/{c.size}"


def drift_plots(label: str, rows, drift_dur_s: float, *, with_units_over_time: bool = True) -> list:
    """The drift sweep's figures for one algorithm: breakdown time vs k (median, 25–75 %, every
    run marked; censored runs at the run's length), the fraction of runs not broken down over time
    per k (Kaplan–Meier), and units over time per k."""
    xs, bd, lo, hi = T.per_drift(rows, "breakdown_s")
    bx, by, cx, cy = T.breakdown_marks(rows)
    groups = T.by_scale(rows)
    out = [Plot(f"Breakdown time vs per-robot heading drift, {label}", T.DRIFT_AXIS, "breakdown [min]",
                [Series("median (25–75 %)", xs, [b / 60 for b in bd], [b / 60 for b in lo], [b / 60 for b in hi],
                        style="line+points"),
                 Series(f"a run that broke down ({len(bx)})", bx, by, style="points"),
                 Series(f"a run with no breakdown (censored at its end, {len(cx)})", cx, cy, style="points")],
                hlines=[(27.0, "Blazing §5.1: ~27 min"), (drift_dur_s / 60, "run length (no breakdown)")],
                caption="runs broken down per k: " + ", ".join(f"k = {k:g}: {_n_broke(g)}" for k, g in groups.items()))]
    t = T.time_grid(drift_dur_s, 121)
    out.append(Plot(f"Fraction of runs not broken down by time t, {label}", "t [min]", "fraction still delivering",
                    [Series(f"k = {k:g} (n = {len(g)})", (t / 60).tolist(), T.survival(g, t).tolist(), style="step")
                     for k, g in groups.items()],
                    caption="Kaplan–Meier: a run breaks down at its last delivery when none followed in the last "
                            "180 s of the run; runs that did not are censored at their end"))
    if with_units_over_time:
        tg = T.time_grid(drift_dur_s)
        out.append(Plot(f"Units over time per drift scale k, {label}", "time [min]", "units (cumulative)",
                        [s for s in (T.band_series(f"k = {k:g}", g, tg) for k, g in groups.items()) if s is not None],
                        caption="mean over seeds with a 10–90 % band: the curves flatten as drift grows"))
    _, last, llo, lhi = T.per_drift(rows, "units_per_10min_last", np.mean)
    out.append(Plot(f"Units in the last 10 minutes vs per-robot drift, {label}", T.DRIFT_AXIS, "units",
                    [Series("mean (25–75 %)", xs, last, llo, lhi, style="line+points")],
                    caption=f"the last 10 minutes of {drift_dur_s / 60:g}-minute runs"))
    return out


SECTION = SectionSpec(
    key="blazing-a-trail",
    title="Blazing a trail: crumb trails in a shared odometric frame (Vaughan et al. 2000)",
    paper=PAPER,
    build=build,
    summary="4 robots forage by broadcast crumb trails; team vs one optimal robot; breakdown under drift.",
    order=30,
    tags=("trails",),
)
