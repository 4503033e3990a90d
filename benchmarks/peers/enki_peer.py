"""Enki peer for benchmarks/bench_engine.py: a swarm of Thymio II robots avoiding obstacles.

Runs under Debian's own interpreter with Debian's Enki bindings (never a teamnav dependency)::

    apt-get install -y python3-enki2
    /usr/bin/python3 benchmarks/peers/enki_peer.py --robots 100 --steps 200

Set-up matched to teamnav's swarm case: a walled square arena of side 1 m x sqrt(N) (about one
robot per square metre), N Thymio II robots at random non-overlapping poses, each with a
Python ``controlStep`` reading its 7 proximity sensors and doing a simple obstacle avoidance
(turn away from the nearer side when a front sensor sees something, else go straight),
``world.step(0.1)`` per step. Prints one JSON line (wall and CPU time of the best repeat).
Enki works in centimetres.
"""

from __future__ import annotations

import argparse
import json
import math
import random
import sys
import time

import pyenki


class Avoider(pyenki.Thymio2):
    """Thymio with a Python control step: straight ahead, turn away from what the front sees."""

    def controlStep(self, dt: float) -> None:  # noqa: N802 - Enki's name
        d = self.proximitySensorDistances  # 7 values [cm], large when nothing is seen
        left = min(d[0], d[1])
        right = min(d[3], d[4])
        front = min(left, d[2], right)
        if front < 8.0:
            if left < right:
                self.leftSpeed, self.rightSpeed = 10.0, -10.0
            else:
                self.leftSpeed, self.rightSpeed = -10.0, 10.0
        else:
            self.leftSpeed, self.rightSpeed = 15.0, 15.0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--robots", type=int, required=True)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--warmup", type=int, default=10)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()

    side_cm = 100.0 * math.sqrt(a.robots)
    world = pyenki.World(side_cm, side_cm)
    rng = random.Random(a.seed)
    robots = []
    placed: list[tuple[float, float]] = []
    tries = 0
    while len(robots) < a.robots:
        tries += 1
        if tries > 1000 * a.robots:
            raise SystemExit(f"could not place {a.robots} robots")
        x, y = rng.uniform(10, side_cm - 10), rng.uniform(10, side_cm - 10)
        if any((x - px) ** 2 + (y - py) ** 2 < 20.0**2 for px, py in placed[-300:]):
            continue
        r = Avoider()
        r.pos = (x, y)
        r.angle = rng.uniform(-math.pi, math.pi)
        world.addObject(r)
        robots.append(r)
        placed.append((x, y))
    start = [tuple(r.pos) for r in robots]
    for _ in range(a.warmup):
        world.step(0.1)
    best = cpu = float("inf")
    for _ in range(a.repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(a.steps):
            world.step(0.1)
        best = min(best, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    moved = sum(math.hypot(r.pos[0] - s[0], r.pos[1] - s[1]) for r, s in zip(robots, start)) / len(robots)
    print(json.dumps({"peer": "enki", "robots": a.robots, "steps": a.steps, "seconds": best,
                      "mean_displacement_m": moved / 100.0, "robot_steps_per_s": a.robots * a.steps / best,
                      "cpu_seconds": cpu, "robot_steps_per_cpu_s": a.robots * a.steps / cpu}))


if __name__ == "__main__":
    sys.exit(main())
