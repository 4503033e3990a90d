"""Where the line-of-sight section's full-mode CPU goes: trials x steps per trial x CPU per step.

The full mode of ``teamnav report los-help`` on the judged tasks 11-20 has not been run yet
(1570 trials of 200-target tasks by ``--list`` on 2026-11-29: 1410 for the tables, route plans,
noise figures and ablation, and 160 for the Avoid-Past half-life readings). This script

1. lists every trial the section's own ``build`` asks for in full mode: a report context whose
   ``sweep`` expands each sweep spec (the same specs, names, cases, grids and durations as a
   real run, both columns, the route plans, the noise figures and the ablation) and returns no
   rows, so nothing runs (``--list`` prints the trials per sweep and stops);
2. runs, of every listed trial, the same scenario with only the first ``--targets K`` targets of
   its task (same overrides, same step budget per target, ``stop_when_finished``), in this
   process, one at a time, and records its CPU (``time.process_time``), steps, targets reached and
   whether R1 gave up (a target over its step budget);
3. scales each configuration (trial minus its task: sweep x case x grid point) to the full task
   of N = 200 targets with a geometric model: with s the steps per reached target of the sample
   (summed over the configuration's sampled tasks), q the give-ups per target attempted and B
   the step budget per target, a task of N targets costs

       E[steps] = sum_{i<N} (1-q)^i ((1-q) s + q B)

   (each target is reached after s steps or abandoned after B, which ends the run), and its CPU
   is E[steps] x the configuration's CPU per step.

The model assumes the first K targets are typical of all 200 (the tasks draw their rooms at
random, so no target is special) and that give-ups happen at a constant rate per target. It is
an estimate: ``--targets`` larger narrows it, at K x the cost.

Usage::

    python benchmarks/los_cost_breakdown.py --list
    nice -n 10 python benchmarks/los_cost_breakdown.py --targets 4 --json out.json
    python benchmarks/los_cost_breakdown.py --from-json out.json      # the tables again, no runs
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

TARGETS_KEY = "robots.0.params.targets_xy"
BUDGET_KEY = "robots.0.params.max_steps_per_target"


class _AnyMetric(dict):
    """Metrics of a listed (not run) trial: every metric reads 1.0, so that the section's analysis
    goes on to ask for every sweep."""

    def get(self, key: Any, default: Any = None) -> Any:
        return 1.0

    def __getitem__(self, key: Any) -> Any:
        return 1.0

    def __contains__(self, key: Any) -> bool:
        return True

    def __len__(self) -> int:  # truthy: ``row["metrics"] or {}`` keeps it
        return 1


class _ListedRows:
    """What the listing context's ``sweep`` returns: a sweep result whose rows are the trials
    asked for, with their params, seed and ``config_hash`` but no metrics (so that the section's
    reuse of identical trials, ``_los_reuse``, acts as in a real run)."""

    def __init__(self, name: str, rows: list) -> None:
        self.name, self.total, self.done, self.failed, self.skipped, self.failures = name, len(rows), 0, 0, 0, []
        self._rows = rows

    def rows(self, **_: Any) -> list:
        return list(self._rows)


def list_trials() -> list[dict[str, Any]]:
    """Every trial of the section's full-mode build (nothing runs)."""
    from teamnav.experiments.report import available_sections
    from teamnav.experiments.report.context import SweepContext
    from teamnav.experiments.sweep import expand, resolve_spec

    trials: list[dict[str, Any]] = []
    seen: set[tuple[str, str]] = set()

    class ListingContext(SweepContext):
        def sweep(self, name_or_spec: Any, **kwargs: Any) -> Any:  # noqa: D401 - the report context's sweep
            keys = ("grid", "seeds", "set", "duration_s", "name")
            spec = resolve_spec(name_or_spec, **{k: kwargs.pop(k) for k in keys if k in kwargs})
            rows = []
            for t in expand(spec):
                rows.append({"trial_id": t.trial_id, "status": "ok", "params": dict(t.params), "seed": t.seed,
                             "config_hash": t.config_hash, "metrics": _AnyMetric()})
                if (spec.sweep_name, t.trial_id) in seen:  # a store per sweep name: a trial runs once
                    continue
                seen.add((spec.sweep_name, t.trial_id))
                trials.append({"sweep": spec.sweep_name, "scenario": t.scenario, "params": t.params, "seed": t.seed,
                               "trial_id": t.trial_id, "config_hash": t.config_hash})
            return _ListedRows(spec.sweep_name, rows)

    ctx = ListingContext(Path(tempfile.mkdtemp(prefix="teamnav-los-list-")), quick=False, section="los-help")
    try:
        available_sections()["los-help"].build(ctx)
    except Exception as exc:  # noqa: BLE001 - with no rows an analysis may raise after every sweep was asked for
        import traceback
        print(f"(build stopped after the sweeps: {type(exc).__name__}: {str(exc)[:120]})", file=sys.stderr)
        if os.environ.get("LOS_LIST_TRACE"):
            traceback.print_exc()
    return trials


def _task_of(trial: dict[str, Any]) -> int:
    """Which of the map's tasks a trial's targets are (1-based; 0 when none matches)."""
    from teamnav.papers.los_help import tasks as L

    xy = trial["params"].get(TARGETS_KEY)
    if xy is None:
        return 0
    for m in L.MAPS:
        for t in range(1, L.N_TASKS + 1):
            if [list(map(float, p)) for p in L.task_targets_xy(m, t)] == [list(map(float, p)) for p in xy]:
                return t
    return 0


def config_key(trial: dict[str, Any]) -> str:
    """A trial's configuration: sweep, case and grid point without the task's targets."""
    p = trial["params"]
    rest = {k: v for k, v in p.items() if k not in (TARGETS_KEY, "duration_s", "case")
            and not k.endswith("patrol_xy")}
    tail = ",".join(f"{'.'.join(k.split('.')[-2:]) if k.endswith('count') else k.split('.')[-1]}={v}" for k, v in sorted(rest.items()) if not isinstance(v, (list, dict)))
    return f"{trial['sweep']}|{p.get('case', '')}|{tail}"


def _plain_key(config: str) -> str:
    """A configuration key without its case name (the ablation's trials moved from grid points to
    cases when the section stopped running the tables' setting twice; the params are the same)."""
    sweep, _case, grid = config.split("|", 2)
    return f"{sweep}|{grid}"


def run_sample(trial: dict[str, Any], k: int) -> dict[str, Any]:
    """The trial with its first ``k`` targets: CPU s, steps, targets reached, gave up, budget."""
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario

    params = dict(trial["params"])
    duration = params.pop("duration_s", None)
    params.pop("case", None)
    xy = params.get(TARGETS_KEY)
    n_full = None
    if xy is not None:
        n_full = len(xy)
        params[TARGETS_KEY] = [list(p) for p in xy[:k]]
    scn = load_scenario(trial["scenario"], overrides=params, seed=trial["seed"], duration_s=duration)
    brain_params = scn.robots[0].params
    if xy is None:
        n_full = len(brain_params["targets_xy"])
        scn = load_scenario(trial["scenario"], overrides={**params, TARGETS_KEY: [list(p) for p in brain_params["targets_xy"][:k]]},
                            seed=trial["seed"], duration_s=duration)
    budget = int(scn.robots[0].params.get("max_steps_per_target") or 0)
    t0 = time.process_time()
    res = run(scn, progress=False)
    cpu = time.process_time() - t0
    brain = res.sim.brains[0]
    brain = brain[0] if isinstance(brain, list) else brain
    return {"cpu_s": cpu, "steps": int(res.sim.step_index), "reached": int(brain.targets_reached),
            "gave_up": bool(brain.gave_up), "budget": budget, "n_targets": n_full, "k": k,
            "n_robots": int(scn.n_robots), "max_steps": int(scn.n_steps)}


def expected_steps(s: float, q: float, budget: int, n: int) -> float:
    """E[steps] of an n-target task: each target reached after s steps or, with probability q,
    abandoned after ``budget`` steps (the run ends there)."""
    if q <= 0.0:
        return n * s
    if q >= 1.0:
        return float(budget)
    geo = (1.0 - (1.0 - q) ** n) / q  # sum_{i<n} (1-q)^i
    return geo * ((1.0 - q) * s + q * budget)


def summarize(samples: list[dict[str, Any]]) -> list[dict[str, Any]]:
    by: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for r in samples:
        by[r["config"]].append(r)
    out = []
    for key, rs in by.items():
        steps = sum(r["steps"] for r in rs)
        cpu = sum(r["cpu_s"] for r in rs)
        reached = sum(r["reached"] for r in rs)
        quits = sum(r["gave_up"] for r in rs)
        budget, n = rs[0]["budget"], rs[0]["n_targets"]
        # steps spent on reached targets: a give-up's last target cost exactly its budget
        s = (steps - quits * budget) / reached if reached else float(budget)
        q = quits / (reached + quits) if (reached + quits) else 0.0
        e = min(expected_steps(s, q, budget, n), float(rs[0]["max_steps"]))
        cps = cpu / steps if steps else 0.0
        out.append({"config": key, "sweep": rs[0]["sweep"], "case": rs[0]["case"], "trials": rs[0]["trials_full"],
                    "tasks_sampled": len(rs), "robots": rs[0]["n_robots"], "reached": reached, "gave_up": quits,
                    "steps_per_target": s, "q_giveup": q, "budget": budget, "exp_steps_per_trial": e,
                    "ms_per_step": 1000 * cps, "cpu_s_per_trial": e * cps,
                    # the configuration's trials in full (one per task) x its expected CPU per trial
                    "cpu_s_full": e * cps * rs[0]["trials_full"]})
    return out


def _group(rows: list[dict[str, Any]], keyf) -> list[tuple[str, dict[str, float]]]:
    acc: dict[str, dict[str, float]] = defaultdict(lambda: defaultdict(float))
    for r in rows:
        a = acc[keyf(r)]
        a["trials"] += r["trials"]
        a["steps"] += r["exp_steps_per_trial"] * r["trials"]
        a["cpu"] += r["cpu_s_full"]
    return sorted(acc.items(), key=lambda kv: -kv[1]["cpu"])


_NAV_CASE = {"potential_field": "pot-field", "avoid_past": "avoid-past", "visbug21": "visbug21"}


def _algo(r: dict[str, Any]) -> str:
    c = r["case"] or ""
    if c and not r["sweep"].startswith("los-ablation"):
        return c.split("/")[0]
    for nav, name in _NAV_CASE.items():  # the ablation's grid points / cases name the navigator
        if f"navigator={nav}" in r["config"]:
            return name
    return "?"


def _team(r: dict[str, Any]) -> str:
    c = r["case"] or ""
    return c.split("/")[1] if "/" in c else f"{r['robots']} robots"


def _column(r: dict[str, Any]) -> str:
    return "paper" if r["sweep"].endswith("-paper-rules") else "teamnav"


def _family(r: dict[str, Any]) -> str:
    s = r["sweep"].replace("-paper-rules", "")
    return s


def report(rows: list[dict[str, Any]], k: int) -> None:
    total = sum(r["cpu_s_full"] for r in rows)
    steps = sum(r["exp_steps_per_trial"] * r["trials"] for r in rows)
    trials = sum(r["trials"] for r in rows)
    print(f"\n{trials} trials, expected {steps / 1e6:.1f} M simulated steps, {total / 3600:.2f} CPU-h "
          f"(this machine's CPU per step measured on the first {k} targets of every task)\n")
    for title, keyf in (("sweep", _family), ("column", _column), ("algorithm", _algo), ("team", _team),
                        ("column x algorithm", lambda r: f"{_column(r)} / {_algo(r)}")):
        print(f"| {title} | trials | M steps | share of steps | CPU-h | share of CPU | ms/step |")
        print("|---|---:|---:|---:|---:|---:|---:|")
        for name, a in _group(rows, keyf):
            print(f"| {name} | {a['trials']:.0f} | {a['steps'] / 1e6:.2f} | {100 * a['steps'] / steps:.0f} % | "
                  f"{a['cpu'] / 3600:.2f} | {100 * a['cpu'] / total:.0f} % | {1000 * a['cpu'] / a['steps']:.3f} |")
        print()
    print("| configuration (sweep / case / grid) | trials | robots | steps/target | give-ups per target | "
          "E steps/trial | ms/step | CPU-h | share |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in sorted(rows, key=lambda r: -r["cpu_s_full"])[:25]:
        print(f"| {r['config']} | {r['trials']} | {r['robots']} | {r['steps_per_target']:.0f} | {r['q_giveup']:.2f} | "
              f"{r['exp_steps_per_trial']:.0f} | {r['ms_per_step']:.3f} | {r['cpu_s_full'] / 3600:.3f} | "
              f"{100 * r['cpu_s_full'] / total:.1f} % |")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--list", action="store_true", help="list the trials per sweep and stop")
    ap.add_argument("--targets", type=int, default=4, help="targets of each task run (default 4)")
    ap.add_argument("--tasks", default="", help="comma list of tasks to sample (default: every task)")
    ap.add_argument("--only", action="append", help="substring filter on the configuration key (repeatable)")
    ap.add_argument("--json", type=Path, default=None, help="write every sample and the summary here")
    ap.add_argument("--from-json", type=Path, default=None, help="print the tables of an earlier --json, run nothing")
    ap.add_argument("--refine", type=Path, action="append", default=[],
                    help="with --from-json: another --json (e.g. more targets on some configurations) whose samples "
                         "replace the first one's for the configurations it holds")
    ap.add_argument("--relist", action="store_true",
                    help="with --from-json: count the trials of today's build (configurations it no longer runs drop out)")
    args = ap.parse_args(argv)
    if args.from_json:
        data = json.loads(args.from_json.read_text())
        if not (args.refine or args.relist):
            report(data["summary"], data["targets"])
            return 0
        samples = {}
        for r in data["samples"]:
            samples.setdefault(_plain_key(r["config"]), []).append(r)
        for extra in args.refine:
            more: dict[str, list] = {}
            for r in json.loads(extra.read_text())["samples"]:
                more.setdefault(_plain_key(r["config"]), []).append(r)
            samples.update(more)
            print(f"{extra}: {len(more)} configurations replaced", file=sys.stderr)
        if args.relist:
            counts: dict[str, int] = defaultdict(int)
            for t in list_trials():
                counts[_plain_key(config_key(t))] += 1
            dropped = [k for k in samples if k not in counts]
            print(f"{len(dropped)} sampled configurations not in today's build (their trials are read from "
                  f"another sweep's rows): dropped", file=sys.stderr)
            samples = {k: [dict(r, trials_full=counts[k]) for r in v] for k, v in samples.items() if k in counts}
        rows = summarize([r for v in samples.values() for r in v])
        report(rows, data["targets"])
        return 0
    trials = list_trials()
    per_sweep: dict[str, int] = defaultdict(int)
    for t in trials:
        per_sweep[t["sweep"]] += 1
    print(f"{len(trials)} trials in full mode:", file=sys.stderr)
    for s, n in per_sweep.items():
        print(f"  {s}: {n}", file=sys.stderr)
    if args.list:
        return 0
    counts: dict[str, int] = defaultdict(int)
    for t in trials:
        t["config"] = config_key(t)
        t["task"] = _task_of(t)
        counts[t["config"]] += 1
    wanted = {int(x) for x in args.tasks.split(",") if x.strip()}
    todo = [t for t in trials if (not wanted or t["task"] in wanted)
            and (not args.only or any(s in t["config"] for s in args.only))]
    print(f"sampling {len(todo)} trials x {args.targets} targets, load {os.getloadavg()[0]:.1f}", file=sys.stderr)
    run_sample(todo[0], 1)  # warm-up: numba loads its cached kernels
    samples = []
    t0 = time.perf_counter()
    for i, t in enumerate(todo):
        r = run_sample(t, args.targets)
        r.update(config=t["config"], sweep=t["sweep"], case=t["params"].get("case", ""), task=t["task"],
                 trials_full=counts[t["config"]])
        samples.append(r)
        if (i + 1) % 20 == 0:
            print(f"  {i + 1}/{len(todo)} ({time.perf_counter() - t0:.0f} s)", file=sys.stderr, flush=True)
    rows = summarize(samples)
    report(rows, args.targets)
    if args.json:
        args.json.write_text(json.dumps({"targets": args.targets, "samples": samples, "summary": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
