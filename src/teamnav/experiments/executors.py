"""Where a sweep's trials run: local worker processes (default) or a Ray cluster (opt-in).

Both executors do the same thing: keep at most ``workers`` trials in flight, and each time one
finishes hand its :class:`TrialResult` to the parent's ``on_result`` callback (which commits it
to the results store) *before* the freed slot gets the next trial. So the store is written by
the parent only, one row per finished trial, and a sweep killed at any moment loses only the
trials that were in flight.

A trial runs :func:`execute` in the worker: load the scenario with the trial's overrides and
seed, call the trial function (by default :func:`run_trial`, a full
:func:`~teamnav.experiments.runner.run`), check its metrics. Any exception is caught *in the
worker* and comes back as a ``'failed'`` result with the error type, message and traceback; a
worker process that dies outright (segfault, ``os._exit``, out of memory) is reported as a
failure of the trials it was running. A failing trial never stops the sweep.

- ``local``: :class:`concurrent.futures.ProcessPoolExecutor` with the ``spawn`` start method
  (the same on Linux, macOS and Windows; no fork of a parent that holds threads or a SQLite
  connection). Scripts that call :func:`teamnav.sweep` must therefore guard their entry point
  with ``if __name__ == "__main__":``, as for any ``multiprocessing`` program.
- ``ray``: ``ray.init(address=...)`` joins a running cluster (every node needs teamnav
  installed); with no address a local Ray is started for the sweep and shut down after it.
  Ray is an optional dependency: ``pip install 'teamnav[ray]'``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import re
import signal

import datetime as _dt
import importlib.util
import logging
import multiprocessing
import os
import sys
import socket
import time
import traceback as _tb
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterable, Iterator, Mapping, Protocol

from teamnav.experiments.trial import Trial, TrialResult, TrialTask  # noqa: F401 - Trial: annotations

if TYPE_CHECKING:  # pragma: no cover
    from teamnav.experiments.spec import Scenario

__all__ = [
    "EXECUTORS",
    "Executor",
    "LocalExecutor",
    "RayExecutor",
    "TrialResult",
    "TrialTask",
    "default_workers",
    "execute",
    "make_executor",
    "run_trial",
]

#: executor names accepted by :func:`make_executor`
EXECUTORS = ("local", "ray")

RAY_MISSING = "executor='ray' needs Ray, which is not installed; expected it importable: pip install 'teamnav[ray]'"


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="milliseconds")


def run_trial(scenario: "Scenario", out_dir: Path | None) -> dict[str, Any]:
    """The default trial function: a full run of ``scenario`` (writing ``out_dir`` if given)."""
    from teamnav.experiments.runner import run

    return dict(run(scenario, out_dir=out_dir, progress=False, force=True).metrics)


def _plain(name: str, value: Any) -> Any:
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    item = getattr(value, "item", None)  # numpy scalars
    if callable(item) and getattr(value, "shape", None) == ():
        return _plain(name, item())
    raise TypeError(f"metric {name!r}: expected a number, bool, string or None, received a {type(value).__name__}")


def _check_metrics(metrics: Any) -> dict[str, Any]:
    if not isinstance(metrics, Mapping):
        raise TypeError(f"trial function: expected a dict of metrics, received a {type(metrics).__name__}")
    out = {}
    for k, v in metrics.items():
        if not isinstance(k, str) or not k:
            raise TypeError(f"trial function: expected metric names to be non-empty strings, received {k!r}")
        out[k] = _plain(k, v)
    return out


def execute(task: TrialTask) -> TrialResult:
    """Run one trial (in a worker); never raises for a failing trial.

    Returns
    -------
    TrialResult
        ``status='ok'`` with the metrics, or ``'failed'`` with the error and traceback of any
        ``Exception`` raised while loading, running or scoring the trial.
    """
    started = _now()
    t0 = time.perf_counter()
    c0 = time.process_time()  # the worker runs one trial at a time: its CPU time is the trial's
    metrics = error = trace = None
    try:
        from teamnav.experiments.runner import group_brains_default

        scenario = task.trial.load()
        fn = task.trial_fn if task.trial_fn is not None else run_trial
        out = Path(task.artifacts_dir) if task.artifacts_dir else None
        with group_brains_default(getattr(task, "group_brains", False)):  # reaches any trial function's run()
            metrics = _check_metrics(fn(scenario, out))
        status = "ok"
    except Exception as exc:  # noqa: BLE001 - a failing trial is data, not a crash
        status = "failed"
        error = f"{type(exc).__name__}: {exc}"
        trace = _tb.format_exc()
    return TrialResult(
        trial_id=task.trial.trial_id,
        status=status,
        metrics=metrics,
        error=error,
        traceback=trace,
        wall_time_s=time.perf_counter() - t0,
        cpu_time_s=time.process_time() - c0,
        started_at=started,
        finished_at=_now(),
        host=socket.gethostname(),
        pid=os.getpid(),
    )


def _lost(task: TrialTask, error: str, started: str) -> TrialResult:
    """A failed result for a trial whose worker never answered."""
    return TrialResult(task.trial.trial_id, "failed", None, error, None, float("nan"), started, _now(), socket.gethostname(), 0)


# ---------------------------------------------------------------------------- executors
class Executor(Protocol):
    """Runs trial tasks; calls ``on_result`` in the calling thread as each one finishes."""

    workers: int | None

    def run(self, tasks: Iterable[TrialTask], on_result: Callable[[TrialResult], None]) -> None: ...


def default_workers() -> int:
    """CPUs this process may use (``os.sched_getaffinity`` where available, else ``os.cpu_count()``)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def _limit_numba_threads(threads: int) -> None:
    """Give a worker process ``threads`` numba threads: K workers on C cores each get C // K,
    instead of every worker waking a pool of C threads (measured on 2 cores with 2 workers:
    threaded kernels 3-5x slower than single-threaded ones when oversubscribed)."""
    os.environ["NUMBA_NUM_THREADS"] = str(threads)  # before numba is imported in a fresh worker
    if "numba" in sys.modules:
        import numba

        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))


def _init_worker(threads: int, parent_pid: int | None) -> None:
    """Initializer of a local worker process: end with the sweep (even when the sweep is
    killed with SIGKILL, which leaves it no chance to stop its workers), and take ``threads``
    numba threads."""
    from teamnav.experiments.signals import die_with_parent

    import faulthandler

    faulthandler.enable()  # a worker that crashes (SIGSEGV, SIGABRT, ...) prints where, on the sweep's stderr
    die_with_parent(parent_pid)
    _limit_numba_threads(threads)


def _stop_workers(pool: ProcessPoolExecutor, grace_s: float = 5.0) -> None:
    """Shut ``pool`` down now: cancel what has not started, SIGTERM the workers (a trial's
    run removes its staging folder), SIGKILL those still there after ``grace_s``."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        with contextlib.suppress(Exception):  # already gone
            p.terminate()
    deadline = time.monotonic() + grace_s
    for p in procs:
        with contextlib.suppress(Exception):
            p.join(max(0.0, deadline - time.monotonic()))
    for p in procs:
        with contextlib.suppress(Exception):
            if p.is_alive():
                p.kill()
                p.join(1.0)


def _exit_status(code: int | None) -> str:
    if code is None:
        return "still running"
    if code < 0:
        try:
            return f"killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit status {code}"


def _how_workers_ended(pool: ProcessPoolExecutor, known: dict | None = None) -> str:
    """``"pid 12: exit status 1; pid 13: killed by SIGTERM"`` for the processes of a broken pool
    (the pool SIGTERMs the survivors after the first death, so the first death is the one not
    ended by SIGTERM, unless SIGTERM was what killed it).

    ``known``: the pool's processes as seen while it ran (pid -> process); the pool's own table
    may already have dropped the dead one by the time its break is noticed."""
    procs = {**(known or {}), **(getattr(pool, "_processes", None) or {})}
    deadline = time.monotonic() + 2.0  # the pool may not have reaped the dead one yet
    for p in list(procs.values()):
        with contextlib.suppress(Exception):
            # join() returns at once on a dead process whose status the pool's own thread is
            # reaping at that moment (our waitpid finds nothing): poll until its status is set
            while p.exitcode is None and time.monotonic() < deadline:
                p.join(min(0.05, max(0.0, deadline - time.monotonic())))
    return "; ".join(f"pid {pid}: {_exit_status(p.exitcode)}" for pid, p in sorted(procs.items())) or "none left"


def _execute_one_thread(task: TrialTask) -> TrialResult:
    """:func:`execute` in a Ray task, which holds one CPU."""
    _limit_numba_threads(1)
    return execute(task)


class LocalExecutor:
    """Trials in local worker processes (a ``spawn`` :class:`ProcessPoolExecutor`).

    Each worker gets ``CPUs // workers`` numba threads (at least one).

    Parameters
    ----------
    workers : int, optional
        Processes; default :func:`default_workers`.
    start_method : {"spawn", "forkserver"}
        Default ``"spawn"``.
    keep_pool : bool
        Keep the worker processes between :meth:`run` calls (a report's many short sweeps then
        pay the workers' start-up, imports and numba cache loads once, not once per sweep);
        :meth:`close` ends them. Default False: each run starts and ends its own pool.
    """

    def __init__(self, workers: int | None = None, start_method: str = "spawn", keep_pool: bool = False) -> None:
        if start_method not in ("spawn", "forkserver"):
            raise ValueError(f"start_method: expected 'spawn' or 'forkserver', received {start_method!r}")
        self.workers = workers
        self.start_method = start_method
        self.keep_pool = bool(keep_pool)
        self._kept: ProcessPoolExecutor | None = None

    def close(self) -> None:
        """End the kept worker processes (if any); a later :meth:`run` starts new ones."""
        pool, self._kept = self._kept, None
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)

    def __enter__(self) -> "LocalExecutor":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _pool(self, n: int) -> ProcessPoolExecutor:
        # a spawned worker's parent is this process; a forkserver's is the server (which ends with us)
        parent = os.getpid() if self.start_method == "spawn" else None
        return ProcessPoolExecutor(max_workers=n, mp_context=multiprocessing.get_context(self.start_method),
                                   initializer=_init_worker, initargs=(max(1, default_workers() // n), parent))

    def run(self, tasks: Iterable[TrialTask], on_result: Callable[[TrialResult], None]) -> None:
        n = self.workers or default_workers()
        pending: Iterator[TrialTask] = iter(tasks)
        in_flight: dict[Future, tuple[TrialTask, str]] = {}
        again: list[tuple[TrialTask, str]] = []  # trials lost with a dead worker, to start first
        lost: dict[str, list[str]] = {}  # trial id -> errors of its lost starts
        pool, self._kept = self._kept, None
        if pool is None or getattr(pool, "_max_workers", n) != n:
            if pool is not None:
                pool.shutdown(wait=True, cancel_futures=True)
            pool = self._pool(n)

        known: dict = dict(getattr(pool, "_processes", None) or {})  # pid -> process of the current pool

        def renew() -> None:
            nonlocal pool
            pool.shutdown(wait=True, cancel_futures=True)
            pool = self._pool(n)
            known.clear()

        def lose(task: TrialTask, started: str, how: str) -> None:
            """A start lost with its worker: run it again (up to LOCAL_MAX_RETRIES times), or
            report it failed with what each start ended with."""
            errors = lost.setdefault(task.trial.trial_id, [])
            errors.append(f"{_DIED} (workers: {how})")
            if len(errors) <= LOCAL_MAX_RETRIES:
                again.append((task, started))
                return
            on_result(dataclasses.replace(_lost(task, errors[-1], started), retries=len(errors) - 1,
                                          retry_errors=tuple(lost.pop(task.trial.trial_id))))

        def fill() -> None:
            while len(in_flight) < n:
                if again:
                    task, started = again.pop(0)
                else:
                    task = next(pending, None)
                    if task is None:
                        return
                    started = _now()
                try:
                    in_flight[pool.submit(execute, task)] = (task, started)
                    known.update(getattr(pool, "_processes", None) or {})
                except BrokenProcessPool:  # the pool broke since the last result: a fresh one
                    again.insert(0, (task, started))
                    renew()

        try:
            fill()
            while in_flight:
                done, _ = wait(in_flight, return_when=FIRST_COMPLETED)
                broken = ""
                for fut in done:
                    task, started = in_flight.pop(fut)
                    try:
                        res = fut.result()
                    except BrokenProcessPool:
                        broken = broken or _how_workers_ended(pool, known)
                        lose(task, started, broken)
                        continue
                    except Exception as exc:  # noqa: BLE001 - e.g. a trial_fn that cannot be pickled
                        res = _lost(task, f"{type(exc).__name__}: {exc}", started)
                    if task.trial.trial_id in lost:  # finished after earlier starts were lost
                        errors = lost.pop(task.trial.trial_id)
                        res = dataclasses.replace(res, retries=len(errors), retry_errors=tuple(errors))
                    on_result(res)
                if broken:
                    # every trial still in flight went down with the pool: start them again afresh
                    for task, started in in_flight.values():
                        lose(task, started, broken)
                    in_flight.clear()
                    renew()
                fill()
        except BaseException:  # Ctrl-C, SIGTERM (signals.Terminated), a failing on_result
            _stop_workers(pool)  # stop the trials in flight: nothing keeps running behind us
            raise
        if self.keep_pool:
            self._kept = pool
        else:
            pool.shutdown(wait=True)


#: Times a local trial whose worker process died is started again before it counts as failed.
LOCAL_MAX_RETRIES = 2

_DIED = (
    "WorkerDied: a worker process ended abruptly (crash, os._exit, out of memory or killed) while this "
    "trial was running (it was started again up to LOCAL_MAX_RETRIES times); the sweep went on"
)


def _import_ray():
    try:
        import ray
    except ImportError:
        from teamnav.experiments.sweep_spec import SweepError

        raise SweepError(RAY_MISSING) from None
    return ray


_ANSI = re.compile(r"\x1b\[[0-9;]*m")


def _system_error_text(exc: BaseException) -> str:
    """``"Type: first line"`` of what Ray raised for a lost trial (its cause where it wraps one),
    without the terminal colour codes Ray puts in its messages."""
    cause = getattr(exc, "cause", None)
    shown = cause if isinstance(cause, BaseException) else exc
    lines = [ln.strip() for ln in _ANSI.sub("", str(shown)).splitlines() if ln.strip()]
    return f"{type(shown).__name__}: {lines[0] if lines else ''}"[:500]


#: Times a Ray trial whose worker or node was lost is started again before it counts as failed.
RAY_MAX_RETRIES = 3


class RayExecutor:
    """Trials as Ray tasks (one CPU each).

    A trial's own exceptions come back as failed results (:func:`execute` catches them in the
    worker), so an exception out of ``ray.get`` means the system lost the trial: its worker
    process died or its node left the cluster. Such a trial is started again, up to
    :data:`RAY_MAX_RETRIES` times, on whatever node is left; the result carries ``retries``
    and ``retry_errors`` and the store records them, so every trial is stored exactly once and
    the store says which ones were retried. (Ray's own task retries are off: they would
    hide which trials were lost.)

    Parameters
    ----------
    workers : int, optional
        Trials in flight at once; default: the cluster's CPU count. For a local Ray started
        here, also its ``num_cpus``.
    address : str, optional
        Cluster to join (``"auto"``, ``"ray://head:10001"``); None starts a local Ray for
        the sweep (no dashboard) and shuts it down afterwards. If Ray is already initialised
        in this process, that session is used and left running.
    """

    def __init__(self, workers: int | None = None, address: str | None = None) -> None:
        self.workers = workers
        self.address = address

    def run(self, tasks: Iterable[TrialTask], on_result: Callable[[TrialResult], None]) -> None:
        ray = _import_ray()
        started_here = False
        if not ray.is_initialized():
            kwargs: dict[str, Any] = {"logging_level": logging.WARNING, "log_to_driver": False}
            if self.address is None:
                kwargs.update(include_dashboard=False, num_cpus=self.workers or default_workers())
            else:
                kwargs["address"] = self.address
            ray.init(**kwargs)
            started_here = True
        in_flight: dict[Any, tuple[TrialTask, str]] = {}
        try:
            n = self.workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
            remote = ray.remote(num_cpus=1, max_retries=0)(_execute_one_thread)
            pending: Iterator[TrialTask] = iter(tasks)

            def fill() -> None:
                while len(in_flight) < n:
                    task = next(pending, None)
                    if task is None:
                        return
                    in_flight[remote.remote(task)] = (task, _now())

            lost: dict[str, list[str]] = {}  # trial id -> errors of its lost starts

            fill()
            while in_flight:
                ready, _ = ray.wait(list(in_flight), num_returns=1)
                for ref in ready:
                    task, started = in_flight.pop(ref)
                    tid = task.trial.trial_id
                    try:
                        res = ray.get(ref)
                    except Exception as exc:  # noqa: BLE001 - worker or node lost, task cancelled, unpicklable
                        errors = lost.setdefault(tid, [])
                        errors.append(_system_error_text(exc))
                        if len(errors) <= RAY_MAX_RETRIES:
                            in_flight[remote.remote(task)] = (task, started)  # again, on a node that is left
                            continue
                        # given up: the last start was lost too (retries counts the restarts)
                        res = dataclasses.replace(_lost(task, errors[-1], started), retries=len(errors) - 1,
                                                  retry_errors=tuple(lost.pop(tid)))
                    if tid in lost:  # finished after its earlier starts were lost
                        errors = lost.pop(tid)
                        res = dataclasses.replace(res, retries=len(errors), retry_errors=tuple(errors))
                    on_result(res)
                fill()
        except BaseException:
            for ref in in_flight:
                with contextlib.suppress(Exception):  # best effort while unwinding
                    ray.cancel(ref, force=True)
            raise
        finally:
            if started_here:
                ray.shutdown()


def make_executor(name: str, *, workers: int | None = None, address: str | None = None) -> Executor:
    """The executor called ``name``, with its options checked (nothing is started yet).

    Raises
    ------
    SweepError
        Unknown name, ``workers`` not an integer >= 1, ``address`` without Ray, or Ray
        requested but not installed.
    """
    from teamnav.experiments.sweep_spec import SweepError

    if name not in EXECUTORS:
        raise SweepError(f"executor: expected one of {', '.join(map(repr, EXECUTORS))}, received {name!r}")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise SweepError(f"workers: expected an integer >= 1 or None (all CPUs), received {workers!r}")
    if name == "local":
        if address is not None:
            raise SweepError(f"address: expected None with executor='local' (it is the Ray cluster's), received {address!r}")
        return LocalExecutor(workers)
    if importlib.util.find_spec("ray") is None:
        raise SweepError(RAY_MISSING)
    return RayExecutor(workers, address)
