"""A Gymnasium ``Env`` for one robot among scripted teammates."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from teamnav.env._checks import action_meaning, as_action
from teamnav.env._core import EnvCore, make_setup
from teamnav.env._proxy import RobotPort

__all__ = ["SingleRobotEnv"]


class SingleRobotEnv(gym.Env):
    """One robot of a scenario is the agent; every other robot keeps its scenario brain
    (teammates in the agent's own group too: their brains are built and seeded exactly as in
    ``teamnav run``).

    Parameters
    ----------
    scenario : str, Path or Scenario
        As for :class:`~teamnav.env.ParallelEnv`.
    robot : int or str, optional
        The agent's robot: an id, an agent name (``GROUP`` for a group of one, ``GROUP_K``)
        or a group name (its first robot). Default: the first robot of the scenario's
        ``env.agents_from`` groups, else robot 0.
    reward, terminate_on, observe_truth, max_inbox, max_detections, render_mode, record_dir,
    dtype, seed, duration_s, overrides, **fields
        As for :class:`~teamnav.env.ParallelEnv`.

    Notes
    -----
    Observation and action spaces are the agent's of :class:`~teamnav.env.ParallelEnv`
    (a ``Dict`` of Boxes; a ``Box`` (2,)), and so are the timing, the episode ends and the
    seeding: ``reset(seed=s)`` is the episode of the scenario with seed ``s``, bit for bit;
    the first ``reset()`` without a seed uses the scenario's seed and later ones draw theirs
    from ``self.np_random``.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, scenario: Any, robot: int | str | None = None, *, reward=None, terminate_on=None,
                 observe_truth=None, max_inbox=None, max_detections=None, render_mode: str | None = None,
                 record_dir: str | os.PathLike | None = None, dtype: Any = np.float64, seed: int | None = None,
                 duration_s: float | None = None, overrides=None, **fields) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or None, got {render_mode!r}")
        self.setup = make_setup(scenario, robot_ref=robot, single=robot is None, reward=reward, terminate_on=terminate_on,
                                observe_truth=observe_truth, max_inbox=max_inbox, max_detections=max_detections,
                                dtype=dtype, seed=seed, duration_s=duration_s, overrides=overrides, fields=fields)
        st = self.setup
        self.agent = st.agent_names[0]
        self.observation_space = st.obs_spaces[self.agent]
        self.action_space = st.act_spaces[self.agent]
        self.render_mode = render_mode
        self.record_dir = Path(record_dir) if record_dir is not None else None
        self._core = EnvCore(st)
        self._core.flat_single = True  # its one agent's block is its observation, in its own shapes
        self._episodes = 0
        self._done = True

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Start an episode; returns ``(observation, info)`` of step 0 (``options`` are not used)."""
        if seed is None and self._np_random is None:
            seed = self.setup.scenario.seed
            super().reset(seed=seed)
        else:
            super().reset(seed=seed)
            if seed is None:
                seed = int(self.np_random.integers(0, 2**63 - 1))
        obs = self._core.reset(int(seed))
        if not self._core.live[0]:
            raise ValueError(f"robot {self.agent!r} is dead from the start of the episode (the scenario's faults.deaths): "
                             "there is nothing to drive")
        self._episodes += 1
        self._done = False
        return obs[0], {"step": 0, "events": (), "seed": int(seed)}

    def step(self, action):
        """Returns ``(observation, reward, terminated, truncated, info)``."""
        if self._done:
            raise RuntimeError("the episode is over: call reset()")
        if type(action) is np.ndarray and action.shape == (2,) and action.dtype.kind in "fiub":
            a = action.astype(np.float64, copy=False).reshape(1, 2)
        else:  # anything else: a real array of two values, or one error naming the agent
            a = as_action(action, self.agent, action_meaning(bool(self.setup.holonomic[0]))).reshape(1, 2)
        res = self._core.step(a)
        terminated = bool(res.terminated[0])
        truncated = bool(res.truncated)
        info = {"step": self._core.sim.step_index, "events": res.events[0],
                "reward_terms": {n: float(v[0]) for n, v in res.terms.items()}}
        if terminated or truncated:
            self._done = True
            if self.record_dir is not None:
                self.save_run(self.record_dir / f"episode-{self._episodes - 1:04d}", force=True)
        return res.obs[0], float(res.reward[0]), terminated, truncated, info

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode='rgb_array' to the environment")
            return None
        from teamnav.env._record import render_rgb

        return render_rgb(self._core)

    def close(self) -> None:
        self._core.sim = None

    # ---------------------------------------------------------------- teamnav extras
    @property
    def robot(self) -> RobotPort:
        """The agent's :class:`~teamnav.env._proxy.RobotPort` (observation object, radio, logs, ...)."""
        return self._core.ports[0]

    def save_run(self, out_dir: str | os.PathLike, *, force: bool = False) -> Path:
        """Write the current (or just finished) episode as a run folder; returns its path."""
        from teamnav.env._record import save_run

        return save_run(self._core, out_dir, force=force)

    @property
    def scenario(self):
        return self.setup.scenario

    @property
    def sim(self):
        """The running simulation (the truth: for scoring and analysis only)."""
        return self._core.sim
