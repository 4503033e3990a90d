"""Helpers shared by the benchmark scripts (not a benchmark itself).

:func:`timed_run`: the CPU time of one simulation run, and the part of it spent inside the
brains, as ``bench_sim_step.py`` and ``bench_los_brains.py`` measure it. :func:`clock_brains`:
the same clock on the brains of a simulation a script builds and steps itself
(``bench_trail_brains.py``).
"""

from __future__ import annotations

import time
from typing import Any, Sequence


def clock_brains(sim: Any, methods: Sequence[str] = ("step", "log")) -> tuple[list[float], list[tuple[Any, str]]]:
    """Wrap the brains of the built simulation ``sim`` with a CPU clock (``time.process_time``):
    each brain's ``methods`` (those it has) and each group brain's ``step_group``. Returns the
    one-element list the clocks add into [s] and the (object, method) pairs wrapped (for
    :func:`unclock_brains`).

    A group team's robots do not get ``step`` wrapped: the engine steps them only through their
    group brain's ``step_group``, which may call a robot's own ``step`` inside it (the trail
    group brains run a robot's reference brain so, and below ``TEAM_MIN`` robots those brains
    are the team's per-robot faces), and that time would count twice.
    """
    clock = time.process_time
    brain_s = [0.0]
    teams = getattr(sim, "group_teams", [])
    in_team = {gi for *_, members in teams for gi in members}
    targets = [(team, "step_group") for team, *_ in teams]
    for gi, group in enumerate(sim.brains):
        for brain in group if isinstance(group, list) else [group]:
            targets += [(brain, m) for m in methods if not (m == "step" and gi in in_team)]
    wrapped = []
    for obj, meth in targets:
        f = getattr(obj, meth, None)
        if not callable(f):
            continue

        def timed(*args, f=f):
            t = clock()
            out = f(*args)
            brain_s[0] += clock() - t
            return out

        setattr(obj, meth, timed)
        wrapped.append((obj, meth))
    return brain_s, wrapped


def unclock_brains(wrapped: Sequence[tuple[Any, str]]) -> None:
    """Take off the clocks :func:`clock_brains` put on (the objects' own methods again)."""
    for obj, meth in wrapped:
        if meth in vars(obj):
            delattr(obj, meth)


def timed_run(scn: Any, methods: Sequence[str] = ("step", "log"), **run_kwargs: Any) -> tuple[float, float, Any]:
    """Run the loaded scenario ``scn`` once; (total CPU [s], CPU inside the brains [s], run result).

    CPU is ``time.process_time`` (this process only: other work on a shared machine changes it
    less than wall time). The brains are clocked by :func:`clock_brains` for this run only:
    ``Simulation.__init__`` is patched while the run lasts and restored after. Imports teamnav
    inside, so that a caller's ``PYTHONPATH`` picks the tree measured. ``run_kwargs`` go to
    :func:`teamnav.experiments.runner.run` (``group_brains=True``: the group brains'
    ``step_group`` counts as inside the brains, their robots' ``step`` not again).
    """
    from teamnav.experiments.runner import run
    from teamnav.sim import engine

    clocks: list[list[float]] = []  # one per simulation the run builds
    orig_init = engine.Simulation.__init__

    def init(self, *args, **kwargs):
        orig_init(self, *args, **kwargs)
        clocks.append(clock_brains(self, methods)[0])

    engine.Simulation.__init__ = init
    try:
        t0 = time.process_time()
        result = run(scn, progress=False, **run_kwargs)
        total = time.process_time() - t0
    finally:
        engine.Simulation.__init__ = orig_init
    return total, sum(c[0] for c in clocks), result
