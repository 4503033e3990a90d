"""What a full-mode report would cost, section by section, measured on a sample of its trials.

A full ``teamnav report all`` takes hours, so the goal of a full report in 30 minutes cannot be checked
by running it after every change. This script builds each section in full mode through a
report context whose ``sweep`` runs, of each sweep the section asks for, only the first
``--seeds-kept`` seeds of every configuration (same scenarios, same durations, same grid and
cases), measures the CPU seconds its worker processes used (``RUSAGE_CHILDREN``: the pool is
shut down, and its workers reaped, at the end of every sweep), splits them into the sweep's
start (pool, imports, numba loading its cache: the CPU beyond the trials' own recorded time,
paid once per sweep in full as in the sample) and the trials, and scales the trials' part by
the number of trials the full sweep has::

    estimate = sum over sweeps of  start + (CPU s of the sample - start) / trials run x trials in full

Stores are per sweep name, so a trial of two sweeps with the same configuration counts twice,
as it runs twice in a real report. The section's own analysis runs on the sample (fewer
seeds); its CPU time (``RUSAGE_SELF``) is reported beside the trials' and counted once. A section whose build raises on the thin
sample (a statistic that needs more seeds) stops calling sweeps there: its row is then marked
"lower bound" and names the error. Seeds differ in how long they run (a team that finishes its
task early stops early), so the estimate carries that sampling error; ``--seeds-kept 2``
costs twice the sample and hedges it.

Usage::

    python benchmarks/estimate_full_report.py                        # every section, 1 seed kept
    python benchmarks/estimate_full_report.py --sections collab-mcl --seeds-kept 2 --workers 2
    python benchmarks/estimate_full_report.py --json est.json

The ≤ 30 min goal on 2 cores needs the summed CPU estimate ≤ 1 CPU-hour (two workers kept
busy: the sweeps order trials longest-first).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from teamnav.experiments.report import available_sections
from teamnav.experiments.report.context import ReportSweepResult, SweepContext
from teamnav.experiments.sweep import expand, parse_seeds, resolve_spec


def _cpu(who: int) -> float:
    r = resource.getrusage(who)
    return r.ru_utime + r.ru_stime


class SampleContext(SweepContext):
    """A full-mode report context whose sweeps run only the first ``keep`` seeds of each
    configuration, and which records what each sweep would have cost in full."""

    def __init__(self, *args: Any, keep: int = 1, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.keep = int(keep)
        self.samples: list[dict[str, Any]] = []
        self._seen: set[tuple[str, str]] = set()  # (sweep, trial id) already counted: a store per sweep name

    def sweep(self, name_or_spec: Any, **kwargs: Any) -> ReportSweepResult:
        keys = ("grid", "seeds", "set", "duration_s", "name")
        spec = resolve_spec(name_or_spec, **{k: kwargs.pop(k) for k in keys if k in kwargs})
        seeds = parse_seeds(spec.seeds)
        seeds = list(range(seeds)) if isinstance(seeds, int) else list(seeds)
        full_ids = {(spec.sweep_name, t.trial_id) for t in expand(spec)}
        new = full_ids - self._seen
        self._seen |= full_ids
        cut = resolve_spec(spec, seeds=seeds[: self.keep])
        cpu0, t0 = _cpu(resource.RUSAGE_CHILDREN), time.perf_counter()
        res = super().sweep(cut, **kwargs)
        cpu = _cpu(resource.RUSAGE_CHILDREN) - cpu0
        ran = res.done + res.failed
        # a sweep pays its pool's start (processes, imports, numba loading its cache) once, in
        # full as in the sample: what the sample's CPU has beyond its trials' own time
        own = sum(float(r.get("wall_time_s") or 0.0) for r in res.rows())
        start = max(0.0, cpu - own) if ran else 0.0
        self.samples.append({
            "sweep": spec.sweep_name,
            "duration_s": spec.duration_s,
            "trials_full": len(full_ids),
            "trials_new": len(new),
            "trials_sampled": ran,
            "failed": res.failed,
            "cpu_s_sampled": round(cpu, 2),
            "wall_s_sampled": round(time.perf_counter() - t0, 2),
            "cpu_s_start": round(start, 2),
            "cpu_s_full_est": round(start + (cpu - start) / ran * len(new), 1) if ran else None,
        })
        return res


def estimate(keys: list[str], keep: int, workers: int, out: Path) -> list[dict[str, Any]]:
    sections = available_sections()
    rows = []
    for key in keys:
        spec = sections.get(key)
        if spec is None:
            rows.append({"section": key, "status": "missing"})
            continue
        ctx = SampleContext(out, quick=False, workers=workers, progress=False, section=key, keep=keep)
        self0, t0 = _cpu(resource.RUSAGE_SELF), time.perf_counter()
        status, error = "ok", ""
        try:
            spec.build(ctx)
        except Exception as exc:  # noqa: BLE001 - a thin sample may break a statistic: say so, keep the sweeps counted
            status, error = "lower bound", f"{type(exc).__name__}: {exc}"[:200]
        own = _cpu(resource.RUSAGE_SELF) - self0
        trials = sum(s["cpu_s_full_est"] or 0.0 for s in ctx.samples)
        unmeasured = [s["sweep"] for s in ctx.samples if s["cpu_s_full_est"] is None and s["trials_new"]]
        rows.append({
            "section": key,
            "status": status,
            "error": error,
            "sweeps": len(ctx.samples),
            "trials_full": sum(s["trials_new"] for s in ctx.samples),
            "trials_sampled": sum(s["trials_sampled"] for s in ctx.samples),
            "cpu_s_sampled": round(sum(s["cpu_s_sampled"] for s in ctx.samples), 1),
            "analysis_cpu_s": round(own, 1),
            "cpu_s_full_est": round(trials + own, 1),
            "unmeasured_sweeps": unmeasured,
            "wall_s": round(time.perf_counter() - t0, 1),
            "detail": ctx.samples,
        })
        print(_line(rows[-1]), file=sys.stderr, flush=True)
    return rows


def _line(r: dict[str, Any]) -> str:
    if r["status"] == "missing":
        return f"{r['section']}: no section"
    return (f"{r['section']}: {r['sweeps']} sweeps, {r['trials_sampled']} of {r['trials_full']} trials run "
            f"({r['cpu_s_sampled']:.0f} CPU s) -> full ≈ {r['cpu_s_full_est'] / 3600:.2f} CPU-h [{r['status']}]"
            + (f" ({r['error']})" if r["error"] else ""))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sections", nargs="+", default=None, help="default: every section of `teamnav report all`")
    ap.add_argument("--seeds-kept", type=int, default=1, help="seeds of each configuration actually run (default 1)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", type=Path, default=None, help="also write every sweep's figures here")
    ap.add_argument("--keep-out", type=Path, default=None, help="build into this folder (kept) instead of a temporary one")
    args = ap.parse_args(argv)
    if args.seeds_kept < 1:
        ap.error(f"--seeds-kept: expected an integer >= 1, received {args.seeds_kept}")
    keys = args.sections or list(available_sections())
    out = args.keep_out or Path(tempfile.mkdtemp(prefix="teamnav-estimate-"))
    os.environ.setdefault("TEAMNAV_PROGRESS_EVERY_S", "3600")
    try:
        rows = estimate(keys, args.seeds_kept, args.workers, out)
    finally:
        if args.keep_out is None:
            shutil.rmtree(out, ignore_errors=True)
    total = sum(r.get("cpu_s_full_est", 0.0) for r in rows)
    print("\n| section | sweeps | trials in full | trials run | CPU s run | full, CPU-h (est.) | full, wall min on 2 cores (≥) | build |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for r in rows:
        if r["status"] == "missing":
            print(f"| {r['section']} | — | — | — | — | — | — | no section |")
            continue
        print(f"| {r['section']} | {r['sweeps']} | {r['trials_full']} | {r['trials_sampled']} | {r['cpu_s_sampled']:.0f} | "
              f"{r['cpu_s_full_est'] / 3600:.2f} | {r['cpu_s_full_est'] / 120:.0f} | {r['status']} |")
    print(f"| **all** | | | | | **{total / 3600:.2f}** | **{total / 120:.0f}** | |")
    print(f"\nseeds kept per configuration: {args.seeds_kept}; workers: {args.workers}; "
          f"the goal (≤ 30 min on 2 cores) needs ≤ 1.00 CPU-h")
    if args.json is not None:
        args.json.write_text(json.dumps(rows, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
