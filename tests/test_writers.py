"""One writer per destination, interrupted exports, and destinations or run folders that are not
what they seem.

- Two writers into one place: ``teamnav run``, ``export``, ``replay`` and ``report`` claim their
  destination (``.NAME.lock`` beside it, created with O_EXCL, holding pid and host) before any
  work; a second writer refuses in one line naming the holder's pid (exit 2), or waits with
  ``--wait``; a claim whose process is gone is taken over. The first writer here is either a real
  process (two runs at once) or this test process holding the claim, so the order is certain.
- An export stopped by SIGINT, SIGTERM or SIGKILL leaves no temporary file once the next export
  has run (SIGINT and SIGTERM: none at all).
- Destinations that cannot be written (a symbolic link, below a file, a read-only folder) are
  refused before the run is simulated, in one line naming the path; run folders whose files are
  a FIFO, a huge sparse file or a link out of the folder are refused in one line.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from teamnav.cli import app
from teamnav.files import ClaimError, claim, claim_path

runner = CliRunner()
PY = [sys.executable, "-m", "teamnav"]


# run_folder: tests/conftest.py (a real, tiny run folder)


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def _error_lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.strip()]


def _one_line_refusal(proc_or_result, *words: str) -> str:
    rc = proc_or_result.returncode if hasattr(proc_or_result, "returncode") else proc_or_result.exit_code
    err = proc_or_result.stderr
    assert rc == 2, err
    lines = _error_lines(err)
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in err, err
    for w in words:
        assert w in lines[0], (w, lines[0])
    return lines[0]


# ---------------------------------------------------------------------------- the claim itself
def test_claim_refuses_a_live_holder_and_is_released(tmp_path):
    dest = tmp_path / "out"
    with claim(dest, "output folder") as lock:
        assert lock == claim_path(dest) and lock.is_file()
        with pytest.raises(ClaimError, match=f"process {os.getpid()}"):
            with claim(dest, "output folder"):
                pass
    assert not claim_path(dest).exists()
    with pytest.raises(RuntimeError):
        with claim(dest, "output folder"):
            raise RuntimeError("boom")
    assert not claim_path(dest).exists()


def test_a_dead_holders_claim_is_taken_over(tmp_path):
    import json

    from teamnav.files import HOST

    dest = tmp_path / "out"
    claim_path(dest).write_text(json.dumps({"pid": _dead_pid(), "host": HOST, "token": "x"}), encoding="utf-8")
    with claim(dest, "output folder"):
        assert json.loads(claim_path(dest).read_text())["pid"] == os.getpid()
    assert not claim_path(dest).exists()
    # another host's claim is never judged stale from here
    claim_path(dest).write_text(json.dumps({"pid": _dead_pid(), "host": "elsewhere", "token": "x"}), encoding="utf-8")
    with pytest.raises(ClaimError, match="on elsewhere"):
        with claim(dest, "output folder"):
            pass


# ---------------------------------------------------------------------------- two writers, real processes
def test_two_runs_into_one_folder_one_wins_one_refuses(tmp_path):
    out = tmp_path / "shared"
    # long enough (~10 s of stepping) that the second starts while the first still works
    first = subprocess.Popen(PY + ["run", "demo", "--duration", "600", "--out", str(out), "--quiet"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.monotonic()
    while not claim_path(out).exists():
        assert first.poll() is None, first.communicate()
        assert time.monotonic() - t0 < 120
        time.sleep(0.02)
    second = subprocess.run(PY + ["run", "demo", "--duration", "2", "--seed", "9", "--out", str(out), "--quiet"],
                            capture_output=True, text=True, timeout=120)
    _one_line_refusal(second, str(out), f"process {first.pid}", "--wait")
    assert first.poll() is None  # the refusal came while the first one worked
    assert first.wait(timeout=300) == 0, first.communicate()
    assert (out / "metrics.json").is_file() and "seed: 9" not in (out / "scenario.yaml").read_text()
    assert not claim_path(out).exists()
    assert [p.name for p in tmp_path.iterdir()] == ["shared"]  # no staging, no lock


def _report_script(out: Path, *extra: str) -> list[str]:
    code = (
        "import sys\n"
        "from teamnav.experiments import report\n"
        "from teamnav.experiments.report.model import SectionSpec\n"
        "report.register_section(SectionSpec(key='fake-writers', title='t', paper='p.txt', build=lambda ctx: []))\n"
        "from teamnav.cli import app\n"
        f"app(['report', 'fake-writers', '--quick', '--quiet', '--out', {str(out)!r}] + {list(extra)!r}, prog_name='teamnav')\n"
    )
    return [sys.executable, "-c", code]


def _second_writer(kind: str, run_folder: Path, dest: Path, *extra: str) -> list[str]:
    if kind == "run":
        return PY + ["run", "demo", "--duration", "1", "--set", "robots.0.count=2", "--out", str(dest), "--quiet", *extra]
    if kind == "export":
        return PY + ["export", str(run_folder), "--mcap", str(dest), *extra]
    if kind == "replay":
        return PY + ["replay", str(run_folder), "--out", str(dest), *extra]
    return _report_script(dest, *extra)


KINDS = {"run": "out", "export": "x.mcap", "replay": "x.html", "report": "rep"}


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_a_second_writer_refuses_while_the_first_holds_the_claim(kind, run_folder, tmp_path):
    dest = tmp_path / KINDS[kind]
    with claim(dest, "test"):
        proc = subprocess.run(_second_writer(kind, run_folder, dest), capture_output=True, text=True, timeout=300)
        _one_line_refusal(proc, str(dest), f"process {os.getpid()}")
        assert not dest.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # no lock, no temporary, no staging


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_a_second_writer_with_wait_waits_then_writes(kind, run_folder, tmp_path):
    dest = tmp_path / KINDS[kind]
    with claim(dest, "test"):
        proc = subprocess.Popen(_second_writer(kind, run_folder, dest, "--wait"), stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        line = proc.stderr.readline()
        assert "waiting" in line and f"process {os.getpid()}" in line, line
        time.sleep(0.5)
        assert proc.poll() is None and not dest.exists()
    out, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    assert dest.exists() and not claim_path(dest).exists()


def test_a_waiting_run_keeps_what_the_first_wrote(run_folder, tmp_path):
    """--wait without --force: the folder the first writer finished is kept, the second refuses."""
    dest = tmp_path / "out"
    with claim(dest, "test"):
        proc = subprocess.Popen(_second_writer("run", run_folder, dest, "--wait"), stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        assert "waiting" in proc.stderr.readline()
        dest.mkdir()
        (dest / "first.txt").write_text("the first run's", encoding="utf-8")
    _out, err = proc.communicate(timeout=300)
    assert proc.returncode == 2 and "not empty" in err, err
    assert sorted(p.name for p in dest.iterdir()) == ["first.txt"]


# ---------------------------------------------------------------------------- interrupted exports
_SLOW_EXPORT = (
    "import signal, sys, time, foxglove\n"
    # Ctrl-C's default handler, whatever disposition the test's worker process passed down
    "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
    "def slow(*a, **k):\n"
    "    print('writing', flush=True)\n"
    "    time.sleep(120)\n"
    "foxglove.open_mcap = slow\n"
    "from teamnav.cli import app\n"
    "app(['export', sys.argv[1], '--mcap', sys.argv[2]], prog_name='teamnav')\n"
)


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL], ids=lambda s: s.name)
def test_an_interrupted_export_leaves_nothing_once_the_next_one_ran(sig, run_folder, tmp_path):
    dest = tmp_path / "x.mcap"
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_EXPORT, str(run_folder), str(dest)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "writing", proc.communicate()
    assert any(n.endswith(".tmp") for n in _leftovers(tmp_path)) and claim_path(dest).exists()
    proc.send_signal(sig)
    try:
        _out, err = proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail(f"the export did not end within 120 s of {sig.name}: {proc.communicate()[1][-2000:]}")
    assert proc.returncode != 0, err
    if sig != signal.SIGKILL:
        assert _leftovers(tmp_path) == [] and not dest.exists()
    res = subprocess.run(PY + ["export", str(run_folder), "--mcap", str(dest)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert _leftovers(tmp_path) == [] and dest.stat().st_size > 0


# ---------------------------------------------------------------------------- two real writers at once
_SLOWED_EXPORT = (
    "import sys, time, foxglove\n"
    "real = foxglove.open_mcap\n"
    "def slowed(*a, **k):\n"
    "    print('writing', flush=True)\n"
    "    time.sleep(3)\n"
    "    return real(*a, **k)\n"
    "foxglove.open_mcap = slowed\n"
    "from teamnav.cli import app\n"
    "app(['export', sys.argv[1], '--mcap', sys.argv[2]], prog_name='teamnav')\n"
)


def _slowed_report(out: Path) -> list[str]:
    code = (
        "import time\n"
        "from teamnav.experiments import report\n"
        "from teamnav.experiments.report.model import SectionSpec, Text\n"
        "def build(ctx):\n"
        "    print('building', flush=True)\n"
        "    time.sleep(3)\n"
        "    return [Text('the first report')]\n"
        "report.register_section(SectionSpec(key='fake-writers', title='t', paper='p.txt', build=build))\n"
        "from teamnav.cli import app\n"
        f"app(['report', 'fake-writers', '--quick', '--quiet', '--out', {str(out)!r}], prog_name='teamnav')\n"
    )
    return [sys.executable, "-c", code]


@pytest.mark.parametrize("kind", ["export", "report"])
def test_two_real_writers_at_once_one_wins_one_refuses(kind, run_folder, tmp_path):
    """Two processes into one destination at once: the one that started first finishes and keeps
    its result; the other refuses in one line naming it, and writes nothing."""
    dest = tmp_path / KINDS[kind]
    first_cmd = ([sys.executable, "-c", _SLOWED_EXPORT, str(run_folder), str(dest)] if kind == "export"
                 else _slowed_report(dest))
    first = subprocess.Popen(first_cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert first.stdout.readline().strip() in ("writing", "building"), first.communicate()
    second = subprocess.run(_second_writer(kind, run_folder, dest), capture_output=True, text=True, timeout=300)
    _one_line_refusal(second, str(dest), f"process {first.pid}")
    assert first.poll() is None  # the refusal came while the first one worked
    _out, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    if kind == "export":
        assert dest.stat().st_size > 0
    else:
        assert "the first report" in (dest / "index.html").read_text(encoding="utf-8")
    assert not claim_path(dest).exists() and _leftovers(tmp_path) == []


# ---------------------------------------------------------------------------- destinations
def _run_into(out: Path):
    return runner.invoke(app, ["run", "demo", "--duration", "1", "--set", "robots.0.count=2", "--out", str(out), "--quiet"])


def _refused_before_work(res, path: Path, cause: str) -> None:
    assert res.exit_code == 2, res.output
    lines = _error_lines(res.stderr)
    assert len(lines) == 1 and str(path) in lines[0] and cause in lines[0], lines
    assert res.exception is None or isinstance(res.exception, SystemExit)


def test_run_into_a_dangling_symlink(tmp_path):
    out = tmp_path / "out"
    out.symlink_to(tmp_path / "nowhere")
    _refused_before_work(_run_into(out), out, "dangling symbolic link")
    assert out.is_symlink() and sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_run_into_a_symlink_to_an_empty_folder(tmp_path):
    (tmp_path / "real").mkdir()
    out = tmp_path / "out"
    out.symlink_to(tmp_path / "real")
    _refused_before_work(_run_into(out), out, "symbolic link")
    assert out.is_symlink() and list((tmp_path / "real").iterdir()) == []


def test_run_below_a_file(tmp_path):
    (tmp_path / "file").write_text("x", encoding="utf-8")
    out = tmp_path / "file" / "sub" / "out"
    _refused_before_work(_run_into(out), out, "is a file, not a folder")
    assert (tmp_path / "file").read_text() == "x"


def test_run_below_a_dangling_symlink(tmp_path):
    (tmp_path / "gone").symlink_to(tmp_path / "nowhere")
    out = tmp_path / "gone" / "out"
    _refused_before_work(_run_into(out), out, "dangling symbolic link")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders: the chmod case needs another user")
def test_run_into_a_read_only_folder(tmp_path):
    parent = tmp_path / "ro"
    parent.mkdir()
    parent.chmod(0o555)
    try:
        _refused_before_work(_run_into(parent / "out"), parent / "out", "read-only")
        assert list(parent.iterdir()) == []
    finally:
        parent.chmod(0o755)


def test_report_and_export_into_symlinks(run_folder, tmp_path):
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "nowhere")
    res = runner.invoke(app, ["export", str(run_folder), "--mcap", str(link)])
    _refused_before_work(res, link, "dangling symbolic link")
    res = runner.invoke(app, ["replay", str(run_folder), "--out", str(link)])
    _refused_before_work(res, link, "dangling symbolic link")
    proc = subprocess.run(_report_script(link), capture_output=True, text=True, timeout=300)
    _one_line_refusal(proc, str(link), "dangling symbolic link")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link"]


# ---------------------------------------------------------------------------- run folders
def _copy(run_folder: Path, dest: Path) -> Path:
    import shutil

    shutil.copytree(run_folder, dest)
    return dest


@pytest.mark.parametrize("command", ["replay", "export"])
def test_a_fifo_in_the_run_folder_is_refused_not_read(command, run_folder, tmp_path):
    folder = _copy(run_folder, tmp_path / "run")
    (folder / "logs.json").unlink()
    os.mkfifo(folder / "logs.json")
    option = "--out" if command == "replay" else "--mcap"
    proc = subprocess.run(PY + [command, str(folder), option, str(tmp_path / "x.out")], capture_output=True, text=True,
                          timeout=60)
    _one_line_refusal(proc, "logs.json", "named pipe")


@pytest.mark.parametrize("command", ["replay", "export"])
def test_a_huge_sparse_file_is_refused_before_it_is_read(command, run_folder, tmp_path):
    folder = _copy(run_folder, tmp_path / "run")
    with open(folder / "logs.json", "r+b") as fh:
        fh.truncate(300 * 1024**3)
    option = "--out" if command == "replay" else "--mcap"
    res = runner.invoke(app, [command, str(folder), option, str(tmp_path / "x.out")])
    _refused_before_work(res, folder, "logs.json")
    assert "MiB" in res.stderr and not (tmp_path / "x.out").exists()


@pytest.mark.parametrize("name", ["logs.json", "trajectories.npz", "map.pgm"])
@pytest.mark.parametrize("command", ["replay", "export"])
def test_a_link_out_of_the_run_folder_is_refused(command, name, run_folder, tmp_path):
    folder = _copy(run_folder, tmp_path / "run")
    outside = tmp_path / f"outside-{name}"
    (folder / name).rename(outside)
    (folder / name).symlink_to(outside)
    option = "--out" if command == "replay" else "--mcap"
    res = runner.invoke(app, [command, str(folder), option, str(tmp_path / "x.out")])
    _refused_before_work(res, folder, "leading out of it")
    assert not (tmp_path / "x.out").exists()


def test_a_link_inside_the_run_folder_is_followed(run_folder, tmp_path):
    folder = _copy(run_folder, tmp_path / "run")
    (folder / "logs.json").rename(folder / "logs-real.json")
    (folder / "logs.json").symlink_to("logs-real.json")
    res = runner.invoke(app, ["replay", str(folder), "--out", str(tmp_path / "x.html")])
    assert res.exit_code == 0, res.output
