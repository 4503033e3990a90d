"""Engine benchmark: robot-steps per second of teamnav beside IR-SIM and Enki, measured in one run.

Usage::

    python benchmarks/bench_engine.py [--quick] [--cases laser,swarm] [--robots 10,100,1000]
                                      [--irsim-python PATH] [--enki-python PATH] [--threads N]
                                      [--profile CASE] [--baseline-src DIR [--rounds K]] [--steps K]

(a) ``laser``: N robots with a 180-beam, 10 m laser on the MIT basement map (0.05 m/px),
    wandering: teamnav's per-robot ``wander-v1`` (a Python Controller per robot) and batched
    ``wander-batched-v1`` (one kernel call per step), beside IR-SIM
    (``benchmarks/peers/irsim_peer.py``; same PNG, lidar, robot radius and step).
(b) ``swarm``: N robots with 7 short-range proximity rays (ProximityConfig defaults: 14 cm) in
    a walled square arena of side 1 m x sqrt(N), beside Enki's Thymio II
    (``benchmarks/peers/enki_peer.py``). Its per-robot Python rows: ``wander-v1`` (form
    ``python``) and Enki's own Python ``Avoider`` rule as a teamnav brain (form ``avoider``,
    ``benchmarks/swarm_avoider.py``, loaded as an outside brain is), compared with Enki's Python
    controllers by CPU time: the same rule on both sides.

Peers run as subprocesses in their own interpreters, found by ``--irsim-python`` /
``$TEAMNAV_BENCH_IRSIM_PYTHON`` (default ``/tmp/irsim-venv/bin/python``) and ``--enki-python``
/ ``$TEAMNAV_BENCH_ENKI_PYTHON`` (default ``/usr/bin/python3``); a missing peer is reported
with how to install it and marked "not measured". teamnav runs in this interpreter: the
simulation is built, stepped ``warmup`` times (JIT compilation excluded), then timed over a
fixed number of steps, best of ``repeats``. ``--profile laser-batched-1000`` (any
case-form-N) prints a cProfile of that run's timed steps instead.

``--baseline-src DIR`` also times another tree's engine (``DIR`` is its ``src`` folder, e.g.
``git archive HEAD~1 src | tar -x -C /tmp/base`` then ``/tmp/base/src``) on the same cells in
the same run: each round times the baseline and this tree, each in a fresh subprocess
(``--measure-one``), ``--rounds`` times alternating, and prints the best of each with the ratio
and the CPU time per step (the fair reading on a shared machine; with ``--threads 1`` CPU
time is the step's own). ``--steps K`` times ``K`` steps per repeat instead of the plan's
count (which falls to one step at 10 000 robots): e.g. ``--robots 10000 --steps 20``.
"""

from __future__ import annotations

import argparse
import cProfile
import json
import math
import os
import pstats
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
PEERS = ROOT / "benchmarks" / "peers"
BASEMENT = ROOT / "src" / "teamnav" / "world" / "maps" / "mit" / "basement_hallways_5cm.png"
IRSIM_INSTALL = "python -m venv /tmp/irsim-venv && /tmp/irsim-venv/bin/pip install ir-sim"
ENKI_INSTALL = "apt-get install -y python3-enki2   (Debian's /usr/bin/python3 then has pyenki)"


@dataclass
class Plan:
    """Step counts for one mode (full or --quick)."""

    teamnav_steps: dict[int, int]
    teamnav_repeats: int
    warmup: int
    irsim_steps: dict[int, int]
    enki_steps: dict[int, int]
    peer_repeats: int


FULL = Plan({10: 500, 100: 200, 1000: 50}, 3, 5, {10: 30, 100: 6, 1000: 2}, {10: 1000, 100: 300, 1000: 50}, 3)
QUICK = Plan({10: 100, 100: 40, 1000: 10}, 2, 3, {10: 10, 100: 2, 1000: 1}, {10: 200, 100: 60, 1000: 10}, 2)


def _steps(table: dict[int, int], n: int) -> int:
    if n in table:
        return table[n]
    return max(1, int(table[10] * 10 / n))


# ------------------------------------------------------------------------------ teamnav side
def swarm_arena(n_robots: int, resolution_m: float = 0.02):
    """A walled square arena of side 1 m x sqrt(N) (walls one cell thick, outside the side)."""
    from teamnav.world.grid import WALL, OccupancyGrid

    side_m = math.sqrt(n_robots) * 1.0
    cells_side = int(round(side_m / resolution_m)) + 2
    cells = np.zeros((cells_side, cells_side), np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = WALL
    return OccupancyGrid(cells, resolution_m, (-resolution_m, -resolution_m), name=f"arena-{side_m:.1f}m")


def build_sim(case: str, form: str, n: int, seed: int = 0):
    """A teamnav Simulation for one benchmark cell."""
    from teamnav.sim.config import LaserConfig, ProximityConfig, RobotGroupConfig, SimConfig
    from teamnav.sim.engine import Simulation
    from teamnav.world.mapio import load_map

    controller = {"python": "wander-v1", "batched": "wander-batched-v1", "avoider": "swarm_avoider:Avoider"}[form]
    if form == "avoider" and case != "swarm":
        raise ValueError("the 'avoider' form (Enki's Python rule) is a swarm cell only")
    if case == "laser":
        grid = load_map(BASEMENT.with_suffix(".yaml"))
        group = RobotGroupConfig(count=n, radius_m=0.2, controller=controller,
                                 sensors=(LaserConfig(n_beams=180, fov_deg=180.0, max_range_m=10.0),))
    else:
        grid = swarm_arena(n)
        # Thymio-sized: radius 8 cm, 0.2 m/s; the wanderer caps its thresholds to the 14 cm range.
        group = RobotGroupConfig(count=n, radius_m=0.08, max_v_mps=0.2, controller=controller,
                                 params={} if form == "avoider" else {"cruise_speed_mps": 0.15},
                                 sensors=(ProximityConfig(),))
    cfg = SimConfig(robots=(group,), seed=seed, record_every=1_000_000)
    return Simulation(grid, cfg)


def _positions(sim) -> np.ndarray:
    return np.stack([np.asarray(sim.state.x_m, float).copy(), np.asarray(sim.state.y_m, float).copy()], axis=1)


def measure_teamnav(case: str, form: str, n: int, steps: int, warmup: int, repeats: int) -> dict:
    sim = build_sim(case, form, n)
    start = _positions(sim)
    for _ in range(warmup):
        sim.step()
    best = cpu = math.inf
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        sim.run(steps)
        best = min(best, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    moved = float(np.mean(np.hypot(*(_positions(sim) - start).T)))
    return {"robot_steps_per_s": n * steps / best, "seconds": best, "steps": steps, "mean_displacement_m": moved,
            "robot_steps_per_cpu_s": n * steps / cpu}


def measure_cpu(case: str, form: str, n: int, steps: int, warmup: int, repeats: int) -> dict:
    """:func:`measure_teamnav` plus the best CPU seconds per step (``time.process_time``)."""
    sim = build_sim(case, form, n)
    for _ in range(warmup):
        sim.step()
    wall = cpu = math.inf
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        sim.run(steps)
        wall = min(wall, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    return {"robot_steps_per_s": n * steps / wall, "wall_ms_per_step": wall / steps * 1e3,
            "cpu_ms_per_step": cpu / steps * 1e3, "steps": steps}


def compare_baseline(src: str, cells: list[tuple[str, str, int]], plan: Plan, threads: int | None, rounds: int,
                     steps: int | None = None) -> None:
    """Time ``cells`` with the engine of source folder ``src`` and with this tree, alternating,
    each round in fresh subprocesses; print the best of each and the ratio."""
    src_dir = Path(src).resolve()
    if not (src_dir / "teamnav" / "__init__.py").exists():
        raise SystemExit(f"--baseline-src must be a folder holding teamnav/ (a tree's src), got {src!r}")
    here = ROOT / "src"

    def one(path: Path, spec: str) -> dict:
        env = dict(os.environ, PYTHONPATH=str(path) + os.pathsep + os.environ.get("PYTHONPATH", ""))
        cmd = [sys.executable, str(Path(__file__).resolve()), "--measure-one", spec]
        if threads is not None:
            cmd += ["--threads", str(threads)]
        if plan is QUICK:
            cmd.append("--quick")
        if steps is not None:
            cmd += ["--steps", str(steps)]
        r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=1800)
        if r.returncode != 0:
            raise SystemExit(f"--measure-one {spec} under {path} failed:\n{r.stderr[-2000:]}")
        return json.loads(r.stdout.strip().splitlines()[-1])

    print(f"\n### this tree ({here}) against the baseline ({src_dir}), same run, {rounds} rounds alternating "
          f"(load average {os.getloadavg()[0]:.1f} at the start)\n")
    print("| cell | baseline cpu ms/step | this tree cpu ms/step | speed-up (cpu) | baseline robot-steps/s | "
          "this tree robot-steps/s | speed-up (wall) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for case, form, n in cells:
        spec = f"{case}-{form}-{n}"
        best = {"base": None, "new": None}
        for _ in range(rounds):
            for tag, path in (("base", src_dir), ("new", here)):
                res = one(path, spec)
                cur = best[tag]
                best[tag] = res if cur is None else {
                    "cpu_ms_per_step": min(cur["cpu_ms_per_step"], res["cpu_ms_per_step"]),
                    "robot_steps_per_s": max(cur["robot_steps_per_s"], res["robot_steps_per_s"])}
        b, w = best["base"], best["new"]
        print(f"| {spec} | {b['cpu_ms_per_step']:.2f} | {w['cpu_ms_per_step']:.2f} | "
              f"{b['cpu_ms_per_step'] / w['cpu_ms_per_step']:.2f}× | {b['robot_steps_per_s']:,.0f} | "
              f"{w['robot_steps_per_s']:,.0f} | {w['robot_steps_per_s'] / b['robot_steps_per_s']:.2f}× |", flush=True)
    print(f"\n(load average {os.getloadavg()[0]:.1f} at the end)")


def profile_teamnav(spec: str, steps: int) -> None:
    case, form, n = spec.split("-")
    sim = build_sim(case, form, int(n))
    for _ in range(5):
        sim.step()
    prof = cProfile.Profile()
    t0 = time.perf_counter()
    prof.enable()
    sim.run(steps)
    prof.disable()
    dt = time.perf_counter() - t0
    print(f"profile {spec}: {steps} steps in {dt:.3f} s = {dt / steps * 1e6:.0f} us/step "
          f"({int(n) * steps / dt:,.0f} robot-steps/s); per-call times below are per step when ncalls == steps")
    st = pstats.Stats(prof)
    st.sort_stats("tottime").print_stats(25)


# ------------------------------------------------------------------------------ peers
def _peer_ok(python: str, module: str) -> bool:
    if not (Path(python).exists() or shutil_which(python)):
        return False
    r = subprocess.run([python, "-c", f"import {module}"], capture_output=True, timeout=120)
    return r.returncode == 0


def shutil_which(cmd: str) -> str | None:
    import shutil

    return shutil.which(cmd)


def run_peer(python: str, script: str, n: int, steps: int, repeats: int, timeout_s: float) -> dict | None:
    cmd = [python, str(PEERS / script), "--robots", str(n), "--steps", str(steps), "--repeats", str(repeats)]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s)
    except subprocess.TimeoutExpired:
        print(f"  ! {script} --robots {n} timed out after {timeout_s:.0f} s", file=sys.stderr)
        return None
    if r.returncode != 0:
        print(f"  ! {script} --robots {n} failed:\n{r.stderr[-2000:]}", file=sys.stderr)
        return None
    return json.loads(r.stdout.strip().splitlines()[-1])


# ------------------------------------------------------------------------------ report
def _fmt(v: float | None) -> str:
    return "not measured" if v is None else f"{v:,.0f}"


def _ratio(a: float | None, b: float | None) -> str:
    return "—" if a is None or b is None or b == 0 else f"{a / b:,.1f}×"


def print_table(title: str, peer: str, rows: list[dict], targets: dict[int, str]) -> None:
    print(f"\n### {title}\n")
    print(f"| robots | teamnav per-robot Python | teamnav batched | {peer} | batched / {peer} | Python / {peer} | target |")
    print("|---:|---:|---:|---:|---:|---:|---|")
    for r in rows:
        print(f"| {r['n']} | {_fmt(r.get('python'))} | {_fmt(r.get('batched'))} | {_fmt(r.get('peer'))} | "
              f"{_ratio(r.get('batched'), r.get('peer'))} | {_ratio(r.get('python'), r.get('peer'))} | "
              f"{targets.get(r['n'], '')} |")
    print("\n(robot-steps per second, best of repeats, JIT warm-up excluded)")
    if any("avoider" in r for r in rows):
        print(f"\n#### the same Python rule on both sides (Enki's Avoider; benchmarks/swarm_avoider.py), CPU time\n")
        print(f"| robots | teamnav per-robot Python, robot-steps per CPU-s | {peer} Python, per CPU-s | teamnav / {peer} | "
              f"teamnav wander-v1 (per-robot Python), per CPU-s | wander-v1 / {peer} | target |")
        print("|---:|---:|---:|---:|---:|---:|---|")
        for r in rows:
            if "avoider" in r:
                print(f"| {r['n']} | {_fmt(r['avoider_cpu'])} | {_fmt(r.get('peer_cpu'))} | "
                      f"{_ratio(r['avoider_cpu'], r.get('peer_cpu'))} | {_fmt(r.get('python_cpu'))} | "
                      f"{_ratio(r.get('python_cpu'), r.get('peer_cpu'))} | ≥ 2× |")
        print("\n(CPU time of the stepping loop, best of repeats: a fair reading on a shared machine)")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer steps and repeats")
    ap.add_argument("--cases", default="laser,swarm", help="comma list of laser, swarm")
    ap.add_argument("--robots", default="10,100,1000", help="comma list of team sizes")
    ap.add_argument("--forms", default="python,avoider,batched",
                    help="comma list of python (wander-v1), avoider (Enki's Python rule, swarm only), batched")
    ap.add_argument("--irsim-python", default=os.environ.get("TEAMNAV_BENCH_IRSIM_PYTHON", "/tmp/irsim-venv/bin/python"))
    ap.add_argument("--enki-python", default=os.environ.get("TEAMNAV_BENCH_ENKI_PYTHON", "/usr/bin/python3"))
    ap.add_argument("--no-peers", action="store_true", help="measure teamnav only")
    ap.add_argument("--threads", type=int, default=None,
                    help="numba threads for teamnav's parallel kernels (default: numba's, all cores)")
    ap.add_argument("--profile", metavar="CASE-FORM-N", help="cProfile one teamnav cell, e.g. swarm-batched-1000")
    ap.add_argument("--baseline-src", metavar="DIR",
                    help="also time the engine of this src folder (another commit's tree) on the same cells, "
                         "alternating")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds of --baseline-src (default 3)")
    ap.add_argument("--steps", type=int, default=None,
                    help="timed steps per repeat of every teamnav cell (default: the plan's, 1 at 10 000 robots)")
    ap.add_argument("--measure-one", metavar="CASE-FORM-N", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    plan = QUICK if a.quick else FULL
    sizes = [int(s) for s in a.robots.split(",") if s]
    cases = [c for c in a.cases.split(",") if c]
    forms = [f for f in a.forms.split(",") if f]
    for c in cases:
        if c not in ("laser", "swarm"):
            raise SystemExit(f"--cases must list 'laser' and/or 'swarm', got {c!r}")
    for f in forms:
        if f not in ("python", "avoider", "batched"):
            raise SystemExit(f"--forms must list 'python', 'avoider' and/or 'batched', got {f!r}")
    if a.steps is not None and a.steps < 1:
        raise SystemExit(f"--steps must be >= 1, got {a.steps}")

    def steps_for(n: int) -> int:
        return a.steps if a.steps is not None else _steps(plan.teamnav_steps, n)

    if any(n < 1 for n in sizes):
        raise SystemExit(f"--robots must list positive team sizes, got {a.robots!r}")
    if a.threads is not None:
        if a.threads < 1:
            raise SystemExit(f"--threads must be >= 1, got {a.threads}")
        import numba

        numba.set_num_threads(min(a.threads, numba.config.NUMBA_NUM_THREADS))
    if a.profile:
        n = int(a.profile.rsplit("-", 1)[1])
        profile_teamnav(a.profile, steps_for(n))
        return 0
    if a.measure_one:
        case, form, n = a.measure_one.split("-")
        print(json.dumps(measure_cpu(case, form, int(n), steps_for(int(n)), plan.warmup,
                                     plan.teamnav_repeats)))
        return 0

    peers = {
        "laser": ("IR-SIM", a.irsim_python, "irsim", "irsim_peer.py", IRSIM_INSTALL, plan.irsim_steps,
                  {10: "batched ≥ 200×", 1000: "batched ≥ 1000×"}),
        "swarm": ("Enki", a.enki_python, "pyenki", "enki_peer.py", ENKI_INSTALL, plan.enki_steps,
                  {100: "batched ≥ 1×", 1000: "batched ≥ 5×"}),
    }
    print(f"teamnav engine benchmark ({'quick' if a.quick else 'full'}); python {sys.version.split()[0]}, "
          f"numpy {np.__version__}, {os.cpu_count()} cpus, load average {os.getloadavg()[0]:.1f}, "
          f"numba threads {a.threads or 'default'}")
    for case in cases:
        label, python, module, script, install, peer_steps, targets = peers[case]
        have_peer = not a.no_peers and _peer_ok(python, module)
        if not a.no_peers and not have_peer:
            print(f"\n{label} not found at {python} (no '{module}'): install it with\n    {install}\n"
                  f"or point --{'irsim' if case == 'laser' else 'enki'}-python at its interpreter; marked 'not measured'.")
        rows = []
        for n in sizes:
            row: dict = {"n": n}
            for form in forms:
                if form == "avoider" and case != "swarm":
                    continue
                res = measure_teamnav(case, form, n, steps_for(n), plan.warmup, plan.teamnav_repeats)
                row[form] = res["robot_steps_per_s"]
                row[f"{form}_cpu"] = res["robot_steps_per_cpu_s"]
                print(f"  {case:5s} teamnav {form:7s} N={n:5d}: {res['robot_steps_per_s']:>14,.0f} robot-steps/s "
                      f"({res['steps']} steps in {res['seconds']:.3f} s; mean displacement {res['mean_displacement_m']:.2f} m)",
                      flush=True)
            if have_peer:
                res = run_peer(python, script, n, _steps(peer_steps, n), plan.peer_repeats if case == "swarm" else 1,
                               timeout_s=900)
                if res is not None:
                    row["peer"] = res["robot_steps_per_s"]
                    row["peer_cpu"] = res.get("robot_steps_per_cpu_s")
                    print(f"  {case:5s} {label:15s} N={n:5d}: {res['robot_steps_per_s']:>14,.0f} robot-steps/s "
                          f"({res['steps']} steps in {res['seconds']:.3f} s; mean displacement "
                          f"{res.get('mean_displacement_m', float('nan')):.2f} m)", flush=True)
            rows.append(row)
        title = ("(a) laser robots, 180 beams / 10 m, MIT basement map" if case == "laser"
                 else "(b) swarm, 7 proximity rays / 14 cm, walled arena of side √N m")
        print_table(title, label, rows, targets)
    if a.baseline_src:
        if a.rounds < 1:
            raise SystemExit(f"--rounds must be >= 1, got {a.rounds}")
        compare_baseline(a.baseline_src, [(c, f, n) for c in cases for n in sizes for f in forms], plan, a.threads,
                         a.rounds, a.steps)
    return 0


if __name__ == "__main__":
    sys.exit(main())
