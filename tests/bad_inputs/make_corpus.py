"""Regenerate the binary and generated cases of this corpus (``python tests/bad_inputs/make_corpus.py``).

The hand-written cases (the YAML scenarios, the JSON files, ``expect.txt``) are edited by hand;
this script writes the cases that are easier to make than to type: ``.npz`` archives, SQLite
stores, the deeply nested and the alias-bomb scenarios. It is deterministic (fixed seeds, no
timestamps) except that the SQLite stores hold the time they were made. See README.md for what
each case is.
"""

from __future__ import annotations

import io
import shutil
import sqlite3
import zipfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
T, N = 11, 2  # the shape of the run folder the tests make (`teamnav run demo --duration 1 --set robots.0.count=2`)


def _traj(**change) -> dict:
    rng = np.random.default_rng(0)
    arrays = {
        "t_s": np.arange(T) * 0.1,
        "step": np.arange(T, dtype=np.int64),
        "true_pose": (rng.uniform(10, 20, (T, N, 3))).astype(np.float32),
        "odom_pose": (rng.uniform(-1, 1, (T, N, 3))).astype(np.float32),
        "stalled": np.zeros((T, N), bool),
    }
    arrays.update(change)
    return {k: v for k, v in arrays.items() if v is not None}


def _npz(path: Path, arrays: dict, *, allow_pickle: bool = False) -> None:
    """An .npz with fixed zip timestamps (np.savez stamps the current time)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        for k, v in arrays.items():
            info = zipfile.ZipInfo(f"{k}.npy", date_time=(2020, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            one = io.BytesIO()
            np.lib.format.write_array(one, np.asanyarray(v), allow_pickle=allow_pickle)
            zf.writestr(info, one.getvalue())
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(buf.getvalue())


def run_folders() -> None:
    rf = HERE / "run_folders"
    _npz(rf / "_tmp.npz", _traj())
    good = (rf / "_tmp.npz").read_bytes()
    (rf / "_tmp.npz").unlink()
    (rf / "truncated_npz").mkdir(parents=True, exist_ok=True)
    (rf / "truncated_npz" / "trajectories.npz").write_bytes(good[: len(good) // 2])
    (rf / "fake_zip_npz").mkdir(parents=True, exist_ok=True)
    (rf / "fake_zip_npz" / "trajectories.npz").write_bytes(b"PK\x03\x04" + bytes(np.random.default_rng(1).integers(0, 256, 400, np.uint8)))
    obj = np.empty((T, N, 3), object)
    obj[...] = 0.0
    _npz(rf / "pickle_npz" / "trajectories.npz", _traj(true_pose=obj), allow_pickle=True)
    _npz(rf / "missing_true_pose" / "trajectories.npz", _traj(true_pose=None))
    _npz(rf / "wrong_shape" / "trajectories.npz", _traj(true_pose=np.zeros((T, N), np.float32)))
    nan = _traj()["true_pose"].copy()
    nan[3, 1, 0] = np.nan
    _npz(rf / "nan_pose" / "trajectories.npz", _traj(true_pose=nan))
    inf = _traj()["odom_pose"].copy()
    inf[5, 0, 2] = np.inf
    _npz(rf / "inf_odom" / "trajectories.npz", _traj(odom_pose=inf))
    _npz(rf / "no_samples" / "trajectories.npz", _traj(t_s=np.zeros(0), step=None, stalled=None,
                                                         true_pose=np.zeros((0, N, 3)), odom_pose=np.zeros((0, N, 3))))
    _npz(rf / "string_array" / "trajectories.npz", _traj(t_s=np.array(["a"] * T)))
    # a layer whose samples name robot 7 of a 2-robot run
    _npz(rf / "layer_bad_robot" / "layers.npz", {"crumbs.step": np.array([0, 1], np.int64), "crumbs.robot": np.array([0, 7], np.int32),
                                                  "crumbs.offset": np.array([0, 1, 2], np.int64),
                                                  "crumbs.data": np.zeros((2, 2), np.float32)})
    _npz(rf / "layers_json_wrong" / "layers.npz", {})
    (rf / "deep_logs").mkdir(parents=True, exist_ok=True)
    (rf / "deep_logs" / "logs.json").write_text('{"logs": ' + "[" * 100_000 + "]" * 100_000 + "}", encoding="utf-8")
    _npz(rf / "layer_bad_offset" / "layers.npz", {"crumbs.step": np.array([0, 1], np.int64), "crumbs.robot": np.array([0, 1], np.int32),
                                                   "crumbs.offset": np.array([0, 5, 2], np.int64),
                                                   "crumbs.data": np.zeros((2, 2), np.float32)})


def stores() -> None:
    from teamnav.experiments.store import ResultsStore

    st = HERE / "stores"
    shutil.rmtree(st / "_tmp", ignore_errors=True)
    (st / "_tmp").mkdir(parents=True)
    real = st / "_tmp" / "results.sqlite"
    with ResultsStore(real) as store:
        store.register_sweep("x", {"scenario": "demo"})
    con = sqlite3.connect(real)
    con.execute("PRAGMA journal_mode=DELETE")  # fold the WAL in: one self-contained file
    con.close()
    good = real.read_bytes()

    def put(case: str, data: bytes) -> None:
        (st / case).mkdir(parents=True, exist_ok=True)
        (st / case / "results.sqlite").write_bytes(data)

    put("truncated_sqlite", good[: len(good) // 2])
    put("garbage", bytes(np.random.default_rng(2).integers(0, 256, 3000, np.uint8)))
    header_only = bytearray(good[:4096])  # an SQLite header, then the rest of the file garbage
    put("sqlite_header_garbage", bytes(header_only) + bytes(np.random.default_rng(3).integers(0, 256, 8192, np.uint8)))

    def db(case: str, *sql: str) -> None:
        (st / case).mkdir(parents=True, exist_ok=True)
        p = st / case / "results.sqlite"
        p.unlink(missing_ok=True)
        con = sqlite3.connect(p)
        for s in sql:
            con.execute(s)
        con.commit()
        con.close()

    db("other_schema", "CREATE TABLE trials (id INTEGER PRIMARY KEY, name TEXT)", "INSERT INTO trials VALUES (1, 'x')")
    db("foreign_tables", "CREATE TABLE customers (id INTEGER, name TEXT)")
    shutil.copy(real, st / "_tmp" / "copy.sqlite")
    con = sqlite3.connect(st / "_tmp" / "copy.sqlite")
    con.execute("DROP TABLE trials")
    con.commit()
    con.close()
    (st / "missing_table").mkdir(parents=True, exist_ok=True)
    shutil.copy(st / "_tmp" / "copy.sqlite", st / "missing_table" / "results.sqlite")
    shutil.rmtree(st / "_tmp")


def scenarios() -> None:
    sc = HERE / "scenarios"
    sc.mkdir(parents=True, exist_ok=True)
    base = "name: bomb\nmap: {arena: {width_m: 10, height_m: 10}}\nduration_s: 1\nrobots: [{controller: wander-v1, count: 1}]\n"
    bomb = ["  - &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    bomb += [f"  - &l{i} [" + ", ".join([f"*l{i - 1}"] * 10) + "]" for i in range(1, 9)]
    (sc / "billion_laughs.yaml").write_text(
        "# expect: expands to more than\n# a YAML 'billion laughs' under a known field: 10**9 values once the aliases are expanded\n"
        + base + "metrics:\n" + "\n".join(bomb) + "\n", encoding="utf-8")
    deep = "[" * 20000 + "]" * 20000
    (sc / "deep_nesting.yaml").write_text(
        "# expect: nested more than 100 levels\n# 20 000 nested brackets under a known field\n" + base + f"metrics: {deep}\n",
        encoding="utf-8")


if __name__ == "__main__":
    run_folders()
    stores()
    scenarios()
