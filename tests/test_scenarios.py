"""Every built-in scenario loads and runs, deterministically per seed (check_scenario)."""

from __future__ import annotations

import pytest

from teamnav.experiments import registry
from teamnav.experiments.runner import check_scenario
from teamnav.experiments.spec import load_scenario


@pytest.mark.parametrize("name", registry.names())
def test_check_scenario(name):
    # robots started one at a time from one spot (a ``launch`` section, as the trail papers start
    # theirs) begin the same whatever the seed: their first seconds are the set-up, so they are
    # checked over 10 s, by when the seeds' sensor noise has moved them apart
    duration = 10.0 if load_scenario(name).launch is not None else 2.0
    metrics = check_scenario(name, duration_s=duration)
    assert metrics["steps"] == load_scenario(name, duration_s=duration).n_steps
    assert metrics["path_length_m_mean"] > 0.0  # the robots move


def test_check_scenario_catches_a_seed_that_changes_nothing(tmp_path):
    # idle robots never move: two seeds give the same trajectories, which check_scenario must refuse
    path = tmp_path / "idle.yaml"
    path.write_text(
        "name: idle\nmap: {builtin: office_simple}\nduration_s: 1\n"
        "robots:\n  - {count: 2, controller: idle-v1, sensors: [], start: {poses: [[3, 7, 0], [6, 7, 0]]}}\n"
    )
    with pytest.raises(AssertionError, match="gave the same trajectories"):
        check_scenario(path, duration_s=0.5)
