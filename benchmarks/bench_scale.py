"""Ten thousand robots on one machine: speed, real-time factor and peak memory beside ARGoS 3.

Usage::

    python benchmarks/bench_scale.py [--quick] [--robots 100,1000,10000] [--cases swarm,laser]
                                     [--threads 1,2] [--argos-build DIR] [--no-peers]

Rows (each teamnav cell in a fresh subprocess, so that its peak memory is its own and its numba
thread count is set before numba starts):

- ``swarm``: the swarm case of ``bench_engine.py`` (N robots, 7 proximity rays, a walled square
  arena of side 1 m x sqrt(N), the batched wanderer ``wander-batched-v1``), beside ARGoS 3's
  foot-bot diffusion example in the same arena (``benchmarks/peers/argos_peer.py``: build it
  once with its ``build`` command; ``--argos-build`` or ``$TEAMNAV_BENCH_ARGOS_BUILD``, default
  ``/tmp/argos3-build``). ARGoS runs with the same number of threads (its ``<system threads>``;
  1 thread = its main thread only, ``threads="0"``).
- ``laser``: the robots of ``bench_engine.py``'s laser case (radius 0.2 m, a 180-beam, 10-m
  laser, the batched wanderer) in the swarm's walled arena (side 1 m x sqrt(N), 2 cm cells), no
  peer (IR-SIM does not reach 10 000 robots in minutes; ``bench_engine.py`` has it at 10-1000 on
  the MIT basement map, which cannot hold 10 000 such robots: its start gives up near 2 000).

Printed per cell: robot-steps per second (wall clock) and per CPU-second, the real-time factor
(simulated seconds per wall second at the scenario's 0.1-s step; also per CPU-second of the
process, all its threads, which a loaded machine distorts less), and the peak resident memory
of the whole process (``ru_maxrss``: interpreter, numba, map, state, as ``/usr/bin/time`` shows
it; ARGoS's the same way). Then the goals as ratios: teamnav / ARGoS speed, teamnav memory /
ARGoS memory, 2 threads / 1 thread. The last lines, for scripts, are ``key: value`` pairs.

What differs from ARGoS (say so beside any ratio): the foot-bot has 24 proximity rays and a 2-D
rigid-body engine; teamnav's swarm has 7 rays and kinematic discs against a distance field.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HERE = Path(__file__).resolve().parent
DT_S = 0.1

#: Steps timed per cell (after 3 warm-up steps that compile the kernels), full / quick.
STEPS = {"full": {100: 400, 1000: 100, 10000: 20}, "quick": {100: 60, 1000: 20, 10000: 4}}


def _steps(mode: str, n: int) -> int:
    table = STEPS[mode]
    return table.get(n, max(2, int(table[1000] * 1000 / n)))


def laser_arena_sim(n: int, seed: int = 0):
    """``n`` laser robots (``bench_engine.py``'s laser group) in the swarm arena of ``n`` robots."""
    sys.path.insert(0, str(HERE))
    from bench_engine import swarm_arena
    from teamnav.sim.config import LaserConfig, RobotGroupConfig, SimConfig
    from teamnav.sim.engine import Simulation

    group = RobotGroupConfig(count=n, radius_m=0.2, controller="wander-batched-v1",
                             sensors=(LaserConfig(n_beams=180, fov_deg=180.0, max_range_m=10.0),))
    return Simulation(swarm_arena(n), SimConfig(robots=(group,), seed=seed, record_every=1_000_000))


def child(case: str, n: int, steps: int) -> dict:
    """Build and time one cell in this process (numba threads come from the environment)."""
    sys.path.insert(0, str(HERE))
    import numba

    from bench_engine import build_sim

    sim = build_sim(case, "batched", n) if case == "swarm" else laser_arena_sim(n)
    for _ in range(3):
        sim.step()
    t0, c0 = time.perf_counter(), time.process_time()
    sim.run(steps)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return {"case": case, "robots": n, "steps": steps, "threads": numba.get_num_threads(), "seconds": wall,
            "robot_steps_per_s": n * steps / wall, "robot_steps_per_cpu_s": n * steps / cpu,
            "realtime": steps * DT_S / wall, "realtime_cpu": steps * DT_S / cpu, "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def run_child(case: str, n: int, steps: int, threads: int) -> dict:
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", f"{case}-{n}-{steps}"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=3600)
    if r.returncode != 0:
        raise SystemExit(f"bench_scale: {case} N={n} threads={threads} failed:\n{r.stderr[-2000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def run_argos(bdir: Path, n: int, steps: int, threads: int) -> dict | None:
    exe = bdir / "core" / "argos3"
    if not exe.exists():
        return None
    cmd = [sys.executable, str(HERE / "peers" / "argos_peer.py"), "run", "--robots", str(n), "--steps", str(steps),
           "--threads", str(0 if threads <= 1 else threads), "--build-dir", str(bdir)]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=7200)
    if r.returncode != 0:
        print(f"  ! ARGoS N={n} failed:\n{r.stderr[-1500:]}", file=sys.stderr)
        return None
    res = json.loads(r.stdout.strip().splitlines()[-1])
    res["realtime"] = res["steps"] * DT_S / res["seconds"]
    return res


def _f(v: float | None, fmt: str = ",.0f") -> str:
    return "not measured" if v is None else format(v, fmt)


def _x(v: float | None, fmt: str) -> str:
    return "—" if v is None else format(v, fmt) + "×"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer steps")
    ap.add_argument("--robots", default="100,1000,10000", help="comma list of team sizes")
    ap.add_argument("--cases", default="swarm,laser", help="comma list of swarm, laser")
    ap.add_argument("--threads", default="1,2", help="comma list of thread counts")
    ap.add_argument("--argos-build", type=Path,
                    default=Path(os.environ.get("TEAMNAV_BENCH_ARGOS_BUILD", "/tmp/argos3-build")))
    ap.add_argument("--no-peers", action="store_true", help="measure teamnav only")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        case, n, steps = a.child.split("-")
        print(json.dumps(child(case, int(n), int(steps))))
        return 0
    try:
        sizes = [int(s) for s in a.robots.split(",") if s]
        threads = [int(t) for t in a.threads.split(",") if t]
    except ValueError:
        raise SystemExit(f"--robots and --threads must be comma lists of integers, got {a.robots!r}, {a.threads!r}")
    if any(n < 1 for n in sizes) or any(t < 1 for t in threads):
        raise SystemExit(f"--robots and --threads must be >= 1, got {a.robots!r}, {a.threads!r}")
    cases = [c for c in a.cases.split(",") if c]
    for c in cases:
        if c not in ("swarm", "laser"):
            raise SystemExit(f"--cases must list 'swarm' and/or 'laser', got {c!r}")
    mode = "quick" if a.quick else "full"
    have_argos = not a.no_peers and (a.argos_build / "core" / "argos3").exists()
    print(f"teamnav scale benchmark ({mode}); {os.cpu_count()} cpus, load average {os.getloadavg()[0]:.1f}")
    if "swarm" in cases and not a.no_peers and not have_argos:
        print(f"ARGoS not found in {a.argos_build}: build it with benchmarks/peers/argos_peer.py build "
              "(see its docstring); marked 'not measured'.")
    rows = []
    for case in cases:
        for n in sizes:
            for t in threads:
                steps = _steps(mode, n)
                res = run_child(case, n, steps, t)
                peer = run_argos(a.argos_build, n, steps, t) if case == "swarm" and have_argos else None
                rows.append((case, n, t, res, peer))
                print(f"  {case:5s} N={n:6d} threads={t}: teamnav {res['robot_steps_per_s']:>12,.0f} robot-steps/s "
                      f"({res['realtime']:.2f}x real time, {res['realtime_cpu']:.2f}x by CPU time, "
                      f"{res['peak_rss_mb']:.0f} MB)"
                      + (f"; ARGoS {peer['robot_steps_per_s']:>10,.0f} ({peer['realtime']:.2f}x, "
                         f"{peer['peak_rss_mb']:.0f} MB, start-up {peer['startup_s']:.1f} s)" if peer else ""),
                      flush=True)
    print("\n| case | robots | threads | teamnav robot-steps/s | × real time | peak MB | ARGoS robot-steps/s | "
          "× real time | peak MB | speed teamnav / ARGoS | memory teamnav / ARGoS |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for case, n, t, res, peer in rows:
        p = peer or {}
        sp = res["robot_steps_per_s"] / p["robot_steps_per_s"] if peer else None
        mem = res["peak_rss_mb"] / p["peak_rss_mb"] if peer else None
        print(f"| {case} | {n} | {t} | {res['robot_steps_per_s']:,.0f} | {res['realtime']:.2f} | "
              f"{res['peak_rss_mb']:.0f} | {_f(p.get('robot_steps_per_s'))} | {_f(p.get('realtime'), '.2f')} | "
              f"{_f(p.get('peak_rss_mb'))} | {_x(sp, '.1f')} | {_x(mem, '.2f')} |")
    print("\n(wall clock, one run per cell after 3 warm-up steps; ARGoS: its start-up subtracted, best of 2)")
    by = {(c, n, t): (r, p) for c, n, t, r, p in rows}
    print()
    for (c, n, t), (r, p) in sorted(by.items()):
        print(f"{c}_{n}_{t}t_realtime: {r['realtime']:.3f}")
        print(f"{c}_{n}_{t}t_realtime_cpu: {r['realtime_cpu']:.3f}")
        print(f"{c}_{n}_{t}t_peak_mb: {r['peak_rss_mb']:.0f}")
        if p:
            print(f"{c}_{n}_{t}t_speed_vs_argos: {r['robot_steps_per_s'] / p['robot_steps_per_s']:.2f}")
            print(f"{c}_{n}_{t}t_memory_vs_argos: {r['peak_rss_mb'] / p['peak_rss_mb']:.2f}")
    for c in cases:
        one, two = by.get((c, max(sizes), 1)), by.get((c, max(sizes), 2))
        if one and two:
            print(f"{c}_{max(sizes)}_threads_gain: {two[0]['robot_steps_per_s'] / one[0]['robot_steps_per_s']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
