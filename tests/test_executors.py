"""Executors: failures caught in the worker, option checks, local vs Ray give the same metrics."""

from __future__ import annotations

import time

import numpy as np
import pytest

from teamnav.experiments import metrics as metric_registry
from teamnav.experiments.executors import LocalExecutor, RayExecutor, TrialTask, execute, make_executor
from teamnav.experiments.sweep import SweepError, SweepSpec, expand, sweep


def bad_metrics_trial(scenario, out_dir):
    return {"path": [1.0, 2.0]}


def ok_trial(scenario, out_dir):
    return {"count": np.int64(scenario.robots[0].count), "seed": scenario.seed, "out": str(out_dir)}


def dies_once_trial(scenario, out_dir):
    """Kills its own worker process the first time it runs for a seed (a marker file remembers)."""
    import os
    from pathlib import Path

    marker = Path(os.environ["TEAMNAV_TEST_MARKERS"]) / f"seed{scenario.seed}"
    if not marker.exists():
        marker.write_text("started once")
        os._exit(1)  # the worker process dies, as on a lost node
    return {"seed": scenario.seed}


def always_dies_trial(scenario, out_dir):
    import os

    os._exit(1)


def slow_trial(scenario, out_dir):
    time.sleep(0.3)
    return {"seed": scenario.seed}


@pytest.fixture(scope="module")
def trials():
    return expand(SweepSpec(scenario="demo", grid={"robots.0.count": [1, 2]}, seeds=2, duration_s=0.5))


def test_execute_returns_metrics_as_plain_python(trials):
    res = execute(TrialTask(trials[3], ok_trial, "/tmp/x"))
    assert res.status == "ok" and res.error is None
    assert res.metrics == {"count": 2, "seed": 1, "out": "/tmp/x"} and type(res.metrics["count"]) is int
    assert res.trial_id == trials[3].trial_id and res.wall_time_s >= 0 and res.started_at <= res.finished_at


def test_execute_catches_errors_in_the_worker(trials):
    res = execute(TrialTask(trials[0], bad_metrics_trial))
    assert res.status == "failed" and res.metrics is None
    assert res.error == "TypeError: metric 'path': expected a number, bool, string or None, received a list"
    assert "Traceback" in res.traceback


def test_default_trial_runs_the_scenario_and_can_write_its_run_folder(trials, tmp_path):
    res = execute(TrialTask(trials[1], None, str(tmp_path / "run")))
    assert res.status == "ok", res.traceback
    assert res.metrics["steps"] == 5 and res.metrics["sim_time_s"] == 0.5
    assert (tmp_path / "run" / "metrics.json").is_file()


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"name": "dask"}, "executor: expected one of 'local', 'ray', received 'dask'"),
        ({"name": "local", "workers": 0}, "workers: expected an integer >= 1 or None (all CPUs), received 0"),
        ({"name": "local", "workers": 1.5}, "received 1.5"),
        ({"name": "local", "address": "auto"}, "address: expected None with executor='local'"),
    ],
)
def test_make_executor_checks_options(kwargs, words):
    name = kwargs.pop("name")
    with pytest.raises(SweepError) as info:
        make_executor(name, **kwargs)
    assert words in str(info.value)


def test_ray_missing_gives_install_hint(monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda n, *a: None if n == "ray" else real(n, *a))
    with pytest.raises(SweepError, match=r"pip install 'teamnav\[ray\]'"):
        make_executor("ray")


def test_local_executor_keeps_at_most_workers_in_flight(trials):
    seen = []
    t0 = time.perf_counter()
    LocalExecutor(workers=2).run([TrialTask(t, slow_trial) for t in trials], seen.append)
    assert sorted(r.trial_id for r in seen) == sorted(t.trial_id for t in trials)
    assert all(r.status == "ok" for r in seen)
    assert len({r.pid for r in seen}) <= 2  # two worker processes served the four trials
    assert time.perf_counter() - t0 >= 0.6  # 4 trials x 0.3 s on 2 workers


def test_a_kept_local_pool_serves_several_runs_with_the_same_workers(trials, tmp_path, monkeypatch):
    """keep_pool (a report's sweeps share it): the second run reuses the first run's worker
    processes; a worker that dies is replaced and the run goes on; close() ends them."""
    monkeypatch.setenv("TEAMNAV_TEST_MARKERS", str(tmp_path))
    runner = LocalExecutor(workers=2, keep_pool=True)
    try:
        first, second = [], []
        runner.run([TrialTask(t, slow_trial) for t in trials[:2]], first.append)
        runner.run([TrialTask(t, slow_trial) for t in trials[2:]], second.append)
        assert all(r.status == "ok" for r in first + second)
        assert {r.pid for r in second} <= {r.pid for r in first}  # no new worker processes
        third = []
        runner.run([TrialTask(t, dies_once_trial) for t in trials[:2]], third.append)
        # each trial kills its worker once; a death also loses the trial running beside it in the
        # same pool, so a trial is started again once or twice, never more, and both end ok
        assert [r.status for r in third] == ["ok", "ok"] and all(1 <= r.retries <= 2 for r in third), third
        fourth = []
        runner.run([TrialTask(trials[0], ok_trial)], fourth.append)
        assert fourth[0].status == "ok" and fourth[0].pid not in {r.pid for r in first}
    finally:
        runner.close()
    assert runner._kept is None
    runner.close()  # twice is fine


def test_local_and_ray_executors_give_identical_metrics(tmp_path):
    ray = pytest.importorskip("ray")
    grid = {"robots.0.count": [1, 3]}
    local = sweep("demo", grid=grid, seeds=2, duration_s=1, out_dir=tmp_path / "local", workers=2, progress=False)
    assert (local.done, local.failed) == (4, 0)
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        remote = sweep("demo", grid=grid, seeds=2, duration_s=1, out_dir=tmp_path / "ray", executor="ray", workers=2,
                       progress=False)
        assert ray.is_initialized()  # a session the caller started is left running
    finally:
        ray.shutdown()
    assert (remote.done, remote.failed) == (4, 0), remote.failures
    a = {r["trial_id"]: r for r in local.rows()}
    b = {r["trial_id"]: r for r in remote.rows()}
    assert set(a) == set(b) and len(a) == 4
    for tid in a:
        ma = metric_registry.deterministic(a[tid]["metrics"])
        mb = metric_registry.deterministic(b[tid]["metrics"])
        assert ma == mb and ma["steps"] == 10
        assert a[tid]["config_hash"] == b[tid]["config_hash"] and a[tid]["seed"] == b[tid]["seed"]
    # different seeds really give different runs
    seeds = {a[t]["seed"]: a[t]["metrics"]["odom_error_m_mean"] for t in a if a[t]["params"]["robots.0.count"] == 3}
    assert seeds[0] != seeds[1]


def test_ray_executor_starts_and_stops_its_own_local_ray(trials):
    ray = pytest.importorskip("ray")
    assert not ray.is_initialized()
    seen = []
    RayExecutor(workers=2).run([TrialTask(t) for t in trials[:2]], seen.append)
    assert [r.status for r in seen] == ["ok", "ok"], [r.error for r in seen]
    assert not ray.is_initialized()


def test_ray_trial_whose_worker_dies_is_run_again_and_the_result_says_so(trials, tmp_path, monkeypatch):
    """A lost worker is the system's failure, not the trial's: the trial runs again (up to
    RAY_MAX_RETRIES times) and its result carries the retries and what each lost start ended with."""
    ray = pytest.importorskip("ray")
    from teamnav.experiments.executors import RAY_MAX_RETRIES

    import sys

    import ray.cloudpickle

    ray.cloudpickle.register_pickle_by_value(sys.modules[__name__])  # workers cannot import the tests folder
    monkeypatch.setenv("TEAMNAV_TEST_MARKERS", str(tmp_path))
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False,
             runtime_env={"env_vars": {"TEAMNAV_TEST_MARKERS": str(tmp_path)}})
    try:
        seen = []
        RayExecutor(workers=2).run([TrialTask(t, dies_once_trial) for t in trials[:2]], seen.append)
        assert sorted(r.trial_id for r in seen) == sorted(t.trial_id for t in trials[:2])  # each exactly once
        assert all(r.status == "ok" and r.retries == 1 for r in seen), seen
        assert all(len(r.retry_errors) == 1 and r.retry_errors[0] for r in seen)
        gave_up = []
        RayExecutor(workers=1).run([TrialTask(trials[0], always_dies_trial)], gave_up.append)
        assert len(gave_up) == 1 and gave_up[0].status == "failed"
        assert gave_up[0].retries == RAY_MAX_RETRIES and len(gave_up[0].retry_errors) == RAY_MAX_RETRIES + 1
    finally:
        ray.shutdown()


def test_store_records_retries_and_opens_a_store_written_before_the_column(tmp_path):
    """The store's retries / retry_errors columns: written from a result, and added to an older
    store (without them) when it is opened."""
    import sqlite3

    from teamnav.experiments.executors import TrialResult
    from teamnav.experiments.store import ResultsStore

    spec_trials = expand(SweepSpec(scenario="demo", seeds=1, duration_s=0.5))
    path = tmp_path / "old.sqlite"
    with ResultsStore(path):
        pass
    con = sqlite3.connect(path)
    con.execute("ALTER TABLE trials DROP COLUMN retry_errors")
    con.execute("ALTER TABLE trials DROP COLUMN retries")
    con.commit()
    con.close()
    with ResultsStore(path) as store:
        res = TrialResult(spec_trials[0].trial_id, "ok", {"x": 1.0}, None, None, 0.1, "a", "b", "h", 1,
                          retries=2, retry_errors=("NodeDiedError: gone", "WorkerCrashedError: gone"))
        store.record(spec_trials[0], res)
        row = store.rows()[0]
    assert row["retries"] == 2 and "NodeDiedError" in row["retry_errors"]
