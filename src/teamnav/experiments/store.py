"""The results store of a sweep: ``OUT/results.sqlite``, one row per finished trial.

A SQLite file (stdlib :mod:`sqlite3`, WAL journal, ``synchronous=FULL``), written only by the
sweep's parent process. Each finished trial is one transaction, committed before its worker
slot gets the next trial, so a sweep killed at any moment (SIGKILL included) leaves every
finished trial in the file and no partial row. Readers (pandas, DuckDB, ``sqlite3``) may read
it while the sweep runs.

Table ``trials`` (a tidy table: one row per trial, one column per variable)::

    trial_id         TEXT PRIMARY KEY   stable id (teamnav.experiments.sweep_trials)
    sweep            TEXT               sweep name
    scenario         TEXT               scenario name
    params           TEXT               JSON: every override of the trial ({key: value})
    seed             INTEGER
    config_hash      TEXT               hash of the resolved scenario without seed
    status           TEXT               'ok' | 'failed'
    metrics          TEXT               JSON: {metric: value} (NULL when failed)
    error            TEXT               "Type: message" (NULL when ok)
    traceback        TEXT
    wall_time_s      REAL               trial wall time in the worker [s]
    cpu_time_s       REAL               the worker's CPU time over the trial [s] (NULL: not measured)
    teamnav_version  TEXT
    started_at       TEXT               ISO 8601 UTC
    finished_at      TEXT
    host             TEXT               worker host name
    attempts         INTEGER            how many times the trial ran (failed ones are retried)
    retries          INTEGER            starts lost with their worker or node and run again (Ray)
    retry_errors     TEXT (JSON list)   what each lost start ended with, or NULL
    <param key>      ...                one column per override key, e.g. "robots.0.count"
    <metric name>    ...                one column per scalar metric, e.g. path_length_m_mean

Parameter and metric columns are added (``ALTER TABLE``) the first time a key appears; a key
that would collide with an existing column gets a ``param_`` / ``metric_`` prefix (so the
runner's ``wall_time_s`` metric is the column ``metric_wall_time_s``). Table ``columns`` maps
every such column to its key, and table ``sweeps`` keeps each sweep's description (JSON).

Examples
--------
Reading a store::

    import sqlite3, pandas as pd
    df = pd.read_sql("SELECT * FROM trials WHERE status = 'ok'", sqlite3.connect("out/results.sqlite"))
    # DuckDB: INSTALL sqlite; SELECT * FROM sqlite_scan('out/results.sqlite', 'trials');
"""

from __future__ import annotations

import json
import math
import os
import sqlite3
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

from teamnav.files import write_cause

if TYPE_CHECKING:  # pragma: no cover
    from teamnav.experiments.trial import Trial, TrialResult

__all__ = ["BASE_COLUMNS", "STORE_NAME", "ResultsStore", "StoreError", "check_store", "load_dataframe", "load_rows"]

#: file name of the store inside a sweep's output folder
STORE_NAME = "results.sqlite"

#: the fixed columns of ``trials`` and their SQL types
BASE_COLUMNS: dict[str, str] = {
    "trial_id": "TEXT PRIMARY KEY NOT NULL",
    "sweep": "TEXT NOT NULL",
    "scenario": "TEXT NOT NULL",
    "params": "TEXT NOT NULL",
    "seed": "INTEGER NOT NULL",
    "config_hash": "TEXT NOT NULL",
    "status": "TEXT NOT NULL CHECK (status IN ('ok', 'failed'))",
    "metrics": "TEXT",
    "error": "TEXT",
    "traceback": "TEXT",
    "wall_time_s": "REAL",
    "teamnav_version": "TEXT",
    "started_at": "TEXT",
    "finished_at": "TEXT",
    "host": "TEXT",
    "attempts": "INTEGER NOT NULL DEFAULT 1",
    "retries": "INTEGER NOT NULL DEFAULT 0",
    "retry_errors": "TEXT",
    "cpu_time_s": "REAL",
}
#: columns added after stores were first written: an older store gets them when opened
_ADDED_COLUMNS = ("retries", "retry_errors", "cpu_time_s")

_SCHEMA = f"""
CREATE TABLE IF NOT EXISTS trials ({", ".join(f"{k} {v}" for k, v in BASE_COLUMNS.items())});
CREATE INDEX IF NOT EXISTS trials_sweep ON trials (sweep, status);
CREATE TABLE IF NOT EXISTS columns (
    name TEXT PRIMARY KEY NOT NULL,
    kind TEXT NOT NULL CHECK (kind IN ('param', 'metric')),
    key TEXT NOT NULL,
    UNIQUE (kind, key)
);
CREATE TABLE IF NOT EXISTS sweeps (
    name TEXT PRIMARY KEY NOT NULL,
    spec TEXT NOT NULL,
    teamnav_version TEXT,
    first_started_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),
    last_started_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))
);
"""


#: columns each table of a teamnav store must have (more are fine: param/metric columns)
_REQUIRED = {
    "trials": tuple(k for k in BASE_COLUMNS if k not in _ADDED_COLUMNS),
    "columns": ("name", "kind", "key"),
    "sweeps": ("name", "spec", "teamnav_version", "first_started_at", "last_started_at"),
}
_SQLITE_MAGIC = b"SQLite format 3\x00"


class StoreError(ValueError):
    """A results store path that holds something other than a teamnav results store (a text
    file, a damaged or truncated SQLite file, a folder, another program's database, a store
    missing a table). The message names the file and what to do."""


def check_store(path: str | os.PathLike) -> None:
    """Refuse ``path`` unless it is absent, empty, or a readable teamnav results store.

    Reads only (the header, the schema and SQLite's ``PRAGMA quick_check``), so a sweep checks
    its store before the first trial and nothing is written on refusal. An SQLite file with no
    tables at all is accepted (it becomes a store).

    Raises
    ------
    StoreError
        Naming the file, what it holds instead, and what to do.
    """
    p = Path(path)
    todo = "use --out with another folder (one that is empty or holds a teamnav sweep's results.sqlite)"
    if not os.path.lexists(p):
        return
    if p.is_dir():
        raise StoreError(f"results store {p}: expected a teamnav results.sqlite file, found a folder; {todo}")
    if not p.is_file():
        raise StoreError(f"results store {p}: expected a teamnav results.sqlite file, found something that is not a file; {todo}")
    try:
        with open(p, "rb") as f:
            head = f.read(100)
    except OSError as exc:
        raise StoreError(f"results store {p}: cannot be read ({exc.strerror or exc}); {todo}") from None
    if not head:
        return  # an empty file: SQLite makes it a new database
    if not head.startswith(_SQLITE_MAGIC):
        try:
            head.decode("utf-8")
            what = "a text file"
        except UnicodeDecodeError:
            what = "a file that is not an SQLite database"
        raise StoreError(f"results store {p}: expected a teamnav results store (an SQLite database), found {what}; {todo}")
    # without a -wal file the main file is the whole database: open it immutable, so the check
    # leaves no -wal/-shm files next to a file it refuses; with one, a normal read-only open
    # replays it (a sweep killed with kill -9 leaves one, and its store is valid)
    wal = Path(f"{p}-wal").exists()
    try:
        con = sqlite3.connect(f"{p.resolve().as_uri()}?mode=ro{'' if wal else '&immutable=1'}", uri=True, timeout=60.0)
    except sqlite3.Error as exc:
        raise StoreError(f"results store {p}: cannot be opened ({exc}); {todo}") from None
    try:
        tables = [name for (name,) in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")]
        have = {t: {row[1] for row in con.execute(f"PRAGMA table_info({_quote(t)})")} for t in tables if t in _REQUIRED}
        check = con.execute("PRAGMA quick_check(5)").fetchall()
    except sqlite3.Error as exc:  # "file is not a database", "database disk image is malformed"
        raise StoreError(f"results store {p}: the SQLite file is damaged or truncated ({exc}); {todo}") from None
    finally:
        con.close()
    if check != [("ok",)]:
        first = check[0][0] if check else "no answer"
        raise StoreError(f"results store {p}: the SQLite file is damaged or truncated (integrity check: {first}); {todo}")
    if not tables:
        return  # an empty database: the store's tables are created in it
    for table, cols in have.items():
        lack = [c for c in _REQUIRED[table] if c not in cols]
        if lack:
            raise StoreError(
                f"results store {p}: table {table} lacks the column(s) {', '.join(lack)} of a teamnav results store "
                f"(another program's table, or an incompatible teamnav version); {todo}"
            )
    missing = [t for t in _REQUIRED if t not in have]
    if missing:
        kind = "another program's database" if not have else "a damaged or partial teamnav store"
        raise StoreError(
            f"results store {p}: expected the tables {', '.join(_REQUIRED)} of a teamnav results store, found "
            f"{', '.join(tables)} (no table {', '.join(missing)}): this looks like {kind}; {todo}"
        )


def _quote(name: str) -> str:
    return '"' + name.replace('"', '""') + '"'


def _sql_type(value: Any) -> str:
    if isinstance(value, bool) or isinstance(value, int):
        return "INTEGER"
    if isinstance(value, float):
        return "REAL"
    return "TEXT"


def _cell(value: Any) -> Any:
    """A value as stored in a param/metric column: numbers and text as is, NaN/inf as NULL,
    anything else (lists, dicts) as JSON text."""
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    return json.dumps(value, sort_keys=True)


def _json(value: Any) -> str:
    """JSON text with NaN and infinities as null (standard JSON, readable by DuckDB)."""

    def clean(v: Any) -> Any:
        if isinstance(v, float) and not math.isfinite(v):
            return None
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v

    return json.dumps(clean(value), sort_keys=True, allow_nan=False)


class ResultsStore:
    """A sweep's SQLite results store (open it with ``with ResultsStore(path) as store:``).

    Parameters
    ----------
    path : str or Path
        The ``.sqlite`` file; created with its tables if missing.
    """

    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        check_store(self.path)
        try:
            self._con = sqlite3.connect(self.path, isolation_level=None, timeout=60.0)
        except sqlite3.Error as exc:
            raise StoreError(f"results store {self.path}: cannot be opened ({exc}); use --out with another folder") from None
        try:
            self._con.execute("PRAGMA journal_mode=WAL")
            self._con.execute("PRAGMA synchronous=FULL")
            self._con.execute("BEGIN IMMEDIATE")
        except sqlite3.Error as exc:  # a read-only folder, a store locked by another process for a minute
            self._con.close()
            raise StoreError(f"results store {self.path}: cannot be written ({write_cause(exc, self.path)}); "
                             "use --out with another folder") from None
        try:
            for stmt in _SCHEMA.split(";"):
                if stmt.strip():
                    self._con.execute(stmt)
            have = {row[1] for row in self._con.execute("PRAGMA table_info(trials)")}
            for col in _ADDED_COLUMNS:
                if col not in have:  # a store written before the column existed
                    self._con.execute(f"ALTER TABLE trials ADD COLUMN {col} {BASE_COLUMNS[col]}")
            self._con.execute("COMMIT")
        except BaseException:
            self._con.execute("ROLLBACK")
            self._con.close()
            raise

    # context manager -------------------------------------------------------------
    def __enter__(self) -> "ResultsStore":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def close(self) -> None:
        self._con.close()

    # reading ----------------------------------------------------------------------
    def existing(self) -> dict[str, tuple[str, str]]:
        """``{trial_id: (status, config_hash)}`` of every stored trial."""
        return {tid: (status, chash) for tid, status, chash in self._con.execute("SELECT trial_id, status, config_hash FROM trials")}

    def rows(self, *, sweep: str | None = None, status: str | None = None) -> list[dict[str, Any]]:
        """Rows of ``trials`` as dicts, with ``params`` and ``metrics`` decoded from JSON."""
        return _rows(self._con, sweep, status)

    # writing ----------------------------------------------------------------------
    def register_sweep(self, name: str, spec: Mapping[str, Any]) -> None:
        """Record (or update) a sweep's description in table ``sweeps``."""
        from teamnav import __version__

        self._con.execute("BEGIN IMMEDIATE")
        try:
            self._con.execute(
                "INSERT INTO sweeps (name, spec, teamnav_version) VALUES (?, ?, ?) ON CONFLICT (name) DO UPDATE SET "
                "spec = excluded.spec, teamnav_version = excluded.teamnav_version, "
                "last_started_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now')",
                (name, _json(dict(spec)), __version__),
            )
            self._con.execute("COMMIT")
        except BaseException:
            self._con.execute("ROLLBACK")
            raise

    def _column(self, kind: str, key: str, value: Any, taken: dict[tuple[str, str], str], names: set[str]) -> str:
        """The column of (kind, key), added to ``trials`` if new (inside the open transaction)."""
        col = taken.get((kind, key))
        if col is not None:
            return col
        col = key
        k = 2
        while col in names or col.lower() in {n.lower() for n in names}:
            col = f"{kind}_{key}" if k == 2 else f"{kind}_{key}_{k}"
            k += 1
        self._con.execute(f"ALTER TABLE trials ADD COLUMN {_quote(col)} {_sql_type(value)}")
        self._con.execute("INSERT INTO columns (name, kind, key) VALUES (?, ?, ?)", (col, kind, key))
        taken[(kind, key)] = col
        names.add(col)
        return col

    def record(self, trial: "Trial", result: "TrialResult") -> None:
        """Write one finished trial, in one transaction (replacing an earlier attempt)."""
        from teamnav import __version__

        if result.trial_id != trial.trial_id:
            raise ValueError(f"result.trial_id: expected {trial.trial_id!r} (the trial's), received {result.trial_id!r}")
        if result.status not in ("ok", "failed"):
            raise ValueError(f"result.status: expected 'ok' or 'failed', received {result.status!r}")
        con = self._con
        con.execute("BEGIN IMMEDIATE")
        try:
            taken = {(kind, key): name for name, kind, key in con.execute("SELECT name, kind, key FROM columns")}
            names = {row[1] for row in con.execute("PRAGMA table_info(trials)")}
            row: dict[str, Any] = {
                "trial_id": trial.trial_id,
                "sweep": trial.sweep,
                "scenario": trial.scenario_name,
                "params": _json(trial.params),
                "seed": int(trial.seed),
                "config_hash": trial.config_hash,
                "status": result.status,
                "metrics": _json(result.metrics) if result.metrics is not None else None,
                "error": result.error,
                "traceback": result.traceback,
                "wall_time_s": _cell(float(result.wall_time_s)),
                "teamnav_version": __version__,
                "started_at": result.started_at,
                "finished_at": result.finished_at,
                "host": result.host,
                "retries": int(getattr(result, "retries", 0)),
                "retry_errors": _json(list(result.retry_errors)) if getattr(result, "retry_errors", ()) else None,
                "cpu_time_s": _cell(float(result.cpu_time_s)) if getattr(result, "cpu_time_s", None) is not None else None,
            }
            for key, value in trial.params.items():
                row[self._column("param", key, value, taken, names)] = _cell(value)
            for key, value in (result.metrics or {}).items():
                row[self._column("metric", key, value, taken, names)] = _cell(value)
            prev = con.execute("SELECT attempts FROM trials WHERE trial_id = ?", (trial.trial_id,)).fetchone()
            row["attempts"] = (prev[0] + 1) if prev else 1
            cols = ", ".join(_quote(c) for c in row)
            marks = ", ".join("?" for _ in row)
            con.execute(f"INSERT OR REPLACE INTO trials ({cols}) VALUES ({marks})", tuple(row.values()))
            con.execute("COMMIT")
        except BaseException:
            con.execute("ROLLBACK")
            raise


def _select_trials(sweep: str | None, status: str | None) -> tuple[str, list[str]]:
    """The SELECT over ``trials`` filtered by sweep name and status, with its arguments."""
    where, args = [], []
    if sweep is not None:
        where.append("sweep = ?")
        args.append(sweep)
    if status is not None:
        where.append("status = ?")
        args.append(status)
    sql = "SELECT * FROM trials" + (" WHERE " + " AND ".join(where) if where else "") + " ORDER BY sweep, finished_at, trial_id"
    return sql, args


def _rows(con: sqlite3.Connection, sweep: str | None, status: str | None) -> list[dict[str, Any]]:
    sql, args = _select_trials(sweep, status)
    cur = con.execute(sql, args)
    names = [d[0] for d in cur.description]
    out = []
    for values in cur:
        row = dict(zip(names, values))
        row["params"] = json.loads(row["params"]) if row["params"] else {}
        row["metrics"] = json.loads(row["metrics"]) if row["metrics"] else None
        out.append(row)
    return out


def _store_file(path: str | os.PathLike) -> Path:
    p = Path(path)
    if p.is_dir():
        p = p / STORE_NAME
    if not p.is_file():
        raise ValueError(f"store: expected a results.sqlite file or a sweep folder holding one, received {str(path)!r}")
    check_store(p)
    return p


def load_rows(path: str | os.PathLike, *, sweep: str | None = None, status: str | None = None) -> list[dict[str, Any]]:
    """Rows of a store (file or sweep folder) as dicts; ``params``/``metrics`` decoded.

    Opens the file read-only, so it is safe while a sweep writes it.
    """
    con = sqlite3.connect(f"{_store_file(path).resolve().as_uri()}?mode=ro", uri=True, timeout=60.0)
    try:
        return _rows(con, sweep, status)
    finally:
        con.close()


def load_dataframe(path: str | os.PathLike, *, sweep: str | None = None, status: str | None = None):
    """The ``trials`` table as a pandas DataFrame (``params``/``metrics`` left as JSON text).

    Raises
    ------
    ImportError
        When pandas is not installed.
    """
    try:
        import pandas as pd
    except ImportError:
        raise ImportError("load_dataframe needs pandas (pip install pandas); load_rows returns plain dicts") from None
    sql, args = _select_trials(sweep, status)
    con = sqlite3.connect(f"{_store_file(path).resolve().as_uri()}?mode=ro", uri=True, timeout=60.0)
    try:
        return pd.read_sql(sql, con, params=args)
    finally:
        con.close()
