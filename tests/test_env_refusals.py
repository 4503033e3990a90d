"""Bad input to the environments gets one clear error: too many batched copies are refused
before anything is allocated, and a bad action (not real, wrong shape, not finite, missing, for
an unknown agent) is refused naming the agent (and the copy) and the expected shape, without
stepping anything."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pettingzoo")
pytest.importorskip("gymnasium")

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as hs  # noqa: E402

from teamnav.env import BatchedEnv, ParallelEnv, SingleRobotEnv  # noqa: E402
from teamnav.env import batched as batched_mod  # noqa: E402
from teamnav.env._checks import as_action, batch_memory_problem  # noqa: E402

TWO = {"robots.0.count": 2}


@pytest.fixture(scope="module")
def batch():
    env = BatchedEnv("demo", 3, duration_s=2.0, **TWO)
    env.reset(seed=1)
    return env


@pytest.fixture(scope="module")
def parallel():
    env = ParallelEnv("demo", duration_s=2.0, **TWO)
    env.reset(seed=1)
    return env


def _clocks(env: BatchedEnv):
    return [(c.sim.step_index, c.sim.time_s) for c in env._cores]


# ---------------------------------------------------------------------------- too many copies
def test_a_million_copies_are_refused_before_any_allocation(monkeypatch):
    made = []
    monkeypatch.setattr(batched_mod, "EnvCore", lambda st: made.append(1))
    with pytest.raises(ValueError) as err:
        BatchedEnv("demo", 1_000_000)
    text = str(err.value)
    assert "num_envs=1,000,000" in text and "TiB" in text and "16.0 GiB" in text
    assert "teamnav.env.batched.MAX_BATCH_BYTES" in text and "8,000,000 robots in all" in text
    assert made == []  # no copy was built


def test_the_limit_can_be_raised_and_counts_robots(monkeypatch):
    few = BatchedEnv("demo", 2, duration_s=1.0)
    per_copy = 16 * few.setup.grid.cells.size
    monkeypatch.setattr(batched_mod, "MAX_BATCH_BYTES", 3 * per_copy)
    with pytest.raises(ValueError, match="num_envs=4 copies"):
        BatchedEnv("demo", 4, duration_s=1.0)
    # more robots per copy: more memory per copy
    one = batch_memory_problem(1000, 1, 100, 10, limit=10**11)
    assert one is None and batch_memory_problem(1000, 10**6, 100, 10, limit=10**11) is not None


@given(cells=hs.integers(0, 10**9), robots=hs.integers(1, 10**4), copies=hs.integers(1, 10**7))
@settings(max_examples=200, deadline=None)
def test_the_estimate_is_monotone_and_names_copies_estimate_and_limit(cells, robots, copies):
    limit = 16 * 1024**3
    problem = batch_memory_problem(cells, robots, 1000, copies, limit)
    if problem is None:
        assert batch_memory_problem(cells, robots, 1000, max(1, copies // 2), limit) is None
    else:
        assert f"num_envs={copies:,}" in problem and "16.0 GiB" in problem and "per copy" in problem
        assert batch_memory_problem(cells, robots, 1000, copies * 2, limit) is not None


# ---------------------------------------------------------------------------- not real numbers
_NOT_REAL = [
    np.array([0.1 + 1j, 0.0]),
    np.array([0.1, 0.0], dtype=complex),
    [0.1 + 0.5j, 0.0],
    np.array([0.1, None], dtype=object),
    [0.1, "fast"],
    "0.1 0.0",
    np.array(["0.1", "0.0"]),
    b"ab",
]


@pytest.mark.parametrize("action", _NOT_REAL, ids=range(len(_NOT_REAL)))
def test_non_real_actions_are_refused_naming_the_agent(action, parallel):
    agents = list(parallel.agents)
    step = parallel.sim.step_index
    with pytest.raises(ValueError) as err:
        parallel.step({a: (action if a == agents[1] else np.zeros(2)) for a in agents})
    assert repr(agents[1]) in str(err.value) and "shape (2,)" in str(err.value)
    assert parallel.sim.step_index == step


def test_complex_actions_are_refused_by_the_single_robot_and_batched_envs(batch):
    one = SingleRobotEnv("demo", duration_s=1.0)
    one.reset(seed=0)
    with pytest.raises(ValueError, match=rf"agent '{one.agent}': action has dtype complex128.*shape \(2,\)"):
        one.step(np.array([0.2 + 0.1j, 0.0]))
    before = _clocks(batch)
    a = np.zeros((3, 2, 2), dtype=complex)
    with pytest.raises(ValueError, match=rf"copy 0, agent '{batch.agents[0]}': .*complex.*shape \(2,\)"):
        batch.step(a)
    with pytest.raises(ValueError, match=rf"copy 0, agent '{batch.agents[0]}'.*text"):
        batch.step([[["a", "b"]] * 2] * 3)
    assert _clocks(batch) == before


# ---------------------------------------------------------------------------- shapes and names
@given(n=hs.integers(0, 6).filter(lambda n: n != 2))
@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_wrong_lengths_name_the_agent_and_the_expected_shape(n, parallel):
    agents = list(parallel.agents)
    with pytest.raises(ValueError) as err:
        parallel.step({a: (np.zeros(n) if a == agents[0] else np.zeros(2)) for a in agents})
    assert repr(agents[0]) in str(err.value) and "shape (2,)" in str(err.value)


def test_scalars_dicts_missing_and_unknown_agents_are_named(parallel):
    agents = list(parallel.agents)
    good = {a: np.zeros(2) for a in agents}
    with pytest.raises(ValueError, match=rf"agent '{agents[0]}': action has shape \(\) .*shape \(2,\)"):
        parallel.step({**good, agents[0]: 0.5})  # a scalar is not spread over v and omega
    with pytest.raises(ValueError, match=rf"missing for live agents \['{agents[1]}'\].*shape \(2,\)"):
        parallel.step({agents[0]: np.zeros(2)})
    with pytest.raises(ValueError, match=r"missing for live agents.*unknown agents \['nobody'\]"):
        parallel.step({agents[0]: np.zeros(2), "nobody": np.zeros(2)})
    with pytest.raises(ValueError, match=r"unknown agents \['nobody'\].*shape \(2,\)"):
        parallel.step({**good, "nobody": np.zeros(2)})
    with pytest.raises(ValueError, match=r"must be a dict .*shape \(2,\)"):
        parallel.step(np.zeros((2, 2)))
    with pytest.raises(ValueError, match=rf"agent '{agents[0]}'.*shape \(2,\)"):
        parallel.step({**good, agents[0]: [[0.1], [0.2, 0.3]]})  # ragged


@given(shape=hs.lists(hs.integers(0, 4), min_size=0, max_size=4).map(tuple).filter(lambda s: s != (3, 2, 2)))
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_batched_shape_errors_name_the_copy_or_agent_and_the_expected_shape(shape, batch):
    before = _clocks(batch)
    with pytest.raises(ValueError) as err:
        batch.step(np.zeros(shape))
    text = str(err.value)
    assert "(3, 2, 2)" in text or ("shape (2,)" in text and "copy " in text and "agent " in text), text
    assert _clocks(batch) == before


def test_batched_ragged_actions_name_the_copy_and_agent(batch):
    rows = [[[0.0, 0.0], [0.0, 0.0]] for _ in range(3)]
    rows[2][1] = [0.0, 0.0, 0.0]
    with pytest.raises(ValueError, match=rf"copy 2, agent '{batch.agents[1]}': action has shape \(3,\)"):
        batch.step(rows)
    rows[2] = [[0.0, 0.0]]
    with pytest.raises(ValueError, match=r"copy 2: 1 actions for its 2 agents"):
        batch.step(rows)


# ---------------------------------------------------------------------------- NaN in one copy
@given(e=hs.integers(0, 2), j=hs.integers(0, 1), k=hs.integers(0, 1),
       bad=hs.sampled_from([np.nan, np.inf, -np.inf]))
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_a_nan_in_one_copy_steps_no_copy(e, j, k, bad, batch):
    before = _clocks(batch)
    a = np.zeros((3, 2, 2))
    a[e, j, k] = bad
    with pytest.raises(ValueError, match=rf"copy {e}, agent '{batch.agents[j]}': action must be finite.*no copy"):
        batch.step(a)
    after = _clocks(batch)
    assert after == before and len(set(after)) == 1  # every copy unchanged, all still in step
    batch.step(np.zeros((3, 2, 2)))  # and the batch goes on, every copy one step further
    assert len(set(_clocks(batch))) == 1 and _clocks(batch)[0][0] == before[0][0] + 1


def test_nan_for_a_finished_agent_is_ignored_as_its_action_is():
    env = BatchedEnv("demo", 2, duration_s=1.0, **TWO)
    env.reset(seed=0)
    env._cores[1].live[1] = False  # as terminate_on leaves it
    env._cores[1]._all_live = False
    a = np.zeros((2, 2, 2))
    a[1, 1] = np.nan
    env.step(a)
    assert _clocks(env)[0] == _clocks(env)[1]


@given(v=hs.lists(hs.floats(allow_nan=False, allow_infinity=False, width=32), min_size=2, max_size=2),
       kind=hs.sampled_from([list, tuple, np.float32, np.float64, np.int64]))
@settings(max_examples=30, deadline=None)
def test_real_actions_of_any_real_dtype_are_taken(v, kind):
    x = kind(v) if kind in (list, tuple) else np.asarray(v).astype(kind)
    out = as_action(x, "R", "(v, omega)")
    assert out.dtype == np.float64 and out.shape == (2,)
    np.testing.assert_array_equal(out, np.asarray(x, dtype=np.float64))
