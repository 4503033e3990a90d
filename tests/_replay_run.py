"""A small run folder that exercises every replay / MCAP layer (shared by the replay and MCAP tests).

"Lab" robots circle in an arena with a laser and a robot detector, broadcast every step, fire
place events and log, through ``log()["layers"]``, crumbs (points in their odometry frame), a
goal (a marker) and a state string, so the run folder holds true and believed poses, scans,
detections, messages, events and controller layers.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from pydantic import BaseModel, ConfigDict

from teamnav.control import registry
from teamnav.control.types import Action, Message

LAB = "lab-replay-test-v1"


class LabParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    v_mps: float = 0.4
    omega_radps: float = 0.5


class Lab:
    Params = LabParams

    def __init__(self, params, rng, info):
        self.p, self.info = params, info
        self.odom: list[tuple[float, float]] = []
        self.step_no = 0

    def step(self, obs):
        self.step_no = obs.step
        self.odom.append((float(obs.odom_pose[0]), float(obs.odom_pose[1])))
        msg = [Message(self.info.robot_id, obs.time_s, {"step": obs.step}, kind="hello")]
        return Action(self.p.v_mps, self.p.omega_radps * (1 if self.info.robot_id % 2 else -1)), msg

    def log(self):
        crumbs = np.array(self.odom[-40::8], float).reshape(-1, 2)
        goal = {"kind": "markers", "data": [[1.0, 0.5, 0.0]], "description": "where it wants to go (odometry frame)"}
        state = "carrying" if (self.step_no // 10) % 2 else "searching"
        return {"n": len(self.odom), "layers": {"crumbs": crumbs, "goal": goal, "state": state}}


def register() -> None:
    if LAB not in registry._REGISTRY:
        registry.register(LAB, f"{__name__}:Lab")


SCENARIO = f"""
name: lab
description: replay / MCAP test run
map:
  arena: {{width_m: 8.0, height_m: 6.0, resolution_m: 0.05, wall_thickness_m: 0.2}}
duration_s: 6.0
dt_s: 0.1
seed: 5
record_scans: true
robots:
  - name: lab
    count: 3
    radius_m: 0.2
    controller: {LAB}
    sensors:
      - kind: laser
        n_beams: 24
        fov_deg: 270
        max_range_m: 5.0
        noise_std_m: 0.01
    detector:
      max_range_m: 6.0
      line_of_sight: false
    odometry:
      alpha: [0.05, 0.01, 0.05, 0.01]
      heading_drift_deg_per_min: 3.0
    start:
      region: [2.0, 6.0, 2.0, 4.0]
places:
  - {{name: middle, x_m: 4.0, y_m: 3.0, radius_m: 1.5, event: at_middle, on: inside}}
radio:
  mode: broadcast
"""


def make_run(folder: Path) -> Path:
    """Run the lab scenario into ``folder / "run"`` and return that run folder."""
    from teamnav.experiments.runner import run

    register()
    yml = folder / "lab.yaml"
    yml.write_text(SCENARIO, encoding="utf-8")
    out = folder / "run"
    run(str(yml), out_dir=out, progress=False)
    return out
