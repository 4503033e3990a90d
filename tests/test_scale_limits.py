"""Scale edges are refused at once with one message, never accepted silently or left to hang.

Steps per run (``duration_s / dt_s``) are at most :data:`~teamnav.experiments.spec.MAX_STEPS_PER_RUN`
unless a scenario raises ``max_steps`` (up to ``MAX_STEPS_RAISED``); ``dt_s`` may not be longer
than ``duration_s``; a sweep has at most :data:`~teamnav.experiments.sweep_spec.MAX_TRIALS_PER_SWEEP`
trials and seeds, counted before anything is made.
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from teamnav.cli import app
from teamnav.experiments.errors import ScenarioError
from teamnav.experiments.spec import MAX_STEPS_PER_RUN, MAX_STEPS_RAISED, load_scenario
from teamnav.experiments.sweep_spec import MAX_TRIALS_PER_SWEEP, SweepError, SweepSpec, parse_seeds, resolve_spec

#: the page that documents the size limits (it was a section of the README before the site)
LIMITS_PAGE = Path(__file__).resolve().parents[1] / "docs" / "reference" / "scenario-files.md"


def invoke(*args: str):
    return CliRunner().invoke(app, list(args))


# ---------------------------------------------------------------------------- steps per run
def test_the_limits_are_what_the_docs_say():
    assert (MAX_STEPS_PER_RUN, MAX_STEPS_RAISED, MAX_TRIALS_PER_SWEEP) == (10**8, 10**12, 10**5)
    text = LIMITS_PAGE.read_text(encoding="utf-8")
    for name in ("MAX_STEPS_PER_RUN", "MAX_STEPS_RAISED", "MAX_TRIALS_PER_SWEEP", "max_steps"):
        assert name in text


@pytest.mark.parametrize("args", [["--set", "dt_s=1e-9"], ["--set", "dt_s=1e-12", "--set", "duration_s=1e7"],
                                  ["--set", "dt_s=1e-12", "--set", "duration_s=1e7", "--set", "max_steps=1000000000000"]])
def test_validate_refuses_too_many_steps_in_one_line(args):
    res = invoke("validate", "demo", *args)
    assert res.exit_code == 2, res.output
    assert "dt_s:" in res.output and "steps; expected at most" in res.output and "Traceback" not in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_max_steps_lets_a_long_run_through_on_purpose():
    res = invoke("validate", "demo", "--set", "dt_s=1e-7", "--set", "max_steps=1000000000")
    assert res.exit_code == 0, res.output
    assert "600000000 steps" in res.output
    assert "max_steps" not in load_scenario("demo").model_dump(mode="json")  # absent: config hashes unchanged


def test_dt_longer_than_the_duration_is_refused_and_nothing_is_written(tmp_path):
    res = invoke("run", "demo", "--set", "dt_s=5", "--duration", "1", "--out", str(tmp_path / "o"), "--quiet")
    assert res.exit_code == 2, res.output
    assert "dt_s: expected a time step no longer than duration_s (1 s), got 5 s" in res.output
    assert not (tmp_path / "o").exists()


def test_validate_says_what_is_simulated_when_dt_does_not_divide_the_duration():
    res = invoke("validate", "demo", "--set", "dt_s=0.6", "--set", "duration_s=1")
    assert res.exit_code == 0, res.output
    assert "1 s = 2 steps of 0.6 s (simulates 1.2 s)" in res.output


@given(dt=st.floats(1e-12, 10.0), duration=st.floats(1e-6, 1e7))
@settings(max_examples=60, deadline=None)
def test_any_step_and_duration_is_loaded_within_the_limit_or_refused(dt, duration):
    try:
        scn = load_scenario("demo", overrides={"dt_s": dt}, duration_s=duration)
    except ScenarioError as exc:
        assert dt > duration or round(duration / dt) > MAX_STEPS_PER_RUN, str(exc)
        assert "dt_s" in str(exc)
        return
    assert dt <= duration and 1 <= scn.n_steps <= MAX_STEPS_PER_RUN
    assert abs(scn.n_steps * scn.dt_s - duration) <= dt / 2 * (1 + 1e-9)  # never more than half a step off


# ---------------------------------------------------------------------------- trials per sweep
@pytest.mark.parametrize("make", [
    lambda: resolve_spec("demo", seeds="0-100000000000"),                      # used to die of MemoryError
    lambda: resolve_spec("demo", seeds="1000000", grid=["robots.0.count=1,2"]),
    lambda: resolve_spec("demo", seeds=60000, grid=["robots.0.count=1,2"]),
    lambda: resolve_spec("demo", grid=["robots.0.count=" + ",".join(map(str, range(1, 1001))),
                                       "radio.p_loss=" + ",".join(str(i / 1000) for i in range(1000))]),
    lambda: resolve_spec(SweepSpec.model_construct(scenario="demo", grid={}, set={}, seeds=1, duration_s=None, name=None,
                                                   description="", cases_replace_set=[],
                                                   cases=[{"case": f"c{i}", "radio.p_loss": 0.1} for i in range(10**6)])),
])
def test_a_sweep_too_big_is_refused_at_once(make):
    t0 = time.perf_counter()
    with pytest.raises(SweepError, match=r"MAX_TRIALS_PER_SWEEP"):
        make()
    assert time.perf_counter() - t0 < 20


def test_the_cli_refuses_a_huge_seed_range_in_one_line(tmp_path):
    res = invoke("sweep", "demo", "--seeds", "0-100000000000", "--out", str(tmp_path / "o"), "--quiet")
    assert res.exit_code == 2, res.output
    assert res.output.strip() == ("error: --seeds: expected at most 100000 seeds (MAX_TRIALS_PER_SWEEP), received "
                                  "'0-100000000000', which names 100000000001 seeds")
    assert not (tmp_path / "o").exists()


@given(spans=st.lists(st.tuples(st.integers(0, 10**12), st.integers(0, 10**6)), min_size=1, max_size=4))
@settings(max_examples=60, deadline=None)
def test_seed_ranges_are_counted_before_they_are_made(spans):
    text = ",".join(f"{lo}-{lo + n}" for lo, n in spans)
    count = sum(n + 1 for _, n in spans)
    if count > MAX_TRIALS_PER_SWEEP:
        with pytest.raises(SweepError, match=f"names {count} seeds"):
            parse_seeds(text)
    else:
        assert parse_seeds(text) == [s for lo, n in spans for s in range(lo, lo + n + 1)]


def test_the_largest_allowed_sweep_is_counted_not_made():
    spec = SweepSpec(scenario="demo", seeds=MAX_TRIALS_PER_SWEEP // 4, grid={"robots.0.count": [1, 2, 3, 4]})
    assert spec.n_trials == MAX_TRIALS_PER_SWEEP
