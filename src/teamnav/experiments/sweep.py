"""Sweeps: one scenario run over a grid of parameter values x seeds, resumably.

A sweep is a scenario, a grid of ``--set``-style overrides and a number (or list) of seeds.
Its trials are the Cartesian product of the grid's values times the seeds; each trial is one
run of the scenario with those overrides and that seed. Trials run in worker processes (or on
a Ray cluster, :mod:`teamnav.experiments.executors`); the parent process writes one row per
finished trial into ``OUT/results.sqlite`` (:mod:`teamnav.experiments.store`), committed
before the next trial starts in that worker slot. Running the same sweep into the same folder
again skips the trials already done, so a sweep killed at any moment (SIGKILL included) resumes
and loses only the trials that were running (DESIGN "Determinism and data").

The sweep's description, its options and the named sweeps are in
:mod:`teamnav.experiments.sweep_spec` (the YAML format is described there); its trials, their
stable ids and configuration hashes in :mod:`teamnav.experiments.sweep_trials`. This module
runs them and re-exports both, so ``from teamnav.experiments.sweep import ...`` gives every name.

Examples
--------
>>> from teamnav.experiments.sweep import SweepSpec, expand
>>> spec = SweepSpec(scenario="demo", grid={"robots.0.count": [2, 4]}, seeds=3, duration_s=2)
>>> trials = expand(spec)
>>> len(trials), trials[0].params, trials[0].seed
(6, {'robots.0.count': 2, 'duration_s': 2.0}, 0)
"""

from __future__ import annotations

import math
import os
import pickle
import shutil
import sqlite3
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence

# The spec and the trials live in their own modules; every name they had here stays importable
# from here (config_hash, trial_id and _validate_spec too: tests and scripts import them).
from teamnav.experiments.sweep_spec import (  # noqa: F401 - re-exports
    SWEEP_DIR,
    SweepError,
    SweepSpec,
    SweepWarning,
    _validate_spec,
    describe_sweep,
    load_sweep,
    parse_grid,
    parse_seeds,
    parse_set,
    resolve_spec,
    sweep_files,
    sweep_names,
)
from teamnav.experiments.sweep_trials import Trial, config_hash, expand, trial_id  # noqa: F401 - re-exports

if TYPE_CHECKING:
    from teamnav.experiments.executors import Executor

__all__ = [
    "SWEEP_DIR",
    "SweepError",
    "SweepResult",
    "SweepSpec",
    "SweepWarning",
    "Trial",
    "describe_sweep",
    "expand",
    "load_sweep",
    "parse_grid",
    "parse_seeds",
    "parse_set",
    "resolve_spec",
    "sweep",
    "sweep_files",
    "sweep_names",
]


# ---------------------------------------------------------------------------- running
@dataclass
class SweepResult:
    """What :func:`sweep` returns.

    Attributes
    ----------
    name : str
        The sweep's name.
    store_path : Path
        ``OUT/results.sqlite``.
    total : int
        Trials in the sweep.
    done : int
        Trials that ran and succeeded in this call.
    failed : int
        Trials that ran and failed in this call.
    skipped : int
        Trials not run because the store already had them (``'ok'``, or ``'failed'`` with
        ``retry_failed=False``).
    elapsed_s : float
        Wall time of this call [s].
    failures : list of dict
        ``{"trial_id", "label", "error"}`` for each trial that failed in this call.
    """

    name: str
    store_path: Path
    total: int
    done: int = 0
    failed: int = 0
    skipped: int = 0
    elapsed_s: float = 0.0
    failures: list[dict[str, str]] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when no trial failed in this call."""
        return self.failed == 0

    def summary(self) -> str:
        """One line: counts, time and the store."""
        return (
            f"sweep {self.name}: {self.done} ok, {self.failed} failed, {self.skipped} skipped (already in the store) "
            f"of {self.total} trials in {self.elapsed_s:.1f} s -> {self.store_path}"
        )

    def rows(self, *, all_sweeps: bool = False) -> list[dict[str, Any]]:
        """The store's rows for this sweep (every sweep in the store with ``all_sweeps``)."""
        from teamnav.experiments.store import load_rows

        return load_rows(self.store_path, sweep=None if all_sweeps else self.name)

    def dataframe(self, *, all_sweeps: bool = False):
        """The rows as a pandas DataFrame (needs pandas)."""
        from teamnav.experiments.store import load_dataframe

        return load_dataframe(self.store_path, sweep=None if all_sweeps else self.name)


def sweep(
    name_or_spec: "SweepSpec | str | os.PathLike",
    *,
    out_dir: str | os.PathLike,
    grid: Sequence[str] | Mapping[str, Sequence[Any]] | None = None,
    seeds: int | str | Sequence[int] | None = None,
    set: Sequence[str] | Mapping[str, Any] | None = None,  # noqa: A002 - mirrors --set
    duration_s: float | None = None,
    name: str | None = None,
    executor: "str | Executor" = "local",
    workers: int | None = None,
    address: str | None = None,
    progress: bool = True,
    retry_failed: bool = True,
    artifacts: bool = False,
    trial_fn: Callable[..., Mapping[str, Any]] | None = None,
    group_brains: bool = False,
) -> SweepResult:
    """Run a sweep into ``out_dir``, resuming what an earlier call left.

    Parameters
    ----------
    name_or_spec : SweepSpec, str or Path
        A spec, a named sweep (:func:`sweep_names`), a sweep YAML file, or a scenario name or
        file (then ``grid`` and ``seeds`` say what to sweep).
    out_dir : str or Path
        Folder of the results store ``results.sqlite`` (created if missing).
    grid : list of "KEY=V1,V2" or dict of key to list, optional
        Grid axes, added to the spec's.
    seeds : int, "1,4,9" or list of int, optional
        Replaces the spec's seeds.
    set : list of "KEY=VALUE" or dict, optional
        Fixed overrides, added to the spec's.
    duration_s : float, optional
        Simulated time of every trial [s].
    name : str, optional
        Replaces the sweep's name.
    executor : {"local", "ray"} or Executor
        ``"local"``: worker processes on this machine (default); ``"ray"``: Ray tasks on the
        cluster at ``address``, or on a local Ray started for this sweep; or an executor object
        (:mod:`teamnav.experiments.executors`, e.g. a ``LocalExecutor(keep_pool=True)`` that
        several sweeps share; ``workers`` and ``address`` are then its own).
    workers : int, optional
        Trials running at once; default ``os.cpu_count()`` (local) or the cluster's CPUs (Ray).
    address : str, optional
        Ray cluster address (``"auto"``, ``"ray://host:10001"``); only with ``executor="ray"``.
    progress : bool
        Show a progress bar on stderr (done / failed / remaining, ETA).
    retry_failed : bool
        Run again the trials stored as ``'failed'`` (default); False skips them too.
    artifacts : bool
        Also write each trial's run folder to ``out_dir/trials/<trial_id>/``.
    trial_fn : callable, optional
        ``trial_fn(scenario, out_dir) -> {metric: number}`` replaces the default (a full
        :func:`~teamnav.experiments.runner.run`); it must be picklable (a module-level
        function) and runs in the workers.
    group_brains : bool
        Every trial's runs step teams through their compiled group brains where they have one
        (:func:`~teamnav.experiments.runner.group_brains_default`, which any trial function's
        :func:`~teamnav.experiments.runner.run` follows). The same runs bit for bit: it is not
        part of any trial id or configuration hash, and trials stored without it are reused.

    Returns
    -------
    SweepResult

    Raises
    ------
    SweepError
        Bad sweep, grid, seeds, option, or a store holding other results under the same ids;
        raised before any trial runs.
    """
    from teamnav.experiments.executors import LocalExecutor, make_executor
    from teamnav.experiments.store import STORE_NAME, StoreError, check_store
    from teamnav.files import write_cause

    t0 = time.perf_counter()
    if out_dir is None or not os.fspath(out_dir):
        raise SweepError("out_dir: expected a folder for results.sqlite, received None")
    spec = resolve_spec(name_or_spec, grid=grid, seeds=seeds, set=set, duration_s=duration_s, name=name)
    if isinstance(executor, str):
        runner = make_executor(executor, workers=workers, address=address)  # checks options, starts nothing
    elif callable(getattr(executor, "run", None)):
        runner = executor
    else:
        raise SweepError(f"executor: expected 'local', 'ray' or an executor object, received {executor!r}")
    if trial_fn is not None and not callable(trial_fn):
        raise SweepError(f"trial_fn: expected a callable or None, received {trial_fn!r}")
    if trial_fn is not None and isinstance(runner, LocalExecutor):
        try:
            pickle.dumps(trial_fn)
        except Exception:  # noqa: BLE001 - any pickling failure means the workers cannot get it
            raise SweepError(
                f"trial_fn: expected a module-level function (spawned worker processes import it by name), "
                f"received {trial_fn!r}, which cannot be pickled"
            ) from None
    trials = expand(spec)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise SweepError(f"out_dir: expected a folder, received the file {out}")
    check_store(out / STORE_NAME)  # a results.sqlite that is not a teamnav store: refused before any trial
    created = not os.path.lexists(out)  # removed again if it cannot be written before any trial is stored
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SweepError(f"out_dir: cannot create or write the folder {out} ({exc.strerror or exc}); "
                         "use --out with another folder") from None
    result = SweepResult(spec.sweep_name, out / STORE_NAME, len(trials))
    # SIGTERM as Ctrl-C: the workers are stopped and the store closed before the process ends
    try:
        _run_into_store(out, spec, trials, runner, trial_fn, artifacts, retry_failed, progress, result, t0,
                        bool(group_brains))
    except (StoreError, sqlite3.Error, OSError) as exc:
        # a full disk or a folder that cannot be written: one line, and a folder this call made
        # and stored nothing in is not left behind (a store with results stays: it resumes)
        if created and result.done + result.failed == 0:
            shutil.rmtree(out, ignore_errors=True)
        if isinstance(exc, StoreError):
            raise
        raise StoreError(f"results store {out / STORE_NAME}: cannot be written ({write_cause(exc, out / STORE_NAME)}); "
                         "use --out with another folder" + ("" if created and result.done + result.failed == 0 else
                                                            f"; the {result.done + result.failed} trials stored are kept "
                                                            "and a rerun into it resumes")) from None
    return result


def _run_into_store(out: Path, spec: Any, trials: list[Trial], runner: Any, trial_fn: Any, artifacts: bool,
                    retry_failed: bool, progress: bool, result: "SweepResult", t0: float,
                    group_brains: bool = False) -> None:
    """:func:`sweep`'s work once the folder exists: skip what the store holds, run the rest."""
    from teamnav.experiments.executors import TrialTask
    from teamnav.experiments.signals import sigterm_raises
    from teamnav.experiments.store import STORE_NAME, ResultsStore

    with sigterm_raises(), ResultsStore(out / STORE_NAME) as store:
        previous = store.existing()
        clash = [t for t in trials if t.trial_id in previous and previous[t.trial_id][1] != t.config_hash]
        if clash:
            t = clash[0]
            raise SweepError(
                f"out_dir {out}: trial {t.trial_id} ({t.label()}) is stored with config hash "
                f"{previous[t.trial_id][1]} but the scenario now resolves to {t.config_hash} (the scenario file or "
                f"teamnav changed); expected the same configuration, so write this sweep to a new folder"
            )
        skip_status = {"ok"} if retry_failed else {"ok", "failed"}
        todo = [t for t in trials if previous.get(t.trial_id, ("",))[0] not in skip_status]
        result.skipped = len(trials) - len(todo)
        store.register_sweep(spec.sweep_name, spec.model_dump(mode="json"))
        art = out / "trials" if artifacts else None
        todo = longest_first(todo, trials, store.rows())  # both cores busy to the end: the longest trials start first
        tasks = [TrialTask(t, trial_fn, str(art / t.trial_id) if art is not None else None, group_brains)
                 for t in todo]
        by_id = {t.trial_id: t for t in todo}
        bar = _Bar(spec.sweep_name, len(todo), result.skipped, show=progress and bool(todo))

        def on_result(res) -> None:
            trial = by_id[res.trial_id]
            store.record(trial, res)
            if res.status == "ok":
                result.done += 1
            else:
                result.failed += 1
                result.failures.append({"trial_id": trial.trial_id, "label": trial.label(), "error": res.error or ""})
            bar.advance(res.status == "ok")

        try:
            if tasks:
                runner.run(tasks, on_result)
        finally:
            bar.close()
            result.elapsed_s = time.perf_counter() - t0


def longest_first(todo: list[Trial], trials: list[Trial], rows: list[dict[str, Any]]) -> list[Trial]:
    """``todo`` ordered by expected wall time, longest first, so that the last trials to start
    are short ones and no worker idles while one long trial finishes.

    The expected time of a trial is the mean ``wall_time_s`` the store holds for its
    configuration (same ``config_hash``: the same scenario, another seed or an earlier try);
    a configuration never run yet is estimated from its robot-steps (``Trial.work``) at the
    median seconds per robot-step of the measured ones, or ranked by robot-steps alone when
    nothing is measured. Ties keep the sweep's own order.
    """
    measured: dict[str, list[float]] = {}
    for r in rows:
        w = r.get("wall_time_s")
        if isinstance(w, (int, float)) and math.isfinite(w) and w > 0:
            measured.setdefault(r.get("config_hash"), []).append(float(w))
    work = {t.config_hash: t.work for t in trials}
    rates = sorted(sum(v) / len(v) / work[h] for h, v in measured.items() if work.get(h, 0) > 0)
    rate = rates[len(rates) // 2] if rates else 1.0

    def expected(t: Trial) -> float:
        times = measured.get(t.config_hash)
        return sum(times) / len(times) if times else t.work * rate

    order = sorted(range(len(todo)), key=lambda i: (-expected(todo[i]), i))
    return [todo[i] for i in order]


class _Bar:
    """Sweep progress on stderr: a rich bar (done / total, ok and failed counts, elapsed and
    ETA) on a terminal; elsewhere (CI, nohup, a pipe) a plain line every
    :func:`~teamnav.experiments.progress.period_s` seconds and one at the end."""

    def __init__(self, name: str, total: int, skipped: int, show: bool) -> None:
        self._progress = None
        self._plain = None
        self._total, self._ok, self._failed = total, 0, 0
        if not show:
            return
        from teamnav.experiments.progress import PlainProgress, stderr_is_terminal

        note = f" ({skipped} already done)" if skipped else ""
        if not stderr_is_terminal():
            self._plain = PlainProgress(f"teamnav sweep {name}{note}", total, "trials", details=self._counts).start()
            return
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        self._progress = Progress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("[green]{task.fields[ok]} ok[/] [red]{task.fields[failed]} failed[/] {task.fields[left]} left"),
            TimeElapsedColumn(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=False,
        )
        from rich.markup import escape

        self._task = self._progress.add_task(escape(f"sweep {name}{note}"), total=total, ok=0, failed=0, left=total)
        self._progress.start()

    def _counts(self) -> str:
        left = self._total - self._ok - self._failed
        return f"{self._ok} ok, {self._failed} failed, {left} left"

    def advance(self, ok: bool) -> None:
        self._ok += ok
        self._failed += not ok
        if self._plain is not None:
            self._plain.update(self._ok + self._failed)
        if self._progress is None:
            return
        left = self._total - self._ok - self._failed
        self._progress.update(self._task, advance=1, ok=self._ok, failed=self._failed, left=left)

    def close(self) -> None:
        if self._plain is not None:
            self._plain.close(final="{line}")
            self._plain = None
        if self._progress is not None:
            self._progress.stop()
            self._progress = None
