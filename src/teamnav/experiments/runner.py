"""Run a scenario: build the map and the simulation, step it, score it, write the run folder.

A run folder holds everything needed to look at, score and reproduce the run::

    scenario.yaml       the resolved scenario: `teamnav run DIR/scenario.yaml` reproduces it
    metrics.json        the metrics, {name: number}
    trajectories.npz    t_s, true_pose (T, N, 3), odom_pose (T, N, 3), stalled (the recorder)
    events.json, logs.json, comm.json   (the recorder)
    map.yaml + map.pgm  the true map (so figures need nothing but the folder)
    robots.json         per-robot group, controller and body radius
    trajectories.png    map, true paths, odometry (dashed), final poses
    run.gif             optional animation

Everything is written to a hidden staging folder next to the target and renamed into place
at the end, so a failure (a bad scenario, an exception in a controller or a metric, Ctrl-C)
never leaves a half-written run folder behind.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from teamnav.experiments import metrics as metric_registry
from teamnav.experiments.errors import Problem, ScenarioError
from teamnav.experiments.spec import Scenario, build_grid, check_controllers, load_scenario, scenario_to_yaml
from teamnav.world.mapio import save_map

__all__ = ["OutputDirError", "RunResult", "check_scenario", "robot_radii", "run", "run_data"]

#: a progress bar appears once a run has taken this long [s]
PROGRESS_AFTER_S = 2.0


class OutputDirError(ValueError):
    """The output folder exists and is not empty (pass ``force=True`` / ``--force`` to replace it)."""


@dataclass
class RunResult:
    """What :func:`run` returns.

    Attributes
    ----------
    metrics : dict of str to number
        The scenario's metrics (see :mod:`teamnav.experiments.metrics`).
    run_dir : Path or None
        The run folder, or None when no ``out_dir`` was given.
    sim : teamnav.sim.engine.Simulation
        The finished simulation (its truth and recorder, for further analysis).
    scenario : Scenario
        The resolved scenario that ran.
    data : RunData
        What the metrics read: recorded trajectories, events, traffic, timing.
    """

    metrics: dict[str, Any]
    run_dir: Path | None
    sim: Any
    scenario: Scenario
    data: metric_registry.RunData


# ---------------------------------------------------------------------------- helpers
def robot_radii(scenario: Scenario) -> np.ndarray:
    """(N,) body radius per robot [m], groups in scenario order (the engine's robot order)."""
    return np.concatenate([np.full(g.count, g.radius_m) for g in scenario.robots])


def _robots_table(scenario: Scenario) -> dict[str, list]:
    group, controller, radius = [], [], []
    for g in scenario.robots:
        group += [g.name] * g.count
        controller += [g.controller] * g.count
        radius += [g.radius_m] * g.count
    return {"group": group, "controller": controller, "radius_m": radius}


def _event_names(events: list[dict]) -> list[str]:
    """Event names, one per firing, from the recorder's ``events`` records."""
    return [str(e.get("event")) for e in events if isinstance(e, dict) and e.get("event") is not None]


def _comm_counts(comm: dict) -> tuple[int, int, int]:
    """(messages sent, bytes sent, deliveries) from the recorder's radio totals."""
    return int(comm.get("messages_sent", 0)), int(comm.get("bytes_sent", 0)), int(comm.get("messages_delivered", 0))


def run_data(run_dir: Path, scenario: Scenario, grid, n_steps: int, wall_s: float, *,
             finished: bool = False) -> metric_registry.RunData:
    """Read the recorder's files in ``run_dir`` into a :class:`~teamnav.experiments.metrics.RunData`."""
    from teamnav.sim.recorder import load

    rec = load(run_dir)
    sent, nbytes, delivered = _comm_counts(rec.comm)
    return metric_registry.RunData(
        t_s=np.asarray(rec.t_s, dtype=float),
        true_pose=np.asarray(rec.true_pose, dtype=float),
        odom_pose=np.asarray(rec.odom_pose, dtype=float),
        stalled=np.asarray(rec.stalled, dtype=bool),
        radius_m=robot_radii(scenario),
        grid=grid,
        events=_event_names(rec.events),
        messages_sent=sent,
        bytes_sent=nbytes,
        messages_delivered=delivered,
        n_steps=n_steps,
        dt_s=scenario.dt_s,
        wall_s=wall_s,
        event_log=list(rec.events),
        logs=list(rec.logs),
        finished=finished,
    )


class _LazyBar:
    """A rich progress bar on stderr that appears only once the run has lasted a while."""

    def __init__(self, total: int, label: str, show: bool) -> None:
        self.total, self.label, self.show = total, label, show
        self.t0 = time.perf_counter()
        self.bar = None
        self.task = None

    def __call__(self, done: int) -> None:
        if self.bar is None:
            if not self.show or time.perf_counter() - self.t0 < PROGRESS_AFTER_S:
                return
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

            self.bar = Progress(
                TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                console=Console(stderr=True), transient=True,
            )
            self.bar.start()
            self.task = self.bar.add_task(self.label, total=self.total)
        self.bar.update(self.task, completed=int(done))

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()


def _check_out_dir(out: Path, force: bool) -> None:
    if out.exists() and not force:
        if not out.is_dir():
            raise OutputDirError(f"output folder {out} exists and is a file; choose another --out or pass --force")
        if any(out.iterdir()):
            raise OutputDirError(f"output folder {out} exists and is not empty; choose another --out or pass --force")


def _move_into_place(staging: Path, out: Path) -> None:
    """Rename the finished staging folder to ``out``, replacing what is there."""
    if out.is_dir() and any(out.iterdir()):
        old = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".old", dir=out.parent))
        os.replace(out, old / "run")
        os.replace(staging, out)
        shutil.rmtree(old, ignore_errors=True)
    elif out.exists() and not out.is_dir():
        out.unlink()
        os.replace(staging, out)
    else:
        os.replace(staging, out)  # onto nothing or an empty folder


def _json_ready(values: dict[str, Any]) -> dict[str, Any]:
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in values.items()}


# ---------------------------------------------------------------------------- run
def all_finished(sim) -> bool:
    """True when every per-robot brain that has a ``finished`` attribute reports it true, and at
    least one does (a brain with a task: R1's 200 targets; a helper has no ``finished``).

    This reads the brains' own outputs, never the truth, so stopping early does not steer.
    """
    seen = False
    for group in sim.brains:
        if not isinstance(group, list):
            continue
        for brain in group:
            flag = getattr(brain, "finished", None)
            if flag is None:
                continue
            seen = True
            if not flag:
                return False
    return seen


def run(
    scenario: Scenario | str | os.PathLike,
    *,
    out_dir: str | os.PathLike | None = None,
    progress: bool | None | Callable[[int], None] = None,
    gif: bool = False,
    force: bool = False,
) -> RunResult:
    """Run ``scenario`` for ``duration_s`` and compute its metrics; optionally write a run folder.

    Parameters
    ----------
    scenario : Scenario, or a built-in scenario name or a file path
    out_dir : str or Path, optional
        Run folder to write (see the module docstring). None writes nothing.
    progress : bool, None or callable
        ``True``: a progress bar on stderr once the run lasts more than 2 s; ``None``
        (default): the same, only when stderr is a terminal; ``False``: none; a callable is
        called with the number of steps done.
    gif : bool
        Also write ``run.gif`` (needs ``out_dir``).
    force : bool
        Replace a non-empty ``out_dir`` instead of refusing.

    Returns
    -------
    RunResult

    Raises
    ------
    ScenarioError
        The scenario is invalid (before anything runs).
    OutputDirError
        ``out_dir`` exists and is not empty, and ``force`` is False (before anything runs).

    Examples
    --------
    >>> from teamnav import load_scenario, run
    >>> result = run(load_scenario("demo", duration_s=1.0), progress=False)  # doctest: +SKIP
    >>> result.metrics["steps"]  # doctest: +SKIP
    10
    """
    from teamnav.sim.engine import Simulation

    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    else:
        problems = check_controllers(scenario)
        if problems:
            raise ScenarioError(scenario.source, problems)
    out = Path(out_dir) if out_dir is not None else None
    if out is not None:
        _check_out_dir(out, force)
    if gif and out is None:
        raise ValueError("gif=True needs an out_dir to write run.gif into")
    grid = build_grid(scenario)
    try:
        sim = Simulation(grid, scenario, known_map=grid if scenario.give_map else None)
    except ScenarioError:
        raise
    except ValueError as exc:
        raise ScenarioError(scenario.source, [Problem("", f"the simulator cannot set up this scenario: {exc}")]) from None

    n_steps = scenario.n_steps
    if callable(progress):
        bar = None
        callback = progress
    else:
        show = progress is True or (progress is None and sys.stderr.isatty())
        bar = _LazyBar(n_steps, f"{scenario.name} ({scenario.n_robots} robots)", show and progress is not False)
        callback = bar

    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".partial", dir=out.parent))
    else:
        staging = Path(tempfile.mkdtemp(prefix="teamnav-run-"))
    try:
        t0 = time.perf_counter()
        try:
            sim.run(n_steps, progress=callback, is_finished=all_finished if scenario.stop_when_finished else None)
        finally:
            if bar is not None:
                bar.close()
        wall_s = time.perf_counter() - t0
        sim.record_last_step()
        sim.recorder.save(staging)
        data = run_data(staging, scenario, grid, int(sim.step_index), wall_s,
                        finished=bool(scenario.stop_when_finished and all_finished(sim)))
        values = metric_registry.compute(scenario.metric_names, data)
        if out is None:
            shutil.rmtree(staging, ignore_errors=True)
            return RunResult(values, None, sim, scenario, data)
        (staging / "scenario.yaml").write_text(scenario_to_yaml(scenario), encoding="utf-8")
        (staging / "metrics.json").write_text(json.dumps(_json_ready(values), indent=2) + "\n", encoding="utf-8")
        (staging / "robots.json").write_text(json.dumps(_robots_table(scenario)) + "\n", encoding="utf-8")
        save_map(grid, staging / "map.yaml")
        from teamnav.viz.plots import plot_run, save_gif

        plot_run(staging, title=f"{scenario.name}: {scenario.n_robots} robots, {scenario.duration_s:g} s, seed {scenario.seed}")
        if gif:
            save_gif(staging)
        _move_into_place(staging, out)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return RunResult(values, out, sim, scenario, data)


# ---------------------------------------------------------------------------- conformance
def check_scenario(scenario: Scenario | str | os.PathLike, *, duration_s: float = 2.0) -> dict[str, Any]:
    """Conformance check of a scenario (STYLE habit 12), like Gymnasium's ``check_env``.

    Runs ``scenario`` for ``duration_s`` of simulated time three times: twice with its seed,
    once with ``seed + 1``, and checks that

    - the two same-seed runs give identical deterministic metrics and identical recorded
      true and odometry trajectories (bit for bit);
    - the other seed gives different trajectories;
    - every metric value is a plain ``int`` or ``float``; counts of collisions are 0.

    Returns
    -------
    dict
        The metrics of the first run.

    Raises
    ------
    AssertionError
        Naming the check that failed.
    """
    scn = load_scenario(scenario, duration_s=duration_s)
    other = load_scenario(scn, seed=(scn.seed + 1) % (2**63))
    a, b, c = (run(s, progress=False) for s in (scn, scn, other))
    keep = scn.metric_names
    ma, mb = metric_registry.deterministic(a.metrics, keep), metric_registry.deterministic(b.metrics, keep)
    assert ma == mb, f"{scn.name}: same seed, different metrics: {sorted(k for k in ma if ma[k] != mb.get(k))}"
    for key in ("true_pose", "odom_pose"):
        assert np.array_equal(getattr(a.data, key), getattr(b.data, key)), f"{scn.name}: same seed, different {key}"
    assert not np.array_equal(a.data.true_pose, c.data.true_pose), (
        f"{scn.name}: seeds {scn.seed} and {other.seed} gave the same trajectories"
    )
    for k, v in a.metrics.items():
        if k.endswith("_series"):  # a time series travels as a JSON string (metric_sets contract)
            assert type(v) is str and isinstance(json.loads(v), (list, dict)), f"{scn.name}: metric {k} is not JSON"
            continue
        assert type(v) in (int, float), f"{scn.name}: metric {k} is a {type(v).__name__}, expected int or float"
    for k in ("collisions_wall", "collisions_robot"):
        assert a.metrics.get(k, 0) == 0, f"{scn.name}: {k} = {a.metrics[k]}"
    return a.metrics

