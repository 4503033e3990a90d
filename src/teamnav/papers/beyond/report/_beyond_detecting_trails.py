"""The ``beyond`` section's block for combination 3: detections help the trail team.

The brain is ``detecting-trails-v1`` (:mod:`teamnav.papers.beyond.brains.detecting`) over
``blazing-trail-v1``: the 2000 paper's crumbs and trail following (Blazing §4.1) laid and followed
on a map-less sample belief (prediction only, each sample with its own heading drift rate) that
collaborative MCL's belief sync corrects whenever one robot detects another (Fox et al. §2.3,
§3.2, eqs. 13-14; the detection model learned in §4.2; Fox et al.'s camera detector on every
robot). No map. Scenario and sweep ``beyond-detecting-trails``: its cases ``x<k>`` (sync on) and
``x<k>-nosync`` (the same belief, no detections used), drift k = 0, 1, 4 x (Bug -1, Ant +1,
Fly +2, Tanis +0.35 deg/min); its part, the odometric team (``blazing-trail-v1`` on odometry), is
sweep ``blazing-drift``'s cases of the same labels, paired by case and seed.

Shown per k: units per hour, runs that broke down (no unit in the last 10 min), the pose error
(``localization`` metric: mean distance of the logged samples to the true position; the
odometric team logs none), trees applied per robot per hour, and the stepping loop's seconds
per simulated hour; then the paired differences (detecting minus odometric, detecting minus
no-sync) and the verdict of ``claims/beyond.yaml``'s ``detecting-trails-drift``.

What it cannot do, said in the block: a detection measures where a teammate is *relative to*
the observer, so the sync shrinks the spread of the team's errors, not their mean: the drift
the team shares (+0.59 k deg/min in this pattern) stays in every belief.

Quick mode (CI): k = 4, seed 0, 5 min: one run of the detecting team beside the odometric one
(the trail sections' quick drift run); the pipeline works, no verdict. Full mode: the claim's
seeds and length (``claims/beyond.yaml``) for x0, x1, x4 and x4-nosync, and blazing-drift's
x0, x1, x4.
"""

from __future__ import annotations

import numpy as np

from teamnav.experiments.report.model import Comparison, Table, Text
from teamnav.papers.trails.report import _trails as T

__all__ = ["CLAIM", "DETECTING_SWEEP", "ODOMETRY_SWEEP", "claim_values", "detecting_trails", "paired"]

DETECTING_SWEEP = "beyond-detecting-trails"
ODOMETRY_SWEEP = "blazing-drift"
CLAIM = "detecting-trails-drift"
QUICK_DURATION_S = 300.0
LABELS = {"sync": "detecting-trails-v1 (belief + sync) + blazing-trail-v1",
          "nosync": "the same belief, no sync (prediction only)",
          "odometry": "blazing-trail-v1, odometry"}


def _units(rows: list[dict], dur: float) -> np.ndarray:
    return T.values(rows, "units_total") * (3600.0 / dur)


def paired(ours: list[dict], theirs: list[dict], dur: float) -> tuple[float, float, int]:
    """Mean and standard error of the per-seed difference in units per hour, ours minus theirs, over
    the seeds both ran: ``(mean, s.e., n)``; NaNs when fewer than two seeds pair.

    Examples
    --------
    >>> a = [{"seed": s, "units_total": 10 + s} for s in range(4)]
    >>> b = [{"seed": s, "units_total": 8} for s in range(3)]
    >>> paired(a, b, 3600.0)
    (3.0, 0.5773502691896258, 3)
    """
    a = {r.get("seed"): r.get("units_total") for r in ours}
    b = {r.get("seed"): r.get("units_total") for r in theirs}
    d = np.array([(float(a[k]) - float(b[k])) * 3600.0 / dur for k in sorted(set(a) & set(b), key=str)
                  if k is not None and isinstance(a[k], (int, float)) and isinstance(b[k], (int, float))])
    if d.size < 2:
        return float("nan"), float("nan"), int(d.size)
    return float(d.mean()), float(d.std(ddof=1) / np.sqrt(d.size)), int(d.size)


def _paired_text(ours: list[dict], theirs: list[dict], dur: float) -> str:
    m, se, n = paired(ours, theirs, dur)
    if n < 2:
        return "too few paired seeds"
    how = "no difference beyond the seeds' spread" if abs(m) <= 2.0 * se else ("more" if m > 0 else "fewer")
    return f"{m:+.1f} ± {se:.1f} units/h (s.e., {n} seeds): {how}"


def claim_values(sync: dict[float, list[dict]], nosync: dict[float, list[dict]], odo: dict[float, list[dict]],
                 dur: float) -> dict[str, float]:
    """The claim's metrics at k = 4: mean units per hour of the three teams, and the paired gain of the
    detecting team over the odometric one (mean, s.e.). NaN where a case was not run."""
    def mean(rows):
        u = _units(rows or [], dur)
        return float(u.mean()) if u.size else float("nan")

    gain, se, _ = paired(sync.get(4.0, []), odo.get(4.0, []), dur)
    return {"units_k4_detecting_mean": mean(sync.get(4.0)), "units_k4_nosync_mean": mean(nosync.get(4.0)),
            "units_k4_odometry_mean": mean(odo.get(4.0)), "units_k4_gain_mean": gain, "units_k4_gain_se": se}


def _by_k(rows: list[dict], suffix: str) -> dict[float, list[dict]]:
    out: dict[float, list[dict]] = {}
    for lab, group in T.by_case(rows).items():
        if lab.startswith("x") and lab.endswith(suffix):
            try:
                out[float(lab[1:len(lab) - len(suffix)])] = group
            except ValueError:
                continue
    return dict(sorted(out.items()))


def detecting_trails(ctx) -> list:
    """The block: the table by k, the paired differences, the verdict, and what the sync cannot do."""
    from teamnav.experiments.claims import history_text, judge, load_claims, rule_text

    missing = T.brains_missing(["detecting-trails-v1", "blazing-trail-v1"])
    if missing is not None:
        return [missing]
    quick = bool(ctx.quick)
    claim = load_claims("beyond")[CLAIM]
    if quick:
        seeds, dur, scales, labels = [0], QUICK_DURATION_S, [4.0], ["x4"]
    else:
        seeds, dur, scales = claim.seed_list, float(claim.min_duration_s), [0.0, 1.0, 4.0]
        labels = ["x0", "x1", "x4", "x4-nosync"]
    rows = T.ok(ctx.sweep(T.case_spec(DETECTING_SWEEP, labels), seeds=seeds, duration_s=dur))
    odo = T.by_scale(T.ok(ctx.sweep(T.drift_spec(ODOMETRY_SWEEP, scales), seeds=seeds, duration_s=dur)))
    sync, nosync = _by_k(rows, ""), _by_k(rows, "-nosync")
    blocks: list = [Text(
        f"Combination 3, detections help the trail team: {LABELS['sync']}, without a map. Each robot's pose is a "
        "sample belief moved by odometry alone (each sample with its own heading drift rate); when a robot's camera "
        "detects a teammate (Fox et al.'s detector: 60°, 6 m, 0.48 m / 2.2° noise), collaborative MCL's belief sync "
        "sends the teammate the density tree of its position (eq. 13), which it multiplies into its belief (eq. 14) "
        "and answers in kind (§2.3). Beside it: the same belief without the sync, and the odometric team "
        f"(sweep {ODOMETRY_SWEEP}), on the 2002 office with the 2002 drift pattern k x ({T.DRIFT_TEXT}), "
        + (f"seeds {seeds[0]}-{seeds[-1]}" if len(seeds) > 1 else f"seed {seeds[0]}") + f", {dur / 60:g} min per run"
        + (" (quick mode: one run each; the pipeline works, the numbers are not the result)." if quick else "."))]
    table = []
    for k in scales:
        for key, data in (("sync", sync), ("nosync", nosync), ("odometry", odo)):
            r = data.get(k, [])
            if not r:
                continue
            err = T.values(r, "loc_mean_error_m")
            trees = T.values(r, "loc_syncs") * (3600.0 / dur) / 4.0
            table.append([f"{k:g}", LABELS[key], T.msd(_units(r, dur), "{:.1f}"), _broke(r),
                          T.msd(err, "{:.2f}", "m") if err.size else "—",
                          T.msd(trees, "{:.0f}") if key == "sync" and trees.size else "—",
                          T.msd(T.values(r, "wall_time_s") * (3600.0 / dur), "{:.0f}", "s")])
    diffs = "; ".join(f"k = {k:g}: detecting − odometric {_paired_text(sync.get(k, []), odo.get(k, []), dur)}"
                      + (f", detecting − no sync {_paired_text(sync[k], nosync[k], dur)}" if k in nosync else "")
                      for k in scales if k in sync)
    blocks.append(Table(
        "Detections for the trail team: units per hour, breakdowns, pose error and cost, by drift scale k",
        ["k", "team", "units per hour", "broke down (no unit in the last 10 min)", "pose error (mean over run)",
         "trees applied per robot per hour", "stepping s per simulated hour"],
        table,
        note="mean ± std over runs (n = runs). Pose error: mean distance of the belief's logged samples to the true "
             "position (it counts the belief's spread, not only its mean's error). Paired differences in units per hour, "
             "per seed: " + (diffs or "none") + ". Cost: the stepping loop's wall time in one worker, which a loaded "
             "machine inflates: compare rows of one run."))
    values = claim_values(sync, nosync, odo, dur)
    holds, how = judge(claim, values, None if quick else dur)
    if quick:
        holds, how = None, "not judged in quick mode (one 5-min run)"
    blocks.append(Comparison(
        f"{claim.title} ({rule_text(claim)})",
        f"{claim.paper_number} ({claim.statement.section}: \u201c{claim.statement.quote}\u201d)",
        how, holds,
        "Where it cannot help: a detection says where a teammate is relative to the observer, so the sync pulls the "
        "robots' beliefs together but cannot remove a drift they share (the mean of the team's rates, +0.59 k deg/min "
        "here): every belief keeps it, and the team's trails rotate with it. History of the rule: " + history_text(claim)))
    return blocks


def _broke(rows: list[dict]) -> str:
    cens = T.values(rows, "breakdown_censored")
    return f"{int((cens == 0).sum())} of {cens.size}" if cens.size else "n/a"
