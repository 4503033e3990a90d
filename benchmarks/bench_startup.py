"""How fast ``teamnav`` starts: ``--help``, ``list``, a 1-s demo run (warm and cold numba cache).

Every command runs in a fresh interpreter (``python -m teamnav ...``, the same code as the
``teamnav`` console script), several times, the commands taking turns round by round so they
all see the same machine load; the table gives the median wall time and CPU time (user +
system of the child) of each, and ratios against peers measured in the same run:

- the interpreter floor, ``python -c pass`` (with this environment's site start-up);
- ``python -c "import numpy"``;
- ``python -c "import irsim"`` when IR-SIM is importable (``--irsim-python``, default this
  interpreter; a robot simulator's bare import, for scale). Stage and IR-SIM are not teamnav
  dependencies: without IR-SIM the interpreter floor and numpy are the only peers.

The warm demo run uses a numba cache filled by one unmeasured run first; each cold run gets a
fresh, empty ``NUMBA_CACHE_DIR`` (numba compiles every kernel the demo calls) and
``TEAMNAV_CACHE_DIR`` (the map's distance field is computed). Python's bytecode
cache is on (``PYTHONDONTWRITEBYTECODE`` is dropped for the children, as for an installed
teamnav): the unmeasured run writes the ``.pyc`` files of the tree measured.

::

    python benchmarks/bench_startup.py                       # 7 rounds, 1 cold run, ~1-2 min
    python benchmarks/bench_startup.py --rounds 11 --cold 3
    python benchmarks/bench_startup.py --src /tmp/base/src   # another tree (git archive BASE src | tar -x -C /tmp/base)
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def _child_cpu() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def timed(cmd: list[str], env: dict[str, str]) -> tuple[float, float]:
    """(wall s, CPU s) of one run of ``cmd``; raises if it fails."""
    c0, t0 = _child_cpu(), time.perf_counter()
    proc = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall, cpu = time.perf_counter() - t0, _child_cpu() - c0
    if proc.returncode != 0:
        raise SystemExit(f"failed ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr[-3000:]}")
    return wall, cpu


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=7, help="measured runs of each warm command (default 7)")
    ap.add_argument("--cold", type=int, default=1, help="cold-cache demo runs (each ~20 s of compiling; default 1, 0: none)")
    ap.add_argument("--src", type=Path, default=REPO / "src", help="the teamnav source tree to time (default this repository's)")
    ap.add_argument("--irsim-python", default=os.environ.get("TEAMNAV_BENCH_IRSIM_PYTHON", sys.executable),
                    help="interpreter that may have IR-SIM (default this one)")
    ap.add_argument("--json", type=Path, help="also write the medians here")
    args = ap.parse_args(argv)

    py = sys.executable
    tmp = Path(tempfile.mkdtemp(prefix="bench-startup-"))
    # bytecode caching on (PYTHONDONTWRITEBYTECODE dropped), as an installed teamnav has it
    base_env = {k: v for k, v in os.environ.items()
                if k not in ("NUMBA_CACHE_DIR", "TEAMNAV_CACHE_DIR", "PYTHONPATH", "TEAMNAV_DEBUG",
                             "PYTHONDONTWRITEBYTECODE")}
    base_env["PYTHONPATH"] = str(args.src.resolve())
    warm_env = {**base_env, "NUMBA_CACHE_DIR": str(tmp / "numba-warm"), "TEAMNAV_CACHE_DIR": str(tmp / "teamnav-warm")}
    demo = ["-m", "teamnav", "run", "demo", "--duration", "1", "--out", str(tmp / "run"), "--force"]
    cases: dict[str, tuple[list[str], dict[str, str]]] = {
        "python -c pass (interpreter floor)": ([py, "-c", "pass"], base_env),
        "python -c 'import numpy'": ([py, "-c", "import numpy"], base_env),
    }
    irsim = subprocess.run([args.irsim_python, "-c", "import irsim"], capture_output=True).returncode == 0
    if irsim:
        cases["python -c 'import irsim' (IR-SIM)"] = ([args.irsim_python, "-c", "import irsim"], base_env)
    cases.update({
        "teamnav --help": ([py, "-m", "teamnav", "--help"], warm_env),
        "teamnav list": ([py, "-m", "teamnav", "list"], warm_env),
        "teamnav run demo --duration 1 (warm cache)": ([py, *demo], warm_env),
    })
    try:
        print(f"teamnav from {args.src}; {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.2f} at start", flush=True)
        timed([py, *demo], warm_env)  # fills the warm cache (not measured)
        walls: dict[str, list[float]] = {k: [] for k in cases}
        cpus: dict[str, list[float]] = {k: [] for k in cases}
        names = list(cases)
        for r in range(args.rounds):
            order = names[r % len(names):] + names[: r % len(names)]  # rotate who goes first
            for name in order:
                w, c = timed(*cases[name])
                walls[name].append(w)
                cpus[name].append(c)
        cold = "teamnav run demo --duration 1 (cold cache: compiles)"
        if args.cold > 0:
            walls[cold], cpus[cold] = [], []
            for k in range(args.cold):
                env = {**base_env, "NUMBA_CACHE_DIR": str(tmp / f"numba-cold-{k}"),
                       "TEAMNAV_CACHE_DIR": str(tmp / f"teamnav-cold-{k}")}
                w, c = timed([py, *demo], env)
                walls[cold].append(w)
                cpus[cold].append(c)
        load = os.getloadavg()[0]
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    med = {k: (statistics.median(walls[k]), statistics.median(cpus[k])) for k in walls}
    floor = med["python -c pass (interpreter floor)"][0]
    numpy_s = med["python -c 'import numpy'"][0]
    irsim_key = "python -c 'import irsim' (IR-SIM)"
    head = "| command | runs | wall s (median) | CPU s (median) | / interpreter floor | / import numpy |"
    sep = "|---|---:|---:|---:|---:|---:|"
    if irsim:
        head += " / import irsim |"
        sep += "---:|"
    print()
    print(head)
    print(sep)
    for k, (w, c) in med.items():
        row = f"| {k} | {len(walls[k])} | {w:.3f} | {c:.3f} | {w / floor:.1f}x | {w / numpy_s:.1f}x |"
        if irsim:
            row += f" {w / med[irsim_key][0]:.2f}x |"
        print(row)
    print(f"\nload {load:.2f} at the end. Peers: the interpreter floor (python -c pass) and numpy's import"
          + ("" if irsim else "; IR-SIM not importable (pip install ir-sim), Stage not installed") + ".")
    if args.json:
        args.json.write_text(json.dumps({k: {"wall_s": w, "cpu_s": c, "runs": len(walls[k])} for k, (w, c) in med.items()},
                                        indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
