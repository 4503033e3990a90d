"""The ``try-to-see-it-my-way`` section's tables and figures: the drift sweep and odometry-error
tables, Table 1 (trips, distance, lifetime per robot), units over time, Fig. 2 (places reached,
trips), breakdown vs drift and the crumb views (Vaughan et al. 2002).

Split from :mod:`.try_to_see_it_my_way` (no behaviour change).
"""

from __future__ import annotations

import json

import numpy as np

from teamnav.papers.trails import metrics as M
from teamnav.experiments.report.model import Missing, Plot, Series, Table
from teamnav.papers.trails.report import _trails as T
from teamnav.papers.trails.report._try_long_runs import HOURS_S, HOURS_SCALE

#: Table 1 of the paper: robot -> (trips, distance m, lifetime min)
PAPER_TABLE1 = {"Tanis": (36, 1102, 81.3), "Bug": (59, 2102, 138.1), "Fly": (78, 2414, 176.6),
                "Ant": (86, 2592, 188.4), "Total": (262, 8211, 583.6)}
#: scenario try-to-see-it-my-way's robot order
OUR_ROBOTS = ("Bug", "Ant", "Fly", "Tanis")


def _broke(rows: list) -> str:
    """"n/N" runs that broke down, "n/a" for none."""
    c = T.values(rows, "breakdown_censored")
    return f"{int((c == 0).sum())}/{c.size}" if c.size else "n/a"


def drift_curves(d_share: list, d_blaze: list) -> tuple:
    """Per drift scale k, both algorithms (:func:`_trails.per_drift`): breakdown time of the 2002
    team, of the 2000 team, then last-10-min units (mean) of the 2002 team, of the 2000 team."""
    return (T.per_drift(d_share, "breakdown_s"), T.per_drift(d_blaze, "breakdown_s"),
            T.per_drift(d_share, "units_per_10min_last", np.mean), T.per_drift(d_blaze, "units_per_10min_last", np.mean))


def drift_table(d_share: list, d_blaze: list, drift_dur: float, quick: bool) -> list:
    """The drift sweep as numbers: mean ± std (n) per drift scale, both algorithms."""
    blocks: list = []
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
    return blocks


def odometry_table(scale_s: list, scale_b: list, slip_s: list, slip_b: list, d_share: list, d_blaze: list,
                   drift_dur: float, quick: bool) -> list:
    """Translational odometry error: the wheel-scale and wheel-slip cases beside no drift and k = 1."""
    blocks: list = []
    gs, gb = T.by_scale(d_share), T.by_scale(d_blaze)
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
    return blocks


def table1_block(share: list, column: str = "") -> Table:
    """Table 1 of the paper: trips, distance and lifetime per robot, ours (one column's runs, named
    by ``column``) beside the paper's."""
    trips = T.values(share, "trips_total")
    rows = []
    for i, name in enumerate(OUR_ROBOTS):
        p = PAPER_TABLE1[name]
        rows.append([name, p[0], T.msd(T.values(share, f"trips.robot{i}"), "{:.0f}"), p[1],
                     T.msd(T.values(share, f"distance_m.robot{i}"), "{:.0f}"), p[2],
                     T.msd(T.values(share, f"lifetime_min.robot{i}"), "{:.1f}")])
    p = PAPER_TABLE1["Total"]
    rows.append(["Total", p[0], T.msd(trips, "{:.0f}"), p[1], T.msd(T.values(share, "distance_m_total"), "{:.0f}"),
                 p[2], T.msd(T.values(share, "lifetime_min_total"), "{:.1f}")])
    return Table("Table 1: trips, distance and lifetime per robot" + (f" ({column})" if column else ""),
                        ["Robot", "Trips (paper)", "Trips (ours)", "Distance m (paper)", "Distance m (ours)",
                         "Lifetime min (paper)", "Lifetime min (ours)"], rows,
                        note="lifetime = time of the robot's last place visit; the paper's Total row (262 trips, "
                             "583.6 min) is not the sum of its columns (259 trips, 584.4 min): §3.6 divides by 262")


def figure_blocks(share: list, long_blaze: list, same_share: list, plain: list, same_blaze: list, d_share: list,
                  d_blaze: list, dur: float, drift_dur: float) -> list:
    """The figures: units over time, Fig. 2 top (arrivals) and bottom (trips), breakdown and last-10-min
    units vs drift, survival per k, and the crumb views (Figs. 3-4)."""
    blocks: list = []
    (xs_s, bd_s, lo_s, hi_s), (xs_b, bd_b, lo_b, hi_b), (_, last_s, llo_s, lhi_s), (_, last_b, llo_b, lhi_b) = \
        drift_curves(d_share, d_blaze)
    gs, gb = T.by_scale(d_share), T.by_scale(d_blaze)
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
