"""One copy of a scenario driven from outside: the episode loop.

:class:`~teamnav.env._setup.EnvSetup` (:mod:`teamnav.env._setup`) is computed once per
environment (which robots are agents, their names, the scenario with proxy brains, the
observation and action spaces, the reward terms); :class:`EnvCore` runs episodes of it with
struct-of-arrays observations and actions. The PettingZoo, Gymnasium and batched environments
are thin views of these two.

Timing (the same as a built-in brain's): the observation of step k is built after the motion
of step k; the agent's action for it is executed by the motion of step k + 1; its radio
messages are heard from where the robot is at step k and delivered at step k + 1. Reset
returns the observation of step 0, before any motion.
"""
from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from teamnav.control.types import Message
from teamnav.env import _engine
from teamnav.env._proxy import EnvProxy, RobotPort
from teamnav.env._setup import Block, EnvSetup
from teamnav.env._setup import Seeds, make_setup  # noqa: F401  (re-exported: the env views import them from here)
from teamnav.env.rewards import RewardContext, StepView, build_terms
from teamnav.experiments.errors import Problem, ScenarioError
from teamnav.experiments.spec import Scenario

__all__ = ["Block", "EnvCore", "EnvSetup"]

_NAN = float("nan")
_TWO_PI = 2.0 * math.pi


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
