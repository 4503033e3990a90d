"""Report section ``try-to-see-it-my-way``: Vaughan, Støy, Sukhatme & Matarić (2002).

EXPERIMENTS.md rows, each a :class:`Comparison`:

1. "4 robots, 3 h 8 min, 262 trips, 8.2 km, ≈ 92 % of cruise speed" → the try-paper runs go on
   for hours under the paper's per-robot drift with no breakdown; efficiency (§3.6: route length
   / (total lifetime / trips) / cruise speed) near the paper's.
2. EXPERIMENTS.md "runs for hours of simulated time with drift that breaks the Blazing-a-trail
   system, with no breakdown" and the issue's "the 2002 one keeps working for hours under the
   same drift" → :func:`hours_blocks`: the 2002 team for 3 h at drift k = 4 (where the 2000
   team collapses within the hour), 8 seeds: breakdowns and units per hour per seed, beside the
   2000 team's 1-hour runs at k = 4.
3. "trails shared despite diverged frames" → the same drift for 1 h with and without Place
   transforms, and the 2000 algorithm (the drift sweeps' k = 1 case: the paper's drift).
4. The drift sweep of both algorithms (each robot its own drift, k x Bug -1, Ant +1, Fly +2,
   Tanis +0.35 deg/min): breakdown time and last-10-minute throughput vs k; the 2002 team's
   k = 1 and k = 4 points are the first hour of the try-paper and hours runs
   (:func:`_trails.first_part`: a run does not know its length, tests/test_trail_experiments.py
   checks it), its k = 0, 2, 6 points 1-hour runs (8 seeds); the 2000 team's k = 0, 1, 2, 3, 4, 6
   1-hour runs (10 seeds, the blazing-a-trail section's).
5. Memory stays flat (crumbs held, first vs second half of the long runs: 4-minute expiry).
6. The issue's "memory stays flat over a 10-hour simulated run" and "a simulated hour of 4 robots
   runs in well under a minute on one core": one 10-hour run of trail-share-v1 at k = 4, sampled
   every 30 min in the trial (:func:`_trails.profile_trial`: the largest Trail any robot holds,
   the process's RSS, CPU seconds per simulated hour), and a 2-hour run of blazing-trail-v1 at
   k = 1 for its CPU cost and its ever-growing crumb list. Measured (commit bec19bc, seed 0,
   machine shared with ~12 other runs): 341 units in 10 h, 5.7 per 10 min on average and 5.7 in
   the last 3 h (no breakdown); largest Trail 462–476 crumbs in every sample (bound 4 x 121);
   RSS 248.9 MiB at 0.5 h and at 10 h; 40 CPU s per simulated hour (38–49 per interval; 58 in
   the first, which loads the compiled kernels). One seed: the long-run claim is item 2's.

Measured this session, trail-share-v1 on f8202ad (the last behaviour commit of trail_share.py;
b635a78's flags are off by default), machine under a load of 6–14, 105 CPU s per 3-h run:

- try-paper (the paper's drift, 3 h, seeds 0-5; 10 asked): 300 ± 12 trips, 14.71 ± 0.04 km,
  149.0 ± 5.9 units, 143 ± 6 s between places → efficiency 55 ± 2 % (paper 92 %; claim 1 does
  not hold: median trip after the first trail 100 ± 2 s against ~79 s at cruise), no breakdown
  in 6 of 6, 41–57 units in every hour; Table 1 (trips / m / min): Bug 78 ± 3 / 3657 ± 11 /
  178.4, Ant 74 ± 6 / 3677 ± 31 / 178.8, Fly 69 ± 4 / 3693 ± 16 / 179.0, Tanis 78 ± 5 / 3687 ±
  40 / 178.7 (the paper's 36–86 trips: its robots failed early); largest Trail 475 / 474 crumbs
  in the first / second half.
- hours at k = 4 (3 h, seeds 0-5; 8 asked): units per hour per seed 16/24/29, 39/22/28,
  34/26/35, 33/35/27, 28/25/33, 28/23/26 (85.2 ± 10.4 in 3 h, fewest in any hour 16): every hour
  of every run worked (claim 2 holds); by the 180-s rule 2 of 6 "broke down" at 176 min, chance
  lulls (their robots still reached places in the last 4 minutes). The 2000 team at k = 4: 8 of
  10 broke down within the hour (38–54 min), 1.0 ± 1.3 units in the last 10 min.
- the drift curve's 2002 points, units in the last 10 min (units in the hour): k = 1 (first hour
  of try-paper, 6 seeds) 8.7 ± 2.0 (47.2 ± 4.1), k = 4 (first hour of the hours runs, 6 seeds)
  5.8 ± 1.0 (29.7 ± 7.9; 1 of 6 broke down by the 180-s rule); k = 0, 2, 6 (1 h, 8/8/7 seeds)
  measured on 812e9bf, before f8202ad's recovery default (H6a measured k = 4 unchanged by it):
  9.0 ± 1.9 (45.8 ± 3.3), 6.6 ± 1.4 (39.8 ± 3.0), 4.0 ± 1.5 (24.0 ± 3.9), no breakdown in any
  run. Against the 2000 team (10.5, 7.3, 3.4, 1.0, 2.1 at k = 0, 1, 2, 4, 6) the 2002 team keeps
  ~64 % of its k = 0 throughput at k = 4 and ~44 % at k = 6 (2000: 10 % and 20 %), and no
  1-hour 2002 run at k = 2 or 6 broke down (2000: 3 and 4 of 10). Claim 4 is judged at the
  drift that breaks the 2000 team (EXPERIMENTS.md: "with drift that breaks the Blazing-a-trail
  system"), the k > 0 where its last-10-min throughput is lowest: k = 4 (64 % against 10 %:
  holds). The rule was first "the highest k both ran" (6, where the 2000 team keeps a trickle by
  exploration and the 2002 team keeps 44 %, under the 50 % bar); it was changed by the lead after
  seeing these data, because k = 6 is not where the 2000 system breaks: at 12 deg/min for Fly the
  2002 team degrades too, and the report shows every k.
- not run (CPU): the 2002 slip case, try-drift k = 0, 2, 6 on f8202ad (24 team-hours), seeds
  6-9 of try-paper and 6-7 of the hours runs; the section's full mode runs them. CPU of this
  session's simulation: 2000 side 1009 s (40 runs of 1 h), 2002 side ≈ 1130 s on f8202ad (12
  runs of 3 h, two cut off) and ≈ 850 s on 812e9bf (23 runs of 1 h), quick report 50 s.

The 2000 team's side (final, the blazing-a-trail section's table), and its k = 1 + wheel-slip
case (0.01 m/√m, 1°/√m, our choice): 5.0 ± 1.8 units in the last 10 min, 41.4 ± 6.0 in the hour,
1 of 10 broke down (k = 1 alone 7.3 ± 1.3, 51.8 ± 2.0): slip costs it a fifth of its throughput.

Beside them: Table 1 (trips, distance, lifetime per robot), units over time, the times each
robot reached the places (Fig. 2 top), the crumbs each robot dropped in its own frame (Fig. 3)
and all crumbs in the fixed frame of the Places (Fig. 4), the N-place mail round (§2.1), the
drift sweep as a table (mean ± std per k, both algorithms) and the wheel-scale-error cases of
the drift sweeps (Bug +5 %, Ant −5 %, Fly +3 %, Tanis −3 %, alone and with k = 1; 3 seeds).

Quick mode: 300 s runs, 2 seeds, drift k = 0 and 4 (the blazing section's quick drift trials,
reused), no hours runs, no run without Place transforms, no long 2000-algorithm runs, no mail
round, no profiled, scale-error or slip runs (≈ 45 s wall on an idle machine; 75 s under a load
of 6.6 on 2 cores, 50 CPU s for both trail sections). Full: try-paper 3 h x 10 seeds (the
paper's trial lasted 3 h 8 min); the hours runs 3 h x 8 seeds at k = 4; the 2000 algorithm
under the paper's drift for 3 h x 5 seeds; the 2002 drift points k = 0, 2, 6 1 h x 8 seeds (k = 1
and 4 read from the long runs), the 2000 drift sweep k = 0..6 1 h x 10 seeds, the no-transform
control 1 h x 10 seeds; the slip case (k = 1 + wheel slip) 1 h x 10 (2000) and x 5 (2002) seeds;
the scale cases 1 h x 3 seeds; the mail round 30 min x 3 seeds; the 10-hour and 2-hour profiled
runs.

Cost of the full mode (measured on one core: 4 robots x 1 simulated hour = 37 CPU s for
trail-share-v1, 26–30 for blazing-trail-v1; more under a heavy shared load): trail-share-v1
30 (try-paper) + 24 (hours) + 24 (drift k = 0, 2, 6) + 10 (no transforms) + 5 (slip) + 6 (scale)
+ 10 (profiled) + 1 (mail round) ≈ 110 team-hours ≈ 68 CPU min; blazing-trail-v1 15 (3-h runs)
+ 10 (slip) + 6 (scale) + 2 (profiled) ≈ 33 team-hours ≈ 16 CPU min; blazing-drift is the
blazing-a-trail section's (60 team-hours, run once for both): ≈ 85 CPU min here, ≈ 2 CPU-hours
for both sections.
"""

from __future__ import annotations

import json

import numpy as np

from teamnav.experiments.metric_sets import trails as M
from teamnav.experiments.report.model import Comparison, Missing, Plot, SectionSpec, Series, Table, Text
from teamnav.experiments.report.sections import _trails as T
from teamnav.experiments.sweep import SweepSpec

PAPER = "vaughan-stoy-sukhatme-mataric-try-to-see-it-my-way.txt"
#: Table 1 of the paper: robot -> (trips, distance m, lifetime min)
PAPER_TABLE1 = {"Tanis": (36, 1102, 81.3), "Bug": (59, 2102, 138.1), "Fly": (78, 2414, 176.6),
                "Ant": (86, 2592, 188.4), "Total": (262, 8211, 583.6)}
#: scenario try-to-see-it-my-way's robot order
OUR_ROBOTS = ("Bug", "Ant", "Fly", "Tanis")
#: seeds of the 2000 algorithm's long runs under the paper's drift (full mode)
LONG_BLAZE_SEEDS = 5
#: seeds of the wheel-scale-error cases (full mode)
SCALE_SEEDS = 3
#: seeds of the wheel-slip case (k = 1 and slip, the drift sweeps' case x1-slip), full mode: 2000, 2002
SLIP_SEEDS = {"blazing-drift": 10, "try-drift": 5}
#: the hours under drift (full mode): the 2002 team for HOURS_S at drift k = HOURS_SCALE (where the
#: 2000 team collapses within the hour), HOURS_SEEDS seeds (the try-drift case x<k>)
HOURS_SCALE, HOURS_SEEDS, HOURS_S = 4.0, 8, 10800.0
#: the 2002 side of the drift sweep in full mode: 1-hour runs of try-drift at these scales
#: (SHARE_DRIFT_SEEDS seeds); its k = 1 point is the first hour of the try-paper runs (the paper's
#: drift) and its k = HOURS_SCALE point the first hour of the hours runs (_trails.first_part)
SHARE_RUN_SCALES, SHARE_DRIFT_SEEDS = (0.0, 2.0, 6.0), 8
#: the long profiled run (full mode): the 2002 team for PROFILE_HOURS at drift k = PROFILE_SCALE,
#: where the 2000 team collapses within the hour; memory and CPU sampled every PROFILE_SAMPLE_S
PROFILE_HOURS, PROFILE_SCALE, PROFILE_SAMPLE_S = 10.0, 4.0, 1800.0
#: the 2000 team's profiled run: the paper's drift (k = 1, where it works), 2 h
PROFILE_BLAZE_HOURS, PROFILE_BLAZE_SCALE = 2.0, 1.0
#: memory is flat when the crumbs held in the run's second half stay within this factor of the first
#: half's (plus a few crumbs in flight) and the process grows by less than PROFILE_RSS_GROWTH_MB
PROFILE_CRUMB_FACTOR, PROFILE_RSS_GROWTH_MB = 1.1, 50.0


def profile_spec(sweep_name: str, scale: float) -> SweepSpec:
    """The drift sweep ``sweep_name`` at drift scale ``scale`` only, recording every
    :data:`PROFILE_SAMPLE_S` (run it with ``trial_fn=_trails.profile_trial``)."""
    spec = T.drift_spec(sweep_name, [scale])
    every = int(round(PROFILE_SAMPLE_S / 0.1))
    return spec.model_copy(update={"name": f"{spec.sweep_name}-profile",
                                   "set": {**spec.set, "record_every": every}})


def _profile_rows(row: dict) -> list[dict]:
    text = row.get("profile_series")
    return json.loads(text) if isinstance(text, str) else []


def _last_quarter_units(rows, dur_s: float) -> np.ndarray:
    """Units delivered in the last quarter of each run (steady state, after any breakdown)."""
    t0 = 0.75 * dur_s
    c = T.cumulative(rows, np.array([t0, dur_s]))
    return c[:, 1] - c[:, 0]


def build(ctx) -> list:
    missing = T.brains_missing(["trail-share-v1", "blazing-trail-v1"])
    if missing is not None:
        return [missing]
    quick = bool(ctx.quick)
    seeds = 2 if quick else 10
    dur = 300.0 if quick else 10800.0
    drift_dur = 300.0 if quick else 3600.0
    # quick: the blazing section's quick drift trials (same arguments: reused)
    from teamnav.experiments.report.sections.blazing_a_trail import DRIFT_SCALES

    cruise = T.cruise_mps("try-to-see-it-my-way")

    share = T.ok(ctx.sweep("try-paper", seeds=seeds, duration_s=dur))
    # the hours at the drift that breaks the 2000 team (full mode)
    hours = [] if quick else T.ok(ctx.sweep(T.drift_spec("try-drift", [HOURS_SCALE]), seeds=HOURS_SEEDS,
                                            duration_s=HOURS_S))
    if quick:
        d_share = T.ok(ctx.sweep(T.drift_spec("try-drift", [0.0, 4.0]), seeds=seeds, duration_s=drift_dur))
        d_blaze = T.ok(ctx.sweep(T.drift_spec("blazing-drift", [0.0, 4.0]), seeds=seeds, duration_s=drift_dur))
    else:
        d_share = T.ok(ctx.sweep(T.drift_spec("try-drift", list(SHARE_RUN_SCALES)), seeds=SHARE_DRIFT_SEEDS,
                                 duration_s=drift_dur))
        # k = 1 and k = HOURS_SCALE: the first hour of the long runs at those drifts (not run again)
        d_share += [T.first_part(r, drift_dur, "x1") for r in share if isinstance(r.get("units_series"), str)]
        d_share += [T.first_part(r, drift_dur, f"x{HOURS_SCALE:g}") for r in hours
                    if isinstance(r.get("units_series"), str)]
        d_blaze = T.ok(ctx.sweep(T.drift_spec("blazing-drift", list(DRIFT_SCALES)), seeds=seeds, duration_s=drift_dur))
    slip_s = [] if quick else T.ok(ctx.sweep(T.case_spec("try-drift", ["x1-slip"]), seeds=SLIP_SEEDS["try-drift"],
                                             duration_s=drift_dur))
    slip_b = [] if quick else T.ok(ctx.sweep(T.case_spec("blazing-drift", ["x1-slip"]),
                                             seeds=SLIP_SEEDS["blazing-drift"], duration_s=drift_dur))
    plain = [] if quick else T.ok(ctx.sweep("try-no-transforms", seeds=seeds, duration_s=drift_dur))
    # the 2000 algorithm for as long as the 2002 one, same drift (fewer seeds: the drift sweep has 10 at 1 h)
    long_blaze = [] if quick else T.ok(ctx.sweep("blazing-under-try-drift", seeds=LONG_BLAZE_SEEDS, duration_s=dur))
    # wheel-scale error (the drift sweeps' scale cases), fewer seeds: a bounded error, see the table's note
    scale_s = [] if quick else T.ok(ctx.sweep(T.case_spec("try-drift", T.SCALE_CASES), seeds=SCALE_SEEDS,
                                              duration_s=drift_dur))
    scale_b = [] if quick else T.ok(ctx.sweep(T.case_spec("blazing-drift", T.SCALE_CASES), seeds=SCALE_SEEDS,
                                              duration_s=drift_dur))
    # the long profiled runs (memory, CPU, hours of work under the drift that breaks the 2000 algorithm)
    prof = [] if quick else T.ok(ctx.sweep(profile_spec("try-drift", PROFILE_SCALE), seeds=1,
                                           duration_s=PROFILE_HOURS * 3600.0, trial_fn=T.profile_trial))
    prof_b = [] if quick else T.ok(ctx.sweep(profile_spec("blazing-drift", PROFILE_BLAZE_SCALE), seeds=1,
                                             duration_s=PROFILE_BLAZE_HOURS * 3600.0, trial_fn=T.profile_trial))
    mail = [] if quick else T.ok(ctx.sweep(
        SweepSpec(scenario="trail-mail-round", seeds=3, name="trail-mail-round",
                  set={"metrics": ["path_length", "events", "trails", "trails_series"]}), duration_s=1800.0))
    # the paper's drift (k = 1) for drift_dur: the 2002 team, the 2000 team
    same_share = T.by_scale(d_share).get(1.0, [])
    same_blaze = T.by_scale(d_blaze).get(1.0, [])

    blocks: list = [Text(
        f"Scenario try-to-see-it-my-way: 4 robots on trail_office_corridors, {dur / 60:g} min per run, heading drift "
        f"{T.DRIFT_TEXT} (§3.6), frames initially aligned, optimistic policy, "
        f"1-crumb trails every 2 s, crumbs expire after 4 min, cruise {cruise:g} m/s, {seeds} seeds. "
        f"The drift sweeps run both algorithms {drift_dur / 60:g} min with each robot drifting k x that pattern; "
        "k = 1 is the paper's drift.")]
    if not share:
        return blocks + [Missing("try-to-see-it-my-way runs", "every trial of the try-paper sweep failed")]
    per_h = T.values(share, "wall_time_s") / (dur / 3600.0)
    if per_h.size:
        blocks.append(Text(f"Speed: 4 robots x 1 simulated hour took {T.msd(per_h, '{:.0f}', 's')} of wall time per run "
                           "(the runs' wall_time metric; one core per trial when the report runs with --workers 1 "
                           "on an idle machine, more on a shared one)."))

    # 1. hours without breakdown, efficiency
    trips = T.values(share, "trips_total")
    dist_km = T.values(share, "distance_m_total") / 1000.0
    cens = T.values(share, "breakdown_censored")
    interval = T.values(share, "place_interval_s")
    speed = T.values(share, "place_speed_mps")
    eff = speed / cruise
    b_rows, b_dur = (long_blaze, dur) if long_blaze else (same_blaze, drift_dur)
    b_cens = T.values(b_rows, "breakdown_censored")
    b_bd = T.values(b_rows, "breakdown_s")
    late_long = _last_quarter_units(share, dur)
    late_long_b = _last_quarter_units(long_blaze, dur)
    # "for hours": no verdict on runs shorter than an hour (quick mode)
    holds1 = bool(cens.size and cens.mean() >= 0.8 and eff.size and np.median(eff) >= 0.75) if dur >= 3600.0 else None
    blocks.append(Comparison(
        "Runs for hours under drift, with no breakdown; efficiency near the paper's",
        "4 robots, 3 h 8 min: 262 trips, 8.2 km; 9 h 43 m 40 s of lifetime / 262 trips = 2 m 13 s between places "
        "= 0.23 m/s over 31 m, of 0.25 m/s cruise (92 %)",
        f"{dur / 60:g} min: {T.msd(trips, '{:.0f}')} trips, {T.msd(dist_km, '{:.2f}', 'km')}; "
        f"{T.msd(interval, '{:.0f}', 's')} between places = {T.msd(speed, '{:.2f}', 'm/s')}: efficiency "
        f"{T.msd(eff * 100, '{:.0f}', '%')}; no breakdown in {int(cens.sum())} of {cens.size} runs, units in the last "
        f"quarter {T.msd(late_long)} (2000 algorithm, same drift, {b_dur / 60:g} min: no breakdown in "
        f"{int(b_cens.sum()) if b_cens.size else 0} of {b_cens.size}, breakdown at {T.msd(b_bd / 60, '{:.0f}', 'min')}"
        + (f", units in the last quarter {T.msd(late_long_b)}" if late_long_b.size else "") + ")",
        holds1,
        f"our robots never fail, so every lifetime is about the whole run (the paper's ran out of power or lost "
        f"odometry); route 31.5 m, cruise {cruise:g} m/s (paper 31 m, 0.25 m/s)"))

    # 1b. hours at the drift that breaks the 2000 team (the long-run claim, several seeds)
    blocks += hours_blocks(hours, T.by_scale(d_blaze).get(HOURS_SCALE, []), T.by_scale(d_blaze).get(0.0, []),
                           drift_dur, quick)

    # 2. with vs without Place transforms, and the 2000 algorithm, same drift, same length
    late_share = _last_quarter_units(same_share, drift_dur)
    late_plain = _last_quarter_units(plain, drift_dur)
    late_blaze = _last_quarter_units(same_blaze, drift_dur)
    holds2 = None
    if late_share.size and late_plain.size and late_blaze.size:
        per_10min = late_share.mean() / (0.25 * drift_dur / 600.0)  # the 2002 team must still be working
        holds2 = bool(per_10min >= T.WORKING_UNITS_PER_10MIN and late_share.mean() >= late_plain.mean()
                      and late_share.mean() > late_blaze.mean())
    blocks.append(Comparison(
        "Trails are shared despite diverged frames (Place transforms)",
        "frames rotated 0.35–2 deg/min in both directions; trails shared throughout the 188 min",
        f"units in the last quarter of {drift_dur / 60:g}-min runs at the paper's drift: with transforms "
        f"{T.msd(late_share)}, without {T.msd(late_plain)}, 2000 algorithm {T.msd(late_blaze)}",
        holds2,
        "the paper had no no-transform or 2000-algorithm control under the same drift; ours are simulated with "
        "pure heading drift (no wheel noise)"))

    # 3. drift sweep, both algorithms
    xs_s, bd_s, lo_s, hi_s = T.per_drift(d_share, "breakdown_s")
    xs_b, bd_b, lo_b, hi_b = T.per_drift(d_blaze, "breakdown_s")
    _, last_s, llo_s, lhi_s = T.per_drift(d_share, "units_per_10min_last", np.mean)
    _, last_b, llo_b, lhi_b = T.per_drift(d_blaze, "units_per_10min_last", np.mean)
    # judged at the drift that breaks the 2000 algorithm (EXPERIMENTS.md: "with drift that breaks the
    # Blazing-a-trail system"): the k > 0 both ran where the 2000 team's last-10-min throughput is
    # lowest, each team against its own k = 0
    ls, lb = dict(zip(xs_s, last_s)), dict(zip(xs_b, last_b))
    bs, bb = dict(zip(xs_s, bd_s)), dict(zip(xs_b, bd_b))
    common = sorted(set(ls) & set(lb))
    worst = [k for k in common if k > 0.0]
    km = min(worst, key=lambda k: lb[k]) if worst else (common[-1] if common else None)
    holds3 = None
    if km is not None and drift_dur >= T.MIN_VERDICT_S:
        holds3 = bool(ls[km] >= T.WORKING_UNITS_PER_10MIN and ls[km] > lb[km]
                      and (0.0 not in ls or km == 0.0 or ls[km] >= 0.5 * ls[0.0])
                      and (0.0 not in lb or km == 0.0 or lb[km] < 0.5 * lb[0.0]))  # the 2000 one must collapse
    kept = ""
    if km and ls.get(0.0, 0) > 0 and lb.get(0.0, 0) > 0:
        kept = (f"; at k = {km:g} the 2002 team keeps {100 * ls[km] / ls[0.0]:.0f} % of its k = 0 "
                f"throughput, the 2000 team {100 * lb[km] / lb[0.0]:.0f} %")
    nan2 = (float("nan"), float("nan"))

    def at(k):
        a, b = (ls[k], bs[k]) if k in ls else nan2
        c, d = (lb[k], bb[k]) if k in lb else nan2
        return f"k = {k:g}: {a:.1f} ({b / 60:.0f} min) / {c:.1f} ({d / 60:.0f} min)"

    blocks.append(Comparison(
        "The 2000 algorithm's throughput collapses as drift grows; the 2002 one keeps working",
        "2000: breaks down at ~27 min; 2002: works for 3 h with 0.35–2 deg/min",
        "last-10-min units (median breakdown), 2002 / 2000: " + "; ".join(at(k) for k in sorted(set(ls) | set(lb)))
        + kept,
        holds3,
        f"{drift_dur / 60:g}-min runs; seeds per point in the drift table; k scales the 2002 paper's per-robot drift"))

    # the drift sweep as numbers: mean ± std (n) per drift scale, both algorithms
    sweep_rows = []
    gs, gb = T.by_scale(d_share), T.by_scale(d_blaze)
    for k in sorted(set(gs) | set(gb)):
        row = [f"{k:g}"]
        for group in (gs.get(k, []), gb.get(k, [])):
            bd = T.values(group, "breakdown_s")
            cens = T.values(group, "breakdown_censored")
            broke = T.values([r for r in group if not r.get("breakdown_censored")], "breakdown_s")
            row += [T.msd(T.values(group, "units_per_10min_last")), T.msd(T.values(group, "units_total")),
                    (f"{int((cens == 0).sum())}/{cens.size}" + (f" ({broke.min() / 60:.0f}–{broke.max() / 60:.0f} min)"
                                                                  if broke.size else "") if cens.size else "n/a"),
                    (f"{np.median(bd) / 60:.0f} min" if bd.size else "n/a")]
        sweep_rows.append(row)
    if sweep_rows:
        blocks.append(Table(f"Drift sweep, {drift_dur / 60:g}-min runs: throughput and breakdown per drift scale k",
                            ["k", "2002: units in last 10 min", f"2002: units in {drift_dur / 60:g} min",
                             "2002: broke down (when)", "2002: median breakdown", "2000: units in last 10 min",
                             f"2000: units in {drift_dur / 60:g} min", "2000: broke down (when)",
                             "2000: median breakdown"], sweep_rows,
                            note=f"k scales each robot's drift ({T.DRIFT_TEXT}); mean ± std over seeds; a run with "
                                 f"no breakdown counts at its length in the median"
                                 + ("" if quick else f"; the 2002 team's k = 1 and k = {HOURS_SCALE:g} rows are the first "
                                    f"hour of the try-paper and the {HOURS_S / 3600:g}-h runs")))

    if scale_s or scale_b or slip_s or slip_b:
        cs, cb = T.by_case(scale_s + slip_s), T.by_case(scale_b + slip_b)
        srows = []
        for label, what, base in (("x0", "no heading drift", 0.0), ("scale5", "no heading drift, wheel scale ±3–5 %", None),
                                  ("x1", "the paper's heading drift (k = 1)", 1.0),
                                  ("x1-scale5", "k = 1 and wheel scale ±3–5 %", None),
                                  ("x1-slip", "k = 1 and wheel slip (0.01 m/√m, 1°/√m)", None)):
            a = gs.get(base, []) if base is not None else cs.get(label, [])
            b = gb.get(base, []) if base is not None else cb.get(label, [])
            srows.append([what, T.msd(T.values(a, "units_per_10min_last")), T.msd(T.values(a, "units_total")),
                          _broke(a), T.msd(T.values(b, "units_per_10min_last")), T.msd(T.values(b, "units_total")),
                          _broke(b)])
        blocks.append(Table(f"Translational odometry error: wheel scale (Bug +5 %, Ant −5 %, Fly +3 %, Tanis −3 %) and "
                            f"wheel slip, {drift_dur / 60:g}-min runs",
                            ["odometry", "2002: units in last 10 min", f"2002: units in {drift_dur / 60:g} min",
                             "2002: broke down", "2000: units in last 10 min", f"2000: units in {drift_dur / 60:g} min",
                             "2000: broke down"], srows,
                            note="slip: a random walk per metre driven for every robot (teamnav.sim.odometry; our "
                                 "choice of size, no paper gives the trail robots' figures: ~5.6 cm and ~5.6 deg of "
                                 "std over the 31 m route, ~35 deg after an hour of driving); "
                                 "a scale error does not accumulate with time: robot frames differ by a fixed similarity "
                                 "(two robots' crumbs differ by at most 10 % of their distance from home), which the 2002 "
                                 "transform from two Places undoes exactly (its scale term) and the 2000 algorithm "
                                 "absorbs within its 2 m crumb radius near home only; the papers report rotation only"))
    elif quick:
        blocks.append(Missing("wheel-scale-error cases", "full mode only"))

    # Table 1
    rows = []
    for i, name in enumerate(OUR_ROBOTS):
        p = PAPER_TABLE1[name]
        rows.append([name, p[0], T.msd(T.values(share, f"trips.robot{i}"), "{:.0f}"), p[1],
                     T.msd(T.values(share, f"distance_m.robot{i}"), "{:.0f}"), p[2],
                     T.msd(T.values(share, f"lifetime_min.robot{i}"), "{:.1f}")])
    p = PAPER_TABLE1["Total"]
    rows.append(["Total", p[0], T.msd(trips, "{:.0f}"), p[1], T.msd(T.values(share, "distance_m_total"), "{:.0f}"),
                 p[2], T.msd(T.values(share, "lifetime_min_total"), "{:.1f}")])
    blocks.append(Table("Table 1: trips, distance and lifetime per robot",
                        ["Robot", "Trips (paper)", "Trips (ours)", "Distance m (paper)", "Distance m (ours)",
                         "Lifetime min (paper)", "Lifetime min (ours)"], rows,
                        note="lifetime = time of the robot's last place visit; the paper's Total row (262 trips, "
                             "583.6 min) is not the sum of its columns (259 trips, 584.4 min): §3.6 divides by 262"))

    # memory
    first, second = T.values(share, "crumbs_max_first_half"), T.values(share, "crumbs_max_second_half")
    if first.size:
        # the 4-min expiry needs the first half to be longer than 4 min before halves can be compared
        flat = bool(second.mean() <= 1.25 * first.mean() + 10) if dur >= 2 * 240.0 * 2 else None
        blocks.append(Comparison(
            "Memory stays flat (crumbs older than 4 min are destroyed)",
            "34,743 crumbs received by Ant over 188 min, many fewer held at any time",
            f"max crumbs held: first half {T.msd(first, '{:.0f}')}, second half {T.msd(second, '{:.0f}')}",
            flat, ""))
    else:
        blocks.append(Missing("crumb counts", "trail-share-v1 did not log n_crumbs"))
    blocks += _profile_blocks(prof, prof_b, T.by_scale(d_blaze).get(PROFILE_SCALE, []),
                              T.by_scale(d_blaze).get(0.0, []), drift_dur, quick)

    # mail round
    if mail:
        blocks.append(Text(
            f"N places (§2.1, mail round of 3 places, 4 robots, 1 deg/min drift): {T.msd(T.values(mail, 'trips_total'), '{:.0f}')} "
            "place-to-place trips in 30 min."))
    elif quick:
        blocks.append(Missing("mail round (N = 3 places)", "full mode only (quick mode keeps the section under a minute)"))

    # baselines
    base = [
        ["trail-share-v1 (2002)", T.msd(T.values(same_share, "units_total")), T.msd(late_share)],
        ["trail-share-v1 without Place transforms", T.msd(T.values(plain, "units_total")), T.msd(late_plain)],
        ["blazing-trail-v1 (2000)", T.msd(T.values(same_blaze, "units_total")), T.msd(late_blaze)],
    ]
    if quick:
        blocks.append(Missing("trail-share-v1 without Place transforms", "full mode only"))
    blocks.append(Table("The paper's drift, three algorithms", ["algorithm", f"units in {drift_dur / 60:g} min",
                                                                "units in the last quarter"], base))

    # figures: units over time, Fig. 2 top (arrivals), breakdown vs drift
    t = T.time_grid(dur)
    blocks.append(Plot("Units transported over time, the paper's drift", "time [min]", "units (cumulative)",
                       [s for s in (T.band_series("trail-share-v1 (2002)", share, t),
                                    T.band_series("blazing-trail-v1 (2000)", long_blaze, t)) if s is not None],
                       caption="mean over seeds with a 10–90 % band"))
    t1 = T.time_grid(drift_dur)
    series = [s for s in (T.band_series("trail-share-v1", same_share, t1),
                          T.band_series("no Place transforms", plain, t1),
                          T.band_series("blazing-trail-v1 (2000)", same_blaze, t1)) if s is not None]
    if series:
        blocks.append(Plot(f"Units over time, the paper's drift, three algorithms ({drift_dur / 60:g} min)",
                           "time [min]", "units (cumulative)", series, caption="mean over seeds with a 10–90 % band"))
    arr = share[0].get("arrivals_series")
    if isinstance(arr, str):
        pts = json.loads(arr)
        ser = []
        for i, name in enumerate(OUR_ROBOTS):
            mine = [p for p in pts if p[1] == i]
            ser.append(Series(name, [p[0] / 60 for p in mine], [i + (0.3 if p[2] == "source" else 0.0) for p in mine],
                              style="points"))
        blocks.append(Plot("Reaching places (Fig. 2 top), first seed", "time [min]", "robot (home low, source high)",
                           ser))
        # Fig. 2 bottom: trips (A-B or B-A, §3.5) accumulated over time, per robot and in total
        events = [{"t_s": p[0], "robot": p[1], "place": p[2], "event": p[2]} for p in pts]
        tr = M.trips(events, len(OUR_ROBOTS))
        ends = sorted(t1 for _, _, t1, _, _ in tr)
        ser = [Series(f"total ({len(ends)})", [0.0] + [t / 60 for t in ends], list(range(len(ends) + 1)), style="step")]
        for i, name in enumerate(OUR_ROBOTS):
            mine = sorted(t1 for r, _, t1, _, _ in tr if r == i)
            ser.append(Series(f"{name} ({len(mine)})", [0.0] + [t / 60 for t in mine], list(range(len(mine) + 1)),
                              style="step"))
        blocks.append(Plot("Trips over time (Fig. 2 bottom), first seed", "time [min]", "trips (cumulative)", ser,
                           caption="a trip is a robot's move from one place to the other (§3.5); the paper's "
                                   "4 robots: 262 in 188 min, about 1.4 per minute while all four ran"))
    if xs_s or xs_b:
        sers = []
        if xs_s:
            sers.append(Series("trail-share-v1 (2002)", xs_s, [b / 60 for b in bd_s], [b / 60 for b in lo_s],
                               [b / 60 for b in hi_s], style="line+points"))
        if xs_b:
            sers.append(Series("blazing-trail-v1 (2000)", xs_b, [b / 60 for b in bd_b], [b / 60 for b in lo_b],
                               [b / 60 for b in hi_b], style="line+points"))
        for name, rows_, dx in (("2002", d_share, -0.06), ("2000", d_blaze, 0.06)):
            bx, by, cx, cy = T.breakdown_marks(rows_)  # every run, nudged sideways per algorithm
            if bx:
                sers.append(Series(f"{name}: a run that broke down ({len(bx)})", [x + dx for x in bx], by, style="points"))
            if cx:
                sers.append(Series(f"{name}: no breakdown, censored at the run's end ({len(cx)})", [x + dx for x in cx],
                                   cy, style="points"))
        blocks.append(Plot("Breakdown time vs per-robot heading drift, both algorithms", T.DRIFT_AXIS,
                           "breakdown [min] (median, 25–75 %; every run marked)", sers,
                           hlines=[(27.0, "Blazing §5.1: ~27 min"), (drift_dur / 60, "run length (no breakdown)")],
                           caption="runs broken down per k, 2002 / 2000: " + "; ".join(
                               f"k = {k:g}: {_broke(gs.get(k, []))} / {_broke(gb.get(k, []))}"
                               for k in sorted(set(gs) | set(gb)))))
        blocks.append(Plot("Units in the last 10 minutes vs per-robot heading drift", T.DRIFT_AXIS, "units",
                           [Series("trail-share-v1 (2002)", xs_s, last_s, llo_s, lhi_s, style="line+points"),
                            Series("blazing-trail-v1 (2000)", xs_b, last_b, llo_b, lhi_b, style="line+points")],
                           caption=f"mean, band 25–75 % over seeds; {drift_dur / 60:g}-min runs"))
        tk = T.time_grid(drift_dur, 121)
        for label, groups in (("trail-share-v1 (2002)", gs), ("blazing-trail-v1 (2000)", gb)):
            if groups:
                blocks.append(Plot(f"Fraction of runs not broken down by time t, {label}", "t [min]",
                                   "fraction still delivering",
                                   [Series(f"k = {k:g} (n = {len(g)})", (tk / 60).tolist(), T.survival(g, tk).tolist(),
                                           style="step") for k, g in groups.items()],
                                   caption="Kaplan–Meier: a run breaks down at its last delivery when none followed in "
                                           "the last 180 s of the run; runs that did not are censored at their end"))
    blocks += T.crumb_views(share[0], OUR_ROBOTS, "try-to-see-it-my-way")
    return blocks


def _broke(rows: list) -> str:
    """"n/N" runs that broke down, "n/a" for none."""
    c = T.values(rows, "breakdown_censored")
    return f"{int((c == 0).sum())}/{c.size}" if c.size else "n/a"


def hours_blocks(hours: list, blaze_k: list, blaze_0: list, drift_dur: float, quick: bool) -> list:
    """The long-run claim: the 2002 team for HOURS_S at drift k = HOURS_SCALE, HOURS_SEEDS seeds,
    beside the 2000 team at the same drift (the drift sweep's 1-hour runs).

    Holds when every 2002 run delivered at least 6 x WORKING_UNITS_PER_10MIN units in every whole
    hour (no hour in which the team stopped working), and the 2000 team at that drift collapsed:
    at least half its runs broke down within the hour and its last-10-min units are below half its
    drift-free ones. None in quick mode or when either side has no runs. The 180-s rule's
    breakdowns (no delivery in the run's last 180 s) are shown but not judged here: over hours a
    team delivering ~5 units per 10 minutes has such a lull at the end of about one run in five
    by chance (one seed at k = 4: 16, 24, 29 units in its three hours, last delivery at 176 min),
    which is not the paper's breakdown ("no more units were transported after this time").
    """
    what = f"{HOURS_S / 3600:g} h at drift k = {HOURS_SCALE:g}"
    if quick or not hours:
        return [Missing(f"the 2002 team for {what} ({HOURS_SEEDS} seeds)",
                        "full mode only" if quick else "every hours trial failed")]
    per_h = [T.units_per_hour(r, HOURS_S) for r in hours]
    cens = T.values(hours, "breakdown_censored")
    b_last, b0_last = T.values(blaze_k, "units_per_10min_last"), T.values(blaze_0, "units_per_10min_last")
    b_cens = T.values(blaze_k, "breakdown_censored")
    b_bd = T.values([r for r in blaze_k if not r.get("breakdown_censored")], "breakdown_s")
    holds = None
    if cens.size and any(per_h) and b_last.size and b0_last.size and drift_dur >= T.MIN_VERDICT_S:
        worst_hour = min((min(u) for u in per_h if u), default=0)
        holds = bool(worst_hour >= 6 * T.WORKING_UNITS_PER_10MIN
                     and (b_cens == 0).mean() >= 0.5 and b_last.mean() < 0.5 * b0_last.mean())
    hourly = np.array([u for u in per_h if len(u) == int(HOURS_S // 3600)], float)
    blocks: list = [Comparison(
        f"Runs for hours under drift that breaks the 2000 system, with no breakdown ({what})",
        "2002: 3 h 8 min of work under 0.35–2 deg/min drift (the trial ended on hardware failures); "
        "2000: breakdown at ~27 min",
        f"2002 team, {cens.size} seeds x {HOURS_S / 3600:g} h: units per hour: "
        + (", ".join(f"hour {h + 1}: {T.msd(hourly[:, h])}" for h in range(hourly.shape[1])) if hourly.size else "n/a")
        + f" (fewest in any hour of any run: {min((min(u) for u in per_h if u), default=0)}); by the 180-s rule "
        f"no breakdown in {int(cens.sum())} of {cens.size}"
        + f"; 2000 team at the same drift ({drift_dur / 60:g}-min runs): {int((b_cens == 0).sum())} of {b_cens.size} broke "
        f"down (at {T.msd(b_bd / 60, '{:.0f}', 'min')}), last-10-min units {T.msd(b_last)} (no drift: {T.msd(b0_last)})",
        holds,
        f"k = {HOURS_SCALE:g} is Fly at {2 * HOURS_SCALE:g} deg/min, {HOURS_SCALE:g}x the paper's worst robot; our robots "
        "never fail, so a run ends on the clock; judged by every hour of every run delivering at least "
        f"{6 * T.WORKING_UNITS_PER_10MIN:g} units: the 180-s rule flags a chance lull at the end of a long run "
        "(about one run in five at ~5 units per 10 min)")]
    rows = [[str(r.get("seed")), *[str(u) for u in per_h[i]], str(r.get("units_total")),
             "none" if r.get("breakdown_censored") else f"{float(r.get('breakdown_s', 0)) / 60:.0f} min"]
            for i, r in enumerate(hours)]
    blocks.append(Table(f"The 2002 team for {what}, per seed", ["seed", *[f"units in hour {h + 1}" for h in
                                                                          range(int(HOURS_S // 3600))],
                                                               "units", "breakdown"], rows,
                        note="units per whole hour of each run; breakdown: the last delivery when none followed in "
                             "the last 180 s of the run"))
    return blocks


def _profile_blocks(prof: list, prof_b: list, blaze_k: list, blaze_0: list, drift_dur: float, quick: bool) -> list:
    """The long profiled runs: hours of work at drift k = PROFILE_SCALE, memory and CPU over time."""
    if quick or not prof:
        return [Missing(f"{PROFILE_HOURS:g}-hour run (memory, CPU per simulated hour, work under k = {PROFILE_SCALE:g} "
                        "drift)", "full mode only" if quick else "the profiled trial failed")]
    row = prof[0]
    samples = _profile_rows(row)
    win = np.asarray(json.loads(row.get("units_per_10min_series", "[]")), float)
    blocks: list = []
    b_last = T.values(blaze_k, "units_per_10min_last")
    # one seed for 10 h: the memory and CPU profile; the long-run claim is read from the hours runs
    late = win[-18:] if win.size >= 18 else win  # the last 3 hours
    bd_text = "none" if row.get("breakdown_censored") else f"at {float(row.get('breakdown_s', 0.0)) / 3600:.1f} h"
    blocks.append(Text(
        f"The {PROFILE_HOURS:g}-hour profiled run (trail-share-v1, k = {PROFILE_SCALE:g}, seed {row.get('seed')}): "
        f"{row.get('units_total')} units, units per 10 min "
        + (f"{win[:6].mean():.1f} in the first hour and {late.mean():.1f} in the last 3 h (min {late.min():.0f}); "
           if win.size else "n/a; ")
        + f"breakdown: {bd_text}."))
    # memory and CPU over the run
    if not samples:
        return blocks + [Missing("memory and CPU samples of the long run", "the trial has no profile_series (run it "
                                 "with trial_fn=_trails.profile_trial)")]
    cr = [s["crumbs_max"] for s in samples]
    half = len(cr) // 2
    flat = None
    if len(cr) >= 4:
        flat = bool(max(cr[half:]) <= PROFILE_CRUMB_FACTOR * max(cr[:half]) + 10
                    and float(row.get("rss_growth_mb", np.inf)) < PROFILE_RSS_GROWTH_MB)
    blocks.append(Comparison(
        f"Memory stays flat over a {PROFILE_HOURS:g}-hour run (crumbs older than 4 min are destroyed)",
        "34,743 crumbs received by Ant over 188 min, many fewer held at any time",
        f"largest Trail held by a robot: ≤ {max(cr[:half], default=0):.0f} crumbs in the first half, "
        f"≤ {max(cr[half:], default=0):.0f} in the second (bound: 4 robots x 240 s / 2 s = 480); process RSS "
        f"{row.get('rss_mb_first', float('nan')):.0f} MiB after {samples[0]['t_h']:g} h, "
        f"{row.get('rss_mb_last', float('nan')):.0f} MiB at {samples[-1]['t_h']:g} h",
        flat,
        "RSS of the process running the trial (simulator, brains and the recorder's few samples); the 2000 "
        "algorithm has no expiry: its global crumb list grows with every broadcast (table below)"))
    rows = [[f"{s['t_h']:g}", f"{s['crumbs_max']:.0f}", f"{s['rss_mb']:.0f}", f"{s['cpu_s_per_h']:.0f}"] for s in samples]
    blocks.append(Table(f"The {PROFILE_HOURS:g}-hour run (trail-share-v1, k = {PROFILE_SCALE:g}), sampled every "
                        f"{PROFILE_SAMPLE_S / 60:g} min", ["simulated h", "largest Trail [crumbs]", "process RSS [MiB]",
                                                          "CPU s per simulated h"], rows,
                        note="CPU time of the process (time.process_time) per simulated hour of 4 robots with "
                             "181-beam lasers at dt = 0.1 s; on a machine shared with other runs the figure is "
                             "inflated by cache and frequency contention, not by waiting"))
    cpu = [["trail-share-v1 (2002)", f"k = {PROFILE_SCALE:g}, {PROFILE_HOURS:g} h", f"{row.get('cpu_s_per_h', float('nan')):.0f}",
            f"{row.get('cpu_s_per_h_max', float('nan')):.0f}", f"{max(cr, default=0):.0f}"]]
    if prof_b:
        rb = prof_b[0]
        crb = [s["crumbs_max"] for s in _profile_rows(rb)]
        cpu.append(["blazing-trail-v1 (2000)", f"k = {PROFILE_BLAZE_SCALE:g}, {PROFILE_BLAZE_HOURS:g} h",
                    f"{rb.get('cpu_s_per_h', float('nan')):.0f}", f"{rb.get('cpu_s_per_h_max', float('nan')):.0f}",
                    " → ".join(f"{c:.0f}" for c in crb)])
    blocks.append(Table("CPU seconds per simulated hour of 4 robots (one core), and crumbs held",
                        ["brain", "run", "CPU s / h (mean)", "CPU s / h (worst interval)", "largest crumb list"], cpu,
                        note="the 2000 algorithm's global list only grows (no expiry in the 2000 paper); sampled every "
                             f"{PROFILE_SAMPLE_S / 60:g} min"))
    if win.size:
        blocks.append(Plot(f"Units per 10 minutes over {PROFILE_HOURS:g} h at drift k = {PROFILE_SCALE:g}",
                           "window end [h]", "units",
                           [Series(f"trail-share-v1 (2002), seed {row.get('seed')}", [(i + 1) / 6 for i in range(win.size)],
                                   win.tolist(), style="bar")],
                           hlines=[(float(b_last.mean()) if b_last.size else 0.0,
                                    f"blazing-trail-v1 (2000), last 10 of {drift_dur / 60:g} min, mean of {b_last.size}")]))
    return blocks


SECTION = SectionSpec(
    key="try-to-see-it-my-way",
    title="Try to see it my way: trails shared through task-level Places (Vaughan et al. 2002)",
    paper=PAPER,
    build=build,
    summary="Hours of foraging under drift with Place transforms; Table 1; both algorithms vs drift.",
    order=40,
    tags=("trails",),
)
