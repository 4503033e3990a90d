"""How an environment is configured from a scenario: the setup fixed once per environment.

:class:`EnvSetup` (which robots are agents, their names, the scenario with proxy brains, the
observation and action spaces per :class:`Block` of agents, the reward terms), :func:`make_setup`
(load a scenario with its ``env:`` section and the constructor's settings on top), the robot
references of :class:`~teamnav.env.single.SingleRobotEnv` (:func:`_robot_id`) and the episode
seeds (:class:`Seeds`). Split from :mod:`teamnav.env._core` (no behaviour change; ``_core``
re-exports these names), which runs episodes of a setup.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from gymnasium import spaces

from teamnav.control import registry
from teamnav.env._proxy import AGENT_ENTRY_POINT, ENTRY_POINT
from teamnav.env.config import EnvSpec, unknown_group_problem
from teamnav.env.rewards import RewardContext, build_terms, default_terms
from teamnav.experiments.errors import Problem, ScenarioError
from teamnav.experiments.spec import Scenario, build_grid

__all__ = ["Block", "EnvSetup", "Seeds", "make_setup"]


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
        if scenario.launch is not None:
            # agents act for every robot from step 0: a scenario's one-at-a-time start (its
            # ``launch`` section) is dropped here and the robots start from their groups' ``start``
            scenario = scenario.model_copy(update={"launch": None})
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
