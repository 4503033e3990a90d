"""Why does the paper-rules MCL collapse? One factor at a time, on tuning seeds.

Fox, Burgard, Kruppa & Thrun (2000) §5.1 / Fig. 10(a): when Marian sees Robin, Robin's belief is
"centered along the main axis of the corridor", "still highly uncertain about its exact location
within the corridor and even does not know its global heading direction"; eq. 14 then reweights it.
In teamnav's ``paper_rules: true`` column Robin's belief is instead 500 samples within
a few decimetres when the tree arrives. This script changes one filter setting at a time on top of
``paper_rules: true`` (:data:`FACTORS`) and measures, per run:

- ``detection`` (``collab-mcl-detection``, Robin's filter only; Marian is unchanged): Robin's
  sample count and spread (sqrt(var x + var y) of the weighted samples, the brain's ``spread_m``)
  at t = 5 s, 30 s and when Marian's tree arrives (the brain's ``det_belief`` record, Fig. 10's
  moment), the error then (mean distance of 64 logged samples to the truth, as the report's
  metric), and Robin's final error and time to < 1.5 m, ignoring (alone) or using (team) the
  detection;
- ``hallway`` (``collab-mcl-hallway``, every robot): the report's time to localize (mean over
  robots of the first time the error is < 1.5 m, censored at the duration) alone and together.

``--column teamnav`` runs the scenarios as they are (the report's teamnav column) with the
variants of :data:`TEAMNAV_CHECKS` instead: a re-check of the values chosen on report
seeds, on tuning seeds.

Seeds must be tuning seeds (>= 1000, never used by the report; ``claims/collab-mcl.yaml``).
Usage::

    nice -n 10 python scripts/collab_mcl_collapse.py detection --seeds 1000-1009 --workers 2
    nice -n 10 python scripts/collab_mcl_collapse.py hallway --seeds 1000-1003 --factors paper,sigma
    nice -n 10 python scripts/collab_mcl_collapse.py detection --column teamnav --seeds 1000-1019

Results (JSON lines, one per run) go to ``--out``; a table per factor is printed (mean ± std over
runs). What was measured with it: ``docs/report/collab-mcl.md`` ("Why the paper-rules filter
collapses").
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

#: Tuning seeds start here; the report's seeds are 0-29 (claims/collab-mcl.yaml).
TUNING_SEED_MIN = 1000

#: name -> (what changes, params merged into the robots' params on top of ``paper_rules: true``,
#: the paper's status of the changed setting). One factor each against ``paper``.
FACTORS: dict[str, tuple[str, dict, str]] = {
    "paper": ("paper_rules: true as the report runs it (KLD floor 500; Robin: 90 laser beams, sigma_hit 0.2 m; "
              "hallway: 16 sonar cones, 0.3 m; motion alpha (0.1, 0.05, 0.05, 0.05); exponent 1; resampling "
              "every update)", {}, "baseline"),
    "floor": ("KLD floor 500 -> 5000 samples", {"min_particles": 5000}, "unspecified (gap-fill)"),
    "fixed": ("fixed 10000 samples (no KLD adaptation)", {"adaptive": False}, "unspecified (gap-fill)"),
    "motion": ("motion noise x3: alpha (0.3, 0.15, 0.15, 0.15)", {"motion": {"alpha": [0.3, 0.15, 0.15, 0.15]}},
               "unspecified (gap-fill)"),
    "sigma": ("beam model sigma_hit 0.2 m (laser) or 0.3 m (sonar) -> 1.0 m", {"beam": {"sigma_hit_m": 1.0}}, "unspecified (gap-fill)"),
    "beams": ("every 10th beam (9 of 90 laser beams; 2 of 16 sonar cones)", {"beam_stride": 10},
              "unspecified (gap-fill)"),
    "sigma+beams": ("sigma_hit 1.0 m and every 10th beam (both unspecified values at once)",
                    {"beam": {"sigma_hit_m": 1.0}, "beam_stride": 10}, "unspecified (gap-fill)"),
    "sigma+beams+floor": ("sigma_hit 1.0 m, every 10th beam and a KLD floor of 5000",
                          {"beam": {"sigma_hit_m": 1.0}, "beam_stride": 10, "min_particles": 5000},
                          "unspecified (gap-fill)"),
    "sigma+floor": ("sigma_hit 1.0 m and a KLD floor of 5000 (every beam; for the 16-cone sonar)",
                    {"beam": {"sigma_hit_m": 1.0}, "min_particles": 5000}, "unspecified (gap-fill)"),
    "update": ("filter update every 1.0 m / 45 deg instead of 0.2 m / 15 deg",
               {"min_update_m": 1.0, "min_update_deg": 45.0}, "unspecified (gap-fill)"),
    "temper": ("likelihood exponent 1 -> 0.03 (teamnav's)", {"likelihood_exponent": 0.03}, "not the paper (eq. 12)"),
    "ess": ("resample only when ESS < 50 % (teamnav's)", {"resample_ess_fraction": 0.5}, "not the paper (§3.1)"),
}

#: the teamnav column's values chosen on report seeds, and their alternatives.
#: name -> (scenario, what it checks, params merged into the given robot groups' params)
TEAMNAV_CHECKS: dict[str, tuple[str, str, dict[int, dict]]] = {
    "detection": ("collab-mcl-detection", "§5.1 as the scenario is (lost prior 0.3)", {}),
    "detection-prior0.1": ("collab-mcl-detection", "§5.1, inject_lost_prior 0.1", {1: {"inject_lost_prior": 0.1}}),
    "detection-prior0.6": ("collab-mcl-detection", "§5.1, inject_lost_prior 0.6", {1: {"inject_lost_prior": 0.6}}),
    # 2026-11-29: the grid extended past 0.6, which the rule picked at the edge (FIDELITY §3)
    "detection-prior0.8": ("collab-mcl-detection", "§5.1, inject_lost_prior 0.8", {1: {"inject_lost_prior": 0.8}}),
    "detection-prior0.9": ("collab-mcl-detection", "§5.1, inject_lost_prior 0.9", {1: {"inject_lost_prior": 0.9}}),
    "detection-scanheading": ("collab-mcl-detection", "§5.1, draws' headings picked by the scan (the hallway's "
                              "setting) instead of half from the own belief",
                              {1: {"inject_heading_belief_share": 0.0, "inject_heading_scan_share": 1.0}}),
    "hallway": ("collab-mcl-hallway", "§5.2.1 as the scenario is", {}),
    "hallway-turns": ("collab-mcl-hallway", "§5.2.1, p_turn_at_opening 0.5 (the wanderer's default)",
                      {0: {"wander": {"cruise_speed_mps": 0.3, "turn_rate_radps": 0.8, "p_turn_at_opening": 0.5}}}),
    "hallway-draws0": ("collab-mcl-hallway", "§5.2.1, inject_min_draws 0 and inject_sender_lost_prior 0 "
                       "(the brain's defaults)", {0: {"inject_min_draws": 0, "inject_sender_lost_prior": 0.0}}),
    "hexagon": ("collab-mcl-hexagon", "§5.2.2 as the scenario is", {}),
    "hexagon-laser0.03": ("collab-mcl-hexagon", "§5.2.2, laser likelihood exponent 0.03 (the first version)",
                          {1: {"likelihood_exponent": 0.03}}),
    "hexagon-heading0.5": ("collab-mcl-hexagon", "§5.2.2, inject_heading_belief_share 0.5 (the brain's default)",
                           {0: {"inject_heading_belief_share": 0.5}, 1: {"inject_heading_belief_share": 0.5}}),
    # rule 9 (2026-11-29) ran the two above when the scenario still had uniform headings (0); the
    # scenario now has the brain's default, so "hexagon" and "hexagon-heading0.5" are the same set-up
    "hexagon-heading0": ("collab-mcl-hexagon", "§5.2.2, inject_heading_belief_share 0 (uniform draw headings)",
                         {0: {"inject_heading_belief_share": 0.0}, 1: {"inject_heading_belief_share": 0.0}}),
}

PART_SCENARIO = {"detection": "collab-mcl-detection", "hallway": "collab-mcl-hallway", "hexagon": "collab-mcl-hexagon"}
PART_DURATION = {"detection": 150.0, "hallway": 600.0, "hexagon": 300.0}


def parse_seeds(text: str) -> list[int]:
    """``"1000-1003,1010"`` -> [1000, 1001, 1002, 1003, 1010]; every seed must be a tuning seed."""
    out: list[int] = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    bad = [s for s in out if s < TUNING_SEED_MIN]
    if bad:
        raise ValueError(f"seeds {bad} are report seeds (< {TUNING_SEED_MIN}); this script tunes, it never runs them")
    return out


def _merge(base: dict, extra: dict) -> dict:
    out = dict(base)
    for k, v in extra.items():
        out[k] = {**out[k], **v} if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def overrides(part: str, factor: str, collaborate: bool, column: str = "paper_rules") -> dict:
    """Scenario overrides of one run: ``paper_rules: true`` plus the factor (``column="paper_rules"``,
    the factor on Robin only in ``detection``, on every group otherwise), or the scenario plus a
    :data:`TEAMNAV_CHECKS` variant (``column="teamnav"``); ``collaborate`` set on every group that
    localizes (in ``detection``, on Robin: Marian keeps sending)."""
    from teamnav.papers.trails.report._trails import paper_rules_spec
    from teamnav.experiments.spec import load_scenario

    scen = PART_SCENARIO[part]
    groups = load_scenario(scen).robots
    if column == "paper_rules":
        base = dict(paper_rules_spec(scen).set)
        extra = {i: FACTORS[factor][1] for i in range(len(groups)) if part != "detection" or i == 1}
    else:
        base = {f"robots.{i}.params": dict(g.params or {}) for i, g in enumerate(groups)}
        extra = dict(TEAMNAV_CHECKS[factor][2])
    out = {}
    for i in range(len(groups)):
        key = f"robots.{i}.params"
        p = _merge(base.get(key, {}), extra.get(i, {}))
        if p.get("paper_rules") and set(extra.get(i, {})) & set(_paper_rules()):
            # a factor that is one of PAPER_RULES' own fields (temper, ess): every other rule written out
            p.pop("paper_rules")
            p = {**_paper_rules(), **p}
        if part != "detection" or i == 1:
            p["collaborate"] = collaborate
        out[key] = p
    return out


def _paper_rules() -> dict:
    from teamnav.papers.collab_mcl.brains.localizing import MCLWanderParams

    return dict(MCLWanderParams.PAPER_RULES)


def _error_at(data, robot: int, t_s: float) -> float:
    """Mean distance of the robot's logged samples to its true position at the record nearest ``t_s``."""
    recs = [r for r in data.logs if r["robot"] == robot and "pts" in r["values"]]
    if not recs:
        return float("nan")
    r = min(recs, key=lambda r: abs(float(r["t_s"]) - t_s))
    rec_t = np.asarray(data.t_s, dtype=float)
    j = int(np.argmin(np.abs(rec_t - float(r["t_s"]))))
    truth = data.true_pose[j, robot]
    pts = np.asarray(r["values"]["pts"], dtype=float).reshape(-1, 2)
    return float(np.mean(np.hypot(pts[:, 0] - truth[0], pts[:, 1] - truth[1])))


def _belief_at(data, robot: int, t_s: float) -> tuple[int, float]:
    recs = [r for r in data.logs if r["robot"] == robot and "n_particles" in r["values"]]
    r = min(recs, key=lambda r: abs(float(r["t_s"]) - t_s))
    return int(r["values"]["n_particles"]), float(r["values"]["spread_m"])


def one_run(job: tuple[str, str, str, int, bool, float | None]) -> dict:
    """One run of ``(part, column, factor, seed, collaborate, duration_s)``; the measures of the module docstring."""
    from teamnav.papers.collab_mcl.metrics import localization
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario

    part, column, factor, seed, collaborate, duration = job
    scen = PART_SCENARIO[part] if column == "paper_rules" else TEAMNAV_CHECKS[factor][0]
    part = next(k for k, v in PART_SCENARIO.items() if v == scen)
    duration = duration or PART_DURATION[part]
    t0 = time.process_time()
    res = run(load_scenario(scen, overrides=overrides(part, factor, collaborate, column), seed=seed,
                            duration_s=duration), progress=False)
    m = localization(res.data)
    out = {"part": part, "column": column, "factor": factor, "seed": seed, "collaborate": collaborate,
           "duration_s": duration, "cpu_s": round(time.process_time() - t0, 2)}
    if part == "detection":
        n5, s5 = _belief_at(res.data, 1, 5.0)
        n30, s30 = _belief_at(res.data, 1, 30.0)
        dets = [d for r in sorted((r for r in res.data.logs if r["robot"] == 1), key=lambda r: r["step"])
                for d in r["values"].get("det_belief", [])]
        first = dets[0] if dets else None
        out.update({"n_5s": n5, "spread_5s_m": s5, "n_30s": n30, "spread_30s_m": s30,
                    "det_t_s": first["t_s"] if first else None,
                    "det_n": first["n_particles"] if first else None,
                    "det_spread_m": first["spread_m"] if first else None,
                    "det_cluster_weight": first["cluster_weight"] if first else None,
                    "det_error_m": _error_at(res.data, 1, first["t_s"]) if first else None,
                    "final_error_m": m.get("loc_final_error_m_g_robin"),
                    "ttl_s": m.get("loc_time_to_localize_s_g_robin")})
    else:
        out.update({"ttl_s": m.get("loc_time_to_localize_s"), "censored": m.get("loc_censored"),
                    "final_localized": m.get("loc_final_localized_fraction"),
                    "final_error_m": m.get("loc_final_error_m"), "syncs": m.get("loc_syncs")})
        for k in ("sonar", "laser"):
            if f"loc_final_localized_fraction_{k}" in m:
                out[f"final_localized_{k}"] = m[f"loc_final_localized_fraction_{k}"]
        if part == "hexagon":
            from teamnav.papers.collab_mcl.metrics import error_matrix

            err = error_matrix(res.data)[1]
            out["all_localized"] = bool(all(e[~np.isnan(e)][-1] < 1.5 for e in err.T))
    return out


def _ms(v) -> str:
    v = np.asarray([x for x in v if x is not None and math.isfinite(x)], dtype=float)
    if v.size == 0:
        return "n/a"
    return f"{v.mean():.2f} ± {v.std(ddof=1) if v.size > 1 else 0.0:.2f}"


def summarize(rows: list[dict]) -> list[str]:
    """One line per (factor, alone/team): means ± std over the runs."""
    lines = []
    keys = sorted({(r["part"], r["factor"], r["collaborate"]) for r in rows},
                  key=lambda k: (k[0], list(FACTORS).index(k[1]) if k[1] in FACTORS else 99, k[1], k[2]))
    for part, factor, collab in keys:
        rs = [r for r in rows if (r["part"], r["factor"], r["collaborate"]) == (part, factor, collab)]
        head = f"{part:9s} {factor:18s} {'team ' if collab else 'alone'} n={len(rs):2d}"
        if part == "detection":
            loc = [r["final_error_m"] < 1.5 for r in rs if r["final_error_m"] is not None]
            lines.append(f"{head} spread5s {_ms(r['spread_5s_m'] for r in rs)} n5s {_ms(r['n_5s'] for r in rs)} | "
                         f"spread30s {_ms(r['spread_30s_m'] for r in rs)} | at det: n {_ms(r['det_n'] for r in rs)} "
                         f"spread {_ms(r['det_spread_m'] for r in rs)} err {_ms(r['det_error_m'] for r in rs)} | "
                         f"final err {_ms(r['final_error_m'] for r in rs)} localized {np.mean(loc):.0%} | "
                         f"ttl {_ms(r['ttl_s'] for r in rs)} | cpu {_ms(r['cpu_s'] for r in rs)}")
        else:
            extra = ""
            if part == "hexagon":
                extra = (f" sonar {_ms(r.get('final_localized_sonar') for r in rs)} laser "
                         f"{_ms(r.get('final_localized_laser') for r in rs)} all-localized "
                         f"{sum(r['all_localized'] for r in rs)}/{len(rs)}")
            lines.append(f"{head} ttl {_ms(r['ttl_s'] for r in rs)} s censored {_ms(r['censored'] for r in rs)} "
                         f"final localized {_ms(r['final_localized'] for r in rs)}{extra} | "
                         f"cpu {_ms(r['cpu_s'] for r in rs)}")
    return lines


def paired(rows: list[dict], key: str = "ttl_s") -> list[str]:
    """Per factor: the paired change team - alone by seed, mean ± standard error."""
    lines = []
    for part, factor in sorted({(r["part"], r["factor"]) for r in rows}):
        a = {r["seed"]: r[key] for r in rows if (r["part"], r["factor"]) == (part, factor) and not r["collaborate"]}
        t = {r["seed"]: r[key] for r in rows if (r["part"], r["factor"]) == (part, factor) and r["collaborate"]}
        d = np.array([t[s] - a[s] for s in sorted(set(a) & set(t)) if a[s] is not None and t[s] is not None])
        if d.size:
            se = d.std(ddof=1) / math.sqrt(d.size) if d.size > 1 else 0.0
            lines.append(f"{part:9s} {factor:18s} paired {key} team - alone: {d.mean():+.1f} ± {se:.1f} (s.e.), "
                         f"{int((d < 0).sum())}/{d.size} seeds lower together")
    return lines


def _mean(v) -> float | None:
    v = [x for x in v if x is not None and math.isfinite(x)]
    return round(float(np.mean(v)), 2) if v else None


def table_rows(rows: list[dict]) -> list[dict]:
    """The numbers the report section and docs/report/collab-mcl.md quote, one dict per (part,
    column, factor), rounded to cm / 0.01 s: means over runs (``runs`` seeds), counts of runs."""
    out = []
    keys = sorted({(r["part"], r["column"], r["factor"]) for r in rows})
    for part, column, factor in keys:
        rs = [r for r in rows if (r["part"], r["column"], r["factor"]) == (part, column, factor)]
        a = {r["seed"]: r for r in rs if not r["collaborate"]}
        t = {r["seed"]: r for r in rs if r["collaborate"]}
        d = {"part": part, "column": column, "factor": factor, "seeds": sorted(set(a) | set(t))}
        if part == "detection":
            both = list(a.values()) or list(t.values())
            d.update({"spread_5s_m": _mean(r["spread_5s_m"] for r in both),
                      "spread_5s_median_m": round(float(np.median([r["spread_5s_m"] for r in both])), 2),
                      "spread_30s_m": _mean(r["spread_30s_m"] for r in both),
                      "det_n": _mean(r["det_n"] for r in t.values()),
                      "det_spread_m": _mean(r["det_spread_m"] for r in t.values()),
                      "det_error_m": _mean(r["det_error_m"] for r in t.values()),
                      "det_right": sum(1 for r in t.values() if r["det_error_m"] is not None and r["det_error_m"] < 1.5),
                      "alone_final_m": _mean(r["final_error_m"] for r in a.values()),
                      "alone_localized": sum(r["final_error_m"] < 1.5 for r in a.values()),
                      "team_final_m": _mean(r["final_error_m"] for r in t.values()),
                      "team_localized": sum(r["final_error_m"] < 1.5 for r in t.values()),
                      "alone_runs": len(a), "team_runs": len(t)})
        else:
            diffs = [t[s]["ttl_s"] - a[s]["ttl_s"] for s in sorted(set(a) & set(t))]
            d.update({"alone_ttl_s": _mean(r["ttl_s"] for r in a.values()),
                      "team_ttl_s": _mean(r["ttl_s"] for r in t.values()),
                      "paired_s": _mean(diffs),
                      "paired_se_s": round(float(np.std(diffs, ddof=1) / math.sqrt(len(diffs))), 2)
                      if len(diffs) > 1 else None,
                      "faster": sum(x < 0 for x in diffs), "pairs": len(diffs),
                      "alone_final_localized": _mean(r["final_localized"] for r in a.values()),
                      "team_final_localized": _mean(r["final_localized"] for r in t.values()),
                      "team_all_localized": sum(bool(r.get("all_localized")) for r in t.values()),
                      "alone_all_localized": sum(bool(r.get("all_localized")) for r in a.values()),
                      "alone_runs": len(a), "team_runs": len(t)})
            for k in ("sonar", "laser"):
                if any(f"final_localized_{k}" in r for r in rs):
                    d[f"alone_localized_{k}"] = _mean(r.get(f"final_localized_{k}") for r in a.values())
                    d[f"team_localized_{k}"] = _mean(r.get(f"final_localized_{k}") for r in t.values())
        out.append(d)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("part", choices=sorted(PART_SCENARIO) + ["summary"],
                    help="the experiment, or 'summary' to print the tables of the --out file's runs")
    ap.add_argument("--column", choices=["paper_rules", "teamnav"], default="paper_rules")
    ap.add_argument("--factors", default=None, help="comma list (default: all of the column's)")
    ap.add_argument("--seeds", default="1000-1007")
    ap.add_argument("--duration", type=float, default=None)
    ap.add_argument("--conditions", default="alone,team")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--out", default=None, help="JSON lines file (appended)")
    a = ap.parse_args(argv)
    if a.part == "summary":
        rows = [json.loads(x) for x in Path(a.out).read_text().splitlines() if x.strip()]
        for part in sorted({r["part"] for r in rows}):
            rs = [r for r in rows if r["part"] == part]
            print("\n".join(summarize(rs) + paired(rs, "ttl_s") + paired(rs, "final_error_m")))
        for d in table_rows(rows):
            print(json.dumps(d))
        return 0
    names = FACTORS if a.column == "paper_rules" else [k for k, v in TEAMNAV_CHECKS.items()
                                                        if v[0] == PART_SCENARIO[a.part]]
    factors = a.factors.split(",") if a.factors else list(names)
    unknown = [f for f in factors if f not in names]
    if unknown:
        ap.error(f"unknown factors {unknown} (known: {', '.join(names)})")
    seeds = parse_seeds(a.seeds)
    conds = [c == "team" for c in a.conditions.split(",")]
    jobs = [(a.part, a.column, f, s, c, a.duration) for f in factors for c in conds for s in seeds]
    t0 = time.time()
    rows = []

    def keep(r: dict) -> None:
        rows.append(r)
        if a.out:
            with open(a.out, "a") as fh:
                fh.write(json.dumps(r) + "\n")

    if a.workers > 1:
        with ProcessPoolExecutor(a.workers) as ex:
            futs = {ex.submit(one_run, j): j for j in jobs}
            for fut in as_completed(futs):
                try:
                    keep(fut.result())
                except Exception as e:  # noqa: BLE001 - one failed run must not lose the others
                    print(f"run {futs[fut]} failed: {e!r}", file=sys.stderr)
    else:
        for j in jobs:
            keep(one_run(j))
    print("\n".join(summarize(rows) + paired(rows, "ttl_s") + (paired(rows, "final_error_m") if a.part == "detection"
                                                                  else [])))
    print(f"{len(rows)} runs, {time.time() - t0:.0f} s wall, {sum(r['cpu_s'] for r in rows):.0f} CPU s in the runs",
          file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
