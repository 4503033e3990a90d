"""Results store: schema, one transaction per trial, retries, columns per metric, readers."""

from __future__ import annotations

import math
import sqlite3

import pytest

from teamnav.experiments.executors import TrialResult
from teamnav.experiments.store import BASE_COLUMNS, STORE_NAME, ResultsStore, load_dataframe, load_rows
from teamnav.experiments.sweep import Trial


def _trial(tid: str = "t1", count: int = 2, seed: int = 0, **params) -> Trial:
    return Trial(tid, "sw", "demo", "demo", {"robots.0.count": count, **params}, seed, "c0ffee", ("robots.0.count",))


def _result(tid: str = "t1", status: str = "ok", metrics=None, error=None) -> TrialResult:
    if status == "ok" and metrics is None:
        metrics = {"path_length_m_mean": 1.5, "collisions_wall": 0}
    return TrialResult(tid, status, metrics, error, "Traceback ..." if error else None, 0.25,
                       "2026-01-01T00:00:00.000+00:00", "2026-01-01T00:00:01.000+00:00", "host-a", 123)


def test_schema_wal_and_round_trip(tmp_path):
    path = tmp_path / STORE_NAME
    with ResultsStore(path) as store:
        store.record(_trial(), _result())
        assert store.existing() == {"t1": ("ok", "c0ffee")}
    con = sqlite3.connect(path)
    assert con.execute("PRAGMA journal_mode").fetchone() == ("wal",)
    cols = [r[1] for r in con.execute("PRAGMA table_info(trials)")]
    assert cols[: len(BASE_COLUMNS)] == list(BASE_COLUMNS)
    assert cols[len(BASE_COLUMNS):] == ["robots.0.count", "path_length_m_mean", "collisions_wall"]
    assert con.execute('SELECT "robots.0.count", path_length_m_mean, collisions_wall, seed, status FROM trials').fetchone() == (
        2, 1.5, 0, 0, "ok")
    con.close()
    (row,) = load_rows(tmp_path)  # a folder works too
    assert row["params"] == {"robots.0.count": 2} and row["metrics"] == {"path_length_m_mean": 1.5, "collisions_wall": 0}
    assert row["teamnav_version"] and row["attempts"] == 1 and row["host"] == "host-a"


def test_failed_then_ok_replaces_the_row_and_counts_attempts(tmp_path):
    with ResultsStore(tmp_path / STORE_NAME) as store:
        store.record(_trial(), _result(status="failed", error="RuntimeError: boom"))
        (row,) = store.rows()
        assert (row["status"], row["error"], row["metrics"], row["path_length_m_mean"] if "path_length_m_mean" in row else None) == (
            "failed", "RuntimeError: boom", None, None)
        store.record(_trial(), _result())
        (row,) = store.rows()
        assert (row["status"], row["error"], row["traceback"], row["attempts"]) == ("ok", None, None, 2)
        assert row["path_length_m_mean"] == 1.5


def test_colliding_metric_names_get_a_prefix_and_new_metrics_add_columns(tmp_path):
    with ResultsStore(tmp_path / STORE_NAME) as store:
        store.record(_trial("a"), _result("a", metrics={"wall_time_s": 9.0, "seed": 4, "x": 1.0}))
        store.record(_trial("b", count=4, extra=[1, 2]), _result("b", metrics={"wall_time_s": 3.0, "y": "text", "z": math.nan}))
        rows = {r["trial_id"]: r for r in store.rows()}
    assert rows["a"]["wall_time_s"] == 0.25 and rows["a"]["metric_wall_time_s"] == 9.0  # trial time vs the metric
    assert rows["a"]["seed"] == 0 and rows["a"]["metric_seed"] == 4
    assert rows["b"]["y"] == "text" and rows["b"]["x"] is None and rows["a"]["y"] is None
    assert rows["b"]["z"] is None and rows["b"]["metrics"]["z"] is None  # NaN is stored as NULL / JSON null
    assert rows["b"]["extra"] == "[1, 2]"
    con = sqlite3.connect(tmp_path / STORE_NAME)
    mapping = dict(((k, key), n) for n, k, key in con.execute("SELECT name, kind, key FROM columns"))
    assert mapping[("metric", "wall_time_s")] == "metric_wall_time_s" and mapping[("param", "robots.0.count")] == "robots.0.count"
    con.close()


def test_a_failing_write_leaves_no_partial_row_or_column(tmp_path):
    with ResultsStore(tmp_path / STORE_NAME) as store:
        bad = _result("t1", metrics={"new_metric": 1.0})
        object.__setattr__(bad, "started_at", object())  # sqlite3 cannot bind it: the INSERT fails
        with pytest.raises(sqlite3.Error):
            store.record(_trial(), bad)
        assert store.rows() == []
        store.record(_trial("t2"), _result("t2", metrics={"other": 2.0}))
    con = sqlite3.connect(tmp_path / STORE_NAME)
    cols = [r[1] for r in con.execute("PRAGMA table_info(trials)")]
    assert "new_metric" not in cols and "other" in cols  # the ALTER TABLE was rolled back with the row
    con.close()


def test_record_checks_its_inputs(tmp_path):
    with ResultsStore(tmp_path / STORE_NAME) as store:
        with pytest.raises(ValueError, match=r"result.trial_id: expected 't1'.*received 'zz'"):
            store.record(_trial(), _result("zz"))
        with pytest.raises(ValueError, match=r"result.status: expected 'ok' or 'failed', received 'maybe'"):
            store.record(_trial(), _result(status="maybe"))
    with pytest.raises(ValueError, match="store: expected a results.sqlite file"):
        load_rows(tmp_path / "nowhere")


def test_readers_see_committed_rows_while_the_writer_is_open(tmp_path):
    with ResultsStore(tmp_path / STORE_NAME) as store:
        store.record(_trial("a"), _result("a"))
        assert [r["trial_id"] for r in load_rows(tmp_path / STORE_NAME)] == ["a"]
        store.register_sweep("sw", {"scenario": "demo", "seeds": 2})
        store.register_sweep("sw", {"scenario": "demo", "seeds": 3})
    con = sqlite3.connect(tmp_path / STORE_NAME)
    assert con.execute("SELECT name, spec FROM sweeps").fetchall() == [("sw", '{"scenario": "demo", "seeds": 3}')]
    con.close()


def test_pandas_reads_the_table(tmp_path):
    pd = pytest.importorskip("pandas")
    with ResultsStore(tmp_path / STORE_NAME) as store:
        for k in range(3):
            store.record(_trial(f"t{k}", count=k + 1, seed=k), _result(f"t{k}", metrics={"v": float(k)}))
    df = load_dataframe(tmp_path, sweep="sw")
    assert isinstance(df, pd.DataFrame) and len(df) == 3
    assert sorted(df["v"]) == [0.0, 1.0, 2.0] and sorted(df["robots.0.count"]) == [1, 2, 3]


def test_a_trial_keeps_its_cpu_time_and_an_older_store_gains_the_column(tmp_path):
    from teamnav.experiments.executors import TrialTask, execute
    from teamnav.experiments.sweep import expand, load_sweep

    # an older store: one row, then the table as it was before cpu_time_s
    path = tmp_path / STORE_NAME
    with ResultsStore(path) as store:
        store.record(_trial("t0"), _result("t0"))
    con = sqlite3.connect(path)
    con.execute("ALTER TABLE trials DROP COLUMN cpu_time_s")
    con.commit()
    con.close()
    trial = expand(load_sweep("demo-robots"))[0]
    res = execute(TrialTask(trial))
    assert res.status == "ok", res.error
    assert 0.0 < res.cpu_time_s < 60.0 * res.wall_time_s + 1.0  # a real CPU time of this trial
    with ResultsStore(path) as store:
        store.record(trial, res)
    rows = {r["trial_id"]: r for r in load_rows(path)}
    assert rows["t0"]["cpu_time_s"] is None  # written before the column: not measured
    assert rows[trial.trial_id]["cpu_time_s"] == pytest.approx(res.cpu_time_s)
