"""IR-SIM peer for benchmarks/bench_engine.py: laser robots wandering on the basement map.

Runs in IR-SIM's own interpreter (never a teamnav dependency)::

    python -m venv /tmp/irsim-venv && /tmp/irsim-venv/bin/pip install ir-sim
    /tmp/irsim-venv/bin/python benchmarks/peers/irsim_peer.py --robots 10 --steps 20

Set-up matched to teamnav's side: the same PNG as IR-SIM's ``obstacle_map`` (60 m x 60 m at
0.05 m/px), differential-drive discs of radius 0.2 m, a 2-D lidar of 180 beams over 180°
with 10 m range, step 0.1 s, headless. Robots start at random free points (0.4 m clear of
walls, 0.5 m apart) and each step a simple behaviour reads every robot's scan in Python: turn
on the spot when the front ±30° is closer than 0.5 m, else drive at 0.4 m/s. Prints one JSON
line: robots, steps, best seconds, robot-steps per second.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time

import numpy as np

MAP = os.path.join(os.path.dirname(__file__), "..", "..", "src", "teamnav", "world", "maps", "mit",
                   "basement_hallways_5cm.png")


def start_poses(png: str, n: int, seed: int, res_m: float = 0.05) -> list[list[float]]:
    from PIL import Image
    from scipy.ndimage import distance_transform_edt

    img = np.asarray(Image.open(png).convert("L"), dtype=np.float64) / 255.0
    free = img > 0.8  # white = free (map_server free_thresh)
    clear_m = distance_transform_edt(free) * res_m
    rows, cols = np.nonzero(clear_m > 0.4)
    rng = np.random.default_rng(seed)
    h = img.shape[0]
    poses: list[list[float]] = []
    for k in rng.permutation(rows.size):
        x = (cols[k] + 0.5) * res_m
        y = (h - 1 - rows[k] + 0.5) * res_m
        if all((x - p[0]) ** 2 + (y - p[1]) ** 2 >= 0.25 for p in poses[-200:]):
            poses.append([float(x), float(y), float(rng.uniform(-np.pi, np.pi))])
            if len(poses) == n:
                return poses
    raise SystemExit(f"could not place {n} robots")


WORLD = """\
world:
  height: {size}
  width: {size}
  step_time: 0.1
  sample_time: 0.1
  offset: [0, 0]
  collision_mode: stop
  obstacle_map: {png}
robot:
  - number: {n}
    distribution: {{name: manual}}
    kinematics: {{name: diff}}
    shape: {{name: circle, radius: 0.2}}
    vel_min: [-0.5, -1.57]
    vel_max: [0.5, 1.57]
    state: {states}
    goal: {states}
    sensors:
      - name: lidar2d
        range_min: 0
        range_max: 10
        angle_range: 3.14159265
        number: 180
        noise: False
"""


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--robots", type=int, required=True)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--warmup", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--map", default=MAP)
    a = ap.parse_args()

    import irsim

    png = os.path.abspath(a.map)
    states = start_poses(png, a.robots, a.seed)
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        f.write(WORLD.format(size=60.0, png=png, n=a.robots, states=json.dumps(states)))
        world = f.name
    env = irsim.make(world, display=False, disable_all_plot=True, log_level="WARNING", seed=a.seed)
    robots = env.robot_list
    assert len(robots) == a.robots, (len(robots), a.robots)
    angles = None

    def one_step() -> None:
        nonlocal angles
        actions = []
        for r in robots:
            scan = r.get_lidar_scan()
            ranges = np.asarray(scan["ranges"], dtype=np.float64)
            if angles is None:
                angles = np.linspace(scan["angle_min"], scan["angle_max"], ranges.size)
            front = ranges[np.abs(angles) <= np.radians(30.0)].min()
            actions.append(np.array([[0.0], [1.0]]) if front < 0.5 else np.array([[0.4], [0.0]]))
        env.step(actions, action_id=list(range(len(robots))))

    start_xy = np.array([np.asarray(r.state).ravel()[:2] for r in robots])
    for _ in range(a.warmup):
        one_step()
    best = float("inf")
    for _ in range(a.repeats):
        t0 = time.perf_counter()
        for _ in range(a.steps):
            one_step()
        best = min(best, time.perf_counter() - t0)
    end_xy = np.array([np.asarray(r.state).ravel()[:2] for r in robots])
    moved_m = float(np.mean(np.hypot(*(end_xy - start_xy).T)))
    print(json.dumps({"peer": "ir-sim", "version": irsim.__version__, "robots": a.robots, "steps": a.steps,
                      "mean_displacement_m": moved_m,
                      "seconds": best, "robot_steps_per_s": a.robots * a.steps / best}))


if __name__ == "__main__":
    sys.exit(main())
