"""Helpers shared by the benchmark scripts (not a benchmark itself).

:func:`timed_run`: the CPU time of one simulation run, and the part of it spent inside the
brains, as ``bench_sim_step.py`` and ``bench_los_brains.py`` measure it.
"""

from __future__ import annotations

import time
from typing import Any, Sequence


def timed_run(scn: Any, methods: Sequence[str] = ("step", "log"), **run_kwargs: Any) -> tuple[float, float, Any]:
    """Run the loaded scenario ``scn`` once; (total CPU [s], CPU inside the brains [s], run result).

    CPU is ``time.process_time`` (this process only: other work on a shared machine changes it
    less than wall time). The brains' ``methods`` (those a brain has) are wrapped with a CPU clock
    for this run only: ``Simulation.__init__`` is patched while the run lasts and restored after.
    Imports teamnav inside, so that a caller's ``PYTHONPATH`` picks the tree measured.
    ``run_kwargs`` go to :func:`teamnav.experiments.runner.run` (``group_brains=True``: the
    group brains' ``step_group`` counts as inside the brains).
    """
    from teamnav.experiments.runner import run
    from teamnav.sim import engine

    brain_s = [0.0]
    clock = time.process_time
    orig_init = engine.Simulation.__init__

    def init(self, *args, **kwargs):
        orig_init(self, *args, **kwargs)
        teams = [team for team, *_ in getattr(self, "group_teams", [])]
        for group in [*self.brains, *([t] for t in teams)]:
            for brain in group if isinstance(group, list) else [group]:
                for meth in (*methods, "step_group"):
                    f = getattr(brain, meth, None)
                    if not callable(f):
                        continue

                    def timed(*args, f=f):
                        t = clock()
                        out = f(*args)
                        brain_s[0] += clock() - t
                        return out

                    setattr(brain, meth, timed)

    engine.Simulation.__init__ = init
    try:
        t0 = clock()
        result = run(scn, progress=False, **run_kwargs)
        total = clock() - t0
    finally:
        engine.Simulation.__init__ = orig_init
    return total, brain_s[0], result
