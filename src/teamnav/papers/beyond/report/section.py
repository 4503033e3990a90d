"""Report section ``beyond``: the four systems combined, each beside its parts.

Each paper gives its robots one kind of help and assumes the others away; here one team gets
two, and the section measures what the second buys against the systems it is built from.

1. **Localized trails** (``localized-v1`` over ``blazing-trail-v1``, scenario and sweep
   ``beyond-localized-trails``): the 2000 paper's crumbs and trail following (Blazing §4.1) laid
   and followed on a Monte Carlo localization pose (Fox et al. §3.1: the robot's laser through
   the likelihood field, 500 samples, tracking from the aligned start, the map given), instead
   of drifting odometry. Its parts: ``blazing-trail-v1`` on odometry (sweep ``blazing-drift``)
   and the 2002 algorithm, ``trail-share-v1``, on odometry (sweep ``try-drift``), under the same
   drift cases k = 0, 1, 4 x (Bug -1, Ant +1, Fly +2, Tanis +0.35 deg/min) and the same seeds.
   Shown: units per hour, runs that broke down (no unit in the last 10 min), the localized
   team's pose error (``localization`` metric: mean distance of its logged samples to the true
   position) and the CPU each brain costs per simulated hour. The verdict rule is
   ``papers/beyond/claims/beyond.yaml``'s ``localized-trails-drift``, judged on full-length
   (1 h) runs only.

Quick mode (CI): k = 0 and 4, the claim's two quick seeds, 5-min runs, 100 samples per
localized robot (the trail sections' quick drift runs are seed 0's odometric ones, which
``report all --quick`` reuses): the pipeline works;
no verdict (the rule needs 1-h runs). Full mode: k = 0, 1, 4, seeds 0-9, 1 h each
(30 localized runs, about 35 CPU-s each on this machine), and the particle counts (50 runs).

Full mode also runs ``beyond-localized-particles``: the localized team at k = 4 with 25, 50,
100, 200 and 500 samples per robot, and names the cheapest count none of whose runs broke
down (the question asked: "the cheapest particle count that removes the 2000 algorithm's breakdown").

The papers' future work, **a moving resource** (Vaughan et al. 2000 §6; the motion is ours,
:class:`~teamnav.sim.config.PlaceMotion`; scenario and sweep ``beyond-moving-resource``):
trail-share-v1 while the source stays, jumps every 30-5 min or glides at 0.01-0.05 m/s between
two spots of C3; units per hour against the source's mean speed, no claim (the paper gives no
number). Quick mode: the static and the fastest gliding case, seed 0, 5 min (two runs); full
mode: the 8 cases x seeds 0-9 x 1 h (about 9 CPU-s per run here), and blazing-trail-v1 (sweep
``beyond-moving-resource-blazing``: 3 motions x crumbs that never expire, the paper, or expire
after 300 s, ``global_crumb_ttl_s``, beyond it; 60 runs).

The papers' future work, **a restricted radio for every system** (the cases and the
bandwidth cap are ours; sweeps ``beyond-radio-<system>``): each system's headline metric against
loss, range and one bandwidth cap, with two verdict rules per system (claims ``radio-*``);
:mod:`~teamnav.papers.beyond.report._radio_beyond` owns the block and documents it.

Also built, each in its own module: combination 2, localized LOS help
(:mod:`._beyond_localized_los`); combination 3, detections help the trail team
(:mod:`._beyond_detecting_trails`); combination 4, trails as LOS memory (:mod:`._beyond_trail_memory`);
Fox et al. §7's negative detections and anonymous robots (:mod:`._beyond_negative_detections`).

Cost of the full section, measured whole (commit a4b747e, 2026-11-27, fresh folder, nothing reused): 1110 trials,
2.07 CPU-h, 79 min on 2 workers; the cost of each sweep is in ``docs/report/beyond.md``.
"""

from __future__ import annotations

import numpy as np

from teamnav.experiments.report.model import Comparison, Plot, SectionSpec, Series, Table, Text
from teamnav.papers.trails.report import _trails as T
from teamnav.papers.beyond.report._beyond_mail_round import mail_round as _mail_round
from teamnav.papers.beyond.report._beyond_trail_memory import trail_memory as _trail_memory

PAPER = "vaughan-stoy-sukhatme-mataric-blazing-a-trail.txt"
LOCALIZED_SWEEP = "beyond-localized-trails"
#: the parts, by column label: odometry-only sweeps with the same drift cases
PARTS = (("blazing-trail-v1, odometry", "blazing-drift"), ("trail-share-v1, odometry", "try-drift"))
LOCALIZED_LABEL = "localized-v1 (MCL) + blazing-trail-v1"
PARTICLES_SWEEP = "beyond-localized-particles"
#: quick mode (CI): MCL samples per localized robot (full: the scenario's 500), the filter's cost
#: being most of a localized run's
QUICK_PARTICLES = 100


def particle_count(row: dict) -> int | None:
    """Samples per robot of a ``beyond-localized-particles`` row (its case ``p<n>``), or None."""
    label = (row.get("params") or {}).get("case", row.get("case"))
    if isinstance(label, str) and label.startswith("p") and label[1:].isdigit():
        return int(label[1:])
    return None


def cheapest_without_breakdown(rows: list[dict]) -> int | None:
    """The smallest particle count none of whose runs broke down (every run still delivering in
    its last 10 min: ``breakdown_censored`` = 1), or None when every count has a breakdown."""
    by: dict[int, list[dict]] = {}
    for r in rows:
        n = particle_count(r)
        if n is not None:
            by.setdefault(n, []).append(r)
    for n in sorted(by):
        cens = T.values(by[n], "breakdown_censored")
        if cens.size and bool((cens == 1).all()):
            return n
    return None


def _settings(quick: bool) -> tuple[list[int], float, list[float]]:
    """(seeds, duration [s], drift scales) of the claim, quick or full."""
    from teamnav.experiments.claims import _parse_seeds, load_claims

    claim = load_claims("beyond")["localized-trails-drift"]
    seeds = _parse_seeds(claim.quick_seeds) if quick and claim.quick_seeds else claim.seed_list
    return seeds, (300.0 if quick else 3600.0), ([0.0, 4.0] if quick else [0.0, 1.0, 4.0])


def _units_per_hour(rows: list[dict], dur: float) -> np.ndarray:
    return T.values(rows, "units_total") * (3600.0 / dur)


def _cpu_per_sim_hour(rows: list[dict], dur: float) -> np.ndarray:
    """CPU seconds of the stepping loop per simulated hour (``wall_time_s``: one thread per worker)."""
    return T.values(rows, "wall_time_s") * (3600.0 / dur)


def _broke(rows: list[dict]) -> str:
    cens = T.values(rows, "breakdown_censored")
    return f"{int((cens == 0).sum())} of {cens.size}" if cens.size else "n/a"


def paired_gain_text(ours: list[dict], theirs: list[dict], dur: float) -> str:
    """The per-seed difference in units per hour, ours minus theirs, on the seeds both ran:
    ``"+0.9 ± 0.8 units/h (s.e., 10 paired seeds): no difference beyond the seeds' spread"``."""
    a = {r.get("seed"): r for r in ours}
    b = {r.get("seed"): r for r in theirs}
    common = sorted(k for k in set(a) & set(b) if k is not None)
    d = np.array([(float(a[k].get("units_total", np.nan)) - float(b[k].get("units_total", np.nan))) * 3600.0 / dur
                  for k in common])
    d = d[np.isfinite(d)]
    if d.size < 2:
        return "too few paired seeds to compare"
    se = float(d.std(ddof=1) / np.sqrt(d.size))
    m = float(d.mean())
    verdict = ("no difference beyond the seeds' spread: localization does not help there (odometry is exact), "
               "and it costs the CPU in the table") if abs(m) <= 2.0 * se else (
        "the localized team delivers more" if m > 0 else "the localized team delivers less")
    return f"{m:+.1f} ± {se:.1f} units/h against the odometric team (s.e., {d.size} paired seeds): {verdict}"


def localized_values(loc: dict[float, list[dict]], odo: dict[float, list[dict]], dur: float) -> dict[str, float]:
    """The claim's metrics: mean units per hour at k = 0 and k = 4 of the localized team, and at
    k = 4 of the odometric blazing team (NaN where a case was not run)."""
    def m(rows):
        u = _units_per_hour(rows or [], dur)
        return float(u.mean()) if u.size else float("nan")

    return {"units_k0_localized_mean": m(loc.get(0.0)), "units_k4_localized_mean": m(loc.get(4.0)),
            "units_k4_odometry_mean": m(odo.get(4.0))}


def _localized_trails(ctx) -> list:
    from teamnav.experiments.claims import history_text, judge, load_claims, rule_text

    quick = bool(ctx.quick)
    seeds, dur, scales = _settings(quick)
    missing = T.brains_missing(["localized-v1", "blazing-trail-v1", "trail-share-v1"])
    if missing is not None:
        return [missing]
    quick_set = {f"robots.{i}.params.particles": QUICK_PARTICLES for i in range(4)} if quick else {}
    loc = T.by_scale(T.ok(ctx.sweep(T.drift_spec(LOCALIZED_SWEEP, scales), seeds=seeds, duration_s=dur,
                                    **({"set": quick_set} if quick else {}))))
    parts = {label: T.by_scale(T.ok(ctx.sweep(T.drift_spec(name, scales), seeds=seeds, duration_s=dur)))
             for label, name in PARTS}
    blocks: list = [Text(
        f"Combination 1, localized trails: {LOCALIZED_LABEL} against its parts, the 2000 and 2002 trail "
        f"algorithms on odometry, on the 2002 office with the 2002 team's drift pattern k x ({T.DRIFT_TEXT}), "
        f"k = {', '.join(f'{k:g}' for k in scales)}, seeds {seeds[0]}-{seeds[-1]}, {dur / 60:g} min per run. "
        "The localized robots are given the map; their filter reads only their own laser and odometry."
        + (f" Quick mode: {QUICK_PARTICLES} samples per localized robot (full: 500)." if quick else ""))]
    rows = []
    for k in scales:
        for label, data in ((LOCALIZED_LABEL, loc), *((lab, parts[lab]) for lab, _ in PARTS)):
            r = data.get(k, [])
            err = T.values(r, "loc_mean_error_m")
            rows.append([f"{k:g}", label, T.msd(_units_per_hour(r, dur), "{:.1f}"), _broke(r),
                         T.msd(err, "{:.2f}", "m") if err.size else "—", T.msd(_cpu_per_sim_hour(r, dur), "{:.0f}", "s")])
    blocks.append(Table(
        "Units per hour, breakdowns, pose error and cost, by drift scale k",
        ["k", "team", "units per hour", "broke down (no unit in the last 10 min)", "MCL pose error (mean over run)",
         "stepping s per simulated hour"],
        rows,
        note="mean ± std over runs (n = runs); cost: the stepping loop's wall time per simulated hour in one worker "
             "(one numba thread), which a loaded machine inflates: compare the rows of one run, not runs."))
    claim = load_claims("beyond")["localized-trails-drift"]
    vals = localized_values(loc, parts[PARTS[0][0]], dur)
    holds, how = judge(claim, vals, dur)
    if not quick:
        blocks += _particles(ctx, seeds, dur, parts[PARTS[0][0]].get(4.0, []))
    where = "Without drift (k = 0): " + paired_gain_text(loc.get(0.0, []), parts[PARTS[0][0]].get(0.0, []), dur) + "."
    blocks.append(Comparison(
        f"{claim.title} ({rule_text(claim)})",
        f"{claim.paper_number} ({claim.statement.section}: \u201c{claim.statement.quote}\u201d)",
        how,
        holds,
        where + " History of the rule: " + history_text(claim)))
    return blocks


def _particles(ctx, seeds: list[int], dur: float, odometric_k4: list[dict]) -> list:
    """Full mode: the localized team at k = 4 with 25 .. 500 samples per robot, beside how many
    runs of the odometric team broke down at k = 4 (``odometric_k4``: its rows)."""
    rows = T.ok(ctx.sweep(PARTICLES_SWEEP, seeds=seeds, duration_s=dur))
    by: dict[int, list[dict]] = {}
    for r in rows:
        n = particle_count(r)
        if n is not None:
            by.setdefault(n, []).append(r)
    table = [[str(n), T.msd(_units_per_hour(by[n], dur), "{:.1f}"), _broke(by[n]),
              T.msd(T.values(by[n], "loc_mean_error_m"), "{:.2f}", "m"), T.msd(_cpu_per_sim_hour(by[n], dur), "{:.0f}", "s")]
             for n in sorted(by)]
    cheapest = cheapest_without_breakdown(rows)
    return [Table(
        "The cheapest particle count that removes the breakdown (k = 4)",
        ["samples per robot", "units per hour", "broke down", "MCL pose error", "stepping s per simulated hour"], table,
        note=("cheapest count with no breakdown in any run: "
              + (f"{cheapest}" if cheapest is not None else "none of those tried")
              + f" (the odometric blazing team at k = 4: {_broke(odometric_k4)} broke down, "
              + f"{T.msd(_units_per_hour(odometric_k4, dur), '{:.1f}')} units per hour)"
              + f"; sweep {PARTICLES_SWEEP}, seeds {seeds[0]}-{seeds[-1]}, {dur / 60:g} min per run"))]


# ---------------------------------------------------------------------------- a moving resource
MOVING_SWEEP = "beyond-moving-resource"
#: quick mode: the static source and the fastest glide (5-min runs: a jump every 5 min would not show)
MOVING_QUICK_CASES = ("static", "glide-0.05")
#: the 2000 algorithm under the same motion, with and without crumb expiry (full mode only)
MOVING_BLAZING_SWEEP = "beyond-moving-resource-blazing"


def motion_speed_mps(start_xy: tuple[float, float], motion: dict | None) -> float:
    """Mean speed [m/s] of a place moving per ``motion`` (a ``PlaceMotion`` dict) from ``start_xy``:
    the distance of one cycle (start, waypoints, and back to the start when periodic) over its
    duration; 0 for a static place. Jumps count the distance jumped, so a jump every T between two
    spots d apart is d / T, comparable with a glide at that speed."""
    if not motion:
        return 0.0
    from teamnav.sim.config import PlaceMotion

    m = PlaceMotion.model_validate(motion)
    pts = [start_xy] + [(w.x_m, w.y_m) for w in m.path]
    if m.period_s is not None:
        pts.append(start_xy)
    dist = sum(float(np.hypot(b[0] - a[0], b[1] - a[1])) for a, b in zip(pts, pts[1:]))
    span = m.period_s if m.period_s is not None else m.path[-1].t_s
    return dist / span


def _moving_resource(ctx) -> list:
    """The papers' future work: a moving resource (Vaughan et al. 2000 §6; the motion is ours).

    trail-share-v1 (the 2002 algorithm: Places updated on task events, crumbs expire after 4 min,
    Try §3) forages while the source stays, jumps or glides between two spots of C3; units per hour
    against the source's mean speed. No claim (the papers give no number): the curve, no verdict."""
    from teamnav.experiments.spec import load_scenario
    from teamnav.experiments.sweep import load_sweep

    quick = bool(ctx.quick)
    missing = T.brains_missing(["trail-share-v1"])
    if missing is not None:
        return [missing]
    spec = load_sweep(MOVING_SWEEP)
    labels = list(MOVING_QUICK_CASES) if quick else [str(c.get("case")) for c in spec.cases]
    seeds, dur = ([0], 300.0) if quick else (list(range(10)), 3600.0)
    src = next(p for p in load_scenario(spec.scenario).places if p.event == "took_resource")
    cases = {str(c.get("case")): c for c in spec.cases}
    speed = {lab: motion_speed_mps((src.x_m, src.y_m), cases[lab].get("places.1.motion")) for lab in labels}
    data = T.by_case(T.ok(ctx.sweep(T.case_spec(MOVING_SWEEP, labels), seeds=seeds, duration_s=dur)))
    rows, curves = [], {"jump": [], "glide": []}
    for lab in labels:
        r = data.get(lab, [])
        u = _units_per_hour(r, dur)
        kind = lab.split("-")[0]
        rows.append([lab, f"{speed[lab]:.4f}", T.msd(u, "{:.1f}"), _broke(r), T.msd(T.values(r, "trip_time_s_after_mean"), "{:.0f}", "s")])
        for k in (("jump", "glide") if kind == "static" else (kind,)):
            if k in curves and u.size:
                curves[k].append((speed[lab], float(u.mean()), float(np.percentile(u, 25)), float(np.percentile(u, 75))))
    series = []
    for k, pts in curves.items():
        if len(pts) > 1:
            pts.sort()
            series.append(Series(f"source {'jumps' if k == 'jump' else 'glides'} (static at 0)", [p[0] for p in pts],
                                 [p[1] for p in pts], [p[2] for p in pts], [p[3] for p in pts], style="line+points"))
    far = next(c["places.1.motion"]["path"][0] for c in spec.cases if c.get("places.1.motion"))
    d = float(np.hypot(far["x_m"] - src.x_m, far["y_m"] - src.y_m))
    blocks: list = [Text(
        f"The papers' future work, a moving resource (Vaughan et al. 2000 §6; the motion is ours): trail-share-v1 "
        f"(scenario {spec.scenario}: try-to-see-it-my-way's four robots and drift) while the source moves along the "
        f"north corridor between x {src.x_m:g} m and a spot {d:.0f} m east of it, the same route length from home "
        "either side of corner 2. It jumps there and back every T, or glides there and back at v; its mean speed is "
        "the distance it covers per cycle over the cycle. A jumping source keeps the route length; a gliding one "
        "passes corner 2 on its way, where the route from home is 9.5 m shorter, so glides mix speed with distance. Seeds {seeds[0]}-{seeds[-1]}, {dur / 60:g} min per run"
        + (" (quick mode: two cases, one seed; the pipeline works, the numbers are not the result)." if quick else "."))]
    blocks.append(Table(
        "Units per hour against the source's speed",
        ["case", "source mean speed [m/s]", "units per hour", "broke down (no unit in the last 10 min)",
         "trip time after the first trail"],
        rows, note=f"mean ± std over runs (n = runs); sweep {MOVING_SWEEP}."))
    if series:
        blocks.append(Plot("Delivery rate against resource speed", "source mean speed [m/s]", "units per hour", series,
                           caption="mean over seeds, band 25-75 %; no paper number to compare (no verdict)."))
    if not quick:
        blocks += _moving_blazing(ctx, seeds, dur, speed)
    return blocks


def _moving_blazing(ctx, seeds: list[int], dur: float, speed: dict[str, float]) -> list:
    """Full mode: blazing-trail-v1 with the moving source, its never-expiring global crumb list (the
    2000 paper) beside ``global_crumb_ttl_s`` = 300 s (beyond the paper)."""
    missing = T.brains_missing(["blazing-trail-v1"])
    if missing is not None:
        return [missing]
    data = T.by_case(T.ok(ctx.sweep(MOVING_BLAZING_SWEEP, seeds=seeds, duration_s=dur)))
    rows = []
    for lab in sorted(data, key=lambda c: (speed.get(c.removesuffix("-ttl300"), 0.0), c)):
        base = lab.removesuffix("-ttl300")
        r = data[lab]
        rows.append([base, f"{speed[base]:.4f}" if base in speed else "?",
                     "300 s after added" if lab.endswith("-ttl300") else "never (the paper)",
                     T.msd(_units_per_hour(r, dur), "{:.1f}"), _broke(r), T.msd(T.values(r, "crumbs_max"), "{:.0f}")])
    return [Table(
        "The 2000 algorithm with a moving source: global crumbs that never expire, and that expire",
        ["case", "source mean speed [m/s]", "global crumbs expire", "units per hour", "broke down", "global crumbs (max)"],
        rows, note=f"mean ± std over runs (n = runs); sweep {MOVING_BLAZING_SWEEP}, seeds {seeds[0]}-{seeds[-1]}, "
                   f"{dur / 60:g} min per run; global_crumb_ttl_s is beyond the paper (blazing_trail's docstring).")]


def build(ctx) -> list:
    """The section's blocks: the four combinations and the papers' future work."""
    blocks: list = [Text(
        "Each paper gives its robots one kind of help; here a team gets two, measured against the systems it is "
        "built from. Every combination is a registered brain composing the papers' rules (no copies); its module "
        "docstring says which. Where a combination does not help, its block says so.")]
    blocks += _localized_trails(ctx)
    blocks += _moving_resource(ctx)
    blocks += _mail_round(ctx)  # N places, a mail round (Try §2.1, §4): _beyond_mail_round.py
    from teamnav.papers.beyond.report._radio_beyond import restricted_radio

    blocks += restricted_radio(ctx)
    from teamnav.papers.beyond.report._beyond_detecting_trails import detecting_trails
    from teamnav.papers.beyond.report._beyond_localized_los import localized_los
    from teamnav.papers.beyond.report._beyond_negative_detections import negative_detections

    blocks += localized_los(ctx)  # combination 2: _beyond_localized_los.py
    blocks += detecting_trails(ctx)  # combination 3, detections help the trail team: _beyond_detecting_trails.py
    blocks += _trail_memory(ctx)  # combination 4, trails as LOS memory: _beyond_trail_memory.py
    blocks += negative_detections(ctx)  # Fox §7.2: negative sights, anonymous robots
    return blocks


SECTION = SectionSpec(
    key="beyond",
    title="Beyond the papers: the systems combined",
    paper=PAPER,
    build=build,
    summary="The four systems combined, each beside its parts, and the papers' future work.",
    order=95,
    tags=("trails", "localization", "beyond"),
)
