"""CPU seconds per simulation step of the long reproductions, split into brains and simulator.

Runs, for a short simulated time and a fixed seed, the scenarios whose full reproductions
take CPU hours (Sgorbissa & Arkin's Tables 1–2: ``los-help-simple`` / ``los-help-complex``;
Vaughan et al.'s trails: ``try-to-see-it-my-way``; Fox et al.'s hallway MCL:
``collab-mcl-hallway``) and prints, per scenario, the median over ``--repeats`` runs of

- CPU seconds per step (``time.process_time``: this process only, so other work on a shared
  machine changes it less than wall time, though cache and core contention still show);
- the part spent inside the brains' ``step`` / ``step_batch`` / ``log`` (everything else is
  the simulator: motion, odometry, sensing, radio, recording, metrics);
- the CPU time a full run costs at that rate: per simulated hour, and for the scenario's
  own ``duration_s`` when it runs it all (los-help stops when R1 has its 200 targets).

A warm-up run of 1 simulated second per scenario loads the numba kernels first.

Usage::

    python benchmarks/bench_sim_step.py                 # ~1-2 min of CPU on one core
    python benchmarks/bench_sim_step.py --quick         # one repeat, shorter runs
    python benchmarks/bench_sim_step.py --scenario los-help-simple --duration-s 300

Compare two trees in one session (same load) by running the script with
``PYTHONPATH=<tree>/src`` for each, alternately.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import timed_run  # noqa: E402  (benchmarks/_common.py)

#: scenario -> simulated seconds per timed run (full mode)
SCENARIOS = {
    "los-help-simple": 200.0,
    "los-help-complex": 200.0,
    "try-to-see-it-my-way": 600.0,
    "collab-mcl-hallway": 30.0,
}


def _timed_run(name: str, duration_s: float, seed: int) -> tuple[float, float, int]:
    """(total CPU [s], CPU inside brain steps [s], steps) of one run."""
    from teamnav import load_scenario

    total, brain_s, result = timed_run(load_scenario(name, duration_s=duration_s, seed=seed),
                                       ("step", "step_batch", "log"))
    return total, brain_s, int(result.sim.step_index)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", action="append", help="scenario name (repeatable; default: the four above)")
    ap.add_argument("--duration-s", type=float, help="simulated seconds per timed run (default: per scenario)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true", help="one repeat, a quarter of the simulated time")
    args = ap.parse_args(argv)
    from teamnav import load_scenario

    names = args.scenario or list(SCENARIOS)
    repeats = 1 if args.quick else max(1, args.repeats)
    import teamnav

    print(f"teamnav from {teamnav.__file__}")
    print(f"{'scenario':24s} {'steps':>6s} {'ms/step':>8s} {'brains':>8s} {'sim':>8s} "
          f"{'CPU s/sim h':>11s} {'full run':>10s}")
    for name in names:
        duration = args.duration_s or SCENARIOS.get(name, 60.0)
        if args.quick:
            duration /= 4
        _timed_run(name, 1.0, args.seed)  # warm-up: numba kernels loaded
        runs = [_timed_run(name, duration, args.seed) for _ in range(repeats)]
        steps = runs[0][2]
        per_step = statistics.median(t / n for t, _, n in runs)
        brains = statistics.median(b / n for _, b, n in runs)
        scn = load_scenario(name)
        per_hour = per_step * 3600.0 / scn.dt_s
        full = per_step * scn.n_steps
        print(f"{name:24s} {steps:6d} {1000 * per_step:8.3f} {1000 * brains:8.3f} {1000 * (per_step - brains):8.3f} "
              f"{per_hour:11.1f} {full / 3600:9.2f}h", flush=True)
    print("ms/step: median CPU per step; brains: inside the brains' step() and log(); sim: the rest. "
          "'full run' is duration_s at that rate (a los-help run usually stops earlier).")


if __name__ == "__main__":
    main()
