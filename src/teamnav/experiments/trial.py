"""What one trial of a sweep is, what a worker gets and what it sends back: :class:`Trial`,
:class:`TrialTask` and :class:`TrialResult`.

The sweep (:mod:`teamnav.experiments.sweep`), the executors
(:mod:`teamnav.experiments.executors`) and the results store
(:mod:`teamnav.experiments.store`) all speak of these; they live here, importing none of the
three, so that none of the three needs another to describe what it handles.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping

__all__ = ["Trial", "TrialResult", "TrialTask"]


# ---------------------------------------------------------------------------- a sweep's trial
@dataclass(frozen=True)
class Trial:
    """One run of a sweep.

    Attributes
    ----------
    trial_id : str
        16 hex digits, stable (see :mod:`teamnav.experiments.sweep_trials`).
    sweep : str
        The sweep's name.
    scenario : str
        The scenario as the sweep names it (built-in name or absolute file path).
    scenario_name : str
        The resolved scenario's ``name``.
    params : dict of str to value
        Every override of this trial: the fixed ``set``, this combination of grid values,
        and ``duration_s`` when the sweep sets it.
    seed : int
    config_hash : str
        16 hex digits: hash of the resolved scenario without seed, name and description.
    grid_keys : tuple of str
        Which keys of ``params`` vary across the sweep.
    """

    trial_id: str
    sweep: str
    scenario: str
    scenario_name: str
    params: dict[str, Any]
    seed: int
    config_hash: str
    grid_keys: tuple[str, ...] = ()
    #: robot-steps of the resolved scenario (robots x steps): the schedule's size estimate
    work: float = 0.0

    @property
    def overrides(self) -> dict[str, Any]:
        """``params`` without ``duration_s`` and the ``case`` label (what ``load_scenario(overrides=...)`` gets)."""
        return {k: v for k, v in self.params.items() if k not in ("duration_s", "case")}

    @property
    def duration_s(self) -> float | None:
        return self.params.get("duration_s")

    def load(self):
        """The trial's validated :class:`~teamnav.experiments.spec.Scenario`."""
        from teamnav.experiments.spec import load_scenario

        return load_scenario(self.scenario, overrides=self.overrides or None, seed=self.seed, duration_s=self.duration_s)

    def label(self) -> str:
        """``robots.0.count=4 seed=2`` (grid values and seed)."""
        shown = " ".join(f"{k}={self.params[k]!r}" for k in self.grid_keys)
        if "case" in self.params:
            shown = f"case={self.params['case']} {shown}"
        return f"{shown} seed={self.seed}".strip()


# ---------------------------------------------------------------------------- what travels
@dataclass(frozen=True)
class TrialTask:
    """What a worker gets: the trial, the trial function (None: :func:`run_trial`), the
    run folder to write (None: none), and whether its runs step teams through their compiled
    group brains (``group_brains``: not part of the trial's identity, the same run bit for bit)."""

    trial: "Trial"
    trial_fn: Callable[..., Mapping[str, Any]] | None = None
    artifacts_dir: str | None = None
    group_brains: bool = False


@dataclass(frozen=True)
class TrialResult:
    """What a worker sends back.

    Attributes
    ----------
    trial_id : str
    status : {"ok", "failed"}
    metrics : dict of str to (int, float, bool, str or None), or None when failed
    error : str or None
        ``"TypeName: message"`` when failed.
    traceback : str or None
        The formatted traceback when failed.
    wall_time_s : float
        Wall time of the trial in the worker (scenario loading included) [s].
    cpu_time_s : float or None
        CPU time of the worker process over the trial (``time.process_time``, every thread of
        the process) [s]: the trial's cost on a shared machine, where wall time also counts the
        waits for a core; None where not measured (a lost worker's trial).
    started_at, finished_at : str
        ISO 8601 UTC timestamps.
    host : str
        Host name of the worker.
    pid : int
        Process id of the worker.
    retries : int
        Times the trial was started again because the worker or node running it was lost
        (a Ray node that died, a worker process killed); 0 when the first start finished.
    retry_errors : tuple of str
        What each lost start ended with, in order.
    """

    trial_id: str
    status: str
    metrics: dict[str, Any] | None
    error: str | None
    traceback: str | None
    wall_time_s: float
    started_at: str
    finished_at: str
    host: str
    pid: int
    retries: int = 0
    retry_errors: tuple[str, ...] = ()
    cpu_time_s: float | None = None
