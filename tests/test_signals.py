"""Kills and signals leave nothing behind; run folders get the user's umask.

Real signals to real ``python -m teamnav`` subprocesses:

- SIGKILL or SIGTERM of a sweep: its worker processes end with it (none is left running,
  reparented to PID 1); SIGTERM stops the pool cleanly and leaves the store consistent.
- SIGTERM of a run: its ``.NAME.HOST-PID.*.partial`` staging folder is removed.
- SIGKILL of a run leaves its staging folder; the next run into the same parent folder
  removes it because its owner is dead, and keeps the staging folders of live runs.

And (commit c101e89, 2026-11-27) a run folder and its files have the modes the umask asks for, not mkdtemp's
0700 and mkstemp's 0600.

Processes are followed through ``/proc`` (pid, parent pid, start time), so these tests run on
Linux only.
"""

from __future__ import annotations

import os
import signal
import sqlite3
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

from teamnav.experiments import runner

pytestmark = pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="follows processes through /proc (Linux)")

#: long enough never to finish while a test watches it (the tests kill it within seconds)
LONG_S = "100000"


# ---------------------------------------------------------------------------- processes
def _stat(pid: int) -> list[str] | None:
    """Fields of /proc/PID/stat after the command name: [state, ppid, ..., starttime (19), ...]."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return text.rpartition(")")[2].split()


def _descendants(pid: int) -> dict[int, str]:
    """Every process below ``pid`` now: {pid: start time}."""
    table = {}
    for name in os.listdir("/proc"):
        if name.isdigit():
            fields = _stat(int(name))
            if fields is not None:
                table[int(name)] = (int(fields[1]), fields[19])
    found: dict[int, str] = {}
    frontier = [pid]
    while frontier:
        parent = frontier.pop()
        for child, (ppid, start) in table.items():
            if ppid == parent and child not in found:
                found[child] = start
                frontier.append(child)
    return found


def _running(procs: dict[int, str]) -> list[int]:
    """Those of ``procs`` still running (same pid and start time, not a zombie)."""
    alive = []
    for pid, start in procs.items():
        fields = _stat(pid)
        if fields is not None and fields[19] == start and fields[0] not in ("Z", "X"):
            alive.append(pid)
    return alive


def _wait_gone(procs: dict[int, str], timeout_s: float) -> list[int]:
    deadline = time.monotonic() + timeout_s
    while (alive := _running(procs)) and time.monotonic() < deadline:
        time.sleep(0.1)
    return alive


def _kill_all(procs: dict[int, str]) -> None:
    for pid in _running(procs):  # a failing test must not leave them either
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


def _env(tmp_path: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["TMPDIR"] = str(tmp_path)  # a run without a folder stages under the temporary folder
    env.pop("TEAMNAV_PROGRESS_EVERY_S", None)
    return env


def _teamnav(args: list[str], tmp_path: Path) -> tuple[subprocess.Popen, Path]:
    log = tmp_path / "stderr.txt"
    with open(log, "wb") as err:
        proc = subprocess.Popen([sys.executable, "-m", "teamnav", *args], env=_env(tmp_path),
                                stdout=subprocess.DEVNULL, stderr=err, cwd=tmp_path)
    return proc, log


def _wait_for(cond, proc: subprocess.Popen, log: Path, what: str, timeout_s: float = 60.0):
    deadline = time.monotonic() + timeout_s
    while True:
        got = cond()
        if got:
            return got
        if proc.poll() is not None:
            pytest.fail(f"the process ended (status {proc.returncode}) before {what}:\n{log.read_text()[-3000:]}")
        if time.monotonic() > deadline:
            proc.kill()
            pytest.fail(f"no {what} after {timeout_s:.0f} s:\n{log.read_text()[-3000:]}")
        time.sleep(0.05)


def _partials(folder: Path) -> list[Path]:
    return sorted(folder.glob(".*.partial")) if folder.is_dir() else []


def _start_sweep(tmp_path: Path) -> tuple[subprocess.Popen, Path, Path, dict[int, str]]:
    """A sweep of two long trials on two workers, returned once both trials are stepping
    (each has its staging folder under OUT/trials), with the sweep's processes."""
    out = tmp_path / "sweep"
    proc, log = _teamnav(["sweep", "demo", "--grid", "robots.0.count=2,3", "--seeds", "1", "--duration", LONG_S,
                          "--workers", "2", "--artifacts", "--quiet", "--out", str(out)], tmp_path)
    _wait_for(lambda: len(_partials(out / "trials")) >= 2, proc, log, "two trials stepping")
    procs = _descendants(proc.pid)
    workers = [p for p in procs if "multiprocessing" in _cmdline(p) and "resource_tracker" not in _cmdline(p)]
    if len(workers) < 2:  # a worker died: say how, with what the sweep printed (faulthandler's dump)
        states = {p: ((_stat(p) or ["gone"])[0], _cmdline(p)) for p in procs}
        proc.kill()
        proc.wait(timeout=10)
        pytest.fail(f"expected 2 live workers, found {states}; the sweep's stderr:\n{log.read_text()[-4000:]}")
    return proc, out, log, procs


# ---------------------------------------------------------------------------- sweeps
def test_sigkill_of_a_sweep_takes_its_workers_with_it(tmp_path):
    proc, out, log, procs = _start_sweep(tmp_path)
    try:
        os.kill(proc.pid, signal.SIGKILL)  # the parent alone: it can clean up nothing
        proc.wait(timeout=10)
        left = _wait_gone(procs, 15.0)
        assert left == [], f"orphaned after SIGKILL: {[(p, _cmdline(p)) for p in left]}"
    finally:
        _kill_all(procs)
    # the workers got SIGTERM from the kernel and their runs removed their staging folders
    assert _partials(out / "trials") == []
    con = sqlite3.connect(out / "results.sqlite")
    try:
        assert con.execute("PRAGMA integrity_check").fetchone() == ("ok",)
    finally:
        con.close()


def test_sigterm_of_a_sweep_stops_the_pool_and_leaves_the_store_consistent(tmp_path):
    proc, out, log, procs = _start_sweep(tmp_path)
    try:
        os.kill(proc.pid, signal.SIGTERM)
        status = proc.wait(timeout=20)
        assert status == -signal.SIGTERM, log.read_text()[-3000:]  # still ends "by SIGTERM", after cleaning up
        left = _wait_gone(procs, 10.0)
        assert left == [], f"left running after SIGTERM: {[(p, _cmdline(p)) for p in left]}"
    finally:
        _kill_all(procs)
    assert _partials(out / "trials") == []
    assert "Traceback" not in log.read_text()
    con = sqlite3.connect(out / "results.sqlite")
    try:
        assert con.execute("PRAGMA integrity_check").fetchone() == ("ok",)
        assert con.execute("SELECT COUNT(*) FROM trials WHERE status = 'ok'").fetchone() == (0,)
    finally:
        con.close()


# ---------------------------------------------------------------------------- runs
def _start_run(tmp_path: Path) -> tuple[subprocess.Popen, Path, Path, Path]:
    out = tmp_path / "runs" / "long"
    proc, log = _teamnav(["run", "demo", "--duration", LONG_S, "--quiet", "--out", str(out)], tmp_path)
    (staging,) = _wait_for(lambda: _partials(out.parent), proc, log, "a staging folder")
    assert f".long.{runner._HOST}-{proc.pid}." in staging.name  # its owner's host and pid
    return proc, out, log, staging


def test_sigterm_of_a_run_removes_its_staging_folder(tmp_path):
    proc, out, log, staging = _start_run(tmp_path)
    time.sleep(0.3)  # well into the stepping loop
    os.kill(proc.pid, signal.SIGTERM)
    assert proc.wait(timeout=20) == -signal.SIGTERM, log.read_text()[-3000:]
    assert not staging.exists() and _partials(out.parent) == [] and not out.exists()
    assert "Traceback" not in log.read_text()


def test_next_run_removes_the_staging_of_a_killed_run_and_keeps_live_ones(tmp_path):
    proc, out, log, staging = _start_run(tmp_path)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=10)
    assert staging.is_dir()  # SIGKILL: nothing could clean up
    parent = out.parent
    live = parent / f".other.{runner._HOST}-{os.getpid()}.abcdefgh.partial"  # this test process: alive
    elsewhere = parent / f".other.some-other-host-{proc.pid}.abcdefgh.partial"  # dead pid, but not our host
    unnamed = parent / ".other.abcdefgh.partial"  # no owner in its name (an older teamnav): not ours to judge
    for folder in (live, elsewhere, unnamed):
        folder.mkdir()
        (folder / "trajectories.npz").write_bytes(b"x")

    runner.run(runner.load_scenario("demo", duration_s=0.5), out_dir=parent / "next", progress=False)
    assert not staging.exists()
    assert live.is_dir() and elsewhere.is_dir() and unnamed.is_dir()
    assert (parent / "next" / "metrics.json").is_file()


def test_a_killed_replacement_puts_the_old_run_folder_back(tmp_path):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    old = tmp_path / f".mine.{runner._HOST}-{dead.pid}.abcdefgh.old"
    (old / "run").mkdir(parents=True)
    (old / "run" / "metrics.json").write_text("{}")
    stale = tmp_path / f".mine.{runner._HOST}-{dead.pid}.ijklmnop.partial"
    stale.mkdir()
    removed = runner.clean_stale_staging(tmp_path)
    assert sorted(removed) == sorted([old, stale])
    assert (tmp_path / "mine" / "metrics.json").is_file() and not old.exists() and not stale.exists()


# ---------------------------------------------------------------------------- modes
_RUN_WITH_UMASK = """
import os, sys
os.umask(int(sys.argv[1], 8))
from teamnav.experiments.runner import run
from teamnav.experiments.spec import load_scenario
run(load_scenario("demo", duration_s=0.5), out_dir=sys.argv[2], progress=False)
"""


@pytest.mark.parametrize("umask", [0o022, 0o077, 0o002])
def test_run_folder_and_files_follow_the_umask(tmp_path, umask):
    out = tmp_path / "deep" / "run"
    subprocess.run([sys.executable, "-c", _RUN_WITH_UMASK, oct(umask), str(out)], check=True, env=_env(tmp_path))
    modes = {}
    for here, dirs, files in os.walk(out):
        for name in dirs + files:
            path = Path(here) / name
            modes[str(path.relative_to(out))] = (path.is_dir(), stat.S_IMODE(path.stat().st_mode))
    assert {"map.pgm", "map.yaml", "trajectories.npz", "metrics.json", "events.json", "trajectories.png"} <= set(modes)
    assert stat.S_IMODE(out.stat().st_mode) == 0o777 & ~umask
    for name, (is_dir, mode) in modes.items():
        want = (0o777 if is_dir else 0o666) & ~umask
        assert mode == want, f"{name}: {oct(mode)}, expected {oct(want)} under umask {oct(umask)}"
    assert _partials(out.parent) == []
