"""Report section ``blazing-a-trail``: Vaughan, Støy, Sukhatme & Matarić (2000), *Blazing a trail*.

EXPERIMENTS.md rows, each a :class:`Comparison`:

1. "first robot finds resource, others follow the optimal route" → after the first broadcast,
   trip times drop to near optimal (median trip time after the first source event vs the
   route-follow-v1 robot's trip time; holds within 1.5x).
2. "4 robots ≈ 3x a single optimal robot" (§5.1: "Since the time for a round-trip from home to
   resource is approximately 3 minutes the robot group performed three times better than a single
   robot performing under optimal conditions": 28 units vs 30 / 3 = 10, i.e. 2.8x) → two ratios.
   The paper's method: the team's units / the units one robot delivers at the optimal round-trip
   rate of the team's own controller, i.e. duration / (2 x the median trip time after its own
   first trail) of ONE blazing-trail-v1 robot with the team's params, alone and without drift
   (sweep trail-solo-blazing). Stricter, beside it: the team's units / the units a measured
   route-follow-v1 robot delivers on the optimal route (trail-solo-optimal: a different, faster
   controller, pure pursuit that cuts the corners without sharp turns). The verdict follows the
   paper's method and holds at >= 2.7x (the paper's own figure, 2.8, is what it calls "three
   times"); the route-follow ratio is shown with its value, not judged.
3. "odometry drift makes the system break down (~27 min)" → units over time flatten and breakdown
   time falls as the drift grows (blazing-drift sweep: each robot its own drift, k x the 2002
   paper's Bug -1, Ant +1, Fly +2, Tanis +0.35 deg/min, k = 0, 1, 2, 3, 4, 6, 10 seeds x 1 h):
   judged by :func:`drift_verdict` on the trend over all runs (rank correlations of breakdown
   time and last-10-minute units with k) and a collapse at the highest k.

Baselines beside them: one optimal robot (route-follow-v1), one robot with the team's own brain
and params alone without drift (trail-solo-blazing, the paper's "optimal conditions"), one
exploring robot (blazing-trail-v1 alone, trail-solo-explore), the team without communication, and the team with the paper's rules
as written (blazing-paper-rules: blazing-trail-v1's navigation gap-fills off). Figures: units over time (Fig. 5
left), units per 10 min (Fig. 5 right); for the drift sweep breakdown time vs k (median and
25–75 %, every run marked, censored runs at the run's end), the fraction of runs not broken down
by time t per k (Kaplan–Meier), units over time per k and last-10-minute units vs k; the trails
each robot announced in its own frame (Fig. 6) and all of them in a fixed frame of the places.

Quick mode: 450 s runs (drift sweep 300 s), 2 seeds (1 for each one-robot baseline), drift
k = 0 and 4 only, no explorer or no-communication baselines. Full: the paper's 30 min, 10 seeds; drift
k = 0, 1, 2, 3, 4, 6 for 1 h, 10 seeds (the sweep's k = 0.5 case is there for ``teamnav sweep``;
the drift sweep is shared with the try-to-see-it-my-way section).

What the section measured (the final drift sweep, the paper's conditions, one robot alone,
the full mode's cost, with commits): ``docs/report/blazing-a-trail.md``.
"""

from __future__ import annotations

import numpy as np

from teamnav.experiments.report.model import Comparison, Missing, Plot, SectionSpec, Series, Table, Text
from teamnav.experiments.report.sections import _trails as T

PAPER = "vaughan-stoy-sukhatme-mataric-blazing-a-trail.txt"
#: §5.1 units per robot (Tanis, Ant, Bee, Punky) and total
PAPER_UNITS = {"Tanis": 7, "Ant": 7, "Bee": 6, "Punky": 8}
#: scenario blazing-a-trail's robot order
OUR_ROBOTS = ("ant", "bee", "punky", "tanis")
#: claim 2 holds when the team delivers at least this many times the units of one robot at the
#: team controller's optimal round-trip rate (§5.1's own figure, 28 / 10 = 2.8, is its "three times")
PAPER_RATIO = 2.7
#: the drift sweep's scales k in full mode (blazing-drift cases x<k>, 10 seeds x 1 h each)
DRIFT_SCALES = (0.0, 1.0, 2.0, 3.0, 4.0, 6.0)


def drift_verdict(rows, drift_dur_s: float) -> tuple[bool | None, str]:
    """Claim 3 from the drift sweep's runs: (holds, the numbers it was read from).

    Holds when (a) the drift-free team works (last-10-min mean >= WORKING_UNITS_PER_10MIN),
    (b) at the highest drift the last-10-min mean is below half the drift-free one (collapsed,
    not just slower), (c) some drift scale has most of its runs broken down (median breakdown
    before the run's end), and (d) over all runs breakdown time and last-10-min units both fall
    with k (Spearman rank correlation < 0; censored runs count at the run's length). The trend,
    not each step, is judged: a breakdown is 180 s without a delivery at the run's end, and a
    collapsed team still delivers a trickle of units by random exploration, so neighbouring
    scales can swap. None for fewer than two scales or runs shorter than MIN_VERDICT_S.
    """
    xs, bd, _, _ = T.per_drift(rows, "breakdown_s")
    _, last, _, _ = T.per_drift(rows, "units_per_10min_last", np.mean)
    rho_bd, rho_u = T.drift_trend(rows, "breakdown_s"), T.drift_trend(rows, "units_per_10min_last")
    text = f"rank correlation with k: breakdown time {rho_bd:+.2f}, last-10-min units {rho_u:+.2f}"
    if len(xs) < 2 or drift_dur_s < T.MIN_VERDICT_S:
        return None, text
    holds = bool(last[0] >= T.WORKING_UNITS_PER_10MIN and last[-1] < 0.5 * last[0]
                 and min(bd) < drift_dur_s and rho_bd < 0 and rho_u < 0)
    return holds, text


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


def build(ctx) -> list:
    missing = T.brains_missing(["blazing-trail-v1", "route-follow-v1"])
    if missing is not None:
        return [missing]
    quick = bool(ctx.quick)
    seeds = 2 if quick else 10
    dur = 450.0 if quick else 1800.0
    drift_dur = 300.0 if quick else 3600.0
    scales = [0.0, 4.0] if quick else list(DRIFT_SCALES)
    cruise = T.cruise_mps("blazing-a-trail")

    paper = T.ok(ctx.sweep("blazing-paper", seeds=seeds, duration_s=dur))
    opt = T.ok(ctx.sweep("trail-solo-optimal", seeds=1 if quick else 3, duration_s=dur))
    # the paper's "single robot performing under optimal conditions": the team's own brain alone, no drift
    solo = T.ok(ctx.sweep("trail-solo-blazing", seeds=1 if quick else seeds, duration_s=dur))
    # quick mode (CI) skips the two baselines: each sweep call costs a worker pool's start-up
    explore = [] if quick else T.ok(ctx.sweep("trail-solo-explore", seeds=seeds, duration_s=dur))
    # (the team with communication and no drift is the drift sweep's k = 0)
    nocomm = [] if quick else T.ok(ctx.sweep("trail-communication", seeds=seeds, duration_s=dur,
                                             set={"robots.0.controller": "blazing-trail-v1"},
                                             grid={"robots.0.params.communicate": [False]}))
    drift = T.ok(ctx.sweep(T.drift_spec("blazing-drift", scales), seeds=seeds, duration_s=drift_dur))
    # ablation: the same trial with the paper's rules as written (our navigation gap-fills off)
    rules = [] if quick else T.ok(ctx.sweep("blazing-paper-rules", seeds=seeds, duration_s=dur))
    drift0 = T.by_scale(drift).get(0.0, [])

    blocks: list = [Text(
        f"Scenario blazing-a-trail: 4 robots on trail_office_corridors (home and source ~31.5 m apart through two "
        f"corners), {dur / 60:g} min per run, per-robot heading drift (Ant 1.5, Bee 1.0, Punky 0.3, "
        f"Tanis -0.3 deg/min), cruise {cruise:g} m/s, {seeds} seeds. A unit is delivered when a robot "
        "that reached the source reaches home; breakdown = the last delivery when none followed in the "
        f"last {180:g} s of the run (otherwise censored at the run's end). The drift sweep gives each robot its "
        f"own drift, k x ({T.DRIFT_TEXT}) (the 2002 paper's robots), {drift_dur / 60:g} min per run.")]
    if not paper or not opt:
        return blocks + [Missing("blazing-a-trail runs", "every trial of the blazing-paper or trail-solo-optimal sweep failed")]

    # 1. first trail, trip times after it vs the optimal robot
    opt_trip = T.values(opt, "trip_time_s_after_median")
    first = T.values(paper, "first_trail_s")
    after = T.values(paper, "trip_time_s_after_median")
    before = T.values(paper, "trip_time_s_before_median")
    after0 = T.values(drift0, "trip_time_s_after_median")
    o = T.mean(opt_trip)
    holds1 = bool(after.size and o > 0 and np.median(after) <= 1.5 * o) if after.size else None
    blocks.append(Comparison(
        "After the first broadcast, trip times drop to near the optimal route's",
        "first robot reaches the resource at 1.25 min; all four then take the optimal route (two correct turns)",
        f"first source visit at {T.msd(first / 60, '{:.1f}', 'min')}; median trip {T.msd(before, '{:.0f}', 's')} "
        f"before it, {T.msd(after, '{:.0f}', 's')} after (no drift: {T.msd(after0, '{:.0f}', 's')}); "
        f"optimal robot {o:.0f} s",
        holds1,
        "our exploration is the H3 navigate-v1 random explorer on a synthetic office; the paper reports one trial, "
        "we report the spread over seeds"))

    # 2. team vs one robot under optimal conditions (§5.1): the paper's method and route-follow
    team_units = T.values(paper, "units_total")
    team0 = T.values(drift0, "units_total") if drift_dur == dur else np.array([])
    opt_units = T.values(opt, "units_total")
    solo_trip = T.values(solo, "trip_time_s_after_median")
    ratio_paper, solo_units = paper_method_ratio(T.mean(team_units) if team_units.size else float("nan"),
                                                 solo_trip, dur)
    ratio_rf = T.mean(team_units) / T.mean(opt_units) if opt_units.size and T.mean(opt_units) > 0 else float("nan")
    blocks.append(Comparison(
        "4 robots ≈ 3x a single robot under optimal conditions",
        "28 units in 30 min; one robot on a ~3 min round trip ≈ 10 units: 2.8x, which the paper calls three times",
        f"team {T.msd(team_units)} units in {dur / 60:g} min"
        + (f" (team without drift {T.msd(team0)})" if team0.size else "") + "; "
        + (f"one blazing-trail-v1 robot alone, no drift: median trip after its first trail "
           f"{T.msd(solo_trip, '{:.0f}', 's')} (round trip {2 * float(np.median(solo_trip)) / 60:.1f} min) → "
           f"{solo_units:.1f} units at that rate: {ratio_paper:.2f}x (the paper's method, judged at ≥ {PAPER_RATIO:g}x); "
           if np.isfinite(ratio_paper) else "one blazing-trail-v1 robot alone: no trip after its first trail; ")
        + f"stricter, one route-follow-v1 robot on the optimal route {T.msd(opt_units)} units: {ratio_rf:.2f}x",
        bool(ratio_paper >= PAPER_RATIO) if np.isfinite(ratio_paper) else None,
        "the paper's single robot is an estimate (a ~3 min round trip, no run); ours applies the same method to "
        "the team's own controller, alone and without drift (its round trip after its first trail), and shows "
        "beside it a measured route-follow-v1 robot, a faster controller (pure pursuit, cuts corners, no sharp "
        "turns), whose ratio is not judged; "
        "in quick mode the runs are short and the initial search weighs more"))

    # 3. breakdown vs drift
    xs, bd, bd_lo, bd_hi = T.per_drift(drift, "breakdown_s")
    _, last, last_lo, last_hi = T.per_drift(drift, "units_per_10min_last", np.mean)
    holds3, trend = drift_verdict(drift, drift_dur)
    groups = T.by_scale(drift)
    paper_bd = T.values(paper, "breakdown_s")
    cens = T.values(paper, "breakdown_censored")
    blocks.append(Comparison(
        "Odometry drift makes the system break down; breakdown comes earlier as drift grows",
        "no unit after ~27 min of 30 (rate falls from the start, Fig. 5 right)",
        f"paper conditions: breakdown at {T.msd(paper_bd / 60, '{:.1f}', 'min')} "
        f"({int(cens.sum()) if cens.size else 0} of {cens.size} runs did not break down within {dur / 60:g} min); "
        f"drift sweep ({drift_dur / 60:g} min): "
        + "; ".join(f"k = {d:g}: {_n_broke(groups.get(d, []))} broke down, median breakdown {b / 60:.0f} min, "
                    f"last-10-min units {u:.1f}" for d, b, u in zip(xs, bd, last))
        + f"; {trend}",
        holds3,
        "the sweep scales the 2002 paper's per-robot drift (the 2000 paper gives no rates); heading drift only "
        "(both papers report rotation only; the wheel-scale and slip cases are in the try-to-see-it-my-way "
        "section); censored runs count at the run's length"))

    # per-robot units (paper's table)
    rows = []
    for i, name in enumerate(OUR_ROBOTS):
        v = T.values(paper, f"units.robot{i}")
        rows.append([name.capitalize(), PAPER_UNITS[name.capitalize()], T.msd(v)])
    rows.append(["Total", sum(PAPER_UNITS.values()), T.msd(team_units)])
    blocks.append(Table("Units transported per robot (§5.1)", ["Robot", "paper (30 min, 1 trial)",
                                                                f"ours ({dur / 60:g} min)"], rows))

    # baselines side by side
    base = [
        ["4 robots, paper drift", T.msd(team_units), T.msd(T.values(paper, "trip_time_s_after_median"), "{:.0f}")],
        ["4 robots, no drift", T.msd(T.values(drift0, "units_total")) + ("" if drift_dur == dur else f" (in {drift_dur / 60:g} min)"),
         T.msd(after0, "{:.0f}")],
        ["4 robots, paper drift, the paper's rules as written (our gap-fills off)", T.msd(T.values(rules, "units_total")),
         T.msd(T.values(rules, "trip_time_s_after_median"), "{:.0f}")],
        ["4 robots, no communication", T.msd(T.values(nocomm, "units_total")),
         T.msd(T.values(nocomm, "trip_time_s_after_median"), "{:.0f}")],
        ["1 robot exploring (blazing-trail-v1)", T.msd(T.values(explore, "units_total")),
         T.msd(T.values(explore, "trip_time_s_after_median"), "{:.0f}")],
        ["1 robot, the team's brain alone, no drift (trail-solo-blazing; its units include its search)",
         T.msd(T.values(solo, "units_total")), T.msd(solo_trip, "{:.0f}")],
        ["1 robot on the optimal route (route-follow-v1)", T.msd(opt_units), T.msd(opt_trip, "{:.0f}")],
    ]
    if quick:
        blocks.append(Missing("baselines: one exploring robot, no communication, the paper's rules as written",
                              "full mode only"))
    blocks.append(Table("Baselines", ["condition", f"units in {dur / 60:g} min", "median trip time after first trail [s]"], base))

    # Fig. 5 left: units over time
    t = T.time_grid(dur)
    series = [s for s in (
        T.band_series("4 robots, paper drift", paper, t),
        T.band_series("4 robots, the paper's rules as written", rules, t),
        T.band_series("4 robots, no communication", nocomm, t),
        T.band_series("1 robot exploring", explore, t),
        T.band_series("1 robot, the team's brain, no drift", solo, t),
        T.band_series("1 robot, optimal route", opt, t),
    ) if s is not None]
    blocks.append(Plot("Units transported over time (Fig. 5 left)", "time [min]", "units (cumulative)", series,
                       caption="mean over seeds with a 10–90 % band"))
    # Fig. 5 right: units per 10 min
    win = [np.asarray(__import__("json").loads(r["units_per_10min_series"]), float) for r in paper
           if isinstance(r.get("units_per_10min_series"), str)]
    if win:
        n = min(w.size for w in win)
        W = np.stack([w[:n] for w in win])
        blocks.append(Plot("Units per 10 minutes (Fig. 5 right)", "window end [min]", "units",
                           [Series("4 robots, paper drift", [10.0 * (k + 1) for k in range(n)], W.mean(0).tolist(),
                                   W.min(0).tolist(), W.max(0).tolist(), style="bar")],
                           caption="mean over seeds, band min..max"))
    if xs:
        blocks += drift_plots("blazing-trail-v1 (2000)", drift, drift_dur)
    blocks += T.crumb_views(paper[0], [n.capitalize() for n in OUR_ROBOTS], "blazing-a-trail")
    return blocks


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
