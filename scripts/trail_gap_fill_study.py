"""What each gap-fill of ``blazing-trail-v1`` buys, and what keeps the 2000 team from breaking down.

Vaughan, Støy, Sukhatme & Matarić (2000) §5.1: the four robots carried 28 units in 30 min, then
"the unbounded odometry error causes the system to break down completely at around 27 minutes".
teamnav's report has two columns: ``paper_rules: true`` (every gap-fill at the paper's value,
cruise 0.25 m/s; :mod:`teamnav.control.paper_rules`) and ours. This script takes them apart with
paired seeds (the same seed gives the same start spots, drift and noise draws in every
configuration), in two parts:

``gapfills``
    The ``blazing-a-trail`` trial (30 min, the scenario's per-robot heading drift). Configurations:
    ``paper`` (every gap-fill at the paper's value), ``teamnav`` (every one at ours, cruise 0.4 m/s),
    ``paper+G`` (the paper's rules with gap-fill G alone at our value: what G buys on its own) and
    ``teamnav-G`` (ours with G alone at the paper's value: what G is worth among the others).
``drift``
    One hour at the drift cases of ``blazing-drift`` (k x the 2002 paper's per-robot rates, Try
    §3.6: Bug -1, Ant +1, Fly +2, Tanis +0.35 deg/min; ``x1-slip``: wheel slip 0.01 m/sqrt(m) and
    1 deg/sqrt(m) on top of k = 1, a heading random walk; ``x1-scale5``: wheel-diameter errors of
    +-3-5 % on top of k = 1; :mod:`teamnav.sim.odometry`), for ``paper``, ``paper+reverse``
    (the paper's rules with homebound crumbs stored reversed), ``teamnav@0.25`` (our gap-fills
    at the paper's cruise speed) and ``teamnav``: which part of the difference between the columns
    is the speed and which the gap-fills, and whether a drift model with a random walk or a
    scale error breaks the team where a constant heading bias does not.

The breakdown is the report's: the last delivery, when the run ends at least
``BREAKDOWN_GAP_S`` (180 s) after it; otherwise none (censored at the run's end).

The seeds are neither the report's (0-9) nor used to choose anything: nothing is tuned here.

Usage::

    nice -n 10 python scripts/trail_gap_fill_study.py gapfills --seeds 100-109 --workers 2 --out F.jsonl
    nice -n 10 python scripts/trail_gap_fill_study.py drift --seeds 100-109 --workers 2 --out F.jsonl
    python scripts/trail_gap_fill_study.py summary --out F.jsonl

Results (JSON lines, one per run) are appended to ``--out`` (a run already there is skipped,
so an interrupted study resumes); ``summary`` prints the tables that
``docs/report/blazing-a-trail.md`` shows (mean ± std over runs, and the paired difference against
``paper`` as mean ± standard error with the count of seeds better).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path


#: system -> (scenario, params model "module:Class", the scenario's own params besides the gap-fills)
SYSTEMS: dict[str, tuple[str, str, dict]] = {
    # blazing-trail-v1 (2000), as blazing-paper-rules.yaml
    "blazing": ("blazing-a-trail", "teamnav.papers.trails.brains.blazing_trail:BlazingTrailParams",
                {"communicate": True, "layer_every_steps": 6000}),
    # trail-share-v1 (2002), as the try-to-see-it-my-way scenario
    "try": ("try-to-see-it-my-way", "teamnav.papers.trails.brains.trail_share:TrailShareParams",
            {"communicate": True, "policy": "optimistic", "layer_every_steps": 6000}),
}
SCENARIO, _, BASE_PARAMS = SYSTEMS["blazing"]
TEAMNAV_CRUISE = 0.4
#: Try §3.6's per-robot rates [deg/min] in robot order (Bug, Ant, Fly, Tanis), as blazing-drift.yaml
RATES = (-1.0, 1.0, 2.0, 0.35)
SCALE5 = (0.05, -0.05, 0.03, -0.03)
DRIFT_CASES = ("x0", "x1", "x4", "x1-slip", "x1-scale5")
DRIFT_CONFIGS = ("paper", "paper+reverse_carried_crumbs", "teamnav@0.25", "teamnav")
#: the 2000 paper column as the report judges it since 2026-11-29: the paper's rules, the single trail
#: followed backwards (crumbs laid while carrying reversed, Try §1) and the cruise speed the 2000 paper
#: implies (0.4 m/s; teamnav.papers.trails.report._trails.BLAZING_IMPLIED_CRUISE_MPS)
PAPER_2000_CRUISE = 0.4
#: the breakdown study (part ``breakdown``): the 2000 paper column at the papers' drift (k = 1) without
#: and with a heading random walk of h deg/sqrt(m) ("x1-slip<h>"; "x1-slip" is h = 1), 1 h, >= 20 seeds
BREAKDOWN_CASES = ("x1", "x1-slip0.5", "x1-slip", "x1-slip2")
BREAKDOWN_CONFIGS = ("paper-2000",)


#: the study's stored runs were made when blazing-trail-v1's ``paper_rules`` also set cruise 0.25 m/s
#: and crumbs laid while carrying unreversed (Blazing §4.1 read literally). Since 2026-11-29 neither
#: is among the brain's paper rules (the 2000 paper column reverses them, Try §1, and drives at the
#: speed the 2000 paper implies); the study keeps its configurations as they were run, so these two
#: are named here as gap-fills of the study: (field, teamnav value, the study's "paper" value, note)
STUDY_EXTRA_FILLS = {"blazing": (
    ("cruise_speed_mps", TEAMNAV_CRUISE, 0.25, "Try §3.6: 0.25 m/s cruise (the study's paper column)"),
    ("reverse_carried_crumbs", True, False, "Blazing §4.1 read literally (the study's paper column)"),
)}


def gap_fill_table(system: str = "blazing") -> list:
    """The gap-fills of the system's brain (Navigate's included), ours at cruise 0.4 m/s, and the
    study's own (:data:`STUDY_EXTRA_FILLS`)."""
    import importlib

    from teamnav.control.paper_rules import GapFill, gap_fills

    module, _, cls = SYSTEMS[system][1].partition(":")
    fills = gap_fills(getattr(importlib.import_module(module), cls), {"cruise_speed_mps": TEAMNAV_CRUISE})
    have = {g.field for g in fills}
    extra = [GapFill(*e) for e in STUDY_EXTRA_FILLS.get(system, ()) if e[0] not in have]
    # the brain's own order first, then the study's, cruise first (as the stored runs' tables list them)
    return sorted(extra, key=lambda g: g.field != "cruise_speed_mps") + fills if extra else fills


def params_for(config: str, system: str = "blazing") -> dict:
    """The robots' params of a configuration (see the module docstring).

    Raises
    ------
    ValueError
        An unknown configuration or gap-fill name (the message lists the known ones).
    """
    fills = gap_fill_table(system)
    names = [g.field for g in fills]
    paper = {g.field: g.paper_value for g in fills}
    ours = {g.field: g.teamnav_value for g in fills}
    if config == "paper":
        chosen = paper
    elif config == "paper-2000":
        chosen = {**paper, "cruise_speed_mps": PAPER_2000_CRUISE, "reverse_carried_crumbs": True}
    elif config == "teamnav":
        chosen = ours
    elif config == "teamnav@0.25":
        chosen = {**ours, "cruise_speed_mps": 0.25}
    elif config.startswith("paper+") and config[6:] in names:
        chosen = {**paper, config[6:]: ours[config[6:]]}
    elif config.startswith("teamnav-") and config[8:] in names:
        chosen = {**ours, config[8:]: paper[config[8:]]}
    else:
        raise ValueError(f"unknown configuration {config!r}: expected paper, paper-2000, teamnav, teamnav@0.25, "
                         f"paper+G or teamnav-G with G one of {', '.join(names)}")
    out: dict = dict(SYSTEMS[system][2])
    for key, value in chosen.items():
        head, _, tail = key.partition(".")
        if tail:
            out.setdefault(head, {})[tail] = value
        else:
            out[head] = value
    return out


def drift_overrides(case: str) -> dict:
    """The odometry overrides of a ``blazing-drift`` case (``x<k>``, ``x1-slip``, ``x1-scale5``)."""
    base, _, extra = case.partition("-")
    if not base.startswith("x"):
        raise ValueError(f"unknown drift case {case!r}: expected one of {', '.join(DRIFT_CASES)}")
    k = float(base[1:])
    out = {f"robots.{i}.odometry.heading_drift_deg_per_min": k * r for i, r in enumerate(RATES)}
    if extra.startswith("slip"):
        try:
            h = float(extra[4:]) if extra[4:] else 1.0  # "slip" = 1 deg/sqrt(m), as stored
        except ValueError:
            raise ValueError(f"unknown drift case {case!r}: expected one of {', '.join(DRIFT_CASES)} "
                             "or x<k>-slip<deg per sqrt m>") from None
        for i in range(4):
            out[f"robots.{i}.odometry.slip_std_m_per_sqrt_m"] = 0.01
            out[f"robots.{i}.odometry.heading_slip_deg_per_sqrt_m"] = h
    elif extra == "scale5":
        for i, s in enumerate(SCALE5):
            out[f"robots.{i}.odometry.scale_error"] = s
    elif extra:
        raise ValueError(f"unknown drift case {case!r}: expected one of {', '.join(DRIFT_CASES)}")
    return out


def one_run(job: tuple) -> dict:
    """One run of ``(part, config, case, seed, duration_s[, system])``: units, breakdown, CPU."""
    from teamnav.papers.trails.metrics import BREAKDOWN_GAP_S, deliveries
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario

    part, config, case, seed, duration = job[:5]
    system = job[5] if len(job) > 5 else "blazing"
    params = params_for(config, system)
    ov = {f"robots.{i}.params": params for i in range(4)}
    if case:
        ov.update(drift_overrides(case))
    t0 = time.process_time()
    res = run(load_scenario(SYSTEMS[system][0], overrides=ov, seed=seed, duration_s=duration), progress=False)
    times = sorted(t for t, _ in deliveries(res.data.event_log))
    # the 180° rule's turns per robot (Navigate's counter, in each brain's log): the last logged value
    last_rev: dict[int, int] = {}
    for rec in res.data.logs:
        v = (rec.get("values") or {}).get("reversals")
        if isinstance(v, int):
            last_rev[int(rec["robot"])] = v
    if times and duration - times[-1] >= BREAKDOWN_GAP_S:
        bd, cens = times[-1], False
    elif not times:
        bd, cens = 0.0, False
    else:
        bd, cens = duration, True
    half = [t for t in times if t > duration / 2]
    row = {} if system == "blazing" else {"system": system}  # rows without it are blazing-trail-v1's
    return {**row, "part": part, "config": config, "case": case, "seed": seed, "duration_s": duration,
            "units": len(times), "units_second_half": len(half), "first_delivery_s": times[0] if times else None,
            "breakdown_s": bd, "breakdown_censored": cens, "cpu_s": round(time.process_time() - t0, 2),
            "reversals": sum(last_rev.values()) if last_rev else None,
            "cruise_mps": float(params.get("cruise_speed_mps", 0.25)),
            "delivery_times_s": [round(t, 1) for t in times]}


def parse_seeds(text: str) -> list[int]:
    """``"100-109"`` or ``"100,105"`` -> seeds; the report's seeds 0-9 are refused."""
    out: list[int] = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out.extend(range(int(a), int(b or a) + 1))
    if any(s < 100 for s in out):
        raise SystemExit(f"--seeds: {text!r} includes seeds below 100; 0-29 belong to the report")
    return out


def summarize(rows: list[dict]) -> list[str]:
    """Markdown tables of the runs, as the report section shows them
    (:mod:`teamnav.papers.trails.report._trails_gap_fills`)."""
    from teamnav.papers.trails.report._trails_gap_fills import BREAKDOWN_HEADER, HEADER, breakdown_rows, cases, table_rows

    out: list[str] = []
    if any(r["part"] == "breakdown" for r in rows):
        out += ["\n## breakdown", "| " + " | ".join(BREAKDOWN_HEADER) + " |", "|" + "---|" * len(BREAKDOWN_HEADER)]
        out += ["| " + " | ".join(r) + " |" for r in breakdown_rows(rows)]
    for part in ("gapfills", "drift"):
        for case in cases(rows, part):
            out += [f"\n## {part} {case or '(the scenario drift)'}", "| " + " | ".join(HEADER) + " |",
                    "|" + "---|" * len(HEADER)]
            out += ["| " + " | ".join(r) + " |" for r in table_rows(rows, part, case)]
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("part", choices=["gapfills", "drift", "breakdown", "summary"])
    ap.add_argument("--seeds", default="100-109")
    ap.add_argument("--system", choices=sorted(SYSTEMS), default="blazing",
                    help="blazing: blazing-trail-v1 on blazing-a-trail; try: trail-share-v1 on try-to-see-it-my-way")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--configs", default=None, help="comma-separated configurations (default: all of the part)")
    ap.add_argument("--cases", default=",".join(DRIFT_CASES), help="drift cases (part drift)")
    ap.add_argument("--duration", type=float, default=None, help="run length [s] (30 min / 1 h by part)")
    a = ap.parse_args(argv)
    if a.part == "summary":
        rows = [json.loads(line) for line in a.out.read_text().splitlines() if line.strip()]
        print("\n".join(summarize(rows)))
        return 0
    seeds = parse_seeds(a.seeds)
    names = [g.field for g in gap_fill_table(a.system)]
    if a.part == "gapfills":
        configs = a.configs.split(",") if a.configs else (
            ["paper", "teamnav"] + [f"paper+{n}" for n in names] + [f"teamnav-{n}" for n in names])
        jobs = [("gapfills", c, "", s, a.duration or 1800.0, a.system) for c in configs for s in seeds]
    elif a.part == "breakdown":
        configs = a.configs.split(",") if a.configs else list(BREAKDOWN_CONFIGS)
        cases = a.cases.split(",") if a.cases != ",".join(DRIFT_CASES) else list(BREAKDOWN_CASES)
        jobs = [("breakdown", c, k, s, a.duration or 3600.0, a.system) for k in cases for c in configs for s in seeds]
    else:
        configs = a.configs.split(",") if a.configs else list(DRIFT_CONFIGS)
        jobs = [("drift", c, k, s, a.duration or 3600.0, a.system)
                for k in a.cases.split(",") for c in configs for s in seeds]
    for c in configs:
        params_for(c, a.system)  # fail before any run
    if a.out.exists():  # resume: a run already in --out is not run again
        done_keys = {(r["part"], r["config"], r["case"], r["seed"])
                     for r in map(json.loads, filter(str.strip, a.out.read_text().splitlines()))}
        jobs = [j for j in jobs if j[:4] not in done_keys]
    a.out.parent.mkdir(parents=True, exist_ok=True)
    done = 0
    with ProcessPoolExecutor(a.workers) as ex, a.out.open("a") as fh:
        for fut in as_completed([ex.submit(one_run, j) for j in jobs]):
            fh.write(json.dumps(fut.result()) + "\n")
            fh.flush()
            done += 1
            print(f"\r{done}/{len(jobs)}", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
