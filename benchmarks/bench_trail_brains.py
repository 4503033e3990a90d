"""CPU per team step of the trail brains: compiled group brains against the Python reference.

The trail sections (Vaughan et al. 2000 ``blazing-a-trail``, ``blazing-trail-v1``; 2002
``try-to-see-it-my-way``, ``trail-share-v1``) run with ``group_brains=True``
(``papers/trails/brains/trail_compiled.py``, ``docs/concepts/group-brains.md``) and without, in
this tree. Configurations:

- ``4 robots``: each section's scenario as the report runs it, both columns: teamnav, and the
  paper as written (every robot ``paper_rules: true``, the params those rules set dropped, as
  ``_trails.paper_rules_spec`` does; the column's cruise speed is left at the rules' or the
  scenario's), tuning seed 1000, with the scenario's drift and launch (started one at a time);
- ``100 robots``: ``trail-team`` (blazing-trail-v1, and trail-share-v1) with 100 robots on
  ``trail_office`` with its room doors open (the section's building; the corridors alone hold
  100 Pioneer-sized robots only as a jam), started at random free spots and headings all over
  the building instead of one at a time from home (100 launches through one spot would take
  most of the run): what a researcher asking whether the trail rules scale to a crowded
  building would run.

Each run is a fresh process (one numba thread) after an untimed warm-up of the same
configuration (numba's cache loaded); reference and compiled alternate ``--repeats`` rounds, so
both see the same load. CPU is ``time.process_time`` of the team steps alone (the simulation and
its brains are built before the clock starts: building 100 robots' Navigates costs about as much
as 50 of their steps); the brains' share is the CPU inside the brains' ``step``/``log`` or the
group brain's ``step_group`` and the robots' ``log``. Each run's outputs (true and odometry
poses, stalls, every robot's log, the places' events, radio totals) are hashed; a configuration
whose runs differ says DIFFER and gets no ratio.

It prints, last, one line per team size, reference CPU over compiled CPU per team step (median
of the configurations), in the form ``Trail team step, 4 robots: compiled / reference = 1.4x``.

Usage::

    python benchmarks/bench_trail_brains.py              # 3 rounds, 3000 steps (100 robots: 400)
    python benchmarks/bench_trail_brains.py --quick      # 1 round, 1000 steps (100 robots: 150)
    python benchmarks/bench_trail_brains.py --only try   # configurations whose name holds "try"
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))

from _common import clock_brains, unclock_brains  # benchmarks/_common.py

SEED = 1000  # a tuning seed (FIDELITY.md: seeds >= 1000); nothing is judged here

#: name -> (scenario, paper column, robots)
CONFIGS = {
    "blazing-a-trail/teamnav": ("blazing-a-trail", False, 4),
    "blazing-a-trail/paper": ("blazing-a-trail", True, 4),
    "try-to-see-it-my-way/teamnav": ("try-to-see-it-my-way", False, 4),
    "try-to-see-it-my-way/paper": ("try-to-see-it-my-way", True, 4),
    "trail-team-100/blazing-trail-v1": ("trail-team", False, 100),
    "trail-team-100/trail-share-v1": ("trail-team", False, 100),
}


def _overrides(name: str) -> dict:
    from teamnav import load_scenario
    from teamnav.control import registry

    scenario, paper, robots = CONFIGS[name]
    if robots != 4:
        ov = {"robots.0.count": robots, "map": {"builtin": "trail_office"}, "launch": None,
              "robots.0.start": {"theta_deg": None}}
        if name.endswith("trail-share-v1"):
            ov["robots.0.controller"] = "trail-share-v1"
            ov["robots.0.params"] = {"cruise_speed_mps": 0.4, "communicate": True, "layer_every_steps": 6000}
        return ov
    ov = {}
    if paper:
        base = load_scenario(scenario)
        for k, g in enumerate(base.robots):
            rules = registry.lookup(g.controller).Params.PAPER_RULES
            ov[f"robots.{k}.params"] = {**{a: b for a, b in g.params.items() if a not in rules}, "paper_rules": True}
    return ov


def _digest(sim) -> str:
    """SHA-256 of a run's outputs: true and odometry poses and stall flags at the end, every
    robot's log, the places' event log and the radio's totals."""
    import hashlib

    import numpy as np

    def default(o):
        return o.tolist() if hasattr(o, "tolist") else str(o)

    h = hashlib.sha256()
    st = sim.state
    for a in (st.x_m, st.y_m, st.theta_rad, sim.odometry.pose):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(st.stalled).astype(np.uint8).tobytes())
    logs = [b.log() for g in sim.brains for b in g]
    radio = [sim.radio.sent_messages.tolist(), sim.radio.sent_bytes.tolist()] if sim.radio is not None else None
    h.update(json.dumps([logs, sim.places.log, radio], sort_keys=True, default=default).encode())
    return h.hexdigest()


def _worker(name: str, compiled: bool, steps: int) -> dict:
    """(in the measuring process) one warm run of ``steps`` team steps: CPU of the steps alone
    (the simulation and its brains are built before the clock starts), and inside the brains."""
    from teamnav import load_scenario
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import build_grid
    from teamnav.sim.engine import Simulation

    scenario = CONFIGS[name][0]
    ov = _overrides(name)
    run(load_scenario(scenario, overrides=ov, duration_s=3.0, seed=SEED), progress=False,
        group_brains=compiled)  # warm-up: kernels loaded
    if compiled:
        from teamnav.control.nav.navigate_compiled import warm_up

        warm_up()  # the kernel's form with a Generator too (first needed at a robot's first Panic)
    scn = load_scenario(scenario, overrides=ov, duration_s=steps * 0.1, seed=SEED)
    sim = Simulation(build_grid(scn), scn, group_brains=compiled)
    # the brains' step and log, or the group brain's step_group and the views' log (its robots'
    # reference brains, whose step it may call, not counted twice: _common.clock_brains)
    brain_s, clocked = clock_brains(sim, ("step", "log"))
    clock = time.process_time
    teams = [team for team, *_ in sim.group_teams]
    t0 = clock()
    for _ in range(steps):
        sim.step()
    total = clock() - t0
    if compiled and not teams:
        raise SystemExit(f"{name}: the group brain did not run the team")
    robots = sum(getattr(team, "compiled_robots", stop - start) for team, start, stop, _ in sim.group_teams)
    unclock_brains(clocked)  # the views' own methods again, for the digest's logs
    return {"cpu_s": total, "brain_s": brain_s[0], "steps": steps, "digest": _digest(sim),
            "compiled_robots": robots, "robots": int(sim.n_robots)}


def _measure(name: str, compiled: bool, steps: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), NUMBA_NUM_THREADS="1")
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--worker", name, "1" if compiled else "0",
                          str(steps)], env=env, check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--worker", nargs=3, metavar=("NAME", "COMPILED", "STEPS"), help=argparse.SUPPRESS)
    ap.add_argument("--steps", type=int, default=3000, help="steps per timed run of 4 robots (default 3000)")
    ap.add_argument("--big-steps", type=int, default=400, help="steps per timed run of 100 robots (default 400)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="one round of 1000 steps (100 robots: 150)")
    ap.add_argument("--only", action="append", help="substring filter on the configuration names (repeatable: any)")
    args = ap.parse_args(argv)
    if args.worker:
        name, compiled, steps = args.worker
        print(json.dumps(_worker(name, compiled == "1", int(steps))))
        return
    steps, big, repeats = (1000, 150, 1) if args.quick else (args.steps, args.big_steps, args.repeats)
    load0 = os.getloadavg()[0]
    t0 = time.process_time()
    print(f"trail team steps, reference vs compiled group brains, seed {SEED}, {repeats} round(s), medians of CPU "
          f"(time.process_time, one numba thread), this tree ({REPO}), load {load0:.1f}")
    print(f"{'configuration':34s} {'robots':>6s} {'steps':>6s} {'ref ms/step':>11s} {'(brains)':>9s} {'compiled':>9s} "
          f"{'(brains)':>9s} {'ratio':>6s} {'brains':>7s}  outputs")
    ratios: dict[int, list[float]] = {}
    lines = []
    for name, (_, _, robots) in CONFIGS.items():
        if args.only and not any(o in name for o in args.only):
            continue
        n_steps = steps if robots == 4 else big
        ref, cmp_ = [], []
        for _ in range(repeats):  # alternate: both see the same load
            ref.append(_measure(name, False, n_steps))
            cmp_.append(_measure(name, True, n_steps))
        same = len({r["digest"] for r in ref + cmp_}) == 1
        rt = statistics.median(1000 * r["cpu_s"] / r["steps"] for r in ref)
        rb = statistics.median(1000 * r["brain_s"] / r["steps"] for r in ref)
        ct = statistics.median(1000 * r["cpu_s"] / r["steps"] for r in cmp_)
        cb = statistics.median(1000 * r["brain_s"] / r["steps"] for r in cmp_)
        if same:  # a ratio only for identical runs
            ratios.setdefault(robots, []).append(rt / ct)
        print(f"{name:34s} {robots:6d} {n_steps:6d} {rt:11.4f} {rb:9.4f} {ct:9.4f} {cb:9.4f} {rt / ct:6.2f} "
              f"{rb / cb:7.2f}  {'identical' if same else 'DIFFER'}; compiled robots {cmp_[0]['compiled_robots']} "
              f"of {cmp_[0]['robots']}", flush=True)
        lines.append(f"Trail team step, {robots} robots ({name}): compiled / reference = {rt / ct:.2f}x")
    print(f"(brains: CPU inside the brains' step and log, or the group brain's step_group; load {load0:.1f} -> "
          f"{os.getloadavg()[0]:.1f}; this script's own CPU {time.process_time() - t0:.1f} s, the runs' in their "
          f"processes)")
    for line in lines:
        print(line)
    for robots in sorted(ratios):
        print(f"Trail team step, {robots} robots: compiled / reference = {statistics.median(ratios[robots]):.1f}x")


if __name__ == "__main__":
    main()
