"""Outside brains (``teamnav run --controller file.py:Class``) that misbehave.

Each ends the run with one error line naming the controller, the robot and the step, a
documented exit status (2: cannot be built; 3: failed during the run), no traceback unless
``--debug``, and no run folder (nothing half-written).
"""

from __future__ import annotations

import os
import pickle
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

BRAINS = """\
import sys
import time

from teamnav.control import Action, NoParams


class Fine:
    Params = NoParams

    def __init__(self, params, rng, info):
        self.id = info.robot_id

    def step(self, obs):
        return Action(v_mps=0.1, omega_radps=0.0), []

    def log(self):
        return {}


class InitRaises(Fine):
    def __init__(self, params, rng, info):
        if info.robot_id == 1:
            raise RuntimeError("no brain for robot one")
        super().__init__(params, rng, info)


class StepRaises(Fine):
    def step(self, obs):
        if obs.step == 4 and self.id == 2:
            raise ValueError("lost at four")
        return super().step(obs)


class StepExits(Fine):
    def step(self, obs):
        if obs.step == 3:
            sys.exit(0)
        return super().step(obs)


class Garbage(Fine):
    def step(self, obs):
        return "forward please"


class NaNs(Fine):
    def step(self, obs):
        return Action(v_mps=float("nan"), omega_radps=0.0), []


class Words(Fine):
    def step(self, obs):
        if self.id == 2:
            return Action(v_mps="fast", omega_radps=0.0), []
        return super().step(obs)


class BadDirection(Fine):
    def step(self, obs):
        return Action(direction_rad="left"), []


class Forever(Fine):
    def step(self, obs):
        if obs.step == 2 and self.id == 0:
            while True:
                time.sleep(0.05)
        return super().step(obs)


class Slow(Fine):
    def step(self, obs):
        if obs.step == 2 and self.id == 0:
            time.sleep(3.0)
        return super().step(obs)
"""


@pytest.fixture(scope="module")
def brains(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("brains") / "brains.py"
    path.write_text(BRAINS)
    return path


def teamnav_run(controller: str, out: Path, *extra: str, env: dict | None = None, timeout: float = 240):
    return subprocess.run(
        [sys.executable, "-m", "teamnav", "run", "demo", "--duration", "2", "--controller", controller,
         "--out", str(out), *extra],
        capture_output=True, text=True, timeout=timeout, env={**os.environ, **(env or {})},
    )


def error_lines(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith("error:")]


def assert_failed(proc, out: Path, status: int, *fragments: str, debug: bool = False) -> str:
    assert proc.returncode == status, (proc.returncode, proc.stderr)
    lines = error_lines(proc.stderr)
    assert len(lines) == 1, proc.stderr
    for frag in fragments:
        assert frag in lines[0], (frag, lines[0])
    if debug:
        assert "Traceback (most recent call last)" in proc.stderr
    else:
        assert "Traceback" not in proc.stderr, proc.stderr
        assert "--debug" in proc.stderr
    assert not out.exists(), "a failed run left its run folder"
    assert not [p for p in out.parent.iterdir() if p.name.endswith(".partial")], "a staging folder was left"
    return lines[0]


@pytest.mark.parametrize(
    "cls, status, fragments",
    [
        ("InitRaises", 2, ["robot wanderer[1] (id 1)", "while being built", "RuntimeError: no brain for robot one"]),
        ("StepRaises", 3, ["robot wanderer[2] (id 2)", "raised at step 4", "ValueError: lost at four"]),
        ("StepExits", 3, ["robot wanderer[0] (id 0)", "at step 3", "SystemExit: sys.exit(0) called"]),
        ("Garbage", 3, ["robot wanderer[0] (id 0)", "at step 0", "must return (Action, list of Message)", "str"]),
        ("NaNs", 3, ["robot wanderer[0] (id 0)", "at step 0", "finite"]),
        ("Words", 3, ["robot wanderer[2] (id 2)", "at step 0", "real numbers", "'fast'"]),
        ("BadDirection", 3, ["robot wanderer[0] (id 0)", "at step 0", "direction_rad must be finite or None", "'left'"]),
    ],
)
def test_failing_brain_one_line_and_status(brains, tmp_path, cls, status, fragments):
    out = tmp_path / "run"
    entry = f"{brains}:{cls}"
    assert_failed(teamnav_run(entry, out), out, status, f"controller {entry} on robot", *fragments)


def test_debug_shows_the_brains_traceback(brains, tmp_path):
    out = tmp_path / "run"
    proc = teamnav_run(f"{brains}:StepRaises", out, "--debug")
    assert_failed(proc, out, 3, "raised at step 4", debug=True)
    assert str(brains) in proc.stderr and "lost at four" in proc.stderr  # the brain's own frame


@pytest.mark.parametrize("body, what", [
    ("import sys\nsys.exit(0)\n", "SystemExit: sys.exit(0) called"),
    ("import sys\nsys.exit('bye')\n", "SystemExit: sys.exit('bye') called"),
    ("raise KeyboardInterrupt\n", "KeyboardInterrupt"),
    ("import no_such_module_here\n", "no_such_module_here"),
    ("class X:\n    pass\n", "not a controller"),
])
def test_module_that_fails_on_import_exits_2(tmp_path, body, what):
    mod = tmp_path / "exiting.py"
    mod.write_text(body)
    out = tmp_path / "run"
    proc = teamnav_run(f"{mod}:X", out)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    lines = error_lines(proc.stderr)
    assert len(lines) == 1 and what in lines[0] and "exiting.py" in lines[0], proc.stderr
    assert not out.exists()


def test_brain_timeout_stops_a_brain_that_never_returns(brains, tmp_path):
    out = tmp_path / "run"
    proc = teamnav_run(f"{brains}:Forever", out, "--brain-timeout", "1", timeout=120)
    line = assert_failed(proc, out, 3, f"controller {brains}:Forever", "robot wanderer[0] (id 0)", "at step 2",
                         "timed out", "1 s")
    assert "--brain-timeout" in line


def test_progress_line_names_the_brain_a_step_waits_on(brains, tmp_path):
    out = tmp_path / "run"
    proc = teamnav_run(f"{brains}:Slow", out, env={"TEAMNAV_PROGRESS_EVERY_S": "0.3"})
    assert proc.returncode == 0, proc.stderr
    assert f"waiting on controller {brains}:Slow, robot wanderer[0] (id 0), step 2 for" in proc.stderr
    assert (out / "metrics.json").is_file()


def test_bad_brain_timeout_is_a_usage_error(brains, tmp_path):
    proc = teamnav_run(f"{brains}:Fine", tmp_path / "run", "--brain-timeout", "0", timeout=120)
    assert proc.returncode == 2 and "--brain-timeout" in proc.stderr


# ------------------------------------------------------------------ in process: the engine and the timer
def _sim(controller: str):
    from teamnav.sim.config import LaserConfig, RobotGroupConfig, SimConfig
    from teamnav.sim.engine import Simulation
    from teamnav.world import builtin_map

    cfg = SimConfig(robots=(RobotGroupConfig(name="g", count=2, controller=controller,
                                             sensors=(LaserConfig(n_beams=8),)),), seed=1)
    return Simulation(builtin_map("office_simple").grid, cfg)


def test_engine_errors_name_controller_robot_step_and_pickle(brains):
    from teamnav.control.guard import BrainError, BrainStepError

    sim = _sim(f"{brains}:Garbage")
    with pytest.raises(BrainStepError) as info:
        sim.run(1)
    err = info.value
    assert isinstance(err, ValueError) and isinstance(err, BrainError)
    assert (err.robot, err.step) == ("g[0] (id 0)", 0)
    again = pickle.loads(pickle.dumps(err))
    assert type(again) is type(err) and str(again) == str(err)
    assert sim.calling is None


def test_timer_is_disarmed_after_every_call_and_handler_restored(brains):
    from teamnav.control.guard import BrainTimeoutError

    before = signal.getsignal(signal.SIGALRM)
    sim = _sim(f"{brains}:Fine")
    with sim.brain_time_limit(5.0):
        sim.run(5)
        assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    assert signal.getsignal(signal.SIGALRM) is before
    sim = _sim(f"{brains}:Forever")
    with pytest.raises(BrainTimeoutError, match=r"g\[0\] \(id 0\) timed out at step 2"):
        with sim.brain_time_limit(0.3):
            sim.run(5)
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    assert signal.getsignal(signal.SIGALRM) is before
    assert np.isfinite(sim.state.x_m).all()


def test_builtin_brain_runs_unchanged_under_a_limit():
    """The limit changes nothing for a brain that answers in time (same trajectories)."""
    a, b = _sim("wander-v1"), _sim("wander-v1")
    a.run(20)
    with b.brain_time_limit(10.0):
        b.run(20)
    assert np.array_equal(a.state.x_m, b.state.x_m) and np.array_equal(a.state.theta_rad, b.state.theta_rad)


def test_example_brain_still_runs(tmp_path):
    example = Path(__file__).resolve().parents[1] / "examples" / "my_brain.py"
    out = tmp_path / "run"
    proc = teamnav_run(f"{example}:Cautious", out, "--quiet", "--brain-timeout", "30")
    assert proc.returncode == 0, proc.stderr
    assert (out / "metrics.json").is_file()
    assert textwrap.dedent(proc.stdout).strip() == str(out)
