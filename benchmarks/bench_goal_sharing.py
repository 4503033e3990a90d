"""Compiled goal sharing against the reference's, on the same captured inputs (CPU clock).

Records a 4-robot line-of-sight team (R1..R4 on office_simple, a tuning task, the teamnav and
the paper column) with the recorder of ``tests/test_goal_sharing_compiled.py``, then times, in
alternating rounds:

- the reference: the goal-sharing part of each brain's step (``GoalSharing`` with the brain's
  own ``_receive`` / ``_broadcast``), robot by robot, fed the captured inputs;
- the compiled kernels: ``gs_begin_step`` and ``gs_end_step`` for the whole team per step, on
  the same inputs built beforehand as arrays (the inbox as packed rows: in a compiled team the
  senders write those rows, so packing is not counted).

Both replays are checked against the recording first. Prints, last, one line per column:
``goal sharing, 4 robots, <column>: compiled / reference = 7.1x``.

    python benchmarks/bench_goal_sharing.py [--steps 1500] [--rounds 3] [--task 1001]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import test_goal_sharing_compiled as T


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1500)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--task", type=int, default=1001)
    a = ap.parse_args()
    print(f"load average at start: {os.getloadavg()[0]:.1f}")
    lines = []
    for paper in (False, True):
        column = "paper" if paper else "teamnav"
        setup, frames = T.record(T._scenario(a.task, paper), a.steps)
        T.reference_replay(setup, frames)
        inputs = T.compiled_inputs(frames)
        T.compiled_replay(setup, frames, inputs=inputs)  # checked, and compiled/loaded once
        ref, comp = [], []
        for _ in range(a.rounds):
            t = time.process_time()
            T.reference_replay(setup, frames, check=False)
            ref.append(time.process_time() - t)
            t = time.process_time()
            T.compiled_replay(setup, frames, check=False, inputs=inputs)
            comp.append(time.process_time() - t)
        n = len(frames)
        r_ms, c_ms = min(ref) / n * 1e3, min(comp) / n * 1e3
        print(f"{column}: {n} team steps; reference {r_ms:.4f} ms/step (rounds {', '.join(f'{x:.3f}' for x in ref)} s), "
              f"compiled {c_ms:.4f} ms/step (rounds {', '.join(f'{x:.3f}' for x in comp)} s)")
        lines.append(f"goal sharing, 4 robots, {column}: compiled / reference = {r_ms / c_ms:.1f}x")
    print(f"load average at end: {os.getloadavg()[0]:.1f}")
    for line in lines:
        print(line)


if __name__ == "__main__":
    main()
