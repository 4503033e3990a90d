"""One copy of a scenario driven from outside: the shared setup and the episode loop.

:class:`EnvSetup` is computed once per environment (which robots are agents, their names, the
scenario with proxy brains, the observation and action spaces, the reward terms);
:class:`EnvCore` runs episodes of it with struct-of-arrays observations and actions. The
PettingZoo, Gymnasium and batched environments are thin views of these two.

Timing (the same as a built-in brain's): the observation of step k is built after the motion
of step k; the agent's action for it is executed by the motion of step k + 1; its radio
messages are heard from where the robot is at step k and delivered at step k + 1. Reset
returns the observation of step 0, before any motion.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from gymnasium import spaces

from teamnav.control import registry
from teamnav.control.types import Message
from teamnav.env import _engine
from teamnav.env._proxy import AGENT_ENTRY_POINT, ENTRY_POINT, EnvProxy, RobotPort
from teamnav.env.config import EnvSpec, unknown_group_problem
from teamnav.env.rewards import RewardContext, StepView, build_terms, default_terms
from teamnav.experiments.errors import Problem, ScenarioError
from teamnav.experiments.spec import Scenario, build_grid

__all__ = ["Block", "EnvCore", "EnvSetup"]

_NAN = float("nan")
_TWO_PI = 2.0 * math.pi


@dataclass
class Block:
    """Agents of one group: they share one observation space and one action space.

    ``rows`` is their slice in the agents' order (agents are in robot-id order and a group's
    robots have consecutive ids).
    """

    group: int
    rows: slice
    robot_ids: np.ndarray
    obs_space: spaces.Dict
    act_space: spaces.Box
    scan_names: tuple[str, ...]
    has_detector: bool
    holonomic: bool
    no_return: tuple[np.ndarray, ...] = ()  # per scan: every beam at max range
    scans: tuple = ()  # per scan: (sensor name, observation key, no-return ranges)
    det_rows: int = 0  # rows of the detections array (0: no detector, or max_detections 0)
    det_rmax: float = 0.0  # detection ranges are clipped to [0, det_rmax]
    n: int = 0  # agents in the block
    index: Any = None  # their robot ids: a slice when consecutive (views), else the ids
    col_index: Any = None  # (index, None): a column (n, 1) of a per-robot array
    in_group: Any = None  # their rows in their group's arrays: a slice when consecutive, else an array
    first: int = 0  # the first agent's robot id
    first_in_group: int = 0  # ... and its row in its group's arrays


def _box(low, high, shape=None, dtype=np.float64) -> spaces.Box:
    """A Box whose bounds are given in its own dtype (no precision warning for float32)."""
    dtype = np.dtype(dtype)
    if shape is not None:
        low, high = np.full(shape, low), np.full(shape, high)
    return spaces.Box(np.asarray(low, dtype=dtype), np.asarray(high, dtype=dtype), dtype=dtype)


def _agent_names(scenario: Scenario, ids: list[int]) -> list[str]:
    """``GROUP`` for a group of one robot, ``GROUP_K`` (K: index in the group) otherwise; made
    unique with ``_ID`` when group names repeat."""
    group_of, index_in = [], []
    for gi, g in enumerate(scenario.robots):
        group_of += [gi] * g.count
        index_in += list(range(g.count))
    names = []
    for i in ids:
        g = scenario.robots[group_of[i]]
        names.append(g.name if g.count == 1 else f"{g.name}_{index_in[i]}")
    if len(set(names)) < len(names):
        names = [f"{n}_{i}" if names.count(n) > 1 else n for n, i in zip(names, ids)]
    return names


class EnvSetup:
    """Everything an environment fixes once: agents, spaces, the proxied scenario, rewards.

    Parameters
    ----------
    scenario : Scenario
        Resolved and validated.
    spec : EnvSpec
    file : str
        For messages.
    robots : list of int, optional
        Explicit agent robot ids (overrides ``spec.agents_from``).
    dtype : numpy dtype
        Of the float observations and actions.
    """

    def __init__(self, scenario: Scenario, spec: EnvSpec, file: str, *, robots: list[int] | None = None,
                 dtype: Any = np.float64) -> None:
        self.scenario = scenario
        self.spec = spec
        self.file = file
        self.dtype = np.dtype(dtype)
        if self.dtype.kind != "f":
            raise ValueError(f"dtype must be a float type (np.float32 or np.float64), got {self.dtype}")
        groups = scenario.robots
        offsets = np.concatenate([[0], np.cumsum([g.count for g in groups])]).astype(int)
        self.offsets = offsets
        self.n_robots = int(offsets[-1])
        if robots is not None:
            ids = sorted({int(r) for r in robots})
            bad = [r for r in ids if not 0 <= r < self.n_robots]
            if bad:
                raise ValueError(f"robot ids must be in [0, {self.n_robots}), got {bad}")
        else:
            unknown_group_problem(spec, scenario, file)
            chosen = set(range(len(groups)))
            if spec.agents_from is not None:
                chosen = {ref if isinstance(ref, int) else gi for ref in spec.agents_from
                          for gi, g in enumerate(groups) if isinstance(ref, int) or g.name == ref}
            ids = [i for gi in sorted(chosen) for i in range(offsets[gi], offsets[gi + 1])]
        if not ids:
            raise ScenarioError(file, [Problem("env.agents_from", "expected groups with at least one robot (every chosen group has count 0)")])
        self.agent_ids = np.asarray(ids, dtype=np.int64)
        self.agent_names = _agent_names(scenario, ids)
        self.n_agents = len(ids)
        lo, hi = int(self.agent_ids[0]), int(self.agent_ids[-1])
        self.contiguous = hi - lo + 1 == self.n_agents
        self.id_index: Any = slice(lo, hi + 1) if self.contiguous else self.agent_ids
        group_of = np.repeat(np.arange(len(groups)), [g.count for g in groups])
        self.group_of = group_of
        self.proxied = sorted({int(group_of[i]) for i in ids})

        # the scenario's own brains of the proxied groups (to wrap teammates, and for ports)
        self.orig: dict[int, tuple[Any, Any]] = {}
        id_set = set(ids)
        entry: dict[int, str] = {}
        for gi in self.proxied:
            g = groups[gi]
            cls = registry.lookup(g.controller)
            params = cls.Params.model_validate(dict(g.params))
            partial = any(i not in id_set for i in range(offsets[gi], offsets[gi + 1]))
            if partial and getattr(cls, "batched", False):
                raise ValueError(
                    f"robots[{gi}] ({g.name!r}) runs the batched controller {g.controller!r}, which cannot keep some of "
                    "the group's robots while others are agents; make the whole group agents or split the group"
                )
            self.orig[gi] = (cls, params)
            entry[gi] = ENTRY_POINT if partial else AGENT_ENTRY_POINT
        self.template = scenario.model_copy(update={"robots": tuple(
            g.model_copy(update={"controller": entry[gi], "params": {}}) if gi in self.proxied else g
            for gi, g in enumerate(groups)
        )})

        # events the observations encode: every event a place of the scenario fires
        self.event_names = tuple(sorted({p.event for p in scenario.places if p.event is not None}))
        self.event_index = {e: k for k, e in enumerate(self.event_names)}
        self.terminate_on = frozenset(spec.terminate_on)
        self.t_hi = float(scenario.duration_s) + scenario.dt_s  # top of time_s and of message stamps
        self.grid = build_grid(scenario)
        self.n_steps = scenario.n_steps
        self.blocks = self._blocks()
        self.det_any = any(b.det_rows for b in self.blocks)
        self.block_of_row = np.concatenate([[b_i] * (b.rows.stop - b.rows.start) for b_i, b in enumerate(self.blocks)])
        self.obs_spaces = {}
        self.act_spaces = {}
        for b in self.blocks:
            for j in range(b.rows.start, b.rows.stop):
                self.obs_spaces[self.agent_names[j]] = b.obs_space
                self.act_spaces[self.agent_names[j]] = b.act_space
        # actions: which agents move by holonomic steps, and the shortest (vx, vy) that moves them
        self.holonomic = np.zeros(self.n_agents, dtype=bool)
        self.half_step_speed = np.zeros(self.n_agents)
        for b in self.blocks:
            g = groups[b.group]
            self.holonomic[b.rows] = b.holonomic
            self.half_step_speed[b.rows] = 0.5 * g.step_length_m / scenario.dt_s
        self.any_holonomic = bool(self.holonomic.any())
        self.all_holonomic = bool(self.holonomic.all())

        terms = spec.reward_terms() or default_terms(scenario)
        self.reward_spec = terms
        build_terms(terms, RewardContext(scenario, self.agent_ids, file))  # check names and parameters now

    # ---------------------------------------------------------------- spaces
    def _blocks(self) -> list[Block]:
        scn = self.scenario
        out: list[Block] = []
        ids = self.agent_ids.tolist()
        j = 0
        xmin, xmax, ymin, ymax = self.grid.bounds_m
        r_map = max(abs(xmin), abs(xmax), abs(ymin), abs(ymax))
        while j < len(ids):
            gi = int(self.group_of[ids[j]])
            k = j
            while k < len(ids) and int(self.group_of[ids[k]]) == gi:
                k += 1
            g = scn.robots[gi]
            holo = g.kinematics == "holonomic_step"
            speed = g.step_length_m / scn.dt_s if holo else g.max_v_mps
            space = self._obs_space(g, speed, r_map, (xmin, xmax, ymin, ymax))
            names = tuple(s.name for s in g.sensors)
            none = tuple(np.full(space[f"scan_{nm}"].shape, float(c.max_range_m)) for nm, c in zip(names, g.sensors))
            det_rows = self.spec.max_detections if g.detector is not None else 0
            rid = np.asarray(ids[j:k], dtype=np.int64)
            consecutive = int(rid[-1]) - int(rid[0]) + 1 == k - j
            index = slice(int(rid[0]), int(rid[-1]) + 1) if consecutive else rid
            start = int(self.offsets[gi])
            in_group = slice(int(rid[0]) - start, int(rid[-1]) + 1 - start) if consecutive else rid - start
            out.append(Block(gi, slice(j, k), rid, space, self._act_space(g, holo), names,
                             g.detector is not None, holo, none,
                             tuple((nm, f"scan_{nm}", nr) for nm, nr in zip(names, none)), det_rows,
                             float(space["detections"].high[0, 0]) if det_rows else 0.0,
                             k - j, index, (index, None), in_group, int(rid[0]), int(rid[0]) - start))
            j = k
        return out

    def _obs_space(self, g, speed: float, r_map: float, bounds) -> spaces.Dict:
        scn, f = self.scenario, self.dtype
        od = g.odometry
        noise = 1.0 + 10.0 * (sum(od.alpha) + od.slip_std_m_per_sqrt_m) + abs(od.scale_error)
        travel = speed * scn.duration_s
        b = r_map + 2.0 * noise * travel + 10.0
        db = 5.0 * noise * speed * scn.dt_s + 1.0
        pi = math.pi
        d: dict[str, spaces.Space] = {
            "odom_pose": _box(np.array([-b, -b, -pi]), np.array([b, b, pi]), dtype=f),
            "odom_delta": _box(np.array([-db, -db, -pi]), np.array([db, db, pi]), dtype=f),
            "time_s": _box(0.0, float(scn.duration_s) + scn.dt_s, shape=(1,), dtype=f),
            "stalled": _box(0.0, 1.0, shape=(1,), dtype=f),
        }
        for cfg in g.sensors:
            n_beams = {"laser": lambda c: c.n_beams, "sonar": lambda c: c.n_transducers,
                       "proximity": lambda c: len(c.angles_deg)}[cfg.kind](cfg)
            d[f"scan_{cfg.name}"] = _box(0.0, float(cfg.max_range_m), shape=(n_beams,), dtype=f)
        if g.detector is not None and self.spec.max_detections > 0:
            det = g.detector
            rmax = 2.0 * det.max_range_m + 10.0 * det.range_noise_std_m + 1.0
            n = self.spec.max_detections
            d["detections"] = _box(np.tile([0.0, -pi, -1.0], (n, 1)), np.tile([rmax, pi, self.n_robots - 1], (n, 1)),
                                         dtype=f)
            d["detections_count"] = _box(0, n, shape=(1,), dtype=np.int64)
        if self.spec.max_inbox > 0:
            n = self.spec.max_inbox
            d["inbox"] = _box(np.tile([-1.0, 0.0, 0.0], (n, 1)),
                                    np.tile([self.n_robots - 1, float(scn.duration_s) + scn.dt_s, 1e12], (n, 1)), dtype=f)
            d["inbox_count"] = _box(0, n, shape=(1,), dtype=np.int64)
        if self.event_names:
            d["events"] = _box(0.0, 1.0, shape=(len(self.event_names),), dtype=f)
        if self.spec.observe_truth:
            xmin, xmax, ymin, ymax = bounds
            d["privileged_true_pose"] = _box(np.array([xmin, ymin, -pi]), np.array([xmax, ymax, pi]), dtype=f)
        return spaces.Dict(d)

    def _act_space(self, g, holo: bool) -> spaces.Box:
        if holo:
            s = g.step_length_m / self.scenario.dt_s
            return _box(np.array([-s, -s]), np.array([s, s]), dtype=self.dtype)
        w = math.radians(g.max_omega_degps)
        return _box(np.array([-g.max_v_mps, -w]), np.array([g.max_v_mps, w]), dtype=self.dtype)

    # ---------------------------------------------------------------- scenario brains
    def build_brain(self, robot_id: int, rng: np.random.Generator, info) -> Any:
        """The scenario's controller for ``robot_id``, built as the engine builds it."""
        gi = int(self.group_of[robot_id])
        cls, params = self.orig[gi]
        if getattr(cls, "batched", False):
            raise ValueError(f"robots[{gi}] runs the batched controller {self.scenario.robots[gi].controller!r}: it has no "
                             "per-robot instance to build")
        return cls(params, rng, info)


class StepResult:
    """One step of every agent, rows in the agents' order."""

    __slots__ = ("obs", "reward", "terms", "terminated", "truncated", "events")

    def __init__(self, obs: list[dict[str, np.ndarray]], reward: np.ndarray, terms: dict[str, np.ndarray],
                 terminated: np.ndarray, truncated: bool, events: list[tuple[str, ...]]) -> None:
        self.obs = obs  # per block
        self.reward = reward
        self.terms = terms
        self.terminated = terminated
        self.truncated = truncated
        self.events = events


class EnvCore:
    """Episodes of one copy of the scenario (see the module docstring)."""

    def __init__(self, setup: EnvSetup) -> None:
        self.setup = setup
        self.sim: Any = None
        self.proxies: list[EnvProxy] = []
        self._proxy_of: dict[int, EnvProxy] = {}
        self.ports = [RobotPort(n, i, self) for n, i in zip(setup.agent_names, setup.agent_ids.tolist())]
        self.live = np.zeros(setup.n_agents, dtype=bool)
        self.seed: int | None = None
        self.episode_return = np.zeros(setup.n_agents)
        self.wall_s = 0.0
        self.episode_over = True
        self._ports_dirty = False  # an agent's port holds messages or log values for the next step
        self._first: int | None = None
        self._whole_groups = False
        #: one-agent blocks in the agent's own shapes (see :meth:`encode`)
        self.flat_single = False

    # ---------------------------------------------------------------- access
    def proxy(self, robot_id: int) -> EnvProxy:
        if self.sim is None:
            raise RuntimeError("call reset() first")
        return self._proxy_of[int(robot_id)]

    def build_scenario_brain(self, robot_id: int, rng: np.random.Generator) -> Any:
        return self.setup.build_brain(robot_id, rng, self.proxy(robot_id).info)

    def episode_scenario(self) -> Scenario:
        """The original scenario with this episode's seed (what `teamnav run` would run)."""
        return self.setup.scenario.model_copy(update={"seed": int(self.seed)})

    # ---------------------------------------------------------------- episode
    def reset(self, seed: int) -> list[dict[str, np.ndarray]]:
        from teamnav.sim.engine import Simulation

        st = self.setup
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) <= 2**63 - 1:
            raise ValueError(f"seed must be an int in [0, 2**63 - 1], got {seed!r}")
        self.seed = int(seed)
        scn = st.template.model_copy(update={"seed": self.seed})
        try:
            sim = Simulation(st.grid, scn, known_map=st.grid if scn.give_map else None)
        except ValueError as exc:
            raise ScenarioError(st.file, [Problem("", f"the simulator cannot set up this scenario: {exc}")]) from None
        _engine.check_engine(sim)
        self.sim = sim
        self._proxy_of = {}
        off = st.offsets
        for gi in st.proxied:
            for k, p in enumerate(sim.brains[gi]):
                self._proxy_of[int(off[gi]) + k] = p
        agent_set = set(st.agent_ids.tolist())
        for i, p in self._proxy_of.items():
            if i not in agent_set:
                p.brain = st.build_brain(i, p.rng, p.info)  # a teammate: the scenario's brain, its own stream
        self.proxies = [self._proxy_of[i] for i in st.agent_ids.tolist()]
        for port in self.ports:
            port._clear()
        self.terms = build_terms(st.reward_spec, RewardContext(st.scenario, st.agent_ids, st.file))
        self.live[:] = True
        self._all_live = True
        self.episode_return[:] = 0.0
        self.wall_s = 0.0
        self.episode_over = False
        self._logged_step = -1
        self._set_commands = _engine.command_writer(sim)
        self._first = int(st.agent_ids[0])
        self._faults = getattr(sim, "faults", None)
        # observations from the engine's whole-group arrays (Simulation.observed) unless faults
        # may leave a robot's observation stale (a dead brain) or without a scan (a dropout)
        self._whole_groups = self._faults is None and hasattr(sim, "observed")
        self._no_events = [()] * st.n_agents if not st.event_names else None
        self._ports_dirty = False
        _engine.decide_first(sim)
        died = _engine.dead(sim, st.id_index)
        if died is not None and died.any():  # dead from the first step: never live
            self.live &= ~died
            self._all_live = False
        # agents whose observation objects the engine did not build (a whole group of agents, no
        # faults): built from Simulation.observed when asked for (RobotPort.observation)
        self._lazy = self._whole_groups and any(p.obs is None for p in self.proxies)
        self._view = view = StepView(sim, st.agent_ids, self._events(), self.ports)
        for _, term in self.terms:
            term.reset(view)
        return self.encode()

    def step(self, actions: np.ndarray) -> StepResult:
        """Apply ``actions`` (n_agents, 2) (rows of agents no longer live are ignored), step once."""
        st = self.setup
        sim = self.sim
        if sim is None or self.episode_over:
            raise RuntimeError("the episode is over (or never started): call reset()")
        a = actions if type(actions) is np.ndarray and actions.dtype == np.float64 else np.asarray(actions, dtype=np.float64)
        if a.shape != (st.n_agents, 2):
            raise ValueError(f"actions must have shape ({st.n_agents}, 2), got {a.shape}")
        live = self.live
        all_live = self._all_live
        if not all_live:
            a = np.where(live[:, None], a, 0.0)
        # finite actions only (NaN would reach the motion kernels): a Python pass is cheaper for a few agents
        few = st.n_agents <= 32
        flat = a.ravel().tolist() if few else None
        if not (all(map(math.isfinite, flat)) if few else bool(np.isfinite(a).all())):
            bad = int(np.flatnonzero(~np.isfinite(a).all(axis=1))[0])
            raise ValueError(f"agent {st.agent_names[bad]!r}: action must be finite, got {a[bad].tolist()}")
        if st.any_holonomic:
            holo = st.holonomic
            move = holo & (np.hypot(a[:, 0], a[:, 1]) >= st.half_step_speed)
            if not all_live:
                move &= live
            self._set_commands(st.id_index, np.where(holo, 0.0, a[:, 0]), np.where(holo, 0.0, a[:, 1]),
                               np.where(move, np.arctan2(a[:, 1], a[:, 0]), _NAN))
        elif st.n_agents == 1:  # one unicycle: two scalar writes, no array views
            self._set_commands(self._first, flat[0], flat[1], None)
        else:  # unicycles: the proxies' placeholder left direction_rad NaN, which unicycles ignore anyway
            self._set_commands(st.id_index, a[:, 0], a[:, 1], None)
        step = sim.step_index
        if self._ports_dirty:
            self._flush_ports(step)
        elif sim.recorder.wants(step):  # nothing to send or log: what _flush_ports would note
            self._logged_step = step
        stop_when_finished = st.scenario.stop_when_finished
        if stop_when_finished and step > 0 and _all_finished(sim):
            return self._finish_without_motion()
        t0 = time.perf_counter()
        sim.step()
        self.wall_s += time.perf_counter() - t0
        obs = self.encode()
        events = self._events()
        view = self._view
        view.events = events
        if len(self.terms) == 1:
            name, term = self.terms[0]
            reward = term(view)
            terms = {name: reward}
        else:
            terms = {name: term(view) for name, term in self.terms}
            reward = np.sum(list(terms.values()), axis=0) if terms else np.zeros(st.n_agents)
        if not all_live:
            reward = np.where(live, reward, 0.0)
        if st.n_agents <= 4:  # the same additions, one float at a time (cheaper than a ufunc call for a few)
            ret = self.episode_return
            for j, r in enumerate(reward.tolist()):
                ret[j] += r
        else:
            self.episode_return += reward
        terminated = np.zeros(st.n_agents, dtype=bool)
        done = False
        if st.terminate_on:
            for j, ev in enumerate(events):
                if ev and not st.terminate_on.isdisjoint(ev):
                    terminated[j] = True
                    done = True
        if stop_when_finished and _all_finished(sim):
            terminated[:] = True
            done = True
        if self._faults is not None:
            died = _engine.dead(sim, st.id_index)
            if died is not None and died.any():  # a faults death: the engine steps that brain no more
                terminated |= died
                done = True
        truncated = sim.step_index >= st.n_steps
        if done:
            terminated &= live
            live &= ~terminated
            self._all_live = False
            if not live.any():
                self.episode_over = True
        if truncated:
            self.episode_over = True
        if self.episode_over:
            live[:] = False
            self._all_live = False
        return StepResult(obs, reward, terms, terminated, truncated, events)

    def _events(self) -> list[tuple[str, ...]]:
        if self._no_events is not None:  # no place of the scenario fires an event
            return self._no_events
        if self._lazy:
            events = self.sim.observed[5]
            if events is None:
                return [()] * self.setup.n_agents
            return [events[i] for i in self.setup.agent_ids.tolist()]
        return [() if p.obs is None else p.obs.events for p in self.proxies]

    def observation(self, robot_id: int) -> Any:
        """Agent ``robot_id``'s :class:`~teamnav.control.types.Observation` of this step, the
        object a brain would be handed: the engine's, or built as the engine builds it from
        :attr:`Simulation.observed` where the engine left it to the environment (once per step)."""
        p = self.proxy(robot_id)
        if not self._lazy:
            return p.obs
        sim = self.sim
        o = p.obs
        if o is not None and o.step == sim.step_index:
            return o
        from teamnav.control.types import Observation, RangeScan

        step, odom, delta, scans_of, inboxes, events, dets_of = sim.observed
        i = int(robot_id)
        gi = int(self.setup.group_of[i])
        k = i - int(self.setup.offsets[gi])
        dets = dets_of[gi] if dets_of is not None and gi in dets_of else None
        p.obs = o = Observation(
            robot_id=i, step=step, time_s=sim.time_s, odom_pose=odom[i], odom_delta=delta[i],
            scans={name: RangeScan(r[k], a, m) for name, r, a, m in scans_of[gi]},
            detections=tuple(dets[k]) if dets is not None else (),
            stalled=sim.state.stalled[i:i + 1].tolist()[0],
            inbox=inboxes[i] if inboxes is not None else (),
            events=events[i] if events is not None else (),
        )
        return o

    def _blank(self, b: Block, proxy) -> Any:
        """An observation of nothing (zeros, no returns) for a robot that never got one."""
        from teamnav.control.types import Observation, RangeScan

        scans = {name: RangeScan(none.copy(), none.copy(), float(none[0]) if none.size else 0.0)
                 for name, none in zip(b.scan_names, b.no_return)}
        return Observation(robot_id=proxy.info.robot_id, step=self.sim.step_index, time_s=self.sim.time_s,
                           odom_pose=np.zeros(3), odom_delta=np.zeros(3), scans=scans)

    def _finish_without_motion(self) -> StepResult:
        """Every robot with a task said it is done (``stop_when_finished``), the agents after
        deciding on this observation: the episode ends here, as ``teamnav run`` stops once
        the brains say so, with no further motion (the observation is this step's again)."""
        st = self.setup
        terminated = self.live.copy()
        self.live[:] = False
        self._all_live = False
        self.episode_over = True
        zeros = np.zeros(st.n_agents)
        return StepResult(self.encode(), zeros, {name: zeros.copy() for name, _ in self.terms}, terminated, False,
                          [() for _ in range(st.n_agents)])

    def finalize_logs(self) -> None:
        """Before a run folder is written: the agents' log values at the last step (the ones
        given after it, else their latest), as a built-in brain's last log is recorded."""
        sim = self.sim
        step = sim.step_index
        if self._logged_step == step:
            return
        sim.record_last_step()
        for port in self.ports:
            log = port._log if port._log is not None else port._last_log
            port._log = None
            if log:
                _record_log(sim.recorder, step, sim.time_s, port.robot_id, log)
        self._logged_step = step

    def _flush_ports(self, step: int) -> None:
        """The agents' messages go on the radio (heard from where they are now) and their log
        values into the recorder at the step they belong to."""
        sim = self.sim
        outgoing: list[tuple[int, Message]] = []
        rec = sim.recorder
        wants = rec.wants(step)
        t = sim.time_s
        for port, alive in zip(self.ports, self.live.tolist()):
            if not port._outbox and port._log is None:
                continue
            out, log = port._take()
            if not alive:
                continue
            for m in out:
                outgoing.append((port.robot_id, m))
            if log is not None:
                port._last_log = log
                if log and wants:
                    _record_log(rec, step, t, port.robot_id, log)
        if wants:
            self._logged_step = step
        self._ports_dirty = False
        if outgoing:
            _engine.send_messages(sim, outgoing)

    # ---------------------------------------------------------------- observations
    def encode(self) -> list[dict[str, np.ndarray]]:
        """This step's observations as arrays, one dict per block (rows: its agents): the
        contents of the observation objects the agents' proxies were handed, read from the
        engine's whole-group arrays (:attr:`Simulation.observed`, one copy per group and key)
        where it can, else from those objects one by one.

        With :attr:`flat_single` set (the PettingZoo and Gymnasium views), a block of one
        agent holds that agent's arrays in their own shapes (no agent axis): its dict is the
        agent's observation as it is handed out, with nothing to split."""
        sim = self.sim
        seen = sim.observed if self._whole_groups else None
        if seen is not None and seen[0] == sim.step_index:
            out = self._encode_groups(seen)
            if out is not None:
                return out
        return self._encode_objects()

    def _encode_groups(self, seen) -> list[dict[str, np.ndarray]] | None:
        """:meth:`encode` from the engine's arrays: odometry, deltas and scans are rows of
        the very arrays each observation views; the stall flags and the clock are the state's
        that the observations were built from (nothing moves between). None if a group's
        scans are not there as expected."""
        st = self.setup
        f = st.dtype
        sim = self.sim
        _, odom, delta, scans_of, inboxes, events, dets_of = seen
        t = sim.step_index * sim.dt_s  # sim.time_s, what the observations were given
        stalled = sim.state.stalled
        flat = self.flat_single
        m_inbox = st.spec.max_inbox
        n_events = len(st.event_names)
        out = []
        for b in st.blocks:
            readings = scans_of.get(b.group)
            if readings is None or len(readings) != len(b.scans):
                return None
            if flat and b.n == 1:  # one agent: its own shapes
                i, rows = b.first, b.first_in_group
                clock = np.array((t, stalled[i]), dtype=f)  # one array, two (1,) views: time_s, stalled
                d: dict[str, np.ndarray] = {
                    "odom_pose": np.array(odom[i], dtype=f),
                    "odom_delta": np.array(delta[i], dtype=f),
                    "time_s": clock[:1],
                    "stalled": clock[1:],
                }
            else:
                ix = b.index
                rows = b.in_group
                time_s = np.empty((b.n, 1), dtype=f)
                time_s.fill(t)
                d = {
                    "odom_pose": np.array(odom[ix], dtype=f),
                    "odom_delta": np.array(delta[ix], dtype=f),
                    "time_s": time_s,
                    "stalled": stalled[b.col_index].astype(f),
                }
            for (name, key, _), r in zip(b.scans, readings):
                if r[0] != name:
                    return None
                d[key] = np.array(r[1][rows], dtype=f)
            if b.det_rows or (m_inbox and inboxes is not None) or (n_events and events is not None):
                ids = b.robot_ids.tolist()
                dets = None
                if b.det_rows and dets_of is not None and b.group in dets_of:
                    found = dets_of[b.group]
                    start = int(st.offsets[b.group])
                    dets = [found[i - start] for i in ids]
                self._encode_lists(b, d, dets, None if inboxes is None else [inboxes[i] for i in ids],
                                   None if events is None else [events[i] for i in ids], flat and b.n == 1)
            else:  # no detector, and no message and no event this step for anyone: all padding
                if m_inbox:
                    d["inbox"] = np.zeros((m_inbox, 3) if flat and b.n == 1 else (b.n, m_inbox, 3), dtype=f)
                    d["inbox_count"] = np.zeros(1 if flat and b.n == 1 else (b.n, 1), dtype=np.int64)
                if n_events:
                    d["events"] = np.zeros(n_events if flat and b.n == 1 else (b.n, n_events), dtype=f)
            if st.spec.observe_truth:
                s = sim.state
                ix = b.index
                truth = np.stack([s.x_m[ix], s.y_m[ix], s.theta_rad[ix]], axis=1).astype(f)
                d["privileged_true_pose"] = truth[0] if flat and b.n == 1 else truth
            out.append(d)
        return out

    def _encode_objects(self) -> list[dict[str, np.ndarray]]:
        """:meth:`encode` from the observation objects, robot by robot (with faults: a dead
        robot keeps its last observation, a dropped scan reads as no return)."""
        st = self.setup
        f = st.dtype
        out = []
        for b in st.blocks:
            proxies = self.proxies[b.rows]
            obs = [self.observation(p.info.robot_id) if self._lazy else p.obs for p in proxies]
            if any(o is None for o in obs):  # a robot dead from the start was never observed
                obs = [o if o is not None else self._blank(b, p) for o, p in zip(obs, proxies)]
            n = len(obs)
            d: dict[str, np.ndarray] = {
                "odom_pose": np.array([o.odom_pose for o in obs], dtype=f),
                "odom_delta": np.array([o.odom_delta for o in obs], dtype=f),
                "time_s": np.full((n, 1), obs[0].time_s, dtype=f),
                "stalled": np.array([[o.stalled] for o in obs], dtype=f),
            }
            for name, key, none in b.scans:
                try:
                    d[key] = np.array([o.scans[name].ranges_m for o in obs], dtype=f)
                except KeyError:  # a sensor fault left the scan out: read as no return on every beam
                    d[key] = np.array([o.scans[name].ranges_m if name in o.scans else none for o in obs], dtype=f)
            self._encode_lists(b, d, [o.detections for o in obs], [o.inbox for o in obs], [o.events for o in obs], False)
            if st.spec.observe_truth:
                s = self.sim.state
                ids = b.robot_ids
                d["privileged_true_pose"] = np.stack([s.x_m[ids], s.y_m[ids], s.theta_rad[ids]], axis=1).astype(f)
            out.append({k: v[0] for k, v in d.items()} if self.flat_single and n == 1 else d)
        return out

    def _encode_lists(self, b: Block, d: dict[str, np.ndarray], dets: list | None, inbox: list | None,
                      events: list | None, flat: bool) -> None:
        """The padded detections, inbox and events of a block's agents into ``d``: per agent
        its detections, messages and events (None: nothing for anyone); ``flat``: one agent,
        in its own shapes."""
        st = self.setup
        f = st.dtype
        n = b.n
        if b.det_rows:
            m, rmax = b.det_rows, b.det_rmax
            det = np.zeros((m, 3) if flat else (n, m, 3), dtype=f)
            cnt = np.zeros(1 if flat else (n, 1), dtype=np.int64)
            rows_det, rows_cnt = (det[None], cnt[None]) if flat else (det, cnt)
            for j, seen in enumerate(dets or ()):
                if seen:
                    rows = seen[:m]
                    rows_det[j, : len(rows)] = [(min(max(x.range_m, 0.0), rmax), math.remainder(x.bearing_rad, _TWO_PI),
                                                 -1 if x.robot_id is None else x.robot_id) for x in rows]
                    rows_cnt[j, 0] = len(rows)
            d["detections"] = det
            d["detections_count"] = cnt
        m = st.spec.max_inbox
        if m:
            box = np.zeros((m, 3) if flat else (n, m, 3), dtype=f)
            cnt = np.zeros(1 if flat else (n, 1), dtype=np.int64)
            rows_box, rows_cnt = (box[None], cnt[None]) if flat else (box, cnt)
            for j, got in enumerate(inbox or ()):
                if got:
                    rows = got[:m]
                    rows_box[j, : len(rows)] = [self._message_row(msg) for msg in rows]
                    rows_cnt[j, 0] = len(rows)
            d["inbox"] = box
            d["inbox_count"] = cnt
        if st.event_names:
            ev = np.zeros(len(st.event_names) if flat else (n, len(st.event_names)), dtype=f)
            rows_ev = ev[None] if flat else ev
            index = st.event_index
            for j, fired in enumerate(events or ()):
                for e in fired:
                    k = index.get(e)
                    if k is not None:
                        rows_ev[j, k] = 1.0
            d["events"] = ev

    def _message_row(self, msg: Message) -> tuple[float, float, float]:
        """(sender, stamp [s], size [bytes]) of a delivered message, within the inbox Box: the
        sender and stamp are what the sending brain wrote, so anything odd reads -1 / 0."""
        st = self.setup
        sender = msg.sender if isinstance(msg.sender, (int, np.integer)) and 0 <= msg.sender < st.n_robots else -1
        try:
            stamp = float(msg.stamp_s)
        except (TypeError, ValueError):
            stamp = 0.0
        stamp = min(max(stamp, 0.0), st.t_hi) if math.isfinite(stamp) else 0.0
        return sender, stamp, min(msg.size_bytes(), 1e12)

def _record_log(rec, step: int, t: float, robot: int, values: dict) -> None:
    """A brain's log entry into the recorder, as ``Recorder.record`` stores one."""
    rec.record_log(step, t, robot, values)


def _all_finished(sim) -> bool:
    """The rule of ``stop_when_finished`` (:func:`teamnav.experiments.runner.all_finished`)."""
    from teamnav.experiments.runner import all_finished

    return all_finished(sim)


# ---------------------------------------------------------------------------- building from a scenario
def make_setup(scenario, *, robots: list[int] | None = None, robot_ref: Any = None, single: bool = False,
               agents_from=None, reward=None,
               terminate_on=None, observe_truth=None, max_inbox=None, max_detections=None, dtype=np.float64,
               seed=None, duration_s=None, overrides=None, fields: dict[str, Any] | None = None) -> EnvSetup:
    """Load ``scenario`` (a built-in name, a file or a Scenario) with its ``env:`` section and
    the constructor's settings on top, and fix the setup.

    ``overrides`` (dotted ``KEY=VALUE`` strings or a dict) and ``fields`` (keyword overrides,
    e.g. ``dt_s=0.05`` or ``**{"robots.0.count": 2}``) change the scenario; ``env.KEY`` keys
    change its ``env:`` section.
    """
    from teamnav.env.config import env_spec, load_env_scenario

    merged: Any = overrides
    if fields:
        if overrides is None:
            merged = dict(fields)
        elif isinstance(overrides, dict):
            merged = {**overrides, **fields}
        else:
            merged = list(overrides) + [f"{k}={_yaml_value(v)}" for k, v in fields.items()]
    scn, env_raw, file = load_env_scenario(scenario, overrides=merged, seed=seed, duration_s=duration_s)
    given = {"agents_from": _as_tuple(agents_from), "reward": _reward_value(reward), "terminate_on": _as_tuple(terminate_on),
             "observe_truth": observe_truth, "max_inbox": max_inbox, "max_detections": max_detections}
    spec = env_spec(env_raw, given, file)
    if robot_ref is not None:
        robots = [_robot_id(scn, robot_ref, spec)]
    elif single:  # the first robot of the first agent group (of every group: robot 0)
        unknown_group_problem(spec, scn, file)
        first = 0
        if spec.agents_from is not None:
            ref = spec.agents_from[0]
            gi = ref if isinstance(ref, int) else [g.name for g in scn.robots].index(ref)
            first = sum(g.count for g in scn.robots[:gi])
        robots = [first]
    return EnvSetup(scn, spec, file, robots=robots, dtype=dtype)


def _yaml_value(v: Any) -> str:
    import json

    return json.dumps(v) if not isinstance(v, str) else v


def _as_tuple(v: Any) -> Any:
    if v is None:
        return None
    if isinstance(v, (str, int)):
        return (v,)
    return tuple(v)


def _reward_value(v: Any) -> Any:
    if v is None or isinstance(v, (str, dict)):
        return v
    return tuple(v)


def _robot_id(scn: Scenario, ref: Any, spec: EnvSpec) -> int:
    """A robot id from an id, an agent name (``GROUP`` or ``GROUP_K``) or a group name (its first robot)."""
    n = scn.n_robots
    if isinstance(ref, (int, np.integer)) and not isinstance(ref, bool):
        if not 0 <= int(ref) < n:
            raise ValueError(f"robot must be a robot id in [0, {n}), got {ref!r}")
        return int(ref)
    if isinstance(ref, str):
        names = _agent_names(scn, list(range(n)))
        if ref in names:
            return names.index(ref)
        off = 0
        for g in scn.robots:
            if g.name == ref and g.count > 0:
                return off
            off += g.count
        raise ValueError(f"robot {ref!r} is neither an agent name ({', '.join(names[:12])}{' ...' if n > 12 else ''}) "
                         f"nor a group of the scenario")
    raise ValueError(f"robot must be a robot id, an agent name or a group name, got {ref!r}")


class Seeds:
    """Episode seeds as Gymnasium seeds episodes: ``reset(seed=s)`` runs the scenario with seed
    ``s`` (bit for bit the episode ``teamnav run --seed s`` would start) and restarts the stream
    that later unseeded resets draw their seeds from; the first reset without a seed uses
    ``default`` (the scenario's own seed)."""

    def __init__(self, default: int) -> None:
        self.default = int(default)
        self.rng: np.random.Generator | None = None

    def next(self, seed: int | None) -> int:
        if seed is not None:
            if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) <= 2**63 - 1:
                raise ValueError(f"seed must be an int in [0, 2**63 - 1] or None, got {seed!r}")
            self.rng = np.random.default_rng(int(seed))
            return int(seed)
        if self.rng is None:
            self.rng = np.random.default_rng(self.default)
            return self.default
        return int(self.rng.integers(0, 2**63 - 1))
