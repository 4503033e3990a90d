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
at the end, so a failure (a bad scenario, an exception in a controller or a metric, Ctrl-C,
SIGTERM) never leaves a half-written run folder behind. The staging folder's name carries the
host and pid of the run that owns it (``.NAME.HOST-PID.XXXXXXXX.partial``): one left by a run
killed outright (SIGKILL, a power cut) is removed by the next run into the same parent folder
once that process is gone, never while it lives. The run folder and its files get the user's
umask (folders ``0o777 & ~umask``, files ``0o666 & ~umask``), like any file a tool writes.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import shutil
import socket
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from teamnav.control.guard import BrainError
from teamnav.experiments import metrics as metric_registry
from teamnav.experiments.errors import Problem, ScenarioError
from teamnav.experiments.spec import (
    PACKAGE_MAP_DIR,
    Scenario,
    build_grid,
    check_controllers,
    load_scenario,
    scenario_to_yaml,
)
from teamnav.files import ClaimError, claim, current_umask, destination_problem, write_cause  # noqa: F401 (current_umask: teamnav.env uses it)
from teamnav.world.mapio import YAML_SUFFIXES, read_map_yaml, save_map

__all__ = [
    "OutputDirError", "RunResult", "check_scenario", "clean_stale_staging", "current_umask", "group_brains_default",
    "robot_radii", "run", "run_data",
]

#: a progress bar appears once a run has taken this long [s]
PROGRESS_AFTER_S = 2.0
#: the progress line names the brain a step waits on once one call has lasted this long [s]
BRAIN_WAIT_S = 2.0
#: what the progress line says while numba compiles a kernel (the cache is empty or stale);
#: the time is the first run of the built-in scenarios on a 2-core machine (demo ~20 s, the
#: MCL ones more; measured by benchmarks/bench_startup.py)
COMPILING = "compiling numba kernels (first run only, ~20-60 s; later runs load them from the cache)"


#: what ``run(group_brains=None)`` uses: False, or True inside :func:`group_brains_default`
_GROUP_BRAINS_DEFAULT = False


@contextlib.contextmanager
def group_brains_default(on: bool):
    """Within the block, :func:`run` without an explicit ``group_brains`` steps teams through
    their compiled group brains (``on``) or the per-robot brains.

    This is how ``teamnav sweep --group-brains`` and ``teamnav report --group-brains`` reach every
    trial, whatever its trial function (a section's own function calls :func:`run` without
    knowing of the option). It is not part of any scenario, configuration hash or trial id: a
    run with group brains is the same run, bit for bit, so stored trials are shared.
    """
    global _GROUP_BRAINS_DEFAULT
    before = _GROUP_BRAINS_DEFAULT
    _GROUP_BRAINS_DEFAULT = bool(on)
    try:
        yield
    finally:
        _GROUP_BRAINS_DEFAULT = before


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
             finished: bool = False, warmup_s: float = 0.0) -> metric_registry.RunData:
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
        warmup_s=warmup_s,
        event_log=list(rec.events),
        logs=list(rec.logs),
        finished=finished,
    )


class _LazyBar:
    """A rich progress bar on stderr that appears only once the run has lasted a while."""

    def __init__(self, total: int, label: str, show: bool = True) -> None:
        self.total, self.label, self.show = total, label, show
        self.t0 = time.perf_counter()
        self.bar = None
        self.task = None
        self._lock = threading.Lock()  # the brain watch (another thread) may start the bar

    def __call__(self, done: int) -> None:
        if self.bar is None:
            if not self.show or time.perf_counter() - self.t0 < PROGRESS_AFTER_S:
                return
            with self._lock:
                if self.bar is None and self.show:
                    self._start()
            if self.bar is None:
                return
        self.bar.update(self.task, completed=int(done))

    def _start(self) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

        bar = Progress(
            TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
            console=Console(stderr=True), transient=True,
        )
        bar.start()
        self.task = bar.add_task(self.label, total=self.total)
        self.bar = bar

    def describe(self, text: str) -> None:
        """Show ``text`` as the bar's description (from any thread; the bar appears if it has
        not yet)."""
        with self._lock:
            if self.bar is None and self.show:
                self._start()
            if self.bar is not None:
                self.bar.update(self.task, description=text)

    def close(self) -> None:
        with self._lock:
            self.show = False
        if self.bar is not None:
            self.bar.stop()


# ---------------------------------------------------------------------------- staging and modes
#: this host in staging folder names (letters, digits and '-'; at most 32)
_HOST = re.sub(r"[^A-Za-z0-9-]", "-", socket.gethostname())[:32] or "host"
#: ``.NAME.HOST-PID.XXXXXXXX.partial`` (staging) and ``.NAME.HOST-PID.XXXXXXXX.old`` (a run
#: folder being replaced); XXXXXXXX is tempfile's random part
_STAGING = re.compile(r"^\.(?P<name>.+)\.(?P<host>[A-Za-z0-9-]{1,32})-(?P<pid>\d+)\.[a-z0-9_]{8}\.(?P<kind>partial|old)$")
#: ``teamnav-run-HOST-PID.XXXXXXXX.partial`` in the temporary folder (a run without out_dir)
_TMP_STAGING = re.compile(r"^teamnav-run-(?P<host>[A-Za-z0-9-]{1,32})-(?P<pid>\d+)\.[a-z0-9_]{8}\.partial$")


def source_thresholds(scenario: Scenario) -> dict[str, float]:
    """The thresholds of the scenario's map file, to write the run folder's ``map.yaml`` with
    them (origin and yaw come with the grid); map_saver's defaults for generated maps."""
    spec = scenario.map
    path = Path(spec.file) if spec.file is not None else PACKAGE_MAP_DIR / str(spec.package) if spec.package else None
    if path is None or path.suffix.lower() not in YAML_SUFFIXES:
        return {}
    meta = read_map_yaml(path)
    return {"occupied_thresh": meta.occupied_thresh, "free_thresh": meta.free_thresh}


def _apply_umask(root: Path, umask: int) -> None:
    """Give ``root`` and everything under it the modes the user's umask asks for (mkdtemp and
    mkstemp create 0700 folders and 0600 files whatever the umask)."""
    dir_mode, file_mode = 0o777 & ~umask, 0o666 & ~umask
    os.chmod(root, dir_mode)
    for here, dirs, files in os.walk(root):
        for d in dirs:
            path = os.path.join(here, d)
            if not os.path.islink(path):
                os.chmod(path, dir_mode)
        for f in files:
            path = os.path.join(here, f)
            if not os.path.islink(path):
                os.chmod(path, file_mode)


def clean_stale_staging(folder: str | os.PathLike) -> list[Path]:
    """Remove the staging folders in ``folder`` that runs on this host left behind when they
    were killed outright; returns them.

    Only folders named by :func:`run` (``.NAME.HOST-PID.*.partial``, ``.NAME.HOST-PID.*.old``,
    ``teamnav-run-HOST-PID.*.partial``) with this host's name and a PID that is no longer a
    live process are touched: another run's staging, here or on another machine sharing the
    folder, is kept. A ``.old`` folder holds a run folder that was being replaced; if the new
    one never arrived, the old one is put back instead of deleted.
    """
    from teamnav.experiments.signals import pid_alive

    folder = Path(folder)
    removed: list[Path] = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        m = _STAGING.match(entry.name) or _TMP_STAGING.match(entry.name)
        if m is None or m["host"] != _HOST or pid_alive(int(m["pid"])):
            continue
        try:
            if not entry.is_dir(follow_symlinks=False):
                continue
        except OSError:
            continue
        path = Path(entry.path)
        if m.groupdict().get("kind") == "old":
            target, previous = folder / m["name"], path / "run"
            if previous.is_dir() and not target.exists():
                try:
                    os.replace(previous, target)
                except OSError:
                    continue  # keep it: it holds the only copy of that run
        shutil.rmtree(path, ignore_errors=True)
        removed.append(path)
    return removed


def _staging_place(out: Path | None) -> tuple[Path, str]:
    """Where the staging folder of a run into ``out`` goes, and its name's prefix (with this
    host and process: see :func:`clean_stale_staging`)."""
    owner = f"{_HOST}-{os.getpid()}"
    if out is not None:
        return out.parent, f".{out.name}.{owner}."
    return Path(tempfile.gettempdir()), f"teamnav-run-{owner}."


def _check_out_dir(out: Path, force: bool) -> None:
    """Refuse, before any work, an ``out`` teamnav cannot or must not write (see
    :func:`teamnav.files.destination_problem`), and one that holds something (without ``force``)."""
    problem = destination_problem(out, folder=True)
    if problem is None and out.is_dir() and not os.access(out, os.W_OK | os.X_OK):
        problem = f"{out} is read-only"  # replacing it moves it, which needs its write permission
    if problem is not None:
        raise OutputDirError(f"output folder {out}: cannot be written ({problem}); choose another --out")
    if out.exists() and not force:
        if not out.is_dir():
            raise OutputDirError(f"output folder {out} exists and is a file; choose another --out or pass --force")
        if any(out.iterdir()):
            raise OutputDirError(f"output folder {out} exists and is not empty; choose another --out or pass --force")


def _move_into_place(staging: Path, out: Path) -> None:
    """Rename the finished staging folder to ``out``, replacing what is there."""
    if out.is_dir() and any(out.iterdir()):
        old = Path(tempfile.mkdtemp(prefix=f".{out.name}.{_HOST}-{os.getpid()}.", suffix=".old", dir=out.parent))
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
    brain_timeout_s: float | None = None,
    wait: bool = False,
    group_brains: bool | None = None,
) -> RunResult:
    """Run ``scenario`` for ``duration_s`` and compute its metrics; optionally write a run folder.

    Parameters
    ----------
    scenario : Scenario, or a built-in scenario name or a file path
    out_dir : str or Path, optional
        Run folder to write (see the module docstring). None writes nothing.
    progress : bool, None or callable
        ``True`` or ``None`` (default): on a terminal, a progress bar on stderr once the run
        lasts more than 2 s; elsewhere (CI, nohup, a pipe) a plain line on stderr every 10 s
        (``TEAMNAV_PROGRESS_EVERY_S``, :mod:`teamnav.experiments.progress`) and one at the end
        when there was any; ``False``: none; a callable is called with the number of steps done.
    gif : bool
        Also write ``run.gif`` (needs ``out_dir``).
    force : bool
        Replace a non-empty ``out_dir`` instead of refusing.
    brain_timeout_s : float, optional
        Stop the run when one brain call (``step``/``step_batch``) takes longer than this
        [s] (:meth:`Simulation.brain_time_limit`); None: no limit.
    wait : bool
        When another process is writing ``out_dir`` (it holds its claim, ``.NAME.lock`` beside
        it: :func:`teamnav.files.claim`), wait for it to finish instead of refusing; then
        ``out_dir`` is checked again (without ``force``, the other run's folder is kept).
    group_brains : bool or None
        Step teams whose brains have a compiled group brain in one call of it
        (:class:`~teamnav.sim.engine.Simulation`'s ``group_brains``; the same run, bit for bit).
        None (default): False, or True inside :func:`group_brains_default` (a sweep or report
        run with ``--group-brains``).

    Returns
    -------
    RunResult

    Raises
    ------
    ScenarioError
        The scenario is invalid (before anything runs).
    OutputDirError
        ``out_dir`` exists and is not empty, and ``force`` is False; or it cannot be written
        (read-only, a symbolic link, a file above it); before anything runs.
    ClaimError
        Another process is writing ``out_dir`` and ``wait`` is False (before anything runs).
    teamnav.control.guard.BrainError
        A brain could not be built (:class:`~teamnav.control.guard.BrainBuildError`, before
        anything runs), or failed, returned no action or ran past ``brain_timeout_s`` during
        the run (:class:`~teamnav.control.guard.BrainStepError`); nothing is written.

    Examples
    --------
    >>> from teamnav import load_scenario, run
    >>> result = run(load_scenario("demo", duration_s=1.0), progress=False)  # doctest: +SKIP
    >>> result.metrics["steps"]  # doctest: +SKIP
    10
    """
    from teamnav.experiments.signals import sigterm_deferred, sigterm_raises
    from teamnav.sim.engine import Simulation

    if group_brains is None:
        group_brains = _GROUP_BRAINS_DEFAULT
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
    umask = current_umask()
    n_steps = scenario.n_steps
    report = _Progress(progress, n_steps, scenario)
    try:
        grid = build_grid(scenario)
        try:
            sim = Simulation(grid, scenario, known_map=grid if scenario.give_map else None, group_brains=group_brains)
        except (ScenarioError, BrainError):  # a brain that cannot be built names itself
            raise
        except ValueError as exc:
            raise ScenarioError(scenario.source, [Problem("", f"the simulator cannot set up this scenario: {exc}")]) from None

        if out is not None:
            try:
                out.parent.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise OutputDirError(f"output folder {out}: its parent {out.parent} cannot be created "
                                     f"({exc.strerror or exc}); choose another --out") from None
        with sigterm_raises(), contextlib.ExitStack() as held:  # SIGTERM: staging and claim removed, then the process ends
            staging: Path | None = None
            writing = False
            if out is not None:  # one writer per run folder, from here to the end
                try:
                    held.enter_context(claim(out, "output folder", command="teamnav run", wait=wait,
                                             say=lambda line: print(line, file=sys.stderr, flush=True)))
                except OSError as exc:
                    raise OutputDirError(f"output folder {out}: cannot write in {out.parent} "
                                         f"({exc.strerror or exc}); choose another --out") from None
                _check_out_dir(out, force)  # what a writer that held it before us left there
            try:
                folder, prefix = _staging_place(out)
                clean_stale_staging(folder)
                with sigterm_deferred():  # no SIGTERM between creating the folder and knowing its name
                    try:
                        staging = Path(tempfile.mkdtemp(prefix=prefix, suffix=".partial", dir=folder))
                    except OSError as exc:
                        raise OutputDirError(f"output folder {out if out is not None else folder}: cannot write in "
                                             f"{folder} ({exc.strerror or exc}); choose another --out") from None
                report.phase("first step: loading numba's cached kernels")
                t0 = time.perf_counter()
                report.sim = sim  # the progress line says when a step waits on a brain
                report.watch_brains()
                with report.watching_compiles(), sim.brain_time_limit(brain_timeout_s):
                    sim.run(n_steps, progress=report.step, is_finished=all_finished if scenario.stop_when_finished else None)
                wall_s = time.perf_counter() - t0
                warmup_s = (report.t_first - t0) if report.t_first is not None else 0.0  # the first step
                report.stepped()
                sim.record_last_step()
                writing = True  # from here on an OSError is the disk's (full, gone), not the run's
                sim.recorder.save(staging)
                data = run_data(staging, scenario, grid, int(sim.step_index), wall_s,
                                finished=bool(scenario.stop_when_finished and all_finished(sim)), warmup_s=warmup_s)
                values = metric_registry.compute(scenario.metric_names, data)
                if out is None:
                    shutil.rmtree(staging, ignore_errors=True)
                    return RunResult(values, None, sim, scenario, data)
                (staging / "scenario.yaml").write_text(scenario_to_yaml(scenario), encoding="utf-8")
                (staging / "metrics.json").write_text(json.dumps(_json_ready(values), indent=2) + "\n", encoding="utf-8")
                (staging / "robots.json").write_text(json.dumps(_robots_table(scenario)) + "\n", encoding="utf-8")
                save_map(grid, staging / "map.yaml", **source_thresholds(scenario))
                from teamnav.viz.plots import plot_run, save_gif

                plot_run(staging, title=f"{scenario.name}: {scenario.n_robots} robots, {scenario.duration_s:g} s, seed {scenario.seed}")
                if gif:
                    report.phase("writing run.gif")
                    save_gif(staging)
                _apply_umask(staging, umask)
                with sigterm_deferred():  # the old folder out and the new one in, not half of it
                    _move_into_place(staging, out)
            except OSError as exc:
                if staging is not None:
                    shutil.rmtree(staging, ignore_errors=True)
                if not writing:
                    raise
                raise OutputDirError(f"output folder {out if out is not None else staging}: cannot be written "
                                     f"({write_cause(exc, staging)}); nothing was kept, choose another --out") from None
            except BaseException:
                if staging is not None:
                    shutil.rmtree(staging, ignore_errors=True)
                raise
    finally:
        report.close()
    return RunResult(values, out, sim, scenario, data)


class _Progress:
    """What :func:`run` shows while it works (see its ``progress`` parameter) and the time of
    its first step (numba compiles or loads its kernels there: the ``warmup_s`` metric)."""

    def __init__(self, progress, n_steps: int, scenario: Scenario) -> None:
        from teamnav.experiments.progress import PlainProgress, stderr_is_terminal

        self.t_first: float | None = None  # perf_counter() at the end of the first step
        self.told_compiling = False
        self.sim: Any = None  # the Simulation once built: waiting_on() says which brain a step waits on
        self._watch_stop: Any = None
        self.bar: _LazyBar | None = None
        self.plain: PlainProgress | None = None
        self.user: Callable[[int], None] | None = progress if callable(progress) else None
        if self.user is None and progress is not False:
            if stderr_is_terminal():
                self.bar = _LazyBar(n_steps, f"{scenario.name} ({scenario.n_robots} robots)")
            else:
                self.plain = PlainProgress(f"teamnav run {scenario.name}", n_steps, "steps",
                                           waiting=self.waiting).start()
                self.plain.phase("setting up")

    def waiting(self) -> str:
        """``"waiting on controller X, robot G[K] (id I), step S for N s"`` while a brain call
        has lasted :data:`BRAIN_WAIT_S` or more, else "" (called from the progress thread)."""
        sim = self.sim
        at = sim.waiting_on() if sim is not None else None
        if at is None or at[3] < BRAIN_WAIT_S:
            return ""
        from teamnav.experiments.progress import format_duration

        controller, robot, step, seconds = at
        return f"waiting on controller {controller}, robot {robot}, step {step} for {format_duration(seconds)}"

    def watch_brains(self) -> None:
        """On a terminal: a thread that shows on the bar when a step waits on a brain (the bar
        is redrawn only when steps finish)."""
        if self.bar is None or self._watch_stop is not None:
            return
        import threading

        stop = self._watch_stop = threading.Event()
        bar = self.bar

        def loop() -> None:
            shown = False
            while not stop.wait(0.5):
                text = self.waiting()
                if text:
                    bar.describe(f"{bar.label}: {text}")
                    shown = True
                elif shown:
                    bar.describe(bar.label)
                    shown = False

        threading.Thread(target=loop, name="teamnav brain watch", daemon=True).start()

    def step(self, k: int) -> None:
        """The engine's ``progress(k)`` callback."""
        if self.t_first is None:
            self.t_first = time.perf_counter()
            if self.plain is not None:
                self.plain.phase("")
        if self.bar is not None:
            self.bar(k)
        elif self.plain is not None:
            self.plain.update(k)
        elif self.user is not None:
            self.user(k)

    def phase(self, text: str) -> None:
        if self.plain is not None:
            self.plain.phase(text)

    @contextlib.contextmanager
    def watching_compiles(self):
        """While stepping: when numba really compiles a kernel (not a load from its cache: that
        sends no event), say so, once on a terminal, in the plain lines while it lasts."""
        if self.plain is None and self.bar is None:
            yield
            return
        from numba.core import event

        progress = self
        depth = [0]

        class _Compiles(event.Listener):
            def on_start(self, ev) -> None:
                depth[0] += 1
                if depth[0] == 1:
                    progress.compiling(True)

            def on_end(self, ev) -> None:
                depth[0] -= 1
                if depth[0] == 0:
                    progress.compiling(False)

        with event.install_listener("numba:compile", _Compiles()):
            yield

    def compiling(self, now: bool) -> None:
        """numba started (``now``) or finished compiling a kernel, outside any other."""
        if self.plain is not None:
            self.plain.phase(COMPILING if now else ("" if self.t_first is not None else "first step"))
        elif now and self.bar is not None and not self.told_compiling:
            self.told_compiling = True
            line = f"{self.bar.label}: {COMPILING}"
            if self.bar.bar is not None:
                self.bar.bar.console.print(line, markup=False)
            else:
                print(line, file=sys.stderr, flush=True)

    def stepped(self) -> None:
        """Stepping is over: the bar goes, the plain lines say what comes next."""
        self._stop_watch()
        if self.bar is not None:
            self.bar.close()
            self.bar = None
        self.phase("scoring and writing the run folder")

    def _stop_watch(self) -> None:
        if self._watch_stop is not None:
            self._watch_stop.set()

    def close(self) -> None:
        self._stop_watch()
        if self.bar is not None:
            self.bar.close()
            self.bar = None
        if self.plain is not None:
            from teamnav.experiments.progress import format_duration

            plain, self.plain = self.plain, None
            final = f"{plain.label}: {plain.done} steps done in {format_duration(plain.elapsed_s())}"
            plain.close(final=final if plain.lines else None)  # a run that printed nothing stays quiet


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

