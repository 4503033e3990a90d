"""Where a reproduction's time goes: one representative trial per report section, profiled.

For each section of ``teamnav report all`` this runs one trial of the section's main sweep
the way a sweep worker runs it (``runner.run(scenario, out_dir=None)``), in a fresh process,
and splits its wall time into

- **start-up**: importing teamnav, building the simulation (map, clearance and distance
  fields, sensors, brains) and the first step over the steady per-step cost (numba's
  compilation or cache load lands here);
- **brains**: ``teamnav.control`` and ``teamnav.localization`` (what a robot computes);
- **sensing**: ``teamnav.sim.sensors`` (the simulated sensors; ray casting and line of sight
  count as sensing when a sensor calls them and as brains when a brain does, e.g. MCL's own
  expected ranges);
- **engine**: the rest of ``teamnav.sim`` (motion, collisions, odometry, radio, places);
- **I/O + metrics**: the recorder, the metrics and everything in ``teamnav.experiments``.

cProfile's own time of a function outside teamnav (numpy, numba dispatchers, builtins) is
given to the teamnav functions that called it, in proportion to the time spent on each call
edge, so a numba kernel counts where it is called from.

Usage::

    python benchmarks/profile_sections.py                 # every section, default lengths
    python benchmarks/profile_sections.py los-help --sim-s 300
    python benchmarks/profile_sections.py --json out.json

The shares are stable across runs; absolute seconds depend on the machine's load, so the
table prints seconds per simulated second only as an indication.
"""

from __future__ import annotations

import argparse
import cProfile
import json
import os
import pstats
import subprocess
import sys
import time
from collections import defaultdict

#: section -> (built-in scenario, overrides, simulated seconds): one trial of the section's
#: main full-mode sweep (the trial kind that dominates the section's CPU time).
TRIALS: dict[str, tuple[str, list[str], float]] = {
    # Table 1's largest team (R1..R4, Avoid-Past) on the simple office, one task
    "los-help": ("los-help-simple", [], 600.0),
    # the 2000 paper's team of four trail robots
    "blazing-a-trail": ("blazing-a-trail", [], 600.0),
    # the 2002 paper's team sharing trails across frames
    "try-to-see-it-my-way": ("try-to-see-it-my-way", [], 600.0),
    # §5.2.1: eight sonar robots with up to 10 000 samples each in the symmetric hallway
    "collab-mcl": ("collab-mcl-hallway", [], 120.0),
}

CATEGORIES = ("brains", "sensing", "engine", "io+metrics")


def _category(filename: str) -> str | None:
    f = filename.replace(os.sep, "/")
    if "/teamnav/" not in f:
        return None
    if "/teamnav/control/" in f or "/teamnav/localization/" in f:
        return "brains"
    if f.endswith(("/teamnav/world/raycast.py", "/teamnav/world/raycast_stretched.py", "/teamnav/world/los.py")):
        return None  # shared geometry kernels: counted where they are called from (a sensor or a brain)
    if "/teamnav/sim/sensors/" in f:
        return "sensing"
    if "/teamnav/sim/recorder.py" in f or "/teamnav/experiments/" in f or "/teamnav/viz/" in f:
        return "io+metrics"
    if "/teamnav/sim/" in f or "/teamnav/world/" in f or "/teamnav/geometry/" in f:
        return "engine"
    return "io+metrics"


def split_profile(stats: pstats.Stats) -> dict[str, float]:
    """Seconds per category, foreign functions' own time given to their teamnav callers."""
    raw = stats.stats  # func -> (cc, nc, tt, ct, callers)
    memo: dict = {}

    def owners(func, depth=0) -> dict[str, float]:
        if func in memo:
            return memo[func]
        cat = _category(func[0])
        if cat is not None:
            memo[func] = {cat: 1.0}
            return memo[func]
        memo[func] = {"io+metrics": 1.0}  # cycle guard
        callers = raw.get(func, (0, 0, 0, 0, {}))[4]
        total = sum(edge[2] + edge[3] * 1e-9 for edge in callers.values())
        if not callers or total <= 0 or depth > 40:
            memo[func] = {"io+metrics": 1.0}
            return memo[func]
        out: dict[str, float] = defaultdict(float)
        for caller, edge in callers.items():
            w = (edge[2] + edge[3] * 1e-9) / total
            for k, v in owners(caller, depth + 1).items():
                out[k] += w * v
        memo[func] = dict(out)
        return memo[func]

    seconds: dict[str, float] = defaultdict(float)
    for func, (_, _, tt, _, _) in raw.items():
        for k, v in owners(func).items():
            seconds[k] += tt * v
    return {k: seconds.get(k, 0.0) for k in CATEGORIES}


def profile_one(section: str, sim_s: float | None) -> dict:
    """Profile one section's trial in this process (call in a fresh process)."""
    t0 = time.perf_counter()
    from teamnav.experiments.spec import build_grid, load_scenario
    from teamnav.sim.engine import Simulation

    t_import = time.perf_counter() - t0
    name, overrides, default_s = TRIALS[section]
    duration = float(sim_s if sim_s is not None else default_s)
    scn = load_scenario(name, overrides=overrides or None, duration_s=duration)
    t1 = time.perf_counter()
    grid = build_grid(scn)
    sim = Simulation(grid, scn, known_map=grid if scn.give_map else None)
    t_build = time.perf_counter() - t1
    t2 = time.perf_counter()
    sim.step()
    t_first = time.perf_counter() - t2
    n = scn.n_steps - 1
    prof = cProfile.Profile()
    t3 = time.perf_counter()
    prof.enable()
    sim.run(n)
    prof.disable()
    t_steps = time.perf_counter() - t3
    # what a sweep trial does after the steps: save the recording to a temporary folder, read
    # it back and compute the scenario's metrics (runner.run with out_dir=None)
    import shutil
    import tempfile

    from teamnav.experiments import metrics as metric_registry
    from teamnav.experiments.runner import run_data

    t4 = time.perf_counter()
    sim.record_last_step()
    staging = tempfile.mkdtemp(prefix="teamnav-profile-")
    try:
        sim.recorder.save(staging)
        data = run_data(__import__("pathlib").Path(staging), scn, grid, int(sim.step_index), t_steps)
        metric_registry.compute(scn.metric_names, data)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    t_tail = time.perf_counter() - t4
    split = split_profile(pstats.Stats(prof))
    scale = t_steps / max(sum(split.values()), 1e-12)  # cProfile's overhead spread evenly
    per_step = t_steps / max(n, 1)
    startup = t_import + t_build + max(0.0, t_first - per_step)
    parts = {"start-up": startup, **{k: v * scale for k, v in split.items()}}
    parts["io+metrics"] += t_tail
    total = sum(parts.values())
    return {
        "section": section, "scenario": name, "overrides": overrides, "sim_s": duration, "steps": scn.n_steps,
        "robots": scn.n_robots, "wall_s": total, "cpu_s_per_sim_s": total / duration,
        "seconds": parts, "shares": {k: v / total for k, v in parts.items()},
        "start_up_detail": {"import_s": t_import, "build_s": t_build, "first_step_s": t_first,
                            "steady_step_s": per_step, "save_and_metrics_s": t_tail},
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sections", nargs="*", default=list(TRIALS), help="sections (default: all)")
    ap.add_argument("--sim-s", type=float, default=None, help="simulated seconds per trial (default per section)")
    ap.add_argument("--json", default=None, help="also write the results here")
    ap.add_argument("--one", default=None, help=argparse.SUPPRESS)  # child process
    args = ap.parse_args(argv)
    if args.one:
        print(json.dumps(profile_one(args.one, args.sim_s)))
        return 0
    results = []
    for section in args.sections:
        if section not in TRIALS:
            ap.error(f"unknown section {section!r}; known: {', '.join(TRIALS)}")
        cmd = [sys.executable, __file__, "--one", section] + (["--sim-s", str(args.sim_s)] if args.sim_s else [])
        out = subprocess.run(cmd, capture_output=True, text=True, check=True)
        results.append(json.loads(out.stdout.strip().splitlines()[-1]))
    cols = ("start-up",) + CATEGORIES
    print(f"| section (trial) | sim s | wall s | {' | '.join(cols)} |")
    print("|---|---:|---:|" + "---:|" * len(cols))
    for r in results:
        shares = " | ".join(f"{100 * r['shares'][c]:.0f} %" for c in cols)
        print(f"| {r['section']} ({r['scenario']}, {r['robots']} robots) | {r['sim_s']:g} | {r['wall_s']:.1f} | {shares} |")
    for r in results:
        d = r["start_up_detail"]
        print(f"{r['section']}: import {d['import_s']:.2f} s, build {d['build_s']:.2f} s, first step "
              f"{d['first_step_s']:.2f} s vs steady {1000 * d['steady_step_s']:.2f} ms; "
              f"save + metrics {d['save_and_metrics_s']:.2f} s")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
