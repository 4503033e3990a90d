"""ARGoS 3 peer for benchmarks/bench_engine.py: the foot-bot diffusion swarm, headless.

ARGoS 3 (Pinciroli et al. 2012, github.com/ilpincy/argos3) is the multi-robot simulator that
swarm researchers measure themselves against. This script builds it from source (the foot-bot
only, no Qt, no Lua, no documentation) and runs its own example controller,
``footbot_diffusion`` (github.com/ilpincy/argos3-examples: go straight, turn away when the 24
proximity rays see something within the ``delta`` threshold), in the arena teamnav's swarm
case uses: a walled square of side 1 m x sqrt(N), N foot-bots placed uniformly at random,
10 ticks per second, the 2-D dynamics engine (``dynamics2d``).

Build once (3-13 minutes on 2 cores; needs cmake and g++, nothing else)::

    git clone https://github.com/ilpincy/argos3 /tmp/argos3-src            # tested at 421bd76 (2025-03-10)
    git clone https://github.com/ilpincy/argos3-examples /tmp/argos3-examples
    python benchmarks/peers/argos_peer.py build --src /tmp/argos3-src \\
        --examples /tmp/argos3-examples --build-dir /tmp/argos3-build

Measure (one JSON line: robot-steps per second by wall and CPU clock, peak memory)::

    python benchmarks/peers/argos_peer.py run --robots 1000 --steps 50 --threads 2

How it is timed: ``argos3`` is a separate process whose start (loading plug-ins, parsing the
XML, placing N robots without overlap) can take longer than the steps themselves at N = 10 000.
So each repeat runs the experiment twice, for ``warmup`` ticks and for ``warmup + steps`` ticks,
and the steps cost the difference (wall clock, and the child's user + system CPU time from
``os.wait4``); the best of ``repeats`` of each is kept. Peak memory is the child's ``ru_maxrss``
of the longer run: the whole simulator, as ``/usr/bin/time`` would report it.

What differs from teamnav's swarm case (say so beside any ratio): the foot-bot has 24
proximity rays (teamnav 7, Enki's Thymio 7), a 2-D rigid-body engine with friction and
collision response (teamnav: kinematic discs against a distance field), and the diffusion
rule in C++ (teamnav's batched rule is a numba kernel, its per-robot rule Python).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: The robot plug-ins ARGoS builds; the rest (drone, builderbot, ...) are not needed here and
#: one of them ships large model files.
ROBOTS_CMAKE = "add_subdirectory(generic)\nadd_subdirectory(foot-bot)\n"
DEFAULT_BUILD = Path(os.environ.get("TEAMNAV_BENCH_ARGOS_BUILD", "/tmp/argos3-build"))
CONTROLLER_LIB = "libfootbot_diffusion.so"

EXPERIMENT = """<?xml version="1.0" ?>
<argos-configuration>
  <framework>
    <system threads="{threads}" />
    <experiment length="{length_s}" ticks_per_second="10" random_seed="{seed}" />
  </framework>
  <controllers>
    <footbot_diffusion_controller id="fdc" library="{library}">
      <actuators><differential_steering implementation="default" /></actuators>
      <sensors><footbot_proximity implementation="default" show_rays="false" /></sensors>
      <params alpha="7.5" delta="0.1" velocity="5" />
    </footbot_diffusion_controller>
  </controllers>
  <arena size="{arena}, {arena}, 1" center="0,0,0.5">
    <box id="wall_north" size="{side},0.1,0.5" movable="false"><body position="0,{wall},0" orientation="0,0,0" /></box>
    <box id="wall_south" size="{side},0.1,0.5" movable="false"><body position="0,-{wall},0" orientation="0,0,0" /></box>
    <box id="wall_east" size="0.1,{side},0.5" movable="false"><body position="{wall},0,0" orientation="0,0,0" /></box>
    <box id="wall_west" size="0.1,{side},0.5" movable="false"><body position="-{wall},0,0" orientation="0,0,0" /></box>
    <distribute>
      <position method="uniform" min="-{inner},-{inner},0" max="{inner},{inner},0" />
      <orientation method="uniform" min="0,0,0" max="360,0,0" />
      <entity quantity="{n}" max_trials="1000">
        <foot-bot id="fb"><controller config="fdc" /></foot-bot>
      </entity>
    </distribute>
  </arena>
  <physics_engines><dynamics2d id="dyn2d" /></physics_engines>
  <media />
</argos-configuration>
"""


def experiment_xml(n: int, ticks: int, threads: int, library: Path, seed: int = 124) -> str:
    """The diffusion experiment for ``n`` foot-bots, ``ticks`` ticks long, in the arena of teamnav's
    swarm case (side 1 m x sqrt(N), walls outside the side; robots at least a body radius, 0.085 m,
    from the walls)."""
    if n < 1 or ticks < 1:
        raise ValueError(f"robots and ticks must be >= 1, got {n} and {ticks}")
    side = math.sqrt(n)
    return EXPERIMENT.format(threads=threads, length_s=f"{ticks / 10:.1f}", seed=seed, library=library,
                             arena=f"{side + 2:.3f}", side=f"{side + 0.2:.3f}", wall=f"{side / 2 + 0.05:.3f}",
                             inner=f"{side / 2 - 0.1:.3f}", n=n)


def _run(cmd: list[str], cwd: Path | None = None, env: dict | None = None) -> None:
    print("+", " ".join(cmd), file=sys.stderr, flush=True)
    r = subprocess.run(cmd, cwd=cwd, env=env)
    if r.returncode != 0:
        raise SystemExit(f"argos_peer: {' '.join(cmd)} failed with exit status {r.returncode}")


#: What the benchmark needs of ARGoS: the simulator, its 2-D engine, the foot-bot and what it uses.
#: Building these targets only (not ``all``) skips the test programs and the 3-D engine's plug-ins
#: that link robots this build leaves out.
TARGETS = ("argos3", "argos3plugin_simulator_footbot", "argos3plugin_simulator_dynamics2d",
           "argos3plugin_simulator_media", "argos3plugin_simulator_entities", "argos3plugin_simulator_genericrobot")


def build(src: Path, examples: Path, bdir: Path, jobs: int) -> None:
    """Configure and build ARGoS (foot-bot only, headless) in ``bdir``, then the diffusion
    controller of argos3-examples against it; nothing is installed (runs use the build tree)."""
    robots = src / "src" / "plugins" / "robots" / "CMakeLists.txt"
    if not robots.exists():
        raise SystemExit(f"--src {src}: expected a checkout of github.com/ilpincy/argos3 (no {robots})")
    ctrl = examples / "controllers" / "footbot_diffusion" / "footbot_diffusion.cpp"
    if not ctrl.exists():
        raise SystemExit(f"--examples {examples}: expected a checkout of github.com/ilpincy/argos3-examples "
                         f"(no {ctrl})")
    if robots.read_text() != ROBOTS_CMAKE:
        robots.with_suffix(".txt.orig").write_text(robots.read_text())
        robots.write_text(ROBOTS_CMAKE)
    bdir.mkdir(parents=True, exist_ok=True)
    _run(["cmake", str(src / "src"), "-DCMAKE_BUILD_TYPE=Release", "-DARGOS_BUILD_FOR=simulator",
          "-DARGOS_DOCUMENTATION=OFF", "-DARGOS_INSTALL_LDSOCONF=OFF", "-DARGOS_BUILD_NATIVE=OFF",
          f"-DCMAKE_INSTALL_PREFIX={bdir / 'unused-prefix'}"], cwd=bdir)
    _run(["make", f"-j{jobs}", *TARGETS], cwd=bdir)
    _run(["g++", "-O2", "-std=c++17", "-shared", "-fPIC", str(ctrl), f"-I{bdir}", f"-I{src / 'src'}",
          f"-I{ctrl.parent}", f"-L{bdir / 'core'}", f"-L{bdir / 'plugins' / 'robots' / 'foot-bot'}",
          f"-L{bdir / 'plugins' / 'robots' / 'generic'}", "-largos3core_simulator", "-largos3plugin_simulator_footbot",
          "-largos3plugin_simulator_genericrobot", "-o", str(bdir / CONTROLLER_LIB)])
    print(f"argos_peer: built {bdir / 'core' / 'argos3'} and {bdir / CONTROLLER_LIB}", file=sys.stderr)


def _argos_env(bdir: Path) -> dict:
    """ARGoS's own ``setup_env.sh`` of the build tree: where its plug-ins and libraries are."""
    plugin_path = ""
    for line in (bdir / "setup_env.sh").read_text().splitlines():
        if line.startswith("export ARGOS_PLUGIN_PATH="):
            plugin_path = line.split("=", 1)[1].strip()
    if not plugin_path:
        raise SystemExit(f"argos_peer: {bdir / 'setup_env.sh'} names no ARGOS_PLUGIN_PATH")
    return dict(os.environ, ARGOS_PLUGIN_PATH=plugin_path,
                LD_LIBRARY_PATH=plugin_path + os.pathsep + os.environ.get("LD_LIBRARY_PATH", ""))


def run_once(bdir: Path, n: int, ticks: int, threads: int, timeout_s: float) -> dict:
    """One ``argos3`` process for ``ticks`` ticks: wall seconds, CPU seconds (user + system of the
    child) and its peak resident memory [MB]."""
    exe = bdir / "core" / "argos3"
    library = bdir / CONTROLLER_LIB
    if not exe.exists() or not library.exists():
        raise SystemExit(f"argos_peer: no ARGoS build in {bdir} (run the 'build' command first)")
    with tempfile.TemporaryDirectory(prefix="argos-peer-") as tmp:
        cfg = Path(tmp) / "diffusion.argos"
        cfg.write_text(experiment_xml(n, ticks, threads, library))
        t0 = time.perf_counter()
        proc = subprocess.Popen([str(exe), "-c", str(cfg), "-n", "-z"], cwd=tmp, env=_argos_env(bdir),
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        deadline = t0 + timeout_s
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if time.perf_counter() > deadline:
                proc.kill()
                raise SystemExit(f"argos_peer: {n} robots, {ticks} ticks: timed out after {timeout_s:.0f} s")
            time.sleep(0.01)
        wall = time.perf_counter() - t0
        err = proc.stderr.read().decode(errors="replace") if proc.stderr else ""
        proc.returncode = os.waitstatus_to_exitcode(status)
        if proc.returncode != 0:
            raise SystemExit(f"argos_peer: argos3 exited with {proc.returncode}:\n{err[-2000:]}")
    return {"wall_s": wall, "cpu_s": usage.ru_utime + usage.ru_stime, "peak_rss_mb": usage.ru_maxrss / 1024}


def measure(bdir: Path, n: int, steps: int, warmup: int, repeats: int, threads: int, timeout_s: float) -> dict:
    """Robot-steps per second of ``steps`` ticks, start-up subtracted (see the module docstring)."""
    short = [run_once(bdir, n, warmup, threads, timeout_s) for _ in range(repeats)]
    long = [run_once(bdir, n, warmup + steps, threads, timeout_s) for _ in range(repeats)]
    wall = min(r["wall_s"] for r in long) - min(r["wall_s"] for r in short)
    cpu = min(r["cpu_s"] for r in long) - min(r["cpu_s"] for r in short)
    if wall <= 0 or cpu <= 0:
        raise SystemExit(f"argos_peer: {steps} steps cost no measurable time beside the start-up "
                         f"(wall {wall:.3f} s, cpu {cpu:.3f} s): use more --steps")
    return {"robots": n, "steps": steps, "threads": threads, "seconds": wall, "cpu_seconds": cpu,
            "robot_steps_per_s": n * steps / wall, "robot_steps_per_cpu_s": n * steps / cpu,
            "startup_s": min(r["wall_s"] for r in short),
            "peak_rss_mb": max(r["peak_rss_mb"] for r in long)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    b = sub.add_parser("build", help="build ARGoS (foot-bot only, headless) and the diffusion controller")
    b.add_argument("--src", type=Path, required=True, help="checkout of github.com/ilpincy/argos3")
    b.add_argument("--examples", type=Path, required=True, help="checkout of github.com/ilpincy/argos3-examples")
    b.add_argument("--build-dir", type=Path, default=DEFAULT_BUILD, help=f"where to build (default {DEFAULT_BUILD})")
    b.add_argument("-j", "--jobs", type=int, default=2)
    r = sub.add_parser("run", help="time the diffusion swarm; prints one JSON line")
    r.add_argument("--robots", type=int, required=True)
    r.add_argument("--steps", type=int, default=50)
    r.add_argument("--warmup", type=int, default=10)
    r.add_argument("--repeats", type=int, default=2)
    r.add_argument("--threads", type=int, default=0, help="ARGoS slave threads (0: the main thread only)")
    r.add_argument("--build-dir", type=Path, default=DEFAULT_BUILD, help="the build command's --build-dir")
    r.add_argument("--timeout", type=float, default=1800.0)
    args = ap.parse_args(argv)
    if args.cmd == "build":
        if not shutil.which("cmake") or not shutil.which("g++"):
            raise SystemExit("argos_peer: building ARGoS needs cmake and g++ (apt-get install -y cmake g++)")
        build(args.src.resolve(), args.examples.resolve(), args.build_dir.resolve(), args.jobs)
        return 0
    res = measure(args.build_dir.resolve(), args.robots, args.steps, args.warmup, args.repeats, args.threads,
                  args.timeout)
    print(json.dumps(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
