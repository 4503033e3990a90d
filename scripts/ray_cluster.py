"""A real two-node Ray cluster on one machine: a sweep that survives losing a node, and scaling.

``lost-node``: starts a head node (``ray start --head``) and a second node (``ray start
--address``) in their own processes, runs ``teamnav sweep ... --executor ray --address`` on
them, SIGKILLs the second node's raylet and its workers while a trial runs there, and checks that the sweep
finishes on the head alone with every trial stored exactly once, all ``ok``, and the lost
ones marked (``retries`` >= 1 with the error of the lost start).

``scaling``: the same sweep on a local cluster with 1, 2 and 4 worker processes (CPU slots),
wall time and speed-up against 1.

Usage::

    python scripts/ray_cluster.py lost-node            # about a minute; prints the store's retried trials
    python scripts/ray_cluster.py scaling --workers 1 2 4

Both stop every Ray process they started (``ray stop --force``: do not run them beside another
Ray session of yours on the same machine). ``tests/test_ray_cluster.py`` runs ``lost-node``
(marked slow).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: the sweep both commands run: 8 trials of 2-5 s each (demo, 3000 s simulated)
SWEEP = ["demo", "--grid", "robots.0.count=2,4", "--seeds", "4", "--duration", "3000"]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _ray(*args: str, env: dict | None = None, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run(["ray", *args], capture_output=True, text=True, timeout=timeout, env=env, check=False)


def _env() -> dict:
    env = dict(os.environ)
    env.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    env.setdefault("RAY_AUTH_MODE", "disabled")  # a cluster on the loopback, started and stopped here
    return env


def start_cluster(head_cpus: int, worker_cpus: int) -> tuple[str, int | None]:
    """Start a head (``head_cpus`` slots) and, if ``worker_cpus``, a second node; return the
    address and the second node's node-manager port (to find its raylet)."""
    env = _env()
    port = _free_port()
    out = _ray("start", "--head", f"--port={port}", "--node-ip-address=127.0.0.1", f"--num-cpus={head_cpus}",
               "--include-dashboard=false", "--disable-usage-stats", env=env)
    if out.returncode != 0:
        raise RuntimeError(f"ray start --head failed:\n{out.stdout}\n{out.stderr}")
    address = f"127.0.0.1:{port}"
    nm_port = None
    if worker_cpus:
        nm_port = _free_port()
        out = _ray("start", f"--address={address}", "--node-ip-address=127.0.0.1", f"--num-cpus={worker_cpus}",
                   f"--node-manager-port={nm_port}", "--disable-usage-stats", env=env)
        if out.returncode != 0:
            raise RuntimeError(f"ray start --address failed:\n{out.stdout}\n{out.stderr}")
    return address, nm_port


def stop_cluster() -> None:
    _ray("stop", "--force", env=_env(), timeout=60.0)


def raylet_pid(node_manager_port: int) -> int | None:
    """PID of the raylet listening on ``node_manager_port`` (read from /proc)."""
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            cmd = (d / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if cmd and cmd[0].endswith(b"raylet") and f"--node_manager_port={node_manager_port}".encode() in cmd:
            return int(d.name)
    return None


def descendants(pid: int) -> list[int]:
    """Every process below ``pid`` (its workers), read from /proc."""
    children: dict[int, list[int]] = {}
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                ppid = int((d / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, ValueError, IndexError):
                continue
            children.setdefault(ppid, []).append(int(d.name))
    out, todo = [], [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            out.append(c)
            todo.append(c)
    return out


def _store_rows(store: Path) -> list[dict]:
    if not store.exists():
        return []
    con = sqlite3.connect(f"file:{store}?mode=ro", uri=True, timeout=30)
    try:
        con.row_factory = sqlite3.Row
        return [dict(r) for r in con.execute("SELECT trial_id, status, retries, retry_errors, host, wall_time_s FROM trials")]
    except sqlite3.Error:
        return []
    finally:
        con.close()


def lost_node(out_dir: Path, *, log=print) -> dict:
    """Run the sweep on two nodes, kill the second one's raylet mid-sweep; return what the
    store says (``trials``, ``ok``, ``retried``, ``expected``)."""
    stop_cluster()
    address, nm_port = start_cluster(1, 1)
    try:
        store = out_dir / "results.sqlite"
        cmd = [sys.executable, "-m", "teamnav", "sweep", *SWEEP, "--executor", "ray", "--address", address,
               "--workers", "2", "--out", str(out_dir), "--quiet"]
        log("sweep: " + " ".join(cmd[2:]))
        t0 = time.monotonic()
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=_env())
        killed_at = None
        first_at = None
        while proc.poll() is None and time.monotonic() - t0 < 600:
            # the two nodes start their first trials together and finish them together (both pay
            # the warm-up); once both are stored, both nodes are on their second: kill the
            # second node a second later, in the middle of it
            rows = _store_rows(store) if killed_at is None else []
            if first_at is None and len(rows) >= 2:
                first_at = time.monotonic()
            if killed_at is None and first_at is not None and time.monotonic() - first_at >= 1.0:
                pid = raylet_pid(nm_port)
                if pid is None:
                    raise RuntimeError("could not find the second node's raylet")
                # the node is lost as a machine is: its raylet and the workers under it. (SIGKILL
                # to the raylet alone lets a running worker finish its trial and hand the result
                # straight to the driver: nothing is lost then, and the store shows no retry.)
                victims = [pid] + descendants(pid)
                for v in victims:
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(v, signal.SIGKILL)
                killed_at = time.monotonic() - t0
                log(f"SIGKILL to the second node's raylet (pid {pid}) and its {len(victims) - 1} workers at {killed_at:.1f} s")
            time.sleep(0.5)
        try:
            stdout, stderr = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            stdout, stderr = proc.communicate()
        rows = _store_rows(store)
        expected = 8
        result = {
            "returncode": proc.returncode, "expected": expected, "trials": len(rows),
            "distinct": len({r["trial_id"] for r in rows}), "ok": sum(r["status"] == "ok" for r in rows),
            "retried": [{"trial_id": r["trial_id"], "retries": r["retries"], "errors": json.loads(r["retry_errors"] or "[]")}
                        for r in rows if r["retries"]],
            "killed_at_s": killed_at, "wall_s": time.monotonic() - t0, "stdout": stdout[-2000:], "stderr": stderr[-2000:],
        }
        log(f"sweep exit {proc.returncode}: {result['trials']} trials stored ({result['distinct']} distinct, "
            f"{result['ok']} ok) of {expected}; retried: {result['retried']}")
        return result
    finally:
        stop_cluster()


def scaling(workers: list[int], out_root: Path, *, log=print) -> list[dict]:
    """Wall time of the sweep on a local Ray cluster with each number of CPU slots."""
    rows = []
    for n in workers:
        stop_cluster()
        address, _ = start_cluster(n, 0)
        try:
            out = out_root / f"w{n}"
            cmd = [sys.executable, "-m", "teamnav", "sweep", *SWEEP, "--executor", "ray", "--address", address,
                   "--workers", str(n), "--out", str(out), "--quiet"]
            t0 = time.monotonic()
            subprocess.run(cmd, check=True, capture_output=True, text=True, env=_env())
            wall = time.monotonic() - t0
        finally:
            stop_cluster()
        rows.append({"workers": n, "wall_s": wall})
        log(f"{n} worker(s): {wall:.1f} s, speed-up x{rows[0]['wall_s'] / wall:.2f} against {workers[0]}")
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("lost-node", help="kill a node mid-sweep")
    sc = sub.add_parser("scaling", help="1, 2, 4 worker processes")
    sc.add_argument("--workers", type=int, nargs="+", default=[1, 2, 4])
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="teamnav-ray-") as tmp:
        if args.cmd == "lost-node":
            r = lost_node(Path(tmp) / "sweep")
            ok = r["returncode"] == 0 and r["trials"] == r["distinct"] == r["ok"] == r["expected"] and r["retried"]
            return 0 if ok else 1
        scaling(args.workers, Path(tmp))
    return 0


if __name__ == "__main__":
    sys.exit(main())
