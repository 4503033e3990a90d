"""Sweep throughput: trials per minute for 1, 2 and all local workers, and Ray beside them.

One command::

    python benchmarks/bench_sweep.py                 # 16 trials of a 2-robot, 5 s demo run
    python benchmarks/bench_sweep.py --trials 32 --duration 10 --robots 4
    python benchmarks/bench_sweep.py --no-ray        # local executor only

Every row runs the same sweep (``demo`` with ``robots.0.count`` fixed, seeds ``0..trials-1``)
into a fresh folder through :func:`teamnav.experiments.sweep.sweep`, so it measures what a user
gets: worker start-up (process spawn or Ray start, imports, numba cache loads), scenario loading,
the runs, and one committed SQLite row per trial. Two rates are printed:

- *end-to-end*: trials / wall time of the whole ``sweep()`` call;
- *steady*: trials finished after the first ``workers`` ones, divided by the time between the
  ``workers``-th and the last ``finished_at`` in the store: the rate once every worker is warm.

Ratios are against the local executor with one worker, measured in the same run. On a machine
shared with other jobs the numbers move; the load average is printed with them.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import importlib.util
import os
import sys
import tempfile
import time
from pathlib import Path

from teamnav.experiments.executors import default_workers
from teamnav.experiments.sweep import sweep


def _steady_rate_per_min(rows: list[dict], workers: int) -> float:
    ends = sorted(_dt.datetime.fromisoformat(r["finished_at"]).timestamp() for r in rows if r["status"] == "ok")
    k = min(workers, len(ends)) - 1
    if len(ends) - 1 <= k:
        return float("nan")
    span = ends[-1] - ends[k]
    return 60.0 * (len(ends) - 1 - k) / span if span > 0 else float("nan")


def _one(executor: str, workers: int, args: argparse.Namespace, root: Path) -> dict:
    out = root / f"{executor}-{workers}"
    t0 = time.perf_counter()
    res = sweep(
        "demo",
        set={"robots.0.count": args.robots},
        seeds=args.trials,
        duration_s=args.duration,
        out_dir=out,
        executor=executor,
        workers=workers,
        progress=False,
    )
    wall = time.perf_counter() - t0
    if res.failed:
        raise SystemExit(f"{executor} x {workers}: {res.failed} trials failed: {res.failures[0]['error']}")
    rows = res.rows()
    return {
        "executor": executor,
        "workers": workers,
        "trials": res.done,
        "wall_s": wall,
        "rate": 60.0 * res.done / wall,
        "steady": _steady_rate_per_min(rows, workers),
    }


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--trials", type=int, default=16, help="trials per row (seeds 0..N-1) [16]")
    p.add_argument("--duration", type=float, default=5.0, help="simulated time per trial [s] [5]")
    p.add_argument("--robots", type=int, default=2, help="robots per trial [2]")
    p.add_argument("--no-ray", action="store_true", help="skip the Ray rows")
    args = p.parse_args(argv)

    n_all = default_workers()
    counts = sorted({1, 2, n_all})
    plan = [("local", w) for w in counts]
    have_ray = importlib.util.find_spec("ray") is not None
    if not args.no_ray and have_ray:
        plan += [("ray", n_all)]
    print(
        f"sweep throughput: demo, {args.robots} robots, {args.duration:g} s simulated per trial, {args.trials} trials per row; "
        f"{n_all} CPUs usable, load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}"
    )
    if not args.no_ray and not have_ray:
        print("(Ray is not installed: pip install 'teamnav[ray]' to add its row)")
    results = []
    with tempfile.TemporaryDirectory(prefix="bench-sweep-") as tmp:
        for executor, workers in plan:
            r = _one(executor, workers, args, Path(tmp))
            results.append(r)
            print(f"  done: {executor} x {workers}: {r['wall_s']:.1f} s", file=sys.stderr)
    base = results[0]
    head = f"{'executor':<9}{'workers':>8}{'trials':>8}{'wall s':>9}{'trials/min':>12}{'x 1 worker':>12}{'steady/min':>12}{'x 1 worker':>12}"
    print(head)
    print("-" * len(head))
    for r in results:
        print(
            f"{r['executor']:<9}{r['workers']:>8}{r['trials']:>8}{r['wall_s']:>9.1f}{r['rate']:>12.1f}"
            f"{r['rate'] / base['rate']:>12.2f}{r['steady']:>12.1f}{r['steady'] / base['steady']:>12.2f}"
        )
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
