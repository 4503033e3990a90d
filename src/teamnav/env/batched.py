"""N independent copies of a scenario stepped in one call, with array-shaped data."""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from teamnav.env import _checks
from teamnav.env._checks import action_meaning, batch_memory_problem, check_batch, first_not_finite
from teamnav.env._core import EnvCore, Seeds, make_setup

__all__ = ["BatchedEnv", "MAX_BATCH_BYTES"]

#: Most memory [bytes] the copies of one BatchedEnv may need together (16 GiB), estimated from
#: each copy's map cells, robots and observation (:func:`teamnav.env._checks.batch_bytes`); more
#: is refused before any copy is allocated, naming the number of copies, the estimate and this
#: limit. Raise it (``teamnav.env.batched.MAX_BATCH_BYTES = ...``) on a machine with the memory.
MAX_BATCH_BYTES: int = _checks.MAX_BATCH_BYTES


class BatchedEnv(VectorEnv):
    """``num_envs`` independent copies of one scenario, each a team of agents, as a Gymnasium
    vector environment.

    It follows Gymnasium's vector API conventions (``gymnasium.vector.VectorEnv``):
    ``reset(seed=..., options=...)`` and ``step(actions)`` return batched data with the copies
    on the first axis; ``single_observation_space`` / ``single_action_space`` describe one
    copy and ``observation_space`` / ``action_space`` the batch; rewards, terminations and
    truncations are arrays of shape ``(num_envs,)``; ``infos`` is a dict of arrays, each with
    its ``_key`` mask; finished copies are reset automatically on the *next* step
    (``metadata["autoreset_mode"] = AutoresetMode.NEXT_STEP``: that step ignores the copy's
    actions and returns its first observation with reward 0); ``reset(seed=s)`` seeds copy i
    with ``s + i`` (a list gives one seed per copy).

    Data is struct-of-arrays with an agent axis: one copy's observation is a ``Dict`` of
    Boxes of shape ``(n_agents, ...)`` (the keys of :class:`~teamnav.env.ParallelEnv`'s
    per-agent observations, agents in robot-id order, :attr:`agents` names them), so a batch
    is ``(num_envs, n_agents, ...)``; actions are ``(num_envs, n_agents, 2)``. Every agent
    must have the same observation keys and shapes (same sensors); their bounds may differ.

    Rewards: a copy's reward is its team's, the sum over its agents; the per-agent rewards are
    ``infos["agent_rewards"]`` ``(num_envs, n_agents)`` and which agents are still live
    ``infos["live"]``. An agent terminated by ``terminate_on`` stands still, scores 0 and its
    actions are ignored; the copy terminates when all its agents have, and is truncated at
    ``duration_s``.

    The copies run one after the other in this process (each a teamnav simulation, its
    kernels compiled); "one call" steps them all and returns arrays, as a learning loop
    wants. Other arguments are :class:`~teamnav.env.ParallelEnv`'s.
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, scenario: Any, num_envs: int, *, agents_from=None, reward=None, terminate_on=None,
                 observe_truth=None, max_inbox=None, max_detections=None, dtype: Any = np.float64,
                 seed: int | None = None, duration_s: float | None = None, overrides=None, **fields) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
            raise ValueError(f"num_envs must be an int >= 1, got {num_envs!r}")
        self.setup = st = make_setup(scenario, agents_from=agents_from, reward=reward, terminate_on=terminate_on,
                                     observe_truth=observe_truth, max_inbox=max_inbox, max_detections=max_detections,
                                     dtype=dtype, seed=seed, duration_s=duration_s, overrides=overrides, fields=fields)
        obs_bytes = sum(int(np.prod(sp.shape)) * sp.dtype.itemsize for a in st.agent_names
                        for sp in st.obs_spaces[a].spaces.values())
        problem = batch_memory_problem(int(st.grid.cells.size), st.n_robots, obs_bytes, int(num_envs), MAX_BATCH_BYTES)
        if problem is not None:  # refused before any copy is allocated
            raise ValueError(problem)
        self.num_envs = int(num_envs)
        self.agents = list(st.agent_names)
        self._meanings = [action_meaning(h) for h in st.holonomic.tolist()]
        self.single_observation_space = self._stacked_obs_space()
        self.single_action_space = spaces.Box(
            np.concatenate([np.broadcast_to(b.act_space.low, (b.rows.stop - b.rows.start, 2)) for b in st.blocks]),
            np.concatenate([np.broadcast_to(b.act_space.high, (b.rows.stop - b.rows.start, 2)) for b in st.blocks]),
            dtype=st.dtype,
        )
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.render_mode = None
        self._cores = [EnvCore(st) for _ in range(self.num_envs)]
        self._seeds = [Seeds(st.scenario.seed + e) for e in range(self.num_envs)]
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._keys = list(self.single_observation_space.spaces)

    def _stacked_obs_space(self) -> spaces.Dict:
        st = self.setup
        first = st.blocks[0].obs_space
        for b in st.blocks[1:]:
            same = list(b.obs_space.spaces) == list(first.spaces) and all(
                b.obs_space[k].shape == first[k].shape and b.obs_space[k].dtype == first[k].dtype for k in first.spaces)
            if not same:
                g0, g1 = st.scenario.robots[st.blocks[0].group].name, st.scenario.robots[b.group].name
                raise ValueError(f"BatchedEnv stacks agents, so their observations must have the same keys and shapes; "
                                 f"groups {g0!r} and {g1!r} differ (sensors, detector): choose agents_from groups alike")
        out = {}
        for k, sp in first.spaces.items():
            lows = [np.broadcast_to(b.obs_space[k].low, (b.rows.stop - b.rows.start,) + sp.shape) for b in st.blocks]
            highs = [np.broadcast_to(b.obs_space[k].high, (b.rows.stop - b.rows.start,) + sp.shape) for b in st.blocks]
            out[k] = spaces.Box(np.concatenate(lows), np.concatenate(highs), dtype=sp.dtype)
        return spaces.Dict(out)

    # ---------------------------------------------------------------- vector API
    def reset(self, *, seed: int | list[int | None] | None = None, options: dict | None = None):
        """Reset every copy; returns ``(observations, infos)``."""
        if seed is None:
            seeds: list[int | None] = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            seeds = [int(seed) + e for e in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"seed must be None, an int or a list of {self.num_envs} seeds, got {len(seeds)}")
        obs = self._new_obs()
        for e, core in enumerate(self._cores):
            self._fill(obs, e, core.reset(self._seeds[e].next(seeds[e])))
        self._autoreset[:] = False
        return obs, {}

    def step(self, actions):
        """Step every copy once; returns ``(observations, rewards, terminations, truncations, infos)``."""
        st = self.setup
        if type(actions) is np.ndarray and actions.dtype == np.float64 and actions.shape == (self.num_envs, st.n_agents, 2):
            a = actions
        else:  # a real array of that shape, or one error naming the copy and the agent
            a = check_batch(actions, self.num_envs, self.agents, self._meanings)
        # every copy's actions are checked before any copy steps, so a refused step leaves them all in step:
        # the rows that count are those of live agents in copies that are not resetting
        check = np.array([c.live for c in self._cores])
        check[self._autoreset] = False
        bad = first_not_finite(a, check)
        if bad is not None:
            e, j = bad
            raise ValueError(f"copy {e}, agent {self.agents[j]!r}: action must be finite, got {a[e, j].tolist()}; "
                             "no copy was stepped")
        obs = self._new_obs()
        rewards = np.zeros(self.num_envs)
        terminated = np.zeros(self.num_envs, dtype=bool)
        truncated = np.zeros(self.num_envs, dtype=bool)
        agent_rewards = np.zeros((self.num_envs, st.n_agents))
        live = np.zeros((self.num_envs, st.n_agents), dtype=bool)
        for e, core in enumerate(self._cores):
            if self._autoreset[e]:
                self._fill(obs, e, core.reset(self._seeds[e].next(None)))
                self._autoreset[e] = False
                live[e] = True
                continue
            res = core.step(a[e])
            self._fill(obs, e, res.obs)
            agent_rewards[e] = res.reward
            rewards[e] = res.reward.sum()
            truncated[e] = res.truncated
            terminated[e] = core.episode_over and not res.truncated
            live[e] = core.live
            self._autoreset[e] = core.episode_over
        ones = np.ones(self.num_envs, dtype=bool)
        infos = {"agent_rewards": agent_rewards, "_agent_rewards": ones, "live": live, "_live": ones.copy()}
        return obs, rewards, terminated, truncated, infos

    def _new_obs(self) -> dict[str, np.ndarray]:
        sp = self.single_observation_space
        return {k: np.empty((self.num_envs,) + sp[k].shape, dtype=sp[k].dtype) for k in self._keys}

    def _fill(self, out: dict[str, np.ndarray], e: int, blocks: list[dict[str, np.ndarray]]) -> None:
        st = self.setup
        if len(blocks) == 1:
            for k in self._keys:
                out[k][e] = blocks[0][k]
            return
        for b, d in zip(st.blocks, blocks):
            for k in self._keys:
                out[k][e, b.rows] = d[k]

    def close_extras(self, **kwargs) -> None:
        for core in self._cores:
            core.sim = None

    # ---------------------------------------------------------------- teamnav extras
    def robot(self, env_index: int, agent: str):
        """The :class:`~teamnav.env._proxy.RobotPort` of ``agent`` in copy ``env_index``."""
        return self._cores[env_index].ports[self.agents.index(agent)]

    def save_run(self, env_index: int, out_dir, *, force: bool = False):
        """Write copy ``env_index``'s current episode as a run folder."""
        from teamnav.env._record import save_run

        return save_run(self._cores[env_index], out_dir, force=force)
