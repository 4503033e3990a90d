"""VMAS peer for benchmarks/bench_env.py: N agents with a 180-ray lidar, stepped through VMAS's env.

Runs in VMAS's own interpreter (never a teamnav dependency; torch's CPU build)::

    python -m venv /tmp/vmas-venv && /tmp/vmas-venv/bin/pip install torch==2.13.0 && /tmp/vmas-venv/bin/pip install vmas
    /tmp/vmas-venv/bin/python benchmarks/peers/vmas_peer.py --agents 10 --steps 50

Set-up as close to bench_env.py's as VMAS allows: VMAS has no occupancy-grid maps, so the world
is a 60 m x 60 m square bounded by 4 walls (``Line`` landmarks) with 40 box obstacles (1-3 m);
N disc agents of radius 0.2 m (VMAS's default holonomic dynamics), each with a ``Lidar`` of 180
rays over 180° and 8 m range that sees walls, boxes and agents; dt 0.1 s; ``num_envs``
copies (1 = one scenario, as ParallelEnv), on the CPU. Each agent gets a constant action
every step; observations are each agent's lidar, position and velocity (what VMAS returns
from ``env.step``). Timed: ``env.step(actions)`` after 10 warm-up steps, best of ``repeats``.
Prints one JSON line: agents, num_envs, steps, best seconds per step, agent-steps per second.
"""

from __future__ import annotations

import argparse
import json
import math
import time


def make_scenario(n_agents: int, n_boxes: int = 40, seed: int = 0):
    import torch
    from vmas.simulator.core import Agent, Box, Landmark, Line, World
    from vmas.simulator.scenario import BaseScenario
    from vmas.simulator.sensors import Lidar

    half = 30.0

    class Basement(BaseScenario):
        def make_world(self, batch_dim, device, **kwargs):
            world = World(batch_dim, device, dt=0.1, x_semidim=half, y_semidim=half)
            g = torch.Generator().manual_seed(seed)
            for k in range(4):
                world.add_landmark(Landmark(f"wall{k}", shape=Line(length=2 * half), collide=True))
            for k in range(n_boxes):
                w, h = (1.0 + 2.0 * torch.rand(2, generator=g)).tolist()
                world.add_landmark(Landmark(f"box{k}", shape=Box(length=w, width=h), collide=True))
            for k in range(n_agents):
                world.add_agent(Agent(f"agent{k}", collide=True, sensors=[
                    Lidar(world, n_rays=180, max_range=8.0, angle_start=-math.pi / 2, angle_end=math.pi / 2, render=False)]))
            self.g = g
            return world

        def reset_world_at(self, env_index=None):
            w = self.world
            walls = w.landmarks[:4]
            pos = [(0.0, half), (0.0, -half), (half, 0.0), (-half, 0.0)]
            for k, wall in enumerate(walls):
                wall.set_pos(torch.tensor(pos[k], device=w.device).expand(w.batch_dim, 2), batch_index=env_index)
                wall.set_rot(torch.tensor([0.0 if k < 2 else math.pi / 2], device=w.device).expand(w.batch_dim, 1),
                             batch_index=env_index)
            for box in w.landmarks[4:]:
                p = (torch.rand(2, generator=self.g) * 2 - 1) * (half - 3.0)
                box.set_pos(p.to(w.device).expand(w.batch_dim, 2), batch_index=env_index)
            for a in w.agents:
                p = (torch.rand(2, generator=self.g) * 2 - 1) * (half - 1.0)
                a.set_pos(p.to(w.device).expand(w.batch_dim, 2), batch_index=env_index)

        def observation(self, agent):
            return torch.cat([agent.sensors[0].measure(), agent.state.pos, agent.state.vel], dim=-1)

        def reward(self, agent):
            return torch.zeros(self.world.batch_dim, device=self.world.device)

    return Basement()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--agents", type=int, default=10)
    ap.add_argument("--num-envs", type=int, default=1)
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args()
    import torch
    import vmas

    torch.set_num_threads(args.threads)
    env = vmas.make_env(make_scenario(args.agents), num_envs=args.num_envs, device="cpu", continuous_actions=True,
                        seed=0)
    env.reset()
    g = torch.Generator().manual_seed(1)
    actions = [(torch.rand(args.num_envs, 2, generator=g) * 2 - 1) * 0.5 for _ in range(args.agents)]
    for _ in range(10):
        env.step(actions)
    best = float("inf")
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        for _ in range(args.steps):
            env.step(actions)
        best = min(best, (time.perf_counter() - t0) / args.steps)
    print(json.dumps({"peer": "vmas", "version": vmas.__version__, "torch": torch.__version__, "agents": args.agents,
                      "num_envs": args.num_envs, "steps": args.steps, "s_per_step": best,
                      "agent_steps_per_s": args.agents * args.num_envs / best}))


if __name__ == "__main__":
    main()
