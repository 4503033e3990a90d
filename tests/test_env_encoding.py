"""The environment's observation arrays are the observation objects the engine hands the
agents' proxies, whichever way they are built (commit 31c052f, 2026-11-27).

``EnvCore.encode`` reads the engine's whole-group arrays (``Simulation.observed``: one copy per
group and key) when the run has no faults, and the observation objects one robot at a time
otherwise. Both must give the same arrays, bit for bit and in the same dtype, and those arrays
must be what the objects carry.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("pettingzoo")
pytest.importorskip("gymnasium")

from teamnav.control.types import Message  # noqa: E402
from teamnav.env import BatchedEnv, ParallelEnv, SingleRobotEnv  # noqa: E402


def _assert_same(a: list[dict[str, np.ndarray]], b: list[dict[str, np.ndarray]]) -> None:
    assert len(a) == len(b)
    for da, db in zip(a, b):
        assert list(da) == list(db)
        for k in da:
            assert da[k].dtype == db[k].dtype and da[k].shape == db[k].shape, k
            np.testing.assert_array_equal(da[k], db[k], err_msg=k)


def _assert_from_objects(core) -> None:
    """Each block's arrays hold what its agents' observation objects carry."""
    st = core.setup
    for b, d in zip(st.blocks, core.encode()):
        if core.flat_single and b.n == 1:  # a one-agent block in the agent's own shapes
            d = {k: v[None] for k, v in d.items()}
        for j, p in enumerate(core.proxies[b.rows]):
            o = core.observation(p.info.robot_id)
            np.testing.assert_array_equal(d["odom_pose"][j], np.asarray(o.odom_pose, dtype=st.dtype))
            np.testing.assert_array_equal(d["odom_delta"][j], np.asarray(o.odom_delta, dtype=st.dtype))
            assert d["time_s"][j, 0] == np.asarray(o.time_s, dtype=st.dtype)
            assert d["stalled"][j, 0] == float(o.stalled)
            for name in b.scan_names:
                np.testing.assert_array_equal(d[f"scan_{name}"][j], np.asarray(o.scans[name].ranges_m, dtype=st.dtype))
            if "inbox_count" in d:
                assert d["inbox_count"][j, 0] == min(len(o.inbox), st.spec.max_inbox)
            if "detections_count" in d:
                assert d["detections_count"][j, 0] == min(len(o.detections), b.det_rows)


def _check_steps(core, step, n_steps: int, rng: np.random.Generator) -> int:
    """Step with random actions; at every step both encoders agree and match the objects.
    Returns how many steps took the whole-group path."""
    whole = 0
    for _ in range(n_steps):
        groups = core._encode_groups(core.sim.observed) if core._whole_groups else None
        objects = core._encode_objects()
        if groups is not None:
            whole += 1
            _assert_same(groups, objects)
        _assert_same(core.encode(), objects)
        _assert_from_objects(core)
        if core.episode_over or not step(rng):
            break
    return whole


def _parallel_stepper(env: ParallelEnv):
    def step(rng):
        if not env.agents:
            return False
        acts = {}
        for a in env.agents:
            sp = env.action_space(a)
            acts[a] = rng.uniform(sp.low, sp.high).astype(sp.dtype)
        env.step(acts)
        return bool(env.agents)
    return step


@pytest.mark.parametrize("name,kw", [
    ("demo", {}),  # radio: inboxes
    ("los-help-simple", {}),  # robot detectors, one-robot groups sharing a cast
    ("blazing-a-trail", {}),  # place events
    ("collab-mcl-detection", {}),
    ("swarm", {"robots.0.count": 5}),  # a batched controller's group, as agents
    ("demo", {"dtype": np.float32, "observe_truth": True}),
    ("los-help-simple", {"agents_from": ["R2", "R4"]}),  # agents of two groups, scripted robots between
    ("los-help-simple", {"dtype": np.float32, "observe_truth": True}),  # one-agent blocks: their own shapes
])
def test_whole_group_observations_equal_the_objects(name, kw):
    kw = dict(kw)
    env = ParallelEnv(name, duration_s=3.0, **kw)
    env.reset(seed=4)
    core = env._core
    assert core._whole_groups  # no faults: the whole-group path is the one taken
    whole = _check_steps(core, _parallel_stepper(env), 25, np.random.default_rng(0))
    assert whole >= 10


def test_messages_reach_the_inbox_arrays_on_the_whole_group_path():
    env = ParallelEnv("demo", duration_s=1.0, radio={"mode": "broadcast"})
    env.reset(seed=1)
    env.robot("wanderer_0").send([Message(0, 0.0, {"hello": 1.0}, kind="hi")])
    obs, *_ = env.step({a: np.zeros(2) for a in env.agents})
    assert obs["wanderer_1"]["inbox_count"][0] == 1 and obs["wanderer_1"]["inbox"][0, 0] == 0
    _assert_same(env._core._encode_groups(env.sim.observed), env._core._encode_objects())


def test_a_robot_among_scripted_teammates_of_its_group():
    """SingleRobotEnv's robot in the middle of its group: its row of the group's arrays."""
    env = SingleRobotEnv("demo", "wanderer_2", duration_s=5.0)
    env.reset(seed=3)
    core = env._core
    rng = np.random.default_rng(1)

    def step(rng):
        _, _, term, trunc, _ = env.step(env.action_space.sample())
        return not (term or trunc)

    env.action_space.seed(5)
    assert _check_steps(core, step, 20, rng) >= 10
    obs = env.step(env.action_space.sample())[0]
    np.testing.assert_array_equal(obs["scan_laser"], env.robot.observation.scans["laser"].ranges_m)


def test_with_faults_the_objects_are_read_and_a_dropped_scan_reads_no_return():
    faults = {"sensor_dropouts": [{"robot": 1, "sensor": "laser", "t0_s": 0.3, "t1_s": 0.8, "reading": "no_scan"}],
              "deaths": [{"robot": 2, "t_s": 0.4}]}
    env = ParallelEnv("demo", duration_s=2.0, faults=faults, **{"robots.0.count": 3})
    env.reset(seed=2)
    core = env._core
    assert not core._whole_groups
    saw_dropout = False
    while env.agents:
        obs, *_ = env.step({a: np.array([0.2, 0.1]) for a in env.agents})
        if "wanderer_1" in obs and "laser" not in env.robot("wanderer_1").observation.scans:
            saw_dropout = True
            assert np.all(obs["wanderer_1"]["scan_laser"] == env.observation_space("wanderer_1")["scan_laser"].high)
    assert saw_dropout


def test_observation_arrays_are_fresh_each_step():
    """An agent may keep an observation: the next step does not write into it, and it does not
    share memory with the observation objects (or the engine's arrays)."""
    env = ParallelEnv("demo", duration_s=1.0)
    obs0, _ = env.reset(seed=1)
    keep = {k: v.copy() for k, v in obs0["wanderer_0"].items()}
    obs1, *_ = env.step({a: np.array([0.3, 0.2]) for a in env.agents})
    for k, v in keep.items():
        np.testing.assert_array_equal(obs0["wanderer_0"][k], v)
    raw = env.robot("wanderer_0").observation
    assert not np.shares_memory(obs1["wanderer_0"]["scan_laser"], raw.scans["laser"].ranges_m)
    assert not np.shares_memory(obs1["wanderer_0"]["odom_pose"], raw.odom_pose)
    assert not math.isnan(float(obs1["wanderer_0"]["time_s"][0]))


def test_batched_copies_fill_from_the_whole_group_path():
    env = BatchedEnv("demo", 2, duration_s=1.0)
    obs, _ = env.reset(seed=[7, 7])
    for _ in range(5):
        obs, *_ = env.step(np.zeros(env.action_space.shape))
        for e, core in enumerate(env._cores):
            (d,) = core._encode_objects()
            for k, v in d.items():
                np.testing.assert_array_equal(obs[k][e], v, err_msg=k)


def _same_observation(a, b) -> None:
    assert (a.robot_id, a.step, a.time_s, a.stalled) == (b.robot_id, b.step, b.time_s, b.stalled)
    assert type(a.stalled) is type(b.stalled)
    for x, y in ((a.odom_pose, b.odom_pose), (a.odom_delta, b.odom_delta)):
        assert x.dtype == y.dtype
        np.testing.assert_array_equal(x, y)
    assert list(a.scans) == list(b.scans)
    for name in a.scans:
        sa, sb = a.scans[name], b.scans[name]
        np.testing.assert_array_equal(sa.ranges_m, sb.ranges_m)
        np.testing.assert_array_equal(sa.angles_rad, sb.angles_rad)
        assert sa.max_range_m == sb.max_range_m
    assert a.detections == b.detections and a.inbox == b.inbox and a.events == b.events


@pytest.mark.parametrize("name,kw", [
    ("demo", {"radio": {"mode": "broadcast"}}),
    ("los-help-simple", {}),
    ("blazing-a-trail", {}),
])
def test_observation_objects_built_for_agents_equal_the_engines(name, kw, monkeypatch):
    """A whole group of agents is handed no per-robot observation by the engine
    (``observes_whole_group``); the object ``RobotPort.observation`` builds instead is the one the
    engine builds for a brain, field by field, step by step, and the episode is the same."""
    from teamnav.env._proxy import AgentProxy

    lazy = ParallelEnv(name, duration_s=3.0, **kw)
    obs_l, _ = lazy.reset(seed=6)
    monkeypatch.setattr(AgentProxy, "observes_whole_group", False)  # the engine builds every object
    eager = ParallelEnv(name, duration_s=3.0, **kw)
    obs_e, _ = eager.reset(seed=6)
    assert lazy._core._lazy and not eager._core._lazy
    rng = np.random.default_rng(2)
    steps = 0
    while lazy.agents:
        for a in lazy.agents:
            _same_observation(lazy.robot(a).observation, eager.robot(a).observation)
            assert lazy.robot(a).observation is lazy.robot(a).observation  # one object per step
            for k in obs_l[a]:
                np.testing.assert_array_equal(obs_l[a][k], obs_e[a][k], err_msg=k)
        if steps % 3 == 0:
            for env in (lazy, eager):  # messages, so inboxes are not all empty
                env.robot(env.agents[0]).send([Message(env.robot_ids[env.agents[0]], 0.0, {"n": steps}, kind="x")])
        acts = {}
        for a in lazy.agents:
            sp = lazy.action_space(a)
            acts[a] = rng.uniform(sp.low, sp.high)
        obs_l, rew_l, term_l, trunc_l, _ = lazy.step(acts)
        obs_e, rew_e, term_e, trunc_e, _ = eager.step(acts)
        assert (rew_l, term_l, trunc_l) == (rew_e, term_e, trunc_e)
        steps += 1
    assert steps >= 20
    s_l, s_e = lazy.sim.state, eager.sim.state
    np.testing.assert_array_equal(s_l.x_m, s_e.x_m)
    np.testing.assert_array_equal(s_l.theta_rad, s_e.theta_rad)
