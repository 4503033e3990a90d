"""The ``beyond`` section's block on Fox et al.'s own future work: negative sights and anonymous robots.

Fox, Burgard, Kruppa & Thrun (2000) §7.2 lists, among the limitations of collaborative MCL:

- *Not seeing each other*: "only 'positive' detections are processed. Not seeing another robot is
  also informative ... However, such an extension would drastically increase the computational
  overhead, and it is unclear as to whether the effects on the localization accuracy justify the
  additional computation and communication." ``mcl-wander-v1``'s ``negative_detections``
  (:mod:`teamnav.papers.collab_mcl.brains.negative_sights`, the likelihood
  :mod:`teamnav.localization.negative_detection`) is that extension; sweeps
  ``beyond-negative-detections-hallway`` (8 sonar robots, symmetric hallway, §5.2.1) and
  ``-hexagon`` (4 sonar + 4 laser robots, §5.2.2), negative sights off (the paper: §2.3 rule 1)
  and on, seeds 0-9, 300 s.
- *Identification of robots*: the factorial representation "cannot deal with measurements such as
  'either robot A or robot B'". The brain's ``anonymous: associate`` (association by belief: the
  observer broadcasts its detection tree, each robot answers with its density under its belief, a
  clear winner gets the tree) against ``ignore`` (the paper's method), with identities withheld by
  the detector, in the 8-robot hallway (sweep ``beyond-anonymous-hallway``, beside the hallway
  with identities: case ``off`` of the negative-sight sweep; the ``collab-mcl``
  section's rows compare the same two on the two robots of §5.1, where the association is easy).

Metrics (the ``localization`` metric set): the time to localize (mean over the robots of the
first time the sample error falls below 1.5 m, §5.2.1; a robot that never does counts the run's
300 s), robots never localized, robots localized at the end, the bytes each robot sent per second
and the stepping loop's time per run (``wall_time_s``: one thread per sweep worker). Paired
differences per seed (the same seed gives the same start poses and, the wanderer reading only
scans, the same paths), mean ± standard error.

Claims (``claims/beyond.yaml``, written before the report-seed runs): ``negdet-hallway``,
``negdet-hexagon``: with negative sights the mean time to localize is at most 0.9 x the one
without and the paired difference is below -2 standard errors (``ttl_paired_z``);
``anon-assoc-hallway``: the same two conditions for associate against ignore.

Quick mode (CI): the hallway, negative sights off and on, seed 0, 60 s (two short runs): the
pipeline works, no verdict. Full mode: the three sweeps, seeds 0-9, 300 s (60 runs; the reference
with identities reported is the hallway sweep's case ``off``, the same configuration).
"""

from __future__ import annotations

import numpy as np

from teamnav.experiments.report.model import Comparison, Missing, Table, Text
from teamnav.papers.trails.report import _trails as T

__all__ = ["ANON_SWEEP", "NEG_SWEEPS", "claim_values", "negative_detections", "paired"]

#: (label, sweep, claim) of the negative-sight comparisons
NEG_SWEEPS = (("hallway (8 sonar robots)", "beyond-negative-detections-hallway", "negdet-hallway"),
              ("hexagon (4 sonar + 4 laser robots)", "beyond-negative-detections-hexagon", "negdet-hexagon"))
ANON_SWEEP = "beyond-anonymous-hallway"
ANON_CLAIM = "anon-assoc-hallway"
TTL = "loc_time_to_localize_s"
QUICK_S = 60.0
FULL_S = 300.0


def per_seed(rows: list[dict], key: str = TTL) -> dict[int, float]:
    """Seed -> the metric of each finished row that has it."""
    out: dict[int, float] = {}
    for r in rows:
        v = T.values([r], key)
        if v.size and r.get("seed") is not None:
            out[int(r["seed"])] = float(v[0])
    return out


def paired(base: dict[int, float], new: dict[int, float]) -> tuple[float, float, int, int]:
    """``(mean, s.e., n, n_lower)`` of ``new - base`` over the seeds both have (NaN when n < 2).

    >>> [round(v, 3) for v in paired({0: 10.0, 1: 20.0, 2: 30.0}, {0: 8.0, 1: 19.0, 2: 27.0})]
    [-2.0, 0.577, 3, 3]
    """
    common = sorted(set(base) & set(new))
    d = np.array([new[s] - base[s] for s in common], dtype=float)
    if d.size < 2:
        return float("nan"), float("nan"), int(d.size), int((d < 0).sum())
    return float(d.mean()), float(d.std(ddof=1) / np.sqrt(d.size)), int(d.size), int((d < 0).sum())


def claim_values(base: dict[int, float], new: dict[int, float], names=("off", "on")) -> dict[str, float]:
    """The claims' metrics: ``ttl_<base>_mean``, ``ttl_<new>_mean`` and ``ttl_paired_z`` (the paired
    mean difference new - base over its standard error; -1e9 / 1e9 when every seed moved by the same
    amount, 0 when none moved).

    >>> claim_values({0: 100.0, 1: 110.0}, {0: 80.0, 1: 92.0})["ttl_paired_z"]
    -19.0
    """
    m, se, n, _ = paired(base, new)
    z = float("nan") if n < 2 else (m / se if se > 0 else float(np.sign(m)) * 1e9)
    mean = (lambda d: float(np.mean(list(d.values()))) if d else float("nan"))
    return {f"ttl_{names[0]}_mean": mean(base), f"ttl_{names[1]}_mean": mean(new), "ttl_paired_z": z}


def _row(label: str, case: str, rows: list[dict], dur: float) -> list:
    ttl = T.values(rows, TTL)
    bps = T.values(rows, "bytes_sent") / (8.0 * dur)  # 8 robots in every scenario here
    return [label, case, len(rows), T.msd(ttl, "{:.0f}"), T.msd(T.values(rows, "loc_censored"), "{:.1f}"),
            T.msd(100.0 * T.values(rows, "loc_final_localized_fraction"), "{:.0f}", "%"), T.msd(bps, "{:.0f}"),
            T.msd(T.values(rows, "wall_time_s"), "{:.1f}")]


def _diff_text(base: dict[int, float], new: dict[int, float]) -> str:
    m, se, n, lower = paired(base, new)
    if n < 2:
        return "too few paired seeds"
    return f"{m:+.0f} ± {se:.0f} s (s.e., {n} paired seeds, {lower} lower)"


def _verdict(claims, cid: str, vals: dict[str, float], quick: bool) -> tuple[bool | None, str]:
    from teamnav.experiments.claims import judge, rule_text

    c = claims[cid]
    if quick:
        return None, f" Rule (claims/beyond.yaml, {cid}): {rule_text(c)}; not judged in quick mode."
    h, how = judge(c, vals)
    return h, f" Rule (claims/beyond.yaml, {cid}): {rule_text(c)}; {how}. Seeds {c.seeds}."


def negative_detections(ctx) -> list:
    """Tables of both comparisons, with paired differences, and the three verdicts."""
    from teamnav.experiments.claims import load_claims

    quick = bool(ctx.quick)
    claims = load_claims("beyond")
    dur = QUICK_S if quick else FULL_S
    seeds = [0] if quick else claims["negdet-hallway"].seed_list
    blocks: list = [Text(
        "The papers' own future work (Fox et al. §7.2): negative sights (\u201cNot seeing another robot is also "
        "informative ... it is unclear as to whether the effects on the localization accuracy justify the additional "
        "computation and communication\u201d) and detections without identity. Negative sights: a robot whose belief "
        "spread is within 1 m broadcasts 24 of its samples before each camera frame; an observer that is itself unsure "
        "and does not detect that robot weighs each of its samples by 1 - (1 - p_fn)(1 - 0.1) P_vis, P_vis the share "
        "of the teammate's points within the detector's 5 m and 180 deg and in line of sight on the map (one use per "
        "teammate per 2.5 m of travel, as §2.3 rule 2). "
        + (f"Quick mode: the hallway only, seed 0, {dur:g} s (the pipeline works; no verdict)." if quick else
           f"Seeds {seeds[0]}-{seeds[-1]}, {dur:g} s per run."))]
    table, comps = [], []
    cases = [NEG_SWEEPS[0]] if quick else list(NEG_SWEEPS)
    hall_off: list[dict] = []  # the scenario as it is: the anonymous comparison's reference
    for label, sweep, cid in cases:
        data = T.by_case(T.ok(ctx.sweep(T.case_spec(sweep, ("off", "on")), seeds=seeds, duration_s=dur)))
        off, on = data.get("off", []), data.get("on", [])
        hall_off = hall_off or off
        table.append(_row(label, "off (the paper, §2.3 rule 1)", off, dur))
        table.append(_row(label, "on (negative sights)", on, dur))
        a, b = per_seed(off), per_seed(on)
        table.append([label, "on - off, paired", "", _diff_text(a, b), "", "", "", ""])
        h, why = _verdict(claims, cid, claim_values(a, b), quick)
        vo, vn = np.array(list(a.values())), np.array(list(b.values()))
        comps.append(Comparison(f"§7.2, beyond the paper: negative sights shorten global localization ({label})",
                                "future work, not measured (\u201cunclear ... whether the effects ... justify\u201d it)",
                                f"time to localize {T.msd(vn, '{:.0f}')} s with, {T.msd(vo, '{:.0f}')} s without; "
                                f"paired {_diff_text(a, b)}", h,
                                "Negative sights only reweight samples that could have seen a teammate; a teammate's "
                                "confidently wrong belief (on a rotated copy of its place, as in the hexagon's seed 8) makes them evidence against "
                                "the right place." + why))
    blocks.append(Table("Negative sights (Fox et al. §7.2): time to localize with and without",
                        ["setting", "negative sights", "runs", "time to localize [s]", "robots never localized",
                         "localized at the end", "bytes sent per robot per s", "stepping time per run [s]"],
                        table, note="mean ± std over runs; a robot never localized counts the run's length. Paired: "
                                    "per seed (same starts and paths), mean ± s.e. Stepping time: the sweep worker's "
                                    "wall time of the stepping loop (one thread), on a shared machine."))
    blocks += comps
    if quick:
        blocks.append(Missing("anonymous robots with data association in the 8-robot hallway",
                              "measured in the full report only (2 cases x 10 seeds x 300 s)"))
        return blocks
    data = T.by_case(T.ok(ctx.sweep(ANON_SWEEP, seeds=seeds, duration_s=dur)))
    lab = "hallway (8 sonar robots)"
    rows = [_row(lab, "identities reported (reference; = negative sights off)", hall_off, dur),
            _row(lab, "withheld, ignored (the paper)", data.get("anon-ignore", []), dur),
            _row(lab, "withheld, associated by belief", data.get("anon-associate", []), dur)]
    ign, asc, ide = per_seed(data.get("anon-ignore", [])), per_seed(data.get("anon-associate", [])), per_seed(hall_off)
    rows.append([lab, "associated - ignored, paired", "", _diff_text(ign, asc), "", "", "", ""])
    rows.append([lab, "associated - identities, paired", "", _diff_text(ide, asc), "", "", "", ""])
    blocks.append(Table("Detections without identity (Fox et al. §7.2) in the 8-robot hallway",
                        ["setting", "identity", "runs", "time to localize [s]", "robots never localized",
                         "localized at the end", "bytes sent per robot per s", "stepping time per run [s]"],
                        rows, note=f"sweep {ANON_SWEEP}; mean ± std over runs; paired per seed, mean ± s.e. Wrong "
                                   "associations are not counted (the brain cannot know them and no metric reads "
                                   "them yet)."))
    h, why = _verdict(claims, ANON_CLAIM, claim_values(ign, asc, ("ignore", "assoc")), False)
    blocks.append(Comparison("§7.2, beyond the paper: anonymous detections associated by belief in a team of 8",
                             "the factorial method cannot use them",
                             f"time to localize {T.msd(np.array(list(asc.values())), '{:.0f}')} s associated, "
                             f"{T.msd(np.array(list(ign.values())), '{:.0f}')} s ignored; paired {_diff_text(ign, asc)}",
                             h, "A detection is used only when one robot's belief explains it 3 x better than any "
                                "other's; while the team is globally uncertain most are dropped." + why))
    return blocks
