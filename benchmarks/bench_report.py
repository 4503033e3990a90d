"""CPU seconds per report section, this tree beside another commit, in the same run.

For each section, ``teamnav report SECTION --out TMP`` is run once from this working tree and
once from a ``git worktree`` of ``--base`` (default ``HEAD~1``), alternately, each in a fresh
process with the same Python and packages (the other tree is put first on ``PYTHONPATH``).
CPU seconds are the report process's and its workers' user + system time
(``RUSAGE_CHILDREN``); wall seconds are printed too. Each tree first runs the section once in
quick mode, unmeasured, so that numba's cache (one per tree) is warm and compilation is never
measured.

Usage::

    python benchmarks/bench_report.py                          # quick mode, all four sections, vs HEAD~1
    python benchmarks/bench_report.py --base ab6e386 --sections collab-mcl los-help
    python benchmarks/bench_report.py --full --sections collab-mcl --workers 2    # full mode (long)

Prints one row per section: CPU s here, CPU s at base, ratio base / here (> 1: this tree is
faster). Machines are shared and noisy: compare ratios from one run, not absolute seconds.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SECTIONS = ("los-help", "collab-mcl", "blazing-a-trail", "try-to-see-it-my-way")


def _child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _run(src: Path, args: list[str], timeout: float) -> tuple[float, float, int]:
    """(CPU s, wall s, exit status) of ``python -m teamnav ARGS`` with ``src`` first on the path."""
    env = dict(os.environ, PYTHONPATH=str(src) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    env.setdefault("TEAMNAV_PROGRESS_EVERY_S", "3600")
    cpu0, t0 = _child_cpu(), time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "teamnav", *args], env=env, capture_output=True, text=True,
                          timeout=timeout, check=False)
    return _child_cpu() - cpu0, time.perf_counter() - t0, proc.returncode


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", default="HEAD~1", help="commit to compare with (default HEAD~1)")
    ap.add_argument("--sections", nargs="+", default=list(SECTIONS))
    ap.add_argument("--full", action="store_true", help="full mode (hours for los-help) instead of --quick")
    ap.add_argument("--workers", type=int, default=1, help="report workers (1: CPU time measured without contention)")
    ap.add_argument("--timeout", type=float, default=4 * 3600)
    args = ap.parse_args(argv)
    tmp = Path(tempfile.mkdtemp(prefix="teamnav-bench-report-"))
    base_tree = tmp / "base"
    try:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(base_tree), args.base],
                       check=True, capture_output=True, text=True)
        trees = {"here": ROOT / "src", "base": base_tree / "src"}
        mode = [] if args.full else ["--quick"]
        print(f"| section ({'full' if args.full else 'quick'}) | CPU s here | CPU s at {args.base} | base / here | wall s here | wall s base |")
        print("|---|---:|---:|---:|---:|---:|")
        for section in args.sections:
            res = {}
            # numba compiles into each tree's own cache on first use: one quick report per tree
            # warms every kernel the section needs (not measured)
            for name in ("base", "here"):
                _run(trees[name], ["report", section, "--quick", "--out", str(tmp / f"warm-{section}-{name}"),
                                   "--workers", "1", "--quiet"], args.timeout)
            for name in ("base", "here"):  # base first: any later machine load counts against this tree
                out = tmp / f"{section}-{name}"
                cpu, wall, rc = _run(trees[name], ["report", section, "--out", str(out), "--workers", str(args.workers),
                                                   "--quiet", *mode], args.timeout)
                res[name] = (cpu, wall, rc)
                shutil.rmtree(out, ignore_errors=True)
            (ch, wh, rh), (cb, wb, rb) = res["here"], res["base"]
            flag = "" if rh in (0, 1) and rb in (0, 1) else f" (exit {rh} / {rb})"
            print(f"| {section}{flag} | {ch:.1f} | {cb:.1f} | {cb / max(ch, 1e-9):.2f} | {wh:.1f} | {wb:.1f} |", flush=True)
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(base_tree)], capture_output=True)
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
