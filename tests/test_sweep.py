"""Sweeps: grid parsing and validation, trial ids, resume after SIGKILL, failing trials, CLI.

Trials that run in worker processes use the fake trial functions below (module level, so
``spawn`` workers import them by reference); each appends a line to the file named by
``TEAMNAV_TEST_SWEEP_LOG`` when it starts, which is how the tests count executions.
"""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from teamnav.experiments.sweep import (
    SweepError,
    SweepSpec,
    expand,
    load_sweep,
    parse_grid,
    parse_seeds,
    parse_set,
    resolve_spec,
    sweep,
    sweep_names,
    trial_id,
)
from teamnav.experiments.sweep_cli import sweep_command

LOG_ENV = "TEAMNAV_TEST_SWEEP_LOG"
SLEEP_ENV = "TEAMNAV_TEST_SWEEP_SLEEP_S"
TESTS = Path(__file__).resolve().parent


# ---------------------------------------------------------------------------- fake trials
def _log(line: str) -> None:
    path = os.environ.get(LOG_ENV)
    if path:
        with open(path, "a", encoding="utf-8") as f:  # one short O_APPEND write: atomic
            f.write(line + "\n")


def fake_trial(scenario, out_dir):
    """Metrics computed from the trial's count and seed; raises for count 3."""
    count = scenario.robots[0].count
    _log(f"start {count} {scenario.seed} {time.time():.6f}")
    time.sleep(float(os.environ.get(SLEEP_ENV, "0")))
    if count == 3:
        raise RuntimeError(f"boom at count {count}")
    return {"value": count * 1000 + scenario.seed, "half": count / 2, "as_numpy": np.float64(count), "flag": count > 1}


def crash_trial(scenario, out_dir):
    """Kills its worker process outright for count 3."""
    count = scenario.robots[0].count
    _log(f"start {count} {scenario.seed}")
    if count == 3:
        os._exit(3)
    return {"value": count * 1000 + scenario.seed}


def _executions(log: Path) -> list[str]:
    return log.read_text().splitlines() if log.exists() else []


@pytest.fixture
def log(tmp_path, monkeypatch):
    path = tmp_path / "executions.log"
    monkeypatch.setenv(LOG_ENV, str(path))
    monkeypatch.setenv(SLEEP_ENV, "0")
    return path


def _ok_rows(out: Path) -> list[tuple]:
    con = sqlite3.connect(out / "results.sqlite")
    try:
        return con.execute("SELECT trial_id, finished_at, attempts FROM trials WHERE status = 'ok'").fetchall()
    finally:
        con.close()


# ---------------------------------------------------------------------------- parsing
def test_parse_grid_reads_yaml_scalars_in_order():
    grid = parse_grid(["robots.0.count=2,4,8", "radio.mode=range, los", "radio.p_loss=0.0,0.25", "a.b=true,'x,y',[1, 2]"])
    assert grid == {
        "robots.0.count": [2, 4, 8],
        "radio.mode": ["range", "los"],
        "radio.p_loss": [0.0, 0.25],
        "a.b": [True, "x,y", [1, 2]],
    }
    assert list(grid) == ["robots.0.count", "radio.mode", "radio.p_loss", "a.b"]


@pytest.mark.parametrize(
    "items, words",
    [
        (["noequals"], ["--grid", "KEY=V1,V2", "'noequals'"]),
        (["=1,2"], ["--grid", "dotted key", "'=1,2'"]),
        (["robots.0.count="], ["--grid robots.0.count", "one or more", "''"]),
        (["robots.0.count=1,,2"], ["--grid robots.0.count", "'1,,2'"]),
        (["robots.0.count=1,2", "robots.0.count=3"], ["--grid robots.0.count", "once"]),
        (["a=[1,"], ["--grid a", "YAML", "'[1,'"]),
    ],
)
def test_parse_grid_rejects_malformed_items_naming_key_and_value(items, words):
    with pytest.raises(SweepError) as info:
        parse_grid(items)
    for w in words:
        assert w in str(info.value)


def test_parse_seeds_and_set():
    assert parse_seeds("5") == 5
    assert parse_seeds(" 1,4,9") == [1, 4, 9]
    assert parse_seeds([3, 7]) == [3, 7]
    assert parse_seeds(None) is None
    with pytest.raises(SweepError, match=r"--seeds: expected a count N .* received 'many'"):
        parse_seeds("many")
    # ranges are inclusive; a single number stays a count (1000 seeds), "1000-1000" is seed 1000 alone
    assert parse_seeds("1000-1002") == [1000, 1001, 1002]
    assert parse_seeds("1000-1000") == [1000]
    assert parse_seeds("1, 4,10-12") == [1, 4, 10, 11, 12]
    assert parse_seeds("1000") == 1000
    for bad in ("9-3", "1-", "1-2-3", "a-b"):
        with pytest.raises(SweepError, match="range such as 1000-1009"):
            parse_seeds(bad)
    assert parse_set(["radio.p_loss=0.1", "robots.0.params.cruise_speed_mps=0.3"]) == {
        "radio.p_loss": 0.1,
        "robots.0.params.cruise_speed_mps": 0.3,
    }
    with pytest.raises(SweepError, match="--set: expected KEY=VALUE"):
        parse_set(["radio.p_loss"])


@pytest.mark.parametrize(
    "data, words",
    [
        ({"scenario": "demo", "seeds": 0}, ["seeds", "received 0"]),
        ({"scenario": "demo", "seeds": []}, ["seeds", "non-empty"]),
        ({"scenario": "demo", "seeds": [1, 2, 1]}, ["seeds", "distinct", "1"]),
        ({"scenario": "demo", "seeds": [-1]}, ["seeds", "-1"]),
        ({"scenario": "demo", "grid": {"robots.0.count": []}}, ["grid robots.0.count", "non-empty", "[]"]),
        ({"scenario": "demo", "grid": {"seed": [1, 2]}}, ["seed", "use seeds"]),
        ({"scenario": "demo", "grid": {"a": [1]}, "set": {"a": 2}}, ["'a'", "only one of grid and set"]),
        ({"scenario": "demo", "duration_s": -1}, ["duration_s", "-1"]),
        ({"scenario": "demo", "gird": {}}, ["gird", "unknown key", "did you mean 'grid'"]),
    ],
)
def test_bad_sweep_description_gives_one_clear_error(data, words):
    with pytest.raises(SweepError) as info:
        _validate(data)
    text = str(info.value)
    for w in words:
        assert w in text, (w, text)


def _validate(data):
    from teamnav.experiments.sweep import _validate_spec

    return _validate_spec(data, "under test")


# ---------------------------------------------------------------------------- expand
def test_expand_is_the_cartesian_product_with_stable_distinct_ids():
    spec = SweepSpec(scenario="demo", grid={"robots.0.count": [1, 2, 4], "radio.range_m": [5.0, 10.0]}, seeds=[3, 7], duration_s=1)
    trials = expand(spec)
    assert len(trials) == spec.n_trials == 12
    combos = [(t.params["robots.0.count"], t.params["radio.range_m"], t.seed) for t in trials]
    assert combos == [(c, r, s) for c in (1, 2, 4) for r in (5.0, 10.0) for s in (3, 7)]
    assert len({t.trial_id for t in trials}) == 12
    again = expand(SweepSpec(scenario="demo", grid={"radio.range_m": [10.0, 5.0], "robots.0.count": [4, 2, 1]}, seeds=[7, 3], duration_s=1))
    assert {t.trial_id for t in again} == {t.trial_id for t in trials}  # ids do not depend on order
    # same configuration, different seeds: same config hash; different counts: different hashes
    by = {(t.params["robots.0.count"], t.params["radio.range_m"], t.seed): t for t in trials}
    assert by[(1, 5.0, 3)].config_hash == by[(1, 5.0, 7)].config_hash
    assert by[(1, 5.0, 3)].config_hash != by[(2, 5.0, 3)].config_hash
    assert by[(1, 5.0, 3)].trial_id == trial_id("demo", {"robots.0.count": 1, "radio.range_m": 5.0, "duration_s": 1.0}, 3)
    # each trial loads to the scenario it names
    scn = by[(4, 10.0, 7)].load()
    assert (scn.robots[0].count, scn.radio.range_m, scn.seed, scn.duration_s) == (4, 10.0, 7, 1.0)


def test_trial_id_changes_with_fixed_overrides_and_duration():
    a = expand(SweepSpec(scenario="demo", seeds=1))[0]
    b = expand(SweepSpec(scenario="demo", seeds=1, set={"radio.range_m": 5.0}))[0]
    c = expand(SweepSpec(scenario="demo", seeds=1, duration_s=3))[0]
    assert len({a.trial_id, b.trial_id, c.trial_id}) == 3
    assert b.params == {"radio.range_m": 5.0}


def test_malformed_grid_fails_before_running_with_one_error_naming_key_type_value(tmp_path, log):
    with pytest.raises(SweepError) as info:
        sweep("demo", grid=["robots.0.count=2,fast", "radio.range_m=5.0,near"], seeds=2, out_dir=tmp_path / "out",
              trial_fn=fake_trial, progress=False)
    text = str(info.value)
    assert "2 invalid grid values" in text
    assert "grid robots.0.count='fast'" in text and "integer" in text
    assert "grid radio.range_m='near'" in text and "number" in text
    assert _executions(log) == [] and not (tmp_path / "out").exists()


def test_unknown_grid_key_is_named(tmp_path):
    with pytest.raises(SweepError, match=r"grid robots\.0\.speeed=1: robots\[0\]\.speeed: unknown key"):
        expand(resolve_spec("demo", grid=["robots.0.speeed=1,2"]))


def test_invalid_fixed_set_reports_the_scenario_error():
    with pytest.raises(SweepError, match=r"the scenario is invalid with set .*radio\.range_m"):
        expand(resolve_spec("demo", set=["radio.range_m=-3"], grid=["robots.0.count=1,2"]))


def test_named_sweep_is_shipped_and_valid():
    assert "demo-robots" in sweep_names()
    spec = load_sweep("demo-robots")
    assert spec.scenario == "demo" and spec.sweep_name == "demo-robots"
    trials = expand(spec)
    assert len(trials) == spec.n_trials >= 2
    with pytest.raises(SweepError, match="did you mean 'demo-robots'"):
        load_sweep("demo-robot")


def test_sweep_file_relative_scenario_and_option_merging(tmp_path):
    (tmp_path / "scn").mkdir()
    (tmp_path / "scn" / "mine.yaml").write_text((Path(__file__).parents[1] / "src/teamnav/experiments/scenarios/demo.yaml").read_text())
    f = tmp_path / "s.yaml"
    f.write_text("scenario: scn/mine.yaml\ngrid:\n  robots.0.count: [1, 2]\nseeds: 2\nset:\n  radio.range_m: 4.0\n")
    spec = resolve_spec(str(f), grid=["radio.range_m=6.0,7.0"], seeds="5,6")
    assert Path(spec.scenario) == tmp_path / "scn" / "mine.yaml"
    assert spec.sweep_name == "s"
    assert spec.grid == {"robots.0.count": [1, 2], "radio.range_m": [6.0, 7.0]}
    assert spec.set == {} and spec.seed_list == [5, 6]
    assert len(expand(spec)) == 8


# ---------------------------------------------------------------------------- running
def test_failing_trial_is_recorded_and_the_rest_complete_then_retried(tmp_path, log):
    out = tmp_path / "out"
    res = sweep("demo", grid={"robots.0.count": [1, 2, 3]}, seeds=2, duration_s=1, out_dir=out, workers=2,
                trial_fn=fake_trial, progress=False)
    assert (res.total, res.done, res.failed, res.skipped) == (6, 4, 2, 0)
    rows = res.rows()
    assert len(rows) == 6
    failed = [r for r in rows if r["status"] == "failed"]
    assert sorted(r["params"]["robots.0.count"] for r in failed) == [3, 3]
    for r in failed:
        assert r["error"] == "RuntimeError: boom at count 3"
        assert "fake_trial" in r["traceback"] and r["metrics"] is None and r["value"] is None
    ok = {(r["params"]["robots.0.count"], r["seed"]): r for r in rows if r["status"] == "ok"}
    assert ok[(2, 1)]["metrics"] == {"value": 2001, "half": 1.0, "as_numpy": 2.0, "flag": True}
    assert ok[(2, 1)]["value"] == 2001 and ok[(2, 1)]["flag"] == 1  # one column per scalar metric
    assert len(_executions(log)) == 6
    assert {f["label"] for f in res.failures} == {"robots.0.count=3 seed=0", "robots.0.count=3 seed=1"}

    # rerun: only the failed trials run again (and fail again)
    res2 = sweep("demo", grid={"robots.0.count": [1, 2, 3]}, seeds=2, duration_s=1, out_dir=out, workers=2,
                 trial_fn=fake_trial, progress=False)
    assert (res2.done, res2.failed, res2.skipped) == (0, 2, 4)
    assert len(_executions(log)) == 8
    assert sorted(r["attempts"] for r in res2.rows()) == [1, 1, 1, 1, 2, 2]
    # ... unless told to skip them
    res3 = sweep("demo", grid={"robots.0.count": [1, 2, 3]}, seeds=2, duration_s=1, out_dir=out, workers=1,
                 trial_fn=fake_trial, progress=False, retry_failed=False)
    assert (res3.done, res3.failed, res3.skipped) == (0, 0, 6)
    assert len(_executions(log)) == 8


def test_rerun_skips_finished_trials_and_extends_a_grown_sweep(tmp_path, log):
    out = tmp_path / "out"
    first = sweep("demo", grid={"robots.0.count": [1, 2]}, seeds=2, duration_s=1, out_dir=out, workers=1,
                  trial_fn=fake_trial, progress=False)
    assert (first.done, first.skipped) == (4, 0)
    before = sorted(_ok_rows(out))
    again = sweep("demo", grid={"robots.0.count": [1, 2]}, seeds=2, duration_s=1, out_dir=out, workers=1,
                  trial_fn=fake_trial, progress=False)
    assert (again.done, again.failed, again.skipped) == (0, 0, 4)
    assert len(_executions(log)) == 4
    assert sorted(_ok_rows(out)) == before  # untouched
    grown = sweep("demo", grid={"robots.0.count": [1, 2, 4]}, seeds=3, duration_s=1, out_dir=out, workers=1,
                  trial_fn=fake_trial, progress=False)
    assert (grown.done, grown.skipped) == (5, 4)
    assert len(_executions(log)) == 9
    assert len(_ok_rows(out)) == 9


def test_store_with_another_configuration_under_the_same_ids_is_refused(tmp_path, log):
    scn = tmp_path / "mine.yaml"
    demo = (Path(__file__).parents[1] / "src/teamnav/experiments/scenarios/demo.yaml").read_text()
    scn.write_text(demo)
    out = tmp_path / "out"
    sweep(str(scn), seeds=1, duration_s=1, out_dir=out, workers=1, trial_fn=fake_trial, progress=False)
    scn.write_text(demo.replace("max_v_mps: 0.6", "max_v_mps: 0.7"))  # same name, params, seed; new config
    with pytest.raises(SweepError, match=r"config hash .* new folder"):
        sweep(str(scn), seeds=1, duration_s=1, out_dir=out, workers=1, trial_fn=fake_trial, progress=False)
    assert len(_executions(log)) == 1


def test_unpicklable_trial_fn_is_refused_before_anything_runs(tmp_path):
    with pytest.raises(SweepError, match=r"trial_fn: expected a module-level function .* cannot be pickled"):
        sweep("demo", seeds=1, out_dir=tmp_path / "o", trial_fn=lambda scn, out: {"x": 1}, progress=False)
    assert not (tmp_path / "o").exists()


def test_a_worker_that_dies_fails_its_trial_and_the_sweep_goes_on(tmp_path, log):
    res = sweep("demo", grid={"robots.0.count": [1, 3, 2]}, seeds=1, duration_s=1, out_dir=tmp_path / "o", workers=1,
                trial_fn=crash_trial, progress=False)
    assert (res.done, res.failed) == (2, 1)
    (bad,) = [r for r in res.rows() if r["status"] == "failed"]
    assert bad["params"]["robots.0.count"] == 3 and bad["error"].startswith("WorkerDied")
    # a lost start is run again (LOCAL_MAX_RETRIES times) before the trial counts as failed
    from teamnav.experiments.executors import LOCAL_MAX_RETRIES

    assert bad["retries"] == LOCAL_MAX_RETRIES and bad["retry_errors"].count("WorkerDied") == LOCAL_MAX_RETRIES + 1
    # each lost start says how the pool's workers ended (crash_trial leaves by os._exit(3))
    assert "pid " in bad["error"] and "exit status 3" in bad["error"]


def test_each_result_is_committed_before_its_slot_runs_the_next_trial(tmp_path, log, monkeypatch):
    from teamnav.experiments import store as store_mod

    commits: list[float] = []
    real = store_mod.ResultsStore.record

    def record(self, trial, result):
        real(self, trial, result)
        commits.append(time.time())

    monkeypatch.setattr(store_mod.ResultsStore, "record", record)
    sweep("demo", grid={"robots.0.count": [1, 2, 4]}, seeds=2, duration_s=1, out_dir=tmp_path / "o", workers=1,
          trial_fn=fake_trial, progress=False)
    starts = [float(line.split()[3]) for line in _executions(log)]
    assert len(starts) == len(commits) == 6
    for k in range(5):
        assert commits[k] <= starts[k + 1], f"trial {k + 1} started before trial {k} was committed"


_KILLED_SWEEP = textwrap.dedent(
    """
    import sys
    sys.path.insert(0, {tests!r})
    from test_sweep import fake_trial
    from teamnav.experiments.sweep import sweep
    if __name__ == "__main__":
        sweep("demo", grid={{"robots.0.count": [1, 2]}}, seeds=6, duration_s=1, out_dir={out!r}, workers=2,
              trial_fn=fake_trial, progress=False)
    """
)


def test_sweep_killed_with_sigkill_resumes_with_every_trial_exactly_once(tmp_path, log, monkeypatch):
    out = tmp_path / "out"
    monkeypatch.setenv(SLEEP_ENV, "0.4")
    code = _KILLED_SWEEP.format(tests=str(TESTS), out=str(out))
    proc = subprocess.Popen([sys.executable, "-c", code], start_new_session=True, env=dict(os.environ))
    deadline = time.monotonic() + 120
    try:
        while True:
            try:
                n = len(_ok_rows(out))
            except sqlite3.OperationalError:  # not created yet
                n = 0
            if n >= 3:
                break
            assert proc.poll() is None, "the sweep ended before it could be killed"
            assert time.monotonic() < deadline, "the sweep made no progress"
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the parent and its worker processes, mid-run
        proc.wait()
    con = sqlite3.connect(out / "results.sqlite")
    assert con.execute("PRAGMA integrity_check").fetchone() == ("ok",)
    con.close()
    survived = dict((tid, fin) for tid, fin, _ in _ok_rows(out))
    assert 3 <= len(survived) < 12
    runs_before = len(_executions(log))

    monkeypatch.setenv(SLEEP_ENV, "0")
    res = sweep("demo", grid={"robots.0.count": [1, 2]}, seeds=6, duration_s=1, out_dir=out, workers=2,
                trial_fn=fake_trial, progress=False)
    assert res.skipped == len(survived) and res.done == 12 - len(survived) and res.failed == 0
    assert len(_executions(log)) - runs_before == 12 - len(survived)  # only the missing trials ran
    rows = _ok_rows(out)
    ids = [tid for tid, _, _ in rows]
    expected = {t.trial_id for t in expand(resolve_spec("demo", grid={"robots.0.count": [1, 2]}, seeds=6, duration_s=1))}
    assert len(ids) == len(set(ids)) == 12 and set(ids) == expected
    assert all(attempts == 1 for _, _, attempts in rows)
    for tid, fin, _ in rows:  # rows written before the kill are the ones still there
        if tid in survived:
            assert fin == survived[tid]


# ---------------------------------------------------------------------------- CLI
def _app() -> typer.Typer:
    app = typer.Typer()

    @app.callback()
    def _root() -> None:
        """test app"""

    app.command("sweep")(sweep_command)
    return app


def test_cli_bad_grid_exits_2_with_one_message_and_no_traceback(tmp_path):
    result = CliRunner().invoke(_app(), ["sweep", "demo", "--grid", "robots.0.count=2,fast", "--out", str(tmp_path / "o")])
    assert result.exit_code == 2, result.output
    assert "grid robots.0.count='fast'" in result.output and "integer" in result.output
    assert "Traceback" not in result.output and not (tmp_path / "o").exists()
    for args, words in [
        (["--grid", "noequals"], "--grid: expected KEY=V1,V2"),
        (["--seeds", "x"], "--seeds"),
        (["--executor", "dask"], "executor: expected one of 'local', 'ray', received 'dask'"),
        (["--workers", "0"], "workers: expected an integer >= 1"),
        (["--address", "auto"], "address: expected None with executor='local'"),
    ]:
        r = CliRunner().invoke(_app(), ["sweep", "demo", "--out", str(tmp_path / "o"), *args])
        assert r.exit_code == 2 and words in r.output and "Traceback" not in r.output, (args, r.output)
    r = CliRunner().invoke(_app(), ["sweep", "no-such-scenario", "--out", str(tmp_path / "o")])
    assert r.exit_code == 2 and "unknown scenario 'no-such-scenario'" in r.output


def test_cli_runs_a_real_sweep_quietly_and_resumes(tmp_path):
    out = tmp_path / "o"
    args = ["sweep", "demo", "--grid", "robots.0.count=1,2", "--seeds", "1", "--duration", "0.5", "--out", str(out), "-j", "2", "-q"]
    r = CliRunner().invoke(_app(), args)
    assert r.exit_code == 0, r.output
    assert r.output.strip().splitlines() == [r.output.strip()]  # one line
    assert "2 ok, 0 failed, 0 skipped" in r.output and str(out / "results.sqlite") in r.output
    con = sqlite3.connect(out / "results.sqlite")
    rows = con.execute('SELECT status, steps, "robots.0.count" FROM trials ORDER BY "robots.0.count"').fetchall()
    con.close()
    assert rows == [("ok", 5, 1), ("ok", 5, 2)]
    r2 = CliRunner().invoke(_app(), args)
    assert r2.exit_code == 0 and "0 ok, 0 failed, 2 skipped" in r2.output


def test_cli_trial_failing_at_run_time_exits_1_and_the_rest_is_stored_with_artifacts(tmp_path):
    # 400 robots pass validation but cannot be placed in the start region: the run raises
    out = tmp_path / "o"
    args = ["sweep", "demo", "--grid", "robots.0.count=1,400", "--duration", "0.5", "--out", str(out), "-j", "1", "--artifacts"]
    r = CliRunner().invoke(_app(), args)
    assert r.exit_code == 1, r.output
    assert "1 ok, 1 failed" in r.output and "could not place robot" in r.output and "robots.0.count=400" in r.output
    con = sqlite3.connect(out / "results.sqlite")
    rows = dict(con.execute('SELECT "robots.0.count", status FROM trials').fetchall())
    (ok_id,) = con.execute("SELECT trial_id FROM trials WHERE status = 'ok'").fetchone()
    con.close()
    assert rows == {1: "ok", 400: "failed"}
    assert (out / "trials" / ok_id / "metrics.json").is_file()  # the ok trial's run folder


def test_progress_bar_shows_counts_on_stderr(tmp_path, log, capfd):
    sweep("demo", grid={"robots.0.count": [1, 3]}, seeds=1, duration_s=1, out_dir=tmp_path / "o", workers=1,
          trial_fn=fake_trial, progress=True)
    err = capfd.readouterr().err
    assert "sweep demo" in err and "2/2" in err and "1 ok" in err and "1 failed" in err
    sweep("demo", grid={"robots.0.count": [1, 3]}, seeds=1, duration_s=1, out_dir=tmp_path / "o", workers=1,
          trial_fn=fake_trial, progress=False)
    assert capfd.readouterr().err == ""


def test_cases_tie_overrides_together_before_the_grid():
    spec = SweepSpec(
        scenario="demo", seeds=2, duration_s=1,
        grid={"radio.p_loss": [0.0, 0.5]},
        cases=[{"case": "two", "robots.0.count": 2, "robots.0.radius_m": 0.2},
               {"case": "three", "robots.0.count": 3}],
    )
    trials = expand(spec)
    assert spec.n_trials == len(trials) == 2 * 2 * 2
    first = trials[0]
    assert first.params == {"robots.0.count": 2, "robots.0.radius_m": 0.2, "radio.p_loss": 0.0,
                            "duration_s": 1.0, "case": "two"}
    assert "case" not in first.overrides and first.load().robots[0].count == 2
    assert [t.params["case"] for t in trials] == ["two"] * 4 + ["three"] * 4
    assert trials[-1].load().robots[0].count == 3
    assert first.label().startswith("case=two ")
    assert len({t.trial_id for t in trials}) == len(trials)


@pytest.mark.parametrize("cases, match", [
    ([{"robots.0.count": 2}], "label under 'case'"),
    ([{"case": "a", "robots.0.count": 2}, {"case": "a", "robots.0.count": 3}], "distinct labels"),
    ([{"case": "a"}], "at least one override"),
    ([{"case": "a", "radio.p_loss": 0.1}], "also a grid key"),
])
def test_bad_cases_get_one_clear_error(cases, match):
    with pytest.raises(ValueError, match=match):
        SweepSpec(scenario="demo", grid={"radio.p_loss": [0.0, 0.5]}, cases=cases)


def test_an_invalid_case_names_the_case():
    spec = SweepSpec(scenario="demo", cases=[{"case": "broken", "robots.0.count": -1}])
    with pytest.raises(SweepError, match="in case 'broken'"):
        expand(spec)


def test_cli_name_option_names_the_sweep(tmp_path):
    from typer.testing import CliRunner

    from teamnav.cli import app

    res = CliRunner().invoke(app, ["sweep", "demo", "--duration", "0.3", "--name", "demo-renamed", "--out",
                                   str(tmp_path / "s"), "--workers", "1", "--quiet"])
    assert res.exit_code == 0, res.output
    with sqlite3.connect(tmp_path / "s" / "results.sqlite") as con:
        assert con.execute("select distinct sweep from trials").fetchall() == [("demo-renamed",)]
    bad = CliRunner().invoke(app, ["sweep", "demo", "--name", "no spaces", "--out", str(tmp_path / "t")])
    assert bad.exit_code == 2 and "name" in bad.output


def test_trials_are_scheduled_longest_first_from_recorded_times_or_robot_steps():
    """The longest expected trials go first (commit 6dbc5ab, 2026-11-27) (measured wall time of the same
    configuration where the store has one, else robot-steps at the measured rate), ties in the
    sweep's order."""
    from teamnav.experiments.sweep import longest_first

    trials = expand(SweepSpec(scenario="demo", grid={"robots.0.count": [2, 8, 4]}, seeds=2, duration_s=1))
    by_count = {}
    for t in trials:
        by_count.setdefault(t.params["robots.0.count"], []).append(t)
    assert by_count[8][0].work == 4 * by_count[2][0].work == 8 * 10  # 8 robots x 10 steps
    # nothing measured: robot-steps decide, seeds keep their order
    order = [t.params["robots.0.count"] for t in longest_first(trials, trials, [])]
    assert order == [8, 8, 4, 4, 2, 2]
    # the store says the 2-robot configuration took 60 s and the 8-robot one 10 s (measured
    # beats robot-steps); the unmeasured 4-robot one is ranked at the median seconds per
    # robot-step of the measured ones (3 s: 120 s expected)
    rows = [{"config_hash": by_count[2][0].config_hash, "wall_time_s": 60.0},
            {"config_hash": by_count[8][0].config_hash, "wall_time_s": 10.0}]
    first = longest_first(trials, trials, rows)
    assert [t.params["robots.0.count"] for t in first] == [4, 4, 2, 2, 8, 8]
    assert [t.seed for t in first[2:4]] == [by_count[2][0].seed, by_count[2][1].seed]


def test_a_case_key_into_a_dict_of_set_does_not_leak_into_other_cases():
    """A case's dotted key (robots.0.params.x) into a dict that ``set`` gives whole
    (robots.0.params: {...}) changes that case only: overrides are copied, not shared (the
    trials of a sweep hold the same ``set`` objects)."""
    from teamnav.experiments.sweep import SweepSpec

    spec = SweepSpec(scenario="demo", seeds=1,
                     set={"robots.0.params": {"cruise_speed_mps": 0.3}},
                     cases=[{"case": "a", "robots.0.params.turn_rate_radps": 0.5}, {"case": "b", "robots.0.count": 2}])
    a, b = expand(spec)
    sa, sb = a.load(), b.load()
    assert sa.robots[0].params["turn_rate_radps"] == 0.5
    assert "turn_rate_radps" not in sb.robots[0].params and sb.robots[0].params["cruise_speed_mps"] == 0.3
    assert spec.set["robots.0.params"] == {"cruise_speed_mps": 0.3}
