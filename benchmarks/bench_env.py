"""Environment benchmark: steps/s of ``teamnav.env`` beside the engine's own step, in one run.

Usage::

    python benchmarks/bench_env.py [--quick] [--agents 1,10,100] [--swarm 1000] [--steps N] [--repeats R]
                                   [--threads N] [--batched] [--copies C] [--vmas-python PATH]
                                   [--clock wall|cpu] [--env-from REV]

For N agents (robots of radius 0.2 m, unicycle, 180-beam 180° 8 m laser, σ = 1 cm) on the MIT
basement map (``mit/basement_hallways_5cm.yaml``, 60 m x 60 m at 5 cm), started at random over
the whole map, every robot drives a constant (v, ω) of its own. Measured, in this process:

- **engine**: ``Simulation.step()`` with a brain per robot that returns that constant action
  (:class:`ConstantDrive`, named as ``bench_env.py:ConstantDrive``): the same robots, the same
  motion, the same sensing, and the cheapest possible brain;
- **engine + wander-v1**: the same with the built-in ``wander-v1`` brain (a real rule);
- **ParallelEnv**: ``env.step(actions)`` with the same constant actions, an ``(2,)`` array per
  agent (observations encoded as Dict-of-Box arrays, rewards, PettingZoo dicts);
- **BatchedEnv** (``--batched``): 4 copies stepped in one call, per copy;
- **VMAS** (peer, a subprocess in its own interpreter: ``--vmas-python`` /
  ``$TEAMNAV_BENCH_VMAS_PYTHON``, default ``/tmp/vmas-venv/bin/python``; see
  ``benchmarks/peers/vmas_peer.py``): N agents with a 180-ray 8 m lidar in a 60 m square with
  40 boxes (VMAS has no grid maps), one environment, torch on the CPU with 1 thread. A missing
  peer is reported with its install command and marked "not measured".

**Swarm** (``--swarm N``, default 1000, 0 to skip): N robots of the built-in ``swarm`` scenario
(r = 0.08 m, 7-beam 0.14 m infrared proximity sensors, the 30 m walled arena), each driving a
constant (v, ω) within its limits: the engine with ``ConstantDrive`` per robot, the engine with
the scenario's own batched brain (``wander-batched-v1``, the engine's fastest path for these
robots: one array brain, no per-robot observation), and the ParallelEnv.

**Before / after** (``--env-from REV``): ``src/teamnav/env`` of git revision ``REV`` is copied
under another package name (``teamnav_env_<rev>``, its own imports rewritten) into a temporary
folder and timed as one more ParallelEnv variant, "env @ REV", beside today's, on the same
engine, in the same rounds.

Each is built, stepped ``warmup`` times (numba kernels loaded, caches warm), then timed over
``steps`` steps, best of ``repeats`` (``time.perf_counter``). Recording is left as the
scenario has it (``record_every`` 10). Reported: steps/s, agent-steps/s and the ratio of the
env's time per step to the engine's (goal ≤ 1.5x).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve()
VMAS_PEER = HERE.parent / "peers" / "vmas_peer.py"
VMAS_INSTALL = ("python -m venv /tmp/vmas-venv && /tmp/vmas-venv/bin/pip install torch==2.13.0 && "
                "/tmp/vmas-venv/bin/pip install vmas")


def vmas(python: str, n: int, steps: int, repeats: int, num_envs: int = 1) -> float | None:
    """VMAS agent-steps per second for ``n`` agents in ``num_envs`` environments, or None when not installed."""
    if not Path(python).exists():
        return None
    out = subprocess.run([python, str(VMAS_PEER), "--agents", str(n), "--steps", str(steps), "--repeats", str(repeats),
                          "--num-envs", str(num_envs)],
                         capture_output=True, text=True, timeout=1800)
    lines = [ln for ln in out.stdout.splitlines() if ln.startswith("{")]
    if out.returncode != 0 or not lines:
        print(f"VMAS peer failed: {out.stderr.strip().splitlines()[-1:] or out.returncode}", file=sys.stderr)
        return None
    return float(json.loads(lines[-1])["agent_steps_per_s"])


class ConstantDrive:
    """A brain that drives a constant (v, ω) drawn once from its own stream (the engine baseline)."""

    from teamnav.control.protocol import NoParams as Params  # noqa: N811

    def __init__(self, params, rng, info) -> None:
        from teamnav.control.types import Action

        v, w = _constant(info.robot_id)
        self.out = (Action(v, w), [])

    def step(self, obs):
        return self.out


def _constant(i: int, arena: str = "basement") -> tuple[float, float]:
    """Robot i's constant command (the same in the engine and the env runs), within its limits."""
    rng = np.random.default_rng(1000 + i)
    v, w = float(rng.uniform(0.1, 0.4)), float(rng.uniform(-0.5, 0.5))
    return (v / 2, w) if arena == "swarm" else (v, w)  # swarm robots: max_v 0.2 m/s


class ConstantDriveSwarm(ConstantDrive):
    """:class:`ConstantDrive` with the swarm robots' commands."""

    def __init__(self, params, rng, info) -> None:
        from teamnav.control.types import Action

        self.out = (Action(*_constant(info.robot_id, "swarm")), [])


def _overrides(n: int, controller: str) -> dict:
    return {
        "name": "bench-env",
        "robots": [{
            "name": "bot", "count": n, "radius_m": 0.2, "max_v_mps": 0.5, "max_omega_degps": 90,
            "controller": controller, "params": {},
            "sensors": [{"kind": "laser", "n_beams": 180, "fov_deg": 180, "max_range_m": 8.0, "noise_std_m": 0.01}],
            "odometry": {"alpha": [0.02, 0.01, 0.02, 0.01]},
        }],
        "radio": {"mode": "range", "range_m": 10.0},
        "places": [],
        "metrics": ["steps"],
    }


def _scenario(n: int, controller: str, seed: int = 1, arena: str = "basement"):
    from teamnav import load_scenario

    if arena == "swarm":  # the built-in swarm, n robots, a brain of our choice
        return load_scenario("swarm", overrides={"robots.0.count": n, "robots.0.controller": controller,
                                                 "robots.0.params": {}}, seed=seed, duration_s=1e6)
    return load_scenario("demo", overrides=_overrides(n, controller), seed=seed, duration_s=1e6)


def _build_engine(n: int, controller: str, warmup: int, arena: str = "basement"):
    from teamnav.experiments.spec import build_grid
    from teamnav.sim.engine import Simulation

    scn = _scenario(n, controller, arena=arena)
    sim = Simulation(build_grid(scn), scn)
    for _ in range(warmup):
        sim.step()
    return sim.step


def _env_from(rev: str):
    """The ParallelEnv class of ``src/teamnav/env`` at git revision ``rev``, as its own package."""
    import importlib
    import re
    import tempfile

    root = HERE.parents[1]
    sha = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", rev], capture_output=True, text=True,
                         check=True).stdout.strip()
    name = f"teamnav_env_{sha}"
    folder = Path(tempfile.mkdtemp(prefix="bench_env_")) / name
    folder.mkdir()
    files = subprocess.run(["git", "-C", str(root), "ls-tree", "--name-only", sha, "src/teamnav/env/"],
                           capture_output=True, text=True, check=True).stdout.split()
    for f in files:
        text = subprocess.run(["git", "-C", str(root), "show", f"{sha}:{f}"], capture_output=True, text=True,
                              check=True).stdout
        (folder / Path(f).name).write_text(re.sub(r"teamnav\.env\b", name, text))
    sys.path.insert(0, str(folder.parent))
    return importlib.import_module(name).ParallelEnv


def _build_parallel(n: int, warmup: int, arena: str = "basement", cls=None):
    from teamnav.env import ParallelEnv

    env = (cls or ParallelEnv)(_scenario(n, "idle-v1", arena=arena))
    env.reset(seed=1)
    actions = {a: np.array(_constant(i, arena)) for a, i in env.robot_ids.items()}
    for _ in range(warmup):
        env.step(actions)
    return lambda: env.step(actions)


def _build_batched(n: int, copies: int, warmup: int):
    from teamnav.env import BatchedEnv

    env = BatchedEnv(_scenario(n, "idle-v1"), copies)
    env.reset(seed=1)
    ids = env.setup.agent_ids.tolist()
    actions = np.broadcast_to(np.array([_constant(i) for i in ids]), (copies, len(ids), 2)).copy()
    for _ in range(warmup):
        env.step(actions)
    return lambda: env.step(actions)


#: the clock of the timings: wall (``time.perf_counter``) or the process's CPU time
#: (``time.process_time``, every thread's; ``--clock cpu``: on a shared, loaded machine a step
#: is not charged for the time the process waits for a core)
CLOCK = {"wall": time.perf_counter, "cpu": time.process_time}
_clock = time.perf_counter


def _time(fn, steps: int) -> float:
    t0 = _clock()
    for _ in range(steps):
        fn()
    return (_clock() - t0) / steps


def measure(n: int, steps: int, repeats: int, warmup: int, batched: int = 0, arena: str = "basement",
            before=None) -> dict[str, float]:
    """Best seconds per step of each variant; the variants take turns, round after round, so
    a change of load on the machine hits them alike."""
    if arena == "swarm":
        fns = {
            "engine": _build_engine(n, "bench_env:ConstantDriveSwarm", warmup, arena),
            "wander": _build_engine(n, "wander-batched-v1", warmup, arena),
            "env": _build_parallel(n, warmup, arena),
        }
    else:
        fns = {
            "engine": _build_engine(n, "bench_env:ConstantDrive", warmup),
            "wander": _build_engine(n, "wander-v1", warmup),
            "env": _build_parallel(n, warmup),
        }
    if batched:
        fns["batched"] = _build_batched(n, batched, warmup)
    if before is not None:
        fns["before"] = _build_parallel(n, warmup, arena, before)
    best = {k: float("inf") for k in fns}
    for _ in range(repeats):
        for k, fn in fns.items():
            t = _time(fn, max(5, steps // batched) if k == "batched" else steps)
            best[k] = min(best[k], t / batched if k == "batched" else t)
    return best


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer steps and repeats")
    ap.add_argument("--agents", default="1,10,100", help="comma-separated agent counts (basement, lasers); '' for none")
    ap.add_argument("--swarm", type=int, default=1000, help="robots in the swarm arena row (0: no swarm row)")
    ap.add_argument("--steps", type=int, help="timed steps per repeat (default: per size)")
    ap.add_argument("--repeats", type=int, help="timings per cell, best kept (default 5, quick 2)")
    ap.add_argument("--clock", choices=sorted(CLOCK), default="wall",
                    help="wall: perf_counter (default); cpu: the process's CPU time (all threads), for a loaded machine")
    ap.add_argument("--env-from", metavar="REV", help="also time the ParallelEnv of git revision REV (before / after)")
    ap.add_argument("--threads", type=int, help="numba threads (NUMBA_NUM_THREADS must be set before import)")
    ap.add_argument("--batched", action="store_true", help="also time BatchedEnv (--copies copies) beside VMAS with as many environments")
    ap.add_argument("--copies", type=int, default=4, help="copies of the batched env and VMAS environments (default 4)")
    ap.add_argument("--vmas-python", default=os.environ.get("TEAMNAV_BENCH_VMAS_PYTHON", "/tmp/vmas-venv/bin/python"),
                    help="interpreter with vmas installed (the peer)")
    args = ap.parse_args(argv)
    global _clock
    _clock = CLOCK[args.clock]
    if args.threads:
        import numba

        numba.set_num_threads(args.threads)
    sys.path.insert(0, str(HERE.parent))  # so `bench_env:ConstantDrive` imports as a module
    sizes = [int(x) for x in args.agents.split(",") if x.strip()]
    before = _env_from(args.env_from) if args.env_from else None
    repeats = args.repeats or (3 if args.quick else 9)
    warmup = 20
    print(f"teamnav.env benchmark: basement map, 180-beam laser, constant actions; best of {repeats}; "
          f"{args.clock} clock; {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}")
    head = "| agents | engine steps/s | engine + wander-v1 steps/s | env steps/s | env agent-steps/s | env / engine (time per step) | env / engine + wander-v1 |"
    if args.batched:
        head += f" batched env agent-steps/s ({args.copies} copies) |"
    have_vmas = Path(args.vmas_python).exists()
    head += " VMAS agent-steps/s (1 env, CPU) | env / VMAS (agent-steps/s) |"
    if not have_vmas:
        print(f"VMAS not measured: no {args.vmas_python}; install with: {VMAS_INSTALL}")
    print(head)
    print("|" + "---:|" * (head.count("|") - 1))
    for n in sizes:
        steps = args.steps or max(20, int((300 if args.quick else 1000) / max(1.0, n ** 0.8)))
        t = measure(n, steps, repeats, warmup, args.copies if args.batched else 0, before=before)
        row = (f"| {n} | {1 / t['engine']:,.0f} | {1 / t['wander']:,.0f} | {1 / t['env']:,.0f} | {n / t['env']:,.0f} | "
               f"{t['env'] / t['engine']:.2f}x | {t['env'] / t['wander']:.2f}x |")
        if args.batched:
            row += f" {n / t['batched']:,.0f} |"
        v = vmas(args.vmas_python, n, max(3, min(50, 300 // n)), 2 if args.quick else 3) if have_vmas else None
        row += f" {v:,.0f} | {n / t['env'] / v:,.0f}x |" if v else " not measured | — |"
        print(row, flush=True)
        if before is not None:
            print(f"  env @ {args.env_from}: {t['before'] * 1e6:,.1f} us/step, {t['before'] / t['engine']:.2f}x the engine; "
                  f"now {t['env'] * 1e6:,.1f} us/step, {t['env'] / t['engine']:.2f}x", flush=True)
        if args.batched and have_vmas:
            vb = vmas(args.vmas_python, n, max(3, min(20, 60 // n)), 2 if args.quick else 3, args.copies)
            if vb:
                print(f"  batched, {n} agents x {args.copies} copies: teamnav {n / t['batched']:,.0f} agent-steps/s, "
                      f"VMAS ({args.copies} envs, CPU) {vb:,.0f}: {n / t['batched'] / vb:,.1f}x", flush=True)
    if args.swarm:
        n = args.swarm
        t = measure(n, args.steps or (20 if args.quick else 60), repeats, warmup, arena="swarm", before=before)
        print(f"\nswarm arena, {n} robots (7-beam infrared proximity), load average {os.getloadavg()[0]:.2f}:\n"
              f"| robots | engine steps/s | engine + wander-batched-v1 steps/s | env steps/s | env agent-steps/s | "
              f"env / engine (time per step) | env / engine + wander-batched-v1 |\n|---:|---:|---:|---:|---:|---:|---:|\n"
              f"| {n} | {1 / t['engine']:,.1f} | {1 / t['wander']:,.1f} | {1 / t['env']:,.1f} | {n / t['env']:,.0f} | "
              f"{t['env'] / t['engine']:.2f}x | {t['env'] / t['wander']:.2f}x |", flush=True)
        if before is not None:
            print(f"  env @ {args.env_from}: {t['before'] * 1e3:,.2f} ms/step, {t['before'] / t['engine']:.2f}x the engine; "
                  f"now {t['env'] * 1e3:,.2f} ms/step, {t['env'] / t['engine']:.2f}x", flush=True)


if __name__ == "__main__":
    main()
