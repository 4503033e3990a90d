"""A full disk: runs, sweeps and exports stop with one line naming the path and the cause, and
leave nothing behind. The disk is a small tmpfs (skipped where it cannot be mounted)."""

from __future__ import annotations

import subprocess
import sys

import pytest

PY = [sys.executable, "-m", "teamnav"]


@pytest.fixture
def tiny_disk(tmp_path, request):
    """A tmpfs of the size the test asks for (``@pytest.mark.parametrize("tiny_disk", ["24k"], indirect=True)``)."""
    mnt = tmp_path / "tiny"
    mnt.mkdir()
    size = getattr(request, "param", "24k")
    try:
        res = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(mnt)], capture_output=True,
                             text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired) as exc:  # no mount command here
        pytest.skip(f"cannot mount a small tmpfs here ({exc})")
    if res.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here ({res.stderr.strip() or 'mount failed'}); needs root")
    yield mnt
    subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


def _one_error_line(res: subprocess.CompletedProcess) -> str:
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), res.stderr
    assert "Traceback" not in res.stderr
    return lines[0]


@pytest.mark.parametrize("tiny_disk", ["24k"], indirect=True)
def test_a_sweep_on_a_full_disk_says_so_and_leaves_no_folder(tiny_disk):
    out = tiny_disk / "sw"
    res = subprocess.run(PY + ["sweep", "demo-robots", "--seeds", "1", "--duration", "2", "--out", str(out), "-q"],
                         capture_output=True, text=True, timeout=300)
    line = _one_error_line(res)
    assert str(out / "results.sqlite") in line and "no space left on device" in line
    assert list(tiny_disk.iterdir()) == []


@pytest.mark.parametrize("tiny_disk", ["512k"], indirect=True)
def test_a_run_on_a_full_disk_says_so_and_leaves_no_staging(tiny_disk):
    out = tiny_disk / "run"
    res = subprocess.run(PY + ["run", "demo", "--duration", "5", "--out", str(out), "-q"], capture_output=True, text=True,
                         timeout=300)
    line = _one_error_line(res)
    assert "No space left on device" in line and str(tiny_disk) in line
    assert list(tiny_disk.iterdir()) == []


@pytest.mark.parametrize("tiny_disk", ["24k"], indirect=True)
def test_an_export_on_a_full_disk_says_so_and_leaves_no_temporary(tiny_disk, run_folder):
    dest = tiny_disk / "run.mcap"
    res = subprocess.run(PY + ["export", str(run_folder), "--mcap", str(dest)], capture_output=True, text=True, timeout=300)
    line = _one_error_line(res)
    assert str(dest) in line
    assert list(tiny_disk.iterdir()) == []


@pytest.mark.parametrize("tiny_disk", ["1520k"], indirect=True)
def test_a_gif_that_does_not_fit_says_so_and_leaves_no_staging(tiny_disk):
    """The run folder fits (about 1.49 MB: the map's 1.44 MB image, arrays, figure) but its GIF
    does not: the run stops with one line, and its staging folder is removed."""
    out = tiny_disk / "run"
    res = subprocess.run(PY + ["run", "demo", "--duration", "5", "--set", "robots.0.count=2", "--gif", "--out", str(out),
                               "-q"], capture_output=True, text=True, timeout=300)
    line = _one_error_line(res)
    assert "no space left on device" in line.lower() and str(out) in line
    assert list(tiny_disk.iterdir()) == []
