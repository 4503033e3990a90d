"""A hand-written policy that drives robots through ``teamnav.env.ParallelEnv`` with the rules of
their scenario's built-in brain, and checks that it scores what the built-in brain scores.

The policy holds, per agent, the controller the scenario gives that robot
(``env.robot(agent).scenario_controller()``: same parameters, same random stream) and each
step calls its rule (``step``) on the observation object the environment hands the agent,
sends its radio messages, passes its log values and ``finished`` flag on, and turns its
``Action`` into the agent's action array. Nothing else crosses: the policy sees what a brain
sees.

Usage::

    python examples/builtin_rules_policy.py blazing-a-trail --metric units_total --seeds 5
    python examples/builtin_rules_policy.py los-help-simple --metric los_targets_reached --duration 600 --seeds 5
    python examples/builtin_rules_policy.py blazing-a-trail --duration 30 --seeds 1    # a quick look

It prints, per seed, the metric of ``teamnav run`` (built-in brains) and of the same scenario
driven through the environment, then both means and whether the environment's mean lies in
the built-in runs' spread (mean ± 2 standard deviations, at least ± 1 unit).
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

from teamnav.control.types import Action
from teamnav.env import ParallelEnv


def action_array(action: Action, info) -> np.ndarray:
    """A brain's ``Action`` as the agent's action: (v, omega) for a unicycle; for a holonomic-step
    robot (vx, vy) at the step speed towards ``direction_rad``, or (0, 0) to stay."""
    if info.kinematics == "holonomic_step":
        if action.direction_rad is None:
            return np.zeros(2)
        speed = info.step_length_m / info.dt_s
        return np.array([speed * math.cos(action.direction_rad), speed * math.sin(action.direction_rad)])
    return np.array([action.v_mps, action.omega_radps])


class BuiltinRules:
    """Per agent, the scenario's own brain, stepped from outside on the agent's observation."""

    def __init__(self, env: ParallelEnv) -> None:
        self.env = env
        self.brains = {agent: env.robot(agent).scenario_controller() for agent in env.agents}

    def __call__(self, agents) -> dict[str, np.ndarray]:
        actions = {}
        for agent in agents:
            port, brain = self.env.robot(agent), self.brains[agent]
            action, outbox = brain.step(port.observation)  # the built-in rule, on what a brain sees
            port.send(outbox)
            port.log(brain.log())
            port.finished = getattr(brain, "finished", None)
            actions[agent] = action_array(action, port.info)
        return actions


def env_episode(scenario: str, seed: int, duration_s: float | None = None, out_dir: str | None = None) -> dict:
    """One episode of ``scenario`` with every robot an agent driven by :class:`BuiltinRules`;
    returns the metrics of its run folder (written to ``out_dir``, or a temporary folder)."""
    env = ParallelEnv(scenario, duration_s=duration_s)
    env.reset(seed=seed)
    policy = BuiltinRules(env)
    while env.agents:
        env.step(policy(env.agents))
    with tempfile.TemporaryDirectory() as tmp:
        path = env.save_run(out_dir or Path(tmp) / "run", force=True)
        import json

        return json.loads((path / "metrics.json").read_text())


def builtin_episode(scenario: str, seed: int, duration_s: float | None = None) -> dict:
    """The same scenario and seed run by ``teamnav run`` (built-in brains)."""
    from teamnav import load_scenario, run

    return run(load_scenario(scenario, seed=seed, duration_s=duration_s), progress=False).metrics


def compare(scenario: str, metric: str, seeds: list[int], duration_s: float | None = None, *, echo=print) -> dict:
    """Both ways over ``seeds``; returns ``{"builtin": [...], "env": [...], "within": bool}``."""
    builtin, env = [], []
    for s in seeds:
        b = builtin_episode(scenario, s, duration_s)[metric]
        e = env_episode(scenario, s, duration_s)[metric]
        builtin.append(float(b))
        env.append(float(e))
        echo(f"seed {s}: teamnav run {b:g}   through ParallelEnv {e:g}")
    mb, me = statistics.fmean(builtin), statistics.fmean(env)
    sd = statistics.stdev(builtin) if len(builtin) > 1 else 0.0
    within = abs(me - mb) <= max(2.0 * sd, 1.0)
    echo(f"{metric}: built-in {mb:.2f} ± {sd:.2f} (n={len(seeds)}), through the environment {me:.2f}: "
         f"{'within' if within else 'OUTSIDE'} the built-in spread")
    return {"builtin": builtin, "env": env, "within": within}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario", help="built-in scenario name or file (e.g. blazing-a-trail, los-help-simple)")
    ap.add_argument("--metric", default="units_total", help="metric to compare (a key of metrics.json)")
    ap.add_argument("--seeds", type=int, default=5, help="seeds 0..N-1")
    ap.add_argument("--duration", type=float, help="simulated seconds (default: the scenario's)")
    args = ap.parse_args(argv)
    result = compare(args.scenario, args.metric, list(range(args.seeds)), args.duration)
    return 0 if result["within"] else 1


if __name__ == "__main__":
    sys.exit(main())
