"""A PettingZoo ``ParallelEnv`` over any teamnav scenario."""

from __future__ import annotations

import copy
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium import logger
from pettingzoo import ParallelEnv as _PZParallelEnv

from teamnav.env._checks import action_meaning, as_action
from teamnav.env._core import EnvCore, Seeds, make_setup
from teamnav.env._proxy import RobotPort

__all__ = ["ParallelEnv"]


class ParallelEnv(_PZParallelEnv):
    """A PettingZoo parallel environment: the robots of some groups are agents, the others
    keep the brains their scenario gives them.

    Parameters
    ----------
    scenario : str, Path or Scenario
        A built-in scenario name (``teamnav list``), a scenario file, or a loaded scenario. A
        file may hold an ``env:`` section (:mod:`teamnav.env.config`); the arguments below
        replace its keys.
    agents_from : list of str or int, optional
        Groups (names or indices) whose robots are agents; default every group.
    reward : str, list of str or dict, optional
        Reward terms (:mod:`teamnav.env.rewards`): a name, names, or ``{name: {param: value}}``.
    terminate_on : list of str, optional
        Events that end an agent's episode when they fire for it (e.g. ``at_goal``).
    observe_truth : bool, optional
        Add ``privileged_true_pose`` (world frame) to observations. Off by default: an agent
        sees what a brain sees and nothing else.
    max_inbox, max_detections : int, optional
        Rows of the padded ``inbox`` and ``detections`` arrays (default 8 each).
    render_mode : {"rgb_array"} or None
    record_dir : str or Path, optional
        Write every finished episode as a run folder ``record_dir/episode-NNNN``
        (``teamnav replay`` works on it); :meth:`save_run` writes one where you want.
    dtype : numpy float type
        Of observations and actions (default float64, the simulator's own precision; float32
        for learning libraries that want it).
    seed, duration_s : optional
        Replace the scenario's seed (the first reset's episode seed) and its duration [s].
    overrides : list of "KEY=VALUE" or dict, optional
        Dotted overrides as ``teamnav run --set`` takes them (``env.KEY`` sets the env section).
    **fields
        More overrides by keyword: ``dt_s=0.05``, or ``**{"robots.0.count": 2}``.

    Observations
    ------------
    Per agent a ``gymnasium.spaces.Dict`` of Boxes, all in the robot's own frames (what
    :class:`teamnav.control.types.Observation` carries):

    - ``odom_pose`` (3,): odometry (x [m], y [m], theta [rad]) in the robot's odometry frame;
    - ``odom_delta`` (3,): odometry motion since the last step, in the previous body frame;
    - ``scan_NAME`` (B,): each range sensor's ranges [m] (``max_range_m`` = no return);
    - ``stalled`` (1,): 1 when the last commanded motion was blocked;
    - ``time_s`` (1,): the robots' common clock [s];
    - ``detections`` (D, 3) and ``detections_count`` (1,): teammates seen (range [m], bearing
      [rad], id or -1), in body frame, padded with zeros (with a robot detector only);
    - ``inbox`` (M, 3) and ``inbox_count`` (1,): messages delivered this step (sender id or -1,
      sender's stamp [s], size [bytes]), padded; their bodies are in
      ``env.robot(agent).observation.inbox``;
    - ``events`` (E,): 1 for each of the scenario's place events that fired for the robot;
    - ``privileged_true_pose`` (3,): only with ``observe_truth``; the true world pose.

    Values beyond a Box's bounds are clipped only where a noise tail could reach them
    (detection ranges, message stamps and sizes).

    Actions
    -------
    Per agent a Box (2,): ``(v [m/s], omega [rad/s])`` for a unicycle, bounded by its
    ``max_v_mps`` and ``max_omega_degps``; ``(vx, vy)`` [m/s] in the body frame for a
    holonomic-step robot, which steps ``step_length_m`` towards ``atan2(vy, vx)`` when the
    vector is at least half the step speed ``step_length_m / dt_s`` long and stays otherwise.
    An agent's action for the observation of step k is executed by the motion of step k + 1,
    as a built-in brain's is. Radio messages, log values and a ``finished`` flag go through
    :meth:`robot`.

    Episodes
    --------
    An agent is *terminated* when an event of ``terminate_on`` fires for it, or, in a scenario
    with ``stop_when_finished``, when every robot with a task reports it done (built-in brains
    by their ``finished`` attribute, agents by ``env.robot(agent).finished``); every agent is
    *truncated* at the scenario's ``duration_s``. A finished agent's robot stands still.

    Seeding follows Gymnasium: ``reset(seed=s)`` starts the episode of the scenario with seed
    ``s`` (bit for bit the one ``teamnav run --seed s`` starts) and restarts the stream from
    which later ``reset()`` calls draw their seeds; the first ``reset()`` without a seed uses
    the scenario's seed.
    """

    metadata = {"name": "teamnav_v0", "render_modes": ["rgb_array"], "render_fps": 10, "is_parallelizable": True}

    def __init__(self, scenario: Any, *, agents_from=None, reward=None, terminate_on=None, observe_truth=None,
                 max_inbox=None, max_detections=None, render_mode: str | None = None,
                 record_dir: str | os.PathLike | None = None, dtype: Any = np.float64, seed: int | None = None,
                 duration_s: float | None = None, overrides=None, _robots: list[int] | None = None, **fields) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or None, got {render_mode!r}")
        self.setup = make_setup(scenario, robots=_robots, agents_from=agents_from, reward=reward, terminate_on=terminate_on,
                                observe_truth=observe_truth, max_inbox=max_inbox, max_detections=max_detections,
                                dtype=dtype, seed=seed, duration_s=duration_s, overrides=overrides, fields=fields)
        st = self.setup
        self.render_mode = render_mode
        self.record_dir = Path(record_dir) if record_dir is not None else None
        self.possible_agents = list(st.agent_names)
        self.agents: list[str] = []
        self.observation_spaces = {a: copy.deepcopy(st.obs_spaces[a]) for a in self.possible_agents}
        self.action_spaces = {a: copy.deepcopy(st.act_spaces[a]) for a in self.possible_agents}
        self._core = EnvCore(st)
        self._core.flat_single = True  # a one-agent block is handed out as that agent's dict
        self._flat = [b.n == 1 for b in st.blocks]
        self._seeds = Seeds(st.scenario.seed)
        self._row = {a: j for j, a in enumerate(self.possible_agents)}
        # (block, row in block) of every agent
        self._where = [(int(st.block_of_row[j]), j - st.blocks[int(st.block_of_row[j])].rows.start)
                       for j in range(st.n_agents)]
        self._episodes = 0
        self._saved = False

    # ---------------------------------------------------------------- PettingZoo API
    def observation_space(self, agent: str):
        return self.observation_spaces[agent]

    def action_space(self, agent: str):
        return self.action_spaces[agent]

    def reset(self, seed: int | None = None, options: dict | None = None):
        """Start an episode; returns ``(observations, infos)`` of step 0 (``options`` are not used)."""
        obs = self._core.reset(self._seeds.next(seed))
        self._episodes += 1
        self._saved = False
        live = self._core.live.tolist()
        self.agents = [a for a, ok in zip(self.possible_agents, live) if ok]  # a robot dead from the start is no agent
        return self._split(obs, self.agents), {a: {"step": 0, "events": ()} for a in self.agents}

    def step(self, actions: dict[str, Any]):
        """Step every live agent once; returns ``(observations, rewards, terminations, truncations, infos)``."""
        live = self.agents
        if not live:
            raise RuntimeError("the episode is over: call reset()")
        st = self.setup
        row = self._row
        a = np.zeros((st.n_agents, 2))
        if not isinstance(actions, Mapping):
            raise ValueError(f"actions must be a dict {{agent: action of shape (2,)}} for the live agents "
                             f"{live[:5]}{' ...' if len(live) > 5 else ''}, got {type(actions).__name__}")
        try:
            for ag in live:
                v = actions[ag]
                if type(v) is np.ndarray and v.shape == (2,) and v.dtype.kind in "fiub":
                    a[row[ag]] = v
                else:  # anything else: a real array of two values, or one error naming the agent
                    a[row[ag]] = as_action(v, ag, action_meaning(bool(st.holonomic[row[ag]])))
        except KeyError:
            missing = [ag for ag in live if ag not in actions]
            extra = [ag for ag in actions if ag not in row]
            also = f"; unknown agents {extra[:5]} in actions" if extra else ""
            raise ValueError(f"actions are missing for live agents {missing[:5]}{' ...' if len(missing) > 5 else ''}"
                             f" (each an action of shape (2,)){also}") from None
        if len(actions) > len(live):
            extra = [ag for ag in actions if ag not in row]
            if extra:
                raise ValueError(f"unknown agents {extra[:5]} in actions (agents: {', '.join(self.possible_agents[:8])}"
                                 f"{' ...' if len(self.possible_agents) > 8 else ''}; each an action of shape (2,))")
        core = self._core
        res = core.step(a)
        step = core.sim.step_index
        trunc = bool(res.truncated)
        events = res.events
        if len(live) == st.n_agents:  # every agent live: rows are the agents' order
            obs = self._split_all(res.obs)
            rew = dict(zip(live, res.reward.tolist()))
            term = dict(zip(live, res.terminated.tolist()))
            truncs = dict.fromkeys(live, trunc)
            if len(res.terms) == 1:
                (name, v), = res.terms.items()
                infos = {ag: {"step": step, "events": ev, "reward_terms": {name: x}}
                         for ag, ev, x in zip(live, events, v.tolist())}
            else:
                names = list(res.terms)
                infos = {ag: {"step": step, "events": ev, "reward_terms": dict(zip(names, xs))}
                         for ag, ev, *xs in zip(live, events, *[v.tolist() for v in res.terms.values()])}
        else:
            obs = self._split(res.obs, live)
            reward = res.reward.tolist()
            terminated = res.terminated.tolist()
            terms = {n: v.tolist() for n, v in res.terms.items()}
            rew, term, truncs, infos = {}, {}, {}, {}
            for ag in live:
                j = row[ag]
                rew[ag] = reward[j]
                term[ag] = terminated[j]
                truncs[ag] = trunc
                infos[ag] = {"step": step, "events": events[j], "reward_terms": {n: v[j] for n, v in terms.items()}}
        if trunc or core.episode_over:
            self.agents = []
        elif True in term.values():
            self.agents = [ag for ag in live if not term[ag]]
        if not self.agents and self.record_dir is not None and not self._saved:
            self.save_run(self.record_dir / f"episode-{self._episodes - 1:04d}", force=True)
        return obs, rew, term, truncs, infos

    def _split(self, blocks: list[dict[str, np.ndarray]], agents: list[str]) -> dict[str, dict[str, np.ndarray]]:
        out = {}
        where, row, flat = self._where, self._row, self._flat
        for ag in agents:
            b, k = where[row[ag]]
            out[ag] = blocks[b] if flat[b] else {key: arr[k] for key, arr in blocks[b].items()}
        return out

    def _split_all(self, blocks: list[dict[str, np.ndarray]]) -> dict[str, dict[str, np.ndarray]]:
        """:meth:`_split` for every agent: the rows of each block's arrays, block after block."""
        out = {}
        names = iter(self.possible_agents)
        for d, flat in zip(blocks, self._flat):
            if flat:  # one agent: already its own dict
                out[next(names)] = d
                continue
            keys = list(d)
            for vals, ag in zip(zip(*d.values()), names):  # iterating an array yields its rows (views)
                out[ag] = dict(zip(keys, vals))
        return out

    def render(self):
        if self.render_mode is None:
            logger.warn("render() called without a render_mode; pass render_mode='rgb_array' to the environment")
            return None
        from teamnav.env._record import render_rgb

        return render_rgb(self._core)

    def close(self) -> None:
        self._core.sim = None

    # ---------------------------------------------------------------- teamnav extras
    def robot(self, agent: str) -> RobotPort:
        """The agent's :class:`~teamnav.env._proxy.RobotPort`: its observation object as a brain
        gets it, ``send`` (radio), ``log`` (recorder), ``finished``, ``report_pose`` and
        ``scenario_controller()`` (the scenario's own brain for this robot)."""
        j = self._row.get(agent)
        if j is None:
            raise ValueError(f"unknown agent {agent!r} (agents: {', '.join(self.possible_agents[:8])} ...)")
        return self._core.ports[j]

    def save_run(self, out_dir: str | os.PathLike, *, force: bool = False) -> Path:
        """Write the current (or just finished) episode as a run folder; returns its path."""
        from teamnav.env._record import save_run

        path = save_run(self._core, out_dir, force=force)
        self._saved = True
        return path

    @property
    def scenario(self):
        """The resolved scenario (with the scenario's own brains)."""
        return self.setup.scenario

    @property
    def sim(self):
        """The running :class:`~teamnav.sim.engine.Simulation` (the truth: for scoring and
        analysis, never for an agent's decisions)."""
        return self._core.sim

    @property
    def robot_ids(self) -> dict[str, int]:
        """Agent name -> robot id in the simulation."""
        return dict(zip(self.possible_agents, self.setup.agent_ids.tolist()))
